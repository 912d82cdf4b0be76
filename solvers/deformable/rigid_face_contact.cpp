#include "solvers/deformable/rigid_face_contact.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>


#include "solvers/collision/collision_impl.h"
#include "solvers/contact/rigid_math.h"
#include "solvers/deformable/face_geometry.h"
#include "solvers/deformable/parallel_indices.h"
#include "solvers/deformable/proximity.h"

namespace monolith::solvers::deformable {

namespace col = solvers::collision;
namespace ct = solvers::contact;

namespace {


template <int d>
using Vec = Eigen::Matrix<double, d, 1>;
template <int d>
using Mat = Eigen::Matrix<double, d, d>;

// Alternating projections from one seed: at most this many face points per seed.
constexpr int kProjections = 4;

// The face point closest to q, with its weights.
template <int d>
Vec<d> closestFacePoint(const Vec<d>* p, const Vec<d>& q, double* weights) {
  if constexpr (d == 3) {
    const Eigen::Vector3d b = closestOnTriangle(q, p[0], p[1], p[2]);
    for (int k = 0; k < 3; ++k) weights[k] = b(k);
    return b(0) * p[0] + b(1) * p[1] + b(2) * p[2];
  } else {
    const double t = closestOnSegment<2>(q, p[0], p[1]);
    weights[0] = 1 - t;
    weights[1] = t;
    return (1 - t) * p[0] + t * p[1];
  }
}

template <int d>
Vec<d> at(const std::vector<double>& x, int i) {
  return Eigen::Map<const Vec<d>>(&x[d * i]);
}

template <int d>
Box<d> faceBox(const std::vector<double>& x, const int* f, double pad) {
  Box<d> b;
  b.lo = b.hi = at<d>(x, f[0]);
  for (int k = 1; k < d; ++k) {
    b.lo = b.lo.cwiseMin(at<d>(x, f[k]));
    b.hi = b.hi.cwiseMax(at<d>(x, f[k]));
  }
  b.lo.array() -= pad;
  b.hi.array() += pad;
  return b;
}

// The impulse j on the face point (minus on the body) that stops an approach u.n < 0, with
// Coulomb friction mu (sticking inside the cone, else sliding on its edge); K the relative
// velocity change per unit impulse.
template <int d>
Vec<d> stoppingImpulse(const Mat<d>& K, const Vec<d>& u, const Vec<d>& n, double mu) {
  const double vn = u.dot(n);
  const Vec<d> stick = K.lu().solve(-u);
  const double jn = stick.dot(n);
  if ((stick - jn * n).norm() <= mu * jn) return stick;
  const Vec<d> ut = u - vn * n;
  const Vec<d> t = ut.norm() > 0 ? Vec<d>(ut.normalized()) : Vec<d>::Zero();
  const Vec<d> dir = n - mu * t;
  const double denom = n.dot(K * dir);
  if (denom > 0) return (-vn / denom) * dir;
  return (-vn / n.dot(K * n)) * n;
}

}  // namespace

template <int d>
FaceContact<d> deepestFacePoint(const RigidFaceBody<d>& body, const Vec<d>* p) {
  FaceContact<d> best;
  best.distance = std::numeric_limits<double>::infinity();
  const col::PreparedGeometry<d>& g = *body.geometry;
  // Distances are needed beyond the contact range while the projections walk: exact out to the
  // body's size (a polytope's value farther than the limit may be a lower bound only).
  const double limit = 4 * g.boundingRadius();
  col::Pose<d> pose;
  pose.x = body.x;
  pose.R = body.R;
  Vec<d> centroid = Vec<d>::Zero();
  for (int k = 0; k < d; ++k) centroid += p[k] / d;
  thread_local std::vector<col::FeaturePoint<d>> seeds;
  seeds.clear();
  seeds.push_back({body.x, 0.0});
  col::featurePoints<d>(g, pose, Vec<d>(centroid - body.x), seeds);
  double w[d];
  for (const auto& seed : seeds) {
    Vec<d> target = seed.x;
    for (int it = 0; it < kProjections; ++it) {
      const Vec<d> q = closestFacePoint<d>(p, target, w);
      const col::SurfaceDistance<d> s = col::signedDistance<d>(g, Vec<d>(body.R.transpose() * (q - body.x)), limit);
      if (s.distance < best.distance) {
        best.distance = s.distance;
        best.point = q;
        best.normal = body.R * s.normal;
        std::copy(w, w + d, best.weights);
      }
      const Vec<d> next = body.R * s.surfacePoint + body.x;
      if ((next - target).squaredNorm() <= 1e-24 * (1 + next.squaredNorm())) break;
      target = next;
    }
  }
  return best;
}

// The pair's thickness and friction: the largest over the face's particles and the body's friction.
template <int d>
void faceMaterial(const FaceSet<d>& faces, const int* idx, double bodyFriction, FaceContact<d>& c) {
  c.thickness = 0;
  c.friction = bodyFriction;
  for (int a = 0; a < d; ++a) {
    c.thickness = std::max(c.thickness, (*faces.thickness)[idx[a]]);
    c.friction = std::max(c.friction, (*faces.friction)[idx[a]]);
  }
}

// The bodies' (body, face) candidate pairs from `tree`: each bounded, non-mesh body's query box
// (half-spaces are left to the particle contact, whose deepest point in a flat face is one of
// its vertices; meshes have no inside), in body order, faces ascending.
template <int d, class QueryBox>
void candidatePairs(const std::vector<RigidFaceBody<d>>& bodies, Bvh<d>& tree, FaceContactWorkspace<d>& work,
                    QueryBox queryBox) {
  work.pairs.clear();
  for (int bi = 0; bi < static_cast<int>(bodies.size()); ++bi) {
    const RigidFaceBody<d>& body = bodies[bi];
    if (body.geometry->unbounded() || body.geometry->geometry().type == col::GeometryType::Mesh) continue;
    Box<d> query;
    if (!queryBox(body, query)) continue;
    work.hits.clear();
    tree.query(query, work.hits);
    std::sort(work.hits.begin(), work.hits.end());
    for (int face : work.hits) work.pairs.emplace_back(bi, face);
  }
}

template <int d>
void findFaceContacts(const std::vector<RigidFaceBody<d>>& bodies, const FaceSet<d>& faces, Bvh<d>& tree,
                      FaceContactWorkspace<d>& work, std::vector<FaceContact<d>>& out) {
  const int nf = faces.faceCount();
  const std::vector<int>& f = *faces.faces;
  work.boxes.resize(nf);
  parallelIndices(nf, [&](int k) {
    double pad = 0;
    for (int a = 0; a < d; ++a) pad = std::max(pad, (*faces.thickness)[f[d * k + a]]);
    work.boxes[k] = faceBox<d>(*faces.x, &f[d * k], pad);
  });
  if (static_cast<int>(tree.size()) != nf) tree.build(work.boxes);
  else tree.refit(work.boxes);
  // The candidate pairs serially (a few BVH queries, one per body).
  candidatePairs<d>(bodies, tree, work, [](const RigidFaceBody<d>& body, Box<d>& query) {
    col::Pose<d> pose;
    pose.x = body.x;
    pose.R = body.R;
    const auto bounds = col::worldBounds<d>(*body.geometry, pose);
    query.lo = bounds.min();
    query.hi = bounds.max();
    return true;
  });
  // The deepest point of every pair, the costly part, in parallel into its own slot.
  const int np = static_cast<int>(work.pairs.size());
  work.slots.resize(np);
  work.close.assign(np, 0);
  parallelIndices(np, [&](int k) {
    const auto [bi, face] = work.pairs[k];
    Vec<d> p[d];
    for (int a = 0; a < d; ++a) p[a] = at<d>(*faces.x, f[d * face + a]);
    FaceContact<d> c = deepestFacePoint<d>(bodies[bi], p);
    faceMaterial<d>(faces, &f[d * face], bodies[bi].friction, c);
    if (!(c.distance < c.thickness)) return;
    c.body = bi;
    c.face = face;
    work.slots[k] = c;
    work.close[k] = 1;
  });
  out.clear();
  for (int k = 0; k < np; ++k)
    if (work.close[k]) out.push_back(work.slots[k]);
}

template <int d>
std::vector<FaceContact<d>> findFaceContacts(const std::vector<RigidFaceBody<d>>& bodies, const FaceSet<d>& faces,
                                             Bvh<d>& tree) {
  FaceContactWorkspace<d> work;
  std::vector<FaceContact<d>> out;
  findFaceContacts<d>(bodies, faces, tree, work, out);
  return out;
}

template <int d>
void findSweptFaceContacts(const std::vector<RigidFaceBody<d>>& bodies, const FaceSet<d>& faces,
                           const std::vector<double>& start, double dt, std::vector<FaceContact<d>>& discrete,
                           Bvh<d>& tree, FaceContactWorkspace<d>& work, std::vector<FaceContact<d>>& out) {
  out.clear();
  if constexpr (d == 3) {
    const int nf = faces.faceCount();
    const std::vector<int>& f = *faces.faces;
    const std::vector<double>& end = *faces.x;
    work.boxes.resize(nf);
    parallelIndices(nf, [&](int k) {
      Box<d> a = faceBox<d>(start, &f[d * k], 0.0), b = faceBox<d>(end, &f[d * k], 0.0);
      a.lo = a.lo.cwiseMin(b.lo);
      a.hi = a.hi.cwiseMax(b.hi);
      work.boxes[k] = a;
    });
    if (static_cast<int>(tree.size()) != nf) tree.build(work.boxes);
    else tree.refit(work.boxes);
    candidatePairs<d>(bodies, tree, work, [&](const RigidFaceBody<d>& body, Box<d>& query) {
      query.lo = body.x.cwiseMin(Vec<d>(body.x - dt * body.v));
      query.hi = body.x.cwiseMax(Vec<d>(body.x - dt * body.v));
      return body.v.squaredNorm() > 0;
    });
    const int np = static_cast<int>(work.pairs.size());
    work.slots.resize(np);
    work.close.assign(np, 0);
    parallelIndices(np, [&](int k) {
      const auto [bi, face] = work.pairs[k];
      const RigidFaceBody<d>& body = bodies[bi];
      const int* idx = &f[d * face];
      // Relative to the face's first vertex: (B - A) x (C - A) . (P - A) as a cubic in t.
      const Vec<d> o = at<d>(start, idx[0]), od = at<d>(end, idx[0]) - o;
      const Vec<d> A = at<d>(start, idx[1]) - o, dA = at<d>(end, idx[1]) - at<d>(start, idx[1]) - od;
      const Vec<d> B = at<d>(start, idx[2]) - o, dB = at<d>(end, idx[2]) - at<d>(start, idx[2]) - od;
      const Vec<d> centre0 = body.x - dt * body.v;
      const Vec<d> C = centre0 - o, dC = dt * body.v - od;
      const Vec<d> AB = A.cross(B), AdB = A.cross(dB) + dA.cross(B), dAdB = dA.cross(dB);
      const double scale = (A.norm() + dA.norm()) * (B.norm() + dB.norm()) * (C.norm() + dC.norm());
      const double c0 = AB.dot(C), c1 = AdB.dot(C) + AB.dot(dC), c2 = dAdB.dot(C) + AdB.dot(dC), c3 = dAdB.dot(dC);
      if (std::abs(c0) <= 1e-12 * scale) return;  // starts in the face's plane: the discrete test's case
      for (double t : rootsInUnitInterval(c0, c1, c2, c3)) {
        if (t <= 0) continue;
        Vec<d> p[d];
        for (int a = 0; a < d; ++a) p[a] = at<d>(start, idx[a]) + t * (at<d>(end, idx[a]) - at<d>(start, idx[a]));
        const Vec<d> centre = centre0 + t * dt * body.v;
        const Eigen::Vector3d w = closestOnTriangle(centre, p[0], p[1], p[2]);
        const Vec<d> q = w(0) * p[0] + w(1) * p[1] + w(2) * p[2];
        if ((q - centre).norm() > 1e-9 * (1 + centre.norm())) continue;  // crosses the plane beside the face
        FaceContact<d> c;
        c.body = bi;
        c.face = face;
        c.point = Vec<d>::Zero();
        for (int a = 0; a < d; ++a) {
          c.weights[a] = w(a);
          c.point += w(a) * at<d>(end, idx[a]);
        }
        Vec<d> n = (at<d>(start, idx[1]) - at<d>(start, idx[0])).cross(at<d>(start, idx[2]) - at<d>(start, idx[0]));
        if (n.dot(centre0 - at<d>(start, idx[0])) > 0) n = -n;  // out of the body: towards the far side
        c.normal = n.normalized();
        c.distance = 0;
        faceMaterial<d>(faces, idx, body.friction, c);
        work.slots[k] = c;
        work.close[k] = 1;
        return;
      }
    });
    for (int k = 0; k < np; ++k)
      if (work.close[k]) out.push_back(work.slots[k]);
    // A crossing pair's discrete contact is dropped: at the candidate positions the centre is
    // already past the face, and that contact's normal would push the body on through.
    discrete.erase(std::remove_if(discrete.begin(), discrete.end(),
                                  [&](const FaceContact<d>& c) {
                                    for (const FaceContact<d>& s : out)
                                      if (s.body == c.body && s.face == c.face) return true;
                                    return false;
                                  }),
                   discrete.end());
  }
}

template <int d>
int applyFaceContactImpulses(std::vector<RigidFaceBody<d>>& bodies, FaceSet<d>& faces,
                             const std::vector<FaceContact<d>>& contacts, int sweeps) {
  const std::vector<int>& f = *faces.faces;
  std::vector<double>& v = *faces.v;
  const std::vector<double>& w = *faces.inverseMass;
  int impulses = 0;
  const int n = static_cast<int>(contacts.size());
  for (int sweep = 0; sweep < sweeps; ++sweep) {
    for (int k = 0; k < n; ++k) {
      const FaceContact<d>& c = contacts[sweep % 2 == 0 ? k : n - 1 - k];
      RigidFaceBody<d>& b = bodies[c.body];
      const int* idx = &f[d * c.face];
      double faceInverseMass = 0;
      Vec<d> faceV = Vec<d>::Zero();
      for (int a = 0; a < d; ++a) {
        faceInverseMass += c.weights[a] * c.weights[a] * w[idx[a]];
        faceV += c.weights[a] * at<d>(v, idx[a]);
      }
      const Vec<d> r = c.point - b.x;
      const Vec<d> u = faceV - (b.v + ct::angularCross<d>(b.omega, r));
      if (u.dot(c.normal) >= 0) continue;
      Mat<d> K = faceInverseMass * Mat<d>::Identity();
      for (int a = 0; a < d; ++a) {
        const Vec<d> e = Vec<d>::Unit(a);
        K.col(a) += b.inverseMass * e + ct::angularCross<d>(AngularD<d>(b.inverseInertia * ct::cross<d>(r, e)), r);
      }
      if (!(K.norm() > 0)) continue;  // both sides immovable
      const Vec<d> j = stoppingImpulse<d>(K, u, c.normal, c.friction);
      for (int a = 0; a < d; ++a)
        Eigen::Map<Vec<d>>(&v[d * idx[a]]) += (c.weights[a] * w[idx[a]]) * j;
      if (b.inverseMass > 0) {
        b.v -= b.inverseMass * j;
        b.omega -= b.inverseInertia * ct::cross<d>(r, j);
        b.impulse -= j;
        b.angularImpulse -= ct::cross<d>(r, j);
      }
      ++impulses;
    }
  }
  return impulses;
}

template <int d>
double pushFacesOut(const std::vector<FaceContact<d>>& contacts, const std::vector<int>& faces,
                    const std::vector<double>& inverseMass, std::vector<double>& x) {
  double deepest = 0;
  for (const FaceContact<d>& c : contacts) {
    const int* idx = &faces[d * c.face];
    // The point's depth now: faces pushed before this one may have moved its particles already.
    Vec<d> q = Vec<d>::Zero();
    double weight = 0;
    for (int a = 0; a < d; ++a) {
      q += c.weights[a] * at<d>(x, idx[a]);
      weight += c.weights[a] * c.weights[a] * inverseMass[idx[a]];
    }
    const double depth = -(c.distance + (q - c.point).dot(c.normal));
    if (depth <= 0 || weight <= 0) continue;
    deepest = std::max(deepest, depth);
    for (int a = 0; a < d; ++a)
      Eigen::Map<Vec<d>>(&x[d * idx[a]]) += (c.weights[a] * inverseMass[idx[a]] / weight * depth) * c.normal;
  }
  return deepest;
}

#define MONOLITH_INSTANTIATE(D)                                                                                   \
  template FaceContact<D> deepestFacePoint<D>(const RigidFaceBody<D>&, const Vec<D>*);                            \
  template std::vector<FaceContact<D>> findFaceContacts<D>(const std::vector<RigidFaceBody<D>>&, const FaceSet<D>&, \
                                                           Bvh<D>&);                                              \
  template void findFaceContacts<D>(const std::vector<RigidFaceBody<D>>&, const FaceSet<D>&, Bvh<D>&,              \
                                    FaceContactWorkspace<D>&, std::vector<FaceContact<D>>&);                      \
  template void findSweptFaceContacts<D>(const std::vector<RigidFaceBody<D>>&, const FaceSet<D>&,                 \
                                         const std::vector<double>&, double, std::vector<FaceContact<D>>&,         \
                                         Bvh<D>&, FaceContactWorkspace<D>&, std::vector<FaceContact<D>>&);         \
  template int applyFaceContactImpulses<D>(std::vector<RigidFaceBody<D>>&, FaceSet<D>&,                           \
                                           const std::vector<FaceContact<D>>&, int);                              \
  template double pushFacesOut<D>(const std::vector<FaceContact<D>>&, const std::vector<int>&,                    \
                                  const std::vector<double>&, std::vector<double>&);
MONOLITH_INSTANTIATE(2)
MONOLITH_INSTANTIATE(3)
#undef MONOLITH_INSTANTIATE

}  // namespace monolith::solvers::deformable
