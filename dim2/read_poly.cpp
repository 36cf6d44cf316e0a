#include "dim2/read_poly.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>

#include "core/error.hpp"
#include "dim2/read_domain.hpp"
#include "dim2/svg_path.hpp"

namespace febemesh::dim2 {

namespace {

struct Token {
  std::string_view text;
  TextPos pos;
};

/// Triangle's files are line records of whitespace-separated numbers; '#' starts a comment.
class Records {
 public:
  Records(const std::string& text, const std::string& source) : source_(source) {
    std::size_t i = 0;
    int line = 1;
    while (i <= text.size()) {
      std::size_t e = text.find('\n', i);
      if (e == std::string::npos) e = text.size();
      std::string_view l(text.data() + i, e - i);
      if (auto h = l.find('#'); h != std::string_view::npos) l = l.substr(0, h);
      std::vector<Token> toks;
      std::size_t k = 0;
      while (k < l.size()) {
        while (k < l.size() && std::isspace(static_cast<unsigned char>(l[k]))) ++k;
        std::size_t b = k;
        while (k < l.size() && !std::isspace(static_cast<unsigned char>(l[k]))) ++k;
        if (k > b) toks.push_back(Token{l.substr(b, k - b), TextPos{line, static_cast<int>(b) + 1}});
      }
      if (!toks.empty()) lines_.push_back(std::move(toks));
      end_ = TextPos{line, static_cast<int>(l.size()) + 1};
      i = e + 1;
      ++line;
    }
  }

  bool at_end() const { return next_ >= lines_.size(); }
  const std::vector<Token>& next(const char* what) {
    if (at_end()) throw InputError(where(source_, end_) + "file ends where " + what + " was expected");
    return lines_[next_++];
  }
  const std::string& source() const { return source_; }

  [[noreturn]] void fail(const Token& t, const std::string& why) const { throw InputError(where(source_, t.pos) + why); }

  long integer(const Token& t, const char* what, long lo, long hi) const {
    long v = 0;
    auto [p, ec] = std::from_chars(t.text.data(), t.text.data() + t.text.size(), v);
    if (ec != std::errc() || p != t.text.data() + t.text.size())
      fail(t, std::string("expected ") + what + " (an integer), got '" + std::string(t.text) + "'");
    if (v < lo || v > hi)
      fail(t, std::string(what) + " " + std::to_string(v) + " out of range [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return v;
  }
  double real(const Token& t, const char* what) const {
    double v = 0;
    const char* b = t.text.data();
    if (!t.text.empty() && *b == '+') ++b;
    auto [p, ec] = std::from_chars(b, t.text.data() + t.text.size(), v);
    if (ec == std::errc::result_out_of_range) fail(t, std::string(what) + " '" + std::string(t.text) + "' overflows");
    if (ec != std::errc() || p != t.text.data() + t.text.size())
      fail(t, std::string("expected ") + what + " (a number), got '" + std::string(t.text) + "'");
    if (!std::isfinite(v)) fail(t, std::string(what) + " is not finite");
    if (std::abs(v) > max_coordinate) fail(t, std::string(what) + " exceeds the largest accepted magnitude 1e15");
    return v;
  }

 private:
  std::string source_;
  std::vector<std::vector<Token>> lines_;
  std::size_t next_ = 0;
  TextPos end_;
};

constexpr long max_count = 100'000'000;

/// Reads a vertex section (header and records) as in .node files; returns the vertices and the
/// first vertex number (0 or 1).
std::vector<P2> read_vertices(Records& r, const std::vector<Token>& head, long& base) {
  if (head.size() < 1) r.fail(head[0], "vertex header needs a count");
  const long nv = r.integer(head[0], "vertex count", 0, max_count);
  long dim = 2, nattr = 0, nmark = 0;
  if (head.size() > 1) dim = r.integer(head[1], "dimension", 2, 2);
  if (head.size() > 2) nattr = r.integer(head[2], "attribute count", 0, 1000);
  if (head.size() > 3) nmark = r.integer(head[3], "boundary marker count", 0, 1);
  (void)dim;
  std::vector<P2> v;
  for (long i = 0; i < nv; ++i) {
    const auto& rec = r.next("a vertex");
    const std::size_t need = static_cast<std::size_t>(3 + nattr + nmark);
    if (rec.size() < need) r.fail(rec[0], "vertex record needs " + std::to_string(need) + " numbers, got " + std::to_string(rec.size()));
    const long id = r.integer(rec[0], "vertex number", 0, max_count + 1);
    if (i == 0) {
      if (id != 0 && id != 1) r.fail(rec[0], "vertex numbers must start at 0 or 1");
      base = id;
    } else if (id != base + i) {
      r.fail(rec[0], "vertex number " + std::to_string(id) + " out of sequence (expected " + std::to_string(base + i) + ")");
    }
    v.emplace_back(r.real(rec[1], "x coordinate"), r.real(rec[2], "y coordinate"));
  }
  return v;
}

double shoelace(const std::vector<P2>& p) {
  double a = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const P2& u = p[i] - p[0];
    const P2& w = p[(i + 1) % p.size()] - p[0];
    a += u.x() * w.y() - u.y() * w.x();
  }
  return 0.5 * a;
}

/// Winding number of a closed polygon around q.
int winding(const std::vector<P2>& poly, const P2& q) {
  int w = 0;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const P2& a = poly[i];
    const P2& b = poly[(i + 1) % poly.size()];
    const double cross = (b.x() - a.x()) * (q.y() - a.y()) - (q.x() - a.x()) * (b.y() - a.y());
    if (a.y() <= q.y()) {
      if (b.y() > q.y() && cross > 0) ++w;
    } else if (b.y() <= q.y() && cross < 0) {
      --w;
    }
  }
  return w;
}

}  // namespace

Domain parse_poly(const std::string& text, const std::string& source, const std::string& node_text,
                  const std::string& node_source) {
  Records r(text, source);
  const auto& head = r.next("the vertex header");
  long base = 0;
  std::vector<P2> verts;
  if (r.integer(head[0], "vertex count", 0, max_count) == 0) {
    // Triangle's convention: the vertices are in the companion .node file.
    if (node_text.empty()) r.fail(head[0], "zero vertices here and no companion .node file to read them from");
    Records nr(node_text, node_source);
    verts = read_vertices(nr, nr.next("the .node header"), base);
  } else {
    verts = read_vertices(r, head, base);
  }

  const auto& shead = r.next("the segment header");
  const long ns = r.integer(shead[0], "segment count", 0, max_count);
  long smark = 0;
  if (shead.size() > 1) smark = r.integer(shead[1], "boundary marker count", 0, 1);
  (void)smark;
  const long nv = static_cast<long>(verts.size());
  std::vector<std::array<long, 2>> segs;
  std::vector<Token> seg_tok;
  std::map<std::pair<long, long>, long> seen;
  for (long i = 0; i < ns; ++i) {
    const auto& rec = r.next("a segment");
    if (rec.size() < 3) r.fail(rec[0], "segment record needs a number and two end points");
    const long a = r.integer(rec[1], "segment end point", base, base + nv - 1) - base;
    const long b = r.integer(rec[2], "segment end point", base, base + nv - 1) - base;
    if (a == b) r.fail(rec[1], "segment joins vertex " + std::to_string(a + base) + " to itself");
    if (verts[a] == verts[b]) r.fail(rec[1], "segment has zero length (vertices " + std::to_string(a + base) + " and " + std::to_string(b + base) + " coincide)");
    auto key = std::minmax(a, b);
    if (seen.count(key)) r.fail(rec[0], "duplicate segment between vertices " + std::to_string(a + base) + " and " + std::to_string(b + base));
    seen[key] = i;
    segs.push_back({a, b});
    seg_tok.push_back(rec[0]);
  }

  std::vector<P2> holes;
  std::vector<Token> hole_tok;
  if (!r.at_end()) {
    const auto& hhead = r.next("the hole header");
    const long nh = r.integer(hhead[0], "hole count", 0, max_count);
    for (long i = 0; i < nh; ++i) {
      const auto& rec = r.next("a hole point");
      if (rec.size() < 3) r.fail(rec[0], "hole record needs a number and x, y");
      holes.emplace_back(r.real(rec[1], "hole x"), r.real(rec[2], "hole y"));
      hole_tok.push_back(rec[0]);
    }
  }
  // Regional attributes (optional) do not affect the geometry; they are checked for form only.
  if (!r.at_end()) {
    const auto& rhead = r.next("the region header");
    const long nr = r.integer(rhead[0], "region count", 0, max_count);
    for (long i = 0; i < nr; ++i) {
      const auto& rec = r.next("a region");
      if (rec.size() < 4) r.fail(rec[0], "region record needs a number, x, y and an attribute");
    }
  }
  if (segs.empty()) throw InputError(source + ": no geometry: the file has no segments");

  // Every vertex on a segment must have exactly two: then the segments are disjoint closed chains.
  std::vector<std::vector<long>> at(verts.size());
  for (long s = 0; s < static_cast<long>(segs.size()); ++s)
    for (long e : segs[s]) at[e].push_back(s);
  for (long v = 0; v < nv; ++v)
    if (!at[v].empty() && at[v].size() != 2)
      throw InputError(where(source, verts[v]) + "vertex " + std::to_string(v + base) + " has " + std::to_string(at[v].size()) +
                       " segments; the segments must form closed loops (each vertex on exactly two)");

  Domain dom;
  dom.source = source;
  std::vector<std::vector<P2>> polys;
  std::vector<std::uint8_t> used(segs.size(), 0);
  for (std::size_t s0 = 0; s0 < segs.size(); ++s0) {
    if (used[s0]) continue;
    std::vector<P2> poly;
    long v = segs[s0][0];
    long s = static_cast<long>(s0);
    while (!used[s]) {
      used[s] = 1;
      poly.push_back(verts[v]);
      v = segs[s][0] == v ? segs[s][1] : segs[s][0];
      s = at[v][0] == s ? at[v][1] : at[v][0];
    }
    const double area = shoelace(poly);
    Box<2> box = Box<2>::empty();
    for (const auto& p : poly) box.expand(p);
    if (const std::optional<std::string> why = loop_extent_problem(box))
      throw InputError(where(source, poly.front()) + "loop " + std::to_string(polys.size() + 1) + " (from segment " +
                       std::to_string(s0 + base) + "): " + *why);
    if (std::abs(area) <= 1e-14 * box.extent().squaredNorm())
      throw InputError(where(source, poly.front()) + "loop " + std::to_string(polys.size() + 1) + " (from segment " +
                       std::to_string(s0 + base) + ") encloses zero area");
    polys.push_back(std::move(poly));
  }

  // Nesting depth of each loop (how many others contain it), probed at an edge midpoint.
  const std::size_t nl = polys.size();
  std::vector<int> depth(nl, 0);
  for (std::size_t i = 0; i < nl; ++i) {
    const P2 probe = 0.5 * (polys[i][0] + polys[i][1]);
    for (std::size_t j = 0; j < nl; ++j)
      if (j != i && winding(polys[j], probe) != 0) ++depth[i];
  }
  std::vector<std::uint8_t> has_hole_point(nl, 0);
  for (std::size_t h = 0; h < holes.size(); ++h) {
    int d = 0;
    std::size_t innermost = nl;
    for (std::size_t j = 0; j < nl; ++j)
      if (winding(polys[j], holes[h]) != 0) {
        ++d;
        if (innermost == nl || depth[j] > depth[innermost]) innermost = j;
      }
    if (d % 2 == 1)
      throw InputError(where(source, hole_tok[h].pos) + "hole point (" + std::to_string(holes[h].x()) + ", " +
                       std::to_string(holes[h].y()) + ") lies in the solid (inside loop " + std::to_string(innermost + 1) +
                       ", which the nesting makes solid)");
    if (innermost < nl) has_hole_point[innermost] = 1;
  }
  for (std::size_t i = 0; i < nl; ++i) {
    const bool is_hole = depth[i] % 2 == 1;
    if (is_hole && !has_hole_point[i])
      throw InputError(where(source, polys[i].front()) + "loop " + std::to_string(i + 1) +
                       " lies inside the solid but no hole point marks it (Triangle would mesh it as solid; add a hole point)");
    // Solid on the left: outer boundaries counter-clockwise, holes clockwise.
    if ((shoelace(polys[i]) > 0) == is_hole) std::reverse(polys[i].begin(), polys[i].end());
    try {
      dom.loops.push_back(loop_from_polygon(polys[i], "loop " + std::to_string(i + 1)));
    } catch (const InputError& e) {
      throw InputError(where(source, polys[i].front()) + e.what());  // the kernel names the loop, not the file
    }
  }
  return dom;
}

Domain read_poly(const std::string& path) {
  const std::string text = read_text_file(path);
  // Only read the .node file if the .poly defers to it.
  std::string node_text, node_path;
  {
    auto first = text.find_first_not_of(" \t\r\n");
    while (first != std::string::npos && text[first] == '#') {
      first = text.find('\n', first);
      if (first != std::string::npos) first = text.find_first_not_of(" \t\r\n", first);
    }
    if (first != std::string::npos && text[first] == '0' &&
        (first + 1 >= text.size() || std::isspace(static_cast<unsigned char>(text[first + 1])))) {
      node_path = std::filesystem::path(path).replace_extension(".node").string();
      node_text = read_text_file(node_path);
    }
  }
  return parse_poly(text, path, node_text, node_path);
}

}  // namespace febemesh::dim2
