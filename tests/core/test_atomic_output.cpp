// core/atomic_output.hpp: nothing is left behind unless committed; commit replaces old output.

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>

#include "core/atomic_output.hpp"
#include "core/error.hpp"
#include "scratch_dir.hpp"

using namespace febemesh;
namespace fs = std::filesystem;

namespace {
std::size_t n_entries(const fs::path& dir) {
  return static_cast<std::size_t>(std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
}
}  // namespace

TEST_CASE("an uncommitted output folder leaves nothing", "[atomic_output]") {
  const test::ScratchDir scratch("atomic");
  const fs::path& root = scratch.path();
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
}

TEST_CASE("commit moves the folder into place and replaces a previous run", "[atomic_output]") {
  const test::ScratchDir scratch("atomic");
  const fs::path& root = scratch.path();
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
}

TEST_CASE("a trailing separator names the same folder", "[atomic_output]") {
  const test::ScratchDir scratch("atomic");
  const fs::path& root = scratch.path();
  {
    AtomicOutputDir dir(root.string() + "/out/");
    dir.commit();
  }
  CHECK(fs::is_directory(root / "out"));
  CHECK(n_entries(root) == 1);
}

TEST_CASE("a folder febemesh did not write is never replaced", "[atomic_output]") {
  const test::ScratchDir scratch("atomic");
  const fs::path& root = scratch.path();
  const fs::path out = root / "work";
  fs::create_directories(out / "thesis");
  std::ofstream(out / "notes.txt") << "mine";
  // Refused before the run, with the folder's name and one of the foreign entries.
  try {
    AtomicOutputDir dir(out);
    FAIL("a user's folder was accepted as output");
  } catch (const InputError& e) {
    const std::string what = e.what();
    CHECK(what.find(out.string()) != std::string::npos);
    CHECK(what.find("did not write") != std::string::npos);
    CHECK((what.find("'notes.txt'") != std::string::npos || what.find("'thesis'") != std::string::npos));
  }
  CHECK(fs::exists(out / "notes.txt"));
  CHECK(fs::is_directory(out / "thesis"));
  CHECK(n_entries(root) == 1);  // no temporary folder left
  // A file in the folder's place is refused too, and kept.
  std::ofstream(root / "file") << "x";
  CHECK_THROWS_AS(AtomicOutputDir(root / "file"), InputError);
  CHECK(fs::is_regular_file(root / "file"));
}

TEST_CASE("a folder that becomes foreign during the run is kept at commit", "[atomic_output]") {
  const test::ScratchDir scratch("atomic");
  const fs::path& root = scratch.path();
  const fs::path out = root / "out";
  {
    AtomicOutputDir dir(out);
    std::ofstream(dir.file("mesh.msh")) << "first";
    dir.commit();
  }
  CHECK(fs::exists(out / std::string(kOutputMarker)));
  {
    AtomicOutputDir dir(out);  // febemesh's own folder: accepted
    std::ofstream(dir.file("mesh.msh")) << "second";
    // While the run goes on, someone replaces the folder with their own.
    fs::remove_all(out);
    fs::create_directories(out);
    std::ofstream(out / "data.csv") << "1,2";
    CHECK_THROWS_AS(dir.commit(), InputError);
    CHECK_FALSE(dir.committed());
  }
  CHECK(fs::exists(out / "data.csv"));
  CHECK(n_entries(root) == 1);  // the temporary folder removed
}

TEST_CASE("an output folder of an earlier version, without the marker, is replaced", "[atomic_output]") {
  const test::ScratchDir scratch("atomic");
  const fs::path& root = scratch.path();
  const fs::path out = root / "out";
  fs::create_directories(out / "figures");
  for (const char* name : {"mesh.msh", "mesh.vtu", "report.json"}) std::ofstream(out / name) << "old";
  {
    AtomicOutputDir dir(out);
    std::ofstream(dir.file("mesh.msh")) << "new";
    dir.commit();
  }
  CHECK_FALSE(fs::exists(out / "report.json"));
  CHECK(fs::exists(out / std::string(kOutputMarker)));
  // An empty folder is taken too.
  const fs::path empty = root / "empty";
  fs::create_directories(empty);
  {
    AtomicOutputDir dir(empty);
    dir.commit();
  }
  CHECK(fs::exists(empty / std::string(kOutputMarker)));
}
