#include "solvers/advection/eno.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace monolith::solvers {

double eno3Derivative(const std::array<double, 7>& v, double dx, bool backward) {
  // Newton divided differences (Osher & Fedkiw Sec. 3.3): d1[j] at j+1/2, d2[j] at node j,
  // d3[j] at j+1/2; the point is node i = 3.
  double d1[6], d2[6], d3[5];
  for (int j = 0; j < 6; ++j) d1[j] = (v[j + 1] - v[j]) / dx;
  for (int j = 1; j < 6; ++j) d2[j] = (d1[j] - d1[j - 1]) / (2 * dx);
  for (int j = 1; j < 5; ++j) d3[j] = (d2[j + 1] - d2[j]) / (3 * dx);
  const int i = 3;
  const int k = backward ? i - 1 : i;  // leftmost node of the first-order (upwind) stencil
  double derivative = d1[k];
  // Extend the stencil to the side with the smaller divided difference (the smoother one).
  const bool left2 = std::abs(d2[k]) <= std::abs(d2[k + 1]);
  const int kstar = left2 ? k - 1 : k;
  derivative += (left2 ? d2[k] : d2[k + 1]) * (2 * (i - k) - 1) * dx;
  const double c3 = std::abs(d3[kstar]) <= std::abs(d3[kstar + 1]) ? d3[kstar] : d3[kstar + 1];
  const int m = i - kstar;
  derivative += c3 * (3 * m * m - 6 * m + 2) * dx * dx;
  return derivative;
}

double weno5Derivative(const std::array<double, 7>& v, double dx, bool backward) {
  // The five one-sided differences a1..a5, ordered from the far upwind side (Osher & Fedkiw
  // eqs. 3.25-3.35; for D^+ the same formulas apply to the mirrored differences).
  double a[5];
  for (int j = 0; j < 5; ++j) a[j] = backward ? (v[j + 1] - v[j]) / dx : (v[6 - j] - v[5 - j]) / dx;
  // The three third-order candidates (the ENO3 stencils) ...
  const double p1 = a[0] / 3 - 7 * a[1] / 6 + 11 * a[2] / 6;
  const double p2 = -a[1] / 6 + 5 * a[2] / 6 + a[3] / 3;
  const double p3 = a[2] / 3 + 5 * a[3] / 6 - a[4] / 6;
  // ... their smoothness indicators ...
  const auto sq = [](double x) { return x * x; };
  const double s1 = 13.0 / 12 * sq(a[0] - 2 * a[1] + a[2]) + 0.25 * sq(a[0] - 4 * a[1] + 3 * a[2]);
  const double s2 = 13.0 / 12 * sq(a[1] - 2 * a[2] + a[3]) + 0.25 * sq(a[1] - a[3]);
  const double s3 = 13.0 / 12 * sq(a[2] - 2 * a[3] + a[4]) + 0.25 * sq(3 * a[2] - 4 * a[3] + a[4]);
  // ... and the nonlinear weights around the optimal 0.1, 0.6, 0.3; eps scales with the data so
  // that the weights do not depend on the units (Fedkiw et al.'s choice, with a floor for a = 0).
  double largest = 0;
  for (double x : a) largest = std::max(largest, x * x);
  const double eps = 1e-6 * largest + 1e-99;
  const double w1 = 0.1 / sq(s1 + eps), w2 = 0.6 / sq(s2 + eps), w3 = 0.3 / sq(s3 + eps);
  return (w1 * p1 + w2 * p2 + w3 * p3) / (w1 + w2 + w3);
}

namespace {

double hjDerivative(HjStencil stencil, const std::array<double, 7>& v, double dx, bool backward) {
  return stencil == HjStencil::Weno5 ? weno5Derivative(v, dx, backward) : eno3Derivative(v, dx, backward);
}

template <int d>
using IndexT = typename MacLayout<d>::Index;
template <int d>
using VecT = typename MacLayout<d>::Vec;

int wrap(int i, int n) { return ((i % n) + n) % n; }

// Seven values along `axis` centred on `node` of a grid with `dims` nodes, whose linear index is
// `first` + (node . stride): periodic axes wrap, others repeat the last stored node
// (zero-gradient ghosts, see eno.h). The index is stepped by the stride, not recomputed.
template <int d, class ValueFn>
std::array<double, 7> gather7(const IndexT<d>& node, int axis, const IndexT<d>& dims, const std::array<bool, d>& periodic,
                              int first, const std::array<int, d>& stride, ValueFn value) {
  std::array<double, 7> v;
  int base = first;
  for (int a = 0; a < d; ++a) base += (a == axis ? 0 : node[a]) * stride[a];
  for (int k = 0; k < 7; ++k) {
    const int j = node[axis] + k - 3;
    const int n = periodic[axis] ? wrap(j, dims[axis]) : std::min(std::max(j, 0), dims[axis] - 1);
    v[k] = value(base + n * stride[axis]);
  }
  return v;
}

// Component `comp` at a point whose coordinate in comp's face grid is base_e + 1/2 on the axes
// with half[e] and base_e on the others, by the tensor-product 4th-order midpoint rule
// (-1, 9, 9, -1)/16. Returns false (caller falls back to the sampler) if the stencil leaves a
// non-periodic domain or touches a prescribed face (walls, structures: data not smooth there).
template <int d>
bool cubicMidpoint(const FaceVelocitySampler<d>& sampler, int comp, const IndexT<d>& base,
                   const std::array<bool, d>& half, double& out) {
  static constexpr double kWeights[4] = {-1.0 / 16, 9.0 / 16, 9.0 / 16, -1.0 / 16};
  const MacLayout<d>& layout = sampler.layout();
  const IndexT<d> dims = layout.faceDims(comp);
  int nodes[d][4];
  int count[d];
  int total = 1;
  for (int e = 0; e < d; ++e) {
    count[e] = half[e] ? 4 : 1;
    total *= count[e];
    for (int k = 0; k < count[e]; ++k) {
      int j = half[e] ? base[e] - 1 + k : base[e];
      if (layout.periodic[e]) j = wrap(j, dims[e]);
      else if (j < 0 || j >= dims[e]) return false;
      nodes[e][k] = j;
    }
  }
  // The nodes lie inside the stored face grid (wrapped or checked above): strides give
  // layout.faceIndex(comp, n) exactly.
  const std::array<int, d> stride = MacLayout<d>::strides(dims);
  const int offset = layout.faceOffset(comp);
  double sum = 0;
  for (int combo = 0; combo < total; ++combo) {
    int face = offset;
    double w = 1;
    for (int e = 0, rest = combo; e < d; ++e) {
      const int k = rest % count[e];
      rest /= count[e];
      face += nodes[e][k] * stride[e];
      if (half[e]) w *= kWeights[k];
    }
    if (sampler.isPrescribed(face)) return false;
    sum += w * sampler.faceValue(face);
  }
  out = sum;
  return true;
}

// Upwinding velocity at face f of `axis` (global index g).
template <int d>
VecT<d> faceUpwindVelocity(const FaceVelocitySampler<d>& sampler, int axis, const IndexT<d>& f, int g) {
  VecT<d> w;
  for (int b = 0; b < d; ++b) {
    if (b == axis) {
      w[b] = sampler.faceValue(g);
      continue;
    }
    IndexT<d> base = f;
    base[axis] -= 1;  // the face lies midway between cell centres f-1 and f along `axis`
    std::array<bool, d> half{};
    half[axis] = half[b] = true;
    if (!cubicMidpoint<d>(sampler, b, base, half, w[b])) w[b] = sampler.component(b, sampler.layout().faceCenter(axis, f));
  }
  return w;
}

template <int d>
VecT<d> cellUpwindVelocity(const FaceVelocitySampler<d>& sampler, const IndexT<d>& c) {
  VecT<d> w;
  for (int b = 0; b < d; ++b) {
    std::array<bool, d> half{};
    half[b] = true;
    if (!cubicMidpoint<d>(sampler, b, c, half, w[b])) w[b] = sampler.component(b, sampler.layout().cellCenter(c));
  }
  return w;
}

void checkDt(double dt) {
  if (!(dt >= 0) || !std::isfinite(dt)) throw std::invalid_argument("ENO advection: dt must be finite and >= 0");
}

template <class Fn>
void forEach(int n, Fn fn) {
  tbb::parallel_for(tbb::blocked_range<int>(0, n), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i != r.end(); ++i) fn(i);
  });
}

// Shu-Osher TVD RK3 for y_t = -C(y); `fix` re-imposes boundary values after every stage.
template <class Conv, class Fix>
Eigen::VectorXd tvdRk3(Eigen::VectorXd y0, double dt, Conv conv, Fix fix) {
  fix(y0);
  Eigen::VectorXd y1 = y0 - dt * conv(y0);
  fix(y1);
  Eigen::VectorXd y2 = 0.75 * y0 + 0.25 * (y1 - dt * conv(y1));
  fix(y2);
  Eigen::VectorXd y3 = (1.0 / 3.0) * y0 + (2.0 / 3.0) * (y2 - dt * conv(y2));
  fix(y3);
  return y3;
}

}  // namespace

template <int d>
Eigen::VectorXd enoConvectiveTerm(const MacLayout<d>& layout, const Eigen::VectorXd& u, const FaceBoundary& boundary,
                                  HjStencil stencil) {
  const FaceVelocitySampler<d> sampler(layout, u, boundary);
  Eigen::VectorXd out(u.size());
  forEach(static_cast<int>(u.size()), [&](int g) {
    if (sampler.isPrescribed(g)) {
      out[g] = 0;
      return;
    }
    const auto [axis, f] = layout.faceCoord(g);
    const VecT<d> w = faceUpwindVelocity(sampler, axis, f, g);
    const IndexT<d> dims = layout.faceDims(axis);
    const std::array<int, d> stride = MacLayout<d>::strides(dims);
    double term = 0;
    for (int b = 0; b < d; ++b) {
      if (w[b] == 0) continue;
      const auto v = gather7<d>(f, b, dims, layout.periodic, layout.faceOffset(axis), stride,
                                [&](int face) { return sampler.sampleValue(face); });
      term += w[b] * hjDerivative(stencil, v, layout.dx, w[b] > 0);
    }
    out[g] = term;
  });
  return out;
}

template <int d>
Eigen::VectorXd advectFacesEnoRk3(const MacLayout<d>& layout, const Eigen::VectorXd& u, double dt,
                                  const FaceBoundary& boundary, HjStencil stencil) {
  checkDt(dt);
  validateBoundary(layout, boundary);
  if (u.size() != layout.totalFaces()) throw std::invalid_argument("advectFacesEnoRk3: field needs one value per face");
  const bool anyPrescribed = !boundary.prescribedFace.empty();
  auto fix = [&](Eigen::VectorXd& y) {
    if (!anyPrescribed) return;
    for (Eigen::Index g = 0; g < y.size(); ++g)
      if (boundary.prescribedFace[g]) y[g] = boundary.prescribedVelocity[g];
  };
  return tvdRk3(u, dt, [&](const Eigen::VectorXd& y) { return enoConvectiveTerm(layout, y, boundary, stencil); }, fix);
}

template <int d>
Eigen::VectorXd enoScalarConvectiveTerm(const MacLayout<d>& layout, const Eigen::VectorXd& phi, const Eigen::VectorXd& u,
                                        const FaceBoundary& boundary, HjStencil stencil) {
  if (phi.size() != layout.cellCount()) throw std::invalid_argument("enoScalarConvectiveTerm: phi needs one value per cell");
  const FaceVelocitySampler<d> sampler(layout, u, boundary);
  Eigen::VectorXd out(phi.size());
  forEach(static_cast<int>(phi.size()), [&](int cell) {
    if (sampler.hasSolids() && boundary.solidCell[cell]) {
      out[cell] = 0;
      return;
    }
    const IndexT<d> c = layout.cellCoord(cell);
    const VecT<d> w = cellUpwindVelocity(sampler, c);
    const std::array<int, d> stride = MacLayout<d>::strides(layout.cells);
    double term = 0;
    for (int b = 0; b < d; ++b) {
      if (w[b] == 0) continue;
      const auto v = gather7<d>(c, b, layout.cells, layout.periodic, 0, stride, [&](int i) { return phi[i]; });
      term += w[b] * hjDerivative(stencil, v, layout.dx, w[b] > 0);
    }
    out[cell] = term;
  });
  return out;
}

template <int d>
Eigen::VectorXd advectScalarEnoRk3(const MacLayout<d>& layout, const Eigen::VectorXd& phi, const Eigen::VectorXd& u,
                                   double dt, const FaceBoundary& boundary, HjStencil stencil) {
  checkDt(dt);
  if (phi.size() != layout.cellCount()) throw std::invalid_argument("advectScalarEnoRk3: phi needs one value per cell");
  validateBoundary(layout, boundary);
  // Solid cells are not evolved (their convective term is 0); restore them bitwise after each
  // stage so the RK averaging cannot perturb them by rounding.
  auto fix = [&](Eigen::VectorXd& y) {
    for (std::size_t c = 0; c < boundary.solidCell.size(); ++c)
      if (boundary.solidCell[c]) y[static_cast<Eigen::Index>(c)] = phi[static_cast<Eigen::Index>(c)];
  };
  return tvdRk3(phi, dt, [&](const Eigen::VectorXd& y) { return enoScalarConvectiveTerm(layout, y, u, boundary, stencil); }, fix);
}

#define MONOLITH_ENO_INSTANTIATE(D)                                                                                   \
  template Eigen::VectorXd enoConvectiveTerm<D>(const MacLayout<D>&, const Eigen::VectorXd&, const FaceBoundary&,     \
                                                HjStencil);                                                           \
  template Eigen::VectorXd advectFacesEnoRk3<D>(const MacLayout<D>&, const Eigen::VectorXd&, double,                  \
                                                const FaceBoundary&, HjStencil);                                      \
  template Eigen::VectorXd enoScalarConvectiveTerm<D>(const MacLayout<D>&, const Eigen::VectorXd&,                    \
                                                      const Eigen::VectorXd&, const FaceBoundary&, HjStencil);        \
  template Eigen::VectorXd advectScalarEnoRk3<D>(const MacLayout<D>&, const Eigen::VectorXd&, const Eigen::VectorXd&, \
                                                 double, const FaceBoundary&, HjStencil);
MONOLITH_ENO_INSTANTIATE(2)
MONOLITH_ENO_INSTANTIATE(3)
#undef MONOLITH_ENO_INSTANTIATE

}  // namespace monolith::solvers
