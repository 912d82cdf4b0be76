// The built-in component parsers and system types. Component configs are validated here with
// located errors (ecs/config.h); the physics lives in systems/.
#include <cmath>
#include <sstream>

#include "components/forces.h"
#include "components/rigid_body.h"
#include "components/shape.h"
#include "components/spring_mount.h"
#include "ecs/registry.h"
#include "scenarios/contact_components.h"
#include "scenarios/cloth_components.h"
#include "scenarios/deformable_components.h"
#include "scenarios/fluid_components.h"
#include "scenarios/joint_components.h"
#include "systems/articulation.h"
#include "scenarios/surface_tension_components.h"
#include "systems/advance_positions.h"
#include "systems/advance_velocity.h"
#include "systems/rigid_diagnostics.h"
#include "systems/fluid_advection.h"
#include "systems/fluid_obstacles.h"
#include "systems/fluid_projection.h"
#include "systems/fluid_structure_coupling.h"
#include "systems/surface_tension_flow.h"
#include "systems/kinematic_motion.h"
#include "systems/rigid_contact.h"
#include "systems/rigid_forces.h"
#include "systems/spring_mount.h"

namespace monolith {

namespace {

// Angular quantities: a 3-vector in 3-D, a number (rotation about z) in 2-D; default zero.
template <int d>
AngularVec<d> angularConfig(const Config& c, const std::string& key) {
  AngularVec<d> a = AngularVec<d>::Zero();
  if constexpr (d == 3) a = c.vector(key, Eigen::VectorXd::Zero(3));
  else a(0) = c.number(key, 0.0);
  return a;
}

// Body-frame inertia from the config ("inertia": principal moments, a full matrix, or in 2-D a
// number), else from the shape. Checked: symmetric positive definite, and physically
// realizable (each principal moment at most the sum of the other two).
template <int d>
InertiaMat<d> parseInertia(World<d>& world, Entity e, const Config& c, double mass) {
  InertiaMat<d> I;
  if (!c.has("inertia")) {
    const Shape<d>* shape = world.template get<Shape<d>>(e);
    // A static body never moves: its inertia is never used (e.g. a level-set fluid obstacle).
    if (!shape && c.boolean("static", false)) return InertiaMat<d>::Identity();
    if (!shape)
      c.failAt("inertia", "an inertia, or a \"shape\" component on the entity to derive it from", "neither");
    const bool noClosedForm =
        shape->type == ShapeType::Mesh || shape->type == ShapeType::Plane || (d == 3 && shape->type == ShapeType::Convex);
    if (noClosedForm && !c.boolean("static", false))
      c.failAt("inertia", "an explicit inertia (a convex hull, mesh or plane shape has none built in)", "none");
    return shape->inertia(mass);
  }
  if constexpr (d == 2) {
    I(0) = c.number("inertia", Bound::Positive);
    return I;
  } else {
    const Json& raw = c.raw()["inertia"];
    if (raw.is_array() && raw.size() == 3 && raw[0].is_array()) {
      I = c.matrix("inertia", 3, 3);
      if ((I - I.transpose()).cwiseAbs().maxCoeff() > 1e-12 * I.cwiseAbs().maxCoeff())
        c.failAt("inertia", "a symmetric 3x3 matrix", "a non-symmetric matrix");
    } else if (raw.is_array() && raw.size() == 3) {
      I = c.vector("inertia", 3, Bound::Any).asDiagonal();
    } else {
      c.failAt("inertia", "principal moments [Ixx, Iyy, Izz] or a 3x3 matrix", describeJson(raw));
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(I);
    const Eigen::Vector3d m = eig.eigenvalues();
    std::ostringstream got;
    got << "principal moments " << m.transpose();
    if (!(m.minCoeff() > 1e-12 * std::max(1.0, m.maxCoeff())))
      c.failAt("inertia", "a positive-definite (non-singular) inertia", got.str());
    if (m(2) > (m(0) + m(1)) * (1 + 1e-12))
      c.failAt("inertia", "a physically realizable inertia (largest moment <= sum of the other two)", got.str());
    return I;
  }
}

template <int d>
void parseRigidBody(World<d>& world, Entity e, const Config& c) {
  RigidBody<d> b;
  b.isStatic = c.boolean("static", false);
  if (const Shape<d>* shape = world.template get<Shape<d>>(e); shape && shape->type == ShapeType::Plane && !b.isStatic)
    c.failAt("static", "true: a plane (half-space) has infinite extent and can only be static", "a dynamic body");
  b.mass = b.isStatic ? c.number("mass", 1.0, Bound::Positive) : c.number("mass", Bound::Positive);
  b.inertiaBody = parseInertia(world, e, c, b.mass);
  b.refresh();
  b.x = c.vector("position", Eigen::VectorXd::Zero(d));
  if constexpr (d == 3) {
    if (c.has("orientation")) {
      const Eigen::VectorXd q = c.vector("orientation", 4);
      if (q.norm() < 1e-12) c.failAt("orientation", "a non-zero quaternion [w, x, y, z]", "a zero quaternion");
      b.orientation = Eigen::Quaterniond(q(0), q(1), q(2), q(3)).normalized();
    }
  } else {
    b.orientation = c.number("angle", 0.0);
  }
  b.v = c.vector("velocity", Eigen::VectorXd::Zero(d));
  const AngularVec<d> w = angularConfig<d>(c, "angular_velocity");
  if (b.isStatic) {
    if (b.v.squaredNorm() > 0)
      c.failAt("velocity", "no velocity on a static body (static bodies never move)", "a non-zero velocity");
    // Reported at its own key: the message must point at the value to remove.
    if (w.squaredNorm() > 0)
      c.failAt("angular_velocity", "no angular velocity on a static body (static bodies never move)",
               "a non-zero angular velocity");
  } else {
    b.setOmega(w);
  }
  world.add(e, b);
  if (!b.isStatic) world.add(e, RigidForces<d>{});
}

// A spring and dashpot from the body to a world anchor (its start position by default).
template <int d>
void parseSpringMount(World<d>& world, Entity e, const Config& c) {
  const RigidBody<d>* body = world.template get<RigidBody<d>>(e);
  if (!body || body->isStatic) c.fail("spring_mount on an entity with a dynamic \"rigid_body\"", body ? "a static body" : "none");
  SpringMount<d> m;
  m.anchor = c.vector("anchor", Eigen::VectorXd(body->x));
  m.stiffness = c.vector("stiffness", d, Bound::NonNegative);
  m.damping = c.vector("damping", Eigen::VectorXd::Zero(d), Bound::NonNegative);
  world.add(e, m);
}

template <int d>
void parseExternalForce(World<d>& world, Entity e, const Config& c) {
  ExternalForce<d> f;
  f.force = c.vector("force", Eigen::VectorXd::Zero(d));
  f.torque = angularConfig<d>(c, "torque");
  world.add(e, f);
}

// A system type with a single instance.
template <class S, class... Args>
auto single(Args... args) {
  std::vector<std::unique_ptr<System<S::dimension>>> v;
  v.push_back(std::make_unique<S>(args...));
  return v;
}

template <int d>
void registerDimension(Registry& r) {
  // Order matters: components parse in this order (shape before rigid_body).
  r.addComponentOf<d, Shape<d>>(d == 3 ? "geometry: box {half_extents}, sphere {radius}, capsule/cylinder {radius, "
                                                "half_height} (axis z), plane {normal}, convex {vertices}, mesh "
                                                "{vertices, triangles} or {file (OBJ), scale}"
                                       : "geometry: box {half_extents}, disk {radius}, polygon {vertices}, plane {normal}",
                                parseShapeComponent<d>);
  r.addComponentOf<d, RigidBody<d>>(
      "rigid body: mass, inertia (or from shape), position, orientation/angle, velocity, angular_velocity, static",
      parseRigidBody<d>);
  r.addComponentOf<d, ExternalForce<d>>("constant world-frame force and torque on a rigid body", parseExternalForce<d>);
  r.addComponentOf<d, SpringMount<d>>("spring and dashpot to a world anchor on a dynamic rigid body: anchor (default: "
                                      "its start position), stiffness and damping per axis",
                                      parseSpringMount<d>);
  r.addComponentOf<d, RigidForces<d>>("(internal) force/torque accumulator of a dynamic rigid body", nullptr);
  registerContactComponents<d>(r);
  registerFluidComponents<d>(r);
  registerJointComponents<d>(r);
  registerSurfaceTensionComponents<d>(r);
  registerDeformableComponents<d>(r);
  if constexpr (d == 3) registerClothComponents(r);
  registerSurfaceCollision<d>(r);
  registerFluidCouplingComponent<d>(r);

  r.addSystem<d>({"clear_rigid_forces", "zero the force accumulators before each force evaluation",
                  [] { return atBothForceStages<ClearRigidForces<d>, d>(); }, ""});
  r.addSystem<d>({"gravity", "m g on dynamic rigid bodies", [] { return atBothForceStages<GravityForce<d>, d>(); }, ""});
  r.addSystem<d>({"external_forces", "constant external force/torque components",
                  [] { return atBothForceStages<ExternalForces<d>, d>(); }, ""});
  r.addSystem<d>({"spring_mount_forces", "spring_mount: -k (x - anchor) - c v on mounted rigid bodies",
                  [] { return atBothForceStages<SpringMountForces<d>, d>(); }, ""});
  r.addSystem<d>({"advance_rigid_velocity_half", "Step I (Sec. 4.3): v^{n+1/2} = v^n + dt/2 a(x^n)",
                  [] { return single<RigidHalfKick<d>>(Stage::AdvanceVelocityHalf); }, ""});
  r.addSystem<d>({"script_kinematic_velocity", "kinematic bodies take their scripted velocity at t^{n+1/2}",
                  [] { return single<ScriptKinematicVelocity<d>>(); }, ""});
  r.addSystem<d>({"advance_rigid_positions",
                  "Step IV (Sec. 4.6): positions, orientation rule (4.4.1/App. A) and energy fix (2.2)",
                  [] { return single<AdvanceRigidPositions<d>>(); }, ""});
  r.addSystem<d>({"advance_rigid_velocity", "Step V (Sec. 4.7): v^{n+1} = v^{n+1/2} + dt/2 a(x^{n+1})",
                  [] { return single<RigidHalfKick<d>>(Stage::AdvanceVelocity); }, ""});
  r.addSystem<d>({"advance_kinematic_positions", "Step IV for kinematic bodies: x += dt v, R = exp(dt w) R",
                  [] { return single<AdvanceKinematicPositions<d>>(); }, ""});
  // Before rigid_contact: PD is Step III.2, ahead of contact (III.3).
  r.addSystem<d>({"joint_pd_control", "Step III.2 (Sec. 4.5): PD drive of revolute joints as impulses",
                  [] { return single<JointPdControl<d>>(); }, ""});
  registerParticleCollisionSystems<d>(r);
  registerRigidSurfaceCollisionSystems<d>(r);
  r.addSystem<d>({"rigid_contact",
                  "Steps II-V contact (Sec. 4.4-4.7, App. B): collisions, contact, shock_propagation, "
                  "resolve_interpenetration, velocity_contact",
                  [] { return makeRigidContactSystems<d>(); }, ""});
  // After rigid_contact: each runs after the contact system of its stage.
  r.addSystem<d>({"joint_stages",
                  "joint stages (Sec. 4.4-4.7, App. C): post-stabilization at Steps II, IV and V, "
                  "pre-stabilization at Step III, joint diagnostics",
                  [] { return makeJointSystems<d>(); },
                  ""});
  r.addSystem<d>({"advect_fluid", "fluid advection u* = u - dt (u.grad)u (semi-Lagrangian, MacCormack, ENO3 or WENO5 with RK3)",
                  [] { return single<FluidAdvection<d>>(); }, ""});
  r.addSystem<d>({"fluid_gravity", "gravity on the fluid's free faces", [] { return single<FluidGravity<d>>(); }, ""});
  r.addSystem<d>({"project_fluid", "coupled SPD pressure-viscosity solve (5.31) or Chorin splitting",
                  [] { return single<FluidProjection<d>>(); }, ""});
  r.addSystem<d>({"rasterize_obstacles", "solid cells (staircase) or cut faces of the MAC grid covered by fluid_obstacle shapes and level sets",
                  [] { return single<RasterizeObstacles<d>>(); }, ""});
  r.addSystem<d>({"obstacle_forces", "first-order force of the fluid on each fluid_obstacle (pressure + wall shear)",
                  [] { return single<ObstacleForces<d>>(); }, ""});
  r.addSystem<d>({"fsi_half_step", "FSI steps 1-4 (Sec. 5.4): coupled fluid-structure solve over dt/2 at x^n for the velocity that moves fluid_coupling bodies",
                  [] { return single<FsiHalfStep<d>>(); }, ""});
  r.addSystem<d>({"project_fluid_structure", "monolithic SPD fluid-structure solve (5.30) with fluid_coupling rigid bodies (Sec. 5.4-5.8)",
                  [] { return single<FluidStructureProjection<d>>(); }, ""});
  r.addSystem<d>({"rigid_diagnostics", "energies and momenta of the rigid bodies",
                  [] { return single<RigidDiagnostics<d>>(); }, ""});
  r.addSystem<d>({"surface_tension_flow",
                  "two-phase flow with implicit surface tension on a Lagrangian front (Ch. 6, eq. 6.33)",
                  [] { return single<SurfaceTensionFlow<d>>(); }, ""});
  if constexpr (d == 3) registerClothSystems(r);  // before the particles' contact of each stage
  registerDeformableSystems<d>(r);
  registerSelfCollisionSystems<d>(r);
  registerEmbeddingSystems<d>(r);  // last: embedded particles follow the stage's final host state
}

}  // namespace

void registerBuiltins(Registry& registry) {
  registry.setOrigin("built-in");
  registerDimension<2>(registry);
  registerDimension<3>(registry);
}

}  // namespace monolith
