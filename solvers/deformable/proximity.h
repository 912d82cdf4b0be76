#pragma once
// Collisions between the surfaces of deformable bodies and of a body with itself, entity-free
// (Bridson, Fedkiw, Anderson 2002 [27]: "Robust treatment of collisions, contact and friction for
// cloth animation"; the thesis's cloth and self-collisions, Ch. 4). The surfaces of all bodies
// are one set of particles (flat arrays x, v, inverse masses, d numbers per particle) with
//  * faces: triangles in 3-D (d = 3 indices each), segments in 2-D (d = 2), and
//  * edges (3-D only, 2 indices each), and the surface points.
// Two passes over the candidate velocities v (the step moves x to x + dt v):
//  1. proximity (repulsion): every point–face and edge–edge pair closer than the thickness at x
//     gets the impulse that stops its approach (inelastic) and, while inside the thickness,
//     pushes it apart at a fraction of (thickness - distance) per step; Coulomb friction
//     removes tangential relative velocity up to mu times the normal change;
//  2. collision: continuous detection over [x, x + dt v] (the times where the point and the
//     triangle, or the two edges, are coplanar, from the cubic of [27] Sec. 6.3; in 2-D the
//     point and segment collinear, a quadratic) with a proximity check at each such time; a hit
//     gets the impulse that makes the pair separate slightly along the normal at that time.
//     Repeated until a pass finds no collision or the pass limit is reached;
//  3. rigid impact zones ([27] Sec. 7.4) when collisions are left after the passes: the particles
//     of colliding pairs merged into zones, each moving with its rigid velocity (linear and
//     angular momentum kept), until no collision is found between zones (`remaining` then 0).
// Every impulse acts on the pair's particles with the weights of the closest points (the point
// +1, the face's vertices -b_i with b the barycentric coordinates; an edge's ends 1-s, s) and
// their inverse masses: the weights sum to zero, so linear momentum is conserved to round-off.
// Candidate pairs come from BVHs over boxes (in parallel, one list per query primitive); impulses
// are applied serially in that fixed order (Gauss-Seidel): the same on any number of threads.
#include <vector>

#include "solvers/deformable/bvh.h"

namespace monolith::solvers::deformable {

template <int d>
struct CollisionSurface {
  std::vector<int> faces;   // d particle indices per face
  std::vector<int> edges;   // 3-D: 2 particle indices per edge (every face edge once)
  std::vector<int> points;  // particles on a surface, each once
  std::vector<double> thickness;  // per particle; a pair uses the largest of its particles'
  std::vector<double> friction;   // per particle; a pair uses the largest of its particles'
  // Per particle: pairs whose particles are all of one group >= 0 are skipped (a solid's own
  // surface); -1 collides with everything, itself included (cloth).
  std::vector<int> group;
  // The BVHs over the faces and edges, built on first use and refitted after (a cache: the
  // candidate pairs are listed in an order that does not depend on the trees).
  mutable Bvh<d> faceTree, edgeTree;
  int faceCount() const { return static_cast<int>(faces.size()) / d; }
  int edgeCount() const { return static_cast<int>(edges.size()) / 2; }
};

struct ProximitySettings {
  double repulsion = 0.1;   // fraction of the thickness overlap removed per step by repulsion
  int collisionPasses = 32;
  double separation = 1e-3;  // a collision leaves the pair separating by this fraction of the thickness per step
  bool impactZones = true;   // rigid impact zones when the passes leave collisions ([27] Sec. 7.4)
};

struct ProximityReport {
  int repulsions = 0;   // pairs given a proximity impulse
  int collisions = 0;   // collision impulses over all passes
  int passes = 0;       // collision passes run
  int remaining = 0;    // collisions left: found by the last pass, or after the impact zones
  int impactZones = 0;       // rigid impact zones of two or more particles (0 when the passes sufficed)
  int impactZoneRounds = 0;  // detections that merged zones
  double closest = 0;   // smallest pair distance at x (infinite without close pairs)
};

// The boundary of a simplex mesh (d+1 indices per element): the faces belonging to one element
// only, with the surface edges (3-D) and points, and the given thickness and friction on every
// surface point. Indices are offset by `first` (the body's first particle in the joint arrays).
template <int d>
void addMeshBoundary(CollisionSurface<d>& s, const std::vector<int>& elements, int first, double thickness,
                     double friction, int group);
// A surface given by its faces (cloth triangles, d indices each), both sides colliding.
template <int d>
void addFaces(CollisionSurface<d>& s, const std::vector<int>& faces, int first, int particleCount, double thickness,
              double friction, int group);

template <int d>
ProximityReport repelProximities(const CollisionSurface<d>& s, const std::vector<double>& x, std::vector<double>& v,
                                 const std::vector<double>& inverseMass, double dt, const ProximitySettings& settings);

template <int d>
ProximityReport resolveCollisions(const CollisionSurface<d>& s, const std::vector<double>& x, std::vector<double>& v,
                                  const std::vector<double>& inverseMass, double dt, const ProximitySettings& settings);

// Rigid impact zones ([27] Sec. 7.4; Provot 1997), the fail-safe resolveCollisions runs when its
// passes leave collisions: the particles of colliding pairs are merged into zones, each given the
// rigid velocity that keeps its linear and angular momentum (a zone holding fixed or bound
// particles, of infinite mass, takes their rigid velocity), and the detection repeated until no
// pair between zones collides. A rigid velocity moves a zone's points by an invertible affine
// map over the step, so pairs within a zone cannot cross.
template <int d>
ProximityReport resolveImpactZones(const CollisionSurface<d>& s, const std::vector<double>& x, std::vector<double>& v,
                                   const std::vector<double>& inverseMass, double dt);

// The number of point–face and edge–edge pairs that cross over [x, x + dt v]: their
// coplanarity function changes sign at a time in (0, 1] where they meet (what resolveCollisions
// removes; a pair merely touching at the start, or sliding in its plane, does not count). For
// tests and diagnostics.
// The roots in [0, 1] of c0 + c1 t + c2 t^2 + c3 t^3 (the coplanarity function of a point and a
// triangle, or of two edges, moving linearly over a step), ascending: the interval is split at the
// critical points and each piece with a sign change bisected.
std::vector<double> rootsInUnitInterval(double c0, double c1, double c2, double c3);

template <int d>
int countCollisions(const CollisionSurface<d>& s, const std::vector<double>& x, const std::vector<double>& v, double dt);

}  // namespace monolith::solvers::deformable
