#pragma once
// The jointed bodies and joints of a world as the joint solvers (solvers/articulation) see them,
// shared by the joint stages (systems/articulation.cpp) and the joint closing after push-out
// (systems/joint_contacts.cpp).
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

// The jointed bodies and joints of the world as the solvers see them. Body 0 is the world;
// bodies follow in the order the joints name them (joint pool order: deterministic).
struct JointAssembly {
  std::vector<solvers::ConstraintBody> bodies;
  std::vector<RigidBody<3>*> rigid;  // null for the world
  std::vector<Entity> entity;
  std::vector<bool> kinematic;
  std::vector<solvers::JointDefinition> joints;
  std::vector<const Joint*> components;
  std::unordered_map<std::uint32_t, int> index;  // entity index -> body

  explicit JointAssembly(World<3>& world) {
    bodies.emplace_back();
    rigid.push_back(nullptr);
    entity.push_back(Entity{});
    kinematic.push_back(false);
    const auto* sleeps = world.findPool<Sleep<3>>();
    auto bodyOf = [&](const std::string& name) -> int {
      if (name == "world") return 0;
      const auto e = world.find(name);
      RigidBody<3>* b = e ? world.get<RigidBody<3>>(*e) : nullptr;
      if (!b) throw std::logic_error("joint names '" + name + "', which is not a rigid body");
      const auto [it, inserted] = index.emplace(e->index, static_cast<int>(bodies.size()));
      if (!inserted) return it->second;
      solvers::ConstraintBody c;
      c.x = b->x;
      c.q = b->orientation;
      const bool moving = world.get<KinematicMotion<3>>(*e) != nullptr;
      const bool immovable = b->isStatic || moving || isAsleep<3>(sleeps, *e);
      if (!immovable) {
        c.invMass = 1 / b->mass;
        c.invInertia = b->worldInverseInertia();
      }
      if (!b->isStatic && !isAsleep<3>(sleeps, *e)) {
        c.v = b->v;
        c.w = b->omega();
      }
      bodies.push_back(c);
      rigid.push_back(b);
      entity.push_back(*e);
      kinematic.push_back(moving);
      return it->second;
    };
    const auto& pool = world.pool<Joint>();
    for (const Joint& j : pool.components()) {
      solvers::JointDefinition def;
      def.type = static_cast<solvers::JointKind>(j.type);
      def.parent = bodyOf(j.parent);
      def.child = bodyOf(j.child);
      def.parentAnchor = j.parentAnchor;
      def.childAnchor = j.childAnchor;
      def.parentFrame = j.parentFrame;
      def.childFrame = j.childFrame;
      def.limited = j.limited;
      def.lower = j.lower;
      def.upper = j.upper;
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
      rigid[i]->v = bodies[i].v;
      rigid[i]->L += bodies[i].angularImpulse;
    }
  }
};

}  // namespace monolith
