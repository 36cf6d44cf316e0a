#pragma once
// Memory of this process (Linux /proc/self/status), for reports and benchmarks. 0 when
// unavailable.

namespace febemesh {

/// Peak resident memory (VmHWM) since the process started or the last reset_peak_memory().
long peak_memory_bytes();
/// Resident memory now (VmRSS).
long current_memory_bytes();
/// Resets the peak to the current resident memory (writes 5 to /proc/self/clear_refs), so a
/// benchmark can measure one run's peak in process. False when the kernel refuses.
bool reset_peak_memory();

}  // namespace febemesh
