#pragma once
// Preconditioners for the pressure Poisson block G^T beta^-1 G, built once per set of operators
// and reused across solves (notes 4.4: IC(0) of the assembled Poisson block in the thesis code).
#include "solvers/fluid/incomplete_cholesky.h"
#include "solvers/fluid/krylov.h"
#include "solvers/fluid/multigrid.h"
#include "solvers/fluid/operators.h"

#include <memory>
#include <string>

namespace monolith::solvers {

enum class PoissonPreconditionerKind { None, Jacobi, IC0, MIC0, Multigrid };

std::string toString(PoissonPreconditionerKind kind);

// MIC(0) relaxation: the customary 0.97 (full modification, 1.0, is sensitive to the near-zero
// pivots of pure-Neumann problems).
inline constexpr double kMicRelaxation = 0.97;

template <int d>
class PoissonPreconditioner {
 public:
  PoissonPreconditioner(const FluidOperators<d>& ops, PoissonPreconditionerKind kind,
                        const MultigridSettings& multigrid = {});
  PoissonPreconditionerKind kind() const { return kind_; }
  // Identity for None.
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const;
  // Empty std::function for None (so CG skips the copy).
  LinearOperator asOperator() const;
  const PoissonMultigrid<d>* multigrid() const { return mg_.get(); }

 private:
  PoissonPreconditionerKind kind_;
  LinearOperator jacobi_;
  IncompleteCholesky ic_;
  std::unique_ptr<PoissonMultigrid<d>> mg_;
};

}  // namespace monolith::solvers
