// Tests for the advection of MAC face velocities (solvers/advection): semi-Lagrangian (thesis
// Sec. 5.2), ENO3 + TVD-RK3 (thesis Sec. 6.3 eq. 6.3), WENO5 + TVD-RK3, velocity sampling near walls and
// structures, the CFL step and thread-count independence. No pressure projection anywhere: every
// reference solution is an exact solution of the pure transport / Burgers-type equation.
#include "solvers/advection/cfl.h"
#include "solvers/advection/eno.h"
#include "solvers/advection/semi_lagrangian.h"
#include "solvers/advection/velocity_sampling.h"
#include "solvers/advection/wall_ghosts.h"
#include "solvers/fluid/boundary.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

namespace {

using namespace monolith::solvers;

constexpr double kPi = 3.14159265358979323846;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

template <int d>
using Vec = typename MacLayout<d>::Vec;
template <int d>
using Index = typename MacLayout<d>::Index;

template <int d>
MacLayout<d> periodicBox(int n, double length) {
  std::array<bool, d> periodic;
  periodic.fill(true);
  return MacLayout<d>(Index<d>::Constant(n), length / n, Vec<d>::Zero(), periodic);
}

// Face field from fn(axis, face centre).
template <int d>
Eigen::VectorXd faceField(const MacLayout<d>& layout, const std::function<double(int, const Vec<d>&)>& fn) {
  Eigen::VectorXd u(layout.totalFaces());
  for (int g = 0; g < layout.totalFaces(); ++g) {
    const auto [axis, f] = layout.faceCoord(g);
    u[g] = fn(axis, layout.faceCenter(axis, f));
  }
  return u;
}

template <int d>
Eigen::VectorXd cellField(const MacLayout<d>& layout, const std::function<double(const Vec<d>&)>& fn) {
  Eigen::VectorXd phi(layout.cellCount());
  for (int c = 0; c < layout.cellCount(); ++c) phi[c] = fn(layout.cellCenter(layout.cellCoord(c)));
  return phi;
}

double order(double coarse, double fine) { return std::log2(coarse / fine); }

// Max error over the faces of one axis (-1: all faces).
template <int d>
double maxError(const MacLayout<d>& layout, const Eigen::VectorXd& a, const Eigen::VectorXd& b, int axis = -1) {
  double e = 0;
  for (int g = 0; g < layout.totalFaces(); ++g)
    if (axis < 0 || layout.faceCoord(g).first == axis) e = std::max(e, std::abs(a[g] - b[g]));
  return e;
}

// Runs `steps` steps of `advance` to time T with dt = T / steps, steps = ceil(T / (cfl dx / speed)).
template <class Advance>
Eigen::VectorXd evolve(Eigen::VectorXd y, double T, double dx, double speed, double cfl, Advance advance) {
  const int steps = static_cast<int>(std::ceil(T / (cfl * dx / speed) - 1e-9));
  const double dt = T / steps;
  for (int s = 0; s < steps; ++s) y = advance(y, dt);
  return y;
}

void printTable(const char* title, const std::vector<int>& n, const std::vector<double>& err) {
  std::printf("%s\n", title);
  for (std::size_t i = 0; i < n.size(); ++i) {
    if (i == 0) std::printf("  n=%4d  err=%.3e\n", n[i], err[i]);
    else std::printf("  n=%4d  err=%.3e  order=%.2f\n", n[i], err[i], order(err[i - 1], err[i]));
  }
}

// ---------------------------------------------------------------------------------------------
// ENO3 kernel.

TEST(HjDerivatives, Eno3AndWeno5ExactForCubicsBothSides) {
  const double h = 0.37;
  auto p = [](double x) { return 1.5 - 2 * x + 0.75 * x * x - 0.4 * x * x * x; };
  auto dp = [](double x) { return -2 + 1.5 * x - 1.2 * x * x; };
  const double x0 = 0.81;
  std::array<double, 7> v;
  for (int k = 0; k < 7; ++k) v[k] = p(x0 + (k - 3) * h);
  // Every ENO3 candidate stencil interpolates a cubic exactly: only rounding remains. WENO5
  // combines the same candidates convexly, so it is exact too.
  EXPECT_NEAR(eno3Derivative(v, h, true), dp(x0), 1e-12);
  EXPECT_NEAR(eno3Derivative(v, h, false), dp(x0), 1e-12);
  EXPECT_NEAR(weno5Derivative(v, h, true), dp(x0), 1e-12);
  EXPECT_NEAR(weno5Derivative(v, h, false), dp(x0), 1e-12);
}

TEST(Eno3Derivative, AvoidsAJump) {
  // Step between nodes 3 and 4: the backward ENO stencil must choose nodes left of the jump and
  // return exactly 0; the forward one necessarily crosses it (first-order difference 1/h).
  const std::array<double, 7> v{0, 0, 0, 0, 1, 1, 1};
  EXPECT_EQ(eno3Derivative(v, 0.5, true), 0.0);
  EXPECT_NE(eno3Derivative(v, 0.5, false), 0.0);
}

// ---------------------------------------------------------------------------------------------
// WENO5 kernel (the "weno5" advection option).

TEST(Weno5Derivative, FifthOrderOnSmoothDataWhereEnoIsThird) {
  // f = exp(sin x) at x0 = 0.4 (no critical point of f' there, where the classic weights are
  // known to lose order). Halving h must divide the WENO5 error by ~2^5 and the ENO3 one by ~2^3.
  auto f = [](double x) { return std::exp(std::sin(x)); };
  const double x0 = 0.4, exact = std::cos(x0) * f(x0);
  for (bool backward : {true, false}) {
    std::vector<double> weno, eno;
    for (double h : {0.1, 0.05, 0.025, 0.0125}) {
      std::array<double, 7> v;
      for (int k = 0; k < 7; ++k) v[k] = f(x0 + (k - 3) * h);
      weno.push_back(std::abs(weno5Derivative(v, h, backward) - exact));
      eno.push_back(std::abs(eno3Derivative(v, h, backward) - exact));
    }
    for (std::size_t i = 1; i < weno.size(); ++i) {
      std::printf("WENO5 %s h/%d: err %.3e order %.2f (ENO3 %.3e order %.2f)\n", backward ? "D-" : "D+", 1 << i, weno[i],
                  order(weno[i - 1], weno[i]), eno[i], order(eno[i - 1], eno[i]));
      EXPECT_GT(order(weno[i - 1], weno[i]), 4.5);
      EXPECT_LT(weno[i], 0.05 * eno[i]);
    }
  }
}

TEST(Weno5Derivative, StaysOnTheSmoothSideOfAJump) {
  // Step between nodes 3 and 4: the weights of the stencils crossing it vanish like
  // (eps / indicator)^2 ~ 1e-12, so D^- is 0 up to that weight times 1/h.
  const double h = 0.5;
  const std::array<double, 7> v{0, 0, 0, 0, 1, 1, 1};
  EXPECT_NEAR(weno5Derivative(v, h, true), 0.0, 1e-9 / h);
  EXPECT_GT(std::abs(weno5Derivative(v, h, false)), 0.1 / h);
  // Units do not matter: eps scales with the data, so scaling v scales the result exactly.
  std::array<double, 7> w;
  const std::array<double, 7> smooth{0.1, 0.3, 0.2, 0.6, 0.5, 0.9, 1.4};
  for (int k = 0; k < 7; ++k) w[k] = 1e6 * smooth[k];
  EXPECT_NEAR(weno5Derivative(w, h, true), 1e6 * weno5Derivative(smooth, h, true), 1e-9 * 1e6);
}

// ---------------------------------------------------------------------------------------------
// Sampling.

TEST(VelocitySampling, ReproducesLinearFieldsAndWraps) {
  // Non-periodic box: multilinear interpolation reproduces a linear field anywhere inside the
  // region covered by the component's face grid.
  MacLayout<3> box(Index<3>(5, 6, 7), 0.2, Vec<3>(-0.3, 0.1, 0.4));
  auto lin = [](int a, const Vec<3>& x) { return 0.5 + a + 1.3 * x[0] - 0.7 * x[1] + 0.2 * a * x[2]; };
  const Eigen::VectorXd u = faceField<3>(box, lin);
  const FaceVelocitySampler<3> s(box, u);
  const Vec<3> x(0.35, 0.62, 1.05);  // at least half a cell away from every wall
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(s.component(a, x), lin(a, x), 1e-12);
  // Periodic axes: shifting by the domain length gives the same sample.
  MacLayout<2> per = periodicBox<2>(8, 1.0);
  const Eigen::VectorXd w = faceField<2>(per, [](int a, const Vec<2>& x) { return std::sin(2 * kPi * (x[0] + a * x[1])); });
  const FaceVelocitySampler<2> sp(per, w);
  const Vec<2> y(0.137, 0.911);
  for (int a = 0; a < 2; ++a) {
    EXPECT_NEAR(sp.component(a, y + Vec<2>(3.0, -2.0)), sp.component(a, y), 1e-12);
  }
}

TEST(VelocitySampling, RejectsUnprescribedFacesNextToSolids) {
  MacLayout<2> layout(Index<2>(4, 4), 0.25);
  std::vector<std::uint8_t> solid(16, 0);
  solid[layout.cellIndex(Index<2>(1, 1))] = 1;
  FaceBoundary b;
  b.solidCell = solid;
  EXPECT_THROW(validateBoundary(layout, b), std::invalid_argument);
  EXPECT_NO_THROW(validateBoundary(layout, staticObstacleBoundary(layout, solid)));
  const Eigen::VectorXd u = Eigen::VectorXd::Zero(layout.totalFaces() + 1);
  EXPECT_THROW(FaceVelocitySampler<2>(layout, u), std::invalid_argument);
}

// A periodic-x channel with walls in y and a solid block; interior faces of the block carry a
// huge "structure" velocity that no fluid sample may ever see.
struct BlockScene {
  MacLayout<2> layout{Index<2>(32, 24), 1.0 / 32, Vec<2>::Zero(), {true, false}};
  FaceBoundary boundary;
  Eigen::VectorXd u;
  static constexpr double kInside = 1e6;
  static constexpr double kVmax = 0.3;

  BlockScene() {
    std::vector<std::uint8_t> solid(layout.cellCount(), 0);
    for (int j = 8; j < 16; ++j)
      for (int i = 12; i < 20; ++i) solid[layout.cellIndex(Index<2>(i, j))] = 1;
    boundary = staticObstacleBoundary(layout, solid);  // coupling + wall faces: 0
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(layout.totalFaces());
    const FaceVelocitySampler<2> probe(layout, zero, boundary);
    u = faceField<2>(layout, [](int a, const Vec<2>& x) { return a == 0 ? 1.0 : kVmax * std::sin(2 * kPi * x[0]); });
    for (int g = 0; g < layout.totalFaces(); ++g) {
      if (!boundary.prescribedFace[g]) continue;
      u[g] = kNaN;  // the field is never read on prescribed faces
      const auto [axis, f] = layout.faceCoord(g);
      if (probe.faceInsideSolid(axis, f)) boundary.prescribedVelocity[g] = kInside;
    }
  }
};

TEST(VelocitySampling, NeverSamplesInsideTheSolid) {
  BlockScene scene;
  const FaceVelocitySampler<2> s(scene.layout, scene.u, scene.boundary);
  const double h = scene.layout.dx;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> ux(0.0, 1.0), uy(0.0, 0.75);
  int fluidPoints = 0;
  for (int k = 0; k < 20000; ++k) {
    const Vec<2> x(ux(rng), uy(rng));
    if (s.pointInSolid(x)) continue;
    ++fluidPoints;
    const Vec<2> v = s.velocity(x);
    // Convex combination of fluid values (u = 1, |v| <= 0.3) and coupling/wall faces (0).
    ASSERT_TRUE(v.allFinite());
    ASSERT_GE(v[0], -1e-14);
    ASSERT_LE(v[0], 1 + 1e-14);
    ASSERT_LE(std::abs(v[1]), BlockScene::kVmax + 1e-14);
  }
  EXPECT_GT(fluidPoints, 15000);
  // A trace from just downstream of the block back into it is clipped at the block face x = 20h;
  // the sample there is the coupling face's 0, not the interior 1e6 (nor the fluid's 1).
  const Vec<2> start(20.5 * h, 12.5 * h), into(18.5 * h, 12.5 * h);
  const Vec<2> clipped = s.clipToFluid(start, into);
  EXPECT_FALSE(s.pointInSolid(clipped));
  EXPECT_NEAR(clipped[0], 20 * h, 1e-12);
  EXPECT_NEAR(s.component(0, clipped), 0.0, 1e-9);
  // Deep inside the block only the structure's own (prescribed) velocity is available.
  EXPECT_EQ(s.component(0, Vec<2>(16 * h, 12.5 * h)), BlockScene::kInside);
}

// clipToFluid skips the walk along a trace that cannot reach a solid cell (the chessboard
// distance from its start exceeds its length). The skip must change nothing: on random traces of
// up to 12 cells, from fluid points of a closed box with a solid block, it returns bitwise the
// walk's answer (the walk re-implemented here as rule 5 states it). The box is large enough
// that the distance scan, limited to the block's surroundings, leaves cells out. On a periodic
// grid there is no skip; BlockScene's channel checks that path.
TEST(VelocitySampling, ClipToFluidSkipsOnlyTracesThatCannotReachASolid) {
  const MacLayout<2> layout(Index<2>(96, 64), 1.0 / 64, Vec<2>::Zero(), {false, false});
  std::vector<std::uint8_t> solid(layout.cellCount(), 0);
  for (int j = 8; j < 16; ++j)
    for (int i = 12; i < 20; ++i) solid[layout.cellIndex(Index<2>(i, j))] = 1;
  const FaceBoundary boundary = staticObstacleBoundary(layout, solid);
  const Eigen::VectorXd u = Eigen::VectorXd::Zero(layout.totalFaces());
  const FaceVelocitySampler<2> s(layout, u, boundary);
  auto walk = [&](const Vec<2>& from, const Vec<2>& to) -> Vec<2> {
    const int n = std::max(1, static_cast<int>(std::ceil((to - from).norm() / (0.25 * layout.dx))));
    Vec<2> previous = from;
    for (int k = 1; k <= n; ++k) {
      const Vec<2> p = k == n ? to : Vec<2>(from + (static_cast<double>(k) / n) * (to - from));
      if (s.pointInSolid(p)) {
        Vec<2> fluid = previous, inSolid = p;
        for (int it = 0; it < 40; ++it) {
          const Vec<2> mid = 0.5 * (fluid + inSolid);
          (s.pointInSolid(mid) ? inSolid : fluid) = mid;
        }
        return fluid;
      }
      previous = p;
    }
    return to;
  };
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> ux(0.0, 1.5), uy(0.0, 1.0), angle(0, 2 * kPi), cells(0.0, 12.0);
  int clipped = 0, free = 0;
  for (int k = 0; k < 40000; ++k) {
    const Vec<2> from(ux(rng), uy(rng));
    if (s.pointInSolid(from)) continue;
    const double a = angle(rng), length = cells(rng) * layout.dx;
    const Vec<2> to = from + length * Vec<2>(std::cos(a), std::sin(a));
    const Vec<2> expected = walk(from, to), got = s.clipToFluid(from, to);
    ASSERT_EQ(got[0], expected[0]) << k;
    ASSERT_EQ(got[1], expected[1]) << k;
    (got == to ? free : clipped) += 1;
  }
  EXPECT_GT(clipped, 300);  // both outcomes were exercised
  EXPECT_GT(free, 10000);
}

// A shear flow u = c (y - y_w) over a solid floor (cell rows 0 and 1, staircase top at y = 2h)
// whose no-slip wall sits at y_w = 1.7 h, inside the top solid row: the free u-faces of row 2
// (y = 2.5 h) are theta = 0.8 cells from the wall, and rule 3b extends their velocity into the
// u-faces of row 1 (y = 1.5 h) with factor -(1 - 0.8) / 0.8 = -0.25.
struct ShearOverFloor {
  static constexpr double kRate = 3.0;
  static constexpr double kWallCells = 1.7;
  MacLayout<2> layout{Index<2>(8, 6), 0.125, Vec<2>::Zero(), {true, false}};
  FaceBoundary boundary;
  Eigen::VectorXd u;

  ShearOverFloor() {
    std::vector<std::uint8_t> solid(layout.cellCount(), 0);
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 8; ++i) solid[layout.cellIndex(Index<2>(i, j))] = 1;
    boundary = staticObstacleBoundary(layout, solid);
    const double h = layout.dx, yWall = kWallCells * h;
    u = faceField<2>(layout, [&](int a, const Vec<2>& x) { return a == 0 ? kRate * (x[1] - yWall) : 0.0; });
    for (int i = 0; i < 8; ++i)
      boundary.ghosts.push_back({layout.faceIndex(0, Index<2>(i, 1)), layout.faceIndex(0, Index<2>(i, 2)),
                                 ghostFactor((2.5 * h - yWall) / h)});
  }
};

TEST(VelocitySampling, GhostRulesPutTheWallAtTheSurface) {
  EXPECT_DOUBLE_EQ(ghostFactor(1.0), 0.0);    // wall at the obstacle face: its own value
  EXPECT_DOUBLE_EQ(ghostFactor(0.8), -0.25);  // linear extension through the wall
  EXPECT_DOUBLE_EQ(ghostFactor(0.5), -1.0);   // mirror
  EXPECT_DOUBLE_EQ(ghostFactor(0.1), -1.0);   // clamped: samples stay within the fluid's range
  EXPECT_THROW(ghostFactor(0.0), std::invalid_argument);
  EXPECT_THROW(ghostFactor(kNaN), std::invalid_argument);

  ShearOverFloor scene;
  const double h = scene.layout.dx, yWall = ShearOverFloor::kWallCells * h;
  const FaceVelocitySampler<2> s(scene.layout, scene.u, scene.boundary);
  // The ghost row holds the shear profile's value at y = 1.5 h, so samples between the wall and
  // the first fluid row follow the profile exactly and vanish at the wall.
  for (double y : {yWall, 2.0 * h, 2.2 * h, 2.5 * h, 3.1 * h})
    EXPECT_NEAR(s.component(0, Vec<2>(0.37, y)), ShearOverFloor::kRate * (y - yWall), 1e-12) << y / h;
  // Without the rules the interior row is dropped (rule 4): zero-gradient below the fluid row.
  FaceBoundary plain = scene.boundary;
  plain.ghosts.clear();
  const FaceVelocitySampler<2> p(scene.layout, scene.u, plain);
  EXPECT_NEAR(p.component(0, Vec<2>(0.37, 2.0 * h)), ShearOverFloor::kRate * 0.8 * h, 1e-12);
  // The advected field keeps prescribed faces at their prescribed value, and the shear flow
  // (steady under pure transport along x) stays put to rounding with either scheme.
  const Eigen::VectorXd sl = advectFacesSemiLagrangian(scene.layout, scene.u, 0.05, scene.boundary);
  const Eigen::VectorXd mc = advectFacesMacCormack(scene.layout, scene.u, 0.05, scene.boundary);
  for (int g = 0; g < scene.layout.totalFaces(); ++g) {
    const double expected = scene.boundary.prescribedFace[g] ? scene.boundary.prescribedVelocity[g] : scene.u[g];
    EXPECT_NEAR(sl[g], expected, 1e-12) << g;
    EXPECT_NEAR(mc[g], expected, 1e-12) << g;
  }
}

TEST(VelocitySampling, RejectsMalformedGhostRules) {
  ShearOverFloor scene;
  const auto& layout = scene.layout;
  const int ghost = layout.faceIndex(0, Index<2>(3, 1)), fluid = layout.faceIndex(0, Index<2>(3, 2));
  const auto rejects = [&](GhostRule rule) {
    FaceBoundary b = scene.boundary;
    b.ghosts = {rule};
    EXPECT_THROW(validateBoundary(layout, b), std::invalid_argument);
  };
  rejects({fluid, ghost, -0.5});                                       // extends into a free face
  rejects({ghost, ghost, -0.5});                                       // from a prescribed face
  rejects({ghost, fluid, -1.5});                                       // factor below -1
  rejects({ghost, fluid, kNaN});                                       // factor not a number
  rejects({ghost, layout.totalFaces(), -0.5});                         // out of range
  rejects({layout.faceIndex(1, Index<2>(3, 1)), fluid, -0.5});         // different axes
  FaceBoundary ok = scene.boundary;
  ok.ghosts = {{ghost, fluid, -0.5}};
  EXPECT_NO_THROW(validateBoundary(layout, ok));
}

TEST(WallGhosts, RulesFromTheWallDistancesAreExactForLinearShear) {
  // The floor of ShearOverFloor as a FluidDomain: the wall lies theta cells below the row-2
  // u-faces. theta = 0.8 extends from row 2; theta = 0.3 from row 3 (extending from row 2 would
  // need a factor below -1). Either way the ghost value is the linear profile's at y = 1.5 h.
  const MacLayout<2> layout(Index<2>(8, 6), 0.125, Vec<2>::Zero(), {true, false});
  BoxSpec<2> sides;
  sides[0] = sides[1] = SideSpec<2>::periodic();
  sides[2] = sides[3] = SideSpec<2>::wall();
  FluidDomain<2> domain = boxDomain(layout, sides);
  std::vector<std::uint8_t> solid(layout.cellCount(), 0);
  for (int i = 0; i < 8; ++i) solid[layout.cellIndex(Index<2>(i, 0))] = solid[layout.cellIndex(Index<2>(i, 1))] = 1;
  markSolid(domain, solid);
  EXPECT_TRUE(obstacleWallGhosts(domain).empty());  // the thesis's staircase: no rules
  const double h = layout.dx, rate = 2.0;
  for (double theta : {0.8, 0.3}) {
    domain.wallDistance.assign(static_cast<std::size_t>(layout.totalFaces()) * 4, 1.0);
    for (int i = 0; i < 8; ++i) domain.wallDistance[FluidDomain<2>::wallDistanceIndex(layout.faceIndex(0, Index<2>(i, 2)), 1, 0)] = theta;
    const std::vector<GhostRule> rules = obstacleWallGhosts(domain);
    ASSERT_EQ(rules.size(), 8u) << theta;  // one per row-2 u-face; none for the v-faces (normal)
    const double yWall = 2.5 * h - theta * h;
    FaceBoundary boundary = staticObstacleBoundary(layout, solid);
    boundary.ghosts = rules;
    const Eigen::VectorXd u = faceField<2>(layout, [&](int a, const Vec<2>& x) { return a == 0 ? rate * (x[1] - yWall) : 0.0; });
    const FaceVelocitySampler<2> s(layout, u, boundary);
    for (const GhostRule& rule : rules) {
      EXPECT_EQ(layout.faceCoord(rule.face).second[1], 1);
      EXPECT_EQ(layout.faceCoord(rule.from).second[1], theta < 0.5 ? 3 : 2);
      EXPECT_GE(rule.factor, -1.0);
      EXPECT_NEAR(s.sampleValue(rule.face), rate * (1.5 * h - yWall), 1e-12);
    }
    EXPECT_NEAR(s.component(0, Vec<2>(0.3, yWall)), 0.0, 1e-12) << theta;  // no slip at the wall
  }
}

TEST(WallGhosts, FacesOnTheStaircaseKeepTheirOwnVelocity) {
  // A 2 x 2 block of solid cells (columns 3-4, rows 2-3) in a closed 8 x 6 box, every wall half a
  // cell from the face next to it (the cell-boundary wall). The u-faces on the block's left and
  // right sides (x = 3 h and 5 h) have a fluid cell on one side: they carry no-penetration where
  // they sit and must get no ghost value, although each has free u-faces above or below it. Only
  // the u-faces inside the block (x = 4 h) get ghosts, one rule from below, one from above.
  const MacLayout<2> layout(Index<2>(8, 6), 0.125, Vec<2>::Zero(), {false, false});
  const SideSpec<2> wall = SideSpec<2>::wall();
  FluidDomain<2> domain = boxDomain(layout, BoxSpec<2>{wall, wall, wall, wall});
  std::vector<std::uint8_t> solid(layout.cellCount(), 0);
  for (int i = 3; i <= 4; ++i)
    for (int j = 2; j <= 3; ++j) solid[layout.cellIndex(Index<2>(i, j))] = 1;
  markSolid(domain, solid);
  domain.wallDistance.assign(static_cast<std::size_t>(layout.totalFaces()) * 4, 0.5);
  const std::vector<GhostRule> rules = obstacleWallGhosts(domain);
  for (const GhostRule& rule : rules) {
    const auto [axis, face] = layout.faceCoord(rule.face);
    EXPECT_EQ(face[axis == 0 ? 0 : 1], axis == 0 ? 4 : 3) << "axis " << axis << " face " << face[0] << "," << face[1];
    EXPECT_DOUBLE_EQ(rule.factor, -1.0);  // theta = 1/2: the mirror image
  }
  // u-faces (4, 2) from below and (4, 3) from above; v-faces (3, 3) from the left, (4, 3) from the right.
  EXPECT_EQ(rules.size(), 4u);
  // A sample at a side face's centre reads its prescribed (zero) velocity, not a ghost.
  FaceBoundary boundary = staticObstacleBoundary(layout, solid);
  boundary.ghosts = rules;
  const Eigen::VectorXd u = faceField<2>(layout, [](int, const Vec<2>& x) { return 1.0 + x[1]; });
  const FaceVelocitySampler<2> s(layout, u, boundary);
  const double h = layout.dx;
  EXPECT_EQ(s.component(0, Vec<2>(3 * h, 2.5 * h)), 0.0);
  EXPECT_EQ(s.component(0, Vec<2>(5 * h, 3.5 * h)), 0.0);
  // Half way between the side face (3, 3) and the free face (3, 4) above it: the mean of 0 and
  // the fluid value, as with the thesis's staircase.
  EXPECT_NEAR(s.component(0, Vec<2>(3 * h, 4 * h)), 0.5 * (1.0 + 4.5 * h), 1e-12);
}

TEST(SemiLagrangian, SolidBlockStaysBoundedAndFinite) {
  BlockScene scene;
  // CFL 2: many traces cross into the block and must be clipped.
  Eigen::VectorXd u = scene.u;
  const double dt = 2.0 * scene.layout.dx;
  for (int step = 0; step < 20; ++step) u = advectFacesSemiLagrangian(scene.layout, u, dt, scene.boundary);
  double umin = 1e300, umax = -1e300, vmax = 0;
  for (int g = 0; g < scene.layout.totalFaces(); ++g) {
    ASSERT_TRUE(std::isfinite(u[g])) << g;
    if (scene.boundary.prescribedFace[g]) {
      EXPECT_EQ(u[g], scene.boundary.prescribedVelocity[g]);
      continue;
    }
    if (scene.layout.faceCoord(g).first == 0) umin = std::min(umin, u[g]), umax = std::max(umax, u[g]);
    else vmax = std::max(vmax, std::abs(u[g]));
  }
  std::printf("SL block: u in [%.3f, %.3f], max|v| = %.3f\n", umin, umax, vmax);
  // Exact bounds: every sample is a convex combination of fluid values and prescribed zeros.
  EXPECT_GE(umin, -1e-12);
  EXPECT_LE(umax, 1 + 1e-12);
  EXPECT_LE(vmax, BlockScene::kVmax + 1e-12);
  EXPECT_LT(umin, 0.5);  // the block really did slow the flow down behind it
}

TEST(MacCormack, SolidBlockStaysBoundedAndFinite) {
  BlockScene scene;
  Eigen::VectorXd u = scene.u;
  const double dt = 2.0 * scene.layout.dx;  // CFL 2, as for semi-Lagrangian above
  for (int step = 0; step < 20; ++step) u = advectFacesMacCormack(scene.layout, u, dt, scene.boundary);
  double umin = 1e300, umax = -1e300, vmax = 0;
  for (int g = 0; g < scene.layout.totalFaces(); ++g) {
    ASSERT_TRUE(std::isfinite(u[g])) << g;
    if (scene.boundary.prescribedFace[g]) {
      EXPECT_EQ(u[g], scene.boundary.prescribedVelocity[g]);
      continue;
    }
    if (scene.layout.faceCoord(g).first == 0) umin = std::min(umin, u[g]), umax = std::max(umax, u[g]);
    else vmax = std::max(vmax, std::abs(u[g]));
  }
  // The limiter clamps each value into the range of the old values it was interpolated from, so
  // the bounds of the plain scheme hold exactly.
  EXPECT_GE(umin, -1e-12);
  EXPECT_LE(umax, 1 + 1e-12);
  EXPECT_LE(vmax, BlockScene::kVmax + 1e-12);
}

TEST(EnoRk3, SolidBlockStaysFiniteAndNearlyBounded) {
  BlockScene scene;
  // ENO reads prescribed values as ghosts inside the structure (eno.h), so give the block its
  // physical (zero) velocity; the NaNs in the raw field must still never be read.
  for (int g = 0; g < scene.layout.totalFaces(); ++g)
    if (scene.boundary.prescribedFace[g]) scene.boundary.prescribedVelocity[g] = 0;
  Eigen::VectorXd u = scene.u;
  const double dt = 0.5 * scene.layout.dx;
  for (int step = 0; step < 40; ++step) u = advectFacesEnoRk3(scene.layout, u, dt, scene.boundary);
  double umin = 1e300, umax = -1e300, vmax = 0;
  for (int g = 0; g < scene.layout.totalFaces(); ++g) {
    ASSERT_TRUE(std::isfinite(u[g])) << g;
    if (scene.layout.faceCoord(g).first == 0) umin = std::min(umin, u[g]), umax = std::max(umax, u[g]);
    else vmax = std::max(vmax, std::abs(u[g]));
  }
  std::printf("ENO block: u in [%.4f, %.4f], max|v| = %.4f\n", umin, umax, vmax);
  // ENO is essentially, not strictly, non-oscillatory, so no exact bound exists; measured: no
  // overshoot at all ([0, 1], |v| <= 0.2982). 1% of the data range is allowed.
  EXPECT_GE(umin, -0.01);
  EXPECT_LE(umax, 1.01);
  EXPECT_LE(vmax, 1.01 * BlockScene::kVmax);
}

// ---------------------------------------------------------------------------------------------
// Convergence on smooth periodic problems with exact solutions (no projection).

// u = (1, 0) constant and a passive v(x, 0) = sin(2 pi x): v is independent of y, so its own
// motion along y does not change it and v(x, t) = sin(2 pi (x - t)) exactly (Burgers equation
// for v degenerates to linear transport). T = 0.5, dt = 0.5 dx.
template <class Advance>
std::vector<double> transverseErrors2d(const std::vector<int>& ns, Advance advance) {
  std::vector<double> errs;
  const double T = 0.5;
  for (int n : ns) {
    const MacLayout<2> layout = periodicBox<2>(n, 1.0);
    auto exact = [&](double t) {
      return faceField<2>(layout, [t](int a, const Vec<2>& x) { return a == 0 ? 1.0 : std::sin(2 * kPi * (x[0] - t)); });
    };
    const Eigen::VectorXd u =
        evolve(exact(0), T, layout.dx, 1.0, 0.5, [&](const Eigen::VectorXd& y, double dt) { return advance(layout, y, dt); });
    errs.push_back(maxError(layout, u, exact(T)));
  }
  return errs;
}

TEST(Convergence, SemiLagrangianTransverse2d) {
  const std::vector<int> ns{32, 64, 128, 256};
  const auto e = transverseErrors2d(ns, [](const MacLayout<2>& l, const Eigen::VectorXd& y, double dt) {
    return advectFacesSemiLagrangian(l, y, dt);
  });
  printTable("SL, 2-D transverse sine, CFL 0.5, max error at T=0.5", ns, e);
  // Interpolation error a(1-a)/2 dx^2 |v''| per step, T/dt = O(1/dx) steps: first order
  // (measured 0.94, 0.97, 0.99; the coarse pair is pre-asymptotic as explained in the 3-D test).
  for (std::size_t i = 1; i < ns.size(); ++i) EXPECT_GT(order(e[i - 1], e[i]), 0.9);
  EXPECT_LT(e.back(), 0.03);
}

TEST(Convergence, EnoRk3Transverse2d) {
  const std::vector<int> ns{16, 32, 64, 128};
  const auto e = transverseErrors2d(ns, [](const MacLayout<2>& l, const Eigen::VectorXd& y, double dt) {
    return advectFacesEnoRk3(l, y, dt);
  });
  printTable("ENO3+RK3, 2-D transverse sine, CFL 0.5, max error at T=0.5", ns, e);
  // Measured 2.97, 2.99, 3.00. The bound 2.5 leaves room for pre-asymptotic coarse pairs (2.78
  // in 3-D) and still fails for any 2nd-order component (e.g. 2nd-order velocity interpolation
  // at the faces gives exactly 2.00 in the convective-term tests below).
  for (std::size_t i = 1; i < ns.size(); ++i) EXPECT_GT(order(e[i - 1], e[i]), 2.5);
  EXPECT_LT(e.back(), 1e-4);
}

TEST(Convergence, MacCormackTransverse2d) {
  const std::vector<int> ns{32, 64, 128};
  const auto e = transverseErrors2d(ns, [](const MacLayout<2>& l, const Eigen::VectorXd& y, double dt) {
    return advectFacesMacCormack(l, y, dt);
  });
  printTable("MacCormack (limited), 2-D transverse sine, CFL 0.5, max error at T=0.5", ns, e);
  // The back-and-forth correction cancels the interpolation's leading error: second order where
  // the limiter is idle. It clips at the sine's extrema, which is where the max error sits, so
  // the measured max-norm orders are 1.74, 1.73 (1.63 from 128 to 256). Plain semi-Lagrangian
  // above is first order (0.97, error 3.8e-2 at 128), so > 1.5 and < 3e-3 fail if the correction is lost.
  for (std::size_t i = 1; i < ns.size(); ++i) EXPECT_GT(order(e[i - 1], e[i]), 1.5);
  EXPECT_LT(e.back(), 3e-3);
}

// 3-D: u = (1, 0.5, 0) constant, w(x, y, 0) = sin(2 pi x) cos(2 pi y), independent of z, so
// w(x, y, t) = w0(x - t, y - t/2) exactly. T = 0.25.
template <class Advance>
std::vector<double> transverseErrors3d(const std::vector<int>& ns, Advance advance) {
  std::vector<double> errs;
  const double T = 0.25;
  for (int n : ns) {
    const MacLayout<3> layout = periodicBox<3>(n, 1.0);
    auto exact = [&](double t) {
      return faceField<3>(layout, [t](int a, const Vec<3>& x) {
        if (a == 0) return 1.0;
        if (a == 1) return 0.5;
        return std::sin(2 * kPi * (x[0] - t)) * std::cos(2 * kPi * (x[1] - 0.5 * t));
      });
    };
    const Eigen::VectorXd u =
        evolve(exact(0), T, layout.dx, 1.0, 0.5, [&](const Eigen::VectorXd& y, double dt) { return advance(layout, y, dt); });
    errs.push_back(maxError(layout, u, exact(T)));
  }
  return errs;
}

TEST(Convergence, SemiLagrangianTransverse3d) {
  const std::vector<int> ns{12, 24, 48};
  const auto e = transverseErrors3d(ns, [](const MacLayout<3>& l, const Eigen::VectorXd& y, double dt) {
    return advectFacesSemiLagrangian(l, y, dt);
  });
  printTable("SL, 3-D transverse, CFL 0.5, max error at T=0.25", ns, e);
  // Measured 0.85, 0.92: at n = 12 the numerical diffusion has already damped the amplitude by
  // ~29%, and the error 1 - exp(-C dx) of such damping grows slower than linearly in dx, so the
  // coarse pair sits below 1. 0.8 still rejects an O(1) error (e.g. a wrong trace: order ~0).
  for (std::size_t i = 1; i < ns.size(); ++i) EXPECT_GT(order(e[i - 1], e[i]), 0.8);
}

TEST(Convergence, EnoRk3Transverse3d) {
  const std::vector<int> ns{8, 16, 32};
  const auto e = transverseErrors3d(ns, [](const MacLayout<3>& l, const Eigen::VectorXd& y, double dt) {
    return advectFacesEnoRk3(l, y, dt);
  });
  printTable("ENO3+RK3, 3-D transverse, CFL 0.5, max error at T=0.25", ns, e);
  for (std::size_t i = 1; i < ns.size(); ++i) EXPECT_GT(order(e[i - 1], e[i]), 2.5);
}

// Cell-centred scalar phi0 = sin(2 pi x) sin(2 pi y) in the constant field (1, 0.5): after
// T = 1, phi = phi0(x - 1, y - 0.5) = -phi0.
TEST(Convergence, EnoRk3Scalar2d) {
  const std::vector<int> ns{16, 32, 64, 128};
  std::vector<double> e;
  for (int n : ns) {
    const MacLayout<2> layout = periodicBox<2>(n, 1.0);
    const Eigen::VectorXd u = faceField<2>(layout, [](int a, const Vec<2>&) { return a == 0 ? 1.0 : 0.5; });
    auto phi0 = [](const Vec<2>& x) { return std::sin(2 * kPi * x[0]) * std::sin(2 * kPi * x[1]); };
    const Eigen::VectorXd phi = evolve(cellField<2>(layout, phi0), 1.0, layout.dx, 1.0, 0.5,
                                       [&](const Eigen::VectorXd& y, double dt) { return advectScalarEnoRk3(layout, y, u, dt); });
    e.push_back((phi + cellField<2>(layout, phi0)).cwiseAbs().maxCoeff());
  }
  printTable("ENO3+RK3 scalar, 2-D diagonal translation, CFL 0.5, max error at T=1", ns, e);
  for (std::size_t i = 1; i < ns.size(); ++i) EXPECT_GT(order(e[i - 1], e[i]), 2.5);
}

// ---------------------------------------------------------------------------------------------
// The full nonlinear operator (u . grad) u against exact values.

// Taylor-Green u = sin x cos y, v = -cos x sin y on [0, 2 pi)^2:
//   u u_x + v u_y = sin x cos x (cos^2 y + sin^2 y) = sin(2x)/2,
//   u v_x + v v_y = sin y cos y (sin^2 x + cos^2 x) = sin(2y)/2.
Eigen::VectorXd taylorGreen(const MacLayout<2>& l) {
  return faceField<2>(l, [](int a, const Vec<2>& x) {
    return a == 0 ? std::sin(x[0]) * std::cos(x[1]) : -std::cos(x[0]) * std::sin(x[1]);
  });
}
Eigen::VectorXd taylorGreenConvection(const MacLayout<2>& l) {
  return faceField<2>(l, [](int a, const Vec<2>& x) { return 0.5 * std::sin(2 * x[a]); });
}

TEST(ConvectiveTerm, EnoTaylorGreenThirdOrder) {
  const std::vector<int> ns{16, 32, 64, 128};
  std::vector<double> e;
  for (int n : ns) {
    const MacLayout<2> layout = periodicBox<2>(n, 2 * kPi);
    e.push_back(maxError(layout, enoConvectiveTerm(layout, taylorGreen(layout)), taylorGreenConvection(layout)));
  }
  printTable("ENO3 (u.grad)u, Taylor-Green, max error", ns, e);
  // Measured 2.93, 2.98, 3.00 (with the 2nd-order 4-face average as upwind velocity instead of
  // the 4th-order midpoint rule this drops to exactly 2.00, which the bound 2.7 rejects).
  for (std::size_t i = 1; i < ns.size(); ++i) EXPECT_GT(order(e[i - 1], e[i]), 2.7);
}

TEST(ConvectiveTerm, Weno5TaylorGreenFourthOrder) {
  const std::vector<int> ns{16, 32, 64, 128};
  std::vector<double> e, eno;
  for (int n : ns) {
    const MacLayout<2> layout = periodicBox<2>(n, 2 * kPi);
    const Eigen::VectorXd u = taylorGreen(layout), exact = taylorGreenConvection(layout);
    e.push_back(maxError(layout, enoConvectiveTerm(layout, u, {}, HjStencil::Weno5), exact));
    eno.push_back(maxError(layout, enoConvectiveTerm(layout, u), exact));
  }
  printTable("WENO5 (u.grad)u, Taylor-Green, max error", ns, e);
  // The derivative is 5th order but the upwind velocity of the transverse component comes from
  // the 4th-order midpoint rule (eno.h), so the term is 4th order: > 3.5 rejects ENO3's 3.
  for (std::size_t i = 1; i < ns.size(); ++i) EXPECT_GT(order(e[i - 1], e[i]), 3.5);
  for (std::size_t i = 1; i < ns.size(); ++i) EXPECT_LT(e[i], 0.2 * eno[i]);
}

TEST(Convergence, Weno5Rk3Transverse2dBeatsEno3) {
  const std::vector<int> ns{16, 32, 64};
  const auto e = transverseErrors2d(ns, [](const MacLayout<2>& l, const Eigen::VectorXd& y, double dt) {
    return advectFacesEnoRk3(l, y, dt, {}, HjStencil::Weno5);
  });
  const auto eno = transverseErrors2d(ns, [](const MacLayout<2>& l, const Eigen::VectorXd& y, double dt) {
    return advectFacesEnoRk3(l, y, dt);
  });
  printTable("WENO5+RK3, 2-D transverse sine, CFL 0.5, max error at T=0.5", ns, e);
  // RK3 caps the order at 3 with dt ~ dx; the spatial error, dominant for ENO3, is much smaller.
  for (std::size_t i = 1; i < ns.size(); ++i) EXPECT_GT(order(e[i - 1], e[i]), 2.8);
  for (std::size_t i = 0; i < ns.size(); ++i) EXPECT_LT(e[i], 0.5 * eno[i]);
}

// A generic smooth, non-divergence-free periodic 3-D field; exact (u . grad) u_a = sum_b u_b d_b u_a.
TEST(ConvectiveTerm, EnoGeneric3dThirdOrder) {
  auto field = [](int a, const Vec<3>& x, Vec<3>* grad) {
    const double X = x[0], Y = x[1], Z = x[2];
    switch (a) {
      case 0:
        if (grad) *grad = Vec<3>(std::cos(X) * std::cos(Y), -std::sin(X) * std::sin(Y), -0.3 * std::sin(Z));
        return std::sin(X) * std::cos(Y) + 0.3 * std::cos(Z);
      case 1:
        if (grad) *grad = Vec<3>(0, 0.5 * std::cos(Y + Z), 0.5 * std::cos(Y + Z));
        return 0.5 * std::sin(Y + Z);
      default:
        if (grad) *grad = Vec<3>(-std::sin(X) * std::sin(Z), 0, std::cos(X) * std::cos(Z));
        return std::cos(X) * std::sin(Z);
    }
  };
  const std::vector<int> ns{16, 32, 64};
  std::vector<double> e;
  for (int n : ns) {
    const MacLayout<3> layout = periodicBox<3>(n, 2 * kPi);
    const Eigen::VectorXd u = faceField<3>(layout, [&](int a, const Vec<3>& x) { return field(a, x, nullptr); });
    const Eigen::VectorXd exact = faceField<3>(layout, [&](int a, const Vec<3>& x) {
      Vec<3> grad, vel;
      for (int b = 0; b < 3; ++b) vel[b] = field(b, x, nullptr);
      field(a, x, &grad);
      return vel.dot(grad);
    });
    e.push_back(maxError(layout, enoConvectiveTerm(layout, u), exact));
  }
  printTable("ENO3 (u.grad)u, generic 3-D field, max error", ns, e);
  for (std::size_t i = 1; i < ns.size(); ++i) EXPECT_GT(order(e[i - 1], e[i]), 2.7);
}

// One semi-Lagrangian step: (u^{n+1} - u^n) / dt = -(u . grad) u + O(dt) + O(dx^2 / dt), i.e.
// first order at fixed CFL (dt = 0.5 dx).
TEST(ConvectiveTerm, SemiLagrangianOneStepFirstOrder) {
  const std::vector<int> ns{32, 64, 128, 256};
  std::vector<double> e;
  for (int n : ns) {
    const MacLayout<2> layout = periodicBox<2>(n, 2 * kPi);
    const double dt = 0.5 * layout.dx;
    const Eigen::VectorXd u0 = taylorGreen(layout);
    const Eigen::VectorXd rate = (advectFacesSemiLagrangian(layout, u0, dt) - u0) / dt;
    e.push_back(maxError(layout, rate, Eigen::VectorXd(-taylorGreenConvection(layout))));
  }
  printTable("SL one step (u1-u0)/dt vs -(u.grad)u, Taylor-Green, dt = 0.5 dx", ns, e);
  for (std::size_t i = 1; i < ns.size(); ++i) EXPECT_GT(order(e[i - 1], e[i]), 0.9);
}

// Walls: a shear flow u = U(y), v = 0 between no-penetration walls is an exact steady solution
// ((u . grad) u = 0). It checks the clamping and ghost rules at non-periodic boundaries and the
// fallback of the ENO upwind velocity there: any leak of wall or out-of-domain values would move
// the field. Only rounding may remain.
TEST(Walls, ShearFlowBetweenWallsIsSteady) {
  const MacLayout<2> layout(Index<2>(20, 16), 1.0 / 16, Vec<2>::Zero(), {true, false});
  const FaceBoundary walls = staticObstacleBoundary(layout, {});
  const Eigen::VectorXd u0 = faceField<2>(layout, [](int a, const Vec<2>& x) {
    return a == 0 ? std::sin(3 * x[1]) + x[1] * x[1] : 0.0;
  });
  Eigen::VectorXd sl = u0, eno = u0;
  for (int s = 0; s < 10; ++s) {
    sl = advectFacesSemiLagrangian(layout, sl, 0.9 * layout.dx, walls);
    eno = advectFacesEnoRk3(layout, eno, 0.5 * layout.dx, walls);
  }
  EXPECT_LT(maxError(layout, sl, u0), 1e-13);
  EXPECT_LT(maxError(layout, eno, u0), 1e-13);
}

// ---------------------------------------------------------------------------------------------
// CFL.

TEST(Cfl, TimeStepAndGuards) {
  MacLayout<2> layout(Index<2>(4, 5), 0.1);
  Eigen::VectorXd u = Eigen::VectorXd::Constant(layout.totalFaces(), 0.5);
  u[7] = -2.0;
  EXPECT_DOUBLE_EQ(maxFaceSpeed(u), 2.0);
  EXPECT_DOUBLE_EQ(cflTimeStep(layout, u, kThesisCflNumber, 1.0), 0.9 * 0.1 / 2.0);
  EXPECT_DOUBLE_EQ(cflTimeStep(layout, u, 0.5, 0.01), 0.01);  // dtMax caps
  // Prescribed faces count with their prescribed velocity (here faster than the field).
  FaceBoundary b = staticObstacleBoundary(layout, {});
  b.prescribedVelocity[0] = 4.0;
  EXPECT_DOUBLE_EQ(cflTimeStep(layout, u, 0.5, 1.0, b), 0.5 * 0.1 / 4.0);
  // u = 0: no advective restriction.
  const Eigen::VectorXd rest = Eigen::VectorXd::Zero(layout.totalFaces());
  EXPECT_EQ(cflTimeStep(layout, rest, 0.9, 0.25), 0.25);
  EXPECT_EQ(cflTimeStep(layout, rest, 0.9, std::numeric_limits<double>::infinity()),
            std::numeric_limits<double>::infinity());
  // Denormal speed: cfl dx / speed overflows; the cap keeps it finite.
  Eigen::VectorXd tiny = rest;
  tiny[3] = 1e-320;
  EXPECT_EQ(cflTimeStep(layout, tiny, 0.9, 0.25), 0.25);
  EXPECT_THROW(cflTimeStep(layout, u, 0.0, 1.0), std::invalid_argument);
  EXPECT_THROW(cflTimeStep(layout, u, 0.5, 0.0), std::invalid_argument);
  u[2] = kNaN;
  EXPECT_THROW(cflTimeStep(layout, u, 0.5, 1.0), std::domain_error);
}

// ---------------------------------------------------------------------------------------------
// Determinism: each output is written once from read-only input, so 1 and 2 threads agree bitwise.

TEST(Determinism, OneAndTwoThreadsBitwiseEqual) {
  BlockScene scene;
  for (int g = 0; g < scene.layout.totalFaces(); ++g)
    if (scene.boundary.prescribedFace[g]) scene.boundary.prescribedVelocity[g] = 0;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> noise(-0.2, 0.2);
  Eigen::VectorXd u0 = scene.u;
  for (int g = 0; g < u0.size(); ++g)
    if (!scene.boundary.prescribedFace[g]) u0[g] += noise(rng);
  const Eigen::VectorXd phi0 = cellField<2>(scene.layout, [](const Vec<2>& x) { return std::cos(5 * x[0] + 3 * x[1]); });
  // The same block with ghost rules (rule 3b) on every face next to it, wall half way.
  FaceBoundary ghosted = scene.boundary;
  for (int g = 0; g < scene.layout.totalFaces(); ++g) {
    if (ghosted.prescribedFace[g]) continue;
    const auto [a, f] = scene.layout.faceCoord(g);
    const int b = 1 - a;
    for (int step : {-1, 1}) {
      Index<2> h = f;
      h[b] += step;
      if (h[b] < 0 || h[b] >= scene.layout.faceDims(a)[b]) continue;
      const int face = scene.layout.faceIndex(a, h);
      if (ghosted.prescribedFace[face]) ghosted.ghosts.push_back({face, g, ghostFactor(0.6)});
    }
  }
  ASSERT_GT(ghosted.ghosts.size(), 20u);
  const MacLayout<3> layout3 = periodicBox<3>(12, 1.0);
  const Eigen::VectorXd w0 = faceField<3>(layout3, [](int a, const Vec<3>& x) { return std::sin(6 * x[a] + a) + x[(a + 1) % 3]; });
  auto run = [&](int threads) {
    tbb::task_arena arena(threads);
    std::vector<Eigen::VectorXd> out;
    arena.execute([&] {
      Eigen::VectorXd sl = u0, mc = u0, eno = u0, weno = u0, phi = phi0, w = w0, mcGhost = u0, wenoGhost = u0;
      for (int s = 0; s < 5; ++s) {
        sl = advectFacesSemiLagrangian(scene.layout, sl, 1.5 * scene.layout.dx, scene.boundary);
        mc = advectFacesMacCormack(scene.layout, mc, 1.5 * scene.layout.dx, scene.boundary);
        eno = advectFacesEnoRk3(scene.layout, eno, 0.4 * scene.layout.dx, scene.boundary);
        weno = advectFacesEnoRk3(scene.layout, weno, 0.4 * scene.layout.dx, scene.boundary, HjStencil::Weno5);
        phi = advectScalarEnoRk3(scene.layout, phi, eno, 0.4 * scene.layout.dx, scene.boundary);
        w = advectFacesEnoRk3(layout3, advectFacesSemiLagrangian(layout3, w, 0.05), 0.02);
        mcGhost = advectFacesMacCormack(scene.layout, mcGhost, 1.5 * scene.layout.dx, ghosted);
        wenoGhost = advectFacesEnoRk3(scene.layout, wenoGhost, 0.4 * scene.layout.dx, ghosted, HjStencil::Weno5);
      }
      out = {sl, mc, eno, weno, phi, w, mcGhost, wenoGhost};
    });
    return out;
  };
  const auto one = run(1), two = run(2);
  ASSERT_EQ(one.size(), two.size());
  for (std::size_t k = 0; k < one.size(); ++k) {
    ASSERT_EQ(one[k].size(), two[k].size());
    EXPECT_EQ(std::memcmp(one[k].data(), two[k].data(), sizeof(double) * one[k].size()), 0) << "output " << k;
    EXPECT_TRUE(one[k].allFinite());
  }
  // The ghost rules are read: they change the flow next to the block.
  EXPECT_GT((one[1] - one[6]).cwiseAbs().maxCoeff(), 1e-3);
  EXPECT_GT((one[3] - one[7]).cwiseAbs().maxCoeff(), 1e-3);
}

}  // namespace
