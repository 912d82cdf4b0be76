#pragma once
// The surfaces drawn in the geometry frames (vtk_writer.h): each body's shape and level set as
// polygons in world coordinates, at the body's pose (x + R * body-frame point), with the body id
// of every point. 3-D: closed surfaces, faces counter-clockwise seen from outside. 2-D: outlines
// in the z = 0 plane, counter-clockwise around the body.
//
//   3-D box         its 6 faces
//   3-D sphere      latitude-longitude quads (kSphereRings x kSphereSegments), a point per pole
//   3-D cylinder    kRoundSegments side quads and two flat cap polygons
//   3-D capsule     a cylinder side and two hemispheres of kCapsuleRings latitude rings each
//   3-D convex      the triangles of the vertices' convex hull (interior vertices are not drawn)
//   3-D mesh        its own triangles
//   3-D plane       a square of side kPlanePatchSize centred on the body, facing the normal
//   2-D box/disk    a rectangle / a polygon of kRoundSegments points on the circle
//   2-D polygon     its vertices
//   2-D plane       a kPlanePatchSize x kPlaneStripDepth strip on the solid side of the line
//   level set       its zero contour (marching squares / marching tetrahedra)
#include <Eigen/Core>
#include <vector>

#include "components/level_set.h"
#include "components/rigid_body.h"
#include "components/shape.h"

namespace monolith {

// How finely round shapes are drawn (the tests derive the volumes of the drawn surfaces from them).
constexpr int kSphereRings = 8;     // latitude bands from pole to pole
constexpr int kSphereSegments = 16;
constexpr int kRoundSegments = 32;  // cylinder, capsule and disk
constexpr int kCapsuleRings = 8;    // latitude bands per hemisphere
// A plane is unbounded: a finite patch of it, large enough to show the ground under a scene of a
// few units, is drawn instead.
constexpr double kPlanePatchSize = 10;
constexpr double kPlaneStripDepth = 0.5;

// A point of the VTK files: 2-D points lie in the z = 0 plane.
inline Eigen::Vector3d lift(const Eigen::Vector2d& p) { return {p.x(), p.y(), 0.0}; }
inline Eigen::Vector3d lift(const Eigen::Vector3d& p) { return p; }

// Points (world coordinates, z = 0 in 2-D), the body id of each point, and polygons of point
// indices.
struct SurfacePolygons {
  std::vector<Eigen::Vector3d> points;
  std::vector<int> pointBody;
  std::vector<std::vector<int>> faces;
};

template <int d>
void appendShapeSurface(const RigidBody<d>& body, const Shape<d>& shape, int bodyId, SurfacePolygons& out);

// The zero contour of phi. 3-D: marching tetrahedra (six per sample cell), triangles facing
// increasing phi; 2-D: marching squares joined into one polygon per loop, counter-clockwise
// around the inside (a hole's loop runs clockwise). Every contour point is a zero of the
// level set's multilinear phi (LevelSet::value) on a cell edge or diagonal.
template <int d>
void appendLevelSetContour(const RigidBody<d>& body, const LevelSet<d>& levelSet, int bodyId, SurfacePolygons& out);

}  // namespace monolith
