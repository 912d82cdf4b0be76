#pragma once
// Reproducible random vectors for operator tests (symmetry, positivity, projections).
#include <Eigen/Core>
#include <random>

namespace monolith::test {

// n entries uniform in [-1, 1] from a fixed seed: the same vector on every run and machine
// (std::mt19937 is fully specified).
inline Eigen::VectorXd randomVector(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> dist(-1, 1);
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) v[i] = dist(rng);
  return v;
}

}  // namespace monolith::test
