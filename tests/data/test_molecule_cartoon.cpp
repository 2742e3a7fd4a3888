// Cartoons on real files (pymol-data, python-biopython-doc): the secondary structure they draw,
// against the program that defines it and against the files' own records:
// * mfr::assignSecondaryStructure against mkdssp 4 (Debian dssp, the reference implementation of
//   Kabsch & Sander's DSSP), residue by residue: its H and I (α- and π-helix) as helix, E as
//   strand, everything else as loop — on a helical protein (il2), a β protein dimer whose sheets
//   cross chains (HIV protease, 1hpv), a β-hairpin peptide (pept), five chains (1tii), an mmCIF
//   file (4CUP) and eight more of Biopython's test files: 2,668 of 2,669 residues alike;
// * files with HELIX/SHEET records are drawn by them (as PyMOL does; PyMOL's reading of 1hpv's and
//   1tii's records is compared residue for residue in tests/peer/pymol_secondary_structure_peer.py);
// * the cartoons of 1hpv's chains are closed and outward, in the three colours, each Cα near its
//   cartoon; and the cartoon of real backbones (1hpv, 1tii, il2) never turns a ring round against
//   the one before it (no pinched or twisted tube);
// * section planes across the cartoons of il2, 1hpv and 1tii cap every part they cut, though the
//   tubes fold over themselves at tight bends and overlap where runs meet, covering what the cartoon
//   encloses.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "mfr/io/load.hpp"
#include "mfr/io/molecule.hpp"
#include "mfr/scene/cartoon.hpp"
#include "mfr/scene/measure.hpp"
#include "mfr/scene/section.hpp"
#include "test_files.hpp"

namespace fs = std::filesystem;

namespace mfr::test {
namespace {

const fs::path kPymolDemo = "/usr/share/pymol/data/demo";
const fs::path kPymolTutorial = "/usr/share/pymol/data/tut";
const fs::path kBiopython = "/usr/share/doc/python-biopython-doc/Tests/PDB";

fs::path requireFile(const fs::path& path, const std::string& package) {
  if (!fs::exists(path)) ADD_FAILURE() << "missing " << path << " (from " << package << "; scripts/setup installs it)";
  return path;
}

using ResidueKey = std::tuple<std::string, int, char>;  // chain, number, insertion code

class SecondaryStructureAsMkdssp : public TempDirTest {
 protected:
  // mkdssp's assignment of `file`, as helix ('H': its H and I), strand ('E') or loop ('-'). A PDB
  // file is given to it as its ATOM records under a minimal HEADER and CRYST1 (mkdssp 4 insists on
  // both), columns 73–80 dropped (old files put line numbers there) and a blank chain named A;
  // mmCIF as it is.
  std::map<ResidueKey, char> mkdssp(const fs::path& file, bool mmcif) {
    fs::path input = dir() / (mmcif ? "in.cif" : "in.pdb");
    if (mmcif) {
      const CliResult unzip = runCommand("zcat '" + file.string() + "' > '" + input.string() + "'");
      EXPECT_EQ(unzip.exitCode, 0) << unzip.out;
    } else {
      fs::path plain = file;
      if (file.extension() == ".gz") {
        plain = dir() / "plain.pdb";
        const CliResult unzip = runCommand("zcat '" + file.string() + "' > '" + plain.string() + "'");
        EXPECT_EQ(unzip.exitCode, 0) << unzip.out;
      }
      std::ifstream in(plain);
      std::ofstream out(input);
      out << "HEADER    TEST                                    01-JAN-00   XXXX              \n"
             "CRYST1    1.000    1.000    1.000  90.00  90.00  90.00 P 1           1          \n";
      std::string line;
      while (std::getline(in, line)) {
        if (line.rfind("ATOM", 0) != 0 && line.rfind("TER", 0) != 0) continue;
        line = line.substr(0, 72);
        if (line.size() > 21 && line[21] == ' ') line[21] = 'A';
        out << line << "\n";
      }
      out << "END\n";
    }
    const fs::path output = dir() / "out.dssp";
    const CliResult r =
        runCommand("mkdssp --output-format dssp '" + input.string() + "' '" + output.string() + "' 2>&1");
    EXPECT_EQ(r.exitCode, 0) << r.out << " (mkdssp is Debian's dssp; scripts/setup installs it)";
    std::map<ResidueKey, char> out;
    std::ifstream in(output);
    std::string line;
    bool table = false;
    while (std::getline(in, line)) {
      if (line.rfind("  #  RESIDUE", 0) == 0) {
        table = true;
        continue;
      }
      if (!table || line.size() < 17 || line[13] == '!') continue;  // '!': a chain break
      const int number = std::stoi(line.substr(5, 5));
      const char ss = line[16];
      out[{std::string(1, line[11]), number, line[10]}] = ss == 'H' || ss == 'I' ? 'H' : ss == 'E' ? 'E' : '-';
    }
    EXPECT_GT(out.size(), 0u) << "no residues read from mkdssp's " << output;
    return out;
  }

  // Ours on the file's residues (never its records), compared with mkdssp's on every residue both
  // assign: at least `minResidues` compared, at most `maxDifferent` differing.
  void expectAsMkdssp(const fs::path& file, bool mmcif, std::size_t minResidues, std::size_t maxDifferent) {
    SCOPED_TRACE(file.string());
    const MoleculeStructure m = readMoleculeStructure(file);
    const std::vector<SecondaryStructure> ours = assignSecondaryStructure(m.residues);
    ASSERT_EQ(ours.size(), m.residues.size());
    const std::map<ResidueKey, char> theirs = mkdssp(file, mmcif);
    std::size_t compared = 0, different = 0, helix = 0, strand = 0;
    std::string oursLine, theirsLine, differences;
    for (std::size_t i = 0; i < ours.size(); ++i) {
      const BackboneResidue& r = m.residues[i];
      const auto it = theirs.find({r.chain.empty() ? "A" : r.chain, r.number, r.insertion});
      if (it == theirs.end()) continue;
      ++compared;
      const char a = secondaryStructureLetter(ours[i]), b = it->second;
      helix += a == 'H';
      strand += a == 'E';
      oursLine += a;
      theirsLine += b;
      if (a != b) {
        ++different;
        differences += " " + r.chain + ":" + r.name + std::to_string(r.number) + " ours " + a + ", mkdssp " + b + ";";
      }
    }
    std::cout << file.filename().string() << ": " << compared << " residues compared, " << helix << " helix, " << strand
              << " strand, " << different << " different\n";
    EXPECT_GE(compared, minResidues);
    EXPECT_LE(different, maxDifferent) << differences << "\nours:   " << oursLine << "\nmkdssp: " << theirsLine;
  }
};

TEST_F(SecondaryStructureAsMkdssp, HelicalProtein) {
  expectAsMkdssp(requireFile(kPymolDemo / "il2.pdb", "Debian package pymol-data"), false, 126, 0);
}

TEST_F(SecondaryStructureAsMkdssp, BetaDimerWithSheetsAcrossChains) {
  expectAsMkdssp(requireFile(kPymolTutorial / "1hpv.pdb", "Debian package pymol-data"), false, 198, 0);
}

TEST_F(SecondaryStructureAsMkdssp, BetaHairpinPeptide) {
  expectAsMkdssp(requireFile(kPymolDemo / "pept.pdb", "Debian package pymol-data"), false, 13, 0);
}

TEST_F(SecondaryStructureAsMkdssp, FiveChains) {
  expectAsMkdssp(requireFile(kPymolDemo / "1tii.pdb", "Debian package pymol-data"), false, 500, 0);
}

TEST_F(SecondaryStructureAsMkdssp, Mmcif) {
  expectAsMkdssp(requireFile(kBiopython / "4CUP.cif.gz", "Debian package python-biopython-doc"), true, 100, 0);
}

// Eight more files of Biopython's test set: an amyloid fibril whose parallel sheets run across
// five chains (2BEG), large α/β proteins (2XHE, 4ZHL), a protein–DNA complex (1LCD), NMR models
// (2OFG, 1LCD) and selenomethionine (1A8O). 3JQH has two residues at one position (ARG and GLN
// at 15, alternative locations of different residues): mkdssp keeps both, with a chain break
// between them, mfr the first — one residue differs there, as that explains.
TEST_F(SecondaryStructureAsMkdssp, MoreFiles) {
  struct Case {
    const char* file;
    std::size_t residues, different;
  };
  for (const Case& c : {Case{"2BEG.pdb.gz", 130, 0}, Case{"2XHE.cif.gz", 786, 0}, Case{"4ZHL.cif.gz", 257, 0},
                        Case{"1A7G.cif.gz", 82, 0}, Case{"2OFG.cif.gz", 106, 0}, Case{"1LCD.cif.gz", 51, 0},
                        Case{"1A8O.cif.gz", 70, 0}, Case{"3JQH.cif.gz", 23, 1}}) {
    const std::string name = c.file;
    expectAsMkdssp(requireFile(kBiopython / name, "Debian package python-biopython-doc"),
                   name.find(".cif") != std::string::npos, c.residues, c.different);
  }
}

// The cartoon of a two-chain β protein from its records: one closed, outward tube set per chain,
// in PyMOL's colours of helix (red), strand (yellow) and loop (green), each residue's Cα within
// the band's reach (2.1 Å) of some vertex, helix and strand residues as the records have them.
TEST(MoleculeCartoon, ClosedPerChainColouredByTheRecords) {
  const fs::path file = requireFile(kPymolTutorial / "1hpv.pdb", "Debian package pymol-data");
  const MoleculeStructure m = readMoleculeStructure(file);
  ASSERT_TRUE(m.secondaryStructureFromFile);
  const std::vector<Object> parts = loadModel(file, LoadOptions({}, MoleculeStyle::parse("cartoon", "t")));
  ASSERT_EQ(parts.size(), 2u);
  EXPECT_EQ(parts[0].name, "chain A");
  EXPECT_EQ(parts[1].name, "chain B");
  std::size_t part = 0;
  for (const Object& o : parts) {
    SCOPED_TRACE(o.name);
    const SurfaceMeasures s = measureSurface(*o.mesh, glm::dmat4(1.0));
    EXPECT_TRUE(s.closed());
    EXPECT_GT(s.volume, 0.0);
    std::size_t red = 0, yellow = 0, green = 0;
    for (const glm::vec4& c : o.mesh->colors) {
      red += c == glm::vec4(1, 0, 0, 1);
      yellow += c == glm::vec4(1, 1, 0, 1);
      green += c == glm::vec4(0, 1, 0, 1);
    }
    EXPECT_EQ(red + yellow + green, o.mesh->colors.size());
    // Residues of the chain by the records: 99 per chain, 4 helix, 47 … strand.
    std::size_t helix = 0, strand = 0, residues = 0;
    for (const BackboneResidue& r : m.residues) {
      if (r.part != part) continue;
      ++residues;
      helix += r.structure == SecondaryStructure::Helix;
      strand += r.structure == SecondaryStructure::Strand;
      // Every Cα within reach of the cartoon: at most the arrowhead's half-width (2.1 Å) from a vertex.
      double nearest = 1e30;
      for (const glm::vec3& v : o.mesh->positions) nearest = std::min(nearest, glm::distance(glm::dvec3(v), *r.ca));
      EXPECT_LT(nearest, 2.11) << r.number;
    }
    EXPECT_EQ(residues, 99u);
    EXPECT_GT(helix, 0u);
    EXPECT_GT(strand, 40u);
    EXPECT_GT(red, 0u);
    EXPECT_GT(yellow, red);
    ++part;
  }
}

// Real backbones, each chain's runs as the loader splits them: between consecutive rings the band's
// width direction (ring vertex 0 from the ring's centre) never turns by more than 90° — a guide
// projected onto a ring's plane can point against the previous one where the curve bends across
// it, and the tube would pinch there (1hpv, 1tii and il2 all have such places).
TEST(MoleculeCartoon, RingsNeverTurnRound) {
  for (const fs::path& file : {requireFile(kPymolTutorial / "1hpv.pdb", "Debian package pymol-data"),
                               requireFile(kPymolDemo / "1tii.pdb", "Debian package pymol-data"),
                               requireFile(kPymolDemo / "il2.pdb", "Debian package pymol-data")}) {
    SCOPED_TRACE(file.string());
    const MoleculeStructure m = readMoleculeStructure(file);
    std::vector<std::vector<CartoonResidue>> segments(1);
    const BackboneResidue* previous = nullptr;
    for (const BackboneResidue& r : m.residues) {
      if (!r.ca) continue;
      if (previous != nullptr && (previous->part != r.part || glm::distance(*previous->ca, *r.ca) > 4.5))
        segments.emplace_back();
      CartoonResidue c;
      c.trace = *r.ca;
      if (r.c && r.o) c.guide = *r.o - *r.c;
      c.structure = r.structure;
      segments.back().push_back(c);
      previous = &r;
    }
    const CartoonOptions options;
    const Mesh mesh = cartoonMesh(segments, options);
    const auto sides = static_cast<std::size_t>(options.sides);
    std::size_t base = 0, rings = 0, worst = 0;
    double smallest = 1.0;
    for (const std::vector<CartoonResidue>& segment : segments) {
      if (segment.size() < 2) continue;
      const std::size_t count = (segment.size() - 1) * static_cast<std::size_t>(options.samplesPerResidue) + 1;
      glm::dvec3 before(0.0);
      for (std::size_t k = 0; k < count; ++k) {
        glm::dvec3 centre(0.0);
        for (std::size_t v = 0; v < sides; ++v) centre += glm::dvec3(mesh.positions[base + k * sides + v]);
        centre /= static_cast<double>(sides);
        const glm::dvec3 width = glm::normalize(glm::dvec3(mesh.positions[base + k * sides]) - centre);
        if (k > 0) {
          const double d = glm::dot(width, before);
          if (d < 0.0) ++worst;
          smallest = std::min(smallest, d);
        }
        before = width;
      }
      rings += count;
      base += count * sides + 2 * (sides + 1);  // the rings, then two caps (centre and rim)
    }
    ASSERT_EQ(base, mesh.positions.size());
    EXPECT_EQ(worst, 0u) << "of " << rings << " rings; smallest cosine " << smallest;
  }
}

// 1LCD's DNA (two chains of the lac repressor's operator): each nucleotide with its phosphorus
// and base drawn, as PyMOL draws them, with a ladder rod reaching its base's N1 or N3; the DNA
// chains' cartoons closed.
TEST(MoleculeCartoon, DnaLaddersReachTheirBases) {
  const fs::path file = requireFile(kBiopython / "1LCD.pdb.gz", "Debian package python-biopython-doc");
  const MoleculeStructure m = readMoleculeStructure(file);
  const std::vector<Object> parts = loadModel(file, LoadOptions({}, MoleculeStyle::parse("cartoon", "t")));
  std::size_t bases = 0;
  for (const BackboneResidue& r : m.residues) {
    if (!r.phosphorus || !r.base) continue;
    ++bases;
    const std::string name = m.parts[r.part];
    const auto part =
        std::find_if(parts.begin(), parts.end(), [&](const Object& o) { return o.name.rfind(name, 0) == 0; });
    ASSERT_NE(part, parts.end()) << name;
    EXPECT_TRUE(measureSurface(*part->mesh, glm::dmat4(1.0)).closed()) << name;
    double nearest = 1e30;
    for (const glm::vec3& v : part->mesh->positions) nearest = std::min(nearest, glm::distance(glm::dvec3(v), *r.base));
    EXPECT_LT(nearest, 1e-3) << name << " " << r.number;  // the rod's end cap is centred on the base atom
  }
  EXPECT_GE(bases, 20u);  // 2 × 11 nucleotides, less the 5' ends without a phosphorus
}

// How many times `mesh` winds around point p: its triangles' signed crossings of a ray from p
// (+1 leaving through an outward face). Nonzero inside the union of outward closed shells, also
// where they overlap.
int windingNumber(const Mesh& mesh, const glm::dvec3& p) {
  const glm::dvec3 d = glm::normalize(glm::dvec3(0.5773, 0.2113, 0.7887));  // off every axis and diagonal
  int winding = 0;
  for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
    const glm::dvec3 a(mesh.positions[mesh.indices[3 * t]]), b(mesh.positions[mesh.indices[3 * t + 1]]),
        c(mesh.positions[mesh.indices[3 * t + 2]]);
    // Möller–Trumbore.
    const glm::dvec3 e1 = b - a, e2 = c - a, q = glm::cross(d, e2);
    const double det = glm::dot(e1, q);
    if (det == 0.0) continue;
    const glm::dvec3 s = p - a;
    const double u = glm::dot(s, q) / det;
    if (u < 0.0 || u > 1.0) continue;
    const glm::dvec3 r = glm::cross(s, e1);
    const double v = glm::dot(d, r) / det;
    if (v < 0.0 || u + v > 1.0) continue;
    if (glm::dot(e2, r) / det <= 0.0) continue;
    winding += glm::dot(glm::cross(e1, e2), d) > 0.0 ? 1 : -1;
  }
  return winding;
}

// A cartoon's tube folds over itself where the curve bends tighter than the band is wide, and the
// runs of one chain overlap where they meet: their cut lines cross themselves. Planes across each
// file's parts (9 per axis) cut 10 to 20 parts each; every one is capped, and the cap covers exactly
// the points of the plane that the uncut cartoon winds around (12 × 12 points over each cap's box,
// against ray crossings of the uncut mesh). Before the caps' winding rule, 21 of 171 planes (19 per
// axis) left a part of these files open.
TEST(MoleculeCartoon, SectionsCapEveryCutPartByWhatItEncloses) {
  for (const fs::path& file : {requireFile(kPymolTutorial / "1hpv.pdb", "Debian package pymol-data"),
                               requireFile(kPymolDemo / "1tii.pdb", "Debian package pymol-data"),
                               requireFile(kPymolDemo / "il2.pdb", "Debian package pymol-data")}) {
    SCOPED_TRACE(file.string());
    const std::vector<Object> parts = loadModel(file, LoadOptions({}, MoleculeStyle::parse("cartoon", "t")));
    ASSERT_FALSE(parts.empty());
    Bounds box;
    for (const Object& o : parts) box.extend(o.mesh->bounds());
    std::size_t cuts = 0, open = 0, inside = 0, wrong = 0;
    for (int axis = 0; axis < 3; ++axis)
      for (int step = 1; step < 10; ++step) {
        glm::dvec4 plane(0.0);
        plane[axis] = 1.0;
        const double at = box.min[axis] + (box.max[axis] - box.min[axis]) * (step + 0.0137) / 10.0;
        plane.w = -at;
        for (const Object& o : parts) {
          const SectionedMesh cut = sectionMesh(*o.mesh, plane, true);
          if (cut.outcome != SectionOutcome::kCut && cut.outcome != SectionOutcome::kCapped) continue;
          ++cuts;
          if (cut.outcome != SectionOutcome::kCapped) {
            ++open;
            ADD_FAILURE() << o.name << " open at axis " << axis << " = " << at;
            continue;
          }
          // The cap's triangles in the plane's two other coordinates.
          const int i = (axis + 1) % 3, j = (axis + 2) % 3;
          const Mesh& m = cut.mesh;
          std::vector<std::array<glm::dvec2, 3>> cap;
          glm::dvec2 lo(1e30), hi(-1e30);
          for (std::size_t t = m.triangleCount() - cut.capTriangles; t < m.triangleCount(); ++t) {
            std::array<glm::dvec2, 3> corners;
            for (std::size_t k = 0; k < 3; ++k) {
              const glm::vec3 q = m.positions[m.indices[3 * t + k]];
              corners[k] = {q[i], q[j]};
              lo = glm::min(lo, corners[k]);
              hi = glm::max(hi, corners[k]);
            }
            cap.push_back(corners);
          }
          const auto covered = [&](const glm::dvec2& q) {
            for (const auto& [a, b, c] : cap) {
              const auto side = [](const glm::dvec2& u, const glm::dvec2& v, const glm::dvec2& w) {
                return (v.x - u.x) * (w.y - u.y) - (v.y - u.y) * (w.x - u.x);
              };
              const double s0 = side(a, b, q), s1 = side(b, c, q), s2 = side(c, a, q);
              if ((s0 >= 0 && s1 >= 0 && s2 >= 0) || (s0 <= 0 && s1 <= 0 && s2 <= 0)) return true;
            }
            return false;
          };
          for (int u = 0; u < 12; ++u)
            for (int v = 0; v < 12; ++v) {
              const glm::dvec2 q = lo + (hi - lo) * glm::dvec2((u + 0.5) / 12.0, (v + 0.5) / 12.0);
              glm::dvec3 point(0.0);
              point[axis] = at;
              point[i] = q.x;
              point[j] = q.y;
              const bool enclosed = windingNumber(*o.mesh, point) != 0;
              inside += enclosed;
              if (enclosed != covered(q)) ++wrong;
            }
        }
      }
    EXPECT_GE(cuts, 27u);
    EXPECT_EQ(open, 0u) << "of " << cuts << " cut parts";
    EXPECT_GT(inside, 5u * cuts) << "of " << cuts * 144 << " points";
    EXPECT_EQ(wrong, 0u) << "of " << cuts * 144 << " points";
    std::cout << file.filename().string() << ": " << cuts << " cut parts, " << inside << " of " << cuts * 144
              << " points inside\n";
  }
}

}  // namespace
}  // namespace mfr::test
