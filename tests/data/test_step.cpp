// The STEP loader against references it does not compute itself:
//  * the real files' part names and counts from their PRODUCT and NEXT_ASSEMBLY_USAGE_OCCURRENCE
//    entities, read from the STEP text with a regular expression;
//  * their volume, area and bounds from Open CASCADE's exact B-rep integrals (BRepGProp with
//    adaptive Gauss integration over the true surfaces, BRepBndLib::AddOptimal on the
//    surfaces, not on triangles), compared with our triangles: the mesh's vertices lie on the
//    surfaces, so it may differ from the solid by at most (area × meshing deflection);
//  * an assembly built here with Open CASCADE's STEP writer from boxes and cylinders whose
//    volumes, placements, names and colours are known by construction.
// Plus bad input (missing, empty, garbage, truncated, shapeless files), gzip, progress and
// cancellation.
#include <gtest/gtest.h>

#include <unistd.h>

#include <zlib.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <numbers>
#include <regex>
#include <tuple>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include <BRepBndLib.hxx>
#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepGProp.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <Bnd_Box.hxx>
#include <GProp_GProps.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Quantity_ColorRGBA.hxx>
#include <STEPCAFControl_Writer.hxx>
#include <STEPControl_Reader.hxx>
#include <STEPControl_StepModelType.hxx>
#include <TDataStd_Name.hxx>
#include <TDocStd_Document.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <XCAFDoc_ColorTool.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>
#include <gp_Ax1.hxx>
#include <gp_Trsf.hxx>

#include "mfr/error.hpp"
#include "mfr/io/load.hpp"
#include "test_files.hpp"

namespace fs = std::filesystem;

namespace {

// The loader's meshing tolerances (docs/architecture.md, Loaders): the linear one is this share
// of the model's bounding-box diagonal.
constexpr double kRelativeDeflection = 1e-3;

const fs::path kLinkrods = "/usr/share/opencascade/data/step/linkrods.step";
const fs::path kScrew = "/usr/share/opencascade/data/step/screw.step";

using mfr::test::expectLoadError;
using mfr::test::TempDir;

std::string readText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

fs::path requireFile(const fs::path& path) {
  if (!fs::exists(path))
    ADD_FAILURE() << "missing " << path << " (Debian package occt-misc; scripts/setup installs it)";
  return path;
}

// ---- independent readings of a STEP file's text -------------------------------------------------

// Names of the PRODUCT entities, in file order.
std::vector<std::string> productNames(const std::string& text) {
  std::vector<std::string> names;
  const std::regex product(R"(=\s*PRODUCT\s*\(\s*'([^']*)')");
  for (std::sregex_iterator m(text.begin(), text.end(), product), end; m != end; ++m) names.push_back((*m)[1].str());
  return names;
}

std::size_t count(const std::string& text, const std::string& entity) {
  const std::regex re("=\\s*" + entity + "\\s*\\(");
  return static_cast<std::size_t>(std::distance(std::sregex_iterator(text.begin(), text.end(), re), {}));
}

// ---- mesh measures --------------------------------------------------------------------------------

glm::dvec3 world(const mfr::Object& o, const glm::vec3& p) {
  return glm::dvec3(o.transform * glm::dvec4(p, 1.0));
}

// Σ a·(b×c)/6 over the triangles, in world space: the enclosed volume when the mesh is closed and
// wound outward (negative when wound inward).
double signedVolume(const mfr::Object& o) {
  const mfr::Mesh& m = *o.mesh;
  double v = 0.0;
  for (std::size_t t = 0; t + 2 < m.indices.size(); t += 3) {
    const glm::dvec3 a = world(o, m.positions[m.indices[t]]), b = world(o, m.positions[m.indices[t + 1]]),
                     c = world(o, m.positions[m.indices[t + 2]]);
    v += glm::dot(a, glm::cross(b, c)) / 6.0;
  }
  return v;
}

struct EdgeCounts {
  std::size_t edges = 0, boundary = 0, nonManifold = 0, inconsistent = 0;
};

// Vertices welded by exact position, then every undirected edge counted: a closed, consistently
// wound surface uses each edge twice, once in each direction.
EdgeCounts edgeCounts(const mfr::Mesh& m) {
  std::map<std::array<float, 3>, std::uint32_t> id;
  std::vector<std::uint32_t> welded(m.positions.size());
  for (std::size_t i = 0; i < m.positions.size(); ++i) {
    const glm::vec3& p = m.positions[i];
    welded[i] = id.emplace(std::array<float, 3>{p.x, p.y, p.z}, static_cast<std::uint32_t>(id.size())).first->second;
  }
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::pair<int, int>> uses;  // (lo, hi) → (lo→hi, hi→lo)
  for (std::size_t t = 0; t + 2 < m.indices.size(); t += 3)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = welded[m.indices[t + static_cast<std::size_t>(k)]];
      const std::uint32_t b = welded[m.indices[t + static_cast<std::size_t>((k + 1) % 3)]];
      if (a == b) continue;
      auto& u = uses[{std::min(a, b), std::max(a, b)}];
      (a < b ? u.first : u.second)++;
    }
  EdgeCounts c;
  c.edges = uses.size();
  for (const auto& [edge, u] : uses) {
    const int total = u.first + u.second;
    if (total == 1) ++c.boundary;
    if (total > 2) ++c.nonManifold;
    if (total == 2 && u.first != 1) ++c.inconsistent;
  }
  return c;
}

void expectUsableMesh(const mfr::Mesh& mesh) {
  EXPECT_NO_THROW(mesh.validate("mesh"));
  ASSERT_GT(mesh.triangleCount(), 0u);
  ASSERT_EQ(mesh.normals.size(), mesh.positions.size());
  for (const glm::vec3& n : mesh.normals) ASSERT_NEAR(glm::length(n), 1.0f, 1e-4f);
}

void expectClosed(const mfr::Mesh& mesh, const std::string& what) {
  const EdgeCounts c = edgeCounts(mesh);
  EXPECT_GT(c.edges, 0u) << what;
  EXPECT_EQ(c.boundary, 0u) << what << ": edges used by one triangle (cracks) of " << c.edges;
  EXPECT_EQ(c.nonManifold, 0u) << what << ": edges used by more than two triangles";
  EXPECT_EQ(c.inconsistent, 0u) << what << ": edges whose two triangles are wound alike (a flipped face)";
}

mfr::Bounds worldBounds(const std::vector<mfr::Object>& objects) {
  mfr::Bounds b;
  for (const auto& o : objects)
    for (const glm::vec3& p : o.mesh->positions) b.extend(world(o, p));
  return b;
}

// ---- exact references from the B-rep --------------------------------------------------------------

struct Exact {
  double volume = 0.0, area = 0.0;
  mfr::Bounds bounds;
};

Exact exactProperties(const TopoDS_Shape& shape) {
  Exact e;
  GProp_GProps volume, area;
  BRepGProp::VolumeProperties(shape, volume, 1e-9);  // adaptive Gauss integration over the surfaces
  BRepGProp::SurfaceProperties(shape, area, 1e-9);
  e.volume = volume.Mass();
  e.area = area.Mass();
  Bnd_Box box;
  BRepBndLib::AddOptimal(shape, box, /*useTriangulation=*/Standard_False, /*useShapeTolerance=*/Standard_False);
  double x0 = 0, y0 = 0, z0 = 0, x1 = 0, y1 = 0, z1 = 0;
  box.Get(x0, y0, z0, x1, y1, z1);
  e.bounds.extend(glm::dvec3(x0, y0, z0));
  e.bounds.extend(glm::dvec3(x1, y1, z1));
  return e;
}

// The file's shape as Open CASCADE's plain (non-XCAF) STEP reader sees it, quietly.
TopoDS_Shape readShape(const fs::path& path) {
  Message::DefaultMessenger()->ChangePrinters().Clear();
  STEPControl_Reader reader;
  if (reader.ReadFile(path.c_str()) != IFSelect_RetDone) return {};
  reader.TransferRoots();
  return reader.OneShape();
}

// The mesh is inscribed in the surfaces (its vertices lie on them) within the meshing deflection
// d, so the two volumes differ by at most area × d, and the mesh's box lies inside the exact one
// by at most d on every side.
void expectMatchesBrep(const mfr::Object& object, const Exact& exact, double deflection, const std::string& what) {
  const double v = signedVolume(object);
  EXPECT_GT(v, 0.0) << what << ": the mesh is wound inward";
  EXPECT_NEAR(v, exact.volume, exact.area * deflection)
      << what << " (area " << exact.area << ", d " << deflection << ")";
  EXPECT_NEAR(v / exact.volume, 1.0, 0.01) << what;
  mfr::Bounds b;
  for (const glm::vec3& p : object.mesh->positions) b.extend(world(object, p));
  const double eps = 1e-5 * (1.0 + glm::length(exact.bounds.max - exact.bounds.min));
  for (int k = 0; k < 3; ++k) {
    EXPECT_GE(b.min[k], exact.bounds.min[k] - eps) << what << " min, axis " << k;
    EXPECT_LE(b.min[k], exact.bounds.min[k] + deflection + eps) << what << " min, axis " << k;
    EXPECT_LE(b.max[k], exact.bounds.max[k] + eps) << what << " max, axis " << k;
    EXPECT_GE(b.max[k], exact.bounds.max[k] - deflection - eps) << what << " max, axis " << k;
  }
}

// ---- the real files (occt-misc) --------------------------------------------------------------------

struct RealFile {
  const char* path;
  std::size_t expectedFaces;  // ADVANCED_FACE entities in the file
};

class StepRealFile : public ::testing::TestWithParam<RealFile> {};

TEST_P(StepRealFile, PartsMeshesVolumesAndBounds) {
  const fs::path path = requireFile(GetParam().path);
  const std::string text = readText(path);
  // The file's own structure: one PRODUCT per part or assembly, one NAUO per placed component;
  // with no NAUO the file is one part, named by its product.
  const std::vector<std::string> products = productNames(text);
  ASSERT_EQ(products.size(), 1u);
  ASSERT_EQ(count(text, "NEXT_ASSEMBLY_USAGE_OCCURRENCE"), 0u);
  EXPECT_EQ(count(text, "MANIFOLD_SOLID_BREP"), 1u);
  EXPECT_EQ(count(text, "ADVANCED_FACE"), GetParam().expectedFaces);
  EXPECT_NE(text.find("SI_UNIT(.MILLI.,.METRE.)"), std::string::npos);  // millimetres: nothing to convert

  const std::vector<mfr::Object> objects = mfr::loadModel(path);
  ASSERT_EQ(objects.size(), 1u);
  const mfr::Object& part = objects[0];
  EXPECT_EQ(part.name, products[0]);
  EXPECT_EQ(part.transform, glm::dmat4(1.0));
  expectUsableMesh(*part.mesh);
  expectClosed(*part.mesh, path.filename().string());
  // No colours in the file: the first palette colour, opaque.
  EXPECT_EQ(part.material.color, glm::vec4(0.000f, 0.447f, 0.698f, 1.0f));
  EXPECT_TRUE(part.mesh->colors.empty());

  const TopoDS_Shape shape = readShape(path);
  ASSERT_FALSE(shape.IsNull());
  const Exact exact = exactProperties(shape);
  const double deflection = kRelativeDeflection * glm::length(exact.bounds.max - exact.bounds.min);
  expectMatchesBrep(part, exact, deflection, path.filename().string());
  std::cout << "[ info     ] " << path.filename().string() << ": " << part.mesh->triangleCount() << " triangles, "
            << part.mesh->positions.size() << " vertices, volume " << signedVolume(part) << " vs exact " << exact.volume
            << " (relative " << signedVolume(part) / exact.volume - 1.0 << ", bound "
            << exact.area * deflection / exact.volume << ")\n";
}

INSTANTIATE_TEST_SUITE_P(Occt, StepRealFile,
                         ::testing::Values(RealFile{"/usr/share/opencascade/data/step/linkrods.step", 37},
                                           RealFile{"/usr/share/opencascade/data/step/screw.step", 10}),
                         [](const auto& test) { return fs::path(test.param.path).stem().string(); });

// ---- an assembly written here -----------------------------------------------------------------------

// demo
// ├── block:1  box 10×20×30 at the origin; the part red, its first face blue
// ├── block:2  the same box turned 90° about z and moved by (50, 0, 0); instance colour green,
// │            50 % transparent; hidden
// └── axle     moved by (0, 0, 100)
//     ├── pin:1  cylinder r 2, h 40, moved by (5, 5, −5); no colour
//     └── pin:2  the same, moved by (55, 5, −5)
constexpr double kBoxVolume = 10.0 * 20.0 * 30.0;
const double kPinVolume = std::numbers::pi * 2.0 * 2.0 * 40.0;

glm::dmat4 translate(double x, double y, double z) {
  return glm::translate(glm::dmat4(1.0), glm::dvec3(x, y, z));
}

std::map<std::string, glm::dmat4> expectedPlacements() {
  const glm::dmat4 turn = glm::rotate(glm::dmat4(1.0), std::numbers::pi / 2, glm::dvec3(0, 0, 1));
  return {{"demo / block:1", glm::dmat4(1.0)},
          {"demo / block:2", translate(50, 0, 0) * turn},
          {"demo / axle / pin:1", translate(0, 0, 100) * translate(5, 5, -5)},
          {"demo / axle / pin:2", translate(0, 0, 100) * translate(50, 0, 0) * translate(5, 5, -5)}};
}

// Writes the assembly above (without its colours unless `withColors`); with `edgeOnly`, a file
// whose only product is a line segment.
bool writeDemo(const fs::path& path, bool edgeOnly = false, bool withColors = true) {
  Message::DefaultMessenger()->ChangePrinters().Clear();  // the writer's statistics
  Handle(TDocStd_Document) doc = new TDocStd_Document("MDTV-XCAF");
  const Handle(XCAFDoc_ShapeTool) shapes = XCAFDoc_DocumentTool::ShapeTool(doc->Main());
  const Handle(XCAFDoc_ColorTool) colors = XCAFDoc_DocumentTool::ColorTool(doc->Main());
  if (edgeOnly) {
    const TDF_Label wire = shapes->AddShape(BRepBuilderAPI_MakeEdge(gp_Pnt(0, 0, 0), gp_Pnt(1, 2, 3)).Shape(), false);
    TDataStd_Name::Set(wire, "wire");
  } else {
    const TopoDS_Shape box = BRepPrimAPI_MakeBox(10.0, 20.0, 30.0).Shape();
    const TopoDS_Shape cylinder = BRepPrimAPI_MakeCylinder(2.0, 40.0).Shape();
    const TDF_Label top = shapes->NewShape();
    TDataStd_Name::Set(top, "demo");
    const TDF_Label axle = shapes->NewShape();
    TDataStd_Name::Set(axle, "axle");
    const TDF_Label block = shapes->AddShape(box, false);
    TDataStd_Name::Set(block, "block");
    const TDF_Label pin = shapes->AddShape(cylinder, false);
    TDataStd_Name::Set(pin, "pin");
    colors->SetColor(block, Quantity_Color(1.0, 0.0, 0.0, Quantity_TOC_RGB), XCAFDoc_ColorSurf);
    const TDF_Label face = shapes->AddSubShape(block, TopExp_Explorer(box, TopAbs_FACE).Current());
    colors->SetColor(face, Quantity_Color(0.0, 0.0, 1.0, Quantity_TOC_RGB), XCAFDoc_ColorSurf);
    gp_Trsf move, turn, pinAt, up;
    move.SetTranslation(gp_Vec(50, 0, 0));
    turn.SetRotation(gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), std::numbers::pi / 2);
    pinAt.SetTranslation(gp_Vec(5, 5, -5));
    up.SetTranslation(gp_Vec(0, 0, 100));
    shapes->AddComponent(top, block, TopLoc_Location());
    const TDF_Label second = shapes->AddComponent(top, block, TopLoc_Location(move * turn));
    colors->SetColor(second, Quantity_ColorRGBA(Quantity_Color(0.0, 1.0, 0.0, Quantity_TOC_RGB), 0.5f),
                     XCAFDoc_ColorSurf);
    // (Hiding an uncoloured instance crashes Open CASCADE 7.6's writer.)
    colors->SetVisibility(second, Standard_False);
    shapes->AddComponent(axle, pin, TopLoc_Location(pinAt));
    shapes->AddComponent(axle, pin, TopLoc_Location(move * pinAt));
    shapes->AddComponent(top, axle, TopLoc_Location(up));
    shapes->UpdateAssemblies();
  }
  STEPCAFControl_Writer writer;
  writer.SetColorMode(withColors ? Standard_True : Standard_False);
  writer.SetNameMode(Standard_True);
  return writer.Transfer(doc, STEPControl_AsIs) && writer.Write(path.c_str()) == IFSelect_RetDone;
}

const mfr::Object* find(const std::vector<mfr::Object>& objects, const std::string& name) {
  for (const auto& o : objects)
    if (o.name == name) return &o;
  return nullptr;
}

TEST(StepAssembly, NamesPlacementsSharingAndColours) {
  TempDir dir;
  const fs::path path = dir.path() / "demo.step";
  ASSERT_TRUE(writeDemo(path));
  // What the writer put in the file, read back from its text: four products (demo, block, axle,
  // pin) and five placed components (two blocks and the axle in demo, two pins in axle).
  const std::string text = readText(path);
  const std::vector<std::string> products = productNames(text);
  EXPECT_EQ(std::set<std::string>(products.begin(), products.end()),
            (std::set<std::string>{"demo", "block", "axle", "pin"}));
  EXPECT_EQ(count(text, "NEXT_ASSEMBLY_USAGE_OCCURRENCE"), 5u);

  const std::vector<mfr::Object> objects = mfr::loadModel(path);
  ASSERT_EQ(objects.size(), 4u);  // the leaves: 2 blocks + 2 pins
  const auto placements = expectedPlacements();
  for (const auto& [name, transform] : placements) {
    const mfr::Object* o = find(objects, name);
    ASSERT_NE(o, nullptr) << "no part named '" << name << "'";
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) EXPECT_NEAR(o->transform[c][r], transform[c][r], 1e-9) << name;
    expectUsableMesh(*o->mesh);
    expectClosed(*o->mesh, name);
  }
  const mfr::Object& block1 = *find(objects, "demo / block:1");
  const mfr::Object& block2 = *find(objects, "demo / block:2");
  const mfr::Object& pin1 = *find(objects, "demo / axle / pin:1");
  const mfr::Object& pin2 = *find(objects, "demo / axle / pin:2");

  // A box's planar faces mesh exactly (12 triangles); the cylinder within the deflection.
  EXPECT_EQ(block1.mesh->triangleCount(), 12u);
  EXPECT_NEAR(signedVolume(block1), kBoxVolume, 1e-6 * kBoxVolume);
  EXPECT_NEAR(signedVolume(block2), kBoxVolume, 1e-6 * kBoxVolume);
  // The model's box: block 1 spans 0…10 × 0…20 × 0…30, block 2 (turned, moved) 30…50 × 0…10 × 0…30,
  // the pins 3…7 and 53…57 × 3…7 × 95…135: 0…57 × 0…20 × 0…135.
  const double deflection = kRelativeDeflection * std::sqrt(57.0 * 57.0 + 20.0 * 20.0 + 135.0 * 135.0);
  const double pinArea = 2.0 * std::numbers::pi * 2.0 * 40.0 + 2.0 * std::numbers::pi * 2.0 * 2.0;
  for (const mfr::Object* pin : {&pin1, &pin2}) {
    EXPECT_GT(signedVolume(*pin), 0.0);
    EXPECT_NEAR(signedVolume(*pin), kPinVolume, pinArea * deflection) << pin->name;
    EXPECT_NEAR(signedVolume(*pin) / kPinVolume, 1.0, 0.01) << pin->name;
  }
  const mfr::Bounds b = worldBounds(objects);
  const glm::dvec3 lo(0, 0, 0), hi(57, 20, 135);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(b.min[k], lo[k], 1e-4) << "axis " << k;  // box corners and the pins' end caps
    EXPECT_NEAR(b.max[k], hi[k], 1e-4) << "axis " << k;
  }

  for (const mfr::Object* o : {&block1, &pin1, &pin2}) EXPECT_TRUE(o->visible) << o->name;
  EXPECT_FALSE(block2.visible) << "the file hides it";

  // Instances of one part look alike only when their colours agree: the pins share one mesh; the
  // blocks bake different colours into their unstyled faces.
  EXPECT_EQ(pin1.mesh, pin2.mesh);
  EXPECT_NE(block1.mesh, block2.mesh);
  // The pins have no colour in a file that colours other parts: neutral grey, opaque.
  EXPECT_EQ(pin1.material.color, glm::vec4(0.8f, 0.8f, 0.8f, 1.0f));
  EXPECT_TRUE(pin1.mesh->colors.empty());
  // The blocks: per-vertex colours, the one styled face blue, the rest the part's red (block 1)
  // or the instance's half-transparent green (block 2); the material white.
  for (const auto& [block, rest] : {std::pair{&block1, glm::vec4(1, 0, 0, 1)}, {&block2, glm::vec4(0, 1, 0, 0.5f)}}) {
    EXPECT_EQ(block->material.color, glm::vec4(1.0f)) << block->name;
    const mfr::Mesh& m = *block->mesh;
    ASSERT_EQ(m.colors.size(), m.positions.size()) << block->name;
    std::size_t blue = 0, other = 0;
    for (const glm::vec4& c : m.colors) {
      if (c == glm::vec4(0, 0, 1, 1))
        ++blue;
      else if (c == rest)
        ++other;
      else
        ADD_FAILURE() << block->name << ": unexpected colour " << c.r << " " << c.g << " " << c.b << " " << c.a;
    }
    EXPECT_EQ(blue, 4u) << block->name;  // one quad face, its own 4 vertices
    EXPECT_EQ(other, 20u) << block->name;
    // The blue face is BRepPrimAPI_MakeBox's first: the x = 0 face (in part coordinates).
    for (std::size_t i = 0; i < m.positions.size(); ++i)
      if (m.colors[i] == glm::vec4(0, 0, 1, 1)) {
        EXPECT_EQ(m.positions[i].x, 0.0f) << block->name;
      }
  }
}

TEST(StepAssembly, UncolouredFileGetsThePalette) {
  TempDir dir;
  const fs::path plain = dir.path() / "plain.stp";
  ASSERT_TRUE(writeDemo(plain, /*edgeOnly=*/false, /*withColors=*/false));
  const std::string text = readText(plain);
  ASSERT_EQ(text.find("STYLED_ITEM"), std::string::npos);  // the file has no colour at all
  ASSERT_EQ(text.find("COLOUR"), std::string::npos);
  const std::vector<mfr::Object> objects = mfr::loadModel(plain);
  ASSERT_EQ(objects.size(), 4u);
  // Okabe-Ito in order of the parts; the four instances get four different colours.
  const std::vector<glm::vec4> palette = {{0.000f, 0.447f, 0.698f, 1.0f},
                                          {0.902f, 0.624f, 0.000f, 1.0f},
                                          {0.000f, 0.620f, 0.451f, 1.0f},
                                          {0.835f, 0.369f, 0.000f, 1.0f}};
  for (std::size_t i = 0; i < objects.size(); ++i) {
    EXPECT_EQ(objects[i].material.color, palette[i]) << objects[i].name;
    EXPECT_TRUE(objects[i].mesh->colors.empty());
  }
  // All block instances now look alike: one shared mesh.
  EXPECT_EQ(find(objects, "demo / block:1")->mesh, find(objects, "demo / block:2")->mesh);
}

TEST(StepAssembly, KeepsTheFilesLengthUnit) {
  TempDir dir;
  const fs::path mm = dir.path() / "demo.step";
  ASSERT_TRUE(writeDemo(mm));
  const std::string text = readText(mm);
  ASSERT_NE(text.find("SI_UNIT(.MILLI.,.METRE.)"), std::string::npos);
  // The same numbers declared in metres, and in inches (a conversion-based unit).
  const fs::path metres = dir.write(
      "metres.step", std::regex_replace(text, std::regex(R"(SI_UNIT\(\.MILLI\.,\.METRE\.\))"), "SI_UNIT($,.METRE.)"));
  std::string inchText = std::regex_replace(
      text, std::regex(R"(\(\s*LENGTH_UNIT\(\)\s*NAMED_UNIT\(\*\)\s*SI_UNIT\(\.MILLI\.,\.METRE\.\)\s*\))"),
      "( CONVERSION_BASED_UNIT('INCH',#90001) LENGTH_UNIT() NAMED_UNIT(#90003) )");
  ASSERT_NE(inchText, text);
  inchText.replace(inchText.rfind("ENDSEC;"), 7,
                   "#90001=LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE(25.4),#90002);\n"
                   "#90002=( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) );\n"
                   "#90003=DIMENSIONAL_EXPONENTS(1.,0.,0.,0.,0.,0.,0.);\nENDSEC;");
  const fs::path inches = dir.write("inches.step", inchText);
  for (const fs::path& p : {mm, metres, inches}) {
    SCOPED_TRACE(p.filename().string());
    const std::vector<mfr::Object> objects = mfr::loadModel(p);
    ASSERT_EQ(objects.size(), 4u);
    const mfr::Bounds b = worldBounds(objects);
    EXPECT_NEAR(b.max.x, 57.0, 1e-4);
    EXPECT_NEAR(b.max.z, 135.0, 1e-4);
    EXPECT_NEAR(signedVolume(*find(objects, "demo / block:2")), kBoxVolume, 1e-6 * kBoxVolume);
  }
}

// ---- gzip, extension case --------------------------------------------------------------------------

TEST(StepFiles, GzippedAndUpperCaseNames) {
  TempDir dir;
  const std::string text = readText(requireFile(kScrew));
  ASSERT_FALSE(text.empty());
  const fs::path gz = dir.path() / "screw.step.gz";
  gzFile out = gzopen(gz.c_str(), "wb");
  ASSERT_NE(out, nullptr);
  ASSERT_EQ(gzwrite(out, text.data(), static_cast<unsigned>(text.size())), static_cast<int>(text.size()));
  gzclose(out);
  const fs::path upper = dir.write("SCREW.STP", text);
  const auto plain = mfr::loadModel(kScrew), zipped = mfr::loadModel(gz), shouted = mfr::loadModel(upper);
  ASSERT_EQ(zipped.size(), 1u);
  ASSERT_EQ(shouted.size(), 1u);
  EXPECT_EQ(zipped[0].mesh->positions, plain[0].mesh->positions);
  EXPECT_EQ(zipped[0].mesh->indices, plain[0].mesh->indices);
  EXPECT_EQ(shouted[0].mesh->indices, plain[0].mesh->indices);
  const auto extensions = mfr::supportedModelExtensions();
  for (const char* e : {".step", ".stp", ".step.gz", ".stp.gz"})
    EXPECT_NE(std::find(extensions.begin(), extensions.end(), e), extensions.end()) << e;
}

// ---- bad input ---------------------------------------------------------------------------------------

TEST(StepBadInput, OneLineErrorsNamingTheFile) {
  TempDir dir;
  const std::string screw = readText(requireFile(kScrew));
  ASSERT_GT(screw.size(), 1000u);
  expectLoadError(dir.path() / "missing.step", "no such file");
  expectLoadError(dir.write("empty.step", ""), "empty file");
  expectLoadError(dir.write("garbage.step", "hello, this is not STEP\n\x01\x02\x03"), "not a readable STEP file");
  expectLoadError(dir.write("binary.stp", std::string("\x89PNG\r\n\x1a\n\0\0\0\rIHDR", 16)),
                  "not a readable STEP file");
  // Cut in the middle of the DATA section: the parser sees an unterminated entity.
  expectLoadError(dir.write("half.step", screw.substr(0, screw.size() / 2)), "not a readable STEP file (line ");
  // Valid syntax without any product or solid.
  expectLoadError(dir.write("point.step",
                            "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION((''),'2;1');\n"
                            "FILE_NAME('p','',(''),(''),'','','');\nFILE_SCHEMA(('AUTOMOTIVE_DESIGN'));\nENDSEC;\n"
                            "DATA;\n#1=CARTESIAN_POINT('',(0.,0.,0.));\nENDSEC;\nEND-ISO-10303-21;\n"),
                  "no shapes");
  // An entity id beyond Open CASCADE's 32-bit ints made its model dereference a null entity
  // (signal 11): refused, naming the line. The largest int is an ordinary id.
  {
    ASSERT_NE(screw.find("\n#338 ="), std::string::npos);
    const std::regex point("#338(?![0-9])");  // the definition and every reference to it
    expectLoadError(dir.write("bigid.step", std::regex_replace(screw, point, "#2147483648")),
                    "entity id #2147483648 out of range");
    EXPECT_NO_THROW((void)mfr::loadModel(dir.write("maxid.step", std::regex_replace(screw, point, "#2147483647"))));
  }
  // Geometry the transfer cannot take (a bug hunt): a vertex at a point of 2 coordinates crashed
  // it (signal 11), one of none too (read as 2); a zero direction lost faces without a word.
  for (const auto& [from, to, mention] : std::vector<std::tuple<std::string, std::string, std::string>>{
           {"#20 = CARTESIAN_POINT('',(-27.8196811084,0.423702927757,5.43633));", "#20 = CARTESIAN_POINT('',(1.,2.));",
            "entity #19: a vertex at a point of 2 coordinates (expected 3)"},
           {"#20 = CARTESIAN_POINT('',(-27.8196811084,0.423702927757,5.43633));", "#20 = CARTESIAN_POINT('',());",
            "entity #19: a vertex at a point of"},
           {"#52 = DIRECTION('',(0.E+000,1.,0.E+000));", "#52 = DIRECTION('',(0.,0.,0.));",
            "entity #52: a direction of zero length"}}) {
    std::string text = screw;
    ASSERT_NE(text.find(from), std::string::npos) << from;
    text.replace(text.find(from), from.size(), to);
    expectLoadError(dir.write("geometry.step", text), "not a readable STEP file (" + mention);
  }
  // A product whose shape is one edge: nothing to draw.
  const fs::path wire = dir.path() / "wire.step";
  ASSERT_TRUE(writeDemo(wire, /*edgeOnly=*/true));
  expectLoadError(wire, "no surfaces");
}

// Faces Open CASCADE drops without failing the read (a cone of negative radius: the transfer
// leaves the face out; a B-spline edge whose first knot is repeated 40 times: the face is not
// meshed) are a note each, and the rest of the part is drawn; the file as it is gives none.
TEST(StepBadInput, DroppedFacesAreNoted) {
  TempDir dir;
  const std::string screw = readText(requireFile(kScrew));
  const auto load = [](const fs::path& path, std::vector<std::string>& notes) {
    mfr::LoadOptions options;
    options.notes = &notes;
    const std::vector<mfr::Object> objects = mfr::loadModel(path, options);
    std::size_t triangles = 0;
    for (const mfr::Object& o : objects) triangles += o.mesh->triangleCount();
    return triangles;
  };
  std::vector<std::string> notes;
  const std::size_t whole = load(kScrew, notes);
  EXPECT_TRUE(notes.empty()) << notes.front();
  for (const auto& [from, to, note] : std::vector<std::tuple<std::string, std::string, std::string>>{
           {"#153 = CONICAL_SURFACE('',#154,7.5,0.785398163397);",
            "#153 = CONICAL_SURFACE('',#154,-7.5,0.785398163397);",
            "1 of the file's 10 faces could not be read (damaged geometry; not drawn)"},
           {"(4,2,2,2,2,3,2,2,2,2,4),(-9.753048731913", "(40,2,2,2,2,3,2,2,2,2,4),(-9.753048731913",
            "1 of 10 faces could not be meshed (not drawn)"}}) {
    std::string text = screw;
    ASSERT_NE(text.find(from), std::string::npos) << from;
    text.replace(text.find(from), from.size(), to);
    const fs::path damaged = dir.write("damaged.step", text);
    notes.clear();
    const std::size_t triangles = load(damaged, notes);
    EXPECT_GT(triangles, 0u);
    ASSERT_EQ(notes.size(), 1u) << to;
    EXPECT_EQ(notes[0], damaged.string() + ": " + note);
  }
  EXPECT_GT(whole, 0u);
}

// Open CASCADE runs in a child process: what it cannot do within the memory limit is one line
// naming the file (its own Standard_OutOfMemory is the limit's message too), and this process
// goes on to read the file when the limit allows.
TEST(StepBadInput, TheMemoryLimitIsOneLine) {
  std::uint64_t size = 0, residentPages = 0;
  std::ifstream("/proc/self/statm") >> size >> residentPages;
  const std::uint64_t residentMiB = residentPages * static_cast<std::uint64_t>(::sysconf(_SC_PAGESIZE)) >> 20;
  const fs::path linkrods = requireFile(kLinkrods);
  ASSERT_EQ(setenv("MFR_MEMORY_LIMIT_MIB", std::to_string(residentMiB + 5).c_str(), 1), 0);
  std::string error;
  try {
    (void)mfr::loadModel(linkrods);
  } catch (const mfr::Error& e) {
    error = e.what();
  }
  ASSERT_EQ(unsetenv("MFR_MEMORY_LIMIT_MIB"), 0);
  EXPECT_EQ(error.rfind(linkrods.string() + ": cannot read step: Open CASCADE needed more than the ", 0), 0u) << error;
  EXPECT_EQ(mfr::loadModel(linkrods).size(), 1u);
}

// Truncations anywhere and damaged bytes: an error or a model, never a crash, hang or foreign
// exception.
TEST(StepBadInput, TruncatedAndDamagedCopies) {
  TempDir dir;
  const std::string screw = readText(requireFile(kScrew));
  ASSERT_GT(screw.size(), 1000u);
  int errors = 0, loaded = 0;
  for (int i = 1; i < 16; ++i) {
    const std::size_t cut = screw.size() * static_cast<std::size_t>(i) / 16;
    const fs::path p = dir.write("cut" + std::to_string(i) + ".step", screw.substr(0, cut));
    try {
      (void)mfr::loadModel(p);
      ++loaded;
    } catch (const mfr::Error& e) {
      ++errors;
      EXPECT_EQ(std::string(e.what()).rfind(p.string() + ": ", 0), 0u) << e.what();
    }
  }
  EXPECT_EQ(errors, 15) << "every cut leaves an unterminated file";
  std::uint64_t state = 12345;
  for (int i = 0; i < 12; ++i) {
    std::string damaged = screw;
    for (int k = 0; k < 8; ++k) {
      state = state * 6364136223846793005ull + 1442695040888963407ull;
      damaged[static_cast<std::size_t>(state >> 33) % damaged.size()] = "(),;'#=X9.\n"[(state >> 20) % 11];
    }
    const fs::path p = dir.write("damaged" + std::to_string(i) + ".step", damaged);
    try {
      const auto objects = mfr::loadModel(p);
      for (const auto& o : objects) EXPECT_NO_THROW(o.mesh->validate(o.name));
      ++loaded;
    } catch (const mfr::Error& e) {
      ++errors;
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    }
  }
  std::cout << "[ info     ] " << errors << " errors, " << loaded << " loaded\n";
}

// ---- progress and cancellation ---------------------------------------------------------------------

TEST(StepProgress, ReportsEachStageAndCancelsAtAnyReport) {
  TempDir dir;
  const fs::path path = dir.path() / "demo.step";
  ASSERT_TRUE(writeDemo(path));
  std::vector<double> reports;
  mfr::LoadProgress progress{[&](double f) {
    reports.push_back(f);
    return true;
  }};
  ASSERT_EQ(mfr::loadModel(path, progress).size(), 4u);
  ASSERT_GE(reports.size(), 6u);  // start, read, transfer, two parts meshed, done
  EXPECT_EQ(reports.front(), 0.0);
  EXPECT_EQ(reports.back(), 1.0);
  EXPECT_TRUE(std::is_sorted(reports.begin(), reports.end()));
  // Cancelling at the n-th report stops the load there, for every n. (Open CASCADE's meshing runs
  // on several threads and only the loading thread's reports are passed on, so a later load may
  // report fewer times; one that ends before its n-th report was never asked to stop.)
  std::size_t stopped = 0;
  for (std::size_t n = 1; n <= reports.size(); ++n) {
    std::size_t calls = 0;
    mfr::LoadProgress cancelling{[&](double) { return ++calls < n; }};
    try {
      (void)mfr::loadModel(path, cancelling);
      EXPECT_LT(calls, n) << "loaded although report " << n << " said stop";
    } catch (const mfr::LoadCancelled&) {
      EXPECT_EQ(calls, n) << "reports after cancelling at report " << n;
      ++stopped;
    }
  }
  EXPECT_GE(stopped, 6u);
  // And at each stage: the first report at or past the end of parsing (0.3 of the STEP loader's
  // 95 %), of the transfer (0.55), of the first part (0.775), of the second (0.95), and the last.
  for (const double stage : {0.0, 0.3 * 0.95, 0.55 * 0.95, 0.775 * 0.95, 0.95, 1.0}) {
    double last = -1.0;
    mfr::LoadProgress cancelling{[&](double f) {
      last = f;
      return f < stage - 1e-9;
    }};
    EXPECT_THROW((void)mfr::loadModel(path, cancelling), mfr::LoadCancelled) << "stage " << stage;
    EXPECT_NEAR(last, stage, 0.05) << "the load went on past the report that said stop";
  }
}

}  // namespace
