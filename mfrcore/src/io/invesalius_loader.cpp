#include "invesalius_loader.hpp"

#include <archive.h>
#include <archive_entry.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

#include <vtkNew.h>
#include <vtkXMLDataElement.h>
#include <vtkXMLDataParser.h>

#include "file_checks.hpp"
#include "mfr/error.hpp"
#include "mfr/host_memory.hpp"
#include "volume_loader.hpp"
#include "vtk_loader.hpp"

namespace mfr::io {
namespace {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------------------------
// The archive: every member this loader may need, by its base name (InVesalius writes them in a
// temporary folder inside the tar). Masks (mask_N.dat, the size of the matrix each) are skipped.

// A property list or a surface is far below this; only the matrix may be larger, and its size is
// known from main.plist before it is used.
constexpr la_int64_t kMaxMemberBytes = la_int64_t{1} << 33;  // 8 GiB: 2^30 float64 samples
constexpr la_int64_t kMaxPlistBytes = la_int64_t{1} << 22;

std::string baseName(const std::string& member) {
  const std::size_t slash = member.find_last_of('/');
  return slash == std::string::npos ? member : member.substr(slash + 1);
}

bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::map<std::string, std::string> readMembers(const fs::path& path, const std::string& name,
                                               const LoadProgress& progress) {
  const std::unique_ptr<archive, int (*)(archive*)> a(archive_read_new(), archive_read_free);
  if (!a) throw Error(name, "out of memory");
  archive_read_support_filter_gzip(a.get());
  archive_read_support_format_tar(a.get());
  if (archive_read_open_filename(a.get(), path.c_str(), 1 << 16) != ARCHIVE_OK)
    throw Error(name, std::string("not an InVesalius project (a gzip-compressed tar): ") +
                          (archive_error_string(a.get()) ? archive_error_string(a.get()) : "unreadable"));
  std::error_code ec;
  const double fileSize = std::max(1.0, static_cast<double>(fs::file_size(path, ec)));
  std::map<std::string, std::string> members;
  archive_entry* entry = nullptr;
  for (;;) {
    const int r = archive_read_next_header(a.get(), &entry);
    if (r == ARCHIVE_EOF) break;
    if (r != ARCHIVE_OK && r != ARCHIVE_WARN)
      throw Error(name, std::string("corrupt or truncated project archive: ") +
                            (archive_error_string(a.get()) ? archive_error_string(a.get()) : "bad entry"));
    const std::string member = baseName(archive_entry_pathname(entry) ? archive_entry_pathname(entry) : "");
    const bool wanted = archive_entry_filetype(entry) == AE_IFREG && !member.empty() &&
                        !(member.rfind("mask_", 0) == 0 && endsWith(member, ".dat"));
    if (!wanted) continue;  // libarchive skips the data of the next header's predecessor itself
    const la_int64_t size = archive_entry_size(entry);
    if (size < 0 || size > kMaxMemberBytes || (endsWith(member, ".plist") && size > kMaxPlistBytes))
      throw Error(name, "project member " + member + " has an implausible size (" + std::to_string(size) + " bytes)");
    // The header's size is only a claim: a 77-byte file claiming 8 GiB was zero-filled to 8 GiB
    // before the archive ended (a bug hunt). Asked for first, then grown as data arrives.
    const auto declared = static_cast<std::size_t>(size);
    requireHostMemory(name, "project member " + member, declared);
    std::string data;
    std::size_t got = 0;
    while (got < declared) {
      data.resize(std::min(declared, got + (std::size_t{1} << 20)));
      const la_ssize_t n = archive_read_data(a.get(), data.data() + got, data.size() - got);
      if (n < 0)
        throw Error(name, "corrupt or truncated project archive while reading " + member + ": " +
                              (archive_error_string(a.get()) ? archive_error_string(a.get()) : "read error"));
      if (n == 0) break;
      got += static_cast<std::size_t>(n);
    }
    if (got != declared)
      throw Error(name, "truncated project archive: " + member + " has " + std::to_string(got) + " of " +
                            std::to_string(declared) + " bytes");
    members[member] = std::move(data);
    progress.step(0.6 * std::min(1.0, static_cast<double>(archive_filter_bytes(a.get(), -1)) / fileSize));
  }
  return members;
}

// ---------------------------------------------------------------------------------------------
// Apple XML property lists: dict, array, string, integer, real, true, false, date, data.

struct Plist {
  enum class Kind { Dict, Array, String, Number, Bool, Other };
  Kind kind = Kind::Other;
  std::map<std::string, Plist> dict;
  std::vector<Plist> array;
  std::string text;
  double number = 0.0;
  bool boolean = false;

  [[nodiscard]] const Plist* find(const std::string& key) const {
    const auto it = dict.find(key);
    return it == dict.end() ? nullptr : &it->second;
  }
};

std::string trimmed(const char* s) {
  std::string t = s ? s : "";
  const std::size_t a = t.find_first_not_of(" \t\r\n");
  if (a == std::string::npos) return {};
  return t.substr(a, t.find_last_not_of(" \t\r\n") - a + 1);
}

// Nesting deeper than this is not a project file (and would only recurse).
constexpr int kMaxPlistDepth = 32;

Plist plistValue(vtkXMLDataElement* e, const std::string& where, int depth) {
  if (depth > kMaxPlistDepth) throw Error(where, "property list nested too deeply");
  const std::string tag = e->GetName() ? e->GetName() : "";
  Plist v;
  if (tag == "dict") {
    v.kind = Plist::Kind::Dict;
    const int n = e->GetNumberOfNestedElements();
    for (int i = 0; i + 1 < n; i += 2) {
      vtkXMLDataElement* key = e->GetNestedElement(i);
      if (std::string(key->GetName() ? key->GetName() : "") != "key")
        throw Error(where, "property list <dict> entry without a <key>");
      v.dict[trimmed(key->GetCharacterData())] = plistValue(e->GetNestedElement(i + 1), where, depth + 1);
    }
    if (n % 2 != 0) throw Error(where, "property list <dict> with a <key> but no value");
  } else if (tag == "array") {
    v.kind = Plist::Kind::Array;
    for (int i = 0; i < e->GetNumberOfNestedElements(); ++i)
      v.array.push_back(plistValue(e->GetNestedElement(i), where, depth + 1));
  } else if (tag == "string") {
    v.kind = Plist::Kind::String;
    v.text = trimmed(e->GetCharacterData());
  } else if (tag == "integer" || tag == "real") {
    v.kind = Plist::Kind::Number;
    v.text = trimmed(e->GetCharacterData());
    const char* first = v.text.data();
    const char* last = first + v.text.size();
    if (!v.text.empty() && *first == '+') ++first;
    const auto [end, ec] = std::from_chars(first, last, v.number);
    if (ec != std::errc() || end != last || !std::isfinite(v.number))
      throw Error(where, "property list <" + tag + "> '" + v.text + "' is not a finite number");
  } else if (tag == "true" || tag == "false") {
    v.kind = Plist::Kind::Bool;
    v.boolean = tag == "true";
  }
  return v;
}

Plist parsePlist(const std::string& xml, const std::string& where) {
  VtkMessages messages;
  vtkNew<vtkXMLDataParser> parser;
  std::istringstream in(xml);
  parser->SetStream(&in);
  if (parser->Parse() == 0 || parser->GetRootElement() == nullptr)
    throw Error(where, "not a property list (malformed XML" +
                           (messages.reason().empty() ? std::string() : ": " + messages.reason()) + ")");
  vtkXMLDataElement* root = parser->GetRootElement();
  if (std::string(root->GetName() ? root->GetName() : "") != "plist" || root->GetNumberOfNestedElements() != 1)
    throw Error(where, "not a property list (no <plist> with one value)");
  Plist v = plistValue(root->GetNestedElement(0), where, 0);
  if (v.kind != Plist::Kind::Dict) throw Error(where, "property list is not a <dict>");
  return v;
}

const Plist& required(const Plist& dict, const std::string& key, Plist::Kind kind, const std::string& where) {
  const Plist* v = dict.find(key);
  if (!v) throw Error(where, "missing key '" + key + "'");
  if (v->kind != kind) throw Error(where, "key '" + key + "' has the wrong type");
  return *v;
}

std::vector<double> numbers(const Plist& dict, const std::string& key, std::size_t count, const std::string& where) {
  const Plist& a = required(dict, key, Plist::Kind::Array, where);
  if (a.array.size() != count)
    throw Error(where,
                "key '" + key + "' needs " + std::to_string(count) + " numbers, has " + std::to_string(a.array.size()));
  std::vector<double> out;
  for (const Plist& v : a.array) {
    if (v.kind != Plist::Kind::Number) throw Error(where, "key '" + key + "' holds a value that is not a number");
    out.push_back(v.number);
  }
  return out;
}

const std::string& memberData(const std::map<std::string, std::string>& members, const std::string& member,
                              const std::string& name) {
  const auto it = members.find(member);
  if (it == members.end()) throw Error(name, "project has no " + member);
  return it->second;
}

// ---------------------------------------------------------------------------------------------
// The matrix: numpy's raw bytes in C order of shape (z, y, x), i.e. x fastest — VolumeGrid's order.

struct Dtype {
  const char* name;
  std::size_t bytes;
  void (*convert)(const void*, std::size_t, std::size_t, std::vector<float>&, const LoadProgress&);
};

// numpy's names as InVesalius writes them (str(matrix.dtype)); little-endian, as the x86 machines
// InVesalius runs on write them.
constexpr std::array<Dtype, 8> kDtypes{{{"int16", 2, convertSamples<std::int16_t>},
                                        {"uint16", 2, convertSamples<std::uint16_t>},
                                        {"int8", 1, convertSamples<std::int8_t>},
                                        {"uint8", 1, convertSamples<std::uint8_t>},
                                        {"int32", 4, convertSamples<std::int32_t>},
                                        {"uint32", 4, convertSamples<std::uint32_t>},
                                        {"float32", 4, convertSamples<float>},
                                        {"float64", 8, convertSamples<double>}}};

Volume readMatrix(const Plist& main, const std::map<std::string, std::string>& members, const std::string& name,
                  const LoadProgress& progress) {
  const std::string where = name + ": main.plist";
  const Plist& matrix = required(main, "matrix", Plist::Kind::Dict, where);
  const std::string& dtypeName = required(matrix, "dtype", Plist::Kind::String, where).text;
  const auto dtype = std::find_if(kDtypes.begin(), kDtypes.end(), [&](const Dtype& d) { return dtypeName == d.name; });
  if (dtype == kDtypes.end()) throw Error(where, "unsupported matrix dtype '" + dtypeName + "'");
  const std::vector<double> shape = numbers(matrix, "shape", 3, where);
  std::array<std::int64_t, 3> dims{};  // x, y, z
  for (int axis = 0; axis < 3; ++axis) {
    const double n = shape[static_cast<std::size_t>(2 - axis)];
    if (n != std::floor(n) || n < 0.0 || n > 1e9) throw Error(where, "matrix shape is not three counts");
    dims[static_cast<std::size_t>(axis)] = static_cast<std::int64_t>(n);
  }
  checkDims(dims, name);
  const std::vector<double> spacing = numbers(main, "spacing", 3, where);
  for (const double s : spacing)
    if (!(s > 0.0)) throw Error(where, "spacing must be positive");

  const std::string& file = required(matrix, "filename", Plist::Kind::String, where).text;
  const std::string& data = memberData(members, baseName(file), name);
  const std::size_t n =
      static_cast<std::size_t>(dims[0]) * static_cast<std::size_t>(dims[1]) * static_cast<std::size_t>(dims[2]);
  if (data.size() != n * dtype->bytes)
    throw Error(name, file + " has " + std::to_string(data.size()) + " bytes, its shape and dtype need " +
                          std::to_string(n * dtype->bytes) + (data.size() < n * dtype->bytes ? " (truncated)" : ""));
  auto grid = std::make_shared<VolumeGrid>();
  grid->dims = glm::ivec3(static_cast<int>(dims[0]), static_cast<int>(dims[1]), static_cast<int>(dims[2]));
  dtype->convert(data.data(), n, dtype->bytes, grid->values, progress);

  Volume volume;
  volume.grid = std::move(grid);
  volume.spacing = glm::dvec3(spacing[0], spacing[1], spacing[2]);
  // InVesalius writes its surfaces with y negated relative to the matrix rows (its images have row
  // 0 at the top): the volume is mirrored into the surfaces' frame. Measured on Cranium.inv3: with
  // the mirror 99.9 % of both surfaces' vertices lie within 150 of their masks' thresholds in the
  // matrix, without it 3 % (tests/data/test_invesalius.cpp).
  volume.transform =
      glm::dmat4(glm::dvec4(1, 0, 0, 0), glm::dvec4(0, -1, 0, 0), glm::dvec4(0, 0, 1, 0), glm::dvec4(0, 0, 0, 1));
  return volume;
}

// The display window InVesalius saved (level ± width/2) decides where the "bone" preset puts soft
// tissue and bone: soft tissue (the window's centre) falls in the preset's faint band, values a
// window above its top are dense. Without a window: the preset over the grid's range.
TransferFunction projectTransfer(const Plist& main, const Volume& volume) {
  const TransferFunction fallback = defaultTransfer(*volume.grid, volume.bounds());
  const Plist* level = main.find("window_level");
  const Plist* width = main.find("window_width");
  if (level && width && level->kind == Plist::Kind::Number && width->kind == Plist::Kind::Number && width->number > 0.0)
    return transferPreset("bone", level->number - width->number, level->number + 2.0 * width->number,
                          fallback.unitDistance);
  return transferPreset("bone", fallback.low(), fallback.high(), fallback.unitDistance);
}

std::vector<Object> readSurfaces(const Plist& main, const std::map<std::string, std::string>& members,
                                 const std::string& name, const LoadProgress& progress) {
  std::vector<Object> objects;
  const Plist* surfaces = main.find("surfaces");
  if (!surfaces) return objects;
  if (surfaces->kind != Plist::Kind::Dict) throw Error(name + ": main.plist", "key 'surfaces' has the wrong type");
  // Keys are the surfaces' indices as text: in numeric order, as InVesalius lists them.
  std::vector<std::pair<double, const Plist*>> ordered;
  for (const auto& [key, value] : surfaces->dict) {
    if (value.kind != Plist::Kind::String) throw Error(name + ": main.plist", "surface " + key + " is not a file name");
    double index = 0.0;
    std::from_chars(key.data(), key.data() + key.size(), index);
    ordered.emplace_back(index, &value);
  }
  std::stable_sort(ordered.begin(), ordered.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::size_t done = 0;
  for (const auto& [index, file] : ordered) {
    const std::string plistName = baseName(file->text);
    const std::string where = name + ": " + plistName;
    const Plist surface = parsePlist(memberData(members, plistName, name), where);
    const std::string vtpName = baseName(required(surface, "polydata", Plist::Kind::String, where).text);
    const std::string label = name + ": " + vtpName;
    Object object;
    const Plist* title = surface.find("name");
    object.name = title && title->kind == Plist::Kind::String && !title->text.empty() ? title->text : vtpName;
    Mesh mesh = readWithVtk(VtkFormat::Vtp, fs::path(vtpName), &memberData(members, vtpName, name), label);
    mesh.validate(label);
    if (mesh.normals.size() != mesh.positions.size()) mesh.computeSmoothNormals();
    object.mesh = std::make_shared<const Mesh>(std::move(mesh));
    const std::vector<double> colour = numbers(surface, "colour", 3, where);
    const Plist* transparency = surface.find("transparency");
    const double alpha = transparency && transparency->kind == Plist::Kind::Number ? 1.0 - transparency->number : 1.0;
    for (const double c : colour)
      if (c < 0.0 || c > 1.0) throw Error(where, "colour outside [0, 1]");
    if (alpha < 0.0 || alpha > 1.0) throw Error(where, "transparency outside [0, 1]");
    object.material.color = glm::vec4(colour[0], colour[1], colour[2], alpha);
    object.material.vertexColors = false;
    const Plist* visible = surface.find("visible");
    object.visible = !(visible && visible->kind == Plist::Kind::Bool && !visible->boolean);
    objects.push_back(std::move(object));
    progress.step(0.7 + 0.3 * static_cast<double>(++done) / static_cast<double>(ordered.size()));
  }
  return objects;
}

}  // namespace

InvesaliusProject readInvesaliusProject(const fs::path& path, const std::string& name, bool withSurfaces,
                                        const LoadProgress& progress) {
  const std::map<std::string, std::string> members = readMembers(path, name, progress.part(0.0, 0.6));
  const Plist main = parsePlist(memberData(members, "main.plist", name), name + ": main.plist");
  InvesaliusProject project;
  const Plist* title = main.find("name");
  project.name =
      title && title->kind == Plist::Kind::String && !title->text.empty() ? title->text : path.filename().string();
  project.volume = readMatrix(main, members, name, progress.part(0.6, 0.7));
  project.volume.name = project.name;
  project.volume.grid->validate(name);
  project.volume.transfer = projectTransfer(main, project.volume);
  if (withSurfaces) project.surfaces = readSurfaces(main, members, name, progress);
  return project;
}

Scene loadInvesaliusScene(const fs::path& path, const LoadProgress& progress) {
  const std::string name = path.string();
  return withFileErrors(name, [&] {
    checkReadable(path, name, "project");
    InvesaliusProject project = readInvesaliusProject(path, name, true, progress);
    Scene scene;
    scene.name = path.filename().string();
    project.volume.validate();
    scene.volumes.push_back(std::move(project.volume));
    scene.objects = std::move(project.surfaces);
    return scene;
  });
}

}  // namespace mfr::io
