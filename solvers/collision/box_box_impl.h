#pragma once
// Private to solvers/collision: the dedicated box-box narrow phase, used instead of
// FCL's dBoxBox for box pairs. In a box pyramid every pair is a box pair and the contact stages
// ask for its manifold ~56 times per pair and step, so this is one of the hot paths.
#include <vector>

#include "solvers/collision/collision_impl.h"

namespace monolith::solvers::collision {

// Separating-axis test over the 15 axes (3 face normals of each box, 9 edge-edge cross
// products). `separation` is the largest signed gap along them: > 0 means the boxes are apart by
// at least that much (the exact distance can only be larger), <= 0 means they overlap and -gap is
// the least overlap over the axes. The chosen axis prefers a face over an edge pair unless the
// edge pair's overlap is clearly smaller (5%), which keeps face contacts face contacts when an
// edge axis ties within rounding.
struct BoxBoxAxis {
  double separation = -kInfinity;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitY();  // unit, out of B towards A
  int code = -1;  // 0-2: a face of A, 3-5: a face of B, 6 + 3i + j: edge i of A x edge j of B
  // The axis of least overlap without the face preference: the boxes' exact penetration
  // direction (for convex polytopes the minimum over all directions is at one of the 15 axes).
  Eigen::Vector3d leastOverlapNormal = Eigen::Vector3d::UnitY();
  double leastOverlap = kInfinity;  // the overlap along it (< 0: apart)
};
// stopAbove: return as soon as some axis shows a gap larger than this (then only `separation`
// > stopAbove is meaningful: the gap found so far, a lower bound on the full test's).
BoxBoxAxis boxBoxAxis(const Geometry<3>& a, const Pose<3>& poseA, const Geometry<3>& b, const Pose<3>& poseB,
                      double stopAbove = kInfinity);

// The contacts of two overlapping boxes on `axis` (what FCL's box-box returns): for a face axis
// the incident face of the other box clipped against the reference face, one point per clipped
// vertex at or below the reference face (at most 4, the deepest and the most spread), each
// midway between the surfaces with its own depth; for an edge pair the one point midway between
// the closest points of the two edges, depth = the overlap along the axis. Normals out of B
// towards A. Appends to `out`; returns how many.
int boxBoxContacts(const Geometry<3>& a, const Pose<3>& poseA, const Geometry<3>& b, const Pose<3>& poseB,
                   const BoxBoxAxis& axis, std::vector<ContactPoint<3>>& out);

// Whether boxBoxContacts would report any point, without computing them all where a corner of
// the incident face already lies inside the reference face (scratch: for the full clip else).
bool boxBoxContactsExist(const Geometry<3>& a, const Pose<3>& poseA, const Geometry<3>& b, const Pose<3>& poseB,
                         const BoxBoxAxis& axis, std::vector<ContactPoint<3>>& scratch);

// Nearest points of two boxes the axis test found apart (axis.separation > 0), exactly: the least
// of the vertex-to-box distances both ways and, unless a vertex already reaches the axis' gap
// (a lower bound on the distance, reached in face contacts), of the edge-to-edge distances.
// False when the boxes are farther apart than `limit`. Replaces fcl::distance for box pairs.
bool boxBoxNearestPoints(const Geometry<3>& a, const Pose<3>& poseA, const Geometry<3>& b, const Pose<3>& poseB,
                         const BoxBoxAxis& axis, double limit, Eigen::Vector3d& onA, Eigen::Vector3d& onB);

}  // namespace monolith::solvers::collision
