// Sleeping: the wake test at Step II's start and fall_asleep after Step V (systems/sleep.h).
#include "systems/sleep.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <tuple>
#include <unordered_map>

#include "components/fluid_obstacle.h"
#include "components/joint.h"
#include "systems/rigid_contact.h"

namespace monolith {

namespace col = solvers::collision;

template <int d>
void enableSleeping(World<d>& world) {
  std::vector<Entity> eligible;
  world.template each<Collider<d>, RigidBody<d>>([&](Entity e, Collider<d>&, RigidBody<d>& b) {
    if (b.isStatic || world.template get<KinematicMotion<d>>(e) || world.template get<FluidObstacle>(e) ||
        world.template get<Sleep<d>>(e))
      return;
    eligible.push_back(e);
  });
  for (const Entity e : eligible) world.add(e, Sleep<d>{});
}

namespace {
// The farthest a point of the geometry lies from the body's centre of mass (a bound: the corner
// of its body-frame bounding box), so |v| + |w| reach bounds every point's speed.
template <int d>
double farthestPoint(const col::PreparedGeometry<d>& g) {
  const Eigen::AlignedBox<double, d> box = col::worldBounds(g, col::Pose<d>{});
  return box.min().cwiseAbs().cwiseMax(box.max().cwiseAbs()).norm();
}

// Union-find over the step's pairs (fall_asleep's islands), with path halving.
int rootOf(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

}  // namespace

template <int d>
int ContactWorkspace<d>::wakeTouchedSleepers(World<d>& world, double dt) {
  if (world.template count<Sleep<d>>() == 0) return 0;
  auto& sleeps = world.template pool<Sleep<d>>();
  const auto* forces = world.template findPool<RigidForces<d>>();
  auto groupOf = [&](std::size_t i) { return sleeps.get(entities_[i])->group; };
  int woken = 0;
  std::vector<std::int64_t> groups;
  // A force that changed since the body fell asleep (a plugin's, or one a program set): by more
  // than 1e-3 of its weight plus the force it slept with, the torque likewise at its reach.
  const double g = gravity.norm();
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (!bodies[i].asleep) continue;
    Sleep<d>& s = *sleeps.get(entities_[i]);
    const RigidForces<d>* f = forces ? forces->get(entities_[i]) : nullptr;
    const Eigen::Matrix<double, d, 1> F = f ? f->force : Eigen::Matrix<double, d, 1>::Zero();
    const AngularVec<d> T = f ? f->torque : AngularVec<d>::Zero();
    if (!s.forceKnown) {
      s.forceKnown = true, s.force = F, s.torque = T, s.reach = farthestPoint(*bodies[i].geometry);
      continue;
    }
    const double scale = s.force.norm() + bodies[i].mass * g;
    if ((F - s.force).norm() > 1e-3 * scale || (T - s.torque).norm() > 1e-3 * (s.torque.norm() + scale * s.reach))
      groups.push_back(s.group);
  }
  for (;;) {
    // A pair of a sleeping body and an awake dynamic one (two bodies of infinite mass never
    // make a pair: the broad phase skips them).
    for (const ContactPairState& p : pairs) {
      const ContactBody<d>& A = bodies[p.a];
      const ContactBody<d>& B = bodies[p.b];
      if (A.asleep && !B.infinite()) groups.push_back(groupOf(p.a));
      if (B.asleep && !A.infinite()) groups.push_back(groupOf(p.b));
    }
    // A joint between a sleeping body and an awake dynamic one (a group started asleep by the
    // scene, or woken by a pair): the jointed bodies wake as one.
    if (world.template count<ArticulationJoint<d>>() > 0) {
      std::unordered_map<std::uint32_t, std::size_t> bodyOf;
      for (std::size_t i = 0; i < bodies.size(); ++i) bodyOf.emplace(entities_[i].index, i);
      auto indexOf = [&](const std::string& name) -> long {
        const auto e = name == "world" ? std::nullopt : world.find(name);
        const auto it = e ? bodyOf.find(e->index) : bodyOf.end();
        return it == bodyOf.end() ? -1 : static_cast<long>(it->second);
      };
      for (const ArticulationJoint<d>& j : world.template pool<ArticulationJoint<d>>().components()) {
        const long p = indexOf(j.parent), c = indexOf(j.child);
        if (p < 0 || c < 0) continue;
        if (bodies[p].asleep && !bodies[c].infinite()) groups.push_back(groupOf(p));
        if (bodies[c].asleep && !bodies[p].infinite()) groups.push_back(groupOf(c));
      }
    }
    // A moving kinematic body: its box (over the step's motion, findPairs) against the sleepers'.
    for (std::size_t k = 0; k < bodies.size(); ++k) {
      const ContactBody<d>& K = bodies[k];
      if (!K.kinematic || (K.v.squaredNorm() == 0 && K.L.squaredNorm() == 0)) continue;
      for (std::size_t i = 0; i < bodies.size(); ++i)
        if (bodies[i].asleep && boxes_[k].intersects(boxes_[i])) groups.push_back(groupOf(i));
    }
    if (groups.empty()) return woken;
    std::sort(groups.begin(), groups.end());
    groups.erase(std::unique(groups.begin(), groups.end()), groups.end());
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      if (!bodies[i].asleep || !std::binary_search(groups.begin(), groups.end(), groupOf(i))) continue;
      Sleep<d>& s = *sleeps.get(entities_[i]);
      s.asleep = false;
      s.stillTime = 0;
      s.group = -1;
      // Step I skipped it (systems/advance_velocity.cpp): its kick now, from rest.
      RigidBody<d>& rb = *bodies[i].body;
      if (const RigidForces<d>* f = forces ? forces->get(entities_[i]) : nullptr) {
        rb.v += (0.5 * dt / rb.mass) * f->force;
        rb.L += 0.5 * dt * f->torque;
      }
      ++woken;
    }
    groups.clear();
    // The woken bodies move from here on: pack them as such and find their pairs (with each
    // other, and with sleepers they touch, which the next pass wakes).
    pack(world, dt, /*subtractKick=*/true);
    findPairs();
  }
}


template <int d>
void FallAsleep<d>::run(World<d>& world, StepContext& ctx) {
  ContactWorkspace<d>& ws = *this->ws_;
  auto& sleeps = world.template pool<Sleep<d>>();
  const ContactSettings& settings = world.template resource<ContactSettings>();
  const int n = static_cast<int>(ws.bodies.size());
  reach_.resize(n);
  reachOf_.resize(n, nullptr);
  parent_.resize(n);
  std::iota(parent_.begin(), parent_.end(), 0);
  blocked_.assign(n, 0);
  held_.assign(n, 0);
  const auto* forces = world.template findPool<RigidForces<d>>();
  // Per body: still for long enough? A dynamic body without a Sleep component never sleeps, nor
  // does its island.
  auto awakeDynamic = [&](int i) {
    const ContactBody<d>& b = ws.bodies[i];
    if (b.isStatic || b.kinematic) return false;
    const Sleep<d>* s = sleeps.get(ws.entityOf(i));
    return !s || !s->asleep;
  };
  for (int i = 0; i < n; ++i) {
    if (!awakeDynamic(i)) continue;
    Sleep<d>* s = sleeps.get(ws.entityOf(i));
    if (!s) {
      blocked_[i] = 1;
      continue;
    }
    const ContactBody<d>& b = ws.bodies[i];
    if (reachOf_[i] != b.geometry) {
      reach_[i] = farthestPoint(*b.geometry);
      reachOf_[i] = b.geometry;
    }
    const RigidBody<d>& rb = *b.body;
    const double speed = rb.v.norm() + rb.omega().norm() * reach_[i];
    s->stillTime = speed <= settings.sleepSpeed ? s->stillTime + ctx.dt : 0.0;
    if (s->stillTime < settings.sleepTime) blocked_[i] = 1;
    // A body no force acts on stays at rest by itself.
    const RigidForces<d>* f = forces ? forces->get(ws.entityOf(i)) : nullptr;
    if (!f || (f->force.squaredNorm() == 0 && f->torque.squaredNorm() == 0)) held_[i] = 1;
  }
  // Islands: the awake dynamic bodies the step's pairs join (a pair is a broad-phase one, so
  // bodies within the contact thickness of each other count as joined: that only delays sleep).
  // A body paired with one that cannot move (static, kinematic or asleep) may be held by it.
  for (const ContactPairState& p : ws.pairs) {
    const bool a = awakeDynamic(p.a), b = awakeDynamic(p.b);
    if (a != b) held_[a ? p.a : p.b] = 1;
    if (!a || !b) continue;
    const int ra = rootOf(parent_, p.a), rb = rootOf(parent_, p.b);
    if (ra != rb) parent_[std::max(ra, rb)] = std::min(ra, rb);
  }
  // Joints: the bodies a joint links are one island, so that they fall asleep and wake
  // together (a jointed body asleep alone would hold its awake partner as if welded to the
  // world). A joint to the world, a static body or a sleeping one holds the island; one to a
  // body that cannot sleep (a kinematic one, or a dynamic one outside the workspace) blocks it.
  if (world.template count<ArticulationJoint<d>>() > 0) {
    std::unordered_map<std::uint32_t, int> bodyOf;
    for (int i = 0; i < n; ++i) bodyOf.emplace(ws.entityOf(i).index, i);
    // The body index of a joint's end; -1: the world or a static body outside the workspace,
    // -2: a body that cannot sleep.
    auto endOf = [&](const std::string& name) {
      if (name == "world") return -1;
      const auto e = world.find(name);
      const auto it = e ? bodyOf.find(e->index) : bodyOf.end();
      if (it != bodyOf.end()) return ws.bodies[it->second].kinematic ? -2 : it->second;
      const RigidBody<d>* b = e ? world.template get<RigidBody<d>>(*e) : nullptr;
      return b && b->isStatic ? -1 : -2;
    };
    for (const ArticulationJoint<d>& j : world.template pool<ArticulationJoint<d>>().components()) {
      const int p = endOf(j.parent), c = endOf(j.child);
      const bool ap = p >= 0 && awakeDynamic(p), ac = c >= 0 && awakeDynamic(c);
      if (ap && ac) {
        const int rp = rootOf(parent_, p), rc = rootOf(parent_, c);
        if (rp != rc) parent_[std::max(rp, rc)] = std::min(rp, rc);
        continue;
      }
      for (const auto& [mine, awake, other] : {std::tuple{p, ap, c}, std::tuple{c, ac, p}}) {
        if (!awake) continue;
        if (other == -2) blocked_[mine] = 1;
        else held_[mine] = 1;  // the world, a static body, or a sleeping one
      }
    }
  }
  // An island sleeps only if something holds it: a body paired with an immovable one, or none
  // pushed by a force. Else it is slow but accelerating: a weak force (under sleep_speed per
  // sleep_time) would otherwise be stopped for good before it got the body moving.
  for (int i = 0; i < n; ++i) {
    if (!awakeDynamic(i)) continue;
    const int root = rootOf(parent_, i);
    if (blocked_[i]) blocked_[root] = 1;
    if (held_[i]) held_[root] = 1;
  }
  for (int i = 0; i < n; ++i)
    if (awakeDynamic(i) && held_[i] == 0 && rootOf(parent_, i) == i) blocked_[i] = 1;
  // An island's group: the entity index of its lowest body (the root, as unions keep the smaller
  // index); unique among the sleeping groups, as is a body's own entity index where the scene
  // starts it asleep.
  int fell = 0, asleep = 0;
  for (int i = 0; i < n; ++i) {
    Sleep<d>* s = sleeps.get(ws.entityOf(i));
    if (!s) continue;
    if (!s->asleep && awakeDynamic(i) && !blocked_[rootOf(parent_, i)]) {
      s->asleep = true;
      s->group = ws.entityOf(rootOf(parent_, i)).index;
      const RigidForces<d>* f = forces ? forces->get(ws.entityOf(i)) : nullptr;
      s->forceKnown = true;
      s->force = f ? f->force : Eigen::Matrix<double, d, 1>::Zero();
      s->torque = f ? f->torque : AngularVec<d>::Zero();
      s->reach = reach_[i];
      RigidBody<d>& rb = *ws.bodies[i].body;
      rb.v.setZero();
      rb.L.setZero();
      ++fell;
    }
    asleep += s->asleep ? 1 : 0;
  }
  ctx.diagnostics.set("bodies_fallen_asleep", fell);
  ctx.diagnostics.set("bodies_asleep", asleep);
}

template void enableSleeping<2>(World<2>&);
template void enableSleeping<3>(World<3>&);
template int ContactWorkspace<2>::wakeTouchedSleepers(World<2>&, double);
template int ContactWorkspace<3>::wakeTouchedSleepers(World<3>&, double);
template class FallAsleep<2>;
template class FallAsleep<3>;

}  // namespace monolith
