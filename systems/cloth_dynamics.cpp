#include "systems/cloth_dynamics.h"

#include <limits>

#include "solvers/deformable/cloth.h"
#include "solvers/deformable/stable_step.h"
#include "systems/deformable_dynamics.h"

namespace monolith {

namespace dm = solvers::deformable;

const dm::ForceModel<3>& ClothForceModels::get(Entity e, const Particles<3>& p, const ClothMesh& mesh,
                                               const ClothMaterial& material) {
  const std::uint64_t key = (std::uint64_t(e.index) << 32) | e.generation;
  auto it = models_.find(key);
  if (it == models_.end()) {
    dm::ClothParameters params;
    params.density = material.density;
    params.stretchStiffness = material.stretchStiffness;
    params.bendStiffness = material.bendStiffness;
    params.overdamping = material.overdamping;
    params.rayleighAlpha = material.rayleighAlpha;
    // The state's masses are authoritative (also for the springs' critical damping).
    it = models_.emplace(key, dm::clothForceModel(mesh.restX, mesh.triangles, params, p.m)).first;
  }
  return it->second;
}

void AdvanceClothVelocity::run(World<3>& world, StepContext& ctx) {
  const bool half = stage_ == Stage::AdvanceVelocityHalf;
  const Vec<3> g = world.settings().gravity;
  int iterations = 0;
  world.each<Particles<3>, ClothMesh, ClothMaterial>(
      [&](Entity e, Particles<3>& p, ClothMesh& mesh, ClothMaterial& material) {
        const auto& fm = cache_.get(e, p, mesh, material);
        const std::vector<double> f = explicitForces<3>(fm, p, g);
        std::vector<double> u;
        // Step I: h = dt/2; Step V: backward Euler over dt/4 to the average, then extrapolated.
        const double h = half ? 0.5 * ctx.dt : 0.25 * ctx.dt;
        const ImplicitSolveReport r = implicitDampingSolve<3>(fm, p, f, h, u);
        iterations = std::max(iterations, r.iterations);
        if (half) p.v = u;
        else
          for (std::size_t i = 0; i < u.size(); ++i) p.v[i] = 2 * u[i] - p.v[i];
      });
  ctx.diagnostics.max(half ? "cloth_cg_iterations_half" : "cloth_cg_iterations", iterations);
}

double AdvanceClothVelocity::unitCflDt(const World<3>& world) const {
  double dt = std::numeric_limits<double>::infinity();
  if (stage_ != Stage::AdvanceVelocityHalf) return dt;
  const auto* pool = world.findPool<ClothMesh>();
  if (!pool) return dt;
  for (std::size_t k = 0; k < pool->size(); ++k) {
    const Entity e = pool->entities()[k];
    const auto* p = world.get<Particles<3>>(e);
    const auto* material = world.get<ClothMaterial>(e);
    if (!p || !material) continue;
    const auto& fm = cache_.get(e, *p, pool->components()[k], *material);
    dt = std::min(dt, dm::stableStep<3>(fm, material->density, p->x.data(), p->v.data(), p->fixed).value());
  }
  return dt;
}

void ClothDiagnostics::run(World<3>& world, StepContext& ctx) {
  double energy = 0;
  world.each<Particles<3>, ClothMesh, ClothMaterial>(
      [&](Entity e, Particles<3>& p, ClothMesh& mesh, ClothMaterial& material) {
        energy += dm::elasticEnergy<3>(cache_.get(e, p, mesh, material), p.x.data());
      });
  ctx.diagnostics.add("potential_energy", energy);
  ctx.diagnostics.add("total_energy", energy);
  ctx.diagnostics.set("cloth_elastic_energy", energy);
}

}  // namespace monolith
