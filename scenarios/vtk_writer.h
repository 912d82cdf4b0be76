#pragma once
// VTK XML PolyData (.vtp) frames and the .pvd collection ParaView opens as a time series.
// Rigid bodies give two files per frame: bodies_N.vtp, one point per body at its centre of
// mass carrying id, name, velocity, angular velocity, orientation (quaternion w,x,y,z) and
// mass; geometry_N.vtp, the surfaces of the bodies' shapes and the zero contours of their level
// sets (scenarios/body_surfaces.h), with the body id per point.
#include <string>
#include <utility>
#include <vector>

#include "ecs/world.h"

namespace monolith {

template <int d>
void writeRigidBodyFrame(const World<d>& world, const std::string& path);
template <int d>
void writeRigidGeometryFrame(const World<d>& world, const std::string& path);

// A .pvd file listing (time, file) datasets; rewritten whole after each frame so it is valid
// whenever the run stops.
class PvdCollection {
 public:
  explicit PvdCollection(std::string path) : path_(std::move(path)) {}
  void add(double time, const std::string& relativeFile);
  // Drops entries after `time` (a resumed run rewrites them).
  void truncateAfter(double time);
  void write() const;
  const std::vector<std::pair<double, std::string>>& entries() const { return entries_; }
  // Reads an existing collection (for resume); missing file = empty.
  void load();

 private:
  std::string path_;
  std::vector<std::pair<double, std::string>> entries_;
};

// One Float64 data array of a VTK file: `components` values per point (or per cell).
struct VtkArray {
  std::string name;
  int components = 1;
  std::vector<double> values;
};
// The text of a PolyData (.vtp) file of polylines: coords holds x, y, z per point, each line lists
// its point ids in order (a closed loop repeats its first id at the end).
std::string polyLineFile(const std::vector<double>& coords, const std::vector<std::vector<int>>& lines,
                         const std::vector<VtkArray>& pointData, const std::vector<VtkArray>& cellData);

// Writes a file atomically: to path + ".tmp", then rename.
void writeFileAtomically(const std::string& path, const std::string& content);

}  // namespace monolith
