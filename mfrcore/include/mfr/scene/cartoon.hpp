#pragma once
// A polymer chain drawn as a cartoon (PyMOL's `cartoon`, Richardson's ribbon diagrams): a smooth
// curve through the backbone's Cα atoms (a nucleic acid's P), swept by a cross-section that says
// the residue's secondary structure — a flat oval along α-helices, a flat band ending in an
// arrowhead along β-strands, a thin round tube elsewhere —, each run of residues one closed tube.
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/io/molecule.hpp"
#include "mfr/scene/mesh.hpp"

namespace mfr {

struct CartoonResidue {
  glm::dvec3 trace{0.0};            // Cα, or a nucleotide's P
  std::optional<glm::dvec3> guide;  // C→O of the residue: the band's width lies along it
  SecondaryStructure structure = SecondaryStructure::Loop;
  glm::vec4 color{1.0f};
  std::vector<float> values;  // one per CartoonOptions::fieldNames, interpolated along the curve
  // Nucleotides: the backbone is a tube of nucleicRadius, and a rod of ladderRadius runs from the
  // curve at this residue to `ladder` (its base's N1 or N3: PyMOL's cartoon_ladder_mode 1).
  bool nucleic = false;
  std::optional<glm::dvec3> ladder;
};

// Sizes in Å are PyMOL's defaults, as semi-axes: cartoon_oval_length/width (helix),
// cartoon_rect_length/width (strand), cartoon_loop_radius.
struct CartoonOptions {
  int samplesPerResidue = 8;  // rings per residue along the curve
  int sides = 16;             // vertices per ring
  double loopRadius = 0.2;
  double helixHalfWidth = 1.35, helixHalfThickness = 0.25;
  double strandHalfWidth = 1.4, strandHalfThickness = 0.4;
  double arrowScale = 1.5;                          // the arrowhead's base, as a multiple of the strand's width
  double nucleicRadius = 0.5, ladderRadius = 0.25;  // PyMOL's cartoon_tube_radius, cartoon_ladder_radius
  std::vector<std::string> fieldNames;
};

// The cartoon of `segments` (each a run of at least two residues whose traces are consecutive
// along the chain; shorter runs draw nothing): one closed, outward-wound tube per segment with
// flat end caps, per-vertex colours (each residue's, from halfway to the previous one to halfway
// to the next) and the residues' values as point-data fields (Mesh::fields). The curve is the
// Catmull–Rom spline through the traces; along a strand's interior the traces are first averaged
// with their neighbours (¼, ½, ¼) and so are the guides, which flattens the pleat as PyMOL's
// flat sheets do. A nucleotide's ladder is a closed rod of its own, in its residue's colour and
// values. Throws mfr::Error("cartoon", reason) for a non-finite trace or bad options.
Mesh cartoonMesh(const std::vector<std::vector<CartoonResidue>>& segments, const CartoonOptions& options = {});

}  // namespace mfr
