// Coordinates are transformed when written (no SVG transform), so text stays upright and
// stroke widths stay in pixels.

#include "core/svg_canvas.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>

#include "core/error.hpp"

namespace febemesh {

namespace {

std::string num(double v) {
  // Three decimals of a pixel are plenty and keep the files small and deterministic.
  char buf[32];
  const double r = std::round(v * 1000.0) / 1000.0;
  const auto res = std::to_chars(buf, buf + sizeof buf, r == 0.0 ? 0.0 : r);
  return std::string(buf, res.ptr);
}

std::string escape(const std::string& s) {
  std::string out;
  for (const char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string style_attrs(const SvgStyle& s) {
  std::string out = " fill=\"" + escape(s.fill) + "\" stroke=\"" + escape(s.stroke) + "\" stroke-width=\"" +
                    num(s.stroke_width) + "\"";
  if (s.opacity != 1.0) out += " opacity=\"" + num(s.opacity) + "\"";
  return out;
}

}  // namespace

std::string svg_rgb(double r, double g, double b) {
  static constexpr char hex[] = "0123456789abcdef";
  std::string out = "#";
  for (const double c : {r, g, b}) {
    const int v = static_cast<int>(std::lround(std::clamp(c, 0.0, 1.0) * 255.0));
    out += hex[v / 16];
    out += hex[v % 16];
  }
  return out;
}

std::string svg_palette(int i) {
  // Okabe-Ito colour-blind-safe palette.
  static const char* colours[] = {"#0072b2", "#e69f00", "#009e73", "#d55e00", "#cc79a7", "#56b4e9", "#f0e442", "#000000"};
  const int n = static_cast<int>(std::size(colours));
  return colours[((i % n) + n) % n];
}

void swatch_row(SvgCanvas& c, const Point<2>& first, double slot, double side,
                const std::vector<std::pair<std::string, std::string>>& items) {
  for (std::size_t k = 0; k < items.size(); ++k) {
    const double x = first.x() + slot * static_cast<double>(k), y = first.y();
    c.polygon({Point<2>(x, y + side), Point<2>(x + side, y + side), Point<2>(x + side, y), Point<2>(x, y)},
              {items[k].first, "#555555", 0.5, 1.0});
    c.text(Point<2>(x + 1.4 * side, y), items[k].second, 12.0, "#222222");
  }
}

SvgCanvas::SvgCanvas(double width_px, double margin_px) : width_px_(width_px), margin_px_(margin_px) {}

void SvgCanvas::polygon(const std::vector<Point<2>>& pts, const SvgStyle& style) {
  for (const auto& p : pts) bounds_.expand(p);
  shapes_.push_back({Kind::Polygon, pts, 0.0, style, {}});
}

void SvgCanvas::polyline(const std::vector<Point<2>>& pts, const SvgStyle& style) {
  for (const auto& p : pts) bounds_.expand(p);
  shapes_.push_back({Kind::Polyline, pts, 0.0, style, {}});
}

void SvgCanvas::line(const Point<2>& a, const Point<2>& b, const SvgStyle& style) { polyline({a, b}, style); }

void SvgCanvas::circle(const Point<2>& c, double radius, const SvgStyle& style) {
  bounds_.expand(c - Point<2>::Constant(radius));
  bounds_.expand(c + Point<2>::Constant(radius));
  shapes_.push_back({Kind::Circle, {c}, radius, style, {}});
}

void SvgCanvas::dot(const Point<2>& c, double radius_px, const SvgStyle& style) {
  bounds_.expand(c);
  shapes_.push_back({Kind::Dot, {c}, radius_px, style, {}});
}

void SvgCanvas::text(const Point<2>& at, const std::string& s, double size_px, const std::string& colour) {
  bounds_.expand(at);
  SvgStyle style;
  style.fill = colour;
  shapes_.push_back({Kind::Text, {at}, size_px, style, s});
}

std::string SvgCanvas::str() const {
  Box<2> box = has_view_ ? view_ : bounds_;
  if (!(box.lo.array() <= box.hi.array()).all()) box = Box<2>{Point<2>::Zero(), Point<2>::Ones()};
  const double extent_x = std::max(box.hi.x() - box.lo.x(), 1e-300);
  const double extent_y = box.hi.y() - box.lo.y();
  double scale = (width_px_ - 2.0 * margin_px_) / extent_x;
  if (!(scale > 0.0) || !std::isfinite(scale)) scale = 1.0;
  const double height_px = extent_y * scale + 2.0 * margin_px_;
  auto x = [&](const Point<2>& p) { return num((p.x() - box.lo.x()) * scale + margin_px_); };
  auto y = [&](const Point<2>& p) { return num((box.hi.y() - p.y()) * scale + margin_px_); };
  auto points = [&](const std::vector<Point<2>>& pts) {
    std::string out;
    for (const auto& p : pts) {
      if (!out.empty()) out += ' ';
      out += x(p);
      out += ',';
      out += y(p);
    }
    return out;
  };

  std::string out = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" +
                    num(width_px_) + "\" height=\"" + num(height_px) + "\" viewBox=\"0 0 " + num(width_px_) + " " +
                    num(height_px) + "\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  for (const Shape& s : shapes_) {
    switch (s.kind) {
      case Kind::Polygon:
        out += "<polygon points=\"" + points(s.pts) + "\"" + style_attrs(s.style) + " stroke-linejoin=\"round\"/>\n";
        break;
      case Kind::Polyline:
        out += "<polyline points=\"" + points(s.pts) + "\"" + style_attrs(s.style) + " stroke-linejoin=\"round\"/>\n";
        break;
      case Kind::Circle:
        out += "<circle cx=\"" + x(s.pts[0]) + "\" cy=\"" + y(s.pts[0]) + "\" r=\"" + num(s.size * scale) + "\"" +
               style_attrs(s.style) + "/>\n";
        break;
      case Kind::Dot:
        out += "<circle cx=\"" + x(s.pts[0]) + "\" cy=\"" + y(s.pts[0]) + "\" r=\"" + num(s.size) + "\"" +
               style_attrs(s.style) + "/>\n";
        break;
      case Kind::Text:
        out += "<text x=\"" + x(s.pts[0]) + "\" y=\"" + y(s.pts[0]) + "\" font-family=\"sans-serif\" font-size=\"" +
               num(s.size) + "\" fill=\"" + escape(s.style.fill) + "\">" + escape(s.text) + "</text>\n";
        break;
    }
  }
  out += "</svg>\n";
  return out;
}

void SvgCanvas::write(const std::filesystem::path& path) const {
  const std::string text = str();
  std::ofstream out(path, std::ios::binary);
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  if (!out) throw InputError("cannot write " + path.string());
}

}  // namespace febemesh
