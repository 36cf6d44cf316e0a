#include "core/process_stats.hpp"

#include <fstream>
#include <string>

namespace febemesh {
namespace {

long status_field(const char* key) {
  std::ifstream in("/proc/self/status");
  const std::string k(key);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(k, 0) == 0) return std::stol(line.substr(k.size())) * 1024;  // reported in kB
  }
  return 0;
}

}  // namespace

long peak_memory_bytes() { return status_field("VmHWM:"); }

long current_memory_bytes() { return status_field("VmRSS:"); }

bool reset_peak_memory() {
  std::ofstream out("/proc/self/clear_refs");
  out << "5\n";
  out.flush();
  return static_cast<bool>(out);
}

}  // namespace febemesh
