#include "solvers/advection/semi_lagrangian.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace monolith::solvers {

namespace {
void checkDt(double dt, const char* who) {
  if (!(dt >= 0) || !std::isfinite(dt)) throw std::invalid_argument(std::string(who) + ": dt must be finite and >= 0");
}

// Foot of the midpoint-rule characteristic through x over a signed time `dt` (dt > 0 traces
// backwards, dt < 0 forwards), both points clipped to the fluid region.
// `vx` is trace.velocity(x), passed in so that MacCormack's two traces from one face sample it once.
template <int d>
typename MacLayout<d>::Vec characteristicFoot(const FaceVelocitySampler<d>& trace, const typename MacLayout<d>::Vec& x,
                                              const typename MacLayout<d>::Vec& vx, double dt) {
  const auto mid = trace.clipToFluid(x, x - 0.5 * dt * vx);
  return trace.clipToFluid(x, x - dt * trace.velocity(mid));
}
template <int d>
typename MacLayout<d>::Vec characteristicFoot(const FaceVelocitySampler<d>& trace, const typename MacLayout<d>::Vec& x,
                                              double dt) {
  return characteristicFoot(trace, x, trace.velocity(x), dt);
}

// out[g] = body(g) for every face that is not prescribed, the prescribed value otherwise;
// every output face is written once from read-only input (bitwise thread-count independent).
template <int d, class Body>
void forEachFreeFace(const FaceVelocitySampler<d>& sampler, Eigen::VectorXd& out, const Body& body) {
  tbb::parallel_for(tbb::blocked_range<int>(0, static_cast<int>(out.size())), [&](const tbb::blocked_range<int>& r) {
    for (int g = r.begin(); g != r.end(); ++g) out[g] = sampler.isPrescribed(g) ? sampler.faceValue(g) : body(g);
  });
}
}  // namespace

template <int d>
Eigen::VectorXd advectFacesSemiLagrangian(const MacLayout<d>& layout, const Eigen::VectorXd& u, double dt,
                                          const FaceBoundary& boundary) {
  checkDt(dt, "advectFacesSemiLagrangian");
  const FaceVelocitySampler<d> sampler(layout, u, boundary);  // validates sizes and boundary
  Eigen::VectorXd out(u.size());
  forEachFreeFace(sampler, out, [&](int g) {
    const auto [axis, f] = layout.faceCoord(g);
    return sampler.component(axis, characteristicFoot(sampler, layout.faceCenter(axis, f), dt));
  });
  return out;
}

template <int d>
Eigen::VectorXd advectFacesMacCormack(const MacLayout<d>& layout, const Eigen::VectorXd& u, double dt,
                                      const FaceBoundary& boundary) {
  checkDt(dt, "advectFacesMacCormack");
  const FaceVelocitySampler<d> trace(layout, u, boundary);
  // Forward semi-Lagrangian step, remembering the range of the values each sample blended and
  // the velocity at each face centre (the backward trace starts with it too).
  Eigen::VectorXd forward(u.size()), lo(u.size()), hi(u.size());
  std::vector<typename MacLayout<d>::Vec> atFace(u.size());
  forEachFreeFace(trace, forward, [&](int g) {
    const auto [axis, f] = layout.faceCoord(g);
    const auto x = layout.faceCenter(axis, f);
    atFace[g] = trace.velocity(x);
    std::pair<double, double> range;
    const double value = trace.component(axis, characteristicFoot(trace, x, atFace[g], dt), &range);
    lo[g] = range.first, hi[g] = range.second;
    return value;
  });
  // Carry the result back over -dt along the same field: the round trip's departure from u^n
  // estimates the forward step's error, half of which is removed.
  const FaceVelocitySampler<d> forwardSampler(layout, forward, boundary);
  Eigen::VectorXd out(u.size());
  forEachFreeFace(trace, out, [&](int g) {
    const auto [axis, f] = layout.faceCoord(g);
    const double roundTrip =
        forwardSampler.component(axis, characteristicFoot(trace, layout.faceCenter(axis, f), atFace[g], -dt));
    return std::clamp(forward[g] + 0.5 * (u[g] - roundTrip), lo[g], hi[g]);
  });
  return out;
}

template Eigen::VectorXd advectFacesSemiLagrangian<2>(const MacLayout<2>&, const Eigen::VectorXd&, double,
                                                      const FaceBoundary&);
template Eigen::VectorXd advectFacesSemiLagrangian<3>(const MacLayout<3>&, const Eigen::VectorXd&, double,
                                                      const FaceBoundary&);
template Eigen::VectorXd advectFacesMacCormack<2>(const MacLayout<2>&, const Eigen::VectorXd&, double,
                                                  const FaceBoundary&);
template Eigen::VectorXd advectFacesMacCormack<3>(const MacLayout<3>&, const Eigen::VectorXd&, double,
                                                  const FaceBoundary&);

}  // namespace monolith::solvers
