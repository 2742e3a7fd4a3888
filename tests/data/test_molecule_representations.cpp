// Molecules drawn as sticks and surfaces, on real files (pymol-data, python-biopython-doc),
// against independent programs and closed facts:
// * the bonds against Open Babel's (Debian openbabel): the same atoms written as XYZ — elements and
//   coordinates only, so that Open Babel too must find the bonds from distances — and the bond
//   table of the MOL2 file it writes compared bond for bond;
// * every one of those bonds drawn: the sticks' triangles are a joint per atom and two half tubes
//   per bond, 112 bonds on pept.pdb (Open Babel's and PyMOL's count);
// * the solvent-excluded surface of real chains: closed, outside every atom's van der Waals sphere
//   and inside the solvent-accessible one. (Its area against PyMOL's own surface is
//   tests/peer/pymol_surface_peer.py.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gemmi/elem.hpp>

#include "mfr/error.hpp"
#include "mfr/io/load.hpp"
#include "mfr/io/molecule.hpp"
#include "mfr/scene/measure.hpp"
#include "test_files.hpp"

namespace fs = std::filesystem;

namespace mfr::test {
namespace {

const fs::path kPymolDemo = "/usr/share/pymol/data/demo";
const fs::path kBiopython = "/usr/share/doc/python-biopython-doc/Tests/PDB";

fs::path requireFile(const fs::path& path, const std::string& package) {
  if (!fs::exists(path)) ADD_FAILURE() << "missing " << path << " (from " << package << "; scripts/setup installs it)";
  return path;
}

class MoleculeBonds : public TempDirTest {
 protected:
  // Open Babel's bonds for `atoms` (from an XYZ file it reads), as index pairs, smaller first: the
  // bond section of the Tripos MOL2 file it writes ("id atom atom type", atoms from 1).
  std::set<Bond> openBabelBonds(const std::vector<MoleculeAtom>& atoms) {
    const fs::path xyz = dir() / "atoms.xyz", mol2 = dir() / "atoms.mol2";
    {
      std::ofstream out(xyz);
      out << atoms.size() << "\nmfr atoms\n";
      out.precision(10);
      for (const MoleculeAtom& a : atoms)
        out << gemmi::Element(static_cast<gemmi::El>(a.atomicNumber)).name() << " " << a.position.x << " "
            << a.position.y << " " << a.position.z << "\n";
    }
    const CliResult r = runCommand("obabel -ixyz '" + xyz.string() + "' -omol2 -O '" + mol2.string() + "'");
    EXPECT_EQ(r.exitCode, 0) << r.out << " (obabel is Debian's openbabel; scripts/setup installs it)";
    std::ifstream in(mol2);
    std::string line;
    bool inBonds = false;
    std::set<Bond> bonds;
    while (std::getline(in, line)) {
      if (line.rfind("@<TRIPOS>", 0) == 0) {
        inBonds = line.rfind("@<TRIPOS>BOND", 0) == 0;
        continue;
      }
      if (!inBonds || line.find_first_not_of(" \t\r") == std::string::npos) continue;
      std::istringstream fields(line);
      std::size_t id = 0, a = 0, b = 0;
      fields >> id >> a >> b;
      EXPECT_TRUE(fields && a >= 1 && b >= 1 && a <= atoms.size() && b <= atoms.size()) << line;
      const auto x = static_cast<std::uint32_t>(a - 1), y = static_cast<std::uint32_t>(b - 1);
      bonds.insert({std::min(x, y), std::max(x, y)});
    }
    EXPECT_FALSE(bonds.empty()) << "no bonds read from " << mol2;
    return bonds;
  }

  void expectSameBonds(const fs::path& file, std::size_t expectedAtoms) {
    SCOPED_TRACE(file.string());
    const MoleculeStructure m = readMoleculeStructure(file);
    ASSERT_EQ(m.atoms.size(), expectedAtoms);
    const std::set<Bond> ours(m.bonds.begin(), m.bonds.end()), theirs = openBabelBonds(m.atoms);
    EXPECT_EQ(ours.size(), m.bonds.size()) << "each bond once";
    std::vector<Bond> onlyOurs, onlyTheirs;
    std::set_difference(ours.begin(), ours.end(), theirs.begin(), theirs.end(), std::back_inserter(onlyOurs));
    std::set_difference(theirs.begin(), theirs.end(), ours.begin(), ours.end(), std::back_inserter(onlyTheirs));
    const auto describe = [&](const std::vector<Bond>& bonds) {
      std::ostringstream s;
      for (const Bond& b : bonds)
        s << " " << m.atoms[b[0]].serial << "-" << m.atoms[b[1]].serial << " ("
          << glm::length(m.atoms[b[0]].position - m.atoms[b[1]].position) << " A)";
      return s.str();
    };
    EXPECT_TRUE(onlyOurs.empty()) << onlyOurs.size() << " bonds Open Babel does not make:" << describe(onlyOurs);
    EXPECT_TRUE(onlyTheirs.empty()) << onlyTheirs.size()
                                    << " of Open Babel's bonds we do not make:" << describe(onlyTheirs);
    EXPECT_GT(ours.size(), expectedAtoms / 2);
  }
};

TEST_F(MoleculeBonds, PeptideAsOpenBabel) {
  expectSameBonds(requireFile(kPymolDemo / "pept.pdb", "Debian package pymol-data"), 107);
}

TEST_F(MoleculeBonds, ProteinWithHydrogensAsOpenBabel) {
  expectSameBonds(requireFile(kPymolDemo / "il2.pdb", "Debian package pymol-data"), 2084);
}

TEST_F(MoleculeBonds, FiveChainsAndWaterAsOpenBabel) {
  expectSameBonds(requireFile(kPymolDemo / "1tii.pdb", "Debian package pymol-data"), 5684);
}

TEST_F(MoleculeBonds, LigandsWaterAndAlternativeLocationsAsOpenBabel) {
  // Only the first alternative location is kept, and Open Babel is given the same atoms.
  const fs::path file = requireFile(kBiopython / "4CUP.cif.gz", "Debian package python-biopython-doc");
  expectSameBonds(file, readMoleculeStructure(file).atoms.size());
}

TEST(MoleculeDrawing, SticksDrawEveryBondAndSurfacesWrapTheAtoms) {
  const fs::path pept = requireFile(kPymolDemo / "pept.pdb", "Debian package pymol-data");
  const std::vector<Object> sticks = loadModel(pept, LoadOptions({}, MoleculeStyle::parse("sticks", "t")));
  ASSERT_EQ(sticks.size(), 1u);
  // 107 atoms: 320 triangles a joint; 16-sided half tubes, 32 triangles each, two per bond.
  EXPECT_EQ(sticks[0].mesh->triangleCount(), 107u * 320u + 112u * 2u * 32u);

  for (const fs::path& file : {pept, requireFile(kPymolDemo / "il2.pdb", "Debian package pymol-data")}) {
    SCOPED_TRACE(file.string());
    const MoleculeStructure m = readMoleculeStructure(file);
    const std::vector<Object> parts = loadModel(file, LoadOptions({}, MoleculeStyle::parse("surface", "t")));
    ASSERT_EQ(parts.size(), 1u);
    const Mesh& surface = *parts[0].mesh;
    EXPECT_TRUE(measureSurface(surface, glm::dmat4(1.0)).closed());
    // Every vertex outside every atom (to within 5 % of the 0.3 Å grid) and inside some grown sphere.
    double deepest = 1e30, farthest = -1e30;
    for (const glm::vec3& vertex : surface.positions) {
      const glm::dvec3 v(vertex);
      double nearestGrown = 1e30;
      for (const MoleculeAtom& a : m.atoms) {
        const double r = gemmi::vdw_radius(static_cast<gemmi::El>(a.atomicNumber));
        const double d = glm::length(v - a.position);
        deepest = std::min(deepest, d - r);
        nearestGrown = std::min(nearestGrown, d - r - 1.4);
      }
      farthest = std::max(farthest, nearestGrown);
    }
    EXPECT_GT(deepest, -0.015);
    EXPECT_LT(farthest, 0.0);
  }
}

}  // namespace
}  // namespace mfr::test
