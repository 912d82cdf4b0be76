#pragma once
// Simplex meshes of deformable bodies, entity-free: tetrahedra in 3-D, triangles in 2-D.
// A built-in mesher (a structured grid of cubes/squares split into simplices, kept where a
// level set is negative and its boundary vertices moved onto the surface) so scenes need no
// files, readers for Gmsh .msh (v2 and v4.1 ASCII) and TetGen .node/.ele, and the checks every mesh
// passes before it is simulated.
#include <Eigen/Core>
#include <stdexcept>
#include <string>
#include <vector>

#include "solvers/deformable/elasticity.h"

namespace monolith::solvers::deformable {

template <int d>
struct MeshData {
  std::vector<VecD<d>> x;     // vertices
  std::vector<int> elements;  // d+1 vertex indices per simplex, positively oriented
  int elementCount() const { return static_cast<int>(elements.size()) / (d + 1); }
};

// A mesh file that cannot be read or is not a valid mesh: the message names the file, the
// line or element and what is wrong.
struct MeshError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Box [-a, a] (componentwise), cells of edge ~h (at least one per axis), each cube split into
// six tetrahedra around its main diagonal (each square into two triangles).
template <int d>
MeshData<d> boxMesh(const VecD<d>& halfExtents, double h);
// Box [-a, a] with the given number of cells per axis (a bar with several elements through its
// thickness and fewer along it, or the reverse), split as above.
template <int d>
MeshData<d> boxMesh(const VecD<d>& halfExtents, const Eigen::Matrix<int, d, 1>& cells);
// Ball of the given radius: grid cells whose centre is inside, the surface vertices then moved
// radially onto the sphere where no element inverts or flattens by it.
template <int d>
MeshData<d> sphereMesh(double radius, double h);
// Torus about the y axis (its core circle of radius `majorRadius` in the xz-plane, tube radius
// `minorRadius`); in 2-D an annulus of mid radius `majorRadius` and half width `minorRadius`.
// Meshed as the ball: grid cells with their centre inside, surface vertices moved onto the torus.
template <int d>
MeshData<d> torusMesh(double majorRadius, double minorRadius, double h);
// Capsule along y: the points within `radius` of the segment from -halfLength to +halfLength on
// the y axis (a stadium in 2-D), meshed as the ball.
template <int d>
MeshData<d> capsuleMesh(double radius, double halfLength, double h);

// "" when the mesh is valid, else what is wrong, naming the first bad element or vertex:
// indices out of range, repeated vertices in an element, inverted (negative signed volume) or
// degenerate (volume below 1e-10 of its edge length^d) elements, vertices used by no element,
// and a mesh in more than one connected piece.
template <int d>
std::string meshProblem(const MeshData<d>& mesh);

// Readers. 3-D takes the 4-node tetrahedra (Gmsh type 4), 2-D the 3-node triangles (type 2,
// z dropped); other element types (points, lines, boundary faces) are skipped. Negatively
// oriented simplices are NOT reordered: they are reported as inverted by meshProblem.
template <int d>
MeshData<d> readGmsh(const std::string& path);
// TetGen: `base`.node and `base`.ele (3-D only; 0- or 1-based as the .node numbering says).
MeshData<3> readTetgen(const std::string& base);

// Lumped masses (density * volume / (d+1) per vertex), rest shape matrices and volumes of
// the elements, and for the spring model the unique edges of the mesh with their rest lengths
// and, with an altitude stiffness, the d+1 altitude springs of every element.
struct Material {
  Model model = Model::Corotated;
  double density = 1000;
  double youngsModulus = 1e5;
  double poissonRatio = 0.3;
  double rayleighAlpha = 0, rayleighBeta = 0;
  double overdamping = 0;     // spring damping as a fraction of critical damping
  double altitudeStiffness = 0;  // Young's modulus of the altitude springs (0: none)
  double clamp = 0.3;
};
// `masses` (one per particle), when given, replace the lumped masses, also in the springs'
// critical damping.
template <int d>
ForceModel<d> prepareForceModel(const std::vector<double>& restX, const std::vector<int>& elements,
                                const Material& material, const std::vector<double>& masses = {});

}  // namespace monolith::solvers::deformable
