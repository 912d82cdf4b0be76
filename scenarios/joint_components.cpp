#include "scenarios/joint_components.h"

#include <cmath>
#include <map>
#include <sstream>

#include "components/joint.h"
#include "components/kinematic.h"
#include "components/rigid_body.h"
#include "ecs/config.h"
#include "solvers/articulation/joint_constraints.h"
#include "systems/joint_assembly.h"

namespace monolith {

namespace {

std::string formatNumber(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

Eigen::Quaterniond quaternionAt(const Config& c, const std::string& key) {
  const Eigen::VectorXd q = c.vector(key, 4);
  if (!(q.norm() > 1e-12)) c.failAt(key, "a non-zero quaternion [w, x, y, z]", "a zero quaternion");
  return Eigen::Quaterniond(q(0), q(1), q(2), q(3)).normalized();
}

// A joint frame in a body's frame: position and orientation (3-D, a quaternion) or angle (2-D).
template <int d>
void parseFrame(const Config& c, Eigen::Matrix<double, d, 1>& position, Orientation<d>& orientation) {
  position = c.vector("position", Eigen::VectorXd::Zero(d));
  if constexpr (d == 3) {
    if (c.has("orientation")) orientation = quaternionAt(c, "orientation");
  } else {
    orientation = c.number("angle", 0.0);
  }
}

template <int d>
void parsePd(const Config& c, ArticulationJoint<d>& j) {
  j.kp = c.number("kp", Bound::NonNegative);
  j.kd = c.number("kd", 0.0, Bound::NonNegative);
  const Json& target = c.raw()["target"];
  if (target.is_number()) {
    j.pd = PdTarget::Constant;
    j.target = c.number("target");
    return;
  }
  if (!target.is_object()) c.failAt("target", "an angle (rad), {\"sinusoid\": {...}} or {\"keyframes\": [[t, angle], ...]}", describeJson(target));
  const Config t = c.child("target");
  if (t.has("sinusoid")) {
    const Config s = t.child("sinusoid");
    j.pd = PdTarget::Sinusoid;
    j.target = s.number("offset", 0.0);
    j.amplitude = s.number("amplitude");
    j.frequency = s.number("frequency", Bound::Positive);
    j.phase = s.number("phase", 0.0);
    s.finish();
  } else {
    t.fail("{\"sinusoid\": {offset, amplitude, frequency, phase}} or {\"keyframes\": [[t, angle], ...]}",
           describeJson(target));
  }
  t.finish();
}

template <int d>
void parseKeyframes(const Config& t, ArticulationJoint<d>& j) {
  const Json& raw = t.raw()["keyframes"];
  const std::string path = t.pathOf("keyframes");
  if (!raw.is_array() || raw.empty())
    throw SceneError(t.file(), path, "a non-empty list of [time, angle] pairs", describeJson(raw));
  for (std::size_t i = 0; i < raw.size(); ++i) {
    const Json& k = raw[i];
    if (!k.is_array() || k.size() != 2 || !k[0].is_number() || !k[1].is_number())
      throw SceneError(t.file(), path + "[" + std::to_string(i) + "]", "a [time, angle] pair of numbers", describeJson(k));
    const double time = k[0].get<double>();
    if (!j.keyTimes.empty() && !(time > j.keyTimes.back()))
      throw SceneError(t.file(), path + "[" + std::to_string(i) + "]", "times increasing from one keyframe to the next",
                       formatNumber(time) + " after " + formatNumber(j.keyTimes.back()));
    j.keyTimes.push_back(time);
    j.keyAngles.push_back(k[1].get<double>());
  }
  j.pd = PdTarget::Keyframes;
}

// The joint types of a dimension: all six in 3-D; in 2-D (three DOFs a body) fixed, revolute
// (a pin) and prismatic.
template <int d>
std::vector<std::string> jointTypes() {
  if constexpr (d == 3) return {"fixed", "revolute", "spherical", "prismatic", "universal", "twist"};
  else return {"fixed", "revolute", "prismatic"};
}

template <int d>
void parseJoint(World<d>& world, Entity e, const Config& c) {
  ArticulationJoint<d> j;
  const std::vector<std::string> types = jointTypes<d>();
  const std::string type = c.oneOf("type", types, "");
  if (type.empty()) {
    std::string list;
    for (const auto& t : types) list += (list.empty() ? "" : ", ") + t;
    c.failAt("type", "one of " + list, "none");
  }
  j.type = type == "fixed"       ? JointType::Fixed
           : type == "revolute"  ? JointType::Revolute
           : type == "spherical" ? JointType::Spherical
           : type == "prismatic" ? JointType::Prismatic
           : type == "twist"     ? JointType::Twist
                                 : JointType::Universal;
  j.parent = c.string("parent");
  j.child = c.string("child", world.name(e));
  if (j.child.empty()) c.failAt("child", "the name of the child body (or a named entity with a rigid_body)", "none");
  if (j.child == "world") c.failAt("child", "a body; only the parent may be \"world\"", "\"world\"");
  if (j.child == j.parent) c.failAt("parent", "a body other than the child", "\"" + j.parent + "\" again");

  const bool frames = c.has("parent_frame") || c.has("child_frame");
  if (frames && (c.has("anchor") || c.has("axis")))
    c.failAt(c.has("anchor") ? "anchor" : "axis",
             "either a world \"anchor\" (and \"axis\") or \"parent_frame\" and \"child_frame\", not both", "both");
  if (frames) {
    if (!c.has("parent_frame") || !c.has("child_frame"))
      c.failAt(c.has("parent_frame") ? "child_frame" : "parent_frame", "both parent_frame and child_frame", "only one");
    const Config pf = c.child("parent_frame"), cf = c.child("child_frame");
    parseFrame(pf, j.parentAnchor, j.parentFrame);
    parseFrame(cf, j.childAnchor, j.childFrame);
    pf.finish();
    cf.finish();
  } else {
    if (!c.has("anchor"))
      c.failAt("anchor", "the joint's world point at the initial poses, or parent_frame and child_frame", "none");
    j.anchorInWorld = true;
    j.worldAnchor = c.vector("anchor", d);
    // In 2-D a pin turns about z whatever its frames; only the slide needs a direction.
    const bool axisNeeded = d == 3 ? j.type == JointType::Revolute || j.type == JointType::Prismatic ||
                                         j.type == JointType::Universal || j.type == JointType::Twist
                                   : j.type == JointType::Prismatic;
    if (c.has("axis")) {
      j.axisInWorld = true;
      j.worldAxis = c.vector("axis", d);
      if (!(j.worldAxis.norm() > 1e-12)) c.failAt("axis", "a non-zero direction", "a zero vector");
      j.worldAxis.normalize();
    } else if (axisNeeded) {
      c.failAt("axis", std::string("the ") + type + " joint's axis (a world direction)", "none");
    } else {
      j.axisInWorld = true;  // frames aligned with the world at the initial poses
    }
  }
  if (c.has("limits")) {
    if (j.type != JointType::Revolute && j.type != JointType::Twist)
      c.failAt("limits", "angle limits on a revolute or twist joint only", "a " + type + " joint");
    const Eigen::VectorXd l = c.vector("limits", 2);
    if (!(l(0) < l(1)) || l(0) < -3.14159265358979323846 || l(1) > 3.14159265358979323846)
      c.failAt("limits", "[lower, upper] in radians with -pi <= lower < upper <= pi",
               "[" + formatNumber(l(0)) + ", " + formatNumber(l(1)) + "]");
    j.limited = true;
    j.lower = l(0);
    j.upper = l(1);
  }
  if (c.has("slide_limits")) {
    if (j.type != JointType::Prismatic && j.type != JointType::Twist)
      c.failAt("slide_limits", "slide limits on a prismatic or twist joint only", "a " + type + " joint");
    const Eigen::VectorXd l = c.vector("slide_limits", 2);
    if (!(l(0) < l(1)))
      c.failAt("slide_limits", "[lower, upper] in length units with lower < upper",
               "[" + formatNumber(l(0)) + ", " + formatNumber(l(1)) + "]");
    j.slideLimited = true;
    j.slideLower = l(0);
    j.slideUpper = l(1);
  }
  if (c.has("pd")) {
    if (j.type != JointType::Revolute) c.failAt("pd", "PD control on a revolute joint only", "a " + type + " joint");
    const Config pd = c.child("pd");
    if (pd.raw().contains("target") && pd.raw()["target"].is_object() && pd.raw()["target"].contains("keyframes")) {
      pd.markUsed("target");
      j.kp = pd.number("kp", Bound::NonNegative);
      j.kd = pd.number("kd", 0.0, Bound::NonNegative);
      const Config t = pd.child("target");
      parseKeyframes(t, j);
      t.finish();
    } else {
      parsePd(pd, j);
    }
    pd.finish();
  }
  world.add(e, j);
}

template <int d>
void parseArticulation(World<d>& world, Entity e, const Config& c) {
  ArticulationSolver s;
  auto method = [&](const char* key) {
    return c.oneOf(key, {"pairwise", "global"}, "pairwise") == "global" ? ArticulationSolver::Method::Global
                                                                        : ArticulationSolver::Method::Pairwise;
  };
  s.post = method("post_stabilization");
  s.pre = method("pre_stabilization");
  s.preStabilization = c.boolean("pre_stabilize", true);
  s.postIterations = static_cast<int>(c.integer("post_iterations", s.postIterations, 1, 1000000));
  s.postTolerance = c.number("post_tolerance", s.postTolerance, Bound::Positive);
  s.preIterations = static_cast<int>(c.integer("pre_iterations", s.preIterations, 1, 1000000));
  s.preTolerance = c.number("pre_tolerance", s.preTolerance, Bound::Positive);
  s.contactRounds = static_cast<int>(c.integer("contact_rounds", s.contactRounds, 0, 1000));
  s.pushOutContactSweeps =
      static_cast<int>(c.integer("push_out_contact_sweeps", s.pushOutContactSweeps, 0, 1000000));
  s.pushOutContactPasses =
      static_cast<int>(c.integer("push_out_contact_passes", s.pushOutContactPasses, 1, 1000));
  s.contactSolveSweeps = static_cast<int>(c.integer("contact_solve_sweeps", s.contactSolveSweeps, 1, 1000000));
  s.rollingResistance = c.number("rolling_resistance", s.rollingResistance, Bound::NonNegative);
  s.stepThreeContactSolve = c.boolean("step_three_contact_solve", false);
  world.add(e, s);
}

// Union-find over bodies, the immovable ones (static, kinematic, world) all one node.
struct Groups {
  std::vector<int> parent;
  int find(int i) { return parent[i] == i ? i : parent[i] = find(parent[i]); }
};

// Loops of other joints over-constrain their bodies too when their rows repeat one another (a
// planar ring of hinges with parallel axes, a spherical joint closing a rigid ring): the
// Newton of pre-stabilization then asks for corrections no impulse can give, and the global
// form (App. C.2) diverges. Checked on the rows at the initial poses.
template <int d>
void refuseRedundantLoops(World<d>& world, const std::string& file, const std::vector<Entity>& created) {
  std::vector<solvers::ConstraintBody> bodies(1);  // 0: the world
  std::map<std::uint32_t, int> index;
  std::vector<solvers::JointDefinition> joints;
  std::vector<std::size_t> entityOf;
  auto bodyOf = [&](const std::string& name) {
    if (name == "world") return 0;
    const Entity e = *world.find(name);
    const auto [it, inserted] = index.emplace(e.index, static_cast<int>(bodies.size()));
    if (inserted) {
      const RigidBody<d>& b = *world.template get<RigidBody<d>>(e);
      bodies.push_back(constraintBody<d>(b, !b.isStatic && !world.template get<KinematicMotion<d>>(e)));
    }
    return it->second;
  };
  for (std::size_t i = 0; i < created.size(); ++i) {
    const ArticulationJoint<d>* j = world.template get<ArticulationJoint<d>>(created[i]);
    if (!j) continue;
    solvers::JointDefinition def = jointDefinition<d>(*j);
    def.limited = false;
    def.parent = bodyOf(j->parent);
    def.child = bodyOf(j->child);
    joints.push_back(def);
    entityOf.push_back(i);
  }
  const solvers::RedundantJoint r = solvers::firstRedundantJoint(joints, bodies);
  if (r.joint < 0) return;
  const ArticulationJoint<d>& j = *world.template get<ArticulationJoint<d>>(created[entityOf[r.joint]]);
  throw SceneError(file, "entities[" + std::to_string(entityOf[r.joint]) + "].joint",
                   "a joint whose rows the loop it closes does not already impose (such a loop over-constrains its bodies)",
                   "a " + std::string(jointTypeName(j.type)) + " joint between \"" + j.parent + "\" and \"" + j.child +
                       "\" closing a loop that already fixes " + std::to_string(r.redundantRows) + " of its rows");
}

}  // namespace

template <int d>
void registerJointComponents(Registry& r) {
  r.addComponentOf<d, ArticulationJoint<d>>(
      d == 3 ? "articulation joint: type (fixed, revolute, spherical, prismatic, universal, twist), parent (entity or "
               "\"world\"), child (default: this entity), anchor + axis (world, at the initial poses) or "
               "parent_frame/child_frame {position, orientation}; limits [lower, upper] (rad) on revolute and twist "
               "joints, slide_limits [lower, upper] on prismatic and twist joints, pd {kp, kd, target} on revolute "
               "joints"
             : "articulation joint of the plane: type (fixed, revolute (a pin), prismatic (slides along axis)), parent "
               "(entity or \"world\"), child (default: this entity), anchor + axis (world, at the initial poses) or "
               "parent_frame/child_frame {position, angle}; limits [lower, upper] and pd {kp, kd, target} on revolute "
               "joints, slide_limits [lower, upper] on prismatic joints",
      parseJoint<d>);
  r.addComponentOf<d, ArticulationSolver>(
      "how the scene's joints are solved (one per scene): post_stabilization/pre_stabilization \"pairwise\" or "
      "\"global\", pre_stabilize, post_iterations, post_tolerance, pre_iterations, pre_tolerance, contact_rounds, "
      "push_out_contact_sweeps, push_out_contact_passes, contact_solve_sweeps, rolling_resistance (m), step_three_contact_solve",
      parseArticulation<d>);
}

namespace {

// A world point as a point in a body's frame (pose x, orientation q).
Eigen::Vector3d toBodyFrame(const Eigen::Vector3d& p, const Eigen::Vector3d& x, const Eigen::Quaterniond& q) {
  return q.conjugate() * (p - x);
}
Eigen::Vector2d toBodyFrame(const Eigen::Vector2d& p, const Eigen::Vector2d& x, double angle) {
  return Eigen::Rotation2Dd(-angle) * (p - x);
}
// A joint frame in a body's frame whose z (3-D) or x (2-D) is the world axis.
Eigen::Quaterniond frameAlong(const Eigen::Vector3d& axis, const Eigen::Quaterniond& q) {
  return (q.conjugate() * Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), axis)).normalized();
}
double frameAlong(const Eigen::Vector2d& axis, double angle) { return std::atan2(axis.y(), axis.x()) - angle; }

}  // namespace

template <int d>
void resolveJoints(World<d>& world, const std::string& file, const std::vector<Entity>& created) {
  std::map<std::uint32_t, int> bodyIndex;  // entity index -> union-find node (0: immovable)
  Groups groups{{0}};
  bool settingsSeen = false;
  for (std::size_t i = 0; i < created.size(); ++i) {
    const std::string at = "entities[" + std::to_string(i) + "]";
    if (world.template get<ArticulationSolver>(created[i])) {
      if (settingsSeen)
        throw SceneError(file, at + ".articulation", "one \"articulation\" component in the scene", "a second one");
      settingsSeen = true;
    }
    ArticulationJoint<d>* j = world.template get<ArticulationJoint<d>>(created[i]);
    if (!j) continue;
    const std::string path = at + ".joint";
    auto body = [&](const std::string& name, const char* key) -> RigidBody<d>* {
      if (name == "world") return nullptr;
      const auto e = world.find(name);
      RigidBody<d>* b = e ? world.template get<RigidBody<d>>(*e) : nullptr;
      if (!b)
        throw SceneError(file, path + "." + key, "the name of an entity with a rigid_body, or \"world\"",
                         "\"" + name + "\"" + (e ? " (no rigid_body)" : " (no such entity)"));
      return b;
    };
    RigidBody<d>* parent = body(j->parent, "parent");
    RigidBody<d>* child = body(j->child, "child");
    auto immovable = [&](const std::string& name, const RigidBody<d>* b) {
      return !b || b->isStatic || world.template get<KinematicMotion<d>>(*world.find(name));
    };
    if (immovable(j->parent, parent) && immovable(j->child, child))
      throw SceneError(file, path, "a joint with at least one dynamic body",
                       "\"" + j->parent + "\" and \"" + j->child + "\", neither of which can move");

    const Eigen::Matrix<double, d, 1> xp = parent ? parent->x : Eigen::Matrix<double, d, 1>::Zero();
    const Orientation<d> qp = parent ? parent->orientation : RigidBody<d>::identityOrientation();
    if (j->anchorInWorld) {
      j->parentAnchor = toBodyFrame(j->worldAnchor, xp, qp);
      j->childAnchor = toBodyFrame(j->worldAnchor, child->x, child->orientation);
      j->anchorInWorld = false;
    }
    if (j->axisInWorld) {
      j->parentFrame = frameAlong(j->worldAxis, qp);
      j->childFrame = frameAlong(j->worldAxis, child->orientation);
      j->axisInWorld = false;
    }

    // Loops of fixed joints (through the ground too) lock a body twice: refused.
    auto node = [&](const std::string& name, bool fixedToGround) {
      if (fixedToGround) return 0;
      const std::uint32_t index = world.find(name)->index;
      auto [it, inserted] = bodyIndex.emplace(index, static_cast<int>(groups.parent.size()));
      if (inserted) groups.parent.push_back(it->second);
      return it->second;
    };
    if (j->type == JointType::Fixed) {
      const int a = groups.find(node(j->parent, immovable(j->parent, parent)));
      const int b = groups.find(node(j->child, immovable(j->child, child)));
      if (a == b)
        throw SceneError(file, path,
                         "a joint that closes no loop of fixed joints (such a loop over-constrains its bodies)",
                         "a fixed joint between \"" + j->parent + "\" and \"" + j->child + "\", already fixed together");
      groups.parent[std::max(a, b)] = std::min(a, b);
    }
  }
  refuseRedundantLoops(world, file, created);
}

template void registerJointComponents<2>(Registry&);
template void registerJointComponents<3>(Registry&);
template void resolveJoints<2>(World<2>&, const std::string&, const std::vector<Entity>&);
template void resolveJoints<3>(World<3>&, const std::string&, const std::vector<Entity>&);

}  // namespace monolith
