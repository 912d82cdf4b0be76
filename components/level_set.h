#pragma once
// LevelSet<d>: a body's geometry as a sampled signed distance phi (negative inside), in the body
// frame, for obstacles in the fluid (thesis Sec. 5.4: the solid is where phi <= 0; its faces get
// the body's rigid velocity). Samples sit on the nodes origin + i * spacing, i = 0 .. samples - 1
// per axis, x fastest; between them phi is multilinear. Outside the sampled box phi is the value
// at the nearest point of the box plus the distance to it, so the body must lie inside the box
// (every boundary sample > 0, checked when the scene is read).
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <vector>

namespace monolith {

template <int d>
struct LevelSet {
  static constexpr const char* kName = "level_set";
  using VecD = Eigen::Matrix<double, d, 1>;
  using Index = Eigen::Matrix<int, d, 1>;

  VecD origin = VecD::Zero();  // body-frame position of sample 0
  double spacing = 1;
  Index samples = Index::Constant(2);
  std::vector<double> values;  // samples.prod() numbers, x fastest
  // Derived when the scene is read (and after a restart, from the samples):
  double lipschitz = 1;  // bound on |grad phi| over all space (see refresh)
  double reach = 0;      // radius about the body origin that holds every point with phi <= 0

  template <class V>
  void visitFields(V& visit) {
    visit("origin", origin);
    visit("spacing", spacing);
    visit("samples", samples);
    visit("values", values);
    visit("lipschitz", lipschitz);
    visit("reach", reach);
  }

  int sampleIndex(const Index& i) const {
    int k = 0, stride = 1;
    for (int a = 0; a < d; ++a) k += i[a] * stride, stride *= samples[a];
    return k;
  }
  Index sampleCoord(int k) const {  // inverse of sampleIndex
    Index i;
    for (int a = 0; a < d; ++a) i[a] = k % samples[a], k /= samples[a];
    return i;
  }
  VecD node(const Index& i) const { return origin + spacing * i.template cast<double>(); }

  // phi at a body-frame point.
  double value(const VecD& p) const {
    const VecD upper = origin + spacing * (samples.array() - 1).matrix().template cast<double>();
    const VecD q = p.cwiseMax(origin).cwiseMin(upper);
    Index base;
    VecD frac;
    for (int a = 0; a < d; ++a) {
      const double s = (q[a] - origin[a]) / spacing;
      base[a] = std::min(static_cast<int>(std::floor(s)), samples[a] - 2);
      frac[a] = s - base[a];
    }
    double phi = 0;
    for (int corner = 0; corner < (1 << d); ++corner) {
      Index i = base;
      double weight = 1;
      for (int a = 0; a < d; ++a) {
        const bool up = (corner >> a) & 1;
        i[a] += up;
        weight *= up ? frac[a] : 1 - frac[a];
      }
      if (weight != 0) phi += weight * values[sampleIndex(i)];
    }
    return phi + (p - q).norm();
  }

  // lipschitz and reach from the samples. Along an axis the multilinear phi changes at most by
  // the largest difference of neighbouring samples per spacing (L); its gradient is then at most
  // sqrt(d) L, and outside the box the distance term adds 1. phi <= 0 only in cells with a corner
  // <= 0, so those corners' distance plus a cell diagonal bounds the body.
  void refresh() {
    double axisSlope = 0;
    reach = 0;
    for (int k = 0; k < static_cast<int>(values.size()); ++k) {
      const Index i = sampleCoord(k);
      for (int a = 0; a < d; ++a) {
        if (i[a] + 1 >= samples[a]) continue;
        Index j = i;
        ++j[a];
        axisSlope = std::max(axisSlope, std::abs(values[sampleIndex(j)] - values[k]) / spacing);
      }
      if (values[k] <= 0) reach = std::max(reach, node(i).norm());
    }
    reach += spacing * std::sqrt(static_cast<double>(d));
    lipschitz = std::sqrt(static_cast<double>(d)) * axisSlope + 1;
  }
};

}  // namespace monolith
