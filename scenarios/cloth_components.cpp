#include "scenarios/cloth_components.h"

#include <Eigen/Geometry>

#include "components/cloth.h"
#include "components/deformable.h"
#include "components/surface_collision.h"
#include "scenarios/deformable_components.h"
#include "solvers/deformable/cloth.h"
#include "systems/cloth_dynamics.h"
#include "systems/deformable_self_collision.h"
#include "systems/rigid_surface_contact.h"

namespace monolith {

namespace {

namespace dm = solvers::deformable;

// "mesh": {"sheet": {"half_extents": [a, b], "edge_length": h}}: a rectangle in the local
// xz-plane, normal +y.
dm::ClothMeshData parseClothMesh(const Config& c) {
  if (!c.has("sheet")) c.fail("a cloth mesh form: sheet {half_extents [a, b], edge_length}", "none");
  const Config s = c.child("sheet");
  const Eigen::VectorXd half = s.vector("half_extents", 2, Bound::Positive);
  const double h = s.number("edge_length", Bound::Positive);
  s.finish();
  if (2 * half.maxCoeff() / h > 1000) s.failAt("edge_length", "at most 1000 cells per side", std::to_string(h));
  return dm::sheetMesh(half(0), half(1), h);
}

void parseCloth(World<3>& world, Entity e, const Config& c) {
  const Config meshConfig = c.child("mesh");
  const dm::ClothMeshData mesh = parseClothMesh(meshConfig);
  meshConfig.finish();
  if (const std::string problem = dm::clothProblem(mesh); !problem.empty())
    c.failAt("mesh", "a valid triangle mesh", problem);
  ClothMaterial material;
  material.density = c.number("density", 0.1, Bound::Positive);
  material.stretchStiffness = c.number("stretch_stiffness", Bound::Positive);
  material.bendStiffness = c.number("bend_stiffness", 0.0, Bound::NonNegative);
  material.overdamping = c.number("overdamping", 0.0, Bound::NonNegative);
  material.rayleighAlpha = c.number("rayleigh_alpha", 0.0, Bound::NonNegative);

  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  if (c.has("orientation")) {
    const Eigen::VectorXd q = c.vector("orientation", 4);
    if (q.norm() < 1e-12) c.failAt("orientation", "a non-zero quaternion [w, x, y, z]", "a zero quaternion");
    R = Eigen::Quaterniond(q(0), q(1), q(2), q(3)).normalized().toRotationMatrix();
  }
  const Vec<3> position = c.vector("position", Eigen::VectorXd::Zero(3));
  const Vec<3> velocity = c.vector("velocity", Eigen::VectorXd::Zero(3));
  Particles<3> p;
  ClothMesh cm;
  cm.triangles = mesh.triangles;
  for (const auto& x : mesh.x) {
    const Vec<3> w = R * x + position;
    for (int a = 0; a < 3; ++a) {
      p.x.push_back(w(a));
      p.v.push_back(velocity(a));
      cm.restX.push_back(w(a));
    }
  }
  p.fixed.assign(mesh.x.size(), 0);
  p.m = dm::clothMasses(cm.restX, cm.triangles, material.density);
  parseFixedParticles<3>(c, p);
  parseRigidBindings<3>(world, e, c, p, false);
  world.add(e, p);
  world.add(e, cm);
  world.add(e, material);
}

template <int d>
void parseSurfaceCollision(World<d>& world, Entity e, const Config& c) {
  if (!world.template has<SimplexMesh<d>>(e) && !world.template has<ClothMesh>(e))
    c.fail("surface_collision on an entity with a \"deformable\" or \"cloth\" entry", "an entity without either");
  SurfaceCollision s;
  s.thickness = c.number("thickness", Bound::Positive);
  s.friction = c.number("friction", 0.0, Bound::NonNegative);
  // Cloth folds onto itself; a solid's own surface meets itself only through large deformations,
  // and its snapped surface vertices may lie closer than the thickness to their neighbours.
  s.self = c.boolean("self", world.template has<ClothMesh>(e)) ? 1 : 0;
  world.add(e, s);
}

}  // namespace

void registerClothComponents(Registry& r) {
  r.addComponent<3>(ComponentType<3>{
      "cloth",
      "cloth (triangle shell of springs): mesh {sheet {half_extents [a, b], edge_length}}, density (kg/m^2), "
      "stretch_stiffness, bend_stiffness (N/m per spring), overdamping, rayleigh_alpha, position, orientation, "
      "velocity, fixed [{min, max}], bind [{body (static or kinematic), min, max}]",
      parseCloth,
      [](World<3>& w) {
        w.ensurePool<Particles<3>>();
        w.ensurePool<ClothMesh>();
        w.ensurePool<ClothMaterial>();
        w.ensurePool<RigidBinding<3>>();
      },
      ""});
  r.addComponentOf<3, ClothMesh>("(internal) a cloth's triangles and rest positions", nullptr);
  r.addComponentOf<3, ClothMaterial>("(internal) a cloth's areal density, spring stiffnesses and damping", nullptr);
}

template <int d>
void registerSurfaceCollision(Registry& r) {
  r.addComponent<d>(ComponentType<d>{
      "surface_collision",
      "on a deformable or cloth entity: its surface collides with other such surfaces and itself (Bridson et al. "
      "2002): thickness (m), friction, self (default: true for cloth, false for solids)",
      parseSurfaceCollision<d>, [](World<d>& w) { w.template ensurePool<SurfaceCollision>(); }, ""});
}

template <int d>
void registerRigidSurfaceCollisionSystems(Registry& r) {
  r.addSystem<d>({"rigid_surface_collisions",
                  "Step II (Sec. 4.4) rigid bodies against the faces of colliding surfaces, two-way, restitution zero, "
                  "Coulomb friction",
                  [] { return makeRigidSurfaceContactSystems<d>({Stage::Collisions}); }, ""});
}

template <int d>
void registerSelfCollisionSystems(Registry& r) {
  r.addSystem<d>({"rigid_surface_contact",
                  "rigid bodies against the faces of colliding surfaces (a body's deepest point in each nearby cloth or "
                  "surface triangle, impulses on the face's particles by barycentric weights): Steps III (steering), IV "
                  "(push-out) and V (two-way)",
                  [] {
                    return makeRigidSurfaceContactSystems<d>({Stage::Contact, Stage::AdvancePositions, Stage::AdvanceVelocity});
                  },
                  ""});
  r.addSystem<d>({"deformable_self_collisions",
                  "deformable-deformable and self collisions (Bridson et al. 2002): proximity repulsion and "
                  "continuous collision passes at Step II, collision passes again at Step III; surface_crossings counts "
                  "what still passed through a colliding surface over the step",
                  [] {
                    std::vector<std::unique_ptr<System<d>>> v;
                    auto afterCollisions = std::make_shared<std::vector<double>>();
                    v.push_back(std::make_unique<DeformableSelfCollision<d>>(Stage::Collisions, afterCollisions));
                    v.push_back(std::make_unique<DeformableSelfCollision<d>>(Stage::Contact, afterCollisions));
                    auto scratch = std::make_shared<SurfaceCrossingScratch>();
                    v.push_back(std::make_unique<SurfaceCrossings<d>>(Stage::ForcesAtStart, scratch));
                    v.push_back(std::make_unique<SurfaceCrossings<d>>(Stage::Diagnostics, scratch));
                    return v;
                  },
                  ""});
}

void registerClothSystems(Registry& r) {
  r.addSystem<3>({"advance_cloth_velocity_half",
                  "Step I (Sec. 4.3) for cloth: (M - dt/2 D) v^{n+1/2} = M v^n + dt/2 f(x^n), CG",
                  [] { return singleSystem<AdvanceClothVelocity>(Stage::AdvanceVelocityHalf); }, ""});
  r.addSystem<3>({"advance_cloth_velocity", "Step V (Sec. 4.7) for cloth: trapezoid in the damping, CG",
                  [] { return singleSystem<AdvanceClothVelocity>(Stage::AdvanceVelocity); }, ""});
  r.addSystem<3>({"cloth_diagnostics", "the cloth springs' energy in the energy columns",
                  [] { return singleSystem<ClothDiagnostics>(); }, ""});
}

template void registerSurfaceCollision<2>(Registry&);
template void registerSurfaceCollision<3>(Registry&);
template void registerRigidSurfaceCollisionSystems<2>(Registry&);
template void registerRigidSurfaceCollisionSystems<3>(Registry&);
template void registerSelfCollisionSystems<2>(Registry&);
template void registerSelfCollisionSystems<3>(Registry&);

}  // namespace monolith
