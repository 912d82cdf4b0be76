#include "scenarios/vtk_deformable_writer.h"

#include <Eigen/Eigenvalues>
#include <iomanip>
#include <sstream>

#include "components/cloth.h"
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

// A cloth triangle's in-plane stretches: the singular values of F = Ds Dm^-1 (3 x 2), Dm the rest
// edges in an orthonormal basis of the rest triangle's plane.
Eigen::Vector2d triangleStretches(const double* x, const double* restX, const int* t) {
  auto at = [](const double* a, int i) { return Eigen::Vector3d(a[3 * i], a[3 * i + 1], a[3 * i + 2]); };
  const Eigen::Vector3d e1 = at(restX, t[1]) - at(restX, t[0]), e2 = at(restX, t[2]) - at(restX, t[0]);
  const Eigen::Vector3d t1 = e1.normalized(), t2 = (e2 - e2.dot(t1) * t1).normalized();
  Eigen::Matrix2d Dm;
  Dm << e1.dot(t1), e2.dot(t1), 0, e2.dot(t2);
  Eigen::Matrix<double, 3, 2> Ds;
  Ds << at(x, t[1]) - at(x, t[0]), at(x, t[2]) - at(x, t[0]);
  const Eigen::Matrix<double, 3, 2> F = Ds * Dm.inverse();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(F.transpose() * F);
  return eig.eigenvalues().cwiseMax(0.0).cwiseSqrt();
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
    if constexpr (d == 3) {
      // Cloth: its triangles, with the area ratio as volume_ratio and the largest in-plane
      // |stretch - 1| as strain; springs have no constitutive stress (von_mises 0).
      if (const ClothMesh* cloth = world.template get<ClothMesh>(e)) {
        for (int c = 0; c < cloth->triangleCount(); ++c) {
          const int* t = &cloth->triangles[3 * c];
          for (int k2 = 0; k2 < 3; ++k2) connectivity.push_back(base + t[k2]);
          offsets.push_back(static_cast<long>(connectivity.size()));
          types.push_back(5);  // VTK_TRIANGLE
          const Eigen::Vector2d s = triangleStretches(p.x.data(), cloth->restX.data(), t);
          volumeRatio.push_back(s(0) * s(1));
          strain.push_back((s.array() - 1).abs().maxCoeff());
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
