// A shape against a triangle mesh. A mesh has no inside (it is a surface, meant for
// static ground and walls), so contacts come from the triangles near the shape (triangle_tree.cpp):
// a sphere gets the exact closest point of each triangle; other shapes get their feature points
// above each triangle (inside its prism, along its normal), so that a box resting on a mesh keeps
// its four corners as on a half-space, and FCL's libccd shape-triangle contact where those do not
// settle it (no feature point over the triangle, or the mesh's border). Everything is computed in
// the mesh's frame and turned to the world at the end.
#include <cmath>

#include "solvers/collision/collision_impl.h"
#include "solvers/collision/contact_axis_impl.h"
#include "solvers/collision/narrow_phase_fcl_impl.h"

namespace monolith::solvers::collision {

namespace {

using Vec3 = Eigen::Vector3d;
using CP = ContactPoint<3>;

// See narrow_phase_3d.cpp: FCL's depth along a face normal agrees with a vertex's to ~1e-7 of the
// size, so within 1e-6 the feature point represents it.
constexpr double kRepresentedDepth = 1e-6;  // times the pair's length scale
// A triangle's own normal must be within 60 degrees of the contact normal for the shape to rest
// on the triangle's face (rather than touch its edge), where feature points make sense.
constexpr double kTriangleFaceCosine = 0.5;
// A sphere contact whose normal is the triangle's own normal to ~1e-6 rad lies inside the face.
constexpr double kFaceRegionCosine = 1 - 1e-12;

struct Scratch {
  std::vector<int> candidates;
  std::vector<char> onFace;
  std::vector<CP> main, extra, result;
  std::vector<FeaturePoint<3>> features;
};
Scratch& scratch() {
  thread_local Scratch s;
  return s;
}

std::array<Vec3, 3> corners(const Geometry<3>& mesh, int t) {
  const auto& tri = mesh.triangles[t];
  return {mesh.vertices[tri[0]], mesh.vertices[tri[1]], mesh.vertices[tri[2]]};
}

// Exact: the centre against the triangle's closest point; a centre on the triangle takes the
// triangle's own normal. `onFace`: the closest point is inside the face, not on its border.
bool sphereTriangle(const Vec3& centre, double radius, const Geometry<3>& mesh, int t, double margin, CP& out,
                    bool& onFace) {
  const auto p = corners(mesh, t);
  const Vec3 closest = closestPointOnTriangle(centre, p[0], p[1], p[2]);
  const Vec3 diff = centre - closest;
  const double dist = diff.norm();
  const double depth = radius - dist;
  if (!(depth >= -margin)) return false;
  const Vec3 faceNormal = (p[1] - p[0]).cross(p[2] - p[0]).normalized();
  const Vec3 n = dist > 0 ? Vec3(diff / dist) : faceNormal;
  onFace = std::abs(n.dot(faceNormal)) > kFaceRegionCosine;
  out = midwayContact<3>(centre - radius * n, closest, n, depth);
  return true;
}

// A sphere over a flat (or convex) patch of triangles touches the one under its centre on the face
// and the neighbours on their shared edges, shallower and tilted: the edge contacts are artefacts
// of the triangulation ("internal edges") when a face contact is at least as deep. Contacts on a
// genuine ridge or border (no deeper face contact) stay.
void dropInternalEdgeContacts(std::vector<CP>& contacts, const std::vector<char>& onFace) {
  double deepestFace = -kInfinity;
  for (std::size_t i = 0; i < contacts.size(); ++i)
    if (onFace[i]) deepestFace = std::max(deepestFace, contacts[i].depth);
  std::size_t kept = 0;
  for (std::size_t i = 0; i < contacts.size(); ++i)
    if (onFace[i] || contacts[i].depth > deepestFace) contacts[kept++] = contacts[i];
  contacts.resize(kept);
}

// Feature points above triangle t: inside its prism, at most `margin` above its plane and no
// deeper below it than the shape's contact with it (deeper points went through to the other side,
// where the triangle does not hold them).
void featuresOnTriangle(const std::vector<FeaturePoint<3>>& features, const Geometry<3>& mesh, int t,
                        const CP& contact, double margin, double tolerance, std::vector<CP>& out) {
  const auto p = corners(mesh, t);
  Vec3 faceNormal = (p[1] - p[0]).cross(p[2] - p[0]);
  const double twiceArea = faceNormal.norm();
  if (!(twiceArea > 0)) return;
  faceNormal /= twiceArea;
  const double facing = faceNormal.dot(contact.normal);
  if (std::abs(facing) < kTriangleFaceCosine) return;
  const Vec3 n = facing > 0 ? faceNormal : Vec3(-faceNormal);
  for (const auto& f : features) {
    const double height = n.dot(f.x - p[0]);
    const double separation = height - f.radius;
    if (separation > margin || separation < -(contact.depth + tolerance)) continue;
    const Vec3 onPlane = f.x - height * n;
    bool inside = true;
    for (int e = 0; e < 3 && inside; ++e)
      inside = (p[(e + 1) % 3] - p[e]).cross(onPlane - p[e]).dot(faceNormal) >= -1e-9 * twiceArea;
    if (inside) out.push_back(midwayContact<3>(f.x - f.radius * n, onPlane, n, -separation));
  }
}

// The triangle's vertices inside the shape (or within the margin), with the shape's face normal
// reversed: the other half of the vertex test, for a mesh bump poking into a shape's face. Normals
// that do not face the shape from the triangle's side (a vertex deep enough to pick a far face)
// are left out.
void triangleVerticesInShape(const PreparedGeometry<3>& a, const Pose<3>& poseAInMesh, const Geometry<3>& mesh, int t,
                             const Vec3& towardsA, double margin, std::vector<CP>& out) {
  const auto& bounds = a.impl().localBounds;
  for (int v : mesh.triangles[t]) {
    const Vec3& x = mesh.vertices[v];
    const Vec3 q = poseAInMesh.R.transpose() * (x - poseAInMesh.x);
    if (bounds.exteriorDistance(q) > margin) continue;
    const SurfaceDistance<3> sd = signedDistance<3>(a, q, margin);
    if (!(-sd.distance >= -margin)) continue;
    const Vec3 n = -(poseAInMesh.R * sd.normal);
    if (n.dot(towardsA) <= 0) continue;
    out.push_back(midwayContact<3>(poseAInMesh.R * sd.surfacePoint + poseAInMesh.x, x, n, -sd.distance));
  }
}

}  // namespace

void meshContacts(const PreparedGeometry<3>& a, const Pose<3>& poseA, const PreparedGeometry<3>& mesh,
                  const Pose<3>& poseMesh, double margin, double scale, std::vector<CP>& out) {
  Pose<3> rel;  // A in the mesh's frame
  rel.R = poseMesh.R.transpose() * poseA.R;
  rel.x = poseMesh.R.transpose() * (poseA.x - poseMesh.x);
  Eigen::AlignedBox3d near = worldBounds<3>(a, rel);
  near.min().array() -= margin;
  near.max().array() += margin;
  Scratch& s = scratch();
  s.candidates.clear();
  trianglesNear(mesh.impl(), near, s.candidates);
  s.main.clear();
  s.extra.clear();
  const Geometry<3>& geo = mesh.geometry();
  const bool sphere = a.geometry().type == GeometryType::Sphere;
  const double tolerance = kRepresentedDepth * scale;
  s.onFace.clear();
  const auto& neighbours = mesh.impl().edgeNeighbours;
  for (int t : s.candidates) {
    CP c;
    if (sphere) {
      bool onFace = false;
      if (sphereTriangle(rel.x, a.geometry().radius, geo, t, margin, c, onFace)) {
        s.main.push_back(c);
        s.onFace.push_back(onFace);
      }
      continue;
    }
    if (separatedFromTriangle(a, rel, mesh, t, margin)) continue;
    // The vertex test both ways: the shape's feature points over the triangle, the triangle's
    // vertices in the shape. Inside the mesh, when these find the contact, FCL's test would only
    // add a point they represent; otherwise (edges crossing, or the mesh's border) FCL decides,
    // and its point stays if nothing represents it.
    if (!triangleNormalContact(a, rel, mesh, t, margin, c)) continue;
    const std::size_t before = s.extra.size();
    s.features.clear();
    featurePoints<3>(a, rel, Vec3(-c.normal), s.features);
    featuresOnTriangle(s.features, geo, t, c, margin, tolerance, s.extra);
    triangleVerticesInShape(a, rel, geo, t, c.normal, margin, s.extra);
    const bool interior = neighbours[t][0] >= 0 && neighbours[t][1] >= 0 && neighbours[t][2] >= 0;
    if (s.extra.size() > before && interior) continue;
    if (fclTriangleContact(a, rel, mesh, t, margin, c)) s.main.push_back(c);
  }
  if (sphere) dropInternalEdgeContacts(s.main, s.onFace);
  s.result.clear();
  keepUnrepresented<3>(s.main, s.extra, tolerance, s.result);
  for (const CP& c : s.result) {
    CP w = c;
    w.point = poseMesh.R * c.point + poseMesh.x;
    w.normal = poseMesh.R * c.normal;
    out.push_back(w);
  }
}

}  // namespace monolith::solvers::collision
