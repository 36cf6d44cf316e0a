#pragma once
// rapidcheck generators of random valid 2D domains and pipeline options for the property suite
// (issue 5). A case is described by a handful of small integers (radii per angle sample, turning
// angles, corner flags, hole count...), so shrinking gives small geometries: few control points,
// no holes, one component, no corners, the lowest level. A case prints itself as a native JSON
// file (docs/native-format.md) so that a shrunk counterexample can be saved as a regression input
// under tests/dim2/regressions/ as it is.
//
// Regime (what the pipeline is meant to handle, so what is generated): every gap between two
// loops and every neck or slot of a loop (two points of one loop closer than a quarter of the arc
// between them) is at least `min_feature_cells` cells of the chosen level wide; corners are no
// sharper than about 40 degrees; levels 6..9 (the level is raised above the drawn one when the
// features need it, cases needing more than 9 are not generated).

#include <ostream>
#include <string>
#include <vector>

#include <rapidcheck.h>

#include "dim2/curve_model.hpp"
#include "dim2/pipeline2d.hpp"

namespace febemesh::test {

inline constexpr double min_feature_cells = 2.0;
inline constexpr int min_generated_level = 6;
inline constexpr int max_generated_level = 9;

/// One loop as the native format states it: B-spline control points.
struct LoopSpec {
  std::string name;
  std::vector<dim2::ControlPoint> points;
};

/// A domain as control points, plus the global level it is meshed at.
struct DomainSpec {
  std::vector<LoopSpec> loops;
  std::vector<dim2::InteriorControl> interior;
  int level = min_generated_level;  ///< global level (options.level)
  std::string shape;                ///< e.g. "star+2 holes, worm": for classification
};

struct PipelineCase {
  DomainSpec domain;
  dim2::ElementKind elements = dim2::ElementKind::Tri;
  int smoothing_iterations = 4;
  double buffer = 0.35;
};

/// The Domain (loops built with loop_from_bspline, default_level = spec.level).
dim2::Domain to_domain(const DomainSpec& spec);
/// The case as a native JSON file (options.level and options.elements set).
std::string to_native_json(const DomainSpec& spec, dim2::ElementKind elements);
/// The case as a native JSON file; smoothing and buffer in "_pipeline" (ignored by the reader,
/// read by test_property_regressions.cpp).
std::string to_native_json(const PipelineCase& c);
/// Options2d for the case (keep_stages off).
dim2::Options2d to_options(const PipelineCase& c);

/// Sampled estimate of the thinnest feature: the smallest distance between two loops or between
/// two points of one loop whose distance is below a quarter of the arc between them (so corners
/// down to ~29 degrees are not features). 24 samples per Bezier piece.
double min_feature_size(const dim2::Domain& domain);
/// Side of the pipeline's root square (CurveBoundary::root_box).
double root_side(const dim2::Domain& domain);
/// The smallest level whose cells fit min_feature_cells times into min_feature_size.
int level_for_features(const dim2::Domain& domain);

/// Valid domains: 1-2 components side by side, each a star-shaped loop (5-12 angle samples,
/// radii 0.6-1.0, random corners, 0-3 holes) or a non-star-shaped "worm" (a thick bent polyline
/// of 2-5 segments, turns up to 60 degrees); random control levels on some points and 0-2
/// interior control points; level in 6..8, raised to level_for_features (<= 9).
rc::Gen<DomainSpec> gen_domain_spec();
/// A case: a domain, elements tri/quad/mixed, smoothing 0..4, buffer 0..0.5.
rc::Gen<PipelineCase> gen_pipeline_case();
/// The same with the element kind fixed.
rc::Gen<PipelineCase> gen_pipeline_case(dim2::ElementKind elements);

// rapidcheck prints counterexamples with showValue, found by argument-dependent lookup.
void showValue(const DomainSpec& spec, std::ostream& os);
void showValue(const PipelineCase& c, std::ostream& os);

}  // namespace febemesh::test
