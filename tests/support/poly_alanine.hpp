#pragma once
// Peptide backbones built from torsions, for tests of secondary structure: the natural extension
// reference frame with Engh & Huber's bond lengths and angles.
#include <cmath>
#include <cstddef>
#include <numbers>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/io/molecule.hpp"

namespace mfr::test {

// The next atom placed from three before it by bond length, angle and torsion (the natural
// extension reference frame, as peptide builders place atoms).
inline glm::dvec3 place(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, double length, double angleDeg,
                        double torsionDeg) {
  const double angle = angleDeg * std::numbers::pi / 180.0, torsion = torsionDeg * std::numbers::pi / 180.0;
  const glm::dvec3 bc = glm::normalize(c - b), n = glm::normalize(glm::cross(b - a, bc)), m = glm::cross(n, bc);
  const glm::dvec3 d(-length * std::cos(angle), length * std::sin(angle) * std::cos(torsion),
                     length * std::sin(angle) * std::sin(torsion));
  return c + d.x * bc + d.y * m + d.z * n;
}

// `count` alanines with backbone torsions φ, ψ (ω = 180°): Engh & Huber bond lengths and angles.
inline std::vector<BackboneResidue> polyAlanine(std::size_t count, double phi, double psi) {
  std::vector<BackboneResidue> out;
  glm::dvec3 n(0.0, 0.0, 0.0), ca(1.458, 0.0, 0.0), c = ca + 1.525 * glm::dvec3(-std::cos(1.94), std::sin(1.94), 0.0);
  for (std::size_t i = 0; i < count; ++i) {
    BackboneResidue r;
    r.chain = "A";
    r.number = static_cast<int>(i + 1);
    r.name = "ALA";
    r.n = n;
    r.ca = ca;
    r.c = c;
    // O in the peptide plane, opposite the next N.
    const glm::dvec3 nextN = place(n, ca, c, 1.329, 116.2, psi);
    r.o = place(nextN, ca, c, 1.231, 120.8, 180.0);
    out.push_back(r);
    const glm::dvec3 nextCa = place(ca, c, nextN, 1.458, 121.7, 180.0);
    const glm::dvec3 nextC = place(c, nextN, nextCa, 1.525, 111.2, phi);
    n = nextN;
    ca = nextCa;
    c = nextC;
  }
  return out;
}

}  // namespace mfr::test
