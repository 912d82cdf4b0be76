#include "scenarios/fluid_probes.h"

#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <sstream>
#include <vector>

#include "components/mac_grid.h"
#include "scenarios/fluid_fields.h"
#include "scenarios/vtk_writer.h"

namespace monolith {

namespace {
const char* kComponents[] = {"u", "v", "w"};

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.12g", v);
  return buf;
}

template <int d>
const MacGrid<d>* gridOf(const World<d>& world) {
  const auto* pool = world.template findPool<MacGrid<d>>();
  return pool && pool->size() > 0 ? &pool->components()[0] : nullptr;
}

template <int d>
bool inside(const MacGrid<d>& grid, const std::vector<double>& x) {
  for (int a = 0; a < d; ++a)
    if (x[a] < grid.origin[a] || x[a] > grid.origin[a] + grid.cells[a] * grid.dx) return false;
  return true;
}
}  // namespace

template <int d>
FluidProbeWriter<d>::FluidProbeWriter(const SceneSpec& scene, const World<d>& world, const std::string& outDir,
                                      long keepThroughStep)
    : scene_(scene), outDir_(outDir) {
  const MacGrid<d>* grid = gridOf(world);
  if ((!scene.probes.empty() || !scene.profiles.empty()) && !grid)
    throw SceneError(scene.file, "output", "probes and profiles only in a scene with a mac_grid", "no mac_grid");
  if (!grid) return;
  std::ostringstream domain;
  domain << "a point inside the grid [" << grid->origin.transpose() << "] .. ["
         << (grid->origin + Eigen::Matrix<double, d, 1>::Constant(grid->cells[0] * grid->dx)).transpose() << "]";
  for (const auto& p : scene.probes)
    if (!inside(*grid, p.position)) throw SceneError(scene.file, p.path, domain.str(), "a point outside it");
  for (const auto& p : scene.profiles)
    if (!inside(*grid, p.from) || !inside(*grid, p.to))
      throw SceneError(scene.file, p.path, "a line with both ends inside the grid", "an end outside it");
  if (!scene.profiles.empty()) std::filesystem::create_directories(outDir_ + "/profiles");
  if (scene.probes.empty()) {
    active_ = !scene.profiles.empty();
    return;
  }
  std::vector<std::string> kept;
  if (keepThroughStep >= 0) {
    std::ifstream in(outDir_ + "/probes.csv");
    for (std::string line; std::getline(in, line);)
      if (kept.empty() || std::stol(line.substr(0, line.find(','))) <= keepThroughStep) kept.push_back(line);
  }
  probes_.open(outDir_ + "/probes.csv", std::ios::trunc);
  if (!probes_) throw std::runtime_error("cannot write '" + outDir_ + "/probes.csv'");
  if (kept.empty()) {
    probes_ << "step,time";
    for (const auto& p : scene.probes) {
      for (int a = 0; a < d; ++a) probes_ << ',' << p.name << '_' << kComponents[a];
      probes_ << ',' << p.name << "_p";
    }
    probes_ << '\n';
  }
  for (const auto& line : kept) probes_ << line << '\n';
  active_ = true;
}

template <int d>
void FluidProbeWriter<d>::afterStep(const World<d>& world, long step, double time) {
  if (!active_ || scene_.probes.empty()) return;
  const MacGrid<d>& grid = *gridOf(world);
  probes_ << step << ',' << num(time);
  for (const auto& p : scene_.probes) {
    const Eigen::Matrix<double, d, 1> x = Eigen::Map<const Eigen::Matrix<double, d, 1>>(p.position.data());
    const auto v = sampleVelocity(grid, x);
    for (int a = 0; a < d; ++a) probes_ << ',' << num(v[a]);
    probes_ << ',' << num(samplePressure(grid, x));
  }
  probes_ << '\n';
  probes_.flush();
}

template <int d>
void FluidProbeWriter<d>::frame(const World<d>& world, long step) {
  if (!active_) return;
  const MacGrid<d>& grid = *gridOf(world);
  for (const auto& p : scene_.profiles) {
    const Eigen::Matrix<double, d, 1> a = Eigen::Map<const Eigen::Matrix<double, d, 1>>(p.from.data());
    const Eigen::Matrix<double, d, 1> b = Eigen::Map<const Eigen::Matrix<double, d, 1>>(p.to.data());
    std::ostringstream csv;
    csv << "s";
    for (int k = 0; k < d; ++k) csv << ',' << "xyz"[k];
    for (int k = 0; k < d; ++k) csv << ',' << kComponents[k];
    csv << ",p\n";
    for (int i = 0; i < p.points; ++i) {
      const double s = p.points == 1 ? 0.0 : double(i) / (p.points - 1);
      const Eigen::Matrix<double, d, 1> x = a + s * (b - a);
      const auto v = sampleVelocity(grid, x);
      csv << num(s);
      for (int k = 0; k < d; ++k) csv << ',' << num(x[k]);
      for (int k = 0; k < d; ++k) csv << ',' << num(v[k]);
      csv << ',' << num(samplePressure(grid, x)) << '\n';
    }
    std::ostringstream file;
    file << outDir_ << "/profiles/" << p.name << "_" << std::setw(6) << std::setfill('0') << step << ".csv";
    writeFileAtomically(file.str(), csv.str());
  }
}

template class FluidProbeWriter<2>;
template class FluidProbeWriter<3>;

}  // namespace monolith
