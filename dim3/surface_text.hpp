#pragma once
// What the text surface readers (OFF, OBJ, ASCII PLY) share: the file's lines with their
// numbers, tokens, numbers parsed whole, and the error "<name>:<line>: <why>".

#include <cerrno>
#include <cstdlib>
#include <istream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "core/error.hpp"

namespace febemesh::dim3::text {

/// Non-empty lines with comments (from '#' on) removed, each with its 1-based number.
struct Lines {
  std::vector<std::pair<std::string, int>> items;
  std::size_t next = 0;
  bool done() const { return next >= items.size(); }
};

inline Lines content_lines(std::istream& in) {
  Lines lines;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    // Blank = only what split() skips (isspace: \f and \v too), so every kept line has a token.
    if (line.find_first_not_of(" \t\r\n\f\v") == std::string::npos) continue;
    lines.items.emplace_back(line, number);
  }
  return lines;
}

inline std::vector<std::string> split(const std::string& s) {
  std::istringstream ss(s);
  std::vector<std::string> out;
  for (std::string tok; ss >> tok;) out.push_back(tok);
  return out;
}

/// The whole of `s` as a double (strtod: "inf" and "nan" parse; the callers refuse them).
inline bool parse_double(const std::string& s, double& out) {
  errno = 0;
  char* end = nullptr;
  out = std::strtod(s.c_str(), &end);
  return end != s.c_str() && *end == '\0';
}

/// The whole of `s` as a decimal integer, without overflow.
inline bool parse_long(const std::string& s, long long& out) {
  errno = 0;
  char* end = nullptr;
  out = std::strtoll(s.c_str(), &end, 10);
  return end != s.c_str() && *end == '\0' && errno == 0;
}

[[noreturn]] inline void fail(const std::string& name, int line, const std::string& why) {
  throw InputError(name + (line > 0 ? ":" + std::to_string(line) : std::string()) + ": " + why);
}

}  // namespace febemesh::dim3::text
