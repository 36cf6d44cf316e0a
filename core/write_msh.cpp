// MSH 4.1 text built in large chunks with std::to_chars (no iostream formatting), or the same
// sections in binary; both spill to the file every few MiB.

#include "core/write_msh.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <charconv>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <exception>
#include <limits>
#include <memory>
#include <mutex>
#include <string_view>
#include <type_traits>
#include <vector>

#include "core/error.hpp"
#include "core/parallel_ranges.hpp"
#include "core/worker_pool.hpp"
#include "core/spill_buffer.hpp"

namespace febemesh {

namespace {

/// The shortest round-trip text of a double (std::to_chars), remembered per bit pattern: most
/// nodes sit on the lattice, whose few coordinates repeat (flange level 9: 344k coordinates,
/// 68k distinct), and std::to_chars was 5% of bench_mesh2d's instructions.
class RealTexts {
 public:
  std::string_view text(double v) {
    std::uint64_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    Text& t = texts_[(bits * 0x9E3779B97F4A7C15ull) >> (64 - log2_texts)];
    if (t.len == 0 || t.bits != bits) {
      t.bits = bits;
      t.len = static_cast<std::uint8_t>(std::to_chars(t.text, t.text + sizeof t.text, v).ptr - t.text);
    }
    return {t.text, t.len};
  }

 private:
  /// A remembered number: len == 0 marks an empty slot (no number prints as nothing).
  struct Text {
    std::uint64_t bits = 0;
    std::uint8_t len = 0;
    char text[31];  ///< a double's shortest text has at most 24 chars
  };
  static constexpr int log2_texts = 13;
  std::unique_ptr<Text[]> texts_ = std::make_unique<Text[]>(std::size_t{1} << log2_texts);  ///< direct-mapped by the bits' multiplicative hash
};

/// MSH fields as text or bytes; with a file it spills every few MiB (SpillBuffer).
class Sink : public SpillBuffer {
 public:
  explicit Sink(bool binary, std::FILE* file = nullptr, std::string path = {})
      : SpillBuffer(file, std::move(path), file ? 2 * chunk : 1 << 16), binary_(binary) {}
  bool binary() const { return binary_; }
  /// The bytes of a trivially copyable value (the writer runs on little-endian hosts only).
  template <class T> void raw(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    put(std::string_view(reinterpret_cast<const char*>(&v), sizeof v));
  }
  /// A field of the file's int type: text followed by `sep`, or 4 raw bytes.
  Sink& i32(int v, char sep = ' ') {
    if (binary_) raw(std::int32_t{v});
    else integer(v) << sep;
    return *this;
  }
  /// A field of the file's size_t type (counts, node and element tags).
  Sink& size(std::uint64_t v, char sep = ' ') {
    if (binary_) raw(v);
    else integer(v) << sep;
    return *this;
  }
  Sink& f64(double v, char sep = ' ') {
    if (binary_) raw(v);
    else real(v) << sep;
    return *this;
  }
  /// Ends a line of text (nothing in binary, where fields have no separators).
  Sink& eol() {
    if (!binary_) put('\n');
    return *this;
  }
  Sink& operator<<(std::string_view s) {
    put(s);
    maybe_flush();
    return *this;
  }
  Sink& operator<<(char c) {
    put(c);
    return *this;
  }
  template <class Int> Sink& integer(Int v) {
    append_number(v);
    return *this;
  }
  Sink& real(double v) {
    if (!texts_) texts_ = std::make_unique<RealTexts>();
    put(texts_->text(v));
    return *this;
  }
  /// Text formatted elsewhere (parallel_lines), appended in one piece: with a file, what is
  /// buffered goes first and then `text` straight from its own buffer.
  void put_block(std::string_view text) {
    if (!has_file()) {
      put(text);
      return;
    }
    flush();
    write_through(text);
  }

 private:
  bool binary_;
  std::unique_ptr<RealTexts> texts_;
};

/// Lines of text formatted into a buffer of their own (a block of parallel_lines).
class LineBlock {
 public:
  /// Room for at least n more bytes at the end; write there, then end(p).
  char* room(std::size_t n) {
    if (capacity_ - size_ < n) {
      const std::size_t capacity = std::max(2 * capacity_, size_ + n);
      std::unique_ptr<char[]> bigger(new char[capacity]);
      if (size_ != 0) std::memcpy(bigger.get(), buf_.get(), size_);
      buf_ = std::move(bigger);
      capacity_ = capacity;
    }
    return buf_.get() + size_;
  }
  void end(const char* p) { size_ = static_cast<std::size_t>(p - buf_.get()); }
  std::string_view text() const { return {buf_.get(), size_}; }
  void clear() { size_ = 0; }
  /// The block's number texts (made on first use: only the coordinate lines have numbers).
  RealTexts& reals() {
    if (!reals_) reals_ = std::make_unique<RealTexts>();
    return *reals_;
  }

 private:
  std::unique_ptr<char[]> buf_;
  std::size_t size_ = 0, capacity_ = 0;
  std::unique_ptr<RealTexts> reals_;
};

/// Items per block of parallel_lines: ~0.5-1 MiB of text (30-60 bytes a line).
constexpr std::size_t lines_per_block = 1 << 14;

/// The text of items [0, count), in blocks of lines_per_block items: format(block, begin, end)
/// appends the lines of items [begin, end) to the block. On n_threads threads each takes the
/// next block, formats it, waits for the block before it to be written and writes its own
/// (Sink::put_block), so that one thread writes while the other formats. The blocks do not
/// depend on n_threads: the same text. The first exception stops the others once their block
/// is done and is rethrown.
template <class Format> void parallel_lines(Sink& out, std::size_t count, int n_threads, const Format& format) {
  const std::size_t n_blocks = (count + lines_per_block - 1) / lines_per_block;
  const auto range = [&](std::size_t k, auto&& f) { f(k * lines_per_block, std::min(count, (k + 1) * lines_per_block)); };
  const int n_workers = static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(std::clamp(n_threads, 1, 256)), n_blocks));
  if (n_workers <= 1) {
    LineBlock block;
    for (std::size_t k = 0; k < n_blocks; ++k) {
      block.clear();
      range(k, [&](std::size_t begin, std::size_t end) { format(block, begin, end); });
      out.put_block(block.text());
    }
    return;
  }
  std::atomic<std::size_t> next{0};
  std::mutex m;
  std::condition_variable cv;
  std::size_t written = 0;  // blocks [0, written) are out
  bool failed = false;
  std::exception_ptr error;
  const auto work = [&] {
    LineBlock block;
    try {
      for (std::size_t k; (k = next.fetch_add(1)) < n_blocks;) {
        block.clear();
        range(k, [&](std::size_t begin, std::size_t end) { format(block, begin, end); });
        std::unique_lock<std::mutex> lock(m);
        cv.wait(lock, [&] { return written == k || failed; });
        if (failed) return;
        lock.unlock();  // the block's turn: no other thread writes until it is done
        out.put_block(block.text());
        lock.lock();
        ++written;
        cv.notify_all();
      }
    } catch (...) {
      const std::lock_guard<std::mutex> lock(m);
      if (!failed) error = std::current_exception();
      failed = true;
      cv.notify_all();
    }
  };
  run_on_threads(n_workers, [&](int) { work(); });
  if (error) std::rethrow_exception(error);
}

template <int Dim> void bbox_line(Sink& out, const Mesh<Dim>& mesh, const Elements& els, int n_threads) {
  // Per-range boxes merged: minima and maxima are exact in any order (serial, with the node
  // tags' texts, 0.07 s of the flange's 5.4 M-triangle write on two threads).
  const std::size_t chunk = chunk_size(els.node.size(), n_threads, std::size_t(1) << 16);
  std::vector<Box<Dim>> part((els.node.size() + chunk - 1) / chunk, Box<Dim>::empty());
  for_each_chunk(els.node.size(), chunk, n_threads, [&](std::size_t c, std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) part[c].expand(mesh.points[els.node[i].v]);
  });
  Box<Dim> b = Box<Dim>::empty();
  for (const Box<Dim>& p : part) b.expand(p.lo), b.expand(p.hi);  // (each chunk holds a node)
  if (els.node.empty()) b = Box<Dim>{};
  for (const auto* corner : {&b.lo, &b.hi})
    for (int d = 0; d < 3; ++d) out.f64(d < Dim ? (*corner)[d] : 0.0);
}

/// The decimal digits of v at p (the text std::to_chars writes), two at a time; returns the end.
char* decimal(char* p, std::uint64_t v) {
  if (v > std::numeric_limits<std::uint32_t>::max()) return std::to_chars(p, p + 20, v).ptr;
  static constexpr char pairs[] =
      "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
      "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
      "8081828384858687888990919293949596979899";
  auto u = static_cast<std::uint32_t>(v);
  int len = 1;
  for (std::uint32_t bound = 10; len < 10 && u >= bound; bound *= 10) ++len;
  char* const end = p + len;
  char* q = end;
  while (u >= 100) {
    const std::uint32_t r = u % 100;
    u /= 100;
    q -= 2;
    q[0] = pairs[2 * r], q[1] = pairs[2 * r + 1];
  }
  if (u >= 10) {
    q -= 2;
    q[0] = pairs[2 * u], q[1] = pairs[2 * u + 1];
  } else {
    *--q = static_cast<char>('0' + u);
  }
  return end;
}

/// Consecutive tags as text: the last one's digits, incremented in place (a carry through the
/// nines, or one more digit); any other value is printed by decimal().
class TagCounter {
 public:
  /// Writes the text of `tag` at p; returns the end.
  char* put(char* p, std::uint64_t tag) {
    if (len_ == 0 || tag != value_ + 1) {
      len_ = static_cast<int>(decimal(digits_, tag) - digits_);
    } else {
      int k = len_ - 1;
      while (k >= 0 && digits_[k] == '9') digits_[k--] = '0';
      if (k >= 0) {
        ++digits_[k];
      } else {
        std::memmove(digits_ + 1, digits_, static_cast<std::size_t>(len_));
        digits_[0] = '1';
        ++len_;
      }
    }
    value_ = tag;
    std::memcpy(p, digits_, static_cast<std::size_t>(len_));
    return p + len_;
  }

 private:
  char digits_[24];
  int len_ = 0;
  std::uint64_t value_ = 0;
};

/// The node tags 1..n as text, 8 bytes a tag (up to 7 digits, the length in the top byte),
/// printed once (TagCounter) and copied wherever an element names the node: decimal() per
/// element node was a third of writing a triangle mesh's text (flange level 9: 1.03M fields for
/// 172k nodes). Empty (decimal() then) above 9,999,999 nodes.
class NodeTagTexts {
 public:
  NodeTagTexts(std::size_t n, int n_threads) {
    if (n > 9'999'999) return;
    text_.resize(n);
    // A counter a range: it starts from its range's first tag (the same texts).
    for_each_range(n, n_threads, [&](std::size_t begin, std::size_t end) {
      TagCounter counter;
      for (std::size_t i = begin; i < end; ++i) {
        char buf[32] = {};
        const auto len = static_cast<std::uint64_t>(counter.put(buf, i + 1) - buf);
        std::uint64_t w = 0;
        std::memcpy(&w, buf, 7);
        text_[i] = w | (len << 56);
      }
    });
  }
  /// Writes the text of node tag `tag` (1-based) at p, which has room for 8 bytes; returns the end.
  char* put(char* p, std::uint64_t tag) const {
    if (tag - 1 >= text_.size()) return decimal(p, tag);  // (none kept)
    const std::uint64_t w = text_[tag - 1];
    std::memcpy(p, &w, 8);
    return p + (w >> 56);
  }

 private:
  std::vector<std::uint64_t> text_;
};

template <int Dim> void write_blocks(Sink& out, const Elements& els, int entity_dim, std::int64_t first_tag,
                  const NodeTagTexts& node_tags, int n_threads) {
  for (int t = 0; t <= static_cast<int>(ElemType::Pyramid5); ++t) {
    const auto type = static_cast<ElemType>(t);
    std::size_t count = 0;
    for (const ElemType et : els.type) count += (et == type);
    if (count == 0) continue;
    out.i32(entity_dim).i32(1).i32(gmsh_type(type)).size(count, '\n');
    if (!out.binary()) {
      // Each line built whole in the block (tag, node tags): the per-field calls were most of
      // the element blocks' cost (flange level 9). Blocks by element index, the lines of this
      // type among them.
      const std::size_t line_bytes = static_cast<std::size_t>(n_nodes(type) + 1) * 21 + 1;
      parallel_lines(out, els.size(), n_threads, [&](LineBlock& b, std::size_t begin, std::size_t end) {
        TagCounter tags;
        char* p = b.room((end - begin) * line_bytes);
        for (std::size_t e = begin; e < end; ++e) {
          if (els.type[e] != type) continue;
          const ElemId id{static_cast<std::int32_t>(e)};
          const int n = els.n_nodes_of(id);
          const VertexId* v = els.nodes(id);
          p = tags.put(p, static_cast<std::uint64_t>(first_tag) + e);
          for (int i = 0; i < n; ++i) {
            *p++ = ' ';
            p = node_tags.put(p, static_cast<std::uint64_t>(v[i].v) + 1);
          }
          *p++ = '\n';
        }
        b.end(p);
      });
      continue;
    }
    for (std::size_t e = 0; e < els.size(); ++e) {
      if (els.type[e] != type) continue;
      const ElemId id{static_cast<std::int32_t>(e)};
      const int n = els.n_nodes_of(id);
      const VertexId* v = els.nodes(id);
      out.size(static_cast<std::uint64_t>(first_tag) + e, n == 0 ? '\n' : ' ');
      for (int i = 0; i < n; ++i) out.size(static_cast<std::uint64_t>(v[i].v) + 1, i + 1 == n ? '\n' : ' ');
      out.maybe_flush();
    }
  }
}

std::size_t n_types(const Elements& els) {
  std::array<bool, 8> seen{};
  for (const ElemType t : els.type) seen[static_cast<std::size_t>(t)] = true;
  std::size_t n = 0;
  for (const bool s : seen) n += s;
  return n;
}

template <int Dim> void write(Sink& out, const Mesh<Dim>& mesh, int n_threads) {
  if (out.binary()) {
    out << "$MeshFormat\n4.1 1 8\n";
    out.raw(std::int32_t{1});  // lets a reader detect the byte order
    out << "\n$EndMeshFormat\n";
  } else {
    out << "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
  }
  out << "$PhysicalNames\n2\n";
  out.integer(Dim - 1) << " 2 \"interface\"\n";
  out.integer(Dim) << " 1 \"solid\"\n";
  out << "$EndPhysicalNames\n";
  // Binary sections end with a newline before their $End line, as Gmsh writes them.
  const std::string_view end_binary = out.binary() ? "\n" : "";

  // One entity per group: the interface is entity (Dim-1, 1) with physical tag 2, the solid
  // entity (Dim, 1) with physical tag 1; no bounding relations (the mesh is all there is).
  out << "$Entities\n";
  for (int d = 0; d < 4; ++d) out.size(d == Dim - 1 || d == Dim ? 1 : 0, d == 3 ? '\n' : ' ');
  for (const auto& [els, phys] : {std::pair{&mesh.interface, 2}, std::pair{&mesh.solid, 1}}) {
    out.i32(1);
    bbox_line<Dim>(out, mesh, *els, n_threads);
    out.size(1).i32(phys).size(0, '\n');
  }
  out << end_binary << "$EndEntities\n";

  const std::size_t n = mesh.points.size();
  const NodeTagTexts node_tags(out.binary() ? 0 : n, n_threads);
  out << "$Nodes\n";
  if (n == 0) {
    for (int k = 0; k < 4; ++k) out.size(0, k == 3 ? '\n' : ' ');
  } else {
    out.size(1).size(n).size(1).size(n, '\n');
    out.i32(Dim).i32(1).i32(0).size(n, '\n');
    if (out.binary()) {
      for (std::size_t i = 0; i < n; ++i) {
        out.size(i + 1, '\n');
        out.maybe_flush();
      }
      for (const auto& p : mesh.points) {
        out.f64(p[0]).f64(p[1]).f64(Dim == 3 ? p[Dim - 1] : 0.0, '\n');
        out.maybe_flush();
      }
    } else {
      parallel_lines(out, n, n_threads, [&](LineBlock& b, std::size_t begin, std::size_t end) {
        char* p = b.room((end - begin) * 22);  // a tag: up to 20 digits (8 bytes copied), '\n'
        for (std::size_t i = begin; i < end; ++i) {
          p = node_tags.put(p, i + 1);
          *p++ = '\n';
        }
        b.end(p);
      });
      // x y z: each the shortest text that reads back as the double (z = 0 in 2D).
      parallel_lines(out, n, n_threads, [&](LineBlock& b, std::size_t begin, std::size_t end) {
        RealTexts& reals = b.reals();
        char* p = b.room((end - begin) * 3 * 32);
        for (std::size_t i = begin; i < end; ++i) {
          const Point<Dim>& x = mesh.points[i];
          for (int d = 0; d < 3; ++d) {
            const std::string_view t = reals.text(d < Dim ? x[d] : 0.0);
            std::memcpy(p, t.data(), t.size());
            p += t.size();
            *p++ = d == 2 ? '\n' : ' ';
          }
        }
        b.end(p);
      });
    }
  }
  out << end_binary << "$EndNodes\n";

  const std::size_t ne = mesh.solid.size() + mesh.interface.size();
  out << "$Elements\n";
  out.size(n_types(mesh.solid) + n_types(mesh.interface)).size(ne).size(ne == 0 ? 0 : 1).size(ne, '\n');
  write_blocks<Dim>(out, mesh.solid, Dim, 1, node_tags, n_threads);
  write_blocks<Dim>(out, mesh.interface, Dim - 1, static_cast<std::int64_t>(mesh.solid.size()) + 1, node_tags, n_threads);
  out << end_binary << "$EndElements\n";
}

}  // namespace

template <int Dim> std::string msh_string(const Mesh<Dim>& mesh, MshEncoding encoding) {
  Sink out(encoding == MshEncoding::Binary);
  write<Dim>(out, mesh, 1);
  return out.take();
}

template <int Dim>
void write_msh(const Mesh<Dim>& mesh, const std::filesystem::path& path, MshEncoding encoding, int n_threads) {
  const std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "wb"), &std::fclose);
  if (!file) throw InputError("cannot open " + path.string() + " for writing: " + std::strerror(errno));
  Sink out(encoding == MshEncoding::Binary, file.get(), path.string());
  write<Dim>(out, mesh, n_threads);
  out.flush();
  if (std::fflush(file.get()) != 0) throw InputError("cannot write " + path.string() + ": " + std::strerror(errno));
}

template std::string msh_string<2>(const Mesh<2>&, MshEncoding);
template std::string msh_string<3>(const Mesh<3>&, MshEncoding);
template void write_msh<2>(const Mesh<2>&, const std::filesystem::path&, MshEncoding, int);
template void write_msh<3>(const Mesh<3>&, const std::filesystem::path&, MshEncoding, int);

}  // namespace febemesh
