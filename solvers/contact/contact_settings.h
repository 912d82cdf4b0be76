#pragma once
// The rigid contact stages' settings (scene "solvers": {"contact": {...}}), read by the systems of
// systems/rigid_contact.h through the world's resources (World::resource; docs/rigid_contact.md).
#include <cstring>

namespace monolith {

// The settings the contact schedules set (docs/rigid_contact.md "The schedule"): each field is
// named here once, and each schedule is one row of kContactSchedules below. The other settings
// (ContactSettings) are the same on every schedule.
struct ContactSchedule {
  int contactIterations;       // outer contact sweeps (Step III, Sec. 4.5), epsilon-ramped (notes 1.6)
  int contactLevelIterations;  // per level and sweep
  int shockLevelIterations;    // shock-propagation passes (GBF 2003)
  // Manifold and joint solves end with an exact active-set step once it applies
  // (solvers/contact/manifold_polish.h; not in the thesis, whose sweeps stop at their count).
  // Off in the thesis schedule: there it costs 3-30 % more than it saves on three of five
  // scenes; on the short schedule it makes the step 3x faster and leaves a standing pyramid
  // exactly at rest.
  bool exactManifoldFinish;
  // After Step V, an island of bodies moved only by gravity and contact whose energy (kinetic +
  // gravity's potential) rose in the step has its velocities scaled down to take the rise back
  // (not in the thesis, which leaves the first contact step unclamped, Sec. 2.3.2; systems/
  // step_energy_clamp.cpp). The short schedule needs it: its one inelastic contact pass can lift
  // a spinning body for the position update without paying for the rise.
  bool stepEnergyClamp;
  // Contact (Steps III and V) lets each point close the gap its bodies have at the base poses
  // within the step: v_n >= -gap/dt instead of v_n >= 0 (not in the thesis, whose ramped sweeps
  // close such gaps approximately). Without it one fully inelastic pass stops a body falling
  // onto a support closer than its step's fall in the air above it.
  bool closeGaps;
  // Where push-out's rounds leave a pair overlapping by more than this fraction of its smaller
  // body's size (a jam), the jam is pushed apart at once (ContactSettings::pushOutJoint). From
  // 2 % on the short schedule: from 5 %, the random-drop campaigns' own bound, its 2-D drops keep
  // single steps 5-10 % deep (docs/benchmarks_rigid_contact.md).
  double pushOutJointOverlap;
  // A jam still deeper than this after its passes is solved again with more rings of neighbours,
  // so that what clamps it can give way (solvers/contact/push_out_rounds.h).
  double pushOutJointRegrowOverlap;
};

struct NamedContactSchedule {
  const char* name;  // the scene's "schedule"
  ContactSchedule values;
};

// The schedules, one row each, the default first.
// - "short": one contact sweep of one level pass, one shock-propagation pass, manifold solves
//   finished exactly, gaps closed, the step energy clamp, the joint push-out of jams from 2 % and
//   its regrowth from 3 %: 12-15x cheaper per awake step than the thesis's (docs/rigid_contact.md).
// - "thesis": the thesis code's schedule (notes 1.4, 1.6, 1.7): ten epsilon-ramped contact sweeps
//   of two level passes, two shock-propagation passes, manifold solves by sweeps alone, no gap
//   closing, no step clamp, and the joint push-out from 5 % (regrown from 5 %).
inline constexpr NamedContactSchedule kContactSchedules[] = {
    // clang-format off
    //          contact level shock exact  step   close  joint regrow
    {"short",  {1,      1,    1,    true,  true,  true,  0.02, 0.03}},
    {"thesis", {10,     2,    2,    false, false, false, 0.05, 0.05}},
    // clang-format on
};

// The schedule of that name, or null.
inline const ContactSchedule* findContactSchedule(const char* name) {
  for (const auto& row : kContactSchedules)
    if (std::strcmp(row.name, name) == 0) return &row.values;
  return nullptr;
}

// Collisions, contact and interpenetration resolution (scene "solvers": {"contact": {...}}).
// The schedule's fields (the base) start as the default schedule's row.
struct ContactSettings : ContactSchedule {
  static constexpr const char* kName = "contact_settings";  // its name among the world's resources
  ContactSettings() : ContactSchedule(kContactSchedules[0].values) {}
  // Sets the schedule's fields to a row of kContactSchedules; the others are left.
  void useSchedule(const ContactSchedule& schedule) { static_cast<ContactSchedule&>(*this) = schedule; }

  int collisionIterations = 5;       // Gauss-Seidel sweeps over the pairs (Step II)
  int collisionPairIterations = 20;  // impulses per pair per sweep
  int contactPairIterations = 10;    // Gauss-Seidel sweeps of one pair's manifold solve (measured)
  bool shockPropagation = true;      // GBF 2003 shock propagation after contact
  int shockPairIterations = 40;      // measured: a 2-D pyramid's joint solves need them (docs/benchmarks.md)
  bool pushOut = true;               // interpenetration resolution, Sec. 4.6.1 / App. B
  int pushOutLevelIterations = 6;    // thesis code: 2; 6 measured on piles (docs/architecture.md)
  int pushOutBodyIterations = 5;
  // Push-out also separates pairs that Steps II-III never saw interpenetrating (not "processed")
  // but that overlap after Step IV's positions: a body moved by contact or by another push-out
  // into a neighbour (not in the thesis, whose push-out keeps to the saved pairs; Sec. 4.6.1).
  bool pushOutNewOverlaps = true;
  // With pushOutNewOverlaps: rounds of push-out while a push carries a body into one it was not
  // paired with (found only by the broad phase grown after the round; not in the thesis).
  int pushOutRounds = 4;
  // ... and while a pair still overlaps by more than this fraction of its smaller body's size.
  double pushOutRoundOverlap = 0.02;
  // ... and then the jams the rounds leave (ContactSchedule::pushOutJointOverlap) pushed apart
  // all at once: the bodies of those pairs and their overlapping dynamic neighbours (two rings),
  // pass by pass while each leaves them shallower (solvers/contact/joint_push_out.h; not in the
  // thesis).
  bool pushOutJoint = true;
  bool velocityContact = true;       // second contact step in Step V (Sec. 2.3.2 "Contact Clamping")
  bool energyClamp = true;           // Sec. 2.3.2 for collisions and the second contact step
  // Step II: a pair moving more than half its thinner body's size in the step is tested at its
  // first contact along the motion instead of at the candidate poses (not in the thesis;
  // solvers/collision/swept_contact.h).
  bool sweptCollisions = true;
  double thickness = 1e-4;           // contact is processed within this separation (m)
  double pushOutTolerance = 1e-5;    // penetration left alone by push-out (m)
  double approachTolerance = 1e-9;   // |v_rel.n| below this is "not approaching" (m/s)
  // Sleeping (not in the thesis; systems/sleep.h): an island of dynamic bodies whose every point
  // has moved slower than sleepSpeed for sleepTime is held still until an awake or moving body
  // touches it. Off by default: it stops bodies the thesis's scheme would still move by up to
  // sleepSpeed. Box2D's defaults are 0.01 m/s (and 2 degrees/s) for 0.5 s.
  bool sleep = false;
  double sleepSpeed = 0.01;          // m/s, at the body's farthest point from its centre of mass
  double sleepTime = 0.5;            // s
};

}  // namespace monolith
