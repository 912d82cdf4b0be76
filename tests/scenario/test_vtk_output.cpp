// VTK output read back by a real VTK reader: runs small 3-D and 2-D scenes through the CLI and
// reads the frames with vtkXMLPolyDataReader (tests/support/read_vtp.py, run with the python
// that has the vtk module), then compares with closed-form values.
//
// The scenes are chosen so that every quantity has an exact solution the integrator reproduces
// up to rounding: constant gravity (velocity Verlet is exact for constant acceleration:
// x^n = x0 + v0 t + g t^2/2), no contacts, and rotating bodies with isotropic inertia (sphere,
// cube, disk), whose angular velocity is constant and whose orientation is exp(w t).
#include <gtest/gtest.h>

#include "support/cli_harness.h"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
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
};
std::map<long, BodyGeometry> splitGeometry(const Json& g) {
  std::map<long, BodyGeometry> out;
  const Json& ids = g["point_data"]["body_id"]["values"];
  const Json& points = g["points"];
  EXPECT_EQ(ids.size(), points.size());
  for (std::size_t i = 0; i < points.size() && i < ids.size(); ++i)
    out[std::lround(ids[i].get<double>())].points.push_back(vec3(points[i]));
  for (const auto& poly : g["polys"]) {
    const long body = std::lround(ids.at(poly.at(0).get<std::size_t>()).get<double>());
    for (const auto& p : poly) EXPECT_EQ(std::lround(ids.at(p.get<std::size_t>()).get<double>()), body) << "polygon spans bodies";
    out[body].polys++;
    out[body].polySizes.push_back(poly.size());
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

}  // namespace
