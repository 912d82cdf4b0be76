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
#include <cstdlib>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using nlohmann::json;
constexpr double kInfinite = std::numeric_limits<double>::infinity();

struct Options {
  std::string scene;
  double dt = 0, end = 0;  // 0: the scene's
  int iterations = 10;     // btContactSolverInfo's default
  bool sleep = false;
  bool ccd = false;  // Bullet's continuous collision detection for fast bodies
};

[[noreturn]] void fail(const std::string& why) {
  std::fprintf(stderr, "compare_bullet: %s\n", why.c_str());
  std::exit(3);
}

// A number (or "1/60") from the command line, positive and finite.
double positive(const std::string& text, const char* what) {
  double value = 0;
  const auto slash = text.find('/');
  char* end = nullptr;
  if (slash != std::string::npos) {
    const double num = std::strtod(text.substr(0, slash).c_str(), &end);
    const double den = std::strtod(text.substr(slash + 1).c_str(), &end);
    value = num / den;
  } else {
    value = std::strtod(text.c_str(), &end);
    if (*end != '\0') value = -1;
  }
  if (!std::isfinite(value) || value <= 0) {
    std::fprintf(stderr, "compare_bullet: %s must be a positive number, got '%s'\n", what, text.c_str());
    std::exit(2);
  }
  return value;
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (++i == argc) {
        std::fprintf(stderr, "compare_bullet: %s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[i];
    };
    if (a == "--sleep") o.sleep = true;
    else if (a == "--ccd") o.ccd = true;
    else if (a == "--dt") o.dt = positive(next(), "--dt");
    else if (a == "--end") o.end = positive(next(), "--end");
    else if (a == "--iterations") o.iterations = static_cast<int>(positive(next(), "--iterations"));
    else if (o.scene.empty() && a.rfind("--", 0) != 0) o.scene = a;
    else {
      std::fprintf(stderr,
                   "usage: compare_bullet SCENE.json [--dt 1/60|SECONDS] [--end SECONDS] [--iterations N] [--sleep] [--ccd]\n");
      std::exit(2);
    }
  }
  if (o.scene.empty()) {
    std::fprintf(stderr, "usage: compare_bullet SCENE.json [--dt 1/60|SECONDS] [--end SECONDS] [--iterations N] [--sleep] [--ccd]\n");
    std::exit(2);
  }
  return o;
}

// A JSON value at `path` that must be an array of 3 finite numbers.
btVector3 vec3(const json& j, const std::string& path) {
  if (!j.is_array() || j.size() != 3) fail(path + ": expected an array of 3 numbers");
  double v[3];
  for (int k = 0; k < 3; ++k) {
    if (!j[k].is_number() || !std::isfinite(j[k].get<double>())) fail(path + ": expected finite numbers");
    v[k] = j[k].get<double>();
  }
  return btVector3(btScalar(v[0]), btScalar(v[1]), btScalar(v[2]));
}

double number(const json& object, const char* key, double fallback, const std::string& path) {
  if (!object.contains(key)) return fallback;
  const json& j = object.at(key);
  if (!j.is_number() || !std::isfinite(j.get<double>())) fail(path + "." + key + ": expected a finite number");
  return j.get<double>();
}

// Fails naming the first key of `object` that is not in `known`.
void refuseOtherKeys(const json& object, std::initializer_list<const char*> known, const std::string& path) {
  if (!object.is_object()) fail(path + ": expected an object");
  for (const auto& item : object.items()) {
    bool listed = false;
    for (const char* k : known) listed = listed || item.key() == k;
    // `path` is "FILE:" for the file's top level, else a JSON path ("FILE: entities[3]").
    if (!listed) fail(path + (path.back() == ':' ? " " : ".") + item.key() + ": not carried over to Bullet");
  }
}

btScalar combineFrictionByMinimum(const btCollisionObject* a, const btCollisionObject* b) {
  return std::min(a->getFriction(), b->getFriction());
}
btScalar combineRestitutionByMinimum(const btCollisionObject* a, const btCollisionObject* b) {
  return std::min(a->getRestitution(), b->getRestitution());
}

struct Scene {
  btVector3 gravity{0, btScalar(-9.81), 0};
  double dt = 0, end = 0;
  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  std::vector<std::unique_ptr<btDefaultMotionState>> states;
  std::vector<std::unique_ptr<btRigidBody>> bodies;
  std::vector<double> sizes;  // smallest extent of each body (Monolith's minimumSize), inf for a plane
  std::vector<btVector3> start;
};

Scene load(const Options& o) {
  std::ifstream in(o.scene);
  if (!in) fail(o.scene + ": cannot open");
  std::stringstream text;
  text << in.rdbuf();
  json root;
  try {
    root = json::parse(text.str(), nullptr, true, /*ignore_comments=*/true);
  } catch (const std::exception& e) {
    fail(o.scene + ": not JSON: " + e.what());
  }
  Scene s;
  // Monolith's own solver settings ("solvers") have no Bullet counterpart and are left out.
  refuseOtherKeys(root, {"description", "dimension", "time", "gravity", "entities", "solvers"}, o.scene + ":");
  if (root.value("dimension", 3) != 3) fail(o.scene + ": dimension: only 3-D scenes run in Bullet here");
  if (root.contains("gravity")) s.gravity = vec3(root["gravity"], o.scene + ": gravity");
  const json time = root.value("time", json::object());
  s.dt = o.dt > 0 ? o.dt : number(time, "dt", 0, o.scene + ": time");
  s.end = o.end > 0 ? o.end : number(time, "end", 0, o.scene + ": time");
  if (!(s.dt > 0) || !(s.end > 0)) fail(o.scene + ": time: expected positive dt and end");
  if (!root.contains("entities") || !root["entities"].is_array()) fail(o.scene + ": entities: expected an array");
  for (std::size_t e = 0; e < root["entities"].size(); ++e) {
    const json& entity = root["entities"][e];
    const std::string path = o.scene + ": entities[" + std::to_string(e) + "]";
    // Anything not listed here (a kinematic motion, forces, a fluid ...) would make Bullet run
    // a different scene: refused.
    refuseOtherKeys(entity, {"name", "shape", "rigid_body", "collider"}, path);
    if (!entity.contains("rigid_body")) fail(path + ".rigid_body: every entity must be a rigid body here");
    const json& rb = entity["rigid_body"];
    refuseOtherKeys(rb, {"static", "mass", "position", "orientation", "velocity", "angular_velocity"},
                    path + ".rigid_body");
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
        const json& q = rb["orientation"];
        if (!q.is_array() || q.size() != 4) fail(path + ".rigid_body.orientation: expected [w, x, y, z]");
        pose.setRotation(btQuaternion(btScalar(q[1].get<double>()), btScalar(q[2].get<double>()),
                                      btScalar(q[3].get<double>()), btScalar(q[0].get<double>())).normalized());
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

  const long steps = std::lround(scene.end / scene.dt);
  double wall = 0, penetration = 0;
  for (long n = 0; n < steps; ++n) {
    const auto t0 = std::chrono::steady_clock::now();
    world.stepSimulation(btScalar(scene.dt), 0);  // no sub-steps: exactly one step of dt
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
  const std::string name = o.scene.substr(o.scene.find_last_of('/') + 1);
  std::printf("| Bullet %d (%zu-byte btScalar) | %s | %d | 1/%.4g | %ld | %d | %s | %.1f | %.2e | %.2e | %.2e | %.3g %% | %s |\n",
              btGetVersion(), sizeof(btScalar), name.c_str(), dynamic, 1 / scene.dt, steps, o.iterations,
              o.sleep ? "on" : "off", 1e6 * wall / steps, drift, kinetic, penetration,
              100 * (highestEnergy - initialEnergy) / std::abs(initialEnergy), o.ccd ? "on" : "off");
  return 0;
}
