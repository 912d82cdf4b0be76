// A capsule against a polytope (box or convex hull) in closed form: the pair's
// penetration depth and its axis exactly, where the general route takes FCL's MPR contact and
// tilts its axis by a local search (contact_axis.cpp) that stops on a budget.
//
// A capsule is its core segment S grown by its radius r, so along any axis it overlaps a
// polytope P by the core's overlap plus r. Two cases:
// - S meets P. The least overlap of S and P over all axes is over the facets of their Minkowski
//   difference, whose normals are P's face normals and the cross products of S's direction with
//   P's edge directions (the separating-axis theorem for a segment and a polytope). The
//   capsule's depth is that least overlap plus r, on the same axis.
// - S misses P. The capsule's depth is r - dist(S, P), along the line between the nearest
//   points. Those have an end of S against P, or S against an edge of P: where S's nearest point
//   is inside S and P's inside a face, S runs parallel to that face, and the distance stays the
//   same along S until S ends or passes the face's edge.
#include <algorithm>
#include <cmath>

#include "solvers/collision/contact_axis_impl.h"

namespace monolith::solvers::collision {

namespace {

using Vec3 = Eigen::Vector3d;

// [lowest, highest] of n.v over the polytope (body frame, n unit).
Eigen::Vector2d polytopeRange(const PreparedGeometry<3>& g, const Vec3& n) {
  if (g.geometry().type == GeometryType::Box) {
    const double half = n.cwiseAbs().dot(g.geometry().halfExtents);
    return {-half, half};
  }
  double lowest = kInfinity, highest = -kInfinity;
  for (const Vec3& v : g.impl().vertices) {
    const double s = n.dot(v);
    lowest = std::min(lowest, s);
    highest = std::max(highest, s);
  }
  return {lowest, highest};
}

}  // namespace

bool capsulePolytopeAxis(const PreparedGeometry<3>& capsule, const Pose<3>& poseC, const PreparedGeometry<3>& polytope,
                         const Pose<3>& poseP, double margin, CapsulePolytopeAxis& out) {
  const PreparedGeometry<3>::Impl& impl = polytope.impl();
  const double r = capsule.geometry().radius;
  const double size = impl.localBounds.diagonal().norm();
  // The core segment [p, q] in the polytope's frame.
  const Vec3 centre = poseP.R.transpose() * (poseC.x - poseP.x);
  const Vec3 half = poseP.R.transpose() * (poseC.R.col(2) * capsule.geometry().halfHeight);
  const Vec3 p = centre - half, q = centre + half;

  // The separating-axis test of the core and the polytope; `leastAxis` points the way the core
  // leaves.
  double least = kInfinity;
  Vec3 leastAxis = Vec3::UnitY();
  auto consider = [&](const Vec3& n) {
    const Eigen::Vector2d range = polytopeRange(polytope, n);
    const double a = n.dot(p), b = n.dot(q);
    const double up = range[1] - std::min(a, b);    // the core leaving along +n
    const double down = std::max(a, b) - range[0];  // along -n
    const double overlap = std::min(up, down);
    if (overlap < least) {
      least = overlap;
      leastAxis = up <= down ? n : Vec3(-n);
    }
  };
  for (const Vec3& n : impl.faceNormals) consider(n);
  const double length = half.norm();
  for (const Vec3& e : impl.edgeDirections) {
    const Vec3 n = half.cross(e);
    const double len = n.norm();
    if (len > 1e-9 * length) consider(n / len);  // parallel to the edge: no facet
  }
  if (least > 0) {  // the core itself is inside: deeper than the radius
    out.axis = poseP.R * leastAxis;
    out.depth = least + r;
    out.near = poseC.x;
    return true;
  }

  // The core is apart from the polytope: its distance, from its ends and from the edges.
  // Distances beyond `limit` need not be exact (signedDistance's lower bound there still rejects).
  const double limit = r + std::max(0.0, margin);
  double best2 = kInfinity;
  Vec3 onCore = centre, onPolytope = centre;
  for (const Vec3& end : {p, q}) {
    const SurfaceDistance<3> s = signedDistance<3>(polytope, end, limit);
    if (s.distance * s.distance < best2) {
      best2 = s.distance * s.distance;
      onCore = end;
      onPolytope = s.surfacePoint;
    }
  }
  for (const std::array<int, 2>& edge : impl.edges) {
    Vec3 c1, c2;
    closestSegmentPoints(p, q, impl.vertices[edge[0]], impl.vertices[edge[1]], c1, c2);
    const double dist2 = (c1 - c2).squaredNorm();
    if (dist2 < best2) {
      best2 = dist2;
      onCore = c1;
      onPolytope = c2;
    }
  }
  const double distance = std::sqrt(best2);
  if (r - distance < -margin) return false;
  const Vec3 gap = onCore - onPolytope;
  // Touching to rounding: the gap has no direction; the separating axis has.
  out.axis = poseP.R * (distance > 1e-12 * size ? Vec3(gap / distance) : leastAxis);
  out.depth = r - distance;
  out.near = poseP.R * (0.5 * (onCore + onPolytope)) + poseP.x;
  return true;
}

bool capsulePolytopeContact(const PreparedGeometry<3>& a, const Pose<3>& poseA, const PreparedGeometry<3>& b,
                            const Pose<3>& poseB, double margin, ContactPoint<3>& out) {
  const bool capsuleIsA = a.geometry().type == GeometryType::Capsule;
  CapsulePolytopeAxis found;
  if (!(capsuleIsA ? capsulePolytopeAxis(a, poseA, b, poseB, margin, found)
                   : capsulePolytopeAxis(b, poseB, a, poseA, margin, found)))
    return false;
  // contactOnAxis measures the same overlap on the axis (either sign) and places the point
  // between the touching features.
  return contactOnAxis(a, poseA, -1, b, poseB, -1, found.near, capsuleIsA ? found.axis : Vec3(-found.axis), margin,
                       out);
}

}  // namespace monolith::solvers::collision
