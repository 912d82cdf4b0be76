// Narrow phase entry points: 2-D goes to the exact routines of narrow_phase_2d.cpp,
// 3-D to narrow_phase_3d.cpp (FCL plus exact pairs).
#include "solvers/collision/narrow_phase.h"

#include "solvers/collision/collision_impl.h"

namespace monolith::solvers::collision {

template <int d>
int findContacts(const PreparedGeometry<d>& a, const Pose<d>& poseA, const PreparedGeometry<d>& b,
                 const Pose<d>& poseB, const ContactQuery& query, std::vector<ContactPoint<d>>& out) {
  if constexpr (d == 2) return findContacts2(a, poseA, b, poseB, query, out);
  else return findContacts3(a, poseA, b, poseB, query, out);
}

template <int d>
bool touches(const PreparedGeometry<d>& a, const Pose<d>& poseA, const PreparedGeometry<d>& b, const Pose<d>& poseB,
             double margin) {
  if constexpr (d == 3) {
    return touches3(a, poseA, b, poseB, margin);
  } else {
    thread_local std::vector<ContactPoint<2>> found;
    found.clear();
    ContactQuery query;
    query.margin = margin;
    query.maxPoints = 1;
    return findContacts2(a, poseA, b, poseB, query, found) > 0;
  }
}

template <int d>
bool overlaps(const PreparedGeometry<d>& a, const Pose<d>& poseA, const PreparedGeometry<d>& b, const Pose<d>& poseB) {
  if constexpr (d == 3) {
    return overlaps3(a, poseA, b, poseB);
  } else {
    // The 2-D routines are exact and cheap: the deepest point decides.
    thread_local std::vector<ContactPoint<2>> deepest;
    deepest.clear();
    ContactQuery query;
    query.maxPoints = 1;
    findContacts2(a, poseA, b, poseB, query, deepest);
    return !deepest.empty() && deepest[0].depth > 0;
  }
}

template int findContacts<2>(const PreparedGeometry<2>&, const Pose<2>&, const PreparedGeometry<2>&, const Pose<2>&,
                             const ContactQuery&, std::vector<ContactPoint<2>>&);
template int findContacts<3>(const PreparedGeometry<3>&, const Pose<3>&, const PreparedGeometry<3>&, const Pose<3>&,
                             const ContactQuery&, std::vector<ContactPoint<3>>&);
template bool touches<2>(const PreparedGeometry<2>&, const Pose<2>&, const PreparedGeometry<2>&, const Pose<2>&, double);
template bool touches<3>(const PreparedGeometry<3>&, const Pose<3>&, const PreparedGeometry<3>&, const Pose<3>&, double);
template bool overlaps<2>(const PreparedGeometry<2>&, const Pose<2>&, const PreparedGeometry<2>&, const Pose<2>&);
template bool overlaps<3>(const PreparedGeometry<3>&, const Pose<3>&, const PreparedGeometry<3>&, const Pose<3>&);

}  // namespace monolith::solvers::collision
