// Point queries shared by the 2-D and 3-D narrow phases: signed distance from a point to
// a shape, the shapes' feature points, and the vertex-in-shape contact test built on them (the
// thesis's "vertices of A inside the level set of B", with exact polytope distances instead of a
// sampled level set), plus the manifold clean-up every pair goes through.
#include <algorithm>
#include <cmath>
#include <numeric>

#include "solvers/collision/collision_impl.h"

namespace monolith::solvers::collision {

namespace {

// Contacts at (almost) the same place whose normals agree to within ~8 degrees are one contact.
constexpr double kSameNormalCosine = 0.99;

template <int d>
using Vec = Eigen::Matrix<double, d, 1>;

template <int d>
Vec<d> closestOnSegment(const Vec<d>& q, const Vec<d>& a, const Vec<d>& b) {
  const Vec<d> ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((q - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return a + t * ab;
}

}  // namespace

// Closest point of triangle abc to q (Ericson, Real-Time Collision Detection, 5.1.5: Voronoi
// regions of the vertices, then of the edges, else the face).
Eigen::Vector3d closestPointOnTriangle(const Eigen::Vector3d& q, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                       const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = q - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Eigen::Vector3d bp = q - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + d1 / (d1 - d3) * ab;
  const Eigen::Vector3d cp = q - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + d2 / (d2 - d6) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  const double denom = 1 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

namespace {

template <int d>
SurfaceDistance<d> outsideAt(const Vec<d>& q, const Vec<d>& surface, const Vec<d>& fallbackNormal) {
  SurfaceDistance<d> r;
  const Vec<d> diff = q - surface;
  r.distance = diff.norm();
  r.normal = r.distance > 0 ? Vec<d>(diff / r.distance) : fallbackNormal;
  r.surfacePoint = surface;
  return r;
}

template <int d>
SurfaceDistance<d> boxDistance(const Vec<d>& h, const Vec<d>& q) {
  const Vec<d> excess = q.cwiseAbs() - h;
  int k = 0;
  for (int i = 1; i < d; ++i)
    if (excess[i] > excess[k]) k = i;
  const double sign = q[k] < 0 ? -1.0 : 1.0;
  if (excess[k] <= 0) {  // inside: the face of least penetration
    SurfaceDistance<d> r;
    r.distance = excess[k];
    r.normal = sign * Vec<d>::Unit(k);
    r.surfacePoint = q;
    r.surfacePoint[k] = sign * h[k];
    return r;
  }
  return outsideAt<d>(q, q.cwiseMax(-h).cwiseMin(h), sign * Vec<d>::Unit(k));
}

template <int d>
SurfaceDistance<d> polytopeDistance(const typename PreparedGeometry<d>::Impl& impl, const Vec<d>& q, double limit) {
  int k = 0;
  double s = -kInfinity;
  for (std::size_t i = 0; i < impl.faceNormals.size(); ++i) {
    const double v = impl.faceNormals[i].dot(q) - impl.faceOffsets[i];
    if (v > s) {
      s = v;
      k = static_cast<int>(i);
      if (s > limit) break;  // already farther than the caller cares about
    }
  }
  SurfaceDistance<d> r;
  r.normal = impl.faceNormals[k];
  r.distance = s;
  r.surfacePoint = q - s * r.normal;
  // Inside, the nearest face plane is the nearest surface; far outside, the plane distance is a
  // lower bound the caller rejects anyway.
  if (s <= 0 || s > limit) return r;
  double best = kInfinity;
  Vec<d> nearest = r.surfacePoint;
  if constexpr (d == 2) {
    const int n = static_cast<int>(impl.vertices.size());
    for (int i = 0; i < n; ++i) {
      if (impl.faceNormals[i].dot(q) - impl.faceOffsets[i] <= 0) continue;  // q is behind this edge
      const Vec<d> c = closestOnSegment<d>(q, impl.vertices[i], impl.vertices[(i + 1) % n]);
      const double dist2 = (q - c).squaredNorm();
      if (dist2 < best) {
        best = dist2;
        nearest = c;
      }
    }
  } else {
    for (const auto& t : impl.hullTriangles) {
      const Vec<d>& a = impl.vertices[t[0]];
      const Vec<d>& b = impl.vertices[t[1]];
      const Vec<d>& c = impl.vertices[t[2]];
      if ((b - a).cross(c - a).dot(q - a) <= 0) continue;  // q is behind this face
      const Vec<d> p = closestPointOnTriangle(q, a, b, c);
      const double dist2 = (q - p).squaredNorm();
      if (dist2 < best) {
        best = dist2;
        nearest = p;
      }
    }
  }
  return outsideAt<d>(q, nearest, r.normal);
}

}  // namespace

template <int d>
SurfaceDistance<d> signedDistance(const PreparedGeometry<d>& g, const Vec<d>& q, double limit) {
  const Geometry<d>& geo = g.geometry();
  SurfaceDistance<d> r;
  switch (geo.type) {
    case GeometryType::Box: return boxDistance<d>(geo.halfExtents, q);
    case GeometryType::Convex: return polytopeDistance<d>(g.impl(), q, limit);
    case GeometryType::HalfSpace:
      r.distance = geo.normal.dot(q) - geo.offset;
      r.normal = geo.normal;
      r.surfacePoint = q - r.distance * geo.normal;
      return r;
    case GeometryType::Sphere: {
      const double len = q.norm();
      r.normal = len > 0 ? Vec<d>(q / len) : Vec<d>(Vec<d>::UnitY());
      r.distance = len - geo.radius;
      r.surfacePoint = geo.radius * r.normal;
      return r;
    }
    case GeometryType::Capsule: {
      // Distance to the segment on the body z axis, minus the radius.
      Vec<d> axisPoint = Vec<d>::Zero();
      axisPoint[d - 1] = std::clamp(q[d - 1], -geo.halfHeight, geo.halfHeight);
      const Vec<d> diff = q - axisPoint;
      const double len = diff.norm();
      r.normal = len > 0 ? Vec<d>(diff / len) : Vec<d>(Vec<d>::UnitX());
      r.distance = len - geo.radius;
      r.surfacePoint = axisPoint + geo.radius * r.normal;
      return r;
    }
    case GeometryType::Cylinder: {
      if constexpr (d == 3) {
        const double rho = std::hypot(q.x(), q.y());
        const Eigen::Vector3d radial = rho > 0 ? Eigen::Vector3d(q.x() / rho, q.y() / rho, 0) : Eigen::Vector3d::UnitX();
        const double zSign = q.z() < 0 ? -1.0 : 1.0;
        const double radialExcess = rho - geo.radius, axialExcess = std::abs(q.z()) - geo.halfHeight;
        if (radialExcess <= 0 && axialExcess <= 0) {  // inside: side or cap, whichever is nearer
          r.surfacePoint = q;
          if (radialExcess >= axialExcess) {
            r.distance = radialExcess;
            r.normal = radial;
            r.surfacePoint.template head<2>() = geo.radius * radial.template head<2>();
          } else {
            r.distance = axialExcess;
            r.normal = zSign * Eigen::Vector3d::UnitZ();
            r.surfacePoint.z() = zSign * geo.halfHeight;
          }
          return r;
        }
        // Outside: the solid is disk x interval, so clamping each factor gives the nearest point.
        Eigen::Vector3d c = std::min(rho, geo.radius) * radial;
        c.z() = std::clamp(q.z(), -geo.halfHeight, geo.halfHeight);
        return outsideAt<3>(q, c, radialExcess >= axialExcess ? radial : Eigen::Vector3d(zSign * Eigen::Vector3d::UnitZ()));
      }
      return r;
    }
    case GeometryType::Mesh: return r;  // no inside: +infinity
  }
  return r;
}

template <int d>
void featurePoints(const PreparedGeometry<d>& g, const Pose<d>& pose, const Vec<d>& deepest,
                   std::vector<FeaturePoint<d>>& out) {
  const Geometry<d>& geo = g.geometry();
  switch (geo.type) {
    case GeometryType::Box:
    case GeometryType::Convex:
    case GeometryType::Mesh:
      for (const auto& v : g.impl().vertices) out.push_back({pose.R * v + pose.x, 0.0});
      return;
    case GeometryType::Sphere: out.push_back({pose.x, geo.radius}); return;
    case GeometryType::Capsule:
      for (double s : {-1.0, 1.0})
        out.push_back({pose.x + s * geo.halfHeight * pose.R.col(d - 1), geo.radius, Vec<d>(s * pose.R.col(d - 1))});
      return;
    case GeometryType::Cylinder:
      if constexpr (d == 3) {
        // On each cap: the rim point extreme along `deepest`, the two at +-90 degrees and the
        // opposite one. A cylinder lying on a face touches with one rim point per cap, one
        // standing on it with the whole rim, which the four points hold like a box's corners.
        const Eigen::Vector3d axis = pose.R.col(2);
        Eigen::Vector3d u = deepest - deepest.dot(axis) * axis;
        const double len = u.norm();
        u = len > 1e-9 * deepest.norm() ? Eigen::Vector3d(u / len) : Eigen::Vector3d(pose.R.col(0));
        const Eigen::Vector3d v = axis.cross(u);
        for (double s : {-1.0, 1.0}) {
          const Eigen::Vector3d cap = pose.x + s * geo.halfHeight * axis;
          for (const Eigen::Vector3d& dir : {u, v, Eigen::Vector3d(-v), Eigen::Vector3d(-u)})
            out.push_back({cap + geo.radius * dir, 0.0});
        }
      }
      return;
    case GeometryType::HalfSpace: return;
  }
}

template <int d>
void featureContacts(const PreparedGeometry<d>& f, const Pose<d>& poseF, const Vec<d>& deepest,
                     const PreparedGeometry<d>& s, const Pose<d>& poseS, double margin, bool shapeIsA,
                     std::vector<FeaturePoint<d>>& scratch, std::vector<ContactPoint<d>>& out) {
  Pose<d> rel;  // F in S's frame
  rel.R = poseS.R.transpose() * poseF.R;
  rel.x = poseS.R.transpose() * (poseF.x - poseS.x);
  const auto& bounds = s.impl().localBounds;
  // The contact of a point onF of F against S, whose surface lies as sd says: midway between
  // the two surfaces, with S's normal, negated when S is A
  // (normals point out of B).
  auto emit = [&](const SurfaceDistance<d>& sd, double depth, const Vec<d>& onF) {
    const Vec<d> n = poseS.R * sd.normal;
    ContactPoint<d> c;
    c.point = poseS.R * (0.5 * (sd.surfacePoint + onF)) + poseS.x;
    c.normal = shapeIsA ? Vec<d>(-n) : n;
    c.depth = depth;
    out.push_back(c);
  };
  const GeometryType typeF = f.geometry().type;
  if (typeF == GeometryType::Box || typeF == GeometryType::Convex || typeF == GeometryType::Mesh) {
    // Plain vertices (no radius, no end axis): every box pair of a pile comes here twice per
    // narrow phase, so they are read straight from the shape instead of through the scratch
    // list. The arithmetic is the general loop's below with radius 0, written the same way so
    // that the results are bitwise the same (0.0 - distance keeps the sign of a zero depth).
    for (const auto& vertex : f.impl().vertices) {
      const Vec<d> x = rel.R * vertex + rel.x;
      if (bounds.squaredExteriorDistance(x) > margin * margin) continue;
      const SurfaceDistance<d> sd = signedDistance<d>(s, x, margin + 0.0);
      const double depth = 0.0 - sd.distance;
      if (!(depth >= -margin)) continue;
      emit(sd, depth, x - 0.0 * sd.normal);
    }
    return;
  }
  scratch.clear();
  featurePoints<d>(f, rel, Vec<d>(poseS.R.transpose() * deepest), scratch);
  for (const auto& p : scratch) {
    // Farther than margin + radius from S's box is farther from S: skip the exact query (big
    // hulls have many vertices and many faces). Squared: no root for the many rejected points.
    const double reach = margin + p.radius;
    if (bounds.squaredExteriorDistance(p.x) > reach * reach) continue;
    SurfaceDistance<d> sd = signedDistance<d>(s, p.x, margin + p.radius);
    double depth = p.radius - sd.distance;
    if (!(depth >= -margin)) continue;
    Vec<d> onF = p.x - p.radius * sd.normal;
    const double inward = -sd.normal.dot(p.axis);
    if (inward < 0) {
      // A capsule end whose nearest point to S lies on the inner half of its sphere, inside the
      // capsule: what touches S there is the rim where the side meets the end. The contact is
      // that rim point's, with its own depth and S's normal there, so that its point lies on
      // both surfaces (the capsule's side itself is the pair's main contact).
      Vec<d> towards = -sd.normal - inward * p.axis;  // -normal without its axial part
      const double len = towards.norm();
      if (!(len > 1e-12)) continue;  // the end faces straight away from S: the side touches
      onF = p.x + (p.radius / len) * towards;
      sd = signedDistance<d>(s, onF, margin);
      depth = -sd.distance;
      if (!(depth >= -margin)) continue;
    }
    emit(sd, depth, onF);
  }
}

namespace {

template <int d>
struct FinishScratch {
  std::vector<int> order, alive;
  std::vector<char> removed, keep;
  std::vector<double> gap;
};
// Per thread, so that a warm query does not allocate.
template <int d>
FinishScratch<d>& finishScratch() {
  thread_local FinishScratch<d> s;
  return s;
}

// Up to this many points, all pairs are compared; beyond (a mesh resting on a half-space), a
// sweep along x keeps the merge O(n log n).
constexpr int kAllPairsMerge = 32;

template <int d>
void mergeDuplicates(const std::vector<ContactPoint<d>>& points, double mergeDistance, FinishScratch<d>& s) {
  const int n = static_cast<int>(points.size());
  s.removed.assign(n, 0);
  // The shallower of two coincident contacts goes, the later one on ties.
  auto consider = [&](int i, int j) {
    if (s.removed[i] || s.removed[j]) return;
    if ((points[i].point - points[j].point).squaredNorm() > mergeDistance * mergeDistance) return;
    if (points[i].normal.dot(points[j].normal) < kSameNormalCosine) return;
    const bool dropI = points[j].depth > points[i].depth || (points[j].depth == points[i].depth && i > j);
    s.removed[dropI ? i : j] = 1;
  };
  if (n <= kAllPairsMerge) {
    for (int i = 0; i < n; ++i)
      for (int j = i + 1; j < n; ++j) consider(i, j);
    return;
  }
  s.order.resize(n);
  std::iota(s.order.begin(), s.order.end(), 0);
  std::sort(s.order.begin(), s.order.end(), [&](int i, int j) {
    return points[i].point.x() != points[j].point.x() ? points[i].point.x() < points[j].point.x() : i < j;
  });
  for (int a = 0; a < n; ++a)
    for (int b = a + 1; b < n && points[s.order[b]].point.x() - points[s.order[a]].point.x() <= mergeDistance; ++b)
      consider(std::min(s.order[a], s.order[b]), std::max(s.order[a], s.order[b]));
}

}  // namespace

template <int d>
void finishManifold(std::vector<ContactPoint<d>>& points, int maxPoints, double mergeDistance) {
  const int n = static_cast<int>(points.size());
  const int cap = std::max(1, maxPoints);
  if (n <= 1) return;
  FinishScratch<d>& s = finishScratch<d>();
  mergeDuplicates<d>(points, mergeDistance, s);
  s.alive.clear();
  for (int i = 0; i < n; ++i)
    if (!s.removed[i]) s.alive.push_back(i);
  s.keep.assign(n, 0);
  if (static_cast<int>(s.alive.size()) <= cap) {
    for (int i : s.alive) s.keep[i] = 1;
  } else {
    // The deepest point, then repeatedly the point farthest from all kept ones: the manifold
    // keeps its extent, so a resting body keeps its support polygon.
    int first = s.alive[0];
    for (int i : s.alive)
      if (points[i].depth > points[first].depth) first = i;
    s.keep[first] = 1;
    s.gap.assign(n, kInfinity);
    int last = first;
    for (int kept = 1; kept < cap; ++kept) {
      int next = -1;
      for (int i : s.alive) {
        if (s.keep[i]) continue;
        s.gap[i] = std::min(s.gap[i], (points[i].point - points[last].point).squaredNorm());
        if (next < 0 || s.gap[i] > s.gap[next]) next = i;
      }
      s.keep[next] = 1;
      last = next;
    }
  }
  int m = 0;
  for (int i = 0; i < n; ++i)
    if (s.keep[i]) points[m++] = points[i];
  points.resize(m);
}

template <int d>
void keepUnrepresented(const std::vector<ContactPoint<d>>& main, const std::vector<ContactPoint<d>>& extra,
                       double tolerance, std::vector<ContactPoint<d>>& out) {
  for (const auto& m : main)
    if (!isRepresented<d>(m, extra, tolerance)) out.push_back(m);
  out.insert(out.end(), extra.begin(), extra.end());
}

template SurfaceDistance<2> signedDistance<2>(const PreparedGeometry<2>&, const Vec<2>&, double);
template SurfaceDistance<3> signedDistance<3>(const PreparedGeometry<3>&, const Vec<3>&, double);
template void featurePoints<2>(const PreparedGeometry<2>&, const Pose<2>&, const Vec<2>&, std::vector<FeaturePoint<2>>&);
template void featurePoints<3>(const PreparedGeometry<3>&, const Pose<3>&, const Vec<3>&, std::vector<FeaturePoint<3>>&);
template void featureContacts<2>(const PreparedGeometry<2>&, const Pose<2>&, const Vec<2>&, const PreparedGeometry<2>&,
                                 const Pose<2>&, double, bool, std::vector<FeaturePoint<2>>&,
                                 std::vector<ContactPoint<2>>&);
template void featureContacts<3>(const PreparedGeometry<3>&, const Pose<3>&, const Vec<3>&, const PreparedGeometry<3>&,
                                 const Pose<3>&, double, bool, std::vector<FeaturePoint<3>>&,
                                 std::vector<ContactPoint<3>>&);
template void finishManifold<2>(std::vector<ContactPoint<2>>&, int, double);
template void finishManifold<3>(std::vector<ContactPoint<3>>&, int, double);
template void keepUnrepresented<2>(const std::vector<ContactPoint<2>>&, const std::vector<ContactPoint<2>>&, double,
                                   std::vector<ContactPoint<2>>&);
template void keepUnrepresented<3>(const std::vector<ContactPoint<3>>&, const std::vector<ContactPoint<3>>&, double,
                                   std::vector<ContactPoint<3>>&);

}  // namespace monolith::solvers::collision
