#include "molecule_loader.hpp"

#include "file_checks.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <numbers>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <tuple>
#include <unordered_set>
#include <utility>

#include <gemmi/cif.hpp>
#include <gemmi/elem.hpp>
#include <gemmi/mmcif.hpp>
#include <gemmi/model.hpp>
#include <gemmi/pdb.hpp>
#include <gemmi/polyheur.hpp>

#include "mfr/error.hpp"
#include "mfr/io/molecule.hpp"
#include "mfr/scene/cartoon.hpp"
#include "mfr/scene/molecular_surface.hpp"
#include "scene/geodesic_sphere.hpp"
#include "scene/perpendicular.hpp"
#include "scene/point_grid.hpp"

namespace mfr::io {
namespace {

// Coordinates beyond this (Å) are taken as corrupt: the PDB format's own field holds at most
// 9999.999, and the largest assemblies in the PDB span a few thousand Å.
constexpr double kMaxCoordinate = 1e5;
// More atoms than this are refused: 40 M triangles at 20 per sphere, several GiB of vertices.
constexpr std::size_t kMaxAtoms = 2'000'000;

// Jmol's element colours ("CPK" as most viewers draw it: C grey, O red, N blue, S yellow,
// P orange, H white), http://jmol.sourceforge.net/jscolors/, by atomic number 1–109, as 0xRRGGBB.
constexpr std::array<std::uint32_t, 110> kJmolColors = {
    0xFF1493,            // 0: unknown element (X): deep pink, as Jmol and RasMol draw unknown atoms
    0xFFFFFF, 0xD9FFFF,  // H He
    0xCC80FF, 0xC2FF00, 0xFFB5B5, 0x909090, 0x3050F8, 0xFF0D0D, 0x90E050, 0xB3E3F5,            // Li–Ne
    0xAB5CF2, 0x8AFF00, 0xBFA6A6, 0xF0C8A0, 0xFF8000, 0xFFFF30, 0x1FF01F, 0x80D1E3,            // Na–Ar
    0x8F40D4, 0x3DFF00, 0xE6E6E6, 0xBFC2C7, 0xA6A6AB, 0x8A99C7, 0x9C7AC7, 0xE06633, 0xF090A0,  // K–Co
    0x50D050, 0xC88033, 0x7D80B0, 0xC28F8F, 0x668F8F, 0xBD80E3, 0xFFA100, 0xA62929, 0x5CB8D1,  // Ni–Kr
    0x702EB0, 0x00FF00, 0x94FFFF, 0x94E0E0, 0x73C2C9, 0x54B5B5, 0x3B9E9E, 0x248F8F, 0x0A7D8C,  // Rb–Rh
    0x006985, 0xC0C0C0, 0xFFD98F, 0xA67573, 0x668080, 0x9E63B5, 0xD47A00, 0x940094, 0x429EB0,  // Pd–Xe
    0x57178F, 0x00C900, 0x70D4FF, 0xFFFFC7, 0xD9FFC7, 0xC7FFC7, 0xA3FFC7, 0x8FFFC7, 0x61FFC7,  // Cs–Eu
    0x45FFC7, 0x30FFC7, 0x1FFFC7, 0x00FF9C, 0x00E675, 0x00D452, 0x00BF38, 0x00AB24, 0x4DC2FF,  // Gd–Hf
    0x4DA6FF, 0x2194D6, 0x267DAB, 0x266696, 0x175487, 0xD0D0E0, 0xFFD123, 0xB8B8D0, 0xA6544D,  // Ta–Tl
    0x575961, 0x9E4FB5, 0xAB5C00, 0x754F45, 0x428296, 0x420066, 0x007D00, 0x70ABFA, 0x00BAFF,  // Pb–Th
    0x00A1FF, 0x008FFF, 0x0080FF, 0x006BFF, 0x545CF2, 0x785CE3, 0x8A4FE3, 0xA136D4, 0xB31FD4,  // Pa–Es
    0xB31FBA, 0xB30DA6, 0xBD0D87, 0xC70066, 0xCC0059, 0xD1004F, 0xD90045, 0xE00038, 0xE6002E,  // Fm–Hs
    0xEB0026,                                                                                  // Mt
};
constexpr std::uint32_t kDeuteriumColor = 0xFFFFC0;  // Jmol's colour for D (²H)

glm::vec4 elementColor(gemmi::El el) {
  std::uint32_t rgb = kJmolColors[0];  // X, and Ds–Og, which Jmol does not colour
  if (el == gemmi::El::D)
    rgb = kDeuteriumColor;
  else if (const auto z = static_cast<std::size_t>(el); z < kJmolColors.size())
    rgb = kJmolColors[z];
  return {static_cast<float>((rgb >> 16) & 0xFFu) / 255.0f, static_cast<float>((rgb >> 8) & 0xFFu) / 255.0f,
          static_cast<float>(rgb & 0xFFu) / 255.0f, 1.0f};
}

// ---- icospheres ---------------------------------------------------------------------------------

// Level l: the geodesic sphere of frequency 2^l (20·4^l triangles; at level ≥ 1 a sphere's bounding
// box is its centre ± radius).
const UnitSphere& icosphere(int level) {
  static const std::array<UnitSphere, 3> spheres = {geodesicSphere(1), geodesicSphere(2), geodesicSphere(4)};
  return spheres[static_cast<std::size_t>(std::clamp(level, 0, 2))];
}

// ---- reading ------------------------------------------------------------------------------------

bool isAtomRecord(std::string_view line) {
  return line.rfind("ATOM", 0) == 0 || line.rfind("HETATM", 0) == 0;
}

std::string_view withoutLineEnd(std::string_view line) {
  while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.remove_suffix(1);
  return line;
}

// A PDB file cut in the middle of its last record: gemmi takes an ATOM/HETATM record that still
// holds its coordinates (54 columns) as complete, so the cut is found here — the file does not
// end with a line end and its last line is a coordinate record shorter than the one before it.
void checkPdbNotCut(const std::string& data, const std::string& name) {
  if (data.empty() || data.back() == '\n' || data.back() == '\r') return;
  const std::size_t lastStart = data.rfind('\n');
  if (lastStart == std::string::npos) return;  // one line: gemmi judges it
  const std::string_view last = withoutLineEnd(std::string_view(data).substr(lastStart + 1));
  if (!isAtomRecord(last)) return;
  const std::size_t prevStart = lastStart == 0 ? std::string::npos : data.rfind('\n', lastStart - 1);
  const std::size_t from = prevStart == std::string::npos ? 0 : prevStart + 1;
  const std::string_view previous = withoutLineEnd(std::string_view(data).substr(from, lastStart - from));
  if (isAtomRecord(previous) && last.size() < previous.size())
    throw Error(name, "truncated file: the last ATOM/HETATM record ends at column " + std::to_string(last.size()) +
                          " (the one before has " + std::to_string(previous.size()) + ")");
}

// Coordinates that are not numbers: gemmi reads "2.0x0" as 2 and a blank field as 0, which would
// put the atom somewhere it is not. Each of columns 31–38, 39–46 and 47–54 of an ATOM/HETATM
// record must hold one decimal number, spaces around it.
void checkPdbCoordinates(const std::string& data, const std::string& name) {
  std::size_t lineNumber = 0;
  for (std::size_t start = 0; start < data.size();) {
    std::size_t end = data.find('\n', start);
    if (end == std::string::npos) end = data.size();
    ++lineNumber;
    const std::string_view line = withoutLineEnd(std::string_view(data).substr(start, end - start));
    start = end + 1;
    if (!isAtomRecord(line) || line.size() < 54) continue;  // a short record: gemmi's and checkPdbNotCut's
    for (const auto& [axis, from] : {std::pair{'x', 30}, std::pair{'y', 38}, std::pair{'z', 46}}) {
      const std::string_view field = line.substr(static_cast<std::size_t>(from), 8);
      const std::size_t first = field.find_first_not_of(' ');
      const std::size_t last = field.find_last_not_of(' ');
      std::size_t digits = 0;
      bool number = first != std::string_view::npos;
      if (number) {
        const std::string_view value = field.substr(first, last - first + 1);
        std::size_t i = value[0] == '-' || value[0] == '+' ? 1 : 0;
        bool point = false;
        for (; i < value.size() && number; ++i) {
          if (std::isdigit(static_cast<unsigned char>(value[i])) != 0)
            ++digits;
          else if (value[i] == '.' && !point)
            point = true;
          else
            number = false;
        }
      }
      if (!number || digits == 0)
        throw Error(name,
                    "line " + std::to_string(lineNumber) + ": the " + std::string(1, axis) + " coordinate (columns " +
                        std::to_string(from + 1) + "–" + std::to_string(from + 8) +
                        (first == std::string_view::npos
                             ? ") is blank"
                             : ") is not a number: '" + std::string(field.substr(first, last - first + 1)) + "'"));
    }
  }
}

// Whether a CIF block looks like a small-molecule (coreCIF) structure rather than mmCIF.
bool isSmallMoleculeCif(const gemmi::cif::Block& block) {
  for (const char* tag : {"_atom_site_fract_x", "_atom_site_label", "_atom_site_Cartn_x", "_cell_length_a"})
    if (block.has_tag(tag)) return true;
  return false;
}

// Old PDB files (PyMOL's tutorial 1hpv.pdb, for one) put the entry ID and a line number in
// columns 73–80, where today's format has the segment, element and charge; gemmi then fails on
// the "charge". Two digits in columns 79–80 of a coordinate record cannot be a charge.
bool hasLineNumbersInColumns73To80(const std::string& data) {
  for (std::size_t start = 0; start < data.size();) {
    std::size_t end = data.find('\n', start);
    if (end == std::string::npos) end = data.size();
    const std::string_view line = withoutLineEnd(std::string_view(data).substr(start, end - start));
    if (isAtomRecord(line) && line.size() >= 80 && std::isdigit(static_cast<unsigned char>(line[78])) != 0 &&
        std::isdigit(static_cast<unsigned char>(line[79])) != 0)
      return true;
    start = end + 1;
  }
  return false;
}

gemmi::Structure parse(const std::string& data, MoleculeFormat format, const std::string& name) {
  if (format == MoleculeFormat::Pdb) {
    checkPdbNotCut(data, name);
    gemmi::PdbReadOptions options;
    // Columns 73–80 ignored: elements then come from the atom names, as in those files' time.
    if (hasLineNumbersInColumns73To80(data)) options.max_line_length = 72;
    gemmi::Structure st = gemmi::read_pdb_from_memory(data.data(), data.size(), name, options);
    checkPdbCoordinates(data, name);  // after gemmi's own checks (an mmCIF file named .pdb)
    return st;
  }
  const gemmi::cif::Document doc = gemmi::cif::read_memory(data.data(), data.size(), name.c_str());
  if (doc.blocks.empty()) throw Error(name, "no CIF data block (data_...) in the file");
  const gemmi::cif::Block& block = doc.blocks[0];
  if (!block.has_tag("_atom_site.Cartn_x")) {
    if (isSmallMoleculeCif(block))
      throw Error(name, "a small-molecule CIF (no _atom_site.Cartn_x): only macromolecular mmCIF files are read");
    throw Error(name,
                "no atoms: not a macromolecular mmCIF file (no _atom_site.Cartn_x in block data_" + block.name + ")");
  }
  for (const char* tag : {"_atom_site.id", "_atom_site.type_symbol", "_atom_site.label_alt_id",
                          "_atom_site.label_asym_id", "_atom_site.Cartn_y", "_atom_site.Cartn_z",
                          "_atom_site.occupancy", "_atom_site.B_iso_or_equiv", "_atom_site.auth_seq_id"})
    if (!block.has_tag(tag)) throw Error(name, std::string("mmCIF _atom_site has no ") + tag + " column");
  return gemmi::make_structure(doc);
}

// gemmi's messages as one line without the source name we gave it; the CIF parser's positions
// ("12:34: …", "12 in data_X: …") spelled out.
std::string reason(std::string message, const std::string& name) {
  if (message.rfind(name, 0) == 0) {
    message.erase(0, name.size());
    while (!message.empty() && (message[0] == ':' || message[0] == ' ')) message.erase(0, 1);
  }
  const auto digitsFrom = [&](std::size_t i) {
    while (i < message.size() && std::isdigit(static_cast<unsigned char>(message[i])) != 0) ++i;
    return i;
  };
  if (const std::size_t line = digitsFrom(0); line > 0 && line < message.size()) {
    if (message[line] == ':') {
      const std::size_t column = digitsFrom(line + 1);
      if (column > line + 1 && column < message.size() && message[column] == ':')
        message = "line " + message.substr(0, line) + ", column " + message.substr(line + 1, column - line - 1) +
                  message.substr(column);
    } else if (message.compare(line, 4, " in ") == 0) {
      message = "line " + message;
    }
  }
  if (message.find("Wrong number of values in the loop") != std::string::npos) message += " (truncated or corrupt?)";
  for (char& c : message)
    if (c == '\n' || c == '\r') c = ' ';
  return message.empty() ? "cannot read the structure" : message;
}

struct Atom {
  glm::dvec3 position;
  gemmi::El element;
  // Colour-by fields (Mesh::fields) of its geometry: the B-factor (Å²), occupancy and residue
  // sequence number as the file gives them (PyMOL's b, q and resi).
  float bFactor = 0.0f;
  float occupancy = 1.0f;
  float residue = 0.0f;
  int serial = 0;
};

enum class PartKind { Polymer, Ligands, Water };

struct Part {
  std::string name;
  std::vector<Atom> atoms;
  PartKind kind = PartKind::Polymer;
  // A polymer chain's residues in file order, and the trace atom (Cα, P) of each that has one:
  // its fields are the cartoon's.
  std::vector<BackboneResidue> residues;
  std::vector<std::optional<Atom>> traceAtoms;
};

// The atoms of the first model sorted into parts: polymer chains by name in order of appearance,
// then ligands, then water. Of alternative locations, the first one that appears at a residue
// position (chain, sequence number, insertion code) is kept, and atoms without one.
std::vector<Part> partsOf(const gemmi::Model& model, const std::string& name, std::vector<std::string>& notes) {
  std::vector<Part> chains;
  std::map<std::string, std::size_t> chainIndex;
  Part ligands{"ligands", {}, PartKind::Ligands, {}, {}}, water{"water", {}, PartKind::Water, {}, {}};
  std::map<std::pair<std::string, gemmi::SeqId>, char> firstAltloc;
  std::size_t total = 0;
  // Atoms of no known element, and atoms at another's position (a file holding its atoms twice):
  // both were drawn without a word, with bonds missing around them (a bug hunt).
  std::size_t unknownElement = 0, repeated = 0;
  std::set<std::tuple<double, double, double>> positions;
  for (const gemmi::Chain& chain : model.chains) {
    for (const gemmi::Residue& residue : chain.residues) {
      char& chosen = firstAltloc[{chain.name, residue.seqid}];
      BackboneResidue backbone;
      std::optional<Atom> trace;
      std::optional<glm::dvec3> n1, n3;
      bool purine = false;
      Part* polymer = nullptr;
      for (const gemmi::Atom& atom : residue.atoms) {
        if (atom.altloc != '\0') {
          if (chosen == '\0') chosen = atom.altloc;
          if (atom.altloc != chosen) continue;
        }
        const glm::dvec3 p(atom.pos.x, atom.pos.y, atom.pos.z);
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) ||
            std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)}) > kMaxCoordinate) {
          std::ostringstream where;
          where << "atom " << atom.serial << " (" << atom.name << " of " << residue.name << " " << residue.seqid.str()
                << ", chain '" << chain.name << "') has coordinates (" << p.x << ", " << p.y << ", " << p.z
                << "), not finite or beyond ±" << kMaxCoordinate << " Å";
          throw Error(name, where.str());
        }
        if (++total > kMaxAtoms)
          throw Error(name, "more than " + std::to_string(kMaxAtoms) + " atoms in the first model: too many to draw");
        unknownElement += atom.element.elem == gemmi::El::X ? 1 : 0;
        repeated += positions.emplace(p.x, p.y, p.z).second ? 0 : 1;
        Part* part = nullptr;
        if (residue.entity_type == gemmi::EntityType::Polymer) {
          const auto [it, isNew] = chainIndex.try_emplace(chain.name, chains.size());
          if (isNew)
            chains.push_back(
                {chain.name.empty() ? "chain (blank)" : "chain " + chain.name, {}, PartKind::Polymer, {}, {}});
          part = &chains[it->second];
        } else {
          part = residue.entity_type == gemmi::EntityType::Water ? &water : &ligands;
        }
        const float number = residue.seqid.num.has_value() ? static_cast<float>(*residue.seqid.num)
                                                           : std::numeric_limits<float>::quiet_NaN();
        part->atoms.push_back({p, atom.element.elem, atom.b_iso, atom.occ, number, atom.serial});
        if (residue.entity_type != gemmi::EntityType::Polymer) continue;
        polymer = part;
        // The backbone atoms by name: PDB's and mmCIF's (label_atom_id) are the same. An atom of no
        // known element is taken by its name (a cartoon was refused for "no Cα" over CA atoms of
        // element X).
        const bool unknown = atom.element.elem == gemmi::El::X;
        const bool carbon = atom.element.elem == gemmi::El::C || unknown;
        if (atom.name == "N" && (atom.element.elem == gemmi::El::N || unknown) && !backbone.n) backbone.n = p;
        if (atom.name == "CA" && carbon && !backbone.ca) {
          backbone.ca = p;
          trace = part->atoms.back();
        }
        if (atom.name == "C" && carbon && !backbone.c) backbone.c = p;
        if (atom.name == "O" && (atom.element.elem == gemmi::El::O || unknown) && !backbone.o) backbone.o = p;
        // The ladder's end: N1 of a purine (which has N9), N3 of a pyrimidine.
        if (atom.name == "N1" && !n1) n1 = p;
        if (atom.name == "N3" && !n3) n3 = p;
        if (atom.name == "N9") purine = true;
        if (atom.name == "P" && atom.element.elem == gemmi::El::P && !backbone.phosphorus) {
          backbone.phosphorus = p;
          if (!backbone.ca) trace = part->atoms.back();
        }
      }
      if (polymer != nullptr) {
        if (backbone.phosphorus && !backbone.ca) backbone.base = purine ? n1 : n3;
        backbone.part = static_cast<std::size_t>(polymer - chains.data());
        backbone.chain = chain.name;
        backbone.number = residue.seqid.num.has_value() ? *residue.seqid.num : 0;
        backbone.insertion = residue.seqid.icode;
        backbone.name = residue.name;
        polymer->residues.push_back(std::move(backbone));
        polymer->traceAtoms.push_back(trace);
      }
    }
  }
  if (!ligands.atoms.empty()) chains.push_back(std::move(ligands));
  if (!water.atoms.empty()) chains.push_back(std::move(water));
  if (unknownElement > 0)
    notes.push_back(name + ": " + std::to_string(unknownElement) +
                    " atoms of no known element (drawn as element X; bonds near them may be missing)");
  if (repeated > 0)
    notes.push_back(name + ": " + std::to_string(repeated) +
                    " atoms at the position of another atom (the file holds them twice?); bonds near them may be "
                    "missing");
  return chains;
}

// A helix or strand as the file records it: a range of residues in one chain.
struct RecordedRange {
  std::string chain;
  gemmi::SeqId first, last;
  SecondaryStructure structure;
};

// The structure's first model, parsed, checked and sorted into parts.
struct Parsed {
  std::vector<Part> parts;
  std::size_t models = 1;
  std::vector<RecordedRange> recorded;  // the file's HELIX/SHEET (mmCIF struct_conf/sheet_range)
  bool structureFromFile = false;       // assignStructure took the records
  std::vector<std::string> notes;       // what was read other than a reader would expect
};

// Each polymer residue's secondary structure: the file's records when it has any that hold a
// residue (every helix class counts as helix, and helix wins where a strand overlaps it, as PyMOL
// reads them), otherwise DSSP's over the whole model (sheets join chains). Records that hold no
// residue at all (chains renamed or residues renumbered after the header was written) are not
// taken as "all loop", as PyMOL takes them, but as no records.
void assignStructure(Parsed& parsed, const std::string& name) {
  std::vector<BackboneResidue*> all;
  for (Part& part : parsed.parts)
    for (BackboneResidue& r : part.residues) all.push_back(&r);
  parsed.structureFromFile = false;
  if (!parsed.recorded.empty()) {
    // A range holds the chain's residues whose (number, insertion code) lies between its ends —
    // by value, so a range whose end residue is missing still ends there. Per chain, residues
    // sorted by that key, and each range adds one at its first residue and takes one off after
    // its last: a running sum says how many helices (strands) hold a residue.
    const auto key = [](int number, char insertion) {
      return static_cast<std::int64_t>(number) * 256 + static_cast<unsigned char>(insertion);
    };
    struct Chain {
      std::vector<std::pair<std::int64_t, BackboneResidue*>> residues;
      std::vector<int> helix, strand;  // the ranges' starts (+1) and ends (−1), per position
    };
    std::map<std::string, Chain> chains;
    for (BackboneResidue* r : all) chains[r->chain].residues.emplace_back(key(r->number, r->insertion), r);
    for (auto& [chainName, chain] : chains) {
      std::stable_sort(chain.residues.begin(), chain.residues.end(),
                       [](const auto& a, const auto& b) { return a.first < b.first; });
      chain.helix.assign(chain.residues.size() + 1, 0);
      chain.strand.assign(chain.residues.size() + 1, 0);
    }
    for (const RecordedRange& range : parsed.recorded) {
      const auto it = chains.find(range.chain);
      if (it == chains.end() || !range.first.num || !range.last.num) continue;
      Chain& chain = it->second;
      const std::int64_t first = key(*range.first.num, range.first.icode),
                         last = key(*range.last.num, range.last.icode);
      const auto lo = std::lower_bound(chain.residues.begin(), chain.residues.end(), first,
                                       [](const auto& r, std::int64_t k) { return r.first < k; });
      const auto hi = std::upper_bound(chain.residues.begin(), chain.residues.end(), last,
                                       [](std::int64_t k, const auto& r) { return k < r.first; });
      if (lo >= hi) continue;
      parsed.structureFromFile = true;
      std::vector<int>& counts = range.structure == SecondaryStructure::Helix ? chain.helix : chain.strand;
      ++counts[static_cast<std::size_t>(lo - chain.residues.begin())];
      --counts[static_cast<std::size_t>(hi - chain.residues.begin())];
    }
    for (auto& [chainName, chain] : chains) {
      if (!parsed.structureFromFile) break;
      int helix = 0, strand = 0;
      for (std::size_t k = 0; k < chain.residues.size(); ++k) {
        helix += chain.helix[k];
        strand += chain.strand[k];
        chain.residues[k].second->structure = helix > 0    ? SecondaryStructure::Helix
                                              : strand > 0 ? SecondaryStructure::Strand
                                                           : SecondaryStructure::Loop;
      }
    }
    if (parsed.structureFromFile) return;
  }
  std::vector<BackboneResidue> copy;
  copy.reserve(all.size());
  for (const BackboneResidue* r : all) copy.push_back(*r);
  std::vector<SecondaryStructure> ss;
  try {
    ss = mfr::assignSecondaryStructure(copy);
  } catch (const Error& e) {
    throw Error(name, e.what());
  }
  for (std::size_t i = 0; i < all.size(); ++i) all[i]->structure = ss[i];
}

// Solvent residue names: gemmi's waters and those of MD programs (GROMACS SOL, CHARMM TIP3, …),
// PyMOL's solvent.
bool isWater(const gemmi::Residue& residue) {
  static const std::array<std::string_view, 9> kSolvent = {"SOL", "TIP", "TIP3", "TIP4", "TIP5",
                                                           "T3P", "T4P", "T5P",  "SPC"};
  return residue.is_water() || std::find(kSolvent.begin(), kSolvent.end(), residue.name) != kSolvent.end();
}

// Whether `residue` is a link of a chain: an amino acid or a nucleotide by gemmi's table, or an
// untabulated residue with the backbone of one (N, Cα, C; or P) — but never a lone atom other than
// a Cα or P (a trace-only model): GROMACS's iodide "I" is inosine by the table.
bool isTabulatedChainResidue(const gemmi::Residue& residue) {
  const gemmi::ResidueInfo info = gemmi::find_tabulated_residue(residue.name);
  return info.found() && (info.is_amino_acid() || info.is_nucleic_acid());
}
bool isChainResidue(const gemmi::Residue& residue) {
  if (residue.atoms.size() == 1 && residue.atoms[0].name != "CA" && residue.atoms[0].name != "P") return false;
  const gemmi::ResidueInfo info = gemmi::find_tabulated_residue(residue.name);
  if (info.found()) return info.is_amino_acid() || info.is_nucleic_acid();
  // By atom names only: MD files' names start in column 13, where gemmi reads " CA" as calcium.
  const auto has = [&](const char* atom) { return residue.find_atom(atom, '*') != nullptr; };
  return (has("N") && has("CA") && has("C")) || (has("P") && (has("O3'") || has("O5'")));
}

// Whether two residues in a row are bonded as a chain is: a peptide bond (C of the first to N of
// the next) or a phosphodiester bond (O3' to P), at most 2 Å long (1.33 and 1.61 Å in proteins and
// nucleic acids).
bool linked(const gemmi::Residue& first, const gemmi::Residue& next) {
  const auto near = [](const gemmi::Atom* a, const gemmi::Atom* b) {
    return a != nullptr && b != nullptr && a->pos.dist(b->pos) <= 2.0;
  };
  const gemmi::Atom* o3 = first.find_atom("O3'", '*');
  if (o3 == nullptr) o3 = first.find_atom("O3*", '*');
  return near(first.find_atom("C", '*'), next.find_atom("N", '*')) || near(o3, next.find_atom("P", '*'));
}

// The serial numbers of a PDB file's ATOM/HETATM records that leave the element (columns 77–78)
// blank: `anyColumn` all of them, `fromColumn13` those that also start the atom name in column 13.
// Files written by MD programs (AMBER, CHARMM) do, and gemmi then takes Cα ("CA  ") for calcium and
// γ-hydrogens ("HG1 ") for mercury. A serial that also names a record that is not in a set is left
// out of it.
struct AtomsWithoutElements {
  std::unordered_set<int> fromColumn13, anyColumn;
};
AtomsWithoutElements pdbAtomsWithoutElements(const std::string& data) {
  const bool columns72 = hasLineNumbersInColumns73To80(data);  // read as 72 columns: no elements
  AtomsWithoutElements without, with;
  for (std::size_t start = 0; start < data.size();) {
    std::size_t end = data.find('\n', start);
    if (end == std::string::npos) end = data.size();
    const std::string_view line = withoutLineEnd(std::string_view(data).substr(start, end - start));
    start = end + 1;
    if (!isAtomRecord(line) || line.size() < 16) continue;
    // As gemmi reads it into Atom::serial: also hybrid-36 ("A0000" is 100000) and the "*****" of
    // programs past 99,999 atoms (0), where MD files put their ions.
    const int serial = gemmi::pdb_impl::read_serial(line.data() + 6);
    const bool blank = columns72 || line.size() < 78 || (line[76] == ' ' && line[77] == ' ');
    (blank ? without : with).anyColumn.insert(serial);
    (blank && line[12] != ' ' ? without : with).fromColumn13.insert(serial);
  }
  for (const int serial : with.anyColumn) without.anyColumn.erase(serial);
  for (const int serial : with.fromColumn13) without.fromColumn13.erase(serial);
  return without;
}

// Elements of the atoms of a chain residue (polymer or free), its caps and water, where the file
// does not give them (`unstated`: pdbAtomsWithoutElements' fromColumn13): those hold only H (D), C, N, O, S, P
// and Se, so an atom gemmi guessed as anything else from its name (or not at all: water's "OW",
// "HW1") is the element of its name's first letter (PyMOL reads AMBER and GROMACS files so too).
// The exception is a metal in a modified residue whose name starts with H: "HG" is serine's
// γ-hydrogen in an AMBER file and the mercury of S-(methylmercury)cysteine (CMH) in an old one.
// A hydrogen is bonded to an atom of its residue within 1.45 Å (S–H, the longest usual bond to
// hydrogen, is 1.34 Å); the mercury's nearest atoms are 2.1 Å (C) and 2.4 Å (S) away.
void fixChainElements(gemmi::Residue& residue, const std::unordered_set<int>& unstated) {
  for (gemmi::Atom& atom : residue.atoms) {
    if (!unstated.contains(atom.serial)) continue;
    const gemmi::El e = atom.element.elem;
    if (e == gemmi::El::H || e == gemmi::El::D || e == gemmi::El::C || e == gemmi::El::N || e == gemmi::El::O ||
        e == gemmi::El::S || e == gemmi::El::P || e == gemmi::El::Se)
      continue;
    const std::size_t letter = atom.name.find_first_not_of("0123456789 ");
    if (letter == std::string::npos) continue;
    const char first = atom.name[letter];
    // Not in residues of gemmi's table (their H-named atoms are hydrogens, wherever a periodic box
    // put them); another location of the same atom, or another hydrogen, is no bonding partner.
    if (first == 'H' && e != gemmi::El::X && !gemmi::find_tabulated_residue(residue.name).found() &&
        std::none_of(residue.atoms.begin(), residue.atoms.end(), [&](const gemmi::Atom& other) {
          const std::size_t o = other.name.find_first_not_of("0123456789 ");
          return other.name != atom.name && o != std::string::npos && other.name[o] != 'H' && other.name[o] != 'D' &&
                 other.pos.dist(atom.pos) <= 1.45;
        }))
      continue;
    // Only those elements; gemmi's Element reads the one-letter symbol.
    if (std::string_view("HDCNOSP").find(first) != std::string_view::npos)
      atom.element = gemmi::Element(std::string(1, first));
  }
}

// The element of an ion by its residue name in CHARMM's force field (SOD, POT, CLA, …) or AMBER's
// older LEaP libraries (IP = Na⁺, IM = Cl⁻), where the file does not give it (`unstated`: names from
// column 13 or 14): gemmi reads the atom names (also SOD, POT, IP, IM) as no element and polonium,
// or from column 14 as S and P.
void fixForceFieldIon(gemmi::Residue& residue, const std::unordered_set<int>& unstated) {
  struct Ion {
    std::string_view residue, atom, element;
  };
  static const std::array<Ion, 13> kIons = {{{"SOD", "SOD", "Na"},
                                             {"POT", "POT", "K"},
                                             {"CLA", "CLA", "Cl"},
                                             {"CAL", "CAL", "Ca"},
                                             {"CES", "CES", "Cs"},
                                             {"LIT", "LIT", "Li"},
                                             {"RUB", "RUB", "Rb"},
                                             {"BAR", "BAR", "Ba"},
                                             {"ZN2", "ZN", "Zn"},
                                             {"CD2", "CD", "Cd"},
                                             {"MG", "MG", "Mg"},
                                             {"IP", "IP", "Na"},
                                             {"IM", "IM", "Cl"}}};
  for (const Ion& ion : kIons) {
    if (residue.name != ion.residue) continue;
    // Each of its atoms named as the ion (several where a program numbered the ions as one residue).
    for (gemmi::Atom& atom : residue.atoms)
      if (atom.name == ion.atom && unstated.contains(atom.serial))
        atom.element = gemmi::Element(std::string(ion.element));
  }
}

// Entity types where the file does not give them (`given` false: a PDB file, whose TER records
// MD programs put anywhere, or an mmCIF file without _entity), residue by residue as PyMOL sorts
// them, not as gemmi's guess (the chain's residues up to the first one that is not of the chain's
// polymer type, so that a chain starting with an acetyl cap, or mixing protein and DNA, lost its
// polymer):
// * water and MD solvent: water;
// * amino acids and nucleotides: polymer if bonded to the residue before or after (a HETATM MSE
//   inside a chain) or, for those in gemmi's table, ATOM records (chain breaks); a lone HETATM one
//   (a free amino acid, ATP) and an unbonded untabulated one (an MD file's cofactor) are ligands;
// * anything else is a ligand unless it is bonded into the chain (ACE and NME caps).
void classifyResidues(gemmi::Chain& chain, const std::vector<bool>& given) {
  std::vector<gemmi::Residue>& residues = chain.residues;
  std::vector<bool> link(residues.size(), false);  // link[i]: residue i is bonded to i + 1
  std::vector<bool> inChain(residues.size(), false), water(residues.size(), false);
  for (std::size_t i = 0; i < residues.size(); ++i) {
    water[i] = isWater(residues[i]);
    inChain[i] = !water[i] && isChainResidue(residues[i]);
    if (i + 1 < residues.size()) link[i] = linked(residues[i], residues[i + 1]);
  }
  for (std::size_t i = 0; i < residues.size(); ++i) {
    if (given[i]) continue;
    gemmi::Residue& residue = residues[i];
    const bool before = i > 0 && link[i - 1], after = link[i];
    bool polymer = false;
    if (water[i])
      polymer = false;
    else if (inChain[i])
      // An untabulated one (a cofactor with N, CA and C atoms: SAM, AMP) only when bonded into the
      // chain: MD programs write ligands as ATOM records too.
      polymer = before || after || (residue.het_flag != 'H' && isTabulatedChainResidue(residue));
    else
      polymer = (before && inChain[i - 1]) || (after && inChain[i + 1]);
    residue.entity_type = polymer    ? gemmi::EntityType::Polymer
                          : water[i] ? gemmi::EntityType::Water
                                     : gemmi::EntityType::NonPolymer;
  }
}

Parsed parseMolecule(const std::string& contents, MoleculeFormat format, const std::string& name,
                     const LoadProgress& progress) {
  progress.step(0.0);
  gemmi::Structure st;
  try {
    st = parse(contents, format, name);
  } catch (const Error&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& e) {
    throw Error(name, reason(e.what(), name));
  }
  progress.step(0.5);

  const std::size_t models = st.models.size();
  if (models == 0 || std::none_of(st.models[0].chains.begin(), st.models[0].chains.end(), [](const gemmi::Chain& c) {
        return std::any_of(c.residues.begin(), c.residues.end(),
                           [](const gemmi::Residue& r) { return !r.atoms.empty(); });
      }))
    throw Error(name, format == MoleculeFormat::Pdb ? "no atoms (no ATOM or HETATM records in the first model)"
                                                    : "no atoms (the _atom_site table of the first model is empty)");
  st.models.erase(st.models.begin() + 1, st.models.end());  // first model only: NMR ensembles hold many
  // Entity types an mmCIF file gives (_entity.type of the residue's label_entity_id) are kept; the
  // others are sorted here (gemmi fills them from the subchains when _entity is missing: a water
  // first is all water, one residue a ligand, more a polymer).
  std::map<std::string, bool> typedEntity;
  if (format == MoleculeFormat::Mmcif)
    for (const gemmi::Entity& entity : st.entities)
      typedEntity[entity.name] = entity.entity_type != gemmi::EntityType::Unknown;
  std::vector<std::vector<bool>> given;
  for (const gemmi::Chain& chain : st.models[0].chains) {
    given.emplace_back();
    for (const gemmi::Residue& residue : chain.residues) {
      const auto it = typedEntity.find(residue.entity_id);
      given.back().push_back(it != typedEntity.end() && it->second);
    }
  }
  for (std::size_t c = 0; c < st.models[0].chains.size(); ++c) classifyResidues(st.models[0].chains[c], given[c]);
  if (format == MoleculeFormat::Pdb) {
    if (const AtomsWithoutElements unstated = pdbAtomsWithoutElements(contents); !unstated.anyColumn.empty()) {
      for (gemmi::Chain& chain : st.models[0].chains)
        for (gemmi::Residue& residue : chain.residues) {
          if (residue.entity_type != gemmi::EntityType::NonPolymer || isChainResidue(residue))
            fixChainElements(residue, unstated.fromColumn13);
          else
            fixForceFieldIon(residue, unstated.anyColumn);
        }
    }
  }
  std::vector<std::string> notes;
  std::vector<Part> parts = partsOf(st.models[0], name, notes);
  Parsed parsed{std::move(parts), models, {}, false, std::move(notes)};
  for (const gemmi::Helix& h : st.helices)
    parsed.recorded.push_back(
        {h.start.chain_name, h.start.res_id.seqid, h.end.res_id.seqid, SecondaryStructure::Helix});
  for (const gemmi::Sheet& sheet : st.sheets)
    for (const gemmi::Sheet::Strand& strand : sheet.strands)
      parsed.recorded.push_back(
          {strand.start.chain_name, strand.start.res_id.seqid, strand.end.res_id.seqid, SecondaryStructure::Strand});
  progress.step(0.55);
  return parsed;
}

int atomicNumber(gemmi::El element) {
  return element == gemmi::El::D ? 1 : static_cast<int>(element);
}

MoleculeStructure structureOf(const Parsed& parsed, const std::string& name) {
  MoleculeStructure out;
  out.models = parsed.models;
  out.secondaryStructureFromFile = parsed.structureFromFile;
  out.secondaryStructureRecordsUnmatched = !parsed.recorded.empty() && !parsed.structureFromFile;
  for (std::size_t p = 0; p < parsed.parts.size(); ++p) {
    out.parts.push_back(parsed.parts[p].name);
    for (const Atom& a : parsed.parts[p].atoms) out.atoms.push_back({a.serial, atomicNumber(a.element), a.position, p});
    out.residues.insert(out.residues.end(), parsed.parts[p].residues.begin(), parsed.parts[p].residues.end());
  }
  try {
    out.bonds = perceiveBonds(out.atoms);
  } catch (const Error& e) {
    throw Error(name, e.what());
  }
  return out;
}

// ---- geometry -----------------------------------------------------------------------------------

// The colour-by fields every representation carries: each atom's B-factor, occupancy and residue
// number (PyMOL's b, q and resi).
constexpr std::array<const char*, 3> kAtomFieldNames = {"b_factor", "occupancy", "residue"};

// Per-vertex colour and colour-by fields of an atom's geometry, appended together.
struct AtomMeshBuilder {
  Mesh mesh;
  MeshField bFactor{kAtomFieldNames[0], false, 1, {}}, occupancy{kAtomFieldNames[1], false, 1, {}},
      residue{kAtomFieldNames[2], false, 1, {}};

  void vertex(const Atom& atom, const glm::dvec3& position, const glm::vec3& normal) {
    mesh.positions.emplace_back(position);
    mesh.normals.push_back(normal);
    mesh.colors.push_back(elementColor(atom.element));
    bFactor.values.push_back(atom.bFactor);
    occupancy.values.push_back(atom.occupancy);
    residue.values.push_back(atom.residue);
  }
  [[nodiscard]] std::uint32_t next() const { return static_cast<std::uint32_t>(mesh.positions.size()); }

  void sphere(const Atom& atom, double radius, const UnitSphere& unit) {
    const std::uint32_t base = next();
    for (const glm::dvec3& u : unit.vertices) vertex(atom, atom.position + radius * u, glm::normalize(glm::vec3(u)));
    for (const std::uint32_t i : unit.indices) mesh.indices.push_back(base + i);
  }

  // An open tube of `sides` quads from `from` to `to` (the half of a bond on an atom's side).
  void tube(const Atom& atom, const glm::dvec3& from, const glm::dvec3& to, double radius, int sides) {
    const glm::dvec3 axis = glm::normalize(to - from);
    const glm::dvec3 u = anyPerpendicular(axis), v = glm::cross(axis, u);
    const std::uint32_t base = next();
    for (int s = 0; s < sides; ++s) {
      const double angle = 2.0 * std::numbers::pi * s / sides;
      const glm::dvec3 n = std::cos(angle) * u + std::sin(angle) * v;
      vertex(atom, from + radius * n, glm::vec3(n));
      vertex(atom, to + radius * n, glm::vec3(n));
    }
    for (int s = 0; s < sides; ++s) {
      const auto a = base + static_cast<std::uint32_t>(2 * s),
                 b = base + static_cast<std::uint32_t>(2 * ((s + 1) % sides));
      // Counter-clockwise seen from outside: (u, v, axis) is right-handed.
      mesh.indices.insert(mesh.indices.end(), {a, b, b + 1, a, b + 1, a + 1});
    }
  }

  Mesh take() {
    mesh.fields = {std::move(bFactor), std::move(occupancy), std::move(residue)};
    return std::move(mesh);
  }
};

// Stick and ball sizes: PyMOL's stick_radius (0.25 Å); Jmol's ball-and-stick default ("spacefill
// 23%; wireframe 0.15").
constexpr double kStickRadius = 0.25;
constexpr double kBallAndStickRadius = 0.15;
constexpr double kBallScale = 0.23;

// Tube sides for the sphere tessellation level (16, 8, 6).
int tubeSides(int level) {
  return level >= 2 ? 16 : level == 1 ? 8 : 6;
}

Mesh spheresMesh(const Part& part, const UnitSphere& unit) {
  AtomMeshBuilder b;
  for (const Atom& atom : part.atoms) b.sphere(atom, gemmi::vdw_radius(atom.element), unit);
  return b.take();
}

// Sticks (ballScale 0: joints of the stick radius at bonded atoms) or balls and sticks: each bond
// drawn as two half tubes, each in its atom's colour and part; an atom without bonds as a ball of
// 23 % of its van der Waals radius, so that ions and waters stay visible.
Mesh sticksMesh(const Part& part, std::size_t firstAtom, const std::vector<Atom*>& all,
                const std::vector<std::vector<std::uint32_t>>& bondedTo, double stickRadius, double ballScale,
                const UnitSphere& unit, int sides) {
  AtomMeshBuilder b;
  for (std::size_t i = 0; i < part.atoms.size(); ++i) {
    const Atom& atom = part.atoms[i];
    const std::vector<std::uint32_t>& bonds = bondedTo[firstAtom + i];
    const double ball = kBallScale * gemmi::vdw_radius(atom.element);
    if (bonds.empty())
      b.sphere(atom, std::max(stickRadius, ball), unit);
    else
      b.sphere(atom, ballScale > 0.0 ? std::max(stickRadius, ballScale * gemmi::vdw_radius(atom.element)) : stickRadius,
               unit);
    for (const std::uint32_t other : bonds)
      b.tube(atom, atom.position, 0.5 * (atom.position + all[other]->position), stickRadius, sides);
  }
  return b.take();
}

// PyMOL's colours by secondary structure (util.cbss): helix red, strand yellow, loop green.
glm::vec4 structureColor(SecondaryStructure s) {
  switch (s) {
    case SecondaryStructure::Helix:
      return {1.0f, 0.0f, 0.0f, 1.0f};
    case SecondaryStructure::Strand:
      return {1.0f, 1.0f, 0.0f, 1.0f};
    case SecondaryStructure::Loop:
      break;
  }
  return {0.0f, 1.0f, 0.0f, 1.0f};
}

// Consecutive traces farther apart than this belong to different runs (missing residues): Cα–Cα
// is 3.8 Å (2.9 Å in a cis peptide), P–P in a nucleic acid's backbone about 6–7.5 Å.
constexpr double kMaxCaStep = 4.5;
constexpr double kMaxPhosphorusStep = 8.0;
// Traces closer than this are one point; a turn sharper than 160° (virtual Cα angle under 20°; a
// protein's are 80–150°) is no backbone either: both are left out of the curve, which could not be
// a closed tube through them.
constexpr double kMinTraceStep = 0.01;
constexpr double kMaxReversal = -0.9397;  // cos 160°

// The chain's cartoon (cartoonMesh): runs of residues with a trace atom, split where the chain is
// broken; protein residues coloured by secondary structure, nucleotides by their P's element
// colour; the trace atoms' fields. As finely sampled as keeps `residues` within the triangle cap
// (down to 24 triangles a residue; 83,000 residues and more exceed it rather than lose residues).
Mesh cartoonOf(const Part& part, std::size_t residues) {
  CartoonOptions options;
  options.fieldNames.assign(kAtomFieldNames.begin(), kAtomFieldNames.end());
  for (const auto& [samples, sides] :
       {std::pair{8, 16}, std::pair{6, 12}, std::pair{4, 8}, std::pair{3, 6}, std::pair{2, 6}}) {
    options.samplesPerResidue = samples;
    options.sides = sides;
    // Per residue: its stretch of tube, and a nucleotide's ladder rod (4 triangles per side).
    if (residues * static_cast<std::size_t>(2 * samples * sides + 4 * std::max(sides / 2, 6)) <= kMoleculeTriangleCap)
      break;
  }
  std::vector<std::vector<CartoonResidue>> segments(1);
  const BackboneResidue* previous = nullptr;
  for (std::size_t i = 0; i < part.residues.size(); ++i) {
    const BackboneResidue& r = part.residues[i];
    const std::optional<Atom>& atom = part.traceAtoms[i];
    if (!atom) continue;
    const bool amino = r.ca.has_value();
    CartoonResidue c;
    c.trace = atom->position;
    if (r.c && r.o) c.guide = *r.o - *r.c;
    c.structure = r.structure;
    c.color = amino ? structureColor(r.structure) : elementColor(atom->element);
    c.values = {atom->bFactor, atom->occupancy, atom->residue};
    c.nucleic = !amino;
    if (!amino) c.ladder = r.base;
    if (previous != nullptr) {
      const bool previousAmino = previous->ca.has_value();
      const std::vector<CartoonResidue>& run = segments.back();
      const double step = glm::distance(run.back().trace, c.trace);
      if (previous->chain != r.chain || amino != previousAmino || step > (amino ? kMaxCaStep : kMaxPhosphorusStep)) {
        segments.emplace_back();
      } else if (step < kMinTraceStep) {
        continue;  // the same point again: no backbone; the tube would fold onto itself
      } else if (run.size() >= 2 && glm::dot(glm::normalize(run.back().trace - run[run.size() - 2].trace),
                                             glm::normalize(c.trace - run.back().trace)) < kMaxReversal) {
        segments.emplace_back();  // the trace turns back on itself: a new run (no backbone does)
      }
    }
    segments.back().push_back(std::move(c));
    previous = &r;
  }
  return cartoonMesh(segments, options);
}

// The part's solvent-excluded surface, each vertex coloured (and given the fields) of the atom
// whose van der Waals sphere is nearest to it, as PyMOL colours a surface. Its errors name the
// file and the part.
Mesh surfaceMesh(const Part& part, const std::string& name) {
  std::vector<SurfaceAtom> spheres;
  std::vector<glm::dvec3> centres;
  spheres.reserve(part.atoms.size());
  double largest = 0.0;
  for (const Atom& atom : part.atoms) {
    spheres.push_back({atom.position, gemmi::vdw_radius(atom.element)});
    centres.push_back(atom.position);
    largest = std::max(largest, spheres.back().radius);
  }
  const MolecularSurfaceOptions options;
  Mesh surface;
  double spacing = options.spacing;
  try {
    surface = solventExcludedSurface(spheres, options);
    spacing = molecularSurfaceSpacing(spheres, options);
  } catch (const Error& e) {
    throw Error(name, "the surface of '" + part.name + "': " + e.what());
  }
  // A surface point is at most the probe's diameter from its nearest sphere (it touches the probe,
  // which touches an atom), plus the grid's error.
  const double reach = largest + 2.0 * options.probeRadius + spacing;
  const PointGrid grid(centres, reach);
  AtomMeshBuilder b;
  for (std::size_t v = 0; v < surface.positions.size(); ++v) {
    const glm::dvec3 p(surface.positions[v]);
    std::size_t best = 0;
    double bestGap = std::numeric_limits<double>::infinity();
    grid.forEachWithin(p, reach, [&](std::uint32_t a, double d2) {
      const double gap = std::sqrt(d2) - spheres[a].radius;
      if (gap < bestGap || (gap == bestGap && a < best)) {
        bestGap = gap;
        best = a;
      }
    });
    b.vertex(part.atoms[best], p, surface.normals[v]);
  }
  b.mesh.indices = surface.indices;
  return b.take();
}

}  // namespace

int sphereSubdivisionLevel(std::size_t atoms) {
  for (int level = 2; level > 0; --level)
    if (atoms * (std::size_t{20} << (2 * level)) <= kMoleculeTriangleCap) return level;
  return 0;
}

MoleculeStructure readMoleculeStructure(const std::string& contents, MoleculeFormat format, const std::string& name) {
  Parsed parsed = parseMolecule(contents, format, name, {});
  assignStructure(parsed, name);
  return structureOf(parsed, name);
}

std::vector<Object> readMolecule(const std::string& contents, MoleculeFormat format, const std::string& name,
                                 const MoleculeStyle& style, const LoadProgress& progress,
                                 std::vector<std::string>* notes) {
  Parsed parsed = parseMolecule(contents, format, name, progress);
  std::vector<Part>& parts = parsed.parts;
  if (notes != nullptr) notes->insert(notes->end(), parsed.notes.begin(), parsed.notes.end());

  std::size_t atoms = 0;
  for (const Part& part : parts) atoms += part.atoms.size();
  const int level = sphereSubdivisionLevel(atoms);
  const UnitSphere& unit = icosphere(level);

  // Bonds over the whole model (a disulphide joins two chains; a ligand binds to a residue), as
  // lists per atom in the parts' order.
  std::vector<Atom*> all;
  std::vector<std::size_t> firstAtom;
  std::vector<std::vector<std::uint32_t>> bondedTo;
  if (style.sticks || style.ballAndStick) {
    const MoleculeStructure structure = structureOf(parsed, name);
    for (Part& part : parts) {
      firstAtom.push_back(all.size());
      for (Atom& atom : part.atoms) all.push_back(&atom);
    }
    bondedTo.resize(all.size());
    for (const Bond& bond : structure.bonds) {
      bondedTo[bond[0]].push_back(bond[1]);
      bondedTo[bond[1]].push_back(bond[0]);
    }
  }
  progress.step(0.6);

  // NMR ensembles: say which model is shown, in every part's name (the scene tree shows it).
  const std::string modelNote = parsed.models > 1 ? " (model 1 of " + std::to_string(parsed.models) + ")" : "";
  int representations = 0;
  for (const MoleculeParts& r : {style.spheres, style.ballAndStick, style.sticks, style.cartoon, style.surface})
    representations += r ? 1 : 0;
  std::size_t residues = 0;
  if (style.cartoon) {
    assignStructure(parsed, name);
    for (const Part& part : parts) residues += part.residues.size();
  }
  std::vector<Object> objects;
  std::map<std::string, std::size_t> drawn;  // parts per representation
  const auto add = [&](const Part& part, const char* representation, Mesh mesh) {
    if (mesh.indices.empty()) return;
    Object object;
    object.name = part.name + (representations > 1 ? std::string(" ") + representation : std::string()) + modelNote;
    object.mesh = std::make_shared<const Mesh>(std::move(mesh));
    // White, so that the per-vertex element colours show as they are; the default opacity.
    object.material.color = glm::vec4(1.0f, 1.0f, 1.0f, Material{}.color.a);
    objects.push_back(std::move(object));
    ++drawn[representation];
  };
  // Whether a representation is drawn on this part.
  const auto on = [](const MoleculeParts& drawnOn, const Part& part) {
    switch (part.kind) {
      case PartKind::Polymer:
        return drawnOn.polymer;
      case PartKind::Ligands:
        return drawnOn.ligands;
      case PartKind::Water:
        break;
    }
    return drawnOn.water;
  };
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const Part& part = parts[i];
    if (on(style.spheres, part)) add(part, "spheres", spheresMesh(part, unit));
    if (on(style.ballAndStick, part))
      add(part, "ball-and-stick",
          sticksMesh(part, firstAtom[i], all, bondedTo, kBallAndStickRadius, kBallScale, unit, tubeSides(level)));
    if (on(style.sticks, part))
      add(part, "sticks", sticksMesh(part, firstAtom[i], all, bondedTo, kStickRadius, 0.0, unit, tubeSides(level)));
    if (on(style.cartoon, part) && !part.residues.empty()) add(part, "cartoon", cartoonOf(part, residues));
    // Water has no surface of its own (PyMOL leaves solvent out of surfaces too).
    if (on(style.surface, part) && part.kind != PartKind::Water) add(part, "surface", surfaceMesh(part, name));
    progress.step(0.6 + 0.4 * static_cast<double>(i + 1) / static_cast<double>(parts.size()));
  }
  // What the structure has, and why a representation can draw nothing on it.
  const auto has = [&](PartKind kind) {
    return std::any_of(parts.begin(), parts.end(), [&](const Part& p) { return p.kind == kind; });
  };
  const auto whyNot = [&](MoleculeParts asked, std::string_view representation) {
    // The parts it can draw on: a cartoon only chains, a surface all but water.
    if (representation == "cartoon") asked.ligands = asked.water = false;
    if (representation == "surface") asked.water = false;
    if (!asked)
      return std::string(representation == "cartoon" ? "ligands and water have no cartoon" : "water has no surface");
    std::vector<std::string> missing;
    if (asked.polymer && !has(PartKind::Polymer)) missing.emplace_back("polymer chains");
    if (asked.ligands && !has(PartKind::Ligands)) missing.emplace_back("ligands");
    if (asked.water && !has(PartKind::Water)) missing.emplace_back("water");
    if (static_cast<int>(missing.size()) == int(asked.polymer) + int(asked.ligands) + int(asked.water)) {
      std::string text = "the structure has no " + missing[0];
      for (std::size_t k = 1; k < missing.size(); ++k) text += (k + 1 == missing.size() ? " or " : ", ") + missing[k];
      return text;
    }
    if (representation == "cartoon") {
      // Why cartoonOf made no run of two: too few trace atoms, or none of them in a row close enough.
      std::size_t mostTraces = 0;
      for (const Part& p : parts)
        if (p.kind == PartKind::Polymer)
          mostTraces = std::max<std::size_t>(mostTraces, std::count_if(p.traceAtoms.begin(), p.traceAtoms.end(),
                                                                       [](const auto& a) { return a.has_value(); }));
      if (mostTraces == 0) return std::string("no polymer residue has a Cα or P atom");
      if (mostTraces == 1) return std::string("no chain has two residues with Cα or P atoms");
      const auto number = [](double v) { return (std::ostringstream() << v).str(); };
      return "no chain has two residues in a row that make a backbone: Cα atoms at most " + number(kMaxCaStep) +
             " Å apart, or P atoms at most " + number(kMaxPhosphorusStep) + " Å apart";
    }
    return std::string("no atoms to draw");
  };
  if (objects.empty()) {
    std::vector<std::string> kinds;
    for (const auto& [kind, what] : {std::pair{PartKind::Polymer, "polymer chains"},
                                     std::pair{PartKind::Ligands, "ligands"}, std::pair{PartKind::Water, "water"}})
      if (has(kind)) kinds.push_back(what);
    std::string why = "the structure has " + kinds[0];
    for (std::size_t k = 1; k < kinds.size(); ++k) why += (k + 1 == kinds.size() ? " and " : ", ") + kinds[k];
    if (kinds.size() < 3) why += " only";
    if (style.cartoon) why += "; a cartoon needs a run of two polymer residues with Cα or P atoms";
    if (style.surface) why += "; water has no surface";
    throw Error(name, "nothing to draw as " + style.text() + " (" + why + ")");
  }
  if (notes != nullptr)
    for (const auto& [representation, asked] :
         {std::pair{"spheres", style.spheres}, std::pair{"ball-and-stick", style.ballAndStick},
          std::pair{"sticks", style.sticks}, std::pair{"cartoon", style.cartoon}, std::pair{"surface", style.surface}})
      if (asked && drawn[representation] == 0)
        notes->push_back(name + ": no " + representation + " drawn (" + whyNot(asked, representation) + ")");
  return objects;
}

}  // namespace mfr::io

namespace mfr {

namespace {

// More atoms than this in one cube of the bond search (about 2 Å a side) is no molecule.
constexpr std::size_t kMaxAtomsPerBondCell = 64;

// The most bonds an element makes, from the Blue Obelisk data Open Babel uses (its element table's
// MaxBnd): 6 for the elements not listed.
int maxBonds(int z) {
  switch (z) {
    case 1:
    case 3:
    case 9:
    case 11:
    case 17:
    case 19:
    case 35:
    case 37:
    case 53:
    case 55:
      return 1;  // H, alkali metals, halogens
    case 4:
    case 8:
    case 12:
    case 20:
    case 34:
    case 38:
    case 56:
      return 2;  // Be, O, Mg, Ca, Se, Sr, Ba
    case 31:
    case 33:
    case 49:
    case 51:
      return 3;  // Ga, As, In, Sb
    case 5:
    case 6:
    case 7:
    case 32:
    case 50:
      return 4;  // B, C, N, Ge, Sn
    case 15:
      return 5;  // P
    case 2:
    case 10:
    case 18:
    case 36:
    case 54:
    case 86:
      return 0;  // noble gases
    default:
      return 6;
  }
}

}  // namespace

std::vector<Bond> perceiveBonds(const std::vector<MoleculeAtom>& atoms) {
  std::vector<Bond> bonds;
  if (atoms.size() < 2) return bonds;
  const auto covalent = [&](std::size_t i) {
    const int z = atoms[i].atomicNumber;
    return static_cast<double>(gemmi::covalent_radius(z >= 0 && z <= 118 ? static_cast<gemmi::El>(z) : gemmi::El::X));
  };
  constexpr double kTolerance = 0.45, kShortest = 0.4;
  double largest = 0.0;
  std::vector<glm::dvec3> positions;
  positions.reserve(atoms.size());
  for (std::size_t i = 0; i < atoms.size(); ++i) {
    largest = std::max(largest, covalent(i));
    positions.push_back(atoms[i].position);
  }
  // Cubes as large as the longest bond possible: each atom's candidates lie in the 27 around it.
  const double reach = 2.0 * largest + kTolerance;
  const PointGrid grid(positions, reach);
  // No molecule packs atoms this densely (a protein has about 1 atom, or 2 with hydrogens, per
  // 10 Å³; the cube is ~12–30 Å³): refused rather than searched pair by pair.
  if (grid.largestCell() > kMaxAtomsPerBondCell)
    throw Error("bonds", std::to_string(grid.largestCell()) + " atoms in one cube of " +
                             std::to_string(static_cast<int>(std::lround(reach * 10.0)) / 10) + "." +
                             std::to_string(static_cast<int>(std::lround(reach * 10.0)) % 10) +
                             " Å: packed denser than any molecule");
  std::vector<std::vector<std::uint32_t>> bondedTo(atoms.size());
  for (std::size_t i = 0; i < atoms.size(); ++i) {
    const double ri = covalent(i);
    grid.forEachWithin(atoms[i].position, ri + largest + kTolerance, [&](std::uint32_t j, double d2) {
      if (j <= i) return;
      const double d = std::sqrt(d2);
      if (d > kShortest && d < ri + covalent(j) + kTolerance) {
        bondedTo[i].push_back(j);
        bondedTo[j].push_back(static_cast<std::uint32_t>(i));
      }
    });
  }
  // Clean-up, atom by atom in order: too many bonds, or two bonds closer than 45°, lose the longest
  // (a hydrogen its bond to another hydrogen first). The angle is looked at only once the count is
  // within the element's maximum, so a crowded atom costs its bonds squared, not cubed.
  const auto length = [&](std::size_t a, std::size_t b) { return glm::length(atoms[a].position - atoms[b].position); };
  const auto unbond = [&](std::size_t a, std::uint32_t b) {
    std::erase(bondedTo[a], b);
    std::erase(bondedTo[b], static_cast<std::uint32_t>(a));
  };
  const auto smallestAngle = [&](std::size_t a) {
    double smallest = 180.0;
    const std::vector<std::uint32_t>& n = bondedTo[a];
    for (std::size_t x = 0; x < n.size(); ++x)
      for (std::size_t y = x + 1; y < n.size(); ++y) {
        const glm::dvec3 u = glm::normalize(atoms[n[x]].position - atoms[a].position),
                         v = glm::normalize(atoms[n[y]].position - atoms[a].position);
        smallest = std::min(smallest, glm::degrees(std::acos(std::clamp(glm::dot(u, v), -1.0, 1.0))));
      }
    return smallest;
  };
  for (std::size_t a = 0; a < atoms.size(); ++a) {
    while (!bondedTo[a].empty() && (static_cast<int>(bondedTo[a].size()) > maxBonds(atoms[a].atomicNumber) ||
                                    (bondedTo[a].size() >= 2 && smallestAngle(a) < 45.0))) {
      std::vector<std::uint32_t>& n = bondedTo[a];
      if (atoms[a].atomicNumber == 1) {
        const auto hh = std::find_if(n.begin(), n.end(), [&](std::uint32_t b) { return atoms[b].atomicNumber == 1; });
        if (hh != n.end()) {
          unbond(a, *hh);
          continue;
        }
      }
      const auto longest = std::max_element(
          n.begin(), n.end(), [&](std::uint32_t x, std::uint32_t y) { return length(a, x) < length(a, y); });
      unbond(a, *longest);
    }
  }
  for (std::size_t a = 0; a < atoms.size(); ++a)
    for (const std::uint32_t b : bondedTo[a])
      if (a < b) bonds.push_back({static_cast<std::uint32_t>(a), b});
  std::sort(bonds.begin(), bonds.end());
  return bonds;
}

namespace {

// The representations in the order text() names them.
constexpr std::array<std::pair<MoleculeParts MoleculeStyle::*, const char*>, 5> kRepresentations = {
    std::pair{&MoleculeStyle::spheres, "spheres"}, std::pair{&MoleculeStyle::ballAndStick, "ball-and-stick"},
    std::pair{&MoleculeStyle::sticks, "sticks"}, std::pair{&MoleculeStyle::cartoon, "cartoon"},
    std::pair{&MoleculeStyle::surface, "surface"}};
constexpr std::array<std::pair<bool MoleculeParts::*, const char*>, 3> kPartKinds = {
    std::pair{&MoleculeParts::polymer, "polymer"}, std::pair{&MoleculeParts::ligands, "ligands"},
    std::pair{&MoleculeParts::water, "water"}};

}  // namespace

std::string MoleculeStyle::text() const {
  std::string out;
  const auto item = [&](const std::string& s) { out += (out.empty() ? "" : ",") + s; };
  for (const auto& [member, name] : kRepresentations) {
    const MoleculeParts& parts = this->*member;
    if (parts == MoleculeParts::all())
      item(name);
    else
      for (const auto& [kind, kindName] : kPartKinds)
        if (parts.*kind) item(std::string(name) + "@" + kindName);
  }
  return out;
}

MoleculeStyle MoleculeStyle::parse(const std::string& text, const std::string& what) {
  // Messages quote the option and the name as one short line, whatever was typed.
  const auto quoted = [](const std::string& s) {
    std::string line = io::oneLine(s);
    if (line.size() > 48) line = line.substr(0, 45) + "...";
    return line;
  };
  // A name in quotes keeps a trailing blank, which oneLine drops: 'sticks ' read as the valid name
  // it is not.
  const auto quotedName = [&](const std::string& s) {
    std::string line = quoted(s);
    if (line.size() <= 48 && !s.empty() && std::isspace(static_cast<unsigned char>(s.back())) != 0) line += ' ';
    return line;
  };
  constexpr const char* kExpected =
      " spheres, sticks, ball-and-stick, cartoon or surface, joined by ',' (cartoon,sticks@ligands: '@' "
      "limits one to polymer, ligands or water)";
  MoleculeStyle style;
  style.spheres = {};
  bool any = false;
  std::string item;
  for (std::size_t i = 0; i <= text.size(); ++i) {
    if (i < text.size() && text[i] != ',' && text[i] != '+') {
      item += text[i];
      continue;
    }
    const std::size_t at = item.find('@');
    const std::string name = item.substr(0, at);
    const auto representation =
        std::find_if(kRepresentations.begin(), kRepresentations.end(), [&](const auto& r) { return name == r.second; });
    if (representation == kRepresentations.end())
      throw Error(quoted(what), (item.empty() ? std::string("expected")
                                              : "unknown representation '" + quotedName(name) + "': expected") +
                                    kExpected);
    MoleculeParts& parts = style.*(representation->first);
    if (at == std::string::npos) {
      parts = MoleculeParts::all();
    } else {
      const std::string kind = item.substr(at + 1);
      const auto k =
          std::find_if(kPartKinds.begin(), kPartKinds.end(), [&](const auto& p) { return kind == p.second; });
      if (k == kPartKinds.end())
        throw Error(quoted(what), "unknown part '" + quotedName(kind) + "' after '" + quoted(name) +
                                      "@': expected polymer, ligands or water");
      parts.*(k->first) = true;
    }
    any = true;
    item.clear();
  }
  if (!any) throw Error(quoted(what), std::string("expected") + kExpected);
  return style;
}

std::string elementSymbol(int atomicNumber) {
  if (atomicNumber <= 0 || atomicNumber > static_cast<int>(gemmi::El::Og)) return "X";
  return gemmi::element_name(static_cast<gemmi::El>(atomicNumber));
}

}  // namespace mfr
