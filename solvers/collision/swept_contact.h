#pragma once
// First contact along a time step's motion (not in the thesis; docs/architecture.md
// "Swept collisions"). Step II tests pairs at the candidate poses x^n + dt v only (GBF 2003):
// a body that moves farther than its thickness in one step can be past a thin partner there (a
// plate dropped at 6 m/s through a 4 cm shelf at dt = 1/30), or so deep inside it that the
// least-overlap axis points the wrong way and the impulse pushes it through. For such pairs the
// collision step asks instead where the two first touch between the start and candidate poses.
#include "solvers/collision/geometry.h"
#include "solvers/contact/rigid_math.h"

namespace monolith::solvers::collision {

// A body's motion over the step: pose(s) = (start.x + s translation, exp(s rotation*) start.R)
// for s in [0, 1] (a screw-free motion: translation and rotation at constant rates; the
// candidate pose of Step II is pose(1)).
template <int d>
struct StepMotion {
  Pose<d> start;
  Eigen::Matrix<double, d, 1> translation = Eigen::Matrix<double, d, 1>::Zero();
  contact::AngVec<d> rotation = contact::AngVec<d>::Zero();  // world rotation vector (2-D: angle)

  Pose<d> at(double s) const;
};

// Size below which a body can be skipped over: its smallest extent (minimumSize), except for a
// half-space (nothing passes it) and a triangle mesh (a surface: the other body's size decides).
template <int d>
double tunnelingSize(const PreparedGeometry<d>& g);

// Largest distance any point of A moves relative to B over the step (bounding radii times the
// rotation angles plus the relative translation): how far a query can be from the truth.
template <int d>
double relativeTravel(const PreparedGeometry<d>& a, const StepMotion<d>& ma, const PreparedGeometry<d>& b,
                      const StepMotion<d>& mb);

struct SweptQuery {
  double sampleTravel = 0;  // at most this relative travel between overlap tests (> 0)
  int maxSamples = 256;     // cap on the tests before the bisection
  int bisections = 12;      // each halves the bracket of the first contact
};

// The smallest sampled s in [0, 1] at which A and B overlap, refined by bisection so that the
// returned s overlaps and s - 2^-bisections of a sample interval does not; -1 if no sample
// overlaps. Only the stretch in which the bodies' bounding balls meet is sampled (none at all if
// they never meet). With sampleTravel below the thinner body's tunnelingSize no pass-through is
// missed (any crossing overlaps for a stretch of travel at least that thickness), unless
// maxSamples caps the count.
template <int d>
double firstContactFraction(const PreparedGeometry<d>& a, const StepMotion<d>& ma, const PreparedGeometry<d>& b,
                            const StepMotion<d>& mb, const SweptQuery& query);

}  // namespace monolith::solvers::collision
