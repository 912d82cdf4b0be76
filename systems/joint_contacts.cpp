// Interpenetration resolution of the jointed bodies (Step IV; not in the thesis): joints and
// contacts in one position solve (solvers/articulation/joint_closing.h).
#include <algorithm>
#include <cmath>

#include "solvers/articulation/joint_closing.h"
#include "solvers/collision/narrow_phase.h"
#include "systems/articulation.h"
#include "systems/contact_workspace.h"
#include "systems/joint_assembly.h"

namespace monolith {

namespace {

namespace col = solvers::collision;

// Step V's contact points: those within 5 mm (a body falling for one step at dt = 1/30 moves
// g dt^2 = 11 mm, one resting on another a few micrometres from it).
constexpr double kStepFiveMargin = 5e-3;

// Per body of `ws`: its body in the assembly if it is jointed and can move, else 0 (the world,
// held still).
template <int d>
std::vector<int> assemblyBodies(const JointAssembly<d>& a, const ContactWorkspace<d>& ws) {
  std::vector<int> bodyOf(ws.bodies.size(), 0);
  for (std::size_t i = 0; i < ws.bodies.size(); ++i) {
    const auto it = a.index.find(ws.entityOf(i).index);
    if (it != a.index.end() && a.bodies[it->second].invMass > 0 && !ws.bodies[i].infinite()) bodyOf[i] = it->second;
  }
  return bodyOf;
}

// A body of the assembly as a pose of dimension d (2-D: the plane's part of the lifted pose).
template <int d>
col::Pose<d> poseOfBody(const solvers::ConstraintBody& b) {
  col::Pose<d> p;
  p.x = b.x.head<d>();
  p.R = b.q.toRotationMatrix().topLeftCorner<d, d>();
  return p;
}

// The orientation of a lifted body as the dimension's orientation; in 2-D the angle nearest to
// `near` (the body's angle is a state that may have turned many times).
template <int d>
Orientation<d> orientationOf(const Eigen::Quaterniond& q, const Orientation<d>& near) {
  if constexpr (d == 3) {
    return q;
  } else {
    constexpr double kTwoPi = 2 * 3.14159265358979323846;
    const double angle = 2 * std::atan2(q.z(), q.w());
    return near + std::remainder(angle - near, kTwoPi);
  }
}

// The contact points, within `margin`, of the pairs with a jointed body that can move: that body
// at its pose in the assembly, the others at their base pose (where push-out left them in Step
// IV, time n+1 in Step V; a static body's collision pose, grounded_box.h). `gainOf(depth)` is
// the row's gain. With `partnerMotion`, a partner held still in the solve moves with its own
// velocity at the point (Step V).
// With `reach` (per body of `ws`), a pair's margin grows by both its bodies' reach.
template <int d, typename GainOf>
std::vector<solvers::ContactRow> contactRows(const JointAssembly<d>& a, const ContactWorkspace<d>& ws,
                                             const std::vector<int>& bodyOf, double margin, GainOf&& gainOf,
                                             bool partnerMotion, const std::vector<double>* reach = nullptr) {
  auto poseOf = [&](std::size_t i) {
    col::Pose<d> p = ws.bodies[i].candidate;
    if (bodyOf[i] > 0) {
      p = poseOfBody<d>(a.bodies[bodyOf[i]]);
    } else if (!ws.bodies[i].still()) {
      p.x = ws.bodies[i].x0;
      p.R = ws.bodies[i].R0;
    }
    return p;
  };
  auto pointVelocity = [&](std::size_t i, const Eigen::Matrix<double, d, 1>& point) -> Eigen::Vector3d {
    const ContactBody<d>& b = ws.bodies[i];
    if (!partnerMotion || b.still()) return Eigen::Vector3d::Zero();
    return liftVector<d>(b.pointVelocity(point - b.x0));
  };
  std::vector<solvers::ContactRow> rows;
  std::vector<col::ContactPoint<d>> points;
  col::ContactQuery query;
  query.margin = margin;
  for (const ContactPairState& p : ws.pairs) {
    if (bodyOf[p.a] == 0 && bodyOf[p.b] == 0) continue;
    points.clear();
    query.margin = reach ? margin + (*reach)[p.a] + (*reach)[p.b] : margin;
    col::findContacts(*ws.bodies[p.a].geometry, poseOf(p.a), *ws.bodies[p.b].geometry, poseOf(p.b), query, points);
    for (const auto& cp : points) {
      solvers::ContactRow r;
      r.a = bodyOf[p.a];
      r.b = bodyOf[p.b];
      r.point = liftVector<d>(cp.point);
      r.normal = liftVector<d>(cp.normal);
      r.gain = gainOf(cp.depth);
      r.friction = std::min(ws.bodies[p.a].friction, ws.bodies[p.b].friction);
      if (r.a == 0) r.offset += pointVelocity(p.a, cp.point);
      if (r.b == 0) r.offset -= pointVelocity(p.b, cp.point);
      rows.push_back(r);
    }
  }
  return rows;
}

}  // namespace

namespace {

// The jointed bodies' velocities projected onto their joints and their contact points together
// (the points within kStepFiveMargin, the other bodies held still with their own velocities);
// `gainOf(depth)` is a point's gain. Returns the contact rows' count.
template <int d, typename GainOf>
std::size_t projectJointsAndContacts(World<d>& world, const ContactWorkspace<d>& ws, StepContext& ctx,
                                     GainOf&& gainOf, const std::vector<double>* reach = nullptr) {
  const ArticulationSolver s = articulationSettings(world);
  JointAssembly<d> a(world);
  const std::vector<int> bodyOf = assemblyBodies(a, ws);
  std::vector<solvers::ContactRow> contacts = contactRows(a, ws, bodyOf, kStepFiveMargin, gainOf, true, reach);
  for (solvers::ContactRow& c : contacts) c.rolling = s.rollingResistance;
  const solvers::ProjectionReport r =
      solvers::projectWithContacts(a.rows(), contacts, a.bodies, s.contactSolveSweeps, s.postTolerance);
  a.writeBack();
  ctx.diagnostics.max("joint_post_iterations", r.iterations);
  return contacts.size();
}

}  // namespace

template <int d>
void preStabilizeWithContacts(World<d>& world, const ContactWorkspace<d>& ws, StepContext& ctx) {
  const double dt = ctx.dt;
  // The jointed bodies start again from their velocities before Step III's contact, gravity's
  // kick in them, so that the contact rows carry their weight and friction and rolling
  // resistance lean on it. From the velocities contact and shock propagation leave, which
  // approach nothing, the rows took almost no normal impulse: a ragdoll lying on the ground had
  // 10 of its 17 points unloaded and 4 sliding, and its forearms slid by 1.5 mm a second.
  {
    JointAssembly<d> start(world);
    const std::vector<int> bodyOf = assemblyBodies(start, ws);
    for (std::size_t i = 0; i < ws.bodies.size() && i < ws.stepThreeStartV.size(); ++i) {
      if (bodyOf[i] == 0) continue;
      ws.bodies[i].body->v = ws.stepThreeStartV[i];
      ws.bodies[i].body->L = ws.stepThreeStartL[i];
    }
  }
  // The contact points as far apart as the bodies can close in the step besides Step V's 5 mm
  // (this replaces what contact did at the candidate poses for the jointed bodies).
  std::vector<double> reach(ws.bodies.size(), 0.0);
  for (std::size_t i = 0; i < ws.bodies.size(); ++i) {
    const ContactBody<d>& b = ws.bodies[i];
    if (b.still()) continue;
    reach[i] = dt * (b.body->v.norm() + b.body->omega().norm() * b.geometry->boundingRadius());
  }
  // Within Step V's 5 mm: no approach, where the contact stages close no gaps, as contact at the
  // candidate poses stops a body at the gap it has (the thesis's schedule); beyond (or where
  // gaps close), the gap may close within the step. With every gap beyond push-out's tolerance
  // closable, the projection stalled in a resting four-ragdoll pile (the largest row error
  // 1e-3 m/s after 500 sweeps and still after 20 000), with gaps to 5 mm held it converges
  // (1e-15 m/s after 5000 sweeps).
  const double hold = ws.settings.closeGaps ? ws.settings.pushOutTolerance : kStepFiveMargin;
  const std::size_t n = projectJointsAndContacts(
      world, ws, ctx, [&](double depth) { return -depth > hold ? std::min(0.0, depth / dt) : 0.0; }, &reach);
  ctx.diagnostics.set("joint_step_iii_contacts", static_cast<double>(n));
}

template <int d>
void postStabilizeWithContacts(World<d>& world, const ContactWorkspace<d>& ws, StepContext& ctx) {
  const double dt = ctx.dt;  // the step Step V's gaps close in
  // Touching or overlapping: no approach (push-out's business). Apart: the gap may close within
  // the step only where the contact stages close gaps (ContactSettings::closeGaps), and a gap
  // within push-out's tolerance counts as touching, as in closableNormalVelocity. On the thesis's
  // schedule Step III stops a body at the gap it has; letting Step V close it kept a ragdoll's
  // arm turning down towards the ground in its velocities at every step while its positions
  // stayed (one ragdoll at rest: kinetic energy 1.3e-3 J, 3.4e-7 J with the same rule).
  const bool closeGaps = ws.settings.closeGaps;
  const double tolerance = ws.settings.pushOutTolerance;
  const std::size_t n = projectJointsAndContacts(world, ws, ctx, [&](double depth) {
    return closeGaps && -depth > tolerance ? std::min(0.0, depth / dt) : 0.0;
  });
  ctx.diagnostics.set("joint_step_v_contacts", static_cast<double>(n));
}

template <int d>
void resolveJointedInterpenetration(World<d>& world, ContactWorkspace<d>& ws, StepContext& ctx) {
  const ArticulationSolver s = articulationSettings(world);
  JointAssembly<d> a(world);
  const std::vector<int> bodyOf = assemblyBodies(a, ws);
  // The joint error push-out's own poses would leave.
  std::vector<solvers::ConstraintBody> pushed = a.bodies;
  {
    for (std::size_t i = 0; i < ws.bodies.size(); ++i)
      if (bodyOf[i] > 0)
        pushed[bodyOf[i]].x = liftVector<d>(ws.bodies[i].x0), pushed[bodyOf[i]].q = liftOrientation<d>(ws.bodies[i].q0);
    double open = 0;
    for (const auto& def : a.joints) {
      const solvers::JointError e =
          solvers::jointError(def, pushed[def.parent].x, pushed[def.parent].q, pushed[def.child].x, pushed[def.child].q);
      open = std::max(open, e.linear.norm());
    }
    ctx.diagnostics.max("joint_push_out_error", open);
  }
  // A row asks the displacements to take away the overlap beyond what push-out accepts; a
  // point apart by a gap may approach by it.
  const double allowed = ws.settings.pushOutTolerance;
  auto gainOf = [&](double depth) { return depth - allowed; };
  auto deepestOverlap = [&] {
    double deepest = 0;
    for (const auto& c : contactRows(a, ws, bodyOf, 0.0, gainOf, false)) deepest = std::max(deepest, c.gain + allowed);
    return deepest;
  };
  const bool global = s.pre == ArticulationSolver::Method::Global;
  solvers::PreStabilizationReport r;
  std::size_t rows = 0;
  double deepest = 0;
  if (s.pushOutContactSweeps == 0) {
    a.bodies = pushed;  // closed from where push-out left them, contacts unseen
    r = solvers::closeJointsAgainstContacts(a.joints, a.bodies, {}, 0, global, s.preIterations, s.preTolerance);
    deepest = deepestOverlap();
  } else {
    // Passes: the contact points up to twice the deepest overlap apart (the displacements are of
    // that size), linearised at the pass's poses, and the solve; then the points found again
    // where it left the bodies. A body pushed along a capsule by the solve reaches the capsule's
    // jointed neighbour, whose points the pass did not have (with one pass a ring hanging on the
    // joint of an articulated loop is left 1.5 cm inside it, and goes through within 0.1 s).
    deepest = deepestOverlap();
    for (int pass = 0; pass < s.pushOutContactPasses; ++pass) {
      std::vector<solvers::ContactRow> contacts;
      if (deepest > allowed) contacts = contactRows(a, ws, bodyOf, 2 * deepest, gainOf, false);
      const solvers::PreStabilizationReport p = solvers::closeJointsAgainstContacts(
          a.joints, a.bodies, contacts, s.pushOutContactSweeps, global, s.preIterations, s.preTolerance);
      if (pass == 0) r.errorBefore = p.errorBefore;
      r.errorAfter = p.errorAfter;
      r.iterations += p.iterations;
      rows = std::max(rows, contacts.size());
      deepest = deepestOverlap();
      if (contacts.empty() || deepest <= allowed) break;
    }
  }
  for (std::size_t i = 0; i < ws.bodies.size(); ++i) {
    if (bodyOf[i] == 0) continue;
    ContactBody<d>& b = ws.bodies[i];
    const col::Pose<d> pose = poseOfBody<d>(a.bodies[bodyOf[i]]);
    b.x0 = pose.x;
    b.q0 = orientationOf<d>(a.bodies[bodyOf[i]].q, b.q0);
    b.R0 = pose.R;
    b.candidate = pose;
  }
  ctx.diagnostics.set("joint_push_out_overlap_left", deepest);
  ctx.diagnostics.set("joint_push_out_contacts", static_cast<double>(rows));
  ctx.diagnostics.set("joint_push_out_error_left", r.errorAfter);
}

template void preStabilizeWithContacts<2>(World<2>&, const ContactWorkspace<2>&, StepContext&);
template void preStabilizeWithContacts<3>(World<3>&, const ContactWorkspace<3>&, StepContext&);
template void postStabilizeWithContacts<2>(World<2>&, const ContactWorkspace<2>&, StepContext&);
template void postStabilizeWithContacts<3>(World<3>&, const ContactWorkspace<3>&, StepContext&);
template void resolveJointedInterpenetration<2>(World<2>&, ContactWorkspace<2>&, StepContext&);
template void resolveJointedInterpenetration<3>(World<3>&, ContactWorkspace<3>&, StepContext&);

}  // namespace monolith
