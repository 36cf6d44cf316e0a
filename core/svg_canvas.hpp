#pragma once
// A tiny SVG writer for the 2D stage figures. Shapes are given in mesh coordinates (y up); the
// canvas fits them into a viewBox of the requested width and flips y, so figures look upright.
// Stroke widths, radii given in pixels and font sizes are in output pixels, whatever the scale.

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "core/box.hpp"

namespace febemesh {

struct SvgStyle {
  std::string fill = "none";
  std::string stroke = "black";
  double stroke_width = 1.0;  ///< pixels
  double opacity = 1.0;
};

/// "#rrggbb" from components in [0, 1].
std::string svg_rgb(double r, double g, double b);
/// A colour of a fixed, distinguishable palette (cycles).
std::string svg_palette(int i);

class SvgCanvas;
/// A legend's row of colour swatches: item k (its fill colour, its label) a square of `side`
/// (mesh units) with its lower left corner at first + (k slot, 0), the label after it on the
/// same baseline (12 px).
void swatch_row(SvgCanvas& c, const Point<2>& first, double slot, double side,
                const std::vector<std::pair<std::string, std::string>>& items);

class SvgCanvas {
 public:
  explicit SvgCanvas(double width_px = 800.0, double margin_px = 10.0);

  void polygon(const std::vector<Point<2>>& pts, const SvgStyle& style);
  void polyline(const std::vector<Point<2>>& pts, const SvgStyle& style);
  void line(const Point<2>& a, const Point<2>& b, const SvgStyle& style);
  /// Radius in mesh units (a disc scaled with the figure).
  void circle(const Point<2>& c, double radius, const SvgStyle& style);
  /// Radius in pixels (a marker that keeps its size).
  void dot(const Point<2>& c, double radius_px, const SvgStyle& style);
  /// Text anchored at its start, upright.
  void text(const Point<2>& at, const std::string& s, double size_px = 12.0, const std::string& colour = "black");
  /// Fits this box instead of the shapes' bounding box.
  void set_view(const Box<2>& box) { view_ = box; has_view_ = true; }

  std::string str() const;
  /// Throws InputError when the file cannot be written.
  void write(const std::filesystem::path& path) const;

 private:
  enum class Kind { Polygon, Polyline, Circle, Dot, Text };
  struct Shape {
    Kind kind;
    std::vector<Point<2>> pts;
    double size;
    SvgStyle style;
    std::string text;
  };
  std::vector<Shape> shapes_;
  Box<2> bounds_ = Box<2>::empty();
  Box<2> view_;
  bool has_view_ = false;
  double width_px_, margin_px_;
};

}  // namespace febemesh
