#pragma once
// Private to solvers/collision: contacts on an axis between two convex shapes, without
// FCL. Used to turn FCL's approximate contacts into exact ones along a chosen axis.
#include <vector>

#include "solvers/collision/collision_impl.h"

namespace monolith::solvers::collision {

// [min, max] of n.x over the posed shape (over triangle `triangle` of a mesh when >= 0; a
// half-space projects onto the whole line).
Eigen::Vector2d projection(const PreparedGeometry<3>& g, const Pose<3>& pose, const Eigen::Vector3d& n, int triangle);

// A point of the posed shape extreme along `dir` (world frame, any length): its support point.
Eigen::Vector3d supportPoint(const PreparedGeometry<3>& g, const Pose<3>& pose, const Eigen::Vector3d& dir);

// The axis (unit, A leaves along it) on which libccd's GJK + EPA finds the pair's penetration,
// from our exact support points (penetration_axis.cpp): a start for the local search in the basin
// of the global minimum. False when GJK finds the shapes apart or EPA fails. `scale`: the pair's
// length scale, for EPA's tolerance.
bool epaAxis(const PreparedGeometry<3>& a, const Pose<3>& poseA, const PreparedGeometry<3>& b, const Pose<3>& poseB,
             double scale, Eigen::Vector3d& axis);

// Closest points c1 on segment p1-q1 and c2 on p2-q2 (either may be a point; Ericson, Real-Time
// Collision Detection, 5.1.9).
void closestSegmentPoints(const Eigen::Vector3d& p1, const Eigen::Vector3d& q1, const Eigen::Vector3d& p2,
                          const Eigen::Vector3d& q2, Eigen::Vector3d& c1, Eigen::Vector3d& c2);

// The contact of A and B on `axis` (either sign): the normal takes the sign along which their
// projections overlap least, the depth is that overlap (exact along the axis: how far A must
// move along it to separate), and the point lies on the middle of the overlap, between the
// touching features (the shapes' extreme sets along the axis, taken nearest to `near`, FCL's
// point). triangleA/B: that triangle of a mesh stands for the shape (-1: the whole shape).
// False when the overlap is below -margin.
bool contactOnAxis(const PreparedGeometry<3>& a, const Pose<3>& poseA, int triangleA, const PreparedGeometry<3>& b,
                   const Pose<3>& poseB, int triangleB, const Eigen::Vector3d& near, const Eigen::Vector3d& axis,
                   double margin, ContactPoint<3>& out);

// Moves contact `c` onto whichever of `axes` (either sign) A and B overlap least along, if that
// is less than along its own normal: the separating-axis choice among candidate axes (FCL's MPR
// axis is only approximately the minimum-translation one). triangleB: B is that triangle of a mesh.
void refineAxis(const PreparedGeometry<3>& a, const Pose<3>& poseA, const PreparedGeometry<3>& b, const Pose<3>& poseB,
                int triangleB, const std::vector<Eigen::Vector3d>& axes, ContactPoint<3>& c);

// Tilts the axis of contact `c` locally to where A and B overlap least (their penetration depth
// is that minimum over all axes), from its own axis and from the local minima MPR tends to miss
// (box faces, cylinder caps and sides), and moves the contact onto the best. libccd's MPR axis,
// which FCL returns for every convex pair but box-box, can be degrees away, overstating the depth.
// Two polytopes (boxes and convex hulls) need no search: their penetration depth is the least
// overlap over their face normals and the cross products of their edge directions (the
// separating-axis theorem), and this is what it does for them.
void descendToMinimumOverlap(const PreparedGeometry<3>& a, const Pose<3>& poseA, const PreparedGeometry<3>& b,
                             const Pose<3>& poseB, ContactPoint<3>& c);

// The least overlap of two polytopes (Box or Convex) over the separating-axis test's candidate
// axes, and its axis (unit, either sign). Exact: no other direction overlaps less.
double leastOverlapOfPolytopes(const PreparedGeometry<3>& a, const Pose<3>& poseA, const PreparedGeometry<3>& b,
                               const Pose<3>& poseB, Eigen::Vector3d& axis);

// A capsule against a polytope (Box or Convex), exactly (capsule_polytope.cpp): the axis the
// capsule leaves along (unit, world frame), its overlap along it -- the pair's penetration depth,
// negative when apart -- and a point near the touching features.
struct CapsulePolytopeAxis {
  Eigen::Vector3d axis, near;
  double depth = 0;
};
// False when the two are farther apart than `margin`.
bool capsulePolytopeAxis(const PreparedGeometry<3>& capsule, const Pose<3>& poseC, const PreparedGeometry<3>& polytope,
                         const Pose<3>& poseP, double margin, CapsulePolytopeAxis& out);
// The pair's main contact on that axis (A or B the capsule, the other the polytope); false when
// farther apart than `margin`.
bool capsulePolytopeContact(const PreparedGeometry<3>& a, const Pose<3>& poseA, const PreparedGeometry<3>& b,
                            const Pose<3>& poseB, double margin, ContactPoint<3>& out);

// True when an axis among the triangle's normal and its in-plane edge normals separates shape A
// (posed in the mesh's frame) from triangle t by more than `margin`: a cheap exact rejection
// before FCL's test.
bool separatedFromTriangle(const PreparedGeometry<3>& a, const Pose<3>& poseAInMesh, const PreparedGeometry<3>& mesh,
                           int triangle, double margin);

// Shape A (posed in the mesh's frame) against triangle t along the triangle's own normal only
// (oriented towards A): depth = how far A reaches below the triangle's plane. False when A is
// more than `margin` above it.
bool triangleNormalContact(const PreparedGeometry<3>& a, const Pose<3>& poseAInMesh, const PreparedGeometry<3>& mesh,
                           int triangle, double margin, ContactPoint<3>& out);

}  // namespace monolith::solvers::collision
