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

namespace {

// The part [first, last] of [0, 1] in which the bodies' bounding balls meet: their centres move
// linearly, so |d0 + s dd| <= Ra + Rb is a quadratic inequality in s. False if they never meet.
// Unbounded shapes (a half-space) meet everywhere.
template <int d>
bool ballsMeet(const PreparedGeometry<d>& a, const StepMotion<d>& ma, const PreparedGeometry<d>& b,
               const StepMotion<d>& mb, double& first, double& last) {
  first = 0;
  last = 1;
  const double reach = a.boundingRadius() + b.boundingRadius();
  if (!std::isfinite(reach)) return true;
  const Eigen::Matrix<double, d, 1> d0 = ma.start.x - mb.start.x, dd = ma.translation - mb.translation;
  // Padded so that rounding cannot cut off a touching contact.
  const double r = reach * (1 + 1e-9) + 1e-12;
  const double qa = dd.squaredNorm(), qb = d0.dot(dd), qc = d0.squaredNorm() - r * r;
  if (qa == 0) return qc <= 0;
  const double disc = qb * qb - qa * qc;
  if (disc < 0) return false;
  const double root = std::sqrt(disc);
  first = std::max(0.0, (-qb - root) / qa);
  last = std::min(1.0, (-qb + root) / qa);
  return first <= last;
}

}  // namespace

template <int d>
double firstContactFraction(const PreparedGeometry<d>& a, const StepMotion<d>& ma, const PreparedGeometry<d>& b,
                            const StepMotion<d>& mb, const SweptQuery& query) {
  auto overlapAt = [&](double s) { return overlaps<d>(a, ma.at(s), b, mb.at(s)); };
  // Only where the bounding balls meet can the shapes touch: sample that stretch of the motion.
  double first = 0, last = 1;
  if (!ballsMeet<d>(a, ma, b, mb, first, last)) return -1.0;
  if (overlapAt(first)) return first;
  const double travel = relativeTravel<d>(a, ma, b, mb) * (last - first);
  const double wanted = query.sampleTravel > 0 ? std::ceil(travel / query.sampleTravel) : 1.0;
  const int samples = std::isfinite(wanted) ? static_cast<int>(std::clamp(wanted, 1.0, double(query.maxSamples)))
                                            : query.maxSamples;
  const double span = last - first;
  for (int k = 1; k <= samples; ++k) {
    const double s = k == samples ? last : first + span * k / samples;
    if (!overlapAt(s)) continue;
    // Apart at lo, overlapping at hi: halve the bracket, keeping that property.
    double lo = first + span * (k - 1) / samples, hi = s;
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
