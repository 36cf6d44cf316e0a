#pragma once
// report.json of a 2D run (DESIGN.md contracts): counts, per-stage timings, quality (angles,
// scaled-Jacobian histogram), fidelity against the exact curve, validation, and the options.

#include <string>

#include "core/validate.hpp"
#include "dim2/fidelity2d.hpp"
#include "dim2/pipeline2d.hpp"

namespace febemesh::dim2 {

struct RunInfo {
  std::string input;
  std::string version;
  double total_seconds = 0.0;
  long peak_memory_bytes = 0;
};

/// The report as pretty-printed JSON. Deterministic apart from the timing and memory fields.
std::string report_json(const Result2d& r, const CurveBoundary& curve, const Options2d& opt, const Fidelity2d& fid,
                        const ValidationReport& valid, const RunInfo& info);

}  // namespace febemesh::dim2
