#pragma once
// Collision geometry, entity-free. A Geometry<d> is a shape in its body frame; a
// Pose<d> places it in the world. The narrow phase (narrow_phase.h) turns two posed geometries
// into contact points; the broad phase (broad_phase.h) turns world bounding boxes into candidate
// pairs.
//
// 3-D shapes: box, sphere, capsule and cylinder (axis = body z), half-space (the static
// ground/walls: points with n.x <= offset in the body frame are inside), convex hull (vertices),
// triangle mesh (vertices + triangles; meant for static bodies, dynamic meshes are allowed but
// only collide through their triangles, no inside test).
// 2-D shapes: box, disk (type Sphere), convex polygon (type Convex, vertices counter-clockwise
// or not: the hull is taken), half-plane (type HalfSpace).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <memory>
#include <vector>

namespace monolith::solvers::collision {

enum class GeometryType : int { Box = 0, Sphere = 1, Capsule = 2, Cylinder = 3, HalfSpace = 4, Convex = 5, Mesh = 6 };

template <int d>
struct Geometry {
  using VecD = Eigen::Matrix<double, d, 1>;
  GeometryType type = GeometryType::Box;
  VecD halfExtents = VecD::Constant(0.5);  // Box
  double radius = 0.5;                     // Sphere/disk, Capsule, Cylinder
  double halfHeight = 0.5;                 // Capsule (segment half length), Cylinder; along body z
  VecD normal = VecD::UnitY();             // HalfSpace: unit outward normal (body frame)
  double offset = 0;                       // HalfSpace: inside is normal.x <= offset
  std::vector<VecD> vertices;              // Convex, Mesh (body frame)
  std::vector<std::array<int, 3>> triangles;  // Mesh (3-D only)
};

template <int d>
struct Pose {
  using VecD = Eigen::Matrix<double, d, 1>;
  using MatD = Eigen::Matrix<double, d, d>;
  VecD x = VecD::Zero();           // world position of the body frame origin (centre of mass)
  MatD R = MatD::Identity();       // body-to-world rotation
};

// One contact point between A and B. The normal is a unit vector pointing out of B towards A
// (the thesis's convention: B is the "level-set body", A receives +j). depth > 0 means the two
// surfaces overlap by that distance along the normal; depth in [-margin, 0] means they are
// separated by -depth (reported only when a margin was asked for). The point lies midway between
// the two surfaces, so pointOnB = point - 0.5*depth*normal... (see pointOnA/pointOnB).
template <int d>
struct ContactPoint {
  using VecD = Eigen::Matrix<double, d, 1>;
  VecD point = VecD::Zero();
  VecD normal = VecD::UnitY();
  double depth = 0;
  VecD pointOnA() const { return point - 0.5 * depth * normal; }  // deepest point of A inside B
  VecD pointOnB() const { return point + 0.5 * depth * normal; }  // deepest point of B inside A
};

// A geometry prepared for queries: validated, with whatever acceleration data the narrow phase
// needs (FCL collision geometry in 3-D, the hull in 2-D). Immutable after construction, safe to
// share across threads. Construction throws std::invalid_argument with a plain-language reason
// for degenerate input (non-positive sizes, fewer than d+1 affinely independent hull vertices,
// triangle indices out of range, non-unit or zero half-space normal, NaN/inf anywhere).
template <int d>
class PreparedGeometry {
 public:
  explicit PreparedGeometry(const Geometry<d>& g);
  ~PreparedGeometry();
  PreparedGeometry(const PreparedGeometry&) = delete;
  PreparedGeometry& operator=(const PreparedGeometry&) = delete;

  const Geometry<d>& geometry() const { return geometry_; }
  bool unbounded() const { return geometry_.type == GeometryType::HalfSpace; }
  // Radius of the smallest origin-centred ball containing the shape (infinite for a half-space):
  // used for bounding boxes and as the body's length scale.
  double boundingRadius() const { return boundingRadius_; }
  // Smallest extent of the shape (2*radius, 2*min half extent, ...): "the smaller body's size"
  // for penetration tolerances.
  double minimumSize() const { return minimumSize_; }
  struct Impl;
  const Impl& impl() const { return *impl_; }

 private:
  Geometry<d> geometry_;
  double boundingRadius_ = 0;
  double minimumSize_ = 0;
  std::unique_ptr<Impl> impl_;
};

// World bounding box of a posed geometry (a half-space gets a huge box).
template <int d>
Eigen::AlignedBox<double, d> worldBounds(const PreparedGeometry<d>& g, const Pose<d>& pose);

}  // namespace monolith::solvers::collision
