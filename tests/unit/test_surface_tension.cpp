// Surface tension on a Lagrangian front (thesis Ch. 6): the front's geometry and remeshing, the
// level-set front of Table 6.1, the cut-cell discretization's identities, and short runs of the
// Sec. 6.4 experiments whose tolerances come from the tables measured in
// docs/benchmarks_surface_tension.md.
#include <gtest/gtest.h>
#include <oneapi/tbb/global_control.h>

#include <cmath>

#include "solvers/surface_tension/front_metrics.h"
#include "solvers/surface_tension/pressure_jump.h"
#include "solvers/surface_tension/scenarios.h"

using namespace monolith::solvers;

TEST(SurfaceTensionFront, CurvatureOfAUniformCircleIsExact) {
  // Sec. 6.3.2: for vertices on a circle with uniform spacing (6.34) is exact to roundoff.
  const Front2 front = perturbedCircle(Eigen::Vector2d(0.5, 0.5), 0.25, 0, 0, 40);
  const auto kn = curvatureNormals(front);
  for (int k = 0; k < front.pointCount(); ++k) {
    EXPECT_NEAR(kn[k].norm(), 4.0, 1e-12);
    const Eigen::Vector2d inward = (Eigen::Vector2d(0.5, 0.5) - front.points[k]).normalized();
    EXPECT_NEAR(kn[k].normalized().dot(inward), 1.0, 1e-12);
  }
}

TEST(SurfaceTensionFront, ForceIsMinusTheGradientOfSigmaTimesLength) {
  // (6.36): phi = sigma l per segment, f = -d phi / dx; checked by central differences.
  const Front2 front = perturbedCircle(Eigen::Vector2d(0.3, 0.4), 0.2, 0.1, 3, 17);
  const double sigma = 0.7, h = 1e-6;
  const auto f = surfaceTensionForces(front, sigma);
  Eigen::Vector2d total = Eigen::Vector2d::Zero();
  for (int k = 0; k < front.pointCount(); ++k) {
    total += f[k];
    for (int a = 0; a < 2; ++a) {
      Front2 plus = front, minus = front;
      plus.points[k][a] += h;
      minus.points[k][a] -= h;
      const double derivative = sigma * (frontLength(plus) - frontLength(minus)) / (2 * h);
      EXPECT_NEAR(f[k][a], -derivative, 1e-8);
    }
  }
  EXPECT_LT(total.norm(), 1e-14);  // surface tension exerts no net force
}

TEST(SurfaceTensionFront, RemeshingKeepsSegmentsBetweenHalfAndOneAndAHalfCells) {
  const double dx = 0.05;
  for (int n : {200, 10}) {  // too fine (merges) and too coarse (third-order splits)
    Front2 front = perturbedCircle(Eigen::Vector2d(0.5, 0.5), 0.25, 0, 0, n);
    const double area = enclosedArea(front);
    EXPECT_GT(remeshClosedFront(front, 0.5 * dx, 1.5 * dx), 0);
    for (const auto& e : front.elements) {
      const double l = (front.points[e[1]] - front.points[e[0]]).norm();
      EXPECT_GE(l, 0.5 * dx);
      EXPECT_LE(l, 1.5 * dx);
    }
    // Merging keeps points on the circle; splitting the 10-gon adds points within the stencil's
    // third-order error of the chord-to-arc gap (the area moves toward the circle's, pi r^2).
    if (n == 200) {
      EXPECT_NEAR(enclosedArea(front) / area, 1.0, 0.02);
    } else {
      EXPECT_GT(enclosedArea(front), area);
    }
  }
}

TEST(SurfaceTensionFront, SineInterfaceMatchesTable61) {
  // Table 6.1's L-inf columns (N = 40, 80, 160); the construction reproduces them to 4 digits, the
  // L1 columns within 3 % (the thesis does not say exactly which points it averages).
  struct Row { int n; double linfG, l1G, linfK, l1K; };
  const Row third[] = {{40, 1.299e-5, 3.214e-6, 3.375e-2, 9.626e-3},
                       {80, 1.478e-6, 2.838e-7, 2.063e-2, 4.931e-3},
                       {160, 1.783e-7, 2.637e-8, 1.065e-2, 2.350e-3}};
  const Row fourth[] = {{40, 1.295e-5, 3.012e-6, 2.876e-2, 8.497e-3},
                        {80, 8.227e-7, 1.848e-7, 1.425e-2, 4.318e-3},
                        {160, 5.179e-8, 1.166e-8, 7.636e-3, 2.043e-3}};
  for (int variant = 0; variant < 2; ++variant) {
    const Row* rows = variant == 0 ? third : fourth;
    std::vector<SineInterfaceErrors> measured;
    for (int i = 0; i < 3; ++i) {
      const SineInterfaceErrors e = sineInterfaceErrors(rows[i].n, variant == 0 ? CrossingOrder::Third : CrossingOrder::Fourth);
      EXPECT_NEAR(e.interfaceMax / rows[i].linfG, 1.0, 1e-3) << rows[i].n;
      EXPECT_NEAR(e.curvatureMax / rows[i].linfK, 1.0, 1e-3) << rows[i].n;
      EXPECT_NEAR(e.interfaceMean / rows[i].l1G, 1.0, 0.03) << rows[i].n;
      EXPECT_NEAR(e.curvatureMean / rows[i].l1K, 1.0, 0.03) << rows[i].n;
      measured.push_back(e);
    }
    // Orders: interface ~3 (third) / ~4 (fourth), curvature ~1.
    const double orderG = std::log2(measured[1].interfaceMax / measured[2].interfaceMax);
    const double orderK = std::log2(measured[1].curvatureMean / measured[2].curvatureMean);
    EXPECT_NEAR(orderG, variant == 0 ? 3.0 : 4.0, 0.2);
    EXPECT_NEAR(orderK, 1.0, 0.2);
  }
}

namespace {
TwoPhaseSettings circleSettings(bool onePhase) {
  TwoPhaseSettings s = staticCircleSettings(onePhase, true);
  return s;
}
}  // namespace

TEST(SurfaceTensionDiscretization, UniformFlowHasNoDivergenceInAnyCellPart) {
  // The coupling face closes each cut cell's phase parts: G^T u = 0 for a uniform velocity whose
  // coupling-face values are its normal components (one and two phases).
  const MacLayout<2> layout(Eigen::Vector2i(16, 16), 1.0 / 16);
  const Front2 front = perturbedCircle(Eigen::Vector2d(0.52, 0.47), 0.27, 0.1, 3, 60);
  const Eigen::Vector2d U(0.3, -0.7);
  for (bool onePhase : {true, false}) {
    const InterfaceDiscretization D = discretizeInterface(layout, front, circleSettings(onePhase), 0.01);
    EXPECT_GT(static_cast<int>(D.couplingCell.size()), 20);
    Eigen::VectorXd u(D.unknowns());
    for (int q = 0; q < D.gridUnknowns; ++q) u[q] = U[layout.faceCoord(D.unknownFace[q]).first];
    for (std::size_t k = 0; k < D.couplingCell.size(); ++k) u[D.gridUnknowns + static_cast<int>(k)] = U.dot(D.couplingNormal[k]);
    const Eigen::VectorXd divergence = D.G.transpose() * u;
    // Wall-adjacent parts see the walls' zero velocity: only check cells away from the walls.
    for (int c = 0; c < layout.cellCount(); ++c) {
      const Eigen::Vector2i ci = layout.cellCoord(c);
      if (ci.minCoeff() == 0 || ci.maxCoeff() == 15) continue;
      for (int dof : {D.insideDof[c], D.outsideDof[c]}) {
        if (dof >= 0) {
          EXPECT_NEAR(divergence[dof], 0.0, 1e-14) << "cell " << c;
        }
      }
    }
  }
}

TEST(SurfaceTensionDiscretization, ForceDistributionConservesEveryParticlesForce) {
  // Each particle's weights in H^T sum to 1 (the force density integrates back to the force), and
  // H^T only acts on coupling faces along their normals; C H has one row per segment.
  const MacLayout<2> layout(Eigen::Vector2i(20, 20), 0.05);
  const Front2 front = perturbedCircle(Eigen::Vector2d(0.5, 0.5), 0.25, 0.05, 2, 37);
  const InterfaceDiscretization D = discretizeInterface(layout, front, circleSettings(false), 0.01);
  std::vector<double> weight(front.pointCount(), 0.0);
  for (int o = 0; o < D.Ht.outerSize(); ++o)
    for (Eigen::SparseMatrix<double>::InnerIterator it(D.Ht, o); it; ++it) {
      ASSERT_GE(it.row(), D.gridUnknowns);
      const int k = static_cast<int>(it.col()) / 2, a = static_cast<int>(it.col()) % 2;
      weight[k] += it.value() * D.couplingNormal[it.row() - D.gridUnknowns][a];
    }
  for (double w : weight) EXPECT_NEAR(w, 1.0, 1e-12);
  EXPECT_EQ(D.CH.rows(), front.elementCount());
  TwoPhaseSettings explicitSettings = circleSettings(false);
  explicitSettings.implicitSurfaceTension = false;
  EXPECT_EQ(discretizeInterface(layout, front, explicitSettings, 0.01).CH.rows(), 0);  // D = C = 0
}

TEST(SurfaceTensionStaticCircle, ParasiticCurrentsAtOrBelowTheThesisOnePhaseAndTwoPhase) {
  // Tables 6.2/6.3 at 1/dx = 20, t = 5 (500 steps), front tracking with the original driver's front
  // (2^7 = 128 points, spacing about dx / 4, no remeshing). The thesis's front tracking: one phase L1 1.83e-7, Linf 9.59e-7;
  // two phase 2.76e-7 / 8.32e-7. Measured: one phase 8.4e-10 / 5.7e-9, two phase 1.2e-8 / 1.1e-7.
  // The jump sigma / r = 4 within 1 % (measured 0.006 % / 0.005 %).
  for (bool onePhase : {false, true}) {
    const StaticCircleResult r = runStaticCircle(20, onePhase, true, 5.0);
    EXPECT_TRUE(r.stable);
    EXPECT_EQ(r.steps, 500);
    EXPECT_NEAR(r.pressureJump, 4.0, 0.04) << (onePhase ? "one phase" : "two phase");
    EXPECT_LE(r.l1, onePhase ? 1.83e-7 : 2.76e-7) << (onePhase ? "one phase" : "two phase");
    EXPECT_LE(r.linf, onePhase ? 9.59e-7 : 8.32e-7) << (onePhase ? "one phase" : "two phase");
  }
  // With one point per dx of arc and remeshing (31 points here) the same run is 8-40x above the
  // thesis (measured two phase 2.1e-6 / 3.6e-5): the segment-angle error above, not a bug.
  const StaticCircleResult coarse = runStaticCircle(20, false, true, 1.0, false, 31, true);
  EXPECT_GT(coarse.linf, 8.32e-7);
}

TEST(SurfaceTensionOscillatingCircle, PeriodAndProbeAtCoarseResolution) {
  // Table 6.4's refinement test at N = 50 (the bench runs N = 100, period within 3 % of pi).
  // Measured here: T = 3.295 (+4.9 %), u(0.75, 0.5, t = 0.5) = -1.812e-2; the thesis's front
  // tracking at N = 50: 3.222 and -1.945e-2.
  const OscillatingCircleResult r = runOscillatingCircle(50, 0.05, 1.2 * M_PI);
  EXPECT_TRUE(r.stable);
  EXPECT_NEAR(r.period / M_PI, 1.0, 0.06);
  EXPECT_NEAR(r.probeAtHalf / -1.945e-2, 1.0, 0.1);
  // Where the max error at t = 0.5 comes from (measured: 0.155 over all faces inside; at the x-face
  // 0.11 dx inside the front on the horizontal axis; 0.084 against the analytic field at the run's
  // own frequency 2 pi / T, so about half is the period's error in amplitude and phase).
  EXPECT_NEAR(r.relativeErrorAtHalf, 0.155, 0.01);
  EXPECT_LT(r.worstDistance, 1.0);
  EXPECT_EQ(r.worstAxis, 0);
  EXPECT_LT(std::abs(std::sin(r.worstAngle * M_PI / 180)), 0.2);
  EXPECT_LT(r.ownFrequencyRelativeErrorAtHalf, 0.6 * r.relativeErrorAtHalf);
  EXPECT_LT(r.ownFrequencyInteriorRelativeErrorAtHalf, r.ownFrequencyRelativeErrorAtHalf);
}

TEST(SurfaceTensionOscillatingCircle, CarriedCouplingVelocitiesLoseLessPerStep) {
  // Sampling the coupling faces' u* from the grid each step discards the last solve's coupling
  // velocities: the drop loses speed by a fixed amount per step, so more steps (smaller dt) give a
  // slower drop. Carried on the front, the result depends far less on dt and lies closer to the
  // analytic u_x = -eps omega (x - 1/2) sin(omega t) = -2.104e-2 at the probe. N = 50 to t = 0.5.
  // Measured: sampled -1.812e-2 (dt = dx/4), -1.856e-2 (dt = dx); carried -1.913e-2, -1.895e-2.
  auto probe = [](double dtPerDx, bool carry) {
    const OscillatingCircleResult r = runOscillatingCircle(50, 0.05, 0.5, 0, true, dtPerDx, carry);
    EXPECT_TRUE(r.stable);
    return r.probeAtHalf;
  };
  const double sampledQuarter = probe(0.25, false), sampledOne = probe(1.0, false);
  const double carriedQuarter = probe(0.25, true), carriedOne = probe(1.0, true);
  EXPECT_LT(std::abs(carriedQuarter - carriedOne), 0.6 * std::abs(sampledQuarter - sampledOne));
  const double analytic = -0.05 * 2 * 0.25 * std::sin(1.0);
  EXPECT_LT(std::abs(carriedQuarter - analytic), 0.75 * std::abs(sampledQuarter - analytic));
}

TEST(SurfaceTensionOscillatingCircle, CarriedVelocitiesAreStateThatARestartNeeds) {
  // The carried H u^n is state, not a cache: dropping it once (as a checkpoint without it would)
  // changes the run, and keeping it reproduces the straight run bitwise. N = 24, 12 + 4 steps.
  auto start = [] {
    return makeTwoPhaseState(MacLayout<2>(Eigen::Vector2i(24, 24), 1.0 / 24),
                             perturbedCircle(Eigen::Vector2d(0.5, 0.5), 1.0 / 3, 0.05, 2, 50));
  };
  TwoPhaseSettings s;
  s.densityInside = 27;
  s.onePhase = true;
  s.sigma = 2.0 / 3;
  s.remesh = false;
  s.carryCouplingVelocity = true;
  const double dt = 0.25 / 24;
  TwoPhaseState straight = start();
  for (int k = 0; k < 12; ++k) advanceTwoPhase(straight, s, dt);
  ASSERT_EQ(static_cast<int>(straight.pointVelocity.size()), straight.front.pointCount());
  TwoPhaseState dropped = straight;
  dropped.pointVelocity.clear();
  for (int k = 0; k < 4; ++k) {
    advanceTwoPhase(straight, s, dt);
    advanceTwoPhase(dropped, s, dt);
  }
  EXPECT_GT((straight.u - dropped.u).cwiseAbs().maxCoeff(), 1e-8 * straight.u.cwiseAbs().maxCoeff());
  TwoPhaseState again = start();
  for (int k = 0; k < 16; ++k) advanceTwoPhase(again, s, dt);
  EXPECT_EQ((again.u - straight.u).cwiseAbs().maxCoeff(), 0.0);
}

TEST(SurfaceTensionRisingBubble, ImplicitStableWhereExplicitBlowsUp) {
  // Sec. 6.4.4 at 40 x 80 (the bench runs 80 x 160): dt = 3 s is 18x the capillary limit here. The
  // explicit variant (D = C = 0) trips the guard within 10 steps (measured: step 6) and the guard
  // names it; the implicit one stays bounded by the bubble's rise speed.
  const RisingBubbleStability explicitRun = runRisingBubbleStability(40, 3.0, false, 10);
  EXPECT_FALSE(explicitRun.stable);
  EXPECT_NE(explicitRun.reason.find("explicit surface tension blew up"), std::string::npos) << explicitRun.reason;
  const RisingBubbleStability implicitRun = runRisingBubbleStability(40, 3.0, true, 10);
  EXPECT_TRUE(implicitRun.stable) << implicitRun.reason;
  EXPECT_LT(implicitRun.maxSpeed, 0.02);
  EXPECT_GT(3.0 / implicitRun.capillaryDt, 15.0);
}

TEST(SurfaceTensionDeterminism, OneAndTwoThreadsAgreeBitwise) {
  auto run = [](int threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    TwoPhaseState state = makeTwoPhaseState(MacLayout<2>(Eigen::Vector2i(24, 24), 1.0 / 24),
                                            perturbedCircle(Eigen::Vector2d(0.5, 0.5), 0.3, 0.1, 2, 50));
    TwoPhaseSettings s = staticCircleSettings(false, true);
    s.densityOutside = 1e3;
    s.gravity = Eigen::Vector2d(0, -1e-2);
    for (int i = 0; i < 20; ++i) advanceTwoPhase(state, s, 0.01);
    return state;
  };
  const TwoPhaseState a = run(1), b = run(2);
  ASSERT_EQ(a.u.size(), b.u.size());
  for (Eigen::Index f = 0; f < a.u.size(); ++f) ASSERT_EQ(a.u[f], b.u[f]);
  ASSERT_EQ(a.front.pointCount(), b.front.pointCount());
  for (int k = 0; k < a.front.pointCount(); ++k) ASSERT_EQ(a.front.points[k], b.front.points[k]);
}

TEST(SurfaceTensionInput, RefusesPeriodicAxesAndBadTimeSteps) {
  MacLayout<2> periodic(Eigen::Vector2i(8, 8), 0.125, Eigen::Vector2d::Zero(), {true, false});
  EXPECT_THROW(makeTwoPhaseState(periodic, perturbedCircle(Eigen::Vector2d(0.5, 0.5), 0.25, 0, 0, 12)), std::invalid_argument);
  TwoPhaseState state = makeTwoPhaseState(MacLayout<2>(Eigen::Vector2i(8, 8), 0.125),
                                          perturbedCircle(Eigen::Vector2d(0.5, 0.5), 0.25, 0, 0, 12));
  EXPECT_THROW(advanceTwoPhase(state, TwoPhaseSettings{}, 0.0), std::invalid_argument);
  EXPECT_THROW(advanceTwoPhase(state, TwoPhaseSettings{}, std::nan("")), std::invalid_argument);
  // A front that left the domain is reported by the guard, not stepped.
  state.front.points[0] = Eigen::Vector2d(2, 0.5);
  const TwoPhaseStepReport r = advanceTwoPhase(state, TwoPhaseSettings{}, 0.01);
  EXPECT_TRUE(r.blewUp);
  EXPECT_NE(r.blowUpReason.find("left the domain"), std::string::npos);
}

TEST(SurfaceTensionStaticCircle, LevelSetTrackedFrontOnePhaseAndTwoPhase) {
  // The level-set-tracked front at 1/dx = 20, t = 5. Measured: one phase L1 8.33e-8, Linf 4.97e-7
  // (the thesis's level set 1.07e-4 / 3.70e-4); two phase L1 3.94e-7, Linf 5.54e-6 (thesis 8.57e-5 /
  // 2.48e-4). Bounds 1.5x measured; the jump within 1 % (measured 0.65 % / 0.72 %, the semi-Lagrangian
  // level set's slow drift).
  for (bool onePhase : {true, false}) {
    const StaticCircleResult r = runStaticCircle(20, onePhase, true, 5.0, true);
    EXPECT_TRUE(r.stable);
    EXPECT_NEAR(r.pressureJump, 4.0, 0.04) << (onePhase ? "one phase" : "two phase");
    EXPECT_LT(r.l1, onePhase ? 1.3e-7 : 6e-7);
    EXPECT_LT(r.linf, onePhase ? 7.5e-7 : 8.3e-6);
  }
}

TEST(SurfaceTensionStaticCircle, LevelSetCurrentsFallUnderRefinement) {
  // One phase, the level-set-tracked front at 1/dx = 20, 40, 80 to t = 0.25. Redistancing leaves the
  // 3 cells the crossing stencils read (TwoPhaseSettings::levelSetKeep). Measured: Linf 4.93e-7,
  // 2.66e-7, 1.14e-7 (orders 0.9, 1.2), L1 8.14e-8, 1.93e-8, 4.82e-9 (orders 2.1, 2.0). Redistancing
  // from 2 cells on (keep = 2) moved the mesh points by an O(dx^2) that varies from point to point,
  // O(1) curvature noise: Linf 1.11e-6, 1.21e-6, 1.40e-6, growing under refinement.
  std::vector<StaticCircleResult> runs;
  for (int n : {20, 40, 80}) runs.push_back(runStaticCircle(n, true, true, 0.25, true));
  for (std::size_t k = 0; k + 1 < runs.size(); ++k) {
    EXPECT_GT(std::log2(runs[k].linf / runs[k + 1].linf), 0.7) << k;
    EXPECT_GT(std::log2(runs[k].l1 / runs[k + 1].l1), 1.7) << k;
  }
  EXPECT_LT(runs[2].linf, 1.5e-7);
  LevelSetFrontOptions keepTwo;
  keepTwo.keep = 2;
  const StaticCircleResult two = runStaticCircle(40, true, true, 0.25, true, 0, false, 1e4, keepTwo);
  EXPECT_GT(two.linf, 3 * runs[1].linf);
}

TEST(SurfaceTensionStaticCircle, TwoPhaseLevelSetCurrentsDoNotGrow) {
  // Two phases, the level-set-tracked front at 1/dx = 40 to t = 1.25. The circle passes within 1e-6
  // of eight grid nodes ((0.5 +- 0.15, 0.5 +- 0.2) and transposed) and touches four more; the corner
  // cells there are cut into tiny parts, and the current then grows steadily (measured without the
  // node snap: L1 5.80e-8 at t = 0.625, 1.105e-7 at 1.25, 2.27e-7 at 2.5). With the crossings put on
  // those nodes (TwoPhaseSettings::levelSetNodeSnap, 1e-4 dx): 5.18e-8 and 6.56e-8 (and at t = 5
  // L1 3.13e-7, L-inf 3.13e-6; the thesis's 7.56e-6 / 3.33e-5).
  auto growth = [](double snap) {
    LevelSetFrontOptions options;
    options.nodeSnap = snap;
    double half = 0;
    const StaticCircleResult r = runStaticCircle(40, false, true, 1.25, true, 0, false, 1e4, options,
                                                 [&](const TwoPhaseState& s, const TwoPhaseStepReport&) {
                                                   if (s.step == 125) half = velocityNorms(s.u).first;
                                                 });
    EXPECT_TRUE(r.stable);
    EXPECT_NEAR(r.pressureJump, 4.0, 0.04);
    return std::make_pair(r.l1 / half, r.l1);
  };
  const auto [snapped, snappedL1] = growth(1e-4);
  EXPECT_LT(snapped, 1.45);
  EXPECT_LT(snappedL1, 8e-8);
  const auto [unsnapped, unsnappedL1] = growth(0);
  EXPECT_GT(unsnapped, 1.7);  // the growth this test is there to catch
  EXPECT_GT(unsnappedL1, 1e-7);
}

TEST(SurfaceTensionFront, LevelSetMeshDoesNotLayASegmentOnAGridLine) {
  // A circle whose top lies 3e-6 above the grid line y = 0.75, over the node (0.5, 0.75): the mesh
  // has a cap over the line, two crossings 1.2e-3 (0.05 dx) either side of the node and its tip on
  // the vertical edge above it. Merging those slivers by deleting the tip laid the merged segment on
  // the line, where its cells' faces cannot be told inside from outside; in the two-phase static
  // circle that kicked the current from 3e-6 to 1e-4 (1/dx = 40, t = 3.9). The merge deletes a
  // crossing instead, and the tip stays.
  const MacLayout<2> layout(Eigen::Vector2i(40, 40), 1.0 / 40);
  const Eigen::Vector2d centre(0.5, 0.5 + 3e-6);
  std::vector<double> phi(layout.cellCount());
  for (int c = 0; c < layout.cellCount(); ++c) phi[c] = (layout.cellCenter(layout.cellCoord(c)) - centre).norm() - 0.25;
  const Front2 front = frontFromLevelSet(layout, phi, CrossingOrder::Fourth);
  bool tip = false;
  for (const auto& x : front.points) tip = tip || (x.y() > 0.75 && std::abs(x.x() - 0.5) < 1e-12);
  EXPECT_TRUE(tip);
  for (const auto& e : front.elements) {
    const Eigen::Vector2d a = front.points[e[0]], b = front.points[e[1]];
    const bool onLine = (a.y() == b.y() && std::abs(a.y() * 40 - std::round(a.y() * 40)) < 1e-9) ||
                        (a.x() == b.x() && std::abs(a.x() * 40 - std::round(a.x() * 40)) < 1e-9);
    EXPECT_FALSE(onLine) << a.transpose() << " -> " << b.transpose();
  }
  EXPECT_NEAR(enclosedArea(front), M_PI * 0.0625, 1e-3);
}

TEST(SurfaceTensionFront, ShapeMeasuresOfASquare) {
  // The unit square about (2, 3): area 1, length 4, centroid (2, 3), top 3.5 and bottom 2.5 on the
  // line x = 2, circularity 2 sqrt(pi) / 4.
  const Front2 square = closedPolyline({{1.5, 2.5}, {2.5, 2.5}, {2.5, 3.5}, {1.5, 3.5}});
  const FrontShape s = measureFront(square);
  EXPECT_NEAR(s.area, 1.0, 1e-14);
  EXPECT_NEAR(s.length, 4.0, 1e-14);
  EXPECT_NEAR(s.centroid.x(), 2.0, 1e-14);
  EXPECT_NEAR(s.centroid.y(), 3.0, 1e-14);
  EXPECT_NEAR(s.top, 3.5, 1e-14);
  EXPECT_NEAR(s.bottom, 2.5, 1e-14);
  EXPECT_NEAR(s.circularity, std::sqrt(M_PI) / 2, 1e-14);
}

TEST(SurfaceTensionRisingBubble, EnoRk3ImplicitStableAt3s) {
  // Sec. 6.4.4 with the thesis's ENO/RK3 advection at 40 x 80, dt = 3 s (18x the capillary limit
  // here), 10 steps: the implicit variant stays bounded by the rise speed (measured max 1.2e-2 m/s
  // over 30 steps, CFL 1.5).
  const RisingBubbleStability r = runRisingBubbleStability(40, 3.0, true, 10, TwoPhaseAdvection::EnoRk3);
  EXPECT_TRUE(r.stable) << r.reason;
  EXPECT_LT(r.maxSpeed, 0.02);
  EXPECT_LT(std::abs(r.areaChange), 0.1);
}

TEST(SurfaceTensionRisingBubble, AirBubbleInWaterAcceleratesAndFlattens) {
  // Sec. 6.4.5 at 20 x 30 cells to t = 0.01 s (5 steps of 2e-3 s). From rest, the bubble's centroid
  // accelerates at most at the unbounded potential-flow value g (rho_w - rho_a) / (rho_w + rho_a)
  // (walls 3 radii away add mass); measured 6.1 m/s^2 over the first step. Its bottom rises faster
  // than its top (the bubble flattens), so the circularity falls; the area stays within 1 %.
  const RisingBubbleRun run = runRisingBubble(20, 0.01, 0.002);
  ASSERT_TRUE(run.stable) << run.reason;
  ASSERT_EQ(run.samples.size(), 6u);
  const double g = 9.8 * (1000 - 1.226) / (1000 + 1.226);
  const double acceleration = run.samples[1].riseVelocity / run.samples[1].time;
  EXPECT_GT(acceleration, 0.5 * g);
  EXPECT_LT(acceleration, g);
  const auto &first = run.samples.front(), &last = run.samples.back();
  EXPECT_GT(last.top, first.top);
  EXPECT_GT(last.bottom - first.bottom, last.top - first.top);
  EXPECT_LT(last.circularity, first.circularity);
  EXPECT_GT(last.riseVelocity, run.samples[1].riseVelocity);
  for (const auto& s : run.samples) EXPECT_LT(std::abs(s.areaDrift), 0.01) << "t = " << s.time;
}

TEST(SurfaceTensionStability, ImplicitLevelSetUpdateClosesTheLevelSetGap) {
  // Sec. 6.4.6's ellipse (Fig. 6.7) at N = 32, dt = 32x the explicit capillary limit, 500 steps.
  // The level set advected with the grid velocity is unstable there even with implicit surface
  // tension (measured: the guard fires at step 45); moving phi with the coupled solve's Lagrangian
  // velocity H u (the implicit level-set update of Sec. 6.5's future work) keeps it stable, as front
  // tracking is (measured stable to 128x).
  const double dt = 32 * stabilityCapillaryDt(32);
  const StabilityCase advected = runStabilityCase(32, dt, true, true, 500, true, false);
  EXPECT_FALSE(advected.stable);
  const StabilityCase updated = runStabilityCase(32, dt, true, true, 500, true, true);
  EXPECT_TRUE(updated.stable);
  EXPECT_EQ(updated.steps, 500);
  EXPECT_LT(updated.maxSpeed, 0.05);
}

TEST(SurfaceTensionDiscretization, FrontThroughAGridNodeKeepsThePhases) {
  // The original driver's circle puts points on the axes through the centre; at 1/dx = 20 four of
  // them sit on grid nodes. A cell that the front touches only at such a corner must keep its own
  // phase (it was once classified by the node's ambiguous parity: a 3.7e-5 jet after one step in two
  // phases). One step of the two-phase static circle: measured max speed 2.1e-9.
  const double dx = 0.05;
  TwoPhaseState state = makeTwoPhaseState(MacLayout<2>(Eigen::Vector2i(20, 20), dx),
                                          perturbedCircle(Eigen::Vector2d(0.5, 0.5), 0.25, 0, 0, 128, 0.0));
  TwoPhaseSettings settings = staticCircleSettings(false, true);
  settings.remesh = false;
  const InterfaceDiscretization D = discretizeInterface(state.layout, state.front, settings, 0.2 * dx);
  const int corner = state.layout.cellIndex(Eigen::Vector2i(15, 10));  // touched at its lower-left node
  EXPECT_FALSE(D.cutCell[corner]);
  EXPECT_LT(D.insideDof[corner], 0);
  EXPECT_GE(D.outsideDof[corner], 0);
  const TwoPhaseStepReport r = advanceTwoPhase(state, settings, 0.2 * dx);
  EXPECT_LT(r.maxSpeed, 1e-8);
}

TEST(SurfaceTensionStability, PressureJumpSchemeIsExplicitlyLimited) {
  // The comparison scheme of Figs. 6.6/6.7 (pressure_jump.h) on Sec. 6.4.6's circle at N = 32:
  // stable for 200 steps at 2x the explicit capillary limit (measured max speed 6.2e-4 m/s, the drop
  // at rest up to parasitic currents), unstable at 8x within a few steps (measured: step 5), like
  // the explicit front-tracked variant.
  const StabilityCase slow = runPressureJumpStabilityCase(32, 2 * stabilityCapillaryDt(32), false, 200);
  EXPECT_TRUE(slow.stable);
  EXPECT_LT(slow.maxSpeed, 2e-3);
  const StabilityCase fast = runPressureJumpStabilityCase(32, 8 * stabilityCapillaryDt(32), false, 500);
  EXPECT_FALSE(fast.stable);
  EXPECT_LT(fast.steps, 50);
}

TEST(SurfaceTensionStability, LevelSetCurvatureOfACircle) {
  // kappa = 1 / r from the signed distance of a circle, r = 10 dx: within 1 % at the cells near it.
  const MacLayout<2> layout(Eigen::Vector2i(40, 40), 0.025);
  std::vector<double> phi(layout.cellCount());
  for (int c = 0; c < layout.cellCount(); ++c)
    phi[c] = (layout.cellCenter(layout.cellCoord(c)) - Eigen::Vector2d(0.5, 0.5)).norm() - 0.25;
  const std::vector<double> kappa = levelSetCurvature(layout, phi);
  for (int c = 0; c < layout.cellCount(); ++c) {
    if (std::abs(phi[c]) > layout.dx) continue;
    const double r = phi[c] + 0.25;
    EXPECT_NEAR(kappa[c] * r, 1.0, 0.01);
  }
}

TEST(SurfaceTensionRisingBubble, EnoRk3LevelSetInCflSubsteps) {
  // The level-set-tracked bubble with ENO/RK3 at 40 x 80, dt = 3 s: the advection split into
  // substeps of CFL <= 0.9 (one surface-tension step) keeps the level set's mesh closed and the
  // speed bounded over 8 steps.
  const RisingBubbleStability r = runRisingBubbleStability(40, 3.0, true, 8, TwoPhaseAdvection::EnoRk3, true, 0.9);
  EXPECT_TRUE(r.stable) << r.reason;
  EXPECT_LT(r.maxSpeed, 0.02);
  EXPECT_LT(std::abs(r.areaChange), 0.05);
}
