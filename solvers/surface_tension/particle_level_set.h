#pragma once
// The particle level set of Enright, Fedkiw, Ferziger & Mitchell [47] (2002), in its semi-Lagrangian
// form (Enright, Losasso & Fedkiw 2005): marker particles on both sides of the interface correct the
// level set where its advection has lost area (thin or sharp features the grid cannot resolve).
//
// One step (particleLevelSetStep):
//  1. phi is advected semi-Lagrangianly (level_set_tracking.h), the particles by the midpoint rule
//     with the same velocity;
//  2. correction: a particle of sign s (s = +1 outside, phi > 0) whose s phi(x_p) < -r_p has escaped,
//     it is on the wrong side by more than its radius. Its sphere phi_p(x) = s (r_p - |x - x_p|)
//     rebuilds phi+ = max(phi+, phi_p) (s = +1) or phi- = min(phi-, phi_p) (s = -1) on the cells
//     around it; then phi = phi+ where |phi+| <= |phi-|, else phi-;
//  3. fast-marching redistancing (fast_marching.h), and the correction again;
//  4. each particle's radius becomes s phi(x_p) clamped to [rMin, rMax] (escaped ones keep theirs).
// Particles are seeded (seedParticles) in the cells within `seedBand` dx of the interface,
// `perCell` each at deterministic pseudo-random positions, attracted along the normal to a random
// level in [rMin, seedBand dx] on their side.
// Reseeding (after [47]; reseedParticles), every `reseedEvery` steps: a stretched interface leaves
// cells near it with few particles and a compressed one crowds them. Reseeding deletes the particles
// that have left the band (escaped ones too, when they are that far on the wrong side); then each
// band cell and sign has a target count, perCell times the share of the cell where that sign's
// levels [rMin, seedBand dx] lie (about the density of the first seeding). A cell with fewer than
// reseedSparse x target is filled up to it with new particles seeded as above, except where an older
// particle of the other sign lies nearer than the new one's level (phi has lost the shape there, and
// the new particle would assert the lost shape against the older one); one with more than
// reseedCrowded x target loses those farthest from the interface down to it. Escaped particles near
// the band are never deleted: they hold the features the grid lost, and deleting those escaped by
// more than 1.5 radii (Enright, Losasso & Fedkiw 2005) or every excess particle (hysteresis 1, 1)
// measured worse on the single vortex (docs/benchmarks_surface_tension.md). The kept particles keep
// their positions and radii.
#include <Eigen/Core>
#include <cstdint>
#include <utility>
#include <vector>

#include "solvers/mac_layout.h"

namespace monolith::solvers {

struct LevelSetParticle {
  Eigen::Vector2d x = Eigen::Vector2d::Zero();
  double radius = 0;
  int sign = 1;  // +1: outside (phi > 0), -1: inside
};

struct ParticleLevelSetSettings {
  int perCell = 16;                       // [47]: 16 per cell in 2-D
  double seedBand = 3;                    // seed in cells with |phi| < seedBand dx
  double minRadius = 0.1, maxRadius = 0.5;  // in dx
  double redistanceBand = 6;              // fast marching out to this many dx
  int reseedEvery = 0;                    // steps between reseedings; 0: never
  double reseedSparse = 0.5, reseedCrowded = 2;  // reseeding's hysteresis, in target counts
  std::uint32_t seed = 12345;             // the particles' pseudo-random positions (deterministic)
};

std::vector<LevelSetParticle> seedParticles(const MacLayout<2>& layout, const std::vector<double>& phi,
                                            const ParticleLevelSetSettings& settings = {});

// What reseedParticles changed.
struct ReseedReport {
  int added = 0, removedOutsideBand = 0, removedEscaped = 0, removedCrowded = 0;
};

// Reseeding (above) against a distance phi; `pass` (e.g. the step number) seeds the new particles'
// pseudo-random positions, so a run is deterministic and a resumed run reseeds as the straight one.
ReseedReport reseedParticles(const MacLayout<2>& layout, const std::vector<double>& phi,
                             std::vector<LevelSetParticle>& particles, std::uint64_t pass,
                             const ParticleLevelSetSettings& settings = {});

// Reseeding's target count of sign `sign` in cell c (0 outside the band or where that sign's levels
// cannot lie), and those levels.
int reseedTarget(const MacLayout<2>& layout, const std::vector<double>& phi, int c, int sign,
                 const ParticleLevelSetSettings& settings = {});
std::pair<double, double> reseedLevels(const MacLayout<2>& layout, const std::vector<double>& phi, int c, int sign,
                                       const ParticleLevelSetSettings& settings = {});

// The (cell, sign) pairs with a target, and how many hold fewer than reseedSparse x or more than
// reseedCrowded x it (escaped particles not counted): what reseeding keeps in bounds.
struct ParticleCountBounds {
  int counted = 0, sparse = 0, crowded = 0;
};
ParticleCountBounds particleCountBounds(const MacLayout<2>& layout, const std::vector<double>& phi,
                                        const std::vector<LevelSetParticle>& particles,
                                        const ParticleLevelSetSettings& settings = {});

// Step 2 above; returns the number of escaped particles that changed phi.
int correctWithParticles(const MacLayout<2>& layout, const std::vector<LevelSetParticle>& particles,
                         std::vector<double>& phi);

// Step 4 above.
void adjustParticleRadii(const MacLayout<2>& layout, const std::vector<double>& phi, std::vector<LevelSetParticle>& particles,
                         const ParticleLevelSetSettings& settings = {});

// Moves the particles by the midpoint rule through the face velocities u (kept inside the domain).
void advectParticles(const MacLayout<2>& layout, const Eigen::VectorXd& u, double dt, std::vector<LevelSetParticle>& particles);

// The whole step through the face velocities u (layout.faceIndex order); returns the escaped count of
// the first correction.
int particleLevelSetStep(const MacLayout<2>& layout, const Eigen::VectorXd& u, double dt, std::vector<double>& phi,
                         std::vector<LevelSetParticle>& particles, const ParticleLevelSetSettings& settings = {});

}  // namespace monolith::solvers
