#include "solvers/surface_tension/particle_level_set.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "solvers/surface_tension/fast_marching.h"
#include "solvers/surface_tension/level_set_tracking.h"
#include "solvers/surface_tension/two_phase_flow.h"

namespace monolith::solvers {

namespace {
Eigen::Vector2d gradientAt(const MacLayout<2>& layout, const std::vector<double>& phi, const Eigen::Vector2d& x) {
  const double h = layout.dx;
  const Eigen::Vector2d ex(h, 0), ey(0, h);
  return Eigen::Vector2d(sampleCellField(layout, phi, x + ex) - sampleCellField(layout, phi, x - ex),
                         sampleCellField(layout, phi, x + ey) - sampleCellField(layout, phi, x - ey)) /
         (2 * h);
}
Eigen::Vector2d velocityAt(const MacLayout<2>& layout, const Eigen::VectorXd& u, const Eigen::Vector2d& x) {
  return {sampleFaceVelocity(layout, u, 0, x), sampleFaceVelocity(layout, u, 1, x)};
}
Eigen::Vector2d clampToDomain(const MacLayout<2>& layout, const Eigen::Vector2d& x) {
  const Eigen::Vector2d upper = layout.origin + layout.dx * layout.cells.cast<double>();
  return x.cwiseMax(layout.origin).cwiseMin(upper);
}
}  // namespace

std::vector<LevelSetParticle> seedParticles(const MacLayout<2>& layout, const std::vector<double>& phi,
                                            const ParticleLevelSetSettings& settings) {
  const double dx = layout.dx, low = settings.minRadius * dx, high = settings.seedBand * dx;
  std::mt19937 random(settings.seed);  // mt19937's sequence is fixed by the standard
  auto uniform = [&random] { return random() * (1.0 / 4294967296.0); };
  std::vector<LevelSetParticle> particles;
  for (int c = 0; c < layout.cellCount(); ++c) {
    if (!(std::abs(phi[c]) < high)) continue;
    const Eigen::Vector2d corner = layout.origin + dx * layout.cellCoord(c).cast<double>();
    for (int k = 0; k < settings.perCell; ++k) {
      LevelSetParticle p;
      p.sign = k % 2 == 0 ? 1 : -1;
      p.x = corner + dx * Eigen::Vector2d(uniform(), uniform());
      const double goal = p.sign * (low + (high - low) * uniform());
      // Attraction along the normal to the goal level ([47], Sec. 3.1).
      double lambda = 1;
      for (int it = 0; it < 15; ++it) {
        const double value = sampleCellField(layout, phi, p.x);
        const double level = p.sign * value;
        if (level >= low && level <= high) break;
        const Eigen::Vector2d g = gradientAt(layout, phi, p.x);
        const double norm = g.norm();
        if (!(norm > 0)) break;
        p.x = clampToDomain(layout, p.x + lambda * (goal - value) * g / norm);
        lambda *= 0.5;
      }
      const double level = p.sign * sampleCellField(layout, phi, p.x);
      if (level < low || level > high) continue;
      p.radius = std::clamp(level, settings.minRadius * dx, settings.maxRadius * dx);
      particles.push_back(p);
    }
  }
  return particles;
}

int correctWithParticles(const MacLayout<2>& layout, const std::vector<LevelSetParticle>& particles, std::vector<double>& phi) {
  std::vector<double> plus = phi, minus = phi;
  int escaped = 0;
  const int nx = layout.cells.x(), ny = layout.cells.y();
  for (const LevelSetParticle& p : particles) {
    if (!(p.sign * sampleCellField(layout, phi, p.x) < -p.radius)) continue;
    ++escaped;
    // The cells of the bilinear stencil around the particle.
    const Eigen::Vector2d g = (p.x - layout.origin) / layout.dx - Eigen::Vector2d::Constant(0.5);
    const int i0 = static_cast<int>(std::floor(g.x())), j0 = static_cast<int>(std::floor(g.y()));
    for (int j = std::max(0, j0); j <= std::min(ny - 1, j0 + 1); ++j)
      for (int i = std::max(0, i0); i <= std::min(nx - 1, i0 + 1); ++i) {
        const Eigen::Vector2i cell(i, j);
        const int c = layout.cellIndex(cell);
        const double sphere = p.sign * (p.radius - (layout.cellCenter(cell) - p.x).norm());
        if (p.sign > 0) plus[c] = std::max(plus[c], sphere);
        else minus[c] = std::min(minus[c], sphere);
      }
  }
  for (std::size_t c = 0; c < phi.size(); ++c) phi[c] = std::abs(plus[c]) <= std::abs(minus[c]) ? plus[c] : minus[c];
  return escaped;
}

void adjustParticleRadii(const MacLayout<2>& layout, const std::vector<double>& phi, std::vector<LevelSetParticle>& particles,
                         const ParticleLevelSetSettings& settings) {
  for (LevelSetParticle& p : particles) {
    const double level = p.sign * sampleCellField(layout, phi, p.x);
    if (level < -p.radius) continue;  // still escaped: keeps its radius
    p.radius = std::clamp(level, settings.minRadius * layout.dx, settings.maxRadius * layout.dx);
  }
}

void advectParticles(const MacLayout<2>& layout, const Eigen::VectorXd& u, double dt, std::vector<LevelSetParticle>& particles) {
  for (LevelSetParticle& p : particles) {
    const Eigen::Vector2d mid = p.x + 0.5 * dt * velocityAt(layout, u, p.x);
    p.x = clampToDomain(layout, p.x + dt * velocityAt(layout, u, mid));
  }
}

int particleLevelSetStep(const MacLayout<2>& layout, const Eigen::VectorXd& u, double dt, std::vector<double>& phi,
                         std::vector<LevelSetParticle>& particles, const ParticleLevelSetSettings& settings) {
  phi = advectCellField(layout, phi, u, dt);
  advectParticles(layout, u, dt, particles);
  const int escaped = correctWithParticles(layout, particles, phi);
  fastMarchingRedistance(layout, phi, settings.redistanceBand);
  correctWithParticles(layout, particles, phi);
  adjustParticleRadii(layout, phi, particles, settings);
  return escaped;
}

}  // namespace monolith::solvers
