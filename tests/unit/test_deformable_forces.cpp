// Forces of deformable solids (solvers/deformable/elasticity.h): elastic forces are the negative
// gradient of the energy (central finite differences), zero at rest and under rigid motion
// (patch test), the damping operator is symmetric negative semidefinite with C^T C = -dt D to
// round-off, and a crushed (inverted) element is pushed back.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <random>

#include "solvers/deformable/simplex_mesh.h"

namespace dm = monolith::solvers::deformable;

namespace {

template <int d>
dm::ForceModel<d> model(dm::Model m, const dm::MeshData<d>& mesh, double alpha = 0, double beta = 0, double zeta = 0,
                        double altitude = 0) {
  dm::Material mat;
  mat.model = m;
  mat.youngsModulus = 1e4;
  mat.poissonRatio = 0.3;
  mat.density = 100;
  mat.rayleighAlpha = alpha;
  mat.rayleighBeta = beta;
  mat.overdamping = zeta;
  mat.altitudeStiffness = altitude;
  std::vector<double> X;
  for (const auto& x : mesh.x)
    for (int a = 0; a < d; ++a) X.push_back(x(a));
  return dm::prepareForceModel<d>(X, mesh.elements, mat);
}

template <int d>
std::vector<double> flat(const dm::MeshData<d>& mesh) {
  std::vector<double> X;
  for (const auto& x : mesh.x)
    for (int a = 0; a < d; ++a) X.push_back(x(a));
  return X;
}

// A random smooth deformation (no inversion) of the rest positions.
template <int d>
std::vector<double> deformed(const std::vector<double>& X, unsigned seed, double amount) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-amount, amount);
  std::vector<double> x = X;
  for (double& v : x) v += u(rng);
  return x;
}

template <int d>
void checkGradient(dm::Model m, double altitude = 0) {
  const auto mesh = dm::boxMesh<d>(dm::VecD<d>::Constant(0.5), 0.5);
  const auto fm = model<d>(m, mesh, 0, 0, 0, altitude);
  if (altitude > 0) {
    ASSERT_EQ(fm.altitudeCount(), (d + 1) * fm.elementCount());
  }
  const auto x = deformed<d>(flat(mesh), 7, 0.08);
  std::vector<double> f(x.size(), 0.0);
  dm::addElasticForces<d>(fm, x.data(), f.data());
  const double h = 1e-6;
  double worst = 0, scale = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    auto xp = x, xm = x;
    xp[i] += h;
    xm[i] -= h;
    const double fd = -(dm::elasticEnergy<d>(fm, xp.data()) - dm::elasticEnergy<d>(fm, xm.data())) / (2 * h);
    worst = std::max(worst, std::abs(fd - f[i]));
    scale = std::max(scale, std::abs(f[i]));
  }
  // Central differences: error O(h^2 |E'''|) + round-off O(eps E / h) ~ 1e-6 of the force scale.
  EXPECT_GT(scale, 1.0);
  EXPECT_LT(worst, 1e-5 * scale) << "worst |f + dE/dx| " << worst << " of force scale " << scale;
}

}  // namespace

TEST(DeformableForces, CorotatedForceIsMinusEnergyGradient3d) { checkGradient<3>(dm::Model::Corotated); }
TEST(DeformableForces, NeoHookeanForceIsMinusEnergyGradient3d) { checkGradient<3>(dm::Model::NeoHookean); }
TEST(DeformableForces, SpringForceIsMinusEnergyGradient3d) { checkGradient<3>(dm::Model::Springs); }
TEST(DeformableForces, AltitudeSpringForceIsMinusEnergyGradient2d) { checkGradient<2>(dm::Model::Springs, 2e4); }
TEST(DeformableForces, AltitudeSpringForceIsMinusEnergyGradient3d) { checkGradient<3>(dm::Model::Springs, 2e4); }
TEST(DeformableForces, CorotatedForceIsMinusEnergyGradient2d) { checkGradient<2>(dm::Model::Corotated); }
TEST(DeformableForces, NeoHookeanForceIsMinusEnergyGradient2d) { checkGradient<2>(dm::Model::NeoHookean); }

// Patch test: rest state and any rigid motion of it carry no elastic force and no energy.
TEST(DeformableForces, ZeroForceAtRestAndUnderRigidMotion) {
  const auto mesh = dm::boxMesh<3>(Eigen::Vector3d(0.5, 0.3, 0.2), 0.2);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.9, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  for (auto m : {dm::Model::Corotated, dm::Model::NeoHookean, dm::Model::Springs}) {
    const auto fm = model<3>(m, mesh, 0, 0.01, 0.5);
    std::vector<double> x = flat(mesh);
    for (std::size_t p = 0; p < mesh.x.size(); ++p) {
      Eigen::Map<Eigen::Vector3d> xp(&x[3 * p]);
      xp = R * mesh.x[p] + Eigen::Vector3d(1, -2, 3);
    }
    std::vector<double> f(x.size(), 0.0);
    dm::addElasticForces<3>(fm, x.data(), f.data());
    double worst = 0;
    for (double v : f) worst = std::max(worst, std::abs(v));
    // Round-off of E * volume / size ~ 1e4 * 1e-3 / 0.2 times eps.
    EXPECT_LT(worst, 1e-9) << "model " << int(m);
    EXPECT_LT(std::abs(dm::elasticEnergy<3>(fm, x.data())), 1e-12);
    // Stiffness damping does not damp a rigid rotation: v = w x (x - c).
    const Eigen::Vector3d w(0.3, -1.0, 0.7);
    std::vector<double> v(x.size()), fd(x.size(), 0.0);
    for (std::size_t p = 0; p < mesh.x.size(); ++p) {
      Eigen::Map<Eigen::Vector3d> vp(&v[3 * p]);
      vp = w.cross(Eigen::Map<Eigen::Vector3d>(&x[3 * p]));
    }
    const auto Rs = dm::dampingRotations<3>(fm, x.data());
    dm::addDampingForces<3>(fm, Rs, x.data(), v.data(), fd.data());
    worst = 0;
    for (double q : fd) worst = std::max(worst, std::abs(q));
    EXPECT_LT(worst, 1e-9) << "model " << int(m);
  }
}

// C^T C = -dt D: u.(C^T C w) against -dt u.(D w) for random u, w, and D symmetric NSD.
template <int d>
void checkFactor(dm::Model m, double altitude = 0) {
  const auto mesh = dm::boxMesh<d>(dm::VecD<d>::Constant(0.5), 0.35);
  const auto fm = model<d>(m, mesh, 0.7, 0.02, 0.4, altitude);
  const auto x = deformed<d>(flat(mesh), 3, 0.05);
  const auto R = dm::dampingRotations<d>(fm, x.data());
  const double dt = 1e-2;
  std::mt19937 rng(11);
  std::normal_distribution<double> g;
  const std::size_t n = x.size();
  std::vector<double> u(n), w(n);
  for (auto& q : u) q = g(rng);
  for (auto& q : w) q = g(rng);
  const int rows = fm.dampingRows();
  ASSERT_GT(rows, 0);
  std::vector<double> Du(n, 0.0), Dw(n, 0.0), Cw(static_cast<std::size_t>(rows)), CtCw(n, 0.0);
  dm::addDampingForces<d>(fm, R, x.data(), u.data(), Du.data());
  dm::addDampingForces<d>(fm, R, x.data(), w.data(), Dw.data());
  dm::applyDampingFactor<d>(fm, R, x.data(), dt, w.data(), Cw.data());
  dm::applyDampingFactorTranspose<d>(fm, R, x.data(), dt, Cw.data(), CtCw.data());
  double uDw = 0, wDu = 0, uCtCw = 0, uDu = 0, scale = 0;
  for (std::size_t i = 0; i < n; ++i) {
    uDw += u[i] * Dw[i];
    wDu += w[i] * Du[i];
    uCtCw += u[i] * CtCw[i];
    uDu += u[i] * Du[i];
    scale += std::abs(u[i] * Dw[i]);
  }
  // Round-off: each sum has n terms of relative error ~1e-16; 1e-12 of the absolute sum.
  EXPECT_NEAR(uDw, wDu, 1e-12 * scale) << "D symmetric";
  EXPECT_NEAR(uCtCw, -dt * uDw, 1e-12 * dt * scale) << "C^T C = -dt D";
  EXPECT_LT(uDu, 0) << "D negative (semi)definite";
  // Also entrywise: C^T C w = -dt D w.
  for (std::size_t i = 0; i < n; ++i) EXPECT_NEAR(CtCw[i], -dt * Dw[i], 1e-11 * dt * scale);
}

TEST(DeformableForces, DampingFactorCorotated3d) { checkFactor<3>(dm::Model::Corotated); }
TEST(DeformableForces, DampingFactorSprings3d) { checkFactor<3>(dm::Model::Springs); }
TEST(DeformableForces, DampingFactorNeoHookean2d) { checkFactor<2>(dm::Model::NeoHookean); }
TEST(DeformableForces, DampingFactorAltitudeSprings2d) { checkFactor<2>(dm::Model::Springs, 2e4); }
TEST(DeformableForces, DampingFactorAltitudeSprings3d) { checkFactor<3>(dm::Model::Springs, 2e4); }

// Altitude springs: no force at rest or under a rigid motion, and an element squashed towards
// its opposite side is pushed back (the altitude grows again), in 2-D.
TEST(DeformableForces, AltitudeSpringsRestAndSquash2d) {
  const auto mesh = dm::boxMesh<2>(Eigen::Vector2d(0.05, 0.25), 0.026);
  const auto fm = model<2>(dm::Model::Springs, mesh, 0, 0, 2, 400);
  ASSERT_EQ(fm.altitudeCount(), 3 * fm.elementCount());
  const Eigen::Matrix2d R = Eigen::Rotation2Dd(0.7).toRotationMatrix();
  std::vector<double> x = flat(mesh);
  for (std::size_t p = 0; p < mesh.x.size(); ++p) {
    Eigen::Map<Eigen::Vector2d> xp(&x[2 * p]);
    xp = R * mesh.x[p];
  }
  std::vector<double> f(x.size(), 0.0);
  dm::addElasticForces<2>(fm, x.data(), f.data());
  for (double v : f) EXPECT_LT(std::abs(v), 1e-10);
  for (int k = 0; k < fm.altitudeCount(); ++k) EXPECT_GT(fm.altitudeRest[k], 0);
  // Squash the whole body vertically by 10 %: every altitude spring pushes outwards, so the
  // total elastic energy falls when the squash is undone a little.
  std::vector<double> xs = flat(mesh);
  for (std::size_t p = 0; p < mesh.x.size(); ++p) xs[2 * p + 1] *= 0.9;
  std::vector<double> fs(xs.size(), 0.0);
  dm::addElasticForces<2>(fm, xs.data(), fs.data());
  double power = 0;  // the force's power on the motion that undoes the squash
  for (std::size_t p = 0; p < mesh.x.size(); ++p) power += fs[2 * p + 1] * xs[2 * p + 1];
  EXPECT_GT(power, 0);
}

// A crushed element (one vertex pushed through the opposite face) gets a force that moves the
// vertex back: along +normal of the face it crossed, for both models.
TEST(DeformableForces, InvertedElementIsPushedBack) {
  dm::MeshData<3> tet;
  tet.x = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, 0, 1)};
  tet.elements = {0, 1, 2, 3};
  for (auto m : {dm::Model::Corotated, dm::Model::NeoHookean}) {
    const auto fm = model<3>(m, tet);
    for (double z : {0.5, 0.01, -0.3, -1.0}) {
      std::vector<double> x = flat(tet);
      x[11] = z;  // vertex 3 at height z: inverted for z < 0
      std::vector<double> f(12, 0.0);
      dm::addElasticForces<3>(fm, x.data(), f.data());
      EXPECT_GT(f[11], 0) << "model " << int(m) << " z " << z;
      for (double q : f) EXPECT_TRUE(std::isfinite(q));
    }
  }
}

// The 3x3 rotated SVD: F = U diag(s) V^T to round-off with U, V rotations, |s| equal to the
// general SVD's singular values (descending), the sign of det F carried by the last one; also
// for repeated singular values (rest, uniform scaling), rank-deficient and zero F.
TEST(DeformableForces, RotatedSvdReconstructsAndCarriesInversion) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Eigen::Matrix3d> cases = {Eigen::Matrix3d::Identity(), 2.5 * Eigen::Matrix3d::Identity(),
                                        Eigen::Matrix3d::Zero(), Eigen::Vector3d(1, 1, -1).asDiagonal(),
                                        Eigen::Vector3d(3, 1e-9, 0).asDiagonal()};
  Eigen::Matrix3d rank1 = Eigen::Vector3d(1, 2, 3) * Eigen::RowVector3d(-1, 0.5, 2);
  cases.push_back(rank1);
  for (int k = 0; k < 200; ++k) {
    Eigen::Matrix3d F;
    for (int i = 0; i < 9; ++i) F(i) = u(rng);
    if (k % 2) F = Eigen::Matrix3d::Identity() + 1e-3 * F;  // near rest, nearly repeated values
    cases.push_back(F);
  }
  for (const Eigen::Matrix3d& F : cases) {
    Eigen::Matrix3d U, V;
    Eigen::Vector3d s;
    dm::rotatedSvd<3>(F, U, s, V);
    const double scale = std::max(1.0, F.norm());
    EXPECT_LT((U * s.asDiagonal() * V.transpose() - F).norm(), 1e-13 * scale) << F;
    EXPECT_LT((U.transpose() * U - Eigen::Matrix3d::Identity()).norm(), 1e-13);
    EXPECT_LT((V.transpose() * V - Eigen::Matrix3d::Identity()).norm(), 1e-13);
    EXPECT_NEAR(U.determinant(), 1, 1e-12);
    EXPECT_NEAR(V.determinant(), 1, 1e-12);
    const Eigen::Vector3d general = Eigen::JacobiSVD<Eigen::Matrix3d>(F).singularValues();
    EXPECT_LT((s.cwiseAbs() - general).norm(), 1e-12 * scale) << F;
    EXPECT_GE(s(0), 0);
    EXPECT_GE(s(1), 0);
    if (std::abs(F.determinant()) > 1e-12) {
      EXPECT_EQ(s(2) < 0, F.determinant() < 0) << F;
    }
  }
}

// Neo-Hookean: the stress of a stretched element matches the closed form in 1-D tension.
TEST(DeformableForces, DiagonalStressClosedForms) {
  const dm::Lame lame = dm::Lame::fromYoung(1e4, 0.3);
  const Eigen::Vector3d s(1.1, 1.0, 1.0);
  const Eigen::Vector3d Pc = dm::diagonalStress<3>(dm::Model::Corotated, lame, s, 0.3);
  EXPECT_NEAR(Pc(0), (2 * lame.mu + lame.lambda) * 0.1, 1e-9);
  const Eigen::Vector3d Pn = dm::diagonalStress<3>(dm::Model::NeoHookean, lame, s, 0.3);
  EXPECT_NEAR(Pn(0), lame.mu * 1.1 - (lame.mu - lame.lambda * std::log(1.1)) / 1.1, 1e-9);
}

// The operator the implicit solves hand to CG, P (M - h D) P with P zeroing fixed particles'
// components (Sec. 4.7.3), is symmetric and positive definite on the free subspace.
TEST(DeformableForces, ProjectedImplicitOperatorIsSymmetricPositive) {
  const auto mesh = dm::boxMesh<3>(Eigen::Vector3d(0.5, 0.2, 0.2), 0.2);
  const auto fm = model<3>(dm::Model::Corotated, mesh, 0.5, 0.05, 0);
  const auto x = deformed<3>(flat(mesh), 5, 0.03);
  const auto R = dm::dampingRotations<3>(fm, x.data());
  const std::size_t n = x.size();
  std::vector<char> fixedDof(n, 0);
  for (std::size_t p = 0; p < mesh.x.size(); ++p)
    if (mesh.x[p].x() < -0.49)
      for (int a = 0; a < 3; ++a) fixedDof[3 * p + a] = 1;
  const double h = 0.005;
  auto apply = [&](std::vector<double> u) {
    for (std::size_t i = 0; i < n; ++i)
      if (fixedDof[i]) u[i] = 0;
    std::vector<double> Du(n, 0.0), out(n);
    dm::addDampingForces<3>(fm, R, x.data(), u.data(), Du.data());
    for (std::size_t i = 0; i < n; ++i) out[i] = fixedDof[i] ? 0.0 : fm.mass[i / 3] * u[i] - h * Du[i];
    return out;
  };
  std::mt19937 rng(2);
  std::normal_distribution<double> g;
  for (int trial = 0; trial < 5; ++trial) {
    std::vector<double> u(n), w(n);
    for (auto& q : u) q = g(rng);
    for (auto& q : w) q = g(rng);
    const auto Au = apply(u), Aw = apply(w);
    double uAw = 0, wAu = 0, uAu = 0, scale = 0;
    for (std::size_t i = 0; i < n; ++i) {
      uAw += u[i] * Aw[i];
      wAu += w[i] * Au[i];
      uAu += u[i] * Au[i];
      scale += std::abs(u[i] * Aw[i]);
    }
    EXPECT_NEAR(uAw, wAu, 1e-13 * scale);
    EXPECT_GT(uAu, 0);
  }
}
