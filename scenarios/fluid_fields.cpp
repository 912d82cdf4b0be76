#include "scenarios/fluid_fields.h"

#include <algorithm>
#include <cmath>

#include "solvers/mac_layout.h"

namespace monolith {

namespace {

template <int d>
solvers::MacLayout<d> layoutOf(const MacGrid<d>& grid) {
  std::array<bool, d> periodic{};
  for (int a = 0; a < d; ++a) periodic[a] = grid.periodic(a);
  return solvers::MacLayout<d>(grid.cells, grid.dx, grid.origin, periodic);
}

// Multilinear interpolation of values stored on a regular lattice of `dims` points whose point
// k sits at `lower + dx * k`; periodic axes wrap, others clamp the lattice coordinate to
// [minK[a], maxK[a]] (which may reach half a cell into ghost points the value functor supplies).
template <int d, class Value>
double interpolate(const Eigen::Matrix<int, d, 1>& dims, const Eigen::Matrix<double, d, 1>& lower, double dx,
                   const std::array<bool, d>& periodic, const Eigen::Matrix<double, d, 1>& x, Value&& value,
                   const Eigen::Matrix<double, d, 1>& minK, const Eigen::Matrix<double, d, 1>& maxK) {
  Eigen::Matrix<int, d, 1> base;
  Eigen::Matrix<double, d, 1> w;
  for (int a = 0; a < d; ++a) {
    double s = (x[a] - lower[a]) / dx;
    if (!periodic[a]) s = std::clamp(s, minK[a], maxK[a]);
    const double fl = std::floor(s);
    base[a] = static_cast<int>(fl);
    w[a] = s - fl;
  }
  double result = 0;
  for (int corner = 0; corner < (1 << d); ++corner) {
    Eigen::Matrix<int, d, 1> k;
    double weight = 1;
    for (int a = 0; a < d; ++a) {
      const int bit = (corner >> a) & 1;
      k[a] = base[a] + bit;
      weight *= bit ? w[a] : 1 - w[a];
      if (periodic[a]) k[a] = ((k[a] % dims[a]) + dims[a]) % dims[a];
      else if (weight == 0) k[a] = std::clamp(k[a], 0, dims[a] - 1);  // unused corner: stay in range
    }
    if (weight != 0) result += weight * value(k);
  }
  return result;
}

}  // namespace

template <int d>
CellFields cellFields(const MacGrid<d>& grid) {
  const auto layout = layoutOf(grid);
  const int n = layout.cellCount();
  CellFields out;
  out.velocity.assign(d * n, 0.0);
  out.divergence.assign(n, 0.0);
  out.vorticity.assign((d == 3 ? 3 : 1) * n, 0.0);
  for (int c = 0; c < n; ++c) {
    const auto cell = layout.cellCoord(c);
    double flux = 0;
    for (int a = 0; a < d; ++a) {
      Eigen::Matrix<int, d, 1> upper = cell;
      ++upper[a];
      const double lo = grid.u[layout.faceIndex(a, cell)], hi = grid.u[layout.faceIndex(a, upper)];
      out.velocity[d * c + a] = 0.5 * (lo + hi);
      flux += hi - lo;
    }
    out.divergence[c] = flux / grid.dx;
  }
  // Vorticity from central differences of cell velocities (one-sided at non-periodic walls).
  auto cellVelocity = [&](Eigen::Matrix<int, d, 1> c, int comp) {
    for (int a = 0; a < d; ++a) {
      if (layout.periodic[a]) c[a] = (c[a] + layout.cells[a]) % layout.cells[a];
      else c[a] = std::clamp(c[a], 0, layout.cells[a] - 1);
    }
    return out.velocity[d * layout.cellIndex(c) + comp];
  };
  auto derivative = [&](const Eigen::Matrix<int, d, 1>& c, int comp, int axis) {
    Eigen::Matrix<int, d, 1> m = c, p = c;
    --m[axis];
    ++p[axis];
    double span = 2 * grid.dx;
    if (!layout.periodic[axis] && (c[axis] == 0 || c[axis] == layout.cells[axis] - 1)) span = grid.dx;
    return (cellVelocity(p, comp) - cellVelocity(m, comp)) / span;
  };
  for (int c = 0; c < n; ++c) {
    const auto cell = layout.cellCoord(c);
    if constexpr (d == 2) {
      out.vorticity[c] = derivative(cell, 1, 0) - derivative(cell, 0, 1);
    } else {
      out.vorticity[3 * c + 0] = derivative(cell, 2, 1) - derivative(cell, 1, 2);
      out.vorticity[3 * c + 1] = derivative(cell, 0, 2) - derivative(cell, 2, 0);
      out.vorticity[3 * c + 2] = derivative(cell, 1, 0) - derivative(cell, 0, 1);
    }
  }
  return out;
}

// Velocity component `axis` sampled up to the domain walls: across a non-periodic axis b != axis
// the lattice of faces stops half a cell from the wall, so a ghost layer supplies the wall
// condition there: mirrored about the wall velocity for a no-slip wall or an inflow (the wall
// value is met at the wall), copied (zero shear) for slip walls and outflow.
template <int d>
Eigen::Matrix<double, d, 1> sampleVelocity(const MacGrid<d>& grid, const Eigen::Matrix<double, d, 1>& x) {
  using Index = Eigen::Matrix<int, d, 1>;
  using VecD = Eigen::Matrix<double, d, 1>;
  const auto layout = layoutOf(grid);
  VecD v;
  for (int axis = 0; axis < d; ++axis) {
    VecD lower = grid.origin + VecD::Constant(0.5 * grid.dx);
    lower[axis] = grid.origin[axis];
    const Index dims = layout.faceDims(axis);
    VecD minK = VecD::Zero(), maxK = (dims.array() - 1).template cast<double>().matrix();
    for (int b = 0; b < d; ++b)
      if (b != axis && !layout.periodic[b]) {
        minK[b] = -0.5;
        maxK[b] = dims[b] - 0.5;
      }
    auto value = [&](Index f) {
      for (int b = 0; b < d; ++b) {
        if (b == axis || layout.periodic[b] || (f[b] >= 0 && f[b] < dims[b])) continue;
        const int side = 2 * b + (f[b] < 0 ? 0 : 1);
        f[b] = f[b] < 0 ? 0 : dims[b] - 1;
        const double inside = grid.u[layout.faceIndex(axis, f)];
        const SideCondition<d>& c = grid.sides[side];
        const bool dirichlet = (c.type == DomainSide::Wall && !c.slip) || c.type == DomainSide::Inflow;
        const double wall = c.type == DomainSide::Inflow && c.parabolic ? 0.0 : c.velocity[axis];
        return dirichlet ? 2 * wall - inside : inside;
      }
      return grid.u[layout.faceIndex(axis, f)];
    };
    v[axis] = interpolate<d>(dims, lower, grid.dx, layout.periodic, x, value, minK, maxK);
  }
  return v;
}

template <int d>
double samplePressure(const MacGrid<d>& grid, const Eigen::Matrix<double, d, 1>& x) {
  const auto layout = layoutOf(grid);
  const Eigen::Matrix<double, d, 1> lower = grid.origin + Eigen::Matrix<double, d, 1>::Constant(0.5 * grid.dx);
  return interpolate<d>(layout.cells, lower, grid.dx, layout.periodic, x,
                        [&](const Eigen::Matrix<int, d, 1>& c) { return grid.p[layout.cellIndex(c)]; },
                        Eigen::Matrix<double, d, 1>::Zero(), (layout.cells.array() - 1).template cast<double>().matrix());
}

template CellFields cellFields<2>(const MacGrid<2>&);
template CellFields cellFields<3>(const MacGrid<3>&);
template Eigen::Matrix<double, 2, 1> sampleVelocity<2>(const MacGrid<2>&, const Eigen::Matrix<double, 2, 1>&);
template Eigen::Matrix<double, 3, 1> sampleVelocity<3>(const MacGrid<3>&, const Eigen::Matrix<double, 3, 1>&);
template double samplePressure<2>(const MacGrid<2>&, const Eigen::Matrix<double, 2, 1>&);
template double samplePressure<3>(const MacGrid<3>&, const Eigen::Matrix<double, 3, 1>&);

}  // namespace monolith
