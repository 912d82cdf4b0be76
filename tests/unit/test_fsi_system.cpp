// The monolithic fluid-structure system (thesis eq. 5.30, Sec. 5.8; solvers/fluid/fsi_system.h):
// symmetric positive definite on random vectors in 2-D and 3-D, the B-orthogonal (mass-symmetric)
// projection onto the constraints when there is no viscosity, J = N J_hat R equal to the rigid
// velocity at the face centres and J^T equal to the force and torque of the face impulses, and a
// solve that never adds kinetic energy.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include <random>

#include "components/mac_grid.h"
#include "solvers/fluid/fsi_system.h"
#include "solvers/fluid/structure_coupling.h"

using namespace monolith;
using namespace monolith::solvers;

namespace {

template <int d>
using Vec = Eigen::Matrix<double, d, 1>;

// A rigid disk/ball of radius `radius` at `centre` in a box with no-slip walls and an outflow top
// (so the pressure is pinned and the system is definite), coupled through one rigid body.
template <int d>
struct Rig {
  FluidDomain<d> domain;
  std::unique_ptr<FluidOperators<d>> ops;
  StructureCoupling coupling;
  Vec<d> centre;
  std::vector<Vec<d>> faceCentres;  // per constraint
  std::vector<int> faceAxes;
};

template <int d>
Rig<d> makeRig(int n, double mu, double mass, bool outflowTop = true, double wallTheta = 0) {
  Rig<d> rig;
  typename MacLayout<d>::Index cells = MacLayout<d>::Index::Constant(n);
  const double dx = 1.0 / n;
  MacLayout<d> layout(cells, dx);
  BoxSpec<d> box;
  for (auto& s : box) s = SideSpec<d>::wall(true);
  if (outflowTop) box[2 * (d - 1) + 1] = SideSpec<d>::outflow();
  rig.domain = boxDomain(layout, box);
  rig.centre = Vec<d>::Constant(0.5);
  rig.centre[0] = 0.47;  // off-centre: torques do not cancel
  const double radius = 0.26;
  std::vector<std::uint8_t> mask(layout.cellCount(), 0);
  for (int c = 0; c < layout.cellCount(); ++c)
    mask[c] = (layout.cellCenter(layout.cellCoord(c)) - rig.centre).norm() < radius;
  const std::vector<int> faces = markStructure(rig.domain, mask, mu > 0);
  // Walls theta cells from every free face ("obstacle_wall": "surface" for the structure's faces).
  if (wallTheta > 0) rig.domain.wallDistance.assign(static_cast<std::size_t>(layout.totalFaces()) * 2 * d, wallTheta);
  rig.ops = std::make_unique<FluidOperators<d>>(buildFluidOperators(rig.domain, FluidParameters{1.3, mu, 0.05}));
  const int ndof = rigidDofs(d);
  std::vector<Eigen::Triplet<double>> r, jhat;
  for (std::size_t k = 0; k < faces.size(); ++k) {
    const auto [axis, fc] = layout.faceCoord(faces[k]);
    rig.faceCentres.push_back(layout.faceCenter(axis, fc));
    rig.faceAxes.push_back(axis);
    rigidSampleRows<d>(static_cast<int>(k), 0, Vec<d>(rig.faceCentres.back() - rig.centre), r);
    for (int a = 0; a < d; ++a) jhat.emplace_back(int(k) * d + a, int(k) * d + a, 1.0);
  }
  const int nc = static_cast<int>(faces.size());
  SparseMatrixR R(nc * d, ndof), Jhat(nc * d, nc * d);
  R.setFromTriplets(r.begin(), r.end());
  Jhat.setFromTriplets(jhat.begin(), jhat.end());
  auto& c = rig.coupling;
  c.constrainedFaces = faces;
  for (int f : faces) c.constrainedVelocities.push_back(rig.ops->dofs.faceToVelocity[f]);
  c.J = faceNormalRows(layout, faces) * Jhat * R;
  // Mass and an anisotropic, non-diagonal world inertia (3-D).
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(ndof, ndof);
  for (int a = 0; a < d; ++a) M(a, a) = mass;
  if constexpr (d == 2) {
    M(2, 2) = 0.3 * mass;
  } else {
    M.block<3, 3>(3, 3) << 0.3, 0.05, 0.0, 0.05, 0.4, 0.02, 0.0, 0.02, 0.5;
    M.block<3, 3>(3, 3) *= mass;
  }
  c.mass = M.sparseView();
  c.massInverse = Eigen::MatrixXd(M.inverse()).sparseView();
  c.velocity = Eigen::VectorXd::Zero(ndof);
  return rig;
}

template <int d>
void expectSymmetricPositiveDefinite(double mu, double wallTheta = 0) {
  Rig<d> rig = makeRig<d>(d == 2 ? 10 : 5, mu, 0.7, true, wallTheta);
  ASSERT_GT(rig.coupling.constraintCount(), 0);
  FsiOperator<d> A(*rig.ops, rig.coupling);
  std::mt19937 rng(7);
  std::normal_distribution<double> g;
  auto random = [&] {
    Eigen::VectorXd x(A.size());
    for (auto& v : x) v = g(rng);
    return x;
  };
  Eigen::VectorXd Ax, Ay;
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::VectorXd x = random(), y = random();
    A.apply(x, Ax);
    A.apply(y, Ay);
    EXPECT_NEAR(x.dot(Ay), y.dot(Ax), 1e-10 * std::abs(x.dot(Ay)) + 1e-12);
    EXPECT_GT(x.dot(Ax), 0.0);
  }
  // And every eigenvalue of the assembled matrix is positive.
  const Eigen::MatrixXd dense = assembleFsiDense(*rig.ops, rig.coupling);
  EXPECT_LT((dense - dense.transpose()).cwiseAbs().maxCoeff(), 1e-10 * dense.cwiseAbs().maxCoeff());
  const Eigen::VectorXd eig = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(dense).eigenvalues();
  EXPECT_GT(eig.minCoeff(), 1e-12 * eig.maxCoeff()) << "smallest " << eig.minCoeff() << " largest " << eig.maxCoeff();
}

}  // namespace

TEST(FsiSystem, SymmetricPositiveDefinite2D) {
  expectSymmetricPositiveDefinite<2>(0.4);
  expectSymmetricPositiveDefinite<2>(0.0);
}
TEST(FsiSystem, SymmetricPositiveDefinite3D) {
  expectSymmetricPositiveDefinite<3>(0.4);
  expectSymmetricPositiveDefinite<3>(0.0);
}

// Walls at the surface: a viscous row from a fluid face to a structure face measures the shear
// against a wall theta cells away, weight w / sqrt(theta); theta = 1 gives the thesis's rows exactly.
// The operator stays symmetric positive definite.
template <int d>
void expectStructureWallRows() {
  const int n = d == 2 ? 10 : 5;
  const Rig<d> plain = makeRig<d>(n, 0.4, 0.7), one = makeRig<d>(n, 0.4, 0.7, true, 1.0),
               quarter = makeRig<d>(n, 0.4, 0.7, true, 0.25);
  ASSERT_EQ(plain.ops->viscousRows.size(), one.ops->viscousRows.size());
  ASSERT_EQ(plain.ops->viscousRows.size(), quarter.ops->viscousRows.size());
  const auto& structure = plain.domain.structureFace;
  const double w = plain.ops->viscousWeight;
  int scaled = 0;
  for (std::size_t r = 0; r < plain.ops->viscousRows.size(); ++r) {
    const auto &a = plain.ops->viscousRows[r], &b = one.ops->viscousRows[r], &q = quarter.ops->viscousRows[r];
    EXPECT_EQ(a.c0, b.c0);
    EXPECT_EQ(a.c1, b.c1);
    if (a.u0 < 0 || a.u1 < 0) continue;
    const bool s0 = structure[plain.ops->dofs.velocityToFace[a.u0]], s1 = structure[plain.ops->dofs.velocityToFace[a.u1]];
    if (s0 == s1) {
      EXPECT_EQ(q.c1, a.c1);
      continue;
    }
    EXPECT_DOUBLE_EQ(q.c1, 2 * w);
    EXPECT_DOUBLE_EQ(q.c0, -2 * w);
    ++scaled;
  }
  EXPECT_GT(scaled, 8);
  expectSymmetricPositiveDefinite<d>(0.4, 0.25);
}

TEST(FsiSystem, StructureWallsAtTheSurfaceScaleTheirRowsAndStaySpd2D) { expectStructureWallRows<2>(); }
TEST(FsiSystem, StructureWallsAtTheSurfaceScaleTheirRowsAndStaySpd3D) { expectStructureWallRows<3>(); }

// J v is the rigid velocity n . (v + w x r) at each face centre (what a one-way obstacle's face
// gets, components/mac_grid.h ObstacleMotion::velocityAt), and J^T lambda is the force and torque
// about the centre of mass of impulses lambda_k n_k applied at the face centres: the same
// interpolation both ways, exactly up to rounding.
template <int d>
void expectJIsTheRigidInterpolation() {
  Rig<d> rig = makeRig<d>(d == 2 ? 12 : 6, 0.1, 1.0);
  const int ndof = rigidDofs(d), nc = rig.coupling.constraintCount();
  std::mt19937 rng(3);
  std::normal_distribution<double> g;
  Eigen::VectorXd v(ndof), lambda(nc);
  for (auto& x : v) x = g(rng);
  for (auto& x : lambda) x = g(rng);
  ObstacleMotion<d> motion;
  motion.centre = rig.centre;
  motion.velocity = v.head(d);
  if constexpr (d == 2) motion.angularVelocity.z() = v[2];
  else motion.angularVelocity = v.tail(3);
  const Eigen::VectorXd Jv = rig.coupling.J * v;
  Eigen::VectorXd impulse = Eigen::VectorXd::Zero(ndof);
  for (int k = 0; k < nc; ++k) {
    const int a = rig.faceAxes[k];
    EXPECT_NEAR(Jv[k], motion.velocityAt(rig.faceCentres[k])[a], 1e-14 * (1 + std::abs(Jv[k])));
    Eigen::Vector3d n = Eigen::Vector3d::Zero(), r = Eigen::Vector3d::Zero();
    n[a] = lambda[k];
    r.head<d>() = rig.faceCentres[k] - rig.centre;
    impulse.head(d) += n.head<d>();
    const Eigen::Vector3d torque = r.cross(n);
    if constexpr (d == 2) impulse[2] += torque.z();
    else impulse.tail(3) += torque;
  }
  const Eigen::VectorXd JTlambda = rig.coupling.J.transpose() * lambda;
  EXPECT_LT((JTlambda - impulse).cwiseAbs().maxCoeff(), 1e-12 * (1 + impulse.cwiseAbs().maxCoeff()));
  // The adjoint identity: lambda . (J v) = (J^T lambda) . v.
  EXPECT_NEAR(lambda.dot(Jv), JTlambda.dot(v), 1e-12 * (1 + std::abs(lambda.dot(Jv))));
}

TEST(FsiSystem, JTransposeIsTheRigidBodyInterpolation2D) { expectJIsTheRigidInterpolation<2>(); }
TEST(FsiSystem, JTransposeIsTheRigidBodyInterpolation3D) { expectJIsTheRigidInterpolation<3>(); }

// Without viscosity, (K B^-1 K^T) z = K w and w' = w - B^-1 K^T z is the B-orthogonal projection
// of w onto the constraints K w' = 0 (divergence free, fluid = structure at the coupling faces):
// w' satisfies them, projecting w' again changes nothing, and w - w' is B-orthogonal to w'.
template <int d>
void expectMassSymmetricProjection() {
  Rig<d> rig = makeRig<d>(d == 2 ? 12 : 6, 0.0, 0.9);
  const auto& ops = *rig.ops;
  const int nu = ops.velocityCount(), ns = rig.coupling.structureCount();
  std::mt19937 rng(11);
  std::normal_distribution<double> g;
  Eigen::VectorXd faces = Eigen::VectorXd::Zero(ops.domain.layout.totalFaces());
  for (int v = 0; v < nu; ++v) faces[ops.dofs.velocityToFace[v]] = g(rng);
  for (auto& x : rig.coupling.velocity) x = g(rng);
  const Eigen::VectorXd u0 = freeVelocities(ops, faces), v0 = rig.coupling.velocity;
  CgSettings cg{2000, 1e-13, 0};
  const FsiReport first = fsiProjection<d>(ops, rig.coupling, faces, cg, nullptr, FsiPreconditionerKind::None);
  ASSERT_TRUE(first.solve.converged);
  const Eigen::VectorXd u1 = freeVelocities(ops, faces), v1 = rig.coupling.velocity;
  // Constraints: divergence free and W u = W J v.
  EXPECT_LT(constraintDivergence(ops, faces).cwiseAbs().maxCoeff(), 1e-9);
  const Eigen::VectorXd Jv = rig.coupling.J * v1;
  for (int k = 0; k < rig.coupling.constraintCount(); ++k)
    EXPECT_NEAR(u1[rig.coupling.constrainedVelocities[k]], Jv[k], 1e-9);
  // B-orthogonality: (w - w')^T B w' = 0.
  const Eigen::VectorXd du = u0 - u1, dv = v0 - v1;
  const double cross = du.dot(u1.cwiseQuotient(ops.faceBetaInv)) + dv.dot(rig.coupling.mass * v1);
  const double scale = u1.dot(u1.cwiseQuotient(ops.faceBetaInv)) + v1.dot(rig.coupling.mass * v1);
  EXPECT_LT(std::abs(cross), 1e-9 * scale);
  // Idempotent.
  fsiProjection<d>(ops, rig.coupling, faces, cg, nullptr, FsiPreconditionerKind::None);
  EXPECT_LT((freeVelocities(ops, faces) - u1).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((rig.coupling.velocity - v1).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_EQ(ns, rigidDofs(d));
}

TEST(FsiSystem, NoViscosityGivesTheMassSymmetricProjection2D) { expectMassSymmetricProjection<2>(); }
TEST(FsiSystem, NoViscosityGivesTheMassSymmetricProjection3D) { expectMassSymmetricProjection<3>(); }

// Sec. 5.8: with walls at rest, 2 KE' - 2 KE* = -z^T (K B^-1 K^T + 2P) z <= 0, for any masses, with
// every preconditioner (which changes the iterates, not the answer).
TEST(FsiSystem, SolveNeverAddsKineticEnergy) {
  for (double mass : {1e-9, 1.0, 1e9})
    for (auto kind : {FsiPreconditionerKind::None, FsiPreconditionerKind::BlockJacobi, FsiPreconditionerKind::BlockExact,
                      FsiPreconditionerKind::Schur}) {
      Rig<2> rig = makeRig<2>(16, 0.3, mass);
      const auto& ops = *rig.ops;
      std::mt19937 rng(5);
      std::normal_distribution<double> g;
      Eigen::VectorXd faces = Eigen::VectorXd::Zero(ops.domain.layout.totalFaces());
      for (int v = 0; v < ops.velocityCount(); ++v) faces[ops.dofs.velocityToFace[v]] = g(rng);
      for (auto& x : rig.coupling.velocity) x = g(rng);
      PoissonPreconditioner<2> pressure(ops, PoissonPreconditionerKind::MIC0);
      CoupledPreconditioner<2> fluid(ops, pressure, CoupledPreconditionerKind::BlockDiagonal);
      const FsiReport r = fsiProjection(ops, rig.coupling, faces, CgSettings{5000, 1e-10, 0}, &fluid, kind);
      EXPECT_TRUE(r.solve.converged) << "mass " << mass << " " << toString(kind);
      EXPECT_LE(r.kineticEnergyAfter, r.kineticEnergyBefore * (1 + 1e-12)) << "mass " << mass << " " << toString(kind);
      if (mass <= 1) {
        EXPECT_LT(r.kineticEnergyAfter, 0.99 * r.kineticEnergyBefore);  // random fluid data: much is removed
      }
    }
}

// Preconditioning changes the iterations, not the solution.
TEST(FsiSystem, PreconditionersAgreeOnTheSolution) {
  Eigen::VectorXd reference;
  for (auto kind : {FsiPreconditionerKind::None, FsiPreconditionerKind::BlockJacobi, FsiPreconditionerKind::BlockExact,
                    FsiPreconditionerKind::Schur}) {
    Rig<2> rig = makeRig<2>(16, 0.3, 2.0);
    const auto& ops = *rig.ops;
    Eigen::VectorXd faces = Eigen::VectorXd::Zero(ops.domain.layout.totalFaces());
    for (int v = 0; v < ops.velocityCount(); ++v) faces[ops.dofs.velocityToFace[v]] = std::sin(0.37 * v);
    rig.coupling.velocity << 0.3, -1.0, 0.7;
    PoissonPreconditioner<2> pressure(ops, PoissonPreconditionerKind::MIC0);
    CoupledPreconditioner<2> fluid(ops, pressure, CoupledPreconditionerKind::BlockDiagonal);
    fsiProjection(ops, rig.coupling, faces, CgSettings{5000, 1e-12, 0}, &fluid, kind);
    if (reference.size() == 0) reference = rig.coupling.velocity;
    EXPECT_LT((rig.coupling.velocity - reference).cwiseAbs().maxCoeff(), 1e-8) << toString(kind);
  }
}

// CG needs a symmetric positive definite preconditioner: the Schur variant's block factorisation
// is one (x^T P y = y^T P x, x^T P x > 0), in 2-D and 3-D.
template <int d>
void expectSchurPreconditionerSpd() {
  Rig<d> rig = makeRig<d>(d == 2 ? 12 : 6, 0.2, 0.8);
  FsiOperator<d> A(*rig.ops, rig.coupling);
  FsiPreconditioner<d> P(A, *rig.ops, rig.coupling, nullptr, FsiPreconditionerKind::Schur, PoissonPreconditionerKind::MIC0);
  std::mt19937 rng(17);
  std::normal_distribution<double> g;
  Eigen::VectorXd x(A.size()), y(A.size()), Px, Py;
  for (int trial = 0; trial < 10; ++trial) {
    for (auto& v : x) v = g(rng);
    for (auto& v : y) v = g(rng);
    P.apply(x, Px);
    P.apply(y, Py);
    EXPECT_NEAR(x.dot(Py), y.dot(Px), 1e-10 * (std::abs(x.dot(Py)) + 1));
    EXPECT_GT(x.dot(Px), 0.0);
  }
}
TEST(FsiSystem, SchurPreconditionerIsSymmetricPositiveDefinite2D) { expectSchurPreconditionerSpd<2>(); }
TEST(FsiSystem, SchurPreconditionerIsSymmetricPositiveDefinite3D) { expectSchurPreconditionerSpd<3>(); }
