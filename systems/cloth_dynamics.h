#pragma once
// The Newmark stages of Ch. 4 for cloth (components/cloth.h): the same Steps I and V as the
// deformable solids (systems/deformable_dynamics.h) with the cloth's spring force model —
// explicit spring forces and gravity, implicit spring and mass damping by CG, fixed and bound
// particles prescribed and projected out of the solve. Step IV, the contact with rigid bodies
// and the bindings are the deformables' own systems (they act on every Particles<3>).
#include <cstdint>
#include <unordered_map>

#include "components/cloth.h"
#include "components/deformable.h"
#include "ecs/system.h"
#include "solvers/deformable/elasticity.h"

namespace monolith {

// One spring force model per cloth (the rest data never changes).
class ClothForceModels {
 public:
  const solvers::deformable::ForceModel<3>& get(Entity e, const Particles<3>& p, const ClothMesh& mesh,
                                                const ClothMaterial& material);

 private:
  std::unordered_map<std::uint64_t, solvers::deformable::ForceModel<3>> models_;
};

class AdvanceClothVelocity final : public System<3> {
 public:
  explicit AdvanceClothVelocity(Stage s) : stage_(s) {}
  std::string name() const override {
    return stage_ == Stage::AdvanceVelocityHalf ? "advance_cloth_velocity_half" : "advance_cloth_velocity";
  }
  Stage stage() const override { return stage_; }
  std::vector<std::string> reads() const override { return {ClothMesh::kName, ClothMaterial::kName}; }
  std::vector<std::string> writes() const override { return {Particles<3>::kName, "diagnostics"}; }
  bool needed(const World<3>& w) const override { return w.count<ClothMesh>() > 0; }
  void run(World<3>& world, StepContext& ctx) override;
  // The springs' explicit limit sqrt(2 m / K) and the motion limit (solvers/deformable/stable_step.h).
  double unitCflDt(const World<3>& world) const override;

 private:
  Stage stage_;
  mutable ClothForceModels cache_;
};

// The cloth's spring energy, added to the standard potential and total energy columns
// (its particles' kinetic and gravitational energy and momenta are counted by
// deformable_diagnostics with every other particle); "cloth_elastic_energy".
class ClothDiagnostics final : public System<3> {
 public:
  std::string name() const override { return "cloth_diagnostics"; }
  Stage stage() const override { return Stage::Diagnostics; }
  std::vector<std::string> reads() const override {
    return {Particles<3>::kName, ClothMesh::kName, ClothMaterial::kName};
  }
  std::vector<std::string> writes() const override { return {"diagnostics"}; }
  bool needed(const World<3>& w) const override { return w.count<ClothMesh>() > 0; }
  void run(World<3>& world, StepContext& ctx) override;

 private:
  ClothForceModels cache_;
};

}  // namespace monolith
