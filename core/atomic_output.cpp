// POSIX rename() is atomic for a folder onto a missing or empty target only, so an existing DIR
// is first moved aside to DIR.old-<pid> and removed after the new folder is in place.

#include "core/atomic_output.hpp"

#include <unistd.h>

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
}  // namespace

AtomicOutputDir::AtomicOutputDir(fs::path dir) {
  if (dir.empty()) throw InputError("empty output folder name");
  // "out/" names the folder "out": drop a trailing separator so the siblings sit next to it.
  if (!dir.has_filename()) dir = dir.parent_path();
  final_ = dir;
  tmp_ = sibling(final_, ".tmp-");
  std::error_code ec;
  fs::remove_all(tmp_, ec);
  if (final_.has_parent_path()) fs::create_directories(final_.parent_path(), ec);
  if (!fs::create_directory(tmp_, ec) || ec)
    throw InputError("cannot create output folder " + tmp_.string() + ": " + ec.message());
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
    if (!fs::is_directory(final_, ec)) throw InputError("output " + final_.string() + " exists and is not a folder");
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
