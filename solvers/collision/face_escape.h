#pragma once
// A way out of a box through one of its faces, for push-out. The narrow phase reports
// the direction of least penetration; when a box lies on another static body (a wall standing on
// the ground plane, its bottom face on the plane), that direction can lead straight into the
// other body, and no push satisfies both. This finds the least push through a face that does
// not.
#include <vector>

#include "solvers/collision/geometry.h"

namespace monolith::solvers::collision {

// Among the faces of `box` (a box geometry, posed; 6 in 3-D, 4 in 2-D) whose outward normal n
// has n.u >= -1/2 for every u in `avoid` (unit directions the body must not be pushed against),
// the one through which `body` (posed, bounded) leaves with the least push along n: the push is
// how far the body must move along n to lie wholly on the outer side of the face's plane.
// Reports it as findContacts(box, body) would (normal out of the body towards the box: -n;
// depth: the push; the point midway between the body's deepest point past the face and the
// face's plane). False when no face qualifies or the body already lies outside one that does
// (depth <= 0). Throws std::invalid_argument if `box` is not a box.
template <int d>
bool escapeThroughBoxFace(const PreparedGeometry<d>& box, const Pose<d>& boxPose, const PreparedGeometry<d>& body,
                          const Pose<d>& bodyPose, const std::vector<Eigen::Matrix<double, d, 1>>& avoid,
                          ContactPoint<d>& out);

}  // namespace monolith::solvers::collision
