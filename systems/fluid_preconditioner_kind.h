#pragma once
// The scene's choice of pressure preconditioner (solvers.fluid.preconditioner) as the solvers'
// kind: one mapping for the fluid's own projection and the coupled fluid-structure solve.
#include "solvers/fluid/fluid_settings.h"
#include "solvers/fluid/poisson_preconditioner.h"

namespace monolith {

solvers::PoissonPreconditionerKind poissonPreconditionerKindOf(FluidSolverSettings::Preconditioner p);

}  // namespace monolith
