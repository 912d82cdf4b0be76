#pragma once
// Static boxes standing on a static half-space or on another static box (not in the
// thesis). The narrow phase pushes a body out of a box along the direction of least
// penetration. For a wall standing on the ground plane that can be the wall's bottom face: a
// small body at the wall's foot that pokes further into the wall sideways than it sticks up out
// of the ground is pushed down, into the ground, by the wall -- in the collision and contact
// stages as in push-out -- while the ground pushes it up, and no motion satisfies both (random
// drops 40, 222, 412, 1316: bodies 50-67 % of their size deep, or sliding through the wall). The
// part of such a box below the plane lies inside the ground, where no body can be, so the box
// may as well reach further down: extended through the plane by its own largest dimension, its
// bottom face is never the cheaper way out for a body above the ground, and every surface a
// body can touch is the same. A wall standing on a static floor box is the same case with a
// solid of finite depth: the wall reaches into the floor box as far as it can without leaving
// it (its footprint must lie on the floor box's face, and it reaches at most to that box's far
// face), so again no surface a body can touch moves.
#include <utility>
#include <vector>

#include "solvers/collision/geometry.h"

namespace monolith::solvers::collision {

template <int d>
struct HalfSpaceInWorld {
  Eigen::Matrix<double, d, 1> normal;  // unit, outward (out of the solid)
  Eigen::Matrix<double, d, 1> point;   // any point on the boundary
};

// A static box as the scene places it: something another static box may stand on.
template <int d>
struct BoxInWorld {
  Pose<d> pose;
  Eigen::Matrix<double, d, 1> halfExtents;
};

// For `box` (a Box geometry) at `pose`: every half-space of `grounds` that one of the box's face
// planes lies on or below (within `tolerance`, metres) while the box's centre lies outside it
// extends the box away from that face by 2 * (its largest half extent), leaving the opposite
// face where it was. Then, for the axes not extended so far, every box of `supports` with a face
// that one of the box's faces lies on or in (within `tolerance`, the box's centre outside the
// support, the face's footprint inside the support's face within `tolerance`) extends the box
// into the support by the same length, or less where the support's far face comes first.
// Returns the centre's shift in the box's body frame (zero when nothing was extended); the
// extended box is centred at pose.x + pose.R * shift. Non-box geometries, and faces not
// parallel to the plane or the support's face (within 1e-9 in the cosine), are left alone. The
// box itself may be among `supports` (its centre is inside it).
template <int d>
Eigen::Matrix<double, d, 1> extendBoxThroughGround(Geometry<d>& box, const Pose<d>& pose,
                                                   const std::vector<HalfSpaceInWorld<d>>& grounds, double tolerance,
                                                   const std::vector<BoxInWorld<d>>& supports = {});

}  // namespace monolith::solvers::collision
