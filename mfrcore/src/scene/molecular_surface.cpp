// The solvent-excluded surface (Richards 1977; Connolly 1983) as a level set on a grid. A point p
// is excluded when no probe sphere of radius r_p centred in the accessible space A touches it:
// A = {c : |c − a_i| ≥ R_i for every atom i}, R_i = r_i + r_p, so p is excluded exactly when
// dist(p, A) ≥ r_p. The grid holds f(p) = dist(p, A) − r_p and VTK's flying edges extracts f = 0.
// dist(p, A) for p inside the solvent-accessible surface (SAS, ∂A) is the distance to ∂A, measured
// to points that lie exactly on it: the projections of the grid points just outside it onto their
// nearest grown sphere (the nearest point of a union of balls to an outside point is on the union's
// boundary), plus points on every circle where two grown spheres meet and no third covers them —
// the probe centres of the concave tori, which projections alone would only approach to within a
// grid step. The probe's own concave patches (three atoms) are measured to the crease points
// around them.
#include "mfr/scene/molecular_surface.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <numbers>
#include <string>
#include <thread>

#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkStaticPointLocator.h>

#include "mfr/error.hpp"
#include "mfr/scene/contour.hpp"
#include "mfr/scene/volume.hpp"
#include "scene/geodesic_sphere.hpp"
#include "scene/perpendicular.hpp"
#include "scene/point_grid.hpp"

namespace mfr {
namespace {

constexpr const char* kWhat = "molecular surface";
// More atoms than this within reach of one grown sphere is no molecule (a protein's have about 100).
constexpr std::size_t kMaxNeighbours = 400;

void check(const std::vector<SurfaceAtom>& atoms, const MolecularSurfaceOptions& options) {
  if (!(options.probeRadius > 0.0 && std::isfinite(options.probeRadius)))
    throw Error(kWhat, "the probe radius must be positive and finite");
  if (!(options.spacing > 0.0 && std::isfinite(options.spacing)))
    throw Error(kWhat, "the grid spacing must be positive and finite");
  if (options.maxGridPoints < 512) throw Error(kWhat, "at least 512 grid points are needed");
  for (const SurfaceAtom& a : atoms) {
    if (!std::isfinite(a.centre.x) || !std::isfinite(a.centre.y) || !std::isfinite(a.centre.z))
      throw Error(kWhat, "an atom's centre is not finite");
    if (!(a.radius > 0.0 && std::isfinite(a.radius))) throw Error(kWhat, "an atom's radius is not positive and finite");
  }
}

// The box of the grown spheres.
void grownBounds(const std::vector<SurfaceAtom>& atoms, double probe, glm::dvec3& lo, glm::dvec3& hi) {
  lo = glm::dvec3(std::numeric_limits<double>::infinity());
  hi = -lo;
  for (const SurfaceAtom& a : atoms) {
    lo = glm::min(lo, a.centre - (a.radius + probe));
    hi = glm::max(hi, a.centre + (a.radius + probe));
  }
}

// Grid points per axis for a box at spacing h: two points of margin on each side, so that every
// point of the SAS has grid points outside it and the outermost layer is outside.
glm::ivec3 gridDims(const glm::dvec3& lo, const glm::dvec3& hi, double h) {
  const glm::dvec3 n = glm::ceil((hi - lo) / h) + 5.0;
  return {static_cast<int>(n.x), static_cast<int>(n.y), static_cast<int>(n.z)};
}

// Union-find over indices 0 … n − 1, with path halving: the connected components of a mesh, and
// the groups of overlapping atoms.
class DisjointSets {
 public:
  explicit DisjointSets(std::size_t n) : parent_(n) {
    for (std::uint32_t i = 0; i < parent_.size(); ++i) parent_[i] = i;
  }
  std::uint32_t root(std::uint32_t x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }
  void join(std::uint32_t a, std::uint32_t b) { parent_[root(b)] = root(a); }

 private:
  std::vector<std::uint32_t> parent_;
};

// The mesh without its buried cavities. A cavity's surface is a closed component inside the
// molecule's whose normals point into the cavity (out of the excluded space around it), so the
// volume it encloses by its winding is negative; the outer surface of each molecule encloses a
// positive one.
Mesh withoutCavities(const Mesh& mesh) {
  DisjointSets sets(mesh.positions.size());
  const auto root = [&](std::uint32_t x) { return sets.root(x); };
  for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    sets.join(mesh.indices[t], mesh.indices[t + 1]);
    sets.join(mesh.indices[t], mesh.indices[t + 2]);
  }
  std::vector<double> volume(mesh.positions.size(), 0.0);  // per component, at its root
  for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const glm::dvec3 a(mesh.positions[mesh.indices[t]]), b(mesh.positions[mesh.indices[t + 1]]),
        c(mesh.positions[mesh.indices[t + 2]]);
    volume[root(mesh.indices[t])] += glm::dot(a, glm::cross(b, c)) / 6.0;
  }
  Mesh out;
  std::vector<std::uint32_t> index(mesh.positions.size(), UINT32_MAX);
  for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    if (!(volume[root(mesh.indices[t])] > 0.0)) continue;
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = mesh.indices[t + static_cast<std::size_t>(k)];
      if (index[v] == UINT32_MAX) {
        index[v] = static_cast<std::uint32_t>(out.positions.size());
        out.positions.push_back(mesh.positions[v]);
        out.normals.push_back(mesh.normals[v]);
      }
      out.indices.push_back(index[v]);
    }
  }
  return out;
}

// Atoms whose grown spheres overlap, transitively: groups whose surfaces are independent (no probe
// touches two of them), each drawn on a grid of its own — so that a stray ion does not coarsen the
// grid of a chain, nor a part's far-apart ligands make one large, empty grid. Throws when atoms
// are packed denser than any molecule (which would make the crease search quadratic).
std::vector<std::vector<SurfaceAtom>> groupsOf(const std::vector<SurfaceAtom>& atoms, double probe) {
  std::vector<glm::dvec3> centres;
  double largest = 0.0;
  for (const SurfaceAtom& a : atoms) {
    centres.push_back(a.centre);
    largest = std::max(largest, a.radius + probe);
  }
  const PointGrid grid(centres, 2.0 * largest);
  DisjointSets sets(atoms.size());
  for (std::size_t a = 0; a < atoms.size(); ++a) {
    const double grown = atoms[a].radius + probe;
    std::size_t near = 0;
    grid.forEachWithin(atoms[a].centre, grown + largest, [&](std::uint32_t b, double d2) {
      ++near;
      const double reach = grown + atoms[b].radius + probe;
      if (d2 < reach * reach) sets.join(static_cast<std::uint32_t>(a), b);
    });
    if (near > kMaxNeighbours)
      throw Error(kWhat, std::to_string(near - 1) + " atoms within " +
                             std::to_string(static_cast<int>(grown + largest)) +
                             " Å of one: packed denser than any molecule (a protein's atoms have about 100)");
  }
  std::vector<std::vector<SurfaceAtom>> groups;
  std::vector<std::size_t> groupOf(atoms.size(), SIZE_MAX);
  for (std::size_t a = 0; a < atoms.size(); ++a) {
    std::size_t& g = groupOf[sets.root(static_cast<std::uint32_t>(a))];
    if (g == SIZE_MAX) {
      g = groups.size();
      groups.emplace_back();
    }
    groups[g].push_back(atoms[a]);
  }
  return groups;
}

// The grid spacing of one group: options.spacing, or the smallest larger one whose grid fits in
// options.maxGridPoints and VolumeGrid's points per axis. Throws when that is coarser than the
// group's smallest atom (its surface would fall between the grid points).
double groupSpacing(const std::vector<SurfaceAtom>& atoms, const MolecularSurfaceOptions& options) {
  glm::dvec3 lo, hi;
  grownBounds(atoms, options.probeRadius, lo, hi);
  const glm::dvec3 extent = hi - lo;
  if (!std::isfinite(extent.x) || !std::isfinite(extent.y) || !std::isfinite(extent.z))
    throw Error(kWhat, "the atoms' coordinates are too large");
  const auto limit = static_cast<double>(options.maxGridPoints);
  const auto perAxis = static_cast<double>(VolumeGrid::kMaxPointsPerAxis);
  const auto fits = [&](double s) {
    const glm::dvec3 n = glm::ceil(extent / s) + 5.0;
    return n.x * n.y * n.z <= limit && std::max({n.x, n.y, n.z}) <= perAxis;
  };
  // From below by the closed forms (points ≥ Π extent/h, per axis ≥ extent/h + 5), then up by 5 %
  // steps: a few at most, since the margin's share is small once it does not fit.
  double h = std::max({options.spacing, std::cbrt(extent.x * extent.y * extent.z / limit),
                       std::max({extent.x, extent.y, extent.z}) / (perAxis - 6.0)});
  for (int step = 0; step < 1000 && !fits(h); ++step) h *= 1.05;
  double smallest = std::numeric_limits<double>::infinity();
  for (const SurfaceAtom& a : atoms) smallest = std::min(smallest, a.radius);
  if (!fits(h) || h > smallest)
    throw Error(kWhat, std::to_string(atoms.size()) + " overlapping atoms span " +
                           std::to_string(static_cast<long long>(std::max({extent.x, extent.y, extent.z}))) +
                           " Å: a grid of at most " + std::to_string(options.maxGridPoints) +
                           " points would be coarser than their smallest atom");
  return h;
}

Mesh groupSurface(const std::vector<SurfaceAtom>& atoms, const MolecularSurfaceOptions& options);

// A lone atom's solvent-excluded surface: its van der Waals sphere (no probe touches it and another
// atom), made directly as a geodesic sphere with edges of about h and at least 1,280 triangles
// (frequency 8: 0.48 % short in area), every vertex shared as on the grid's surfaces. Its
// triangles are nearly equilateral; a latitude–longitude sphere's pole triangles were slivers
// (aspect ratio up to 8). On grids, 10,000 lone ions took 127 s.
Mesh loneAtomSurface(const SurfaceAtom& atom, double h) {
  // The projected grid's longest edges, at the faces' centres, are 1.32 / frequency (radius 1).
  const double wanted = std::ceil(1.32 * atom.radius / h);
  const int frequency = static_cast<int>(std::clamp(wanted, 8.0, 256.0));
  // One unit sphere per frequency for the whole process: 10,000 lone ions at one spacing build it
  // once (building it per atom cost 0.5 ms each, more than the rest of the atom's work).
  static std::mutex mutex;
  static std::map<int, std::shared_ptr<const UnitSphere>> spheres;
  std::shared_ptr<const UnitSphere> shared;
  {
    const std::lock_guard<std::mutex> lock(mutex);
    auto& entry = spheres[frequency];
    if (!entry) entry = std::make_shared<const UnitSphere>(geodesicSphere(frequency));
    shared = entry;
  }
  const UnitSphere& unit = *shared;
  Mesh m;
  m.positions.reserve(unit.vertices.size());
  m.normals.reserve(unit.vertices.size());
  for (const glm::dvec3& n : unit.vertices) {
    m.positions.emplace_back(atom.centre + atom.radius * n);
    m.normals.emplace_back(n);
  }
  m.indices = unit.indices;
  return m;
}

}  // namespace

double molecularSurfaceSpacing(const std::vector<SurfaceAtom>& atoms, const MolecularSurfaceOptions& options) {
  check(atoms, options);
  double h = options.spacing;
  for (const std::vector<SurfaceAtom>& group : groupsOf(atoms, options.probeRadius))
    h = std::max(h, groupSpacing(group, options));
  return h;
}

Mesh solventExcludedSurface(const std::vector<SurfaceAtom>& atoms, const MolecularSurfaceOptions& options) {
  check(atoms, options);
  Mesh out;
  for (const std::vector<SurfaceAtom>& group : groupsOf(atoms, options.probeRadius)) {
    const Mesh mesh =
        group.size() == 1 ? loneAtomSurface(group[0], groupSpacing(group, options)) : groupSurface(group, options);
    const auto base = static_cast<std::uint32_t>(out.positions.size());
    out.positions.insert(out.positions.end(), mesh.positions.begin(), mesh.positions.end());
    out.normals.insert(out.normals.end(), mesh.normals.begin(), mesh.normals.end());
    for (const std::uint32_t i : mesh.indices) out.indices.push_back(base + i);
  }
  return out;
}

namespace {

Mesh groupSurface(const std::vector<SurfaceAtom>& atoms, const MolecularSurfaceOptions& options) {
  const double h = groupSpacing(atoms, options);
  const double probe = options.probeRadius;
  glm::dvec3 lo, hi;
  grownBounds(atoms, probe, lo, hi);
  const glm::dvec3 origin = lo - 2.0 * h;
  const glm::ivec3 dims = gridDims(lo, hi, h);
  const auto nx = static_cast<std::size_t>(dims.x), ny = static_cast<std::size_t>(dims.y),
             nz = static_cast<std::size_t>(dims.z);
  const auto at = [&](int i, int j, int k) {
    return (static_cast<std::size_t>(k) * ny + static_cast<std::size_t>(j)) * nx + static_cast<std::size_t>(i);
  };
  const auto position = [&](int i, int j, int k) { return origin + h * glm::dvec3(i, j, k); };

  // depth(p) = max_i (R_i − |p − a_i|): > 0 inside the SAS, a lower bound of the distance to its
  // boundary there; outside, minus the distance to the nearest grown sphere, whose index is kept.
  // Every grid point within 1.5 h of a grown sphere is visited, which covers every point next to
  // the inside (those are within h of it).
  std::vector<float> depth(nx * ny * nz, -std::numeric_limits<float>::infinity());
  std::vector<std::int32_t> nearest(depth.size(), -1);
  double largest = 0.0;
  for (std::size_t a = 0; a < atoms.size(); ++a) {
    const glm::dvec3 c = atoms[a].centre;
    const double grown = atoms[a].radius + probe, reach = grown + 1.5 * h;
    largest = std::max(largest, grown);
    const glm::ivec3 from = glm::max(glm::ivec3(glm::floor((c - reach - origin) / h)), glm::ivec3(0));
    const glm::ivec3 to = glm::min(glm::ivec3(glm::ceil((c + reach - origin) / h)), dims - 1);
    for (int k = from.z; k <= to.z; ++k)
      for (int j = from.y; j <= to.y; ++j)
        for (int i = from.x; i <= to.x; ++i) {
          const glm::dvec3 d = position(i, j, k) - c;
          const double d2 = glm::dot(d, d);
          if (d2 > reach * reach) continue;
          const auto value = static_cast<float>(grown - std::sqrt(d2));
          const std::size_t n = at(i, j, k);
          if (value > depth[n]) {
            depth[n] = value;
            nearest[n] = static_cast<std::int32_t>(a);
          }
        }
  }

  // Points on the SAS: each grid point outside it next to one inside, projected onto its nearest
  // grown sphere.
  vtkNew<vtkPoints> samples;
  samples->SetDataTypeToDouble();
  for (int k = 1; k + 1 < dims.z; ++k)
    for (int j = 1; j + 1 < dims.y; ++j)
      for (int i = 1; i + 1 < dims.x; ++i) {
        const std::size_t n = at(i, j, k);
        if (depth[n] > 0.0f || nearest[n] < 0) continue;
        const bool nextToInside = depth[at(i - 1, j, k)] > 0.0f || depth[at(i + 1, j, k)] > 0.0f ||
                                  depth[at(i, j - 1, k)] > 0.0f || depth[at(i, j + 1, k)] > 0.0f ||
                                  depth[at(i, j, k - 1)] > 0.0f || depth[at(i, j, k + 1)] > 0.0f;
        if (!nextToInside) continue;
        const SurfaceAtom& s = atoms[static_cast<std::size_t>(nearest[n])];
        const glm::dvec3 d = position(i, j, k) - s.centre;
        const double length = glm::length(d);
        if (!(length > 0.0)) continue;
        const glm::dvec3 q = s.centre + (s.radius + probe) / length * d;
        samples->InsertNextPoint(q.x, q.y, q.z);
      }

  // Points on the circles where two grown spheres meet, where no third one covers them, every
  // h/2 along the circle. Any sphere that covers a point of atom a's circle has its centre within
  // R_a + R_max of a's.
  std::vector<glm::dvec3> centres;
  centres.reserve(atoms.size());
  for (const SurfaceAtom& a : atoms) centres.push_back(a.centre);
  const PointGrid atomGrid(centres, 2.0 * largest);
  std::vector<std::size_t> candidates;
  for (std::size_t a = 0; a < atoms.size(); ++a) {
    const glm::dvec3 ca = atoms[a].centre;
    const double ra = atoms[a].radius + probe;
    candidates.clear();
    atomGrid.forEachWithin(ca, ra + largest, [&](std::uint32_t b, double) {
      if (b != a) candidates.push_back(b);
    });
    for (const std::size_t b : candidates) {
      if (b < a) continue;  // each pair once
      const glm::dvec3 cb = atoms[b].centre;
      const double rb = atoms[b].radius + probe;
      const double d = glm::length(cb - ca);
      if (!(d < ra + rb) || !(d > std::abs(ra - rb))) continue;  // apart, or one inside the other
      const glm::dvec3 u = (cb - ca) / d;
      const double x = (d * d + ra * ra - rb * rb) / (2.0 * d);
      const double rho = std::sqrt(std::max(0.0, ra * ra - x * x));
      const glm::dvec3 m = ca + x * u;
      const glm::dvec3 v = anyPerpendicular(u), w = glm::cross(u, v);
      const int count = std::max(8, static_cast<int>(std::ceil(2.0 * std::numbers::pi * rho / (0.5 * h))));
      for (int t = 0; t < count; ++t) {
        const double angle = 2.0 * std::numbers::pi * t / count;
        const glm::dvec3 q = m + rho * (std::cos(angle) * v + std::sin(angle) * w);
        const bool covered = std::any_of(candidates.begin(), candidates.end(), [&](std::size_t c) {
          if (c == b) return false;
          const double rc = atoms[c].radius + probe;
          const glm::dvec3 e = q - atoms[c].centre;
          return glm::dot(e, e) < rc * rc * (1.0 - 1e-12);
        });
        if (!covered) samples->InsertNextPoint(q.x, q.y, q.z);
      }
    }
  }

  auto grid = std::make_shared<VolumeGrid>();
  grid->dims = dims;
  grid->values.assign(depth.size(), static_cast<float>(-probe));
  if (samples->GetNumberOfPoints() > 0) {
    vtkNew<vtkPolyData> sampleSet;
    sampleSet->SetPoints(samples);
    vtkNew<vtkStaticPointLocator> sampleLocator;
    sampleLocator->SetDataSet(sampleSet);
    sampleLocator->BuildLocator();
    // Deeper than r_p + 2h (depth is a lower bound of the distance), f > 2h: no crossing there.
    // The queries — most of the time — in slabs of z on every core (the locator's queries are
    // thread-safe once it is built).
    const double near = probe + 2.0 * h, search = probe + 3.0 * h;
    const auto slabs = [&](int kBegin, int kEnd) {
      for (int k = kBegin; k < kEnd; ++k)
        for (int j = 0; j < dims.y; ++j)
          for (int i = 0; i < dims.x; ++i) {
            const std::size_t n = at(i, j, k);
            if (!(depth[n] > 0.0f)) continue;
            float f = static_cast<float>(2.0 * h);
            if (static_cast<double>(depth[n]) < near) {
              const glm::dvec3 p = position(i, j, k);
              double query[3] = {p.x, p.y, p.z}, d2 = 0.0;
              if (sampleLocator->FindClosestPointWithinRadius(search, query, d2) >= 0)
                f = static_cast<float>(std::min(std::sqrt(d2) - probe, 2.0 * h));
            }
            grid->values[n] = f;
          }
    };
    // Threads only where they pay: a lone ion's grid is done before they would have started.
    const int threads = depth.size() < (std::size_t{1} << 20)
                            ? 1
                            : std::clamp(static_cast<int>(std::thread::hardware_concurrency()), 1, dims.z);
    {
      std::vector<std::jthread> pool;  // joined when it goes, also if starting one throws
      for (int t = 1; t < threads; ++t) pool.emplace_back(slabs, dims.z * t / threads, dims.z * (t + 1) / threads);
      slabs(0, dims.z / threads);
    }
  }
  depth = {};
  nearest = {};

  Volume volume;
  volume.name = kWhat;
  volume.origin = origin;
  volume.spacing = glm::dvec3(h);
  volume.grid = grid;
  Mesh mesh = contourVolume(volume, 0.0);
  return options.cavities ? mesh : withoutCavities(mesh);
}

}  // namespace

}  // namespace mfr
