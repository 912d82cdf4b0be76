#pragma once
// Private to solvers/collision: what PreparedGeometry keeps besides the user's Geometry,
// and the small geometric queries both narrow phases share. Not part of the public API.
#include <algorithm>
#include <array>
#include <limits>
#include <memory>
#include <vector>

#include "solvers/collision/geometry.h"
#include "solvers/collision/narrow_phase.h"

namespace fcl {
template <typename S>
class CollisionGeometry;
}

namespace monolith::solvers::collision {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
// Half extent of a half-space's "bounding box": large enough to contain any scene, small enough
// that sums and differences of such bounds stay finite.
constexpr double kHugeExtent = 1e30;

template <int d>
struct PreparedGeometry<d>::Impl {
  using VecD = Eigen::Matrix<double, d, 1>;
  // Polytope (Box, Convex) in the body frame: its vertices (2-D: counter-clockwise, edge i runs
  // from vertex i to vertex i+1) and its distinct face planes, inside where n.x <= offset.
  // Mesh: `vertices` holds the mesh vertices (used against half-spaces and for bounds).
  std::vector<VecD> vertices;
  std::vector<VecD> faceNormals;
  std::vector<double> faceOffsets;
  // 3-D convex hull boundary triangles (indices into `vertices`, counter-clockwise seen from
  // outside): exact distances from points outside the hull.
  std::vector<std::array<int, 3>> hullTriangles;
  // 3-D polytope (Box, Convex): its edges' directions (unit, one per direction up to sign; a
  // hull's face diagonals too, which only add candidate axes). With the face normals they give
  // every candidate axis of the exact separating-axis test of two polytopes (contact_axis.cpp).
  std::vector<VecD> edgeDirections;
  // 3-D polytope: its edges as vertex index pairs (a hull's face diagonals too, which lie on its
  // surface): the features a segment's nearest point can meet (capsule_polytope.cpp).
  std::vector<std::array<int, 2>> edges;
  Eigen::AlignedBox<double, d> localBounds;
  // Mesh: a bounding-box tree over the triangles (body frame). FCL's own BVH traversal against a
  // shape costs ~10 us for a few hundred triangles (OBB tests all the way down); the narrow phase
  // finds its candidate triangles here and runs FCL per triangle (narrow_phase_mesh.cpp).
  struct TreeNode {
    Eigen::AlignedBox<double, d> box;
    int first = 0, count = 0;  // leaf: triangleOrder[first, first + count)
    int left = -1, right = -1;  // inner node: children
  };
  std::vector<TreeNode> triangleTree;
  std::vector<int> triangleOrder;
  // Mesh: for each triangle and edge e (vertex e to vertex e+1), the other triangle sharing that
  // edge, or -1 on the mesh's border (also for an edge of more than two triangles). Whether a
  // shape may be pushed across an edge, rather than along the faces' normals, depends on it
  // (narrow_phase_fcl.cpp, "internal edges").
  std::vector<std::array<int, 3>> edgeNeighbours;
  // FCL's copy of the shape (3-D, every type but the half-space, whose pairs are all exact).
  std::shared_ptr<fcl::CollisionGeometry<double>> fclGeometry;
};

// --- convex hulls (convex_hull.cpp) -------------------------------------------------------
// Counter-clockwise hull without collinear points; throws std::invalid_argument when the points
// span no area.
std::vector<Eigen::Vector2d> convexHull2(const std::vector<Eigen::Vector2d>& points);

struct Hull3 {
  std::vector<Eigen::Vector3d> vertices;         // hull vertices, in input order
  std::vector<std::array<int, 3>> triangles;     // counter-clockwise seen from outside
};
// Throws std::invalid_argument when the points span no volume.
Hull3 convexHull3(const std::vector<Eigen::Vector3d>& points);

// --- mesh triangle tree (triangle_tree.cpp) ------------------------------------------------
// Fills triangleTree, triangleOrder and edgeNeighbours.
void buildTriangleTree(PreparedGeometry<3>::Impl& impl, const Geometry<3>& mesh);
// Triangles whose bounding box meets `box` (body frame), in a fixed order.
void trianglesNear(const PreparedGeometry<3>::Impl& impl, const Eigen::AlignedBox3d& box, std::vector<int>& out);

// --- point queries (shape_queries.cpp) ----------------------------------------------------
// Closest point of triangle abc to q.
Eigen::Vector3d closestPointOnTriangle(const Eigen::Vector3d& q, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                       const Eigen::Vector3d& c);

template <int d>
struct SurfaceDistance {
  Eigen::Matrix<double, d, 1> normal = Eigen::Matrix<double, d, 1>::Zero();        // outward unit normal there
  Eigen::Matrix<double, d, 1> surfacePoint = Eigen::Matrix<double, d, 1>::Zero();  // nearest surface point
  double distance = kInfinity;               // signed: negative inside
};

// Signed distance from the body-frame point q to the shape's surface (all in the body frame).
// Exact for every type but Mesh, which has no inside and reports +infinity. When the point is
// farther than `limit` outside a polytope, the result may be a lower bound only (callers drop it).
template <int d>
SurfaceDistance<d> signedDistance(const PreparedGeometry<d>& g, const Eigen::Matrix<double, d, 1>& q, double limit);

// A point of a shape that may touch the other shape: a polytope vertex, a capsule end (with the
// capsule's radius), a cylinder rim point. This is the thesis's vertex-in-level-set test
// generalised: the point is "inside" the other shape when its signed distance < radius.
template <int d>
struct FeaturePoint {
  Eigen::Matrix<double, d, 1> x;  // in the frame `pose` maps into (featurePoints)
  double radius = 0;
  // A capsule end: its axis pointing out of that end (unit); zero for other points. Only the
  // outer half of the end's sphere is the capsule's surface.
  Eigen::Matrix<double, d, 1> axis = Eigen::Matrix<double, d, 1>::Zero();
};

// Feature points of a posed shape. `deepest` (same frame, any length) is the direction in which
// the other shape lies: cylinders pick their rim points extreme along it. Half-spaces have none;
// a mesh gives its vertices.
template <int d>
void featurePoints(const PreparedGeometry<d>& g, const Pose<d>& pose, const Eigen::Matrix<double, d, 1>& deepest,
                   std::vector<FeaturePoint<d>>& out);

// The thesis's vertex-in-level-set test: every feature point of F inside S, or within `margin`
// of it, becomes a contact with S's surface normal. shapeIsA: S is body A and F is body B, so the
// normal (out of B) is negated. `deepest` (world) is the direction in which S lies seen from F.
// The points are generated directly in S's frame; `scratch` holds them.
template <int d>
void featureContacts(const PreparedGeometry<d>& f, const Pose<d>& poseF, const Eigen::Matrix<double, d, 1>& deepest,
                     const PreparedGeometry<d>& s, const Pose<d>& poseS, double margin, bool shapeIsA,
                     std::vector<FeaturePoint<d>>& scratch, std::vector<ContactPoint<d>>& out);

// Merges points closer than `mergeDistance` with nearly equal normals (keeps the deeper) and caps
// the manifold at maxPoints: the deepest point first, then the points farthest from those already
// kept. The survivors keep their relative order, so the result is deterministic.
template <int d>
void finishManifold(std::vector<ContactPoint<d>>& points, int maxPoints, double mergeDistance);

// The contact between surface points onA and onB: midway, with the given normal and depth.
template <int d>
ContactPoint<d> midwayContact(const Eigen::Matrix<double, d, 1>& onA, const Eigen::Matrix<double, d, 1>& onB,
                              const Eigen::Matrix<double, d, 1>& normal, double depth) {
  ContactPoint<d> c;
  c.point = 0.5 * (onA + onB);
  c.normal = normal;
  c.depth = depth;
  return c;
}

// Whether some `extra` point represents `main`: as deep (within `tolerance`) along nearly the
// same normal (2.5 degrees: FCL's MPR axis matches a face normal to ~1e-7 rad in a face contact).
template <int d>
bool isRepresented(const ContactPoint<d>& main, const std::vector<ContactPoint<d>>& extra, double tolerance) {
  for (const auto& e : extra)
    if (e.depth >= main.depth - tolerance && e.normal.dot(main.normal) >= 0.999) return true;
  return false;
}

// Appends the `main` points (FCL's or the closest features') that no `extra` point already
// represents, then the extra points.
template <int d>
void keepUnrepresented(const std::vector<ContactPoint<d>>& main, const std::vector<ContactPoint<d>>& extra,
                       double tolerance, std::vector<ContactPoint<d>>& out);

// The same contact seen with A and B exchanged.
template <int d>
ContactPoint<d> flipped(const ContactPoint<d>& c) {
  ContactPoint<d> r = c;
  r.normal = -c.normal;
  return r;
}

// Length scale of a pair for tolerances: the smaller finite bounding radius.
template <int d>
double pairLengthScale(const PreparedGeometry<d>& a, const PreparedGeometry<d>& b) {
  const double ra = a.boundingRadius(), rb = b.boundingRadius();
  const double r = std::min(ra, rb);
  return r < kInfinity ? r : 1.0;
}

// --- the two narrow phases ----------------------------------------------------------------
int findContacts2(const PreparedGeometry<2>& a, const Pose<2>& poseA, const PreparedGeometry<2>& b,
                  const Pose<2>& poseB, const ContactQuery& query, std::vector<ContactPoint<2>>& out);
int findContacts3(const PreparedGeometry<3>& a, const Pose<3>& poseA, const PreparedGeometry<3>& b,
                  const Pose<3>& poseB, const ContactQuery& query, std::vector<ContactPoint<3>>& out);
bool overlaps3(const PreparedGeometry<3>& a, const Pose<3>& poseA, const PreparedGeometry<3>& b, const Pose<3>& poseB);
bool touches3(const PreparedGeometry<3>& a, const Pose<3>& poseA, const PreparedGeometry<3>& b, const Pose<3>& poseB,
              double margin);
// A shape (not a half-space or a mesh) against a mesh, appended to `out` unfinished (no merging).
void meshContacts(const PreparedGeometry<3>& a, const Pose<3>& poseA, const PreparedGeometry<3>& mesh,
                  const Pose<3>& poseMesh, double margin, double scale, std::vector<ContactPoint<3>>& out);

}  // namespace monolith::solvers::collision
