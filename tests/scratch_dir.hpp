#pragma once
// A test's scratch folder, removed with everything in it when the test's scope ends: also when a
// REQUIRE fails or an exception escapes, which skip a remove_all at the end of a TEST_CASE (after
// many runs /tmp held dozens of such folders). Header only, so that the fuzz targets
// (tests/fuzz, which link neither Catch2 nor test_paths.cpp) use it too.

#include <atomic>
#include <filesystem>
#include <string>
#include <string_view>
#include <system_error>

#include <unistd.h>

namespace febemesh::test {

/// A new, empty folder temp_directory_path()/febemesh_<name>_<pid>_<n>, removed by the destructor
/// (which never throws). The process id keeps apart the test processes ctest runs in parallel;
/// n counts this process's folders, so two never share a name (a name taken by a leftover of an
/// earlier process with the same id is skipped). Throws filesystem_error when the folder cannot
/// be made.
class ScratchDir {
 public:
  explicit ScratchDir(std::string_view name) {
    static std::atomic<unsigned> n_made{0};
    const std::string stem = "febemesh_" + std::string(name) + "_" + std::to_string(::getpid()) + "_";
    do {
      path_ = std::filesystem::temp_directory_path() / (stem + std::to_string(n_made++));
    } while (!std::filesystem::create_directory(path_));
  }
  ~ScratchDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;

  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

}  // namespace febemesh::test
