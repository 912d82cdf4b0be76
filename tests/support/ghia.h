#pragma once
// Ghia, Ghia & Shin (1982), lid-driven cavity centre-line velocities (values as listed in
// ../shared/REFERENCES.md): u on the vertical centre line x = 0.5, v on the horizontal centre
// line y = 0.5, for Re = 100 and Re = 1000.
#include <array>
#include <cmath>

#include "components/mac_grid.h"
#include "scenarios/fluid_fields.h"

namespace monolith::test {

struct GhiaPoint {
  double coordinate, re100, re1000;
};

inline constexpr std::array<GhiaPoint, 17> kGhiaU = {{
    {1.0000, 1.00000, 1.00000},   {0.9766, 0.84123, 0.65928},   {0.9688, 0.78871, 0.57492},
    {0.9609, 0.73722, 0.51117},   {0.9531, 0.68717, 0.46604},   {0.8516, 0.23151, 0.33304},
    {0.7344, 0.00332, 0.18719},   {0.6172, -0.13641, 0.05702},  {0.5000, -0.20581, -0.06080},
    {0.4531, -0.21090, -0.10648}, {0.2813, -0.15662, -0.27805}, {0.1719, -0.10150, -0.38289},
    {0.1016, -0.06434, -0.29730}, {0.0703, -0.04775, -0.22220}, {0.0625, -0.04192, -0.20196},
    {0.0547, -0.03717, -0.18109}, {0.0000, 0.00000, 0.00000},
}};

inline constexpr std::array<GhiaPoint, 17> kGhiaV = {{
    {1.0000, 0.00000, 0.00000},   {0.9688, -0.05906, -0.21388}, {0.9609, -0.07391, -0.27669},
    {0.9531, -0.08864, -0.33714}, {0.9453, -0.10313, -0.39188}, {0.9063, -0.16914, -0.51550},
    {0.8594, -0.22445, -0.42665}, {0.8047, -0.24533, -0.31966}, {0.5000, 0.05454, 0.02526},
    {0.2344, 0.17527, 0.32235},   {0.2266, 0.17507, 0.33075},   {0.1563, 0.16077, 0.37095},
    {0.0938, 0.12317, 0.32627},   {0.0781, 0.10890, 0.30353},   {0.0703, 0.10091, 0.29012},
    {0.0625, 0.09233, 0.27485},   {0.0000, 0.00000, 0.00000},
}};

// Largest deviation of a unit-square cavity's centre-line velocities from the table, and where.
struct GhiaDeviation {
  double u = 0, v = 0;        // max |u - Ghia| on x = 0.5, max |v - Ghia| on y = 0.5
  double uAt = 0, vAt = 0;    // the y (resp. x) coordinate of that point
};

inline GhiaDeviation ghiaDeviation(const MacGrid<2>& grid, int re) {
  GhiaDeviation worst;
  for (const auto& p : kGhiaU) {
    const double error = std::abs(sampleVelocity(grid, Eigen::Vector2d(0.5, p.coordinate)).x() - (re == 100 ? p.re100 : p.re1000));
    if (error > worst.u) worst.u = error, worst.uAt = p.coordinate;
  }
  for (const auto& p : kGhiaV) {
    const double error = std::abs(sampleVelocity(grid, Eigen::Vector2d(p.coordinate, 0.5)).y() - (re == 100 ? p.re100 : p.re1000));
    if (error > worst.v) worst.v = error, worst.vAt = p.coordinate;
  }
  return worst;
}

}  // namespace monolith::test
