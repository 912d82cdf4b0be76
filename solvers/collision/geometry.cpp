// PreparedGeometry: validates a Geometry once and keeps what the narrow phase needs,
// the polytope form (box corners, convex hull vertices and face planes) and FCL's copy of the
// shape, so that no query rebuilds anything.
#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/geometry/shape/convex.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/math/bv/OBBRSS.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "solvers/collision/collision_impl.h"

namespace monolith::solvers::collision {

namespace {

// Up to this many vertices, bounds come from the transformed vertices themselves; larger
// convexes and meshes use their rotated local box (looser, but O(1)).
constexpr int kExactBoundsVertexLimit = 64;
// Face planes of a hull closer than this (relative to its size) are one plane.
constexpr double kCoplanarTolerance = 1e-9;

[[noreturn]] void reject(const std::string& why) { throw std::invalid_argument("collision geometry: " + why); }

void requirePositive(double value, const char* what) {
  if (!(std::isfinite(value) && value > 0)) reject(std::string(what) + " must be positive and finite");
}

template <int d>
void requireFinite(const std::vector<Eigen::Matrix<double, d, 1>>& points, const char* what) {
  for (const auto& p : points)
    if (!p.allFinite()) reject(std::string(what) + " contain NaN or infinite coordinates");
}

template <int d>
void addPlane(typename PreparedGeometry<d>::Impl& impl, const Eigen::Matrix<double, d, 1>& n, double offset,
              double size) {
  for (std::size_t i = 0; i < impl.faceNormals.size(); ++i)
    if (impl.faceNormals[i].dot(n) > 1 - kCoplanarTolerance &&
        std::abs(impl.faceOffsets[i] - offset) <= kCoplanarTolerance * size)
      return;
  impl.faceNormals.push_back(n);
  impl.faceOffsets.push_back(offset);
}

template <int d>
void setBox(typename PreparedGeometry<d>::Impl& impl, const Eigen::Matrix<double, d, 1>& h) {
  using VecD = Eigen::Matrix<double, d, 1>;
  if constexpr (d == 2) {
    // Counter-clockwise, so that the polygon routines treat boxes like any convex polygon.
    impl.vertices = {VecD(-h.x(), -h.y()), VecD(h.x(), -h.y()), VecD(h.x(), h.y()), VecD(-h.x(), h.y())};
    impl.faceNormals = {VecD(0, -1), VecD(1, 0), VecD(0, 1), VecD(-1, 0)};
    impl.faceOffsets = {h.y(), h.x(), h.y(), h.x()};
  } else {
    for (int corner = 0; corner < 8; ++corner)
      impl.vertices.push_back(
          VecD(corner & 1 ? h.x() : -h.x(), corner & 2 ? h.y() : -h.y(), corner & 4 ? h.z() : -h.z()));
    for (int axis = 0; axis < 3; ++axis)
      for (double sign : {-1.0, 1.0}) {
        impl.faceNormals.push_back(sign * VecD::Unit(axis));
        impl.faceOffsets.push_back(h[axis]);
      }
    for (int axis = 0; axis < 3; ++axis) impl.edgeDirections.push_back(VecD::Unit(axis));
    for (int corner = 0; corner < 8; ++corner)  // corners differing in one coordinate's sign
      for (int bit : {1, 2, 4})
        if (!(corner & bit)) impl.edges.push_back({corner, corner | bit});
  }
  impl.localBounds = Eigen::AlignedBox<double, d>(-h, h);
}

// Minimum width of a polytope over its face normals (exact in 2-D; an upper bound of the true
// minimum width in 3-D, attained for boxes and prisms).
template <int d>
double polytopeMinimumWidth(const typename PreparedGeometry<d>::Impl& impl) {
  double width = kInfinity;
  for (std::size_t i = 0; i < impl.faceNormals.size(); ++i) {
    double lowest = kInfinity;
    for (const auto& v : impl.vertices) lowest = std::min(lowest, impl.faceNormals[i].dot(v));
    width = std::min(width, impl.faceOffsets[i] - lowest);
  }
  return width;
}

template <int d>
double maxNorm(const std::vector<Eigen::Matrix<double, d, 1>>& points) {
  double r = 0;
  for (const auto& p : points) r = std::max(r, p.norm());
  return r;
}

void setPolygon(PreparedGeometry<2>::Impl& impl, const std::vector<Eigen::Vector2d>& points) {
  impl.vertices = convexHull2(points);
  const int n = static_cast<int>(impl.vertices.size());
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d edge = impl.vertices[(i + 1) % n] - impl.vertices[i];
    const Eigen::Vector2d normal = Eigen::Vector2d(edge.y(), -edge.x()).normalized();  // outward for CCW
    impl.faceNormals.push_back(normal);
    impl.faceOffsets.push_back(normal.dot(impl.vertices[i]));
  }
  for (const auto& v : impl.vertices) impl.localBounds.extend(v);
}

void setPolyhedron(PreparedGeometry<3>::Impl& impl, const std::vector<Eigen::Vector3d>& points) {
  Hull3 hull = convexHull3(points);
  impl.vertices = std::move(hull.vertices);
  impl.hullTriangles = std::move(hull.triangles);
  for (const auto& v : impl.vertices) impl.localBounds.extend(v);
  const double size = impl.localBounds.diagonal().norm();
  // Planes from the largest triangles first: a big triangle's normal is the accurate one when a
  // coplanar sliver would give a slightly tilted duplicate.
  std::vector<std::pair<double, int>> bySize;
  for (std::size_t t = 0; t < impl.hullTriangles.size(); ++t) {
    const auto& tri = impl.hullTriangles[t];
    const double area = (impl.vertices[tri[1]] - impl.vertices[tri[0]])
                            .cross(impl.vertices[tri[2]] - impl.vertices[tri[0]])
                            .norm();
    bySize.push_back({-area, static_cast<int>(t)});
  }
  std::sort(bySize.begin(), bySize.end());
  for (const auto& [negArea, t] : bySize) {
    const auto& tri = impl.hullTriangles[t];
    const Eigen::Vector3d n =
        (impl.vertices[tri[1]] - impl.vertices[tri[0]]).cross(impl.vertices[tri[2]] - impl.vertices[tri[0]]).normalized();
    // Every hull vertex is behind its face plane: the largest n.v is the exact offset, robust
    // to the rounding of a thin triangle's normal.
    double offset = -kInfinity;
    for (const auto& v : impl.vertices) offset = std::max(offset, n.dot(v));
    addPlane<3>(impl, n, offset, size);
  }
  // The triangles' edges, one per direction (a hull's faces share edges, and its flat faces'
  // diagonals are kept: an extra candidate axis only costs a projection).
  for (const auto& tri : impl.hullTriangles)
    for (int e = 0; e < 3; ++e) {
      const std::array<int, 2> ends = {std::min(tri[e], tri[(e + 1) % 3]), std::max(tri[e], tri[(e + 1) % 3])};
      if (std::find(impl.edges.begin(), impl.edges.end(), ends) == impl.edges.end()) impl.edges.push_back(ends);
      const Eigen::Vector3d edge = impl.vertices[tri[(e + 1) % 3]] - impl.vertices[tri[e]];
      const double length = edge.norm();
      if (!(length > 1e-12 * size)) continue;
      const Eigen::Vector3d u = edge / length;
      bool known = false;
      for (const auto& k : impl.edgeDirections) known = known || std::abs(k.dot(u)) > 1 - 1e-12;
      if (!known) impl.edgeDirections.push_back(u);
    }
}

std::shared_ptr<fcl::CollisionGeometry<double>> makeFclGeometry(const Geometry<3>& g,
                                                                 const PreparedGeometry<3>::Impl& impl) {
  std::shared_ptr<fcl::CollisionGeometry<double>> shape;
  switch (g.type) {
    case GeometryType::Box: shape = std::make_shared<fcl::Boxd>(2 * g.halfExtents); break;
    case GeometryType::Sphere: shape = std::make_shared<fcl::Sphered>(g.radius); break;
    case GeometryType::Capsule: shape = std::make_shared<fcl::Capsuled>(g.radius, 2 * g.halfHeight); break;
    case GeometryType::Cylinder: shape = std::make_shared<fcl::Cylinderd>(g.radius, 2 * g.halfHeight); break;
    case GeometryType::HalfSpace: return nullptr;  // every half-space pair is exact (narrow_phase_3d.cpp)
    case GeometryType::Convex: {
      auto vertices = std::make_shared<std::vector<Eigen::Vector3d>>(impl.vertices);
      auto faces = std::make_shared<std::vector<int>>();
      for (const auto& t : impl.hullTriangles) faces->insert(faces->end(), {3, t[0], t[1], t[2]});
      shape = std::make_shared<fcl::Convexd>(vertices, static_cast<int>(impl.hullTriangles.size()), faces);
      break;
    }
    case GeometryType::Mesh: {
      auto mesh = std::make_shared<fcl::BVHModel<fcl::OBBRSSd>>();
      std::vector<fcl::Triangle> triangles;
      for (const auto& t : g.triangles) triangles.emplace_back(t[0], t[1], t[2]);
      mesh->beginModel(static_cast<int>(triangles.size()), static_cast<int>(g.vertices.size()));
      mesh->addSubModel(g.vertices, triangles);
      mesh->endModel();
      shape = mesh;
      break;
    }
  }
  shape->computeLocalAABB();
  return shape;
}

}  // namespace

template <int d>
PreparedGeometry<d>::PreparedGeometry(const Geometry<d>& g) : geometry_(g), impl_(std::make_unique<Impl>()) {
  using VecD = Eigen::Matrix<double, d, 1>;
  Impl& impl = *impl_;
  switch (g.type) {
    case GeometryType::Box:
      for (int i = 0; i < d; ++i) requirePositive(g.halfExtents[i], "box half extents");
      setBox<d>(impl, g.halfExtents);
      boundingRadius_ = g.halfExtents.norm();
      minimumSize_ = 2 * g.halfExtents.minCoeff();
      break;
    case GeometryType::Sphere:
      requirePositive(g.radius, d == 2 ? "disk radius" : "sphere radius");
      impl.localBounds = Eigen::AlignedBox<double, d>(VecD::Constant(-g.radius), VecD::Constant(g.radius));
      boundingRadius_ = g.radius;
      minimumSize_ = 2 * g.radius;
      break;
    case GeometryType::Capsule:
    case GeometryType::Cylinder: {
      const bool capsule = g.type == GeometryType::Capsule;
      if constexpr (d == 2) {
        reject(std::string(capsule ? "capsules" : "cylinders") + " exist only in 3-D (use a box or a convex polygon)");
      } else {
        requirePositive(g.radius, capsule ? "capsule radius" : "cylinder radius");
        requirePositive(g.halfHeight, capsule ? "capsule half height" : "cylinder half height");
        const VecD h(g.radius, g.radius, g.halfHeight + (capsule ? g.radius : 0.0));
        impl.localBounds = Eigen::AlignedBox<double, d>(-h, h);
        boundingRadius_ = capsule ? g.halfHeight + g.radius : std::hypot(g.radius, g.halfHeight);
        minimumSize_ = capsule ? 2 * g.radius : 2 * std::min(g.radius, g.halfHeight);
      }
      break;
    }
    case GeometryType::HalfSpace: {
      const double length = g.normal.norm();
      if (!g.normal.allFinite() || !std::isfinite(g.offset)) reject("half-space normal and offset must be finite");
      if (!(length > 0)) reject("half-space normal must not be zero");
      // Scaling n.x <= offset by 1/|n| keeps the same set of points.
      geometry_.normal = g.normal / length;
      geometry_.offset = g.offset / length;
      impl.localBounds = Eigen::AlignedBox<double, d>(VecD::Constant(-kHugeExtent), VecD::Constant(kHugeExtent));
      boundingRadius_ = kInfinity;
      minimumSize_ = kInfinity;
      break;
    }
    case GeometryType::Convex:
      requireFinite<d>(g.vertices, "convex vertices");
      if constexpr (d == 2) setPolygon(impl, g.vertices);
      else setPolyhedron(impl, g.vertices);
      boundingRadius_ = maxNorm<d>(impl.vertices);
      minimumSize_ = polytopeMinimumWidth<d>(impl);
      break;
    case GeometryType::Mesh: {
      if constexpr (d == 2) {
        reject("triangle meshes exist only in 3-D (use a convex polygon)");
      } else {
        requireFinite<d>(g.vertices, "mesh vertices");
        if (g.triangles.empty()) reject("mesh has no triangles");
        const int n = static_cast<int>(g.vertices.size());
        for (std::size_t t = 0; t < g.triangles.size(); ++t) {
          const auto& tri = g.triangles[t];
          for (int v : tri)
            if (v < 0 || v >= n)
              reject("mesh triangle " + std::to_string(t) + " has vertex index " + std::to_string(v) +
                     " out of range [0, " + std::to_string(n) + ")");
          if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2])
            reject("mesh triangle " + std::to_string(t) + " repeats a vertex");
        }
        impl.vertices = g.vertices;
        for (const auto& v : g.vertices) impl.localBounds.extend(v);
        buildTriangleTree(impl, g);
        boundingRadius_ = maxNorm<d>(g.vertices);
        // A surface mesh has no thickness: its size is its smallest nonzero bounding-box extent
        // (a flat ground mesh is as big as it is wide, not of size 0).
        const VecD extent = impl.localBounds.sizes();
        minimumSize_ = kInfinity;
        for (int i = 0; i < d; ++i)
          if (extent[i] > 0) minimumSize_ = std::min(minimumSize_, extent[i]);
        if (!(minimumSize_ < kInfinity)) reject("mesh vertices all coincide");
      }
      break;
    }
    default: reject("unknown geometry type " + std::to_string(static_cast<int>(g.type)));
  }
  if constexpr (d == 3) impl.fclGeometry = makeFclGeometry(geometry_, impl);
}

template <int d>
PreparedGeometry<d>::~PreparedGeometry() = default;

template <int d>
Eigen::AlignedBox<double, d> worldBounds(const PreparedGeometry<d>& g, const Pose<d>& pose) {
  using VecD = Eigen::Matrix<double, d, 1>;
  const Geometry<d>& geo = g.geometry();
  const auto& impl = g.impl();
  VecD half;
  switch (geo.type) {
    case GeometryType::HalfSpace:
      return Eigen::AlignedBox<double, d>(VecD::Constant(-kHugeExtent), VecD::Constant(kHugeExtent));
    case GeometryType::Sphere: half = VecD::Constant(geo.radius); break;
    case GeometryType::Capsule: half = pose.R.col(d - 1).cwiseAbs() * geo.halfHeight + VecD::Constant(geo.radius); break;
    case GeometryType::Cylinder: {
      // A disk of radius r with unit normal a spans r*sqrt(1 - a_i^2) along axis i.
      const VecD a = pose.R.col(d - 1);
      for (int i = 0; i < d; ++i) half[i] = geo.halfHeight * std::abs(a[i]) + geo.radius * std::sqrt(std::max(0.0, 1 - a[i] * a[i]));
      break;
    }
    case GeometryType::Convex:
    case GeometryType::Mesh:
      if (static_cast<int>(impl.vertices.size()) <= kExactBoundsVertexLimit) {
        Eigen::AlignedBox<double, d> box;
        for (const auto& v : impl.vertices) box.extend(pose.R * v + pose.x);
        return box;
      }
      [[fallthrough]];
    default: {  // box, or the local box of a large vertex set, rotated
      const VecD c = impl.localBounds.center(), h = 0.5 * impl.localBounds.sizes();
      const VecD centre = pose.R * c + pose.x;
      const VecD extent = pose.R.cwiseAbs() * h;
      return Eigen::AlignedBox<double, d>(centre - extent, centre + extent);
    }
  }
  return Eigen::AlignedBox<double, d>(pose.x - half, pose.x + half);
}

template class PreparedGeometry<2>;
template class PreparedGeometry<3>;
template Eigen::AlignedBox<double, 2> worldBounds<2>(const PreparedGeometry<2>&, const Pose<2>&);
template Eigen::AlignedBox<double, 3> worldBounds<3>(const PreparedGeometry<3>&, const Pose<3>&);

}  // namespace monolith::solvers::collision
