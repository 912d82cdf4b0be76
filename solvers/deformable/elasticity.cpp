#include "solvers/deformable/elasticity.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <Eigen/LU>
#include <Eigen/Geometry>
#include <Eigen/SVD>

// GCC 12 reports Eigen's JacobiSVD internals as maybe-uninitialized where they are instantiated
// (a false positive inside Eigen); silenced for this file.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

namespace monolith::solvers::deformable {

namespace {

// Each element writes only its own slot; a fixed grain and simple partitioner keep the split
// independent of the thread count, and the scatter afterwards is serial in element order, so the
// forces are bitwise the same on any number of threads.
template <class F>
void forEachElement(int n, F&& f) {
  if (n <= 0) return;
  tbb::parallel_for(
      tbb::blocked_range<int>(0, n, 256),
      [&](const tbb::blocked_range<int>& r) {
        for (int i = r.begin(); i != r.end(); ++i) f(i);
      },
      tbb::simple_partitioner());
}

template <int d>
VecD<d> at(const double* a, int i) {
  return Eigen::Map<const VecD<d>>(a + d * i);
}

// f_{idx[a]} += s g_a: a force s along an altitude spring's gradient.
template <int d>
void addAlongGradient(const int* idx, const VecD<d>* g, double s, double* f) {
  for (int a = 0; a <= d; ++a) Eigen::Map<VecD<d>>(f + d * idx[a]) += s * g[a];
}

template <int d>
MatD<d> edgeMatrix(const ForceModel<d>& fm, int e, const double* a) {
  const int* n = &fm.elements[(d + 1) * e];
  MatD<d> D;
  for (int k = 0; k < d; ++k) D.col(k) = at<d>(a, n[k + 1]) - at<d>(a, n[0]);
  return D;
}

// Adds the nodal forces of an element whose force on the edge matrix Ds is G (d x d): node k+1
// receives column k, node 0 minus their sum.
template <int d>
void scatter(const ForceModel<d>& fm, int e, const MatD<d>& G, double* f) {
  const int* n = &fm.elements[(d + 1) * e];
  for (int k = 0; k < d; ++k) {
    Eigen::Map<VecD<d>>(f + d * n[k + 1]) += G.col(k);
    Eigen::Map<VecD<d>>(f + d * n[0]) -= G.col(k);
  }
}

template <int d>
MatD<d> deviator(const MatD<d>& A) {
  return A - (A.trace() / d) * MatD<d>::Identity();
}

}  // namespace

namespace {

// 3x3 rotated SVD as McAdams et al. (2011, "Computing the singular value decomposition of 3x3
// matrices with minimal branching"): V from the eigenvectors of F^T F by cyclic Jacobi rotations
// to round-off, then U from a QR factorization of F V, whose diagonal is the singular values with
// the sign of det F in the last. Several times faster than the general JacobiSVD, which dominated
// the cost of a step, and as accurate: U and s come from F V itself, so a tiny or negative
// singular value of a crushed element is exact to round-off of |F| even though F^T F squares it.
void rotatedSvd3(const Eigen::Matrix3d& F, Eigen::Matrix3d& U, Eigen::Vector3d& s, Eigen::Matrix3d& V) {
  Eigen::Matrix3d A = F.transpose() * F;
  V.setIdentity();
  const double scale = A.squaredNorm();
  for (int sweep = 0; sweep < 16; ++sweep) {
    const double off = A(0, 1) * A(0, 1) + A(0, 2) * A(0, 2) + A(1, 2) * A(1, 2);
    if (!(off > 1e-30 * scale)) break;
    for (int k = 0; k < 3; ++k) {
      // The rotation in the (p, q) plane that zeroes A(p, q) (Numerical Recipes, jacobi).
      const int p = k == 2 ? 1 : 0, q = k == 0 ? 1 : 2, r = 3 - p - q;
      const double apq = A(p, q);
      if (apq == 0) continue;
      const double theta = (A(q, q) - A(p, p)) / (2 * apq);
      const double t = std::abs(theta) > 1e150 ? 0.5 / theta
                                               : (theta >= 0 ? 1 : -1) / (std::abs(theta) + std::sqrt(theta * theta + 1));
      const double c = 1 / std::sqrt(t * t + 1), sn = t * c;
      A(p, p) -= t * apq;
      A(q, q) += t * apq;
      A(p, q) = A(q, p) = 0;
      const double arp = A(r, p), arq = A(r, q);
      A(r, p) = A(p, r) = c * arp - sn * arq;
      A(r, q) = A(q, r) = sn * arp + c * arq;
      for (int i = 0; i < 3; ++i) {
        const double vp = V(i, p), vq = V(i, q);
        V(i, p) = c * vp - sn * vq;
        V(i, q) = sn * vp + c * vq;
      }
    }
  }
  // Descending eigenvalues, V a rotation.
  std::array<int, 3> order = {0, 1, 2};
  std::sort(order.begin(), order.end(), [&](int a, int b) { return A(a, a) > A(b, b) || (A(a, a) == A(b, b) && a < b); });
  const Eigen::Matrix3d W = V;
  for (int k = 0; k < 3; ++k) V.col(k) = W.col(order[k]);
  if (V.determinant() < 0) V.col(2) *= -1;
  // QR of B = F V by Gram-Schmidt (its columns are orthogonal up to round-off); a vanishing
  // column (a flattened element) takes any direction that completes the frame.
  const Eigen::Matrix3d B = F * V;
  const double tiny = 1e-12 * std::max(B.norm(), std::numeric_limits<double>::min());
  Eigen::Vector3d u0 = B.col(0);
  u0 = u0.norm() > tiny ? Eigen::Vector3d(u0.normalized()) : Eigen::Vector3d::UnitX();
  Eigen::Vector3d u1 = B.col(1) - u0.dot(B.col(1)) * u0;
  u1 = u1.norm() > tiny ? Eigen::Vector3d(u1.normalized()) : Eigen::Vector3d(u0.unitOrthogonal());
  U.col(0) = u0;
  U.col(1) = u1;
  U.col(2) = u0.cross(u1);
  for (int k = 0; k < 3; ++k) s(k) = U.col(k).dot(B.col(k));
}

}  // namespace

template <int d>
void rotatedSvd(const MatD<d>& F, MatD<d>& U, VecD<d>& s, MatD<d>& V) {
  if constexpr (d == 3) {
    rotatedSvd3(F, U, s, V);
  } else {
    Eigen::JacobiSVD<MatD<d>> svd(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
    U = svd.matrixU();
    V = svd.matrixV();
    s = svd.singularValues();
    // [81] Sec. 5: make U and V rotations; the reflection goes into the smallest singular value.
    if (U.determinant() < 0) {
      U.col(d - 1) *= -1;
      s(d - 1) *= -1;
    }
    if (V.determinant() < 0) {
      V.col(d - 1) *= -1;
      s(d - 1) *= -1;
    }
  }
}

template <int d>
double energyDensity(Model m, const Lame& lame, const VecD<d>& s, double clamp) {
  if (m == Model::Corotated) {
    const VecD<d> e = s - VecD<d>::Ones();
    return lame.mu * e.squaredNorm() + 0.5 * lame.lambda * e.sum() * e.sum();
  }
  const VecD<d> c = s.cwiseMax(clamp);
  const double lnJ = c.array().log().sum();
  return 0.5 * lame.mu * (c.squaredNorm() - d) - lame.mu * lnJ + 0.5 * lame.lambda * lnJ * lnJ;
}

template <int d>
VecD<d> diagonalStress(Model m, const Lame& lame, const VecD<d>& s, double clamp) {
  if (m == Model::Corotated) {
    const VecD<d> e = s - VecD<d>::Ones();
    return 2 * lame.mu * e + VecD<d>::Constant(lame.lambda * e.sum());
  }
  const VecD<d> c = s.cwiseMax(clamp);
  const double lnJ = c.array().log().sum();
  VecD<d> P;
  for (int i = 0; i < d; ++i) P(i) = lame.mu * c(i) - (lame.mu - lame.lambda * lnJ) / c(i);
  return P;
}

template <int d>
double signedAltitude(const double* x, const int* idx, VecD<d>* gradient) {
  const VecD<d> a = at<d>(x, idx[0]), b = at<d>(x, idx[1]);
  VecD<d> n;
  VecD<d> bary;  // barycentric coordinates of the projection on the side, for idx[1..d]
  if constexpr (d == 2) {
    const VecD<d> e = at<d>(x, idx[2]) - b;
    const double len2 = e.squaredNorm();
    if (len2 == 0) {
      for (int k = 0; k <= d; ++k) gradient[k].setZero();
      return 0;
    }
    n = VecD<d>(-e(1), e(0)) / std::sqrt(len2);
    const double t = (a - b).dot(e) / len2;
    bary << 1 - t, t;
  } else {
    const VecD<d> e1 = at<d>(x, idx[2]) - b, e2 = at<d>(x, idx[3]) - b;
    const VecD<d> c = e1.cross(e2);
    const double area2 = c.squaredNorm();
    if (area2 == 0) {
      for (int k = 0; k <= d; ++k) gradient[k].setZero();
      return 0;
    }
    n = c / std::sqrt(area2);
    // Barycentric coordinates of q = a - h n in the triangle (b, b + e1, b + e2).
    const VecD<d> r = a - b;
    const double s1 = r.cross(e2).dot(c) / area2, s2 = e1.cross(r).dot(c) / area2;
    bary << 1 - s1 - s2, s1, s2;
  }
  gradient[0] = n;
  for (int k = 0; k < d; ++k) gradient[k + 1] = -bary(k) * n;
  return n.dot(a - b);
}

template <int d>
int ForceModel<d>::dampingRows() const {
  int rows = 0;
  if (finiteElements() && rayleighBeta > 0) rows += (d * d + 1) * elementCount();
  if (rayleighAlpha > 0) rows += d * static_cast<int>(mass.size());
  rows += springCount() + altitudeCount();
  return rows;
}

template <int d>
MatD<d> deformationGradient(const ForceModel<d>& fm, int e, const double* x) {
  return edgeMatrix(fm, e, x) * fm.DmInv[e];
}

template <int d>
double elasticEnergy(const ForceModel<d>& fm, const double* x) {
  double E = 0;
  if (fm.finiteElements()) {
    // Element energies in parallel into their own slots, summed serially in element order: the
    // same bits on any number of threads.
    std::vector<double> energy(fm.elementCount());
    forEachElement(fm.elementCount(), [&](int e) {
      MatD<d> U, V;
      VecD<d> s;
      rotatedSvd<d>(deformationGradient(fm, e, x), U, s, V);
      energy[e] = fm.restVolume[e] * energyDensity<d>(fm.model, fm.lame, s, fm.clamp);
    });
    for (double w : energy) E += w;
  }
  for (int k = 0; k < fm.springCount(); ++k) {
    const double L = (at<d>(x, fm.springs[2 * k + 1]) - at<d>(x, fm.springs[2 * k])).norm();
    E += 0.5 * fm.springK[k] * (L - fm.springRest[k]) * (L - fm.springRest[k]);
  }
  for (int k = 0; k < fm.altitudeCount(); ++k) {
    VecD<d> g[d + 1];
    const double h = signedAltitude<d>(x, &fm.altitudes[(d + 1) * k], g);
    E += 0.5 * fm.altitudeK[k] * (h - fm.altitudeRest[k]) * (h - fm.altitudeRest[k]);
  }
  return E;
}

template <int d>
void addElasticForces(const ForceModel<d>& fm, const double* x, double* f, std::vector<MatD<d>>* rotations) {
  const bool withRotations = rotations && fm.finiteElements() && fm.rayleighBeta > 0;
  if (rotations) rotations->assign(withRotations ? fm.elementCount() : 0, MatD<d>::Identity());
  if (fm.finiteElements()) {
    std::vector<MatD<d>> G(fm.elementCount());
    forEachElement(fm.elementCount(), [&](int e) {
      MatD<d> U, V;
      VecD<d> s;
      rotatedSvd<d>(deformationGradient(fm, e, x), U, s, V);
      if (withRotations) (*rotations)[e] = U * V.transpose();
      const MatD<d> P = U * diagonalStress<d>(fm.model, fm.lame, s, fm.clamp).asDiagonal() * V.transpose();
      G[e] = -fm.restVolume[e] * P * fm.DmInv[e].transpose();
    });
    for (int e = 0; e < fm.elementCount(); ++e) scatter(fm, e, G[e], f);
  }
  for (int k = 0; k < fm.springCount(); ++k) {
    const int i = fm.springs[2 * k], j = fm.springs[2 * k + 1];
    const VecD<d> l = at<d>(x, j) - at<d>(x, i);
    const double L = l.norm();
    if (L == 0) continue;
    const VecD<d> fi = fm.springK[k] * (L - fm.springRest[k]) / L * l;
    Eigen::Map<VecD<d>>(f + d * i) += fi;
    Eigen::Map<VecD<d>>(f + d * j) -= fi;
  }
  for (int k = 0; k < fm.altitudeCount(); ++k) {
    VecD<d> g[d + 1];
    const int* idx = &fm.altitudes[(d + 1) * k];
    const double h = signedAltitude<d>(x, idx, g);
    addAlongGradient<d>(idx, g, -fm.altitudeK[k] * (h - fm.altitudeRest[k]), f);
  }
}

template <int d>
std::vector<MatD<d>> dampingRotations(const ForceModel<d>& fm, const double* x) {
  std::vector<MatD<d>> R;
  if (!fm.finiteElements() || fm.rayleighBeta <= 0) return R;
  R.resize(fm.elementCount());
  forEachElement(fm.elementCount(), [&](int e) {
    MatD<d> U, V;
    VecD<d> s;
    rotatedSvd<d>(deformationGradient(fm, e, x), U, s, V);
    R[e] = U * V.transpose();
  });
  return R;
}

namespace {

// dh/dt = sum_a g_a . v_{idx[a]} for an altitude spring's gradient g.
template <int d>
double alongGradient(const int* idx, const VecD<d>* g, const double* v) {
  double r = 0;
  for (int a = 0; a <= d; ++a) r += g[a].dot(at<d>(v, idx[a]));
  return r;
}

template <int d>
VecD<d> springDirection(const ForceModel<d>& fm, int k, const double* x) {
  const VecD<d> l = at<d>(x, fm.springs[2 * k + 1]) - at<d>(x, fm.springs[2 * k]);
  const double L = l.norm();
  return L > 0 ? VecD<d>(l / L) : VecD<d>::Zero();
}

}  // namespace

template <int d>
void addDampingForces(const ForceModel<d>& fm, const std::vector<MatD<d>>& R, const double* x, const double* v,
                      double* f) {
  if (!R.empty()) {
    std::vector<MatD<d>> G(fm.elementCount());
    const double beta = fm.rayleighBeta;
    forEachElement(fm.elementCount(), [&](int e) {
      const MatD<d> Fdot = edgeMatrix(fm, e, v) * fm.DmInv[e];
      const MatD<d> RtF = R[e].transpose() * Fdot;
      const MatD<d> eps = 0.5 * (RtF + RtF.transpose());
      const MatD<d> S = beta * (2 * fm.lame.mu * eps + fm.lame.lambda * eps.trace() * MatD<d>::Identity());
      G[e] = -fm.restVolume[e] * R[e] * S * fm.DmInv[e].transpose();
    });
    for (int e = 0; e < fm.elementCount(); ++e) scatter(fm, e, G[e], f);
  }
  if (fm.rayleighAlpha > 0)
    for (std::size_t p = 0; p < fm.mass.size(); ++p)
      for (int a = 0; a < d; ++a) f[d * p + a] -= fm.rayleighAlpha * fm.mass[p] * v[d * p + a];
  for (int k = 0; k < fm.springCount(); ++k) {
    const int i = fm.springs[2 * k], j = fm.springs[2 * k + 1];
    const VecD<d> n = springDirection(fm, k, x);
    const VecD<d> fi = fm.springC[k] * n.dot(at<d>(v, j) - at<d>(v, i)) * n;
    Eigen::Map<VecD<d>>(f + d * i) += fi;
    Eigen::Map<VecD<d>>(f + d * j) -= fi;
  }
  for (int k = 0; k < fm.altitudeCount(); ++k) {
    VecD<d> g[d + 1];
    const int* idx = &fm.altitudes[(d + 1) * k];
    signedAltitude<d>(x, idx, g);
    addAlongGradient<d>(idx, g, -fm.altitudeC[k] * alongGradient<d>(idx, g, v), f);
  }
}

template <int d>
void applyDampingFactor(const ForceModel<d>& fm, const std::vector<MatD<d>>& R, const double* x, double dt,
                        const double* v, double* y) {
  int row = 0;
  if (!R.empty()) {
    forEachElement(fm.elementCount(), [&](int e) {
      const double w = dt * fm.restVolume[e] * fm.rayleighBeta;
      const double a = std::sqrt(w * 2 * fm.lame.mu), b = std::sqrt(w * (2 * fm.lame.mu / d + fm.lame.lambda));
      const MatD<d> RtF = R[e].transpose() * edgeMatrix(fm, e, v) * fm.DmInv[e];
      const MatD<d> eps = 0.5 * (RtF + RtF.transpose());
      const MatD<d> dev = deviator<d>(eps);
      double* out = y + (d * d + 1) * e;
      for (int i = 0; i < d; ++i)
        for (int j = 0; j < d; ++j) out[d * i + j] = a * dev(i, j);
      out[d * d] = b * eps.trace();
    });
    row += (d * d + 1) * fm.elementCount();
  }
  if (fm.rayleighAlpha > 0) {
    for (std::size_t p = 0; p < fm.mass.size(); ++p) {
      const double a = std::sqrt(dt * fm.rayleighAlpha * fm.mass[p]);
      for (int k = 0; k < d; ++k) y[row++] = a * v[d * p + k];
    }
  }
  for (int k = 0; k < fm.springCount(); ++k) {
    const int i = fm.springs[2 * k], j = fm.springs[2 * k + 1];
    y[row++] = std::sqrt(dt * fm.springC[k]) * springDirection(fm, k, x).dot(at<d>(v, j) - at<d>(v, i));
  }
  for (int k = 0; k < fm.altitudeCount(); ++k) {
    VecD<d> g[d + 1];
    const int* idx = &fm.altitudes[(d + 1) * k];
    signedAltitude<d>(x, idx, g);
    y[row++] = std::sqrt(dt * fm.altitudeC[k]) * alongGradient<d>(idx, g, v);
  }
}

template <int d>
void applyDampingFactorTranspose(const ForceModel<d>& fm, const std::vector<MatD<d>>& R, const double* x, double dt,
                                 const double* y, double* f) {
  int row = 0;
  if (!R.empty()) {
    std::vector<MatD<d>> G(fm.elementCount());
    forEachElement(fm.elementCount(), [&](int e) {
      const double w = dt * fm.restVolume[e] * fm.rayleighBeta;
      const double a = std::sqrt(w * 2 * fm.lame.mu), b = std::sqrt(w * (2 * fm.lame.mu / d + fm.lame.lambda));
      const double* in = y + (d * d + 1) * e;
      MatD<d> Y;
      for (int i = 0; i < d; ++i)
        for (int j = 0; j < d; ++j) Y(i, j) = in[d * i + j];
      // The adjoint of v -> (a dev(e), b tr e), e = sym(R^T Ds(v) DmInv): dev and sym are
      // self-adjoint projections, so the stress-like matrix is a sym(dev Y) + b y_t I.
      const MatD<d> devY = deviator<d>(Y);
      const MatD<d> S = a * 0.5 * (devY + devY.transpose()) + b * in[d * d] * MatD<d>::Identity();
      G[e] = R[e] * S * fm.DmInv[e].transpose();
    });
    for (int e = 0; e < fm.elementCount(); ++e) scatter(fm, e, G[e], f);
    row += (d * d + 1) * fm.elementCount();
  }
  if (fm.rayleighAlpha > 0) {
    for (std::size_t p = 0; p < fm.mass.size(); ++p) {
      const double a = std::sqrt(dt * fm.rayleighAlpha * fm.mass[p]);
      for (int k = 0; k < d; ++k) f[d * p + k] += a * y[row++];
    }
  }
  for (int k = 0; k < fm.springCount(); ++k) {
    const int i = fm.springs[2 * k], j = fm.springs[2 * k + 1];
    const VecD<d> g = std::sqrt(dt * fm.springC[k]) * y[row++] * springDirection(fm, k, x);
    Eigen::Map<VecD<d>>(f + d * i) -= g;
    Eigen::Map<VecD<d>>(f + d * j) += g;
  }
  for (int k = 0; k < fm.altitudeCount(); ++k) {
    VecD<d> g[d + 1];
    const int* idx = &fm.altitudes[(d + 1) * k];
    signedAltitude<d>(x, idx, g);
    addAlongGradient<d>(idx, g, std::sqrt(dt * fm.altitudeC[k]) * y[row++], f);
  }
}

#define MONOLITH_INSTANTIATE(D)                                                                                   \
  template void rotatedSvd<D>(const MatD<D>&, MatD<D>&, VecD<D>&, MatD<D>&);                                      \
  template double energyDensity<D>(Model, const Lame&, const VecD<D>&, double);                                   \
  template VecD<D> diagonalStress<D>(Model, const Lame&, const VecD<D>&, double);                                 \
  template struct ForceModel<D>;                                                                                  \
  template MatD<D> deformationGradient<D>(const ForceModel<D>&, int, const double*);                              \
  template double elasticEnergy<D>(const ForceModel<D>&, const double*);                                          \
  template double signedAltitude<D>(const double*, const int*, VecD<D>*);                                          \
  template void addElasticForces<D>(const ForceModel<D>&, const double*, double*, std::vector<MatD<D>>*);         \
  template std::vector<MatD<D>> dampingRotations<D>(const ForceModel<D>&, const double*);                         \
  template void addDampingForces<D>(const ForceModel<D>&, const std::vector<MatD<D>>&, const double*,             \
                                    const double*, double*);                                                      \
  template void applyDampingFactor<D>(const ForceModel<D>&, const std::vector<MatD<D>>&, const double*, double,   \
                                      const double*, double*);                                                    \
  template void applyDampingFactorTranspose<D>(const ForceModel<D>&, const std::vector<MatD<D>>&, const double*, \
                                               double, const double*, double*);
MONOLITH_INSTANTIATE(2)
MONOLITH_INSTANTIATE(3)
#undef MONOLITH_INSTANTIATE

}  // namespace monolith::solvers::deformable
