#pragma once
// Held by WorldSettings (ecs/world.h), read by the rigid contact systems (systems/rigid_contact.h;
// docs/rigid_contact.md).

namespace monolith {

// Collisions, contact and interpenetration resolution (scene "solvers": {"contact": {...}}).
// The defaults are the short schedule (useShortSchedule, docs/rigid_contact.md): one contact
// sweep of one level pass, one shock-propagation pass, exact manifold solves, contact that lets a
// gap close in the step, the step energy clamp and the joint push-out of jams from 2 %: 12-15x
// cheaper per awake step than the thesis code's schedule (notes 1.4, 1.6, 1.7), which
// `"schedule": "thesis"` (useThesisSchedule) selects.
struct ContactSettings {
  int collisionIterations = 5;       // Gauss-Seidel sweeps over the pairs (Step II)
  int collisionPairIterations = 20;  // impulses per pair per sweep
  int contactIterations = 1;         // outer contact sweeps (Step III), epsilon-scaled; thesis: 10
  int contactLevelIterations = 1;    // per level and sweep; thesis: 2
  int contactPairIterations = 10;    // Gauss-Seidel sweeps of one pair's manifold solve (measured)
  bool shockPropagation = true;      // GBF 2003 shock propagation after contact
  int shockLevelIterations = 1;      // thesis: 2
  int shockPairIterations = 40;      // measured: a 2-D pyramid's joint solves need them (docs/benchmarks.md)
  // Manifold and joint solves end with an exact active-set step once it applies
  // (solvers/contact/manifold_polish.h; not in the thesis, whose sweeps stop at their count).
  // Off in the thesis schedule: there it costs 3-30 % more than it saves on three of five
  // scenes; on the short schedule it makes the step 3x faster and leaves a standing pyramid
  // exactly at rest.
  bool exactManifoldFinish = true;
  bool pushOut = true;               // interpenetration resolution, Sec. 4.6.1 / App. B
  int pushOutLevelIterations = 6;    // thesis code: 2; measured on piles (the git history of docs/benchmarks.md ("Six push-out passes"))
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
  // ... and then, where the rounds leave a pair overlapping by more than pushOutJointOverlap of
  // its smaller body's size (a jam), the bodies of those pairs and their overlapping dynamic
  // neighbours (two rings) pushed apart all at once (solvers/contact/joint_push_out.h; not in the
  // thesis), pass by pass while each leaves them shallower.
  // From 2 %: started at 5 %, the random-drop campaigns' own bound, the short schedule's 2-D
  // drops kept single steps 5-10 % deep (docs/benchmarks_rigid_contact.md); thesis: 5 %.
  bool pushOutJoint = true;
  double pushOutJointOverlap = 0.02;
  // ... and where a jam is still deeper than pushOutJointRegrowOverlap after its passes, it is
  // solved again with more rings of neighbours (systems/interpenetration.cpp), so that what
  // clamps it can give way; thesis: 5 %, its start and the campaigns' bound.
  double pushOutJointRegrowOverlap = 0.03;
  bool velocityContact = true;       // second contact step in Step V (Sec. 2.3.2 "Contact Clamping")
  bool energyClamp = true;           // Sec. 2.3.2 for collisions and the second contact step
  // After Step V, an island of bodies moved only by gravity and contact whose energy (kinetic +
  // gravity's potential) rose in the step has its velocities scaled down to take the rise back
  // (not in the thesis, which leaves the first contact step unclamped, Sec. 2.3.2; systems/
  // step_energy_clamp.cpp). The short schedule needs it: its one inelastic contact pass can lift
  // a spinning body for the position update without paying for the rise. Thesis: off.
  bool stepEnergyClamp = true;
  // Contact (Steps III and V) lets each point close the gap its bodies have at the base poses
  // within the step: v_n >= -gap/dt instead of v_n >= 0 (not in the thesis, whose ramped sweeps
  // close such gaps approximately). Without it one fully inelastic pass stops a body falling
  // onto a support closer than its step's fall in the air above it. Thesis: off.
  bool closeGaps = true;
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

  // The short schedule (the defaults above): one contact sweep of one level pass, one
  // shock-propagation pass, manifold solves finished exactly, gaps closed, the step energy clamp,
  // the joint push-out from 2 % and its regrowth from 3 %.
  void useShortSchedule() {
    contactIterations = 1;
    contactLevelIterations = 1;
    shockLevelIterations = 1;
    exactManifoldFinish = true;
    stepEnergyClamp = true;
    closeGaps = true;
    pushOutJointOverlap = 0.02;
    pushOutJointRegrowOverlap = 0.03;
  }
  // The thesis code's schedule: ten epsilon-ramped contact sweeps of two level passes, two
  // shock-propagation passes, manifold solves by sweeps alone, no gap closing, no step clamp, and
  // the joint push-out from 5 % (regrown from 5 %).
  void useThesisSchedule() {
    contactIterations = 10;
    contactLevelIterations = 2;
    shockLevelIterations = 2;
    exactManifoldFinish = false;
    stepEnergyClamp = false;
    closeGaps = false;
    pushOutJointOverlap = 0.05;
    pushOutJointRegrowOverlap = 0.05;
  }
};

}  // namespace monolith
