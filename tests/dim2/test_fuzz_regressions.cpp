// Inputs the fuzz targets (tests/fuzz) once crashed on, replayed in the normal suite: each must
// now be read or refused with InputError (fuzz_inputs.hpp), nothing else.

#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "fuzz/fuzz_inputs.hpp"

namespace fs = std::filesystem;

TEST_CASE("inputs found by the fuzzers are read or refused with InputError", "[fuzz][readers]") {
  const fs::path root = fs::path(FEBEMESH_SOURCE_DIR) / "tests" / "fuzz" / "regressions";
  if (!fs::exists(root)) return;
  const std::vector<std::pair<std::string, void (*)(std::string_view)>> targets = {
      {"svg", febemesh::fuzz::svg_input},
      {"native", febemesh::fuzz::native_input},
      {"poly", febemesh::fuzz::poly_input},
      {"off", febemesh::fuzz::off_input},
      {"stl", febemesh::fuzz::stl_input},
      {"obj", febemesh::fuzz::obj_input},
      {"ply", febemesh::fuzz::ply_input}};
  for (const auto& [dir, run] : targets) {
    if (!fs::exists(root / dir)) continue;
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(root / dir)) files.push_back(e.path());
    std::sort(files.begin(), files.end());
    for (const fs::path& f : files) {
      INFO(f.string());
      std::ifstream in(f, std::ios::binary);
      std::ostringstream ss;
      ss << in.rdbuf();
      CHECK_NOTHROW(run(ss.str()));
    }
  }
}
