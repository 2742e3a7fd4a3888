#include "vtk_loader.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <mutex>
#include <string_view>
#include <utility>

#include <unistd.h>

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkIdTypeArray.h>
#include <vtkDataArray.h>
#include <vtkFloatArray.h>
#include <vtkIdList.h>
#include <vtkLogger.h>
#include <vtkNew.h>
#include <vtkOutputWindow.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolygon.h>
#include <vtkSTLReader.h>
#include <vtkSmartPointer.h>
#include <vtkUnsignedCharArray.h>
#include <vtkXMLPolyDataReader.h>

#include "mfr/error.hpp"
#include "mfr/scene/feature_normals.hpp"
#include "file_checks.hpp"

namespace mfr::io {
namespace {

namespace fs = std::filesystem;

constexpr const char* kSoupColorArray = "mfr_colors";
// Cell data of triangulate's output: the input cell each triangle came from (for the file's cell data).
constexpr const char* kSourceCellArray = "mfr_source_cell";

// ---------------------------------------------------------------------------------------------
// VTK reports problems through a global output window (and vtkLogger), which prints to stderr.
// We install a window that prints nothing and hands each message to the load running on the
// same thread, so a failed read can name VTK's reason in its one-line mfr::Error.

thread_local std::vector<VtkMessages::Message>* tlMessages = nullptr;

class QuietOutputWindow final : public vtkOutputWindow {
 public:
  static QuietOutputWindow* New() {
    auto* window = new QuietOutputWindow;
    window->InitializeObjectBase();
    return window;
  }
  void DisplayText(const char* text) override { record(false, text); }
  void DisplayErrorText(const char* text) override { record(true, text); }
  void DisplayWarningText(const char* text) override { record(false, text); }
  void DisplayGenericWarningText(const char* text) override { record(false, text); }
  void DisplayDebugText(const char*) override {}

 private:
  static void record(bool error, const char* text) {
    if (tlMessages != nullptr && text != nullptr) tlMessages->push_back({error, text});
  }
};

void silenceVtk() {
  static std::once_flag once;
  std::call_once(once, [] {
    vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
    QuietOutputWindow* window = QuietOutputWindow::New();
    vtkOutputWindow::SetInstance(window);
    window->Delete();
  });
}

// "ERROR: In /…/vtkSTLReader.cxx, line 657\nvtkSTLReader (0x55…): reason\n\n" → "reason".
std::string cleanMessage(std::string_view text) {
  std::string out;
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(start, end - start);
    start = end + 1;
    if (line.find(": In ") != std::string_view::npos && line.find(", line ") != std::string_view::npos)
      continue;  // the source location line
    if (const std::size_t p = line.find(" (0x"); p != std::string_view::npos) {
      if (const std::size_t q = line.find("): ", p); q != std::string_view::npos) line = line.substr(q + 3);
    }
    while (!line.empty() && std::isspace(static_cast<unsigned char>(line.front()))) line.remove_prefix(1);
    while (!line.empty() && std::isspace(static_cast<unsigned char>(line.back()))) line.remove_suffix(1);
    if (line.empty()) continue;
    if (!out.empty()) out += ' ';
    out += line;
  }
  return out;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
VtkMessages::VtkMessages() : previous_(tlMessages) {
  silenceVtk();
  tlMessages = &messages_;
}

VtkMessages::~VtkMessages() {
  tlMessages = previous_;
}

bool VtkMessages::hasError() const {
  return std::any_of(messages_.begin(), messages_.end(), [](const Message& m) { return m.error; });
}

bool VtkMessages::hasWarning() const {
  return std::any_of(messages_.begin(), messages_.end(), [](const Message& m) { return !m.error; });
}

std::string VtkMessages::reason() const {
  for (const bool wantError : {true, false})
    for (const Message& m : messages_)
      if (m.error == wantError && m.text.find("returned failure for request") == std::string::npos) {
        std::string r = cleanMessage(m.text);
        if (!r.empty()) return r;
      }
  return {};
}

namespace {

// ---------------------------------------------------------------------------------------------
// A temporary copy of decompressed bytes, for the VTK readers that only read named files.
class TempFile {
 public:
  TempFile(const std::string& contents, const std::string& suffix, const std::string& name) {
    // The reason names the folder (TMPDIR's): a missing or read-only TMPDIR read as
    // "filesystem error: temp_directory_path: No such file or directory", or gave no reason (a bug hunt).
    // libstdc++ takes the first of TMPDIR, TMP, TEMP and TEMPDIR that is set (a review).
    std::error_code ec;
    const fs::path folder = fs::temp_directory_path(ec);
    std::string variable;
    for (const char* v : {"TMPDIR", "TMP", "TEMP", "TEMPDIR"})
      if (const char* value = std::getenv(v); value != nullptr && variable.empty())
        variable = std::string(v) + " " + value;
    const std::string where = !ec                ? folder.string() + (variable.empty() ? "" : " (" + variable + ")")
                              : variable.empty() ? std::string("the temporary folder")
                                                 : variable;
    if (ec)
      throw Error(name,
                  "cannot create a temporary file for the decompressed data in " + where + " (" + ec.message() + ")");
    std::string pattern = (folder / ("mfr-load-XXXXXX" + suffix)).string();
    const int fd = ::mkstemps(pattern.data(), static_cast<int>(suffix.size()));
    if (fd < 0)
      throw Error(name, "cannot create a temporary file for the decompressed data in " + where + " (" +
                            std::strerror(errno) + ")");
    path_ = pattern;
    std::size_t written = 0;
    while (written < contents.size()) {
      const ssize_t n = ::write(fd, contents.data() + written, contents.size() - written);
      if (n <= 0) break;
      written += static_cast<std::size_t>(n);
    }
    ::close(fd);
    if (written != contents.size()) {
      fs::remove(path_, ec);
      throw Error(name, "cannot write the decompressed data to a temporary file in " + where);
    }
  }
  ~TempFile() {
    std::error_code ec;
    fs::remove(path_, ec);
  }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  [[nodiscard]] const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

void replaceAll(std::string& s, const std::string& from, const std::string& to) {
  if (from.empty()) return;
  for (std::size_t p = s.find(from); p != std::string::npos; p = s.find(from, p + to.size()))
    s.replace(p, from.size(), to);
}

// ---------------------------------------------------------------------------------------------
// Binary STL carries its triangle count in the header, and vtkSTLReader silently reads as many
// triangles as are present, so the size is checked here first.
void checkStl(std::string_view head, std::uintmax_t size, const std::string& name) {
  std::size_t i = 0;
  while (i < head.size() && std::isspace(static_cast<unsigned char>(head[i]))) ++i;
  bool solid = head.size() >= i + 5;
  for (std::size_t k = 0; solid && k < 5; ++k)
    solid = std::tolower(static_cast<unsigned char>(head[i + k])) == "solid"[k];

  if (size >= 84) {
    const auto* b = reinterpret_cast<const unsigned char*>(head.data() + 80);
    const std::uint64_t n =
        std::uint64_t{b[0]} | std::uint64_t{b[1]} << 8 | std::uint64_t{b[2]} << 16 | std::uint64_t{b[3]} << 24;
    const std::uint64_t expected = 84 + 50 * n;
    if (expected == size) {
      if (n == 0) throw Error(name, "no triangles (binary STL with a triangle count of 0)");
      return;  // binary, complete
    }
    if (solid) return;  // ASCII: vtkSTLReader parses it and reports syntax errors
    if (size < expected)
      throw Error(name, "truncated binary STL (" + std::to_string(size) + " of " + std::to_string(expected) +
                            " bytes for " + std::to_string(n) + " triangles)");
    return;  // binary with trailing bytes, which readers ignore
  }
  if (solid) return;
  throw Error(name, "not an STL file (" + std::to_string(size) +
                        " bytes: too short for a binary STL header and not ASCII 'solid')");
}

// ---------------------------------------------------------------------------------------------
bool finite3(const double p[3]) {
  return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
}

// Readers do not check what they read: ids can be out of range (which would crash the filters)
// and coordinates NaN.
void checkPolyData(vtkPolyData* pd, const std::string& name) {
  const vtkIdType np = pd->GetNumberOfPoints();
  for (vtkIdType i = 0; i < np; ++i) {
    double p[3];
    pd->GetPoint(i, p);
    if (!finite3(p)) throw Error(name, "non-finite coordinate in vertex " + std::to_string(i));
  }
  for (vtkCellArray* cells : {pd->GetVerts(), pd->GetLines(), pd->GetPolys(), pd->GetStrips()}) {
    if (cells == nullptr) continue;
    vtkIdType n = 0;
    const vtkIdType* ids = nullptr;
    vtkIdType cell = 0;
    for (cells->InitTraversal(); cells->GetNextCell(n, ids) != 0; ++cell)
      for (vtkIdType k = 0; k < n; ++k)
        if (ids[k] < 0 || ids[k] >= np)
          throw Error(name, "face " + std::to_string(cell) + " refers to vertex " + std::to_string(ids[k]) +
                                " but there are " + std::to_string(np) + " vertices");
  }
  if (pd->GetNumberOfPolys() + pd->GetNumberOfStrips() == 0) {
    if (pd->GetNumberOfLines() + pd->GetNumberOfVerts() > 0) throw Error(name, "no triangles (only points or lines)");
    throw Error(name, "no triangles");
  }
}

// Normals the file brought along are kept only when usable.
bool usableNormals(vtkPolyData* pd) {
  vtkDataArray* n = pd->GetPointData()->GetNormals();
  if (n == nullptr || n->GetNumberOfComponents() != 3 || n->GetNumberOfTuples() != pd->GetNumberOfPoints())
    return false;
  for (vtkIdType i = 0; i < n->GetNumberOfTuples(); ++i) {
    double v[3];
    n->GetTuple(i, v);
    if (!finite3(v)) return false;
  }
  return true;
}

vtkDataArray* colorArray(vtkPolyData* pd) {
  vtkPointData* data = pd->GetPointData();
  if (vtkDataArray* soup = data->GetArray(kSoupColorArray)) return soup;
  // Readers put per-vertex colours in unsigned char scalars with 3 or 4 components (PLY "RGB",
  // VTP/legacy colour scalars); other scalars are data values, not colours.
  vtkDataArray* s = data->GetScalars();
  if (s != nullptr && s->GetDataType() == VTK_UNSIGNED_CHAR &&
      (s->GetNumberOfComponents() == 3 || s->GetNumberOfComponents() == 4))
    return s;
  return nullptr;
}

// Polygons and strips to triangles. Ear cutting (vtkPolygon) handles concave polygons; where it
// gives up (non-planar or partly degenerate polygons, where vtkTriangleFilter silently drops
// triangles) a fan keeps the n−2 triangles the file implies. Points and point data are shared; each
// triangle's input cell id is its cell data kSourceCellArray.
vtkSmartPointer<vtkPolyData> triangulate(vtkPolyData* in) {
  auto out = vtkSmartPointer<vtkPolyData>::New();
  out->SetPoints(in->GetPoints());
  out->GetPointData()->ShallowCopy(in->GetPointData());
  vtkNew<vtkIdTypeArray> source;
  source->SetName(kSourceCellArray);
  // vtkPolyData numbers its cells vertices first, then lines, polygons and strips.
  vtkIdType cellId = in->GetNumberOfVerts() + in->GetNumberOfLines();
  vtkNew<vtkCellArray> triangles;
  triangles->AllocateEstimate(in->GetNumberOfPolys() + in->GetNumberOfStrips(), 3);
  vtkNew<vtkPolygon> polygon;
  vtkNew<vtkIdList> local;
  vtkIdType n = 0;
  const vtkIdType* ids = nullptr;
  vtkCellArray* polys = in->GetPolys();
  for (polys->InitTraversal(); polys->GetNextCell(n, ids) != 0; ++cellId) {
    if (n < 3) continue;
    const vtkIdType before = triangles->GetNumberOfCells();
    if (n == 3) {
      triangles->InsertNextCell(3, ids);
      source->InsertNextValue(cellId);
      continue;
    }
    polygon->PointIds->SetNumberOfIds(n);
    polygon->Points->SetNumberOfPoints(n);
    for (vtkIdType k = 0; k < n; ++k) {
      polygon->PointIds->SetId(k, ids[k]);
      polygon->Points->SetPoint(k, in->GetPoint(ids[k]));
    }
    local->Reset();
    if (polygon->Triangulate(local) != 0 && local->GetNumberOfIds() == 3 * (n - 2)) {
      for (vtkIdType k = 0; k < local->GetNumberOfIds(); k += 3) {
        const vtkIdType t[3] = {ids[local->GetId(k)], ids[local->GetId(k + 1)], ids[local->GetId(k + 2)]};
        triangles->InsertNextCell(3, t);
      }
    } else {
      for (vtkIdType k = 1; k + 1 < n; ++k) {
        const vtkIdType t[3] = {ids[0], ids[k], ids[k + 1]};
        triangles->InsertNextCell(3, t);
      }
    }
    for (vtkIdType t = before; t < triangles->GetNumberOfCells(); ++t) source->InsertNextValue(cellId);
  }
  vtkCellArray* strips = in->GetStrips();
  for (strips->InitTraversal(); strips->GetNextCell(n, ids) != 0; ++cellId)
    for (vtkIdType k = 0; k + 2 < n; ++k) {
      // Every other strip triangle is wound the other way round.
      const vtkIdType t[3] = {ids[k + (k & 1)], ids[k + 1 - (k & 1)], ids[k + 2]};
      triangles->InsertNextCell(3, t);
      source->InsertNextValue(cellId);
    }
  out->SetPolys(triangles);
  out->GetCellData()->AddArray(source);
  return out;
}

// The numeric arrays of a file's point and cell data as Mesh::fields (what a surface can be
// coloured by), except the normals and the colours read as colours. Point data comes from the
// triangulated `triangles`, one tuple per mesh vertex by `source` (a vertex split at a crease keeps
// its values); cell data from the input, one tuple per triangle of `triangles` by its
// kSourceCellArray.
void readFields(vtkPolyData* input, vtkPolyData* triangles, const std::vector<std::uint32_t>& source, Mesh& mesh) {
  vtkPointData* pd = triangles->GetPointData();
  const vtkDataArray* colors = colorArray(triangles);
  for (int i = 0; i < pd->GetNumberOfArrays(); ++i) {
    vtkDataArray* a = pd->GetArray(i);
    if (a == nullptr || a->GetName() == nullptr || a == pd->GetNormals() || a == colors ||
        std::strcmp(a->GetName(), kSoupColorArray) == 0 || a->GetNumberOfTuples() != triangles->GetNumberOfPoints())
      continue;
    MeshField f{a->GetName(), false, a->GetNumberOfComponents(), {}};
    f.values.reserve(source.size() * static_cast<std::size_t>(f.components));
    for (const std::uint32_t t : source)
      for (int c = 0; c < f.components; ++c) f.values.push_back(static_cast<float>(a->GetComponent(t, c)));
    mesh.fields.push_back(std::move(f));
  }
  vtkCellData* cd = input->GetCellData();
  vtkDataArray* cellSource = triangles->GetCellData()->GetArray(kSourceCellArray);
  if (cellSource == nullptr || cellSource->GetNumberOfTuples() != static_cast<vtkIdType>(mesh.triangleCount())) return;
  for (int i = 0; i < cd->GetNumberOfArrays(); ++i) {
    vtkDataArray* a = cd->GetArray(i);
    if (a == nullptr || a->GetName() == nullptr || a == cd->GetNormals() ||
        a->GetNumberOfTuples() != input->GetNumberOfCells())
      continue;
    MeshField f{a->GetName(), true, a->GetNumberOfComponents(), {}};
    f.values.reserve(mesh.triangleCount() * static_cast<std::size_t>(f.components));
    for (vtkIdType t = 0; t < cellSource->GetNumberOfTuples(); ++t) {
      const auto cell = static_cast<vtkIdType>(cellSource->GetComponent(t, 0));
      for (int c = 0; c < f.components; ++c) f.values.push_back(static_cast<float>(a->GetComponent(cell, c)));
    }
    mesh.fields.push_back(std::move(f));
  }
}

// Triangulates, adds feature-angle normals when missing (orientAndSplitAtFeatures: consistent
// winding, creases split), and converts to a Mesh.
Mesh finish(vtkPolyData* input, const std::string& name) {
  checkPolyData(input, name);
  const bool keepNormals = usableNormals(input);
  if (!keepNormals) input->GetPointData()->SetNormals(nullptr);

  vtkSmartPointer<vtkPolyData> triangles = triangulate(input);
  if (triangles->GetPoints() == nullptr || triangles->GetNumberOfPolys() == 0)
    throw Error(name, "no triangles after triangulation");
  const vtkIdType np = triangles->GetNumberOfPoints();
  std::vector<glm::dvec3> points(static_cast<std::size_t>(np));
  for (vtkIdType i = 0; i < np; ++i) triangles->GetPoint(i, &points[static_cast<std::size_t>(i)].x);
  std::vector<std::uint32_t> indices;
  vtkCellArray* polys = triangles->GetPolys();
  indices.reserve(static_cast<std::size_t>(polys->GetNumberOfConnectivityIds()));
  vtkIdType n = 0;
  const vtkIdType* ids = nullptr;
  for (polys->InitTraversal(); polys->GetNextCell(n, ids) != 0;)
    for (vtkIdType k = 0; k < 3; ++k) indices.push_back(static_cast<std::uint32_t>(ids[k]));  // triangulate's

  Mesh mesh;
  std::vector<std::uint32_t> source;
  if (keepNormals) {
    mesh.indices = std::move(indices);
    source.resize(points.size());
    for (std::size_t i = 0; i < source.size(); ++i) source[i] = static_cast<std::uint32_t>(i);
    vtkDataArray* normals = triangles->GetPointData()->GetNormals();
    mesh.normals.resize(source.size());
    for (std::size_t i = 0; i < source.size(); ++i) {
      double v[3];
      normals->GetTuple(static_cast<vtkIdType>(i), v);
      mesh.normals[i] = glm::vec3(v[0], v[1], v[2]);
    }
  } else {
    FeatureSplit split =
        orientAndSplitAtFeatures(points, std::move(indices), kFeatureAngleDegrees, /*majorityWinding=*/true);
    mesh.indices = std::move(split.indices);
    source = std::move(split.source);
    mesh.normals = std::move(split.normals);
  }
  mesh.positions.resize(source.size());
  for (std::size_t i = 0; i < source.size(); ++i) mesh.positions[i] = glm::vec3(points[source[i]]);
  for (glm::vec3& v : mesh.normals) {
    const float len = glm::length(v);
    // Degenerate triangles get zero normals; shaders would normalise them into NaN.
    v = len > 0.0f && std::isfinite(len) ? v / len : glm::vec3(0, 0, 1);
  }
  if (vtkDataArray* c = colorArray(triangles); c != nullptr && c->GetNumberOfTuples() == np) {
    const int comps = c->GetNumberOfComponents();
    const double scale = c->GetDataType() == VTK_UNSIGNED_CHAR ? 1.0 / 255.0 : 1.0;
    mesh.colors.resize(source.size());
    for (std::size_t i = 0; i < source.size(); ++i) {
      double v[4] = {0.0, 0.0, 0.0, 1.0 / scale};
      for (int k = 0; k < comps && k < 4; ++k) v[k] = c->GetComponent(source[i], k);
      glm::vec4 rgba(v[0] * scale, v[1] * scale, v[2] * scale, v[3] * scale);
      mesh.colors[i] = glm::clamp(rgba, 0.0f, 1.0f);
    }
  }
  readFields(input, triangles, source, mesh);
  return mesh;
}

vtkSmartPointer<vtkPolyData> polyDataFromSoup(const PolygonSoup& soup, const std::string& name) {
  const std::size_t np = soup.points.size();
  if (soup.offsets.empty() || soup.offsets.back() != soup.ids.size())
    throw Error(name, "internal error: inconsistent polygon offsets");
  for (std::size_t i = 0; i < np; ++i) {
    const glm::vec3& p = soup.points[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw Error(name, "non-finite coordinate in vertex " + std::to_string(i));
  }
  for (std::size_t f = 0; f + 1 < soup.offsets.size(); ++f)
    for (std::uint32_t k = soup.offsets[f]; k < soup.offsets[f + 1]; ++k)
      if (soup.ids[k] >= np)
        throw Error(name, "face " + std::to_string(f) + " refers to vertex " + std::to_string(soup.ids[k]) +
                              " but there are " + std::to_string(np) + " vertices");

  auto pd = vtkSmartPointer<vtkPolyData>::New();
  vtkNew<vtkPoints> points;
  points->SetDataTypeToFloat();
  points->SetNumberOfPoints(static_cast<vtkIdType>(np));
  for (std::size_t i = 0; i < np; ++i) {
    const glm::vec3& p = soup.points[i];
    points->SetPoint(static_cast<vtkIdType>(i), p.x, p.y, p.z);
  }
  pd->SetPoints(points);

  vtkNew<vtkCellArray> polys;
  polys->AllocateExact(static_cast<vtkIdType>(soup.polygonCount()), static_cast<vtkIdType>(soup.ids.size()));
  std::vector<vtkIdType> cell;
  for (std::size_t f = 0; f + 1 < soup.offsets.size(); ++f) {
    const std::uint32_t begin = soup.offsets[f], end = soup.offsets[f + 1];
    if (end - begin < 3) continue;  // points and edges are not surfaces
    cell.assign(soup.ids.begin() + begin, soup.ids.begin() + end);
    polys->InsertNextCell(static_cast<vtkIdType>(cell.size()), cell.data());
  }
  pd->SetPolys(polys);

  if (soup.normals.size() == np && np > 0) {
    vtkNew<vtkFloatArray> normals;
    normals->SetName("Normals");
    normals->SetNumberOfComponents(3);
    normals->SetNumberOfTuples(static_cast<vtkIdType>(np));
    for (std::size_t i = 0; i < np; ++i) {
      const glm::vec3& n = soup.normals[i];
      normals->SetTypedTuple(static_cast<vtkIdType>(i), &n.x);
    }
    pd->GetPointData()->SetNormals(normals);
  }
  // Fields: point data as is; cell data for the polygons kept above (three corners or more).
  for (const MeshField& f : soup.fields) {
    vtkNew<vtkFloatArray> a;
    a->SetName(f.name.c_str());
    a->SetNumberOfComponents(f.components);
    const auto n = static_cast<std::size_t>(f.components);
    if (!f.cellData) {
      if (f.values.size() != np * n) throw Error(name, "internal error: point field '" + f.name + "' size");
      a->SetNumberOfTuples(static_cast<vtkIdType>(np));
      for (std::size_t i = 0; i < np; ++i) a->SetTypedTuple(static_cast<vtkIdType>(i), f.values.data() + i * n);
      pd->GetPointData()->AddArray(a);
      continue;
    }
    if (f.values.size() != soup.polygonCount() * n)
      throw Error(name, "internal error: cell field '" + f.name + "' size");
    for (std::size_t c = 0; c < soup.polygonCount(); ++c)
      if (soup.offsets[c + 1] - soup.offsets[c] >= 3) a->InsertNextTypedTuple(f.values.data() + c * n);
    pd->GetCellData()->AddArray(a);
  }
  if (soup.colors.size() == np && np > 0) {
    vtkNew<vtkFloatArray> colors;
    colors->SetName(kSoupColorArray);
    colors->SetNumberOfComponents(4);
    colors->SetNumberOfTuples(static_cast<vtkIdType>(np));
    for (std::size_t i = 0; i < np; ++i) {
      const glm::vec4& c = soup.colors[i];
      colors->SetTypedTuple(static_cast<vtkIdType>(i), &c.x);
    }
    pd->GetPointData()->AddArray(colors);
  }
  return pd;
}

std::string readHead(const fs::path& path, std::size_t count) {
  std::ifstream in(path, std::ios::binary);
  std::string head(count, '\0');
  in.read(head.data(), static_cast<std::streamsize>(count));
  head.resize(static_cast<std::size_t>(in.gcount()));
  return head;
}

// Runs a reader and throws with VTK's reason when it failed or produced nothing.
template <typename Reader>
vtkSmartPointer<vtkPolyData> runReader(Reader* reader, VtkMessages& messages, bool warningsFail, const char* format,
                                       const std::string& name, const std::string& tempPath = {}) {
  reader->Update();
  vtkPolyData* out = reader->GetOutput();
  const bool failed =
      reader->GetErrorCode() != 0 || messages.hasError() || (warningsFail && messages.hasWarning()) || out == nullptr;
  if (failed) {
    std::string reason = messages.reason();
    replaceAll(reason, tempPath, name);
    throw Error(name, std::string("cannot read ") + format + (reason.empty() ? "" : ": " + reason));
  }
  messages.clear();
  vtkSmartPointer<vtkPolyData> pd = out;  // keep it alive past the reader
  return pd;
}

}  // namespace

Mesh meshFromSoup(const PolygonSoup& soup, const std::string& name) {
  VtkMessages messages;
  vtkSmartPointer<vtkPolyData> pd = polyDataFromSoup(soup, name);
  return finish(pd, name);
}

void computeFeatureNormals(Mesh& mesh, const std::string& name) {
  PolygonSoup soup;
  soup.points = mesh.positions;
  soup.colors = mesh.colors;
  soup.ids = mesh.indices;
  soup.offsets.resize(mesh.triangleCount() + 1);
  for (std::size_t t = 0; t < soup.offsets.size(); ++t) soup.offsets[t] = static_cast<std::uint32_t>(3 * t);
  mesh = meshFromSoup(soup, name);
}

Mesh readWithVtk(VtkFormat format, const fs::path& path, const std::string* contents, const std::string& name) {
  VtkMessages messages;
  vtkSmartPointer<vtkPolyData> pd;
  switch (format) {
    case VtkFormat::Stl: {
      if (contents != nullptr)
        checkStl(std::string_view(*contents).substr(0, 84), contents->size(), name);
      else
        checkStl(readHead(path, 84), fs::file_size(path), name);
      // vtkSTLReader only reads named files.
      std::unique_ptr<TempFile> temp;
      if (contents != nullptr) temp = std::make_unique<TempFile>(*contents, ".stl", name);
      const std::string file = temp ? temp->path().string() : path.string();
      vtkNew<vtkSTLReader> reader;
      reader->SetFileName(file.c_str());
      reader->MergingOn();  // STL repeats shared corners; merged, they get smooth normals
      pd = runReader(reader.GetPointer(), messages, false, "STL", name, temp ? file : std::string{});
      break;
    }
    case VtkFormat::Vtp: {
      checkVtkXmlFileEnd(path, contents, name);
      {
        // What VTK allocates or seeks to before it reads a value, checked first (fuzzing: 2^32 − 1
        // components spun for minutes, 2^31 − 1 took 12 GB). A part's points and indices are 32-bit.
        constexpr long long kMaxComponents = 4096, kMaxTuples = 0xffffffffLL;
        const std::uintmax_t bytes = contents != nullptr ? contents->size() : fs::file_size(path);
        for (const std::string& tag : vtkXmlTags(path, contents))
          if (isVtkXmlElement(tag, "DataArray")) checkVtkXmlDataArray(tag, kMaxComponents, kMaxTuples, bytes, name);
      }
      vtkNew<vtkXMLPolyDataReader> reader;
      if (contents != nullptr) {
        reader->ReadFromInputStringOn();
        reader->SetInputString(*contents);
      } else {
        reader->SetFileName(path.string().c_str());
      }
      pd = runReader(reader.GetPointer(), messages, true, "VTP (XML PolyData)", name);
      break;
    }
  }
  return finish(pd, name);
}

}  // namespace mfr::io
