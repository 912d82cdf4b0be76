#pragma once
// The jointed bodies and joints of a world as the joint solvers (solvers/articulation) see them,
// shared by the joint stages (systems/articulation.cpp), the joint closing after push-out
// (systems/joint_contacts.cpp) and the scene's loop check (scenarios/joint_components.cpp).
// The solvers are 3-D; a 2-D world's bodies and joints are those of the plane z = 0 (a body
// turns about z only: inverse inertia diag(0, 0, 1/I)) and its joints are planar
// (solvers::JointDefinition::planar), so that one solver serves both dimensions.
#include <cmath>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

#include "components/joint.h"
#include "components/kinematic.h"
#include "components/rigid_body.h"
#include "components/sleep.h"
#include "ecs/world.h"
#include "solvers/articulation/joint_constraints.h"

namespace monolith {

// A 2-D point or direction in the plane z = 0; 3-D ones as they are.
template <int d>
Eigen::Vector3d liftVector(const Eigen::Matrix<double, d, 1>& v) {
  if constexpr (d == 3) return v;
  else return Eigen::Vector3d(v.x(), v.y(), 0.0);
}

// A 2-D orientation (angle) as the turn about z.
template <int d>
Eigen::Quaterniond liftOrientation(const Orientation<d>& q) {
  if constexpr (d == 3) return q;
  else return Eigen::Quaterniond(Eigen::AngleAxisd(q, Eigen::Vector3d::UnitZ()));
}

// The solver's view of a rigid body: pose, and with `movable` its inverse mass and inertia.
template <int d>
solvers::ConstraintBody constraintBody(const RigidBody<d>& b, bool movable) {
  solvers::ConstraintBody c;
  c.x = liftVector<d>(b.x);
  c.q = liftOrientation<d>(b.orientation);
  if (!movable) return c;
  c.invMass = 1 / b.mass;
  if constexpr (d == 3) c.invInertia = b.worldInverseInertia();
  else c.invInertia(2, 2) = b.worldInverseInertia()(0, 0);
  return c;
}

// The solver's joint (body indices left to the caller). A 2-D prismatic joint slides along its
// frames' x; the 3-D prismatic joint slides along z, so its frames are turned by R_y(90 deg),
// which takes z onto x and keeps the frame's y in the plane.
template <int d>
solvers::JointDefinition jointDefinition(const ArticulationJoint<d>& j) {
  solvers::JointDefinition def;
  def.type = static_cast<solvers::JointKind>(j.type);
  def.parentAnchor = liftVector<d>(j.parentAnchor);
  def.childAnchor = liftVector<d>(j.childAnchor);
  def.parentFrame = liftOrientation<d>(j.parentFrame);
  def.childFrame = liftOrientation<d>(j.childFrame);
  def.limited = j.limited;
  def.lower = j.lower;
  def.upper = j.upper;
  def.slideLimited = j.slideLimited;
  def.slideLower = j.slideLower;
  def.slideUpper = j.slideUpper;
  if constexpr (d == 2) {
    def.planar = true;
    if (j.type == JointType::Prismatic) {
      const Eigen::Quaterniond zOntoX(Eigen::AngleAxisd(0.5 * 3.14159265358979323846, Eigen::Vector3d::UnitY()));
      def.parentFrame = def.parentFrame * zOntoX;
      def.childFrame = def.childFrame * zOntoX;
    }
  }
  return def;
}

// The jointed bodies and joints of the world as the solvers see them. Body 0 is the world;
// bodies follow in the order the joints name them (joint pool order: deterministic).
template <int d>
struct JointAssembly {
  std::vector<solvers::ConstraintBody> bodies;
  std::vector<RigidBody<d>*> rigid;  // null for the world
  std::vector<Entity> entity;
  std::vector<bool> kinematic;
  std::vector<solvers::JointDefinition> joints;
  std::vector<const ArticulationJoint<d>*> components;
  std::unordered_map<std::uint32_t, int> index;  // entity index -> body

  explicit JointAssembly(World<d>& world) {
    bodies.emplace_back();
    rigid.push_back(nullptr);
    entity.push_back(Entity{});
    kinematic.push_back(false);
    const auto* sleeps = world.template findPool<Sleep<d>>();
    auto bodyOf = [&](const std::string& name) -> int {
      if (name == "world") return 0;
      const auto e = world.find(name);
      RigidBody<d>* b = e ? world.template get<RigidBody<d>>(*e) : nullptr;
      if (!b) throw std::logic_error("joint names '" + name + "', which is not a rigid body");
      const auto [it, inserted] = index.emplace(e->index, static_cast<int>(bodies.size()));
      if (!inserted) return it->second;
      const bool moving = world.template get<KinematicMotion<d>>(*e) != nullptr;
      const bool asleep = isAsleep<d>(sleeps, *e);
      solvers::ConstraintBody c = constraintBody<d>(*b, !(b->isStatic || moving || asleep));
      if (!b->isStatic && !asleep) {
        c.v = liftVector<d>(b->v);
        if constexpr (d == 3) c.w = b->omega();
        else c.w.z() = b->omega()(0);
      }
      bodies.push_back(c);
      rigid.push_back(b);
      entity.push_back(*e);
      kinematic.push_back(moving);
      return it->second;
    };
    const auto& pool = world.template pool<ArticulationJoint<d>>();
    for (const ArticulationJoint<d>& j : pool.components()) {
      solvers::JointDefinition def = jointDefinition<d>(j);
      def.parent = bodyOf(j.parent);
      def.child = bodyOf(j.child);
      joints.push_back(def);
      components.push_back(&j);
    }
  }

  std::vector<solvers::JointRows> rows() const {
    std::vector<solvers::JointRows> out;
    out.reserve(joints.size());
    for (const auto& j : joints) out.push_back(solvers::jointRows(j, bodies));
    return out;
  }

  // The new velocities of the dynamic bodies; angular momentum takes the torque impulses
  // exactly (L is the state, w is derived).
  void writeBack() const {
    for (std::size_t i = 1; i < bodies.size(); ++i) {
      if (bodies[i].invMass == 0) continue;
      if constexpr (d == 3) {
        rigid[i]->v = bodies[i].v;
        rigid[i]->L += bodies[i].angularImpulse;
      } else {
        rigid[i]->v = bodies[i].v.head<2>();
        rigid[i]->L(0) += bodies[i].angularImpulse.z();
      }
    }
  }
};

}  // namespace monolith
