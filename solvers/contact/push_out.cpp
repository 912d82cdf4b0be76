// Central-body interpenetration resolution, thesis Sec. 4.6.1 and Appendix B (notes 1.7).
// Unknown x = (Delta v, Delta omega) of the central body; everything is for dtau = 1, so
// velocities and displacements coincide.
#include "solvers/contact/push_out.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cmath>

#include "solvers/contact/impulse.h"

namespace monolith::solvers::contact {

namespace {

template <int d>
constexpr int kGeneralized = d + kAngularDim<d>;  // 6 in 3-D, 3 in 2-D
template <int d>
using GenVec = Eigen::Matrix<double, kGeneralized<d>, 1>;
template <int d>
using GenMat = Eigen::Matrix<double, kGeneralized<d>, kGeneralized<d>>;
// G_o = (delta; r_o*): maps an impulse at p_o to (linear, angular) impulse about c's centre;
// G_o^T x = Delta v + r_o*^T Delta omega is c's velocity at p_o.
template <int d>
using Lever = Eigen::Matrix<double, kGeneralized<d>, d>;

template <int d>
Lever<d> leverMatrix(const Vec<d>& r) {
  Lever<d> g;
  g.template topRows<d>().setIdentity();
  g.template bottomRows<kAngularDim<d>>() = crossMatrix<d>(r);
  return g;
}

// K_o = m_o^{-1} delta + q_o*^T I_o^{-1} q_o* (for a static outer this is K_hat_s of B.1).
// A static outer given without a finite mass gets K_hat_s = delta, the unit weight the original
// code gives every static contact (notes 1.7).
template <int d>
Mat<d> outerFactor(const PushOutOuter<d>& o) {
  if (o.isStatic && !(std::isfinite(o.mass) && o.mass > 0 && o.inertia.allFinite())) {
    return Mat<d>::Identity();
  }
  ImpulseBody<d> body;
  body.inverseMass = 1 / o.mass;
  body.inverseInertia = o.inertia.inverse();
  body.r = o.q;
  return impulseFactor<d>(body);
}

// A x = b over a set of outers, (B.2) and the A_d, b_d, A_s, b_s of B.3.2.
template <int d>
struct NormalSystem {
  GenMat<d> a = GenMat<d>::Zero();
  GenVec<d> b = GenVec<d>::Zero();
  void add(const Vec<d>& r, const Mat<d>& kInverse, const Vec<d>& v) {
    const Lever<d> g = leverMatrix<d>(r);
    const Eigen::Matrix<double, kGeneralized<d>, d> gk = g * kInverse;
    a.noalias() += gk * g.transpose();
    b.noalias() += gk * v;
  }
};

// The central body's own block diag(m_c delta, I_c) of A_d.
template <int d>
void addCentralMass(const PushOutCentral<d>& c, GenMat<d>& a) {
  a.template topLeftCorner<d, d>() += c.mass * Mat<d>::Identity();
  a.template bottomRightCorner<kAngularDim<d>, kAngularDim<d>>() += c.inertia;
}

// B.3.1 with the static contact at r_s demanding c's velocity v_s there (B.4):
//   (I_c + sum_d rt_d* K_d^{-1} rt_d*^T + m_c r_s* r_s*^T) Delta omega
//       = sum_d rt_d* K_d^{-1} (v_d - v_s) + m_c r_s* v_s,          rt_d = r_d - r_s,
//   Delta v = v_s - r_s*^T Delta omega.
template <int d>
GenVec<d> solveOneStatic(const PushOutCentral<d>& c, const std::vector<PushOutOuter<d>>& outers,
                         const std::vector<Mat<d>>& kInverse, const Vec<d>& rs, const Vec<d>& vs) {
  constexpr int k = kAngularDim<d>;
  const CrossMat<d> rsStar = crossMatrix<d>(rs);
  AngMat<d> m = c.inertia + c.mass * rsStar * rsStar.transpose();
  AngVec<d> rhs = c.mass * rsStar * vs;
  for (std::size_t i = 0; i < outers.size(); ++i) {
    if (outers[i].isStatic) continue;
    const CrossMat<d> rt = crossMatrix<d>(Vec<d>(outers[i].r - rs));
    m.noalias() += rt * kInverse[i] * rt.transpose();
    rhs.noalias() += rt * kInverse[i] * (outers[i].displacement - vs);
  }
  const AngVec<d> dw = m.llt().solve(rhs);
  GenVec<d> x;
  x.template head<d>() = vs - angularCross<d>(dw, rs);
  x.template tail<k>() = dw;
  return x;
}

// An orthonormal basis of the complement of the unit-normalised z: the columns 2..n of the
// Householder reflection that maps e_1 to +-z/|z| (the sign chosen to avoid cancellation).
template <int n>
Eigen::Matrix<double, n, n - 1> orthogonalComplement(const Eigen::Matrix<double, n, 1>& z) {
  Eigen::Matrix<double, n, 1> w = z.normalized();
  w(0) += w(0) >= 0 ? 1.0 : -1.0;
  const Eigen::Matrix<double, n, n> h =
      Eigen::Matrix<double, n, n>::Identity() - (2 / w.squaredNorm()) * w * w.transpose();
  return h.template rightCols<n - 1>();
}

// B.3.2 when A_s has the one-dimensional nullspace z (collinear statics):
//   (Y^T A_s; z^T A_d) x = (Y^T b_s; z^T b_d),
// Y the orthogonal complement of z (= the column space of the symmetric A_s).
template <int d>
GenVec<d> solveWithNullspace(const NormalSystem<d>& dyn, const NormalSystem<d>& stat,
                             const GenVec<d>& z) {
  constexpr int n = kGeneralized<d>;
  const Eigen::Matrix<double, n, n - 1> y = orthogonalComplement<n>(z);
  GenMat<d> m;
  GenVec<d> rhs;
  m.template topRows<n - 1>() = y.transpose() * stat.a;
  m.template bottomRows<1>() = z.transpose() * dyn.a;
  rhs.template head<n - 1>() = y.transpose() * stat.b;
  rhs(n - 1) = z.dot(dyn.b);
  return m.fullPivLu().solve(rhs);
}

// A dynamic central body with at least one static outer: B.3.1-B.3.3, the case chosen by the
// spread of the static contact points (scatter C C^T about their centroid, threshold 0.01 L^2).
template <int d>
GenVec<d> solveWithStatics(const PushOutCentral<d>& central,
                           const std::vector<PushOutOuter<d>>& outers,
                           const std::vector<Mat<d>>& kInverse, const std::vector<int>& statics,
                           const NormalSystem<d>& dyn, const NormalSystem<d>& stat,
                           PushOutCase& kind) {
  Vec<d> centroid = Vec<d>::Zero();
  for (int s : statics) centroid += outers[s].r;
  centroid /= static_cast<double>(statics.size());
  Mat<d> scatter = Mat<d>::Zero();
  for (int s : statics) {
    const Vec<d> offset = outers[s].r - centroid;
    scatter.noalias() += offset * offset.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Mat<d>> eigen;
  eigen.computeDirect(scatter);  // closed form for 2x2 and 3x3; eigenvalues ascending
  const double threshold = 0.01 * central.lengthScale * central.lengthScale;
  int spread = 0;
  for (int i = 0; i < d; ++i) spread += eigen.eigenvalues()(i) > threshold ? 1 : 0;

  if (spread == 0) {
    // One static, or all statics at one point c: B.3.1 with r_s = c. In the coincident case
    // A_s = (delta; c*) L (delta; c*)^T, so Y^T A_s x = Y^T b_s reads
    //   L (Delta v + c*^T Delta omega) = sum_s K_hat_s^{-1} v_s:
    // B.4 with v_s the K_hat^{-1}-weighted mean of the static displacements.
    kind = PushOutCase::OneStatic;
    Vec<d> vs = outers[statics.front()].displacement;
    if (statics.size() > 1) {
      Mat<d> l = Mat<d>::Zero();
      Vec<d> weighted = Vec<d>::Zero();
      for (int s : statics) {
        l += kInverse[s];
        weighted += kInverse[s] * outers[s].displacement;
      }
      vs = l.llt().solve(weighted);
    }
    return solveOneStatic<d>(central, outers, kInverse, centroid, vs);
  }
  if constexpr (d == 3) {
    if (spread == 1) {
      // Collinear statics (3-D only): Z = (c x u; u), the rotation about the line c + alpha u
      // that no static contact resists; Z^T b_s = 0 so the eps^{-1} term drops (B.3.3).
      kind = PushOutCase::StaticsCollinear;
      const Vec<d> u = eigen.eigenvectors().col(d - 1);  // the one large eigenvalue
      GenVec<d> z;
      z << centroid.cross(u), u;
      return solveWithNullspace<d>(dyn, stat, z);
    }
  }
  // A_s nonsingular (in 2-D already for two distinct points): the statics alone fix the
  // central body and the dynamic outers do not affect it (B.3.2).
  kind = PushOutCase::StaticsGeneral;
  return stat.a.ldlt().solve(stat.b);
}

}  // namespace

template <int d>
void solvePushOut(const PushOutCentral<d>& central, const std::vector<PushOutOuter<d>>& outers,
                  PushOutResult<d>& result) {
  constexpr int k = kAngularDim<d>;
  result.kind = PushOutCase::AllDynamic;
  result.centralDisplacement.setZero();
  result.centralRotation.setZero();
  const std::size_t count = outers.size();
  result.outerImpulses.assign(count, Vec<d>::Zero());
  result.outerDisplacements.assign(count, Vec<d>::Zero());
  result.outerRotations.assign(count, AngVec<d>::Zero());
  if (count == 0) return;

  // Per thread and kept: push-out solves one such system per body and round.
  thread_local std::vector<Mat<d>> kInverse;
  thread_local std::vector<int> statics;
  kInverse.resize(count);
  statics.clear();
  NormalSystem<d> dyn;   // A_d (the central mass is added below), b_d
  NormalSystem<d> stat;  // A_s, b_s from K_hat_s
  for (std::size_t i = 0; i < count; ++i) {
    kInverse[i] = outerFactor<d>(outers[i]).inverse();
    if (outers[i].isStatic) {
      statics.push_back(static_cast<int>(i));
      stat.add(outers[i].r, kInverse[i], outers[i].displacement);
    } else {
      dyn.add(outers[i].r, kInverse[i], outers[i].displacement);
    }
  }

  GenVec<d> x = GenVec<d>::Zero();
  if (central.isStatic) {
    // B.3: m_c^{-1} = I_c^{-1} = 0, so (B.3) decouples into j_d = -K_d^{-1} v_d; outer statics
    // cannot exchange anything with a static centre and are ignored.
    result.kind = PushOutCase::CentralStatic;
  } else {
    addCentralMass<d>(central, dyn.a);
    if (statics.empty()) {
      result.kind = PushOutCase::AllDynamic;
      x = dyn.a.llt().solve(dyn.b);  // (B.2) is SPD
    } else {
      x = solveWithStatics<d>(central, outers, kInverse, statics, dyn, stat, result.kind);
    }
  }

  // (B.3): j_o = K_o^{-1}(-v_o + Delta v + r_o*^T Delta omega), applied to dynamic outers only
  // (B.2.1): position m_o^{-1} j_o, rotation vector I_o^{-1}(q_o x j_o).
  for (std::size_t i = 0; i < count; ++i) {
    const PushOutOuter<d>& o = outers[i];
    if (o.isStatic) continue;
    const Vec<d> centralAtPoint = leverMatrix<d>(o.r).transpose() * x;
    const Vec<d> j = kInverse[i] * (centralAtPoint - o.displacement);
    result.outerImpulses[i] = j;
    result.outerDisplacements[i] = j / o.mass;
    result.outerRotations[i] = o.inertia.inverse() * cross<d>(o.q, j);
  }
  result.centralDisplacement = x.template head<d>();
  result.centralRotation = x.template tail<k>();
}

template <int d>
PushOutResult<d> solvePushOut(const PushOutCentral<d>& central, const std::vector<PushOutOuter<d>>& outers) {
  PushOutResult<d> result;
  solvePushOut<d>(central, outers, result);
  return result;
}

template PushOutResult<2> solvePushOut<2>(const PushOutCentral<2>&,
                                          const std::vector<PushOutOuter<2>>&);
template PushOutResult<3> solvePushOut<3>(const PushOutCentral<3>&,
                                          const std::vector<PushOutOuter<3>>&);
template void solvePushOut<2>(const PushOutCentral<2>&, const std::vector<PushOutOuter<2>>&, PushOutResult<2>&);
template void solvePushOut<3>(const PushOutCentral<3>&, const std::vector<PushOutOuter<3>>&, PushOutResult<3>&);

}  // namespace monolith::solvers::contact
