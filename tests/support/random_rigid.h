#pragma once
// Random rigid-body quantities for the contact unit tests: vectors with uniform components and
// symmetric positive definite inertia-like matrices (random rotation of a random diagonal).
#include <random>

#include <Eigen/Geometry>

#include "solvers/contact/rigid_math.h"

namespace monolith::test {

template <int d>
Eigen::Matrix<double, d, 1> randomVec(std::mt19937& rng, double scale = 1) {
  std::uniform_real_distribution<double> u(-scale, scale);
  Eigen::Matrix<double, d, 1> r;
  for (int i = 0; i < d; ++i) r(i) = u(rng);
  return r;
}

// R diag(a, b, c) R^T with a, b, c uniform in [lo, hi] (a number in [lo, hi] in 2-D).
template <int d>
solvers::contact::AngMat<d> randomInertiaLike(std::mt19937& rng, double lo, double hi) {
  std::uniform_real_distribution<double> u(lo, hi);
  if constexpr (d == 3) {
    const Eigen::Quaterniond q(Eigen::Vector4d(randomVec<4>(rng)).normalized());
    const Eigen::Matrix3d rot = q.toRotationMatrix();
    return rot * Eigen::Vector3d(u(rng), u(rng), u(rng)).asDiagonal() * rot.transpose();
  } else {
    return solvers::contact::AngMat<d>::Constant(u(rng));
  }
}

}  // namespace monolith::test
