#include "molecule_loader.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <utility>

#include <gemmi/cif.hpp>
#include <gemmi/elem.hpp>
#include <gemmi/mmcif.hpp>
#include <gemmi/model.hpp>
#include <gemmi/pdb.hpp>
#include <gemmi/polyheur.hpp>

#include "mfr/error.hpp"

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

struct UnitSphere {
  std::vector<glm::dvec3> vertices;  // unit length
  std::vector<std::uint32_t> indices;
};

// The icosahedron subdivided `level` times, every new vertex pushed out to the unit sphere;
// triangles counter-clockwise seen from outside. 10·4^level + 2 vertices, 20·4^level triangles.
// At level ≥ 1 the six points (±1, 0, 0), (0, ±1, 0), (0, 0, ±1) are vertices (midpoints of the
// icosahedron's edges along the axes), so a sphere's bounding box is its centre ± radius.
UnitSphere makeIcosphere(int level) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  UnitSphere s;
  for (const glm::dvec3& v : {glm::dvec3(-1, t, 0), glm::dvec3(1, t, 0), glm::dvec3(-1, -t, 0), glm::dvec3(1, -t, 0),
                              glm::dvec3(0, -1, t), glm::dvec3(0, 1, t), glm::dvec3(0, -1, -t), glm::dvec3(0, 1, -t),
                              glm::dvec3(t, 0, -1), glm::dvec3(t, 0, 1), glm::dvec3(-t, 0, -1), glm::dvec3(-t, 0, 1)})
    s.vertices.push_back(glm::normalize(v));
  s.indices = {0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11, 1, 5, 9, 5, 11, 4,  11, 10, 2,  10, 7, 6, 7, 1, 8,
               3, 9,  4, 3, 4, 2, 3, 2, 6, 3, 6, 8,  3, 8,  9,  4, 9, 5, 2, 4,  11, 6,  2,  10, 8,  6, 7, 9, 8, 1};
  for (int l = 0; l < level; ++l) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> midpoints;
    const auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
      const auto key = std::minmax(a, b);
      const auto [it, isNew] = midpoints.try_emplace(key, static_cast<std::uint32_t>(s.vertices.size()));
      if (isNew) s.vertices.push_back(glm::normalize(s.vertices[a] + s.vertices[b]));
      return it->second;
    };
    std::vector<std::uint32_t> finer;
    finer.reserve(4 * s.indices.size());
    for (std::size_t i = 0; i < s.indices.size(); i += 3) {
      const std::uint32_t a = s.indices[i], b = s.indices[i + 1], c = s.indices[i + 2];
      const std::uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
      finer.insert(finer.end(), {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca});
    }
    s.indices = std::move(finer);
  }
  // Orientation made certain rather than trusted to the table: outward normals.
  for (std::size_t i = 0; i < s.indices.size(); i += 3) {
    const glm::dvec3 &a = s.vertices[s.indices[i]], &b = s.vertices[s.indices[i + 1]],
                     &c = s.vertices[s.indices[i + 2]];
    if (glm::dot(glm::cross(b - a, c - a), a + b + c) < 0.0) std::swap(s.indices[i + 1], s.indices[i + 2]);
  }
  return s;
}

const UnitSphere& icosphere(int level) {
  static const std::array<UnitSphere, 3> spheres = {makeIcosphere(0), makeIcosphere(1), makeIcosphere(2)};
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
    return gemmi::read_pdb_from_memory(data.data(), data.size(), name, options);
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
  // Colour-by fields (Mesh::fields) of its sphere: the B-factor (Å²), occupancy and residue
  // sequence number as the file gives them (PyMOL's b, q and resi).
  float bFactor = 0.0f;
  float occupancy = 1.0f;
  float residue = 0.0f;
};

struct Part {
  std::string name;
  std::vector<Atom> atoms;
};

// The atoms of the first model sorted into parts: polymer chains by name in order of appearance,
// then ligands, then water. Of alternative locations, the first one that appears at a residue
// position (chain, sequence number, insertion code) is kept, and atoms without one.
std::vector<Part> partsOf(const gemmi::Model& model, const std::string& name) {
  std::vector<Part> chains;
  std::map<std::string, std::size_t> chainIndex;
  Part ligands{"ligands", {}}, water{"water", {}};
  std::map<std::pair<std::string, gemmi::SeqId>, char> firstAltloc;
  std::size_t total = 0;
  for (const gemmi::Chain& chain : model.chains) {
    for (const gemmi::Residue& residue : chain.residues) {
      char& chosen = firstAltloc[{chain.name, residue.seqid}];
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
        Part* part = nullptr;
        if (residue.entity_type == gemmi::EntityType::Polymer) {
          const auto [it, isNew] = chainIndex.try_emplace(chain.name, chains.size());
          if (isNew) chains.push_back({chain.name.empty() ? "chain (blank)" : "chain " + chain.name, {}});
          part = &chains[it->second];
        } else {
          part = residue.entity_type == gemmi::EntityType::Water ? &water : &ligands;
        }
        const float number = residue.seqid.num.has_value() ? static_cast<float>(*residue.seqid.num)
                                                           : std::numeric_limits<float>::quiet_NaN();
        part->atoms.push_back({p, atom.element.elem, atom.b_iso, atom.occ, number});
      }
    }
  }
  if (!ligands.atoms.empty()) chains.push_back(std::move(ligands));
  if (!water.atoms.empty()) chains.push_back(std::move(water));
  return chains;
}

Mesh sphereMesh(const std::vector<Atom>& atoms, const UnitSphere& unit) {
  Mesh mesh;
  const std::size_t nv = unit.vertices.size();
  mesh.positions.reserve(atoms.size() * nv);
  mesh.normals.reserve(atoms.size() * nv);
  mesh.colors.reserve(atoms.size() * nv);
  mesh.indices.reserve(atoms.size() * unit.indices.size());
  std::vector<glm::vec3> normals;
  for (const glm::dvec3& u : unit.vertices) normals.push_back(glm::normalize(glm::vec3(u)));
  MeshField bFactor{"b_factor", false, 1, {}}, occupancy{"occupancy", false, 1, {}}, residue{"residue", false, 1, {}};
  for (MeshField* f : {&bFactor, &occupancy, &residue}) f->values.reserve(atoms.size() * nv);
  for (const Atom& atom : atoms) {
    bFactor.values.insert(bFactor.values.end(), nv, atom.bFactor);
    occupancy.values.insert(occupancy.values.end(), nv, atom.occupancy);
    residue.values.insert(residue.values.end(), nv, atom.residue);
    const auto base = static_cast<std::uint32_t>(mesh.positions.size());
    const double r = gemmi::vdw_radius(atom.element);
    const glm::vec4 color = elementColor(atom.element);
    for (std::size_t k = 0; k < nv; ++k) {
      mesh.positions.emplace_back(atom.position + r * unit.vertices[k]);
      mesh.normals.push_back(normals[k]);
      mesh.colors.push_back(color);
    }
    for (const std::uint32_t i : unit.indices) mesh.indices.push_back(base + i);
  }
  mesh.fields = {std::move(bFactor), std::move(occupancy), std::move(residue)};
  return mesh;
}

}  // namespace

int sphereSubdivisionLevel(std::size_t atoms) {
  for (int level = 2; level > 0; --level)
    if (atoms * (std::size_t{20} << (2 * level)) <= kMoleculeTriangleCap) return level;
  return 0;
}

std::vector<Object> readMolecule(const std::string& contents, MoleculeFormat format, const std::string& name,
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
  progress.step(0.6);

  const std::size_t models = st.models.size();
  if (models == 0 || std::none_of(st.models[0].chains.begin(), st.models[0].chains.end(), [](const gemmi::Chain& c) {
        return std::any_of(c.residues.begin(), c.residues.end(),
                           [](const gemmi::Residue& r) { return !r.atoms.empty(); });
      }))
    throw Error(name, format == MoleculeFormat::Pdb ? "no atoms (no ATOM or HETATM records in the first model)"
                                                    : "no atoms (the _atom_site table of the first model is empty)");
  st.models.erase(st.models.begin() + 1, st.models.end());  // first model only: NMR ensembles hold many
  try {
    gemmi::setup_entities(st);  // entity types (polymer, non-polymer, water) where the file lacks them
  } catch (const std::exception& e) {
    throw Error(name, reason(e.what(), name));
  }
  std::vector<Part> parts = partsOf(st.models[0], name);
  progress.step(0.65);

  std::size_t atoms = 0;
  for (const Part& part : parts) atoms += part.atoms.size();
  const UnitSphere& unit = icosphere(sphereSubdivisionLevel(atoms));
  // NMR ensembles: say which model is shown, in every part's name (the scene tree shows it).
  const std::string modelNote = models > 1 ? " (model 1 of " + std::to_string(models) + ")" : "";
  std::vector<Object> objects;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    Object object;
    object.name = parts[i].name + modelNote;
    object.mesh = std::make_shared<const Mesh>(sphereMesh(parts[i].atoms, unit));
    // White, so that the per-vertex element colours show as they are; the default opacity.
    object.material.color = glm::vec4(1.0f, 1.0f, 1.0f, Material{}.color.a);
    objects.push_back(std::move(object));
    parts[i].atoms = {};
    progress.step(0.65 + 0.35 * static_cast<double>(i + 1) / static_cast<double>(parts.size()));
  }
  return objects;
}

}  // namespace mfr::io
