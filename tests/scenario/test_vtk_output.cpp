// VTK output read back by a real VTK reader: runs small 3-D and 2-D scenes through the CLI and
// reads the frames with vtkXMLPolyDataReader (tests/support/read_vtp.py, run with the python
// that has the vtk module), then compares with closed-form values.
//
// The scenes are chosen so that every quantity has an exact solution the integrator reproduces
// up to rounding: constant gravity (velocity Verlet is exact for constant acceleration:
// x^n = x0 + v0 t + g t^2/2), no contacts, and rotating bodies with isotropic inertia (sphere,
// cube, disk), whose angular velocity is constant and whose orientation is exp(w t).
#include <gtest/gtest.h>

#include "components/level_set.h"
#include "components/rigid_body.h"
#include "components/shape.h"
#include "ecs/world.h"
#include "scenarios/body_surfaces.h"
#include "scenarios/vtk_writer.h"
#include "support/cli_harness.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <filesystem>
#include <map>
#include <set>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using namespace monolith::test;

// Rounding of a handful of steps on O(1..10) values is ~1e-14; 1e-12 leaves a wide margin and
// still catches any real error (a first-order integrator is off by g dt^2/2 ~ 0.05 here).
constexpr double kTol = 1e-12;

std::string vtkPython() {
  const char* p = std::getenv("MONOLITH_VTK_PYTHON");
  return p && *p ? p : "/usr/bin/python3";  // the python3 first on PATH may lack the vtk module
}

// Reads files with the helper script. Returns false (and sets `skip`) when VTK is missing.
bool readWithVtk(const std::vector<fs::path>& files, const fs::path& logDir, Json& out, std::string& skip) {
  std::vector<std::string> argv = {vtkPython(), std::string(MONOLITH_SOURCE_DIR) + "/tests/support/read_vtp.py"};
  for (const auto& f : files) argv.push_back(f.string());
  const CommandResult r = run(argv, logDir);
  if (r.exitCode == 77) {
    skip = "the vtk python module is not available to " + vtkPython() + ": " + r.err;
    return false;
  }
  EXPECT_EQ(r.exitCode, 0) << r.err;
  out = Json::parse(r.out.empty() ? "{}" : r.out);
  for (const auto& f : files) {
    EXPECT_TRUE(out["files"].contains(f.string())) << f;
    // VTK prints errors and warnings (bad XML, bad array sizes, unknown types) but keeps going:
    // a clean read must print nothing.
    EXPECT_EQ(out["files"][f.string()].value("vtk_messages", std::string("?")), "") << f;
  }
  return true;
}

Eigen::Vector3d vec3(const Json& j) { return {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()}; }

void expectNear3(const Eigen::Vector3d& got, const Eigen::Vector3d& want, double tol, const std::string& what) {
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(got(k), want(k), tol) << what << " component " << k;
}

// Quaternion (w, x, y, z) of a rotation by |w| t about w (isotropic body, constant w).
Eigen::Vector4d rotationQuaternion(const Eigen::Vector3d& omega, double t) {
  const double angle = omega.norm() * t;
  if (angle == 0) return {1, 0, 0, 0};
  const Eigen::Vector3d axis = omega.normalized();
  return {std::cos(angle / 2), std::sin(angle / 2) * axis.x(), std::sin(angle / 2) * axis.y(),
          std::sin(angle / 2) * axis.z()};
}

struct BodySpec {
  std::string name;
  Eigen::Vector3d x0, v0, omega;
  double mass;
};

// Per-body points and polygons of a geometry frame, split by the body_id point array.
struct BodyGeometry {
  std::vector<Eigen::Vector3d> points;
  int polys = 0;
  std::vector<std::size_t> polySizes;
  std::vector<std::vector<int>> faces;  // indices into `points`
};
std::map<long, BodyGeometry> splitGeometry(const Json& g) {
  std::map<long, BodyGeometry> out;
  const Json& ids = g["point_data"]["body_id"]["values"];
  const Json& points = g["points"];
  EXPECT_EQ(ids.size(), points.size());
  std::vector<int> localIndex;
  for (std::size_t i = 0; i < points.size() && i < ids.size(); ++i) {
    auto& body = out[std::lround(ids[i].get<double>())];
    localIndex.push_back(static_cast<int>(body.points.size()));
    body.points.push_back(vec3(points[i]));
  }
  for (const auto& poly : g["polys"]) {
    const long body = std::lround(ids.at(poly.at(0).get<std::size_t>()).get<double>());
    std::vector<int> face;
    for (const auto& p : poly) {
      EXPECT_EQ(std::lround(ids.at(p.get<std::size_t>()).get<double>()), body) << "polygon spans bodies";
      face.push_back(localIndex.at(p.get<std::size_t>()));
    }
    out[body].polys++;
    out[body].polySizes.push_back(poly.size());
    out[body].faces.push_back(face);
  }
  return out;
}

constexpr const char* kScene3d = R"({
  "description": "three free bodies under gravity for the VTK read-back test",
  "dimension": 3,
  "time": { "dt": 0.1, "steps": 4, "frame_rate": 10 },
  "gravity": [0, 0, -9.81],
  "entities": [
    { "name": "crate", "shape": { "type": "box", "half_extents": [0.5, 1.0, 1.5] },
      "rigid_body": { "mass": 2.0, "position": [1, 2, 3], "velocity": [0.5, -1, 2] } },
    { "name": "ball", "shape": { "type": "sphere", "radius": 0.25 },
      "rigid_body": { "mass": 1.0, "position": [-1, 0, 5], "velocity": [0, 3, 0], "angular_velocity": [0, 0, 3] } },
    { "name": "spinner", "shape": { "type": "box", "half_extents": [0.2, 0.2, 0.2] },
      "rigid_body": { "mass": 1.5, "position": [0, 0, 0], "angular_velocity": [1, 2, 3] } }
  ]
})";

TEST(VtkOutput, BodiesGeometryAndCollection3D) {
  TempDir tmp;
  const fs::path scene = tmp.path() / "three_bodies.json", out = tmp.path() / "run";
  writeFile(scene, kScene3d);
  const CommandResult r = run({MONOLITH_CLI, "run", scene.string(), "--out", out.string(), "--quiet"}, tmp.logs());
  ASSERT_EQ(r.exitCode, 0) << r.err;

  const double dt = 0.1, t = 4 * dt;
  const Eigen::Vector3d g(0, 0, -9.81);
  const std::vector<BodySpec> bodies = {{"crate", {1, 2, 3}, {0.5, -1, 2}, {0, 0, 0}, 2.0},
                                        {"ball", {-1, 0, 5}, {0, 3, 0}, {0, 0, 3}, 1.0},
                                        {"spinner", {0, 0, 0}, {0, 0, 0}, {1, 2, 3}, 1.5}};

  const fs::path b0 = out / "frames/bodies_000000.vtp", b4 = out / "frames/bodies_000004.vtp",
                 g4 = out / "frames/geometry_000004.vtp", bp = out / "bodies.pvd", gp = out / "geometry.pvd";
  Json j;
  std::string skip;
  if (!readWithVtk({b0, b4, g4, bp, gp}, tmp.logs(), j, skip)) GTEST_SKIP() << skip;

  // Frame 0 is the initial state: values written with 17 significant digits read back exactly.
  const Json& f0 = j["files"][b0.string()];
  ASSERT_EQ(f0["number_of_points"], 3);
  for (std::size_t i = 0; i < bodies.size(); ++i)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(f0["points"][i][k].get<double>(), bodies[i].x0(k)) << bodies[i].name;

  const Json& f = j["files"][b4.string()];
  ASSERT_EQ(f["number_of_points"], 3);
  EXPECT_EQ(f["number_of_verts"], 3);  // one vertex cell per body, so ParaView shows the points
  const Json& pd = f["point_data"];
  for (const char* a : {"id", "name", "velocity", "angular_velocity", "orientation", "mass"})
    ASSERT_TRUE(pd.contains(a)) << "missing point array " << a;
  EXPECT_EQ(pd["name"]["class"], "vtkStringArray");
  EXPECT_EQ(pd["name"]["tuples"], 3);
  EXPECT_EQ(pd["velocity"]["components"], 3);
  EXPECT_EQ(pd["angular_velocity"]["components"], 3);
  EXPECT_EQ(pd["orientation"]["components"], 4);
  EXPECT_EQ(pd["mass"]["components"], 1);
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const BodySpec& b = bodies[i];
    SCOPED_TRACE(b.name);
    EXPECT_EQ(pd["name"]["values"][i].get<std::string>(), b.name);
    EXPECT_EQ(pd["id"]["values"][i].get<double>(), double(i));  // entity index, in file order
    EXPECT_EQ(pd["mass"]["values"][i].get<double>(), b.mass);   // exact: written with %.17g
    expectNear3(vec3(f["points"][i]), b.x0 + b.v0 * t + 0.5 * g * t * t, kTol, "position");
    expectNear3(vec3(pd["velocity"]["values"][i]), b.v0 + g * t, kTol, "velocity");
    expectNear3(vec3(pd["angular_velocity"]["values"][i]), b.omega, kTol, "angular velocity");
    const Eigen::Vector4d q = rotationQuaternion(b.omega, t);
    for (int k = 0; k < 4; ++k)
      EXPECT_NEAR(pd["orientation"]["values"][i][k].get<double>(), q(k), kTol) << "orientation (w,x,y,z) " << k;
  }

  // Geometry: the crate does not rotate, so its box spans position +/- half extents.
  const Json& geo = j["files"][g4.string()];
  auto parts = splitGeometry(geo);
  ASSERT_EQ(parts.size(), 3u);
  const Eigen::Vector3d crate = bodies[0].x0 + bodies[0].v0 * t + 0.5 * g * t * t, half(0.5, 1.0, 1.5);
  ASSERT_EQ(parts[0].points.size(), 8u);
  EXPECT_EQ(parts[0].polys, 6);
  for (auto n : parts[0].polySizes) EXPECT_EQ(n, 4u);
  Eigen::Vector3d lo = parts[0].points[0], hi = lo;
  for (const auto& p : parts[0].points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  expectNear3(lo, crate - half, kTol, "crate box lower bound");
  expectNear3(hi, crate + half, kTol, "crate box upper bound");
  // The ball's surface points lie on its sphere (rotation only moves them on it); the spinning
  // cube's corners stay at |h| sqrt(3) from its centre and it keeps its 6 faces.
  const Eigen::Vector3d ball = bodies[1].x0 + bodies[1].v0 * t + 0.5 * g * t * t;
  EXPECT_GT(parts[1].polys, 0);
  for (const auto& p : parts[1].points) EXPECT_NEAR((p - ball).norm(), 0.25, kTol);
  const Eigen::Vector3d spinner = 0.5 * g * t * t;
  ASSERT_EQ(parts[2].points.size(), 8u);
  EXPECT_EQ(parts[2].polys, 6);
  for (const auto& p : parts[2].points) EXPECT_NEAR((p - spinner).norm(), 0.2 * std::sqrt(3.0), kTol);
  // VTK's own bounds of the whole surface agree with the points.
  Eigen::Vector3d all_lo = vec3(geo["points"][0]), all_hi = all_lo;
  for (const auto& p : geo["points"]) {
    all_lo = all_lo.cwiseMin(vec3(p));
    all_hi = all_hi.cwiseMax(vec3(p));
  }
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(geo["bounds"][2 * k].get<double>(), all_lo(k));
    EXPECT_EQ(geo["bounds"][2 * k + 1].get<double>(), all_hi(k));
  }
  EXPECT_EQ(geo["number_of_polys"].get<std::size_t>(), geo["polys"].size());

  // The collections: one dataset per written frame (0..4), at t = n dt, all files present.
  for (const fs::path& pvd : {bp, gp}) {
    const Json& c = j["files"][pvd.string()];
    ASSERT_EQ(c["timesteps"].size(), 5u) << pvd;
    for (std::size_t n = 0; n < 5; ++n) {
      EXPECT_NEAR(c["timesteps"][n].get<double>(), n * dt, kTol);
      EXPECT_TRUE(c["files_exist"][n].get<bool>()) << c["files"][n];
    }
    EXPECT_EQ(c["files"][4], pvd == bp ? "frames/bodies_000004.vtp" : "frames/geometry_000004.vtp");
  }
}

// Names are written as a vtkStringArray: empty names, spaces and UTF-8 must survive.
TEST(VtkOutput, StringArrayNamesReadBackExactly) {
  TempDir tmp;
  const fs::path scene = tmp.path() / "names.json", out = tmp.path() / "run";
  writeFile(scene, R"({
    "dimension": 3, "time": { "dt": 0.1, "steps": 1 },
    "entities": [
      { "shape": { "type": "sphere", "radius": 1 }, "rigid_body": { "mass": 1 } },
      { "name": "two words", "shape": { "type": "sphere", "radius": 1 }, "rigid_body": { "mass": 1 } },
      { "name": "caf\u00e9 \u2192 \u03c9", "shape": { "type": "sphere", "radius": 1 }, "rigid_body": { "mass": 1 } },
      { "shape": { "type": "sphere", "radius": 1 }, "rigid_body": { "mass": 1 } },
      { "name": "x", "shape": { "type": "sphere", "radius": 1 }, "rigid_body": { "mass": 1 } }
    ]
  })");
  const CommandResult r = run({MONOLITH_CLI, "run", scene.string(), "--out", out.string(), "--quiet"}, tmp.logs());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const fs::path frame = out / "frames/bodies_000001.vtp";
  Json j;
  std::string skip;
  if (!readWithVtk({frame}, tmp.logs(), j, skip)) GTEST_SKIP() << skip;
  const Json& names = j["files"][frame.string()]["point_data"]["name"];
  EXPECT_EQ(names["tuples"], 5);
  const std::vector<std::string> want = {"", "two words", "caf\xc3\xa9 \xe2\x86\x92 \xcf\x89", "", "x"};
  ASSERT_EQ(names["values"].size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) EXPECT_EQ(names["values"][i].get<std::string>(), want[i]) << i;
}

TEST(VtkOutput, TwoDimensionalSceneLiesInTheXYPlane) {
  TempDir tmp;
  const fs::path scene = tmp.path() / "planar.json", out = tmp.path() / "run";
  writeFile(scene, R"({
    "dimension": 2,
    "time": { "dt": 0.05, "steps": 4, "frame_rate": 20 },
    "gravity": [0, -9.81],
    "entities": [
      { "name": "disk", "shape": { "type": "disk", "radius": 0.5 },
        "rigid_body": { "mass": 1.0, "position": [0, 2], "velocity": [1, 0], "angular_velocity": 2 } },
      { "name": "plank", "shape": { "type": "box", "half_extents": [1.0, 0.25] },
        "rigid_body": { "mass": 3.0, "position": [3, 1], "velocity": [0, 0.5] } }
    ]
  })");
  const CommandResult r = run({MONOLITH_CLI, "run", scene.string(), "--out", out.string(), "--quiet"}, tmp.logs());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const fs::path bf = out / "frames/bodies_000004.vtp", gf = out / "frames/geometry_000004.vtp";
  Json j;
  std::string skip;
  if (!readWithVtk({bf, gf, out / "bodies.pvd"}, tmp.logs(), j, skip)) GTEST_SKIP() << skip;

  const double t = 4 * 0.05;
  const Eigen::Vector3d g(0, -9.81, 0);
  const Eigen::Vector3d disk = Eigen::Vector3d(0, 2, 0) + Eigen::Vector3d(1, 0, 0) * t + 0.5 * g * t * t;
  const Eigen::Vector3d plank = Eigen::Vector3d(3, 1, 0) + Eigen::Vector3d(0, 0.5, 0) * t + 0.5 * g * t * t;

  const Json& b = j["files"][bf.string()];
  ASSERT_EQ(b["number_of_points"], 2);
  EXPECT_EQ(b["number_of_verts"], 2);
  for (const auto& p : b["points"]) EXPECT_EQ(p[2].get<double>(), 0.0);  // z is exactly 0 in 2-D
  expectNear3(vec3(b["points"][0]), disk, kTol, "disk position");
  expectNear3(vec3(b["points"][1]), plank, kTol, "plank position");
  const Json& pd = b["point_data"];
  EXPECT_EQ(pd["name"]["values"], Json::array({"disk", "plank"}));
  expectNear3(vec3(pd["velocity"]["values"][0]), Eigen::Vector3d(1, 0, 0) + g * t, kTol, "disk velocity");
  // 2-D spin is about z: angular velocity (0, 0, w), orientation (cos(a/2), 0, 0, sin(a/2)), a = w t.
  expectNear3(vec3(pd["angular_velocity"]["values"][0]), Eigen::Vector3d(0, 0, 2), kTol, "disk angular velocity");
  const Eigen::Vector4d q(std::cos(t), 0, 0, std::sin(t));
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(pd["orientation"]["values"][0][k].get<double>(), q(k), kTol) << k;

  const Json& geo = j["files"][gf.string()];
  EXPECT_EQ(geo["number_of_polys"], 2);  // one polygon per body in 2-D
  EXPECT_EQ(geo["bounds"][4].get<double>(), 0.0);
  EXPECT_EQ(geo["bounds"][5].get<double>(), 0.0);
  auto parts = splitGeometry(geo);
  ASSERT_EQ(parts.size(), 2u);
  // The plank is a 4-corner polygon spanning position +/- half extents (it does not rotate).
  ASSERT_EQ(parts[1].points.size(), 4u);
  EXPECT_EQ(parts[1].polys, 1);
  Eigen::Vector3d lo = parts[1].points[0], hi = lo;
  for (const auto& p : parts[1].points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  expectNear3(lo, plank - Eigen::Vector3d(1.0, 0.25, 0), kTol, "plank lower bound");
  expectNear3(hi, plank + Eigen::Vector3d(1.0, 0.25, 0), kTol, "plank upper bound");
  // The disk outline: one polygon whose points are all on the circle.
  EXPECT_EQ(parts[0].polys, 1);
  EXPECT_GE(parts[0].points.size(), 16u);
  for (const auto& p : parts[0].points) EXPECT_NEAR((p - disk).norm(), 0.5, kTol);
  EXPECT_EQ(geo["number_of_points"].get<std::size_t>(), parts[0].points.size() + parts[1].points.size());
  EXPECT_EQ(j["files"][(out / "bodies.pvd").string()]["timesteps"].size(), 5u);
}

// --- every shape type and level set drawn as itself (scenarios/body_surfaces.h) -------------------
// Geometry frames written straight from a World, read back with VTK and compared with closed forms:
// the volume the drawn faces enclose (divergence theorem, polygons fanned into triangles), the
// distance of every drawn point to the analytic surface, 2-D areas (shoelace), and phi at level-set
// contour points. Closed surfaces must also be watertight and consistently turned: every directed
// edge of a face meets exactly one opposite edge of another.

using monolith::LevelSet;
using monolith::RigidBody;
using monolith::Shape;
using monolith::ShapeType;
using monolith::World;

// Drawn points are x + R * (a point of the surface); the writer rounds once, so 1e-12 holds for
// positions of size O(1); distances to curved surfaces get 1e-9 as the brief's bound.
constexpr double kOnSurface = 1e-9;

double enclosedVolume(const BodyGeometry& g) {
  const Eigen::Vector3d o = g.points.at(0);  // about a nearby origin: less cancellation
  double v = 0;
  for (const auto& f : g.faces)
    for (std::size_t k = 1; k + 1 < f.size(); ++k)
      v += (g.points[f[0]] - o).dot((g.points[f[k]] - o).cross(g.points[f[k + 1]] - o)) / 6;
  return v;
}

// Normal times area of one polygon (in 2-D, z is the shoelace area).
Eigen::Vector3d vectorArea(const BodyGeometry& g, const std::vector<int>& f) {
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < f.size(); ++k) a += g.points[f[k]].cross(g.points[f[(k + 1) % f.size()]]) / 2;
  return a;
}

double perimeter(const BodyGeometry& g, const std::vector<int>& f) {
  double length = 0;
  for (std::size_t k = 0; k < f.size(); ++k) length += (g.points[f[(k + 1) % f.size()]] - g.points[f[k]]).norm();
  return length;
}

// Directed edges without exactly one opposite partner (0 for a closed, consistently turned surface).
int unmatchedEdges(const BodyGeometry& g) {
  std::map<std::pair<int, int>, int> count;
  for (const auto& f : g.faces)
    for (std::size_t k = 0; k < f.size(); ++k) count[{f[k], f[(k + 1) % f.size()]}]++;
  int bad = 0;
  for (const auto& [edge, n] : count) {
    const auto back = count.find({edge.second, edge.first});
    bad += n != 1 || back == count.end() || back->second != 1;
  }
  return bad;
}

// Vertices - edges + faces: 2 for a sphere-like surface, 0 for a torus.
int eulerCharacteristic(const BodyGeometry& g) {
  std::set<std::pair<int, int>> edges;
  std::set<int> used;
  for (const auto& f : g.faces)
    for (std::size_t k = 0; k < f.size(); ++k) {
      const int a = f[k], b = f[(k + 1) % f.size()];
      edges.insert({std::min(a, b), std::max(a, b)});
      used.insert(a);
    }
  return static_cast<int>(used.size()) - static_cast<int>(edges.size()) + static_cast<int>(g.faces.size());
}

// The body-frame point of every drawn point, undoing x + R * local.
struct Pose {
  Eigen::Vector3d x;
  Eigen::Matrix3d R;
  Eigen::Vector3d toBody(const Eigen::Vector3d& p) const { return R.transpose() * (p - x); }
};

// The largest |f(body-frame point)| over the drawn points.
double worstOver(const BodyGeometry& g, const Pose& pose, const std::function<double(const Eigen::Vector3d&)>& f) {
  double worst = 0;
  for (const auto& p : g.points) worst = std::max(worst, std::abs(f(pose.toBody(p))));
  return worst;
}

double boxDistance(const Eigen::Vector3d& q, const Eigen::Vector3d& h) {
  const Eigen::Vector3d d = q.cwiseAbs() - h;
  return d.cwiseMax(0.0).norm() + std::min(d.maxCoeff(), 0.0);
}
double cylinderDistance(const Eigen::Vector3d& q, double r, double h) {
  const Eigen::Vector2d d(std::hypot(q.x(), q.y()) - r, std::abs(q.z()) - h);
  return d.cwiseMax(0.0).norm() + std::min(d.maxCoeff(), 0.0);
}
double capsuleDistance(const Eigen::Vector3d& q, double r, double h) {
  return (q - Eigen::Vector3d(0, 0, std::clamp(q.z(), -h, h))).norm() - r;
}

// Rings of n points at (rho, z), top to bottom, joined by planar trapezoids (triangles at a pole),
// enclose a stack of frustums of regular n-gon pyramids: sum of (z1 - z2)/3 (A1 + A2 + sqrt(A1 A2)),
// A = n/2 rho^2 sin(2 pi/n). That is the exact volume of the drawn sphere, cylinder and capsule.
double stackedFrustums(const std::vector<Eigen::Vector2d>& rings, int n) {
  auto area = [n](double rho) { return n / 2.0 * rho * rho * std::sin(2 * M_PI / n); };
  double v = 0;
  for (std::size_t k = 0; k + 1 < rings.size(); ++k) {
    const double a1 = area(rings[k].x()), a2 = area(rings[k + 1].x());
    v += (rings[k].y() - rings[k + 1].y()) / 3 * (a1 + a2 + std::sqrt(a1 * a2));
  }
  return v;
}
// Latitude rings i = first..last of a sphere about height zc whose meridian is cut in `bands`.
std::vector<Eigen::Vector2d> latitudeRings(double r, double zc, int first, int last, int bands) {
  std::vector<Eigen::Vector2d> rings;
  for (int i = first; i <= last; ++i) rings.emplace_back(r * std::sin(M_PI * i / bands), zc + r * std::cos(M_PI * i / bands));
  return rings;
}

// A new entity with a rigid body at the given pose and `component` (a shape or a level set).
template <int d, class Component>
void addPosed(World<d>& world, const Eigen::Matrix<double, d, 1>& x, const monolith::Orientation<d>& orientation,
              const Component& component) {
  const monolith::Entity e = world.create();
  RigidBody<d> body;
  body.x = x;
  body.orientation = orientation;
  world.add(e, body);
  world.add(e, component);
}

// Writes the geometry frame of `world`, reads it back with VTK and splits it by body.
template <int d>
bool writeAndRead(const World<d>& world, TempDir& tmp, std::map<long, BodyGeometry>& parts, std::string& skip) {
  const fs::path file = tmp.path() / "geometry.vtp";
  monolith::writeRigidGeometryFrame(world, file.string());
  Json j;
  if (!readWithVtk({file}, tmp.logs(), j, skip)) return false;
  parts = splitGeometry(j["files"][file.string()]);
  return true;
}

Shape<3> makeShape(ShapeType type, double radius = 0.5, double halfHeight = 0.5) {
  Shape<3> s;
  s.type = type;
  s.radius = radius;
  s.halfHeight = halfHeight;
  return s;
}

// A house: the box [-1,1] x [-0.5,0.5] x [-0.75,0.75] with a roof apex at z = 1.5, plus a point
// inside that the hull must leave out. Volume 3 + 2 * 0.75 / 3 = 3.5.
const std::vector<Eigen::Vector3d> kHouse = {{-1, -0.5, -0.75}, {1, -0.5, -0.75}, {-1, 0.5, -0.75}, {1, 0.5, -0.75},
                                             {-1, -0.5, 0.75},  {1, -0.5, 0.75},  {-1, 0.5, 0.75},  {1, 0.5, 0.75},
                                             {0, 0, 1.5}};
const Eigen::Vector3d kHouseInside(0.1, 0.05, 0.2);

// The octahedron with vertices (+-a, 0, 0), (0, +-b, 0), (0, 0, +-c): volume 4/3 a b c.
Shape<3> octahedron(double a, double b, double c) {
  Shape<3> s = makeShape(ShapeType::Mesh);
  s.vertices = {a, 0, 0, -a, 0, 0, 0, b, 0, 0, -b, 0, 0, 0, c, 0, 0, -c};
  for (int sx = 0; sx < 2; ++sx)
    for (int sy = 0; sy < 2; ++sy)
      for (int sz = 0; sz < 2; ++sz) {
        const bool outward = (sx + sy + sz) % 2 == 0;  // (x, y, z) turns outwards in the octants + + +, + - -, ...
        const int vx = sx, vy = 2 + sy, vz = 4 + sz;
        s.triangles.insert(s.triangles.end(), {vx, outward ? vy : vz, outward ? vz : vy});
      }
  return s;
}

TEST(VtkOutput, EveryShapeTypeIsDrawnAsItself3D) {
  World<3> world;
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  const Pose pose{{1, -2, 0.5}, q.toRotationMatrix()};
  const Eigen::Vector3d half(0.5, 1.0, 1.5);
  const double sphereR = 0.75, cylR = 0.6, cylH = 0.9, capR = 0.4, capH = 0.8;
  Shape<3> box = makeShape(ShapeType::Box), convex = makeShape(ShapeType::Convex), plane = makeShape(ShapeType::Plane);
  box.halfExtents = half;
  for (const auto& v : kHouse) convex.vertices.insert(convex.vertices.end(), {v.x(), v.y(), v.z()});
  convex.vertices.insert(convex.vertices.end(), {kHouseInside.x(), kHouseInside.y(), kHouseInside.z()});
  plane.normal = Eigen::Vector3d(0, 0, 2);  // not unit: the drawing normalizes
  const std::vector<Shape<3>> shapes = {box,
                                        makeShape(ShapeType::Sphere, sphereR),
                                        makeShape(ShapeType::Cylinder, cylR, cylH),
                                        makeShape(ShapeType::Capsule, capR, capH),
                                        convex,
                                        octahedron(0.5, 1.0, 1.5),
                                        plane};
  for (const auto& shape : shapes) {
    addPosed<3>(world, pose.x, q, shape);
  }
  TempDir tmp;
  std::map<long, BodyGeometry> parts;
  std::string skip;
  if (!writeAndRead(world, tmp, parts, skip)) GTEST_SKIP() << skip;
  ASSERT_EQ(parts.size(), shapes.size());

  for (long b = 0; b < 6; ++b) EXPECT_EQ(unmatchedEdges(parts[b]), 0) << "body " << b << " is not a closed surface";
  for (long b = 0; b < 6; ++b) EXPECT_EQ(eulerCharacteristic(parts[b]), 2) << "body " << b;

  // Box: exact.
  EXPECT_NEAR(enclosedVolume(parts[0]), 8 * half.prod(), 1e-12);
  EXPECT_LT(worstOver(parts[0], pose, [&](const Eigen::Vector3d& p) { return boxDistance(p, half); }), kOnSurface);
  // Sphere: kSphereRings x kSphereSegments latitude-longitude polyhedron, inscribed.
  const double sphere = enclosedVolume(parts[1]);
  EXPECT_NEAR(sphere, stackedFrustums(latitudeRings(sphereR, 0, 0, 8, 8), 16), 1e-12);
  EXPECT_LT(sphere, 4.0 / 3 * M_PI * std::pow(sphereR, 3));
  EXPECT_LT(worstOver(parts[1], pose, [&](const Eigen::Vector3d& p) { return p.norm() - sphereR; }), kOnSurface);
  EXPECT_EQ(parts[1].points.size(), 2u + 7 * monolith::kSphereSegments);  // a point per pole
  // Cylinder: a regular 32-gon prism, (32 / 2 pi) sin(2 pi / 32) of the cylinder's volume.
  const int n = monolith::kRoundSegments;
  const double cylinder = M_PI * cylR * cylR * 2 * cylH;
  EXPECT_NEAR(enclosedVolume(parts[2]), cylinder * n / (2 * M_PI) * std::sin(2 * M_PI / n), 1e-12);
  EXPECT_LT(worstOver(parts[2], pose, [&](const Eigen::Vector3d& p) { return cylinderDistance(p, cylR, cylH); }),
            kOnSurface);
  EXPECT_EQ(parts[2].polys, n + 2);  // side quads and two caps
  // Capsule: two hemispheres of kCapsuleRings bands and the cylinder side between their equators.
  std::vector<Eigen::Vector2d> capsule = latitudeRings(capR, capH, 0, 8, 16);
  const auto lower = latitudeRings(capR, -capH, 8, 16, 16);
  capsule.insert(capsule.end(), lower.begin(), lower.end());
  const double capsuleVolume = enclosedVolume(parts[3]);
  EXPECT_NEAR(capsuleVolume, stackedFrustums(capsule, n), 1e-12);
  const double capsuleExact = M_PI * capR * capR * (2 * capH + 4.0 / 3 * capR);
  EXPECT_LT(capsuleVolume, capsuleExact);
  EXPECT_GT(capsuleVolume, 0.98 * capsuleExact);
  EXPECT_LT(worstOver(parts[3], pose, [&](const Eigen::Vector3d& p) { return capsuleDistance(p, capR, capH); }),
            kOnSurface);
  // Convex: the hull of the house, without its inside point.
  EXPECT_NEAR(enclosedVolume(parts[4]), 3.5, 1e-12);
  EXPECT_EQ(parts[4].points.size(), kHouse.size());
  for (const auto& p : parts[4].points) {
    double nearest = 1e9;
    for (const auto& v : kHouse) nearest = std::min(nearest, (pose.toBody(p) - v).norm());
    EXPECT_LT(nearest, 1e-12);
  }
  // Mesh: its own vertices and triangles.
  EXPECT_NEAR(enclosedVolume(parts[5]), 4.0 / 3 * 0.5 * 1.0 * 1.5, 1e-12);
  EXPECT_EQ(parts[5].points.size(), 6u);
  EXPECT_EQ(parts[5].polys, 8);
  std::printf("[ measured ] drawn/exact volume: sphere %.6f, cylinder %.6f, capsule %.6f; box %.3e, hull %.3e, mesh %.3e off\n",
              sphere / (4.0 / 3 * M_PI * std::pow(sphereR, 3)), enclosedVolume(parts[2]) / cylinder,
              capsuleVolume / capsuleExact, enclosedVolume(parts[0]) - 6, enclosedVolume(parts[4]) - 3.5,
              enclosedVolume(parts[5]) - 1.0);
  // Plane: a kPlanePatchSize square through the body position, facing the (unit) normal.
  const BodyGeometry& patch = parts[6];
  ASSERT_EQ(patch.points.size(), 4u);
  ASSERT_EQ(patch.polys, 1);
  const Eigen::Vector3d worldNormal = pose.R * Eigen::Vector3d::UnitZ();
  const double side = monolith::kPlanePatchSize;
  expectNear3(vectorArea(patch, patch.faces[0]), side * side * worldNormal, 1e-12, "plane patch area and facing");
  for (const auto& p : patch.points) {
    EXPECT_NEAR(pose.toBody(p).z(), 0, 1e-12);
    EXPECT_NEAR(pose.toBody(p).norm(), side / std::sqrt(2.0), 1e-12);
  }
}

TEST(VtkOutput, PolygonDiskAndHalfPlaneOutlines2D) {
  World<2> world;
  const double angle = 0.6;
  const Eigen::Vector2d x(0.5, -1);
  const Eigen::Matrix2d R2 = Eigen::Rotation2Dd(angle).toRotationMatrix();
  Pose pose{{x.x(), x.y(), 0}, Eigen::Matrix3d::Identity()};
  pose.R.topLeftCorner<2, 2>() = R2;
  Shape<2> polygon, disk, plane;
  polygon.type = ShapeType::Convex;
  polygon.vertices = {0, 0, 2, 0, 2.5, 1, 1, 2, -0.5, 1};  // counter-clockwise
  disk.type = ShapeType::Sphere;
  disk.radius = 0.75;
  plane.type = ShapeType::Plane;
  plane.normal = Eigen::Vector2d(0, 1);
  for (const Shape<2>& shape : {polygon, disk, plane}) {
    addPosed<2>(world, x, angle, shape);
  }
  TempDir tmp;
  std::map<long, BodyGeometry> parts;
  std::string skip;
  if (!writeAndRead(world, tmp, parts, skip)) GTEST_SKIP() << skip;
  ASSERT_EQ(parts.size(), 3u);
  for (auto& [body, g] : parts) {
    ASSERT_EQ(g.polys, 1) << body;
    for (const auto& p : g.points) EXPECT_EQ(p.z(), 0.0);
  }
  // The polygon: its own vertices, in order, enclosing its shoelace area (5.0).
  double shoelace = 0;
  for (int i = 0; i < polygon.vertexCount(); ++i) {
    const Eigen::Vector2d a = polygon.vertex(i), b = polygon.vertex((i + 1) % polygon.vertexCount());
    shoelace += (a.x() * b.y() - a.y() * b.x()) / 2;
  }
  ASSERT_EQ(parts[0].points.size(), 5u);
  for (int i = 0; i < 5; ++i)
    expectNear3(pose.toBody(parts[0].points[parts[0].faces[0][i]]), Eigen::Vector3d(polygon.vertex(i).x(), polygon.vertex(i).y(), 0),
                1e-12, "polygon vertex " + std::to_string(i));
  EXPECT_NEAR(vectorArea(parts[0], parts[0].faces[0]).z(), shoelace, 1e-12);
  // The disk: a regular kRoundSegments-gon inscribed in the circle.
  const int n = monolith::kRoundSegments;
  EXPECT_NEAR(vectorArea(parts[1], parts[1].faces[0]).z(), n / 2.0 * 0.75 * 0.75 * std::sin(2 * M_PI / n), 1e-12);
  EXPECT_LT(worstOver(parts[1], pose, [](const Eigen::Vector3d& p) { return p.norm() - 0.75; }), kOnSurface);
  // The half-plane: a kPlanePatchSize x kPlaneStripDepth strip below its boundary line y = 0.
  EXPECT_NEAR(vectorArea(parts[2], parts[2].faces[0]).z(), monolith::kPlanePatchSize * monolith::kPlaneStripDepth, 1e-12);
  int onLine = 0;
  for (const auto& p : parts[2].points) {
    const Eigen::Vector3d local = pose.toBody(p);
    EXPECT_LE(local.y(), 1e-12);  // on the solid side
    EXPECT_NEAR(std::abs(local.x()), monolith::kPlanePatchSize / 2, 1e-12);
    onLine += std::abs(local.y()) < 1e-12;
  }
  EXPECT_EQ(onLine, 2);
}

// A level set sampled from phi on the nodes lo + i * spacing, i = 0 .. samples - 1.
template <int d>
LevelSet<d> sampled(const Eigen::Matrix<double, d, 1>& lo, double spacing, int samples,
                    const std::function<double(const Eigen::Matrix<double, d, 1>&)>& phi) {
  LevelSet<d> ls;
  ls.origin = lo;
  ls.spacing = spacing;
  ls.samples.setConstant(samples);
  ls.values.resize(static_cast<std::size_t>(ls.samples.prod()));
  for (std::size_t k = 0; k < ls.values.size(); ++k) ls.values[k] = phi(ls.node(ls.sampleCoord(static_cast<int>(k))));
  ls.refresh();
  return ls;
}

TEST(VtkOutput, LevelSetContoursFollowTheZeroOfPhi2D) {
  World<2> world;
  const double angle = -0.4;
  const Eigen::Vector2d x(2, 1), centre(0.013, -0.021);
  Pose pose{{x.x(), x.y(), 0}, Eigen::Matrix3d::Identity()};
  pose.R.topLeftCorner<2, 2>() = Eigen::Rotation2Dd(angle).toRotationMatrix();
  const double r = 1, h = 0.1, outer = 1, inner = 0.5;
  const LevelSet<2> disk = sampled<2>(Eigen::Vector2d(-1.5, -1.5), h, 31, [&](const Eigen::Vector2d& p) {
    return (p - centre).norm() - r;
  });
  const LevelSet<2> ring = sampled<2>(Eigen::Vector2d(-1.5, -1.5), h / 2, 61, [&](const Eigen::Vector2d& p) {
    return std::max((p - centre).norm() - outer, inner - (p - centre).norm());
  });
  for (const LevelSet<2>* ls : {&disk, &ring}) {
    addPosed<2>(world, x, angle, *ls);
  }
  TempDir tmp;
  std::map<long, BodyGeometry> parts;
  std::string skip;
  if (!writeAndRead(world, tmp, parts, skip)) GTEST_SKIP() << skip;
  ASSERT_EQ(parts.size(), 2u);
  auto phiOf = [](const LevelSet<2>& ls) {
    return [&ls](const Eigen::Vector3d& p) { return ls.value(Eigen::Vector2d(p.x(), p.y())); };
  };
  // The disk: one counter-clockwise loop on phi = 0, a polygon inscribed in the circle up to the
  // O(h^2) error of interpolating |p| - r linearly along cell edges: length and area within
  // h^2 / r^2 = 1% (a chord of length h falls short of its arc by ~h^2 / 24 r^2).
  ASSERT_EQ(parts[0].polys, 1);
  EXPECT_LT(worstOver(parts[0], pose, phiOf(disk)), kOnSurface);
  const double length = perimeter(parts[0], parts[0].faces[0]), area = vectorArea(parts[0], parts[0].faces[0]).z();
  EXPECT_NEAR(length / (2 * M_PI * r), 1, h * h / (r * r));
  EXPECT_NEAR(area / (M_PI * r * r), 1, h * h / (r * r));
  EXPECT_EQ(parts[0].points.size(), parts[0].faces[0].size());  // every crossing on the loop, once
  // The ring: an outer counter-clockwise loop and an inner clockwise one (the hole).
  ASSERT_EQ(parts[1].polys, 2);
  EXPECT_LT(worstOver(parts[1], pose, phiOf(ring)), kOnSurface);
  std::vector<double> areas = {vectorArea(parts[1], parts[1].faces[0]).z(), vectorArea(parts[1], parts[1].faces[1]).z()};
  std::sort(areas.begin(), areas.end());
  EXPECT_NEAR(areas[0] / (-M_PI * inner * inner), 1, h * h / 4 / (inner * inner));
  EXPECT_NEAR(areas[1] / (M_PI * outer * outer), 1, h * h / 4 / (outer * outer));
  std::printf("[ measured ] disk length/2pi r - 1 = %.3e, area/pi r^2 - 1 = %.3e; ring areas %.6f %.6f\n",
              length / (2 * M_PI * r) - 1, area / (M_PI * r * r) - 1, areas[0], areas[1]);
}

// A cell with its two inside corners on a diagonal: the bilinear phi at the cell centre decides
// whether the inside joins through the cell (one loop) or not (two loops).
TEST(VtkOutput, LevelSetSaddleCellsFollowTheCellCentre2D) {
  World<2> world;
  std::vector<LevelSet<2>> levelSets;
  for (const double across : {0.5, 1.5}) {  // the other diagonal: centre phi -0.25, then +0.25
    LevelSet<2> ls;
    ls.samples.setConstant(4);
    ls.values.assign(16, 1.0);
    ls.values[1 + 4 * 1] = ls.values[2 + 4 * 2] = -1;
    ls.values[2 + 4 * 1] = ls.values[1 + 4 * 2] = across;
    ls.refresh();
    levelSets.push_back(ls);
    addPosed<2>(world, Eigen::Vector2d::Zero(), 0.0, ls);
  }
  TempDir tmp;
  std::map<long, BodyGeometry> parts;
  std::string skip;
  if (!writeAndRead(world, tmp, parts, skip)) GTEST_SKIP() << skip;
  ASSERT_EQ(parts.size(), 2u);
  EXPECT_EQ(parts[0].polys, 1);  // joined
  EXPECT_EQ(parts[1].polys, 2);  // separate
  const Pose identity{Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity()};
  for (long b = 0; b < 2; ++b) {
    for (const auto& f : parts[b].faces) EXPECT_GT(vectorArea(parts[b], f).z(), 0) << "body " << b;
    const LevelSet<2>& ls = levelSets[b];
    EXPECT_LT(worstOver(parts[b], identity, [&](const Eigen::Vector3d& p) { return ls.value(Eigen::Vector2d(p.x(), p.y())); }),
              kOnSurface);
  }
}

TEST(VtkOutput, LevelSetSurfacesAreClosedAndFollowTheZeroOfPhi3D) {
  World<3> world;
  const Eigen::Quaterniond q(Eigen::AngleAxisd(-1.1, Eigen::Vector3d(0.3, -1, 0.5).normalized()));
  const Pose pose{{-0.5, 0.25, 3}, q.toRotationMatrix()};
  const Eigen::Vector3d centre(0.03, -0.02, 0.05);
  const double r = 1, h = 0.2, major = 1, minor = 0.4;
  const LevelSet<3> ball = sampled<3>(Eigen::Vector3d::Constant(-1.6), h, 17, [&](const Eigen::Vector3d& p) {
    return (p - centre).norm() - r;
  });
  const LevelSet<3> torus = sampled<3>(Eigen::Vector3d::Constant(-1.6), h / 2, 33, [&](const Eigen::Vector3d& p) {
    const Eigen::Vector3d c = p - centre;
    return Eigen::Vector2d(std::hypot(c.x(), c.y()) - major, c.z()).norm() - minor;
  });
  for (const LevelSet<3>* ls : {&ball, &torus}) {
    addPosed<3>(world, pose.x, q, *ls);
  }
  TempDir tmp;
  std::map<long, BodyGeometry> parts;
  std::string skip;
  if (!writeAndRead(world, tmp, parts, skip)) GTEST_SKIP() << skip;
  ASSERT_EQ(parts.size(), 2u);
  auto phiOf = [](const LevelSet<3>& ls) { return [&ls](const Eigen::Vector3d& p) { return ls.value(p); }; };
  // Ball: a closed, outward sphere-like surface whose points are zeros of the multilinear phi
  // (on cell diagonals too); its volume within h^2 / r^2 = 4% of the ball's (linear
  // interpolation of the distance cuts corners by O(h^2 / r)).
  const double ballVolume = enclosedVolume(parts[0]), ballExact = 4.0 / 3 * M_PI * r * r * r;
  EXPECT_EQ(unmatchedEdges(parts[0]), 0);
  EXPECT_EQ(eulerCharacteristic(parts[0]), 2);
  EXPECT_LT(worstOver(parts[0], pose, phiOf(ball)), kOnSurface);
  EXPECT_NEAR(ballVolume / ballExact, 1, h * h / (r * r));
  // Torus: closed, genus 1, volume 2 pi^2 R r^2 within (h/2)^2 / r^2.
  const double torusVolume = enclosedVolume(parts[1]), torusExact = 2 * M_PI * M_PI * major * minor * minor;
  EXPECT_EQ(unmatchedEdges(parts[1]), 0);
  EXPECT_EQ(eulerCharacteristic(parts[1]), 0);
  EXPECT_LT(worstOver(parts[1], pose, phiOf(torus)), kOnSurface);
  EXPECT_NEAR(torusVolume / torusExact, 1, h * h / 4 / (minor * minor));
  std::printf("[ measured ] ball volume/exact - 1 = %.3e (%zu triangles), torus %.3e (%zu triangles), worst |phi| %.1e %.1e\n",
              ballVolume / ballExact - 1, parts[0].faces.size(), torusVolume / torusExact - 1, parts[1].faces.size(),
              worstOver(parts[0], pose, phiOf(ball)), worstOver(parts[1], pose, phiOf(torus)));
}

// The same shapes and a level set read from a scene and drawn by the CLI run: the scene's
// parsers and the frame series hand the writer what it draws.
TEST(VtkOutput, SceneShapesAndLevelSetsAreDrawnAsThemselves) {
  const Eigen::Quaterniond q = Eigen::Quaterniond(0.9, 0.1, -0.3, 0.2).normalized();
  const Eigen::Matrix3d R = q.toRotationMatrix();
  const LevelSet<3> ball = sampled<3>(Eigen::Vector3d::Constant(-2), 0.25, 17, [](const Eigen::Vector3d& p) {
    return p.norm() - 1.2;
  });
  Json house = Json::array(), octaVertices = Json::array(), octaTriangles = Json::array();
  for (const auto& v : kHouse) house.push_back({v.x(), v.y(), v.z()});
  house.push_back({kHouseInside.x(), kHouseInside.y(), kHouseInside.z()});
  const Shape<3> octa = octahedron(0.5, 1.0, 1.5);
  for (int i = 0; i < octa.vertexCount(); ++i) octaVertices.push_back({octa.vertex(i).x(), octa.vertex(i).y(), octa.vertex(i).z()});
  for (std::size_t k = 0; k < octa.triangles.size(); k += 3)
    octaTriangles.push_back({octa.triangles[k], octa.triangles[k + 1], octa.triangles[k + 2]});
  const std::vector<Json> geometry = {
      {{"shape", {{"type", "cylinder"}, {"radius", 0.6}, {"half_height", 0.9}}}},
      {{"shape", {{"type", "capsule"}, {"radius", 0.4}, {"half_height", 0.8}}}},
      {{"shape", {{"type", "convex"}, {"vertices", house}}}},
      {{"shape", {{"type", "mesh"}, {"vertices", octaVertices}, {"triangles", octaTriangles}}}},
      {{"shape", {{"type", "plane"}, {"normal", {0, 0, 1}}}}},
      {{"level_set", {{"origin", {-2, -2, -2}}, {"spacing", 0.25}, {"samples", {17, 17, 17}}, {"values", ball.values}}}}};
  Json scene = {{"dimension", 3}, {"time", {{"dt", 0.1}, {"steps", 1}, {"frame_rate", 10}}}, {"entities", Json::array()}};
  std::vector<Pose> poses;
  for (std::size_t b = 0; b < geometry.size(); ++b) {
    poses.push_back({Eigen::Vector3d(3.0 * b, -1, 0.5), R});
    Json entity = geometry[b];
    entity["rigid_body"] = {{"static", true}, {"position", {3.0 * b, -1, 0.5}}, {"orientation", {q.w(), q.x(), q.y(), q.z()}}};
    scene["entities"].push_back(entity);
  }
  TempDir tmp;
  const fs::path file = tmp.path() / "shapes.json", out = tmp.path() / "run", frame = out / "frames/geometry_000000.vtp";
  writeFile(file, scene.dump(2));
  const CommandResult r = run({MONOLITH_CLI, "run", file.string(), "--out", out.string(), "--quiet"}, tmp.logs());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  Json j;
  std::string skip;
  if (!readWithVtk({frame}, tmp.logs(), j, skip)) GTEST_SKIP() << skip;
  auto parts = splitGeometry(j["files"][frame.string()]);
  ASSERT_EQ(parts.size(), geometry.size());
  for (long b : {0, 1, 2, 3, 5}) EXPECT_EQ(unmatchedEdges(parts[b]), 0) << "body " << b;
  const int n = monolith::kRoundSegments;
  EXPECT_NEAR(enclosedVolume(parts[0]), M_PI * 0.36 * 1.8 * n / (2 * M_PI) * std::sin(2 * M_PI / n), 1e-12);
  EXPECT_LT(worstOver(parts[0], poses[0], [](const Eigen::Vector3d& p) { return cylinderDistance(p, 0.6, 0.9); }),
            kOnSurface);
  std::vector<Eigen::Vector2d> capsule = latitudeRings(0.4, 0.8, 0, 8, 16);
  const auto lower = latitudeRings(0.4, -0.8, 8, 16, 16);
  capsule.insert(capsule.end(), lower.begin(), lower.end());
  EXPECT_NEAR(enclosedVolume(parts[1]), stackedFrustums(capsule, n), 1e-12);
  EXPECT_LT(worstOver(parts[1], poses[1], [](const Eigen::Vector3d& p) { return capsuleDistance(p, 0.4, 0.8); }),
            kOnSurface);
  EXPECT_NEAR(enclosedVolume(parts[2]), 3.5, 1e-12);
  EXPECT_EQ(parts[2].points.size(), kHouse.size());
  EXPECT_NEAR(enclosedVolume(parts[3]), 1.0, 1e-12);
  const double side = monolith::kPlanePatchSize;
  ASSERT_EQ(parts[4].polys, 1);
  expectNear3(vectorArea(parts[4], parts[4].faces[0]), side * side * (R * Eigen::Vector3d::UnitZ()), 1e-12, "plane");
  // The level set: closed, on phi = 0, within (h / r)^2 of the ball's volume.
  EXPECT_EQ(eulerCharacteristic(parts[5]), 2);
  EXPECT_LT(worstOver(parts[5], poses[5], [&](const Eigen::Vector3d& p) { return ball.value(p); }), kOnSurface);
  EXPECT_NEAR(enclosedVolume(parts[5]) / (4.0 / 3 * M_PI * std::pow(1.2, 3)), 1, std::pow(0.25 / 1.2, 2));
}

}  // namespace
