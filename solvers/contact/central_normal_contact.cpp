#include "solvers/contact/central_normal_contact.h"

#include <Eigen/Cholesky>
#include <algorithm>

namespace monolith::solvers::contact {

namespace {

constexpr int kMaxActiveSetRounds = 32;

template <int d>
using Dof = Eigen::Matrix<double, d + kAngularDim<d>, 1>;
template <int d>
using DofMat = Eigen::Matrix<double, d + kAngularDim<d>, d + kAngularDim<d>>;

template <int d>
Dof<d> rowOf(const CentralNormalOuter<d>& o) {
  Dof<d> g;
  g << o.n, cross<d>(o.r, o.n);
  return g;
}

}  // namespace

template <int d>
CentralNormalResult<d> solveCentralNormalContact(const CentralNormalBody<d>& body,
                                                 const std::vector<CentralNormalOuter<d>>& outers) {
  const int n = static_cast<int>(outers.size());
  CentralNormalResult<d> out;
  out.lambda.assign(n, 0.0);
  // Wanted normal velocity change of each particle alone: target - u.n (> 0: approaching).
  std::vector<double> gap(n);
  for (int o = 0; o < n; ++o) gap[o] = outers[o].target - outers[o].normalVelocity;
  if (body.infinite) {
    for (int o = 0; o < n; ++o) out.lambda[o] = gap[o] > 0 ? outers[o].mass * gap[o] : 0.0;
  } else {
    std::vector<Dof<d>> g(n);
    std::vector<char> active(n);
    for (int o = 0; o < n; ++o) {
      g[o] = rowOf(outers[o]);
      active[o] = gap[o] > 0;
    }
    DofMat<d> M = DofMat<d>::Zero();
    M.template topLeftCorner<d, d>() = body.mass * Mat<d>::Identity();
    M.template bottomRightCorner<kAngularDim<d>, kAngularDim<d>>() = body.inertia;
    for (int round = 0; round < kMaxActiveSetRounds; ++round) {
      DofMat<d> A = M;
      Dof<d> b = Dof<d>::Zero();
      for (int o = 0; o < n; ++o)
        if (active[o]) {
          A.noalias() += outers[o].mass * g[o] * g[o].transpose();
          b -= outers[o].mass * gap[o] * g[o];
        }
      const Dof<d> dxi = A.ldlt().solve(b);
      ++out.solves;
      bool changed = false;
      for (int o = 0; o < n; ++o) {
        const double lambda = outers[o].mass * (gap[o] + g[o].dot(dxi));
        out.lambda[o] = active[o] ? lambda : 0.0;
        if (active[o] && lambda < 0) active[o] = 0, changed = true;
      }
      // Only once nothing pulls: particles the body's change would now drive into it join.
      if (!changed)
        for (int o = 0; o < n; ++o)
          if (!active[o] && gap[o] + g[o].dot(dxi) > 0) active[o] = 1, changed = true;
      if (!changed) break;
    }
    // An unfinished loop (never seen) leaves pulls: drop them, keeping what is applied consistent.
    for (double& l : out.lambda) l = std::max(l, 0.0);
  }
  for (int o = 0; o < n; ++o) {
    if (out.lambda[o] <= 0) continue;
    ++out.active;
    const Vec<d> j = out.lambda[o] * outers[o].n;
    out.bodyImpulse -= j;
    out.bodyAngularImpulse -= cross<d>(outers[o].r, j);
  }
  return out;
}

template CentralNormalResult<2> solveCentralNormalContact<2>(const CentralNormalBody<2>&,
                                                             const std::vector<CentralNormalOuter<2>>&);
template CentralNormalResult<3> solveCentralNormalContact<3>(const CentralNormalBody<3>&,
                                                             const std::vector<CentralNormalOuter<3>>&);

}  // namespace monolith::solvers::contact
