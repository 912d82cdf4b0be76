#pragma once
// From the scene's MacGrid component to the solvers' description of the fluid's degrees of
// freedom (solvers/fluid/boundary.h): side conditions, inflow profiles, obstacle cells.
#include "components/mac_grid.h"
#include "solvers/fluid/boundary.h"

namespace monolith {

template <int d>
solvers::MacLayout<d> macLayoutOf(const MacGrid<d>& grid);

// Side conditions and solid cells of the grid. A parabolic inflow on side (axis a, lower or
// upper) has normal speed U prod_b 4 s_b (H_b - s_b) / H_b^2 over the tangential axes b, pointing
// into the domain (the Poiseuille / DFG profile).
template <int d>
solvers::FluidDomain<d> fluidDomainOf(const MacGrid<d>& grid);

}  // namespace monolith
