#include "scenarios/vtk_deformable_writer.h"

#include <iomanip>
#include <sstream>

#include "components/deformable.h"
#include "scenarios/vtk_writer.h"
#include "systems/deformable_dynamics.h"

namespace monolith {

namespace dm = solvers::deformable;

namespace {

template <class T>
void appendArray(std::ostringstream& x, const char* type, const char* name, int components, const std::vector<T>& v) {
  x << "        <DataArray type=\"" << type << "\" Name=\"" << name << "\" NumberOfComponents=\"" << components
    << "\" format=\"ascii\">\n          ";
  for (const T& q : v) x << q << ' ';
  x << "\n        </DataArray>\n";
}

template <int d>
double vonMises(const Eigen::Matrix<double, d, d>& sigma) {
  const Eigen::Matrix<double, d, d> dev = sigma - (sigma.trace() / d) * Eigen::Matrix<double, d, d>::Identity();
  return std::sqrt(1.5 * dev.squaredNorm());
}

}  // namespace

template <int d>
void writeDeformableFrame(const World<d>& world, const std::string& path) {
  std::vector<double> points, velocity, mass, volumeRatio, strain, mises;
  std::vector<long> fixed, body, connectivity, offsets, types;
  long base = 0;
  const auto* pool = world.template findPool<Particles<d>>();
  for (std::size_t k = 0; pool && k < pool->size(); ++k) {
    const Entity e = pool->entities()[k];
    const Particles<d>& p = pool->components()[k];
    for (int i = 0; i < p.count(); ++i) {
      for (int a = 0; a < 3; ++a) {
        points.push_back(a < d ? p.x[d * i + a] : 0.0);
        velocity.push_back(a < d ? p.v[d * i + a] : 0.0);
      }
      mass.push_back(p.m[i]);
      fixed.push_back(p.fixed[i]);
      body.push_back(e.index);
    }
    const SimplexMesh<d>* mesh = world.template get<SimplexMesh<d>>(e);
    const Elasticity* el = world.template get<Elasticity>(e);
    if (mesh && el) {
      const dm::ForceModel<d> fm = forceModelOf(p, *mesh, *el);
      for (int c = 0; c < mesh->elementCount(); ++c) {
        for (int k2 = 0; k2 <= d; ++k2) connectivity.push_back(base + mesh->elements[(d + 1) * c + k2]);
        offsets.push_back(static_cast<long>(connectivity.size()));
        types.push_back(d == 3 ? 10 : 5);  // VTK_TETRA, VTK_TRIANGLE
        const Eigen::Matrix<double, d, d> F = dm::deformationGradient<d>(fm, c, p.x.data());
        Eigen::Matrix<double, d, d> U, V;
        Eigen::Matrix<double, d, 1> s;
        dm::rotatedSvd<d>(F, U, s, V);
        const double J = F.determinant();
        volumeRatio.push_back(J);
        strain.push_back((s.array() - 1).abs().maxCoeff());
        if (fm.finiteElements() && std::abs(J) > 1e-12) {
          const Eigen::Matrix<double, d, d> P =
              U * dm::diagonalStress<d>(fm.model, fm.lame, s, fm.clamp).asDiagonal() * V.transpose();
          mises.push_back(vonMises<d>(P * F.transpose() / J));
        } else {
          mises.push_back(0.0);
        }
      }
    }
    base += p.count();
  }
  std::ostringstream x;
  x << std::setprecision(17);
  x << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
       "header_type=\"UInt64\">\n  <UnstructuredGrid>\n    <Piece NumberOfPoints=\""
    << mass.size() << "\" NumberOfCells=\"" << types.size() << "\">\n      <Points>\n";
  appendArray(x, "Float64", "points", 3, points);
  x << "      </Points>\n      <Cells>\n";
  appendArray(x, "Int64", "connectivity", 1, connectivity);
  appendArray(x, "Int64", "offsets", 1, offsets);
  std::vector<int> typeBytes(types.begin(), types.end());
  appendArray(x, "UInt8", "types", 1, typeBytes);
  x << "      </Cells>\n      <PointData Vectors=\"velocity\">\n";
  appendArray(x, "Float64", "velocity", 3, velocity);
  appendArray(x, "Float64", "mass", 1, mass);
  appendArray(x, "Int64", "fixed", 1, fixed);
  appendArray(x, "Int64", "body", 1, body);
  x << "      </PointData>\n      <CellData>\n";
  appendArray(x, "Float64", "volume_ratio", 1, volumeRatio);
  appendArray(x, "Float64", "strain", 1, strain);
  appendArray(x, "Float64", "von_mises", 1, mises);
  x << "      </CellData>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n";
  writeFileAtomically(path, x.str());
}

template void writeDeformableFrame<2>(const World<2>&, const std::string&);
template void writeDeformableFrame<3>(const World<3>&, const std::string&);

}  // namespace monolith
