#pragma once
// The fixed pipeline of one time step. The solid stages are those of thesis Sec. 4.2
// (I advance velocity to n+1/2, II collisions, III contact, IV advance positions, V advance
// velocity to n+1); the fluid of Ch. 5 advects after the positions, takes its body forces with
// the second force evaluation and is projected in Step V by the coupled solve. Forces are evaluated by their own systems at the two time levels the
// Newmark scheme needs them: (x^n, v^n) before Step I and (x^{n+1}, v^{n+1/2}) before Step V.
#include <array>
#include <string>

namespace monolith {

enum class Stage : int {
  ForcesAtStart = 0,    // forces at x^n, v^n
  AdvanceVelocityHalf,  // Step I   (Sec. 4.3)
  Collisions,           // Step II  (Sec. 4.4)
  Contact,              // Step III (Sec. 4.5)
  AdvancePositions,     // Step IV  (Sec. 4.6, 4.4.1, 2.2)
  Advection,            // fluid: u* = u^n - dt (u.grad)u (Sec. 5.4 step 6)
  ForcesAtEnd,          // forces at x^{n+1}, v^{n+1/2}
  AdvanceVelocity,      // Step V   (Sec. 4.7)
  Diagnostics,          // measurements of the state at t^{n+1}; never changes the state
  Count
};

inline constexpr std::array<Stage, static_cast<int>(Stage::Count)> kAllStages = {
    Stage::ForcesAtStart, Stage::AdvanceVelocityHalf, Stage::Collisions,  Stage::Contact,
    Stage::AdvancePositions, Stage::Advection,       Stage::ForcesAtEnd,  Stage::AdvanceVelocity,
    Stage::Diagnostics};

inline const char* stageName(Stage s) {
  switch (s) {
    case Stage::ForcesAtStart: return "forces_at_start";
    case Stage::AdvanceVelocityHalf: return "advance_velocity_half";
    case Stage::Collisions: return "collisions";
    case Stage::Contact: return "contact";
    case Stage::AdvancePositions: return "advance_positions";
    case Stage::Advection: return "advection";
    case Stage::ForcesAtEnd: return "forces_at_end";
    case Stage::AdvanceVelocity: return "advance_velocity";
    case Stage::Diagnostics: return "diagnostics";
    case Stage::Count: break;
  }
  return "?";
}

}  // namespace monolith
