#include "solvers/geometry/signed_distance.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "solvers/collision/collision_impl.h"

namespace monolith::solvers {

template <int d>
SampledField<d> latticeAround(const std::vector<Eigen::Matrix<double, d, 1>>& points, double spacing, int margin) {
  using Vec = Eigen::Matrix<double, d, 1>;
  Vec lo = Vec::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Vec& p : points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  SampledField<d> field;
  field.origin = lo - Vec::Constant(margin * spacing);
  for (int a = 0; a < d; ++a)
    field.samples[a] = static_cast<int>(std::min(std::ceil((hi[a] - lo[a]) / spacing) + 2 * margin + 1, double(1 << 30)));
  return field;
}

namespace {

// Calls f(k, x) for every sample k at position x, x fastest.
template <int d, class F>
void forEachSample(const SampledField<d>& field, double spacing, F&& f) {
  Eigen::Matrix<int, d, 1> i = Eigen::Matrix<int, d, 1>::Zero();
  for (std::size_t k = 0; k < field.values.size(); ++k) {
    f(k, (field.origin + spacing * i.template cast<double>()).eval());
    for (int a = 0; a < d; ++a) {
      if (++i[a] < field.samples[a]) break;
      i[a] = 0;
    }
  }
}

// Solid angle of triangle abc seen from the origin (Van Oosterom & Strackee 1983), signed by
// the triangle's orientation.
double solidAngle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const double la = a.norm(), lb = b.norm(), lc = c.norm();
  const double numerator = a.dot(b.cross(c));
  const double denominator = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
  return 2 * std::atan2(numerator, denominator);
}

}  // namespace

SampledField<2> polygonDistance(const std::vector<Eigen::Vector2d>& vertices, double spacing, int margin) {
  SampledField<2> field = latticeAround<2>(vertices, spacing, margin);
  field.values.assign(static_cast<std::size_t>(field.sampleCount()), 0.0);
  const std::size_t n = vertices.size();
  forEachSample<2>(field, spacing, [&](std::size_t k, const Eigen::Vector2d& x) {
    double nearest = std::numeric_limits<double>::infinity();
    bool inside = false;
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector2d& a = vertices[i];
      const Eigen::Vector2d& b = vertices[(i + 1) % n];
      const Eigen::Vector2d edge = b - a;
      const double t = std::clamp((x - a).dot(edge) / edge.squaredNorm(), 0.0, 1.0);
      nearest = std::min(nearest, (a + t * edge - x).squaredNorm());
      // Even-odd: the edges a horizontal ray to +x from x crosses.
      if ((a.y() > x.y()) != (b.y() > x.y()) && x.x() < a.x() + (x.y() - a.y()) / edge.y() * edge.x()) inside = !inside;
    }
    field.values[k] = inside ? -std::sqrt(nearest) : std::sqrt(nearest);
  });
  return field;
}

SampledField<3> meshDistance(const std::vector<Eigen::Vector3d>& vertices, const std::vector<int>& triangles,
                             double spacing, int margin) {
  SampledField<3> field = latticeAround<3>(vertices, spacing, margin);
  field.values.assign(static_cast<std::size_t>(field.sampleCount()), 0.0);
  forEachSample<3>(field, spacing, [&](std::size_t k, const Eigen::Vector3d& x) {
    double nearest = std::numeric_limits<double>::infinity(), angle = 0;
    for (std::size_t t = 0; t + 2 < triangles.size(); t += 3) {
      const Eigen::Vector3d& a = vertices[triangles[t]];
      const Eigen::Vector3d& b = vertices[triangles[t + 1]];
      const Eigen::Vector3d& c = vertices[triangles[t + 2]];
      nearest = std::min(nearest, (collision::closestPointOnTriangle(x, a, b, c) - x).squaredNorm());
      angle += solidAngle(a - x, b - x, c - x);
    }
    const bool inside = std::abs(angle) > 2 * M_PI;  // winding number |angle / 4 pi| > 1/2
    field.values[k] = inside ? -std::sqrt(nearest) : std::sqrt(nearest);
  });
  return field;
}

template SampledField<2> latticeAround<2>(const std::vector<Eigen::Vector2d>&, double, int);
template SampledField<3> latticeAround<3>(const std::vector<Eigen::Vector3d>&, double, int);

}  // namespace monolith::solvers
