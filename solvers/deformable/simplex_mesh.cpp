#include "solvers/deformable/simplex_mesh.h"

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <map>
#include <numeric>
#include <sstream>
#include <unordered_map>

namespace monolith::solvers::deformable {

namespace {

template <int d>
MatD<d> edgeMatrixOf(const MeshData<d>& m, int e) {
  const int* n = &m.elements[(d + 1) * e];
  MatD<d> D;
  for (int k = 0; k < d; ++k) D.col(k) = m.x[n[k + 1]] - m.x[n[0]];
  return D;
}

double factorial(int d) { return d == 2 ? 2.0 : 6.0; }

template <int d>
double signedVolume(const MeshData<d>& m, int e) {
  return edgeMatrixOf(m, e).determinant() / factorial(d);
}

template <int d>
void orientPositively(MeshData<d>& m) {
  for (int e = 0; e < m.elementCount(); ++e)
    if (signedVolume(m, e) < 0) std::swap(m.elements[(d + 1) * e + 1], m.elements[(d + 1) * e + 2]);
}

// Keeps only the vertices some element uses, renumbering the elements.
template <int d>
void dropUnusedVertices(MeshData<d>& m) {
  std::vector<int> map(m.x.size(), -1);
  std::vector<VecD<d>> x;
  for (int& v : m.elements) {
    if (v < 0 || v >= static_cast<int>(map.size())) continue;  // left for meshProblem to report
    if (map[v] < 0) {
      map[v] = static_cast<int>(x.size());
      x.push_back(m.x[v]);
    }
    v = map[v];
  }
  m.x = std::move(x);
}

// A structured grid of n cells per axis over [lo, lo + n h], all cells split into simplices,
// keeping those cells `keep` accepts (by centre).
template <int d, class Keep>
MeshData<d> gridMesh(const VecD<d>& lo, const Eigen::Matrix<int, d, 1>& n, const VecD<d>& h, Keep keep) {
  MeshData<d> m;
  Eigen::Matrix<int, d, 1> nv = n.array() + 1;
  auto vertexIndex = [&](const Eigen::Matrix<int, d, 1>& c) {
    int idx = 0;
    for (int a = d - 1; a >= 0; --a) idx = idx * nv(a) + c(a);
    return idx;
  };
  const int vertexCount = nv.prod();
  m.x.resize(vertexCount);
  for (int i = 0; i < vertexCount; ++i) {
    Eigen::Matrix<int, d, 1> c;
    int r = i;
    for (int a = 0; a < d; ++a) {
      c(a) = r % nv(a);
      r /= nv(a);
    }
    m.x[i] = lo + (c.template cast<double>().array() * h.array()).matrix();
  }
  std::array<int, d> perm;
  std::iota(perm.begin(), perm.end(), 0);
  std::vector<std::array<int, d>> perms;
  do perms.push_back(perm);
  while (std::next_permutation(perm.begin(), perm.end()));
  const int cellCount = n.prod();
  for (int i = 0; i < cellCount; ++i) {
    Eigen::Matrix<int, d, 1> c;
    int r = i;
    for (int a = 0; a < d; ++a) {
      c(a) = r % n(a);
      r /= n(a);
    }
    const VecD<d> centre = lo + ((c.template cast<double>().array() + 0.5) * h.array()).matrix();
    if (!keep(centre)) continue;
    // Freudenthal (Kuhn) split: one simplex per axis order, along the cell's main diagonal, so
    // neighbouring cells share their faces' diagonals and the mesh is conforming.
    for (const auto& p : perms) {
      Eigen::Matrix<int, d, 1> corner = c;
      m.elements.push_back(vertexIndex(corner));
      for (int k = 0; k < d; ++k) {
        corner(p[k]) += 1;
        m.elements.push_back(vertexIndex(corner));
      }
    }
  }
  dropUnusedVertices(m);
  orientPositively(m);
  return m;
}

template <int d>
std::vector<std::vector<int>> boundaryFaces(const MeshData<d>& m) {
  std::map<std::vector<int>, int> count;
  for (int e = 0; e < m.elementCount(); ++e)
    for (int skip = 0; skip <= d; ++skip) {
      std::vector<int> f;
      for (int k = 0; k <= d; ++k)
        if (k != skip) f.push_back(m.elements[(d + 1) * e + k]);
      std::sort(f.begin(), f.end());
      ++count[f];
    }
  std::vector<std::vector<int>> out;
  for (const auto& [f, c] : count)
    if (c == 1) out.push_back(f);
  return out;
}

}  // namespace

template <int d>
MeshData<d> boxMesh(const VecD<d>& halfExtents, double h) {
  if (!(h > 0) || !(halfExtents.minCoeff() > 0)) throw std::invalid_argument("box mesh: sizes must be positive");
  Eigen::Matrix<int, d, 1> n;
  for (int a = 0; a < d; ++a) n(a) = std::max(1, static_cast<int>(std::lround(2 * halfExtents(a) / h)));
  return boxMesh<d>(halfExtents, n);
}

template <int d>
MeshData<d> boxMesh(const VecD<d>& halfExtents, const Eigen::Matrix<int, d, 1>& cells) {
  if (!(halfExtents.minCoeff() > 0) || cells.minCoeff() < 1)
    throw std::invalid_argument("box mesh: sizes and cell counts must be positive");
  const VecD<d> cell = (2 * halfExtents.array() / cells.template cast<double>().array()).matrix();
  return gridMesh<d>(-halfExtents, cells, cell, [](const VecD<d>&) { return true; });
}

namespace {

// The grid cells (of edge about h, at least two per axis) of the box [-a, a] whose centres are
// inside, then the surface vertices moved onto the surface by `project`, one at a time, keeping a
// move only if every element around the vertex keeps at least a fifth of its volume.
template <int d, class Inside, class Project>
MeshData<d> implicitMesh(const VecD<d>& half, double h, Inside inside, Project project) {
  Eigen::Matrix<int, d, 1> cells;
  VecD<d> c;
  for (int a = 0; a < d; ++a) {
    cells(a) = std::max(2, static_cast<int>(std::ceil(2 * half(a) / h)));
    c(a) = 2 * half(a) / cells(a);
  }
  MeshData<d> m = gridMesh<d>(-half, cells, c, inside);
  std::vector<std::vector<int>> around(m.x.size());
  for (int e = 0; e < m.elementCount(); ++e)
    for (int k = 0; k <= d; ++k) around[m.elements[(d + 1) * e + k]].push_back(e);
  std::vector<char> onSurface(m.x.size(), 0);
  for (const auto& f : boundaryFaces(m))
    for (int v : f) onSurface[v] = 1;
  for (std::size_t v = 0; v < m.x.size(); ++v) {
    if (!onSurface[v]) continue;
    VecD<d> target;
    if (!project(m.x[v], target)) continue;
    std::vector<double> before;
    for (int e : around[v]) before.push_back(signedVolume(m, e));
    const VecD<d> old = m.x[v];
    m.x[v] = target;
    for (std::size_t k = 0; k < around[v].size(); ++k)
      if (signedVolume(m, around[v][k]) < 0.2 * before[k]) {
        m.x[v] = old;
        break;
      }
  }
  return m;
}

// The point of a sphere of radius r about centre c nearest to x (false at the centre).
template <int d>
bool ontoSphere(const VecD<d>& x, const VecD<d>& centre, double r, VecD<d>& out) {
  const VecD<d> q = x - centre;
  if (q.norm() == 0) return false;
  out = centre + r * q.normalized();
  return true;
}

// The nearest point of the torus' core circle (radius R about the y axis in the xz-plane; in
// 2-D the circle about the origin) to x; false on the axis.
template <int d>
bool torusCore(const VecD<d>& x, double R, VecD<d>& core) {
  VecD<d> radial = x;
  if constexpr (d == 3) radial(1) = 0;
  if (radial.norm() == 0) return false;
  core = R * radial.normalized();
  return true;
}

template <int d>
VecD<d> capsuleCore(const VecD<d>& x, double halfLength) {
  VecD<d> core = VecD<d>::Zero();
  core(1) = std::clamp(x(1), -halfLength, halfLength);
  return core;
}

}  // namespace

template <int d>
MeshData<d> sphereMesh(double radius, double h) {
  if (!(h > 0) || !(radius > 0)) throw std::invalid_argument("sphere mesh: sizes must be positive");
  return implicitMesh<d>(
      VecD<d>::Constant(radius), h, [&](const VecD<d>& x) { return x.norm() < radius; },
      [&](const VecD<d>& x, VecD<d>& out) {
        if (x.norm() == 0) return false;
        out = radius * x.normalized();
        return true;
      });
}

template <int d>
MeshData<d> torusMesh(double majorRadius, double minorRadius, double h) {
  if (!(h > 0) || !(minorRadius > 0) || !(majorRadius > minorRadius))
    throw std::invalid_argument("torus mesh: need edge length > 0 and major radius > minor radius > 0");
  VecD<d> half = VecD<d>::Constant(majorRadius + minorRadius);
  if constexpr (d == 3) half(1) = minorRadius;
  return implicitMesh<d>(
      half, h,
      [&](const VecD<d>& x) {
        VecD<d> core;
        return torusCore<d>(x, majorRadius, core) && (x - core).norm() < minorRadius;
      },
      [&](const VecD<d>& x, VecD<d>& out) {
        VecD<d> core;
        return torusCore<d>(x, majorRadius, core) && ontoSphere<d>(x, core, minorRadius, out);
      });
}

template <int d>
MeshData<d> capsuleMesh(double radius, double halfLength, double h) {
  if (!(h > 0) || !(radius > 0) || !(halfLength >= 0))
    throw std::invalid_argument("capsule mesh: need radius, edge length > 0 and half length >= 0");
  VecD<d> half = VecD<d>::Constant(radius);
  half(1) = halfLength + radius;
  return implicitMesh<d>(
      half, h, [&](const VecD<d>& x) { return (x - capsuleCore<d>(x, halfLength)).norm() < radius; },
      [&](const VecD<d>& x, VecD<d>& out) { return ontoSphere<d>(x, capsuleCore<d>(x, halfLength), radius, out); });
}

template <int d>
std::string meshProblem(const MeshData<d>& m) {
  std::ostringstream out;
  if (m.elements.empty()) return "no elements";
  if (m.elements.size() % (d + 1) != 0) return "element index list not a multiple of " + std::to_string(d + 1);
  const int nv = static_cast<int>(m.x.size());
  for (int v = 0; v < nv; ++v)
    if (!m.x[v].allFinite()) return "vertex " + std::to_string(v) + ": non-finite coordinates";
  std::vector<int> parent(nv);
  std::iota(parent.begin(), parent.end(), 0);
  auto root = [&](int v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  std::vector<char> used(nv, 0);
  for (int e = 0; e < m.elementCount(); ++e) {
    const int* n = &m.elements[(d + 1) * e];
    for (int k = 0; k <= d; ++k) {
      if (n[k] < 0 || n[k] >= nv) {
        out << "element " << e << ": vertex index " << n[k] << " out of range [0, " << nv << ")";
        return out.str();
      }
      for (int j = 0; j < k; ++j)
        if (n[j] == n[k]) {
          out << "element " << e << ": vertex " << n[k] << " repeated";
          return out.str();
        }
    }
    double longest = 0;
    for (int k = 0; k <= d; ++k)
      for (int j = 0; j < k; ++j) longest = std::max(longest, (m.x[n[k]] - m.x[n[j]]).norm());
    const double vol = signedVolume(m, e);
    const double scale = std::pow(longest, d) / factorial(d);
    if (std::abs(vol) <= 1e-10 * scale) {
      out << "element " << e << ": degenerate (volume " << vol << " for longest edge " << longest << ")";
      return out.str();
    }
    if (vol < 0) {
      out << "element " << e << ": inverted (signed volume " << vol << "; list its vertices in positive order)";
      return out.str();
    }
    for (int k = 0; k <= d; ++k) {
      used[n[k]] = 1;
      parent[root(n[k])] = root(n[0]);
    }
  }
  for (int v = 0; v < nv; ++v)
    if (!used[v]) return "vertex " + std::to_string(v) + " is used by no element";
  int pieces = 0;
  for (int v = 0; v < nv; ++v) pieces += root(v) == v;
  if (pieces > 1) return "the mesh is disconnected (" + std::to_string(pieces) + " separate pieces); give each piece its own entity";
  return "";
}

namespace {

struct LineReader {
  std::ifstream in;
  std::string path;
  int line = 0;
  explicit LineReader(const std::string& p) : in(p), path(p) {
    if (!in) throw MeshError(path + ": cannot be opened");
  }
  // Next non-empty line with '#' comments removed (TetGen) or as is (Gmsh).
  bool next(std::string& s, bool hashComments) {
    while (std::getline(in, s)) {
      ++line;
      if (hashComments) s = s.substr(0, s.find('#'));
      if (s.find_first_not_of(" \t\r") != std::string::npos) return true;
    }
    return false;
  }
  [[noreturn]] void fail(const std::string& what) const {
    throw MeshError(path + ": line " + std::to_string(line) + ": " + what);
  }
};

template <int d>
MeshData<d> finishRead(MeshData<d> m, const std::string& path) {
  if (m.elements.empty())
    throw MeshError(path + ": no " + std::string(d == 3 ? "4-node tetrahedra" : "3-node triangles") + " in the file");
  dropUnusedVertices(m);
  return m;
}

}  // namespace

template <int d>
MeshData<d> readGmsh(const std::string& path) {
  LineReader r(path);
  MeshData<d> m;
  std::unordered_map<long, int> nodeIndex;
  std::string s;
  bool sawFormat = false;
  double version = 0;
  const int wanted = d == 3 ? 4 : 2;
  auto addNode = [&](long id, const std::string& line) {
    std::istringstream ls(line);
    double c[3];
    if (!(ls >> c[0] >> c[1] >> c[2])) r.fail("expected node coordinates \"x y z\", got \"" + line + "\"");
    VecD<d> x;
    for (int a = 0; a < d; ++a) x(a) = c[a];
    nodeIndex[id] = static_cast<int>(m.x.size());
    m.x.push_back(x);
  };
  auto addElementNodes = [&](long id, std::istringstream& ls) {
    for (int k = 0; k <= d; ++k) {
      long node;
      if (!(ls >> node)) r.fail("element " + std::to_string(id) + ": expected " + std::to_string(d + 1) + " node ids");
      auto it = nodeIndex.find(node);
      if (it == nodeIndex.end()) r.fail("element " + std::to_string(id) + ": node " + std::to_string(node) + " is not in $Nodes");
      m.elements.push_back(it->second);
    }
  };
  // Reads "count..." header numbers of a version 4 section.
  auto header = [&](const char* what, int count) {
    std::vector<long> v(count);
    if (!r.next(s, false)) r.fail(std::string("expected ") + what);
    std::istringstream ls(s);
    for (long& x : v)
      if (!(ls >> x) || x < 0) r.fail(std::string("expected ") + what + ", got \"" + s + "\"");
    return v;
  };
  while (r.next(s, false)) {
    if (s.rfind("$MeshFormat", 0) == 0) {
      if (!r.next(s, false)) r.fail("expected the format line \"2.2 0 8\" or \"4.1 0 8\"");
      std::istringstream ls(s);
      int fileType = -1;
      ls >> version >> fileType;
      if (!ls || !((version >= 2 && version < 3) || (version >= 4.1 && version < 5)))
        r.fail("expected Gmsh format version 2 or 4.1 (got \"" + s + "\"; save the mesh as \"Version 2 ASCII\" or "
               "\"Version 4 ASCII\")");
      if (fileType != 0) r.fail("expected an ASCII file (file type 0), got binary");
      sawFormat = true;
    } else if (s.rfind("$Nodes", 0) == 0 && version >= 4) {
      if (!sawFormat) r.fail("$Nodes before $MeshFormat");
      // 4.1: "blocks nodes minTag maxTag", then per block "dim entity parametric count", the
      // block's node tags one a line, then their coordinates one a line.
      const long blocks = header("\"numEntityBlocks numNodes minNodeTag maxNodeTag\"", 4)[0];
      for (long b = 0; b < blocks; ++b) {
        const long count = header("a node block \"entityDim entityTag parametric numNodesInBlock\"", 4)[3];
        std::vector<long> ids(count);
        for (long& id : ids) id = header("a node tag", 1)[0];
        for (long id : ids) {
          if (!r.next(s, false)) r.fail("expected the coordinates of node " + std::to_string(id));
          addNode(id, s);
        }
      }
    } else if (s.rfind("$Elements", 0) == 0 && version >= 4) {
      // 4.1: "blocks elements minTag maxTag", then per block "dim entity type count" and one
      // line "tag node..." per element.
      const long blocks = header("\"numEntityBlocks numElements minElementTag maxElementTag\"", 4)[0];
      for (long b = 0; b < blocks; ++b) {
        const std::vector<long> block = header("an element block \"entityDim entityTag elementType numElementsInBlock\"", 4);
        for (long i = 0; i < block[3]; ++i) {
          if (!r.next(s, false)) r.fail("expected " + std::to_string(block[3]) + " elements in the block, the file ends");
          if (block[2] != wanted) continue;
          std::istringstream ls(s);
          long id;
          if (!(ls >> id)) r.fail("expected an element \"tag node...\", got \"" + s + "\"");
          addElementNodes(id, ls);
        }
      }
    } else if (s.rfind("$Nodes", 0) == 0) {
      if (!sawFormat) r.fail("$Nodes before $MeshFormat");
      if (!r.next(s, false)) r.fail("expected the node count");
      const long n = std::stol(s);
      for (long i = 0; i < n; ++i) {
        if (!r.next(s, false)) r.fail("expected " + std::to_string(n) + " nodes, the file ends after " + std::to_string(i));
        std::istringstream ls(s);
        long id;
        if (!(ls >> id)) r.fail("expected a node \"id x y z\", got \"" + s + "\"");
        std::string rest;
        std::getline(ls, rest);
        addNode(id, rest);
      }
    } else if (s.rfind("$Elements", 0) == 0) {
      if (!r.next(s, false)) r.fail("expected the element count");
      const long n = std::stol(s);
      for (long i = 0; i < n; ++i) {
        if (!r.next(s, false)) r.fail("expected " + std::to_string(n) + " elements, the file ends after " + std::to_string(i));
        std::istringstream ls(s);
        long id;
        int type, tags;
        if (!(ls >> id >> type >> tags)) r.fail("expected an element \"id type ntags ...\", got \"" + s + "\"");
        for (int t = 0; t < tags; ++t) {
          long tag;
          ls >> tag;
        }
        if (type != wanted) continue;
        addElementNodes(id, ls);
      }
    }
  }
  if (!sawFormat) throw MeshError(path + ": not a Gmsh mesh (no $MeshFormat section)");
  return finishRead(std::move(m), path);
}

MeshData<3> readTetgen(const std::string& base) {
  MeshData<3> m;
  int firstId = 0;
  {
    LineReader r(base + ".node");
    std::string s;
    if (!r.next(s, true)) r.fail("expected the header \"points dimension attributes markers\"");
    std::istringstream hs(s);
    long n;
    int dim, attrs = 0, markers = 0;
    if (!(hs >> n >> dim) || dim != 3) r.fail("expected \"<points> 3 <attributes> <markers>\", got \"" + s + "\"");
    hs >> attrs >> markers;
    for (long i = 0; i < n; ++i) {
      if (!r.next(s, true)) r.fail("expected " + std::to_string(n) + " points, the file ends after " + std::to_string(i));
      std::istringstream ls(s);
      long id;
      Eigen::Vector3d x;
      if (!(ls >> id >> x(0) >> x(1) >> x(2))) r.fail("expected a point \"id x y z\", got \"" + s + "\"");
      if (i == 0) firstId = static_cast<int>(id);
      else if (id != firstId + i) r.fail("expected point number " + std::to_string(firstId + i) + ", got " + std::to_string(id));
      m.x.push_back(x);
    }
  }
  LineReader r(base + ".ele");
  std::string s;
  if (!r.next(s, true)) r.fail("expected the header \"tetrahedra nodes-per-tet attributes\"");
  std::istringstream hs(s);
  long n;
  int per;
  if (!(hs >> n >> per) || (per != 4 && per != 10)) r.fail("expected \"<tetrahedra> 4|10 <attributes>\", got \"" + s + "\"");
  for (long i = 0; i < n; ++i) {
    if (!r.next(s, true)) r.fail("expected " + std::to_string(n) + " tetrahedra, the file ends after " + std::to_string(i));
    std::istringstream ls(s);
    long id, v[4];
    if (!(ls >> id >> v[0] >> v[1] >> v[2] >> v[3])) r.fail("expected a tetrahedron \"id a b c d\", got \"" + s + "\"");
    for (long k : v) m.elements.push_back(static_cast<int>(k - firstId));
  }
  return finishRead(std::move(m), base + ".ele");
}

template <int d>
ForceModel<d> prepareForceModel(const std::vector<double>& restX, const std::vector<int>& elements,
                                const Material& mat, const std::vector<double>& masses) {
  ForceModel<d> fm;
  fm.model = mat.model;
  fm.lame = Lame::fromYoung(mat.youngsModulus, mat.poissonRatio);
  fm.clamp = mat.clamp;
  fm.rayleighAlpha = mat.rayleighAlpha;
  fm.rayleighBeta = mat.model == Model::Springs ? 0.0 : mat.rayleighBeta;
  fm.elements = elements;
  const int np = static_cast<int>(restX.size()) / d;
  const int ne = static_cast<int>(elements.size()) / (d + 1);
  fm.mass.assign(np, 0.0);
  fm.DmInv.resize(ne);
  fm.restVolume.resize(ne);
  auto X = [&](int i) { return VecD<d>(Eigen::Map<const VecD<d>>(restX.data() + d * i)); };
  for (int e = 0; e < ne; ++e) {
    const int* n = &elements[(d + 1) * e];
    MatD<d> Dm;
    for (int k = 0; k < d; ++k) Dm.col(k) = X(n[k + 1]) - X(n[0]);
    fm.DmInv[e] = Dm.inverse();
    fm.restVolume[e] = Dm.determinant() / factorial(d);
    for (int k = 0; k <= d; ++k) fm.mass[n[k]] += mat.density * fm.restVolume[e] / (d + 1);
  }
  if (!masses.empty()) fm.mass = masses;
  if (mat.model == Model::Springs) {
    std::vector<std::pair<int, int>> edges;
    for (int e = 0; e < ne; ++e)
      for (int a = 0; a <= d; ++a)
        for (int b = a + 1; b <= d; ++b) {
          const int i = elements[(d + 1) * e + a], j = elements[(d + 1) * e + b];
          edges.emplace_back(std::min(i, j), std::max(i, j));
        }
    std::sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
    for (auto [i, j] : edges) {
      const double L = (X(j) - X(i)).norm();
      // A spring stands for a rod of cross-section L^(d-1) per unit depth: k = E L^(d-2).
      const double k = mat.youngsModulus * std::pow(L, d - 2);
      const double mEff = fm.mass[i] * fm.mass[j] / (fm.mass[i] + fm.mass[j]);
      fm.springs.push_back(i);
      fm.springs.push_back(j);
      fm.springRest.push_back(L);
      fm.springK.push_back(k);
      fm.springC.push_back(mat.overdamping * 2 * std::sqrt(k * mEff));
    }
    if (mat.altitudeStiffness > 0) {
      for (int e = 0; e < ne; ++e)
        for (int a = 0; a <= d; ++a) {
          int idx[d + 1];
          idx[0] = elements[(d + 1) * e + a];
          for (int b = 1, k = 0; b <= d; ++b, ++k) idx[b] = elements[(d + 1) * e + (a + b) % (d + 1)];
          VecD<d> g[d + 1];
          double H = signedAltitude<d>(restX.data(), idx, g);
          if (H < 0) {  // order the side so that the rest altitude is positive
            std::swap(idx[1], idx[2]);
            H = signedAltitude<d>(restX.data(), idx, g);
          }
          // Critical damping of the altitude in isolation: the effective mass of h is
          // 1 / sum_a |g_a|^2 / m_a (an edge spring's m1 m2 / (m1 + m2)).
          double invM = 0;
          for (int b = 0; b <= d; ++b) invM += g[b].squaredNorm() / fm.mass[idx[b]];
          const double k = mat.altitudeStiffness * std::pow(H, d - 2);
          fm.altitudes.insert(fm.altitudes.end(), idx, idx + d + 1);
          fm.altitudeRest.push_back(H);
          fm.altitudeK.push_back(k);
          fm.altitudeC.push_back(mat.overdamping * 2 * std::sqrt(k / invM));
        }
    }
  }
  return fm;
}

#define MONOLITH_INSTANTIATE(D)                                                                                   \
  template MeshData<D> boxMesh<D>(const VecD<D>&, double);                                                        \
  template MeshData<D> boxMesh<D>(const VecD<D>&, const Eigen::Matrix<int, D, 1>&);                                \
  template MeshData<D> sphereMesh<D>(double, double);                                                             \
  template MeshData<D> torusMesh<D>(double, double, double);                                                      \
  template MeshData<D> capsuleMesh<D>(double, double, double);                                                             \
  template std::string meshProblem<D>(const MeshData<D>&);                                                        \
  template MeshData<D> readGmsh<D>(const std::string&);                                                           \
  template ForceModel<D> prepareForceModel<D>(const std::vector<double>&, const std::vector<int>&, const Material&, \
                                              const std::vector<double>&);
MONOLITH_INSTANTIATE(2)
MONOLITH_INSTANTIATE(3)
#undef MONOLITH_INSTANTIATE

}  // namespace monolith::solvers::deformable
