#pragma once
// report.json of a 2D run (DESIGN.md contracts): counts, per-stage timings, quality (angles,
// scaled-Jacobian histogram), fidelity against the exact curve, validation, and the options.

#include <optional>
#include <string>
#include <vector>

#include "core/quality.hpp"
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

/// The quality section's measures: the summary (elements under 20 deg), the smallest angle away
/// from input corners sharper than 20 deg and, with quads, the quad angles away from those
/// sharper than 30 deg.
struct Quality2d {
  QualitySummary summary;
  double min_angle_away_deg = 0.0;
  std::size_t n_near_sharp_corners = 0;
  std::optional<AnglesAwayFromCorners> quad_bar;
};
/// On n_threads threads: the same numbers for every count. (The CLI times it with the run.
/// Measured inside report_json, after the total was taken, it was time report.json left out:
/// NimbusSans U0067 at 964,528 triangles, the process's wall time less the total 0.11 s, now
/// 0.02 s.)
Quality2d measure_quality(const Mesh<2>& m, const CurveBoundary& curve, int n_threads);

/// The report as pretty-printed JSON. Deterministic apart from the timing and memory fields.
std::string report_json(const Result2d& r, const CurveBoundary& curve, const Options2d& opt, const Fidelity2d& fid,
                        const Quality2d& quality, const ValidationReport& valid, const RunInfo& info);

}  // namespace febemesh::dim2
