#pragma once
// The writers' output buffer (MSH and VTU): text and bytes appended to a buffer which, when a
// file is given, is spilled to it every few MiB, so that a large mesh's text is never held whole
// (it was the CLI's memory peak); without a file the whole output stays in memory (take()).

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <string_view>
#include <type_traits>

#include "core/error.hpp"

namespace febemesh {

class SpillBuffer {
 public:
  static constexpr std::size_t chunk = 4 << 20;

  /// `path` names the file in the error thrown when a write fails.
  SpillBuffer(std::FILE* file, std::string path, std::size_t reserve) : file_(file), path_(std::move(path)) {
    grow(std::max<std::size_t>(reserve, 256));
  }
  /// Writes what is buffered once it reaches `chunk` bytes (with a file).
  void maybe_flush() {
    if (file_ && size_ >= chunk) flush();
  }
  void flush() {
    if (file_ && size_ != 0) {
      if (std::fwrite(buf_.get(), 1, size_, file_) != size_)
        throw InputError("cannot write " + path_ + ": " + std::strerror(errno));
      size_ = 0;
    }
  }
  /// Everything appended (without a file) or what has not been flushed yet.
  std::string take() {
    std::string out(buf_.get(), size_);
    size_ = 0;
    return out;
  }

 protected:
  bool has_file() const { return file_ != nullptr; }
  /// Writes `s` to the file at once, past the buffer (which the caller has flushed).
  void write_through(std::string_view s) {
    if (!s.empty() && std::fwrite(s.data(), 1, s.size(), file_) != s.size())
      throw InputError("cannot write " + path_ + ": " + std::strerror(errno));
  }
  // The text is written through a cursor into a buffer sized once (grown only when no file
  // takes it, or a field overruns a chunk): std::string::append and push_back per field, with
  // their capacity checks and calls, were 2% of the CLI's instructions (flange level 9).
  void put(std::string_view s) {
    std::memcpy(room(s.size()), s.data(), s.size());
    size_ += s.size();
  }
  void put(char c) {
    *room(1) = c;
    ++size_;
  }
  /// The shortest text that reads back as `v` (std::to_chars).
  template <class Num> void append_number(Num v) {
    char* p = room(max_number);
    // Integers that fit take the 32-bit path: the same digits, with 32-bit divisions by 100
    // (the 64-bit ones were most of the element blocks' cost, flange level 9).
    if constexpr (std::is_integral_v<Num> && sizeof(Num) > sizeof(std::uint32_t)) {
      if (v >= 0 && static_cast<std::uint64_t>(v) <= std::numeric_limits<std::uint32_t>::max()) {
        size_ = static_cast<std::size_t>(std::to_chars(p, p + max_number, static_cast<std::uint32_t>(v)).ptr - buf_.get());
        return;
      }
    }
    size_ = static_cast<std::size_t>(std::to_chars(p, p + max_number, v).ptr - buf_.get());
  }

 private:
  static constexpr std::size_t max_number = 32;  ///< a double's shortest text has at most 24 chars
  char* room(std::size_t n) {
    if (capacity_ - size_ < n) [[unlikely]]
      grow(std::max(2 * capacity_, size_ + n));
    return buf_.get() + size_;
  }
  /// Uninitialised room (a reserve, not written until used: the untouched part of a chunk
  /// costs no memory).
  void grow(std::size_t capacity) {
    std::unique_ptr<char[]> bigger(new char[capacity]);
    if (size_ != 0) std::memcpy(bigger.get(), buf_.get(), size_);
    buf_ = std::move(bigger);
    capacity_ = capacity;
  }

  std::unique_ptr<char[]> buf_;  ///< bytes [0, size_) are the output, capacity_ in all
  std::size_t size_ = 0, capacity_ = 0;
  std::FILE* file_;
  std::string path_;
};

}  // namespace febemesh
