// FCL glue for the 3-D narrow phase (issue 3).
//
// FCL 0.7's conventions differ between its algorithms (checked against this build, see
// tests/unit/test_narrow_phase.cpp): Contact::normal points from o1 to o2 for the shape pairs,
// box-box (ODE's dBoxBox) puts each point midway between the surfaces with its own depth, but
// libccd's MPR (every other convex pair) returns a point somewhere inside the overlap and an
// approximate depth, and the mesh routines report the normal and the sign of the depth
// inconsistently with the argument order (sphere-triangle: depth < 0). Distance queries return
// the nearest points in world coordinates for shape pairs but in each object's own frame for
// sphere-mesh. So apart from box-box we keep only FCL's axis (and its sign for shape pairs) and
// recompute depth and point exactly along it from the shapes' projections.
#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/geometry/shape/convex.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/math/bv/OBBRSS.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/detail/gjk_solver_libccd.h>
#include <fcl/narrowphase/distance.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <exception>

#include "solvers/collision/narrow_phase_fcl.h"

namespace monolith::solvers::collision {

namespace {

using Vec3 = Eigen::Vector3d;

// FCL's box-box keeps at most this many points of the clipped face polygon (it culls the rest).
constexpr int kShapeContacts = 4;
// A mesh reports one contact per touching triangle; more than this are dropped by FCL.
constexpr int kMeshContacts = 256;

fcl::Transform3d transformOf(const Pose<3>& pose) {
  fcl::Transform3d t = fcl::Transform3d::Identity();
  t.linear() = pose.R;
  t.translation() = pose.x;
  return t;
}

// [min, max] of n.x over the posed shape (over one triangle of a mesh when `triangle` >= 0).
Eigen::Vector2d projection(const PreparedGeometry<3>& g, const Pose<3>& pose, const Vec3& n, int triangle) {
  const Geometry<3>& geo = g.geometry();
  const double c = n.dot(pose.x);
  const Vec3 nb = pose.R.transpose() * n;  // n in the body frame
  double half = 0;
  switch (geo.type) {
    case GeometryType::Box: half = nb.cwiseAbs().dot(geo.halfExtents); break;
    case GeometryType::Sphere: half = geo.radius; break;
    case GeometryType::Capsule: half = geo.halfHeight * std::abs(nb.z()) + geo.radius; break;
    case GeometryType::Cylinder:
      half = geo.halfHeight * std::abs(nb.z()) + geo.radius * std::sqrt(std::max(0.0, 1 - nb.z() * nb.z()));
      break;
    case GeometryType::HalfSpace: return {-kInfinity, kInfinity};
    case GeometryType::Convex:
    case GeometryType::Mesh: {
      double lo = kInfinity, hi = -kInfinity;
      auto visit = [&](const Vec3& v) {
        const double t = nb.dot(v);
        lo = std::min(lo, t);
        hi = std::max(hi, t);
      };
      if (geo.type == GeometryType::Mesh && triangle >= 0 && triangle < static_cast<int>(geo.triangles.size())) {
        for (int v : geo.triangles[triangle]) visit(geo.vertices[v]);
      } else {
        for (const auto& v : g.impl().vertices) visit(v);
      }
      return {c + lo, c + hi};
    }
  }
  return {c - half, c + half};
}

// A contact on `axis` (either sign) near `near`: the normal takes the sign along which the
// projections of A and B overlap least, the depth is that overlap (exact along the axis: the
// distance A must move along it to separate), and the point sits on the middle of the overlap.
// False when the overlap is below -margin.
bool contactOnAxis(const PreparedGeometry<3>& a, const Pose<3>& poseA, int triangleA, const PreparedGeometry<3>& b,
                   const Pose<3>& poseB, int triangleB, const Vec3& near, const Vec3& axis, double margin,
                   ContactPoint<3>& out) {
  const double len = axis.norm();
  if (!(len > 0) || !std::isfinite(len)) return false;
  const Vec3 n = axis / len;
  const Eigen::Vector2d pa = projection(a, poseA, n, triangleA);
  const Eigen::Vector2d pb = projection(b, poseB, n, triangleB);
  const double depthPlus = pb[1] - pa[0];   // normal +n: A lies on the + side of B
  const double depthMinus = pa[1] - pb[0];  // normal -n
  const bool plus = depthPlus <= depthMinus;
  out.normal = plus ? n : Vec3(-n);
  out.depth = plus ? depthPlus : depthMinus;
  const double middle = plus ? 0.5 * (pa[0] + pb[1]) : -0.5 * (pa[1] + pb[0]);  // along out.normal
  out.point = near + (middle - out.normal.dot(near)) * out.normal;
  return out.depth >= -margin;
}

}  // namespace

bool fclContacts(const PreparedGeometry<3>& a, const Pose<3>& poseA, const PreparedGeometry<3>& b,
                 const Pose<3>& poseB, std::vector<ContactPoint<3>>& out, std::vector<int>& trianglesOfB) {
  const bool meshB = b.geometry().type == GeometryType::Mesh;
  const bool meshA = a.geometry().type == GeometryType::Mesh;
  const bool boxBox = a.geometry().type == GeometryType::Box && b.geometry().type == GeometryType::Box;
  fcl::CollisionRequestd request(meshB ? kMeshContacts : kShapeContacts, true);
  fcl::CollisionResultd result;
  try {
    // A mesh goes first: FCL reports b1 = the triangle of o1 (it reorders BVH-shape pairs itself
    // without fixing the normal, so we normalise below either way).
    if (meshB) fcl::collide(b.impl().fclGeometry.get(), transformOf(poseB), a.impl().fclGeometry.get(), transformOf(poseA), request, result);
    else fcl::collide(a.impl().fclGeometry.get(), transformOf(poseA), b.impl().fclGeometry.get(), transformOf(poseB), request, result);
  } catch (const std::exception&) {
    return false;
  }
  for (std::size_t i = 0; i < result.numContacts(); ++i) {
    const fcl::Contactd& c = result.getContact(i);
    ContactPoint<3> p;
    if (boxBox) {  // already midway, per-point depth; FCL's normal points from A (o1) to B
      p.point = c.pos;
      p.normal = -c.normal.normalized();
      p.depth = c.penetration_depth;
      out.push_back(p);
      trianglesOfB.push_back(-1);
      continue;
    }
    const int triangleB = meshB ? static_cast<int>(c.b1) : -1;
    const int triangleA = meshB && meshA ? static_cast<int>(c.b2) : -1;
    if (contactOnAxis(a, poseA, triangleA, b, poseB, triangleB, c.pos, c.normal, 0.0, p)) {
      out.push_back(p);
      trianglesOfB.push_back(triangleB);
    }
  }
  return true;
}

bool fclMarginContact(const PreparedGeometry<3>& a, const Pose<3>& poseA, const PreparedGeometry<3>& b,
                      const Pose<3>& poseB, double margin, ContactPoint<3>& out, int& triangleOfB) {
  const bool meshB = b.geometry().type == GeometryType::Mesh;
  const bool meshA = a.geometry().type == GeometryType::Mesh;
  const fcl::Transform3d tA = transformOf(poseA), tB = transformOf(poseB);
  const fcl::Transform3d& t1 = meshB ? tB : tA;
  const fcl::Transform3d& t2 = meshB ? tA : tB;
  fcl::DistanceRequestd request(true);
  fcl::DistanceResultd result;
  try {
    if (meshB) fcl::distance(b.impl().fclGeometry.get(), tB, a.impl().fclGeometry.get(), tA, request, result);
    else fcl::distance(a.impl().fclGeometry.get(), tA, b.impl().fclGeometry.get(), tB, request, result);
  } catch (const std::exception&) {
    return false;
  }
  const double distance = result.min_distance;
  if (!(distance > 0) || distance > margin) return false;  // colliding (collide missed it) or too far
  // World or object frames, whichever pair of points is `distance` apart.
  Vec3 p = result.nearest_points[0], q = result.nearest_points[1];
  const Vec3 pw = t1 * p, qw = t2 * q;
  if (std::abs((pw - qw).norm() - distance) < std::abs((p - q).norm() - distance)) {
    p = pw;
    q = qw;
  }
  triangleOfB = meshB ? result.b1 : -1;
  const int triangleA = meshB && meshA ? result.b2 : -1;
  return contactOnAxis(a, poseA, triangleA, b, poseB, triangleOfB, 0.5 * (p + q), p - q, margin, out);
}

namespace {

// FCL's solver is templated on the shape type: dispatch on ours.
template <typename Visit>
bool withFclShape(const PreparedGeometry<3>& g, Visit&& visit) {
  const fcl::CollisionGeometryd& shape = *g.impl().fclGeometry;
  switch (g.geometry().type) {
    case GeometryType::Box: return visit(static_cast<const fcl::Boxd&>(shape));
    case GeometryType::Capsule: return visit(static_cast<const fcl::Capsuled&>(shape));
    case GeometryType::Cylinder: return visit(static_cast<const fcl::Cylinderd&>(shape));
    case GeometryType::Convex: return visit(static_cast<const fcl::Convexd&>(shape));
    case GeometryType::Sphere: return visit(static_cast<const fcl::Sphered&>(shape));
    default: return false;  // half-spaces and meshes have no shape-triangle test
  }
}

}  // namespace

void refineAxis(const PreparedGeometry<3>& a, const Pose<3>& poseA, const PreparedGeometry<3>& b, const Pose<3>& poseB,
                int triangleB, const std::vector<Vec3>& axes, ContactPoint<3>& c) {
  for (const Vec3& axis : axes) {
    ContactPoint<3> candidate;
    if (contactOnAxis(a, poseA, -1, b, poseB, triangleB, c.point, axis, kInfinity, candidate) &&
        candidate.depth < c.depth)
      c = candidate;
  }
}

bool separatedFromTriangle(const PreparedGeometry<3>& a, const Pose<3>& poseAInMesh, const PreparedGeometry<3>& mesh,
                           int triangle, double margin) {
  const Geometry<3>& geo = mesh.geometry();
  const auto& tri = geo.triangles[triangle];
  const std::array<Vec3, 3> p = {geo.vertices[tri[0]], geo.vertices[tri[1]], geo.vertices[tri[2]]};
  const Vec3 face = (p[1] - p[0]).cross(p[2] - p[0]);
  std::array<Vec3, 4> axes = {face, face.cross(p[1] - p[0]), face.cross(p[2] - p[1]), face.cross(p[0] - p[2])};
  for (Vec3& axis : axes) {
    const double len = axis.norm();
    if (!(len > 0)) continue;
    axis /= len;
    const Eigen::Vector2d shape = projection(a, poseAInMesh, axis, -1);
    const double t0 = axis.dot(p[0]), t1 = axis.dot(p[1]), t2 = axis.dot(p[2]);
    const double lo = std::min({t0, t1, t2}), hi = std::max({t0, t1, t2});
    if (shape[0] > hi + margin || lo > shape[1] + margin) return true;
  }
  return false;
}

namespace {

// The axis of a shape-triangle contact: the triangle's own normal, or FCL's axis if the shape
// overlaps the triangle less along it and that axis pushes the shape out across a border edge of
// the mesh (a shape beside the mesh's edge). Across an edge shared with a neighbour it would be an
// artefact of the triangulation, not of the surface. `separated`: FCL found the shape apart from
// the triangle (the margin case); an overlap along the normal then means the shape is beside the
// triangle, below its plane, over a neighbour that has the contact.
bool onTriangleAxis(const PreparedGeometry<3>& a, const Pose<3>& poseAInMesh, const PreparedGeometry<3>& mesh,
                    int triangle, const Vec3& near, const Vec3& fclAxis, double margin, bool separated,
                    ContactPoint<3>& out) {
  const Geometry<3>& geo = mesh.geometry();
  const auto& tri = geo.triangles[triangle];
  const std::array<Vec3, 3> p = {geo.vertices[tri[0]], geo.vertices[tri[1]], geo.vertices[tri[2]]};
  const Vec3 face = (p[1] - p[0]).cross(p[2] - p[0]).normalized();
  const Pose<3> meshFrame;
  if (!contactOnAxis(a, poseAInMesh, -1, mesh, meshFrame, triangle, near, face, kInfinity, out)) return false;
  ContactPoint<3> alternative = out;
  refineAxis(a, poseAInMesh, mesh, meshFrame, triangle, {fclAxis}, alternative);
  // The edge the alternative normal leaves through: the one whose outward in-plane normal it
  // follows most.
  const Vec3 inPlane = alternative.normal - alternative.normal.dot(face) * face;
  int edge = 0;
  double best = -kInfinity;
  for (int e = 0; e < 3; ++e) {
    const Vec3 outward = (p[(e + 1) % 3] - p[e]).cross(face).normalized();  // counter-clockwise about face
    if (outward.dot(inPlane) > best) {
      best = outward.dot(inPlane);
      edge = e;
    }
  }
  if (alternative.depth < out.depth && mesh.impl().borderEdges[triangle][edge]) out = alternative;
  else if (separated && out.depth > 0) return false;
  return out.depth >= -margin;
}

}  // namespace

bool fclTriangleContact(const PreparedGeometry<3>& a, const Pose<3>& poseAInMesh, const PreparedGeometry<3>& mesh,
                        int triangle, double margin, ContactPoint<3>& out) {
  const Geometry<3>& geo = mesh.geometry();
  const auto& tri = geo.triangles[triangle];
  const Vec3 &p0 = geo.vertices[tri[0]], &p1 = geo.vertices[tri[1]], &p2 = geo.vertices[tri[2]];
  const fcl::Transform3d tf = transformOf(poseAInMesh);  // everything is in the mesh's frame
  fcl::detail::GJKSolver_libccd<double> solver;
  try {
    Vec3 position, normal;
    double depth = 0;
    if (withFclShape(a, [&](const auto& shape) {
          return solver.shapeTriangleIntersect(shape, tf, p0, p1, p2, &position, &depth, &normal);
        }))
      return onTriangleAxis(a, poseAInMesh, mesh, triangle, position, normal, 0.0, false, out);
    if (!(margin > 0)) return false;
    double distance = kInfinity;
    Vec3 onA, onTriangle;
    if (!withFclShape(a, [&](const auto& shape) {
          return solver.shapeTriangleDistance(shape, tf, p0, p1, p2, &distance, &onA, &onTriangle);
        }))
      return false;
    if (!(distance > 0) || distance > margin) return false;
    return onTriangleAxis(a, poseAInMesh, mesh, triangle, 0.5 * (onA + onTriangle), onA - onTriangle, margin, true,
                          out);
  } catch (const std::exception&) {
    return false;
  }
}

bool fclOverlap(const PreparedGeometry<3>& a, const Pose<3>& poseA, const PreparedGeometry<3>& b,
                const Pose<3>& poseB) {
  fcl::CollisionRequestd request(1, false);
  fcl::CollisionResultd result;
  try {
    fcl::collide(a.impl().fclGeometry.get(), transformOf(poseA), b.impl().fclGeometry.get(), transformOf(poseB), request,
                 result);
  } catch (const std::exception&) {
    return false;
  }
  return result.isCollision();
}

}  // namespace monolith::solvers::collision
