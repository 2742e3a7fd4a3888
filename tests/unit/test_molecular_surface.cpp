// The solvent-excluded surface (scene/molecular_surface.hpp) against closed forms: one atom's is
// its van der Waals sphere; two atoms the probe cannot pass between give two spherical caps joined
// by a concave torus (Connolly 1983), whose areas follow from the circle the probe's centre runs
// along; two atoms the probe passes between give two whole spheres. And what holds for any
// structure: the surface is closed, wound outwards, outside every van der Waals sphere and inside
// the solvent-accessible one; and bad input is refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "mfr/error.hpp"
#include "mfr/scene/measure.hpp"
#include "mfr/scene/molecular_surface.hpp"

namespace mfr::test {
namespace {

constexpr double kPi = std::numbers::pi;

SurfaceMeasures measure(const Mesh& mesh) {
  return measureSurface(mesh, glm::dmat4(1.0));
}

// The SES area of two atoms (radii r1, r2, centres d apart) with a probe of radius rp that cannot
// pass between them (d < r1 + r2 + 2rp) and whose centre circle stays off the axis (ρ > rp): the
// cap of each sphere beyond the probe's contact circle, plus the torus the probe's arc between
// the two contact points sweeps around the axis (Pappus: 2π ∫ radial distance · rp dφ).
double twoAtomSesArea(double r1, double r2, double d, double rp) {
  const double R1 = r1 + rp, R2 = r2 + rp;
  const double x = (d * d + R1 * R1 - R2 * R2) / (2.0 * d);  // probe circle's place on the axis
  const double rho = std::sqrt(R1 * R1 - x * x);             // and its radius
  const double cap1 = 2.0 * kPi * r1 * r1 * (1.0 + x / R1);
  const double cap2 = 2.0 * kPi * r2 * r2 * (1.0 + (d - x) / R2);
  // Directions from the probe's centre (x, ρ) to the contact points, as angles in the meridian
  // plane (axial, radial).
  const double phiA = std::atan2(-rho / R1, -x / R1), phiB = std::atan2(-rho / R2, (d - x) / R2);
  const double torus = 2.0 * kPi * rp * (rho * (phiB - phiA) - rp * (std::cos(phiB) - std::cos(phiA)));
  return cap1 + cap2 + torus;
}

// The volume the same SES encloses, integrated over the meridian half-plane (axial a, radial r)
// by Pappus (V = 2π ∬ r da dr) with exact membership: inside either van der Waals disc, or inside
// the triangle of the two centres and the probe's centre but outside the probe's disc — the region
// under the torus's arc.
double twoAtomSesVolume(double r1, double r2, double d, double rp) {
  const double R1 = r1 + rp, R2 = r2 + rp;
  const double x = (d * d + R1 * R1 - R2 * R2) / (2.0 * d), rho = std::sqrt(R1 * R1 - x * x);
  const auto side = [](double ax, double ay, double bx, double by, double px, double py) {
    return (bx - ax) * (py - ay) - (by - ay) * (px - ax);
  };
  const int n = 1500;
  const double a0 = -r1, a1 = d + r2, top = std::max({r1, r2, rho});
  const double da = (a1 - a0) / n, dr = top / n;
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    const double a = a0 + (i + 0.5) * da;
    for (int j = 0; j < n; ++j) {
      const double r = (j + 0.5) * dr;
      const double s1 = side(0, 0, x, rho, a, r), s2 = side(x, rho, d, 0, a, r), s3 = side(d, 0, 0, 0, a, r);
      const bool inTriangle = (s1 <= 0 && s2 <= 0 && s3 <= 0) || (s1 >= 0 && s2 >= 0 && s3 >= 0);
      if (a * a + r * r <= r1 * r1 || (a - d) * (a - d) + r * r <= r2 * r2 ||
          (inTriangle && (a - x) * (a - x) + (r - rho) * (r - rho) > rp * rp))
        sum += r;
    }
  }
  return 2.0 * kPi * sum * da * dr;
}

// The smallest |v − a| − r over the atoms (negative: inside a van der Waals sphere), and the
// largest over vertices of the smallest |v − a| − (r + rp) (negative: every vertex inside the SAS).
struct Clearance {
  double vdw = 1e30, sas = -1e30;
};
Clearance clearance(const Mesh& mesh, const std::vector<SurfaceAtom>& atoms, double rp) {
  Clearance c;
  for (const glm::vec3& v : mesh.positions)
    for (const SurfaceAtom& a : atoms) {
      const double d = glm::length(glm::dvec3(v) - a.centre);
      c.vdw = std::min(c.vdw, d - a.radius);
    }
  for (const glm::vec3& v : mesh.positions) {
    double inside = 1e30;
    for (const SurfaceAtom& a : atoms) inside = std::min(inside, glm::length(glm::dvec3(v) - a.centre) - a.radius - rp);
    c.sas = std::max(c.sas, inside);  // the largest over vertices
  }
  return c;
}

TEST(MolecularSurface, OneAtomIsItsVanDerWaalsSphere) {
  MolecularSurfaceOptions options;
  options.spacing = 0.1;
  const std::vector<SurfaceAtom> atoms = {{{0.3, -0.2, 0.1}, 1.7}};
  const Mesh mesh = solventExcludedSurface(atoms, options);
  const SurfaceMeasures m = measure(mesh);
  ASSERT_TRUE(m.closed());
  EXPECT_NEAR(m.area, 4.0 * kPi * 1.7 * 1.7, 0.005 * 4.0 * kPi * 1.7 * 1.7);
  EXPECT_NEAR(m.volume, 4.0 / 3.0 * kPi * std::pow(1.7, 3), 0.005 * 4.0 / 3.0 * kPi * std::pow(1.7, 3));
  for (const glm::vec3& v : mesh.positions) EXPECT_NEAR(glm::length(glm::dvec3(v) - atoms[0].centre), 1.7, 0.01);
  // Normals point out, and the triangles wind counter-clockwise seen from outside (volume > 0).
  for (std::size_t i = 0; i < mesh.positions.size(); ++i)
    EXPECT_GT(glm::dot(glm::dvec3(mesh.normals[i]), glm::dvec3(mesh.positions[i]) - atoms[0].centre), 0.0);
  // No slivers at either spacing: every triangle nearly equilateral (a latitude–longitude sphere's
  // pole triangles have an aspect ratio of 6–17 here), none longer than about the spacing.
  for (const double spacing : {0.1, 0.3}) {
    options.spacing = spacing;
    const Mesh sphere = solventExcludedSurface(atoms, options);
    double worstRatio = 0.0, longest = 0.0;
    for (std::size_t t = 0; t < sphere.indices.size(); t += 3) {
      double lo = 1e30, hi = 0.0;
      for (std::size_t e = 0; e < 3; ++e) {
        const double length = glm::length(glm::dvec3(sphere.positions[sphere.indices[t + e]]) -
                                          glm::dvec3(sphere.positions[sphere.indices[t + (e + 1) % 3]]));
        lo = std::min(lo, length);
        hi = std::max(hi, length);
      }
      worstRatio = std::max(worstRatio, hi / lo);
      longest = std::max(longest, hi);
    }
    EXPECT_LT(worstRatio, 1.25) << spacing;
    EXPECT_LT(longest, 1.05 * spacing) << spacing;
  }
}

TEST(MolecularSurface, TwoAtomsAreTwoCapsAndAConcaveTorus) {
  MolecularSurfaceOptions options;
  options.spacing = 0.1;
  // Carbon and oxygen, two carbons, hydrogen and sulphur; the probe circle's radius ρ is 2.2–2.7 Å
  // (> rp: the torus does not cross the axis).
  for (const auto& [r1, r2, d] : {std::tuple{1.7, 1.52, 3.2}, std::tuple{1.7, 1.7, 3.0}, std::tuple{1.2, 1.8, 3.6}}) {
    const std::vector<SurfaceAtom> atoms = {{{0.0, 0.0, 0.0}, r1}, {{d * 0.6, d * 0.8, 0.0}, r2}};
    const double expected = twoAtomSesArea(r1, r2, d, options.probeRadius);
    // The van der Waals union (a crease where the spheres meet) differs by more than 2 % here.
    const double union2 = 2.0 * kPi *
                          (r1 * r1 * (1.0 + (d * d + r1 * r1 - r2 * r2) / (2.0 * d * r1)) +
                           r2 * r2 * (1.0 + (d * d + r2 * r2 - r1 * r1) / (2.0 * d * r2)));
    ASSERT_GT(std::abs(expected - union2), 0.02 * expected) << "the case must tell the torus from a crease";
    const SurfaceMeasures m = measure(solventExcludedSurface(atoms, options));
    ASSERT_TRUE(m.closed());
    EXPECT_NEAR(m.area, expected, 0.002 * expected) << r1 << " " << r2 << " " << d;
    const double volume = twoAtomSesVolume(r1, r2, d, options.probeRadius);
    EXPECT_NEAR(m.volume, volume, 0.003 * volume) << r1 << " " << r2 << " " << d;
    // At the default spacing (0.3 Å), as molecules are drawn.
    const SurfaceMeasures coarse = measure(solventExcludedSurface(atoms));
    ASSERT_TRUE(coarse.closed());
    EXPECT_NEAR(coarse.area, expected, 0.01 * expected) << r1 << " " << r2 << " " << d;
  }
}

TEST(MolecularSurface, AProbeThatPassesBetweenLeavesTwoSpheres) {
  MolecularSurfaceOptions options;
  options.spacing = 0.1;
  const std::vector<SurfaceAtom> atoms = {{{0.0, 0.0, 0.0}, 1.5}, {{6.5, 0.0, 0.0}, 1.5}};  // gap 3.5 > 2 rp
  const SurfaceMeasures m = measure(solventExcludedSurface(atoms, options));
  ASSERT_TRUE(m.closed());
  EXPECT_NEAR(m.area, 2.0 * 4.0 * kPi * 1.5 * 1.5, 0.005 * 8.0 * kPi * 1.5 * 1.5);
}

TEST(MolecularSurface, AnyStructureIsClosedOutsideTheAtomsAndInsideTheSas) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> coordinate(-4.0, 4.0), radius(1.2, 1.9);
  std::vector<SurfaceAtom> atoms;
  for (int i = 0; i < 40; ++i) atoms.push_back({{coordinate(rng), coordinate(rng), coordinate(rng)}, radius(rng)});
  MolecularSurfaceOptions options;
  options.spacing = 0.25;
  const Mesh mesh = solventExcludedSurface(atoms, options);
  const SurfaceMeasures m = measure(mesh);
  ASSERT_TRUE(m.closed());
  EXPECT_GT(m.volume, 0.0);
  const Clearance c = clearance(mesh, atoms, options.probeRadius);
  // On the grid the surface is within a small part of a spacing of the true one.
  EXPECT_GT(c.vdw, -0.05 * options.spacing * 4);
  EXPECT_LT(c.sas, 0.0);
}

TEST(MolecularSurface, ACoarserGridWhenTheFineOneIsTooLarge) {
  // Eleven overlapping carbons in a row, 30 Å long: one group, whose grid must be coarser to fit in
  // 20,000 points.
  std::vector<SurfaceAtom> row;
  for (int i = 0; i <= 10; ++i) row.push_back({{3.0 * i, 0.0, 0.0}, 1.7});
  MolecularSurfaceOptions options;
  options.maxGridPoints = 20'000;
  const double h = molecularSurfaceSpacing(row, options);
  EXPECT_GT(h, options.spacing);
  const SurfaceMeasures m = measure(solventExcludedSurface(row, options));
  EXPECT_TRUE(m.closed());
  options.maxGridPoints = std::size_t{1} << 25;
  EXPECT_DOUBLE_EQ(molecularSurfaceSpacing(row, options), options.spacing);
  EXPECT_NEAR(measure(solventExcludedSurface(row, options)).area, m.area, 0.03 * m.area);
  // Two atoms 10⁵ Å apart are two groups, each on a fine grid of its own: two exact spheres.
  const std::vector<SurfaceAtom> apart = {{{-5e4, 0.0, 0.0}, 1.7}, {{5e4, 0.0, 0.0}, 1.7}};
  EXPECT_DOUBLE_EQ(molecularSurfaceSpacing(apart, options), options.spacing);
  EXPECT_NEAR(measure(solventExcludedSurface(apart, options)).area, 2.0 * 4.0 * kPi * 1.7 * 1.7,
              0.01 * 8.0 * kPi * 1.7 * 1.7);
  // A grid too coarse for the atoms is refused, not drawn as nothing.
  options.maxGridPoints = 512;
  try {
    (void)solventExcludedSurface(row, options);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()),
              "molecular surface: 11 overlapping atoms span 36 Å: a grid of at most 512 points would be coarser than "
              "their smallest atom");
  }
}

TEST(MolecularSurface, BadInputIsRefused) {
  EXPECT_TRUE(solventExcludedSurface({}).indices.empty());
  const auto reason = [](const std::vector<SurfaceAtom>& atoms, const MolecularSurfaceOptions& options) {
    try {
      (void)solventExcludedSurface(atoms, options);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::vector<SurfaceAtom> one = {{{0.0, 0.0, 0.0}, 1.7}};
  MolecularSurfaceOptions bad;
  bad.probeRadius = 0.0;
  EXPECT_EQ(reason(one, bad), "molecular surface: the probe radius must be positive and finite");
  bad = {};
  bad.spacing = -1.0;
  EXPECT_EQ(reason(one, bad), "molecular surface: the grid spacing must be positive and finite");
  EXPECT_EQ(reason({{{0.0, NAN, 0.0}, 1.7}}, {}), "molecular surface: an atom's centre is not finite");
  EXPECT_EQ(reason({{{0.0, 0.0, 0.0}, 0.0}}, {}), "molecular surface: an atom's radius is not positive and finite");
  // Atoms packed denser than any molecule: refused before the crease search, which would be
  // quadratic in them.
  const std::vector<SurfaceAtom> pile(500, SurfaceAtom{{1.0, 2.0, 3.0}, 1.7});
  EXPECT_EQ(reason(pile, {}),
            "molecular surface: 499 atoms within 6 Å of one: packed denser than any molecule (a "
            "protein's atoms have about 100)");
}

// Every vertex lies on the exact surface — one of the two spheres or the torus (the points at
// distance rp from the circle the probe's centre runs along) — to within 5 % of the grid spacing.
// Measured to points of the SAS alone the tori come out bumpy, up to a third of a spacing off.
TEST(MolecularSurface, VerticesLieOnTheExactSurface) {
  const double r1 = 1.7, r2 = 1.52, d = 3.2, rp = 1.4;
  const double R1 = r1 + rp, R2 = r2 + rp, x = (d * d + R1 * R1 - R2 * R2) / (2.0 * d);
  const double rho = std::sqrt(R1 * R1 - x * x);
  const std::vector<SurfaceAtom> atoms = {{{0.0, 0.0, 0.0}, r1}, {{d, 0.0, 0.0}, r2}};
  for (const double h : {0.1, 0.3}) {
    MolecularSurfaceOptions options;
    options.spacing = h;
    const Mesh mesh = solventExcludedSurface(atoms, options);
    ASSERT_FALSE(mesh.positions.empty());
    double worst = 0.0;
    for (const glm::vec3& vertex : mesh.positions) {
      const glm::dvec3 v(vertex);
      const double toCircle = std::hypot(v.x - x, std::hypot(v.y, v.z) - rho);
      worst =
          std::max(worst, std::min({std::abs(glm::length(v) - r1),
                                    std::abs(glm::length(v - glm::dvec3(d, 0.0, 0.0)) - r2), std::abs(toCircle - rp)}));
    }
    EXPECT_LT(worst, 0.05 * h) << "spacing " << h;
  }
}

// A hollow ball of atoms — 162 carbons evenly on a sphere of radius 6 Å (a Fibonacci lattice,
// about 1.8 Å apart: too close for the probe to pass) — holds a cavity the probe fits in. By
// default (PyMOL, MSMS) only the outer surface is drawn; with cavities also the cavity's, a closed
// component whose winding encloses a negative volume (its normals point into the cavity).
TEST(MolecularSurface, BuriedCavitiesOnlyWhenAskedFor) {
  std::vector<SurfaceAtom> shell;
  const int n = 162;
  const double golden = kPi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / n, r = std::sqrt(1.0 - z * z);
    shell.push_back({6.0 * glm::dvec3(r * std::cos(golden * i), r * std::sin(golden * i), z), 1.7});
  }
  MolecularSurfaceOptions options;
  const Mesh outer = solventExcludedSurface(shell, options);
  options.cavities = true;
  const Mesh both = solventExcludedSurface(shell, options);
  const SurfaceMeasures o = measure(outer), b = measure(both);
  ASSERT_TRUE(o.closed());
  ASSERT_TRUE(b.closed());
  EXPECT_GT(o.volume, 0.0);
  // The cavity: a surface inside radius 6 − 1.7 = 4.3 Å, of negative enclosed volume.
  EXPECT_LT(b.volume, o.volume);
  EXPECT_GT(b.area, o.area + 4.0 * kPi * 2.0 * 2.0);
  std::size_t inside = 0;
  for (const glm::vec3& p : both.positions) inside += glm::length(p) < 4.31f ? 1u : 0u;
  EXPECT_GT(inside, 100u);
  for (const glm::vec3& p : outer.positions) EXPECT_GT(glm::length(p), 4.29f);
}

}  // namespace
}  // namespace mfr::test
