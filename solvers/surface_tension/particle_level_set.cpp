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

// The cell whose square holds x (clamped to the grid).
int cellContaining(const MacLayout<2>& layout, const Eigen::Vector2d& x) {
  const Eigen::Vector2d g = (x - layout.origin) / layout.dx;
  const int i = std::clamp(static_cast<int>(std::floor(g.x())), 0, layout.cells.x() - 1);
  const int j = std::clamp(static_cast<int>(std::floor(g.y())), 0, layout.cells.y() - 1);
  return layout.cellIndex(Eigen::Vector2i(i, j));
}

// Moves p along the normal of phi toward the level `goal` on its side ([47], Sec. 3.1); true when it
// ends with its level s phi in [low, high].
bool attractToLevel(const MacLayout<2>& layout, const std::vector<double>& phi, LevelSetParticle& p, double goal, double low,
                    double high) {
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
  return level >= low && level <= high;
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
      if (!attractToLevel(layout, phi, p, goal, low, high)) continue;
      p.radius = std::clamp(p.sign * sampleCellField(layout, phi, p.x), settings.minRadius * dx, settings.maxRadius * dx);
      particles.push_back(p);
    }
  }
  return particles;
}

// The levels s phi a particle of sign s can take in cell c: a distance changes by about dx across a
// cell, so [s phi_c - dx/2, s phi_c + dx/2] within [rMin, seedBand dx].
std::pair<double, double> reseedLevels(const MacLayout<2>& layout, const std::vector<double>& phi, int c, int sign,
                                       const ParticleLevelSetSettings& settings) {
  const double dx = layout.dx, centre = sign * phi[c];
  return {std::max(settings.minRadius * dx, centre - 0.5 * dx), std::min(settings.seedBand * dx, centre + 0.5 * dx)};
}

int reseedTarget(const MacLayout<2>& layout, const std::vector<double>& phi, int c, int sign,
                 const ParticleLevelSetSettings& settings) {
  // The levels' length over dx is the share of the cell where such particles live, and perCell
  // times it their target count there: the density the first seeding leaves (each band cell seeds
  // perCell/2 of each sign over about 2 seedBand cells of levels, so about perCell per cell on each side).
  if (!(std::abs(phi[c]) < (settings.seedBand + 0.5) * layout.dx)) return 0;
  const auto [from, to] = reseedLevels(layout, phi, c, sign, settings);
  return to > from ? static_cast<int>(std::lround(settings.perCell * (to - from) / layout.dx)) : 0;
}

ParticleCountBounds particleCountBounds(const MacLayout<2>& layout, const std::vector<double>& phi,
                                        const std::vector<LevelSetParticle>& particles, const ParticleLevelSetSettings& settings) {
  ParticleCountBounds bounds;
  std::vector<int> count(2 * static_cast<std::size_t>(layout.cellCount()), 0);
  for (const LevelSetParticle& p : particles) {
    if (p.sign * sampleCellField(layout, phi, p.x) < 0) continue;  // escaped: not counted
    ++count[2 * cellContaining(layout, p.x) + (p.sign > 0)];
  }
  for (int c = 0; c < layout.cellCount(); ++c)
    for (int side = 0; side < 2; ++side) {
      const int want = reseedTarget(layout, phi, c, side ? 1 : -1, settings), have = count[2 * c + side];
      if (want == 0) continue;
      ++bounds.counted;
      if (have < settings.reseedSparse * want) ++bounds.sparse;
      if (have > settings.reseedCrowded * want) ++bounds.crowded;
    }
  return bounds;
}

ReseedReport reseedParticles(const MacLayout<2>& layout, const std::vector<double>& phi,
                             std::vector<LevelSetParticle>& particles, std::uint64_t pass,
                             const ParticleLevelSetSettings& settings) {
  const double dx = layout.dx, low = settings.minRadius * dx, high = settings.seedBand * dx;
  ReseedReport report;
  auto cellOf = [&layout](const Eigen::Vector2d& x) { return cellContaining(layout, x); };
  auto target = [&](int c, int sign) { return reseedTarget(layout, phi, c, sign, settings); };

  // Delete the particles outside the band (escaped ones too, when that far on the wrong side).
  std::vector<double> level(particles.size());
  std::vector<char> drop(particles.size(), 0);
  for (std::size_t k = 0; k < particles.size(); ++k) {
    const LevelSetParticle& p = particles[k];
    level[k] = p.sign * sampleCellField(layout, phi, p.x);
    if (std::abs(level[k]) > high + settings.maxRadius * dx) {
      drop[k] = 1;
      ++(level[k] < 0 ? report.removedEscaped : report.removedOutsideBand);
    }
  }
  // Crowded cells lose the particles farthest from the interface, down to the target (escaped ones
  // are never counted or deleted here).
  std::vector<std::vector<std::size_t>> members(2 * static_cast<std::size_t>(layout.cellCount()));
  for (std::size_t k = 0; k < particles.size(); ++k)
    if (!drop[k] && level[k] >= 0) members[2 * cellOf(particles[k].x) + (particles[k].sign > 0)].push_back(k);
  std::vector<int> count(members.size(), 0);
  for (int c = 0; c < layout.cellCount(); ++c)
    for (int side = 0; side < 2; ++side) {
      std::vector<std::size_t>& m = members[2 * c + side];
      const int want = target(c, side ? 1 : -1);
      if (static_cast<int>(m.size()) > settings.reseedCrowded * want) {
        std::stable_sort(m.begin(), m.end(), [&](std::size_t a, std::size_t b) { return level[a] > level[b]; });
        for (std::size_t q = 0; q < m.size() - static_cast<std::size_t>(want); ++q) drop[m[q]] = 1, ++report.removedCrowded;
      }
      count[2 * c + side] = std::min(static_cast<int>(m.size()), want);
    }
  std::size_t kept = 0;
  for (std::size_t k = 0; k < particles.size(); ++k)
    if (!drop[k]) particles[kept++] = particles[k];
  particles.resize(kept);

  // Add: sparse cells are filled up to the target with new particles at pseudo-random positions in
  // them, attracted to a level they can take there, unless an older particle contradicts them. The
  // generator starts from the seed and the pass, so the positions depend on nothing else (threads,
  // restarts). The older particles by cell, for that test:
  const std::size_t existing = particles.size();
  std::vector<std::vector<int>> inCell(layout.cellCount());
  for (std::size_t k = 0; k < existing; ++k) inCell[cellOf(particles[k].x)].push_back(static_cast<int>(k));
  // True when an existing particle of the other sign lies within `reach` of x. A new particle at
  // level l says the interface is l away; an older particle of the other sign nearer than that says
  // phi has lost the shape there, and the new particle would hold the lost shape against it.
  auto contradicted = [&](const Eigen::Vector2d& x, int sign, double reach) {
    const Eigen::Vector2d g = (x - layout.origin) / dx;
    const int ci = static_cast<int>(std::floor(g.x())), cj = static_cast<int>(std::floor(g.y()));
    const int span = static_cast<int>(std::ceil(reach / dx));
    for (int j = std::max(0, cj - span); j <= std::min(layout.cells.y() - 1, cj + span); ++j)
      for (int i = std::max(0, ci - span); i <= std::min(layout.cells.x() - 1, ci + span); ++i)
        for (int k : inCell[layout.cellIndex(Eigen::Vector2i(i, j))])
          if (particles[k].sign != sign && (particles[k].x - x).norm() < reach) return true;
    return false;
  };
  std::seed_seq sequence{settings.seed, static_cast<std::uint32_t>(pass), static_cast<std::uint32_t>(pass >> 32)};
  std::mt19937 random(sequence);
  auto uniform = [&random] { return random() * (1.0 / 4294967296.0); };
  for (int c = 0; c < layout.cellCount(); ++c)
    for (int side = 0; side < 2; ++side) {
      const int sign = side ? 1 : -1, want = target(c, sign);
      const auto [from, to] = reseedLevels(layout, phi, c, sign, settings);
      const Eigen::Vector2d corner = layout.origin + dx * layout.cellCoord(c).cast<double>();
      if (count[2 * c + side] >= settings.reseedSparse * want) continue;
      for (int k = count[2 * c + side]; k < want; ++k) {
        LevelSetParticle p;
        p.sign = sign;
        p.x = corner + dx * Eigen::Vector2d(uniform(), uniform());
        const double goal = sign * (from + (to - from) * uniform());
        if (!attractToLevel(layout, phi, p, goal, low, high)) continue;
        const double level = sign * sampleCellField(layout, phi, p.x);
        if (contradicted(p.x, sign, level)) continue;
        p.radius = std::clamp(level, settings.minRadius * dx, settings.maxRadius * dx);
        particles.push_back(p);
        ++report.added;
      }
    }
  return report;
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
