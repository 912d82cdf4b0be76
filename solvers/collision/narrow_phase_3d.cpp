// 3-D narrow phase: which pairs are exact and which go through FCL, and how FCL's
// single contact point becomes a manifold.
//
// Exact (no FCL): every pair with a half-space (the feature points of the other shape: box and
// hull vertices, capsule ends, cylinder rim points, sphere centre, mesh vertices), every sphere
// pair but sphere-mesh (the centre against the other shape's exact signed distance) and
// capsule-capsule (closest points of the two segments plus the end caps). These support the
// margin exactly.
// Box-box: our separating-axis test and clipped face manifold (box_box.cpp, FCL's contract).
// Capsule against box or hull: the exact penetration depth and axis (capsule_polytope.cpp) for
// the main contact, plus the feature points both ways.
// FCL: the rest. The other pairs give FCL's one point,
// completed as in the thesis by the vertex-in-shape test both ways (the vertices of A inside B
// with B's face normal and vice versa). Beyond FCL's contact, the margin is served by
// fcl::distance (one point; box pairs: their exact nearest points) and by the feature tests
// (exact). Shapes against a mesh go through
// narrow_phase_mesh.cpp (FCL per nearby triangle plus the feature points above each).
#include <cmath>

#include "solvers/collision/box_box_impl.h"
#include "solvers/collision/collision_impl.h"
#include "solvers/collision/contact_axis_impl.h"
#include "solvers/collision/narrow_phase_fcl_impl.h"

namespace monolith::solvers::collision {

namespace {

using Vec3 = Eigen::Vector3d;
using CP = ContactPoint<3>;
using PG = PreparedGeometry<3>;

// FCL's point is redundant when a feature point is as deep along (nearly) the same normal: MPR's
// axis matches a face normal to ~1e-7 rad and the depths along it then agree to ~1e-7 of the size.
constexpr double kRedundantDepth = 1e-6;  // times the pair's length scale
// Contacts closer than this (times the length scale) are duplicates, e.g. a corner found both by
// FCL's box-box clipping and by the vertex test.
constexpr double kMergeDistance = 1e-6;
// Pairs with a cylinder keep a feature contact only if its normal is within 70 degrees of the
// pair's minimum-translation normal (exact for them, penetration_axis.cpp). A rim point near the
// other cylinder's rim takes the nearest face's normal, which can be the side at 90 degrees to
// the cap the pair actually touches on; pushed along it, the body would slide sideways further
// in (seen in the shallow random contacts of test_narrow_phase). Other pairs keep the thesis's
// vertex-in-level-set rule as it is: only normals opposing the main one are dropped.
constexpr double kCylinderFeatureAgreement = 0.34;  // cos 70 degrees
// Other pairs drop feature contacts whose normal is perpendicular to the main one to rounding.
// Two boxes stacked with coplanar side faces (every pyramid pair) put a corner of each exactly
// on the other's side plane: the vertex test gives it that side's normal at depth 0. Such a
// point cannot push the pair apart along its normal, but as a sticking point it fixes the slip
// across the real contact's normal (the exact manifold finish then finds the rows inconsistent)
// and it adds half again to the pair's points.
constexpr double kPerpendicularToRounding = 1e-6;

struct Scratch {
  std::vector<CP> main, extra, result;
  std::vector<int> triangles;
  std::vector<Vec3> axes;
  std::vector<FeaturePoint<3>> features;
};
// Per thread: queries are const and run concurrently, and reuse their buffers once warm.
Scratch& scratch() {
  thread_local Scratch s;
  return s;
}

GeometryType typeOf(const PG& g) { return g.geometry().type; }

// Box pairs: what descendToMinimumOverlap searches for locally is known exactly from the
// separating-axis test (the least overlap over the 15 axes is the boxes' penetration depth), so
// the contact moves there directly when that is shallower than its own axis.
void moveToLeastOverlap(const PG& a, const Pose<3>& pa, const PG& b, const Pose<3>& pb, const BoxBoxAxis& axis,
                        CP& c) {
  if (!(axis.leastOverlap < c.depth)) return;
  CP moved;
  if (contactOnAxis(a, pa, -1, b, pb, -1, c.point, axis.leastOverlapNormal, kInfinity, moved) && moved.depth < c.depth)
    c = moved;
}

void capsulePair(const PG& a, const Pose<3>& pa, const PG& b, const Pose<3>& pb, double margin, double scale,
                 Scratch& s) {
  const Vec3 axisA = pa.R.col(2) * a.geometry().halfHeight, axisB = pb.R.col(2) * b.geometry().halfHeight;
  Vec3 ca, cb;
  closestSegmentPoints(pa.x - axisA, pa.x + axisA, pb.x - axisB, pb.x + axisB, ca, cb);
  const Vec3 diff = ca - cb;
  const double dist = diff.norm();
  Vec3 n;
  if (dist > 1e-12 * scale) {
    n = diff / dist;
  } else {  // the axes cross: the common normal of the two axes, facing A
    n = axisA.cross(axisB);
    n = n.norm() > 1e-12 * axisA.norm() * axisB.norm() ? Vec3(n.normalized()) : Vec3(axisA.unitOrthogonal());
    if (n.dot(pa.x - pb.x) < 0) n = -n;
  }
  const double ra = a.geometry().radius, rb = b.geometry().radius;
  s.main.clear();
  s.extra.clear();
  const double depth = ra + rb - dist;
  if (depth >= -margin) s.main.push_back(midwayContact<3>(ca - ra * n, cb + rb * n, n, depth));
  // The end caps: two points for capsules lying side by side.
  featureContacts<3>(a, pa, -n, b, pb, margin, false, s.features, s.extra);
  featureContacts<3>(b, pb, n, a, pa, margin, true, s.features, s.extra);
  keepUnrepresented<3>(s.main, s.extra, kRedundantDepth * scale, s.result);
}

// How a box pair's main contacts were found (boxBoxMain).
enum class BoxMain { None, Clipped, Nearest };

bool isPolytope(GeometryType t) { return t == GeometryType::Box || t == GeometryType::Convex; }
bool isCapsulePolytope(GeometryType ta, GeometryType tb) {
  return (ta == GeometryType::Capsule && isPolytope(tb)) || (tb == GeometryType::Capsule && isPolytope(ta));
}

// A box pair's main contacts, appended to `main`: our separating-axis test (`sat`) and face
// clipping (box_box.cpp) instead of FCL's dBoxBox; apart but within the margin, one contact
// between the exact nearest points instead of fcl::distance. None: farther apart than the margin
// (then neither could the feature points find anything), or nothing within it.
// touchOnly: only whether there is a main contact matters (`main` may be left incomplete).
BoxMain boxBoxMain(const PG& a, const Pose<3>& pa, const PG& b, const Pose<3>& pb, double margin, BoxBoxAxis& sat,
                   std::vector<CP>& main, bool touchOnly = false) {
  sat = boxBoxAxis(a.geometry(), pa, b.geometry(), pb, margin);
  if (sat.separation > margin) return BoxMain::None;
  if (touchOnly ? boxBoxContactsExist(a.geometry(), pa, b.geometry(), pb, sat, main)
                : boxBoxContacts(a.geometry(), pa, b.geometry(), pb, sat, main) > 0)
    return BoxMain::Clipped;
  if (!(margin > 0)) return BoxMain::None;
  Vec3 onA, onB;
  CP c;
  if (!boxBoxNearestPoints(a.geometry(), pa, b.geometry(), pb, sat, margin, onA, onB)) return BoxMain::None;
  if (!contactOnAxis(a, pa, -1, b, pb, -1, 0.5 * (onA + onB), onA - onB, margin, c)) return BoxMain::None;
  main.push_back(c);
  return BoxMain::Nearest;
}

void generalPair(const PG& a, const Pose<3>& pa, const PG& b, const Pose<3>& pb, double margin, double scale,
                 Scratch& s) {
  if (typeOf(b) == GeometryType::Mesh && typeOf(a) != GeometryType::Mesh) {
    meshContacts(a, pa, b, pb, margin, scale, s.result);
    return;
  }
  const bool boxBox = typeOf(a) == GeometryType::Box && typeOf(b) == GeometryType::Box;
  const bool capsulePolytope = isCapsulePolytope(typeOf(a), typeOf(b));
  const double tolerance = kRedundantDepth * scale;
  s.main.clear();
  s.extra.clear();
  s.triangles.clear();
  bool fclWorked = true;
  BoxBoxAxis sat;  // box pairs: the separating-axis test
  BoxMain boxMain = BoxMain::None;
  if (boxBox) {
    boxMain = boxBoxMain(a, pa, b, pb, margin, sat, s.main);
    if (boxMain == BoxMain::None) return;
    s.triangles.assign(s.main.size(), -1);
  } else if (capsulePolytope) {  // exact (capsule_polytope.cpp): no FCL, no search
    CP c;
    if (!capsulePolytopeContact(a, pa, b, pb, margin, c)) return;
    s.main.push_back(c);
    s.triangles.push_back(-1);
  } else {
    fclWorked = fclContacts(a, pa, b, pb, s.main, s.triangles);
  }
  const bool clippedManifold = boxMain == BoxMain::Clipped;  // the clipped box-box points: all kept
  // Else from the distance query (exact axis).
  const bool fromFcl = boxBox ? clippedManifold : !capsulePolytope && !s.main.empty();
  if (fclWorked && s.main.empty()) {  // (not box pairs: boxBoxMain did their distance query)
    if (!(margin > 0)) return;
    CP c;
    int triangle = -1;
    if (!fclMarginContact(a, pa, b, pb, margin, c, triangle)) return;
    s.main.push_back(c);
    s.triangles.push_back(triangle);
  }
  // Mesh-mesh keeps FCL's triangle contacts as they are (two static bodies, normally never
  // paired); box-box without margin needs nothing more (FCL clipped the faces already); the
  // rest gets the feature points both ways.
  if (typeOf(b) != GeometryType::Mesh && !(boxBox && fclWorked && !(margin > 0))) {
    const Vec3 towardsB = s.main.empty() ? Vec3(pb.x - pa.x) : Vec3(-s.main[0].normal);
    featureContacts<3>(a, pa, towardsB, b, pb, margin, false, s.features, s.extra);
    featureContacts<3>(b, pb, -towardsB, a, pa, margin, true, s.features, s.extra);
    if (s.main.size() == 1 && !capsulePolytope) {
      // The feature contacts' normals are face normals of A and B: candidate separating axes.
      // The one along which the shapes overlap least (if less than along FCL's axis) carries the
      // main contact, as the minimum-translation direction of the pair.
      s.axes.clear();
      for (const CP& c : s.extra) {
        bool known = false;
        for (const Vec3& axis : s.axes) known = known || std::abs(axis.dot(c.normal)) > 1 - 1e-12;
        if (!known) s.axes.push_back(c.normal);
      }
      refineAxis(a, pa, b, pb, -1, s.axes, s.main[0]);
      // Still not represented by a feature point (an edge contact): search for the axis of least
      // overlap around it, which is what MPR approximates.
      if (fromFcl && !isRepresented<3>(s.main[0], s.extra, tolerance)) {
        if (boxBox) moveToLeastOverlap(a, pa, b, pb, sat, s.main[0]);
        else descendToMinimumOverlap(a, pa, b, pb, s.main[0]);
      }
    }
    if (!s.main.empty()) {
      // A vertex that went more than half way through picks the far face: its normal opposes
      // the pair's minimum-translation direction and would push the wrong way.
      const Vec3 n = s.main[0].normal;
      const bool cylinder = typeOf(a) == GeometryType::Cylinder || typeOf(b) == GeometryType::Cylinder;
      const double agreement = cylinder ? kCylinderFeatureAgreement : kPerpendicularToRounding;
      std::size_t kept = 0;
      for (const CP& c : s.extra)
        if (c.normal.dot(n) > agreement) s.extra[kept++] = c;
      s.extra.resize(kept);
    }
  }
  if (clippedManifold) {
    s.result.insert(s.result.end(), s.main.begin(), s.main.end());
    s.result.insert(s.result.end(), s.extra.begin(), s.extra.end());
  } else {
    keepUnrepresented<3>(s.main, s.extra, tolerance, s.result);
  }
}

// A sphere (a) against a sphere or a half-space (b) in closed form: the contact featureContacts
// gives them (a's centre as a feature point of a's radius against b's exact signed distance),
// computed in the world frame without the relative pose and the feature list. These are most
// of the queries of a pour; the general route costs several times more.
void sphereContacts(const PG& a, const Pose<3>& pa, const PG& b, const Pose<3>& pb, double margin,
                    std::vector<CP>& out) {
  const Geometry<3>& gb = b.geometry();
  Vec3 normal, onB;  // normal out of b, towards a's centre
  double distance;   // of a's centre from b's surface
  if (gb.type == GeometryType::Sphere) {
    const Vec3 q = pa.x - pb.x;
    const double len = q.norm();
    normal = len > 0 ? Vec3(q / len) : Vec3(pb.R.col(1));  // coincident: b's y axis, as signedDistance
    distance = len - gb.radius;
    onB = pb.x + gb.radius * normal;
  } else {
    normal = pb.R * gb.normal;
    distance = normal.dot(pa.x - pb.x) - gb.offset;
    onB = pa.x - distance * normal;
  }
  const double radius = a.geometry().radius, depth = radius - distance;
  if (!(depth >= -margin)) return;
  CP c;
  c.point = 0.5 * (onB + (pa.x - radius * normal));
  c.normal = normal;
  c.depth = depth;
  out.push_back(c);
}

// A and B in the order the routines expect: a half-space is B, a sphere is A (unless the other is
// a mesh), a mesh is B.
void orderedContacts(const PG& a, const Pose<3>& pa, const PG& b, const Pose<3>& pb, double margin, double scale,
                     Scratch& s) {
  const GeometryType ta = typeOf(a), tb = typeOf(b);
  if (ta == GeometryType::Sphere && (tb == GeometryType::Sphere || tb == GeometryType::HalfSpace)) {
    sphereContacts(a, pa, b, pb, margin, s.result);
  } else if (tb == GeometryType::HalfSpace || (ta == GeometryType::Sphere && tb != GeometryType::Mesh)) {
    const Vec3 towardsB = tb == GeometryType::HalfSpace ? Vec3(-(pb.R * b.geometry().normal)) : Vec3(pb.x - pa.x);
    featureContacts<3>(a, pa, towardsB, b, pb, margin, false, s.features, s.result);
  } else if (ta == GeometryType::Capsule && tb == GeometryType::Capsule) {
    capsulePair(a, pa, b, pb, margin, scale, s);
  } else {
    generalPair(a, pa, b, pb, margin, scale, s);
  }
}

bool swapForOrder(GeometryType ta, GeometryType tb) {
  if (ta == GeometryType::HalfSpace || tb == GeometryType::HalfSpace) return ta == GeometryType::HalfSpace;
  if (ta == GeometryType::Mesh || tb == GeometryType::Mesh) return ta == GeometryType::Mesh && tb != GeometryType::Mesh;
  return tb == GeometryType::Sphere && ta != GeometryType::Sphere;
}

// Pairs whose contacts cost about as much as FCL's boolean test: overlaps() asks for the deepest
// contact instead (the mesh path included: FCL's own BVH traversal is the slow part).
bool contactsAreCheap(GeometryType ta, GeometryType tb) {
  if (ta == GeometryType::HalfSpace || tb == GeometryType::HalfSpace) return true;
  if (ta == GeometryType::Mesh || tb == GeometryType::Mesh) return ta != tb;
  return ta == GeometryType::Sphere || tb == GeometryType::Sphere ||
         (ta == GeometryType::Capsule && tb == GeometryType::Capsule) || isCapsulePolytope(ta, tb);
}

}  // namespace

int findContacts3(const PG& a, const Pose<3>& poseA, const PG& b, const Pose<3>& poseB, const ContactQuery& query,
                  std::vector<CP>& out) {
  if (a.unbounded() && b.unbounded()) return 0;
  const bool swap = swapForOrder(typeOf(a), typeOf(b));
  const double margin = std::max(0.0, query.margin);
  const double scale = pairLengthScale<3>(a, b);
  Scratch& s = scratch();
  s.result.clear();
  if (swap) orderedContacts(b, poseB, a, poseA, margin, scale, s);
  else orderedContacts(a, poseA, b, poseB, margin, scale, s);
  finishManifold<3>(s.result, query.maxPoints, kMergeDistance * scale);
  for (const CP& c : s.result) out.push_back(swap ? flipped<3>(c) : c);
  return static_cast<int>(s.result.size());
}

bool touches3(const PG& a, const Pose<3>& poseA, const PG& b, const Pose<3>& poseB, double margin) {
  margin = std::max(0.0, margin);
  if (typeOf(a) == GeometryType::Box && typeOf(b) == GeometryType::Box) {
    // generalPair's box-box route up to its main contacts: once they hold a point, the feature
    // points can only add more, and the merge keeps at least one.
    Scratch& s = scratch();
    s.main.clear();
    BoxBoxAxis sat;
    return boxBoxMain(a, poseA, b, poseB, margin, sat, s.main, /*touchOnly=*/true) != BoxMain::None;
  }
  thread_local std::vector<CP> found;
  found.clear();
  ContactQuery query;
  query.margin = margin;
  query.maxPoints = 1;
  return findContacts3(a, poseA, b, poseB, query, found) > 0;
}

bool overlaps3(const PG& a, const Pose<3>& poseA, const PG& b, const Pose<3>& poseB) {
  if (a.unbounded() && b.unbounded()) return false;
  if (typeOf(a) == GeometryType::Box && typeOf(b) == GeometryType::Box)
    return boxBoxAxis(a.geometry(), poseA, b.geometry(), poseB).separation < 0;
  if (!contactsAreCheap(typeOf(a), typeOf(b))) return fclOverlap(a, poseA, b, poseB);
  thread_local std::vector<CP> deepest;
  deepest.clear();
  ContactQuery query;
  query.maxPoints = 1;  // the deepest point decides
  findContacts3(a, poseA, b, poseB, query, deepest);
  return !deepest.empty() && deepest[0].depth > 0;
}

}  // namespace monolith::solvers::collision
