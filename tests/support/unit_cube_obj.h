#pragma once
// A closed unit cube (edge 1, centred at the origin, outward-facing triangles) as a Wavefront
// OBJ file, for tests of dynamic mesh bodies.
#include <filesystem>
#include <fstream>

namespace monolith::test {

inline void writeUnitCubeObj(const std::filesystem::path& file) {
  std::ofstream obj(file);
  obj << "v -0.5 -0.5 -0.5\nv 0.5 -0.5 -0.5\nv 0.5 0.5 -0.5\nv -0.5 0.5 -0.5\n"
         "v -0.5 -0.5 0.5\nv 0.5 -0.5 0.5\nv 0.5 0.5 0.5\nv -0.5 0.5 0.5\n"
         "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 4 8 7\nf 4 7 3\nf 1 5 8\nf 1 8 4\nf 2 3 7\nf 2 7 6\n";
}

}  // namespace monolith::test
