#include "solvers/advection/semi_lagrangian.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <stdexcept>

namespace monolith::solvers {

template <int d>
Eigen::VectorXd advectFacesSemiLagrangian(const MacLayout<d>& layout, const Eigen::VectorXd& u, double dt,
                                          const FaceBoundary& boundary) {
  if (!(dt >= 0) || !std::isfinite(dt)) throw std::invalid_argument("advectFacesSemiLagrangian: dt must be finite and >= 0");
  const FaceVelocitySampler<d> sampler(layout, u, boundary);  // validates sizes and boundary
  using Vec = typename MacLayout<d>::Vec;
  Eigen::VectorXd out(u.size());
  tbb::parallel_for(tbb::blocked_range<int>(0, static_cast<int>(u.size())), [&](const tbb::blocked_range<int>& r) {
    for (int g = r.begin(); g != r.end(); ++g) {
      if (sampler.isPrescribed(g)) {
        out[g] = sampler.faceValue(g);
        continue;
      }
      const auto [axis, f] = layout.faceCoord(g);
      const Vec x = layout.faceCenter(axis, f);
      const Vec mid = sampler.clipToFluid(x, x - 0.5 * dt * sampler.velocity(x));
      const Vec departure = sampler.clipToFluid(x, x - dt * sampler.velocity(mid));
      out[g] = sampler.component(axis, departure);
    }
  });
  return out;
}

template Eigen::VectorXd advectFacesSemiLagrangian<2>(const MacLayout<2>&, const Eigen::VectorXd&, double,
                                                      const FaceBoundary&);
template Eigen::VectorXd advectFacesSemiLagrangian<3>(const MacLayout<3>&, const Eigen::VectorXd&, double,
                                                      const FaceBoundary&);

}  // namespace monolith::solvers
