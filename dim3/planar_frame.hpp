#pragma once
// The frame of a surface's planar faces: axes along which most of the surface's area lies on
// planes normal to an axis. A machined part meshed in it has its flat faces on the octree's
// lattice planes, as when it is given aligned: the octants they cut are whole slabs, not
// wedges (Options3d::align_planar_faces). Measured (CLI, level 4, one thread; the bar's parts
// turned by a random rotation): spool refused after 90 s, fandisk valid but 8.50 deg, anchor
// 23-33 s CPU against 3.7 s aligned.

#include <Eigen/Core>

#include "dim3/surface.hpp"

namespace febemesh::dim3 {

struct PlanarFrame {
  /// Rows: the frame's axes in the surface's coordinates (a rotation: x_frame = to_frame x).
  Eigen::Matrix3d to_frame = Eigen::Matrix3d::Identity();
  bool turned = false;       ///< to_frame is not the identity
  double share_given = 0.0;  ///< share of the area on planes normal to an axis, as given
  double share_frame = 0.0;  ///< the same in the frame (share_given when not turned)
};

/// Candidate axes: the mean normals of the 12 largest groups of triangles with about the same
/// normal (up to sign), every pair of them within `tolerance_deg` of square making a frame. A
/// triangle counts for a frame when its normal is within `tolerance_deg` of an axis. The best
/// frame is taken when its share beats the given axes' by `min_gain` of the area; its axes are
/// ordered and signed to be nearest the given ones. Deterministic (no hashing, no threads).
PlanarFrame planar_frame(const Surface& s, double tolerance_deg = 1.0, double min_gain = 0.1);

/// The surface with every vertex turned into the frame (to_frame x); the same triangles.
Surface turned_surface(const Surface& s, const Eigen::Matrix3d& to_frame);

}  // namespace febemesh::dim3
