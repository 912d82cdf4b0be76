#include "scenarios/vtk_grid_writer.h"

#include <cstdio>
#include <sstream>

#include "components/mac_grid.h"
#include "scenarios/fluid_fields.h"
#include "scenarios/vtk_writer.h"

namespace monolith {

namespace {
void appendCellArray(std::ostringstream& x, const char* name, int components, const std::vector<double>& values) {
  x << "        <DataArray type=\"Float64\" Name=\"" << name << "\" NumberOfComponents=\"" << components
    << "\" format=\"ascii\">\n          ";
  char buf[32];
  for (std::size_t i = 0; i < values.size(); ++i) {
    std::snprintf(buf, sizeof buf, "%.9g", values[i]);  // frames are for viewing: 9 digits
    x << (i ? " " : "") << buf;
  }
  x << "\n        </DataArray>\n";
}
}  // namespace

template <int d>
bool writeMacGridFrame(const World<d>& world, const std::string& path) {
  const auto* pool = world.template findPool<MacGrid<d>>();
  if (!pool || pool->size() == 0) return false;
  const MacGrid<d>& grid = pool->components()[0];
  const CellFields fields = cellFields(grid);
  const int n = grid.cells.prod();
  std::vector<double> velocity(3 * n, 0.0), vorticity, solid(n);
  for (int c = 0; c < n; ++c) {
    for (int a = 0; a < d; ++a) velocity[3 * c + a] = fields.velocity[d * c + a];
    solid[c] = grid.solid[c];
  }
  std::ostringstream x;
  const int nz = d == 3 ? grid.cells[2] : 1;
  x << "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"1.0\" byte_order=\"LittleEndian\" "
       "header_type=\"UInt64\">\n  <ImageData WholeExtent=\"0 "
    << grid.cells[0] << " 0 " << grid.cells[1] << " 0 " << (d == 3 ? nz : 0) << "\" Origin=\"" << grid.origin[0]
    << " " << grid.origin[1] << " " << (d == 3 ? grid.origin[d - 1] : 0.0) << "\" Spacing=\"" << grid.dx << " "
    << grid.dx << " " << grid.dx << "\">\n    <Piece Extent=\"0 " << grid.cells[0] << " 0 " << grid.cells[1] << " 0 "
    << (d == 3 ? nz : 0) << "\">\n      <CellData Scalars=\"pressure\" Vectors=\"velocity\">\n";
  appendCellArray(x, "velocity", 3, velocity);
  appendCellArray(x, "pressure", 1, grid.p);
  appendCellArray(x, "divergence", 1, fields.divergence);
  appendCellArray(x, "vorticity", d == 3 ? 3 : 1, fields.vorticity);
  appendCellArray(x, "solid", 1, solid);
  x << "      </CellData>\n    </Piece>\n  </ImageData>\n</VTKFile>\n";
  writeFileAtomically(path, x.str());
  return true;
}

template bool writeMacGridFrame<2>(const World<2>&, const std::string&);
template bool writeMacGridFrame<3>(const World<3>&, const std::string&);

}  // namespace monolith
