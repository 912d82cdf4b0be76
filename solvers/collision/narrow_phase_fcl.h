#pragma once
// Private to solvers/collision: FCL's 3-D narrow phase behind our contact convention (issue 3).
#include <vector>

#include "solvers/collision/collision_impl.h"

namespace monolith::solvers::collision {

// Contacts FCL finds between A and B (fcl::collide), converted to our convention: unit normal out
// of B towards A, depth > 0, point midway between the surfaces. Box-box gives FCL's clipped face
// manifold (up to 4 points); a mesh B gives one point per touching triangle, whose index goes to
// `trianglesOfB` (-1 for other shapes); every other pair gives FCL's single point. Neither shape
// may be a half-space. Returns false when FCL threw (a degenerate configuration).
bool fclContacts(const PreparedGeometry<3>& a, const Pose<3>& poseA, const PreparedGeometry<3>& b,
                 const Pose<3>& poseB, std::vector<ContactPoint<3>>& out, std::vector<int>& trianglesOfB);

// When A and B are separated by at most `margin` (fcl::distance), their nearest points as one
// contact with depth = -distance; `triangleOfB` gets the nearest triangle of a mesh B (else -1).
bool fclMarginContact(const PreparedGeometry<3>& a, const Pose<3>& poseA, const PreparedGeometry<3>& b,
                      const Pose<3>& poseB, double margin, ContactPoint<3>& out, int& triangleOfB);

// Shape A (box, capsule, cylinder or convex), posed in the mesh's frame, against triangle t of
// the mesh (FCL's libccd shape-triangle test; within `margin`, its GJK distance). The contact is
// in the mesh's frame, its normal out of the triangle towards A.
bool fclTriangleContact(const PreparedGeometry<3>& a, const Pose<3>& poseAInMesh, const PreparedGeometry<3>& mesh,
                        int triangle, double margin, ContactPoint<3>& out);

// Moves contact `c` onto whichever of `axes` (either sign) A and B overlap least along, if that
// is less than along its own normal: the separating-axis choice among candidate axes (FCL's MPR
// axis is only approximately the minimum-translation one). triangleB: B is that triangle of a mesh.
void refineAxis(const PreparedGeometry<3>& a, const Pose<3>& poseA, const PreparedGeometry<3>& b, const Pose<3>& poseB,
                int triangleB, const std::vector<Eigen::Vector3d>& axes, ContactPoint<3>& c);

// True when an axis among the triangle's normal and its in-plane edge normals separates shape A
// (posed in the mesh's frame) from triangle t by more than `margin`: a cheap exact rejection
// before FCL's test.
bool separatedFromTriangle(const PreparedGeometry<3>& a, const Pose<3>& poseAInMesh, const PreparedGeometry<3>& mesh,
                           int triangle, double margin);

// fcl::collide without contact generation. Neither shape may be a half-space.
bool fclOverlap(const PreparedGeometry<3>& a, const Pose<3>& poseA, const PreparedGeometry<3>& b,
                const Pose<3>& poseB);

}  // namespace monolith::solvers::collision
