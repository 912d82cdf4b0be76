#pragma once
// The exact end of a manifold solve once projected Gauss-Seidel has found which points carry
// load and which slide (docs/architecture.md "One pair update", docs/benchmarks.md
// "Manifold solves finished exactly" and "Exact finish before the first sweep"). Not in the
// thesis; scene switch solvers.contact.exact_manifold_finish (off by default).
//
// Why: the points of a face contact are redundant. Four corners of a box on a face, or the eight
// of a pyramid box on the two below it, put 12 or 24 impulse components against the 6 degrees
// of freedom of the relative motion, and on such a singular problem Gauss-Seidel converges
// linearly (about 0.4 per sweep) down to a floor of about 1e-9 set by the friction projection's
// own tolerance: shock propagation's joint solves ran all their 40 sweeps and were half of a
// short-schedule pyramid step. Once the states of the points are known, the answer is a small
// linear problem in the relative motion instead.
//
// Tried before the first sweep, then after sweeps 3, 6, 12, ...:
//   1. states: before any sweep, a point whose normal velocity is at or below its target is
//      taken as loaded and sticking, the others as unloaded (a resting manifold is then solved
//      without sweeping at all), unless the caller gives start states (PgsPoint::startState:
//      the contact stages pass those the pair's last solve ended in, which in a resting pile are
//      this solve's own); after sweeps, as their impulses say: unloaded (normal impulse 0),
//      sticking (friction strictly inside its disk), sliding (on the rim), frictionless;
//   2. the relative twist meeting every active row -- normal velocity at its target for loaded
//      points, zero slip for sticking ones -- by least squares on the 6 x 6 (3 x 3 in 2-D) normal
//      equations N = G G^T. Rows that cannot all be met fail, and so do more than 6 dependent
//      ones; an unloaded point left approaching takes load (next pass). Fewer rows than 6 (a box
//      on one corner), or 6 dependent ones (a box on one edge), cannot fix the twist: if no point
//      slides, the impulse changes on the rows' own columns solve (G^T W G) x = wanted - G^T twist
//      directly instead, a dependent row dropped and checked after (steps 3-4 skipped);
//   3. a sliding point's friction is mu lambda against the slip that twist leaves there, so its
//      impulse is lambda (n + mu T dir), one unknown;
//   4. the wrench about x_a that gives the twist (W^{-1} times the change, W the effective
//      inverse mass of the relative twist) and the impulse change of least norm giving it;
//   5. a sticking point that slips at that twist becomes sliding, and a point whose normal
//      impulse would turn negative becomes unloaded; else the sticking point whose impulse lies
//      farthest outside its disk becomes sliding, its friction along that impulse (one such point
//      per pass: turning all of them at once left pyramid boxes on one sticking and three
//      sliding corners, rows that cannot fix the turn about the normal, and 41 % of the solves
//      between two moving boxes failed): steps 2-5 again (at most 4 passes);
//   6. accepted only if the bodies end with no more kinetic energy than before the solve.
//      With sliding friction the complementarity problem can have spurious solutions with large
//      impulses that feed energy in (Painleve's paradox): without this test pyramid_20 blew up
//      to 18 J at the thesis's schedule. The sweeps never find those.
// An accepted result meets every condition of the problem the sweeps converge to (to rounding,
// instead of to the sweeps' stop test), and the sweeps stop. Otherwise nothing changes and the
// sweeps go on.
//
// The twist: D = (v_a - v_b - w_b x (x_a - x_b), w_a - w_b), the relative velocity field at A's
// centre, so that the relative velocity at a point along u is u.D_lin + (r_a x u).D_ang + const:
// the row of a point along u is g = (u, r_a x u), the wrench about x_a of a unit impulse along u.
#include <Eigen/Core>
#include <array>
#include <cmath>
#include <vector>

#include "solvers/contact/rigid_math.h"
#include "solvers/contact/small_cholesky.h"

namespace monolith::solvers::contact {

// A manifold point's state in the active-set step below. `Unknown`: no start state is given.
enum class PointState : char { Unloaded, Sticking, Sliding, Frictionless, Unknown };

// A point's state as its accumulated impulses say: unloaded (normal impulse 0), sticking
// (friction strictly inside its disk), sliding (on the rim), frictionless.
template <class Point>
PointState stateFromImpulses(const Point& p) {
  const double limit = p.mu * p.normalImpulse;
  return !(p.normalImpulse > 0) ? PointState::Unloaded
         : !(p.mu > 0)          ? PointState::Frictionless
         : p.tangentImpulse.squaredNorm() < (1 - 1e-9) * limit * limit ? PointState::Sticking
                                                                         : PointState::Sliding;
}

template <int d>
constexpr int kTwistDim = d + kAngularDim<d>;
template <int d>
using Twist = Eigen::Matrix<double, kTwistDim<d>, 1>;
template <int d>
using TwistMat = Eigen::Matrix<double, kTwistDim<d>, kTwistDim<d>>;

// y += a x, element by element: what Eigen's y += a * x computes, written out so that the
// compiler inlines it (Eigen's unrolled 6-vector loop was a call of its own, 1 % of a pyramid step).
template <int n>
[[gnu::always_inline]] inline void addScaled(Eigen::Matrix<double, n, 1>& y, double a,
                                             const Eigen::Matrix<double, n, 1>& x) {
  for (int c = 0; c < n; ++c) y[c] += a * x[c];
}

// M += weight g g^T on the lower triangle (Eigen's rankUpdate is slower on these fixed 6 x 6).
template <int d>
inline void addOuterLower(TwistMat<d>& M, const Twist<d>& g, double weight = 1.0) {
  for (int c = 0; c < kTwistDim<d>; ++c) {
    const double gc = weight * g[c];
    for (int r = c; r < kTwistDim<d>; ++r) M(r, c) += g[r] * gc;
  }
}

// M += [[1, C^T], [C, C C^T]] on the lower triangle, C = r* (d x d identity; C C^T = |r|^2 - r r^T
// in 3-D, |r|^2 in 2-D): the sum of g g^T over the rows g = (u, r x u) of an orthonormal basis u.
template <int d>
inline void addStickingBlock(TwistMat<d>& M, const Vec<d>& r) {
  constexpr int A = kAngularDim<d>;
  M.template topLeftCorner<d, d>().diagonal().array() += 1.0;
  M.template bottomLeftCorner<A, d>() += crossMatrix<d>(r);
  const double r2 = r.squaredNorm();
  if constexpr (d == 3) {
    for (int c = 0; c < 3; ++c)
      for (int q = c; q < 3; ++q) M(d + q, d + c) += (q == c ? r2 : 0.0) - r[q] * r[c];
  } else {
    M(d, d) += r2;
  }
}

// Point: PgsPoint<d> (prepared, offsets set); Bodies: PgsBodies<d>. va..wb: the sweeps' working
// velocities, updated on success. Returns true if the solve is finished.
// An impulse change at point p (dn along its normal, dt along its tangents) applied to the
// working velocities: the sweeps' step (pgsStep) and the finish's result apply it alike, in the
// same order of operations.
template <int d, bool movesA, bool movesB, class Point>
[[gnu::always_inline]] inline void applyImpulseChange(const Point& p, double dn, const double* dt, double inverseMassA,
                                                      double inverseMassB, Vec<d>& va, AngVec<d>& wa, Vec<d>& vb,
                                                      AngVec<d>& wb) {
  Vec<d> j = dn * p.n;
  AngVec<d> ja = dn * p.IaRaN, jb = dn * p.IbRbN;
  for (int k = 0; k < d - 1; ++k) {
    j += dt[k] * p.T.col(k);
    if constexpr (movesA) ja += dt[k] * p.IaRaT.col(k);
    if constexpr (movesB) jb += dt[k] * p.IbRbT.col(k);
  }
  if constexpr (movesA) {
    va += inverseMassA * j;
    wa += ja;
  }
  if constexpr (movesB) {
    vb -= inverseMassB * j;
    wb -= jb;
  }
}

template <int d, bool movesA, bool movesB, class Point, class Bodies>
bool polishManifold(std::vector<Point>& points, const Bodies& s, Vec<d>& va, AngVec<d>& wa, Vec<d>& vb,
                    AngVec<d>& wb, double tolerance, bool guessLoaded = false) {
  constexpr int D = kTwistDim<d>, A = kAngularDim<d>, m = d - 1;
  using Tangent = Eigen::Matrix<double, m, 1>;
  // x_a - x_b, needed only when b moves (a joint solve's points carry no r_b).
  const Vec<d> arm = movesB ? Vec<d>(points.front().rb - points.front().ra) : Vec<d>::Zero();
  // The current relative twist (moving bodies only: a fixed body's velocity is in the offsets).
  Twist<d> twist = Twist<d>::Zero();
  if constexpr (movesA) twist.template head<d>() += va, twist.template tail<A>() += wa;
  if constexpr (movesB)
    twist.template head<d>() -= vb + angularCross<d>(wb, arm), twist.template tail<A>() -= wb;
  // The points' states, first as the sweeps left them; per point its rows (u, r_a x u) for
  // u = n, T_1, ..., built once per call (the loops below read them many times). One
  // thread-local block: each lookup of a thread_local costs a call.
  using State = PointState;
  struct Impulse {
    double normal;
    Tangent tangent;
  };
  struct Scratch {
    std::vector<State> states;
    std::vector<Tangent> directions;  // of a sliding point's friction
    std::vector<Impulse> result;
    std::vector<std::array<Twist<d>, d>> rows;
  };
  thread_local Scratch scratch;
  std::vector<State>& states = scratch.states;
  std::vector<Tangent>& directions = scratch.directions;
  std::vector<Impulse>& result = scratch.result;
  std::vector<std::array<Twist<d>, d>>& rows = scratch.rows;
  states.resize(points.size());
  directions.resize(points.size());
  result.resize(points.size());
  rows.resize(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Point& p = points[i];
    rows[i][0].template head<d>() = p.n;
    rows[i][0].template tail<A>() = p.raN;
    for (int k = 0; k < m; ++k) {
      rows[i][1 + k].template head<d>() = p.T.col(k);
      rows[i][1 + k].template tail<A>() = p.raT.col(k);
    }
  }
  auto rowN = [&rows](std::size_t i) -> const Twist<d>& { return rows[i][0]; };
  auto tangentRow = [&rows](std::size_t i, int k) -> const Twist<d>& { return rows[i][1 + k]; };
  // The column of a sliding point: its impulse is lambda (n + mu T dir).
  auto slidingColumn = [&](std::size_t i, const Tangent& dir) {
    Twist<d> c = rows[i][0];
    for (int k = 0; k < m; ++k) addScaled<D>(c, points[i].mu * dir[k], rows[i][1 + k]);
    return c;
  };
  // The wrench about x_a of the impulse dn n + T dt at point i.
  auto impulseWrench = [&rows](std::size_t i, double dn, const Tangent& dt) {
    Twist<d> w;
    for (int c = 0; c < D; ++c) w[c] = dn * rows[i][0][c];
    for (int k = 0; k < m; ++k) addScaled<D>(w, dt[k], rows[i][1 + k]);
    return w;
  };

  const State loaded = State::Sticking, frictionless = State::Frictionless;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Point& p = points[i];
    if (guessLoaded && p.startState != State::Unknown) {
      // Before any sweep, the state the pair's last solve ended in (the caller's memory).
      states[i] = p.startState == loaded && !(p.mu > 0) ? frictionless : p.startState;
      if (states[i] == State::Sliding) directions[i] = p.startDirection;
      continue;
    }
    if (guessLoaded) {
      // Before any sweep: a point carries load if it would otherwise end below its target.
      const bool carries = p.offsetN + rowN(i).dot(twist) < p.target + tolerance;
      states[i] = !carries ? State::Unloaded : p.mu > 0 ? loaded : frictionless;
      continue;
    }
    states[i] = stateFromImpulses(p);
    // A sliding point's friction keeps the sweeps' direction unless the twist slips it.
    if (states[i] == State::Sliding)
      directions[i] = p.tangentImpulse.squaredNorm() > 0 ? Tangent(p.tangentImpulse.normalized()) : Tangent::UnitX();
  }
  // A's inertia (the inverse of the inverse inertia the points were prepared with), for the
  // energy test and, when only A moves, for W^{-1}; B's for the energy test. Each inverted once
  // per finish, on first use.
  AngMat<d> inertiaA, inertiaB;
  bool inertiaReady = false, inertiaBReady = false;
  auto inertiaOfA = [&]() -> const AngMat<d>& {
    if (!inertiaReady) inertiaA = s.inverseInertiaA.inverse(), inertiaReady = true;
    return inertiaA;
  };
  auto inertiaOfB = [&]() -> const AngMat<d>& {
    if (!inertiaBReady) inertiaB = s.inverseInertiaB.inverse(), inertiaBReady = true;
    return inertiaB;
  };
  // W = W_A + S^T W_B S: the effective inverse mass of the relative twist for a wrench about x_a
  // (S: a wrench about x_a to one about x_b; C: F -> (x_a - x_b) x F). Built on first use.
  TwistMat<d> W;
  SmallCholesky<D> mass;
  bool massReady = false, massFactored = false;
  auto buildMass = [&]() {
    if (massReady) return;
    massReady = true;
    W.setZero();
    if constexpr (movesA) {
      W.template topLeftCorner<d, d>().diagonal().array() += s.inverseMassA;
      W.template bottomRightCorner<A, A>() += s.inverseInertiaA;
    }
    if constexpr (movesB) {
      const CrossMat<d> C = crossMatrix<d>(arm);
      const AngMat<d>& Ib = s.inverseInertiaB;
      W.template topLeftCorner<d, d>().diagonal().array() += s.inverseMassB;
      W.template topLeftCorner<d, d>() += C.transpose() * Ib * C;
      W.template topRightCorner<d, A>() += C.transpose() * Ib;
      W.template bottomLeftCorner<A, d>() += Ib * C;
      W.template bottomRightCorner<A, A>() += Ib;
    }
  };
  // The wrench W^{-1} change. Only A moving: W is block diagonal, W^{-1} = diag(m_a, I_a).
  auto wrenchFor = [&](const Twist<d>& change, Twist<d>& wrench) {
    if constexpr (movesA && !movesB) {
      wrench.template head<d>() = change.template head<d>() / s.inverseMassA;
      wrench.template tail<A>() = inertiaOfA() * change.template tail<A>();
      return true;
    }
    buildMass();
    if (!massFactored && !(massFactored = mass.compute(W))) return false;
    wrench = mass.solve(change);
    return true;
  };

  // An unloaded point that would end below its target at `next` carries load after all (the
  // next pass). Returns whether it changed.
  auto takesLoad = [&](std::size_t i, const Twist<d>& next) {
    const Point& p = points[i];
    if (p.offsetN + rowN(i).dot(next) >= p.target - tolerance) return false;
    states[i] = p.mu > 0 ? loaded : frictionless;
    return true;
  };

  // The velocities the impulses in `result` give, applied as the sweeps apply theirs, if the
  // bodies gain no kinetic energy.
  auto accept = [&]() {
    Vec<d> va1 = va, vb1 = vb;
    AngVec<d> wa1 = wa, wb1 = wb;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Point& p = points[i];
      const double dn = result[i].normal - p.normalImpulse;
      const Tangent dt = result[i].tangent - p.tangentImpulse;
      if (dn == 0 && dt.squaredNorm() == 0) continue;
      applyImpulseChange<d, movesA, movesB>(p, dn, dt.data(), s.inverseMassA, s.inverseMassB, va1, wa1, vb1, wb1);
    }
    // With sliding friction the complementarity problem can have spurious solutions of large
    // impulses that feed energy in (Painleve's paradox; seen in pyramid_20: a pair of boxes given
    // 3 J); projected Gauss-Seidel does not find them. An exact finish must not give the bodies
    // more kinetic energy than they had before the solve, or the sweeps go on instead.
    double before = 0, after = 0;
    if constexpr (movesA) {
      const AngMat<d>& inertia = inertiaOfA();
      before += s.va.squaredNorm() / s.inverseMassA + s.wa.dot(inertia * s.wa);
      after += va1.squaredNorm() / s.inverseMassA + wa1.dot(inertia * wa1);
    }
    if constexpr (movesB) {
      const AngMat<d>& inertia = inertiaOfB();
      before += s.vb.squaredNorm() / s.inverseMassB + s.wb.dot(inertia * s.wb);
      after += vb1.squaredNorm() / s.inverseMassB + wb1.dot(inertia * wb1);
    }
    if (!(after <= before * (1 + 1e-9))) return false;
    for (std::size_t i = 0; i < points.size(); ++i) {
      points[i].normalImpulse = result[i].normal;
      points[i].tangentImpulse = result[i].tangent;
    }
    va = va1, wa = wa1, vb = vb1, wb = wb1;
    return true;
  };

  // Fewer active rows than the twist has dimensions (a box pivoting on one corner), or as many
  // but dependent (a box on one edge: its two sticking corners' slips along the edge are one
  // row): they cannot fix the relative motion, the bodies' masses decide the rest. For loaded
  // points that all stick (or have no friction) the impulse changes x on the rows' own columns
  // solve (G^T W G) x = wanted - G^T twist; a row dependent on those before it is dropped (its
  // impulse change stays 0), and must then be met by the others' solution, else this fails.
  enum class Outcome { Failed, Changed, Accepted };
  auto solveFewRows = [&]() {
    for (const State st : states)
      if (st == State::Sliding) return Outcome::Failed;
    buildMass();
    // Reference impulses: the current ones, an unloaded point's removed.
    Twist<d> base = twist;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Point& p = points[i];
      result[i].normal = states[i] == State::Unloaded ? 0.0 : p.normalImpulse;
      result[i].tangent = states[i] == State::Sticking ? p.tangentImpulse : Tangent::Zero();
      const double dn = result[i].normal - p.normalImpulse;
      const Tangent dt = result[i].tangent - p.tangentImpulse;
      if (dn != 0 || dt.squaredNorm() != 0) base += W * impulseWrench(i, dn, dt);
    }
    Twist<d> g[D], Wg[D];
    Twist<d> wanted = Twist<d>::Zero(), goal;
    int k = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (states[i] == State::Unloaded) continue;
      const Point& p = points[i];
      g[k] = rowN(i);
      wanted[k++] = p.target - p.offsetN;
      if (states[i] == State::Sticking)
        for (int t = 0; t < m; ++t) g[k] = tangentRow(i, t), wanted[k++] = -p.offsetT[t];
    }
    TwistMat<d> system = TwistMat<d>::Zero();
    double scale = 0;
    goal = wanted;  // each row's own condition: g . next = goal
    for (int c = 0; c < k; ++c) {
      Wg[c] = W * g[c];
      for (int r = c; r < k; ++r) system(r, c) = g[r].dot(Wg[c]);
      scale += system(c, c);
      wanted[c] -= g[c].dot(base);
    }
    if (k == 0) {  // nothing loaded: the points left approaching take load, if any
      bool changed = false;
      for (std::size_t i = 0; i < points.size(); ++i) changed = takesLoad(i, base) || changed;
      return changed ? Outcome::Changed : Outcome::Failed;
    }
    // Padded to D x D with the mean pivot, so that the rank test compares like with like.
    for (int c = k; c < D; ++c) system(c, c) = scale / k;
    SmallCholesky<D> few;
    const int dropped = few.computeDroppingDependent(system, 1e-6);
    const Twist<d> x = few.solve(wanted);
    Twist<d> next = base;
    for (int c = 0; c < k; ++c) next += x[c] * Wg[c];
    for (int c = 0; c < k && dropped > 0; ++c)
      if (!(std::abs(g[c].dot(next) - goal[c]) <= tolerance)) return Outcome::Failed;
    bool changed = false;
    k = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Point& p = points[i];
      if (states[i] == State::Unloaded) {
        changed = takesLoad(i, next) || changed;
        continue;
      }
      result[i].normal += x[k++];
      if (states[i] == State::Sticking)
        for (int t = 0; t < m; ++t) result[i].tangent[t] += x[k++];
      if (!(result[i].normal >= 0)) {
        states[i] = State::Unloaded, changed = true;
        continue;
      }
      const double limit = p.mu * result[i].normal;
      if (states[i] == State::Sticking && !(result[i].tangent.squaredNorm() <= limit * limit))
        return Outcome::Failed;
    }
    if (changed) return Outcome::Changed;
    return accept() ? Outcome::Accepted : Outcome::Failed;
  };

  // An active-set iteration: a sticking point that the twist would make slip, or whose impulse
  // leaves its disk, slides; a point whose impulse would turn negative is unloaded; then again.
  for (int pass = 0; pass < 4; ++pass) {
    int activeRows = 0;
    for (const State st : states) activeRows += st == State::Sticking ? d : st == State::Unloaded ? 0 : 1;
    if (activeRows < D) {
      const Outcome outcome = solveFewRows();
      if (outcome == Outcome::Changed) continue;
      return outcome == Outcome::Accepted;
    }

    // The twist meeting every active row (normal velocity at its target; no slip where sticking),
    // by least squares on the normal equations N y = G r.
    TwistMat<d> N = TwistMat<d>::Zero();
    Twist<d> Gr = Twist<d>::Zero();
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (states[i] == State::Unloaded) continue;
      const Point& p = points[i];
      const Twist<d>& gn = rowN(i);
      addScaled<D>(Gr, p.target - p.offsetN - gn.dot(twist), gn);
      if (states[i] != State::Sticking) {
        addOuterLower<d>(N, gn);
        continue;
      }
      // A sticking point's d rows (u, r_a x u) over the orthonormal (n, T): their sum of
      // g g^T is [[1, C^T], [C, C C^T]] with C = r_a*, in closed form.
      addStickingBlock<d>(N, p.ra);
      for (int k = 0; k < m; ++k) {
        const Twist<d>& g = tangentRow(i, k);
        addScaled<D>(Gr, -p.offsetT[k] - g.dot(twist), g);
      }
    }
    SmallCholesky<D> normal;
    if (!(normal.compute(N) && normal.wellConditioned(1e-6))) {
      // Rank-deficient rows: as many as the twist has dimensions are solved as a few rows.
      if (activeRows > D) return false;
      const Outcome outcome = solveFewRows();
      if (outcome == Outcome::Changed) continue;
      return outcome == Outcome::Accepted;
    }
    const Twist<d> next = twist + normal.solve(Gr);

    // Rows that cannot all be met fail; slip at a sticking point turns it to sliding; a sliding
    // point's friction opposes the slip the twist leaves there.
    bool changed = false;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Point& p = points[i];
      if (states[i] == State::Unloaded) {
        changed = takesLoad(i, next) || changed;
        continue;
      }
      const double vn = p.offsetN + rowN(i).dot(next);
      if (!(std::abs(vn - p.target) <= tolerance)) return false;
      if (states[i] == State::Frictionless) continue;
      Tangent slip;
      for (int k = 0; k < m; ++k) slip[k] = p.offsetT[k] + tangentRow(i, k).dot(next);
      const double size = slip.norm();
      if (states[i] == State::Sticking) {
        if (size > tolerance) states[i] = State::Sliding, directions[i] = -slip / size, changed = true;
        continue;
      }
      if (size > tolerance) directions[i] = -slip / size;
    }
    if (changed) continue;

    // The wrench about x_a that changes the twist to `next`, and the impulses that give it:
    // the change of least norm from reference impulses (the current ones, a sliding point's
    // turned to its new direction, an unloaded point's zero).
    Twist<d> wrench;
    if (!wrenchFor(next - twist, wrench)) return false;
    // The columns' Gram matrix M: the rows' N unless a point slides (its column is n + mu T dir
    // instead of the normal row n), so the factorisation of N serves where all points stick.
    bool anySliding = false;
    TwistMat<d> M = N;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Point& p = points[i];
      Impulse& r = result[i];
      r.normal = 0;
      r.tangent.setZero();
      if (states[i] != State::Unloaded) r.normal = p.normalImpulse;
      if (states[i] == State::Sticking) r.tangent = p.tangentImpulse;
      if (states[i] == State::Sliding) r.tangent = p.mu * p.normalImpulse * directions[i];
      // The wrench of moving the current impulse to the reference one.
      const double dn = r.normal - p.normalImpulse;
      const Tangent dt = r.tangent - p.tangentImpulse;
      if (dn != 0 || dt.squaredNorm() != 0) wrench -= impulseWrench(i, dn, dt);
      if (states[i] == State::Sliding) {
        anySliding = true;
        addOuterLower<d>(M, slidingColumn(i, directions[i]));
        addOuterLower<d>(M, rowN(i), -1.0);
      }
    }
    SmallCholesky<D> slidingColumns;
    if (anySliding && !(slidingColumns.compute(M) && slidingColumns.wellConditioned(1e-6))) return false;
    const Twist<d> multiplier = anySliding ? slidingColumns.solve(wrench) : normal.solve(wrench);

    // The impulses must stay in their cones.
    std::size_t worst = points.size();
    double worstRatio = 1;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Point& p = points[i];
      Impulse& r = result[i];
      switch (states[i]) {
        case State::Unloaded:
        case State::Unknown: continue;  // (never: states are set above)
        case State::Sliding:
          r.normal += slidingColumn(i, directions[i]).dot(multiplier);
          r.tangent = p.mu * r.normal * directions[i];
          break;
        case State::Sticking:
          for (int k = 0; k < m; ++k) r.tangent[k] += tangentRow(i, k).dot(multiplier);
          [[fallthrough]];
        case State::Frictionless: r.normal += rowN(i).dot(multiplier); break;
      }
      if (!(r.normal >= 0)) {
        states[i] = State::Unloaded, changed = true;
        continue;
      }
      const double limit = p.mu * r.normal;
      const double t2 = r.tangent.squaredNorm();
      const double ratio = t2 == 0 ? 0.0 : t2 / (limit * limit);  // (no friction: inside any disk)
      if (states[i] == State::Sticking && !(ratio <= worstRatio)) worst = i, worstRatio = ratio;
    }
    if (changed) continue;
    if (worst < points.size()) {
      states[worst] = State::Sliding;
      directions[worst] = result[worst].tangent.normalized();
      continue;
    }

    return accept();
  }
  return false;
}

}  // namespace monolith::solvers::contact
