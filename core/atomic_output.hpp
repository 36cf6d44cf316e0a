#pragma once
// An output folder written atomically (DESIGN.md: "a failed run leaves no partial output").
// Files go to DIR.tmp-<pid> next to DIR; commit() renames it over DIR (replacing the DIR of a
// previous run); destruction without commit() removes the temporary folder.

#include <filesystem>
#include <string>

namespace febemesh {

class AtomicOutputDir {
 public:
  /// Creates the temporary folder (and DIR's parent folders). Throws InputError if it cannot.
  explicit AtomicOutputDir(std::filesystem::path dir);
  ~AtomicOutputDir();
  AtomicOutputDir(const AtomicOutputDir&) = delete;
  AtomicOutputDir& operator=(const AtomicOutputDir&) = delete;

  /// Where to write now (the temporary folder until commit, then the final one).
  const std::filesystem::path& path() const { return committed_ ? final_ : tmp_; }
  std::filesystem::path file(const std::string& name) const { return path() / name; }
  const std::filesystem::path& final_path() const { return final_; }
  bool committed() const { return committed_; }

  /// Moves the folder into place. Throws InputError if the rename fails (the temporary folder
  /// is then removed by the destructor).
  void commit();

 private:
  std::filesystem::path final_;
  std::filesystem::path tmp_;
  bool committed_ = false;
};

}  // namespace febemesh
