#include "solvers/surface_tension/fast_marching.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <stdexcept>
#include <utility>

namespace monolith::solvers {

void fastMarchingRedistance(const MacLayout<2>& layout, std::vector<double>& phi, double band, double keep) {
  const int nx = layout.cells.x(), ny = layout.cells.y(), n = nx * ny;
  if (static_cast<int>(phi.size()) != n) throw std::invalid_argument("fastMarchingRedistance: phi has the wrong size");
  const double dx = layout.dx, limit = band * dx, infinity = std::numeric_limits<double>::infinity();
  std::vector<double> distance(n, infinity);
  std::vector<char> accepted(n, 0);
  // The face neighbours of cell c along `axis` (-1 where the grid ends).
  auto neighbour = [&](int c, int axis, int side) {
    const int i = c % nx, j = c / nx;
    if (axis == 0) return (side < 0 ? i > 0 : i < nx - 1) ? c + side : -1;
    return (side < 0 ? j > 0 : j < ny - 1) ? c + side * nx : -1;
  };
  bool any = false;
  for (int c = 0; c < n; ++c) {
    if (keep > 0) {
      if (std::abs(phi[c]) <= keep * dx) distance[c] = std::abs(phi[c]), accepted[c] = 1, any = true;
      continue;
    }
    // Start cells: the nearer linear crossing per axis, combined as the distance to their line.
    double inverseSquares = 0;
    bool start = false, onInterface = phi[c] == 0;
    for (int axis = 0; axis < 2; ++axis) {
      double theta = infinity;
      for (int side : {-1, 1}) {
        const int m = neighbour(c, axis, side);
        if (m < 0 || (phi[m] < 0) == (phi[c] < 0)) continue;
        theta = std::min(theta, phi[c] / (phi[c] - phi[m]));
      }
      if (theta == infinity) continue;
      start = true;
      if (theta <= 0) onInterface = true;
      else inverseSquares += 1 / (theta * theta * dx * dx);
    }
    if (!start && !onInterface) continue;
    distance[c] = onInterface ? 0.0 : 1 / std::sqrt(inverseSquares);
    accepted[c] = 1;
    any = true;
  }
  if (!any) {  // no interface: every cell is far
    for (double& value : phi) value = value < 0 ? -limit : limit;
    return;
  }
  // The upwind update from the accepted neighbours.
  auto update = [&](int c) {
    double smallest[2] = {infinity, infinity};
    for (int axis = 0; axis < 2; ++axis)
      for (int side : {-1, 1}) {
        const int m = neighbour(c, axis, side);
        if (m >= 0 && accepted[m]) smallest[axis] = std::min(smallest[axis], distance[m]);
      }
    const double a = smallest[0], b = smallest[1];
    if (a == infinity || b == infinity || std::abs(a - b) >= dx) return std::min(a, b) + dx;
    return 0.5 * (a + b + std::sqrt(2 * dx * dx - (a - b) * (a - b)));
  };
  using Entry = std::pair<double, int>;  // (tentative distance, cell): ties go to the smaller index
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> trial;
  auto offer = [&](int c) {
    for (int axis = 0; axis < 2; ++axis)
      for (int side : {-1, 1}) {
        const int m = neighbour(c, axis, side);
        if (m < 0 || accepted[m]) continue;
        const double value = update(m);
        if (value < distance[m]) distance[m] = value, trial.emplace(value, m);
      }
  };
  for (int c = 0; c < n; ++c)
    if (accepted[c]) offer(c);
  while (!trial.empty()) {
    const auto [value, c] = trial.top();
    trial.pop();
    if (accepted[c] || value > distance[c]) continue;  // stale entry
    if (value > limit) break;
    accepted[c] = 1;
    offer(c);
  }
  for (int c = 0; c < n; ++c) {
    const double d = accepted[c] ? std::min(distance[c], limit) : limit;
    phi[c] = phi[c] < 0 ? -d : d;
  }
}

}  // namespace monolith::solvers
