#include "solvers/advection/cfl.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace monolith::solvers {

double maxFaceSpeed(const Eigen::VectorXd& u, const FaceBoundary& boundary) {
  const bool anyPrescribed = !boundary.prescribedFace.empty();
  if (anyPrescribed && (static_cast<Eigen::Index>(boundary.prescribedFace.size()) != u.size() ||
                        boundary.prescribedVelocity.size() != u.size()))
    throw std::invalid_argument("maxFaceSpeed: boundary and field sizes differ");
  double speed = 0;
  for (Eigen::Index g = 0; g < u.size(); ++g) {
    const double value = anyPrescribed && boundary.prescribedFace[g] ? boundary.prescribedVelocity[g] : u[g];
    if (!std::isfinite(value)) throw std::domain_error("maxFaceSpeed: non-finite face velocity");
    speed = std::max(speed, std::abs(value));
  }
  return speed;
}

template <int d>
double cflTimeStep(const MacLayout<d>& layout, const Eigen::VectorXd& u, double cfl, double dtMax,
                   const FaceBoundary& boundary) {
  if (!(cfl > 0) || !std::isfinite(cfl)) throw std::invalid_argument("cflTimeStep: cfl must be finite and > 0");
  if (!(dtMax > 0)) throw std::invalid_argument("cflTimeStep: dtMax must be > 0");
  if (u.size() != layout.totalFaces()) throw std::invalid_argument("cflTimeStep: field needs one value per face");
  const double speed = maxFaceSpeed(u, boundary);
  if (speed == 0) return dtMax;
  // Dividing by a tiny speed may overflow to +inf; min() with dtMax keeps the result finite then.
  return std::min(cfl * layout.dx / speed, dtMax);
}

template double cflTimeStep<2>(const MacLayout<2>&, const Eigen::VectorXd&, double, double, const FaceBoundary&);
template double cflTimeStep<3>(const MacLayout<3>&, const Eigen::VectorXd&, double, double, const FaceBoundary&);

}  // namespace monolith::solvers
