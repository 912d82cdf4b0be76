#include "scenarios/level_set_component.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "components/level_set.h"
#include "components/shape.h"
#include "scenarios/contact_components.h"
#include "solvers/geometry/signed_distance.h"

namespace monolith {

namespace {

// At most this many samples (8 bytes each), and for a mesh this many sample-triangle distance
// evaluations (about a minute on one core): beyond either the spacing is too fine for the body.
constexpr double kMaxSamples = 1e8;
constexpr double kMaxMeshWork = 2e10;
// Generated level sets extend this many samples beyond the boundary's box (their boundary
// samples lie at least that far outside the body).
constexpr int kMargin = 2;

// The checks every level set passes, whatever its source: a body (some sample <= 0) that lies
// inside the sampled box (every boundary sample > 0), so that phi outside the box is positive.
template <int d>
void checkEnclosed(const Config& c, const std::string& key, const LevelSet<d>& ls) {
  bool anyInside = false;
  for (int k = 0; k < static_cast<int>(ls.values.size()); ++k) {
    const double v = ls.values[k];
    anyInside |= v <= 0;
    const auto i = ls.sampleCoord(k);
    const bool boundary = (i.array() == 0).any() || (i.array() == ls.samples.array() - 1).any();
    if (boundary && v <= 0) {
      std::ostringstream got;
      got << "sample [";
      for (int a = 0; a < d; ++a) got << (a ? ", " : "") << i[a];
      got << "] = " << v;
      c.failAt(key, "every sample on the sampled box's boundary > 0 (the body must lie inside the box)", got.str());
    }
  }
  if (!anyInside) c.failAt(key, "some sample <= 0 (phi is negative inside the body)", "every sample positive");
}

// {"origin", "spacing", "samples", "values"}.
template <int d>
LevelSet<d> sampledLevelSet(const Config& c) {
  LevelSet<d> ls;
  ls.origin = c.vector("origin", d);
  ls.spacing = c.number("spacing", Bound::Positive);
  const Json& samples = c.raw().contains("samples") ? c.raw()["samples"] : Json();
  if (!samples.is_array() || samples.size() != static_cast<std::size_t>(d))
    c.failAt("samples", "the number of samples per axis, [" + std::string(d == 3 ? "nx, ny, nz" : "nx, ny") + "]",
             c.raw().contains("samples") ? describeJson(samples) : "nothing");
  double total = 1;
  for (int a = 0; a < d; ++a) {
    if (!samples[a].is_number_integer() || samples[a].get<long>() < 2)
      c.failAt("samples", "integers >= 2 (samples per axis)", describeJson(samples[a]));
    ls.samples[a] = static_cast<int>(std::min<long>(samples[a].get<long>(), 1L << 30));
    total *= ls.samples[a];
  }
  c.markUsed("samples");
  if (total > kMaxSamples) c.failAt("samples", "at most 1e8 samples in all", std::to_string(total));
  const Json& values = c.raw().contains("values") ? c.raw()["values"] : Json();
  if (!values.is_array() || values.size() != static_cast<std::size_t>(total))
    c.failAt("values", "an array of " + std::to_string(static_cast<long>(total)) + " numbers (the samples, x fastest)",
             c.raw().contains("values") ? describeJson(values) : "nothing");
  const Config list(values, c.file(), c.pathOf("values"));
  ls.values.reserve(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!values[i].is_number() || !std::isfinite(values[i].get<double>()))
      list.element(i).fail("a finite number", describeJson(values[i]));
    ls.values.push_back(values[i].get<double>());
  }
  c.markUsed("values");
  checkEnclosed(c, "values", ls);
  return ls;
}

// {"file": "name.json"}: the sampled form in its own JSON file (comments allowed), read relative
// to the scene file; its errors name that file.
template <int d>
LevelSet<d> levelSetFromFile(const Config& c) {
  std::filesystem::path path(c.string("file"));
  if (path.is_relative()) path = std::filesystem::path(c.file()).parent_path() / path;
  std::ifstream in(path);
  if (!in || std::filesystem::is_directory(path))
    c.failAt("file", "a readable level-set JSON file {origin, spacing, samples, values}",
             "\"" + path.string() + "\" (cannot be opened)");
  Json doc;
  try {
    doc = Json::parse(in, nullptr, /*allow_exceptions=*/true, /*ignore_comments=*/true);
  } catch (const Json::exception& err) {
    c.failAt("file", "a level-set file in JSON", "\"" + path.string() + "\": " + err.what());
  }
  if (!doc.is_object()) throw SceneError(path.string(), "", "a JSON object {origin, spacing, samples, values}", describeJson(doc));
  const Config fileConfig(doc, path.string(), "");
  LevelSet<d> ls = sampledLevelSet<d>(fileConfig);
  fileConfig.finish();
  return ls;
}

template <int d>
LevelSet<d> fromField(const solvers::SampledField<d>& field, double spacing) {
  LevelSet<d> ls;
  ls.origin = field.origin;
  ls.spacing = spacing;
  ls.samples = field.samples;
  ls.values = field.values;
  return ls;
}

template <int d>
double latticeSize(const std::vector<Eigen::Matrix<double, d, 1>>& points, double spacing) {
  return solvers::latticeAround<d>(points, spacing, kMargin).sampleCount();
}

// {"polygon": [[x, y], ...], "spacing"} (2-D) or {"mesh": "file.obj", "scale", "spacing"} (3-D).
template <int d>
LevelSet<d> generatedLevelSet(const Config& c) {
  using Vec = Eigen::Matrix<double, d, 1>;
  const double spacing = c.number("spacing", Bound::Positive);
  std::vector<Vec> points;
  if constexpr (d == 2) {
    const std::vector<double> flat = pointList<2>(c, "polygon", 3);
    for (std::size_t i = 0; i < flat.size(); i += 2) points.emplace_back(flat[i], flat[i + 1]);
    double area = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Vec& a = points[i];
      const Vec& b = points[(i + 1) % points.size()];
      area += 0.5 * (a.x() * b.y() - a.y() * b.x());
    }
    if (std::abs(area) < 1e-14) c.failAt("polygon", "a closed outline of non-zero area", "collinear or repeated points");
    if (latticeSize<2>(points, spacing) > kMaxSamples)
      c.failAt("spacing", "a spacing giving at most 1e8 samples over the polygon", std::to_string(spacing));
    return fromField<2>(solvers::polygonDistance(points, spacing, kMargin), spacing);
  } else {
    Shape<3> mesh;
    readObj(c, "mesh", mesh);
    const double scale = c.number("scale", 1.0, Bound::Positive);
    for (int i = 0; i < mesh.vertexCount(); ++i) points.push_back(scale * mesh.vertex(i));
    const double samples = latticeSize<3>(points, spacing);
    if (samples > kMaxSamples || samples * (mesh.triangles.size() / 3) > kMaxMeshWork)
      c.failAt("spacing", "a coarser spacing: at most 1e8 samples and 2e10 sample-triangle distances",
               std::to_string(static_cast<long>(samples)) + " samples x " + std::to_string(mesh.triangles.size() / 3) +
                   " triangles");
    return fromField<3>(solvers::meshDistance(points, mesh.triangles, spacing, kMargin), spacing);
  }
}

}  // namespace

template <int d>
void parseLevelSetComponent(World<d>& world, Entity e, const Config& c) {
  const std::string outline = d == 2 ? "polygon" : "mesh";
  int forms = 0;
  for (const char* key : {"values", "file", d == 2 ? "polygon" : "mesh"}) forms += c.has(key);
  if (forms != 1)
    c.fail("exactly one of \"values\" (with origin, spacing, samples), \"file\" (a JSON file of those) or \"" + outline +
               "\" (with spacing)",
           forms == 0 ? "none of them" : std::to_string(forms) + " of them");
  LevelSet<d> ls = c.has("values") ? sampledLevelSet<d>(c) : c.has("file") ? levelSetFromFile<d>(c) : generatedLevelSet<d>(c);
  if (!c.has("values") && !c.has("file")) checkEnclosed(c, outline, ls);  // e.g. a mesh that encloses nothing
  ls.refresh();
  world.add(e, std::move(ls));
}

template void parseLevelSetComponent<2>(World<2>&, Entity, const Config&);
template void parseLevelSetComponent<3>(World<3>&, Entity, const Config&);

}  // namespace monolith
