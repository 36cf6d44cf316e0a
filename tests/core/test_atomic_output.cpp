// core/atomic_output.hpp: nothing is left behind unless committed; commit replaces old output.

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "core/atomic_output.hpp"

using namespace febemesh;
namespace fs = std::filesystem;

namespace {
fs::path scratch() {
  const fs::path dir = fs::temp_directory_path() / ("febemesh_atomic_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}
std::size_t n_entries(const fs::path& dir) {
  return static_cast<std::size_t>(std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
}
}  // namespace

TEST_CASE("an uncommitted output folder leaves nothing", "[atomic_output]") {
  const fs::path root = scratch();
  const fs::path out = root / "out";
  {
    AtomicOutputDir dir(out);
    CHECK(fs::is_directory(dir.path()));
    CHECK(dir.path().parent_path() == root);
    std::ofstream(dir.file("mesh.msh")) << "partial";
    CHECK_FALSE(fs::exists(out));
  }
  CHECK_FALSE(fs::exists(out));
  CHECK(n_entries(root) == 0);
  // An exception between creation and commit behaves the same.
  try {
    AtomicOutputDir dir(out);
    std::ofstream(dir.file("a.txt")) << "x";
    throw std::runtime_error("failed run");
  } catch (const std::runtime_error&) {
  }
  CHECK(n_entries(root) == 0);
  fs::remove_all(root);
}

TEST_CASE("commit moves the folder into place and replaces a previous run", "[atomic_output]") {
  const fs::path root = scratch();
  const fs::path out = root / "nested" / "out";
  {
    AtomicOutputDir dir(out);
    std::ofstream(dir.file("old.txt")) << "old";
    dir.commit();
    CHECK(dir.committed());
    CHECK(dir.path() == out);
  }
  CHECK(fs::exists(out / "old.txt"));
  {
    AtomicOutputDir dir(out);
    std::ofstream(dir.file("new.txt")) << "new";
    CHECK(fs::exists(out / "old.txt"));  // the previous run stays until commit
    dir.commit();
  }
  CHECK(fs::exists(out / "new.txt"));
  CHECK_FALSE(fs::exists(out / "old.txt"));
  CHECK(n_entries(out.parent_path()) == 1);  // no temporary or old folder left
  fs::remove_all(root);
}

TEST_CASE("a trailing separator names the same folder", "[atomic_output]") {
  const fs::path root = scratch();
  {
    AtomicOutputDir dir(root.string() + "/out/");
    dir.commit();
  }
  CHECK(fs::is_directory(root / "out"));
  CHECK(n_entries(root) == 1);
  fs::remove_all(root);
}
