// The interior-region rules of the boundary octants: remove_opposing.

#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <set>

#include "core/free_facets.hpp"
#include "core/orthtree.hpp"
#include "dim3/boundary_octants.hpp"

using namespace febemesh;
using namespace febemesh::dim3;

namespace {

/// The uniform level-2 tree of the unit cube (4 x 4 x 4 leaves) and the leaf at cell (x, y, z).
struct Grid4 {
  Orthtree<3> t;
  std::array<std::size_t, 64> leaf{};

  Grid4() {
    for (int l = 0; l < 2; ++l) t = refine(t, Flags(t.n_leaves(), 1));
    REQUIRE(t.n_leaves() == 64);
    for (std::size_t i = 0; i < t.n_leaves(); ++i) {
      const Box<3> b = geometry(t, t.leaf(i));
      const P3 c = 0.5 * (b.lo + b.hi);
      leaf[index(static_cast<int>(c[0] * 4), static_cast<int>(c[1] * 4), static_cast<int>(c[2] * 4))] = i;
    }
  }
  static int index(int x, int y, int z) { return x + 4 * y + 16 * z; }
};

/// The faces (2 * axis + side) of the free facets that have lattice point p as a corner.
std::set<int> faces_at(const Orthtree<3>& t, const Flags& in, const LatticePoint<3>& p) {
  std::set<int> faces;
  for (const FreeFacet<3>& f : free_facets(t, in))
    for (const auto& c : f.corners())
      if (c == p) faces.insert(f.face);
  return faces;
}

bool opposing(const std::set<int>& faces) {
  for (int d = 0; d < 3; ++d)
    if (faces.count(2 * d) && faces.count(2 * d + 1)) return true;
  return false;
}

}  // namespace

TEST_CASE("remove_opposing drops the octant nearest the surface of a twisted staircase", "[boundary_octants]") {
  // Around the centre node four of the eight octants are kept: (0,1,0), (0,0,1), (0,1,1) and
  // (1,1,0) (1 = the upper side along x, y, z). Kept and unkept ones are each face-connected,
  // so it is no pinch, but (0,0,1) has a free face facing -z at the node and (1,1,0) one facing
  // +z: spool's first tree at level 6 has 70 such nodes.
  Grid4 g;
  Flags in(g.t.n_leaves(), 0);
  const std::array<std::array<int, 3>, 4> kept = {{{0, 1, 0}, {0, 0, 1}, {0, 1, 1}, {1, 1, 0}}};
  for (const auto& o : kept) in[g.leaf[Grid4::index(1 + o[0], 1 + o[1], 1 + o[2])]] = 1;
  const std::uint32_t half = root_length<3> / 2;
  const LatticePoint<3> centre = {half, half, half};
  REQUIRE(remove_pinches(g.t, in) == 0);
  REQUIRE(opposing(faces_at(g.t, in, centre)));

  // The surface as the plane z = 0: the lower octant (1,1,0) is the nearer one and goes.
  const std::size_t dropped = remove_opposing(g.t, in, [](const P3& p) { return p[2]; });
  CHECK(dropped == 1);
  CHECK(!in[g.leaf[Grid4::index(2, 2, 1)]]);
  CHECK(in[g.leaf[Grid4::index(1, 1, 2)]]);
  CHECK(!opposing(faces_at(g.t, in, centre)));

  // With the surface above (z = 1) the upper one, (0,0,1), goes instead.
  Flags in2(g.t.n_leaves(), 0);
  for (const auto& o : kept) in2[g.leaf[Grid4::index(1 + o[0], 1 + o[1], 1 + o[2])]] = 1;
  CHECK(remove_opposing(g.t, in2, [](const P3& p) { return 1.0 - p[2]; }) == 1);
  CHECK(!in2[g.leaf[Grid4::index(1, 1, 2)]]);
  CHECK(in2[g.leaf[Grid4::index(2, 2, 1)]]);
  CHECK(!opposing(faces_at(g.t, in2, centre)));
}

TEST_CASE("remove_opposing leaves a staircase without opposing faces alone", "[boundary_octants]") {
  // An L-shaped step: (0,0,0), (1,0,0), (0,1,0) kept around the centre node; its free faces
  // there face +x, +y and +z only.
  Grid4 g;
  Flags in(g.t.n_leaves(), 0);
  for (const auto& o : std::array<std::array<int, 3>, 3>{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}})
    in[g.leaf[Grid4::index(1 + o[0], 1 + o[1], 1 + o[2])]] = 1;
  const Flags before = in;
  CHECK(remove_opposing(g.t, in, [](const P3& p) { return p[2]; }) == 0);
  CHECK(in == before);
}

namespace {

/// Face-connected components of the octants set in `mask` (bit o: octant o of a 2x2x2 block).
int block_components(unsigned mask) {
  int n = 0;
  unsigned seen = 0;
  for (int s = 0; s < 8; ++s) {
    if (!((mask >> s) & 1u) || ((seen >> s) & 1u)) continue;
    ++n;
    std::array<int, 8> stack{};
    int top = 0;
    stack[top++] = s;
    seen |= 1u << s;
    while (top > 0) {
      const int o = stack[--top];
      for (int d = 0; d < 3; ++d) {
        const int q = o ^ (1 << d);
        if (((mask >> q) & 1u) && !((seen >> q) & 1u)) seen |= 1u << q, stack[top++] = q;
      }
    }
  }
  return n;
}

}  // namespace

TEST_CASE("remove_pinches leaves no pinch and drops the same octants on any thread count", "[boundary_octants]") {
  // The uniform 16^3 grid with random kept octants (over half of them): many pinches, several
  // passes. Around every interior lattice point the kept octants must be face-connected
  // afterwards (a pass drops all but the largest component wherever they are not; the unkept
  // ones it joins only where one kept octant touches two of their components, so random flags
  // keep some such points: 3, 4 and 10 here, on the code before session 27 too).
  Orthtree<3> t;
  for (int l = 0; l < 4; ++l) t = refine(t, Flags(t.n_leaves(), 1));
  REQUIRE(t.n_leaves() == 4096);
  constexpr int n = 16;
  std::vector<std::size_t> leaf(n * n * n);
  for (std::size_t i = 0; i < t.n_leaves(); ++i) {
    const Box<3> b = geometry(t, t.leaf(i));
    const P3 c = 0.5 * (b.lo + b.hi) * n;
    leaf[static_cast<int>(c[0]) + n * (static_cast<int>(c[1]) + n * static_cast<int>(c[2]))] = i;
  }
  for (const unsigned seed : {1u, 2u, 3u}) {
    Flags in(t.n_leaves(), 0);
    unsigned x = seed * 2654435761u;
    for (std::size_t i = 0; i < in.size(); ++i) {
      x = x * 1664525u + 1013904223u;
      in[i] = (x >> 16) % 100 < 55 ? 1 : 0;
    }
    Flags one = in, three = in;
    const std::size_t dropped = remove_pinches(t, one, 1);
    CHECK(remove_pinches(t, three, 3) == dropped);
    CHECK(one == three);
    CHECK(dropped > 0);
    std::size_t pinched = 0;
    for (int z = 1; z < n; ++z)
      for (int y = 1; y < n; ++y)
        for (int xx = 1; xx < n; ++xx) {
          unsigned kept = 0;
          for (int o = 0; o < 8; ++o) {
            const int cx = xx - 1 + (o & 1), cy = y - 1 + ((o >> 1) & 1), cz = z - 1 + ((o >> 2) & 1);
            if (one[leaf[cx + n * (cy + n * cz)]]) kept |= 1u << o;
          }
          if (block_components(kept) > 1) ++pinched;
        }
    CHECK(pinched == 0);
  }
}
