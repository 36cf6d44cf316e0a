#include "dim2/read_native.hpp"

#include <cmath>
#include <nlohmann/json.hpp>
#include <set>

#include "core/error.hpp"
#include "dim2/read_domain.hpp"
#include "dim2/svg_path.hpp"

namespace febemesh::dim2 {

namespace {

using nlohmann::json;

class NativeReader {
 public:
  explicit NativeReader(const std::string& source) : source_(source) {}

  Domain read(const json& doc, NativeOptions* options) {
    if (!doc.is_object()) fail("", "the document must be a JSON object with a \"loops\" array");
    check_keys(doc, "", {"loops", "interior", "options"});
    Domain dom;
    dom.source = source_;
    if (!doc.contains("loops")) fail("", "no geometry: missing \"loops\"");
    const json& loops = doc["loops"];
    if (!loops.is_array()) fail("/loops", "must be an array of loops");
    if (loops.empty()) fail("/loops", "no geometry: the loop list is empty");
    for (std::size_t i = 0; i < loops.size(); ++i) dom.loops.push_back(loop(loops[i], "/loops/" + std::to_string(i), i));
    if (doc.contains("interior")) {
      const json& in = doc["interior"];
      if (!in.is_array()) fail("/interior", "must be an array of points");
      for (std::size_t i = 0; i < in.size(); ++i) dom.interior.push_back(interior(in[i], "/interior/" + std::to_string(i)));
    }
    if (doc.contains("options")) {
      const json& o = doc["options"];
      if (!o.is_object()) fail("/options", "must be an object");
      check_keys(o, "/options", {"level", "elements"});
      if (o.contains("level")) {
        dom.default_level = number(o["level"], "/options/level");
        check_level(dom.default_level, source_ + ": /options/level: ");
      }
      if (o.contains("elements")) {
        const json& e = o["elements"];
        if (!e.is_string() || (e != "tri" && e != "quad" && e != "mixed"))
          fail("/options/elements", "must be \"tri\", \"quad\" or \"mixed\"");
        if (options) options->elements = e.get<std::string>();
      }
    }
    return dom;
  }

 private:
  const std::string& source_;

  [[noreturn]] void fail(const std::string& pointer, const std::string& why) const {
    throw InputError(source_ + ": " + (pointer.empty() ? std::string("/") : pointer) + ": " + why);
  }

  void check_keys(const json& o, const std::string& pointer, std::set<std::string> allowed) const {
    for (const auto& [k, v] : o.items()) {
      (void)v;
      if (allowed.count(k) || k == "comment" || (!k.empty() && k[0] == '_')) continue;
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      fail(pointer + "/" + k, "unknown key \"" + k + "\" (expected " + list + ")");
    }
  }

  double number(const json& v, const std::string& pointer) const {
    if (!v.is_number()) fail(pointer, "must be a number");
    const double x = v.get<double>();
    if (!std::isfinite(x)) fail(pointer, "must be finite");
    if (std::abs(x) > max_coordinate) fail(pointer, "magnitude exceeds the largest accepted 1e15");
    return x;
  }

  P2 point(const json& p, const std::string& pointer) const {
    if (!p.is_object()) fail(pointer, "must be an object {\"x\": .., \"y\": ..}");
    if (!p.contains("x") || !p.contains("y")) fail(pointer, "needs both \"x\" and \"y\"");
    return P2(number(p["x"], pointer + "/x"), number(p["y"], pointer + "/y"));
  }

  Loop loop(const json& l, const std::string& pointer, std::size_t index) const {
    if (!l.is_object()) fail(pointer, "must be an object with \"points\"");
    check_keys(l, pointer, {"name", "points"});
    std::string name = "loop " + std::to_string(index + 1);
    if (l.contains("name")) {
      if (!l["name"].is_string()) fail(pointer + "/name", "must be a string");
      name = l["name"].get<std::string>();
    }
    if (!l.contains("points") || !l["points"].is_array()) fail(pointer, "needs a \"points\" array");
    const json& pts = l["points"];
    if (pts.size() < 3) fail(pointer + "/points", "a closed loop needs at least 3 control points, got " + std::to_string(pts.size()));
    std::vector<ControlPoint> cps;
    for (std::size_t k = 0; k < pts.size(); ++k) {
      const std::string pp = pointer + "/points/" + std::to_string(k);
      ControlPoint cp;
      cp.p = point(pts[k], pp);
      check_keys(pts[k], pp, {"x", "y", "corner", "level"});
      if (pts[k].contains("corner")) {
        if (!pts[k]["corner"].is_boolean()) fail(pp + "/corner", "must be true or false");
        cp.corner = pts[k]["corner"].get<bool>();
      }
      if (pts[k].contains("level")) {
        cp.level = number(pts[k]["level"], pp + "/level");
        check_level(cp.level, where(source_, cp.p) + pp + "/level: ");
      }
      cps.push_back(cp);
    }
    Loop loop = loop_from_bspline(cps, name);
    Box<2> box = Box<2>::empty();
    for (const auto& c : cps) box.expand(c.p);
    if (const std::optional<std::string> why = loop_extent_problem(box))
      throw InputError(where(source_, cps.front().p) + pointer + " (\"" + name + "\"): " + *why);
    const double size = box.extent().norm();
    if (loop.pieces.empty() || std::abs(signed_area(loop.pieces)) <= 1e-14 * size * size)
      throw InputError(where(source_, cps.front().p) + pointer + " (\"" + name + "\"): loop encloses zero area (degenerate)");
    return loop;
  }

  InteriorControl interior(const json& p, const std::string& pointer) const {
    InteriorControl c;
    c.p = point(p, pointer);
    check_keys(p, pointer, {"x", "y", "level", "radius"});
    if (!p.contains("level")) fail(pointer, "an interior control point needs a \"level\"");
    c.level = number(p["level"], pointer + "/level");
    check_level(c.level, where(source_, c.p) + pointer + "/level: ");
    if (p.contains("radius")) {
      c.radius = number(p["radius"], pointer + "/radius");
      if (c.radius < 0) fail(pointer + "/radius", "must not be negative");
    }
    return c;
  }
};

}  // namespace

Domain parse_native(const std::string& text, const std::string& source, NativeOptions* options) {
  json doc;
  try {
    doc = json::parse(text, nullptr, true, false);
  } catch (const json::parse_error& e) {
    // e.byte is 1-based: the byte at which the parser gave up.
    const std::size_t at = e.byte > 0 ? e.byte - 1 : 0;
    std::string why = e.what();
    if (auto p = why.find("parse error"); p != std::string::npos) why = why.substr(p);
    throw InputError(where(source, position_of_offset(text, at)) + "malformed JSON: " + why);
  } catch (const json::exception& e) {
    throw InputError(source + ": malformed JSON: " + e.what());
  }
  try {
    return NativeReader(source).read(doc, options);
  } catch (const InputError& e) {
    // The curve kernel names the loop but not the file.
    if (std::string_view(e.what()).substr(0, source.size()) != source) throw InputError(source + ": " + e.what());
    throw;
  }
}

Domain read_native(const std::string& path, NativeOptions* options) {
  return parse_native(read_text_file(path), path, options);
}

}  // namespace febemesh::dim2
