#include "core/process_stats.hpp"

#include <fstream>
#include <string>

namespace febemesh {

long peak_memory_bytes() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("VmHWM:", 0) == 0) return std::stol(line.substr(6)) * 1024;  // reported in kB
  }
  return 0;
}

}  // namespace febemesh
