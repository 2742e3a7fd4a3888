#include "assimp_loader.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <new>
#include <mutex>
#include <optional>
#include <system_error>
#include <iterator>
#include <streambuf>
#include <set>
#include <string_view>
#include <utility>

#include <assimp/Importer.hpp>
#include <assimp/ProgressHandler.hpp>
#include <assimp/config.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "child_process.hpp"
#include "file_checks.hpp"
#include "mfr/error.hpp"
#include "vtk_loader.hpp"

namespace mfr::io {
namespace {

bool finite(const aiVector3D& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// assimp matrices are row-major with the translation in the last column; glm is column-major.
glm::dmat4 toGlm(const aiMatrix4x4& m) {
  glm::dmat4 out(1.0);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out[c][r] = static_cast<double>(m[static_cast<unsigned>(r)][c]);
  return out;
}

// One triangle mesh from an aiMesh; nullptr when it holds no triangles (points, lines).
std::shared_ptr<const Mesh> convertMesh(const aiMesh& src, const std::string& name) {
  if ((src.mPrimitiveTypes & aiPrimitiveType_TRIANGLE) == 0 || src.mNumVertices == 0 || src.mVertices == nullptr)
    return nullptr;
  auto mesh = std::make_shared<Mesh>();
  mesh->positions.reserve(src.mNumVertices);
  for (unsigned i = 0; i < src.mNumVertices; ++i) {
    const aiVector3D& p = src.mVertices[i];
    if (!finite(p)) throw Error(name, "non-finite coordinate in vertex " + std::to_string(i));
    mesh->positions.emplace_back(p.x, p.y, p.z);
  }
  mesh->indices.reserve(3 * std::size_t{src.mNumFaces});
  for (unsigned f = 0; f < src.mNumFaces; ++f) {
    const aiFace& face = src.mFaces[f];
    if (face.mNumIndices != 3) continue;  // points and lines left after triangulation
    for (unsigned k = 0; k < 3; ++k) {
      if (face.mIndices[k] >= src.mNumVertices)
        throw Error(name, "face " + std::to_string(f) + " refers to vertex " + std::to_string(face.mIndices[k]) +
                              " but there are " + std::to_string(src.mNumVertices) + " vertices");
      mesh->indices.push_back(face.mIndices[k]);
    }
  }
  if (mesh->indices.empty()) return nullptr;
  if (src.HasVertexColors(0)) {
    mesh->colors.reserve(src.mNumVertices);
    for (unsigned i = 0; i < src.mNumVertices; ++i) {
      const aiColor4D& c = src.mColors[0][i];
      mesh->colors.push_back(glm::clamp(glm::vec4(c.r, c.g, c.b, c.a), 0.0f, 1.0f));
    }
  }
  bool normalsOk = src.HasNormals();
  for (unsigned i = 0; normalsOk && i < src.mNumVertices; ++i)
    normalsOk = finite(src.mNormals[i]) && src.mNormals[i].SquareLength() > 0.0f;
  if (normalsOk) {
    mesh->normals.reserve(src.mNumVertices);
    for (unsigned i = 0; i < src.mNumVertices; ++i) {
      const aiVector3D n = src.mNormals[i].NormalizeSafe();
      mesh->normals.emplace_back(n.x, n.y, n.z);
    }
  } else {
    computeFeatureNormals(*mesh, name);  // same crease rule as the VTK formats
  }
  return mesh;
}

// Base colour (glTF PBR) or diffuse colour, and opacity; the default material when the file
// says nothing.
Material convertMaterial(const aiScene& scene, unsigned index) {
  Material material;
  if (index >= scene.mNumMaterials || scene.mMaterials[index] == nullptr) return material;
  const aiMaterial& m = *scene.mMaterials[index];
  aiColor4D c;
  if (m.Get(AI_MATKEY_BASE_COLOR, c) == AI_SUCCESS || m.Get(AI_MATKEY_COLOR_DIFFUSE, c) == AI_SUCCESS)
    material.color = glm::vec4(c.r, c.g, c.b, c.a);
  float opacity = 1.0f;
  if (m.Get(AI_MATKEY_OPACITY, opacity) == AI_SUCCESS) material.color.a = opacity;
  material.color = glm::clamp(material.color, 0.0f, 1.0f);
  if (!std::isfinite(material.color.r + material.color.g + material.color.b + material.color.a))
    material.color = Material{}.color;
  return material;
}

// A few importers (OpenGEX's DDL parser, for one) write to std::cerr directly instead of to
// assimp's logger. std::cerr and std::clog are muted while assimp runs (std::cout is left alone:
// it carries the CLI's output); the mutex keeps concurrent loads from restoring each other's
// buffers out of order.
class MutedStandardStreams {
 public:
  MutedStandardStreams() : lock_(mutex()) {
    cerr_ = std::cerr.rdbuf(&null_);
    clog_ = std::clog.rdbuf(&null_);
  }
  ~MutedStandardStreams() {
    std::cerr.rdbuf(cerr_);
    std::clog.rdbuf(clog_);
  }
  MutedStandardStreams(const MutedStandardStreams&) = delete;
  MutedStandardStreams& operator=(const MutedStandardStreams&) = delete;

 private:
  struct NullBuffer final : std::streambuf {
    int overflow(int c) override { return traits_type::not_eof(c); }
  };
  static std::mutex& mutex() {
    static std::mutex m;
    return m;
  }
  std::lock_guard<std::mutex> lock_;
  NullBuffer null_;
  std::streambuf* cerr_ = nullptr;
  std::streambuf* clog_ = nullptr;
};

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  return s;
}

// assimp's import progress (it reports percentages that may step back between its stages, so
// the largest so far is passed on) into a LoadProgress. Cancelling makes Update return false,
// which aborts the import; exceptions must not cross assimp's code.
class ImportProgress final : public Assimp::ProgressHandler {
 public:
  explicit ImportProgress(LoadProgress progress) : progress_(std::move(progress)) {}
  bool Update(float percentage) override {
    if (cancelled_) return false;
    if (percentage >= 0.0f) done_ = std::max(done_, std::clamp(static_cast<double>(percentage), 0.0, 1.0));
    cancelled_ = !progress_.tryStep(done_);
    return !cancelled_;
  }
  [[nodiscard]] bool cancelled() const { return cancelled_; }

 private:
  LoadProgress progress_;
  double done_ = 0.0;
  bool cancelled_ = false;
};

// assimp's glTF importers parse JSON with rapidjson's recursive parser: a document nested tens of
// thousands deep overflows the stack. A real glTF needs a depth of about ten: deeper than
// kMaxJsonDepth is refused before the import. The JSON is the .gltf file, or a .glb's first chunk.
constexpr int kMaxJsonDepth = 512;

void checkGltfJsonDepth(const std::filesystem::path& path, const std::string* contents, const std::string& extension,
                        const std::string& name) {
  if (extension != ".gltf" && extension != ".glb") return;
  // Only the JSON is read: an in-memory file is looked at, not copied; from disk a .glb's binary
  // buffers after its JSON chunk are not read.
  std::string bytes;
  std::string_view json;
  if (contents != nullptr) {
    json = *contents;
  } else {
    std::ifstream in(path, std::ios::binary);
    bytes.resize(20);
    in.read(bytes.data(), 20);
    bytes.resize(static_cast<std::size_t>(in.gcount()));
    if (bytes.size() == 20 && bytes.compare(0, 4, "glTF") == 0) {
      std::uint32_t length = 0;
      std::memcpy(&length, bytes.data() + 12, sizeof length);
      bytes.resize(20 + std::min<std::uint32_t>(length, 1u << 30));
      in.read(bytes.data() + 20, static_cast<std::streamsize>(bytes.size() - 20));
      bytes.resize(20 + static_cast<std::size_t>(in.gcount()));
    } else {
      bytes.append(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    json = bytes;
  }
  if (extension == ".glb" || json.substr(0, 4) == "glTF") {
    if (json.size() < 20) return;  // assimp says what is wrong with it
    // The header's total length against the file's: a cut-off download, which assimp reports only
    // as "no suitable reader found".
    std::uint32_t version = 0, total = 0;
    std::memcpy(&version, json.data() + 4, sizeof version);
    std::memcpy(&total, json.data() + 8, sizeof total);
    std::error_code error;
    const std::uintmax_t size = contents != nullptr ? contents->size() : std::filesystem::file_size(path, error);
    if (json.substr(0, 4) == "glTF" && version == 2 && !error && size < total)
      throw Error(name, "truncated binary glTF (" + std::to_string(size) + " of the " + std::to_string(total) +
                            " bytes its header gives)");
    std::uint32_t length = 0;
    std::memcpy(&length, json.data() + 12, sizeof length);  // little-endian, as every host mfr builds on
    json = json.substr(20, length);
  }
  int depth = 0;
  bool inString = false, escaped = false;
  for (const char c : json) {
    if (inString) {
      if (escaped)
        escaped = false;
      else if (c == '\\')
        escaped = true;
      else if (c == '"')
        inString = false;
      continue;
    }
    if (c == '"') {
      inString = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxJsonDepth)
        throw Error(name, "glTF JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
}

// The error for assimp's refusal `reason`.
Error importError(const std::string& reason, const std::string& extension, const std::string& name) {
  // What SortByPType says when it removed every mesh because all were points or lines.
  if (reason.find("No meshes remaining") != std::string::npos)
    return Error(name, "no triangles (only points or lines)");
  return Error(name, "cannot read " + (extension.empty() ? std::string("file") : extension.substr(1)) +
                         (reason.empty() ? std::string() : ": " + reason));
}

// One importer, set up as both imports use it.
const aiScene* importScene(Assimp::Importer& importer, const std::filesystem::path& path, const std::string* contents,
                           const std::string& extension) {
  // Points and lines are no surfaces; skeleton dummies are no geometry.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  importer.SetPropertyBool(AI_CONFIG_IMPORT_NO_SKELETON_MESHES, true);
  // No PreTransformVertices: node transforms become Object::transform so instanced meshes are shared.
  const unsigned flags =
      aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_SortByPType | aiProcess_ValidateDataStructure;
  if (contents != nullptr) {
    const std::string hint = extension.empty() ? std::string() : extension.substr(1);
    return importer.ReadFileFromMemory(contents->data(), contents->size(), flags, hint.c_str());
  }
  return importer.ReadFile(path.string(), flags);
}

// The import and the conversion into objects, in this process.
std::vector<Object> readHere(const std::filesystem::path& path, const std::string* contents,
                             const std::string& extension, const std::string& name, const LoadProgress& progress) {
  Assimp::Importer importer;
  // The importer owns (and deletes) its progress handler; the import takes the first 80 %.
  auto* importProgress = new ImportProgress(progress.part(0.0, 0.8));
  importer.SetProgressHandler(importProgress);
  const MutedStandardStreams muted;
  const aiScene* scene = importScene(importer, path, contents, extension);
  if (importProgress->cancelled()) throw LoadCancelled();
  if (scene == nullptr) {
    const std::string reason = importer.GetErrorString();
    if (reason.find("bad_alloc") != std::string::npos) throw std::bad_alloc();  // the memory limit's message
    throw importError(reason, extension, name);
  }
  if (scene->mRootNode == nullptr || scene->mNumMeshes == 0) throw Error(name, "no triangles (the file has no meshes)");

  std::vector<std::shared_ptr<const Mesh>> meshes(scene->mNumMeshes);
  std::vector<bool> converted(scene->mNumMeshes, false);
  unsigned convertedCount = 0;
  std::vector<Object> objects;
  std::set<std::string> usedNames;

  // Depth-first over the node tree, accumulating parent transforms.
  std::vector<std::pair<const aiNode*, glm::dmat4>> stack{{scene->mRootNode, glm::dmat4(1.0)}};
  std::size_t visited = 0;
  while (!stack.empty()) {
    auto [node, parent] = stack.back();
    stack.pop_back();
    if (++visited > 10'000'000) throw Error(name, "node hierarchy too large or cyclic");
    const glm::dmat4 world = parent * toGlm(node->mTransformation);
    for (unsigned k = 0; k < node->mNumMeshes; ++k) {
      const unsigned mi = node->mMeshes[k];
      if (mi >= scene->mNumMeshes || scene->mMeshes[mi] == nullptr) continue;
      const aiMesh& src = *scene->mMeshes[mi];
      if (!converted[mi]) {
        meshes[mi] = convertMesh(src, name);
        converted[mi] = true;
        ++convertedCount;
        progress.step(0.8 + 0.2 * static_cast<double>(convertedCount) / scene->mNumMeshes);
      }
      if (!meshes[mi]) continue;
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
          if (!std::isfinite(world[c][r])) throw Error(name, "non-finite node transform");

      std::string partName = node->mName.length > 0 ? node->mName.C_Str() : "";
      if (node->mNumMeshes > 1 || partName.empty()) {
        const std::string meshName = src.mName.length > 0 ? src.mName.C_Str() : "mesh " + std::to_string(mi);
        partName = partName.empty() ? meshName : partName + "/" + meshName;
      }
      // Names identify parts in the UI and scene files, so keep them unique.
      if (usedNames.count(partName) != 0) {
        int n = 2;
        while (usedNames.count(partName + " #" + std::to_string(n)) != 0) ++n;
        partName += " #" + std::to_string(n);
      }
      usedNames.insert(partName);

      Object object;
      object.name = std::move(partName);
      object.mesh = meshes[mi];
      object.transform = world;
      object.material = convertMaterial(*scene, src.mMaterialIndex);
      objects.push_back(std::move(object));
    }
    for (unsigned c = node->mNumChildren; c-- > 0;)  // reversed so parts come out in file order
      if (node->mChildren[c] != nullptr) stack.emplace_back(node->mChildren[c], world);
  }
  if (objects.empty()) throw Error(name, "no triangles");
  return objects;
}

// An IFC file is a STEP physical file (ISO 10303-21): it ends with "END-ISO-10303-21;". assimp's
// IFC reader takes a file cut off anywhere and builds what came before it — 4 of 294 parts of a
// house cut at 10 %, with exit 0 and no note (a bug hunt). A file that begins as one and lacks the
// end is refused.
void checkStepPhysicalFileEnd(const std::filesystem::path& path, const std::string* contents,
                              const std::string& extension, const std::string& name) {
  if (extension != ".ifc") return;
  const auto [head, tail] = fileEnds(path, contents, 64, 4096);
  const std::size_t start = head.find_first_not_of(" \t\r\n\xEF\xBB\xBF");
  if (start == std::string::npos || head.compare(start, 12, "ISO-10303-21") != 0) return;  // assimp names it
  if (tail.find("END-ISO-10303-21") == std::string::npos)
    throw Error(name, "truncated: the IFC (ISO 10303-21) file does not end with END-ISO-10303-21;");
}

}  // namespace

// assimp 5.2 crashes (SIGSEGV; an uncaught DeadlyImportError, abort), hangs, or allocates without
// end on some truncated or corrupt files — a bug hunt's cases: COB, X, MDL, ASE, 3MF and LWO
// crashed mfr, SMD, OpenGEX and Q3S hung, DAE and LWS grew past 3 GB. None of that can be caught
// in this process, so the import and the conversion run in a child process (child_process.hpp),
// whose objects come back as bytes; a failure the child reports (assimp's own error) is thrown as
// it is.
std::vector<Object> readWithAssimp(const std::filesystem::path& path, const std::string* contents,
                                   const std::string& extension, const std::string& name,
                                   const LoadProgress& progress) {
  checkGltfJsonDepth(path, contents, extension, name);
  checkStepPhysicalFileEnd(path, contents, extension, name);
  const ChildLibrary assimp{extension.empty() ? std::string("file") : extension.substr(1), "the importer (assimp)"};
  if (const std::optional<std::string> bytes = runInChild(name, assimp, progress, [&](const LoadProgress& child) {
        return packObjects(readHere(path, contents, extension, name, child));
      }))
    return unpackObjects(*bytes);
  try {
    return readHere(path, contents, extension, name, progress);
  } catch (const std::bad_alloc&) {
    throw Error(name, "cannot read " + assimp.format + ": the importer (assimp) ran out of memory");
  }
}

std::vector<std::string> assimpExtensions() {
  // Formats with loaders of their own, STEP (assimp reads only IFC-style STEP, not CAD B-rep),
  // motion/camera-only formats, and the over-generic ".xml".
  static const std::set<std::string> excluded = {".stl", ".ply",     ".obj",       ".off", ".step",
                                                 ".stp", ".md5anim", ".md5camera", ".bvh", ".xml"};
  Assimp::Importer importer;
  std::string list;
  importer.GetExtensionList(list);  // "*.3d;*.3ds;…"
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start < list.size()) {
    std::size_t end = list.find(';', start);
    if (end == std::string::npos) end = list.size();
    std::string ext = lower(list.substr(start, end - start));
    start = end + 1;
    if (!ext.empty() && ext[0] == '*') ext.erase(0, 1);
    if (ext.size() < 2 || ext[0] != '.' || excluded.count(ext) != 0) continue;
    out.push_back(ext);
  }
  return out;
}

}  // namespace mfr::io
