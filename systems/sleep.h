#pragma once
// Sleeping (not in the thesis; what Box2D and Bullet call deactivation). With "sleep": true in
// "solvers": {"contact": {...}} every dynamic collider body carries a Sleep component
// (components/sleep.h), and:
//  * falls asleep with its island (fall_asleep, after Step V): when every dynamic body the step's
//    pairs join it to has moved slower than sleep_speed (at its farthest point) for sleep_time,
//    and something holds the island (one of its bodies is paired with a static, kinematic or
//    sleeping body, or no force acts on any of them: a weak force would otherwise be stopped
//    for good before it got a body moving), they all stop (v = 0, L = 0) and share a group;
//  * while asleep it is held still: Steps I, IV and V skip it, and the contact stages treat it
//    as a body of infinite mass at rest, so pairs between sleeping and static bodies are never
//    formed and a settled pile costs a broad phase per step;
//  * wakes, with its whole group, at the start of Step II when a pair joins it to an awake
//    dynamic body, a moving kinematic body's box reaches its box, or the force or torque on it
//    has changed by more than 1e-3 of its weight plus the force it fell asleep with (a plugin's
//    force, or one a program set) (ContactWorkspace::wakeTouchedSleepers), and takes the Step I
//    kick it missed.
// An awake body that meets a sleeping one in mid-step (sent there by an impulse after Step II's
// broad phase) meets it as an immovable body and wakes it the step after.
#include "ecs/world.h"

namespace monolith {

// Gives every dynamic collider body a Sleep component, except kinematic bodies and fluid
// obstacles (the fluid's forces on them change while they rest). The scene loader calls it.
template <int d>
void enableSleeping(World<d>& world);

}  // namespace monolith
