// Unique lattice nodes of the leaves: corners are integer lattice points, so shared nodes are
// found by sorting their Morton keys (exact, no tolerance), and a node is hanging when one of the
// kept leaves around it has it on its boundary without having it as a corner.

#include <algorithm>
#include <array>
#include <bit>

#include "core/error.hpp"
#include "core/huge_pages.hpp"
#include "core/lattice_nodes.hpp"
#include "core/orthtree.hpp"
#include "core/parallel_ranges.hpp"

namespace febemesh {

namespace {

/// Orders [first, last) by the byte at `shift` in place (one pass of an American flag sort) and
/// returns where each of the 256 buckets starts (start[256] = last - first).
std::array<std::size_t, 257> partition_by_byte(std::uint64_t* first, std::uint64_t* last, int shift) {
  auto digit = [shift](std::uint64_t k) { return static_cast<std::size_t>((k >> shift) & 0xffu); };
  std::array<std::size_t, 257> start{};
  for (const std::uint64_t* p = first; p != last; ++p) ++start[digit(*p) + 1];
  for (int b = 0; b < 256; ++b) start[b + 1] += start[b];
  std::array<std::size_t, 256> head;
  std::copy(start.begin(), start.end() - 1, head.begin());
  for (std::size_t b = 0; b < 256; ++b) {
    while (head[b] < start[b + 1]) {
      std::uint64_t v = first[head[b]];
      for (std::size_t d = digit(v); d != b; d = digit(v)) std::swap(v, first[head[d]++]);
      first[head[b]++] = v;
    }
  }
  return start;
}

/// Ranges of at most this many keys go from the MSD partitions to LSD passes in a scratch
/// buffer of this size (128 KiB: in L2).
constexpr std::size_t lsd_max_keys = std::size_t(1) << 14;

/// Sorts [first, last) by the bits at `low` and above (low a multiple of 8; ties in any order),
/// where the keys agree above the byte at `shift`: MSD partitions while a range has more than
/// lsd_max_keys keys, then one LSD pass a byte from `low` up to `shift` (a byte in which the
/// range agrees is skipped), short ranges by insertion.
void sort_above(std::uint64_t* first, std::uint64_t* last, int shift, int low, std::vector<std::uint64_t>& scratch) {
  const auto n = static_cast<std::size_t>(last - first);
  if (n < 2 || shift < low) return;
  if (n <= 32) {
    for (std::uint64_t* i = first + 1; i < last; ++i) {
      const std::uint64_t k = *i;
      std::uint64_t* j = i;
      for (; j > first && (*(j - 1) >> low) > (k >> low); --j) *j = *(j - 1);
      *j = k;
    }
    return;
  }
  if (n > lsd_max_keys) {
    const auto start = partition_by_byte(first, last, shift);
    for (std::size_t b = 0; b < 256; ++b) sort_above(first + start[b], first + start[b + 1], shift - 8, low, scratch);
    return;
  }
  const int n_bytes = (shift - low) / 8 + 1;
  std::array<std::array<std::uint32_t, 256>, 8> count;
  for (int d = 0; d < n_bytes; ++d) count[d].fill(0);
  for (const std::uint64_t* p = first; p != last; ++p)
    for (int d = 0; d < n_bytes; ++d) ++count[d][(*p >> (low + 8 * d)) & 0xffu];
  scratch.resize(lsd_max_keys);
  std::uint64_t* from = first;
  std::uint64_t* to = scratch.data();
  for (int d = 0; d < n_bytes; ++d) {
    std::array<std::uint32_t, 256>& c = count[d];
    if (c[(*from >> (low + 8 * d)) & 0xffu] == n) continue;  // all keys agree in this byte
    std::uint32_t at = 0;
    for (std::uint32_t& x : c) at += std::exchange(x, at);
    for (std::size_t i = 0; i < n; ++i) to[c[(from[i] >> (low + 8 * d)) & 0xffu]++] = from[i];
    std::swap(from, to);
  }
  if (from != first) std::copy(from, from + n, first);
}

/// Sorts `keys` by their bits at `low` and above (low a multiple of 8; ties in any order, so
/// the bits below `low` may be anything; low = 0: ascending), sort_above from the highest byte
/// in which they differ. On several threads the first byte's pass runs on the caller and its
/// buckets spread over the threads (a sort: the same keys for every count). In place but for a
/// 128 KiB buffer a thread: this runs at the boundary stage's memory peak.
void radix_sort_above(std::vector<std::uint64_t>& keys, int low, int n_threads) {
  std::uint64_t any = 0, all = ~std::uint64_t{0};
  for (const std::uint64_t k : keys) any |= k, all &= k;
  int shift = 56;
  while (shift > low && (((any ^ all) >> shift) & 0xffu) == 0) shift -= 8;
  std::uint64_t* const first = keys.data();
  if (n_threads <= 1 || keys.size() < (std::size_t(1) << 16)) {
    std::vector<std::uint64_t> scratch;
    sort_above(first, first + keys.size(), shift, low, scratch);
    return;
  }
  const auto start = partition_by_byte(first, first + keys.size(), shift);
  // The buckets in runs of about equal numbers of keys (buckets are uneven: a tree's corners
  // crowd where it is fine), four runs a thread.
  const std::size_t n_parts = 4 * static_cast<std::size_t>(std::clamp(n_threads, 1, 64));
  std::vector<std::size_t> part_first(n_parts + 1, 256);
  for (std::size_t p = 0; p < n_parts; ++p)
    part_first[p] = static_cast<std::size_t>(
        std::lower_bound(start.begin(), start.begin() + 256, p * keys.size() / n_parts) - start.begin());
  for_each_range(n_parts, n_threads, [&](std::size_t p0, std::size_t p1) {
    std::vector<std::uint64_t> scratch;
    for (std::size_t b = part_first[p0]; b < part_first[p1]; ++b)
      sort_above(first + start[b], first + start[b + 1], shift - 8, low, scratch);
  });
}

/// LimitError when n nodes would not have 32-bit ids.
void check_node_ids(std::size_t n) {
  if (n > std::size_t(std::numeric_limits<std::int32_t>::max()))
    throw LimitError("lattice_nodes: " + std::to_string(n) + " nodes exceed 32-bit node ids");
}

/// The nodes and every kept leaf's corner nodes from one sort: each corner key packed with its
/// place (leaf * n_corners + corner) below it, sorted, then read in order (a new key, a new
/// node). The same nodes and corners as sorting the keys alone and searching each corner
/// among them (that search was 25 of lattice_nodes' 98 ms at flange 1e6, one thread). `keys`
/// holds the kept leaves' corner keys in leaf order; it is overwritten. False, and nothing
/// done, when a key's varying bits and the place do not fit in 64 bits together.
template <int Dim, class Kept>
bool sort_with_corners(const Orthtree<Dim>& t, const Kept& kept, std::size_t run, const std::vector<std::size_t>& run_start,
                       std::vector<std::uint64_t>& keys, LatticeNodes<Dim>& nodes, int n_threads) {
  constexpr int n_corners = Cube<Dim>::n_corners;
  const std::size_t n_leaves = t.n_leaves();
  if (keys.empty()) {
    for (auto& row : nodes.leaf_corners) row.fill(-1);
    return true;
  }
  std::uint64_t any = 0, all = ~std::uint64_t{0};
  for (const std::uint64_t k : keys) any |= k, all &= k;
  const std::uint64_t varying = any ^ all;  // outside these bits every key has all's bits
  const int low = varying == 0 ? 0 : std::countr_zero(varying);
  const int width = varying == 0 ? 0 : 64 - std::countl_zero(varying) - low;
  const int place_bits = std::bit_width(n_leaves * n_corners - 1);
  if (width + place_bits > 64) return false;
  const std::uint64_t place_mask = place_bits == 64 ? ~std::uint64_t{0} : (std::uint64_t(1) << place_bits) - 1;
  // The key part from a byte boundary on when it fits (the sort then reads whole bytes of it).
  const int place_shift = width + (place_bits + 7) / 8 * 8 <= 64 ? (place_bits + 7) / 8 * 8 : place_bits;
  const std::uint64_t part_mask = width == 64 ? ~std::uint64_t{0} : (std::uint64_t(1) << width) - 1;
  // Pack in place: run c of leaves (as the keys were written) holds its kept leaves' corners
  // from run_start[c] * n_corners on, in leaf order.
  for_each_chunk(n_leaves, run, n_threads, [&](std::size_t c, std::size_t begin, std::size_t end) {
    std::uint64_t* at = keys.data() + run_start[c] * n_corners;
    for (std::size_t i = begin; i < end; ++i) {
      if (!kept(i)) {
        nodes.leaf_corners[i].fill(-1);
        continue;
      }
      for (int k = 0; k < n_corners; ++k, ++at)
        *at = (((*at >> low) & part_mask) << place_shift) | static_cast<std::uint64_t>(i * n_corners + static_cast<std::size_t>(k));
    }
  });
  // By the key part only: the order of a node's corners among themselves changes nothing below.
  radix_sort_above(keys, place_shift / 8 * 8, n_threads);
  // Node ids in key order: a chunk's first node id is the count of distinct keys before it.
  const std::size_t n_keys = keys.size();
  const std::size_t chunk = chunk_size(n_keys, n_threads, std::size_t(1) << 16);
  const auto starts_node = [&](std::size_t j) { return j == 0 || (keys[j] >> place_shift) != (keys[j - 1] >> place_shift); };
  const std::vector<std::size_t> first_id =
      chunk_starts(n_keys, chunk, n_threads, std::size_t{0}, [&](std::size_t begin, std::size_t end) {
        std::size_t k = 0;
        for (std::size_t j = begin; j < end; ++j) k += starts_node(j) ? 1 : 0;
        return k;
      });
  const std::size_t n_nodes = first_id.back();
  check_node_ids(n_nodes);
  reserve_huge(nodes.points, n_nodes, n_threads);
  nodes.points.resize(n_nodes);
  const std::uint64_t fixed = all & ~(part_mask << low);
  for_each_chunk(n_keys, chunk, n_threads, [&](std::size_t c, std::size_t begin, std::size_t end) {
    std::size_t id = first_id[c];  // the id of the next new key
    for (std::size_t j = begin; j < end; ++j) {
      if (starts_node(j)) nodes.points[id++] = point_from_key<Dim>(fixed | ((keys[j] >> place_shift) << low));
      const std::uint64_t place = keys[j] & place_mask;
      nodes.leaf_corners[place / n_corners][place % n_corners] = static_cast<std::int32_t>(id - 1);
    }
  });
  return true;
}

/// The nodes by sorting the corner keys alone, and each kept leaf's corners by searching them
/// (sort_with_corners' fallback). `keys` as there; it is left as the sorted distinct keys.
template <int Dim, class Kept>
void sort_then_search(const Orthtree<Dim>& t, const Kept& kept, std::vector<std::uint64_t>& keys, LatticeNodes<Dim>& nodes,
                      int n_threads) {
  constexpr int n_corners = Cube<Dim>::n_corners;
  const std::size_t n_leaves = t.n_leaves();
  radix_sort_above(keys, 0, n_threads);
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  check_node_ids(keys.size());

  reserve_huge(nodes.points, keys.size(), n_threads);
  nodes.points.resize(keys.size());
  for_each_range(keys.size(), n_threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t n = begin; n < end; ++n) nodes.points[n] = point_from_key<Dim>(keys[n]);
  });

  for_each_range(n_leaves, n_threads, [&](std::size_t begin, std::size_t end) {
    // Corner k's answer for the previous kept leaf: a hint only (the same answers from any).
    std::array<std::size_t, n_corners> near{};
    for (std::size_t i = begin; i < end; ++i) {
      auto& row = nodes.leaf_corners[i];
      if (!kept(i)) {
        row.fill(-1);
        continue;
      }
      const auto corner_key = corner_keys(t.leaf(i));
      for (int k = 0; k < n_corners; ++k) {
        near[k] = lower_bound_from(keys, corner_key[k], near[k]);
        row[k] = std::int32_t(near[k]);
      }
    }
  });
}

}  // namespace

std::size_t lower_bound_from(const std::vector<std::uint64_t>& keys, std::uint64_t key, std::size_t hint) {
  const std::size_t n = keys.size();
  hint = std::min(hint, n);
  std::size_t lo = 0, hi = 0;  // the answer lies in [lo, hi]
  if (hint < n && keys[hint] < key) {
    lo = hint + 1;
    for (std::size_t step = 1;; step *= 2) {
      hi = lo + step - 1;
      if (hi >= n) {
        hi = n;
        break;
      }
      if (keys[hi] >= key) break;
      lo = hi + 1;
    }
  } else {
    hi = hint;
    for (std::size_t step = 1;; step *= 2) {
      if (hi < step) {
        lo = 0;
        break;
      }
      const std::size_t probe = hi - step;
      if (keys[probe] < key) {
        lo = probe + 1;
        break;
      }
      hi = probe;
    }
  }
  return static_cast<std::size_t>(std::lower_bound(keys.begin() + static_cast<std::ptrdiff_t>(lo),
                                                   keys.begin() + static_cast<std::ptrdiff_t>(hi), key) -
                                  keys.begin());
}


template <int Dim> std::int32_t LatticeNodes<Dim>::find(const LatticePoint<Dim>& p) const {
  const std::uint64_t key = point_key<Dim>(p);
  const auto it = std::lower_bound(points.begin(), points.end(), key,
                                   [](const LatticePoint<Dim>& q, std::uint64_t k) { return point_key<Dim>(q) < k; });
  if (it == points.end() || *it != p) return -1;
  return std::int32_t(it - points.begin());
}

template <int Dim> LatticeNodes<Dim> lattice_nodes(const Orthtree<Dim>& t, const Flags* keep) {
  return lattice_nodes(t, keep, HangingFlags::Computed, 1);
}

template <int Dim>
LatticeNodes<Dim> lattice_nodes(const Orthtree<Dim>& t, const Flags* keep, HangingFlags hanging, int n_threads) {
  if (keep != nullptr && keep->size() != t.n_leaves()) {
    throw InputError("lattice_nodes: keep mask has " + std::to_string(keep->size()) + " entries for " +
                     std::to_string(t.n_leaves()) + " leaves");
  }
  const auto kept = [&](std::size_t i) { return keep == nullptr || (*keep)[i] != 0; };
  constexpr int n_corners = Cube<Dim>::n_corners;

  // Every kept leaf's corner keys, in leaf order: each run of leaves writes at its count of
  // kept leaves before it.
  const std::size_t n_leaves = t.n_leaves();
  const std::size_t run = chunk_size(n_leaves, n_threads, std::size_t(1) << 14);
  const std::vector<std::size_t> run_start =
      chunk_starts(n_leaves, run, n_threads, std::size_t{0}, [&](std::size_t begin, std::size_t end) {
        std::size_t k = 0;
        for (std::size_t i = begin; i < end; ++i) k += kept(i) ? 1 : 0;
        return k;
      });
  std::vector<std::uint64_t> keys;
  reserve_huge(keys, run_start.back() * n_corners, n_threads);
  keys.resize(run_start.back() * n_corners);
  for_each_chunk(n_leaves, run, n_threads, [&](std::size_t c, std::size_t begin, std::size_t end) {
    std::uint64_t* out = keys.data() + run_start[c] * n_corners;
    for (std::size_t i = begin; i < end; ++i) {
      if (!kept(i)) continue;
      for (const std::uint64_t key : corner_keys(t.leaf(i))) *out++ = key;
    }
  });
  LatticeNodes<Dim> nodes;
  reserve_huge(nodes.leaf_corners, t.n_leaves(), n_threads);
  nodes.leaf_corners.resize(t.n_leaves());
  if (!sort_with_corners<Dim>(t, kept, run, run_start, keys, nodes, n_threads)) sort_then_search<Dim>(t, kept, keys, nodes, n_threads);
  if (hanging == HangingFlags::Skipped) return nodes;
  // The leaves touching node p are those containing the 2^Dim finest lattice cells around p.
  const LeafKeys<Dim> leaf_keys(t);
  // Nodes come in Morton order, so each of the 2^Dim cells around them moves little in the
  // leaves' Morton order from one node to the next: its search starts at its previous answer.
  nodes.hanging.assign(nodes.points.size(), 0);
  for_each_range(nodes.points.size(), n_threads, [&](std::size_t begin, std::size_t end) {
    std::array<std::size_t, n_corners> hint{};  // hints only: the same leaves from any
    for (std::size_t n = begin; n < end; ++n) {
      const LatticePoint<Dim>& p = nodes.points[n];
      for (int o = 0; o < n_corners && !nodes.hanging[n]; ++o) {
        LatticePoint<Dim> q = p;
        bool inside = true;
        for (int d = 0; d < Dim; ++d) {
          if (corner_is_upper(o, d)) {
            inside = inside && q[d] < root_length<Dim>;
          } else {
            inside = inside && q[d] > 0;
            q[d] -= inside ? 1 : 0;
          }
        }
        if (!inside) continue;
        const std::size_t j = leaf_keys.locate_near(q, hint[o]);
        if (j != no_leaf) hint[o] = j;
        if (j != no_leaf && kept(j) && !is_corner(t.leaf(j), p)) nodes.hanging[n] = 1;
      }
    }
  });
  return nodes;
}

template struct LatticeNodes<2>;
template struct LatticeNodes<3>;
template LatticeNodes<2> lattice_nodes<2>(const Orthtree<2>&, const Flags*);
template LatticeNodes<3> lattice_nodes<3>(const Orthtree<3>&, const Flags*);
template LatticeNodes<2> lattice_nodes<2>(const Orthtree<2>&, const Flags*, HangingFlags, int);
template LatticeNodes<3> lattice_nodes<3>(const Orthtree<3>&, const Flags*, HangingFlags, int);

}  // namespace febemesh
