// Meshes a native 2D file with the installed library and prints "elements interface_elements".
#include <cstdio>

#include "dim2/pipeline2d.hpp"
#include "dim2/read_domain.hpp"

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  using namespace febemesh::dim2;
  const CurveBoundary curve(read_domain(argv[1]));
  Options2d opt;
  opt.level = 3;
  const Result2d r = mesh2d(curve, opt);
  std::printf("%zu %zu\n", r.fe.mesh.solid.size(), r.fe.mesh.interface.size());
  return r.fe.mesh.solid.size() > 0 && r.fe.mesh.interface.size() > 0 ? 0 : 1;
}
