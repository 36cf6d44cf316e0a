#pragma once
// report.json of a 2D run (DESIGN.md contracts): counts, per-stage timings, quality (angles,
// scaled-Jacobian histogram), fidelity against the exact curve, validation, and the options.

#include <string>
#include <vector>

#include "core/stage_timer.hpp"
#include "core/validate.hpp"
#include "dim2/fidelity2d.hpp"
#include "dim2/pipeline2d.hpp"

namespace febemesh::dim2 {

struct RunInfo {
  std::string input;
  std::string version;
  double total_seconds = 0.0;
  long peak_memory_bytes = 0;
  /// The caller's own steps around mesh2d (reading, writing, checking), in the report's
  /// timings after the pipeline's stages.
  std::vector<StageTime> steps;
};

/// The report as pretty-printed JSON. Deterministic apart from the timing and memory fields.
std::string report_json(const Result2d& r, const CurveBoundary& curve, const Options2d& opt, const Fidelity2d& fid,
                        const ValidationReport& valid, const RunInfo& info);

}  // namespace febemesh::dim2
