// A Monolith 2-D rigid-body scene file run in Box2D (Debian's libbox2d-dev 2.4.1: single
// precision, its sequential-impulse solver with 8 velocity and 3 position iterations by default),
// the 2-D engine people use, measured on the same machine and the same scene.
//
// What carries over: gravity, dt and end time, and each entity's shape (box, disk, convex polygon
// of at most 8 vertices, plane as a long two-sided edge), mass (Box2D's uniform-density inertia,
// as Monolith's), pose, velocities, friction and restitution. A polygon is centred on its area
// centroid, as Monolith stores it (scenarios/contact_components.cpp). Friction and restitution
// are combined by the pair's minimum, Monolith's rule (Box2D's defaults are the geometric mean
// and the maximum), by a contact listener. Anything else is refused with its JSON path. Box2D
// keeps contacts up to 0.5 cm deep on purpose (b2_linearSlop) and is tuned for bodies of 0.1 to
// 10 m: figures for centimetre bodies are outside its design range.
//
// Joints: a "revolute" joint (a pin) with a world `anchor` and a parent that is "world" or an
// earlier entity becomes a b2RevoluteJoint (the linked bodies do not collide, as in Monolith);
// in a jointed scene a body without a `collider` touches nothing. Other joint types, frames,
// limits and PD are refused with the JSON path. The largest distance between a joint's two
// anchors over the run is printed after the row.
//
// Prints the row of compare_bullet: us/step, largest distance of a dynamic body from its start
// after the run, final kinetic energy, deepest contact penetration over the smaller body's size
// at any step (Box2D's separations at its contact points after the step), and the largest rise
// of the total energy over its initial value.
//
// usage: compare_box2d SCENE.json [--dt 1/60|SECONDS] [--end SECONDS] [--velocity-iterations N]
//                      [--position-iterations N] [--sleep]
#include <box2d/box2d.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "scene_file.h"

namespace {

using namespace comparisons;
constexpr double kInfinite = std::numeric_limits<double>::infinity();
constexpr const char* kUsage =
    "SCENE.json [--dt 1/60|SECONDS] [--end SECONDS] [--velocity-iterations N] [--position-iterations N] [--sleep]";

struct Options : CommonOptions {
  int velocityIterations = 8, positionIterations = 3;  // Box2D's recommended defaults
};

Options parse(int argc, char** argv) {
  Options o;
  static_cast<CommonOptions&>(o) = parseCommon(argc, argv, kUsage, [&](const std::string& a, auto&& next) {
    if (a == "--velocity-iterations") o.velocityIterations = static_cast<int>(positive(next(), a.c_str(), kUsage));
    else if (a == "--position-iterations") o.positionIterations = static_cast<int>(positive(next(), a.c_str(), kUsage));
    else return false;
    return true;
  });
  return o;
}

b2Vec2 vec2(const json& j, const std::string& path) {
  const auto v = numbers<2>(j, path);
  return b2Vec2(float(v[0]), float(v[1]));
}

// Monolith's rule for a pair's coefficients, applied to every contact before it is solved.
class MinimumCoefficients : public b2ContactListener {
 public:
  void PreSolve(b2Contact* contact, const b2Manifold*) override {
    const b2Fixture* a = contact->GetFixtureA();
    const b2Fixture* b = contact->GetFixtureB();
    contact->SetFriction(std::min(a->GetFriction(), b->GetFriction()));
    contact->SetRestitution(std::min(a->GetRestitution(), b->GetRestitution()));
  }
};

// The smallest width of a convex outline (over its edge normals): Monolith's minimumSize.
double smallestWidth(const std::vector<b2Vec2>& v) {
  double width = kInfinite;
  for (std::size_t i = 0; i < v.size(); ++i) {
    b2Vec2 n(v[(i + 1) % v.size()].y - v[i].y, v[i].x - v[(i + 1) % v.size()].x);
    n.Normalize();
    double lo = kInfinite, hi = -kInfinite;
    for (const b2Vec2& p : v) lo = std::min(lo, double(b2Dot(n, p))), hi = std::max(hi, double(b2Dot(n, p)));
    width = std::min(width, hi - lo);
  }
  return width;
}

// A pin of the scene: body indices (-1: the world) and the world anchor at the initial poses.
struct Pin {
  int parent = -1, child = -1;
  b2Vec2 anchor;
};

struct Body {
  b2Body* body = nullptr;
  double size = kInfinite;  // smallest extent (Monolith's minimumSize); infinite for a plane
  b2Vec2 start;
};

// Builds the scene's bodies in `world`; returns them in entity order, and the pins in `pins`.
std::vector<Body> load(const Options& o, const json& root, b2World& world, std::vector<Pin>& pins) {
  refuseOtherKeys(root, {"description", "dimension", "time", "gravity", "entities", "solvers", "checks"}, o.scene + ":",
                  "Box2D");
  if (root.value("dimension", 3) != 2) fail(o.scene + ": dimension: only 2-D scenes run in Box2D");
  if (root.contains("gravity")) world.SetGravity(vec2(root["gravity"], o.scene + ": gravity"));
  if (!root.contains("entities") || !root["entities"].is_array()) fail(o.scene + ": entities: expected an array");
  std::vector<Body> bodies;
  bool jointed = false;
  for (const json& entity : root["entities"]) jointed = jointed || (entity.is_object() && entity.contains("joint"));
  for (std::size_t e = 0; e < root["entities"].size(); ++e) {
    const json& entity = root["entities"][e];
    const std::string path = o.scene + ": entities[" + std::to_string(e) + "]";
    refuseOtherKeys(entity, {"name", "shape", "rigid_body", "collider", "joint"}, path, "Box2D");
    if (entity.contains("joint")) {
      const json& j = entity["joint"];
      refuseOtherKeys(j, {"type", "parent", "anchor"}, path + ".joint", "Box2D");
      if (j.value("type", "") != "revolute") fail(path + ".joint.type: only revolute joints (pins) run in Box2D here");
      if (!j.contains("anchor")) fail(path + ".joint.anchor: a world anchor is needed here");
      Pin pin;
      pin.child = static_cast<int>(e);
      pin.anchor = vec2(j["anchor"], path + ".joint.anchor");
      const std::string parent = j.value("parent", "world");
      if (parent != "world") {
        for (std::size_t k = 0; k < e; ++k)
          if (root["entities"][k].value("name", "") == parent) pin.parent = static_cast<int>(k);
        if (pin.parent < 0) fail(path + ".joint.parent: the parent must be an earlier entity here");
      }
      pins.push_back(pin);
    }
    if (!entity.contains("rigid_body")) fail(path + ".rigid_body: every entity must be a rigid body here");
    if (!entity.contains("shape")) fail(path + ".shape: a rigid body needs a shape");
    const json& rb = entity["rigid_body"];
    refuseOtherKeys(rb, {"static", "mass", "position", "angle", "velocity", "angular_velocity"}, path + ".rigid_body",
                    "Box2D");
    const json& shape = entity["shape"];
    const std::string type = shape.value("type", "");
    const bool isStatic = rb.value("static", false);
    const b2Vec2 x = rb.contains("position") ? vec2(rb["position"], path + ".rigid_body.position") : b2Vec2(0, 0);
    const double mass = isStatic ? 0 : positiveNumber(rb, "mass", 1.0, path + ".rigid_body");

    b2BodyDef def;
    def.type = isStatic ? b2_staticBody : b2_dynamicBody;
    def.position = x;
    def.angle = float(number(rb, "angle", 0.0, path + ".rigid_body"));
    if (!isStatic) {
      if (rb.contains("velocity")) def.linearVelocity = vec2(rb["velocity"], path + ".rigid_body.velocity");
      def.angularVelocity = float(number(rb, "angular_velocity", 0.0, path + ".rigid_body"));
    }
    def.allowSleep = o.sleep;
    Body made;
    made.start = x;
    made.body = world.CreateBody(&def);

    const json collider = entity.value("collider", json::object());
    b2FixtureDef fixture;
    fixture.friction = float(number(collider, "friction", 0.5, path + ".collider"));
    fixture.restitution = float(number(collider, "restitution", 0.0, path + ".collider"));
    b2PolygonShape polygon;
    b2CircleShape circle;
    b2EdgeShape edge;
    double area = 0;
    if (type == "box") {
      const auto h = numbers<2>(shape.value("half_extents", json()), path + ".shape.half_extents");
      if (!(h[0] > 0 && h[1] > 0)) fail(path + ".shape.half_extents: expected positive numbers");
      polygon.SetAsBox(float(h[0]), float(h[1]));
      fixture.shape = &polygon;
      area = 4 * h[0] * h[1];
      made.size = 2 * std::min(h[0], h[1]);
    } else if (type == "disk") {
      const double r = positiveNumber(shape, "radius", 0, path + ".shape");
      circle.m_radius = float(r);
      fixture.shape = &circle;
      area = M_PI * r * r;
      made.size = 2 * r;
    } else if (type == "polygon") {
      const json& list = shape.value("vertices", json());
      if (!list.is_array() || list.size() < 3 || list.size() > std::size_t(b2_maxPolygonVertices))
        fail(path + ".shape.vertices: expected 3 to " + std::to_string(b2_maxPolygonVertices) + " vertices (Box2D's limit)");
      std::vector<b2Vec2> v;
      for (std::size_t i = 0; i < list.size(); ++i)
        v.push_back(vec2(list[i], path + ".shape.vertices[" + std::to_string(i) + "]"));
      double twiceArea = 0;
      b2Vec2 centroid(0, 0);
      for (std::size_t i = 0; i < v.size(); ++i) {
        const b2Vec2 a = v[i], b = v[(i + 1) % v.size()];
        const double cross = double(a.x) * b.y - double(a.y) * b.x;
        twiceArea += cross;
        centroid += float(cross / 3) * (a + b);
      }
      if (!(std::abs(twiceArea) > 0)) fail(path + ".shape.vertices: a polygon of non-zero area");
      centroid *= float(1 / twiceArea);
      for (b2Vec2& p : v) p -= centroid;
      polygon.Set(v.data(), int32(v.size()));
      // Box2D welds vertices closer than half its slop and falls back to a unit box when the
      // hull degenerates: that would be a different body, so it is refused.
      if (polygon.m_count != int32(v.size()))
        fail(path + ".shape.vertices: Box2D merges some of these vertices (closer than " +
             std::to_string(0.5 * b2_linearSlop) + " m or not convex)");
      fixture.shape = &polygon;
      area = 0.5 * std::abs(twiceArea);
      made.size = smallestWidth(v);
    } else if (type == "plane") {
      if (!isStatic) fail(path + ".shape: a plane must be static");
      b2Vec2 n = vec2(shape.value("normal", json()), path + ".shape.normal");
      if (!(n.Length() > 0)) fail(path + ".shape.normal: expected a non-zero vector");
      n.Normalize();
      const b2Vec2 along(-n.y, n.x);
      edge.SetTwoSided(-1000.0f * along, 1000.0f * along);  // the body sits on the plane's point
      fixture.shape = &edge;
    } else {
      fail(path + ".shape.type: '" + type + "' is not carried over (box, disk, polygon and plane are)");
    }
    fixture.density = isStatic ? 0.0f : float(mass / area);
    // Monolith's bodies without a collider touch nothing; in a jointed scene (a chain that swings
    // through itself) Box2D's must not either.
    if (jointed && !entity.contains("collider")) fixture.filter.maskBits = 0;
    made.body->CreateFixture(&fixture);
    bodies.push_back(made);
  }
  return bodies;
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  const json root = readSceneFile(o.scene);
  const SceneTime time = sceneTime(root, o);
  b2World world(b2Vec2(0, -9.81f));
  world.SetAllowSleeping(o.sleep);
  MinimumCoefficients coefficients;
  world.SetContactListener(&coefficients);
  std::vector<Pin> pins;
  std::vector<Body> bodies = load(o, root, world, pins);
  for (std::size_t i = 0; i < bodies.size(); ++i) bodies[i].body->GetUserData().pointer = i;
  // Pins to the world hang on one static body without a fixture.
  b2Body* ground = nullptr;
  std::vector<b2Joint*> joints;
  for (const Pin& pin : pins) {
    if (pin.parent < 0 && !ground) {
      b2BodyDef def;
      ground = world.CreateBody(&def);
    }
    b2RevoluteJointDef def;
    def.Initialize(pin.parent < 0 ? ground : bodies[pin.parent].body, bodies[pin.child].body, pin.anchor);
    joints.push_back(world.CreateJoint(&def));
  }
  // The largest distance between a joint's two anchors (m).
  const auto jointError = [&] {
    double worst = 0;
    for (const b2Joint* j : joints) worst = std::max(worst, double((j->GetAnchorA() - j->GetAnchorB()).Length()));
    return worst;
  };
  double jointErrorMax = 0;

  // Kinetic and total (kinetic + gravity's potential) energy of the dynamic bodies.
  const auto energies = [&] {
    double kinetic = 0, potential = 0;
    for (const Body& b : bodies) {
      const b2Body& body = *b.body;
      if (body.GetType() != b2_dynamicBody) continue;
      const double m = body.GetMass();
      const b2Vec2 c = body.GetLocalCenter();
      const double inertia = body.GetInertia() - m * double(b2Dot(c, c));  // about the centre of mass
      const double w = body.GetAngularVelocity();
      kinetic += 0.5 * m * double(body.GetLinearVelocity().LengthSquared()) + 0.5 * inertia * w * w;
      potential -= m * double(b2Dot(world.GetGravity(), body.GetWorldCenter()));
    }
    return std::make_pair(kinetic, kinetic + potential);
  };
  const double initialEnergy = energies().second;
  double highestEnergy = initialEnergy, wall = 0, penetration = 0;
  for (long n = 0; n < time.steps; ++n) {
    const auto t0 = std::chrono::steady_clock::now();
    world.Step(float(time.dt), o.velocityIterations, o.positionIterations);
    wall += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    for (b2Contact* c = world.GetContactList(); c; c = c->GetNext()) {  // outside the timed part
      if (!c->IsTouching()) continue;
      b2WorldManifold manifold;
      c->GetWorldManifold(&manifold);
      const double size = std::min(bodies[c->GetFixtureA()->GetBody()->GetUserData().pointer].size,
                                   bodies[c->GetFixtureB()->GetBody()->GetUserData().pointer].size);
      for (int p = 0; p < c->GetManifold()->pointCount; ++p)
        penetration = std::max(penetration, -double(manifold.separations[p]) / size);
    }
    highestEnergy = std::max(highestEnergy, energies().second);
    jointErrorMax = std::max(jointErrorMax, jointError());
  }
  double drift = 0;
  int dynamic = 0;
  for (const Body& b : bodies) {
    if (b.body->GetType() != b2_dynamicBody) continue;
    ++dynamic;
    drift = std::max(drift, double((b.body->GetPosition() - b.start).Length()));
  }

  std::printf("| engine | scene | bodies | dt | steps | solver iterations | sleeping | us/step | max drift | final KE | "
              "max penetration / size | max energy rise |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  std::printf("| Box2D %d.%d.%d (%zu-byte float) | %s | %d | 1/%.4g | %ld | %d velocity, %d position | %s | %.1f | %.2e | "
              "%.2e | %.2e | %s |\n",
              b2_version.major, b2_version.minor, b2_version.revision, sizeof(float), fileName(o.scene).c_str(), dynamic,
              1 / time.dt, time.steps, o.velocityIterations, o.positionIterations, o.sleep ? "on" : "off",
              1e6 * wall / time.steps, drift, energies().first, penetration,
              energyRise(highestEnergy, initialEnergy).c_str());
  if (!joints.empty())
    std::printf("\n%zu revolute joints: max joint error %.3e m, energy end - start %.4g J\n", joints.size(),
                jointErrorMax, energies().second - initialEnergy);
  return 0;
}
