#pragma once
// Cell-centred fields derived from a MAC grid's face velocities, for frames, probes and
// diagnostics: velocity (average of the two faces per axis), divergence (net area-weighted
// flux over the cell volume) and vorticity (central differences of the cell velocities).
#include <vector>

#include "components/mac_grid.h"

namespace monolith {

struct CellFields {
  std::vector<double> velocity;    // d per cell
  std::vector<double> divergence;  // 1 per cell
  std::vector<double> vorticity;   // 1 per cell in 2-D, 3 in 3-D
};

template <int d>
CellFields cellFields(const MacGrid<d>& grid);

// Velocity at a point: each component interpolated (multi)linearly from its own faces.
template <int d>
Eigen::Matrix<double, d, 1> sampleVelocity(const MacGrid<d>& grid, const Eigen::Matrix<double, d, 1>& x);

// Pressure at a point, bilinear from cell centres (clamped at the domain).
template <int d>
double samplePressure(const MacGrid<d>& grid, const Eigen::Matrix<double, d, 1>& x);

}  // namespace monolith
