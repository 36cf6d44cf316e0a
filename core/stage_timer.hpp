#pragma once
// Per-stage wall-clock timings of a pipeline run (report.json "timings_seconds").

#include <chrono>
#include <string>
#include <vector>

namespace febemesh {

struct StageTime {
  std::string name;
  double seconds = 0.0;
};

/// Appends the time since the previous lap (or construction) under `name`.
class StageTimer {
 public:
  explicit StageTimer(std::vector<StageTime>& out) : out_(out) {}
  void lap(const std::string& name) {
    const auto now = std::chrono::steady_clock::now();
    out_.push_back({name, std::chrono::duration<double>(now - last_).count()});
    last_ = now;
  }

 private:
  std::vector<StageTime>& out_;
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

}  // namespace febemesh
