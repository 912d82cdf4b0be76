// Built-in mesher and mesh readers (solvers/deformable/simplex_mesh.h): the meshes are valid,
// have the right volume, and bad input is rejected naming the file, the element and the fault.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "solvers/deformable/simplex_mesh.h"

namespace dm = monolith::solvers::deformable;

namespace {

template <int d>
double volume(const dm::MeshData<d>& m) {
  dm::Material mat;
  mat.density = 1;
  std::vector<double> X;
  for (const auto& x : m.x)
    for (int a = 0; a < d; ++a) X.push_back(x(a));
  const auto fm = dm::prepareForceModel<d>(X, m.elements, mat);
  double v = 0;
  for (double q : fm.restVolume) v += q;
  return v;
}

std::string writeFile(const std::string& name, const std::string& text) {
  const auto dir = std::filesystem::temp_directory_path() / "monolith_mesh_tests";
  std::filesystem::create_directories(dir);
  const auto path = (dir / name).string();
  std::ofstream(path) << text;
  return path;
}

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(DeformableMesh, BoxMeshIsValidWithExactVolume) {
  const auto m3 = dm::boxMesh<3>(Eigen::Vector3d(1.0, 0.5, 0.25), 0.25);
  EXPECT_EQ(dm::meshProblem(m3), "");
  EXPECT_EQ(m3.elementCount(), 8 * 4 * 2 * 6);
  EXPECT_NEAR(volume(m3), 2.0 * 1.0 * 0.5, 1e-12);
  const auto m2 = dm::boxMesh<2>(Eigen::Vector2d(1.0, 0.5), 0.5);
  EXPECT_EQ(dm::meshProblem(m2), "");
  EXPECT_NEAR(volume(m2), 2.0, 1e-12);
}

// A bar meshed by cell counts per axis: more cells through the thickness than its edge length
// would give, one across the width.
TEST(DeformableMesh, BoxMeshByCellsPerAxis) {
  const auto bar = dm::boxMesh<3>(Eigen::Vector3d(0.5, 0.05, 0.05), Eigen::Vector3i(30, 6, 1));
  EXPECT_EQ(dm::meshProblem(bar), "");
  EXPECT_EQ(bar.elementCount(), 30 * 6 * 1 * 6);
  EXPECT_EQ(bar.x.size(), 31u * 7u * 2u);
  EXPECT_NEAR(volume(bar), 1.0 * 0.1 * 0.1, 1e-14);
  const auto m2 = dm::boxMesh<2>(Eigen::Vector2d(0.5, 0.05), Eigen::Vector2i(40, 4));
  EXPECT_EQ(dm::meshProblem(m2), "");
  EXPECT_EQ(m2.elementCount(), 40 * 4 * 2);
  EXPECT_THROW(dm::boxMesh<3>(Eigen::Vector3d(1, 1, 1), Eigen::Vector3i(2, 0, 2)), std::invalid_argument);
}

// The ball's volume converges to 4/3 pi r^3 as the cells shrink (the cut-cell boundary moved
// onto the sphere); at h = r/4 within 8 %, at r/8 within 4 %.
TEST(DeformableMesh, SphereMeshConvergesToBallVolume) {
  const double r = 0.5, exact = 4.0 / 3.0 * M_PI * r * r * r;
  const auto coarse = dm::sphereMesh<3>(r, r / 4), fine = dm::sphereMesh<3>(r, r / 8);
  EXPECT_EQ(dm::meshProblem(coarse), "");
  EXPECT_EQ(dm::meshProblem(fine), "");
  const double ec = std::abs(volume(coarse) - exact) / exact, ef = std::abs(volume(fine) - exact) / exact;
  EXPECT_LT(ec, 0.08);
  EXPECT_LT(ef, 0.04);
  EXPECT_LT(ef, ec);
  const auto disk = dm::sphereMesh<2>(r, r / 8);
  EXPECT_EQ(dm::meshProblem(disk), "");
  EXPECT_NEAR(volume(disk), M_PI * r * r, 0.03 * M_PI * r * r);
}

TEST(DeformableMesh, ProblemsNameElementAndFault) {
  dm::MeshData<3> m;
  m.x = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, 0, 1),
         Eigen::Vector3d(1, 1, 1)};
  m.elements = {0, 1, 2, 3, 1, 2, 3, 4};
  EXPECT_EQ(dm::meshProblem(m), "");
  m.elements = {0, 1, 2, 3, 1, 3, 2, 4};  // second tetrahedron listed in negative order
  EXPECT_NE(dm::meshProblem(m).find("element 1: inverted"), std::string::npos) << dm::meshProblem(m);
  m.x[4] = Eigen::Vector3d(1.0 / 3, 1.0 / 3, 1.0 / 3);  // on the plane of 1, 2, 3
  m.elements = {0, 1, 2, 3, 1, 2, 3, 4};
  EXPECT_NE(dm::meshProblem(m).find("element 1: degenerate"), std::string::npos) << dm::meshProblem(m);
  m.x.push_back(Eigen::Vector3d(5, 5, 5));
  m.x[4] = Eigen::Vector3d(1, 1, 1);
  EXPECT_NE(dm::meshProblem(m).find("vertex 5 is used by no element"), std::string::npos);
  m.x = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, 0, 1),
         Eigen::Vector3d(5, 0, 0), Eigen::Vector3d(6, 0, 0), Eigen::Vector3d(5, 1, 0), Eigen::Vector3d(5, 0, 1)};
  m.elements = {0, 1, 2, 3, 4, 5, 6, 7};
  EXPECT_NE(dm::meshProblem(m).find("disconnected (2 separate pieces)"), std::string::npos);
  m.elements = {0, 1, 2, 9};
  EXPECT_NE(dm::meshProblem(m).find("element 0: vertex index 9 out of range"), std::string::npos);
}

TEST(DeformableMesh, ReadsGmshV2AndV41AndTetgen) {
  const std::string msh = writeFile("two_tets.msh",
                                    "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n5\n"
                                    "1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 1 1 1\n$EndNodes\n"
                                    "$Elements\n3\n1 15 2 0 1 1\n2 4 2 0 1 1 2 3 4\n3 4 2 0 1 2 3 4 5\n$EndElements\n");
  const auto m = dm::readGmsh<3>(msh);
  EXPECT_EQ(m.elementCount(), 2);
  EXPECT_EQ(m.x.size(), 5u);
  EXPECT_EQ(dm::meshProblem(m), "");
  const std::string base = writeFile("two_tets.node", "# comment\n5 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n4 1 1 1\n");
  writeFile("two_tets.ele", "2 4 0\n0 0 1 2 3\n1 1 2 3 4\n");
  const auto t = dm::readTetgen(base.substr(0, base.size() - 5));
  EXPECT_EQ(t.elementCount(), 2);
  EXPECT_EQ(dm::meshProblem(t), "");
  // The same two tetrahedra in Gmsh 4.1 ASCII: nodes in two entity blocks (tags, then
  // coordinates), a point block and a triangle block skipped, the tetrahedra in a third block.
  const std::string v4 = writeFile("two_tets_v4.msh",
                                   "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 0 0 1\n1 0 0 0 1 1 1 0 0\n$EndEntities\n"
                                   "$Nodes\n2 5 1 5\n0 1 0 1\n1\n0 0 0\n3 1 0 4\n2\n3\n4\n5\n1 0 0\n0 1 0\n0 0 1\n1 1 1\n"
                                   "$EndNodes\n$Elements\n3 4 1 4\n0 1 15 1\n1 1\n2 1 2 1\n2 1 2 3\n"
                                   "3 1 4 2\n3 1 2 3 4\n4 2 3 4 5\n$EndElements\n");
  const auto m4 = dm::readGmsh<3>(v4);
  EXPECT_EQ(m4.elements, m.elements);  // the same mesh as from version 2
  for (std::size_t i = 0; i < m.x.size() && i < m4.x.size(); ++i) EXPECT_EQ(m4.x[i], m.x[i]) << "vertex " << i;
  EXPECT_EQ(m4.x.size(), m.x.size());
  const auto tri = dm::readGmsh<2>(v4);  // in 2-D the triangle, its z dropped
  EXPECT_EQ(tri.elementCount(), 1);
  EXPECT_EQ(dm::meshProblem(tri), "");
}

TEST(DeformableMesh, BadFilesNameFileAndLine) {
  const std::string v40 = writeFile("v40.msh", "$MeshFormat\n4 0 8\n$EndMeshFormat\n");
  EXPECT_NE(errorOf([&] { dm::readGmsh<3>(v40); }).find("v40.msh: line 2: expected Gmsh format version 2 or 4.1"),
            std::string::npos);
  const std::string v4short = writeFile("v4_short.msh", "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 2 1 2\n"
                                                        "0 1 0 2\n1\n2\n0 0 0\n");
  EXPECT_NE(errorOf([&] { dm::readGmsh<3>(v4short); }).find("expected the coordinates of node 2"), std::string::npos)
      << errorOf([&] { dm::readGmsh<3>(v4short); });
  const std::string truncated = writeFile("truncated.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n3\n1 0 0 0\n");
  EXPECT_NE(errorOf([&] { dm::readGmsh<3>(truncated); }).find("expected 3 nodes, the file ends after 1"),
            std::string::npos);
  const std::string missing = writeFile("missing_node.msh",
                                        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n1\n1 0 0 0\n$EndNodes\n"
                                        "$Elements\n1\n7 4 0 1 2 3 4\n$EndElements\n");
  EXPECT_NE(errorOf([&] { dm::readGmsh<3>(missing); }).find("line 10: element 7: node 2 is not in $Nodes"),
            std::string::npos)
      << errorOf([&] { dm::readGmsh<3>(missing); });
  EXPECT_NE(errorOf([&] { dm::readGmsh<3>("/nonexistent/x.msh"); }).find("/nonexistent/x.msh: cannot be opened"),
            std::string::npos);
}

// Torus and capsule (meshed as the ball: grid cells kept by centre, surface vertices moved onto
// the surface): valid (no inverted or degenerate element, one piece), and the volume converges
// to the analytic one: 2 pi^2 R r^2 for the torus, pi r^2 (2L) + 4/3 pi r^3 for the capsule.
// Measured: torus 1.87 % at r/3, 1.05 % at r/6; capsule 1.59 % at r/4, 1.37 % at r/8 (the volume
// lost where a surface vertex may not move without flattening an element); asserted below 3 %
// and 1.5 % (torus), 2.5 % (capsule).
TEST(DeformableMesh, TorusAndCapsuleConvergeToTheirVolumes) {
  const double R = 0.3, r = 0.1;
  const double torus = 2 * M_PI * M_PI * R * r * r;
  const auto tc = dm::torusMesh<3>(R, r, r / 3), tf = dm::torusMesh<3>(R, r, r / 6);
  EXPECT_EQ(dm::meshProblem(tc), "");
  EXPECT_EQ(dm::meshProblem(tf), "");
  const double etc = std::abs(volume(tc) - torus) / torus, etf = std::abs(volume(tf) - torus) / torus;
  std::printf("torus R %.2f r %.2f: %zu / %zu vertices, volume error %.4f at r/3, %.4f at r/6\n", R, r, tc.x.size(),
              tf.x.size(), etc, etf);
  EXPECT_LT(etc, 0.03);
  EXPECT_LT(etf, 0.015);
  EXPECT_LT(etf, etc);

  const double rc = 0.1, L = 0.15;
  const double capsule = M_PI * rc * rc * 2 * L + 4.0 / 3.0 * M_PI * rc * rc * rc;
  const auto cc = dm::capsuleMesh<3>(rc, L, rc / 4), cf = dm::capsuleMesh<3>(rc, L, rc / 8);
  EXPECT_EQ(dm::meshProblem(cc), "");
  EXPECT_EQ(dm::meshProblem(cf), "");
  const double ecc = std::abs(volume(cc) - capsule) / capsule, ecf = std::abs(volume(cf) - capsule) / capsule;
  std::printf("capsule r %.2f L %.2f: volume error %.4f at r/4, %.4f at r/8\n", rc, L, ecc, ecf);
  EXPECT_LT(ecc, 0.025);
  EXPECT_LT(ecf, 0.025);

  // 2-D: an annulus pi ((R + r)^2 - (R - r)^2) = 4 pi R r and a stadium 4 r L + pi r^2.
  const auto annulus = dm::torusMesh<2>(R, r, r / 6);
  EXPECT_EQ(dm::meshProblem(annulus), "");
  EXPECT_NEAR(volume(annulus), 4 * M_PI * R * r, 0.03 * 4 * M_PI * R * r);
  const auto stadium = dm::capsuleMesh<2>(rc, L, rc / 8);
  EXPECT_EQ(dm::meshProblem(stadium), "");
  EXPECT_NEAR(volume(stadium), 4 * rc * L + M_PI * rc * rc, 0.03 * (4 * rc * L + M_PI * rc * rc));

  EXPECT_THROW(dm::torusMesh<3>(0.1, 0.2, 0.05), std::invalid_argument);  // major below minor
  EXPECT_THROW(dm::capsuleMesh<3>(0.1, -1, 0.05), std::invalid_argument);
}
