// Box-box narrow phase: separating axes, then face clipping or the edge-edge point,
// and the nearest points of boxes apart by less than the contact margin. Same contracts as FCL's
// dBoxBox and fcl::distance, which they replace for box pairs (narrow_phase_3d.cpp). In a box
// pyramid every pair is a box pair, queried ~56 times per step; FCL's general machinery (request
// and result objects, GJK for the distance) cost several times the geometry itself.
#include <algorithm>
#include <array>
#include <cmath>
#include <type_traits>

#include "solvers/collision/box_box_impl.h"
#include "solvers/collision/contact_axis_impl.h"

namespace monolith::solvers::collision {

namespace {

using Vec3 = Eigen::Vector3d;

// An edge axis replaces the best face axis only when its overlap is smaller by this factor:
// along a face normal and an edge pair lying in that face the overlaps agree up to rounding, and
// the face axis is the one that gives the full manifold.
constexpr double kEdgePreference = 1.05;
// Edge pairs closer than this to parallel (sine of the angle) give no axis of their own: the
// cross product's direction is ill-conditioned and the face axes already cover them.
constexpr double kParallelSine = 1e-6;
// The clipped face polygon keeps at most this many points, as FCL's box-box does.
constexpr int kMaxFacePoints = 4;
// A vertex whose distance is within this (times the smaller box's size) of the axis' gap is a
// nearest point: the distance cannot be below that gap.
constexpr double kReachesGap = 1e-12;

double sign(double x) { return x < 0 ? -1.0 : 1.0; }

struct ClipVertex {
  double x, y, depth;  // reference-face coordinates; depth below the reference face
};

// Sutherland-Hodgman against the half plane s * coordinate(axis) <= limit. Depth is linear on
// the incident face, so interpolating it is exact.
int clip(const ClipVertex* in, int n, int axis, double s, double limit, ClipVertex* out) {
  auto value = [&](const ClipVertex& v) { return s * (axis == 0 ? v.x : v.y) - limit; };
  int m = 0;
  for (int k = 0; k < n; ++k) {
    const ClipVertex& p = in[k];
    const ClipVertex& q = in[(k + 1) % n];
    const double fp = value(p), fq = value(q);
    if (fp <= 0) out[m++] = p;
    if ((fp < 0 && fq > 0) || (fp > 0 && fq < 0)) {
      const double t = fp / (fp - fq);
      out[m++] = {p.x + t * (q.x - p.x), p.y + t * (q.y - p.y), p.depth + t * (q.depth - p.depth)};
    }
  }
  return m;
}

// Keeps `cap` of the points: the deepest, then repeatedly the one farthest from those kept (the
// support polygon keeps its extent, as in finishManifold), in their original order.
int cull(ClipVertex* points, int n, int cap) {
  if (n <= cap) return n;
  std::array<char, 8> keep{};
  std::array<double, 8> gap;
  gap.fill(kInfinity);
  int last = 0;
  for (int i = 1; i < n; ++i)
    if (points[i].depth > points[last].depth) last = i;
  keep[last] = 1;
  for (int kept = 1; kept < cap; ++kept) {
    int next = -1;
    for (int i = 0; i < n; ++i) {
      if (keep[i]) continue;
      const double dx = points[i].x - points[last].x, dy = points[i].y - points[last].y;
      gap[i] = std::min(gap[i], dx * dx + dy * dy);
      if (next < 0 || gap[i] > gap[next]) next = i;
    }
    keep[next] = 1;
    last = next;
  }
  int m = 0;
  for (int i = 0; i < n; ++i)
    if (keep[i]) points[m++] = points[i];
  return m;
}

// A face axis's reference face (of the box whose face normal the axis is; nRef out of it) and
// the other box's incident face in its coordinates: the polygon faceContacts clips.
struct FacePair {
  Vec3 nRef, e1, e2, faceCentre;
  double limit1 = 0, limit2 = 0;  // the reference face's half extents along e1, e2
  ClipVertex polygon[4];
};

FacePair facePair(const Geometry<3>& a, const Pose<3>& poseA, const Geometry<3>& b, const Pose<3>& poseB,
                  const BoxBoxAxis& axis) {
  FacePair f;
  const bool refIsA = axis.code < 3;
  const Pose<3>& ref = refIsA ? poseA : poseB;
  const Pose<3>& inc = refIsA ? poseB : poseA;
  const Vec3& hRef = refIsA ? a.halfExtents : b.halfExtents;
  const Vec3& hInc = refIsA ? b.halfExtents : a.halfExtents;
  const int k = refIsA ? axis.code : axis.code - 3;
  f.nRef = refIsA ? Vec3(-axis.normal) : axis.normal;
  const int u1 = (k + 1) % 3, u2 = (k + 2) % 3;
  f.e1 = ref.R.col(u1);
  f.e2 = ref.R.col(u2);
  f.limit1 = hRef[u1];
  f.limit2 = hRef[u2];
  f.faceCentre = ref.x + hRef[k] * f.nRef;
  // Incident face: the face of the other box whose outward normal opposes nRef most.
  int m = 0;
  double best = -1;
  for (int j = 0; j < 3; ++j) {
    const double c = std::abs(inc.R.col(j).dot(f.nRef));
    if (c > best) best = c, m = j;
  }
  const double s = -sign(inc.R.col(m).dot(f.nRef));
  const int i1 = (m + 1) % 3, i2 = (m + 2) % 3;
  const Vec3 incCentre = inc.x + s * hInc[m] * inc.R.col(m);
  const Vec3 f1 = hInc[i1] * inc.R.col(i1), f2 = hInc[i2] * inc.R.col(i2);
  int n = 0;
  for (const auto& c : {std::array<double, 2>{1, 1}, {-1, 1}, {-1, -1}, {1, -1}}) {
    const Vec3 v = incCentre + c[0] * f1 + c[1] * f2 - f.faceCentre;
    f.polygon[n++] = {v.dot(f.e1), v.dot(f.e2), -v.dot(f.nRef)};
  }
  return f;
}

int faceContacts(const Geometry<3>& a, const Pose<3>& poseA, const Geometry<3>& b, const Pose<3>& poseB,
                 const BoxBoxAxis& axis, std::vector<ContactPoint<3>>& out) {
  const FacePair f = facePair(a, poseA, b, poseB, axis);
  const Vec3 &nRef = f.nRef, &e1 = f.e1, &e2 = f.e2, &faceCentre = f.faceCentre;
  ClipVertex polygon[8], scratch[8];
  int n = 4;
  std::copy(f.polygon, f.polygon + 4, polygon);
  n = clip(polygon, n, 0, 1, f.limit1, scratch);
  n = clip(scratch, n, 0, -1, f.limit1, polygon);
  n = clip(polygon, n, 1, 1, f.limit2, scratch);
  n = clip(scratch, n, 1, -1, f.limit2, polygon);
  int kept = 0;
  for (int i = 0; i < n; ++i)
    if (polygon[i].depth >= 0) polygon[kept++] = polygon[i];
  kept = cull(polygon, kept, kMaxFacePoints);
  for (int i = 0; i < kept; ++i) {
    const ClipVertex& v = polygon[i];
    ContactPoint<3> c;  // midway: the incident point lies depth below the reference face
    c.point = faceCentre + v.x * e1 + v.y * e2 - (0.5 * v.depth) * nRef;
    c.normal = axis.normal;
    c.depth = v.depth;
    out.push_back(c);
  }
  return kept;
}

// Whether a corner of the incident face survives faceContacts' clipping and depth test: inside
// the reference face's rectangle by the clip's own comparisons (a vertex on an edge is kept) and
// at or below the face. Then faceContacts reports at least one point.
bool cornerInFace(const FacePair& f) {
  for (const ClipVertex& v : f.polygon)
    if (v.x - f.limit1 <= 0 && -v.x - f.limit1 <= 0 && v.y - f.limit2 <= 0 && -v.y - f.limit2 <= 0 && v.depth >= 0)
      return true;
  return false;
}

int edgeContact(const Geometry<3>& a, const Pose<3>& poseA, const Geometry<3>& b, const Pose<3>& poseB,
                const BoxBoxAxis& axis, std::vector<ContactPoint<3>>& out) {
  const int i = (axis.code - 6) / 3, j = (axis.code - 6) % 3;
  const Vec3& n = axis.normal;
  // A's edge along axis i that reaches furthest towards B (along -n), B's along j towards A.
  Vec3 pa = poseA.x, pb = poseB.x;
  for (int k = 0; k < 3; ++k) {
    if (k != i) pa -= sign(poseA.R.col(k).dot(n)) * a.halfExtents[k] * poseA.R.col(k);
    if (k != j) pb += sign(poseB.R.col(k).dot(n)) * b.halfExtents[k] * poseB.R.col(k);
  }
  // Closest points of the two edge lines (not clamped to the edges, as FCL's dBoxBox: the
  // same point for a genuine edge crossing, and continuous as the edges slide past their ends).
  const Vec3 ua = poseA.R.col(i), ub = poseB.R.col(j);
  const Vec3 w = pa - pb;
  const double k = ua.dot(ub), denominator = 1 - k * k;  // > 0: the edges are not parallel
  const double sa = (k * ub.dot(w) - ua.dot(w)) / denominator;
  const double sb = (ub.dot(w) - k * ua.dot(w)) / denominator;
  ContactPoint<3> c;
  c.point = 0.5 * ((pa + sa * ua) + (pb + sb * ub));
  c.normal = n;
  c.depth = -axis.separation;
  out.push_back(c);
  return 1;
}

struct Nearest {
  double distance2 = kInfinity;
  Vec3 onA = Vec3::Zero(), onB = Vec3::Zero();
};

// The vertices of box F against box S (clamping in S's frame gives the nearest point exactly).
void vertexDistances(const Vec3& hf, const Pose<3>& pf, const Vec3& hs, const Pose<3>& ps, bool fIsA, Nearest& best) {
  const Eigen::Matrix3d R = ps.R.transpose() * pf.R;
  const Vec3 x = ps.R.transpose() * (pf.x - ps.x);
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner((c & 1 ? 1 : -1) * hf.x(), (c & 2 ? 1 : -1) * hf.y(), (c & 4 ? 1 : -1) * hf.z());
    const Vec3 v = x + R * corner;
    const Vec3 clamped = v.cwiseMax(-hs).cwiseMin(hs);
    const double d2 = (v - clamped).squaredNorm();
    if (!(d2 < best.distance2)) continue;
    best.distance2 = d2;
    const Vec3 pv = ps.R * v + ps.x, pc = ps.R * clamped + ps.x;
    best.onA = fIsA ? pv : pc;
    best.onB = fIsA ? pc : pv;
  }
}

struct Edge {
  Vec3 p, q;  // world end points
};

// The edges of box F that may lie within `limit` of box S: per axis of S, the gap between the
// edge's extent and the box's is a lower bound on their distance.
int nearEdges(const Vec3& hf, const Pose<3>& pf, const Vec3& hs, const Pose<3>& ps, double limit, Edge* out) {
  int n = 0;
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    const Vec3 along = hf[i] * pf.R.col(i);
    for (int c = 0; c < 4; ++c) {
      const Vec3 centre = pf.x + (c & 1 ? 1 : -1) * hf[j] * pf.R.col(j) + (c & 2 ? 1 : -1) * hf[k] * pf.R.col(k);
      const Edge e{centre - along, centre + along};
      const Vec3 p = ps.R.transpose() * (e.p - ps.x), q = ps.R.transpose() * (e.q - ps.x);
      double gap = 0;
      for (int m = 0; m < 3; ++m)
        gap = std::max({gap, std::min(p[m], q[m]) - hs[m], -hs[m] - std::max(p[m], q[m])});
      if (gap <= limit) out[n++] = e;
    }
  }
  return n;
}

}  // namespace

bool boxBoxNearestPoints(const Geometry<3>& a, const Pose<3>& poseA, const Geometry<3>& b, const Pose<3>& poseB,
                         const BoxBoxAxis& axis, double limit, Vec3& onA, Vec3& onB) {
  const Vec3& hA = a.halfExtents;
  const Vec3& hB = b.halfExtents;
  Nearest best;
  vertexDistances(hA, poseA, hB, poseB, true, best);
  vertexDistances(hB, poseB, hA, poseA, false, best);
  const double scale = std::min(hA.minCoeff(), hB.minCoeff());
  if (std::sqrt(best.distance2) > axis.separation + kReachesGap * scale) {
    // An edge pair may be nearer (crossing edges): only edges near the other box can be.
    const double reach = std::min(limit, std::sqrt(best.distance2));
    Edge edgesA[12], edgesB[12];
    const int nA = nearEdges(hA, poseA, hB, poseB, reach, edgesA);
    const int nB = nearEdges(hB, poseB, hA, poseA, reach, edgesB);
    for (int i = 0; i < nA; ++i)
      for (int j = 0; j < nB; ++j) {
        Vec3 ca, cb;
        closestSegmentPoints(edgesA[i].p, edgesA[i].q, edgesB[j].p, edgesB[j].q, ca, cb);
        const double d2 = (ca - cb).squaredNorm();
        if (!(d2 < best.distance2)) continue;
        best.distance2 = d2;
        best.onA = ca;
        best.onB = cb;
      }
  }
  if (!(std::sqrt(best.distance2) <= limit)) return false;
  onA = best.onA;
  onB = best.onB;
  return true;
}

BoxBoxAxis boxBoxAxis(const Geometry<3>& a, const Pose<3>& poseA, const Geometry<3>& b, const Pose<3>& poseB,
                      double stopAbove) {
  const Vec3 D = poseA.x - poseB.x;  // from B to A
  const Eigen::Matrix3d C = poseA.R.transpose() * poseB.R;  // C(i, j) = a_i . b_j
  const Eigen::Matrix3d absC = C.cwiseAbs();
  const Vec3& hA = a.halfExtents;
  const Vec3& hB = b.halfExtents;
  BoxBoxAxis best;
  double separation = -kInfinity;  // the largest gap over every axis, edges unweighted
  // unit(): the axis as a world unit vector, only evaluated for an axis that is kept.
  auto consider = [&](double s, double along, int code, bool preferred, auto unit) {
    const bool least = s > separation;
    const bool chosen = preferred ? s > best.separation : s * kEdgePreference > best.separation;
    if (!least && !chosen) return;
    const Vec3 n = sign(along) * unit();
    if (least) {
      separation = s;
      best.leastOverlapNormal = n;
    }
    if (chosen) {
      best.separation = s;
      best.normal = n;
      best.code = code;
    }
  };
  // A gap above stopAbove already decides the caller's question (apart by more than it cares
  // about): the remaining axes could only make the gap larger.
  auto stop = [&] {
    if (!(separation > stopAbove)) return false;
    best.separation = separation;
    best.leastOverlap = -separation;
    return true;
  };
  for (int i = 0; i < 3; ++i) {
    const double along = D.dot(poseA.R.col(i));
    consider(std::abs(along) - (hA[i] + hB.dot(absC.row(i).transpose())), along, i, true,
             [&] { return Vec3(poseA.R.col(i)); });
    if (stop()) return best;
  }
  for (int j = 0; j < 3; ++j) {
    const double along = D.dot(poseB.R.col(j));
    consider(std::abs(along) - (hA.dot(absC.col(j)) + hB[j]), along, 3 + j, true, [&] { return Vec3(poseB.R.col(j)); });
    if (stop()) return best;
  }
  // Edge pairs in A's frame: b_j is column j of C and u = a_i x b_j, so a_k.u and b_k.u are
  // entries of C (their radii need no products), and |u| = sine of the angle between the edges.
  // The indices are compile-time constants (the nine pairs spelled out below, in the order of a
  // loop over i then j): no index arithmetic, and a_i x b_j read off C without products. The
  // same numbers as Vec3::Unit(i).cross(C.col(j)) (its other terms are exact zeros).
  const Vec3 DA = poseA.R.transpose() * D;
  auto edge = [&](auto iConstant, auto jConstant) -> bool {
    constexpr int i = decltype(iConstant)::value, j = decltype(jConstant)::value;
    constexpr int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
    Vec3 uA;
    uA[i] = 0;
    uA[i1] = -C(i2, j);
    uA[i2] = C(i1, j);
    const double length = uA.norm();
    if (length < kParallelSine) return false;
    const double inverseLength = 1 / length;
    const double along = DA.dot(uA) * inverseLength;
    const double radii = hA[i1] * absC(i2, j) + hA[i2] * absC(i1, j) + hB[j1] * absC(i, j2) + hB[j2] * absC(i, j1);
    consider(std::abs(along) - radii * inverseLength, along, 6 + 3 * i + j, false,
             [&] { return Vec3(poseA.R * (uA * inverseLength)); });
    return stop();
  };
  using I0 = std::integral_constant<int, 0>;
  using I1 = std::integral_constant<int, 1>;
  using I2 = std::integral_constant<int, 2>;
  if (edge(I0{}, I0{}) || edge(I0{}, I1{}) || edge(I0{}, I2{}) ||  //
      edge(I1{}, I0{}) || edge(I1{}, I1{}) || edge(I1{}, I2{}) ||  //
      edge(I2{}, I0{}) || edge(I2{}, I1{}) || edge(I2{}, I2{}))
    return best;
  best.leastOverlap = -separation;
  // Apart: report the largest gap (a lower bound on the distance); the axis is then irrelevant.
  if (separation > 0) best.separation = separation;
  return best;
}

bool boxBoxContactsExist(const Geometry<3>& a, const Pose<3>& poseA, const Geometry<3>& b, const Pose<3>& poseB,
                         const BoxBoxAxis& axis, std::vector<ContactPoint<3>>& scratch) {
  if (!(axis.separation <= 0) || axis.code < 0) return false;
  if (axis.code >= 6) return true;  // an edge pair gives its one point
  if (cornerInFace(facePair(a, poseA, b, poseB, axis))) return true;
  scratch.clear();
  return faceContacts(a, poseA, b, poseB, axis, scratch) > 0;
}

int boxBoxContacts(const Geometry<3>& a, const Pose<3>& poseA, const Geometry<3>& b, const Pose<3>& poseB,
                   const BoxBoxAxis& axis, std::vector<ContactPoint<3>>& out) {
  if (!(axis.separation <= 0) || axis.code < 0) return 0;  // apart, or no axis (non-finite poses)
  return axis.code < 6 ? faceContacts(a, poseA, b, poseB, axis, out) : edgeContact(a, poseA, b, poseB, axis, out);
}

}  // namespace monolith::solvers::collision
