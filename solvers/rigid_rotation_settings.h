#pragma once
// A world resource (World::resource), read by Step IV's orientation update
// (systems/advance_positions.cpp) and by the joints' prediction of it (systems/articulation.cpp).

namespace monolith {

// How rigid orientations are advanced in Step IV (scene "solvers": {"rigid_rotation": {...}};
// Sec. 4.4.1, App. A, Sec. 2.2; the rules themselves are solvers/rigid_rotation.h).
struct RigidRotationSettings {
  static constexpr const char* kName = "rigid_rotation_settings";  // its name among the world's resources
  int order = 2;          // 1: exp(dt w*) [169]; 2: Sec. 4.4.1; 3: App. A (solvers::RotationOrder)
  bool energyFix = true;  // kinetic-energy orientation fix, Sec. 2.2.2-2.2.4
};

}  // namespace monolith
