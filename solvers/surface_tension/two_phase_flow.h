#pragma once
// Two-phase (or one-phase) incompressible flow on a 2-D MAC grid with surface tension on a
// Lagrangian front, implicit in the coupled SPD system of thesis eq. (6.33):
//     (P + K beta^-1 K^T) z = K u*,   K = (G^T; G_mu; C H),   u^{n+1} = u* - beta^-1 K^T z.
//
// Eulerian discretization (Sec. 6.3.3-6.3.4). Cells the front passes through are cut cells; each
// gets a coupling face, the chord from where the front enters the cell to where it leaves, whose
// area-weighted outward normal n_i = sum (beta - alpha) R (x_{k+1} - x_k) is the sum over the front's
// pieces in the cell (R = [[0, 1], [-1, 0]]), with one velocity unknown along n_i.
//  * One phase: a pressure in every inside and cut cell, Dirichlet p = 0 (air) outside the
//    coupling faces; velocity unknowns on the grid faces with an inside part and on the coupling faces.
//  * Two phase: cut cells carry an inside and an outside pressure; every interior grid face and every
//    coupling face carries a velocity (continuous across the front).
//  * G: the entry of face f for (the inside or outside part of) cell c is +-(length of f's part in
//    that phase), + when u_f flows into the part; a coupling face leaves the inside part (-l) and
//    enters the outside part (+l).
//  * beta: (rho l + rho' l') dx on grid faces (rho' = 0 in one phase), 1/2 l dx (rho + rho') on
//    coupling faces. First order (Sec. 6.3.4).
//  * G_mu: central differences between neighbouring same-axis grid faces, w = sqrt(dt mu) (2-D),
//    no-slip walls by the mirrored ghost (as solvers/fluid/operators.h); in one phase pairs that
//    reach into the air are dropped (the first-order stress-free condition). Viscosity is the
//    same in both phases (an implicit viscosity jump is not what (6.33) factors).
// Lagrangian part (Sec. 6.3.2, 6.3.5):
//  * f_e,k = sigma (t_{k+1/2} - t_{k-1/2}) (6.35/6.36), applied explicitly through H^T into u*;
//  * H^T: the force density f_k / l_k (6.37), linear along each segment, integrated over the
//    segment's part [alpha, beta] in cell i and projected on n^_i: the force on coupling face i.
//    Its entries are (6.38) with the length ratio l_{k+-1/2} / l_k (the printed l_k / l_{k+-1/2}
//    does not conserve the total force; this one does: every particle's weights sum to 1);
//    H = (H^T)^T interpolates coupling-face normal velocities to the particles (normal only);
//  * C: per segment, C_{k,k} = -C_{k,k+1} = dt sqrt(sigma / l) n^T (C^T C = -dt D, D the normal-only
//    force derivative); the explicit variant drops the C H rows (D = C = 0).
// Time step: advection of the grid face velocities (semi-Lagrangian or ENO/RK3), gravity, the explicit
// force, the solve, then the front moves with x^{n+1} = x^n + dt H u^{n+1} and is remeshed.
// Walls bound the domain on all sides (normal velocity 0, no-slip for the viscous rows).
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <string>
#include <vector>

#include "solvers/fluid/krylov.h"
#include "solvers/mac_layout.h"
#include "solvers/surface_tension/front.h"
#include "solvers/surface_tension/particle_level_set.h"

namespace monolith::solvers {

// The convective step of the grid velocities (and of a level-set-tracked front's phi): none,
// semi-Lagrangian (solvers/advection/semi_lagrangian.h; unconditionally stable), or the thesis's
// third-order Hamilton-Jacobi ENO with TVD RK3 (Sec. 6.3; solvers/advection/eno.h; stable for
// CFL numbers up to about 1).
enum class TwoPhaseAdvection { None, SemiLagrangian, EnoRk3 };

// How a level-set-tracked front's phi is made a distance again after it moved (the cells within
// TwoPhaseSettings::levelSetKeep dx keep their values): the exact distance to the rebuilt mesh
// (level_set_tracking.h), fast marching from the kept cells (fast_marching.h), or not at all.
enum class LevelSetRedistancing { ToMesh, FastMarching, None };

struct TwoPhaseSettings {
  double densityInside = 1;   // rho: the phase the front's loops enclose
  double densityOutside = 1;  // rho': ignored in one phase
  bool onePhase = false;
  double viscosity = 0;  // mu, both phases
  double sigma = 0;      // surface tension coefficient
  bool implicitSurfaceTension = true;  // false: the explicit variant, D = C = 0
  Eigen::Vector2d gravity = Eigen::Vector2d::Zero();
  TwoPhaseAdvection advection = TwoPhaseAdvection::SemiLagrangian;
  // ENO/RK3 only: 0 advects in one step whatever the CFL number (as the thesis, whose ENO runs are
  // CFL-limited); > 0 splits the advection into substeps of at most this CFL number (the surface
  // tension step stays one step).
  double advectionCfl = 0;
  bool remesh = true;                         // front tracking: remesh after every step (Sec. 6.3.1)
  double minSegment = 0.5, maxSegment = 1.5;  // remeshing bounds, in dx
  CgSettings solve{20000, 1e-12, 0};
  double blowUpSpeed = 1e3;  // the guard: a step whose max speed exceeds this (or is not finite) blew up
  // Level-set-tracked front (level_set_tracking.h): the front is rebuilt from TwoPhaseState::phi
  // each step and phi, not the points, is advected. Else front tracking.
  bool levelSetFront = false;
  // Level-set-tracked front, beyond the thesis (its future work, Sec. 6.5): instead of advecting phi
  // with the grid velocity, move the mesh's points with the coupled solve's Lagrangian velocity
  // H u^{n+1}, as front tracking does (the update the force derivatives assume, backward-Euler
  // like), and set phi to the signed distance to the moved mesh. The next step's mesh is rebuilt
  // from that phi as usual.
  bool levelSetImplicitUpdate = false;
  LevelSetRedistancing levelSetRedistancing = LevelSetRedistancing::ToMesh;
  // In dx; 0 re-initialises every cell (the fast marching of [47]). The crossing stencils read phi up
  // to about 3 cells from the front, and any redistancing there moves the mesh points by an O(dx^2)
  // that varies from point to point: O(1) curvature noise, parasitic currents that do not converge
  // (docs/benchmarks_surface_tension.md). 3 keeps every value the stencils read.
  double levelSetKeep = 3;
  // Two phases only, in dx: the rebuilt mesh puts the crossings next to a grid node whose level-set
  // value is within this of zero on the node itself (frontFromLevelSet's nodeSnap). A front passing
  // a node at a tiny distance cuts the corner cells into tiny parts; in two phases that made the
  // static circle's current grow steadily at 1/dx = 40 (L1 linearly from the start). In one phase
  // the snapped configuration (a front through a node) measured worse, so it is not used there
  // (docs/benchmarks_surface_tension.md). 0 turns it off.
  double levelSetNodeSnap = 1e-4;
  // The particle level set [47] (particle_level_set.h) corrects the advected phi before and after
  // redistancing; its particles live in TwoPhaseState::levelSetParticles (seeded on the first step,
  // reseeded every particleSettings.reseedEvery steps, counted by TwoPhaseState::step).
  bool particleLevelSet = false;
  ParticleLevelSetSettings particleSettings;
  // Front tracking, beyond the thesis (which does not say where a coupling face's u* comes from):
  // false samples it from the grid velocity each step, which discards the last solve's coupling
  // velocities and damps the interface's motion by a fixed amount per step (more steps, more
  // damping: docs/benchmarks_surface_tension.md, Table 6.4). true carries them on the front: the
  // points keep H u^n, and a coupling face's u* is n^_i . (the H^T-weighted mean of its points'
  // velocities). After a remesh that changed the points, one step samples the grid again.
  bool carryCouplingVelocity = false;
};

struct TwoPhaseState {
  MacLayout<2> layout;
  Eigen::VectorXd u;                  // grid face velocities (layout.faceIndex order)
  Front2 front;
  std::vector<double> pInside, pOutside;  // per cell: the phase's pressure (0 where it has none)
  std::vector<double> phi;                // level-set-tracked fronts: signed distance per cell
  std::vector<Eigen::Vector2d> pointVelocity;  // carryCouplingVelocity: H u^n per front point, else empty
  std::vector<LevelSetParticle> levelSetParticles;  // particleLevelSet: the marker particles
  double time = 0;
  int step = 0;
};

// A state at rest with the front given; the layout's axes must not be periodic.
TwoPhaseState makeTwoPhaseState(const MacLayout<2>& layout, Front2 front);

// The discretization of one step, exposed for tests.
struct InterfaceDiscretization {
  std::vector<int> insideDof, outsideDof;  // per cell: pressure unknown of the phase, -1 if none
  std::vector<char> cutCell;
  std::vector<double> insideLength;        // per grid face: length of its inside part
  std::vector<int> faceUnknown;            // per grid face: velocity unknown, -1 if none
  int gridUnknowns = 0;                    // unknowns [0, gridUnknowns) are grid faces, the rest coupling faces
  std::vector<int> unknownFace;            // grid-face unknowns -> face index
  std::vector<int> couplingCell;           // coupling unknowns (offset gridUnknowns) -> cell
  std::vector<Eigen::Vector2d> couplingNormal;  // unit normals n^_i
  std::vector<double> couplingLength;
  std::vector<Eigen::Vector2d> couplingCentre;
  int pressureCount = 0;
  Eigen::VectorXd beta;          // per velocity unknown
  Eigen::SparseMatrix<double> G;   // velocity unknowns x pressure unknowns
  Eigen::SparseMatrix<double> Gmu; // viscous rows x velocity unknowns
  Eigen::SparseMatrix<double> Ht;  // velocity unknowns x 2 * front points (nonzero on coupling rows only)
  Eigen::SparseMatrix<double> CH;  // segments x velocity unknowns (empty when explicit)
  int unknowns() const { return static_cast<int>(beta.size()); }
};

InterfaceDiscretization discretizeInterface(const MacLayout<2>& layout, const Front2& front,
                                            const TwoPhaseSettings& settings, double dt);

struct TwoPhaseStepReport {
  CgReport solve;
  double maxSpeed = 0;        // max |u| over the grid faces after the step
  double cfl = 0;             // maxSpeed dt / dx
  double capillaryDt = 0;     // sqrt((rho + rho') dx^3 / (4 pi sigma)) (Brackbill et al.)
  double pressureJump = 0;    // mean inside minus mean outside pressure, uncut cells only
  double area = 0;            // enclosed by the front after the step
  int remeshChanges = 0;
  int cutCells = 0;
  bool blewUp = false;
  std::string blowUpReason;   // names the variant, the step and the limits when blewUp
};

TwoPhaseStepReport advanceTwoPhase(TwoPhaseState& state, const TwoPhaseSettings& settings, double dt);

// Bilinear sample of velocity component `axis` at x (clamped to the domain).
double sampleFaceVelocity(const MacLayout<2>& layout, const Eigen::VectorXd& u, int axis, const Eigen::Vector2d& x);

// Parasitic-current norms of Sec. 6.4.2: L1 = mean |u_f|, Linf = max |u_f| over all faces.
std::pair<double, double> velocityNorms(const Eigen::VectorXd& u);

}  // namespace monolith::solvers
