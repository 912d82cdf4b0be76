// Two-way rigid-body/fluid coupling: the FSI step of Sec. 5.4 (see fluid_structure_coupling.h).
#include "systems/fluid_structure_coupling.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "components/level_set.h"
#include "components/shape.h"
#include "systems/fluid_domain.h"
#include "systems/fluid_preconditioner_kind.h"
#include "systems/obstacle_geometry.h"
#include "systems/shape_volume.h"

namespace monolith {

namespace {

constexpr int kAngular(int d) { return d == 2 ? 1 : 3; }

template <int d>
FsiSolver fsiSolverOf(const World<d>& world) {
  const auto* pool = world.template findPool<FsiSolver>();
  return pool && pool->size() > 0 ? pool->components()[0] : FsiSolver{};
}

solvers::FsiPreconditionerKind kindOf(FsiSolver::Preconditioner p) {
  switch (p) {
    case FsiSolver::Preconditioner::None: return solvers::FsiPreconditionerKind::None;
    case FsiSolver::Preconditioner::BlockJacobi: return solvers::FsiPreconditionerKind::BlockJacobi;
    case FsiSolver::Preconditioner::BlockExact: return solvers::FsiPreconditionerKind::BlockExact;
    case FsiSolver::Preconditioner::Schur: return solvers::FsiPreconditionerKind::Schur;
  }
  return solvers::FsiPreconditionerKind::BlockExact;
}

// Writes the structure velocity of body b (dofs from b * (d + angular)) into the body.
template <int d>
void writeBody(RigidBody<d>& body, const Eigen::VectorXd& v, int b) {
  const int n = d + kAngular(d), off = b * n;
  body.v = v.segment(off, d);
  AngularVec<d> w;
  for (int i = 0; i < kAngular(d); ++i) w[i] = v[off + d + i];
  body.setOmega(w);
}

// One coupled solve over `dt` of the grid's face velocities `u` (in/out) with setup.coupling.velocity
// as v* (in) and v^{n+1} (out).
template <int d>
solvers::FsiReport coupledSolve(const World<d>& world, StructureCouplingSetup<d>& setup, double rho, double mu, double dt,
                                Eigen::VectorXd& u, std::unique_ptr<solvers::FluidOperators<d>>& opsOut) {
  const FluidSolverSettings& settings = world.template resource<FluidSolverSettings>();
  auto ops = std::make_unique<solvers::FluidOperators<d>>(
      solvers::buildFluidOperators(setup.domain, solvers::FluidParameters{rho, mu, dt}));
  auto& c = setup.coupling;
  c.constrainedVelocities.resize(c.constrainedFaces.size());
  for (std::size_t k = 0; k < c.constrainedFaces.size(); ++k)
    c.constrainedVelocities[k] = ops->dofs.faceToVelocity[c.constrainedFaces[k]];
  const solvers::PoissonPreconditioner<d> pressure(*ops, poissonPreconditionerKindOf(settings.preconditioner));
  const solvers::CoupledPreconditioner<d> fluid(*ops, pressure,
                                                settings.coupledCutCorrection
                                                    ? solvers::CoupledPreconditionerKind::CutCorrected
                                                    : solvers::CoupledPreconditionerKind::BlockDiagonal);
  solvers::CgSettings cg{settings.maxIterations, settings.tolerance, 0};
  solvers::FsiReport report =
      solvers::fsiProjection(*ops, c, u, cg, &fluid, kindOf(fsiSolverOf(world).preconditioner),
                             poissonPreconditionerKindOf(settings.preconditioner));
  opsOut = std::move(ops);
  return report;
}

// The share of a face's dual cell that holds fluid, for the weight gravity puts on it: 0 inside a
// structure (a viscous neighbour of a fluid face, no fluid cell beside it: its fluid mass would add
// its weight to the body's), 1/2 on a coupling face between a fluid cell and a structure cell,
// else 1. The
// coupling faces keep their whole dual cell's mass beta (Sec. 5.4.2), but a full cell's weight on
// the faces above and below a body would be a column's half cell of fluid too many on each side:
// the body's buoyancy would fall one cell per column short of rho g V (measured: the falling
// cylinder's Stokes speed 14 % too fast at 40 x 160 cells, 1.0 % with the shares).
template <int d>
double fluidShare(const solvers::FluidDomain<d>& domain, int f) {
  if (domain.structureFace.empty() || !domain.structureFace[f]) return 1.0;
  int fluid = 0;
  for (int which = 0; which < 2; ++which) {
    int cell = -1;
    if (domain.faceCell(f, which, cell) && domain.cells[cell] == solvers::CellKind::Fluid) ++fluid;
  }
  return fluid == 0 ? 0.0 : fluid == 1 ? 0.5 : 1.0;
}

// A body's own volume (area in 2-D), 0 without a shape or where its shape has none here.
template <int d>
double bodyVolume(const Shape<d>* shape) {
  return shape ? monolith::shapeVolume(*shape) : 0.0;
}

template <int d>
double fluidDensity(const World<d>& world, Entity grid) {
  const FluidMaterial* m = world.template get<FluidMaterial>(grid);
  return m ? m->density : 1.0;
}
template <int d>
double fluidViscosity(const World<d>& world, Entity grid) {
  const FluidMaterial* m = world.template get<FluidMaterial>(grid);
  return m ? m->viscosity : 0.0;
}

// A deformable's wall seen from a fluid face at x along e (axis b), in cells, weighted by how much
// of the face's dual cell the structure covers across the pair: rays from kSamples points spread
// over the dual cell's section normal to e (kSamples along the one other axis in 2-D, a square of
// them in 3-D), each as far as 1.5 cells. The row's weight squared is w^2 phi / theta for a wall
// covering the fraction phi of the section at the mean distance theta of the rays that hit it, so
// the shear the fluid feels follows the structure's end as it moves inside its cell (a flag's tip
// that covers a quarter of the end cell's top face pulls a quarter of that face's shear) instead of
// jumping by a whole cell's shear when the staircase gains or loses a cell. theta / phi can exceed
// 1 (a weaker row, still of G_mu^T G_mu form: SPD). No ray hits: a weight of 1e-3 w^2.
template <int d>
double deformableWallDistance(const solvers::SimplexLocator<d>& locator, const solvers::MacLayout<d>& layout,
                              const Eigen::Matrix<double, d, 1>& x, int b, const Eigen::Matrix<double, d, 1>& e) {
  constexpr int kPerAxis = d == 2 ? 16 : 4, kSamples = 16;
  constexpr double kReach = 1.5, kNoWall = 1e3;
  double sum = 0;
  int hits = 0;
  for (int k = 0; k < kSamples; ++k) {
    Eigen::Matrix<double, d, 1> p = x;
    int rest = k;
    for (int axis = 0; axis < d; ++axis) {
      if (axis == b) continue;
      p[axis] += ((rest % kPerAxis) + 0.5) / kPerAxis * layout.dx - 0.5 * layout.dx;
      rest /= kPerAxis;
    }
    const double t = locator.rayEntry(p, e, kReach * layout.dx);
    if (!std::isfinite(t)) continue;
    sum += std::max(t / layout.dx, solvers::FluidDomain<d>::kMinWallDistance);
    ++hits;
  }
  if (hits == 0) return kNoWall;
  const double theta = sum / hits, phi = static_cast<double>(hits) / kSamples;
  return std::clamp(theta / phi, solvers::FluidDomain<d>::kMinWallDistance, kNoWall);
}

// "obstacle_wall": "surface" or "cell_boundary" for the coupled structures too: the viscous row
// between a fluid face and a structure face (the tangential coupling of Sec. 5.7 sits on faces half
// a cell inside the staircase, Fig. 5.2) measures the shear against a wall theta cells from the
// fluid face, at the body's true surface along the pair (or at the structure cells' boundary),
// instead of at the structure face one cell away: row weight w / sqrt(theta), the obstacles'
// symmetric Dirichlet treatment (solvers/fluid/operators.h). The wall moves with the structure
// face's velocity (exact for translation; a rotating body's wall speed is taken at the face,
// theta' dx deeper). With "face" (default) nothing is stored and the rows stay the thesis's.
template <int d>
void placeStructureWalls(FluidSolverSettings::ObstacleWall where, const std::vector<ObstacleGeometry<d>>& geometry,
                         StructureCouplingSetup<d>& setup) {
  using Vec = Eigen::Matrix<double, d, 1>;
  if (where == FluidSolverSettings::ObstacleWall::Face || (geometry.empty() && setup.locators.empty())) return;
  auto& domain = setup.domain;
  const auto& layout = domain.layout;
  const int nf = layout.totalFaces(), nb = static_cast<int>(geometry.size());
  if (domain.wallDistance.empty()) domain.wallDistance.assign(static_cast<std::size_t>(nf) * 2 * d, 1.0);
  for (int f = 0; f < nf; ++f) {
    if (domain.faces[f] != solvers::FaceKind::Free || domain.structureFace[f]) continue;
    const auto [a, fc] = layout.faceCoord(f);
    const auto dims = layout.faceDims(a);
    for (int b = 0; b < d; ++b)
      for (int s = 0; s < 2; ++s) {
        auto g = fc;
        g[b] += s ? 1 : -1;
        if (g[b] < 0 || g[b] >= dims[b]) {
          if (!layout.periodic[b]) continue;
          g[b] = (g[b] + dims[b]) % dims[b];
        }
        const int other = layout.faceIndex(a, g);
        if (!domain.structureFace[other]) continue;
        double theta = std::numeric_limits<double>::infinity();
        Vec e = Vec::Zero();
        e[b] = s ? 1.0 : -1.0;
        for (int which = 0; which < 2; ++which) {
          int cell = -1;
          if (!domain.faceCell(other, which, cell) || setup.cellBody[cell] < 0) continue;
          const int body = setup.cellBody[cell];
          if (where == FluidSolverSettings::ObstacleWall::CellBoundary)
            theta = b == a ? 1.0 : 0.5;
          else if (body < nb)
            theta = std::min(theta, std::clamp(geometry[body].rayEntry(layout.faceCenter(a, fc), e, layout.dx) / layout.dx,
                                               solvers::FluidDomain<d>::kMinWallDistance, 1.0));
          else
            theta = std::min(theta, deformableWallDistance(setup.locators[body - nb], layout, layout.faceCenter(a, fc), b, e));
        }
        if (!std::isfinite(theta)) continue;
        domain.wallDistance[solvers::FluidDomain<d>::wallDistanceIndex(f, b, s)] = theta;
      }
  }
}

}  // namespace

template <int d>
StructureCouplingSetup<d> buildStructureCoupling(const World<d>& world, const MacGrid<d>& grid, bool viscous,
                                                 double dt, ForceModelCache<d>& models) {
  using Vec = Eigen::Matrix<double, d, 1>;
  StructureCouplingSetup<d> setup;
  setup.domain = fluidDomainOf(grid);
  const auto& layout = setup.domain.layout;
  const auto* pool = world.template findPool<FluidCoupling<d>>();
  std::vector<ObstacleGeometry<d>> geometry;
  const int ndof = d + kAngular(d);
  std::vector<Entity> coupled = pool ? pool->entities() : std::vector<Entity>{};
  for (Entity e : coupled) {
    const RigidBody<d>* body = world.template get<RigidBody<d>>(e);
    if (!body) continue;
    setup.bodies.push_back(e);
    geometry.emplace_back(world.template get<Shape<d>>(e), world.template get<LevelSet<d>>(e), *body);
  }
  const int nb = static_cast<int>(setup.bodies.size());
  int dofs = nb * ndof, dampingRows = 0;
  for (Entity e : coupled) {
    const Particles<d>* p = world.template get<Particles<d>>(e);
    const SimplexMesh<d>* mesh = world.template get<SimplexMesh<d>>(e);
    const Elasticity* el = world.template get<Elasticity>(e);
    if (world.template has<RigidBody<d>>(e) || !p || !mesh || !el) continue;
    setup.deformables.push_back(e);
    setup.deformableOffset.push_back(dofs);
    dofs += d * p->count();
    setup.locators.emplace_back(p->x, mesh->elements, layout);
    const auto& fm = models.get(e, *p, *mesh, *el);
    setup.models.push_back(&fm);
    setup.rotations.push_back(solvers::deformable::dampingRotations<d>(fm, p->x.data()));
    setup.positions.push_back(p->x);
    setup.dampingOffset.push_back(dampingRows);
    dampingRows += fm.dampingRows();
  }
  const int nd = static_cast<int>(setup.deformables.size());
  // Structure cells: centre inside a body or an element (the first listed rigid body wins where
  // bodies overlap, rigid bodies before deformables).
  setup.cellBody.assign(layout.cellCount(), -1);
  std::vector<std::uint8_t> mask(layout.cellCount(), 0);
  for (int c = 0; c < layout.cellCount(); ++c) {
    const Vec x = layout.cellCenter(layout.cellCoord(c));
    for (int b = 0; b < nb; ++b)
      if (geometry[b].contains(x)) {
        setup.cellBody[c] = b;
        mask[c] = 1;
        break;
      }
  }
  // A structure smaller than a cell may cover no cell centre, and would then never see the
  // fluid: it claims the cells around its centre of mass (a rigid body) or its particles (a
  // deformable body), and moves with the fluid in them as one composite body: the fluid mass
  // rho_f (claimed volume - body volume) joins the structure's mass (and, about the centre, its
  // inertia). Gravity accelerates both alike, so v* is unchanged; the pressure on the claimed
  // cells' faces then carries the buoyancy of the whole claimed volume, which that fluid's weight
  // cancels: the net force is (m - rho_f V) g as it should be, while the drag is that of a
  // one-cell body (resolution-limited). The solve keeps every property (SPD, no energy gain).
  std::vector<double> extraMass(nb + nd, 0.0);
  std::vector<int> claimed(nb + nd, 0);
  auto claim = [&](const Vec& x, int structure) {
    typename solvers::MacLayout<d>::Index cell;
    for (int a = 0; a < d; ++a) {
      cell[a] = static_cast<int>(std::floor((x[a] - layout.origin[a]) / layout.dx));
      if (cell[a] < 0 || cell[a] >= layout.cells[a]) return;
    }
    const int c = layout.cellIndex(cell);
    if (setup.cellBody[c] >= 0 || setup.domain.cells[c] != solvers::CellKind::Fluid) return;
    setup.cellBody[c] = structure;
    mask[c] = 1;
    ++claimed[structure];
  };
  const auto* grids = world.template findPool<MacGrid<d>>();
  const double rhoFluid = fluidDensity(world, grids->entities()[0]);
  for (int b = 0; b < nb; ++b)
    if (std::find(setup.cellBody.begin(), setup.cellBody.end(), b) == setup.cellBody.end()) {
      claim(geometry[b].body().x, b);
      extraMass[b] = std::max(0.0, rhoFluid * (claimed[b] * layout.cellVolume() - bodyVolume(world.template get<Shape<d>>(setup.bodies[b]))));
    }
  for (int k = 0; k < nd; ++k) {
    const std::vector<int> inside = setup.locators[k].cellsInside();
    bool any = false;
    for (int c = 0; c < layout.cellCount(); ++c)
      if (inside[c] >= 0 && setup.cellBody[c] < 0) {
        setup.cellBody[c] = nb + k;
        mask[c] = 1;
        any = true;
      }
    if (!any) {
      const Particles<d>& p = *world.template get<Particles<d>>(setup.deformables[k]);
      for (int i = 0; i < p.count(); ++i) claim(Vec(Eigen::Map<const Vec>(&p.x[d * i])), nb + k);
      double volume = 0;
      for (double v : setup.models[k]->restVolume) volume += v;
      extraMass[nb + k] = std::max(0.0, rhoFluid * (claimed[nb + k] * layout.cellVolume() - volume));
    }
  }
  auto& coupling = setup.coupling;
  coupling.constrainedFaces = solvers::markStructure(setup.domain, mask, viscous);
  if (viscous) placeStructureWalls(world.template resource<FluidSolverSettings>().obstacleWall, geometry, setup);
  const int nc = static_cast<int>(coupling.constrainedFaces.size());

  // J = N J_hat R: one sample per (face, adjacent rigid body) at the face centre, and one per
  // particle (R = I there, its rows zero for fixed particles: they are infinitely massive and at
  // rest); J_hat averages the adjacent structures of a face between two (alpha = 1/2) and holds
  // the barycentric weights of the particles around the face centre (Sec. 5.4.3).
  std::vector<Eigen::Triplet<double>> jhat, jhatParticles, r, rAll, rStatic;
  int samples = 0;
  for (int k = 0; k < nc; ++k) {
    const int f = coupling.constrainedFaces[k];
    int adjacent[2] = {-1, -1}, count = 0;
    for (int which = 0; which < 2; ++which) {
      int cell = -1;
      if (!setup.domain.faceCell(f, which, cell) || setup.cellBody[cell] < 0) continue;
      if (count == 1 && adjacent[0] == setup.cellBody[cell]) continue;
      adjacent[count++] = setup.cellBody[cell];
    }
    const auto [axis, fc] = layout.faceCoord(f);
    const Vec x = layout.faceCenter(axis, fc);
    for (int i = 0; i < count; ++i) {
      if (adjacent[i] < nb) {
        const RigidBody<d>& body = geometry[adjacent[i]].body();
        for (int a = 0; a < d; ++a) jhat.emplace_back(k * d + a, samples * d + a, 1.0 / count);
        // A static body is an infinite-mass structure: its J columns are zero (u = J v = 0 there), its
        // rows kept for the force report only.
        solvers::rigidSampleRows<d>(samples, adjacent[i] * ndof, Vec(x - body.x), body.isStatic ? rStatic : r);
        ++samples;
        continue;
      }
      const int def = adjacent[i] - nb;
      const solvers::SimplexWeights<d> w = setup.locators[def].weightsAt(x);
      const int first = (setup.deformableOffset[def] - nb * ndof) / d;  // particle sample of particle 0
      for (int v = 0; v < d + 1; ++v)
        for (int a = 0; a < d; ++a)
          jhatParticles.emplace_back(k * d + a, (first + w.particle[v]) * d + a, w.weight[v] / count);
    }
  }
  const int particleSamples = (dofs - nb * ndof) / d;
  for (const auto& t : jhatParticles) jhat.emplace_back(t.row(), t.col() + samples * d, t.value());
  for (int k = 0; k < nd; ++k) {
    const Particles<d>& p = *world.template get<Particles<d>>(setup.deformables[k]);
    const int first = (setup.deformableOffset[k] - nb * ndof) / d;
    for (int i = 0; i < p.count(); ++i)
      for (int a = 0; a < d; ++a) {
        const Eigen::Triplet<double> t((samples + first + i) * d + a, setup.deformableOffset[k] + d * i + a, 1.0);
        if (!p.fixed[i]) r.push_back(t);
        rAll.push_back(t);
      }
  }
  const int allSamples = samples + particleSamples;
  solvers::SparseMatrixR Jhat(nc * d, allSamples * d), R(allSamples * d, dofs);
  Jhat.setFromTriplets(jhat.begin(), jhat.end());
  R.setFromTriplets(r.begin(), r.end());
  const solvers::SparseMatrixR NJhat = solvers::faceNormalRows(layout, coupling.constrainedFaces) * Jhat;
  coupling.J = NJhat * R;
  if (nd > 0 || !rStatic.empty()) {
    // The rigid bodies' R rows (all of r before the particles') are shared.
    for (const auto& t : r)
      if (t.row() < samples * d) rAll.push_back(t);
    rAll.insert(rAll.end(), rStatic.begin(), rStatic.end());
    solvers::SparseMatrixR Rall(allSamples * d, dofs);
    Rall.setFromTriplets(rAll.begin(), rAll.end());
    setup.forceJ = NJhat * Rall;
  }

  std::vector<Eigen::Triplet<double>> m, minv;
  coupling.velocity.resize(dofs);
  for (int b = 0; b < nb; ++b) {
    const RigidBody<d>& body = geometry[b].body();
    const int off = b * ndof;
    const double mass = body.mass + extraMass[b];
    for (int a = 0; a < d; ++a) {
      m.emplace_back(off + a, off + a, mass);
      if (!body.isStatic) minv.emplace_back(off + a, off + a, 1.0 / mass);
    }
    InertiaMat<d> I = body.worldInertia(), Iinv = body.worldInverseInertia();
    if (extraMass[b] > 0) {  // the claimed fluid: a square (cube) of side dx about the centre
      I += InertiaMat<d>::Identity() * extraMass[b] * layout.dx * layout.dx / 6.0;
      Iinv = I.inverse();
    }
    for (int i = 0; i < kAngular(d); ++i)
      for (int j = 0; j < kAngular(d); ++j) {
        m.emplace_back(off + d + i, off + d + j, I(i, j));
        if (!body.isStatic) minv.emplace_back(off + d + i, off + d + j, Iinv(i, j));
      }
    coupling.velocity.segment(off, d) = body.v;
    // "buoyancy": "body_volume": the pressure lifts the body by the weight of its structure cells'
    // fluid, rho_f g V_cells; v* takes the difference to its own volume's, dt rho_f (V_cells - V) g / m,
    // so that the net force is (m - rho_f V) g whatever the staircase. The weight the system holds is
    // then exactly the body's plus the fluid's outside the body (the fluid counted in V - V_cells
    // weighs on the walls through the pressure, the same amount taken off the body). Not for a body
    // that claims its cell (its composite mass already balances the claimed fluid) or a shape of
    // unknown volume.
    const double volume = bodyVolume(world.template get<Shape<d>>(setup.bodies[b]));
    if (fsiSolverOf(world).bodyVolumeBuoyancy && !body.isStatic && claimed[b] == 0 && volume > 0) {
      const double cells = static_cast<double>(std::count(setup.cellBody.begin(), setup.cellBody.end(), b));
      coupling.velocity.segment(off, d) += dt * rhoFluid * (cells * layout.cellVolume() - volume) / mass * world.settings().gravity;
    }
    const AngularVec<d> w = body.omega();
    for (int i = 0; i < kAngular(d); ++i) coupling.velocity[off + d + i] = w[i];
  }
  for (int k = 0; k < nd; ++k) {
    // Lumped particle masses; a fixed particle's M^-1 is 0 (infinite mass: v* stays, at rest).
    const Particles<d>& p = *world.template get<Particles<d>>(setup.deformables[k]);
    const int off = setup.deformableOffset[k];
    int free = 0;
    for (int i = 0; i < p.count(); ++i) free += p.fixed[i] ? 0 : 1;
    const double extra = free > 0 ? extraMass[nb + k] / free : 0.0;  // claimed fluid, spread evenly
    for (int i = 0; i < p.count(); ++i)
      for (int a = 0; a < d; ++a) {
        m.emplace_back(off + d * i + a, off + d * i + a, p.m[i] + (p.fixed[i] ? 0.0 : extra));
        if (!p.fixed[i]) minv.emplace_back(off + d * i + a, off + d * i + a, 1.0 / (p.m[i] + extra));
      }
    for (int i = 0; i < d * p.count(); ++i) coupling.velocity[off + i] = p.v[i];
  }
  coupling.mass.resize(dofs, dofs);
  coupling.mass.setFromTriplets(m.begin(), m.end());
  coupling.massInverse.resize(dofs, dofs);
  coupling.massInverse.setFromTriplets(minv.begin(), minv.end());

  // C over this solve's dt (C^T C = -dt D), body by body.
  coupling.dampingRows = dampingRows;
  if (dampingRows > 0) {
    auto fms = setup.models;
    auto rotations = setup.rotations;
    auto positions = setup.positions;
    auto offsets = setup.deformableOffset;
    auto rows = setup.dampingOffset;
    coupling.damping = [=](const Eigen::VectorXd& v, Eigen::VectorXd& y) {
      y.setZero(dampingRows);
      for (std::size_t k = 0; k < fms.size(); ++k)
        if (fms[k]->dampingRows() > 0)
          solvers::deformable::applyDampingFactor<d>(*fms[k], rotations[k], positions[k].data(), dt,
                                                     v.data() + offsets[k], y.data() + rows[k]);
    };
    coupling.dampingTranspose = [=](const Eigen::VectorXd& y, Eigen::VectorXd& f) {
      f.setZero(dofs);
      for (std::size_t k = 0; k < fms.size(); ++k)
        if (fms[k]->dampingRows() > 0)
          solvers::deformable::applyDampingFactorTranspose<d>(*fms[k], rotations[k], positions[k].data(), dt,
                                                              y.data() + rows[k], f.data() + offsets[k]);
    };
  }
  return setup;
}

namespace {

// Writes the solved structure velocities into the coupled rigid bodies and particles.
template <int d>
void writeStructures(World<d>& world, const StructureCouplingSetup<d>& setup) {
  const Eigen::VectorXd& v = setup.coupling.velocity;
  for (std::size_t b = 0; b < setup.bodies.size(); ++b)
    writeBody(*world.template get<RigidBody<d>>(setup.bodies[b]), v, static_cast<int>(b));
  for (std::size_t k = 0; k < setup.deformables.size(); ++k) {
    Particles<d>& p = *world.template get<Particles<d>>(setup.deformables[k]);
    for (std::size_t i = 0; i < p.v.size(); ++i) p.v[i] = v[setup.deformableOffset[k] + static_cast<int>(i)];
  }
}

}  // namespace

template <int d>
void FsiHalfStep<d>::run(World<d>& world, StepContext& ctx) {
  auto& couplings = world.template pool<FluidCoupling<d>>();
  const bool stokes = world.template resource<FluidSolverSettings>().advection == FluidSolverSettings::Advection::None;
  const Eigen::Matrix<double, d, 1> g = world.settings().gravity;
  for (std::size_t i = 0; i < couplings.size(); ++i) {
    FluidCoupling<d>& c = couplings.components()[i];
    const Entity e = couplings.entities()[i];
    if (const RigidBody<d>* body = world.template get<RigidBody<d>>(e)) {
      c.startVelocity = c.halfVelocity = body->v;
      c.startL = c.halfL = body->L;
      c.startPosition = body->x;
      c.startOrientation = body->orientation;
      c.started = true;
      continue;
    }
    // A deformable body (its own Newmark systems skip it): step 1, v^* = v^n + dt/2 M^-1 f(x^n).
    Particles<d>* p = world.template get<Particles<d>>(e);
    const SimplexMesh<d>* mesh = world.template get<SimplexMesh<d>>(e);
    const Elasticity* el = world.template get<Elasticity>(e);
    if (!p || !mesh || !el) continue;
    const auto& fm = cache_.get(e, *p, *mesh, *el);
    c.particleStart = p->v;
    c.particleStartX = p->x;
    c.particleForce = explicitForces(fm, *p, g);
    for (std::size_t k = 0; k < p->v.size(); ++k) p->v[k] += 0.5 * ctx.dt * c.particleForce[k] / p->m[k / d];
    c.particleHalf = p->v;
    c.started = true;
  }
  if (stokes || !fsiSolverOf(world).halfStep) return;

  auto& grids = world.template pool<MacGrid<d>>();
  MacGrid<d>& grid = grids.components()[0];
  const Entity fluidEntity = grids.entities()[0];
  const double rho = fluidDensity(world, fluidEntity), mu = fluidViscosity(world, fluidEntity);
  StructureCouplingSetup<d> setup = buildStructureCoupling(world, grid, mu > 0, 0.5 * ctx.dt, cache_);
  // u^ = u^n + dt/2 g on the free faces (step 2).
  Eigen::VectorXd u = Eigen::Map<const Eigen::VectorXd>(grid.u.data(), grid.u.size());
  for (int f = 0; f < setup.domain.layout.totalFaces(); ++f)
    if (setup.domain.faces[f] == solvers::FaceKind::Free)
      u[f] += 0.5 * ctx.dt * fluidShare(setup.domain, f) * g[setup.domain.layout.faceCoord(f).first];
  std::unique_ptr<solvers::FluidOperators<d>> ops;
  const solvers::FsiReport report = coupledSolve(world, setup, rho, mu, 0.5 * ctx.dt, u, ops);
  writeStructures(world, setup);
  for (std::size_t b = 0; b < setup.bodies.size(); ++b) {
    const RigidBody<d>& body = *world.template get<RigidBody<d>>(setup.bodies[b]);
    FluidCoupling<d>& c = *world.template get<FluidCoupling<d>>(setup.bodies[b]);
    c.halfVelocity = body.v;
    c.halfL = body.L;
  }
  for (Entity e : setup.deformables) world.template get<FluidCoupling<d>>(e)->particleHalf = world.template get<Particles<d>>(e)->v;
  ctx.diagnostics.set("fsi_half_step_iterations", report.solve.iterations);
  ctx.diagnostics.set("fsi_half_step_energy_change", report.kineticEnergyAfter - report.kineticEnergyBefore);
}

template <int d>
void FluidStructureProjection<d>::run(World<d>& world, StepContext& ctx) {
  const bool stokes = world.template resource<FluidSolverSettings>().advection == FluidSolverSettings::Advection::None;
  const Eigen::Matrix<double, d, 1> g = world.settings().gravity;
  auto& couplings = world.template pool<FluidCoupling<d>>();
  // v* = v^n + dt/2 (a^n + a^{n+1}) (step 5): the start velocity plus what the rigid stages added
  // after the half-step solve.
  for (std::size_t i = 0; i < couplings.size(); ++i) {
    FluidCoupling<d>& c = couplings.components()[i];
    const Entity e = couplings.entities()[i];
    if (!c.started) continue;
    c.started = false;
    if (RigidBody<d>* body = world.template get<RigidBody<d>>(e)) {
      if (stokes) {
        body->x = c.startPosition;
        body->orientation = c.startOrientation;
      }
      body->v = c.startVelocity + (body->v - c.halfVelocity);
      body->L = c.startL + (body->L - c.halfL);
      continue;
    }
    Particles<d>* p = world.template get<Particles<d>>(e);
    const SimplexMesh<d>* mesh = world.template get<SimplexMesh<d>>(e);
    const Elasticity* el = world.template get<Elasticity>(e);
    if (!p || !mesh || !el) continue;
    if (stokes) p->x = c.particleStartX;
    const std::vector<double> f = explicitForces(cache_.get(e, *p, *mesh, *el), *p, g);
    // v^n + dt/2 M^-1 (f^n + f^{n+1}), plus any contact change since the half-step solve.
    for (std::size_t k = 0; k < p->v.size(); ++k)
      p->v[k] = c.particleStart[k] + 0.5 * ctx.dt * (c.particleForce[k] + f[k]) / p->m[k / d] +
                (p->v[k] - c.particleHalf[k]);
  }

  auto& grids = world.template pool<MacGrid<d>>();
  MacGrid<d>& grid = grids.components()[0];
  const Entity fluidEntity = grids.entities()[0];
  const double rho = fluidDensity(world, fluidEntity), mu = fluidViscosity(world, fluidEntity);
  StructureCouplingSetup<d> setup = buildStructureCoupling(world, grid, mu > 0, ctx.dt, cache_);
  Eigen::VectorXd u = Eigen::Map<const Eigen::VectorXd>(grid.u.data(), grid.u.size());
  // fluid_gravity added dt g on every face of the grid; keep only the fluid's share of it.
  if (world.template count<MacGrid<d>>() > 0 && g.squaredNorm() > 0)
    for (int f = 0; f < setup.domain.layout.totalFaces(); ++f)
      u[f] -= (1.0 - fluidShare(setup.domain, f)) * ctx.dt * g[setup.domain.layout.faceCoord(f).first];
  std::unique_ptr<solvers::FluidOperators<d>> ops;
  const solvers::FsiReport report = coupledSolve(world, setup, rho, mu, ctx.dt, u, ops);
  const auto& layout = setup.domain.layout;
  const int ndof = d + kAngular(d);
  const int nb = static_cast<int>(setup.bodies.size());
  writeStructures(world, setup);
  // Faces inside the structures that are no unknowns carry the structure's velocity (what
  // advection and the next step's u^n see there, as for an obstacle's faces).
  const Eigen::VectorXd& v = setup.coupling.velocity;
  for (int f = 0; f < layout.totalFaces(); ++f) {
    if (setup.domain.faces[f] != solvers::FaceKind::Inactive) continue;
    int body = -1;
    for (int which = 0; which < 2 && body < 0; ++which) {
      int cell = -1;
      if (setup.domain.faceCell(f, which, cell)) body = setup.cellBody[cell];
    }
    if (body < 0) continue;
    const auto [axis, fc] = layout.faceCoord(f);
    const Eigen::Matrix<double, d, 1> x = layout.faceCenter(axis, fc);
    if (body >= nb) {
      const int k = body - nb;
      const solvers::SimplexWeights<d> w = setup.locators[k].weightsAt(x);
      double value = 0;
      for (int i = 0; i < d + 1; ++i) value += w.weight[i] * v[setup.deformableOffset[k] + d * w.particle[i] + axis];
      u[f] = value;
      continue;
    }
    const Eigen::Matrix<double, d, 1> r = x - world.template get<RigidBody<d>>(setup.bodies[body])->x;
    double w = v[body * ndof + axis];
    if constexpr (d == 2) {
      w += (axis == 0 ? -r.y() : r.x()) * v[body * ndof + 2];
    } else {
      Eigen::Vector3d omega = v.segment<3>(body * ndof + 3);
      w += omega.cross(Eigen::Vector3d(r))[axis];
    }
    u[f] = w;
  }
  Eigen::Map<Eigen::VectorXd>(grid.u.data(), grid.u.size()) = u;
  for (std::size_t i = 0; i < grid.p.size(); ++i) grid.p[i] = report.pressure[static_cast<Eigen::Index>(i)];

  // Diagnostics of t^{n+1}: the fluid's (as project_fluid reports them) and the bodies'.
  auto& out = ctx.diagnostics;
  const Eigen::VectorXd divergence = solvers::constraintDivergence(*ops, u);
  double kinetic = 0, change = 0;
  Eigen::Vector3d momentum = Eigen::Vector3d::Zero();
  const double faceMass = rho * layout.cellVolume();
  for (int f = 0; f < layout.totalFaces(); ++f) {
    if (setup.domain.faces[f] == solvers::FaceKind::Inactive || setup.domain.structureFace[f]) continue;
    kinetic += 0.5 * faceMass * u[f] * u[f];
    momentum[layout.faceCoord(f).first] += faceMass * u[f];
    change = std::max(change, std::abs(u[f] - grid.uPrevious[f]));
  }
  grid.uPrevious = grid.u;
  out.add("kinetic_energy", kinetic);
  out.add("total_energy", kinetic);
  out.add("linear_momentum_x", momentum.x());
  out.add("linear_momentum_y", momentum.y());
  out.add("linear_momentum_z", momentum.z());
  out.set("fluid_kinetic_energy", kinetic);
  out.set("fluid_solver_iterations", report.solve.iterations);
  out.set("fluid_solver_relative_residual", report.solve.relativeResidual());
  out.set("fluid_divergence_max", (divergence.size() > 0 ? divergence.cwiseAbs().maxCoeff() : 0.0) / layout.cellVolume());
  out.set("fluid_velocity_change", change / ctx.dt);
  out.set("fluid_cfl", u.cwiseAbs().maxCoeff() * ctx.dt / layout.dx);
  out.set("fsi_solver_iterations", report.solve.iterations);
  out.set("fsi_energy_change", report.kineticEnergyAfter - report.kineticEnergyBefore);
  out.set("fsi_coupling_faces", setup.coupling.constraintCount());
  static const char* axes[3] = {"_x", "_y", "_z"};
  if (setup.coupling.dampingRows > 0) out.set("fsi_damping_work", report.dampingWork);
  // The impulse on every structure dof, static bodies and a deformable's fixed particles included.
  const Eigen::VectorXd allImpulse = setup.forceJ.rows() == 0 ? report.structureImpulse
                                                              : Eigen::VectorXd(setup.forceJ.transpose() * report.lambda);
  Eigen::Matrix<double, d, 1> totalForce = Eigen::Matrix<double, d, 1>::Zero();
  for (std::size_t k = 0; k < setup.deformables.size(); ++k) {
    // The fluid's force on a deformable body: the sum of -J_all^T W^T lambda over its particles,
    // fixed ones included (the force its support takes).
    const std::string prefix = "fsi_" + world.name(setup.deformables[k]);
    const int off = setup.deformableOffset[k];
    const int n = world.template get<Particles<d>>(setup.deformables[k])->count();
    for (int a = 0; a < d; ++a) {
      double force = 0;
      for (int i = 0; i < n; ++i) force -= allImpulse[off + d * i + a];
      out.set(prefix + "_force" + axes[a], force / ctx.dt);
      totalForce[a] += force / ctx.dt;
    }
    const int track = world.template get<FluidCoupling<d>>(setup.deformables[k])->trackParticle;
    if (track >= 0 && track < n)
      for (int a = 0; a < d; ++a)
        out.set(prefix + "_track" + axes[a], world.template get<Particles<d>>(setup.deformables[k])->x[d * track + a]);
  }
  for (std::size_t b = 0; b < setup.bodies.size(); ++b) {
    const std::string prefix = "fsi_" + world.name(setup.bodies[b]);
    const int off = static_cast<int>(b) * ndof;
    // The fluid's impulse on the body is -J^T W^T lambda (eq. 5.11).
    const Eigen::VectorXd force = -allImpulse.segment(off, ndof) / ctx.dt;
    const Eigen::Matrix<double, d, 1> x = world.template get<RigidBody<d>>(setup.bodies[b])->x;
    for (int a = 0; a < d; ++a) {
      out.set(prefix + "_position" + axes[a], x[a]);
      out.set(prefix + "_velocity" + axes[a], v[off + a]);
      out.set(prefix + "_force" + axes[a], force[a]);
      totalForce[a] += force[a];
    }
    if constexpr (d == 2) {
      out.set(prefix + "_angular_velocity_z", v[off + 2]);
      out.set(prefix + "_torque_z", force[2]);
    } else {
      for (int a = 0; a < 3; ++a) {
        out.set(prefix + "_angular_velocity" + axes[a], v[off + 3 + a]);
        out.set(prefix + "_torque" + axes[a], force[3 + a]);
      }
    }
  }
  // The fluid's force on all coupled structures together (a cylinder and its flag: drag, lift).
  for (int a = 0; a < d; ++a) out.set(std::string("fsi_total_force") + axes[a], totalForce[a]);
}

template <int d>
double FluidStructureProjection<d>::unitCflDt(const World<d>& world) const {
  const auto* grids = world.template findPool<MacGrid<d>>();
  const auto* couplings = world.template findPool<FluidCoupling<d>>();
  if (!grids || grids->size() == 0 || !couplings) return std::numeric_limits<double>::infinity();
  const double dx = grids->components()[0].dx;
  double speed = 0;
  for (Entity e : couplings->entities()) {
    const RigidBody<d>* body = world.template get<RigidBody<d>>(e);
    const Shape<d>* shape = world.template get<Shape<d>>(e);
    if (!body) {
      if (const Particles<d>* p = world.template get<Particles<d>>(e))
        for (int i = 0; i < p->count(); ++i)
          speed = std::max(speed, Eigen::Map<const Eigen::Matrix<double, d, 1>>(&p->v[d * i]).norm());
      continue;
    }
    double reach = 0;
    if (shape) reach = ObstacleGeometry<d>(shape, world.template get<LevelSet<d>>(e), *body).boundingRadius();
    speed = std::max(speed, body->v.norm() + body->omega().norm() * reach);
  }
  return speed > 0 ? dx / speed : std::numeric_limits<double>::infinity();
}

template StructureCouplingSetup<2> buildStructureCoupling<2>(const World<2>&, const MacGrid<2>&, bool, double,
                                                              ForceModelCache<2>&);
template StructureCouplingSetup<3> buildStructureCoupling<3>(const World<3>&, const MacGrid<3>&, bool, double,
                                                              ForceModelCache<3>&);
template class FsiHalfStep<2>;
template class FsiHalfStep<3>;
template class FluidStructureProjection<2>;
template class FluidStructureProjection<3>;

}  // namespace monolith
