// A Monolith rigid-body scene file run in Bullet (Debian's libbullet-dev: single precision, its
// default sequential-impulse solver), to measure the "popular engine" the contact speed goal is set
// against on the same machine and the same scene instead of quoting a figure.
//
// What carries over from the scene: gravity, dt and end time, and each entity's shape (sphere,
// box, capsule, cylinder, convex hull or plane), mass, inertia, pose, velocities, friction and
// restitution. The inertia is Monolith's own (components/shape.h, or the scene's principal
// moments), not Bullet's: Bullet gives capsules and hulls the inertia of their bounding box, which
// would make a different body. Anything else (a triangle mesh, a non-diagonal inertia, kinematic
// motion, forces, fluids, 2-D) is refused with the JSON path, rather than compared as a different
// scene. Monolith combines a pair's coefficients by their minimum
// (systems/contact_workspace.cpp, findPairImpulse); Bullet's combination callbacks are set to the
// same rule. Sleeping is off by default: a sleeping body costs nothing and Monolith has none, so
// per-step figures would not compare (`--sleep` turns Bullet's default deactivation back on).
//
// Collision margins: Bullet keeps boxes and cylinders at their size by colliding a core shrunk by
// the margin (default 0.04) and rounded by it, so a body thinner than twice the margin would get
// a core of negative size. Each body's margin is therefore min(0.04, a quarter of its smallest
// size); unit boxes keep Bullet's default. A hull is shrunk by its margin
// (btConvexHullComputer) so that with the margin added it is the scene's hull with rounded edges.
//
// Prints one row per run: us/step, the largest distance of a dynamic body from its start after
// the run, the final kinetic energy, the deepest contact penetration over the smaller body's
// size at any step (Bullet's own contact distances, measured at the start of each step, i.e. on
// the state the step before produced; sizes as Monolith measures them,
// solvers/collision/geometry.h) — the columns of bench_rigid_contact's tables — and the
// largest rise of the total energy (kinetic + gravity's potential) over its initial value after
// any step, relative to that value (the project's rule: at most 0.1 %).
//
// usage: compare_bullet SCENE.json [--dt 1/60|SECONDS] [--end SECONDS] [--iterations N] [--sleep] [--ccd]
//                       [--multibody]
//   --ccd: Bullet's continuous collision detection on every dynamic body (off by default, as in
//   Bullet).
//   --multibody: the jointed bodies as Bullet btMultiBody trees (Featherstone's articulated-body
//   algorithm in reduced coordinates, btMultiBodyDynamicsWorld) instead of rigid bodies held by
//   btPoint2PointConstraints (maximal coordinates, sequential impulses). A tree whose root is
//   jointed to the world gets a fixed base at that anchor; one whose root is a free body gets
//   that body as a floating base. Its bodies must have no collider and start at rest (refused
//   with the JSON path otherwise), and Bullet's default multibody damping is off.
#include <btBulletDynamicsCommon.h>
#include <BulletDynamics/Featherstone/btMultiBody.h>
#include <BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h>
#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>
#include <LinearMath/btConvexHullComputer.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "components/shape.h"
#include "scene_file.h"
#include "solvers/collision/geometry.h"

namespace {

using namespace comparisons;
constexpr double kInfinite = std::numeric_limits<double>::infinity();
constexpr const char* kUsage =
    "SCENE.json [--dt 1/60|SECONDS] [--end SECONDS] [--iterations N] [--sleep] [--ccd] [--multibody]";

struct Options : CommonOptions {
  int iterations = 10;     // btContactSolverInfo's default
  bool ccd = false;        // Bullet's continuous collision detection for fast bodies
  bool multibody = false;  // jointed bodies as btMultiBody trees instead of point-to-point constraints
};

Options parse(int argc, char** argv) {
  Options o;
  static_cast<CommonOptions&>(o) = parseCommon(argc, argv, kUsage, [&](const std::string& a, auto&& next) {
    if (a == "--ccd") o.ccd = true;
    else if (a == "--multibody") o.multibody = true;
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

constexpr double kBulletMargin = 0.04;  // Bullet's default collision margin (CONVEX_DISTANCE_MARGIN)

// The margin of a body of the given smallest size: Bullet's default, or a quarter of the size
// for a thin body (see the top of this file).
btScalar marginFor(double size) { return btScalar(std::min(kBulletMargin, 0.25 * size)); }

// A scene shape in Bullet, with its size as Monolith measures it and Monolith's description of it
// (for the inertia).
struct MadeShape {
  std::unique_ptr<btCollisionShape> shape;
  double size = kInfinite;
  monolith::Shape<3> monolithShape;
};

// The smallest size of a shape as Monolith's narrow phase measures it (a box's smallest extent,
// a hull's least width ...), so that the overlap column means the same thing in both programs.
double monolithSize(const monolith::solvers::collision::Geometry<3>& g, const std::string& path) {
  try {
    return monolith::solvers::collision::PreparedGeometry<3>(g).minimumSize();
  } catch (const std::exception& e) {
    fail(path + ": " + e.what());
  }
}

MadeShape makeShape(const json& shape, const std::string& path, bool isStatic, const btVector3& x) {
  namespace col = monolith::solvers::collision;
  MadeShape m;
  col::Geometry<3> g;
  const std::string type = shape.value("type", "");
  if (type == "sphere") {
    refuseOtherKeys(shape, {"type", "radius"}, path, "Bullet");
    const double r = positiveNumber(shape, "radius", 0, path);
    m.shape = std::make_unique<btSphereShape>(btScalar(r));
    m.monolithShape.type = monolith::ShapeType::Sphere;
    m.monolithShape.radius = r;
    m.size = 2 * r;
  } else if (type == "box") {
    refuseOtherKeys(shape, {"type", "half_extents"}, path, "Bullet");
    const auto h = numbers<3>(shape.value("half_extents", json()), path + ".half_extents");
    if (!(std::min({h[0], h[1], h[2]}) > 0)) fail(path + ".half_extents: expected positive numbers");
    m.monolithShape.type = monolith::ShapeType::Box;
    m.monolithShape.halfExtents = Eigen::Vector3d(h[0], h[1], h[2]);
    m.size = 2 * std::min({h[0], h[1], h[2]});
    m.shape = std::make_unique<btBoxShape>(btVector3(btScalar(h[0]), btScalar(h[1]), btScalar(h[2])));
    m.shape->setMargin(marginFor(m.size));  // btBoxShape keeps its extents when the margin changes
  } else if (type == "capsule" || type == "cylinder") {
    refuseOtherKeys(shape, {"type", "radius", "half_height"}, path, "Bullet");
    const double r = positiveNumber(shape, "radius", 0, path), h = positiveNumber(shape, "half_height", 0, path);
    const bool capsule = type == "capsule";
    // Monolith's axis is the body's z: Bullet's Z variants. A capsule's height in Bullet is its
    // segment's length; its margin is its radius.
    m.monolithShape.type = capsule ? monolith::ShapeType::Capsule : monolith::ShapeType::Cylinder;
    m.monolithShape.radius = r;
    m.monolithShape.halfHeight = h;
    m.size = capsule ? 2 * r : 2 * std::min(r, h);
    if (capsule) {
      m.shape = std::make_unique<btCapsuleShapeZ>(btScalar(r), btScalar(2 * h));
    } else {
      m.shape = std::make_unique<btCylinderShapeZ>(btVector3(btScalar(r), btScalar(r), btScalar(h)));
      m.shape->setMargin(marginFor(m.size));  // kept at its size, as a box
    }
  } else if (type == "convex") {
    refuseOtherKeys(shape, {"type", "vertices"}, path, "Bullet");
    const json& vertices = shape.value("vertices", json());
    if (!vertices.is_array() || vertices.size() < 4) fail(path + ".vertices: expected at least 4 points");
    std::vector<double> coordinates;
    g.type = col::GeometryType::Convex;
    for (std::size_t i = 0; i < vertices.size(); ++i) {
      const auto v = numbers<3>(vertices[i], path + ".vertices[" + std::to_string(i) + "]");
      coordinates.insert(coordinates.end(), v.begin(), v.end());
      g.vertices.emplace_back(v[0], v[1], v[2]);
    }
    m.monolithShape.type = monolith::ShapeType::Convex;
    m.size = monolithSize(g, path);
    // Shrunk by the margin (at most a quarter of its inner radius), which Bullet adds back.
    btConvexHullComputer hull;
    const btScalar shrunk = hull.compute(coordinates.data(), 3 * int(sizeof(double)), int(vertices.size()),
                                         marginFor(m.size), btScalar(0.25));
    if (hull.vertices.size() < 4) fail(path + ".vertices: Bullet found no solid hull of these points");
    auto convex = std::make_unique<btConvexHullShape>();
    for (int i = 0; i < hull.vertices.size(); ++i) convex->addPoint(hull.vertices[i], false);
    convex->recalcLocalAabb();
    convex->setMargin(shrunk);
    m.shape = std::move(convex);
  } else if (type == "plane") {
    refuseOtherKeys(shape, {"type", "normal"}, path, "Bullet");
    if (!isStatic) fail(path + ": a plane must be static");
    btVector3 n = vec3(shape.value("normal", json()), path + ".normal");
    if (n.length2() == 0) fail(path + ".normal: expected a non-zero vector");
    n.normalize();
    m.shape = std::make_unique<btStaticPlaneShape>(n, n.dot(x));
    m.monolithShape.type = monolith::ShapeType::Plane;
  } else {
    fail(path + ".type: '" + type + "' is not carried over (sphere, box, capsule, cylinder, convex and plane are)");
  }
  return m;
}

// Principal moments of inertia in the body axes: the scene's, or Monolith's formula for the shape
// (the same one Monolith uses when the scene gives none).
btVector3 principalInertia(const json& rb, const monolith::Shape<3>& shape, double mass, const std::string& path) {
  Eigen::Matrix3d I;
  if (rb.contains("inertia")) {
    const json& given = rb["inertia"];
    if (given.is_array() && given.size() == 3 && given[0].is_array()) {
      for (int r = 0; r < 3; ++r) {
        const auto row = numbers<3>(given[r], path + ".inertia[" + std::to_string(r) + "]");
        for (int c = 0; c < 3; ++c) I(r, c) = row[c];
      }
      if (!I.isDiagonal(0))
        fail(path + ".inertia: a non-diagonal inertia is not carried over (Bullet takes principal moments)");
    } else {
      const auto d = numbers<3>(given, path + ".inertia");
      I = Eigen::Vector3d(d[0], d[1], d[2]).asDiagonal();
    }
  } else if (shape.type == monolith::ShapeType::Convex || shape.type == monolith::ShapeType::Plane) {
    fail(path + ".inertia: a convex hull needs the scene's inertia (Monolith has no formula for it either)");
  } else {
    I = shape.inertia(mass);
  }
  if (!(I.diagonal().minCoeff() > 0)) fail(path + ".inertia: expected positive moments");
  return btVector3(btScalar(I(0, 0)), btScalar(I(1, 1)), btScalar(I(2, 2)));
}

struct Scene {
  btVector3 gravity{0, btScalar(-9.81), 0};
  SceneTime time;
  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  std::vector<std::unique_ptr<btDefaultMotionState>> states;
  std::vector<std::unique_ptr<btRigidBody>> bodies;
  std::vector<double> sizes;  // smallest extent of each body (Monolith's minimumSize), inf for a plane
  std::vector<btVector3> start;
  // Spherical joints (Monolith's "joint" with type spherical and a world anchor) as Bullet
  // point-to-point constraints; no other joint type is carried over.
  std::vector<std::unique_ptr<btPoint2PointConstraint>> joints;
  struct JointPivots {
    int parent = -1, child = -1;  // body indices, -1: the world
    btVector3 inParent, inChild;
  };
  std::vector<JointPivots> pivots;
  // The scene's spherical joints (body indices, -1: the world; the world anchor), whichever way
  // they are carried over.
  struct JointSpec {
    int parent, child;
    btVector3 anchor;
  };
  std::vector<JointSpec> jointSpecs;
};

Scene load(const Options& o) {
  const json root = readSceneFile(o.scene);
  Scene s;
  // Monolith's own solver settings ("solvers") have no Bullet counterpart and are left out.
  refuseOtherKeys(root, {"description", "dimension", "time", "gravity", "entities", "solvers", "checks"}, o.scene + ":",
                  "Bullet");
  if (root.value("dimension", 3) != 3) fail(o.scene + ": dimension: only 3-D scenes run in Bullet here");
  if (root.contains("gravity")) s.gravity = vec3(root["gravity"], o.scene + ": gravity");
  s.time = sceneTime(root, o);
  if (!root.contains("entities") || !root["entities"].is_array()) fail(o.scene + ": entities: expected an array");
  using WorldJoint = Scene::JointSpec;
  std::vector<WorldJoint> names;
  std::vector<bool> jointed(root["entities"].is_array() ? root["entities"].size() : 0, false);
  for (std::size_t e = 0; e < root["entities"].size(); ++e) {
    const json& entity = root["entities"][e];
    const std::string path = o.scene + ": entities[" + std::to_string(e) + "]";
    // Anything not listed here (a kinematic motion, forces, a fluid ...) would make Bullet run
    // a different scene: refused.
    refuseOtherKeys(entity, {"name", "shape", "rigid_body", "collider", "joint"}, path, "Bullet");
    if (!entity.contains("rigid_body")) fail(path + ".rigid_body: every entity must be a rigid body here");
    if (entity.contains("joint")) {
      const json& j = entity["joint"];
      if (j.value("type", "") != "spherical") fail(path + ".joint.type: only spherical joints (point-to-point) run in Bullet here");
      refuseOtherKeys(j, {"type", "parent", "anchor"}, path + ".joint", "Bullet");
      if (!j.contains("anchor")) fail(path + ".joint.anchor: a world anchor is needed here");
      const std::string parent = j.value("parent", "world");
      int p = -1;
      if (parent != "world") {
        for (std::size_t k = 0; k < e; ++k)
          if (root["entities"][k].value("name", "") == parent) p = static_cast<int>(k);
        if (p < 0) fail(path + ".joint.parent: the parent must be an earlier entity here");
      }
      names.push_back({p, static_cast<int>(e), vec3(j["anchor"], path + ".joint.anchor")});
      jointed[e] = true;
      if (p >= 0) jointed[p] = true;
    }
    const json& rb = entity["rigid_body"];
    refuseOtherKeys(rb, {"static", "mass", "inertia", "position", "orientation", "velocity", "angular_velocity"},
                    path + ".rigid_body", "Bullet");
    if (!entity.contains("shape")) fail(path + ".shape: a rigid body needs a shape");
    const json& shape = entity["shape"];
    const std::string type = shape.value("type", "");
    const bool isStatic = rb.value("static", false);
    const btVector3 x = rb.contains("position") ? vec3(rb["position"], path + ".rigid_body.position") : btVector3(0, 0, 0);
    btTransform pose;
    pose.setIdentity();
    MadeShape made = makeShape(shape, path + ".shape", isStatic, x);
    if (type != "plane") {
      pose.setOrigin(x);
      if (rb.contains("orientation")) {
        const auto q = numbers<4>(rb["orientation"], path + ".rigid_body.orientation");  // [w, x, y, z]
        pose.setRotation(btQuaternion(btScalar(q[1]), btScalar(q[2]), btScalar(q[3]), btScalar(q[0])).normalized());
      }
    }
    const double mass = isStatic ? 0 : positiveNumber(rb, "mass", 1.0, path + ".rigid_body");
    btVector3 inertia(0, 0, 0);
    if (mass > 0) inertia = principalInertia(rb, made.monolithShape, mass, path + ".rigid_body");
    s.shapes.push_back(std::move(made.shape));
    const double size = made.size;
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
  s.jointSpecs = names;
  if (o.multibody) {
    // A multibody's links are carried over as bodies of the articulated-body algorithm alone.
    for (std::size_t e = 0; e < jointed.size(); ++e) {
      if (!jointed[e]) continue;
      const json& entity = root["entities"][e];
      const std::string path = o.scene + ": entities[" + std::to_string(e) + "]";
      if (entity.contains("collider")) fail(path + ".collider: a body of a multibody (--multibody) has no collider here");
      const json& rb = entity["rigid_body"];
      if (rb.value("static", false)) fail(path + ".rigid_body.static: a multibody's body must be dynamic here");
      for (const char* key : {"velocity", "angular_velocity"})
        if (rb.contains(key) && vec3(rb[key], path + ".rigid_body." + key).length2() != 0)
          fail(path + ".rigid_body." + key + ": a multibody starts at rest here");
    }
  }
  // Joints need every entity to be a body (checked above), so entity index = body index.
  for (const WorldJoint& j : o.multibody ? std::vector<WorldJoint>{} : names) {
    Scene::JointPivots p;
    p.parent = j.parent, p.child = j.child;
    btRigidBody& child = *s.bodies[j.child];
    p.inChild = child.getCenterOfMassTransform().inverse() * j.anchor;
    if (j.parent < 0) {
      p.inParent = j.anchor;
      s.joints.push_back(std::make_unique<btPoint2PointConstraint>(child, p.inChild));
    } else {
      btRigidBody& parent = *s.bodies[j.parent];
      p.inParent = parent.getCenterOfMassTransform().inverse() * j.anchor;
      s.joints.push_back(std::make_unique<btPoint2PointConstraint>(parent, child, p.inParent, p.inChild));
    }
    s.pivots.push_back(p);
  }
  // Monolith's bodies without a collider touch nothing; in a jointed scene (a chain that swings
  // through itself) Bullet's must not either.
  if (!names.empty())
    for (std::size_t e = 0; e < s.bodies.size(); ++e)
      if (!root["entities"][e].contains("collider"))
        s.bodies[e]->setCollisionFlags(s.bodies[e]->getCollisionFlags() | btCollisionObject::CF_NO_CONTACT_RESPONSE);
  return s;
}

// The scene's jointed bodies as btMultiBody trees (--multibody). The rigid bodies load() made
// for them only carry their mass, inertia and initial pose; they are not added to the world.
struct MultiBodies {
  struct Link {
    int body = -1;    // the scene's body
    int parent = -1;  // the parent's link, -1: the base
    btVector3 parentComToPivot, pivotToCom;  // in the parent's frame, in the link's frame
  };
  struct Tree {
    std::unique_ptr<btMultiBody> body;
    int baseBody = -1;  // the floating base's scene body, -1: a fixed base at the root's anchor
    std::vector<Link> links;
  };
  std::vector<Tree> trees;
  std::vector<bool> member;  // per scene body: in a tree (and not in the rigid-body world)

  // Per tree: the links' (and base's, at 0) world-to-local rotations and centres, and their
  // angular and linear velocities in their own frames.
  struct Kinematics {
    btAlignedObjectArray<btQuaternion> worldToLocal;
    btAlignedObjectArray<btVector3> origin;
    std::vector<btVector3> omega, v;
  };
  static Kinematics kinematics(btMultiBody& mb) {
    Kinematics k;
    k.worldToLocal.resize(mb.getNumLinks() + 1);
    k.origin.resize(mb.getNumLinks() + 1);
    mb.forwardKinematics(k.worldToLocal, k.origin);
    k.omega.resize(mb.getNumLinks() + 1);
    k.v.resize(mb.getNumLinks() + 1);
    mb.compTreeLinkVelocities(k.omega.data(), k.v.data());
    return k;
  }
};

MultiBodies buildMultiBodies(const Scene& scene) {
  MultiBodies m;
  const int n = static_cast<int>(scene.bodies.size());
  m.member.assign(n, false);
  std::vector<int> parentOf(n, -2), jointOf(n, -1);  // -2: no joint, -1: jointed to the world
  for (std::size_t j = 0; j < scene.jointSpecs.size(); ++j) {
    parentOf[scene.jointSpecs[j].child] = scene.jointSpecs[j].parent;
    jointOf[scene.jointSpecs[j].child] = static_cast<int>(j);
  }
  std::vector<int> rootOf(n, -1);
  for (const auto& j : scene.jointSpecs) {
    // Parents come before their children (load() requires it), so a parent's root is known.
    const int root = j.parent < 0 ? j.child : (parentOf[j.parent] == -2 ? j.parent : rootOf[j.parent]);
    rootOf[j.child] = root;
    if (j.parent >= 0 && parentOf[j.parent] == -2) rootOf[j.parent] = j.parent;
    m.member[j.child] = true;
    if (j.parent >= 0) m.member[j.parent] = true;
  }
  const auto massOf = [&](int b) { return btScalar(1) / scene.bodies[b]->getInvMass(); };
  const auto poseOf = [&](int b) { return scene.bodies[b]->getCenterOfMassTransform(); };
  for (int r = 0; r < n; ++r) {
    if (!m.member[r] || rootOf[r] != r) continue;
    MultiBodies::Tree t;
    const bool fixed = parentOf[r] == -1;
    t.baseBody = fixed ? -1 : r;
    std::vector<int> linkOf(n, -1);
    for (int b = 0; b < n; ++b)
      if (m.member[b] && rootOf[b] == r && (fixed || b != r)) {
        linkOf[b] = static_cast<int>(t.links.size());
        t.links.push_back({b, -1, {}, {}});
      }
    const btVector3 basePosition = fixed ? scene.jointSpecs[jointOf[r]].anchor : poseOf(r).getOrigin();
    const btQuaternion baseRotation = fixed ? btQuaternion::getIdentity() : poseOf(r).getRotation();
    t.body = std::make_unique<btMultiBody>(static_cast<int>(t.links.size()), fixed ? btScalar(0) : massOf(r),
                                           fixed ? btVector3(0, 0, 0) : scene.bodies[r]->getLocalInertia(), fixed,
                                           /*canSleep=*/false);
    t.body->setBasePos(basePosition);
    t.body->setWorldToBaseRot(baseRotation.inverse());
    for (std::size_t k = 0; k < t.links.size(); ++k) {
      MultiBodies::Link& link = t.links[k];
      const Scene::JointSpec& j = scene.jointSpecs[jointOf[link.body]];
      const bool onBase = j.parent < 0 || j.parent == t.baseBody;
      link.parent = onBase ? -1 : linkOf[j.parent];
      const btVector3 parentX = onBase ? basePosition : poseOf(j.parent).getOrigin();
      const btQuaternion parentQ = onBase ? baseRotation : poseOf(j.parent).getRotation();
      const btTransform pose = poseOf(link.body);
      link.parentComToPivot = quatRotate(parentQ.inverse(), j.anchor - parentX);
      link.pivotToCom = quatRotate(pose.getRotation().inverse(), pose.getOrigin() - j.anchor);
      t.body->setupSpherical(static_cast<int>(k), massOf(link.body), scene.bodies[link.body]->getLocalInertia(),
                             link.parent, (pose.getRotation().inverse() * parentQ).normalized(), link.parentComToPivot,
                             link.pivotToCom, /*disableParentCollision=*/true);
    }
    t.body->finalizeMultiDof();
    // Bullet's multibody defaults damp (0.04) and cap joint speeds (100 rad/s): neither is in
    // the scene.
    t.body->setLinearDamping(0);
    t.body->setAngularDamping(0);
    t.body->setMaxCoordinateVelocity(btScalar(1e30));
    t.body->setHasSelfCollision(false);
    m.trees.push_back(std::move(t));
  }
  return m;
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
  btMultiBodyConstraintSolver multiBodySolver;
  MultiBodies multi;
  if (o.multibody) multi = buildMultiBodies(scene);
  std::unique_ptr<btDiscreteDynamicsWorld> worldPointer;
  if (o.multibody)
    worldPointer = std::make_unique<btMultiBodyDynamicsWorld>(&dispatcher, &broadphase, &multiBodySolver, &configuration);
  else
    worldPointer = std::make_unique<btDiscreteDynamicsWorld>(&dispatcher, &broadphase, &solver, &configuration);
  btDiscreteDynamicsWorld& world = *worldPointer;
  world.setGravity(scene.gravity);
  world.getSolverInfo().m_numIterations = o.iterations;
  const auto inWorld = [&](std::size_t i) { return !o.multibody || !multi.member[i]; };
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    scene.bodies[i]->setUserIndex(static_cast<int>(i));
    if (inWorld(i)) world.addRigidBody(scene.bodies[i].get());
  }
  for (auto& j : scene.joints) world.addConstraint(j.get(), true);
  for (auto& t : multi.trees) static_cast<btMultiBodyDynamicsWorld&>(world).addMultiBody(t.body.get());
  // The largest distance between a joint's two pivots (m); for a multibody, between the pivot as
  // its parent link places it and as its own link does.
  const auto jointError = [&] {
    double worst = 0;
    for (const auto& p : scene.pivots) {
      const btVector3 a = p.parent < 0 ? p.inParent : scene.bodies[p.parent]->getCenterOfMassTransform() * p.inParent;
      const btVector3 b = scene.bodies[p.child]->getCenterOfMassTransform() * p.inChild;
      worst = std::max(worst, double((a - b).length()));
    }
    for (auto& t : multi.trees) {
      const MultiBodies::Kinematics k = MultiBodies::kinematics(*t.body);
      for (std::size_t i = 0; i < t.links.size(); ++i) {
        const MultiBodies::Link& l = t.links[i];
        const int p = l.parent + 1;
        const btVector3 a = k.origin[p] + quatRotate(k.worldToLocal[p].inverse(), l.parentComToPivot);
        const btVector3 b = k.origin[int(i) + 1] - quatRotate(k.worldToLocal[int(i) + 1].inverse(), l.pivotToCom);
        worst = std::max(worst, double((a - b).length()));
      }
    }
    return worst;
  };
  // A multibody's links at their scene poses (the construction's convention checked; single
  // precision accumulates along a long chain: 1e-5 m at the end of 1000 links of 0.1 m).
  double builtOff = 0;
  for (auto& t : multi.trees) {
    const MultiBodies::Kinematics k = MultiBodies::kinematics(*t.body);
    for (std::size_t i = 0; i < t.links.size(); ++i) {
      const btTransform pose = scene.bodies[t.links[i].body]->getCenterOfMassTransform();
      const btQuaternion turn = k.worldToLocal[int(i) + 1] * pose.getRotation();  // (+-1, 0) when they agree
      const double off = (k.origin[int(i) + 1] - pose.getOrigin()).length() + btVector3(turn.x(), turn.y(), turn.z()).length();
      builtOff = std::max(builtOff, off);
      if (off > 1e-3) fail("--multibody: link " + std::to_string(i) + " built away from its scene pose");
    }
  }
  double jointErrorMax = 0;

  // Kinetic and total (kinetic + gravity's potential) energy of the dynamic bodies.
  const auto energies = [&] {
    double kinetic = 0, potential = 0;
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
      const auto& body = scene.bodies[i];
      if (body->getInvMass() == 0 || !inWorld(i)) continue;
      const double m = 1 / double(body->getInvMass());
      const btVector3 v = body->getLinearVelocity(), w = body->getAngularVelocity();
      kinetic += 0.5 * m * double(v.length2()) + 0.5 * double(w.dot(body->getInvInertiaTensorWorld().inverse() * w));
      potential -= m * double(scene.gravity.dot(body->getCenterOfMassPosition()));
    }
    for (auto& t : multi.trees) {
      const MultiBodies::Kinematics k = MultiBodies::kinematics(*t.body);
      for (int i = t.baseBody < 0 ? 1 : 0; i <= t.body->getNumLinks(); ++i) {
        const double m = i == 0 ? t.body->getBaseMass() : t.body->getLink(i - 1).m_mass;
        const btVector3 I = i == 0 ? t.body->getBaseInertia() : t.body->getLink(i - 1).m_inertiaLocal;
        const btVector3 w = k.omega[i];
        kinetic += 0.5 * m * double(k.v[i].length2()) + 0.5 * double(w.dot(I * w));
        potential -= m * double(scene.gravity.dot(k.origin[i]));
      }
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
    jointErrorMax = std::max(jointErrorMax, jointError());
  }
  double drift = 0;
  int dynamic = 0;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const btRigidBody& b = *scene.bodies[i];
    if (b.getInvMass() == 0) continue;
    ++dynamic;
    if (inWorld(i)) drift = std::max(drift, double((b.getCenterOfMassPosition() - scene.start[i]).length()));
  }
  for (auto& t : multi.trees) {
    const MultiBodies::Kinematics k = MultiBodies::kinematics(*t.body);
    if (t.baseBody >= 0) drift = std::max(drift, double((k.origin[0] - scene.start[t.baseBody]).length()));
    for (std::size_t i = 0; i < t.links.size(); ++i)
      drift = std::max(drift, double((k.origin[int(i) + 1] - scene.start[t.links[i].body]).length()));
  }
  const double kinetic = energies().first;
  const double energyChange = energies().second - initialEnergy;
  for (auto& j : scene.joints) world.removeConstraint(j.get());
  for (auto& t : multi.trees) static_cast<btMultiBodyDynamicsWorld&>(world).removeMultiBody(t.body.get());
  for (std::size_t i = 0; i < scene.bodies.size(); ++i)
    if (inWorld(i)) world.removeRigidBody(scene.bodies[i].get());

  std::printf("| engine | scene | bodies | dt | steps | solver iterations | sleeping | us/step | max drift | final KE | "
              "max penetration / size | max energy rise | CCD |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  std::printf("| Bullet %d (%zu-byte btScalar) | %s | %d | 1/%.4g | %ld | %d | %s | %.1f | %.2e | %.2e | %.2e | %s | %s |\n",
              btGetVersion(), sizeof(btScalar), fileName(o.scene).c_str(), dynamic, 1 / scene.time.dt, steps, o.iterations,
              o.sleep ? "on" : "off", 1e6 * wall / steps, drift, kinetic, penetration,
              energyRise(highestEnergy, initialEnergy).c_str(), o.ccd ? "on" : "off");
  if (!scene.joints.empty())
    std::printf("\n%zu point-to-point joints: max joint error %.3e m, energy end - start %.4g J\n", scene.joints.size(),
                jointErrorMax, energyChange);
  if (!multi.trees.empty())
    std::printf("\n%zu spherical joints in %zu multibodies (Featherstone): max joint error %.3e m, energy end - start %.4g J "
                "(links built within %.1e of their scene poses)\n",
                scene.jointSpecs.size(), multi.trees.size(), jointErrorMax, energyChange, builtOff);
  return 0;
}
