#include "mfr/scene/cartoon.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "mfr/error.hpp"
#include "mfr/scene/primitives.hpp"
#include "scene/perpendicular.hpp"

namespace mfr {
namespace {

bool finite(const glm::dvec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// The cross-section at a point of the curve: semi-axes along the band's width (a) and thickness
// (b), and the superellipse exponent (2: ellipse; larger: a rectangle with rounded corners).
struct Section {
  double a, b, exponent;
};

struct Segment {
  std::vector<glm::dvec3> points;  // the curve's control points (smoothed along strands)
  std::vector<glm::dvec3> guides;  // unit, sign-consistent; zero where none is known
};

Segment prepare(const std::vector<CartoonResidue>& residues) {
  const std::size_t m = residues.size();
  Segment s;
  s.points.resize(m);
  s.guides.assign(m, glm::dvec3(0.0));
  const auto strandInterior = [&](std::size_t i) {
    return i > 0 && i + 1 < m && residues[i].structure == SecondaryStructure::Strand &&
           residues[i - 1].structure == SecondaryStructure::Strand &&
           residues[i + 1].structure == SecondaryStructure::Strand;
  };
  for (std::size_t i = 0; i < m; ++i)
    s.points[i] = strandInterior(i)
                      ? 0.25 * residues[i - 1].trace + 0.5 * residues[i].trace + 0.25 * residues[i + 1].trace
                      : residues[i].trace;
  // Guides: each residue's C→O, turned to agree with the previous one (in a strand they alternate).
  glm::dvec3 previous(0.0);
  for (std::size_t i = 0; i < m; ++i) {
    if (!residues[i].guide) continue;
    glm::dvec3 g = *residues[i].guide;
    const double len = glm::length(g);
    if (!(len > 1e-9) || !finite(g)) continue;
    g /= len;
    if (glm::dot(g, previous) < 0.0) g = -g;
    s.guides[i] = previous = g;
  }
  std::vector<glm::dvec3> smoothed = s.guides;
  for (std::size_t i = 0; i < m; ++i)
    if (strandInterior(i)) {
      const glm::dvec3 g = s.guides[i - 1] + 2.0 * s.guides[i] + s.guides[i + 1];
      if (glm::length(g) > 1e-9) smoothed[i] = glm::normalize(g);
    }
  s.guides = std::move(smoothed);
  return s;
}

// Catmull–Rom through the points, the ends continued straight; position and derivative at
// parameter u ∈ [0, m − 1].
void evaluate(const std::vector<glm::dvec3>& p, double u, glm::dvec3& position, glm::dvec3& derivative) {
  const auto m = static_cast<std::ptrdiff_t>(p.size());
  auto i = static_cast<std::ptrdiff_t>(std::floor(u));
  i = std::clamp<std::ptrdiff_t>(i, 0, m - 2);
  const double t = u - static_cast<double>(i);
  const auto at = [&](std::ptrdiff_t k) {
    if (k < 0) return 2.0 * p[0] - p[1];
    if (k >= m) return 2.0 * p[static_cast<std::size_t>(m - 1)] - p[static_cast<std::size_t>(m - 2)];
    return p[static_cast<std::size_t>(k)];
  };
  const glm::dvec3 p0 = at(i - 1), p1 = at(i), p2 = at(i + 1), p3 = at(i + 2);
  const glm::dvec3 c1 = -p0 + p2, c2 = 2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3, c3 = -p0 + 3.0 * p1 - 3.0 * p2 + p3;
  position = 0.5 * (2.0 * p1 + c1 * t + c2 * t * t + c3 * t * t * t);
  derivative = 0.5 * (c1 + 2.0 * c2 * t + 3.0 * c3 * t * t);
}

}  // namespace

Mesh cartoonMesh(const std::vector<std::vector<CartoonResidue>>& segments, const CartoonOptions& o) {
  if (o.samplesPerResidue < 1 || o.sides < 3 || !(o.loopRadius > 0.0) || !(o.helixHalfWidth > 0.0) ||
      !(o.helixHalfThickness > 0.0) || !(o.strandHalfWidth > 0.0) || !(o.strandHalfThickness > 0.0) ||
      !(o.arrowScale > 0.0) || !(o.nucleicRadius > 0.0) || !(o.ladderRadius > 0.0))
    throw Error("cartoon", "samples ≥ 1, sides ≥ 3 and positive sizes expected");
  Mesh mesh;
  std::vector<MeshField> fields;
  for (const std::string& name : o.fieldNames) fields.push_back({name, false, 1, {}});
  // The ring's directions (cos, sin), the same for every ring.
  std::vector<std::pair<double, double>> unitRing;
  for (int v = 0; v < o.sides; ++v) {
    const double angle = 2.0 * std::numbers::pi * v / o.sides;
    unitRing.emplace_back(std::cos(angle), std::sin(angle));
  }

  for (const std::vector<CartoonResidue>& residues : segments) {
    const std::size_t m = residues.size();
    if (m < 2) continue;
    for (const CartoonResidue& r : residues) {
      if (!finite(r.trace) || (r.ladder && !finite(*r.ladder)))
        throw Error("cartoon", "a residue's trace point is not finite");
      if (r.values.size() != o.fieldNames.size())
        throw Error("cartoon", "a residue has " + std::to_string(r.values.size()) + " values for " +
                                   std::to_string(o.fieldNames.size()) + " fields");
    }
    const Segment seg = prepare(residues);
    const auto structureAt = [&](std::ptrdiff_t r) {
      return r < 0 || r >= static_cast<std::ptrdiff_t>(m) ? SecondaryStructure::Loop
                                                          : residues[static_cast<std::size_t>(r)].structure;
    };
    // The section at parameter u: the nearest residue's; a strand's last residue is the arrowhead,
    // from 1.5× the band's width halfway before it down to the loop's radius halfway after it.
    const auto sectionAt = [&](double u) -> Section {
      const auto r = static_cast<std::ptrdiff_t>(std::lround(u));
      switch (structureAt(r)) {
        case SecondaryStructure::Helix:
          return {o.helixHalfWidth, o.helixHalfThickness, 2.0};
        case SecondaryStructure::Strand: {
          if (structureAt(r + 1) == SecondaryStructure::Strand || r == 0)
            return {o.strandHalfWidth, o.strandHalfThickness, 8.0};
          const double f = std::clamp(u - (static_cast<double>(r) - 0.5), 0.0, 1.0);  // 0 → 1 over the residue
          const double base = o.arrowScale * o.strandHalfWidth;
          return {base + (o.loopRadius - base) * f, o.strandHalfThickness + (o.loopRadius - o.strandHalfThickness) * f,
                  8.0};
        }
        case SecondaryStructure::Loop:
          break;
      }
      const double radius =
          residues[static_cast<std::size_t>(std::clamp<std::ptrdiff_t>(r, 0, static_cast<std::ptrdiff_t>(m) - 1))]
                  .nucleic
              ? o.nucleicRadius
              : o.loopRadius;
      return {radius, radius, 2.0};
    };

    const std::size_t rings = (m - 1) * static_cast<std::size_t>(o.samplesPerResidue) + 1;
    const auto sides = static_cast<std::size_t>(o.sides);
    const auto base = static_cast<std::uint32_t>(mesh.positions.size());
    glm::dvec3 width = glm::dvec3(0.0), firstCentre(0.0), lastCentre(0.0);
    glm::dvec3 previousTangent(0.0);
    // The residues' values at parameter u, once, for `copies` vertices.
    const auto pushValues = [&](double u, std::size_t copies) {
      const double lo = std::floor(u);
      const auto i = static_cast<std::size_t>(std::clamp(lo, 0.0, static_cast<double>(m - 1)));
      const std::size_t j = std::min(i + 1, m - 1);
      const double t = u - static_cast<double>(i);
      for (std::size_t f = 0; f < fields.size(); ++f) {
        const auto value = static_cast<float>((1.0 - t) * residues[i].values[f] + t * residues[j].values[f]);
        fields[f].values.insert(fields[f].values.end(), copies, value);
      }
    };
    for (std::size_t k = 0; k < rings; ++k) {
      const double u = static_cast<double>(k) / o.samplesPerResidue;
      glm::dvec3 centre, d;
      evaluate(seg.points, u, centre, d);
      glm::dvec3 tangent = glm::length(d) > 1e-12 ? glm::normalize(d) : previousTangent;
      if (glm::length(tangent) < 0.5) tangent = glm::dvec3(0, 0, 1);  // coincident traces: any direction
      // The band's width: the guides interpolated and made perpendicular to the curve; where
      // there is none (nucleic acids) or it runs along the curve, the previous width carried on
      // (parallel transport).
      const auto i = static_cast<std::size_t>(std::clamp(std::floor(u), 0.0, static_cast<double>(m - 2)));
      const double t = u - static_cast<double>(i);
      glm::dvec3 g = (1.0 - t) * seg.guides[i] + t * seg.guides[i + 1];
      if (glm::length(seg.guides[i]) == 0.0) g = seg.guides[i + 1];
      if (glm::length(seg.guides[i + 1]) == 0.0) g = seg.guides[i];
      glm::dvec3 w = g - glm::dot(g, tangent) * tangent;
      if (glm::length(w) < 0.2 * std::max(glm::length(g), 1e-300) || glm::length(g) == 0.0) {
        w = glm::length(width) > 0.0 ? width - glm::dot(width, tangent) * tangent : anyPerpendicular(tangent);
        if (glm::length(w) < 1e-9) w = anyPerpendicular(tangent);
      }
      w = glm::normalize(w);
      // Projected onto the ring's plane, consecutive guides can still point apart (where the curve
      // bends across them); every section is symmetric about its centre, so turning w round keeps
      // the shape and stops the tube pinching there.
      if (k > 0 && glm::dot(w, width) < 0.0) w = -w;
      const glm::dvec3 n = glm::cross(tangent, w);  // (w, n, tangent) right-handed
      width = w;
      previousTangent = tangent;
      if (k == 0) firstCentre = centre;
      lastCentre = centre;

      const Section s = sectionAt(u);
      const auto r = static_cast<std::size_t>(std::clamp(std::lround(u), 0L, static_cast<long>(m - 1)));
      const double e = 2.0 / s.exponent;
      for (const auto& [c, sn] : unitRing) {
        const double x = s.a * std::copysign(std::pow(std::abs(c), e), c);
        const double y = s.b * std::copysign(std::pow(std::abs(sn), e), sn);
        mesh.positions.emplace_back(centre + x * w + y * n);
      }
      mesh.colors.insert(mesh.colors.end(), sides, residues[r].color);
      pushValues(u, sides);
    }
    // Quads between consecutive rings, counter-clockwise seen from outside.
    for (std::size_t k = 0; k + 1 < rings; ++k)
      for (std::size_t v = 0; v < sides; ++v) {
        const auto a = base + static_cast<std::uint32_t>(k * sides + v);
        const auto b = base + static_cast<std::uint32_t>(k * sides + (v + 1) % sides);
        const auto c = static_cast<std::uint32_t>(b + sides), d = static_cast<std::uint32_t>(a + sides);
        mesh.indices.insert(mesh.indices.end(), {a, b, c, a, c, d});
      }
    // Flat end caps of their own vertices (so the smooth normals keep a crisp rim): a fan around
    // the curve's end point, facing back along the curve at the start and forward at the end.
    for (const bool atEnd : {false, true}) {
      const std::size_t ring = atEnd ? rings - 1 : 0;
      const double u = atEnd ? static_cast<double>(m - 1) : 0.0;
      const std::size_t r = atEnd ? m - 1 : 0;
      const auto centreIndex = static_cast<std::uint32_t>(mesh.positions.size());
      mesh.positions.emplace_back(atEnd ? lastCentre : firstCentre);
      for (std::size_t v = 0; v < sides; ++v) mesh.positions.push_back(mesh.positions[base + ring * sides + v]);
      mesh.colors.insert(mesh.colors.end(), sides + 1, residues[r].color);
      pushValues(u, sides + 1);
      for (std::size_t v = 0; v < sides; ++v) {
        const auto a = centreIndex + 1 + static_cast<std::uint32_t>(v);
        const auto b = centreIndex + 1 + static_cast<std::uint32_t>((v + 1) % sides);
        if (atEnd)
          mesh.indices.insert(mesh.indices.end(), {centreIndex, a, b});
        else
          mesh.indices.insert(mesh.indices.end(), {centreIndex, b, a});
      }
    }
    // Ladders: a capped rod from the curve at each nucleotide to its base atom.
    for (std::size_t i = 0; i < m; ++i) {
      if (!residues[i].ladder) continue;
      glm::dvec3 centre, d;
      evaluate(seg.points, static_cast<double>(i), centre, d);
      if (glm::distance(centre, *residues[i].ladder) < 1e-6) continue;
      const Mesh rod = makeTube({centre, *residues[i].ladder}, o.ladderRadius, std::max(o.sides / 2, 6));
      const auto first = static_cast<std::uint32_t>(mesh.positions.size());
      mesh.positions.insert(mesh.positions.end(), rod.positions.begin(), rod.positions.end());
      mesh.colors.insert(mesh.colors.end(), rod.positions.size(), residues[i].color);
      pushValues(static_cast<double>(i), rod.positions.size());
      for (const std::uint32_t index : rod.indices) mesh.indices.push_back(first + index);
    }
  }
  mesh.computeSmoothNormals();
  mesh.fields = std::move(fields);
  return mesh;
}

}  // namespace mfr
