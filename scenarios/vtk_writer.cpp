#include "scenarios/vtk_writer.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "components/level_set.h"
#include "components/rigid_body.h"
#include "components/shape.h"
#include "scenarios/body_surfaces.h"

namespace monolith {

namespace {

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

void appendArray(std::ostringstream& x, const char* type, const char* name, int components,
                 const std::vector<double>& values) {
  x << "        <DataArray type=\"" << type << "\" Name=\"" << name << "\" NumberOfComponents=\"" << components
    << "\" format=\"ascii\">\n          ";
  for (std::size_t i = 0; i < values.size(); ++i) x << (i ? " " : "") << num(values[i]);
  x << "\n        </DataArray>\n";
}

void appendIntArray(std::ostringstream& x, const char* name, const std::vector<long>& values) {
  x << "        <DataArray type=\"Int64\" Name=\"" << name << "\" format=\"ascii\">\n          ";
  for (std::size_t i = 0; i < values.size(); ++i) x << (i ? " " : "") << values[i];
  x << "\n        </DataArray>\n";
}

// VTK's ASCII encoding of a string array: each string as its character codes, then a 0.
void appendStringArray(std::ostringstream& x, const char* name, const std::vector<std::string>& values) {
  x << "        <DataArray type=\"String\" Name=\"" << name << "\" format=\"ascii\">\n          ";
  bool first = true;
  for (const auto& s : values) {
    for (unsigned char c : s) {
      x << (first ? "" : " ") << static_cast<int>(c);
      first = false;
    }
    x << (first ? "" : " ") << 0;
    first = false;
  }
  x << "\n        </DataArray>\n";
}

std::string polyDataFile(std::size_t nPoints, const std::vector<double>& coords, const std::string& pointData,
                         const std::string& cells, std::size_t nVerts, std::size_t nPolys, std::size_t nLines = 0,
                         const std::string& cellData = "") {
  std::ostringstream x;
  x << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" "
       "header_type=\"UInt64\">\n  <PolyData>\n    <Piece NumberOfPoints=\""
    << nPoints << "\" NumberOfVerts=\"" << nVerts << "\" NumberOfLines=\"" << nLines
    << "\" NumberOfStrips=\"0\" NumberOfPolys=\"" << nPolys << "\">\n      <PointData>\n"
    << pointData << "      </PointData>\n";
  if (!cellData.empty()) x << "      <CellData>\n" << cellData << "      </CellData>\n";
  x << "      <Points>\n";
  appendArray(x, "Float64", "Points", 3, coords);
  x << "      </Points>\n" << cells << "    </Piece>\n  </PolyData>\n</VTKFile>\n";
  return x.str();
}

std::string cellBlock(const char* tag, const std::vector<std::vector<int>>& cells) {
  std::ostringstream x;
  std::vector<long> connectivity, offsets;
  long offset = 0;
  for (const auto& c : cells) {
    for (int i : c) connectivity.push_back(i);
    offset += static_cast<long>(c.size());
    offsets.push_back(offset);
  }
  x << "      <" << tag << ">\n";
  appendIntArray(x, "connectivity", connectivity);
  appendIntArray(x, "offsets", offsets);
  x << "      </" << tag << ">\n";
  return x.str();
}

}  // namespace

std::string polyLineFile(const std::vector<double>& coords, const std::vector<std::vector<int>>& lines,
                         const std::vector<VtkArray>& pointData, const std::vector<VtkArray>& cellData) {
  auto arrays = [](const std::vector<VtkArray>& list) {
    std::ostringstream x;
    for (const VtkArray& a : list) appendArray(x, "Float64", a.name.c_str(), a.components, a.values);
    return x.str();
  };
  return polyDataFile(coords.size() / 3, coords, arrays(pointData), cellBlock("Lines", lines), 0, 0, lines.size(),
                      arrays(cellData));
}

void writeFileAtomically(const std::string& path, const std::string& content) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error("cannot write '" + tmp + "'");
    out << content;
    out.flush();
    if (!out) throw std::runtime_error("error while writing '" + tmp + "'");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) throw std::runtime_error("cannot rename '" + tmp + "' to '" + path + "'");
}

template <int d>
void writeRigidBodyFrame(const World<d>& world, const std::string& path) {
  std::vector<double> coords, velocity, omega, orientation, mass;
  std::vector<long> ids;
  std::vector<std::string> names;
  if (const auto* pool = world.template findPool<RigidBody<d>>()) {
    for (std::size_t i = 0; i < pool->size(); ++i) {
      const auto& b = pool->components()[i];
      const Entity e = pool->entities()[i];
      const Eigen::Vector3d x = lift(b.x);
      const Eigen::Vector3d v = lift(b.v);
      Eigen::Vector3d w = Eigen::Vector3d::Zero();
      Eigen::Vector4d q;
      if constexpr (d == 3) {
        w = b.omega();
        q << b.orientation.w(), b.orientation.x(), b.orientation.y(), b.orientation.z();
      } else {
        w.z() = b.omega()(0);
        q << std::cos(b.orientation / 2), 0, 0, std::sin(b.orientation / 2);  // rotation about z
      }
      coords.insert(coords.end(), x.data(), x.data() + 3);
      velocity.insert(velocity.end(), v.data(), v.data() + 3);
      omega.insert(omega.end(), w.data(), w.data() + 3);
      orientation.insert(orientation.end(), q.data(), q.data() + 4);
      mass.push_back(b.isStatic ? 0.0 : b.mass);
      ids.push_back(e.index);
      names.push_back(world.name(e));
    }
  }
  std::ostringstream pd;
  appendIntArray(pd, "id", ids);
  appendStringArray(pd, "name", names);
  appendArray(pd, "Float64", "velocity", 3, velocity);
  appendArray(pd, "Float64", "angular_velocity", 3, omega);
  appendArray(pd, "Float64", "orientation", 4, orientation);
  appendArray(pd, "Float64", "mass", 1, mass);
  std::vector<std::vector<int>> verts;
  for (std::size_t i = 0; i < ids.size(); ++i) verts.push_back({static_cast<int>(i)});
  writeFileAtomically(path, polyDataFile(ids.size(), coords, pd.str(), cellBlock("Verts", verts), verts.size(), 0));
}

namespace {

// draw(body, component, body id) for every component of type C whose entity has a rigid body,
// in pool order.
template <class C, int d, class Draw>
void forEachBodyWith(const World<d>& world, Draw&& draw) {
  const auto* pool = world.template findPool<C>();
  for (std::size_t i = 0; pool && i < pool->size(); ++i) {
    const Entity e = pool->entities()[i];
    if (const auto* body = world.template get<RigidBody<d>>(e)) draw(*body, pool->components()[i], static_cast<int>(e.index));
  }
}

}  // namespace

// Every shape, then every level set: an entity with both shows both (a fluid obstacle moves the
// fluid with its level set, a collider collides with its shape).
template <int d>
void writeRigidGeometryFrame(const World<d>& world, const std::string& path) {
  SurfacePolygons polys;
  forEachBodyWith<Shape<d>>(world, [&](const RigidBody<d>& body, const Shape<d>& shape, int id) {
    appendShapeSurface(body, shape, id, polys);
  });
  forEachBodyWith<LevelSet<d>>(world, [&](const RigidBody<d>& body, const LevelSet<d>& levelSet, int id) {
    appendLevelSetContour(body, levelSet, id, polys);
  });
  std::vector<double> coords;
  for (const auto& p : polys.points) coords.insert(coords.end(), p.data(), p.data() + 3);
  std::ostringstream pd;
  std::vector<long> bodyIds(polys.pointBody.begin(), polys.pointBody.end());
  appendIntArray(pd, "body_id", bodyIds);
  writeFileAtomically(path, polyDataFile(polys.points.size(), coords, pd.str(), cellBlock("Polys", polys.faces), 0,
                                         polys.faces.size()));
}

void PvdCollection::add(double time, const std::string& relativeFile) { entries_.emplace_back(time, relativeFile); }

void PvdCollection::truncateAfter(double time) {
  while (!entries_.empty() && entries_.back().first > time) entries_.pop_back();
}

void PvdCollection::write() const {
  std::ostringstream x;
  x << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"1.0\" byte_order=\"LittleEndian\">\n"
       "  <Collection>\n";
  for (const auto& [t, file] : entries_)
    x << "    <DataSet timestep=\"" << num(t) << "\" group=\"\" part=\"0\" file=\"" << file << "\"/>\n";
  x << "  </Collection>\n</VTKFile>\n";
  writeFileAtomically(path_, x.str());
}

void PvdCollection::load() {
  entries_.clear();
  std::ifstream in(path_);
  for (std::string line; std::getline(in, line);) {
    const auto t = line.find("timestep=\""), f = line.find("file=\"");
    if (t == std::string::npos || f == std::string::npos) continue;
    const double time = std::stod(line.substr(t + 10));
    const auto fEnd = line.find('"', f + 6);
    entries_.emplace_back(time, line.substr(f + 6, fEnd - f - 6));
  }
}

template void writeRigidBodyFrame<2>(const World<2>&, const std::string&);
template void writeRigidBodyFrame<3>(const World<3>&, const std::string&);
template void writeRigidGeometryFrame<2>(const World<2>&, const std::string&);
template void writeRigidGeometryFrame<3>(const World<3>&, const std::string&);

}  // namespace monolith
