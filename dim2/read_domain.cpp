#include "dim2/read_domain.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "dim2/read_native.hpp"
#include "dim2/read_poly.hpp"
#include "dim2/read_svg.hpp"

namespace febemesh::dim2 {

std::string read_text_file(const std::string& path) {
  std::error_code ec;
  auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) throw InputError(path + ": cannot read: no such file");
  if (std::filesystem::is_directory(status)) throw InputError(path + ": cannot read: it is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot read: " + std::strerror(errno));
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw InputError(path + ": cannot read: I/O error");
  return ss.str();
}

TextPos position_of_offset(const std::string& text, std::size_t offset) {
  TextPos p;
  for (std::size_t i = 0; i < offset && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++p.line;
      p.col = 1;
    } else if ((static_cast<unsigned char>(text[i]) & 0xC0) != 0x80) {
      ++p.col;
    }
  }
  return p;
}

std::string where(const std::string& source, TextPos p) {
  return source + ":" + std::to_string(p.line) + ":" + std::to_string(p.col) + ": ";
}

std::string where(const std::string& source, const P2& p) {
  std::ostringstream os;
  os.precision(9);
  os << source << ": near (" << p.x() << ", " << p.y() << "): ";
  return os.str();
}

std::optional<std::string> loop_extent_problem(const Box<2>& box) {
  const double across = box.extent().maxCoeff();
  if (across >= min_loop_extent) return std::nullopt;
  std::ostringstream os;
  os.precision(3);
  os << "the loop is " << across << " across, under the smallest accepted extent " << min_loop_extent << " (scale the input)";
  return os.str();
}

void check_level(double level, const std::string& place) {
  constexpr double max_level = 28.0;
  if (!std::isfinite(level)) throw InputError(place + "control level is not a finite number");
  if (level < 0.0) throw InputError(place + "control level " + std::to_string(level) + " is negative (levels are 0..28)");
  if (level > max_level) {
    // A tree refined to `level` everywhere has 4^level leaves; about 12 bytes each.
    const double cells = std::pow(4.0, level);
    const double bytes = cells * 12.0;
    std::ostringstream os;
    os.precision(3);
    os << place << "control level " << level << " is above the maximum 28: a mesh at that level needs up to 4^" << level
       << " = " << cells << " cells, about " << bytes / 1e9 << " GB at 12 bytes per cell";
    throw InputError(os.str());
  }
}

namespace {

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

}  // namespace

Domain read_domain(const std::string& path) {
  const std::string ext = lower_extension(path);
  if (ext == ".json") return read_native(path);
  if (ext == ".svg") return read_svg(path);
  if (ext == ".poly") return read_poly(path);
  if (!ext.empty())
    throw InputError(path + ": unknown input format '" + ext + "' (expected .json, .svg or .poly)");
  // No extension: look at the content.
  const std::string text = read_text_file(path);
  auto first = text.find_first_not_of(" \t\r\n");
  if (first != std::string::npos && text[first] == '{') return parse_native(text, path);
  if (first != std::string::npos && text[first] == '<' && text.find("<svg") != std::string::npos)
    return parse_svg(text, path);
  throw InputError(path + ": cannot tell the input format (no extension; expected .json, .svg or .poly content)");
}

}  // namespace febemesh::dim2
