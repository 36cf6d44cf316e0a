#pragma once
// The writers' output buffer (MSH and VTU): text and bytes appended to a string which, when a
// file is given, is spilled to it every few MiB, so that a large mesh's text is never held whole
// (it was the CLI's memory peak); without a file the whole output stays in memory (take()).

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <string>

#include "core/error.hpp"

namespace febemesh {

class SpillBuffer {
 public:
  static constexpr std::size_t chunk = 4 << 20;

  /// `path` names the file in the error thrown when a write fails.
  SpillBuffer(std::FILE* file, std::string path, std::size_t reserve) : file_(file), path_(std::move(path)) {
    buf_.reserve(reserve);
  }
  /// Writes what is buffered once it reaches `chunk` bytes (with a file).
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
  /// Everything appended (without a file) or what has not been flushed yet.
  std::string take() { return std::move(buf_); }

 protected:
  bool has_file() const { return file_ != nullptr; }
  /// The shortest text that reads back as `v` (std::to_chars).
  template <class Num> void append_number(Num v) {
    char tmp[32];
    const auto res = std::to_chars(tmp, tmp + sizeof tmp, v);
    buf_.append(tmp, static_cast<std::size_t>(res.ptr - tmp));
  }

  std::string buf_;

 private:
  std::FILE* file_;
  std::string path_;
};

}  // namespace febemesh
