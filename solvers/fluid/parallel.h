#pragma once
// Deterministic data-parallel building blocks for the fluid solvers (docs/architecture.md,
// "Determinism by construction"): every loop writes only its own index, and every floating-point
// reduction is split into the same fixed-size chunks on any number of threads, so results are
// bitwise identical for 1 and 2 threads.
#include <Eigen/Core>
#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>

namespace monolith::solvers::parallel {

// Rows per task. Large enough that task overhead is small next to a stencil row; the value does
// not change results (loops are per-row), only the reduction below depends on a grain and it uses
// its own fixed constant.
inline constexpr int kRowGrain = 2048;
// Chunk size of the deterministic reductions. parallel_deterministic_reduce with its default
// simple_partitioner splits a range into the same binary tree of chunks whatever the thread count,
// so the summation order depends only on n and this constant.
inline constexpr int kReduceGrain = 4096;

// Calls body(i) for i in [0, n); body must write only data owned by row i.
template <class Body>
void forRows(int n, const Body& body) {
  if (n <= kRowGrain) {
    for (int i = 0; i < n; ++i) body(i);
    return;
  }
  tbb::parallel_for(tbb::blocked_range<int>(0, n, kRowGrain), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i != r.end(); ++i) body(i);
  });
}

// Deterministic sum over i in [0, n) of term(i).
template <class Term>
double sum(int n, const Term& term) {
  return tbb::parallel_deterministic_reduce(
      tbb::blocked_range<int>(0, n, kReduceGrain), 0.0,
      [&](const tbb::blocked_range<int>& r, double acc) {
        double local = 0;
        for (int i = r.begin(); i != r.end(); ++i) local += term(i);
        return acc + local;
      },
      [](double a, double b) { return a + b; });
}

inline double dot(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  const double* pa = a.data();
  const double* pb = b.data();
  return sum(static_cast<int>(a.size()), [=](int i) { return pa[i] * pb[i]; });
}

// Max-norm (max is exact, so any split is deterministic; the same tree is used for simplicity).
inline double maxAbs(const Eigen::VectorXd& a) {
  const double* pa = a.data();
  return tbb::parallel_deterministic_reduce(
      tbb::blocked_range<int>(0, static_cast<int>(a.size()), kReduceGrain), 0.0,
      [=](const tbb::blocked_range<int>& r, double acc) {
        for (int i = r.begin(); i != r.end(); ++i) acc = std::max(acc, std::abs(pa[i]));
        return acc;
      },
      [](double a, double b) { return std::max(a, b); });
}

}  // namespace monolith::solvers::parallel
