#include "solvers/contact/central_normal_contact.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>

namespace monolith::solvers::contact {

namespace {

constexpr int kMaxActiveSetRounds = 1000;
constexpr int kMaxGaussSeidelSweeps = 10000;
constexpr double kGaussSeidelTolerance = 1e-13;  // velocity change per sweep, relative to the largest gap

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

// The same problem (lambda >= 0, post-contact normal velocity >= target, complementary) by
// projected Gauss-Seidel from lambda = 0, for the rare configurations where the active-set loop
// cycles (random normals in every direction; a resting face never does). Each update minimizes
// the problem's convex energy along one lambda, so it converges and never adds energy.
template <int d>
void projectedGaussSeidel(const DofMat<d>& M, const std::vector<Dof<d>>& g, const std::vector<CentralNormalOuter<d>>& outers,
                          const std::vector<double>& gap, std::vector<double>& lambda) {
  const int n = static_cast<int>(outers.size());
  const DofMat<d> Minv = M.inverse();
  std::vector<Dof<d>> Mg(n);
  std::vector<double> diagonal(n);
  for (int o = 0; o < n; ++o) {
    Mg[o] = Minv * g[o];
    diagonal[o] = 1 / outers[o].mass + g[o].dot(Mg[o]);
  }
  lambda.assign(n, 0.0);
  Dof<d> dxi = Dof<d>::Zero();  // the body's velocity change
  double scale = 0;
  for (int o = 0; o < n; ++o) scale = std::max(scale, std::abs(gap[o]));
  for (int sweep = 0; sweep < kMaxGaussSeidelSweeps; ++sweep) {
    double largest = 0;
    for (int o = 0; o < n; ++o) {
      // Still wanted normal velocity change of particle o relative to the body.
      const double wanted = gap[o] - lambda[o] / outers[o].mass + g[o].dot(dxi);
      const double next = std::max(0.0, lambda[o] + wanted / diagonal[o]);
      const double change = next - lambda[o];
      if (change == 0) continue;
      lambda[o] = next;
      dxi -= change * Mg[o];
      largest = std::max(largest, std::abs(change) / outers[o].mass);
    }
    if (largest <= kGaussSeidelTolerance * scale) break;
  }
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
    bool converged = false;
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
      // Murty's least-index rule: flip the first contact that pulls (active, lambda < 0) or
      // would approach after the body's change (inactive); on this P-matrix problem it ends.
      bool changed = false;
      for (int o = 0; o < n && !changed; ++o) {
        const double lambda = outers[o].mass * (gap[o] + g[o].dot(dxi));
        if (active[o] ? lambda < 0 : lambda > 0) active[o] = !active[o], changed = true;
      }
      for (int o = 0; o < n; ++o) out.lambda[o] = active[o] ? outers[o].mass * (gap[o] + g[o].dot(dxi)) : 0.0;
      if (!changed) {
        converged = true;
        break;
      }
    }
    if (!converged) projectedGaussSeidel(M, g, outers, gap, out.lambda);
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
