#include "solvers/surface_tension/level_set_tracking.h"

#include <algorithm>
#include <cmath>

#include "solvers/surface_tension/two_phase_flow.h"

namespace monolith::solvers {

double sampleCellField(const MacLayout<2>& layout, const std::vector<double>& phi, const Eigen::Vector2d& x) {
  const Eigen::Vector2d g = (x - layout.origin) / layout.dx - Eigen::Vector2d::Constant(0.5);
  const int nx = layout.cells.x(), ny = layout.cells.y();
  const double cx = std::clamp(g.x(), 0.0, nx - 1.0), cy = std::clamp(g.y(), 0.0, ny - 1.0);
  const int i = std::min(static_cast<int>(cx), nx - 2), j = std::min(static_cast<int>(cy), ny - 2);
  const double wx = cx - i, wy = cy - j;
  auto at = [&](int a, int b) { return phi[static_cast<std::size_t>(b) * nx + a]; };
  return (1 - wy) * ((1 - wx) * at(i, j) + wx * at(i + 1, j)) + wy * ((1 - wx) * at(i, j + 1) + wx * at(i + 1, j + 1));
}

namespace {
Eigen::Vector2d velocityAt(const MacLayout<2>& layout, const Eigen::VectorXd& u, const Eigen::Vector2d& x) {
  return {sampleFaceVelocity(layout, u, 0, x), sampleFaceVelocity(layout, u, 1, x)};
}
// The closest point of segment ab to x: its parameter t in [0, 1] along ab, and the distance.
struct ClosestOnSegment {
  double t, distance;
};
ClosestOnSegment closestOnSegment(const Eigen::Vector2d& x, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d e = b - a;
  const double t = std::clamp((x - a).dot(e) / e.squaredNorm(), 0.0, 1.0);
  return {t, (x - (a + t * e)).norm()};
}
// Calls visit(c, x) for each cell c (centre x) in the bounding box of segment ab grown by band + 1
// cells: every cell within band dx of the segment.
template <class Visit>
void forCellsNearSegment(const MacLayout<2>& layout, const Eigen::Vector2d& a, const Eigen::Vector2d& b, double band,
                         Visit visit) {
  const Eigen::Vector2d lo = (a.cwiseMin(b) - layout.origin) / layout.dx - Eigen::Vector2d::Constant(band + 1);
  const Eigen::Vector2d hi = (a.cwiseMax(b) - layout.origin) / layout.dx + Eigen::Vector2d::Constant(band + 1);
  const int i0 = std::max(0, static_cast<int>(std::floor(lo.x()))), i1 = std::min(layout.cells.x() - 1, static_cast<int>(hi.x()));
  const int j0 = std::max(0, static_cast<int>(std::floor(lo.y()))), j1 = std::min(layout.cells.y() - 1, static_cast<int>(hi.y()));
  for (int j = j0; j <= j1; ++j)
    for (int i = i0; i <= i1; ++i) visit(layout.cellIndex(Eigen::Vector2i(i, j)), layout.cellCenter(Eigen::Vector2i(i, j)));
}
// Unsigned distance to the front within the band, band dx beyond it.
std::vector<double> bandDistance(const MacLayout<2>& layout, const Front2& front, double band) {
  std::vector<double> distance(layout.cellCount(), band * layout.dx);
  for (const auto& e : front.elements) {
    const Eigen::Vector2d a = front.points[e[0]], b = front.points[e[1]];
    forCellsNearSegment(layout, a, b, band, [&](int c, const Eigen::Vector2d& x) {
      distance[c] = std::min(distance[c], closestOnSegment(x, a, b).distance);
    });
  }
  return distance;
}
}  // namespace

std::vector<double> advectCellField(const MacLayout<2>& layout, const std::vector<double>& phi, const Eigen::VectorXd& u,
                                    double dt) {
  std::vector<double> out(phi.size());
  for (int c = 0; c < layout.cellCount(); ++c) {
    const Eigen::Vector2d x = layout.cellCenter(layout.cellCoord(c));
    const Eigen::Vector2d mid = x - 0.5 * dt * velocityAt(layout, u, x);
    const Eigen::Vector2d departure = x - dt * velocityAt(layout, u, mid);
    out[c] = sampleCellField(layout, phi, departure);
  }
  return out;
}

void moveLevelSetWithFront(const MacLayout<2>& layout, const Front2& front, const std::vector<Eigen::Vector2d>& velocity,
                           double dt, std::vector<double>& phi, double band) {
  const double reach = band * layout.dx;
  std::vector<double> best(layout.cellCount(), reach), speed(layout.cellCount(), 0.0);
  std::vector<char> found(layout.cellCount(), 0);
  for (const auto& e : front.elements) {
    const Eigen::Vector2d a = front.points[e[0]], b = front.points[e[1]], edge = b - a;
    const double length = edge.norm();
    if (!(length > 0)) continue;
    const Eigen::Vector2d normal(edge.y() / length, -edge.x() / length);  // outward: R t
    forCellsNearSegment(layout, a, b, band, [&](int c, const Eigen::Vector2d& x) {
      const auto [t, distance] = closestOnSegment(x, a, b);
      if ((distance >= best[c] && found[c]) || distance > reach) return;
      best[c] = distance;
      found[c] = 1;
      speed[c] = ((1 - t) * velocity[e[0]] + t * velocity[e[1]]).dot(normal);
    });
  }
  for (int c = 0; c < layout.cellCount(); ++c)
    if (found[c]) phi[c] -= dt * speed[c];
}

void redistanceToFront(const MacLayout<2>& layout, const Front2& front, std::vector<double>& phi, double band, double keep) {
  const std::vector<double> distance = bandDistance(layout, front, band);
  for (int c = 0; c < layout.cellCount(); ++c)
    if (distance[c] > keep * layout.dx) phi[c] = phi[c] < 0 ? -distance[c] : distance[c];
}

std::vector<double> signedDistanceToFront(const MacLayout<2>& layout, const Front2& front, double band) {
  std::vector<double> phi = bandDistance(layout, front, band);
  for (int c = 0; c < layout.cellCount(); ++c)
    if (insideFront(front, layout.cellCenter(layout.cellCoord(c)))) phi[c] = -phi[c];
  return phi;
}

}  // namespace monolith::solvers
