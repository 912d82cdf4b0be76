// 2-D narrow phase: exact routines, no FCL.
// Disk pairs and half-plane pairs: the feature points (disk centre with its radius, polygon
// vertices) against the other shape's exact signed distance (shape_queries.cpp). Polygon pairs:
// the separating axis of least penetration (SAT) picks a reference edge, the other polygon's
// most anti-parallel edge is clipped to the reference edge's side planes and the clipped points
// below it (or within the margin above it) are the contacts, two for edges lying on each other.
#include <cmath>

#include "solvers/collision/collision_impl.h"

namespace monolith::solvers::collision {

namespace {

using Vec2 = Eigen::Vector2d;
using CP = ContactPoint<2>;
using PG = PreparedGeometry<2>;

// Contacts closer than this (times the length scale) are duplicates.
constexpr double kMergeDistance = 1e-6;
// Relative tie on the SAT separations: B's edge is the reference unless A's is clearly better,
// so that symmetric configurations give normals straight out of B.
constexpr double kReferenceTie = 1e-9;

struct Polygon {  // world frame; edge i runs from v[i] to v[i+1], outward normal n[i]
  std::vector<Vec2> v, n;
  std::vector<double> offset;
  int size() const { return static_cast<int>(v.size()); }
  const Vec2& next(int i) const { return v[(i + 1) % v.size()]; }
};

struct Scratch {
  Polygon a, b;
  std::vector<CP> result;
  std::vector<FeaturePoint<2>> features;
};
Scratch& scratch() {
  thread_local Scratch s;
  return s;
}

void toWorld(const PG& g, const Pose<2>& pose, Polygon& out) {
  const auto& impl = g.impl();
  out.v.clear();
  out.n.clear();
  out.offset.clear();
  for (std::size_t i = 0; i < impl.vertices.size(); ++i) {
    out.v.push_back(pose.R * impl.vertices[i] + pose.x);
    out.n.push_back(pose.R * impl.faceNormals[i]);
    out.offset.push_back(out.n.back().dot(out.v.back()));
  }
}

// Largest separation of Q from P's edges: for each edge of P the deepest vertex of Q along its
// normal; the edge where that is largest is P's candidate separating axis.
void maxSeparation(const Polygon& p, const Polygon& q, int& edge, double& separation) {
  separation = -kInfinity;
  edge = 0;
  for (int i = 0; i < p.size(); ++i) {
    double deepest = kInfinity;
    for (const Vec2& v : q.v) deepest = std::min(deepest, p.n[i].dot(v) - p.offset[i]);
    if (deepest > separation) {
      separation = deepest;
      edge = i;
    }
  }
}

Vec2 closestOnSegment(const Vec2& q, const Vec2& a, const Vec2& b) {
  const Vec2 ab = b - a;
  const double len2 = ab.squaredNorm();
  return a + (len2 > 0 ? std::clamp((q - a).dot(ab) / len2, 0.0, 1.0) : 0.0) * ab;
}

// Separated polygons whose nearest features are two vertices have no clipped point within the
// margin: their exact distance (vertex to edge, both ways) gives the contact.
void nearestPoints(const Polygon& a, const Polygon& b, double margin, std::vector<CP>& out) {
  double best = kInfinity;
  Vec2 onA = Vec2::Zero(), onB = Vec2::Zero();
  for (int pass = 0; pass < 2; ++pass) {
    const Polygon& vertices = pass == 0 ? a : b;
    const Polygon& edges = pass == 0 ? b : a;
    for (const Vec2& v : vertices.v)
      for (int i = 0; i < edges.size(); ++i) {
        const Vec2 c = closestOnSegment(v, edges.v[i], edges.next(i));
        const double dist2 = (v - c).squaredNorm();
        if (dist2 < best) {
          best = dist2;
          onA = pass == 0 ? v : c;
          onB = pass == 0 ? c : v;
        }
      }
  }
  const double dist = std::sqrt(best);
  if (!(dist > 0) || dist > margin) return;
  CP c;
  c.normal = (onA - onB) / dist;
  c.depth = -dist;
  c.point = 0.5 * (onA + onB);
  out.push_back(c);
}

void polygonPair(const Polygon& a, const Polygon& b, double margin, double scale, std::vector<CP>& out) {
  int edgeA, edgeB;
  double sepA, sepB;
  maxSeparation(a, b, edgeA, sepA);
  maxSeparation(b, a, edgeB, sepB);
  const double separation = std::max(sepA, sepB);
  if (separation > margin) return;  // an axis separates them by more than the margin
  const bool referenceIsB = sepB >= sepA - kReferenceTie * scale;
  const Polygon& ref = referenceIsB ? b : a;
  const Polygon& inc = referenceIsB ? a : b;
  const int e = referenceIsB ? edgeB : edgeA;
  const Vec2 n = ref.n[e];
  // Incident edge: the one facing the reference edge most directly.
  int j = 0;
  for (int i = 1; i < inc.size(); ++i)
    if (inc.n[i].dot(n) < inc.n[j].dot(n)) j = i;
  // Clip the incident edge to the slab between the reference edge's side planes.
  const Vec2 r1 = ref.v[e], r2 = ref.next(e);
  const Vec2 tangent = (r2 - r1).normalized();
  const double lo = tangent.dot(r1), hi = tangent.dot(r2);
  const Vec2 v1 = inc.v[j], v2 = inc.next(j);
  const double s1 = tangent.dot(v1), s2 = tangent.dot(v2);
  double u0 = 0, u1 = 1;
  if (s1 != s2) {
    const double ua = (lo - s1) / (s2 - s1), ub = (hi - s1) / (s2 - s1);
    u0 = std::max(0.0, std::min(ua, ub));
    u1 = std::min(1.0, std::max(ua, ub));
  } else if (s1 < lo || s1 > hi) {
    u0 = 1;  // the edge lies outside the slab
    u1 = 0;
  }
  const std::size_t before = out.size();
  if (u0 <= u1) {
    for (double u : {u0, u1}) {
      const Vec2 p = u == 0 ? v1 : (u == 1 ? v2 : Vec2(v1 + u * (v2 - v1)));
      const double depth = ref.offset[e] - n.dot(p);
      if (!(depth >= -margin)) continue;
      // p is the incident polygon's point: pointOnA (reference B) or pointOnB (reference A); in
      // both cases the midpoint is half the depth along the reference normal.
      CP c;
      c.point = p + 0.5 * depth * n;
      c.normal = referenceIsB ? n : Vec2(-n);
      c.depth = depth;
      out.push_back(c);
    }
  }
  if (out.size() > before) return;
  if (separation > 0) {
    nearestPoints(a, b, margin, out);
    return;
  }
  // Overlapping but nothing clipped (a degenerate sliver): the SAT witness vertex.
  int deepest = 0;
  for (int i = 1; i < inc.size(); ++i)
    if (n.dot(inc.v[i]) < n.dot(inc.v[deepest])) deepest = i;
  const double depth = ref.offset[e] - n.dot(inc.v[deepest]);
  CP c;
  c.point = inc.v[deepest] + 0.5 * depth * n;
  c.normal = referenceIsB ? n : Vec2(-n);
  c.depth = depth;
  out.push_back(c);
}

void orderedContacts(const PG& a, const Pose<2>& pa, const PG& b, const Pose<2>& pb, double margin, double scale,
                     Scratch& s) {
  const GeometryType ta = a.geometry().type, tb = b.geometry().type;
  if (tb == GeometryType::HalfSpace || ta == GeometryType::Sphere) {
    featureContacts<2>(a, pa, Vec2(pb.x - pa.x), b, pb, margin, false, s.features, s.result);
    return;
  }
  toWorld(a, pa, s.a);
  toWorld(b, pb, s.b);
  polygonPair(s.a, s.b, margin, scale, s.result);
}

// A half-plane is B, a disk is A.
bool swapForOrder(GeometryType ta, GeometryType tb) {
  if (ta == GeometryType::HalfSpace || tb == GeometryType::HalfSpace) return ta == GeometryType::HalfSpace;
  return tb == GeometryType::Sphere && ta != GeometryType::Sphere;
}

}  // namespace

int findContacts2(const PG& a, const Pose<2>& poseA, const PG& b, const Pose<2>& poseB, const ContactQuery& query,
                  std::vector<CP>& out) {
  if (a.unbounded() && b.unbounded()) return 0;
  const bool swap = swapForOrder(a.geometry().type, b.geometry().type);
  const double margin = std::max(0.0, query.margin);
  const double scale = pairLengthScale<2>(a, b);
  Scratch& s = scratch();
  s.result.clear();
  if (swap) orderedContacts(b, poseB, a, poseA, margin, scale, s);
  else orderedContacts(a, poseA, b, poseB, margin, scale, s);
  finishManifold<2>(s.result, query.maxPoints, kMergeDistance * scale);
  for (const CP& c : s.result) out.push_back(swap ? flipped<2>(c) : c);
  return static_cast<int>(s.result.size());
}

}  // namespace monolith::solvers::collision
