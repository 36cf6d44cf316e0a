// MSH 4.1 ASCII text built in large chunks with std::to_chars (no iostream formatting).

#include "core/write_msh.hpp"

#include <array>
#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <memory>

#include "core/error.hpp"

namespace febemesh {

namespace {

/// Appends text to a string and, when given a file, spills it in chunks of a few MiB.
class Sink {
 public:
  explicit Sink(std::FILE* file = nullptr, std::string path = {}) : file_(file), path_(std::move(path)) {
    buf_.reserve(file_ ? 2 * chunk : 1 << 16);
  }
  Sink& operator<<(std::string_view s) {
    buf_.append(s);
    maybe_flush();
    return *this;
  }
  Sink& operator<<(char c) {
    buf_.push_back(c);
    return *this;
  }
  template <class Int> Sink& integer(Int v) {
    char tmp[24];
    const auto res = std::to_chars(tmp, tmp + sizeof tmp, v);
    buf_.append(tmp, static_cast<std::size_t>(res.ptr - tmp));
    return *this;
  }
  Sink& real(double v) {
    char tmp[32];
    const auto res = std::to_chars(tmp, tmp + sizeof tmp, v);
    buf_.append(tmp, static_cast<std::size_t>(res.ptr - tmp));
    return *this;
  }
  void maybe_flush() {
    if (file_ && buf_.size() >= chunk) flush();
  }
  void flush() {
    if (file_ && !buf_.empty()) {
      if (std::fwrite(buf_.data(), 1, buf_.size(), file_) != buf_.size())
        throw InputError("cannot write " + path_ + ": " + std::strerror(errno));
      buf_.clear();
    }
  }
  std::string take() { return std::move(buf_); }

 private:
  static constexpr std::size_t chunk = 4 << 20;
  std::FILE* file_;
  std::string path_;
  std::string buf_;
};

template <int Dim> void bbox_line(Sink& out, const Mesh<Dim>& mesh, const Elements& els) {
  Box<Dim> b = Box<Dim>::empty();
  for (const VertexId v : els.node) b.expand(mesh.points[v.v]);
  if (els.node.empty()) b = Box<Dim>{};
  for (const auto* corner : {&b.lo, &b.hi})
    for (int d = 0; d < 3; ++d) out.real(d < Dim ? (*corner)[d] : 0.0) << ' ';
}

template <int Dim> void write_blocks(Sink& out, const Elements& els, int entity_dim, std::int64_t first_tag) {
  for (int t = 0; t <= static_cast<int>(ElemType::Pyramid5); ++t) {
    const auto type = static_cast<ElemType>(t);
    std::size_t count = 0;
    for (const ElemType et : els.type) count += (et == type);
    if (count == 0) continue;
    out.integer(entity_dim) << ' ' << '1' << ' ';
    out.integer(gmsh_type(type)) << ' ';
    out.integer(count) << '\n';
    for (std::size_t e = 0; e < els.size(); ++e) {
      if (els.type[e] != type) continue;
      out.integer(first_tag + static_cast<std::int64_t>(e));
      const ElemId id{static_cast<std::int32_t>(e)};
      for (int i = 0; i < els.n_nodes_of(id); ++i) out << ' ', out.integer(std::int64_t{els.nodes(id)[i].v} + 1);
      out << '\n';
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

template <int Dim> void write(Sink& out, const Mesh<Dim>& mesh) {
  out << "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
  out << "$PhysicalNames\n2\n";
  out.integer(Dim - 1) << " 2 \"interface\"\n";
  out.integer(Dim) << " 1 \"solid\"\n";
  out << "$EndPhysicalNames\n";

  // One entity per group: the interface is entity (Dim-1, 1) with physical tag 2, the solid
  // entity (Dim, 1) with physical tag 1; no bounding relations (the mesh is all there is).
  out << "$Entities\n";
  out << (Dim == 2 ? "0 1 1 0\n" : "0 0 1 1\n");
  out << '1' << ' ';
  bbox_line<Dim>(out, mesh, mesh.interface);
  out << "1 2 0\n";
  out << '1' << ' ';
  bbox_line<Dim>(out, mesh, mesh.solid);
  out << "1 1 0\n";
  out << "$EndEntities\n";

  const std::size_t n = mesh.points.size();
  out << "$Nodes\n";
  if (n == 0) {
    out << "0 0 0 0\n";
  } else {
    out << "1 ";
    out.integer(n) << " 1 ";
    out.integer(n) << '\n';
    out.integer(Dim) << " 1 0 ";
    out.integer(n) << '\n';
    for (std::size_t i = 0; i < n; ++i) {
      out.integer(i + 1) << '\n';
      out.maybe_flush();
    }
    for (const auto& p : mesh.points) {
      out.real(p[0]) << ' ';
      out.real(p[1]) << ' ';
      out.real(Dim == 3 ? p[Dim - 1] : 0.0) << '\n';
      out.maybe_flush();
    }
  }
  out << "$EndNodes\n";

  const std::size_t ne = mesh.solid.size() + mesh.interface.size();
  out << "$Elements\n";
  out.integer(n_types(mesh.solid) + n_types(mesh.interface)) << ' ';
  out.integer(ne) << ' ';
  out.integer(ne == 0 ? 0 : 1) << ' ';
  out.integer(ne) << '\n';
  write_blocks<Dim>(out, mesh.solid, Dim, 1);
  write_blocks<Dim>(out, mesh.interface, Dim - 1, static_cast<std::int64_t>(mesh.solid.size()) + 1);
  out << "$EndElements\n";
}

}  // namespace

template <int Dim> std::string msh_string(const Mesh<Dim>& mesh) {
  Sink out;
  write<Dim>(out, mesh);
  return out.take();
}

template <int Dim> void write_msh(const Mesh<Dim>& mesh, const std::filesystem::path& path) {
  const std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "wb"), &std::fclose);
  if (!file) throw InputError("cannot open " + path.string() + " for writing: " + std::strerror(errno));
  Sink out(file.get(), path.string());
  write<Dim>(out, mesh);
  out.flush();
  if (std::fflush(file.get()) != 0) throw InputError("cannot write " + path.string() + ": " + std::strerror(errno));
}

template std::string msh_string<2>(const Mesh<2>&);
template std::string msh_string<3>(const Mesh<3>&);
template void write_msh<2>(const Mesh<2>&, const std::filesystem::path&);
template void write_msh<3>(const Mesh<3>&, const std::filesystem::path&);

}  // namespace febemesh
