#include "scenarios/deformable_components.h"

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "components/deformable.h"
#include "components/kinematic.h"
#include "components/rigid_body.h"
#include "solvers/deformable/simplex_mesh.h"
#include "systems/deformable_dynamics.h"
#include "systems/embedded_binding.h"
#include "systems/particle_binding.h"
#include "systems/particle_contact.h"

namespace monolith {

namespace {

namespace dm = solvers::deformable;

std::string resolvePath(const Config& c, const std::string& file) {
  std::filesystem::path path(file);
  if (path.is_relative()) path = std::filesystem::path(c.file()).parent_path() / path;
  return path.string();
}

// "mesh": {"box": {half_extents, edge_length | cells}} | {"sphere": {radius, edge_length}} |
//         {"torus": {major_radius, minor_radius, edge_length}} | {"capsule": {radius, half_length, edge_length}} |
//         {"gmsh": "file.msh"} | {"tetgen": "base"} (3-D; base.node + base.ele)
template <int d>
dm::MeshData<d> parseMesh(const Config& c, std::string& origin) {
  const std::vector<std::string> forms = d == 3
                                             ? std::vector<std::string>{"box", "sphere", "torus", "capsule", "gmsh", "tetgen"}
                                             : std::vector<std::string>{"box", "sphere", "torus", "capsule", "gmsh"};
  int given = 0;
  for (const auto& f : forms) given += c.has(f);
  std::string list;
  for (const auto& f : forms) list += (list.empty() ? "" : ", ") + f;
  if (given != 1) c.fail("exactly one mesh form of: " + list, std::to_string(given) + " given");
  try {
    if (c.has("box")) {
      const Config b = c.child("box");
      const Vec<d> half = b.vector("half_extents", d, Bound::Positive);
      if (b.has("edge_length") == b.has("cells"))
        b.fail("exactly one of edge_length (a number) or cells (" + std::to_string(d) + " whole cell counts per axis)",
               b.has("cells") ? "both" : "neither");
      origin = "built-in box";
      if (b.has("edge_length")) {
        const double h = b.number("edge_length", Bound::Positive);
        b.finish();
        return dm::boxMesh<d>(half, h);
      }
      const Eigen::VectorXd counts = b.vector("cells", d, Bound::Positive);
      Eigen::Matrix<int, d, 1> cells;
      for (int a = 0; a < d; ++a) {
        if (counts(a) != std::round(counts(a)) || counts(a) > 1e4)
          b.failAt("cells", "whole cell counts from 1 to 10000 per axis", describeJson(b.raw()["cells"]));
        cells(a) = static_cast<int>(counts(a));
      }
      b.finish();
      return dm::boxMesh<d>(half, cells);
    }
    if (c.has("sphere")) {
      const Config b = c.child("sphere");
      const double r = b.number("radius", Bound::Positive), h = b.number("edge_length", Bound::Positive);
      b.finish();
      origin = "built-in sphere";
      return dm::sphereMesh<d>(r, h);
    }
    if (c.has("torus")) {
      const Config b = c.child("torus");
      const double R = b.number("major_radius", Bound::Positive), r = b.number("minor_radius", Bound::Positive);
      if (!(R > r)) b.failAt("major_radius", "a major radius above the minor radius", std::to_string(R));
      const double h = b.number("edge_length", Bound::Positive);
      b.finish();
      origin = "built-in torus";
      return dm::torusMesh<d>(R, r, h);
    }
    if (c.has("capsule")) {
      const Config b = c.child("capsule");
      const double r = b.number("radius", Bound::Positive), L = b.number("half_length", Bound::NonNegative);
      const double h = b.number("edge_length", Bound::Positive);
      b.finish();
      origin = "built-in capsule";
      return dm::capsuleMesh<d>(r, L, h);
    }
    if (c.has("gmsh")) {
      origin = resolvePath(c, c.string("gmsh"));
      return dm::readGmsh<d>(origin);
    }
    if constexpr (d == 3) {
      origin = resolvePath(c, c.string("tetgen"));
      return dm::readTetgen(origin);
    }
  } catch (const dm::MeshError& e) {
    c.failAt(c.has("gmsh") ? "gmsh" : "tetgen", "a readable, valid mesh file", e.what());
  }
  c.fail("a mesh", "none");
}

}  // namespace

template <int d>
void parseFixedParticles(const Config& c, Particles<d>& p) {
  // "fixed": [{"min": [...], "max": [...]}, ...]: particles inside any of these world boxes.
  if (c.has("fixed")) {
    const Config list(c.raw()["fixed"], c.file(), c.pathOf("fixed"));
    c.markUsed("fixed");
    for (std::size_t k = 0; k < list.arraySize(); ++k) {
      const Config box = list.element(k);
      const Vec<d> lo = box.vector("min", d), hi = box.vector("max", d);
      box.finish();
      int count = 0;
      for (std::size_t i = 0; i < p.fixed.size(); ++i) {
        const Vec<d> x = Eigen::Map<const Vec<d>>(&p.x[d * i]);
        if ((x.array() >= lo.array()).all() && (x.array() <= hi.array()).all()) {
          p.fixed[i] = 1;
          for (int a = 0; a < d; ++a) p.v[d * i + a] = 0;
          ++count;
        }
      }
      if (count == 0) box.fail("a box containing at least one particle of the mesh", "a box containing none");
    }
  }
}

template <int d>
void parseRigidBindings(World<d>& world, Entity e, const Config& c, Particles<d>& p, bool dynamicBodies) {
  // "bind": [{"body": NAME, "min": [...], "max": [...]}, ...]: particles inside the world box are
  // hard-bound to the rigid body NAME (listed before this entity); their mass and inertia about
  // the body's centre join a dynamic body's (the shift of its centre of mass is neglected).
  if (c.has("bind")) {
    const Config list(c.raw()["bind"], c.file(), c.pathOf("bind"));
    c.markUsed("bind");
    RigidBinding<d> binding;
    for (std::size_t k = 0; k < list.arraySize(); ++k) {
      const Config item = list.element(k);
      const std::string name = item.string("body");
      const auto target = world.find(name);
      RigidBody<d>* body = target ? world.template get<RigidBody<d>>(*target) : nullptr;
      if (!body) item.failAt("body", "the name of a rigid body listed before this entity", "\"" + name + "\"");
      const Vec<d> lo = item.vector("min", d), hi = item.vector("max", d);
      item.finish();
      const bool heavy = !body->isStatic && !world.template has<KinematicMotion<d>>(*target);
      if (heavy && !dynamicBodies)
        item.failAt("body", "a static or kinematic rigid body (cloth forces are not passed to dynamic bodies)",
                    "\"" + name + "\", a dynamic body");
      const Eigen::Matrix<double, d, d> Rb = body->rotation();
      int count = 0;
      for (std::size_t i = 0; i < p.fixed.size(); ++i) {
        const Vec<d> x = Eigen::Map<const Vec<d>>(&p.x[d * i]);
        if (!((x.array() >= lo.array()).all() && (x.array() <= hi.array()).all()) || p.fixed[i]) continue;
        p.fixed[i] = 2;
        const Vec<d> r = Rb.transpose() * (x - body->x);
        binding.particle.push_back(static_cast<int>(i));
        binding.body.push_back(static_cast<int>(k));
        for (int a = 0; a < d; ++a) binding.offset.push_back(r(a));
        if (heavy) {
          body->mass += p.m[i];
          if constexpr (d == 3)
            body->inertiaBody += p.m[i] * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
          else
            body->inertiaBody(0) += p.m[i] * r.squaredNorm();
        }
        ++count;
      }
      if (count == 0) item.fail("a box containing at least one free particle of the mesh", "a box containing none");
      if (heavy) body->refresh();
      binding.bodies += (k ? "\n" : "") + name;
      // The bound particles start with the body's point velocity.
      for (std::size_t q = 0; q < binding.particle.size(); ++q) {
        if (binding.body[q] != static_cast<int>(k)) continue;
        const int i = binding.particle[q];
        const Vec<d> r = Rb * Vec<d>(Eigen::Map<const Vec<d>>(&binding.offset[d * q]));
        Vec<d> w = Vec<d>::Zero();
        if constexpr (d == 3) w = body->omega().cross(r);
        else w = Vec<d>(-body->omega()(0) * r.y(), body->omega()(0) * r.x());
        for (int a = 0; a < d; ++a) p.v[d * i + a] = body->isStatic ? 0.0 : body->v(a) + w(a);
      }
    }
    world.add(e, binding);
  }
}

template <int d>
void parseEmbeddedBindings(World<d>& world, Entity e, const Config& c, Particles<d>& p) {
  // "embed": [{"body": NAME, "min": [...], "max": [...]}, ...]: the free particles inside the world
  // box are embedded in the elements of the deformable body NAME (listed before this entity) that
  // contain them, with barycentric weights (Sifakis et al. 2007); their mass joins the element's
  // particles in those weights.
  if (!c.has("embed")) return;
  const Config list(c.raw()["embed"], c.file(), c.pathOf("embed"));
  c.markUsed("embed");
  EmbeddedBinding<d> binding;
  for (std::size_t k = 0; k < list.arraySize(); ++k) {
    const Config item = list.element(k);
    const std::string name = item.string("body");
    const auto target = world.find(name);
    Particles<d>* host = target ? world.template get<Particles<d>>(*target) : nullptr;
    const SimplexMesh<d>* mesh = target ? world.template get<SimplexMesh<d>>(*target) : nullptr;
    if (!host || !mesh)
      item.failAt("body", "the name of a deformable (simplex mesh) body listed before this entity", "\"" + name + "\"");
    if (world.template has<EmbeddedBinding<d>>(*target))
      item.failAt("body", "a host that is not itself embedded in another body", "\"" + name + "\", embedded");
    const Vec<d> lo = item.vector("min", d), hi = item.vector("max", d);
    item.finish();
    int count = 0;
    for (std::size_t i = 0; i < p.fixed.size(); ++i) {
      const Vec<d> x = Eigen::Map<const Vec<d>>(&p.x[d * i]);
      if (!((x.array() >= lo.array()).all() && (x.array() <= hi.array()).all()) || p.fixed[i]) continue;
      // The first element (in mesh order) that contains the particle, at the host's positions.
      int found = -1;
      Eigen::Matrix<double, d + 1, 1> w;
      for (int el = 0; el < mesh->elementCount() && found < 0; ++el) {
        const int* v = &mesh->elements[(d + 1) * el];
        const Vec<d> x0 = Eigen::Map<const Vec<d>>(&host->x[d * v[0]]);
        Eigen::Matrix<double, d, d> D;
        for (int a = 0; a < d; ++a) D.col(a) = Eigen::Map<const Vec<d>>(&host->x[d * v[a + 1]]) - x0;
        const Vec<d> l = D.inverse() * (x - x0);
        w(0) = 1 - l.sum();
        w.template tail<d>() = l;
        if (w.minCoeff() >= -1e-9) found = el;
      }
      if (found < 0) {
        std::ostringstream where;
        where << "particle " << i << " at (" << x.transpose() << ") outside every element";
        item.fail("a box whose free particles all lie inside elements of \"" + name + "\"", where.str());
      }
      p.fixed[i] = 3;
      binding.particle.push_back(static_cast<int>(i));
      binding.host.push_back(static_cast<int>(k));
      binding.element.push_back(found);
      const int* v = &mesh->elements[(d + 1) * found];
      Vec<d> velocity = Vec<d>::Zero();
      for (int a = 0; a <= d; ++a) {
        binding.weight.push_back(w(a));
        host->m[v[a]] += w(a) * p.m[i];
        velocity += w(a) * Vec<d>(Eigen::Map<const Vec<d>>(&host->v[d * v[a]]));
      }
      Eigen::Map<Vec<d>>(&p.v[d * i]) = velocity;  // it starts with its element's velocity
      ++count;
    }
    if (count == 0) item.fail("a box containing at least one free particle of the mesh", "a box containing none");
    binding.hosts += (k ? "\n" : "") + name;
  }
  world.add(e, binding);
}

namespace {

template <int d>
void parseDeformable(World<d>& world, Entity e, const Config& c) {
  std::string origin;
  const Config meshConfig = c.child("mesh");
  dm::MeshData<d> mesh = parseMesh<d>(meshConfig, origin);
  meshConfig.finish();
  if (const std::string problem = dm::meshProblem(mesh); !problem.empty())
    c.failAt("mesh", "a valid simplex mesh (positively oriented, non-degenerate, connected)", origin + ": " + problem);

  Elasticity el;
  const std::string model = c.oneOf("model", {"corotated", "neo_hookean", "springs"}, "corotated");
  el.model = model == "corotated" ? 0 : model == "neo_hookean" ? 1 : 2;
  el.density = c.number("density", 1000.0, Bound::Positive);
  el.youngsModulus = c.number("youngs_modulus", Bound::Positive);
  el.poissonRatio = c.number("poisson_ratio", 0.3);
  if (!(el.poissonRatio > -1 && el.poissonRatio < 0.5))
    c.failAt("poisson_ratio", "a Poisson ratio in (-1, 0.5)", std::to_string(el.poissonRatio));
  el.rayleighAlpha = c.number("rayleigh_alpha", 0.0, Bound::NonNegative);
  el.rayleighBeta = c.number("rayleigh_beta", 0.0, Bound::NonNegative);
  el.overdamping = c.number("overdamping", 0.0, Bound::NonNegative);
  el.altitudeStiffness = c.number("altitude_stiffness", 0.0, Bound::NonNegative);
  if (el.altitudeStiffness > 0 && el.model != 2)
    c.failAt("altitude_stiffness", "altitude springs only with \"model\": \"springs\"", model);
  el.clamp = c.number("clamp", 0.3, Bound::Positive);
  if (el.clamp >= 1) c.failAt("clamp", "a singular-value clamp below 1", std::to_string(el.clamp));

  // Placement: rotate about the mesh's own origin, then translate.
  Eigen::Matrix<double, d, d> R = Eigen::Matrix<double, d, d>::Identity();
  if constexpr (d == 3) {
    if (c.has("orientation")) {
      const Eigen::VectorXd q = c.vector("orientation", 4);
      if (q.norm() < 1e-12) c.failAt("orientation", "a non-zero quaternion [w, x, y, z]", "a zero quaternion");
      R = Eigen::Quaterniond(q(0), q(1), q(2), q(3)).normalized().toRotationMatrix();
    }
  } else {
    R = Eigen::Rotation2Dd(c.number("angle", 0.0)).toRotationMatrix();
  }
  const Vec<d> position = c.vector("position", Eigen::VectorXd::Zero(d));
  const Vec<d> velocity = c.vector("velocity", Eigen::VectorXd::Zero(d));

  Particles<d> p;
  SimplexMesh<d> sm;
  sm.elements = mesh.elements;
  for (const auto& x : mesh.x) {
    const Vec<d> w = R * x + position;
    for (int a = 0; a < d; ++a) {
      p.x.push_back(w(a));
      p.v.push_back(velocity(a));
      sm.restX.push_back(w(a));
    }
  }
  p.fixed.assign(mesh.x.size(), 0);
  parseFixedParticles<d>(c, p);
  // Lumped masses from the density (the force model's own computation).
  dm::Material mat;
  mat.density = el.density;
  p.m = dm::prepareForceModel<d>(sm.restX, sm.elements, mat).mass;
  // "particle_mass": every particle the same mass instead (a mass-spring model's lumping, as the
  // thesis's beam, Sec. 5.11.5).
  if (c.has("particle_mass")) p.m.assign(mesh.x.size(), c.number("particle_mass", Bound::Positive));
  parseRigidBindings<d>(world, e, c, p, true);
  parseEmbeddedBindings<d>(world, e, c, p);
  world.add(e, p);
  world.add(e, sm);
  world.add(e, el);
}

// "particle": {"mass", "position", "velocity"}: a single free mass point (no mesh, no elastic
// forces), in contact with rigid bodies like a deformable body's particles (Fig. 4.8).
template <int d>
void parseParticle(World<d>& world, Entity e, const Config& c) {
  Particles<d> p;
  const Vec<d> x = c.vector("position", Eigen::VectorXd::Zero(d));
  const Vec<d> v = c.vector("velocity", Eigen::VectorXd::Zero(d));
  p.m.push_back(c.number("mass", Bound::Positive));
  for (int a = 0; a < d; ++a) {
    p.x.push_back(x(a));
    p.v.push_back(v(a));
  }
  p.fixed.push_back(0);
  world.add(e, p);
}

}  // namespace

template <int d>
void registerDeformableComponents(Registry& r) {
  r.addComponent<d>(ComponentType<d>{
      "deformable",
      "deformable solid: mesh {box {half_extents, edge_length | cells} | sphere {radius, edge_length} | torus "
      "{major_radius, minor_radius, edge_length} | capsule {radius, half_length, edge_length} | gmsh FILE" +
          std::string(d == 3 ? " | tetgen BASE" : "") +
          "}, model (corotated | neo_hookean | springs), youngs_modulus, poisson_ratio, density, rayleigh_alpha, "
          "rayleigh_beta, overdamping, altitude_stiffness, particle_mass, clamp, position, " +
          std::string(d == 3 ? "orientation" : "angle") + ", velocity, fixed [{min, max}], bind [{body, min, max}], embed [{body, min, max}]",
      parseDeformable<d>,
      [](World<d>& w) {
        w.template ensurePool<Particles<d>>();
        w.template ensurePool<SimplexMesh<d>>();
        w.template ensurePool<Elasticity>();
        w.template ensurePool<RigidBinding<d>>();
        w.template ensurePool<EmbeddedBinding<d>>();
      },
      ""});
  r.addComponent<d>(ComponentType<d>{"particle", "a single free mass point: mass, position, velocity",
                                     parseParticle<d>,
                                     [](World<d>& w) { w.template ensurePool<Particles<d>>(); }, ""});
  r.addComponentOf<d, Particles<d>>("(internal) a deformable body's particles: position, velocity, mass, fixed", nullptr);
  r.addComponentOf<d, SimplexMesh<d>>("(internal) a deformable body's elements and rest positions", nullptr);
  r.addComponentOf<d, Elasticity>("(internal) a deformable body's material", nullptr);
  r.addComponentOf<d, RigidBinding<d>>("(internal) a deformable body's particles hard-bound to rigid bodies", nullptr);
  r.addComponentOf<d, EmbeddedBinding<d>>("(internal) a deformable body's particles embedded in another body's elements",
                                          nullptr);
}

template <int d>
void registerDeformableSystems(Registry& r) {
  r.addSystem<d>({"advance_deformable_velocity_half",
                  "Step I (Sec. 4.3) for deformables: (M - dt/2 D) v^{n+1/2} = M v^n + dt/2 f(x^n), CG",
                  [] { return singleSystem<AdvanceDeformableVelocity<d>>(Stage::AdvanceVelocityHalf); }, ""});
  r.addSystem<d>({"advance_deformable_positions", "Step IV (Sec. 4.6) for deformables: x^{n+1} = x^n + dt v^{n+1/2}",
                  [] { return singleSystem<AdvanceDeformablePositions<d>>(); }, ""});
  r.addSystem<d>({"advance_deformable_velocity",
                  "Step V (Sec. 4.7) for deformables: trapezoid in the damping as backward Euler + extrapolation, CG",
                  [] { return singleSystem<AdvanceDeformableVelocity<d>>(Stage::AdvanceVelocity); }, ""});
  r.addSystem<d>({"particle_bindings",
                  "particles hard-bound to rigid bodies: binding_forces@n/@n+1 (elastic forces on the bodies), "
                  "follow_bound_bodies (Step IV, Step V)",
                  [] {
                    std::vector<std::unique_ptr<System<d>>> v;
                    v.push_back(std::make_unique<BindingForces<d>>(Stage::ForcesAtStart));
                    v.push_back(std::make_unique<BindingForces<d>>(Stage::ForcesAtEnd));
                    v.push_back(std::make_unique<FollowBoundBodies<d>>(Stage::AdvancePositions));
                    v.push_back(std::make_unique<FollowBoundBodies<d>>(Stage::AdvanceVelocity));
                    return v;
                  },
                  ""});
  r.addSystem<d>({"particle_contact",
                  "particles against rigid bodies (zero restitution, Coulomb friction): particle_contact (Step III), "
                  "particle_push_out (Step IV), particle_velocity_contact (Step V, two-way)",
                  [] { return makeParticleContactSystems<d>(); }, ""});
  r.addSystem<d>({"deformable_diagnostics", "energies (kinetic, gravity, elastic) and momenta of deformables",
                  [] { return singleSystem<DeformableDiagnostics<d>>(); }, ""});
}

template <int d>
void registerEmbeddingSystems(Registry& r) {
  r.addSystem<d>({"embedded_bindings",
                  "particles embedded in another deformable's elements (Sifakis et al. 2007): follow_embedded_hosts "
                  "(Step IV, Step V); their forces act on the host element's particles in the damping solves",
                  [] { return makeEmbeddedBindingSystems<d>(); }, ""});
}

template <int d>
void registerParticleCollisionSystems(Registry& r) {
  r.addSystem<d>({"particle_collisions",
                  "Step II (Sec. 4.4) particles against rigid bodies, two-way, restitution zero, Coulomb friction",
                  [] { return makeParticleCollisionSystems<d>(); }, ""});
}

template void parseFixedParticles<2>(const Config&, Particles<2>&);
template void parseFixedParticles<3>(const Config&, Particles<3>&);
template void parseRigidBindings<2>(World<2>&, Entity, const Config&, Particles<2>&, bool);
template void parseRigidBindings<3>(World<3>&, Entity, const Config&, Particles<3>&, bool);
template void parseEmbeddedBindings<2>(World<2>&, Entity, const Config&, Particles<2>&);
template void parseEmbeddedBindings<3>(World<3>&, Entity, const Config&, Particles<3>&);
template void registerParticleCollisionSystems<2>(Registry&);
template void registerParticleCollisionSystems<3>(Registry&);
template void registerDeformableComponents<2>(Registry&);
template void registerDeformableComponents<3>(Registry&);
template void registerEmbeddingSystems<2>(Registry&);
template void registerEmbeddingSystems<3>(Registry&);
template void registerDeformableSystems<2>(Registry&);
template void registerDeformableSystems<3>(Registry&);

}  // namespace monolith
