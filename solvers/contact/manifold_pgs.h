#pragma once
// Projected Gauss-Seidel on one small contact problem (docs/architecture.md "One pair
// update"): the points of a pair's manifold, or of one body against its frozen partners in shock
// propagation, on accumulated impulses (normal >= 0, friction inside the Coulomb disk).
//
// Written in Jacobian form: each point keeps r x n, r x t_k and I^{-1} (r x n), I^{-1} (r x t_k)
// of both bodies, prepared once per solve, so a sweep step is a few dot products and
// multiply-adds. It is the same iteration as applying j at the point and re-evaluating
// v_rel = v_a + w_a x r_a - v_b - w_b x r_b, since (w x r).u = w.(r x u) and
// I^{-1}(r x j) = sum_k j_k I^{-1}(r x u_k); only the rounding differs. The sweeps are the hot
// loop of the contact stages (up to 10 per solve, ~56 solves per pair and step).
#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products
#include <Eigen/LU>        // the 2x2 tangent mass inverse
#include <algorithm>
#include <cmath>
#include <vector>

#include "solvers/contact/manifold_polish.h"
#include "solvers/contact/rigid_math.h"

namespace monolith::solvers::contact {

template <int d>
struct PgsPoint {
  using VecD = Vec<d>;
  using TangentBasis = Eigen::Matrix<double, d, d - 1>;
  using TangentVec = Eigen::Matrix<double, d - 1, 1>;
  using TangentMat = Eigen::Matrix<double, d - 1, d - 1>;
  using AngTangent = Eigen::Matrix<double, kAngularDim<d>, d - 1>;

  // Fields a solve writes before it reads them (the tangent basis, K's blocks, the Jacobian rows,
  // the offsets) have no initial value: a contact update builds thousands of points a step, and
  // zeroing the ~90 numbers of each was 4 % of pyramid_20's step. The constructor is written
  // out so that `points.emplace_back()` does not zero them either (value-initialisation does,
  // for a class whose default constructor the compiler defines).
  PgsPoint() {}

  VecD ra = VecD::Zero(), rb = VecD::Zero(), n = VecD::Zero();  // lever arms, normal out of b
  Mat<d> K;                   // K_a + K_b at the point (impulse.h): prepareOnePoint only
  double target = 0, mu = 0;  // target normal velocity, Coulomb coefficient
  // Normal impulse the point's friction may lean on beyond its own: the Coulomb disk's radius is
  // mu (lambda + frictionPreload). Shock propagation sets it from what the pair carried earlier
  // in the stage (ManifoldProblem::solve); otherwise 0, the plain Coulomb law.
  double frictionPreload = 0;
  // Constant velocity of the partner at the point (joint solve against frozen bodies), else 0.
  VecD partnerVelocity = VecD::Zero();
  // Accumulated impulses.
  double normalImpulse = 0;
  TangentVec tangentImpulse = TangentVec::Zero();
  // Where the exact finish starts (manifold_polish.h): a state, and a sliding point's friction
  // direction; Unknown: guessed from the velocities.
  PointState startState = PointState::Unknown;
  TangentVec startDirection = TangentVec::UnitX();

  // Prepared by prepare(): tangent basis, K's normal and tangent-plane blocks, Jacobian rows.
  TangentBasis T;
  double kn, inverseKn;
  TangentVec TKn;  // T^T K n: tangent velocity per unit normal impulse
  TangentMat tangentMass;
  double inverseTangentMassNorm2;  // 1 / |tangentMass|_F^2
  // Ktt = T^T K T = Q diag(tangentStiffness) Q^T, Q = [(c, s), (-s, c)] in 3-D (1 x 1 in 2-D):
  // the metric of the friction projection (projectFriction).
  double tangentStiffness[d - 1];
  double eigenCos, eigenSin;
  AngVec<d> raN, rbN, IaRaN, IbRbN;
  AngTangent raT, rbT, IaRaT, IbRbT;
  double biasN;      // n . partnerVelocity
  TangentVec biasT;  // T^T partnerVelocity
  // Set by pgsOffsets: the constant part of the relative normal and tangent velocities.
  double offsetN;
  TangentVec offsetT;
  // What prepareRows leaves for prepareSweeps.
  double inverseMasses_;
  // Initialised: a growing vector copies its points, and copying an unset bool is undefined.
  bool rotatesA_ = false, rotatesB_ = false;

  // inverseMasses: m_a^{-1} + m_b^{-1}; Ia, Ib: the inverse inertias the impulses are applied
  // with (zero for a body of infinite mass). K's blocks come from the Jacobian rows:
  // u.K v = (m_a^{-1} + m_b^{-1}) u.v + (r_a x u).I_a^{-1}(r_a x v) + (r_b x u).I_b^{-1}(r_b x v),
  // with T^T n = 0 and T^T T = 1 (K itself, 3x3, only for a one-point manifold: prepareOnePoint).
  void prepare(double inverseMasses, const AngMat<d>& Ia, const AngMat<d>& Ib) {
    prepareRows(inverseMasses, Ia, Ib);
    prepareSweeps();
  }
  // The Jacobian rows and what the exact finish needs (manifold_polish.h).
  void prepareRows(double inverseMasses, const AngMat<d>& Ia, const AngMat<d>& Ib) {
    prepareRows(inverseMasses, Ia, Ib, !Ia.isZero(0), !Ib.isZero(0));
  }
  // The same with whether each inverse inertia is non-zero given (a solve tells once for all its
  // points). A body of infinite mass (zero inverse inertia) adds nothing to K: its terms are
  // skipped and its I^{-1}(r x u) are zero.
  void prepareRows(double inverseMasses, const AngMat<d>& Ia, const AngMat<d>& Ib, bool rotatesA, bool rotatesB) {
    setTangentBasis();
    rotatesA_ = rotatesA, rotatesB_ = rotatesB;
    inverseMasses_ = inverseMasses;
    raN = crossOf(ra, n);
    rbN = crossOf(rb, n);
    if (rotatesA_) IaRaN = Ia * raN;
    else IaRaN.setZero();
    if (rotatesB_) IbRbN = Ib * rbN;
    else IbRbN.setZero();
    biasN = n.dot(partnerVelocity);
    for (int k = 0; k < d - 1; ++k) {
      raT.col(k) = crossOf(ra, T.col(k));
      rbT.col(k) = crossOf(rb, T.col(k));
      if (rotatesA_) IaRaT.col(k) = Ia * raT.col(k);
      else IaRaT.col(k).setZero();
      if (rotatesB_) IbRbT.col(k) = Ib * rbT.col(k);
      else IbRbT.col(k).setZero();
      biasT[k] = T.col(k).dot(partnerVelocity);
    }
  }
  // What a solve needs before it starts: with the exact finish, which may end it before any
  // sweep, only the rows (pgsSweeps prepares the rest if it sweeps: PgsBodies::sweepsPrepared).
  void prepareForSolve(bool exactFinish, double inverseMasses, const AngMat<d>& Ia, const AngMat<d>& Ib) {
    prepareForSolve(exactFinish, inverseMasses, Ia, Ib, !Ia.isZero(0), !Ib.isZero(0));
  }
  void prepareForSolve(bool exactFinish, double inverseMasses, const AngMat<d>& Ia, const AngMat<d>& Ib,
                       bool rotatesA, bool rotatesB) {
    prepareRows(inverseMasses, Ia, Ib, rotatesA, rotatesB);
    if (!exactFinish) prepareSweeps();
  }
  // K's normal and tangent-plane blocks, which only the sweeps use (after prepareRows). A solve
  // that the exact finish ends before its first sweep never needs them.
  void prepareSweeps() {
    kn = inverseMasses_;
    if (rotatesA_) kn += raN.dot(IaRaN);
    if (rotatesB_) kn += rbN.dot(IbRbN);
    inverseKn = 1 / kn;
    TangentMat Ktt = inverseMasses_ * TangentMat::Identity();
    for (int k = 0; k < d - 1; ++k) {
      TKn[k] = 0;
      if (rotatesA_) TKn[k] += raT.col(k).dot(IaRaN);
      if (rotatesB_) TKn[k] += rbT.col(k).dot(IbRbN);
    }
    for (int k = 0; k < d - 1; ++k)
      for (int l = 0; l < d - 1; ++l) {
        if (rotatesA_) Ktt(k, l) += raT.col(k).dot(IaRaT.col(l));
        if (rotatesB_) Ktt(k, l) += rbT.col(k).dot(IbRbT.col(l));
      }
    tangentMass = Ktt.inverse();
    if constexpr (d == 3) {
      // Eigen-decomposition of the symmetric 2 x 2 Ktt in closed form (the rotation by theta
      // with cos 2 theta = (a - c) / 2r, sin 2 theta = b / r), without trigonometric calls.
      const double a = Ktt(0, 0), b = Ktt(0, 1), c = Ktt(1, 1);
      const double half = 0.5 * (a - c), r = std::sqrt(half * half + b * b);
      if (r > 0) {
        const double cos2 = half / r;
        eigenCos = std::sqrt(0.5 * (1 + cos2));
        eigenSin = std::copysign(std::sqrt(0.5 * (1 - cos2)), b);
      } else {
        eigenCos = 1;
        eigenSin = 0;
      }
      tangentStiffness[0] = 0.5 * (a + c) + r;
      tangentStiffness[1] = 0.5 * (a + c) - r;
    } else {
      tangentStiffness[0] = Ktt(0, 0);
    }
    inverseTangentMassNorm2 = 1 / tangentMass.squaredNorm();
  }
  // What a one-point manifold's closed-form impulse (impulse.h) needs, and nothing else: the
  // tangent basis and K. The Jacobian rows and the tangent-plane blocks are the sweeps' (about
  // 10 % of a sphere pour's time went into preparing them for points that never swept).
  void prepareOnePoint(double inverseMasses, const AngMat<d>& Ia, const AngMat<d>& Ib) {
    setTangentBasis();
    setK(inverseMasses, Ia, Ib);
  }
  void setTangentBasis() {
    if constexpr (d == 3) {
      const VecD t1 = (std::abs(n.x()) < 0.6 ? VecD::UnitX() : VecD::UnitY()).cross(n).normalized();
      T.col(0) = t1;
      T.col(1) = n.cross(t1);
    } else {
      T.col(0) = VecD(-n.y(), n.x());
    }
  }
  void setK(double inverseMasses, const AngMat<d>& Ia, const AngMat<d>& Ib) {
    const CrossMat<d> ca = crossMatrix<d>(ra), cb = crossMatrix<d>(rb);
    K = inverseMasses * Mat<d>::Identity() + ca.transpose() * Ia * ca + cb.transpose() * Ib * cb;
  }
  static AngVec<d> crossOf(const VecD& r, const VecD& u) {
    if constexpr (d == 3) return r.cross(u);
    else return AngVec<d>(r.x() * u.y() - r.y() * u.x());
  }
  VecD impulse() const { return normalImpulse * n + T * tangentImpulse; }
};

// The two bodies' working velocities during a solve; b is absent (zero, not moving) in the
// joint solve against frozen partners, whose velocities enter as PgsPoint::partnerVelocity.
template <int d>
struct PgsBodies {
  Vec<d> va = Vec<d>::Zero(), vb = Vec<d>::Zero();
  AngVec<d> wa = AngVec<d>::Zero(), wb = AngVec<d>::Zero();
  double inverseMassA = 0, inverseMassB = 0;
  // The inverse inertias the points were prepared with (PgsPoint::prepare's Ia, Ib).
  AngMat<d> inverseInertiaA = AngMat<d>::Zero(), inverseInertiaB = AngMat<d>::Zero();
  bool movesA = false, movesB = false;  // bodies of infinite mass take no impulse
  // Finish with the exact active-set step of manifold_polish.h once it applies (tried before
  // the first sweep, then after sweeps 3, 6, 12, 24, ...); off: sweeps only, to the stop test
  // or the sweep limit.
  bool exactFinish = false;
  // The points had only prepareRows (exact finish): pgsSweeps prepares the rest before sweeping.
  bool sweepsPrepared = true;
  // The switch above and what it means for the points (PgsPoint::prepareForSolve).
  void setExactFinish(bool on) {
    exactFinish = on;
    sweepsPrepared = !on;
  }
};

// Part of the relative velocity at p that no impulse of this solve changes: the partner's
// velocity, and the velocity of a body that does not move (folded in once per solve).
template <int d>
void pgsOffsets(PgsPoint<d>& p, const PgsBodies<d>& s) {
  p.offsetN = -p.biasN;
  p.offsetT = -p.biasT;
  if (!s.movesA) {
    p.offsetN += p.n.dot(s.va) + p.raN.dot(s.wa);
    p.offsetT += p.T.transpose() * s.va + p.raT.transpose() * s.wa;
  }
  if (!s.movesB) {
    p.offsetN -= p.n.dot(s.vb) + p.rbN.dot(s.wb);
    p.offsetT -= p.T.transpose() * s.vb + p.rbT.transpose() * s.wb;
  }
}

// Friction at a point whose sticking impulse f (on entry) lies outside the Coulomb disk
// |f| <= limit: the impulse in the disk that leaves the least tangential slip energy,
//   argmin over |f'| <= limit of (f' - f)^T Ktt (f' - f),
// since the slip it leaves is v_t + Ktt (f' - f_old) = Ktt (f' - f). Its optimality condition
// makes that slip anti-parallel to f' -- the friction opposes the sliding it leaves, Coulomb's
// maximal dissipation -- and, being a projection, it cannot overshoot. Solution:
// f' = (Ktt + g I)^{-1} Ktt f with g >= 0 the root of 1/|f'(g)| = 1/limit, found by Newton's
// method on that nearly linear function (the trust-region secular equation; exact at once when
// Ktt is isotropic, 1-3 steps otherwise, stopping once the radius is right to 1e-7: after the
// final rescaling onto the rim that leaves a direction error of that order). 2-D: a clamp.
//
// The earlier rule, friction of the full size -limit v_t/|v_t| along the slip before the step,
// is an explicit guess of that direction. A point of a pair update carries only that update's
// share of the load, so its disk is small and hit on most steps, and where the slip is tiny and
// of arbitrary direction (bodies at rest) the guess flipped the friction from sweep to sweep:
// pyramid_20 needed 8 epsilon-ramped shock propagation passes to stand and collapsed with 1 or
// 2 (the git history of docs/benchmarks.md ("A friction step that cannot overshoot")). Scaling f radially onto the
// disk instead is stable but, with the rotational coupling in Ktt, slides a cube down an incline
// 7 % too far and 17 cm sideways in 2 s.
template <int d>
inline void projectFriction(const PgsPoint<d>& p, double* f, double limit) {
  if (!(limit > 0)) {
    for (int k = 0; k < d - 1; ++k) f[k] = 0;
    return;
  }
  if constexpr (d == 2) {
    f[0] = f[0] > 0 ? limit : -limit;
  } else {
    const double c = p.eigenCos, s = p.eigenSin;
    const double k0 = p.tangentStiffness[0], k1 = p.tangentStiffness[1];
    // Worked on f / |f| with the disk's radius rho = limit / |f| < 1, so that neither a tiny
    // load nor a tiny f under- or overflows: Ktt f / |f| in Ktt's eigenbasis, (a0, a1); f' there
    // is |f| (a0 / (k0 + g), a1 / (k1 + g)).
    const double inverseSize = 1 / std::sqrt(f[0] * f[0] + f[1] * f[1]), rho = limit * inverseSize;
    const double x0 = (c * f[0] + s * f[1]) * inverseSize, x1 = (-s * f[0] + c * f[1]) * inverseSize;
    const double a0 = k0 * x0, a1 = k1 * x1;
    // Start at the root for an isotropic Ktt of the a-weighted mean stiffness.
    const double w0 = std::abs(a0), w1 = std::abs(a1);
    const double mean = (k0 * w0 + k1 * w1) / (w0 + w1);
    double g = std::max(0.0, std::sqrt(a0 * a0 + a1 * a1) / rho - mean);
    double h0 = a0, h1 = a1;  // g >> Ktt (a disk far smaller than f): f' is along Ktt f
    if (g < 1e8 * (k0 + k1)) {
      for (int it = 0; it < 16; ++it) {
        const double e0 = 1 / (k0 + g), e1 = 1 / (k1 + g);
        const double n2 = a0 * a0 * e0 * e0 + a1 * a1 * e1 * e1;
        const double norm = std::sqrt(n2);
        const double psi = 1 / norm - 1 / rho;
        if (std::abs(psi) * rho <= 1e-7) break;
        const double dpsi = (a0 * a0 * e0 * e0 * e0 + a1 * a1 * e1 * e1 * e1) / (n2 * norm);
        g = std::max(0.0, g - psi / dpsi);
      }
      h0 = a0 / (k0 + g);
      h1 = a1 / (k1 + g);
    }
    const double rim = limit / std::sqrt(h0 * h0 + h1 * h1);  // exactly on the disk's rim
    h0 *= rim;
    h1 *= rim;
    f[0] = c * h0 - s * h1;
    f[1] = s * h0 + c * h1;
  }
}

// One step at point p: the increments of the accumulated impulses, applied to the moving
// bodies' velocities (local copies, so they stay in registers: the step is short and the sweep
// is a chain of dependent steps, which is what bounds its speed, hence also the reciprocals and
// squares prepared once to keep divisions and square roots off that chain). Returns the square
// of the size of the velocity change, for the convergence test. Normal: accumulated impulse >= 0
// reaching the target normal velocity. Friction: the sticking step in the tangent plane (the
// point velocity after the normal change is v_rel + K n dl), limited to the Coulomb disk
// |f| <= mu lambda by projectFriction (maximal dissipation).
//
// Written on scalars: with Eigen's 2-vectors for the tangent components GCC assembled each from
// two scalar stores and one packed load, a stalled store-to-load forward twice per step (about
// 30% of the sweeps' samples in perf).
template <int d, bool movesA, bool movesB>
[[gnu::always_inline]] inline double pgsStep(PgsPoint<d>& p, double inverseMassA, double inverseMassB, Vec<d>& va,
                                             AngVec<d>& wa, Vec<d>& vb, AngVec<d>& wb) {
  constexpr int m = d - 1;  // tangent directions
  // Relative velocity along the Jacobian row (u, r_a x u, r_b x u).
  Vec<d> dv;
  if constexpr (movesA && movesB) dv = va - vb;
  else if constexpr (movesA) dv = va;
  else dv = -vb;
  auto along = [&](const auto& u, const auto& raU, const auto& rbU) {
    double v = u.dot(dv);
    if constexpr (movesA) v += raU.dot(wa);
    if constexpr (movesB) v -= rbU.dot(wb);
    return v;
  };
  const double vn = p.offsetN + along(p.n, p.raN, p.rbN);
  const double lambda = std::max(0.0, p.normalImpulse + (p.target - vn) * p.inverseKn);
  // A point that carries nothing and stays unloaded (separating): the Coulomb disk has radius 0,
  // so the step below would change nothing; skip it.
  bool unloaded = lambda == 0 && p.normalImpulse == 0 && p.frictionPreload == 0;
  for (int k = 0; k < m; ++k) unloaded = unloaded && p.tangentImpulse[k] == 0;
  if (unloaded) return 0.0;
  const double dl = lambda - p.normalImpulse;
  p.normalImpulse = lambda;
  double change2 = dl * dl * (p.kn * p.kn);
  double df[m] = {};
  if (p.mu > 0) {
    double vt[m], f[m];
    for (int k = 0; k < m; ++k) vt[k] = p.offsetT[k] + along(p.T.col(k), p.raT.col(k), p.rbT.col(k)) + p.TKn[k] * dl;
    double f2 = 0;
    for (int k = 0; k < m; ++k) {
      f[k] = p.tangentImpulse[k];
      for (int l = 0; l < m; ++l) f[k] -= p.tangentMass(k, l) * vt[l];
      f2 += f[k] * f[k];
    }
    const double limit = p.mu * (lambda + p.frictionPreload);
    if (f2 > limit * limit) projectFriction<d>(p, f, limit);
    double df2 = 0;
    for (int k = 0; k < m; ++k) {
      df[k] = f[k] - p.tangentImpulse[k];
      p.tangentImpulse[k] = f[k];
      df2 += df[k] * df[k];
    }
    change2 = std::max(change2, df2 * p.inverseTangentMassNorm2);
  }
  applyImpulseChange<d, movesA, movesB>(p, dl, df, inverseMassA, inverseMassB, va, wa, vb, wb);
  return change2;
}

template <int d, bool movesA, bool movesB>
void pgsSweeps(std::vector<PgsPoint<d>>& points, PgsBodies<d>& s, int iterations, double tolerance) {
  const double tolerance2 = tolerance * tolerance;
  Vec<d> va = s.va, vb = s.vb;
  AngVec<d> wa = s.wa, wb = s.wb;
  int nextFinish = 3;
  if (s.exactFinish && polishManifold<d, movesA, movesB>(points, s, va, wa, vb, wb, tolerance, true)) {
    s.va = va, s.vb = vb, s.wa = wa, s.wb = wb;
    return;
  }
  if (!s.sweepsPrepared)
    for (PgsPoint<d>& p : points) p.prepareSweeps();
  for (int sweep = 1; sweep <= iterations; ++sweep) {
    double change2 = 0;
    for (PgsPoint<d>& p : points)
      change2 = std::max(change2, pgsStep<d, movesA, movesB>(p, s.inverseMassA, s.inverseMassB, va, wa, vb, wb));
    if (change2 < tolerance2) break;
    if (s.exactFinish && sweep == nextFinish && sweep < iterations) {
      if (polishManifold<d, movesA, movesB>(points, s, va, wa, vb, wb, tolerance)) break;
      nextFinish *= 2;
    }
  }
  s.va = va;
  s.vb = vb;
  s.wa = wa;
  s.wb = wb;
}

// Up to `iterations` sweeps over the points, stopping once a sweep changes no point velocity by
// `tolerance` or more. At least one body moves.
template <int d>
void pgsSolve(std::vector<PgsPoint<d>>& points, PgsBodies<d>& s, int iterations, double tolerance) {
  for (PgsPoint<d>& p : points) pgsOffsets<d>(p, s);
  if (s.movesA && s.movesB) pgsSweeps<d, true, true>(points, s, iterations, tolerance);
  else if (s.movesA) pgsSweeps<d, true, false>(points, s, iterations, tolerance);
  else pgsSweeps<d, false, true>(points, s, iterations, tolerance);
}

}  // namespace monolith::solvers::contact
