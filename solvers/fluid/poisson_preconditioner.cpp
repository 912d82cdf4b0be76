// Poisson-block preconditioner selection (see poisson_preconditioner.h).
#include "solvers/fluid/poisson_preconditioner.h"

#include "solvers/fluid/spd_systems.h"

namespace monolith::solvers {

std::string toString(PoissonPreconditionerKind kind) {
  switch (kind) {
    case PoissonPreconditionerKind::None: return "none";
    case PoissonPreconditionerKind::Jacobi: return "jacobi";
    case PoissonPreconditionerKind::IC0: return "ic0";
    case PoissonPreconditionerKind::MIC0: return "mic0";
    case PoissonPreconditionerKind::Multigrid: return "mg";
  }
  return "?";
}

template <int d>
PoissonPreconditioner<d>::PoissonPreconditioner(const FluidOperators<d>& ops, PoissonPreconditionerKind kind,
                                                 const MultigridSettings& multigrid)
    : kind_(kind) {
  switch (kind) {
    case PoissonPreconditionerKind::None: break;
    case PoissonPreconditionerKind::Jacobi: {
      // Isolated cells (all faces prescribed) have a zero diagonal; any positive value will do there.
      Eigen::VectorXd diag = PoissonOperator<d>(ops).diagonal();
      for (double& v : diag)
        if (!(v > 0)) v = 1;
      jacobi_ = jacobiPreconditioner(diag);
      break;
    }
    case PoissonPreconditionerKind::IC0: ic_ = IncompleteCholesky(assemblePoisson(ops), 0.0); break;
    case PoissonPreconditionerKind::MIC0: ic_ = IncompleteCholesky(assemblePoisson(ops), kMicRelaxation); break;
    case PoissonPreconditionerKind::Multigrid: mg_ = std::make_unique<PoissonMultigrid<d>>(ops, multigrid); break;
  }
}

template <int d>
void PoissonPreconditioner<d>::apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const {
  switch (kind_) {
    case PoissonPreconditionerKind::None: z = r; break;
    case PoissonPreconditionerKind::Jacobi: jacobi_(r, z); break;
    case PoissonPreconditionerKind::IC0:
    case PoissonPreconditionerKind::MIC0: ic_.apply(r, z); break;
    case PoissonPreconditionerKind::Multigrid: mg_->apply(r, z); break;
  }
}

template <int d>
LinearOperator PoissonPreconditioner<d>::asOperator() const {
  if (kind_ == PoissonPreconditionerKind::None) return {};
  const PoissonPreconditioner* self = this;
  return [self](const Eigen::VectorXd& r, Eigen::VectorXd& z) { self->apply(r, z); };
}

template class PoissonPreconditioner<2>;
template class PoissonPreconditioner<3>;

}  // namespace monolith::solvers
