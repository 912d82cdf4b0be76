#include "solvers/collision/swept_contact.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Geometry>

#include "solvers/collision/narrow_phase.h"

namespace monolith::solvers::collision {

template <int d>
Pose<d> StepMotion<d>::at(double s) const {
  Pose<d> p;
  p.x = start.x + s * translation;
  if constexpr (d == 3) {
    const double angle = s * rotation.norm();
    p.R = angle == 0 ? start.R
                     : Eigen::Matrix3d(Eigen::AngleAxisd(angle, rotation.normalized()).toRotationMatrix() * start.R);
  } else {
    p.R = Eigen::Rotation2Dd(s * rotation(0)).toRotationMatrix() * start.R;
  }
  return p;
}

template <int d>
double tunnelingSize(const PreparedGeometry<d>& g) {
  const GeometryType t = g.geometry().type;
  if (t == GeometryType::HalfSpace || t == GeometryType::Mesh) return std::numeric_limits<double>::infinity();
  return g.minimumSize();
}

template <int d>
double relativeTravel(const PreparedGeometry<d>& a, const StepMotion<d>& ma, const PreparedGeometry<d>& b,
                      const StepMotion<d>& mb) {
  // A half-space or a static body does not turn: skip its infinite radius times a zero angle.
  auto turning = [](const PreparedGeometry<d>& g, const StepMotion<d>& m) {
    const double angle = m.rotation.norm();
    return angle == 0 ? 0.0 : angle * g.boundingRadius();
  };
  return (ma.translation - mb.translation).norm() + turning(a, ma) + turning(b, mb);
}

template <int d>
double firstContactFraction(const PreparedGeometry<d>& a, const StepMotion<d>& ma, const PreparedGeometry<d>& b,
                            const StepMotion<d>& mb, const SweptQuery& query) {
  auto overlapAt = [&](double s) { return overlaps<d>(a, ma.at(s), b, mb.at(s)); };
  if (overlapAt(0.0)) return 0.0;
  const double travel = relativeTravel<d>(a, ma, b, mb);
  const double wanted = query.sampleTravel > 0 ? std::ceil(travel / query.sampleTravel) : 1.0;
  const int samples = std::isfinite(wanted) ? static_cast<int>(std::clamp(wanted, 1.0, double(query.maxSamples)))
                                            : query.maxSamples;
  for (int k = 1; k <= samples; ++k) {
    const double s = double(k) / samples;
    if (!overlapAt(s)) continue;
    // Apart at lo, overlapping at hi: halve the bracket, keeping that property.
    double lo = double(k - 1) / samples, hi = s;
    for (int i = 0; i < query.bisections; ++i) {
      const double mid = 0.5 * (lo + hi);
      (overlapAt(mid) ? hi : lo) = mid;
    }
    return hi;
  }
  return -1.0;
}

template struct StepMotion<2>;
template struct StepMotion<3>;
template double tunnelingSize<2>(const PreparedGeometry<2>&);
template double tunnelingSize<3>(const PreparedGeometry<3>&);
template double relativeTravel<2>(const PreparedGeometry<2>&, const StepMotion<2>&, const PreparedGeometry<2>&,
                                  const StepMotion<2>&);
template double relativeTravel<3>(const PreparedGeometry<3>&, const StepMotion<3>&, const PreparedGeometry<3>&,
                                  const StepMotion<3>&);
template double firstContactFraction<2>(const PreparedGeometry<2>&, const StepMotion<2>&, const PreparedGeometry<2>&,
                                        const StepMotion<2>&, const SweptQuery&);
template double firstContactFraction<3>(const PreparedGeometry<3>&, const StepMotion<3>&, const PreparedGeometry<3>&,
                                        const StepMotion<3>&, const SweptQuery&);

}  // namespace monolith::solvers::collision
