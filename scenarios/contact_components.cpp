#include "scenarios/contact_components.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <fstream>
#include <sstream>

#include "components/collider.h"
#include "components/forces.h"
#include "components/kinematic.h"
#include "components/rigid_body.h"
#include "components/shape.h"
#include "components/sleep.h"
#include "systems/contact_workspace.h"

namespace monolith {

// A list of d-vectors, e.g. "vertices": [[0,0,0], [1,0,0], ...], flattened.
template <int d>
std::vector<double> pointList(const Config& c, const std::string& key, int minimum) {
  const Json& raw = c.raw().contains(key) ? c.raw()[key] : Json();
  if (!raw.is_array() || static_cast<int>(raw.size()) < minimum)
    c.failAt(key, "an array of at least " + std::to_string(minimum) + " points [" + (d == 3 ? "x, y, z" : "x, y") + "]",
             c.raw().contains(key) ? describeJson(raw) : "nothing");
  const Config list(raw, c.file(), c.pathOf(key));
  std::vector<double> out;
  for (std::size_t i = 0; i < raw.size(); ++i) {
    const Config p = list.element(i);
    if (!p.raw().is_array() || p.raw().size() != static_cast<std::size_t>(d))
      p.fail("a point of " + std::to_string(d) + " numbers", describeJson(p.raw()));
    for (int k = 0; k < d; ++k) {
      const Json& v = p.raw()[k];
      if (!v.is_number() || !std::isfinite(v.get<double>())) p.fail("finite numbers", describeJson(p.raw()));
      out.push_back(v.get<double>());
    }
  }
  c.markUsed(key);
  return out;
}

// Wavefront OBJ: "v x y z" and "f i j k ..." (1-based or negative indices, "i/t/n" forms;
// polygons are fanned into triangles).
void readObj(const Config& c, const std::string& key, Shape<3>& shape) {
  const std::string name = c.string(key);
  std::filesystem::path path(name);
  if (path.is_relative()) path = std::filesystem::path(c.file()).parent_path() / path;
  std::ifstream in(path);
  if (!in) c.failAt(key, "a readable Wavefront OBJ mesh file", "\"" + path.string() + "\" (cannot be opened)");
  std::string line;
  int lineNo = 0;
  while (std::getline(in, line)) {
    ++lineNo;
    std::istringstream ls(line);
    std::string tag;
    ls >> tag;
    if (tag == "v") {
      double x, y, z;
      if (!(ls >> x >> y >> z))
        c.failAt(key, "an OBJ file with \"v x y z\" vertex lines", path.string() + " line " + std::to_string(lineNo));
      shape.vertices.insert(shape.vertices.end(), {x, y, z});
    } else if (tag == "f") {
      std::vector<int> face;
      std::string item;
      while (ls >> item) {
        const int index = std::atoi(item.c_str());
        const int n = shape.vertexCount();
        const int resolved = index > 0 ? index - 1 : n + index;
        if (index == 0 || resolved < 0 || resolved >= n)
          c.failAt(key, "face indices of existing vertices",
                   path.string() + " line " + std::to_string(lineNo) + ": \"" + item + "\"");
        face.push_back(resolved);
      }
      for (std::size_t k = 1; k + 1 < face.size(); ++k)
        shape.triangles.insert(shape.triangles.end(), {face[0], face[k], face[k + 1]});
    }
  }
  if (shape.triangles.empty()) c.failAt(key, "an OBJ mesh with at least one face", path.string() + " has none");
}

namespace {

// A 2-D polygon is stored counter-clockwise with its area centroid at the body origin: the
// body's position is its centre of mass.
void centrePolygon(const Config& c, Shape<2>& shape) {
  const int n = shape.vertexCount();
  double area = 0;
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d a = shape.vertex(i), b = shape.vertex((i + 1) % n);
    const double cross = a.x() * b.y() - a.y() * b.x();
    area += 0.5 * cross;
    centroid += cross * (a + b) / 6;
  }
  if (std::abs(area) < 1e-14) c.failAt("vertices", "a polygon of non-zero area", "collinear or repeated points");
  centroid /= area;
  for (int i = 0; i < n; ++i) {
    shape.vertices[2 * i] -= centroid.x();
    shape.vertices[2 * i + 1] -= centroid.y();
  }
  if (area < 0) {  // clockwise: reverse
    std::vector<double> v;
    for (int i = n - 1; i >= 0; --i) v.insert(v.end(), {shape.vertices[2 * i], shape.vertices[2 * i + 1]});
    shape.vertices = v;
  }
  // Convex, in order around it: every turn to the left (collinear points allowed) and one turn
  // around in all. The narrow phase works on the points' convex hull and the inertia on the
  // polygon as listed, so a concave or crossed list would give a body whose inertia is not its
  // shape's (a crossed one even a negative inertia, which made collisions add energy).
  double turning = 0, size = 0;
  for (int i = 0; i < n; ++i) size = std::max(size, shape.vertex(i).norm());
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d e0 = shape.vertex(i) - shape.vertex((i + n - 1) % n);
    const Eigen::Vector2d e1 = shape.vertex((i + 1) % n) - shape.vertex(i);
    const double cross = e0.x() * e1.y() - e0.y() * e1.x();
    // The input's index of this vertex (the list was reversed if clockwise).
    const int given = area < 0 ? n - 1 - i : i;
    if (cross < -1e-12 * size * size)
      c.failAt("vertices", "a convex polygon's vertices in order around it",
               "an inward turn at vertices[" + std::to_string(given) + "]");
    turning += std::atan2(cross, e0.dot(e1));
  }
  if (turning > 2 * M_PI + 1e-6)
    c.failAt("vertices", "a convex polygon's vertices in order around it", "a list that winds around more than once");
}

}  // namespace

template <int d>
void parseShapeComponent(World<d>& world, Entity e, const Config& c) {
  Shape<d> shape;
  const std::string sphereName = d == 3 ? "sphere" : "disk";
  const std::string otherName = d == 3 ? "disk" : "sphere";
  const std::vector<std::string> types = d == 3 ? std::vector<std::string>{"box", "sphere", "capsule", "cylinder",
                                                                          "plane", "convex", "mesh"}
                                                : std::vector<std::string>{"box", "disk", "polygon", "plane"};
  std::string allowed;
  for (const auto& t : types) allowed += (allowed.empty() ? "one of \"" : ", \"") + t + "\"";
  // The round shape of the other dimension is too far from this one's name for "did you
  // mean": point at it explicitly.
  if (c.has("type") && c.raw()["type"] == otherName)
    c.failAt("type", allowed, describeJson(c.raw()["type"]) + " (a " + std::to_string(5 - d) +
                                  "-D shape; did you mean \"" + sphereName + "\"?)");
  const std::string type = c.oneOf("type", types, "");
  if (type == "box") {
    shape.type = ShapeType::Box;
    shape.halfExtents = c.vector("half_extents", d, Bound::Positive);
  } else if (type == sphereName) {
    shape.type = ShapeType::Sphere;
    shape.radius = c.number("radius", Bound::Positive);
  } else if (type == "capsule" || type == "cylinder") {
    shape.type = type == "capsule" ? ShapeType::Capsule : ShapeType::Cylinder;
    shape.radius = c.number("radius", Bound::Positive);
    shape.halfHeight = c.number("half_height", Bound::Positive);
  } else if (type == "plane") {
    shape.type = ShapeType::Plane;
    const Eigen::VectorXd n = c.vector("normal", Eigen::VectorXd(Eigen::Matrix<double, d, 1>::UnitY()));
    if (n.norm() < 1e-12) c.failAt("normal", "a non-zero normal", "a zero vector");
    shape.normal = n.normalized();
  } else if (type == "convex" || type == "polygon") {
    shape.type = ShapeType::Convex;
    shape.vertices = pointList<d>(c, "vertices", d + 1);
    if constexpr (d == 2) centrePolygon(c, shape);
  } else {  // mesh (3-D)
    shape.type = ShapeType::Mesh;
    if constexpr (d == 3) {
      if (c.has("file")) {
        readObj(c, "file", shape);
        const double scale = c.number("scale", 1.0, Bound::Positive);
        for (double& v : shape.vertices) v *= scale;
      } else {
        shape.vertices = pointList<d>(c, "vertices", 3);
        const Json& t = c.raw().contains("triangles") ? c.raw()["triangles"] : Json();
        if (!t.is_array() || t.empty())
          c.failAt("triangles", "an array of [i, j, k] vertex index triples", describeJson(t));
        const Config triangles(t, c.file(), c.pathOf("triangles"));
        for (std::size_t i = 0; i < t.size(); ++i) {
          if (!t[i].is_array() || t[i].size() != 3)
            triangles.element(i).fail("three vertex indices", describeJson(t[i]));
          for (int k = 0; k < 3; ++k) {
            if (!t[i][k].is_number_integer())
              triangles.element(i).fail("integer vertex indices (0-based)", describeJson(t[i][k]));
            if (t[i][k].get<long>() < 0 || t[i][k].get<long>() >= shape.vertexCount())
              triangles.element(i).fail("indices of existing vertices (0-based)",
                                        "index " + std::to_string(t[i][k].get<long>()) + " (the mesh has " +
                                            std::to_string(shape.vertexCount()) + " vertices)");
            shape.triangles.push_back(t[i][k].get<int>());
          }
        }
        c.markUsed("triangles");
      }
    }
  }
  try {
    solvers::collision::PreparedGeometry<d> check(collisionGeometryOf(shape));
  } catch (const std::invalid_argument& err) {
    c.fail("a valid " + type + " geometry", err.what());
  }
  world.add(e, shape);
}

namespace {

template <int d>
void parseCollider(World<d>& world, Entity e, const Config& c) {
  if (!world.template has<Shape<d>>(e))
    c.fail("a \"shape\" component on the same entity (the collider's geometry)", "no shape");
  if (!world.template has<RigidBody<d>>(e))
    c.fail("a \"rigid_body\" component on the same entity", "no rigid_body");
  Collider<d> col;
  col.restitution = c.number("restitution", col.restitution, Bound::NonNegative);
  if (col.restitution > 1) c.failAt("restitution", "a restitution in [0, 1]", std::to_string(col.restitution));
  col.friction = c.number("friction", col.friction, Bound::NonNegative);
  world.add(e, col);
}

template <int d>
void parseKinematic(World<d>& world, Entity e, const Config& c) {
  RigidBody<d>* body = world.template get<RigidBody<d>>(e);
  if (!body) c.fail("a \"rigid_body\" component on the same entity", "no rigid_body");
  if (body->isStatic) c.fail("a non-static rigid_body (a kinematic body moves by its script)", "\"static\": true");
  KinematicMotion<d> k;
  auto segment = [&](const Config& s, double until) {
    const Eigen::VectorXd v = s.vector("velocity", Eigen::VectorXd::Zero(d));
    Eigen::VectorXd w = Eigen::VectorXd::Zero(KinematicMotion<d>::kAngular);
    if constexpr (d == 3) w = s.vector("angular_velocity", w);
    else w(0) = s.number("angular_velocity", 0.0);
    // The last segment lasts forever; its "until" is never read (stored as 0: checkpoints
    // reject non-finite numbers).
    k.segments.push_back(std::isfinite(until) ? until : 0.0);
    for (int i = 0; i < d; ++i) k.segments.push_back(v(i));
    for (int i = 0; i < KinematicMotion<d>::kAngular; ++i) k.segments.push_back(w(i));
  };
  if (c.has("schedule")) {
    const Config list(c.raw()["schedule"], c.file(), c.pathOf("schedule"));
    c.markUsed("schedule");
    double previous = -std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < list.arraySize(); ++i) {
      const Config s = list.element(i);
      const bool last = i + 1 == list.arraySize();
      if (!last && !s.has("until")) s.failAt("until", "the end time of this segment (all but the last need one)", "nothing");
      const double until = s.number("until", std::numeric_limits<double>::infinity());
      if (!(until > previous)) s.failAt("until", "times increasing along the schedule", std::to_string(until));
      previous = until;
      segment(s, until);
      s.finish();
    }
    if (k.segments.empty()) c.failAt("schedule", "at least one segment", "an empty list");
  } else {
    segment(c, std::numeric_limits<double>::infinity());
  }
  // The script replaces forces: no accumulator, infinite mass in contact.
  world.template remove<RigidForces<d>>(e);
  AngularVec<d> w;
  k.velocityAt(0.0, body->v, w);
  body->setOmega(w);
  world.add(e, k);
}

// "sleep": {"asleep": true} starts a body asleep (systems/sleep.h): a pile built at rest stays as
// built until something reaches it. Only a dynamic collider body sleeps; the scene must turn
// sleeping on (checked by the scene loader, which reads "solvers" after the entities).
template <int d>
void parseSleep(World<d>& world, Entity e, const Config& c) {
  const RigidBody<d>* body = world.template get<RigidBody<d>>(e);
  if (!body || body->isStatic || !world.template has<Collider<d>>(e))
    c.fail("a dynamic rigid_body with a collider on the same entity (only those sleep)",
           !body ? "no rigid_body" : body->isStatic ? "a static body" : "no collider");
  if (world.template has<KinematicMotion<d>>(e))
    c.fail("a body that is not kinematic (its script moves it)", "a kinematic body");
  Sleep<d> s;
  s.asleep = c.boolean("asleep", false);
  if (s.asleep && (body->v.squaredNorm() > 0 || body->L.squaredNorm() > 0))
    c.failAt("asleep", "false for a moving body (a sleeping body is at rest)", "true with a velocity");
  s.group = e.index;  // fall_asleep's groups are entity indices too
  world.add(e, s);
}

}  // namespace

template <int d>
void registerContactComponents(Registry& r) {
  r.addComponentOf<d, Collider<d>>(
      "takes part in collisions and contact: restitution (0..1), friction (Coulomb mu); pair values = min of the two",
      parseCollider<d>);
  r.addComponentOf<d, KinematicMotion<d>>(
      "scripted motion of a rigid body: velocity/angular_velocity, or schedule [{until, velocity, angular_velocity}]",
      parseKinematic<d>);
  r.addComponentOf<d, Sleep<d>>(
      "sleep state of a dynamic collider body (with \"solvers\": {\"contact\": {\"sleep\": true}}): asleep (start "
      "asleep, held still until something reaches it)",
      parseSleep<d>);
}

template std::vector<double> pointList<2>(const Config&, const std::string&, int);
template std::vector<double> pointList<3>(const Config&, const std::string&, int);
template void parseShapeComponent<2>(World<2>&, Entity, const Config&);
template void parseShapeComponent<3>(World<3>&, Entity, const Config&);
template void registerContactComponents<2>(Registry&);
template void registerContactComponents<3>(Registry&);

}  // namespace monolith
