// POSIX rename() is atomic for a folder onto a missing or empty target only, so an existing DIR
// is first moved aside to DIR.old-<pid> and removed after the new folder is in place. Only a
// folder febemesh wrote is ever replaced (check_output_folder): `-o ~/work` used to remove the
// whole of ~/work at the end of the run.

#include "core/atomic_output.hpp"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <fstream>
#include <string_view>
#include <system_error>

#include "core/error.hpp"

namespace febemesh {

namespace fs = std::filesystem;

namespace {
fs::path sibling(const fs::path& dir, const char* what) {
  fs::path p = dir;
  p += std::string(what) + std::to_string(::getpid());
  return p;
}

/// What the subcommands write at the top of their output folders (before the marker existed,
/// an output folder held these only).
constexpr std::array<std::string_view, 13> written_names = {
    kOutputMarker, "mesh.msh", "mesh.vtu",  "report.json", "figures",       "comparison.md",  "comparison.json",
    "interface.svg", "tetgen.msh", "tetgen.log", "gmsh.geo", "gmsh.msh", "gmsh.log"};

}  // namespace

void check_output_folder(fs::path dir) {
  if (!dir.has_filename()) dir = dir.parent_path();
  std::error_code ec;
  const fs::file_status st = fs::symlink_status(dir, ec);
  if (ec || !fs::exists(st)) return;
  if (fs::is_symlink(st)) throw InputError("output " + dir.string() + " is a symbolic link: name the folder itself");
  if (!fs::is_directory(st)) throw InputError("output " + dir.string() + " exists and is not a folder");
  if (fs::exists(dir / std::string(kOutputMarker), ec)) return;
  std::size_t n = 0;
  std::string foreign;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    ++n;
    const std::string name = it->path().filename().string();
    if (foreign.empty() && std::find(written_names.begin(), written_names.end(), name) == written_names.end())
      foreign = name;
  }
  if (ec) throw InputError("output folder " + dir.string() + ": cannot read it: " + ec.message());
  if (foreign.empty()) return;
  throw InputError("output folder " + dir.string() + " exists and holds files febemesh did not write ('" + foreign +
                   "'" + (n > 1 ? " and " + std::to_string(n - 1) + " more" : std::string()) +
                   "); it would be replaced whole: name a new or empty folder");
}

AtomicOutputDir::AtomicOutputDir(fs::path dir) {
  if (dir.empty()) throw InputError("empty output folder name");
  // "out/" names the folder "out": drop a trailing separator so the siblings sit next to it.
  if (!dir.has_filename()) dir = dir.parent_path();
  final_ = dir;
  // Before the run, not after it: the user learns at once, and nothing is computed in vain.
  check_output_folder(final_);
  tmp_ = sibling(final_, ".tmp-");
  std::error_code ec;
  fs::remove_all(tmp_, ec);
  if (final_.has_parent_path()) fs::create_directories(final_.parent_path(), ec);
  if (!fs::create_directory(tmp_, ec) || ec)
    throw InputError("cannot create output folder " + tmp_.string() + ": " + ec.message());
  std::ofstream marker(tmp_ / std::string(kOutputMarker));
  marker << "written by febemesh; the next run into this folder replaces it whole\n";
  if (!marker) throw InputError("cannot write in output folder " + tmp_.string());
}

AtomicOutputDir::~AtomicOutputDir() {
  if (committed_) return;
  std::error_code ec;
  fs::remove_all(tmp_, ec);
}

void AtomicOutputDir::commit() {
  if (committed_) return;
  std::error_code ec;
  fs::path old;
  if (fs::exists(final_, ec)) {
    check_output_folder(final_);  // again: the folder may have been made while the run went on
    old = sibling(final_, ".old-");
    fs::remove_all(old, ec);
    fs::rename(final_, old, ec);
    if (ec) throw InputError("cannot replace output folder " + final_.string() + ": " + ec.message());
  }
  fs::rename(tmp_, final_, ec);
  if (ec) {
    std::error_code restore;
    if (!old.empty()) fs::rename(old, final_, restore);
    throw InputError("cannot move " + tmp_.string() + " to " + final_.string() + ": " + ec.message());
  }
  committed_ = true;
  if (!old.empty()) fs::remove_all(old, ec);
}

}  // namespace febemesh
