#include "solvers/deformable/proximity.h"

#include "solvers/deformable/parallel_indices.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include "solvers/deformable/elasticity.h"
#include "solvers/deformable/face_geometry.h"

namespace monolith::solvers::deformable {

namespace {

constexpr int kGrain = 64;

// One candidate: point `a` (a particle) against face `b`, or edge `a` against edge `b`.
struct Pair {
  bool edges;
  int a, b;
};

// The pair's particles, the weights of its closest points (the relative velocity is
// sum w_i v_i, point side minus face side), their distance and the unit normal from the face
// side to the point side.
template <int d>
struct Stencil {
  int n = 0;
  int idx[4];
  double w[4];
  VecD<d> normal;
  double distance = 0;
};

template <int d>
VecD<d> at(const std::vector<double>& x, int i) {
  return Eigen::Map<const VecD<d>>(&x[d * i]);
}


// Ericson 5.1.9: parameters s, t of the closest points of segments p1 q1 and p2 q2.
void closestSegmentSegment(const Eigen::Vector3d& p1, const Eigen::Vector3d& q1, const Eigen::Vector3d& p2,
                           const Eigen::Vector3d& q2, double& s, double& t) {
  const Eigen::Vector3d d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  const double eps = 1e-300;
  if (a <= eps && e <= eps) {
    s = t = 0;
    return;
  }
  if (a <= eps) {
    s = 0;
    t = clamp01(f / e);
    return;
  }
  const double c = d1.dot(r);
  if (e <= eps) {
    t = 0;
    s = clamp01(-c / a);
    return;
  }
  const double b = d1.dot(d2), denom = a * e - b * b;
  s = denom > 0 ? clamp01((b * f - c * e) / denom) : 0.0;
  t = (b * s + f) / e;
  if (t < 0) {
    t = 0;
    s = clamp01(-c / a);
  } else if (t > 1) {
    t = 1;
    s = clamp01((b - c) / a);
  }
}

// The stencil of a pair at positions X (a lambda giving particle i's position).
template <int d, class X>
Stencil<d> stencilOf(const CollisionSurface<d>& s, const Pair& pair, X pos) {
  Stencil<d> st;
  VecD<d> fallback = VecD<d>::Zero();
  VecD<d> gap = VecD<d>::Zero();
  if (!pair.edges) {
    const int* f = &s.faces[d * pair.b];
    st.n = d + 1;
    st.idx[0] = pair.a;
    st.w[0] = 1;
    const VecD<d> p = pos(pair.a);
    if constexpr (d == 3) {
      const Eigen::Vector3d a = pos(f[0]), b = pos(f[1]), c = pos(f[2]);
      const Eigen::Vector3d bary = closestOnTriangle(p, a, b, c);
      for (int k = 0; k < 3; ++k) {
        st.idx[k + 1] = f[k];
        st.w[k + 1] = -bary(k);
      }
      gap = p - (bary(0) * a + bary(1) * b + bary(2) * c);
      fallback = (b - a).cross(c - a);
    } else {
      const VecD<2> a = pos(f[0]), b = pos(f[1]);
      const double t = closestOnSegment<2>(p, a, b);
      st.idx[1] = f[0];
      st.idx[2] = f[1];
      st.w[1] = -(1 - t);
      st.w[2] = -t;
      gap = p - ((1 - t) * a + t * b);
      fallback = VecD<2>(a.y() - b.y(), b.x() - a.x());
    }
  } else {
    if constexpr (d == 3) {
      const int* e1 = &s.edges[2 * pair.a];
      const int* e2 = &s.edges[2 * pair.b];
      const Eigen::Vector3d p1 = pos(e1[0]), q1 = pos(e1[1]), p2 = pos(e2[0]), q2 = pos(e2[1]);
      double a, b;
      closestSegmentSegment(p1, q1, p2, q2, a, b);
      st.n = 4;
      st.idx[0] = e1[0];
      st.idx[1] = e1[1];
      st.idx[2] = e2[0];
      st.idx[3] = e2[1];
      st.w[0] = 1 - a;
      st.w[1] = a;
      st.w[2] = -(1 - b);
      st.w[3] = -b;
      gap = (p1 + a * (q1 - p1)) - (p2 + b * (q2 - p2));
      fallback = (q1 - p1).cross(q2 - p2);
    }
  }
  st.distance = gap.norm();
  const double scale = fallback.norm();
  if (st.distance > 1e-12 * std::sqrt(scale > 0 ? scale : 1.0)) st.normal = gap / st.distance;
  else if (scale > 0) st.normal = fallback / scale;
  else st.normal = VecD<d>::Unit(d - 1);
  return st;
}

template <int d>
double pairValue(const std::vector<double>& perParticle, const Stencil<d>& st) {
  double h = 0;
  for (int k = 0; k < st.n; ++k) h = std::max(h, perParticle[st.idx[k]]);
  return h;
}

// Changes the pair's relative normal velocity to at least `target` (nothing if already so),
// with Coulomb friction mu on the tangential part; returns whether it acted.
template <int d>
bool applyImpulse(Stencil<d>& st, std::vector<double>& v, const std::vector<double>& invMass, double target,
                  double mu, bool orientAgainstApproach) {
  VecD<d> vr = VecD<d>::Zero();
  double denom = 0;
  for (int k = 0; k < st.n; ++k) {
    vr += st.w[k] * at<d>(v, st.idx[k]);
    denom += st.w[k] * st.w[k] * invMass[st.idx[k]];
  }
  if (!(denom > 0)) return false;
  if (orientAgainstApproach && vr.dot(st.normal) > 0) st.normal = -st.normal;
  const double vn = vr.dot(st.normal);
  if (vn >= target) return false;
  const double dvn = target - vn;
  VecD<d> dvr = dvn * st.normal;
  if (mu > 0) {
    const VecD<d> vt = vr - vn * st.normal;
    const double speed = vt.norm();
    if (speed > 0) dvr -= std::min(mu * dvn, speed) / speed * vt;
  }
  const VecD<d> impulse = dvr / denom;
  for (int k = 0; k < st.n; ++k) {
    const double scale = st.w[k] * invMass[st.idx[k]];
    for (int a = 0; a < d; ++a) v[d * st.idx[k] + a] += scale * impulse(a);
  }
  return true;
}

template <int d>
Box<d> boundsOf(const std::vector<double>& x, const std::vector<double>& v, double dt, const int* idx, int n,
                const std::vector<double>& pad) {
  Box<d> b;
  b.lo = VecD<d>::Constant(std::numeric_limits<double>::infinity());
  b.hi = -b.lo;
  for (int k = 0; k < n; ++k) {
    const VecD<d> p = at<d>(x, idx[k]);
    const VecD<d> q = p + dt * at<d>(v, idx[k]);
    const double h = pad[idx[k]];
    b.lo = b.lo.cwiseMin(p.cwiseMin(q) - VecD<d>::Constant(h));
    b.hi = b.hi.cwiseMax(p.cwiseMax(q) + VecD<d>::Constant(h));
  }
  return b;
}

// Candidate pairs whose boxes (over [x, x + dt v], each particle padded by pad) overlap, in a
// fixed order: points in surface order, each with its faces ascending; then edges, each with the
// later edges ascending. Pairs sharing a particle are left out.
template <int d>
std::vector<Pair> candidatePairs(const CollisionSurface<d>& s, const std::vector<double>& x, const std::vector<double>& v,
                                 double dt, const std::vector<double>& pad) {
  const int nf = s.faceCount(), ne = s.edgeCount(), np = static_cast<int>(s.points.size());
  std::vector<Box<d>> faceBoxes(nf), edgeBoxes(ne);
  parallelIndices(nf, [&](int f) { faceBoxes[f] = boundsOf<d>(x, v, dt, &s.faces[d * f], d, pad); }, kGrain);
  parallelIndices(ne, [&](int e) { edgeBoxes[e] = boundsOf<d>(x, v, dt, &s.edges[2 * e], 2, pad); }, kGrain);
  Bvh<d>& faceTree = s.faceTree;
  Bvh<d>& edgeTree = s.edgeTree;
  faceTree.refit(faceBoxes);
  edgeTree.refit(edgeBoxes);
  std::vector<std::vector<int>> pointHits(np), edgeHits(ne);
  parallelIndices(np, [&](int k) {
    const int i = s.points[k];
    std::vector<int>& hits = pointHits[k];
    faceTree.query(boundsOf<d>(x, v, dt, &i, 1, pad), hits);
    hits.erase(std::remove_if(hits.begin(), hits.end(),
                              [&](int f) {
                                const int* idx = &s.faces[d * f];
                                const int g = s.group[i];
                                return std::find(idx, idx + d, i) != idx + d || (g >= 0 && g == s.group[idx[0]]);
                              }),
               hits.end());
    std::sort(hits.begin(), hits.end());
  }, kGrain);
  parallelIndices(ne, [&](int e) {
    std::vector<int>& hits = edgeHits[e];
    edgeTree.query(edgeBoxes[e], hits);
    const int a0 = s.edges[2 * e], a1 = s.edges[2 * e + 1];
    hits.erase(std::remove_if(hits.begin(), hits.end(),
                              [&](int f) {
                                const int b0 = s.edges[2 * f], b1 = s.edges[2 * f + 1];
                                const int g = s.group[a0];
                                return f <= e || b0 == a0 || b0 == a1 || b1 == a0 || b1 == a1 ||
                                       (g >= 0 && g == s.group[b0]);
                              }),
               hits.end());
    std::sort(hits.begin(), hits.end());
  }, kGrain);
  std::vector<Pair> pairs;
  for (int k = 0; k < np; ++k)
    for (int f : pointHits[k]) pairs.push_back({false, s.points[k], f});
  for (int e = 0; e < ne; ++e)
    for (int f : edgeHits[e]) pairs.push_back({true, e, f});
  return pairs;
}

}  // namespace

// Real roots in [0, 1] of c0 + c1 t + c2 t^2 + c3 t^3, ascending: the interval split at the
// critical points, a sign change in a piece bisected to round-off.
std::vector<double> rootsInUnitInterval(double c0, double c1, double c2, double c3) {
  auto f = [&](double t) { return ((c3 * t + c2) * t + c1) * t + c0; };
  std::vector<double> cuts = {0.0};
  // f' = c1 + 2 c2 t + 3 c3 t^2
  const double A = 3 * c3, B = 2 * c2, C = c1;
  if (A != 0) {
    const double disc = B * B - 4 * A * C;
    if (disc >= 0) {
      const double sq = std::sqrt(disc);
      const double q = -0.5 * (B + (B >= 0 ? sq : -sq));
      double r1 = q / A, r2 = q != 0 ? C / q : r1;
      if (r1 > r2) std::swap(r1, r2);
      if (r1 > 0 && r1 < 1) cuts.push_back(r1);
      if (r2 > 0 && r2 < 1 && r2 != r1) cuts.push_back(r2);
    }
  } else if (B != 0) {
    const double r = -C / B;
    if (r > 0 && r < 1) cuts.push_back(r);
  }
  cuts.push_back(1.0);
  std::vector<double> roots;
  for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
    double lo = cuts[k], hi = cuts[k + 1];
    double flo = f(lo), fhi = f(hi);
    if (flo == 0) {
      if (roots.empty() || roots.back() != lo) roots.push_back(lo);
      continue;
    }
    if (fhi == 0) {
      roots.push_back(hi);
      continue;
    }
    if ((flo < 0) == (fhi < 0)) continue;
    for (int it = 0; it < 100 && hi - lo > 1e-15; ++it) {
      const double mid = 0.5 * (lo + hi);
      const double fm = f(mid);
      if ((fm < 0) == (flo < 0)) {
        lo = mid;
        flo = fm;
      } else {
        hi = mid;
      }
    }
    roots.push_back(0.5 * (lo + hi));
  }
  return roots;
}

namespace {

// The earliest time in [0, 1] at which the pair, moving along x + t dt v, is coplanar (3-D;
// collinear in 2-D) and within `tolerance`; negative if none.
template <int d>
double firstContactTime(const CollisionSurface<d>& s, const Pair& pair, const std::vector<double>& x,
                        const std::vector<double>& v, double dt, double tolerance, bool crossingsOnly = false) {
  int idx[4];
  if (!pair.edges) {
    idx[0] = pair.a;
    for (int k = 0; k < d; ++k) idx[k + 1] = s.faces[d * pair.b + k];
  } else {
    idx[0] = s.edges[2 * pair.a];
    idx[1] = s.edges[2 * pair.a + 1];
    idx[2] = s.edges[2 * pair.b];
    idx[3] = s.edges[2 * pair.b + 1];
  }
  // Relative to particle idx[1] (3-D point-face: the face's first vertex; edge-edge: its own
  // other end is idx[1], so use idx[0] as origin there).
  const int origin = pair.edges ? idx[0] : idx[1];
  const VecD<d> o = at<d>(x, origin), ov = dt * at<d>(v, origin);
  auto rel = [&](int i, VecD<d>& p, VecD<d>& dp) {
    p = at<d>(x, i) - o;
    dp = dt * at<d>(v, i) - ov;
  };
  double c[4] = {0, 0, 0, 0};
  double scale = 0;
  if constexpr (d == 3) {
    Eigen::Vector3d A, dA, B, dB, C, dC;
    if (!pair.edges) {  // (b - a) x (c - a) . (p - a)
      rel(idx[2], A, dA);
      rel(idx[3], B, dB);
      rel(idx[0], C, dC);
    } else {  // (q1 - p1) x (p2 - p1) . (q2 - p1)
      rel(idx[1], A, dA);
      rel(idx[2], B, dB);
      rel(idx[3], C, dC);
    }
    const Eigen::Vector3d AB = A.cross(B), AdB = A.cross(dB) + dA.cross(B), dAdB = dA.cross(dB);
    c[0] = AB.dot(C);
    c[1] = AdB.dot(C) + AB.dot(dC);
    c[2] = dAdB.dot(C) + AdB.dot(dC);
    c[3] = dAdB.dot(dC);
    scale = (A.norm() + dA.norm()) * (B.norm() + dB.norm()) * (C.norm() + dC.norm());
  } else {  // (b - a) x (p - a), a quadratic
    VecD<2> A, dA, C, dC;
    rel(idx[2], A, dA);
    rel(idx[0], C, dC);
    auto cross = [](const VecD<2>& u, const VecD<2>& w) { return u.x() * w.y() - u.y() * w.x(); };
    c[0] = cross(A, C);
    c[1] = cross(dA, C) + cross(A, dC);
    c[2] = cross(dA, dC);
    scale = (A.norm() + dA.norm()) * (C.norm() + dC.norm());
  }
  auto within = [&](double t) {
    auto pos = [&](int i) { return VecD<d>(at<d>(x, i) + t * dt * at<d>(v, i)); };
    return stencilOf<d>(s, pair, pos).distance <= tolerance;
  };
  const double tiny = 1e-12 * scale;
  const bool coplanar =
      std::abs(c[0]) <= tiny && std::abs(c[1]) <= tiny && std::abs(c[2]) <= tiny && std::abs(c[3]) <= tiny;
  if (crossingsOnly) {  // a sign change of the coplanarity function inside the step, nothing else
    if (coplanar) return -1;
    for (double t : rootsInUnitInterval(c[0], c[1], c[2], c[3]))
      if (t > 0 && within(t)) return t;
    return -1;
  }
  if (coplanar) {
    // Coplanar throughout (a flat sheet moving in its plane): check proximity at a few times.
    for (double t : {0.0, 0.25, 0.5, 0.75, 1.0})
      if (within(t)) return t;
    return -1;
  }
  for (double t : rootsInUnitInterval(c[0], c[1], c[2], c[3]))
    if (within(t)) return t;
  return -1;
}

template <int d>
void addEdgesAndPoints(CollisionSurface<d>& s, const std::vector<int>& newFaces, int particleCount, int first,
                       double thickness, double friction, int group) {
  const int base = static_cast<int>(s.thickness.size());
  const int needed = first + particleCount;
  if (base < needed) {
    s.thickness.resize(needed, 0.0);
    s.friction.resize(needed, 0.0);
    s.group.resize(needed, -1);
  }
  std::vector<char> used(particleCount, 0);
  std::vector<std::pair<int, int>> edges;
  const int nf = static_cast<int>(newFaces.size()) / d;
  for (int f = 0; f < nf; ++f) {
    for (int k = 0; k < d; ++k) {
      const int i = newFaces[d * f + k];
      s.faces.push_back(first + i);
      used[i] = 1;
      if constexpr (d == 3) {
        const int j = newFaces[d * f + (k + 1) % d];
        edges.emplace_back(std::min(i, j), std::max(i, j));
      }
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  for (auto [i, j] : edges) {
    s.edges.push_back(first + i);
    s.edges.push_back(first + j);
  }
  for (int i = 0; i < particleCount; ++i)
    if (used[i]) {
      s.points.push_back(first + i);
      s.thickness[first + i] = thickness;
      s.friction[first + i] = friction;
      s.group[first + i] = group;
    }
}

}  // namespace

template <int d>
void addMeshBoundary(CollisionSurface<d>& s, const std::vector<int>& elements, int first, double thickness,
                     double friction, int group) {
  // Faces of one element only, kept with the orientation they have in it.
  std::map<std::vector<int>, std::pair<int, std::vector<int>>> faces;
  const int ne = static_cast<int>(elements.size()) / (d + 1);
  int particleCount = 0;
  for (int i : elements) particleCount = std::max(particleCount, i + 1);
  for (int e = 0; e < ne; ++e)
    for (int skip = 0; skip <= d; ++skip) {
      std::vector<int> f;
      for (int k = 0; k <= d; ++k)
        if (k != skip) f.push_back(elements[(d + 1) * e + k]);
      std::vector<int> key = f;
      std::sort(key.begin(), key.end());
      auto& entry = faces[key];
      ++entry.first;
      entry.second = f;
    }
  std::vector<int> boundary;
  for (const auto& [key, entry] : faces)
    if (entry.first == 1) boundary.insert(boundary.end(), entry.second.begin(), entry.second.end());
  addEdgesAndPoints<d>(s, boundary, particleCount, first, thickness, friction, group);
}

template <int d>
void addFaces(CollisionSurface<d>& s, const std::vector<int>& faces, int first, int particleCount, double thickness,
              double friction, int group) {
  addEdgesAndPoints<d>(s, faces, particleCount, first, thickness, friction, group);
}

template <int d>
ProximityReport repelProximities(const CollisionSurface<d>& s, const std::vector<double>& x, std::vector<double>& v,
                                 const std::vector<double>& inverseMass, double dt, const ProximitySettings& settings) {
  ProximityReport report;
  report.closest = std::numeric_limits<double>::infinity();
  const std::vector<double> zero(v.size(), 0.0);
  const std::vector<Pair> pairs = candidatePairs<d>(s, x, zero, 0.0, s.thickness);
  auto pos = [&](int i) { return at<d>(x, i); };
  for (const Pair& pair : pairs) {
    Stencil<d> st = stencilOf<d>(s, pair, pos);
    const double h = pairValue<d>(s.thickness, st);
    if (st.distance >= h) continue;
    report.closest = std::min(report.closest, st.distance);
    const double target = settings.repulsion * (h - st.distance) / dt;
    if (applyImpulse<d>(st, v, inverseMass, target, pairValue<d>(s.friction, st), st.distance == 0))
      ++report.repulsions;
  }
  return report;
}

namespace {

int zoneRoot(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

// The rigid velocity field v_c + w x (x - x_c) of a set of particles with weights m: their centre
// of mass, linear and angular momentum kept (w = I^{-1} L about the centre; a singular inertia,
// collinear particles, is inverted on its range).
template <int d>
void rigidVelocity(const std::vector<int>& members, const std::vector<double>& weight, const std::vector<double>& x,
                   const std::vector<double>& v, VecD<d>& centre, VecD<d>& linear, Eigen::Vector3d& omega) {
  double mass = 0;
  centre.setZero();
  linear.setZero();
  for (int i : members) {
    mass += weight[i];
    centre += weight[i] * at<d>(x, i);
    linear += weight[i] * at<d>(v, i);
  }
  centre /= mass;
  linear /= mass;
  Eigen::Vector3d L = Eigen::Vector3d::Zero();
  Eigen::Matrix3d I = Eigen::Matrix3d::Zero();
  for (int i : members) {
    Eigen::Vector3d r = Eigen::Vector3d::Zero(), u = Eigen::Vector3d::Zero();
    r.template head<d>() = at<d>(x, i) - centre;
    u.template head<d>() = at<d>(v, i) - linear;
    L += weight[i] * r.cross(u);
    I += weight[i] * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
  }
  omega.setZero();
  if constexpr (d == 2) {
    if (I(2, 2) > 0) omega.z() = L.z() / I(2, 2);
  } else {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(I);
    const double largest = eig.eigenvalues().maxCoeff();
    for (int k = 0; k < 3; ++k) {
      const double lambda = eig.eigenvalues()(k);
      if (lambda > 1e-12 * largest)
        omega += eig.eigenvectors().col(k) * (eig.eigenvectors().col(k).dot(L) / lambda);
    }
  }
}

}  // namespace

// Rigid impact zones (Bridson, Fedkiw, Anderson 2002, Sec. 7.4; Provot 1997), the fail-safe when
// the collision passes leave collisions: the particles of every colliding pair are merged into
// zones (a pair joining two zones merges them), and each zone's particles are given the rigid
// velocity of the zone that keeps its linear and angular momentum. A rigid velocity moves the
// zone's points by the invertible affine map 1 + t dt [w]x over the step, so no pair within a
// zone changes the sign of its coplanarity function: only pairs between zones can still collide,
// and they merge the zones at the next detection, until none is found (or every colliding pair
// lies within one zone). A zone with particles of infinite mass (fixed or bound) moves with their
// rigid velocity (equal weights on them; its free particles take it).
template <int d>
ProximityReport resolveImpactZones(const CollisionSurface<d>& s, const std::vector<double>& x, std::vector<double>& v,
                                   const std::vector<double>& inverseMass, double dt) {
  ProximityReport report;
  std::vector<double> pad(s.thickness.size());
  for (std::size_t i = 0; i < pad.size(); ++i) pad[i] = 1e-3 * s.thickness[i];
  const int n = static_cast<int>(inverseMass.size());
  std::vector<int> parent(n);
  for (int i = 0; i < n; ++i) parent[i] = i;
  std::vector<char> zoned(n, 0);
  std::vector<double> mass(n), pinned(n);
  for (int i = 0; i < n; ++i) {
    mass[i] = inverseMass[i] > 0 ? 1 / inverseMass[i] : 0.0;
    pinned[i] = inverseMass[i] > 0 ? 0.0 : 1.0;
  }
  for (int round = 0; round < n; ++round) {
    // A pair within one zone moves rigidly (it may touch, not cross): only pairs spanning zones
    // count, and each merges its zones.
    int hits = 0;
    for (const Pair& pair : candidatePairs<d>(s, x, v, dt, pad)) {
      auto pos = [&](int i) { return at<d>(x, i); };
      const Stencil<d> st = stencilOf<d>(s, pair, pos);
      bool spans = false;
      for (int k = 1; k < st.n; ++k) spans = spans || zoneRoot(parent, st.idx[k]) != zoneRoot(parent, st.idx[0]);
      if (!spans) continue;
      const double tolerance = std::max(pad[pair.edges ? s.edges[2 * pair.a] : pair.a],
                                        pad[pair.edges ? s.edges[2 * pair.b] : s.faces[d * pair.b]]);
      if (firstContactTime<d>(s, pair, x, v, dt, std::max(tolerance, 1e-12)) < 0) continue;
      ++hits;
      for (int k = 0; k < st.n; ++k) {
        zoned[st.idx[k]] = 1;
        const int a = zoneRoot(parent, st.idx[0]), b = zoneRoot(parent, st.idx[k]);
        if (a != b) parent[std::max(a, b)] = std::min(a, b);
      }
    }
    report.remaining = hits;
    if (hits == 0) break;
    ++report.impactZoneRounds;
    // Members of each zone in particle order, zones in order of their smallest particle.
    std::vector<std::vector<int>> zones(n);
    for (int i = 0; i < n; ++i)
      if (zoned[i]) zones[zoneRoot(parent, i)].push_back(i);
    report.impactZones = 0;
    for (const std::vector<int>& members : zones) {
      if (members.size() < 2) continue;
      ++report.impactZones;
      bool anyPinned = false;
      for (int i : members) anyPinned = anyPinned || pinned[i] > 0;
      VecD<d> centre, linear;
      Eigen::Vector3d omega;
      rigidVelocity<d>(members, anyPinned ? pinned : mass, x, v, centre, linear, omega);
      for (int i : members) {
        if (inverseMass[i] == 0) continue;
        Eigen::Vector3d r = Eigen::Vector3d::Zero();
        r.template head<d>() = at<d>(x, i) - centre;
        const VecD<d> vi = linear + omega.cross(r).template head<d>();
        for (int a = 0; a < d; ++a) v[d * i + a] = vi(a);
      }
    }
  }
  return report;
}

template <int d>
ProximityReport resolveCollisions(const CollisionSurface<d>& s, const std::vector<double>& x, std::vector<double>& v,
                                  const std::vector<double>& inverseMass, double dt, const ProximitySettings& settings) {
  ProximityReport report;
  std::vector<double> pad(s.thickness.size());
  for (std::size_t i = 0; i < pad.size(); ++i) pad[i] = 1e-3 * s.thickness[i];
  for (int pass = 0; pass < settings.collisionPasses; ++pass) {
    const std::vector<Pair> pairs = candidatePairs<d>(s, x, v, dt, pad);
    int hits = 0;
    for (const Pair& pair : pairs) {
      // Within a thousandth of the thickness at a coplanarity time counts as touching.
      const double tolerance = std::max(pad[pair.edges ? s.edges[2 * pair.a] : pair.a],
                                        pad[pair.edges ? s.edges[2 * pair.b] : s.faces[d * pair.b]]);
      const double t = firstContactTime<d>(s, pair, x, v, dt, std::max(tolerance, 1e-12));
      if (t < 0) continue;
      auto pos = [&](int i) { return VecD<d>(at<d>(x, i) + t * dt * at<d>(v, i)); };
      Stencil<d> st = stencilOf<d>(s, pair, pos);
      const double target = settings.separation * pairValue<d>(s.thickness, st) / dt;
      if (applyImpulse<d>(st, v, inverseMass, target, pairValue<d>(s.friction, st), true)) ++hits;
    }
    report.passes = pass + 1;
    report.collisions += hits;
    report.remaining = hits;
    if (hits == 0) break;
  }
  if (report.remaining > 0 && settings.impactZones) {
    const ProximityReport zones = resolveImpactZones<d>(s, x, v, inverseMass, dt);
    report.remaining = zones.remaining;
    report.impactZones = zones.impactZones;
    report.impactZoneRounds = zones.impactZoneRounds;
  }
  return report;
}

template <int d>
int countCollisions(const CollisionSurface<d>& s, const std::vector<double>& x, const std::vector<double>& v, double dt) {
  std::vector<double> pad(s.thickness.size());
  for (std::size_t i = 0; i < pad.size(); ++i) pad[i] = 1e-3 * s.thickness[i];
  int count = 0;
  for (const Pair& pair : candidatePairs<d>(s, x, v, dt, pad))
    if (firstContactTime<d>(s, pair, x, v, dt, 1e-9, true) >= 0) ++count;
  return count;
}

#define MONOLITH_INSTANTIATE(D)                                                                                   \
  template void addMeshBoundary<D>(CollisionSurface<D>&, const std::vector<int>&, int, double, double, int);     \
  template void addFaces<D>(CollisionSurface<D>&, const std::vector<int>&, int, int, double, double, int);       \
  template ProximityReport repelProximities<D>(const CollisionSurface<D>&, const std::vector<double>&,           \
                                               std::vector<double>&, const std::vector<double>&, double,         \
                                               const ProximitySettings&);                                        \
  template ProximityReport resolveCollisions<D>(const CollisionSurface<D>&, const std::vector<double>&,          \
                                                std::vector<double>&, const std::vector<double>&, double,        \
                                                const ProximitySettings&);                                       \
  template ProximityReport resolveImpactZones<D>(const CollisionSurface<D>&, const std::vector<double>&,         \
                                                 std::vector<double>&, const std::vector<double>&, double);      \
  template int countCollisions<D>(const CollisionSurface<D>&, const std::vector<double>&, const std::vector<double>&, \
                                  double);
MONOLITH_INSTANTIATE(2)
MONOLITH_INSTANTIATE(3)
#undef MONOLITH_INSTANTIATE

}  // namespace monolith::solvers::deformable
