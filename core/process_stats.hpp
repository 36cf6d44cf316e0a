#pragma once
// Peak resident memory of this process (Linux /proc/self/status VmHWM), for reports and
// benchmarks. 0 when unavailable.

namespace febemesh {

long peak_memory_bytes();

}  // namespace febemesh
