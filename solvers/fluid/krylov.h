#pragma once
// Preconditioned conjugate gradients for the SPD systems of thesis Sec. 5.5.2 / 5.7 / 6.2.6
// (the thesis solves them with CG, Sec. 5.2). Generic over the matrix and preconditioner, which
// are passed as functors; deterministic on any thread count (all dot products go through
// parallel::dot, a parallel_deterministic_reduce over fixed 4096-entry chunks; vector updates are
// element-wise), so the iterates are bitwise identical for 1 and 2 threads.
//
// Singular systems (pure-Neumann pressure, Sec. 6.2.6): pass `project`, the orthogonal projector
// onto the complement of the null space. It is applied to the right-hand side, to the initial
// residual and to every preconditioned residual, so all search directions stay orthogonal to the
// null space even when the preconditioner does not preserve it, and the iterate converges to the
// minimum-norm solution (for the pressure: zero mean on every closed region).
#include <Eigen/Core>

#include <functional>

namespace monolith::solvers {

// out = Op(in); `out` arrives with the right size.
using LinearOperator = std::function<void(const Eigen::VectorXd& in, Eigen::VectorXd& out)>;
// In-place projection.
using Projector = std::function<void(Eigen::VectorXd& v)>;

struct CgSettings {
  int maxIterations = 1000;
  // Stop when ||r||_2 <= relativeTolerance ||b||_2 (b after projection) ...
  double relativeTolerance = 1e-10;
  // ... or when ||r||_inf <= absoluteTolerance (disabled when 0). The thesis' codes use an absolute
  // max-norm test in velocity units (notes 7.2); both are offered.
  double absoluteTolerance = 0;
};

struct CgReport {
  int iterations = 0;
  bool converged = false;
  double rhsNorm = 0;           // ||b||_2 after projection
  double residualNorm = 0;      // final recursive residual, 2-norm
  double residualMaxNorm = 0;   // final recursive residual, max-norm
  double trueResidualNorm = 0;  // ||b - A x||_2 recomputed at exit (one extra apply)
  double relativeResidual() const { return rhsNorm > 0 ? trueResidualNorm / rhsNorm : 0.0; }
};

// Solves A x = b starting from the given x (resized and zeroed if its size differs).
// `preconditioner` and `project` may be empty (identity / no null space).
CgReport conjugateGradient(const LinearOperator& A, const LinearOperator& preconditioner, const Projector& project,
                           const Eigen::VectorXd& b, Eigen::VectorXd& x, const CgSettings& settings);

// z = r ./ diagonal (entries of `diagonal` must be positive).
LinearOperator jacobiPreconditioner(Eigen::VectorXd diagonal);

}  // namespace monolith::solvers
