// loadModel: picks the loader family by extension, reads compressed files into memory, and makes
// sure that whatever goes wrong leaves as one mfr::Error("<path>", "<one-line reason>").
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <new>
#include <optional>
#include <set>
#include <string>

#include <unistd.h>
#include <zlib.h>

#include "assimp_loader.hpp"
#include "file_checks.hpp"
#include "mfr/error.hpp"
#include "mfr/host_memory.hpp"
#include "mfr/io/load.hpp"
#include "mfr/io/molecule.hpp"
#include "molecule_loader.hpp"
#include "obj_loader.hpp"
#include "off_loader.hpp"
#include "ply_loader.hpp"
#include "step_loader.hpp"
#include "vtk_legacy_loader.hpp"
#include "vtk_loader.hpp"

namespace mfr {
namespace {

namespace fs = std::filesystem;

enum class Family { Vtk, Ply, Off, Obj, VtkLegacy, Assimp, Step, Molecule };

struct Format {
  Family family;
  io::VtkFormat vtk = io::VtkFormat::Stl;
};

// Decompressed data beyond this is refused (a gzip bomb, or a file we could not hold anyway).
constexpr std::uint64_t kMaxDecompressedBytes = std::uint64_t{4} << 30;

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

const std::map<std::string, Format>& formats() {
  static const std::map<std::string, Format> table = [] {
    std::map<std::string, Format> t;
    for (const std::string& ext : io::assimpExtensions()) t[ext] = {Family::Assimp};
    t[".stl"] = {Family::Vtk, io::VtkFormat::Stl};
    t[".obj"] = {Family::Obj};
    t[".vtp"] = {Family::Vtk, io::VtkFormat::Vtp};
    t[".vtk"] = {Family::VtkLegacy};
    t[".ply"] = {Family::Ply};
    t[".off"] = {Family::Off};
    t[".step"] = {Family::Step};
    t[".stp"] = {Family::Step};
    for (const char* ext : {".pdb", ".ent", ".cif", ".mmcif"}) t[ext] = {Family::Molecule};  // gemmi
    return t;
  }();
  return table;
}

// The longest registered extension ending the (lower-case) file name, e.g. ".mesh.xml".
std::optional<std::pair<std::string, Format>> match(const std::string& lowerName) {
  std::optional<std::pair<std::string, Format>> best;
  for (const auto& [ext, format] : formats())
    if (lowerName.size() > ext.size() && endsWith(lowerName, ext) && (!best || ext.size() > best->first.size()))
      best = {ext, format};
  return best;
}

std::string readAll(const fs::path& path, const std::string& name) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(name, "cannot open file for reading");
  std::string data;
  const std::uintmax_t size = fs::file_size(path);
  if (size >= (std::uintmax_t{64} << 20))  // as readFile (a bug hunt: 2 GB at a 500 MiB limit)
    requireHostMemory(name, "reading the file (" + formatMemory(size) + ")", size);
  data.resize(static_cast<std::size_t>(size));
  in.read(data.data(), static_cast<std::streamsize>(data.size()));
  if (in.gcount() != static_cast<std::streamsize>(data.size()))
    throw Error(name, "read error (file changed while reading?)");
  return data;
}

// Whole .gz file into memory. gzread would pass non-gzip bytes through unchanged, so the magic is
// checked first; truncated or corrupt streams are errors, not short data.
std::string decompress(const fs::path& path, const std::string& name) {
  {
    std::ifstream in(path, std::ios::binary);
    unsigned char magic[2] = {0, 0};
    in.read(reinterpret_cast<char*>(magic), 2);
    if (in.gcount() != 2 || magic[0] != 0x1f || magic[1] != 0x8b)
      throw Error(name, "not a gzip file (bad magic bytes)");
  }
  gzFile gz = gzopen(path.c_str(), "rb");
  if (gz == nullptr) throw Error(name, "cannot open gzip file");
  const std::unique_ptr<gzFile_s, int (*)(gzFile)> closer(gz, gzclose);
  gzbuffer(gz, 1 << 17);
  std::string out;
  std::string chunk(1 << 20, '\0');
  while (true) {
    const int n = gzread(gz, chunk.data(), static_cast<unsigned>(chunk.size()));
    if (n < 0) {
      int code = 0;
      const char* message = gzerror(gz, &code);
      throw Error(name, std::string("corrupt gzip data: ") + (message ? message : "read error"));
    }
    if (n == 0) break;
    // Growing the string takes about twice what it holds: asked of the host's memory first (an
    // 8.7 MB .ply.gz held 2.2 GB at a 500 MiB limit; a bug hunt).
    if (out.size() + static_cast<std::size_t>(n) > out.capacity() && out.capacity() >= (std::size_t{32} << 20))
      requireHostMemory(name, "decompressing (" + formatMemory(out.size()) + " so far)",
                        2 * std::max<std::uint64_t>(out.capacity(), chunk.size()));
    out.append(chunk.data(), static_cast<std::size_t>(n));
    if (out.size() > kMaxDecompressedBytes) throw Error(name, "decompressed data exceeds 4 GiB");
  }
  int code = Z_OK;
  const char* message = gzerror(gz, &code);
  if (code != Z_OK && code != Z_STREAM_END)
    throw Error(name, std::string("corrupt or truncated gzip data: ") + (message ? message : "read error"));
  if (out.empty()) throw Error(name, "empty file (after decompression)");
  return out;
}

// A file's per-vertex colours are the part's colours ("the file's colours", docs/scene-format.md):
// its material is white, keeping the default opacity, so that they are not tinted by the light grey
// of parts without colours (pure red came out 204, a bug hunt).
void takeVertexColours(Object& object) {
  if (!object.mesh->colors.empty()) object.material.color = glm::vec4(1.0f, 1.0f, 1.0f, object.material.color.a);
}

std::vector<Object> singleObject(Mesh mesh, const std::string& partName) {
  Object object;
  object.name = partName;
  object.mesh = std::make_shared<const Mesh>(std::move(mesh));
  takeVertexColours(object);
  return {std::move(object)};
}

std::vector<Object> load(const fs::path& path, const std::string& name, const LoadOptions& options,
                         const LoadProgress& progress) {
  io::checkReadable(path, name, "model");
  if (isVolumeFile(path))
    throw Error(name,
                "is a volume file, not a model: open it as a scene, or list it under \"volumes\" in a .mfrscene file");

  std::string fileName = lower(path.filename().string());
  const bool gz = endsWith(fileName, ".gz");
  if (gz) fileName.resize(fileName.size() - 3);
  const auto found = match(fileName);
  if (!found) {
    const std::string ext = path.extension().string();
    if (gz) throw Error(name, "unsupported compressed file type: name it after its contents, e.g. model.ply.gz");
    throw Error(
        name,
        "unsupported file type '" + (ext.empty() ? path.filename().string() : lower(ext)) +
            "' (supported: .stl .ply .obj .off .vtp .vtk .step .stp .glb .gltf and the other formats "
            "assimp reads, .pdb .ent .cif .mmcif molecules, optionally gzip-compressed as .gz; volumes: .vti .vtk "
            ".mha .mhd .nrrd .nhdr .inr(.gz) .vdb, InVesalius .inv3; scenes: .mfrscene)");
  }
  const auto& [ext, format] = *found;
  // The part name of single-object formats: the file name without its extension(s).
  std::string stem = path.filename().string();
  stem.resize(stem.size() - ext.size() - (gz ? 3 : 0));

  std::string data;
  const std::string* contents = nullptr;
  if (gz) {
    data = decompress(path, name);
    contents = &data;
    progress.step(0.3);
  }

  switch (format.family) {
    case Family::Vtk:
      return singleObject(io::readWithVtk(format.vtk, path, contents, name), stem);
    case Family::Ply:
    case Family::Off:
    case Family::VtkLegacy: {
      if (!gz) data = readAll(path, name);
      const io::PolygonSoup soup = format.family == Family::Ply   ? io::parsePly(data, name)
                                   : format.family == Family::Off ? io::parseOff(data, name)
                                                                  : io::parseLegacyVtk(data, name);
      data.clear();
      data.shrink_to_fit();
      return singleObject(io::meshFromSoup(soup, name), stem);
    }
    case Family::Obj: {
      if (!gz) data = readAll(path, name);
      std::vector<io::ObjPart> parts = io::parseObj(data, path.parent_path(), name, options.notes);
      data.clear();
      data.shrink_to_fit();
      std::vector<Object> objects;
      for (io::ObjPart& part : parts) {
        Object object;
        // Parts are named by material; a file without materials is one part named by the file.
        object.name = parts.size() == 1 && part.material.empty() ? stem
                      : part.material.empty()                    ? stem + " (no material)"
                                                                 : part.material;
        object.mesh = std::make_shared<const Mesh>(io::meshFromSoup(part.soup, name));
        if (part.color)
          object.material.color = *part.color;  // a material's Kd tints the vertex colours, as OBJ viewers draw them
        else
          takeVertexColours(object);
        objects.push_back(std::move(object));
      }
      return objects;
    }
    case Family::Assimp:
      return io::readWithAssimp(path, contents, ext, name, progress.part(gz ? 0.3 : 0.0, 0.95));
    case Family::Step:
      return io::readStep(path, contents, stem, name, progress.part(gz ? 0.3 : 0.0, 0.95), options.notes);
    case Family::Molecule: {
      if (!gz) data = readAll(path, name);
      const auto molecule = ext == ".pdb" || ext == ".ent" ? io::MoleculeFormat::Pdb : io::MoleculeFormat::Mmcif;
      return io::readMolecule(data, molecule, name, options.molecule.value_or(MoleculeStyle{}),
                              progress.part(gz ? 0.3 : 0.0, 0.95), options.notes);
    }
  }
  throw Error(name, "unsupported file type");
}

}  // namespace

std::vector<Object> loadModel(const fs::path& path, const LoadProgress& progress) {
  return loadModel(path, LoadOptions{}, progress);
}

bool isMoleculeFile(const fs::path& path) {
  std::string fileName = lower(path.filename().string());
  if (endsWith(fileName, ".gz")) fileName.resize(fileName.size() - 3);
  const auto found = match(fileName);
  return found && found->second.family == Family::Molecule;
}

MoleculeStructure readMoleculeStructure(const fs::path& path) {
  const std::string name = path.string();
  return io::withFileErrors(name, [&] {
    io::checkReadable(path, name, "molecule");
    if (!isMoleculeFile(path)) throw Error(name, "not a molecule file (.pdb .ent .cif .mmcif, optionally .gz)");
    const std::string data =
        endsWith(lower(path.filename().string()), ".gz") ? decompress(path, name) : readAll(path, name);
    std::string fileName = lower(path.filename().string());
    if (endsWith(fileName, ".gz")) fileName.resize(fileName.size() - 3);
    const bool pdb = endsWith(fileName, ".pdb") || endsWith(fileName, ".ent");
    return io::readMoleculeStructure(data, pdb ? io::MoleculeFormat::Pdb : io::MoleculeFormat::Mmcif, name);
  });
}

std::vector<Object> loadModel(const fs::path& path, const LoadOptions& options, const LoadProgress& progress) {
  const std::string name = path.string();
  if (!options.field.empty())
    throw Error(name, "field '" + options.field + "' can be chosen only for a volume file (this is not one)");
  if (options.molecule && !isMoleculeFile(path))
    throw Error(name, "a molecule representation (" + options.molecule->text() +
                          ") can be chosen only for a molecule file (.pdb .ent .cif .mmcif)");
  return io::withFileErrors(name, [&] {
    progress.step(0.0);
    std::vector<Object> objects = load(path, name, options, progress);
    if (objects.empty()) throw Error(name, "no triangles");
    // Part names as UTF-8 (a Latin-1 name in an OBJ ended `--json` in an internal error).
    for (Object& object : objects) object.name = io::utf8Name(object.name);
    // Every mesh once (assemblies share meshes between parts): the invariants renderers rely on.
    std::set<const Mesh*> checked;
    for (Object& object : objects) {
      if (!object.mesh) throw Error(name, "part '" + object.name + "' has no mesh");
      if (!checked.insert(object.mesh.get()).second) continue;
      const std::string label = objects.size() == 1 ? name : name + " (part '" + object.name + "')";
      object.mesh->validate(label);
      if (object.mesh->normals.size() != object.mesh->positions.size()) {
        auto fixed = std::make_shared<Mesh>(*object.mesh);
        fixed->computeSmoothNormals();
        const Mesh* old = object.mesh.get();
        for (Object& other : objects)
          if (other.mesh.get() == old) other.mesh = fixed;
        checked.insert(fixed.get());
      }
    }
    progress.step(1.0);
    return objects;
  });
}

std::vector<std::string> supportedModelExtensions() {
  std::set<std::string> out;
  for (const auto& [ext, format] : formats()) out.insert(ext);
  // Compressed variants that parse from memory without side files.
  for (const char* ext :
       {".stl", ".ply", ".obj", ".off", ".vtp", ".vtk", ".glb", ".step", ".stp", ".pdb", ".ent", ".cif", ".mmcif"})
    out.insert(std::string(ext) + ".gz");
  return {out.begin(), out.end()};
}

}  // namespace mfr
