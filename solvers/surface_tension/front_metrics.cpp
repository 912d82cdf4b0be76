#include "solvers/surface_tension/front_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace monolith::solvers {

FrontShape measureFront(const Front2& front) {
  FrontShape s;
  s.area = enclosedArea(front);
  s.length = frontLength(front);
  Eigen::Vector2d moment = Eigen::Vector2d::Zero();
  for (const auto& e : front.elements) {
    const Eigen::Vector2d a = front.points[e[0]], b = front.points[e[1]];
    moment += (a.x() * b.y() - b.x() * a.y()) * (a + b) / 6;  // the polygon's first moment, triangle by triangle
  }
  if (s.area != 0) s.centroid = moment / s.area;
  if (s.length > 0) s.circularity = 2 * std::sqrt(M_PI * std::abs(s.area)) / s.length;
  const double x0 = s.centroid.x();
  s.top = -std::numeric_limits<double>::infinity();
  s.bottom = std::numeric_limits<double>::infinity();
  for (const auto& e : front.elements) {
    const Eigen::Vector2d a = front.points[e[0]], b = front.points[e[1]];
    // The half-open rule of insideFront: a crossing at a vertex is counted once.
    if ((a.x() <= x0 && x0 < b.x()) || (b.x() <= x0 && x0 < a.x())) {
      const double y = a.y() + (x0 - a.x()) / (b.x() - a.x()) * (b.y() - a.y());
      s.top = std::max(s.top, y);
      s.bottom = std::min(s.bottom, y);
    }
  }
  if (!std::isfinite(s.top)) s.top = s.bottom = std::numeric_limits<double>::quiet_NaN();
  return s;
}

}  // namespace monolith::solvers
