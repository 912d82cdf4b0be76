#include "systems/fluid_preconditioner_kind.h"

namespace monolith {

solvers::PoissonPreconditionerKind poissonPreconditionerKindOf(FluidSolverSettings::Preconditioner p) {
  using P = FluidSolverSettings::Preconditioner;
  using K = solvers::PoissonPreconditionerKind;
  switch (p) {
    case P::None: return K::None;
    case P::Jacobi: return K::Jacobi;
    case P::IC0: return K::IC0;
    case P::MIC0: return K::MIC0;
    case P::Multigrid: return K::Multigrid;
  }
  return K::MIC0;
}

}  // namespace monolith
