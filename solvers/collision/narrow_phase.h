#pragma once
// Narrow phase: contact points between two posed geometries.
// 3-D pairs go through FCL (with libccd for general convex pairs); 2-D pairs use exact 2-D
// routines (see narrow_phase_2d.cpp). For face contacts the result is a manifold of several
// points (box resting on a box or plane: its corners / the clipped face polygon), so that a
// body lying flat is held at several points, as the thesis's vertex-in-level-set test does.
#include <vector>

#include "solvers/collision/geometry.h"

namespace monolith::solvers::collision {

struct ContactQuery {
  // Also report points separated by at most this distance (depth in [-margin, 0]).
  double margin = 0;
  // Upper bound on points returned per pair (the deepest are kept, then spread).
  int maxPoints = 8;
};

// Appends the contact points between A and B (normals out of B towards A) to `out`; returns how
// many were appended (0: separated by more than the margin). Deterministic: the same inputs give
// the same points in the same order. Two half-spaces never collide. Thread-safe.
template <int d>
int findContacts(const PreparedGeometry<d>& a, const Pose<d>& poseA, const PreparedGeometry<d>& b,
                 const Pose<d>& poseB, const ContactQuery& query, std::vector<ContactPoint<d>>& out);

// True when findContacts with this margin would report a point (any point, of any depth): the
// same answer, without the manifold (box pairs: without the feature points and the merging).
template <int d>
bool touches(const PreparedGeometry<d>& a, const Pose<d>& poseA, const PreparedGeometry<d>& b, const Pose<d>& poseB,
             double margin);

// True when A and B overlap (depth > 0 anywhere). Cheaper than findContacts.
template <int d>
bool overlaps(const PreparedGeometry<d>& a, const Pose<d>& poseA, const PreparedGeometry<d>& b, const Pose<d>& poseB);

}  // namespace monolith::solvers::collision
