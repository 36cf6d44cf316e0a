#pragma once
// An output folder written atomically (DESIGN.md: "a failed run leaves no partial output").
// Files go to DIR.tmp-<pid> next to DIR; commit() renames it over DIR (replacing the DIR of a
// previous run); destruction without commit() removes the temporary folder. Every such folder
// holds the marker file kOutputMarker, and an existing DIR is replaced only when it is empty or
// febemesh wrote it (the marker, or only the names febemesh writes): never a user's folder.

#include <filesystem>
#include <string>
#include <string_view>

namespace febemesh {

/// The file that marks an output folder as febemesh's, so that a later run may replace it.
inline constexpr std::string_view kOutputMarker = ".febemesh-output";

/// Throws InputError unless `dir` is missing, an empty folder or one febemesh wrote (it holds the
/// marker, or only the names febemesh writes): the check AtomicOutputDir makes, for a command
/// to make before its run, so that the user learns at once.
void check_output_folder(std::filesystem::path dir);

class AtomicOutputDir {
 public:
  /// Creates the temporary folder (and DIR's parent folders) with the marker. Throws
  /// InputError if it cannot, or if DIR exists and is not a folder febemesh wrote.
  explicit AtomicOutputDir(std::filesystem::path dir);
  ~AtomicOutputDir();
  AtomicOutputDir(const AtomicOutputDir&) = delete;
  AtomicOutputDir& operator=(const AtomicOutputDir&) = delete;

  /// Where to write now (the temporary folder until commit, then the final one).
  const std::filesystem::path& path() const { return committed_ ? final_ : tmp_; }
  std::filesystem::path file(const std::string& name) const { return path() / name; }
  const std::filesystem::path& final_path() const { return final_; }
  bool committed() const { return committed_; }

  /// Moves the folder into place. Throws InputError if the rename fails or DIR has become a
  /// folder febemesh did not write (the temporary folder is then removed by the destructor).
  void commit();

 private:
  std::filesystem::path final_;
  std::filesystem::path tmp_;
  bool committed_ = false;
};

}  // namespace febemesh
