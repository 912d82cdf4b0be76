// A Monolith rigid-body scene file run in Bullet (Debian's libbullet-dev: single precision, its
// default sequential-impulse solver), to measure the "popular engine" issue 3 sets its speed goal
// against on the same machine and the same scene instead of quoting a figure.
//
// What carries over from the scene: gravity, dt and end time, and each entity's shape (sphere,
// box or plane), mass (inertia from the shape), pose, velocities, friction and restitution.
// Anything else (other shapes, an explicit inertia, kinematic motion, forces, fluids, 2-D) is
// refused with the JSON path, rather than compared as a different scene. Monolith combines a pair's coefficients by their minimum
// (systems/contact_workspace.cpp, findPairImpulse); Bullet's combination callbacks are set to the
// same rule. Sleeping is off by default: a sleeping body costs nothing and Monolith has none, so
// per-step figures would not compare (`--sleep` turns Bullet's default deactivation back on).
//
// Prints one row per run: us/step, the largest distance of a dynamic body from its start after
// the run, the final kinetic energy, the deepest contact penetration over the smaller body's
// size at any step (Bullet's own contact distances, measured at the start of each step, i.e. on
// the state the step before produced) — the columns of bench_rigid_contact's tables — and the
// largest rise of the total energy (kinetic + gravity's potential) over its initial value after
// any step, relative to that value (issue 3's rule: at most 0.1 %).
//
// usage: compare_bullet SCENE.json [--dt 1/60|SECONDS] [--end SECONDS] [--iterations N] [--sleep] [--ccd]
//   --ccd: Bullet's continuous collision detection on every dynamic body (off by default, as in
//   Bullet).
#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "scene_file.h"

namespace {

using namespace comparisons;
constexpr double kInfinite = std::numeric_limits<double>::infinity();
constexpr const char* kUsage = "SCENE.json [--dt 1/60|SECONDS] [--end SECONDS] [--iterations N] [--sleep] [--ccd]";

struct Options : CommonOptions {
  int iterations = 10;  // btContactSolverInfo's default
  bool ccd = false;     // Bullet's continuous collision detection for fast bodies
};

Options parse(int argc, char** argv) {
  Options o;
  static_cast<CommonOptions&>(o) = parseCommon(argc, argv, kUsage, [&](const std::string& a, auto&& next) {
    if (a == "--ccd") o.ccd = true;
    else if (a == "--iterations") o.iterations = static_cast<int>(positive(next(), a.c_str(), kUsage));
    else return false;
    return true;
  });
  return o;
}

btVector3 vec3(const json& j, const std::string& path) {
  const auto v = numbers<3>(j, path);
  return btVector3(btScalar(v[0]), btScalar(v[1]), btScalar(v[2]));
}

btScalar combineFrictionByMinimum(const btCollisionObject* a, const btCollisionObject* b) {
  return std::min(a->getFriction(), b->getFriction());
}
btScalar combineRestitutionByMinimum(const btCollisionObject* a, const btCollisionObject* b) {
  return std::min(a->getRestitution(), b->getRestitution());
}

struct Scene {
  btVector3 gravity{0, btScalar(-9.81), 0};
  SceneTime time;
  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  std::vector<std::unique_ptr<btDefaultMotionState>> states;
  std::vector<std::unique_ptr<btRigidBody>> bodies;
  std::vector<double> sizes;  // smallest extent of each body (Monolith's minimumSize), inf for a plane
  std::vector<btVector3> start;
};

Scene load(const Options& o) {
  const json root = readSceneFile(o.scene);
  Scene s;
  // Monolith's own solver settings ("solvers") have no Bullet counterpart and are left out.
  refuseOtherKeys(root, {"description", "dimension", "time", "gravity", "entities", "solvers"}, o.scene + ":",
                  "Bullet");
  if (root.value("dimension", 3) != 3) fail(o.scene + ": dimension: only 3-D scenes run in Bullet here");
  if (root.contains("gravity")) s.gravity = vec3(root["gravity"], o.scene + ": gravity");
  s.time = sceneTime(root, o);
  if (!root.contains("entities") || !root["entities"].is_array()) fail(o.scene + ": entities: expected an array");
  for (std::size_t e = 0; e < root["entities"].size(); ++e) {
    const json& entity = root["entities"][e];
    const std::string path = o.scene + ": entities[" + std::to_string(e) + "]";
    // Anything not listed here (a kinematic motion, forces, a fluid ...) would make Bullet run
    // a different scene: refused.
    refuseOtherKeys(entity, {"name", "shape", "rigid_body", "collider"}, path, "Bullet");
    if (!entity.contains("rigid_body")) fail(path + ".rigid_body: every entity must be a rigid body here");
    const json& rb = entity["rigid_body"];
    refuseOtherKeys(rb, {"static", "mass", "position", "orientation", "velocity", "angular_velocity"},
                    path + ".rigid_body", "Bullet");
    if (!entity.contains("shape")) fail(path + ".shape: a rigid body needs a shape");
    const json& shape = entity["shape"];
    const std::string type = shape.value("type", "");
    const bool isStatic = rb.value("static", false);
    const btVector3 x = rb.contains("position") ? vec3(rb["position"], path + ".rigid_body.position") : btVector3(0, 0, 0);
    btTransform pose;
    pose.setIdentity();
    double size = kInfinite;
    if (type == "sphere") {
      const double r = number(shape, "radius", 0, path + ".shape");
      if (!(r > 0)) fail(path + ".shape.radius: expected a positive number");
      s.shapes.push_back(std::make_unique<btSphereShape>(btScalar(r)));
      size = 2 * r;
    } else if (type == "box") {
      const btVector3 h = vec3(shape.value("half_extents", json()), path + ".shape.half_extents");
      if (!(h.minAxis() == 0 ? h.x() > 0 : h.minAxis() == 1 ? h.y() > 0 : h.z() > 0))
        fail(path + ".shape.half_extents: expected positive numbers");
      s.shapes.push_back(std::make_unique<btBoxShape>(h));
      size = 2 * double(h.minAxis() == 0 ? h.x() : h.minAxis() == 1 ? h.y() : h.z());
    } else if (type == "plane") {
      if (!isStatic) fail(path + ".shape: a plane must be static");
      btVector3 n = vec3(shape.value("normal", json()), path + ".shape.normal");
      if (n.length2() == 0) fail(path + ".shape.normal: expected a non-zero vector");
      n.normalize();
      s.shapes.push_back(std::make_unique<btStaticPlaneShape>(n, n.dot(x)));
    } else {
      fail(path + ".shape.type: '" + type + "' is not carried over (sphere, box and plane are)");
    }
    if (type != "plane") {
      pose.setOrigin(x);
      if (rb.contains("orientation")) {
        const auto q = numbers<4>(rb["orientation"], path + ".rigid_body.orientation");  // [w, x, y, z]
        pose.setRotation(btQuaternion(btScalar(q[1]), btScalar(q[2]), btScalar(q[3]), btScalar(q[0])).normalized());
      }
    }
    const double mass = isStatic ? 0 : number(rb, "mass", 1.0, path + ".rigid_body");
    if (!isStatic && !(mass > 0)) fail(path + ".rigid_body.mass: expected a positive number");
    btVector3 inertia(0, 0, 0);
    if (mass > 0) s.shapes.back()->calculateLocalInertia(btScalar(mass), inertia);
    s.states.push_back(std::make_unique<btDefaultMotionState>(pose));
    btRigidBody::btRigidBodyConstructionInfo info(btScalar(mass), s.states.back().get(), s.shapes.back().get(), inertia);
    const json collider = entity.value("collider", json::object());
    info.m_friction = btScalar(number(collider, "friction", 0.5, path + ".collider"));
    info.m_restitution = btScalar(number(collider, "restitution", 0.0, path + ".collider"));
    s.bodies.push_back(std::make_unique<btRigidBody>(info));
    btRigidBody& body = *s.bodies.back();
    if (!isStatic) {
      if (rb.contains("velocity")) body.setLinearVelocity(vec3(rb["velocity"], path + ".rigid_body.velocity"));
      if (rb.contains("angular_velocity"))
        body.setAngularVelocity(vec3(rb["angular_velocity"], path + ".rigid_body.angular_velocity"));
      if (!o.sleep) body.setActivationState(DISABLE_DEACTIVATION);
      if (o.ccd) {
        // A body moving more than a quarter of its size in a step is swept (a sphere of 40 % of
        // its size) and stopped at the first hit, instead of landing deep inside.
        body.setCcdMotionThreshold(btScalar(0.25 * size));
        body.setCcdSweptSphereRadius(btScalar(0.4 * size));
      }
    }
    s.sizes.push_back(size);
    s.start.push_back(pose.getOrigin());
  }
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  Scene scene = load(o);
  gCalculateCombinedFrictionCallback = &combineFrictionByMinimum;
  gCalculateCombinedRestitutionCallback = &combineRestitutionByMinimum;

  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher(&configuration);
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld world(&dispatcher, &broadphase, &solver, &configuration);
  world.setGravity(scene.gravity);
  world.getSolverInfo().m_numIterations = o.iterations;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    scene.bodies[i]->setUserIndex(static_cast<int>(i));
    world.addRigidBody(scene.bodies[i].get());
  }

  // Kinetic and total (kinetic + gravity's potential) energy of the dynamic bodies.
  const auto energies = [&] {
    double kinetic = 0, potential = 0;
    for (const auto& body : scene.bodies) {
      if (body->getInvMass() == 0) continue;
      const double m = 1 / double(body->getInvMass());
      const btVector3 v = body->getLinearVelocity(), w = body->getAngularVelocity();
      kinetic += 0.5 * m * double(v.length2()) + 0.5 * double(w.dot(body->getInvInertiaTensorWorld().inverse() * w));
      potential -= m * double(scene.gravity.dot(body->getCenterOfMassPosition()));
    }
    return std::make_pair(kinetic, kinetic + potential);
  };
  const double initialEnergy = energies().second;
  double highestEnergy = initialEnergy;

  const long steps = scene.time.steps;
  double wall = 0, penetration = 0;
  for (long n = 0; n < steps; ++n) {
    const auto t0 = std::chrono::steady_clock::now();
    world.stepSimulation(btScalar(scene.time.dt), 0);  // no sub-steps: exactly one step of dt
    wall += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    for (int m = 0; m < dispatcher.getNumManifolds(); ++m) {  // outside the timed part
      const btPersistentManifold* manifold = dispatcher.getManifoldByIndexInternal(m);
      const double size = std::min(scene.sizes[manifold->getBody0()->getUserIndex()],
                                   scene.sizes[manifold->getBody1()->getUserIndex()]);
      for (int p = 0; p < manifold->getNumContacts(); ++p)
        penetration = std::max(penetration, -double(manifold->getContactPoint(p).getDistance()) / size);
    }
    highestEnergy = std::max(highestEnergy, energies().second);
  }
  double drift = 0;
  int dynamic = 0;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const btRigidBody& b = *scene.bodies[i];
    if (b.getInvMass() == 0) continue;
    ++dynamic;
    drift = std::max(drift, double((b.getCenterOfMassPosition() - scene.start[i]).length()));
  }
  const double kinetic = energies().first;
  for (auto& b : scene.bodies) world.removeRigidBody(b.get());

  std::printf("| engine | scene | bodies | dt | steps | solver iterations | sleeping | us/step | max drift | final KE | "
              "max penetration / size | max energy rise | CCD |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  std::printf("| Bullet %d (%zu-byte btScalar) | %s | %d | 1/%.4g | %ld | %d | %s | %.1f | %.2e | %.2e | %.2e | %.3g %% | %s |\n",
              btGetVersion(), sizeof(btScalar), fileName(o.scene).c_str(), dynamic, 1 / scene.time.dt, steps, o.iterations,
              o.sleep ? "on" : "off", 1e6 * wall / steps, drift, kinetic, penetration,
              100 * (highestEnergy - initialEnergy) / std::abs(initialEnergy), o.ccd ? "on" : "off");
  return 0;
}
