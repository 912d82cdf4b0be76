// Deformable bodies in the monolithic fluid-structure system (thesis eq. 5.30 with the damping
// rows C, Sec. 5.5.1; systems/fluid_structure_coupling.h): with a damped deformable ball in a
// viscous fluid the operator (K B^-1 K^T + P) is symmetric positive definite on random vectors
// (2-D and 3-D) and by its eigenvalues (2-D); J interpolates the particle velocities to the
// coupling faces with the barycentric weights of the element around each face centre, exact for
// affine velocity fields, and J^T spreads the face impulses with those very weights; a solve
// never adds kinetic energy and the damping takes energy.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <random>

#include "components/deformable.h"
#include "components/mac_grid.h"
#include "scenarios/scene.h"
#include "solvers/fluid/fsi_system.h"
#include "support/scenes.h"
#include "systems/fluid_structure_coupling.h"

using namespace monolith;
using namespace monolith::test;

namespace {

// A closed box with an outflow top (the pressure is pinned), viscosity `mu`, and a deformable
// ball with Rayleigh stiffness and mass damping and a few fixed particles, coupled to the fluid.
template <int d>
std::string sceneText(int n, double mu) {
  const std::string v = d == 2 ? "[0, 0]" : "[0, 0, 0]";
  const std::string hi = d == 2 ? "[1, 1]" : "[1, 1, 1]";
  const std::string cells = d == 2 ? "[" + std::to_string(n) + "," + std::to_string(n) + "]"
                                   : "[" + std::to_string(n) + "," + std::to_string(n) + "," + std::to_string(n) + "]";
  const std::string top = d == 2 ? "y_max" : "z_max";
  const std::string pos = d == 2 ? "[0.47, 0.5]" : "[0.47, 0.5, 0.5]";
  const std::string fixLo = d == 2 ? "[0, 0]" : "[0, 0, 0]", fixHi = d == 2 ? "[1, 0.3]" : "[1, 1, 0.3]";
  return R"({ "dimension": )" + std::to_string(d) + R"(, "time": { "dt": 0.01, "end": 0.01 },
    "entities": [
      { "name": "fluid", "mac_grid": { "cells": )" + cells + R"(, "domain_min": )" + v + R"(, "domain_max": )" + hi +
         R"(, "boundaries": { ")" + top + R"(": { "type": "outflow" } } },
        "fluid_material": { "density": 1.3, "viscosity": )" + std::to_string(mu) + R"( } },
      { "name": "ball", "deformable": { "mesh": { "sphere": { "radius": 0.3, "edge_length": )" +
         std::to_string(d == 2 ? 0.1 : 0.2) + R"( } },
          "model": "corotated", "youngs_modulus": 100, "poisson_ratio": 0.3, "density": 2,
          "rayleigh_alpha": 0.5, "rayleigh_beta": 0.05, "position": )" + pos + R"(,
          "fixed": [ { "min": )" + fixLo + R"(, "max": )" + fixHi + R"( } ] },
        "fluid_coupling": {} } ] })";
}

template <int d>
struct DeformableRig {
  World<d> world;
  ForceModelCache<d> cache;
  StructureCouplingSetup<d> setup;
  std::unique_ptr<solvers::FluidOperators<d>> ops;
};

template <int d>
std::unique_ptr<DeformableRig<d>> makeRig(int n, double mu, std::mt19937& rng) {
  auto rig = std::make_unique<DeformableRig<d>>();
  const Registry registry = builtins();
  populateWorld(parseScene(sceneText<d>(n, mu), "deformable_rig.json"), registry, rig->world);
  // Random particle velocities (the fixed ones at rest) and a deformed pose, so that the damping
  // rotations are not the identity.
  std::normal_distribution<double> g;
  Particles<d>& p = rig->world.template pool<Particles<d>>().components()[0];
  for (int i = 0; i < p.count(); ++i)
    for (int a = 0; a < d; ++a) {
      p.x[d * i + a] += 0.01 * g(rng);
      p.v[d * i + a] = p.fixed[i] ? 0.0 : g(rng);
    }
  const MacGrid<d>& grid = rig->world.template pool<MacGrid<d>>().components()[0];
  rig->setup = buildStructureCoupling(rig->world, grid, mu > 0, 0.01, rig->cache);
  rig->ops = std::make_unique<solvers::FluidOperators<d>>(
      solvers::buildFluidOperators(rig->setup.domain, solvers::FluidParameters{1.3, mu, 0.01}));
  auto& c = rig->setup.coupling;
  c.constrainedVelocities.clear();
  for (int f : c.constrainedFaces) c.constrainedVelocities.push_back(rig->ops->dofs.faceToVelocity[f]);
  return rig;
}

template <int d>
void expectSpd(int n, bool eigenvalues) {
  std::mt19937 rng(11);
  for (double mu : {0.4, 0.0}) {
    auto rig = makeRig<d>(n, mu, rng);
    const auto& c = rig->setup.coupling;
    ASSERT_GT(c.constraintCount(), 0);
    ASSERT_GT(c.dampingRows, 0);
    ASSERT_EQ(rig->setup.deformables.size(), 1u);
    solvers::FsiOperator<d> A(*rig->ops, c);
    std::normal_distribution<double> g;
    Eigen::VectorXd x(A.size()), y(A.size()), Ax, Ay;
    for (int trial = 0; trial < 20; ++trial) {
      for (auto& v : x) v = g(rng);
      for (auto& v : y) v = g(rng);
      A.apply(x, Ax);
      A.apply(y, Ay);
      EXPECT_NEAR(x.dot(Ay), y.dot(Ax), 1e-10 * std::abs(x.dot(Ay)) + 1e-12);
      EXPECT_GT(x.dot(Ax), 0.0);
    }
    if (!eigenvalues) continue;
    const Eigen::MatrixXd dense = solvers::assembleFsiDense(*rig->ops, c);
    EXPECT_LT((dense - dense.transpose()).cwiseAbs().maxCoeff(), 1e-10 * dense.cwiseAbs().maxCoeff());
    const Eigen::VectorXd eig = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(dense).eigenvalues();
    EXPECT_GT(eig.minCoeff(), 1e-12 * eig.maxCoeff()) << "smallest " << eig.minCoeff();
  }
}

// Barycentric coordinates of p in element e, computed here independently of SimplexLocator.
template <int d>
Eigen::VectorXd barycentric(const Particles<d>& p, const SimplexMesh<d>& mesh, int e, const Eigen::Matrix<double, d, 1>& x) {
  Eigen::MatrixXd T(d + 1, d + 1);
  for (int v = 0; v < d + 1; ++v) {
    const int i = mesh.elements[e * (d + 1) + v];
    for (int a = 0; a < d; ++a) T(a, v) = p.x[d * i + a];
    T(d, v) = 1;
  }
  Eigen::VectorXd rhs(d + 1);
  rhs.head(d) = x;
  rhs[d] = 1;
  return T.fullPivLu().solve(rhs);
}

template <int d>
void expectJIsTheBarycentricInterpolation(int n) {
  std::mt19937 rng(5);
  auto rig = makeRig<d>(n, 0.1, rng);
  const auto& setup = rig->setup;
  const auto& c = setup.coupling;
  const Particles<d>& p = rig->world.template pool<Particles<d>>().components()[0];
  const SimplexMesh<d>& mesh = rig->world.template pool<SimplexMesh<d>>().components()[0];
  const auto& layout = setup.domain.layout;
  ASSERT_EQ(c.structureCount(), d * p.count());
  // An affine velocity field v(x) = A x + b on the particles (fixed ones at rest).
  Eigen::Matrix<double, d, d> A = Eigen::Matrix<double, d, d>::Random();
  Eigen::Matrix<double, d, 1> b = Eigen::Matrix<double, d, 1>::Random();
  Eigen::VectorXd v(c.structureCount());
  for (int i = 0; i < p.count(); ++i)
    v.segment<d>(d * i) = p.fixed[i] ? Eigen::Matrix<double, d, 1>::Zero().eval()
                                     : (A * Eigen::Map<const Eigen::Matrix<double, d, 1>>(&p.x[d * i]) + b).eval();
  const Eigen::VectorXd Jv = c.J * v;
  std::normal_distribution<double> g;
  Eigen::VectorXd lambda(c.constraintCount());
  for (auto& l : lambda) l = g(rng);
  Eigen::VectorXd spread = Eigen::VectorXd::Zero(c.structureCount());
  int insideAndFree = 0;
  for (int k = 0; k < c.constraintCount(); ++k) {
    const auto [axis, fc] = layout.faceCoord(c.constrainedFaces[k]);
    const Eigen::Matrix<double, d, 1> x = layout.faceCenter(axis, fc);
    // Among the elements near the face (bounding box grown by one cell around the cell holding
    // the face centre), the one with the largest smallest coordinate, clamped and renormalised.
    Eigen::Matrix<int, d, 1> cell;
    for (int a = 0; a < d; ++a)
      cell[a] = std::clamp(static_cast<int>(std::floor((x[a] - layout.origin[a]) / layout.dx)), 0, layout.cells[a] - 1);
    int best = -1;
    Eigen::VectorXd bestL;
    for (int e = 0; e < mesh.elementCount(); ++e) {
      bool near = true;
      for (int a = 0; a < d; ++a) {
        double lo = 1e300, hi = -1e300;
        for (int w = 0; w < d + 1; ++w) {
          lo = std::min(lo, p.x[d * mesh.elements[e * (d + 1) + w] + a]);
          hi = std::max(hi, p.x[d * mesh.elements[e * (d + 1) + w] + a]);
        }
        near = near && cell[a] >= static_cast<int>(std::floor((lo - layout.origin[a]) / layout.dx)) - 1 &&
               cell[a] <= static_cast<int>(std::floor((hi - layout.origin[a]) / layout.dx)) + 1;
      }
      if (!near) continue;
      const Eigen::VectorXd l = barycentric<d>(p, mesh, e, x);
      if (best < 0 || l.minCoeff() > bestL.minCoeff()) {
        best = e;
        bestL = l;
      }
    }
    const bool inside = bestL.minCoeff() >= 0;
    bestL = bestL.cwiseMax(0.0);
    bestL /= bestL.sum();
    double expected = 0;
    bool free = true;
    for (int w = 0; w < d + 1; ++w) {
      const int i = mesh.elements[best * (d + 1) + w];
      free = free && !p.fixed[i];
      if (!p.fixed[i]) {
        expected += bestL[w] * v[d * i + axis];
        spread[d * i + axis] += bestL[w] * lambda[k];
      }
    }
    EXPECT_NEAR(Jv[k], expected, 1e-12) << "constraint " << k;
    if (inside && free) {
      ++insideAndFree;  // barycentric interpolation is exact for affine fields
      EXPECT_NEAR(Jv[k], (A * x + b)[axis], 1e-12) << "constraint " << k;
    }
  }
  EXPECT_GT(insideAndFree, 0);
  const Eigen::VectorXd JtLambda = c.J.transpose() * lambda;
  EXPECT_LT((JtLambda - spread).cwiseAbs().maxCoeff(), 1e-12);
}

}  // namespace

TEST(FsiDeformable, CoupledOperatorIsSymmetricPositiveDefinite2D) { expectSpd<2>(8, true); }
TEST(FsiDeformable, CoupledOperatorIsSymmetricPositiveDefinite3D) { expectSpd<3>(6, false); }
TEST(FsiDeformable, JTransposeIsTheBarycentricInterpolation2D) { expectJIsTheBarycentricInterpolation<2>(10); }
TEST(FsiDeformable, JTransposeIsTheBarycentricInterpolation3D) { expectJIsTheBarycentricInterpolation<3>(6); }

// Sec. 5.8: 2 KE^{n+1} - 2 KE* = -z^T (K B^-1 K^T + 2P) z <= 0, with |v_hat|^2 the damping's share.
TEST(FsiDeformable, SolveNeverAddsKineticEnergy) {
  std::mt19937 rng(3);
  for (auto kind : {solvers::FsiPreconditionerKind::None, solvers::FsiPreconditionerKind::BlockExact,
                    solvers::FsiPreconditionerKind::Schur}) {
    auto rig = makeRig<2>(10, 0.2, rng);
    const solvers::PoissonPreconditioner<2> pressure(*rig->ops, solvers::PoissonPreconditionerKind::MIC0);
    const solvers::CoupledPreconditioner<2> fluid(*rig->ops, pressure, solvers::CoupledPreconditionerKind::BlockDiagonal);
    Eigen::VectorXd u = Eigen::VectorXd::Random(rig->setup.domain.layout.totalFaces());
    solvers::CgSettings cg{4000, 1e-12, 0};
    const solvers::FsiReport r =
        solvers::fsiProjection(*rig->ops, rig->setup.coupling, u, cg, &fluid, kind, solvers::PoissonPreconditionerKind::MIC0);
    EXPECT_TRUE(r.solve.converged) << solvers::toString(kind);
    EXPECT_LT(r.kineticEnergyAfter, r.kineticEnergyBefore) << solvers::toString(kind);
    EXPECT_GT(r.dampingWork, 0.0);
    EXPECT_LE(r.kineticEnergyAfter - r.kineticEnergyBefore, -r.dampingWork * (1 - 1e-6));
  }
}

// SimplexLocator::rayEntry (walls at a deformable's surface): exact entry distances into a
// triangulated square and a tetrahedron, 0 from inside, +inf on a miss or beyond tMax.
TEST(FsiDeformable, RayEntryIntoTheMeshIsExact) {
  {
    const solvers::MacLayout<2> layout(Eigen::Vector2i(8, 8), 0.25);
    // The square [0.5, 1.5]^2 as two triangles.
    const solvers::SimplexLocator<2> square({0.5, 0.5, 1.5, 0.5, 1.5, 1.5, 0.5, 1.5}, {0, 1, 2, 0, 2, 3}, layout);
    EXPECT_NEAR(square.rayEntry(Eigen::Vector2d(1.0, 1.6), Eigen::Vector2d(0, -1), 0.25), 0.1, 1e-14);
    EXPECT_NEAR(square.rayEntry(Eigen::Vector2d(0.3, 0.7), Eigen::Vector2d(1, 0), 0.25), 0.2, 1e-14);
    EXPECT_EQ(square.rayEntry(Eigen::Vector2d(1.0, 1.0), Eigen::Vector2d(1, 0), 0.25), 0.0);
    EXPECT_TRUE(std::isinf(square.rayEntry(Eigen::Vector2d(1.0, 1.6), Eigen::Vector2d(0, -1), 0.05)));
    EXPECT_TRUE(std::isinf(square.rayEntry(Eigen::Vector2d(1.6, 1.0), Eigen::Vector2d(0, 1), 0.25)));
    const Eigen::Vector2d diagonal = Eigen::Vector2d(1, 1).normalized();  // into the corner (0.5, 0.5)
    EXPECT_NEAR(square.rayEntry(Eigen::Vector2d(0.4, 0.4), diagonal, 0.25), 0.1 * std::sqrt(2.0), 1e-14);
  }
  const solvers::MacLayout<3> layout(Eigen::Vector3i(4, 4, 4), 0.5);
  const solvers::SimplexLocator<3> tet({0.5, 0.5, 0.5, 1.5, 0.5, 0.5, 0.5, 1.5, 0.5, 0.5, 0.5, 1.5}, {0, 1, 2, 3}, layout);
  // Down onto the face x + y + z = 2.5 from above (0.6, 0.6, 1.6): it enters at z = 1.3.
  EXPECT_NEAR(tet.rayEntry(Eigen::Vector3d(0.6, 0.6, 1.6), Eigen::Vector3d(0, 0, -1), 1.0), 0.3, 1e-14);
  EXPECT_NEAR(tet.rayEntry(Eigen::Vector3d(0.6, 0.6, 0.2), Eigen::Vector3d(0, 0, 1), 1.0), 0.3, 1e-14);
}
