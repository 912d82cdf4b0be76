#include "solvers/deformable/stable_step.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace monolith::solvers::deformable {

namespace {

// Smallest altitude of a simplex whose edge matrix (columns x_a - x_0) has inverse Inv: the
// barycentric gradients are Inv's rows and minus their sum, altitude_a = 1 / |grad N_a|.
template <int d>
double minAltitude(const MatD<d>& Inv) {
  double g2 = Inv.colwise().sum().squaredNorm();
  for (int a = 0; a < d; ++a) g2 = std::max(g2, Inv.row(a).squaredNorm());
  return 1.0 / std::sqrt(g2);
}

}  // namespace

template <int d>
StableStep stableStep(const ForceModel<d>& fm, double density, const double* x, const double* v,
                      const std::vector<int>& fixed) {
  const double inf = std::numeric_limits<double>::infinity();
  StableStep s{inf, inf, inf};
  if (fm.finiteElements()) {
    const double modulus = fm.lame.lambda + 2 * fm.lame.mu;
    const double c = modulus > 0 && density > 0 ? std::sqrt(modulus / density) : 0.0;
    for (int e = 0; e < fm.elementCount(); ++e) {
      const int* n = &fm.elements[(d + 1) * e];
      const double rest = minAltitude<d>(fm.DmInv[e]);
      MatD<d> Ds;
      for (int a = 0; a < d; ++a)
        for (int b = 0; b < d; ++b) Ds(b, a) = x[d * n[a + 1] + b] - x[d * n[0] + b];
      const double det = Ds.determinant();
      double h = fm.clamp * rest;
      if (det > 0 && std::isfinite(det)) h = std::max(h, minAltitude<d>(MatD<d>(Ds.inverse())));
      s.minAltitude = std::min(s.minAltitude, h);
      if (c > 0) s.elastic = std::min(s.elastic, h / c);
    }
  } else {
    std::vector<double> K(fm.mass.size(), 0.0);
    for (int k = 0; k < fm.springCount(); ++k) {
      K[fm.springs[2 * k]] += fm.springK[k];
      K[fm.springs[2 * k + 1]] += fm.springK[k];
      s.minAltitude = std::min(s.minAltitude, fm.springRest[k]);
    }
    for (int k = 0; k < fm.altitudeCount(); ++k) {
      // The altitude spring's stiffness as particle idx[a] feels it: k |dh/dx_a|^2.
      VecD<d> g[d + 1];
      const int* idx = &fm.altitudes[(d + 1) * k];
      signedAltitude<d>(x, idx, g);
      for (int a = 0; a <= d; ++a) K[idx[a]] += fm.altitudeK[k] * g[a].squaredNorm();
      s.minAltitude = std::min(s.minAltitude, fm.altitudeRest[k]);
    }
    for (std::size_t i = 0; i < K.size(); ++i)
      if (!fixed[i] && K[i] > 0) s.elastic = std::min(s.elastic, std::sqrt(2 * fm.mass[i] / K[i]));
  }
  double speed2 = 0;
  for (std::size_t i = 0; i < fixed.size(); ++i)
    if (!fixed[i]) speed2 = std::max(speed2, Eigen::Map<const VecD<d>>(v + d * i).squaredNorm());
  if (speed2 > 0 && std::isfinite(s.minAltitude)) s.motion = s.minAltitude / std::sqrt(speed2);
  return s;
}

template StableStep stableStep<2>(const ForceModel<2>&, double, const double*, const double*, const std::vector<int>&);
template StableStep stableStep<3>(const ForceModel<3>&, double, const double*, const double*, const std::vector<int>&);

}  // namespace monolith::solvers::deformable
