#pragma once
// Rigid bodies against the faces of deformable surfaces (cloth triangles, the boundary triangles
// of solids; segments in 2-D), entity-free. The particle/rigid contact (thesis Sec. 4.2) lets a
// body touch a surface at its particles only, so a body smaller than a face passes through its
// interior. Here each face near a body gets the point of the face deepest in the body's signed
// distance (its rigid feature against the face): the face point closest to a seed (the body's
// centre and its feature points: box corners, capsule ends, cylinder rims), then alternating
// projections between the body's surface and the face (for a convex body they converge to the
// closest pair; for a sphere the first is exact). A face point q with barycentric weights b (on
// the face's particles) closer to the body than the thickness and approaching gets the impulse j
// of the particle/rigid contact (restitution zero, Coulomb friction): the particles' velocity
// changes are b_i j / m_i, the body's -j at the arm q - x_body, so linear momentum
// (sum b_i = 1) and angular momentum about any point (q = sum b_i x_i) are conserved exactly.
// The pair's effective inverse mass at q is sum b_i^2 / m_i plus the body's response.
#include <Eigen/Core>
#include <vector>

#include "solvers/collision/geometry.h"
#include "solvers/contact/rigid_math.h"
#include "solvers/deformable/bvh.h"

namespace monolith::solvers::deformable {

template <int d>
using AngularD = solvers::contact::AngVec<d>;
template <int d>
using InertiaD = solvers::contact::AngMat<d>;

// One rigid body as the face contact sees it. Velocities are updated as impulses are applied
// (Gauss-Seidel); `impulse` and `angularImpulse` sum what it received (about its centre x), for
// the caller to add to its momentum.
template <int d>
struct RigidFaceBody {
  const collision::PreparedGeometry<d>* geometry = nullptr;
  Eigen::Matrix<double, d, 1> x = Eigen::Matrix<double, d, 1>::Zero();  // pose: centre of mass
  Eigen::Matrix<double, d, d> R = Eigen::Matrix<double, d, d>::Identity();
  Eigen::Matrix<double, d, 1> v = Eigen::Matrix<double, d, 1>::Zero();
  AngularD<d> omega = AngularD<d>::Zero();
  double inverseMass = 0;  // zero: immovable (static, kinematic, or held for this pass)
  InertiaD<d> inverseInertia = InertiaD<d>::Zero();  // world frame
  double friction = 0;
  Eigen::Matrix<double, d, 1> impulse = Eigen::Matrix<double, d, 1>::Zero();
  AngularD<d> angularImpulse = AngularD<d>::Zero();
};

// The faces (d particle indices each) and their particles: positions at which the contact is
// tested, velocities changed by the impulses, inverse masses (zero: fixed or bound), and per
// particle thickness and friction (a pair uses the largest over the face and the body's friction).
template <int d>
struct FaceSet {
  const std::vector<int>* faces = nullptr;
  const std::vector<double>* x = nullptr;
  std::vector<double>* v = nullptr;
  const std::vector<double>* inverseMass = nullptr;
  const std::vector<double>* thickness = nullptr;
  const std::vector<double>* friction = nullptr;
  int faceCount() const { return static_cast<int>(faces->size()) / d; }
};

// The deepest point of face f in body b.
template <int d>
struct FaceContact {
  int body = 0, face = 0;
  double weights[d];  // barycentric coordinates on the face's particles
  Eigen::Matrix<double, d, 1> point;   // on the face
  Eigen::Matrix<double, d, 1> normal;  // out of the body
  double distance = 0;                 // signed distance of `point` to the body (negative inside)
  double thickness = 0, friction = 0;
};

// The point of the face (vertices p[0..d-1]) deepest in the body, searched as described above.
template <int d>
FaceContact<d> deepestFacePoint(const RigidFaceBody<d>& body, const Eigen::Matrix<double, d, 1>* p);

// Faces within the thickness of some body (bounding boxes through `tree`, which is built on first
// use or when the face count changes and refitted otherwise), each pair's deepest point; in body
// order, faces ascending (the same on any thread count).
template <int d>
std::vector<FaceContact<d>> findFaceContacts(const std::vector<RigidFaceBody<d>>& bodies, const FaceSet<d>& faces,
                                             Bvh<d>& tree);
// Storage findFaceContacts reuses from call to call.
template <int d>
struct FaceContactWorkspace {
  std::vector<Box<d>> boxes;
  std::vector<int> hits;
  std::vector<std::pair<int, int>> pairs;  // (body, face) whose boxes overlap
  std::vector<FaceContact<d>> slots;       // one per pair
  std::vector<char> close;                 // the pair's deepest point is within the thickness
};
// The same into `out`; the face boxes and the deepest points of the (body, face) pairs are
// computed in parallel, one slot per pair, and kept in pair order: bitwise the same on any thread
// count.
template <int d>
void findFaceContacts(const std::vector<RigidFaceBody<d>>& bodies, const FaceSet<d>& faces, Bvh<d>& tree,
                      FaceContactWorkspace<d>& work, std::vector<FaceContact<d>>& out);

// The swept test (3-D; 2-D returns none): the centre of each moving body, from x - dt v to its
// candidate x (the bodies at their candidate poses), against every face moving from `start` to
// start + dt v (faces.v); where the centre passes through a face within the step (a root of the
// point-triangle coplanarity cubic with the centre inside the triangle) the body would tunnel
// through it between the discrete tests' positions. Each such (body, face) pair becomes a contact
// (replacing the pair's contact in `discrete`, whose normal, found past the face, would push the
// body on through) at the crossing's barycentric weights (the point the face's
// candidate positions give them, so that impulses there keep angular momentum), its normal the
// face normal turned towards the side the centre came from. `tree` is built over the faces'
// swept boxes. In body order, faces ascending.
template <int d>
void findSweptFaceContacts(const std::vector<RigidFaceBody<d>>& bodies, const FaceSet<d>& faces,
                           const std::vector<double>& start, double dt, std::vector<FaceContact<d>>& discrete,
                           Bvh<d>& tree, FaceContactWorkspace<d>& work, std::vector<FaceContact<d>>& out);
// Gauss-Seidel sweeps over the contacts, forward and backward in turn: each approaching pair
// (relative normal velocity at the point < 0) gets the impulse that stops the approach, with
// Coulomb friction. Returns the number of impulses applied.
template <int d>
int applyFaceContactImpulses(std::vector<RigidFaceBody<d>>& bodies, FaceSet<d>& faces,
                             const std::vector<FaceContact<d>>& contacts, int sweeps);

// Moves the face particles (positions `x`, inverse masses as weights) so that each contact point
// inside its body reaches the body's surface: dx_i = b_i w_i / (sum b_k^2 w_k) * depth * n.
// The bodies are not moved. Returns the deepest depth met.
template <int d>
double pushFacesOut(const std::vector<FaceContact<d>>& contacts, const std::vector<int>& faces,
                    const std::vector<double>& inverseMass, std::vector<double>& x);

}  // namespace monolith::solvers::deformable
