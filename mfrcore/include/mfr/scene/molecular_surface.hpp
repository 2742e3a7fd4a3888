#pragma once
// The solvent-excluded (molecular) surface of a set of atoms — PyMOL's `show surface`, Connolly's
// surface (Richards 1977, Connolly 1983): the boundary of the space a probe sphere cannot enter when
// it rolls over the atoms' van der Waals spheres. Where the probe touches one atom the surface is
// that atom's sphere; where it touches two it is a concave torus; where three, a concave piece of
// the probe's own sphere. Computed on a grid as the level set dist(p, A) = probe radius, A the
// space of accessible probe centres (outside every atom's sphere grown by the probe radius), with
// the distance measured to exact points of A's boundary — the solvent-accessible surface — and
// extracted by VTK's flying edges.
#include <cstddef>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/scene/mesh.hpp"

namespace mfr {

struct SurfaceAtom {
  glm::dvec3 centre{0.0};
  double radius = 0.0;  // van der Waals radius, > 0
};

struct MolecularSurfaceOptions {
  double probeRadius = 1.4;  // water, as PyMOL's solvent_radius and every SES program
  double spacing = 0.3;      // grid spacing (Å): the surface is within a small fraction of it
  // The most grid points one group of atoms may use; a larger group gets a coarser grid (spacing
  // grows until it fits), never a partial surface.
  std::size_t maxGridPoints = std::size_t{1} << 25;
  // Also the surfaces of buried cavities — pockets inside that a probe fits in but cannot reach
  // from outside. Off, as PyMOL (surface_cavity_mode 0) and MSMS draw a molecule by default.
  bool cavities = false;
};

// The solvent-excluded surface of `atoms`, a closed mesh (one component per separate molecule, and
// per buried cavity with options.cavities) whose normals point out of the excluded space and whose
// triangles wind counter-clockwise seen from outside; positions and normals only (colours are the
// caller's). Atoms whose grown spheres (radius + probe) overlap, transitively, form a group; no
// probe touches two groups, so each is computed on a grid of its own. Empty for no atoms. Throws
// mfr::Error("molecular surface", reason) for a non-finite centre, a radius that is not positive and
// finite, options out of range (probe radius or spacing not positive and finite, fewer than 512
// grid points), atoms packed denser than any molecule (more than 400 within reach of one), or a
// group so large that its grid would be coarser than its smallest atom.
Mesh solventExcludedSurface(const std::vector<SurfaceAtom>& atoms, const MolecularSurfaceOptions& options = {});

// The coarsest grid spacing solventExcludedSurface uses for a group of `atoms`: options.spacing,
// or larger where a group's grid would exceed options.maxGridPoints.
double molecularSurfaceSpacing(const std::vector<SurfaceAtom>& atoms, const MolecularSurfaceOptions& options = {});

}  // namespace mfr
