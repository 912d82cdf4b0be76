#pragma once
// One manifold problem: the contact points one contact update solves together, in the two
// shapes the contact stages meet (docs/rigid_contact.md, "The step"; docs/architecture.md "One
// pair update"):
//   - a pair: the points of two bodies' manifold, one or both of which move;
//   - a body against its frozen partners (shock propagation, GBF 2003): the points of its
//     manifolds with all of them at once, only the body moving, each point carrying its
//     partner's velocity there.
// Both add their points (each point's target normal velocity set here: restitution, gaps
// closed), solve them (projected Gauss-Seidel finished exactly, manifold_pgs.h and
// manifold_polish.h; a lone point of a pair by the closed form of impulse.h), solve again
// leaning on the stage's normal impulse where the plain law leaves a slip (shock propagation),
// and read the net impulse. Knows nothing of entities: ContactWorkspace finds the manifolds,
// clamps the energy and applies the result.
#include <algorithm>
#include <cmath>
#include <vector>

#include "solvers/contact/impulse.h"
#include "solvers/contact/manifold_pgs.h"
#include "solvers/contact/manifold_solve_end.h"

namespace monolith::solvers::contact {

// w x r written out (2-D: w is a 1-vector about z).
template <int d>
inline Vec<d> spinVelocity(const AngVec<d>& w, const Vec<d>& r) {
  if constexpr (d == 3) return w.cross(r);
  else return Vec<d>(-w(0) * r.y(), w(0) * r.x());
}

// The normal velocity a contact point may keep while its bodies close the gap they have at the
// base poses (ContactSettings::closeGaps). The point is found at the candidate poses, which are
// the base poses moved by dt times the velocities, so to first order the bodies are apart by
// gap = -depth - dt v_n at the base: they may approach at up to gap/dt and end the step just
// touching. Zero where they already overlap at the base (push-out separates them) or when gaps
// are not closed (the thesis: every point within the margin counts as touching). A gap within
// `tolerance` (push-out's: the overlap it leaves alone) counts as touching too: the estimate is
// first order, a turning body's candidate points lie off it by (dt omega)^2 |r| / 2, and closing
// such phantom gaps kept a resting pyramid creeping (1e-6 in 3 s instead of 1e-16).
inline double closableNormalVelocity(bool closeGaps, double depth, double vn, double dt, double tolerance) {
  if (!closeGaps) return 0.0;
  const double gap = -depth - dt * vn;
  return gap > tolerance ? -gap / dt : 0.0;
}

// A point's target normal velocity: -e v_n where it approaches (contact's e = -1 + eps removes
// the fraction eps of the approach, notes 1.6), but never more of the approach than the gap
// leaves to remove (the approach at gap/dt is kept); where it does not approach (beyond closing
// the gap) it must not start to.
inline double targetNormalVelocity(bool approaching, double restitution, double vn, double closable) {
  if (!approaching) return closable;
  return closable < 0 ? std::min(-restitution * vn, closable) : -restitution * vn;
}

// Shock propagation solves an update again leaning on the stage (ManifoldProblem::solve) when
// the plain one leaves a slip above this fraction of the update's largest speed (approach or
// slip): the creeping stacks it is for keep nearly all their slip, while a projected Gauss-Seidel
// solve that converged leaves about its stop tolerance (1e-7 of it). Measured on pyramid_20 at
// the thesis's schedule, 1 s: a re-solve for 9 % of shock propagation's sliding updates at 1e-3,
// 57 % at the stop tolerance; an off-centre box stays put at 1e-4 to 1e-2 alike.
constexpr double kLeanSlip = 1e-3;

// What sets the points' target normal velocities, and which speeds count.
struct ManifoldTargets {
  double restitution = 0;        // contact: -1 + eps (notes 1.6); a collision's e
  bool closeGaps = false;        // closableNormalVelocity (the contact stages only)
  double dt = 0;                 // the step
  double gapTolerance = 0;       // a gap within this counts as touching (push-out's tolerance)
  double approachTolerance = 0;  // a point approaches, or slips, when faster than this
};

template <int d>
class ManifoldProblem {
 public:
  using VecD = Vec<d>;
  using Point = PgsPoint<d>;
  enum class Shape : char {
    Pair,           // both bodies in `bodies` (b's velocity there), either may be of infinite mass
    AgainstFrozen,  // body a only; each point carries its partner's velocity
  };

  // A new problem: the bodies' velocities (split state: w = I_split^{-1} L), inverse masses and
  // which of them move.
  void start(Shape shape, const PgsBodies<d>& bodies, const ManifoldTargets& targets) {
    shape_ = shape;
    state_ = bodies;
    targets_ = targets;
    points_.clear();
    preloads_.clear();
    anyApproaching_ = anySliding_ = false;
    speedScale_ = 0;
  }

  // Adds a contact point: lever arms ra (and rb, in a pair) from the bodies' centres, the normal
  // out of b (or of the partner) towards a, the partner's velocity at the point (AgainstFrozen),
  // the depth and the friction coefficient. `measureSlip`: the point's friction may lean on the
  // stage (shock propagation, setLeaning), so its slip counts as something to solve.
  void add(const VecD& ra, const VecD& rb, const VecD& n, const VecD& partnerVelocity, double depth, double mu,
           bool measureSlip) {
    Point& p = points_.emplace_back();  // in place: a prepared point is ~90 numbers
    p.ra = ra;
    p.n = n;
    VecD vrel;
    if (shape_ == Shape::Pair) {
      p.rb = rb;
      vrel = state_.va + spinVelocity<d>(state_.wa, p.ra) - state_.vb - spinVelocity<d>(state_.wb, p.rb);
    } else {
      p.partnerVelocity = partnerVelocity;
      vrel = state_.va + spinVelocity<d>(state_.wa, p.ra) - p.partnerVelocity;
    }
    const double vn = vrel.dot(p.n);
    const double closable =
        closableNormalVelocity(targets_.closeGaps, depth, vn, targets_.dt, targets_.gapTolerance);
    const bool approaching = vn < closable - targets_.approachTolerance;
    anyApproaching_ = anyApproaching_ || approaching;
    if (measureSlip) {
      const double slip = (vrel - vn * p.n).norm();
      anySliding_ = anySliding_ || slip > targets_.approachTolerance;
      speedScale_ = std::max(speedScale_, slip);
    }
    p.target = targetNormalVelocity(approaching, targets_.restitution, vn, closable);
    p.mu = mu;
    // The stop tolerance's scale: a pair's approach counts too; against frozen partners only the
    // targets (and slips) do, as each solve was tuned.
    speedScale_ = std::max(speedScale_, shape_ == Shape::Pair ? std::abs(p.target) + std::abs(vn) : std::abs(p.target));
  }

  // The normal impulse the friction of points [begin, end of the points so far) may lean on
  // beyond their own if the plain solve leaves them slipping (shock propagation): `allowance`,
  // shared evenly (PgsPoint::frictionPreload).
  void setLeaning(std::size_t begin, double allowance) {
    // The plain law: nothing to store (entries not set are 0 when read, solveAgainLeaningOnStage).
    if (!(allowance > 0)) return;
    preloads_.resize(points_.size(), 0.0);
    for (std::size_t k = begin; k < points_.size(); ++k) preloads_[k] = allowance / double(points_.size() - begin);
  }

  std::size_t size() const { return points_.size(); }
  bool empty() const { return points_.empty(); }
  // Whether anything is to be solved: a point approaches, or one whose slip counts slips.
  bool needsSolve() const { return anyApproaching_ || anySliding_; }
  const std::vector<Point>& points() const { return points_; }

  // Solves the points with the given inverse inertias (zero for a body of infinite mass; the
  // split state's, Sec. 2.3.2) and inverse mass sum: the closed form of impulse.h when a pair
  // has one point (`onePoint`, its restitution and friction law; null: never), else projected
  // Gauss-Seidel (at most `iterations` sweeps) with the exact finish if `exactFinish`, started
  // from `end` (a pair's last solve) and leaving its end there. Then, where points measured
  // their slip and the plain solve leaves one above kLeanSlip of the speeds, again leaning on
  // setLeaning's allowances. Call only when needsSolve().
  void solve(double inverseMasses, const AngMat<d>& Ia, const AngMat<d>& Ib, bool exactFinish, int iterations,
             const ImpulseSettings* onePoint, ManifoldSolveEnd* end) {
    state_.inverseInertiaA = Ia;
    state_.inverseInertiaB = Ib;
    state_.setExactFinish(exactFinish);
    const bool closedForm = onePoint && points_.size() == 1;
    if (closedForm) {
      points_[0].prepareOnePoint(inverseMasses, Ia, Ib);
    } else {
      const bool rotatesA = !Ia.isZero(0), rotatesB = !Ib.isZero(0);
      for (Point& p : points_) p.prepareForSolve(state_.exactFinish, inverseMasses, Ia, Ib, rotatesA, rotatesB);
    }
    const double tolerance = 1e-7 * speedScale_ + 1e-12;
    // The state before the solve, for the solve again leaning on the stage (only with a slip).
    if (anySliding_) before_ = state_;
    if (!anyApproaching_) {
      // Only a slip (shock propagation): the plain law has no normal impulse to stop it with.
    } else if (closedForm) {
      // One point: the impulse of notes 1.5 (sticking, else sliding along K(n - mu t)).
      Point& p = points_[0];
      const VecD vrel =
          state_.va + spinVelocity<d>(state_.wa, p.ra) - state_.vb - spinVelocity<d>(state_.wb, p.rb);
      // Its target as a restitution (the same one unless the gap bounds it; vn < 0 here).
      ImpulseSettings toTarget = *onePoint;
      const double vn = vrel.dot(p.n);
      if (p.target != -onePoint->restitution * vn) toTarget.restitution = -p.target / vn;
      const VecD j = pointImpulse<d>(p.K, vrel, p.n, toTarget);
      p.normalImpulse = j.dot(p.n);
      p.tangentImpulse = p.T.transpose() * (j - p.normalImpulse * p.n);
    } else {
      // Several points (a face contact, or a body on several partners): solved together, so a
      // box lying flat stops at all its corners at once instead of rocking between them as
      // one-point-at-a-time impulses do.
      if (end && state_.exactFinish) recallEnd(*end);
      pgsSolve<d>(points_, state_, iterations, tolerance);
      if (end && state_.exactFinish) rememberEnd(*end);
    }
    if (anySliding_) {
      const double slipBound = std::max(tolerance + targets_.approachTolerance, kLeanSlip * speedScale_);
      solveAgainLeaningOnStage(before_, slipBound, inverseMasses, Ia, Ib, iterations, tolerance);
    }
  }

  // The net impulse J of the solved points on body a, its angular impulse about a's centre
  // tau = sum r_a x j, and how many points carry an impulse.
  int netImpulse(VecD& J, AngVec<d>& tau) const {
    J.setZero();
    tau.setZero();
    int active = 0;
    for (const Point& p : points_) {
      const VecD j = p.impulse();
      if (j.squaredNorm() == 0) continue;
      ++active;
      J += j;
      tau += cross<d>(p.ra, j);
    }
    return active;
  }

 private:
  // The largest slip the solved impulses leave: the tangential relative velocity at each point
  // after them, from the bodies' velocities before the solve (against frozen partners: minus
  // their point velocities).
  double slipLeft(const PgsBodies<d>& before) const {
    VecD J = VecD::Zero();
    AngVec<d> tauA = AngVec<d>::Zero(), tauB = AngVec<d>::Zero();
    for (const Point& p : points_) {
      const VecD j = p.impulse();
      J += j;
      tauA += cross<d>(p.ra, j);
      tauB += cross<d>(p.rb, j);
    }
    const VecD va = before.va + before.inverseMassA * J, vb = before.vb - before.inverseMassB * J;
    const AngVec<d> wa = before.wa + before.inverseInertiaA * tauA, wb = before.wb - before.inverseInertiaB * tauB;
    double worst = 0;
    for (const Point& p : points_) {
      const VecD vrel = va + spinVelocity<d>(wa, p.ra) - vb - spinVelocity<d>(wb, p.rb) - p.partnerVelocity;
      worst = std::max(worst, (vrel - vrel.dot(p.n) * p.n).norm());
    }
    return worst;
  }

  // Where the plain solve, from `before`, leaves a slip above `slipBound`: solved again from
  // `before` with each point's friction leaning on its share of the stage's normal impulse, by
  // projected Gauss-Seidel (the closed forms have only the plain law). The points are prepared
  // for sweeps in full again: they may have had only the closed form's or the exact finish's
  // preparation.
  void solveAgainLeaningOnStage(const PgsBodies<d>& before, double slipBound, double inverseMasses,
                                const AngMat<d>& Ia, const AngMat<d>& Ib, int iterations, double tolerance) {
    if (!(slipLeft(before) > slipBound)) return;
    state_ = before;
    state_.setExactFinish(false);
    preloads_.resize(points_.size(), 0.0);
    for (std::size_t k = 0; k < points_.size(); ++k) {
      points_[k].prepareForSolve(false, inverseMasses, Ia, Ib);
      points_[k].normalImpulse = 0;
      points_[k].tangentImpulse.setZero();
      points_[k].frictionPreload = preloads_[k];
    }
    pgsSolve<d>(points_, state_, iterations, tolerance);
  }

  // The solve starts where the pair's last one ended, if the narrow phase gave as many points;
  // the point order of a manifold that barely moved is the same. Only a start: the exact finish
  // still checks every condition and changes what fails.
  void recallEnd(const ManifoldSolveEnd& end) {
    if (end.points != static_cast<int>(points_.size())) return;
    for (std::size_t i = 0; i < points_.size(); ++i) {
      Point& p = points_[i];
      p.startState = static_cast<PointState>((end.states >> (2 * i)) & 3u);
      if (p.startState != PointState::Sliding) continue;
      const double angle = end.angles[i];
      if constexpr (d == 3) p.startDirection = Eigen::Vector2d(std::cos(angle), std::sin(angle));
      else p.startDirection[0] = angle == 0 ? 1.0 : -1.0;
    }
  }

  void rememberEnd(ManifoldSolveEnd& end) const {
    end.points = 0;
    if (points_.size() > static_cast<std::size_t>(ManifoldSolveEnd::kPoints)) return;
    end.states = 0;
    for (std::size_t i = 0; i < points_.size(); ++i) {
      const Point& p = points_[i];
      const PointState state = stateFromImpulses(p);
      end.states |= static_cast<std::uint16_t>(static_cast<unsigned>(state) << (2 * i));
      if (state != PointState::Sliding) continue;
      if constexpr (d == 3) end.angles[i] = static_cast<float>(std::atan2(p.tangentImpulse[1], p.tangentImpulse[0]));
      else end.angles[i] = p.tangentImpulse[0] >= 0 ? 0.0f : 3.14159265f;
    }
    end.points = static_cast<signed char>(points_.size());
  }

  Shape shape_ = Shape::Pair;
  PgsBodies<d> state_, before_;
  ManifoldTargets targets_;
  std::vector<Point> points_;
  std::vector<double> preloads_;  // per point (setLeaning); empty: none
  bool anyApproaching_ = false, anySliding_ = false;
  double speedScale_ = 0;  // the largest speed of the problem: the stop tolerance's scale
};

}  // namespace monolith::solvers::contact
