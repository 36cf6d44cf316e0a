#pragma once
// The progress lines of a long command on stderr, each with the seconds since the command
// started: "mesh3d: [  12.3 s] untangling: ...". A refused try on a machined part can run for
// minutes (spool L6: 8 CPU minutes), and the times say where they went.

#include <chrono>
#include <cstdio>
#include <iostream>
#include <string>

namespace febemesh::cli {

class Progress {
 public:
  Progress(std::string command, bool quiet)
      : command_(std::move(command)), quiet_(quiet), start_(std::chrono::steady_clock::now()) {}

  /// "COMMAND: [  SS.S s] MESSAGE" from the seconds since construction.
  static std::string line(const std::string& command, double seconds, const std::string& message) {
    char stamp[32];
    std::snprintf(stamp, sizeof stamp, "[%6.1f s] ", seconds);
    return command + ": " + stamp + message;
  }

  void operator()(const std::string& message) const {
    if (quiet_) return;
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    std::cerr << line(command_, s, message) << "\n";
  }

 private:
  std::string command_;
  bool quiet_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace febemesh::cli
