// Preconditioned CG (see krylov.h).
#include "solvers/fluid/krylov.h"

#include "solvers/fluid/parallel.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace monolith::solvers {

namespace {
// p = z + beta p (element-wise: deterministic).
void xpby(const Eigen::VectorXd& z, double beta, Eigen::VectorXd& p) {
  const double* pz = z.data();
  double* pp = p.data();
  parallel::forRows(static_cast<int>(p.size()), [=](int i) { pp[i] = pz[i] + beta * pp[i]; });
}

struct Norms {
  double squared = 0, max = 0;
};

// x += alpha p, r -= alpha q, and the new ||r||^2 and ||r||_inf, in one pass over memory (CG is
// bandwidth bound). Chunks are the fixed ones of parallel_deterministic_reduce: deterministic.
Norms updateIterate(double alpha, const Eigen::VectorXd& p, const Eigen::VectorXd& q, Eigen::VectorXd& x,
                    Eigen::VectorXd& r) {
  const double* pp = p.data();
  const double* pq = q.data();
  double* px = x.data();
  double* pr = r.data();
  return tbb::parallel_deterministic_reduce(
      tbb::blocked_range<int>(0, static_cast<int>(r.size()), parallel::kReduceGrain), Norms{},
      [=](const tbb::blocked_range<int>& range, Norms acc) {
        double squared = 0;
        for (int i = range.begin(); i != range.end(); ++i) {
          px[i] += alpha * pp[i];
          const double ri = pr[i] - alpha * pq[i];
          pr[i] = ri;
          squared += ri * ri;
          acc.max = std::max(acc.max, std::abs(ri));
        }
        acc.squared += squared;
        return acc;
      },
      [](Norms a, const Norms& b) {
        a.squared += b.squared;
        a.max = std::max(a.max, b.max);
        return a;
      });
}
}  // namespace

CgReport conjugateGradient(const LinearOperator& A, const LinearOperator& preconditioner, const Projector& project,
                           const Eigen::VectorXd& bIn, Eigen::VectorXd& x, const CgSettings& settings) {
  const Eigen::Index n = bIn.size();
  if (x.size() != n) x.setZero(n);
  Eigen::VectorXd b = bIn;
  if (project) project(b);
  CgReport report;
  report.rhsNorm = std::sqrt(parallel::dot(b, b));

  Eigen::VectorXd r(n), z(n), p(n), q(n);
  A(x, q);
  r = b - q;
  if (project) project(r);
  const double relTarget = settings.relativeTolerance * report.rhsNorm;
  auto done = [&](double rr, double rmax) {
    return std::sqrt(rr) <= relTarget || (settings.absoluteTolerance > 0 && rmax <= settings.absoluteTolerance);
  };
  double rr = parallel::dot(r, r);
  double rmax = parallel::maxAbs(r);
  if (!done(rr, rmax)) {
    // Without preconditioner and projection z is r itself (no copy).
    const bool plain = !preconditioner && !project;
    const Eigen::VectorXd& zr = plain ? r : z;
    auto precondition = [&] {
      if (plain) return;
      if (preconditioner) preconditioner(r, z); else z = r;
      if (project) project(z);
    };
    precondition();
    p = zr;
    double rz = parallel::dot(r, zr);
    for (int it = 0; it < settings.maxIterations; ++it) {
      A(p, q);
      const double pq = parallel::dot(p, q);
      if (!(pq > 0) || !(rz > 0)) break;  // breakdown: A or the preconditioner not SPD on this vector
      const double alpha = rz / pq;
      const Norms norms = updateIterate(alpha, p, q, x, r);
      ++report.iterations;
      rr = norms.squared;
      rmax = norms.max;
      if (done(rr, rmax)) break;
      precondition();
      const double rzNew = plain ? rr : parallel::dot(r, zr);
      xpby(zr, rzNew / rz, p);
      rz = rzNew;
    }
  }
  report.residualNorm = std::sqrt(rr);
  report.residualMaxNorm = rmax;
  report.converged = done(rr, rmax);
  A(x, q);
  r = b - q;
  if (project) project(r);
  report.trueResidualNorm = std::sqrt(parallel::dot(r, r));
  return report;
}

LinearOperator jacobiPreconditioner(Eigen::VectorXd diagonal) {
  if (diagonal.size() > 0 && !(diagonal.minCoeff() > 0))
    throw std::invalid_argument("jacobiPreconditioner: the diagonal must be positive");
  Eigen::VectorXd inverse = diagonal.cwiseInverse();
  return [inverse](const Eigen::VectorXd& r, Eigen::VectorXd& z) {
    const double* pr = r.data();
    const double* pi = inverse.data();
    double* pz = z.data();
    parallel::forRows(static_cast<int>(r.size()), [=](int i) { pz[i] = pr[i] * pi[i]; });
  };
}

}  // namespace monolith::solvers
