// Krylov solver and preconditioner tests (solvers/fluid/krylov.h, incomplete_cholesky.h,
// multigrid.h): symmetry of every preconditioner (CG needs it), IC(0) exactness on a tridiagonal
// matrix, iteration counts of plain / IC(0) / MIC(0) / multigrid PCG on the 2-D Poisson problem
// at 64^2, 128^2, 256^2 (multigrid must be nearly resolution independent), and bitwise identical
// results on 1 and 2 threads.
#include "solvers/fluid/boundary.h"
#include "solvers/fluid/coupled_preconditioner.h"
#include "solvers/fluid/krylov.h"
#include "solvers/fluid/operators.h"
#include "solvers/fluid/poisson_preconditioner.h"
#include "solvers/fluid/projection.h"
#include "solvers/fluid/spd_systems.h"

#include <gtest/gtest.h>

#include "support/random_vector.h"
#include <oneapi/tbb/task_arena.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <vector>

namespace {

using namespace monolith::solvers;
using Eigen::VectorXd;
using Kind = PoissonPreconditionerKind;

using monolith::test::randomVector;

FluidDomain<2> closedBox2(int n) {
  using S = SideSpec<2>;
  return boxDomain(MacLayout<2>(Eigen::Vector2i(n, n), 1.0 / n), BoxSpec<2>{S::wall(), S::wall(), S::wall(), S::wall()});
}

// Channel with outflow and an obstacle: Dirichlet boundary, solid cells, non-square.
FluidDomain<2> obstacleChannel2(int nx, int ny) {
  using S = SideSpec<2>;
  MacLayout<2> layout(Eigen::Vector2i(nx, ny), 1.0 / ny);
  FluidDomain<2> domain = boxDomain(layout, BoxSpec<2>{S::inflow(Eigen::Vector2d(1, 0)), S::outflow(), S::wall(), S::wall()});
  std::vector<uint8_t> solid(layout.cellCount(), 0);
  for (int j = ny / 3; j < 2 * ny / 3; ++j)
    for (int i = nx / 4; i < nx / 4 + ny / 4; ++i) solid[layout.cellIndex(Eigen::Vector2i(i, j))] = 1;
  markSolid<2>(domain, solid);
  return domain;
}

// The obstacle channel with some free faces cut: open fractions in [0.02, 1) from a fixed
// pseudo-random sequence on every third free face (the covered parts at rest).
FluidDomain<2> cutObstacleChannel2(int nx, int ny) {
  FluidDomain<2> domain = obstacleChannel2(nx, ny);
  std::vector<double> fractions(domain.layout.totalFaces(), 1.0);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> uniform(0.02, 1.0);
  for (int f = 0; f < domain.layout.totalFaces(); ++f)
    if (domain.faces[f] == FaceKind::Free && f % 3 == 0) fractions[f] = uniform(rng);
  cutFaces<2>(domain, fractions);
  return domain;
}

FluidDomain<3> closedBox3(int n) {
  using S = SideSpec<3>;
  return boxDomain(MacLayout<3>(Eigen::Vector3i(n, n, n), 1.0 / n),
                   BoxSpec<3>{S::wall(), S::wall(), S::wall(), S::wall(), S::wall(), S::wall()});
}

// Consistent Poisson right-hand side G^T u* for a random u*.
template <int d>
VectorXd poissonRhs(const FluidOperators<d>& ops, unsigned seed) {
  VectorXd b(ops.pressureCount());
  applyGradientTranspose(ops, randomVector(ops.velocityCount(), seed), b);
  return b;
}

template <int d>
CgReport solvePoisson(const FluidOperators<d>& ops, const PoissonPreconditioner<d>& pre, const VectorXd& b,
                      VectorXd& x, double tol = 1e-8) {
  PoissonOperator<d> A(ops);
  x.setZero(ops.pressureCount());
  return conjugateGradient(A.asOperator(), pre.asOperator(), closedRegionProjector(ops.dofs), b, x,
                           CgSettings{20000, tol, 0});
}

// Every preconditioner must be symmetric (x^T M y = y^T M x, 1e-12 relative: rounding of a few
// hundred operations per entry) and positive on random vectors, or PCG loses its guarantees.
template <int d>
void expectSymmetricPositive(const FluidDomain<d>& domain) {
  const FluidOperators<d> ops = buildFluidOperators(domain, FluidParameters{1.3, 0, 0.1});
  for (Kind kind : {Kind::Jacobi, Kind::IC0, Kind::MIC0, Kind::Multigrid}) {
    const PoissonPreconditioner<d> pre(ops, kind);
    for (unsigned seed = 0; seed < 3; ++seed) {
      const VectorXd x = randomVector(ops.pressureCount(), 100 + seed), y = randomVector(ops.pressureCount(), 200 + seed);
      VectorXd Mx(x.size()), My(y.size());
      pre.apply(x, Mx);
      pre.apply(y, My);
      const double scale = x.cwiseAbs().dot(My.cwiseAbs()) + y.cwiseAbs().dot(Mx.cwiseAbs());
      EXPECT_LE(std::abs(x.dot(My) - y.dot(Mx)), 1e-12 * scale) << toString(kind);
      EXPECT_GT(x.dot(Mx), 0.0) << toString(kind);
    }
  }
}

TEST(FluidKrylov, PreconditionersAreSymmetricPositive) {
  expectSymmetricPositive(closedBox2(32));
  expectSymmetricPositive(obstacleChannel2(48, 32));
  expectSymmetricPositive(obstacleChannel2(45, 21));  // odd counts: coarse cells with one child
  expectSymmetricPositive(closedBox3(16));
  expectSymmetricPositive(cutObstacleChannel2(45, 21));  // weighted faces on every level
}

// With cut faces the Poisson block weights each free face by its open fraction; the multigrid's
// level 0 must carry the same weights (multigrid.h). A hierarchy of one level solves that level
// exactly (dense pseudo-inverse), so MG-PCG then converges at once, which it cannot if level 0
// differs from the block (with unit weights: 21 iterations here, and 19 against 10 on the deep one). On a deep hierarchy the
// weighted coarse levels keep the count near the uncut channel's.
TEST(FluidKrylov, MultigridMatchesTheCutFacePoissonBlock) {
  {
    const FluidOperators<2> ops = buildFluidOperators(cutObstacleChannel2(30, 14), FluidParameters{});
    ASSERT_TRUE(ops.cut);
    const PoissonPreconditioner<2> exact(ops, Kind::Multigrid, MultigridSettings{2, 100000});
    ASSERT_EQ(exact.multigrid()->levelCount(), 1);
    VectorXd x;
    const CgReport r = solvePoisson(ops, exact, poissonRhs(ops, 8), x, 1e-10);
    EXPECT_TRUE(r.converged);
    EXPECT_LE(r.iterations, 2);
  }
  {
    const FluidOperators<2> cut = buildFluidOperators(cutObstacleChannel2(220, 41), FluidParameters{});
    const FluidOperators<2> plain = buildFluidOperators(obstacleChannel2(220, 41), FluidParameters{});
    const PoissonPreconditioner<2> mgCut(cut, Kind::Multigrid), mgPlain(plain, Kind::Multigrid);
    VectorXd x;
    const CgReport rc = solvePoisson(cut, mgCut, poissonRhs(cut, 9), x);
    const CgReport rp = solvePoisson(plain, mgPlain, poissonRhs(plain, 9), x);
    std::printf("obstacle channel 220x41: MG-PCG %d iterations cut, %d uncut\n", rc.iterations, rp.iterations);
    EXPECT_TRUE(rc.converged);
    EXPECT_LE(rc.iterations, rp.iterations + 6);
  }
}

// ---- the coupled solve's preconditioner (coupled_preconditioner.h) ---------------------------
// Viscous parameters with dt nu / h^2 well above one on these grids (1.5 at 45 x 21, 6 at
// 120 x 40), where the cut faces couple the pressure and viscous unknowns strongly (the DFG 2D-2
// scene has 0.32 at 880 x 164 and dt = 0.002).
constexpr FluidParameters kViscousCut{1.3, 0.05, 0.1};

// x^T M y = y^T M x and x^T M x > 0 for both kinds on cut domains, a closed one included: on a
// 3 x 3 closed box with every free face cut the whole pure-Neumann region lies inside the band, so
// its cells must leave the band (else the band's block is singular).
TEST(CoupledPreconditioner, IsSymmetricPositive) {
  using S = SideSpec<2>;
  FluidDomain<2> tiny = boxDomain(MacLayout<2>(Eigen::Vector2i(3, 3), 1.0 / 3), BoxSpec<2>{S::wall(), S::wall(), S::wall(), S::wall()});
  std::vector<double> fractions(tiny.layout.totalFaces(), 1.0);
  for (int f = 0; f < tiny.layout.totalFaces(); ++f)
    if (tiny.faces[f] == FaceKind::Free) fractions[f] = 0.3 + 0.05 * (f % 7);
  cutFaces<2>(tiny, fractions);
  for (const FluidDomain<2>& domain : {cutObstacleChannel2(45, 21), tiny}) {
    const FluidOperators<2> ops = buildFluidOperators(domain, kViscousCut);
    ASSERT_TRUE(ops.cut);
    const PoissonPreconditioner<2> mg(ops, Kind::Multigrid);
    for (auto kind : {CoupledPreconditionerKind::BlockDiagonal, CoupledPreconditionerKind::CutCorrected}) {
      const CoupledPreconditioner<2> pre(ops, mg, kind);
      const int n = ops.pressureCount() + ops.viscousCount();
      if (kind == CoupledPreconditionerKind::CutCorrected) {
        EXPECT_GT(pre.bandSize(), 0);
      }
      for (unsigned seed = 0; seed < 3; ++seed) {
        const VectorXd x = randomVector(n, 300 + seed), y = randomVector(n, 400 + seed);
        VectorXd Mx(n), My(n);
        pre.apply(x, Mx);
        pre.apply(y, My);
        const double scale = x.cwiseAbs().dot(My.cwiseAbs()) + y.cwiseAbs().dot(Mx.cwiseAbs());
        EXPECT_LE(std::abs(x.dot(My) - y.dot(Mx)), 1e-12 * scale) << toString(kind);
        EXPECT_GT(x.dot(Mx), 0.0) << toString(kind);
      }
    }
  }
  // The band's rows, built from the face stencils, are the rows of the assembled (5.31).
  {
    const FluidOperators<2> ops = buildFluidOperators(cutObstacleChannel2(45, 21), kViscousCut);
    const PoissonPreconditioner<2> mg(ops, Kind::Multigrid);
    const CoupledPreconditioner<2> pre(ops, mg, CoupledPreconditionerKind::CutCorrected);
    const SparseMatrixR assembled = assembleCoupled(ops);
    ASSERT_EQ(pre.bandRows().rows(), pre.bandSize());
    for (int k = 0; k < pre.bandSize(); ++k) {
      const Eigen::SparseVector<double> difference = pre.bandRows().row(k) - assembled.row(pre.band()[k]);
      EXPECT_LE(difference.cwiseAbs().sum(), 1e-12 * assembled.row(pre.band()[k]).cwiseAbs().sum()) << "band row " << k;
    }
  }
  // The closed box's cells all border a cut face, yet none may be in the band: only viscous rows.
  const FluidOperators<2> ops = buildFluidOperators(tiny, kViscousCut);
  const PoissonPreconditioner<2> mg(ops, Kind::Multigrid);
  const CoupledPreconditioner<2> pre(ops, mg, CoupledPreconditionerKind::CutCorrected);
  EXPECT_EQ(pre.bandSize(), ops.viscousCount());
}

// The band correction takes the coupled CG's iterations on a cut channel well below the
// block-diagonal's (measured: see the printout) and gives the same velocities to the solver
// tolerance; without cut faces the band is empty and the result is bitwise the block-diagonal's.
TEST(CoupledPreconditioner, CutCorrectionCutsIterationsWithTheSameAnswer) {
  auto solve = [](const FluidOperators<2>& ops, CoupledPreconditionerKind kind, VectorXd& faces) {
    faces = randomVector(ops.domain.layout.totalFaces(), 12);
    ProjectionSettings s;
    s.preconditioner = Kind::Multigrid;
    s.coupledPreconditioner = kind;
    s.solve = CgSettings{5000, 1e-10, 0};
    const ProjectionReport r = coupledProjection(ops, faces, s);
    EXPECT_TRUE(r.solve.converged);
    return r.solve.iterations;
  };
  {
    const FluidOperators<2> ops = buildFluidOperators(cutObstacleChannel2(120, 40), kViscousCut);
    VectorXd block, corrected;
    const int nBlock = solve(ops, CoupledPreconditionerKind::BlockDiagonal, block);
    const int nCorrected = solve(ops, CoupledPreconditionerKind::CutCorrected, corrected);
    std::printf("cut channel 120x40, dt nu/h^2 = %.2f: coupled CG %d iterations block-diagonal, %d cut-corrected\n",
                kViscousCut.dt * kViscousCut.viscosity / kViscousCut.density * 40 * 40, nBlock, nCorrected);
    EXPECT_LE(2 * nCorrected, nBlock);
    EXPECT_LE((block - corrected).cwiseAbs().maxCoeff(), 1e-7 * block.cwiseAbs().maxCoeff());
  }
  {
    const FluidOperators<2> ops = buildFluidOperators(obstacleChannel2(60, 20), kViscousCut);
    ASSERT_FALSE(ops.cut);
    const PoissonPreconditioner<2> mg(ops, Kind::Multigrid);
    EXPECT_EQ(CoupledPreconditioner<2>(ops, mg, CoupledPreconditionerKind::CutCorrected).bandSize(), 0);
    VectorXd block, corrected;
    EXPECT_EQ(solve(ops, CoupledPreconditionerKind::BlockDiagonal, block),
              solve(ops, CoupledPreconditionerKind::CutCorrected, corrected));
    EXPECT_EQ(0, std::memcmp(block.data(), corrected.data(), sizeof(double) * block.size()));
  }
}

// A 1-D tube (walls at x = 0, outflow at x = L) has a tridiagonal, nonsingular Poisson matrix:
// IC(0) drops no fill there, so it is the exact Cholesky factor and PCG converges in 1 iteration.
TEST(FluidKrylov, IncompleteCholeskyIsExactOnATridiagonalMatrix) {
  using S = SideSpec<2>;
  const FluidDomain<2> tube =
      boxDomain(MacLayout<2>(Eigen::Vector2i(50, 1), 0.1), BoxSpec<2>{S::wall(), S::outflow(), S::wall(), S::wall()});
  const FluidOperators<2> ops = buildFluidOperators(tube, FluidParameters{});
  const PoissonPreconditioner<2> ic(ops, Kind::IC0);
  VectorXd x;
  const CgReport report = solvePoisson(ops, ic, poissonRhs(ops, 1), x, 1e-12);
  EXPECT_TRUE(report.converged);
  EXPECT_EQ(report.iterations, 1);
}

TEST(FluidKrylov, AbsoluteMaxNormStopping) {
  const FluidOperators<2> ops = buildFluidOperators(closedBox2(32), FluidParameters{});
  PoissonOperator<2> A(ops);
  const VectorXd b = poissonRhs(ops, 2);
  VectorXd x;
  const CgReport r = conjugateGradient(A.asOperator(), {}, closedRegionProjector(ops.dofs), b, x,
                                       CgSettings{10000, 0.0, 1e-6 * b.cwiseAbs().maxCoeff()});
  EXPECT_TRUE(r.converged);
  EXPECT_LE(r.residualMaxNorm, 1e-6 * b.cwiseAbs().maxCoeff());
  EXPECT_GT(r.residualMaxNorm, 1e-9 * b.cwiseAbs().maxCoeff());  // it stopped early, not at 0
}

// Iteration counts on the pure-Neumann 2-D Poisson problem (closed box, relative tolerance 1e-8).
// Recorded in the test output; asserted: each preconditioner beats plain CG, MIC(0) beats IC(0),
// and multigrid grows by < 1.5x from 64^2 to 256^2 (plain CG and IC(0) grow ~4x, MIC(0) ~2x).
TEST(FluidKrylov, PreconditionedIterationCounts2D) {
  std::printf("| grid | none | ic0 | mic0 | mg |\n|---|---|---|---|---|\n");
  int mg64 = 0, mg256 = 0;
  for (int n : {64, 128, 256}) {
    const FluidOperators<2> ops = buildFluidOperators(closedBox2(n), FluidParameters{1.0, 0, 0.01});
    const VectorXd b = poissonRhs(ops, 3);
    int its[4] = {0, 0, 0, 0};
    int k = 0;
    for (Kind kind : {Kind::None, Kind::IC0, Kind::MIC0, Kind::Multigrid}) {
      const PoissonPreconditioner<2> pre(ops, kind);
      VectorXd x;
      const CgReport r = solvePoisson(ops, pre, b, x);
      EXPECT_TRUE(r.converged) << toString(kind) << " " << n;
      EXPECT_LE(r.relativeResidual(), 2e-8) << toString(kind) << " " << n;  // true residual ~ recursive
      its[k++] = r.iterations;
    }
    std::printf("| %d^2 | %d | %d | %d | %d |\n", n, its[0], its[1], its[2], its[3]);
    EXPECT_LT(its[1], its[0]);
    EXPECT_LT(its[2], its[1]);
    EXPECT_LT(its[3], its[0]);
    EXPECT_LT(its[3], its[2]);
    if (n == 64) mg64 = its[3];
    if (n == 256) mg256 = its[3];
  }
  EXPECT_LT(mg256, 1.5 * mg64);
}

// Multigrid stays effective with Dirichlet (outflow) sides, an obstacle, odd coarse sizes and 3-D.
TEST(FluidKrylov, MultigridOnOtherDomains) {
  {
    const FluidOperators<2> ops = buildFluidOperators(obstacleChannel2(192, 64), FluidParameters{});
    const PoissonPreconditioner<2> mg(ops, Kind::Multigrid);
    VectorXd x;
    const CgReport r = solvePoisson(ops, mg, poissonRhs(ops, 4), x);
    std::printf("obstacle channel 192x64: MG-PCG %d iterations, %d levels\n", r.iterations, mg.multigrid()->levelCount());
    EXPECT_TRUE(r.converged);
    EXPECT_LT(r.iterations, 30);
  }
  {
    // The DFG channel's 220 x 41 cells: 41 is odd. Coarsening (n + 1) / 2 keeps the V-cycle deep;
    // without it the hierarchy had a single level (20 Gauss-Seidel pairs per application).
    const FluidOperators<2> ops = buildFluidOperators(obstacleChannel2(220, 41), FluidParameters{});
    const PoissonPreconditioner<2> mg(ops, Kind::Multigrid);
    VectorXd x;
    const CgReport r = solvePoisson(ops, mg, poissonRhs(ops, 6), x);
    std::printf("obstacle channel 220x41: MG-PCG %d iterations, %d levels\n", r.iterations, mg.multigrid()->levelCount());
    EXPECT_TRUE(r.converged);
    EXPECT_GE(mg.multigrid()->levelCount(), 4);
    EXPECT_LT(r.iterations, 30);
  }
  {
    const FluidOperators<3> ops = buildFluidOperators(closedBox3(32), FluidParameters{});
    const PoissonPreconditioner<3> mg(ops, Kind::Multigrid);
    VectorXd x;
    const CgReport r = solvePoisson(ops, mg, poissonRhs(ops, 5), x);
    std::printf("closed box 32^3: MG-PCG %d iterations, %d levels\n", r.iterations, mg.multigrid()->levelCount());
    EXPECT_TRUE(r.converged);
    EXPECT_LT(r.iterations, 30);
  }
}

// ---- determinism ---------------------------------------------------------------------------
// The same solve in a 1-thread and a 2-thread arena must give bitwise identical results (fixed
// reduction chunks, row-owned writes). 128^2 has 16384 unknowns, well above the chunk sizes, so the
// 2-thread run really splits the work.
bool bitwiseEqual(const VectorXd& a, const VectorXd& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), sizeof(double) * a.size()) == 0;
}

TEST(FluidKrylov, BitwiseIdenticalOnOneAndTwoThreads) {
  const FluidOperators<2> ops = buildFluidOperators(closedBox2(128), FluidParameters{1.0, 0.01, 0.01});
  const VectorXd b = poissonRhs(ops, 6);
  const VectorXd uStar = randomVector(ops.domain.layout.totalFaces(), 7);
  for (Kind kind : {Kind::None, Kind::MIC0, Kind::Multigrid}) {
    const PoissonPreconditioner<2> pre(ops, kind);
    VectorXd x[2], u[2];
    int its[2];
    for (int t = 0; t < 2; ++t) {
      tbb::task_arena arena(t + 1);
      arena.execute([&] {
        its[t] = solvePoisson(ops, pre, b, x[t]).iterations;
        u[t] = uStar;
        ProjectionSettings s;
        s.solve = CgSettings{2000, 1e-10, 0};
        coupledProjection(ops, u[t], s, &pre);
      });
    }
    EXPECT_EQ(its[0], its[1]) << toString(kind);
    EXPECT_TRUE(bitwiseEqual(x[0], x[1])) << toString(kind);
    EXPECT_TRUE(bitwiseEqual(u[0], u[1])) << toString(kind);
  }
  // The coupled solve with the cut-face band correction (its band solves are sequential).
  const FluidOperators<2> cut = buildFluidOperators(cutObstacleChannel2(160, 60), kViscousCut);
  const PoissonPreconditioner<2> mg(cut, Kind::Multigrid);
  const CoupledPreconditioner<2> corrected(cut, mg, CoupledPreconditionerKind::CutCorrected);
  ASSERT_GT(corrected.bandSize(), 0);
  VectorXd u[2];
  for (int t = 0; t < 2; ++t) {
    tbb::task_arena arena(t + 1);
    arena.execute([&] {
      u[t] = randomVector(cut.domain.layout.totalFaces(), 13);
      ProjectionSettings s;
      s.solve = CgSettings{2000, 1e-10, 0};
      coupledProjection(cut, u[t], s, &mg, &corrected);
    });
  }
  EXPECT_TRUE(bitwiseEqual(u[0], u[1]));
}

}  // namespace
