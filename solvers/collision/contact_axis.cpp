// Contacts on an axis, without FCL: given an axis between two convex shapes (FCL's,
// a face normal, the nearest points' direction), the depth is the overlap of the shapes'
// projections on it (exact along the axis: the distance A must move along it to separate), the
// normal takes the sign of least overlap, and the point lies midway between the touching
// features. The penetration depth of two convex shapes is the least such overlap over all axes,
// which the refinements below approach from FCL's axis.
#include <algorithm>
#include <array>
#include <cmath>

#include "solvers/collision/contact_axis_impl.h"

namespace monolith::solvers::collision {

namespace {

using Vec3 = Eigen::Vector3d;

// Local search for the axis of least overlap (descendToMinimumOverlap): first tilt ~3 degrees,
// stop below ~1e-7 rad (FCL's own accuracy) or after this many overlap evaluations per start.
constexpr double kInitialTilt = 0.05;
constexpr double kFinalTilt = 1e-7;
constexpr int kMaxTiltEvaluations = 64;

}  // namespace

namespace {

// The shape's extent along n as [lowest, highest], computing only the ends asked for (the
// descent below needs one end of each shape and evaluates it ~300 times per contact it refines).
// Each end is computed the same way whether or not the other is, so projection() and the
// one-sided calls agree bitwise.
template <bool kLow, bool kHigh>
Eigen::Vector2d projectionEnds(const PreparedGeometry<3>& g, const Pose<3>& pose, const Vec3& n, int triangle) {
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
        if constexpr (kLow) lo = std::min(lo, t);
        if constexpr (kHigh) hi = std::max(hi, t);
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

}  // namespace

Eigen::Vector2d projection(const PreparedGeometry<3>& g, const Pose<3>& pose, const Vec3& n, int triangle) {
  return projectionEnds<true, true>(g, pose, n, triangle);
}

namespace {

// Directions within this (~0.6 degrees) of perpendicular to a box axis or a capsule/cylinder axis
// count as perpendicular: a body lying almost flat touches along its edge or face, not at the one
// end that rounding would pick. Only where the contact point goes depends on it.
constexpr double kFlatSupport = 1e-2;

// The extreme set of a posed shape along `dir` (unit) as a segment [p, q] (p == q for a point):
// a vertex or a rounded point, an edge, or, for a face, its point nearest to `ref` (the contact's
// location as FCL found it). Convex hulls and triangles: the vertices within kFlatSupport of the
// extreme, one (a point), two (an edge), or more (a face: `ref` moved onto its plane).
struct Support {
  Vec3 p, q;
  bool face = false;  // a face: p == q is only its point nearest to the reference
};

Support extremeSet(const PreparedGeometry<3>& g, const Pose<3>& pose, const Vec3& dir, const Vec3& ref, int triangle) {
  const Geometry<3>& geo = g.geometry();
  const Vec3 d = pose.R.transpose() * dir;  // body frame
  const Vec3 r = pose.R.transpose() * (ref - pose.x);
  auto sign = [](double v) { return v > 0 ? 1.0 : -1.0; };
  Vec3 p = Vec3::Zero(), q = Vec3::Zero();
  bool face = false;
  switch (geo.type) {
    case GeometryType::Box: {
      int flat = 0, edgeAxis = -1;
      for (int k = 0; k < 3; ++k) {
        if (std::abs(d[k]) > kFlatSupport) {
          p[k] = sign(d[k]) * geo.halfExtents[k];
        } else {
          p[k] = std::clamp(r[k], -geo.halfExtents[k], geo.halfExtents[k]);
          ++flat;
          edgeAxis = k;
        }
      }
      q = p;
      face = flat >= 2;
      if (flat == 1) {  // an edge: its whole length
        p[edgeAxis] = -geo.halfExtents[edgeAxis];
        q[edgeAxis] = geo.halfExtents[edgeAxis];
      }
      break;
    }
    case GeometryType::Sphere: p = q = geo.radius * d; break;
    case GeometryType::Capsule:
    case GeometryType::Cylinder: {
      const bool capsule = geo.type == GeometryType::Capsule;
      const Eigen::Vector2d radial = d.head<2>();
      Vec3 side = Vec3::Zero();  // offset from the axis towards `dir`
      if (capsule) {
        side = geo.radius * d;
      } else if (radial.norm() > kFlatSupport) {
        side.head<2>() = geo.radius * radial.normalized();
      } else {  // a cap face: the reference's place on it
        face = std::abs(d.z()) > kFlatSupport;
        const Eigen::Vector2d onCap = r.head<2>();
        side.head<2>() = onCap.norm() > geo.radius ? Eigen::Vector2d(geo.radius * onCap.normalized()) : onCap;
      }
      if (std::abs(d.z()) > kFlatSupport) {
        p = q = side + Vec3(0, 0, sign(d.z()) * geo.halfHeight);
      } else {  // lying across `dir`: the line along the side
        p = side - Vec3(0, 0, geo.halfHeight);
        q = side + Vec3(0, 0, geo.halfHeight);
      }
      break;
    }
    case GeometryType::HalfSpace: return {ref, ref, true};
    case GeometryType::Convex:
    case GeometryType::Mesh: {
      const bool oneTriangle = geo.type == GeometryType::Mesh && triangle >= 0;
      const int count = oneTriangle ? 3 : static_cast<int>(g.impl().vertices.size());
      auto vertex = [&](int i) -> const Vec3& {
        return oneTriangle ? geo.vertices[geo.triangles[triangle][i]] : g.impl().vertices[i];
      };
      double top = -kInfinity;
      for (int i = 0; i < count; ++i) top = std::max(top, d.dot(vertex(i)));
      const double size = g.impl().localBounds.diagonal().norm();
      int found = 0;
      for (int i = 0; i < count; ++i) {
        if (d.dot(vertex(i)) < top - kFlatSupport * size) continue;
        if (found == 0) p = vertex(i);
        if (found == 1) q = vertex(i);
        ++found;
      }
      if (found == 1) q = p;
      if (found > 2) p = q = r + (top - d.dot(r)) * d, face = true;
      break;
    }
  }
  return {pose.R * p + pose.x, pose.R * q + pose.x, face};
}

// The point of segment [p, q] nearest to x.
Vec3 nearestOnSegment(const Vec3& p, const Vec3& q, const Vec3& x) {
  const Vec3 e = q - p;
  const double len2 = e.squaredNorm();
  return len2 > 0 ? Vec3(p + std::clamp((x - p).dot(e) / len2, 0.0, 1.0) * e) : p;
}

}  // namespace

void closestSegmentPoints(const Vec3& p1, const Vec3& q1, const Vec3& p2, const Vec3& q2, Vec3& c1, Vec3& c2) {
  const Vec3 d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double s = 0, t = 0;
  if (a <= 0 && e <= 0) {
    s = t = 0;
  } else if (a <= 0) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= 0) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2), denom = a * e - b * b;
      s = denom > 1e-12 * a * e ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0) {
        t = 0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1) {
        t = 1;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  c1 = p1 + s * d1;
  c2 = p2 + t * d2;
}

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
  // The touching features: A's extreme set against -normal, B's along it; their closest points.
  Support sa = extremeSet(a, poseA, -out.normal, near, triangleA);
  Support sb = extremeSet(b, poseB, out.normal, near, triangleB);
  // A face against a vertex, rim point or edge: the face's point is taken under that feature,
  // not under `near` (the contact's place before its axis moved), which can lie centimetres
  // aside and would put the point off both surfaces.
  if (sa.face && !sb.face) sa = extremeSet(a, poseA, -out.normal, nearestOnSegment(sb.p, sb.q, near), triangleA);
  else if (sb.face && !sa.face) sb = extremeSet(b, poseB, out.normal, nearestOnSegment(sa.p, sa.q, near), triangleB);
  Vec3 ca, cb;
  closestSegmentPoints(sa.p, sa.q, sb.p, sb.q, ca, cb);
  const Vec3 witness = 0.5 * (ca + cb);
  out.point = witness + (middle - out.normal.dot(witness)) * out.normal;
  return out.depth >= -margin;
}

void refineAxis(const PreparedGeometry<3>& a, const Pose<3>& poseA, const PreparedGeometry<3>& b, const Pose<3>& poseB,
                int triangleB, const std::vector<Vec3>& axes, ContactPoint<3>& c) {
  for (const Vec3& axis : axes) {
    ContactPoint<3> candidate;
    if (contactOnAxis(a, poseA, -1, b, poseB, triangleB, c.point, axis, kInfinity, candidate) &&
        candidate.depth < c.depth)
      c = candidate;
  }
}

namespace {

// Pattern search on the unit sphere from n (oriented with A on its + side): try the axis tilted
// by `step` four ways, keep any that lowers the overlap, halve the step when none does. The
// overlap is the support function of the Minkowski difference: convex but kinked for polytopes,
// where gradients would zigzag. Returns the overlap reached; n becomes its axis.
double descend(const PreparedGeometry<3>& a, const Pose<3>& poseA, const PreparedGeometry<3>& b, const Pose<3>& poseB,
               Vec3& n) {
  auto overlap = [&](const Vec3& m) {
    return projectionEnds<false, true>(b, poseB, m, -1)[1] - projectionEnds<true, false>(a, poseA, m, -1)[0];
  };
  double best = overlap(n);
  double step = kInitialTilt;
  Vec3 u = n.unitOrthogonal(), v = n.cross(u);  // the tilts' basis, found again only when n moves
  for (int evaluation = 0; evaluation < kMaxTiltEvaluations && step > kFinalTilt;) {
    bool improved = false;
    for (const Vec3& tilt : {u, Vec3(-u), v, Vec3(-v)}) {
      const Vec3 m = (n + step * tilt).normalized();
      const double value = overlap(m);
      ++evaluation;
      if (value < best) {
        best = value;
        n = m;
        improved = true;
        break;
      }
    }
    if (improved) {
      u = n.unitOrthogonal();
      v = n.cross(u);
    } else {
      step *= 0.5;
    }
  }
  return best;
}

// Extra starting axes where the overlap has separate local minima that MPR's axis may miss: a
// box's face normals, a cylinder's flat caps against its round side (its axis, and the radial
// direction towards the other shape).
void extraStarts(const PreparedGeometry<3>& g, const Pose<3>& pose, const Vec3& other, std::vector<Vec3>& out) {
  if (g.geometry().type == GeometryType::Box) {
    for (int k = 0; k < 3; ++k) out.push_back(pose.R.col(k));
  } else if (g.geometry().type == GeometryType::Cylinder) {
    const Vec3 axis = pose.R.col(2);
    out.push_back(axis);
    const Vec3 towards = other - pose.x;
    const Vec3 radial = towards - towards.dot(axis) * axis;
    if (radial.norm() > 0) out.push_back(radial);
  }
}

}  // namespace

double leastOverlapOfPolytopes(const PreparedGeometry<3>& a, const Pose<3>& poseA, const PreparedGeometry<3>& b,
                               const Pose<3>& poseB, Vec3& axis) {
  double best = kInfinity;
  auto consider = [&](const Vec3& n) {  // n: unit, world frame
    const Eigen::Vector2d pa = projection(a, poseA, n, -1), pb = projection(b, poseB, n, -1);
    const double overlap = std::min(pb[1] - pa[0], pa[1] - pb[0]);
    if (overlap < best) {
      best = overlap;
      axis = n;
    }
  };
  for (const Vec3& n : a.impl().faceNormals) consider(poseA.R * n);
  for (const Vec3& n : b.impl().faceNormals) consider(poseB.R * n);
  // Edge against edge: the cross products of their directions (parallel edges give none).
  for (const Vec3& ea : a.impl().edgeDirections) {
    const Vec3 ua = poseA.R * ea;
    for (const Vec3& eb : b.impl().edgeDirections) {
      const Vec3 n = ua.cross(poseB.R * eb);
      const double length = n.norm();
      if (length > 1e-9) consider(n / length);
    }
  }
  return best;
}

void descendToMinimumOverlap(const PreparedGeometry<3>& a, const Pose<3>& poseA, const PreparedGeometry<3>& b,
                             const Pose<3>& poseB, ContactPoint<3>& c) {
  auto polytope = [](const PreparedGeometry<3>& g) {
    return g.geometry().type == GeometryType::Box || g.geometry().type == GeometryType::Convex;
  };
  if (polytope(a) && polytope(b)) {
    Vec3 axis;
    if (leastOverlapOfPolytopes(a, poseA, b, poseB, axis) < c.depth) {
      ContactPoint<3> moved;
      if (contactOnAxis(a, poseA, -1, b, poseB, -1, c.point, axis, kInfinity, moved) && moved.depth < c.depth) c = moved;
    }
    return;
  }
  std::vector<Vec3> starts = {c.normal};
  extraStarts(a, poseA, poseB.x, starts);
  extraStarts(b, poseB, poseA.x, starts);
  // Local minima a few degrees apart (a cylinder's rim against an edge or a face, a hull's edges)
  // are not told apart by the starts above; EPA's axis lies in the global one
  // (penetration_axis.cpp). Only contacts no feature point represents get here (edge and rim
  // contacts, not a body resting on a face), and box pairs never (their SAT is exact).
  Vec3 axis;
  if (epaAxis(a, poseA, b, poseB, pairLengthScale<3>(a, b), axis)) starts.push_back(axis);
  Vec3 bestAxis = c.normal;
  double best = c.depth;
  for (std::size_t k = 0; k < starts.size(); ++k) {
    Vec3 n = starts[k].normalized();
    if (k > 0) {  // orient the extra starts like any contact axis: the sign of least overlap
      ContactPoint<3> oriented;
      if (!contactOnAxis(a, poseA, -1, b, poseB, -1, c.point, n, kInfinity, oriented)) continue;
      n = oriented.normal;
    }
    const double value = descend(a, poseA, b, poseB, n);
    if (value < best) {
      best = value;
      bestAxis = n;
    }
  }
  if (best < c.depth) {
    ContactPoint<3> moved;
    if (contactOnAxis(a, poseA, -1, b, poseB, -1, c.point, bestAxis, kInfinity, moved) && moved.depth < c.depth) c = moved;
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

bool triangleNormalContact(const PreparedGeometry<3>& a, const Pose<3>& poseAInMesh, const PreparedGeometry<3>& mesh,
                           int triangle, double margin, ContactPoint<3>& out) {
  const Geometry<3>& geo = mesh.geometry();
  const auto& tri = geo.triangles[triangle];
  const Vec3 face = (geo.vertices[tri[1]] - geo.vertices[tri[0]]).cross(geo.vertices[tri[2]] - geo.vertices[tri[0]]);
  const Vec3 centroid = (geo.vertices[tri[0]] + geo.vertices[tri[1]] + geo.vertices[tri[2]]) / 3;
  return contactOnAxis(a, poseAInMesh, -1, mesh, Pose<3>(), triangle, centroid, face, margin, out);
}

}  // namespace monolith::solvers::collision
