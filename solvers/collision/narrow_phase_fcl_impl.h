#pragma once
// Private to solvers/collision: FCL's 3-D narrow phase behind our contact convention.
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
// in the mesh's frame, its normal out of the triangle towards A: the triangle's own normal, or
// FCL's axis where A lies beside the mesh's border or on a convex ridge. False also when A lies
// beyond an edge the triangle shares with a flat or concave neighbour (the neighbour's contact).
bool fclTriangleContact(const PreparedGeometry<3>& a, const Pose<3>& poseAInMesh, const PreparedGeometry<3>& mesh,
                        int triangle, double margin, ContactPoint<3>& out);

// fcl::collide without contact generation. Neither shape may be a half-space.
bool fclOverlap(const PreparedGeometry<3>& a, const Pose<3>& poseA, const PreparedGeometry<3>& b,
                const Pose<3>& poseB);

}  // namespace monolith::solvers::collision
