#include "solvers/contact/joint_push_out.h"

#include <Eigen/QR>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <numeric>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

namespace monolith::solvers::contact {

namespace {

// Per point: its rows' angular parts r x n, their images under the inverse inertias, and the
// inverse of the point's effective mass along n (the diagonal of J M^{-1} J^T).
template <int d>
struct Row {
  AngVec<d> ca = AngVec<d>::Zero(), cb = AngVec<d>::Zero(), inertiaCa = AngVec<d>::Zero(), inertiaCb = AngVec<d>::Zero();
  double inverseMass = 0;
};

// The separation the moves give point k along its normal ((dtheta x r).n = dtheta.(r x n)).
template <int d>
inline double separationGained(const JointPoint<d>& p, const Row<d>& row, const std::vector<JointMove<d>>& moves) {
  double s = 0;
  if (p.a >= 0) s += p.n.dot(moves[p.a].dx) + row.ca.dot(moves[p.a].dtheta);
  if (p.b >= 0) s -= p.n.dot(moves[p.b].dx) + row.cb.dot(moves[p.b].dtheta);
  return s;
}

// A change of point k's multiplier, moved into the bodies (dx = M^{-1} J^T dlambda).
template <int d>
inline void moveBodies(const std::vector<JointBody<d>>& bodies, const JointPoint<d>& p, const Row<d>& row, double change,
                       std::vector<JointMove<d>>& moves) {
  if (p.a >= 0) {
    moves[p.a].dx += change * bodies[p.a].inverseMass * p.n;
    moves[p.a].dtheta += change * row.inertiaCa;
  }
  if (p.b >= 0) {
    moves[p.b].dx -= change * bodies[p.b].inverseMass * p.n;
    moves[p.b].dtheta -= change * row.inertiaCb;
  }
}

// Up to this many points the multipliers come from the exact active-set solve below; beyond, from
// Gauss-Seidel sweeps (whose convergence slows with the mass ratio: 1e6 gives ~1e6 sweeps).
constexpr int kDenseJointPoints = 96;

// The dual of the program, min 1/2 l^T A l - depth^T l over l >= 0 with A = J M^{-1} J^T, by the
// active-set method of Lawson and Hanson: the point whose constraint is violated most joins the
// free set, the free multipliers solve their equations (the least-norm solution: redundant
// points, a face's corners, make them singular), and a multiplier that would turn negative stops
// the step at zero and leaves the set. Exact to rounding where the program is feasible.
template <int d>
void solveDense(const std::vector<JointBody<d>>& bodies, const std::vector<JointPoint<d>>& points,
                const std::vector<Row<d>>& rows, std::vector<double>& lambda) {
  const int m = static_cast<int>(points.size());
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(m, m);
  Eigen::VectorXd depth(m);
  // A(k, l) = sum over the bodies of both points of the product of their rows through M^{-1}.
  auto coupling = [&](int k, int l) {
    const JointPoint<d>& p = points[k];
    const JointPoint<d>& q = points[l];
    double sum = 0;
    for (int side = 0; side < 2; ++side) {
      const int body = side == 0 ? p.a : p.b;
      if (body < 0) continue;
      const double sp = side == 0 ? 1.0 : -1.0;
      const AngVec<d>& cp = side == 0 ? rows[k].ca : rows[k].cb;
      for (int other = 0; other < 2; ++other) {
        if ((other == 0 ? q.a : q.b) != body) continue;
        const double sq = other == 0 ? 1.0 : -1.0;
        const AngVec<d>& iq = other == 0 ? rows[l].inertiaCa : rows[l].inertiaCb;
        sum += sp * sq * (bodies[body].inverseMass * p.n.dot(q.n) + cp.dot(iq));
      }
    }
    return sum;
  };
  double largest = 0;
  for (int k = 0; k < m; ++k) {
    depth[k] = points[k].depth;
    for (int l = 0; l <= k; ++l) A(k, l) = A(l, k) = coupling(k, l);
    largest = std::max(largest, A(k, k));
  }
  if (!(largest > 0)) return;
  Eigen::VectorXd x = Eigen::VectorXd::Zero(m);
  std::vector<char> free(m, 0);
  std::vector<int> index;
  const double tolerance = 1e-12 * largest * (1 + depth.cwiseAbs().maxCoeff());
  for (int iteration = 0; iteration < 4 * m + 10; ++iteration) {
    const Eigen::VectorXd gradient = A * x - depth;
    int entering = -1;
    for (int k = 0; k < m; ++k)
      if (!free[k] && gradient[k] < -tolerance && (entering < 0 || gradient[k] < gradient[entering])) entering = k;
    if (entering < 0) break;
    free[entering] = 1;
    for (int inner = 0; inner < m + 1; ++inner) {
      index.clear();
      for (int k = 0; k < m; ++k)
        if (free[k]) index.push_back(k);
      const int f = static_cast<int>(index.size());
      Eigen::MatrixXd Aff(f, f);
      Eigen::VectorXd bf(f);
      for (int i = 0; i < f; ++i) {
        bf[i] = depth[index[i]];
        for (int j = 0; j < f; ++j) Aff(i, j) = A(index[i], index[j]);
      }
      const Eigen::VectorXd z = Aff.completeOrthogonalDecomposition().solve(bf);
      double step = 1;
      for (int i = 0; i < f; ++i)
        if (z[i] <= 0) {
          const double drop = x[index[i]] - z[i];
          step = std::min(step, drop > 0 ? x[index[i]] / drop : 0.0);
        }
      for (int i = 0; i < f; ++i) x[index[i]] += step * (z[i] - x[index[i]]);
      if (step >= 1) break;
      for (int i = 0; i < f; ++i)
        if (x[index[i]] <= 0) x[index[i]] = 0, free[index[i]] = 0;
    }
  }
  for (int k = 0; k < m; ++k) lambda[k] = std::max(0.0, x[k]);
}

// The Gauss-Seidel sweeps of solveJointPushOut over all points, stopped after the first sweep
// in which no point's separation changes by more than `tolerance` (or after `sweeps`), computed
// per connected component of the points (points sharing a body of the jam) at once. Points of
// different components touch different bodies, so a component's points see in every sweep
// exactly what the sweep over all points gives them, and the moves are bitwise those of the
// sweeps over all points, on any thread count. Only the stop is shared: the sweep over all
// points stops at the first sweep S in which every component is quiet. Each component runs
// ahead to its first quiet sweep at or after a target t; the latest of those is the next
// target, since no earlier sweep from t on is quiet for that component; the components left
// behind run on from where they are (a component never sweeps beyond S, so nothing is undone),
// until all stop at the same sweep. `sweepOver(list, count)` sweeps the listed points and
// returns the sweep's largest correction. Returns false, having swept nothing, on one thread or
// when the points form one component (the caller then sweeps them all in order).
template <int d, class SweepOver>
bool sweepComponents(std::size_t bodyCount, const std::vector<JointPoint<d>>& points, int sweeps, double tolerance,
                     SweepOver&& sweepOver) {
  if (tbb::this_task_arena::max_concurrency() <= 1) return false;  // the same sweeps, in one loop
  // Components by union-find over the jam's bodies (a fixed partner joins nothing).
  std::vector<int> parent(bodyCount);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&parent](int v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (const JointPoint<d>& p : points)
    if (p.a >= 0 && p.b >= 0) {
      const int ra = find(p.a), rb = find(p.b);
      if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
    }
  // Each component's points, ascending, components in the order of their first point.
  std::vector<int> componentOfRoot(bodyCount, -1), start, list;
  std::vector<int> componentOfPoint(points.size(), -1);
  int components = 0;
  for (std::size_t k = 0; k < points.size(); ++k) {
    const int body = points[k].a >= 0 ? points[k].a : points[k].b;
    if (body < 0) continue;  // no body of the jam: never swept (its row has no mass)
    int& c = componentOfRoot[find(body)];
    if (c < 0) c = components++;
    componentOfPoint[k] = c;
  }
  start.assign(static_cast<std::size_t>(components) + 1, 0);
  for (int c : componentOfPoint)
    if (c >= 0) ++start[c + 1];
  for (int c = 0; c < components; ++c) start[c + 1] += start[c];
  list.resize(start[components]);
  {
    std::vector<int> next(start.begin(), start.end() - 1);
    for (std::size_t k = 0; k < points.size(); ++k)
      if (componentOfPoint[k] >= 0) list[next[componentOfPoint[k]]++] = static_cast<int>(k);
  }
  if (components <= 1) return false;
  // Per component: sweeps done, whether the last was quiet, and the sweep it stops at
  // (`sweeps`: none quiet from the target on).
  std::vector<int> done(components, 0), stop(components, 0);
  std::vector<char> lastQuiet(components, 0);
  int target = 0;
  for (;;) {
    tbb::parallel_for(
        tbb::blocked_range<int>(0, components, 1),
        [&](const tbb::blocked_range<int>& r) {
          for (int c = r.begin(); c != r.end(); ++c) {
            if (done[c] - 1 >= target && lastQuiet[c]) {
              stop[c] = done[c] - 1;
              continue;
            }
            stop[c] = sweeps;
            while (done[c] < sweeps) {
              const int sweep = done[c]++;
              lastQuiet[c] = sweepOver(list.data() + start[c], static_cast<std::size_t>(start[c + 1] - start[c])) <= tolerance;
              if (sweep >= target && lastQuiet[c]) {
                stop[c] = sweep;
                break;
              }
            }
          }
        },
        tbb::simple_partitioner());
    const int latest = *std::max_element(stop.begin(), stop.end());
    if (std::all_of(stop.begin(), stop.end(), [&](int s) { return s == latest; })) return true;
    target = latest;
  }
}

// solveJointPushOut's sweeps per component (sweepComponents), on its rows and multipliers. Kept out
// of solveJointPushOut's own loop (not inlined): with this path inlined there, the one-component
// loop took 17 % more instructions (callgrind, pour_spheres_1000).
template <int d>
[[gnu::noinline]] bool sweepJamsAtOnce(const std::vector<JointBody<d>>& bodies, const std::vector<JointPoint<d>>& points,
                                      const std::vector<Row<d>>& rows, int sweeps, double tolerance,
                                      std::vector<double>& lambda, std::vector<JointMove<d>>& moves) {
  auto sweepOver = [&](const int* list, std::size_t count) {
    double largest = 0;
    for (std::size_t i = 0; i < count; ++i) {
      const std::size_t k = static_cast<std::size_t>(list[i]);
      if (!(rows[k].inverseMass > 0)) continue;
      const JointPoint<d>& p = points[k];
      const double next = std::max(0.0, lambda[k] + (p.depth - separationGained<d>(p, rows[k], moves)) * rows[k].inverseMass);
      const double change = next - lambda[k];
      if (change == 0) continue;
      largest = std::max(largest, std::abs(change) / rows[k].inverseMass);
      lambda[k] = next;
      moveBodies<d>(bodies, p, rows[k], change, moves);
    }
    return largest;
  };
  return sweepComponents(bodies.size(), points, sweeps, tolerance, sweepOver);
}

// One point's row as the in-order sweeps read it, packed with what they read of its bodies: the
// sweeps over one connected jam stay on one thread (they have no order-keeping parallelism),
// so they read one contiguous record per point instead of the point, its row and its bodies'
// masses from three places. The arithmetic is separationGained's and moveBodies' own.
template <int d>
struct SweepRow {
  int a = -1, b = -1;
  double inverseMassA = 0, inverseMassB = 0, depth = 0, inverseMass = 0;
  Vec<d> n = Vec<d>::Zero();
  AngVec<d> ca = AngVec<d>::Zero(), cb = AngVec<d>::Zero(), inertiaCa = AngVec<d>::Zero(),
            inertiaCb = AngVec<d>::Zero();
};

// solveJointPushOut's Gauss-Seidel sweeps over all points in their order (the points whose row
// has no mass are never swept), stopped after the first sweep in which no point's separation
// changes by more than `tolerance`, or after `sweeps`.
template <int d>
void sweepInOrder(const std::vector<JointBody<d>>& bodies, const std::vector<JointPoint<d>>& points,
                  const std::vector<Row<d>>& rows, int sweeps, double tolerance, std::vector<JointMove<d>>& moves) {
  thread_local std::vector<SweepRow<d>> packed;
  thread_local std::vector<double> lambda;
  packed.clear();
  for (std::size_t k = 0; k < points.size(); ++k) {
    if (!(rows[k].inverseMass > 0)) continue;
    const JointPoint<d>& p = points[k];
    SweepRow<d>& q = packed.emplace_back();
    q.a = p.a;
    q.b = p.b;
    if (p.a >= 0) q.inverseMassA = bodies[p.a].inverseMass;
    if (p.b >= 0) q.inverseMassB = bodies[p.b].inverseMass;
    q.depth = p.depth;
    q.inverseMass = rows[k].inverseMass;
    q.n = p.n;
    q.ca = rows[k].ca;
    q.cb = rows[k].cb;
    q.inertiaCa = rows[k].inertiaCa;
    q.inertiaCb = rows[k].inertiaCb;
  }
  lambda.assign(packed.size(), 0.0);
  for (int sweep = 0; sweep < sweeps; ++sweep) {
    double largest = 0;  // the largest correction of a point's separation in this sweep
    for (std::size_t k = 0; k < packed.size(); ++k) {
      const SweepRow<d>& q = packed[k];
      double gained = 0;
      if (q.a >= 0) gained += q.n.dot(moves[q.a].dx) + q.ca.dot(moves[q.a].dtheta);
      if (q.b >= 0) gained -= q.n.dot(moves[q.b].dx) + q.cb.dot(moves[q.b].dtheta);
      const double next = std::max(0.0, lambda[k] + (q.depth - gained) * q.inverseMass);
      const double change = next - lambda[k];
      if (change == 0) continue;
      largest = std::max(largest, std::abs(change) / q.inverseMass);
      lambda[k] = next;
      if (q.a >= 0) {
        moves[q.a].dx += change * q.inverseMassA * q.n;
        moves[q.a].dtheta += change * q.inertiaCa;
      }
      if (q.b >= 0) {
        moves[q.b].dx -= change * q.inverseMassB * q.n;
        moves[q.b].dtheta -= change * q.inertiaCb;
      }
    }
    if (largest <= tolerance) break;
  }
}

}  // namespace

template <int d>
double solveJointPushOut(const std::vector<JointBody<d>>& bodies, const std::vector<JointPoint<d>>& points, int sweeps,
                         double tolerance, std::vector<JointMove<d>>& moves) {
  moves.assign(bodies.size(), JointMove<d>{});
  std::vector<Row<d>> rows(points.size());
  for (std::size_t k = 0; k < points.size(); ++k) {
    const JointPoint<d>& p = points[k];
    Row<d>& r = rows[k];
    double mass = 0;
    if (p.a >= 0) {
      r.ca = cross<d>(p.ra, p.n);
      r.inertiaCa = bodies[p.a].inverseInertia * r.ca;
      mass += bodies[p.a].inverseMass + r.ca.dot(r.inertiaCa);
    }
    if (p.b >= 0) {
      r.cb = cross<d>(p.rb, p.n);
      r.inertiaCb = bodies[p.b].inverseInertia * r.cb;
      mass += bodies[p.b].inverseMass + r.cb.dot(r.inertiaCb);
    }
    r.inverseMass = mass > 0 ? 1 / mass : 0;
  }
  auto gained = [&](std::size_t k) { return separationGained<d>(points[k], rows[k], moves); };
  auto apply = [&](std::size_t k, double change) { moveBodies<d>(bodies, points[k], rows[k], change, moves); };
  std::vector<double> lambda(points.size(), 0.0);
  if (points.size() <= static_cast<std::size_t>(kDenseJointPoints)) {
    solveDense<d>(bodies, points, rows, lambda);
    for (std::size_t k = 0; k < points.size(); ++k) apply(k, lambda[k]);
  } else if (!sweepJamsAtOnce<d>(bodies, points, rows, sweeps, tolerance, lambda, moves)) {
    sweepInOrder<d>(bodies, points, rows, sweeps, tolerance, moves);
  }
  double violation = 0;
  for (std::size_t k = 0; k < points.size(); ++k) violation = std::max(violation, points[k].depth - gained(k));
  return violation;
}

template double solveJointPushOut<2>(const std::vector<JointBody<2>>&, const std::vector<JointPoint<2>>&, int, double,
                                     std::vector<JointMove<2>>&);
template double solveJointPushOut<3>(const std::vector<JointBody<3>>&, const std::vector<JointPoint<3>>&, int, double,
                                     std::vector<JointMove<3>>&);

}  // namespace monolith::solvers::contact
