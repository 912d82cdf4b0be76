// Operator tests for the volume-weighted MAC operators of thesis Ch. 5 (solvers/fluid/): G = -D^T,
// matrix-free applies equal to the assembled matrices, the affine boundary terms, the viscous
// factor G_mu (scaling, mirrored no-slip ghosts), and symmetry / positivity of the (5.31) matrix.
#include "solvers/fluid/boundary.h"
#include "solvers/fluid/operators.h"
#include "solvers/fluid/spd_systems.h"

#include <gtest/gtest.h>

#include "support/random_vector.h"

#include <cmath>
#include <random>
#include <vector>

namespace {

using namespace monolith::solvers;
using Eigen::MatrixXd;
using Eigen::VectorXd;

using monolith::test::randomVector;

// 2-D: x has a moving no-slip lid below and an outflow above, y is periodic; a moving obstacle and
// one Dirichlet (air) cell make every face kind and every boundary rule appear.
FluidDomain<2> mixedDomain2() {
  using S = SideSpec<2>;
  MacLayout<2> layout(Eigen::Vector2i(12, 10), 0.1, Eigen::Vector2d(0.3, -0.2), {false, true});
  BoxSpec<2> sides{S::wall(true, Eigen::Vector2d(0, 0.7)), S::outflow(), S::periodic(), S::periodic()};
  FluidDomain<2> domain = boxDomain(layout, sides);
  std::vector<uint8_t> solid(layout.cellCount(), 0), air(layout.cellCount(), 0);
  for (int j = 3; j < 6; ++j)
    for (int i = 4; i < 7; ++i) solid[layout.cellIndex(Eigen::Vector2i(i, j))] = 1;
  markSolid<2>(domain, solid, [](const Eigen::Vector2d& x) { return Eigen::Vector2d(0.2 - x[1], 0.5 + x[0]); });
  air[layout.cellIndex(Eigen::Vector2i(10, 8))] = 1;
  markDirichlet(domain, air);
  return domain;
}

// 3-D: inflow / outflow along x, y periodic, z: no-slip moving wall below, slip wall above.
FluidDomain<3> mixedDomain3() {
  using S = SideSpec<3>;
  MacLayout<3> layout(Eigen::Vector3i(7, 6, 5), 0.25, Eigen::Vector3d::Zero(), {false, true, false});
  BoxSpec<3> sides{S::inflow([](const Eigen::Vector3d& x) { return Eigen::Vector3d(1 + x[2], 0.1, 0.2 * x[1]); }),
                   S::outflow(),
                   S::periodic(),
                   S::periodic(),
                   S::wall(true, Eigen::Vector3d(0.3, -0.4, 0)),
                   S::wall(false)};
  FluidDomain<3> domain = boxDomain(layout, sides);
  std::vector<uint8_t> solid(layout.cellCount(), 0);
  for (int k = 1; k < 3; ++k)
    for (int j = 2; j < 4; ++j)
      for (int i = 2; i < 4; ++i) solid[layout.cellIndex(Eigen::Vector3i(i, j, k))] = 1;
  markSolid<3>(domain, solid, [](const Eigen::Vector3d&) { return Eigen::Vector3d(0.5, -0.25, 0.125); });
  return domain;
}

// D restricted to free faces, built here from the layout independently of operators.cpp:
// (D u)_c = A (sum over axes of u(upper face) - u(lower face)).
template <int d>
MatrixXd independentDivergence(const FluidOperators<d>& ops) {
  const auto& layout = ops.domain.layout;
  MatrixXd D = MatrixXd::Zero(ops.pressureCount(), ops.velocityCount());
  for (int cell = 0; cell < layout.cellCount(); ++cell) {
    const int p = ops.dofs.cellToPressure[cell];
    if (p < 0) continue;
    const auto c = layout.cellCoord(cell);
    for (int a = 0; a < d; ++a)
      for (int side = 0; side < 2; ++side) {
        auto f = c;
        f[a] += side;
        const int v = ops.dofs.faceToVelocity[layout.faceIndex(a, f)];
        if (v >= 0) D(p, v) += side == 1 ? layout.faceArea() : -layout.faceArea();
      }
  }
  return D;
}

template <int d>
void expectGradientIsMinusDivergenceTransposed(const FluidDomain<d>& domain) {
  const FluidOperators<d> ops = buildFluidOperators(domain, FluidParameters{1.3, 0.2, 0.05});
  ASSERT_GT(ops.pressureCount(), 0);
  ASSERT_GT(ops.velocityCount(), 0);
  const MatrixXd G = MatrixXd(ops.G);
  const MatrixXd D = independentDivergence(ops);
  // Entries are exactly +-A or 0 on both sides: compare exactly.
  for (int v = 0; v < ops.velocityCount(); ++v)
    for (int p = 0; p < ops.pressureCount(); ++p) ASSERT_EQ(G(v, p), -D(p, v)) << "face " << v << " cell " << p;
}

TEST(FluidOperators, GradientIsMinusDivergenceTransposed2D) { expectGradientIsMinusDivergenceTransposed(mixedDomain2()); }
TEST(FluidOperators, GradientIsMinusDivergenceTransposed3D) { expectGradientIsMinusDivergenceTransposed(mixedDomain3()); }

TEST(FluidOperators, FaceClassification2D) {
  const FluidDomain<2> domain = mixedDomain2();
  const auto& L = domain.layout;
  // Lid (x lower): boundary x-faces prescribed with the wall's normal velocity (0).
  EXPECT_EQ(domain.faces[L.faceIndex(0, Eigen::Vector2i(0, 4))], FaceKind::Prescribed);
  EXPECT_EQ(domain.faceVelocity[L.faceIndex(0, Eigen::Vector2i(0, 4))], 0.0);
  // Outflow (x upper): boundary faces free.
  EXPECT_EQ(domain.faces[L.faceIndex(0, Eigen::Vector2i(12, 4))], FaceKind::Free);
  // Periodic y: 10 face layers, the one at j = 0 is an interior face.
  EXPECT_EQ(L.faceLayers(1), 10);
  EXPECT_EQ(domain.faces[L.faceIndex(1, Eigen::Vector2i(2, 0))], FaceKind::Free);
  // Obstacle face: prescribed with the obstacle velocity at the face centre (x-face at i = 4, j = 3).
  const int face = L.faceIndex(0, Eigen::Vector2i(4, 3));
  const Eigen::Vector2d x = L.faceCenter(0, Eigen::Vector2i(4, 3));
  EXPECT_EQ(domain.faces[face], FaceKind::Prescribed);
  EXPECT_DOUBLE_EQ(domain.faceVelocity[face], 0.2 - x[1]);
  // Faces between the Dirichlet cell and fluid are free.
  EXPECT_EQ(domain.faces[L.faceIndex(0, Eigen::Vector2i(10, 8))], FaceKind::Free);
  // The air cell is not a pressure unknown.
  const auto dofs = numberFluidDofs(domain);
  EXPECT_EQ(dofs.cellToPressure[L.cellIndex(Eigen::Vector2i(10, 8))], -1);
  EXPECT_EQ(dofs.closedComponentCount, 0);  // pinned by the outflow and the air cell
}

TEST(FluidOperators, ClosedRegionsAreDetected) {
  using S = SideSpec<2>;
  MacLayout<2> layout(Eigen::Vector2i(8, 6), 1.0);
  FluidDomain<2> box = boxDomain(layout, BoxSpec<2>{S::wall(), S::wall(), S::wall(), S::wall()});
  EXPECT_EQ(numberFluidDofs(box).closedComponentCount, 1);
  // A solid column splits the box into two closed regions.
  std::vector<uint8_t> solid(layout.cellCount(), 0);
  for (int j = 0; j < 6; ++j) solid[layout.cellIndex(Eigen::Vector2i(3, j))] = 1;
  markSolid<2>(box, solid);
  const FluidDofs dofs = numberFluidDofs(box);
  EXPECT_EQ(dofs.closedComponentCount, 2);
  EXPECT_NE(dofs.closedComponent[dofs.cellToPressure[layout.cellIndex(Eigen::Vector2i(0, 0))]],
            dofs.closedComponent[dofs.cellToPressure[layout.cellIndex(Eigen::Vector2i(7, 5))]]);
}

TEST(FluidOperators, BoxDomainRejectsInconsistentPeriodicity) {
  using S = SideSpec<2>;
  MacLayout<2> layout(Eigen::Vector2i(4, 4), 1.0);
  EXPECT_THROW(boxDomain(layout, BoxSpec<2>{S::periodic(), S::periodic(), S::wall(), S::wall()}), std::invalid_argument);
}

// The matrix-free applies agree with the assembled matrices (different summation order only:
// 1e-14 relative to the magnitude of the terms).
template <int d>
void expectApplyMatchesAssembly(const FluidDomain<d>& domain) {
  const FluidOperators<d> ops = buildFluidOperators(domain, FluidParameters{0.9, 0.3, 0.1});
  ASSERT_GT(ops.viscousCount(), 0);
  const VectorXd p = randomVector(ops.pressureCount(), 1), u = randomVector(ops.velocityCount(), 2),
                 r = randomVector(ops.viscousCount(), 3);
  VectorXd out(ops.velocityCount());
  applyGradient(ops, p, out);
  EXPECT_LE((out - ops.G * p).cwiseAbs().maxCoeff(), 1e-14 * ops.area);
  VectorXd outP(ops.pressureCount());
  applyGradientTranspose(ops, u, outP);
  EXPECT_LE((outP - ops.G.transpose() * u).cwiseAbs().maxCoeff(), 1e-14 * ops.area);
  VectorXd outR(ops.viscousCount());
  applyViscousGradient(ops, u, outR);
  EXPECT_LE((outR - ops.Gmu * u).cwiseAbs().maxCoeff(), 1e-14 * ops.viscousWeight);
  applyViscousGradientTranspose(ops, r, out);
  EXPECT_LE((out - ops.Gmu.transpose() * r).cwiseAbs().maxCoeff(), 1e-14 * ops.viscousWeight);

  // Poisson and coupled operators against their assembled forms.
  const SparseMatrixR P = assemblePoisson(ops);
  PoissonOperator<d> poisson(ops);
  poisson.apply(p, outP);
  const double scale = ops.area * ops.area * ops.betaInv;
  EXPECT_LE((outP - P * p).cwiseAbs().maxCoeff(), 1e-13 * scale);
  EXPECT_LE((poisson.diagonal() - VectorXd(P.diagonal())).cwiseAbs().maxCoeff(), 1e-13 * scale);
  const SparseMatrixR A = assembleCoupled(ops);
  CoupledOperator<d> coupled(ops);
  const VectorXd z = randomVector(coupled.size(), 4);
  VectorXd Az(coupled.size());
  coupled.apply(z, Az);
  // A cut face's viscous terms carry beta^-1 / theta.
  const double scaleA = std::max(scale, 1.0 + ops.betaInv * ops.viscousWeight * ops.viscousWeight / ops.openFraction.minCoeff());
  EXPECT_LE((Az - A * z).cwiseAbs().maxCoeff(), 1e-13 * scaleA);
  EXPECT_LE((coupled.viscousDiagonal() - VectorXd(A.diagonal().tail(ops.viscousCount()))).cwiseAbs().maxCoeff(), 1e-13 * scaleA);
}

TEST(FluidOperators, ApplyMatchesAssembly2D) { expectApplyMatchesAssembly(mixedDomain2()); }
TEST(FluidOperators, ApplyMatchesAssembly3D) { expectApplyMatchesAssembly(mixedDomain3()); }

// The affine terms: for any full face field, the divergence over all faces (prescribed included)
// equals -G^T u_free + g on every pressure unknown (rounding only).
template <int d>
void expectPrescribedDivergence(const FluidDomain<d>& domain) {
  const FluidOperators<d> ops = buildFluidOperators(domain, FluidParameters{});
  VectorXd faces = randomVector(domain.layout.totalFaces(), 5);
  writeVelocities(ops, freeVelocities(ops, faces), faces);  // prescribed faces take their values
  const VectorXd div = volumeDivergence(domain.layout, faces);
  VectorXd GTu(ops.pressureCount());
  applyGradientTranspose(ops, freeVelocities(ops, faces), GTu);
  for (int p = 0; p < ops.pressureCount(); ++p)
    EXPECT_NEAR(div[ops.dofs.pressureToCell[p]], -GTu[p] + ops.prescribedDivergence[p], 1e-14 * 2 * d * ops.area * 3);
}

TEST(FluidOperators, PrescribedFacesMoveToTheRightHandSide2D) { expectPrescribedDivergence(mixedDomain2()); }
TEST(FluidOperators, PrescribedFacesMoveToTheRightHandSide3D) { expectPrescribedDivergence(mixedDomain3()); }

// (5.31) is symmetric and positive: x^T A y = y^T A x to 1e-12 relative, x^T A x > 0, for random
// vectors (2-D and 3-D; the 2-D case has no closed region so A is definite; the closed 3-D box is
// only semidefinite on (1, 0), which random vectors do not hit).
template <int d>
void expectCoupledSymmetricPositive(const FluidDomain<d>& domain) {
  const FluidOperators<d> ops = buildFluidOperators(domain, FluidParameters{1.1, 0.05, 0.02});
  CoupledOperator<d> A(ops);
  for (unsigned seed = 0; seed < 5; ++seed) {
    const VectorXd x = randomVector(A.size(), 10 + seed), y = randomVector(A.size(), 20 + seed);
    VectorXd Ax(A.size()), Ay(A.size());
    A.apply(x, Ax);
    A.apply(y, Ay);
    const double xAy = x.dot(Ay), yAx = y.dot(Ax);
    const double scale = x.cwiseAbs().dot(Ay.cwiseAbs()) + y.cwiseAbs().dot(Ax.cwiseAbs());
    EXPECT_LE(std::abs(xAy - yAx), 1e-12 * scale);
    EXPECT_GT(x.dot(Ax), 0.0);
    EXPECT_GT(y.dot(Ay), 0.0);
  }
}

TEST(FluidOperators, CoupledMatrixSymmetricPositive2D) { expectCoupledSymmetricPositive(mixedDomain2()); }
TEST(FluidOperators, CoupledMatrixSymmetricPositive3D) { expectCoupledSymmetricPositive(mixedDomain3()); }
TEST(FluidOperators, CoupledMatrixSymmetricPositiveClosedBox3D) {
  using S = SideSpec<3>;
  MacLayout<3> layout(Eigen::Vector3i(5, 4, 6), 0.2);
  expectCoupledSymmetricPositive(boxDomain(layout, BoxSpec<3>{S::wall(), S::wall(), S::wall(false), S::wall(),
                                                                S::wall(true, Eigen::Vector3d(1, 0, 0)), S::wall()}));
}

// Channel periodic in x between no-slip walls at y = 0 (at rest) and y = H (moving with U):
// the viscous force of a velocity field, -(G_mu^T (G_mu u + h)), per unit beta.
VectorXd viscousAcceleration(const FluidOperators<2>& ops, const VectorXd& faces) {
  VectorXd rows(ops.viscousCount()), out(ops.velocityCount());
  applyViscousGradient(ops, freeVelocities(ops, faces), rows);
  rows += ops.viscousKnown;
  applyViscousGradientTranspose(ops, rows, out);
  return -ops.betaInv * out;
}

TEST(FluidOperators, ViscousFactorReproducesLaplacianAndNoSlipGhosts) {
  using S = SideSpec<2>;
  const int n = 8;
  const double h = 1.0 / n, U = 1.7, mu = 0.3, rho = 2.0, dt = 0.01;
  MacLayout<2> layout(Eigen::Vector2i(n, n), h, Eigen::Vector2d::Zero(), {true, false});
  const FluidDomain<2> domain =
      boxDomain(layout, BoxSpec<2>{S::periodic(), S::periodic(), S::wall(), S::wall(true, Eigen::Vector2d(U, 0))});
  const FluidOperators<2> ops = buildFluidOperators(domain, FluidParameters{rho, mu, dt});
  // Couette flow u = U y / H is an exact discrete steady state: the mirrored ghost is exact for
  // linear profiles, so the viscous force vanishes to rounding (1e-12 of the single-row scale).
  VectorXd faces = VectorXd::Zero(layout.totalFaces());
  for (int f = 0; f < layout.totalFaces(); ++f) {
    auto [axis, c] = layout.faceCoord(f);
    if (axis == 0) faces[f] = U * layout.faceCenter(axis, c)[1];
  }
  const double rowScale = ops.betaInv * ops.viscousWeight * ops.viscousWeight * U;
  EXPECT_LE(viscousAcceleration(ops, faces).cwiseAbs().maxCoeff(), 1e-12 * rowScale);
  // u = y^2: beta^-1 (-G_mu^T G_mu u) = dt nu u'' = 2 dt nu away from the walls (the 3-point stencil
  // is exact for quadratics), which checks the scaling w = sqrt(dt mu / V) A.
  for (int f = 0; f < layout.totalFaces(); ++f) {
    auto [axis, c] = layout.faceCoord(f);
    faces[f] = axis == 0 ? std::pow(layout.faceCenter(axis, c)[1], 2) : 0.0;
  }
  const VectorXd acc = viscousAcceleration(ops, faces);
  for (int v = 0; v < ops.velocityCount(); ++v) {
    auto [axis, c] = layout.faceCoord(ops.dofs.velocityToFace[v]);
    if (axis == 0 && c[1] > 0 && c[1] < n - 1) {
      EXPECT_NEAR(acc[v], 2 * dt * mu / rho, 1e-12);
    }
  }
  // At the moving lid, the face next to it sees the mirrored ghost 2U - u: for u = y^2 the force on
  // that face is w^2 beta^-1 (u_below - u) + 2 w^2 beta^-1 (U - u).
  const double k = ops.betaInv * ops.viscousWeight * ops.viscousWeight;
  const double yTop = (n - 0.5) * h, yBelow = (n - 1.5) * h;
  for (int v = 0; v < ops.velocityCount(); ++v) {
    auto [axis, c] = layout.faceCoord(ops.dofs.velocityToFace[v]);
    if (axis == 0 && c[1] == n - 1) {
      EXPECT_NEAR(acc[v], k * (yBelow * yBelow - yTop * yTop) + 2 * k * (U - yTop * yTop), 1e-12);
    }
  }
}

TEST(FluidOperators, SlipWallsAndOutflowDropShearRows) {
  using S = SideSpec<2>;
  MacLayout<2> layout(Eigen::Vector2i(4, 3), 0.5);
  // Slip walls on three sides, outflow on the fourth: no tangential Dirichlet side at all.
  const FluidDomain<2> slip = boxDomain(layout, BoxSpec<2>{S::wall(false), S::outflow(), S::wall(false), S::wall(false)});
  const FluidOperators<2> ops = buildFluidOperators(slip, FluidParameters{1, 1, 1});
  for (int r = 0; r < ops.viscousCount(); ++r) {
    const ViscousRow& row = ops.viscousRows[r];
    EXPECT_TRUE(row.u0 >= 0 || row.u1 >= 0);
    EXPECT_NE(std::abs(row.c0) + std::abs(row.c1), 0.0);
    // No sqrt(2) rows: there is no Dirichlet tangential side.
    EXPECT_NEAR(std::max(std::abs(row.c0), std::abs(row.c1)), ops.viscousWeight, 1e-15);
  }
  // Rows: x-faces (5 layers x 3) have pairs along y: 2 interior per column -> 5 columns, of which
  // the wall column is prescribed on both ends (dropped): 4 x 2 = 8; along x: layers 0..4, pairs
  // (0,1) (1,2) (2,3) (3,4) per row = 4 x 3 = 12 (beyond the outflow face: dropped).
  // y-faces (4 x 4 layers, boundary layers prescribed): along y: pairs (0,1),(1,2),(2,3) = 3 per
  // column x 4 = 12; along x: 3 interior pairs per layer x 2 free layers = 6, plus the pairs at
  // the x walls/outflow: the lower wall is slip (dropped) and the outflow drops shear: 0.
  EXPECT_EQ(ops.viscousCount(), 8 + 12 + 12 + 6);
}

}  // namespace

// --- cut faces (cutFaces, operators.h): area theta A in G and D, mass theta rho V in beta ---

// The mixed domains with some free faces cut: fractions from a fixed pseudo-random sequence in
// [0.05, 1), one face covered whole (fraction 0 -> prescribed); the covered parts move with the
// field `covered`.
template <int d>
FluidDomain<d> withCutFaces(FluidDomain<d> domain, std::vector<double>& fractions) {
  const int n = domain.layout.totalFaces();
  fractions.assign(n, 1.0);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uniform(0.05, 1.0);
  int cut = 0;
  for (int f = 0; f < n; ++f) {
    if (domain.faces[f] != FaceKind::Free || f % 3 != 0) continue;
    fractions[f] = cut == 5 ? 0.0 : uniform(rng);
    ++cut;
  }
  cutFaces<d>(domain, fractions, [](const Eigen::Matrix<double, d, 1>& x) {
    Eigen::Matrix<double, d, 1> v = Eigen::Matrix<double, d, 1>::Constant(0.3);
    v[0] += x[d - 1];
    return v;
  });
  return domain;
}

template <int d>
void expectCutOperatorsConsistent(const FluidDomain<d>& plain) {
  std::vector<double> fractions;
  const FluidDomain<d> domain = withCutFaces(plain, fractions);
  const FluidOperators<d> ops = buildFluidOperators(domain, FluidParameters{0.9, 0.3, 0.1});
  ASSERT_TRUE(ops.cut);
  const double minTheta = ops.openFraction.minCoeff();
  ASSERT_GE(minTheta, 0.05);

  // The covered face became prescribed with the field's velocity.
  int covered = 0;
  for (int f = 0; f < domain.layout.totalFaces(); ++f) covered += fractions[f] == 0 && domain.faces[f] == FaceKind::Prescribed;
  EXPECT_EQ(covered, 1);

  // D u = sum over the cell's faces of +-A (theta u + (1 - theta) U), written out here.
  VectorXd faces = randomVector(domain.layout.totalFaces(), 5);
  writeVelocities(ops, freeVelocities(ops, faces), faces);
  const VectorXd div = constraintDivergence(ops, faces);
  for (int p = 0; p < ops.pressureCount(); ++p) {
    const auto c = domain.layout.cellCoord(ops.dofs.pressureToCell[p]);
    double expected = 0;
    for (int a = 0; a < d; ++a)
      for (int side = 0; side < 2; ++side) {
        auto f = c;
        f[a] += side;
        const int g = domain.layout.faceIndex(a, f);
        const double theta = domain.faces[g] == FaceKind::Free ? domain.openFraction[g] : 0.0;
        const double value = domain.faces[g] == FaceKind::Free ? theta * faces[g] + (1 - theta) * domain.faceVelocity[g]
                                                               : domain.faceVelocity[g];
        expected += (side == 1 ? 1 : -1) * ops.area * value;
      }
    EXPECT_NEAR(div[p], expected, 1e-13 * 2 * d * ops.area * 3);
  }

  // Matrix-free applies equal the assembled operators; the velocity update beta^-1 G p is the
  // plain pressure difference on cut faces too.
  expectApplyMatchesAssembly(domain);
  const VectorXd p = randomVector(ops.pressureCount(), 1);
  VectorXd grad(ops.velocityCount());
  applyGradient(ops, p, grad);
  const VectorXd update = faceBetaInverse(ops).cwiseProduct(grad);
  for (int v = 0; v < ops.velocityCount(); ++v) {
    const auto& cells = ops.gradientCells[v];
    const double dp = (cells[1] >= 0 ? p[cells[1]] : 0.0) - (cells[0] >= 0 ? p[cells[0]] : 0.0);
    EXPECT_NEAR(update[v], ops.betaInv * ops.area * dp, 1e-13 * ops.betaInv * ops.area);
  }

  // Both systems stay symmetric positive: (5.31) and the Chorin viscosity system Theta + b G_mu^T G_mu.
  expectCoupledSymmetricPositive(domain);
  ViscousOperator<d> viscous(ops);
  for (unsigned seed = 0; seed < 3; ++seed) {
    const VectorXd a = randomVector(ops.velocityCount(), 30 + seed), b = randomVector(ops.velocityCount(), 40 + seed);
    VectorXd Va(ops.velocityCount()), Vb(ops.velocityCount());
    viscous.apply(a, Va);
    viscous.apply(b, Vb);
    EXPECT_LE(std::abs(a.dot(Vb) - b.dot(Va)), 1e-12 * (a.cwiseAbs().dot(Vb.cwiseAbs()) + b.cwiseAbs().dot(Va.cwiseAbs())));
    EXPECT_GT(a.dot(Va), 0.0);
  }
}

TEST(FluidOperators, CutFacesKeepTheOperatorsConsistentAndSpd2D) { expectCutOperatorsConsistent(mixedDomain2()); }
TEST(FluidOperators, CutFacesKeepTheOperatorsConsistentAndSpd3D) { expectCutOperatorsConsistent(mixedDomain3()); }

TEST(FluidOperators, CutFacesRejectBadFractions) {
  FluidDomain<2> domain = mixedDomain2();
  std::vector<double> fractions(domain.layout.totalFaces(), 1.0);
  fractions[3] = 1.5;
  EXPECT_THROW(cutFaces<2>(domain, fractions), std::invalid_argument);
  fractions[3] = std::nan("");
  EXPECT_THROW(cutFaces<2>(domain, fractions), std::invalid_argument);
  fractions.pop_back();
  EXPECT_THROW(cutFaces<2>(domain, fractions), std::invalid_argument);
}
