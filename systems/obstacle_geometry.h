#pragma once
// The geometry of one fluid obstacle at its body's pose, as rasterization needs it (thesis Sec.
// 5.4.1): whether a point is inside, where a segment runs inside, and a bounding radius. An
// obstacle is a body's level_set when it has one, else its shape: box, disk/sphere, 2-D convex
// polygon, 3-D cylinder or capsule (axis = body z). Exact for the shapes; for a level set the
// segment's crossings of phi = 0 are found by marching with steps phi / L (L bounds |grad phi|,
// so no crossing is stepped over) but at least a quarter sample spacing, then bisection: a part
// of the body thinner than that along the segment can be missed.
#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "components/level_set.h"
#include "components/rigid_body.h"
#include "components/shape.h"

namespace monolith {

template <int d>
class ObstacleGeometry {
 public:
  using Vec = Eigen::Matrix<double, d, 1>;
  using Interval = std::pair<double, double>;

  // levelSet may be null (then shape is used and must be one of the supported types).
  ObstacleGeometry(const Shape<d>* shape, const LevelSet<d>* levelSet, const RigidBody<d>& body)
      : shape_(shape), levelSet_(levelSet), body_(&body) {}

  const RigidBody<d>& body() const { return *body_; }
  const Shape<d>* shape() const { return shape_; }
  const LevelSet<d>* levelSet() const { return levelSet_; }

  // World point x inside the body (boundary included).
  bool contains(const Vec& x) const;
  // Appends to `out` the parts [t0, t1] of the segment x + t e, t in [0, tMax] (|e| = 1), inside
  // the body, in increasing order (one part for a convex shape, any number for a level set).
  void segmentInside(const Vec& x, const Vec& e, double tMax, std::vector<Interval>& out) const;
  // Distance t in [0, tMax] at which x + t e enters the body: 0 if x is inside, +inf on a miss.
  double rayEntry(const Vec& x, const Vec& e, double tMax) const;
  // Signed distance from x to the body's surface, negative inside (a level set's interpolated phi).
  double signedDistance(const Vec& x) const;
  // Radius of the ball about the body's position that holds the body.
  double boundingRadius() const;
  // The numbers the rasterization depends on (besides the pose): equal keys, equal geometry.
  void appendKey(std::vector<double>& key) const;

  // Whether a fluid obstacle can have this shape type (the others need a level_set).
  static bool supports(ShapeType type);
  // "box, disk or polygon" / "box, sphere, cylinder or capsule", for error messages.
  static std::string supportedNames();

 private:
  Vec toBody(const Vec& x) const { return body_->rotation().transpose() * (x - body_->x); }
  void levelSetInside(const Vec& p, const Vec& q, double tMax, std::vector<Interval>& out) const;

  const Shape<d>* shape_;
  const LevelSet<d>* levelSet_;
  const RigidBody<d>* body_;
};

}  // namespace monolith
