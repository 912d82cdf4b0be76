// Pressure Poisson benchmark (solvers/fluid): PCG on the pure-Neumann closed-box Poisson problem
// G^T beta^-1 G p = G^T u* (random u*) with each preconditioner (none, IC(0), MIC(0), multigrid) on
// 1 and 2 threads (tbb::task_arena). Prints a markdown table: iterations, setup and solve seconds,
// and the final true relative residual (speed against error), plus whether the 1- and 2-thread
// solutions are bitwise identical. Relative tolerance 1e-8 (2-norm).
// A combination whose predicted solve time exceeds 60 s (from the same preconditioner one size
// down: x8 per 2-D refinement, x16 per 3-D one, i.e. unknowns times the iteration growth of plain
// CG), or would push the whole run past 280 s, is skipped with a note.
// A second table times the dot product (the only reduction in CG) three ways: the deterministic
// parallel reduce used by krylov.cpp on 1 and 2 threads, a plain serial loop and serial Kahan.
#include "solvers/fluid/boundary.h"
#include "solvers/fluid/krylov.h"
#include "solvers/fluid/operators.h"
#include "solvers/fluid/parallel.h"
#include "solvers/fluid/poisson_preconditioner.h"
#include "solvers/fluid/spd_systems.h"

#include <oneapi/tbb/task_arena.h>

#include <chrono>
#include <cstdio>
#include <cmath>
#include <cstring>
#include <map>
#include <random>
#include <string>

using namespace monolith::solvers;
using Kind = PoissonPreconditionerKind;

namespace {

double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

template <int d>
FluidDomain<d> closedBox(int n) {
  using S = SideSpec<d>;
  BoxSpec<d> sides;
  sides.fill(S::wall());
  return boxDomain(MacLayout<d>(MacLayout<d>::Index::Constant(n), 1.0 / n), sides);
}

struct Result {
  int iterations = 0;
  double setup = 0, solve = 0, residual = 0;
  Eigen::VectorXd x;
};

template <int d>
Result run(const FluidOperators<d>& ops, const Eigen::VectorXd& b, Kind kind, int threads) {
  Result r;
  tbb::task_arena arena(threads);
  arena.execute([&] {
    const double t0 = now();
    const PoissonPreconditioner<d> pre(ops, kind);
    const double t1 = now();
    PoissonOperator<d> A(ops);
    r.x.setZero(ops.pressureCount());
    const CgReport report = conjugateGradient(A.asOperator(), pre.asOperator(), closedRegionProjector(ops.dofs), b,
                                              r.x, CgSettings{100000, 1e-8, 0});
    const double t2 = now();
    r.iterations = report.iterations;
    r.setup = t1 - t0;
    r.solve = t2 - t1;
    r.residual = report.relativeResidual();
  });
  return r;
}

std::map<std::string, double> lastSolve;  // (dimension, preconditioner, threads) -> seconds
double benchStart = 0;
constexpr double kCombinationLimit = 60.0, kTotalBudget = 280.0;

template <int d>
void benchmark(int n) {
  const FluidOperators<d> ops = buildFluidOperators(closedBox<d>(n), FluidParameters{1.0, 0.0, 0.01});
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> dist(-1, 1);
  Eigen::VectorXd u(ops.velocityCount());
  for (int i = 0; i < u.size(); ++i) u[i] = dist(rng);
  Eigen::VectorXd b(ops.pressureCount());
  applyGradientTranspose(ops, u, b);
  const std::string grid = d == 2 ? std::to_string(n) + "^2" : std::to_string(n) + "^3";
  for (Kind kind : {Kind::None, Kind::IC0, Kind::MIC0, Kind::Multigrid}) {
    Eigen::VectorXd first;
    for (int threads : {1, 2}) {
      const std::string key = std::to_string(d) + toString(kind) + std::to_string(threads);
      const double growth = d == 2 ? 8.0 : 16.0;
      const double predicted = lastSolve.count(key) ? lastSolve[key] * growth : 0.0;
      const double elapsed = now() - benchStart;
      if (predicted > kCombinationLimit || elapsed + predicted > kTotalBudget) {
        std::printf("| %s | %d | %s | %d | skipped: predicted %.0f s (limit %.0f s, %.0f s of %.0f s budget used) | | | | | |\n",
                    grid.c_str(), ops.pressureCount(), toString(kind).c_str(), threads, predicted, kCombinationLimit,
                    elapsed, kTotalBudget);
        lastSolve[key] = predicted;
        continue;
      }
      const Result r = run(ops, b, kind, threads);
      lastSolve[key] = r.solve;
      std::string same = "-";
      if (threads == 1) first = r.x;
      else if (first.size() == r.x.size())
        same = std::memcmp(first.data(), r.x.data(), sizeof(double) * first.size()) == 0 ? "yes" : "NO";
      std::printf("| %s | %d | %s | %d | %d | %.3f | %.3f | %.2e | %.1e | %s |\n", grid.c_str(), ops.pressureCount(),
                  toString(kind).c_str(), threads, r.iterations, r.setup, r.solve,
                  r.iterations > 0 ? r.solve / r.iterations : 0.0, r.residual, same.c_str());
      std::fflush(stdout);
    }
  }
}

// Best of 20 repetitions of a dot product of length n, in microseconds.
template <class Dot>
double timeDot(const Dot& dot, double& result) {
  double best = 1e30;
  for (int rep = 0; rep < 20; ++rep) {
    asm volatile("" ::: "memory");  // keep the compiler from hoisting the loop-invariant dot
    const double t0 = now();
    result = dot();
    asm volatile("" ::: "memory");
    best = std::min(best, now() - t0);
  }
  return best * 1e6;
}

void benchmarkDot(int n) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> dist(-1, 1);
  Eigen::VectorXd a(n), b(n);
  for (int i = 0; i < n; ++i) {
    a[i] = dist(rng);
    b[i] = dist(rng);
  }
  double r1 = 0, r2 = 0, rs = 0, rk = 0;
  double t1 = 0, t2 = 0;
  for (int threads : {1, 2}) {
    tbb::task_arena arena(threads);
    arena.execute([&] { (threads == 1 ? t1 : t2) = timeDot([&] { return parallel::dot(a, b); }, threads == 1 ? r1 : r2); });
  }
  // The pointers are laundered through an empty asm so that the loop cannot be hoisted out of the
  // timing loop (it is loop invariant).
  const double ts = timeDot([&] {
    const double* pa = a.data();
    const double* pb = b.data();
    asm volatile("" : "+r"(pa), "+r"(pb));
    double s = 0;
    for (int i = 0; i < n; ++i) s += pa[i] * pb[i];
    return s;
  }, rs);
  const double tk = timeDot([&] {
    const double* pa = a.data();
    const double* pb = b.data();
    asm volatile("" : "+r"(pa), "+r"(pb));
    double s = 0, c = 0;  // Kahan compensated summation
    for (int i = 0; i < n; ++i) {
      const double y = pa[i] * pb[i] - c;
      const double t = s + y;
      c = (t - s) - y;
      s = t;
    }
    return s;
  }, rk);
  std::printf("| %d | %.0f | %.0f | %.0f | %.0f | %s | %.1e | %.1e |\n", n, t1, t2, ts, tk, r1 == r2 ? "yes" : "NO",
              std::abs(r1 - rk) / std::abs(rk), std::abs(rs - rk) / std::abs(rk));
}

}  // namespace

int main(int argc, char** argv) {
  // --quick: only the smaller grids (a smoke run).
  const bool quick = argc > 1 && std::string(argv[1]) == "--quick";
  const double start = now();
  benchStart = start;
  std::printf("Dot product timing (microseconds, best of 20):\n\n");
  std::printf("| n | deterministic reduce, 1 thread | same, 2 threads | serial | serial Kahan | 1 = 2 threads bitwise | "
              "reduce: rel. diff to Kahan | serial: rel. diff to Kahan |\n|---|---|---|---|---|---|---|---|\n");
  for (int n : {65536, 1048576}) benchmarkDot(n);
  std::printf("\nClosed-box Poisson, PCG to 1e-8 relative residual; setup = preconditioner build.\n\n");
  std::printf("| grid | unknowns | preconditioner | threads | iterations | setup s | solve s | s / iteration | "
              "true rel. residual | bitwise = 1 thread |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
  for (int n : {256, 512, 1024})
    if (!quick || n < 1024) benchmark<2>(n);
  for (int n : {64, 128})
    if (!quick || n < 128) benchmark<3>(n);
  std::printf("\ntotal %.1f s\n", now() - start);
  return 0;
}
