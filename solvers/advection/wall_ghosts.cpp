#include "solvers/advection/wall_ghosts.h"

#include <optional>

namespace monolith::solvers {

namespace {
// Face one step from f along b (periodic axes wrap), if it exists.
template <int d>
std::optional<int> stepFace(const MacLayout<d>& layout, int axis, typename MacLayout<d>::Index f, int b, int step) {
  const auto dims = layout.faceDims(axis);
  f[b] += step;
  if (layout.periodic[b]) f[b] = (f[b] + dims[b]) % dims[b];
  else if (f[b] < 0 || f[b] >= dims[b]) return std::nullopt;
  return layout.faceIndex(axis, f);
}

// A prescribed face with a fluid cell on one side lies on the fluid's boundary (a side of the
// staircase): its prescribed velocity is the no-penetration condition at that very point, exact
// there, and the advection also reads it along its own axis.
template <int d>
bool onFluidBoundary(const FluidDomain<d>& domain, int face) {
  for (int which = 0; which < 2; ++which) {
    int cell = -1;
    if (domain.faceCell(face, which, cell) && domain.cells[cell] == CellKind::Fluid) return true;
  }
  return false;
}
}  // namespace

template <int d>
std::vector<GhostRule> obstacleWallGhosts(const FluidDomain<d>& domain) {
  std::vector<GhostRule> rules;
  if (domain.wallDistance.empty()) return rules;
  const MacLayout<d>& layout = domain.layout;
  for (int g = 0; g < layout.totalFaces(); ++g) {
    if (domain.faces[g] != FaceKind::Free) continue;
    const auto [a, f] = layout.faceCoord(g);
    for (int b = 0; b < d; ++b) {
      if (b == a) continue;
      for (int s = 0; s < 2; ++s) {
        const int towards = s == 0 ? -1 : 1;
        const auto h = stepFace(layout, a, f, b, towards);
        if (!h || domain.faces[*h] != FaceKind::Prescribed || onFluidBoundary(domain, *h)) continue;
        const double theta = domain.wallDistance[FluidDomain<d>::wallDistanceIndex(g, b, s)];
        if (theta < 0.5) {
          const auto o = stepFace(layout, a, f, b, -towards);
          if (o && domain.faces[*o] == FaceKind::Free) {
            rules.push_back({*h, *o, -(1 - theta) / (1 + theta)});
            continue;
          }
        }
        rules.push_back({*h, g, ghostFactor(theta)});
      }
    }
  }
  return rules;
}

template std::vector<GhostRule> obstacleWallGhosts<2>(const FluidDomain<2>&);
template std::vector<GhostRule> obstacleWallGhosts<3>(const FluidDomain<3>&);

}  // namespace monolith::solvers
