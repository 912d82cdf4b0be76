// Barycentric interpolation on a simplex mesh at MAC grid points (see simplex_interpolation.h).
#include "solvers/fluid/simplex_interpolation.h"

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace monolith::solvers {

namespace {
template <int d>
using Index = typename MacLayout<d>::Index;

// Cell range [lo, hi] covering the box [a, b] grown by `grow` cells, clamped to the grid.
template <int d>
void cellRange(const MacLayout<d>& layout, const Eigen::Matrix<double, d, 1>& a, const Eigen::Matrix<double, d, 1>& b,
               int grow, Index<d>& lo, Index<d>& hi) {
  for (int k = 0; k < d; ++k) {
    lo[k] = std::max(0, static_cast<int>(std::floor((a[k] - layout.origin[k]) / layout.dx)) - grow);
    hi[k] = std::min(layout.cells[k] - 1, static_cast<int>(std::floor((b[k] - layout.origin[k]) / layout.dx)) + grow);
  }
}
}  // namespace

template <int d>
SimplexLocator<d>::SimplexLocator(const std::vector<double>& x, const std::vector<int>& elements,
                                  const MacLayout<d>& layout)
    : x_(x), elements_(elements), layout_(layout) {
  if (elements.size() % (d + 1) != 0) throw std::invalid_argument("SimplexLocator: d+1 indices per element");
  const int ne = elementCount(), nc = layout.cellCount();
  std::vector<std::vector<int>> buckets(nc);
  for (int e = 0; e < ne; ++e) {
    Vec a = Vec::Constant(std::numeric_limits<double>::infinity()), b = -a;
    for (int v = 0; v < d + 1; ++v) {
      const Vec p = Eigen::Map<const Vec>(&x_[d * elements_[e * (d + 1) + v]]);
      a = a.cwiseMin(p);
      b = b.cwiseMax(p);
    }
    Index<d> lo, hi;
    cellRange<d>(layout, a, b, 1, lo, hi);
    forEachIndexIn<d>(lo, hi, [&](const Index<d>& c) { buckets[layout.cellIndex(c)].push_back(e); });
  }
  bucketStart_.assign(nc + 1, 0);
  for (int c = 0; c < nc; ++c) bucketStart_[c + 1] = bucketStart_[c] + static_cast<int>(buckets[c].size());
  bucketElements_.reserve(bucketStart_[nc]);
  for (const auto& bucket : buckets) bucketElements_.insert(bucketElements_.end(), bucket.begin(), bucket.end());
}

template <int d>
Eigen::Matrix<double, d + 1, 1> SimplexLocator<d>::barycentric(int e, const Vec& p) const {
  const int* v = &elements_[e * (d + 1)];
  const Vec x0 = Eigen::Map<const Vec>(&x_[d * v[0]]);
  Eigen::Matrix<double, d, d> T;
  for (int k = 0; k < d; ++k) T.col(k) = Eigen::Map<const Vec>(&x_[d * v[k + 1]]) - x0;
  const Vec l = T.inverse() * (p - x0);
  Eigen::Matrix<double, d + 1, 1> out;
  out[0] = 1 - l.sum();
  out.template tail<d>() = l;
  return out;
}

template <int d>
int SimplexLocator<d>::bucketOf(const Vec& p) const {
  Index<d> c;
  for (int k = 0; k < d; ++k)
    c[k] = std::clamp(static_cast<int>(std::floor((p[k] - layout_.origin[k]) / layout_.dx)), 0, layout_.cells[k] - 1);
  return layout_.cellIndex(c);
}

template <int d>
std::vector<int> SimplexLocator<d>::cellsInside() const {
  std::vector<int> inside(layout_.cellCount(), -1);
  for (int c = 0; c < layout_.cellCount(); ++c) {
    const Vec p = layout_.cellCenter(layout_.cellCoord(c));
    for (int k = bucketStart_[c]; k < bucketStart_[c + 1]; ++k)
      if (barycentric(bucketElements_[k], p).minCoeff() >= 0) {
        inside[c] = bucketElements_[k];
        break;
      }
  }
  return inside;
}

template <int d>
SimplexWeights<d> SimplexLocator<d>::weightsAt(const Vec& p) const {
  const int c = bucketOf(p);
  int best = -1;
  double bestMin = -std::numeric_limits<double>::infinity();
  Eigen::Matrix<double, d + 1, 1> bestL;
  auto consider = [&](int e) {
    const auto l = barycentric(e, p);
    if (l.minCoeff() > bestMin) {
      bestMin = l.minCoeff();
      best = e;
      bestL = l;
    }
  };
  for (int k = bucketStart_[c]; k < bucketStart_[c + 1]; ++k) consider(bucketElements_[k]);
  if (best < 0)  // far from the mesh (no element near this cell): every element is a candidate
    for (int e = 0; e < elementCount(); ++e) consider(e);
  if (best < 0) throw std::invalid_argument("SimplexLocator: empty mesh");
  bestL = bestL.cwiseMax(0.0);
  bestL /= bestL.sum();
  SimplexWeights<d> w;
  for (int v = 0; v < d + 1; ++v) {
    w.particle[v] = elements_[best * (d + 1) + v];
    w.weight[v] = bestL[v];
  }
  return w;
}

template <int d>
double SimplexLocator<d>::rayEntry(const Vec& p, const Vec& e, double tMax) const {
  const Vec q = p + tMax * e;
  Index<d> lo, hi;
  cellRange<d>(layout_, p.cwiseMin(q), p.cwiseMax(q), 0, lo, hi);
  std::vector<int> candidates;
  forEachIndexIn<d>(lo, hi, [&](const Index<d>& c) {
    const int cell = layout_.cellIndex(c);
    candidates.insert(candidates.end(), bucketElements_.begin() + bucketStart_[cell],
                      bucketElements_.begin() + bucketStart_[cell + 1]);
  });
  std::sort(candidates.begin(), candidates.end());
  candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
  double entry = std::numeric_limits<double>::infinity();
  for (int el : candidates) {
    // lambda(t) = l0 + t (l1 - l0) / tMax >= 0 for every coordinate: an interval of t.
    const auto l0 = barycentric(el, p), l1 = barycentric(el, q);
    double t0 = 0, t1 = tMax;
    for (int v = 0; v < d + 1 && t0 <= t1; ++v) {
      const double slope = (l1[v] - l0[v]) / tMax;
      if (slope == 0) {
        if (l0[v] < 0) t1 = -1;
      } else if (slope > 0) {
        t0 = std::max(t0, -l0[v] / slope);
      } else {
        t1 = std::min(t1, -l0[v] / slope);
      }
    }
    if (t0 <= t1) entry = std::min(entry, t0);
  }
  return entry;
}

template class SimplexLocator<2>;
template class SimplexLocator<3>;

}  // namespace monolith::solvers
