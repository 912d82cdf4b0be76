// A global starting axis for the penetration depth of two convex shapes: libccd's
// GJK + EPA on our exact support points.
//
// Why: the penetration depth is the least overlap of the two shapes' projections over all axes,
// and that overlap has several local minima on the sphere of axes wherever the Minkowski
// difference has a ridge near the origin (a box edge against a cylinder's side, a cap's rim
// against a face). The local search of descendToMinimumOverlap, started from MPR's axis and the
// shapes' face/cap/side axes, then stops in the wrong one: with cylinders, 1-9 % of shallow
// contacts (1 cm deep) reported 1.2-2.9 cm, with hulls about 0.5 % up to 1.4 cm
// (docs/benchmarks.md, narrow phase). EPA expands a
// polytope inside the Minkowski difference towards the origin, so the face it ends on lies in
// the basin of the global minimum; the local search then polishes that axis on the exact
// overlap. EPA itself stops at an absolute tolerance and under-estimates the depth (its
// polytope is inscribed), so only its axis is used.
#include <ccd/ccd.h>

#include <algorithm>
#include <cmath>

#include "solvers/collision/contact_axis_impl.h"

namespace monolith::solvers::collision {

namespace {

using Vec3 = Eigen::Vector3d;

// EPA stops when a new support point lies within this fraction of the pair's length scale of
// the polytope face it was found for. Tighter costs EPA iterations on curved shapes without
// changing the basin the local search starts in.
constexpr double kEpaTolerance = 1e-6;
// GJK's iteration cap (libccd's default is unbounded; GJK needs a handful here).
constexpr unsigned long kGjkIterations = 100;

struct PosedShape {
  const PreparedGeometry<3>* geometry;
  const Pose<3>* pose;
};

void supportCallback(const void* object, const ccd_vec3_t* dir, ccd_vec3_t* out) {
  const auto& s = *static_cast<const PosedShape*>(object);
  const Vec3 p = supportPoint(*s.geometry, *s.pose, Vec3(dir->v[0], dir->v[1], dir->v[2]));
  for (int k = 0; k < 3; ++k) out->v[k] = p[k];
}

void centreCallback(const void* object, ccd_vec3_t* centre) {
  const auto& s = *static_cast<const PosedShape*>(object);
  for (int k = 0; k < 3; ++k) centre->v[k] = s.pose->x[k];
}

}  // namespace

Vec3 supportPoint(const PreparedGeometry<3>& g, const Pose<3>& pose, const Vec3& dir) {
  const Geometry<3>& geo = g.geometry();
  const Vec3 d = pose.R.transpose() * dir;  // body frame
  auto sign = [](double v) { return v >= 0 ? 1.0 : -1.0; };
  Vec3 p = Vec3::Zero();
  switch (geo.type) {
    case GeometryType::Box:
      for (int k = 0; k < 3; ++k) p[k] = sign(d[k]) * geo.halfExtents[k];
      break;
    case GeometryType::Sphere:
    case GeometryType::Capsule: {
      const double len = d.norm();
      if (len > 0) p = geo.radius / len * d;
      if (geo.type == GeometryType::Capsule) p.z() += sign(d.z()) * geo.halfHeight;
      break;
    }
    case GeometryType::Cylinder: {
      const double radial = std::hypot(d.x(), d.y());
      if (radial > 0) p.head<2>() = geo.radius / radial * d.head<2>();
      p.z() = sign(d.z()) * geo.halfHeight;
      break;
    }
    case GeometryType::Convex:
    case GeometryType::Mesh: {
      double top = -kInfinity;
      for (const Vec3& v : g.impl().vertices) {
        const double t = d.dot(v);
        if (t > top) top = t, p = v;
      }
      break;
    }
    case GeometryType::HalfSpace: return pose.x;  // unbounded: never asked (no EPA with a half-space)
  }
  return pose.R * p + pose.x;
}

bool epaAxis(const PreparedGeometry<3>& a, const Pose<3>& poseA, const PreparedGeometry<3>& b, const Pose<3>& poseB,
             double scale, Vec3& axis) {
  const PosedShape sa{&a, &poseA}, sb{&b, &poseB};
  ccd_t ccd;
  CCD_INIT(&ccd);
  ccd.support1 = supportCallback;
  ccd.support2 = supportCallback;
  ccd.center1 = centreCallback;
  ccd.center2 = centreCallback;
  ccd.max_iterations = kGjkIterations;
  ccd.epa_tolerance = kEpaTolerance * scale;
  ccd_real_t depth = 0;
  ccd_vec3_t dir, pos;
  if (ccdGJKPenetration(&sa, &sb, &ccd, &depth, &dir, &pos) != 0) return false;
  // libccd: moving B by depth * dir separates the pair, so A leaves along -dir.
  axis = -Vec3(dir.v[0], dir.v[1], dir.v[2]);
  const double len = axis.norm();
  if (!(len > 0) || !std::isfinite(len)) return false;
  axis /= len;
  return true;
}

}  // namespace monolith::solvers::collision
