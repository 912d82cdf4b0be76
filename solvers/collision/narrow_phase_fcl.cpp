// FCL glue for the 3-D narrow phase.
//
// FCL 0.7's conventions differ between its algorithms (checked against this build, see
// tests/unit/test_narrow_phase.cpp): Contact::normal points from o1 to o2 for the shape pairs and
// box-box (ODE's dBoxBox) puts each point midway between the surfaces with its own depth, but
// libccd's MPR (every other convex pair) returns a point somewhere inside the overlap, an
// approximate depth and an axis that can be degrees from the minimum-translation one, and the
// mesh routines report the normal and the sign of the depth inconsistently with the argument
// order (sphere-triangle: depth < 0). Distance queries return the nearest points in world
// coordinates for shape pairs but in each object's own frame for sphere-mesh. So apart from
// box-box only FCL's axis and point are kept, and the contact is rebuilt on that axis exactly
// (contact_axis_impl.h); the callers refine the axis further.
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

#include <array>
#include <cmath>
#include <exception>

#include "solvers/collision/contact_axis_impl.h"
#include "solvers/collision/narrow_phase_fcl_impl.h"

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

namespace {

// Whether contact axis `c` may leave triangle t across the edge it points to (in the triangle's
// plane), rather than along the face normal n1 (oriented towards the shape). Yes across the mesh's
// border, and across a convex ridge when c lies between the two faces' normals (the edge's
// Voronoi region). Across a flat or concave shared edge no: the edge belongs to the
// triangulation, not to the surface ("internal edge").
bool mayLeaveAcrossEdge(const PreparedGeometry<3>& mesh, int t, const Vec3& n1, const Vec3& c) {
  const Geometry<3>& geo = mesh.geometry();
  const auto& tri = geo.triangles[t];
  const std::array<Vec3, 3> p = {geo.vertices[tri[0]], geo.vertices[tri[1]], geo.vertices[tri[2]]};
  const Vec3 face = (p[1] - p[0]).cross(p[2] - p[0]).normalized();
  const Vec3 inPlane = c - c.dot(face) * face;
  int e = 0;
  double best = -kInfinity;
  for (int k = 0; k < 3; ++k) {
    const double along = (p[(k + 1) % 3] - p[k]).cross(face).normalized().dot(inPlane);  // outward edge normal
    if (along > best) {
      best = along;
      e = k;
    }
  }
  const int other = mesh.impl().edgeNeighbours[t][e];
  if (other < 0) return true;
  const auto& tri2 = geo.triangles[other];
  const int a = tri[e], b = tri[(e + 1) % 3];
  int far = tri2[0];
  for (int v : tri2)
    if (v != a && v != b) far = v;
  const Vec3 edge = (p[(e + 1) % 3] - p[e]).normalized();
  // Convex seen from the shape: the neighbour falls away below this face's plane.
  if (!(n1.dot(geo.vertices[far] - p[e]) < -1e-9 * (p[(e + 1) % 3] - p[e]).norm())) return false;
  // The neighbour's normal on the shape's side: opposite to the direction from the edge to the
  // far vertex's side, i.e. the face normal of the neighbour that points away from this face.
  Vec3 n2 = (geo.vertices[tri2[1]] - geo.vertices[tri2[0]]).cross(geo.vertices[tri2[2]] - geo.vertices[tri2[0]]);
  n2.normalize();
  const Vec3 intoThis = (p[(e + 2) % 3] - p[e]) - (p[(e + 2) % 3] - p[e]).dot(edge) * edge;  // from the edge into t
  if (n2.dot(intoThis) < 0) n2 = -n2;  // the ridge: both normals lean away from each other
  const Vec3 cc = c - c.dot(edge) * edge;
  const double s12 = n1.cross(n2).dot(edge), s1 = n1.cross(cc).dot(edge), s2 = cc.cross(n2).dot(edge);
  return s1 * s12 >= 0 && s2 * s12 >= 0;
}

// The axis of a shape-triangle contact: the triangle's own normal, or FCL's axis if the shape
// overlaps the triangle less along it and it may leave the triangle across that edge (above). If
// it may not, the shape lies beyond an internal edge, over the neighbour, whose contact it is:
// none here. `separated`: FCL found the shape apart from the triangle (the margin case); an
// overlap along the normal then means the shape is beside the triangle as well.
bool onTriangleAxis(const PreparedGeometry<3>& a, const Pose<3>& poseAInMesh, const PreparedGeometry<3>& mesh,
                    int triangle, const Vec3& near, const Vec3& fclAxis, double margin, bool separated,
                    ContactPoint<3>& out) {
  const Geometry<3>& geo = mesh.geometry();
  const auto& tri = geo.triangles[triangle];
  const Vec3 face = (geo.vertices[tri[1]] - geo.vertices[tri[0]]).cross(geo.vertices[tri[2]] - geo.vertices[tri[0]]);
  const Pose<3> meshFrame;
  if (!contactOnAxis(a, poseAInMesh, -1, mesh, meshFrame, triangle, near, face, kInfinity, out)) return false;
  ContactPoint<3> alternative = out;
  refineAxis(a, poseAInMesh, mesh, meshFrame, triangle, {fclAxis}, alternative);
  if (alternative.depth < out.depth) {
    if (!mayLeaveAcrossEdge(mesh, triangle, out.normal, alternative.normal)) return false;
    out = alternative;
  } else if (separated && out.depth > 0) {
    return false;
  }
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
