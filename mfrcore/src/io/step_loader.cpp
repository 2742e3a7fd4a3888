// STEP files through Open CASCADE: STEPCAFControl_Reader fills an XCAF document (names,
// colours, assembly structure), the assembly tree is walked like OCCT's own XCAFPrs
// DocumentExplorer does (locations multiplied down the tree; a part's style, then its instance's,
// overrides what it inherits; face styles override the part's), every distinct part is meshed
// once with BRepMesh and its mesh shared by all instances that look the same.
#include "step_loader.hpp"

#include <algorithm>
#include <cctype>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <mutex>
#include <new>
#include <optional>
#include <set>
#include <streambuf>
#include <system_error>
#include <thread>
#include <tuple>
#include <utility>

#include <BRepBndLib.hxx>
#include <BRepMesh_IncrementalMesh.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <IMeshTools_Parameters.hxx>
#include <Interface_Check.hxx>
#include <Interface_InterfaceModel.hxx>
#include <Message.hxx>
#include <Message_Gravity.hxx>
#include <Message_Messenger.hxx>
#include <Message_Printer.hxx>
#include <Message_ProgressIndicator.hxx>
#include <Message_ProgressScope.hxx>
#include <Poly_Triangulation.hxx>
#include <Quantity_ColorRGBA.hxx>
#include <STEPCAFControl_Reader.hxx>
#include <STEPConstruct_UnitContext.hxx>
#include <STEPControl_Reader.hxx>
#include <Standard_Failure.hxx>
#include <Standard_OutOfMemory.hxx>
#include <StepData_GlobalFactors.hxx>
#include <StepData_Protocol.hxx>
#include <StepData_StepModel.hxx>
#include <StepFile_Read.hxx>
#include <StepGeom_CartesianPoint.hxx>
#include <StepGeom_Direction.hxx>
#include <StepGeom_GeomRepContextAndGlobUnitAssCtxAndGlobUncertaintyAssCtx.hxx>
#include <StepGeom_GeometricRepresentationContextAndGlobalUnitAssignedContext.hxx>
#include <StepRepr_GlobalUnitAssignedContext.hxx>
#include <StepShape_ConnectedFaceSet.hxx>
#include <StepShape_Face.hxx>
#include <StepShape_FaceSurface.hxx>
#include <StepShape_OrientedFace.hxx>
#include <StepShape_VertexPoint.hxx>
#include <TCollection_AsciiString.hxx>
#include <TDF_Label.hxx>
#include <TDF_LabelSequence.hxx>
#include <TDF_Tool.hxx>
#include <TDataStd_Name.hxx>
#include <TDocStd_Document.hxx>
#include <TopExp_Explorer.hxx>
#include <TopLoc_Location.hxx>
#include <TopTools_DataMapOfShapeInteger.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>
#include <UnitsMethods.hxx>
#include <XCAFDoc_ColorTool.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>
#include <XCAFDoc_VisMaterial.hxx>
#include <XCAFDoc_VisMaterialTool.hxx>
#include <XSControl_WorkSession.hxx>
#include <gp_Dir.hxx>
#include <gp_Pnt.hxx>
#include <gp_Trsf.hxx>

#include "child_process.hpp"
#include "mfr/error.hpp"

namespace mfr::io {
namespace {

// Parts of a file without any colour get these in turn (Okabe & Ito's colour-blind-safe
// qualitative palette, black left out), so an assembly's parts can be told apart.
constexpr std::array<glm::vec4, 7> kPalette = {{
    {0.000f, 0.447f, 0.698f, 1.0f},  // blue
    {0.902f, 0.624f, 0.000f, 1.0f},  // orange
    {0.000f, 0.620f, 0.451f, 1.0f},  // bluish green
    {0.835f, 0.369f, 0.000f, 1.0f},  // vermillion
    {0.337f, 0.706f, 0.914f, 1.0f},  // sky blue
    {0.800f, 0.475f, 0.655f, 1.0f},  // reddish purple
    {0.941f, 0.894f, 0.259f, 1.0f},  // yellow
}};
// Parts without a colour in a file that colours others.
constexpr glm::vec4 kUncoloured{0.8f, 0.8f, 0.8f, 1.0f};

constexpr int kMaxAssemblyDepth = 256;
constexpr std::size_t kMaxInstances = 10'000'000;

// ---- Open CASCADE's messages, progress and errors ---------------------------------------------

// Keeps the failures Open CASCADE reports (the STEP parser's syntax errors among them) for the
// error message instead of printing them.
class CapturePrinter final : public Message_Printer {
 public:
  [[nodiscard]] std::string firstFailure() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    return first_;
  }

 protected:
  void send(const TCollection_AsciiString& text, const Message_Gravity gravity) const override {
    if (gravity < Message_Fail) return;
    const std::lock_guard<std::mutex> lock(mutex_);
    if (first_.empty()) first_ = text.ToCString();
  }

 private:
  mutable std::mutex mutex_;
  mutable std::string first_;
};

// Open CASCADE reports through one process-wide messenger whose printers write to stdout (which
// carries the CLI's output). While a file loads they are replaced by a CapturePrinter.
class QuietMessenger {
 public:
  QuietMessenger() : messenger_(Message::DefaultMessenger()), printer_(new CapturePrinter) {
    saved_ = messenger_->Printers();
    messenger_->ChangePrinters().Clear();
    messenger_->AddPrinter(printer_);
  }
  ~QuietMessenger() { messenger_->ChangePrinters() = saved_; }
  QuietMessenger(const QuietMessenger&) = delete;
  QuietMessenger& operator=(const QuietMessenger&) = delete;

  // The first failure reported, tidied into a phrase ("" when none).
  [[nodiscard]] std::string failure() const {
    std::string s = printer_->firstFailure();
    for (char& c : s)
      if (c == '\n' || c == '\r' || c == '\t' || c == '*') c = ' ';
    s.erase(std::unique(s.begin(), s.end(), [](char a, char b) { return a == ' ' && b == ' '; }), s.end());
    while (!s.empty() && s.front() == ' ') s.erase(s.begin());
    while (!s.empty() && s.back() == ' ') s.pop_back();
    // "ERR StepFile : Undefined Parsing: Line 43: Incorrect syntax: …" → "line 43: incorrect syntax: …"
    for (const char* prefix : {"ERR StepFile : Undefined Parsing: ", "ERR StepFile : "})
      if (s.rfind(prefix, 0) == 0) s.erase(0, std::char_traits<char>::length(prefix));
    if (s.rfind("Line ", 0) == 0) s[0] = 'l';
    return s;
  }

 private:
  Handle(Message_Messenger) messenger_;
  Handle(CapturePrinter) printer_;
  Message_SequenceOfPrinters saved_;
};

// One Open CASCADE algorithm's progress as a LoadProgress. Its workers may report from other
// threads: those reports only move the position, LoadProgress hears from the loading thread. A
// cancelled load makes UserBreak true, which stops the algorithm; nothing is thrown through
// Open CASCADE's frames.
class OcctProgress final : public Message_ProgressIndicator {
 public:
  explicit OcctProgress(LoadProgress progress) : progress_(std::move(progress)), thread_(std::this_thread::get_id()) {}
  Standard_Boolean UserBreak() override { return cancelled_.load(); }
  void Show(const Message_ProgressScope& /*scope*/, const Standard_Boolean force) override {
    if (cancelled_.load() || std::this_thread::get_id() != thread_) return;
    const double position = std::clamp(GetPosition(), 0.0, 1.0);
    if (!force && position < shown_ + 0.01) return;  // a few dozen reports per algorithm at most
    shown_ = std::max(shown_, position);
    if (!progress_.tryStep(shown_)) cancelled_.store(true);
  }
  [[nodiscard]] bool cancelled() const { return cancelled_.load(); }

 private:
  LoadProgress progress_;
  std::thread::id thread_;
  double shown_ = 0.0;
  std::atomic<bool> cancelled_{false};
};

// Open CASCADE's session length unit is process-wide (twice: UnitsMethods and the STEP
// reader's StepData_GlobalFactors, which a transfer sets to the document's unit and which the
// file's unit factors are computed against): every load starts from millimetres and leaves both
// as it found them.
class SessionLengthUnit {
 public:
  SessionLengthUnit()
      : units_(UnitsMethods::GetCasCadeLengthUnit(UnitsMethods_LengthUnit_Millimeter)),
        step_(StepData_GlobalFactors::Intance().CascadeUnit()) {
    UnitsMethods::SetCasCadeLengthUnit(1.0, UnitsMethods_LengthUnit_Millimeter);
    StepData_GlobalFactors::Intance().SetCascadeUnit(1.0);
  }
  ~SessionLengthUnit() {
    UnitsMethods::SetCasCadeLengthUnit(units_, UnitsMethods_LengthUnit_Millimeter);
    StepData_GlobalFactors::Intance().SetCascadeUnit(step_);
  }
  SessionLengthUnit(const SessionLengthUnit&) = delete;
  SessionLengthUnit& operator=(const SessionLengthUnit&) = delete;

 private:
  double units_, step_;
};

// Open CASCADE's STEP reader keeps its settings in process-wide statics and the messenger is
// shared: one STEP load at a time.
std::mutex& occtMutex() {
  static std::mutex m;
  return m;
}

// ---- conversions --------------------------------------------------------------------------------

glm::vec4 rgba(const Quantity_ColorRGBA& c) {
  // Quantity_TOC_RGB gives back the numbers the file wrote (its display values).
  const Quantity_Color& rgb = c.GetRGB();
  glm::vec4 v(static_cast<float>(rgb.Red()), static_cast<float>(rgb.Green()), static_cast<float>(rgb.Blue()),
              c.Alpha());
  v = glm::clamp(v, 0.0f, 1.0f);
  if (!std::isfinite(v.r + v.g + v.b + v.a)) v = kUncoloured;
  return v;
}

glm::dmat4 toGlm(const gp_Trsf& t) {
  glm::dmat4 m(1.0);
  for (int r = 1; r <= 3; ++r)
    for (int c = 1; c <= 4; ++c) m[c - 1][r - 1] = t.Value(r, c);
  return m;
}

std::string cleanName(std::string s) {
  for (char& c : s)
    if (static_cast<unsigned char>(c) < 0x20) c = ' ';
  while (!s.empty() && s.back() == ' ') s.pop_back();
  while (!s.empty() && s.front() == ' ') s.erase(s.begin());
  return s;
}

std::string labelName(const TDF_Label& label) {
  Handle(TDataStd_Name) attribute;
  if (label.IsNull() || !label.FindAttribute(TDataStd_Name::GetID(), attribute)) return {};
  return cleanName(TCollection_AsciiString(attribute->Get()).ToCString());  // UTF-8
}

std::string entry(const TDF_Label& label) {
  TCollection_AsciiString e;
  TDF_Tool::Entry(label, e);
  return e.ToCString();
}

// The length unit of the file's first unit context, in metres; 0 when the file states none.
double fileLengthUnitInMetres(const Handle(Interface_InterfaceModel) & model) {
  if (model.IsNull()) return 0.0;
  for (Standard_Integer i = 1; i <= model->NbEntities(); ++i) {
    const Handle(Standard_Transient)& entity = model->Value(i);
    Handle(StepRepr_GlobalUnitAssignedContext) context = Handle(StepRepr_GlobalUnitAssignedContext)::DownCast(entity);
    if (const auto complex = Handle(StepGeom_GeomRepContextAndGlobUnitAssCtxAndGlobUncertaintyAssCtx)::DownCast(entity))
      context = complex->GlobalUnitAssignedContext();
    if (const auto complex =
            Handle(StepGeom_GeometricRepresentationContextAndGlobalUnitAssignedContext)::DownCast(entity))
      context = complex->GlobalUnitAssignedContext();
    if (context.IsNull()) continue;
    STEPConstruct_UnitContext units;
    units.ComputeFactors(context);
    // LengthFactor: the file's unit in the session unit, millimetres (SessionLengthUnit).
    const double metres = units.LengthFactor() * 1e-3;
    if (units.LengthDone() && std::isfinite(metres) && metres > 0.0) return metres;
  }
  return 0.0;
}

// ---- the assembly walk --------------------------------------------------------------------------

struct Instance {
  TDF_Label part;                  // the referred simple shape
  TopLoc_Location location;        // part → world
  std::string name;                // "assembly / sub / part:2"
  std::optional<glm::vec4> color;  // inherited and own styles merged
  bool visible = true;
};

class Walker {
 public:
  Walker(const Handle(TDocStd_Document) & doc, std::string stem, std::string name)
      : shapes_(XCAFDoc_DocumentTool::ShapeTool(doc->Main())),
        colors_(XCAFDoc_DocumentTool::ColorTool(doc->Main())),
        materials_(XCAFDoc_DocumentTool::VisMaterialTool(doc->Main())),
        stem_(std::move(stem)),
        name_(std::move(name)) {}

  std::vector<Instance> walk(const TDF_LabelSequence& roots) {
    std::vector<Instance> out;
    for (Standard_Integer i = 1; i <= roots.Length(); ++i) {
      const TDF_Label& root = roots.Value(i);
      TDF_Label ref = root;
      XCAFDoc_ShapeTool::GetReferredShape(root, ref);
      std::string rootName = labelName(root);
      if (rootName.empty()) rootName = labelName(ref);
      if (rootName.empty()) rootName = roots.Length() == 1 ? stem_ : stem_ + " " + std::to_string(i);
      visit(ref, XCAFDoc_ShapeTool::GetLocation(root), merged(std::nullopt, root, ref), visible(root) && visible(ref),
            rootName, 0, out);
    }
    return out;
  }

  // The label's own colour: a visualisation material's base colour, overridden by a generic
  // colour, overridden by a surface colour (as XCAFPrs does).
  [[nodiscard]] std::optional<glm::vec4> ownColor(const TDF_Label& label) const {
    std::optional<glm::vec4> color;
    if (!materials_.IsNull())
      if (const Handle(XCAFDoc_VisMaterial) material = materials_->GetShapeMaterial(label); !material.IsNull())
        color = rgba(material->BaseColor());
    Quantity_ColorRGBA c;
    if (colors_->GetColor(label, XCAFDoc_ColorGen, c)) color = rgba(c);
    if (colors_->GetColor(label, XCAFDoc_ColorSurf, c)) color = rgba(c);
    return color;
  }

  [[nodiscard]] const Handle(XCAFDoc_ShapeTool) & shapes() const { return shapes_; }

  // Whether the file assigns any colour or material at all.
  [[nodiscard]] bool fileHasColors() const {
    TDF_LabelSequence colors, materials;
    colors_->GetColors(colors);
    if (!materials_.IsNull()) materials_->GetMaterials(materials);
    return colors.Length() > 0 || materials.Length() > 0;
  }

 private:
  // The style of a node: what it inherits, overridden by the referred shape's own, overridden by
  // the instance's own.
  std::optional<glm::vec4> merged(std::optional<glm::vec4> inherited, const TDF_Label& label,
                                  const TDF_Label& ref) const {
    if (auto c = ownColor(ref)) inherited = c;
    if (label != ref)
      if (auto c = ownColor(label)) inherited = c;
    return inherited;
  }

  bool visible(const TDF_Label& label) const { return colors_->IsVisible(label) != Standard_False; }

  // `ref`: the shape a node places (its own label for a root); `location`: where, in world space.
  void visit(const TDF_Label& ref, const TopLoc_Location& location, const std::optional<glm::vec4>& color,
             bool isVisible, const std::string& path, int depth, std::vector<Instance>& out) const {
    if (depth > kMaxAssemblyDepth) throw Error(name_, "assembly nested too deeply (or cyclic)");
    if (!XCAFDoc_ShapeTool::IsAssembly(ref)) {
      if (out.size() >= kMaxInstances) throw Error(name_, "more than 10 million part instances");
      out.push_back({ref, location, path, color, isVisible});
      return;
    }
    TDF_LabelSequence components;
    XCAFDoc_ShapeTool::GetComponents(ref, components, Standard_False);
    // Components are named by their instance name when the file gives one (OCCT's own writer
    // stores a label entry "=>[0:1:1:3]" there: no name), else by the part they place; names
    // shared by siblings are numbered "rod:1", "rod:2".
    std::vector<std::string> names;
    std::map<std::string, int> count;
    for (Standard_Integer i = 1; i <= components.Length(); ++i) {
      const TDF_Label& component = components.Value(i);
      TDF_Label child = component;
      XCAFDoc_ShapeTool::GetReferredShape(component, child);
      std::string n = labelName(component);
      if (n.empty() || n.rfind("=>[", 0) == 0) n = labelName(child);
      if (n.empty()) n = "part";
      names.push_back(n);
      ++count[n];
    }
    std::map<std::string, int> seen;
    for (Standard_Integer i = 1; i <= components.Length(); ++i) {
      const TDF_Label& component = components.Value(i);
      TDF_Label child = component;
      if (!XCAFDoc_ShapeTool::GetReferredShape(component, child) || child.IsNull()) continue;
      std::string n = names[static_cast<std::size_t>(i - 1)];
      if (count[n] > 1) n += ":" + std::to_string(++seen[n]);
      visit(child, location * XCAFDoc_ShapeTool::GetLocation(component), merged(color, component, child),
            isVisible && visible(component) && visible(child), path + " / " + n, depth + 1, out);
    }
  }

  Handle(XCAFDoc_ShapeTool) shapes_;
  Handle(XCAFDoc_ColorTool) colors_;
  Handle(XCAFDoc_VisMaterialTool) materials_;
  std::string stem_, name_;
};

// ---- meshing -------------------------------------------------------------------------------------

// A part's triangles in its own coordinates, and per vertex the style of its face, if any.
struct PartMesh {
  Mesh mesh;                     // positions, normals, indices; no colours
  std::vector<int> vertexStyle;  // index into styles, −1: none; empty when no face has a style
  std::vector<glm::vec4> styles;
  std::size_t faces = 0;                                               // of the shape
  std::size_t unmeshed = 0;                                            // of those, faces BRepMesh gave no triangles
  std::map<std::array<float, 4>, std::shared_ptr<const Mesh>> shared;  // by the colour baked in
  std::shared_ptr<const Mesh> plain;
};

// Area-weighted normals of one face's triangles, summed over the face's nodes that coincide (a
// periodic face repeats its seam nodes) and never across faces: CAD edges are sharp.
void smoothFaceNormals(Mesh& mesh, std::uint32_t firstVertex, std::size_t firstIndex) {
  const std::size_t n = mesh.positions.size() - firstVertex;
  std::vector<glm::dvec3> sum(n, glm::dvec3(0.0));
  for (std::size_t t = firstIndex; t + 2 < mesh.indices.size(); t += 3) {
    const glm::dvec3 a(mesh.positions[mesh.indices[t]]), b(mesh.positions[mesh.indices[t + 1]]),
        c(mesh.positions[mesh.indices[t + 2]]);
    const glm::dvec3 normal = glm::cross(b - a, c - a);
    for (int k = 0; k < 3; ++k) sum[mesh.indices[t + static_cast<std::size_t>(k)] - firstVertex] += normal;
  }
  std::map<std::array<float, 3>, glm::dvec3> welded;
  for (std::size_t i = 0; i < n; ++i) {
    const glm::vec3& p = mesh.positions[firstVertex + i];
    welded[{p.x, p.y, p.z}] += sum[i];
  }
  for (std::size_t i = 0; i < n; ++i) {
    const glm::vec3& p = mesh.positions[firstVertex + i];
    const glm::dvec3 s = welded[{p.x, p.y, p.z}];
    const double length = glm::length(s);
    mesh.normals[firstVertex + i] = length > 0.0 ? glm::vec3(s / length) : glm::vec3(0.0f, 0.0f, 1.0f);
  }
}

// Every face's triangulation, in the part's coordinates: the shape's own location (an instance
// location, XCAFPrs ignores it for referred shapes) is taken out.
PartMesh collectTriangles(const TopoDS_Shape& shape, const TopTools_DataMapOfShapeInteger& faceStyle,
                          std::vector<glm::vec4> styles, const std::string& name) {
  PartMesh part;
  part.styles = std::move(styles);
  const TopLoc_Location toPart = shape.Location().Inverted();
  Mesh& mesh = part.mesh;
  std::vector<int> vertexStyle;
  for (TopExp_Explorer faces(shape, TopAbs_FACE); faces.More(); faces.Next()) {
    const TopoDS_Face& face = TopoDS::Face(faces.Current());
    ++part.faces;
    TopLoc_Location location;
    const Handle(Poly_Triangulation)& triangulation = BRep_Tool::Triangulation(face, location);
    if (triangulation.IsNull() || triangulation->NbTriangles() == 0 || triangulation->NbNodes() < 3) {
      ++part.unmeshed;
      continue;
    }
    const gp_Trsf trsf = (toPart * location).Transformation();
    const bool reversed = face.Orientation() == TopAbs_REVERSED;
    // A mirroring location turns the winding too.
    const bool flip = reversed != trsf.IsNegative();
    const Standard_Integer nodes = triangulation->NbNodes();
    if (mesh.positions.size() + static_cast<std::size_t>(nodes) > std::size_t{0xffffffffu})
      throw Error(name, "part too large (over 4 billion vertices)");
    const auto first = static_cast<std::uint32_t>(mesh.positions.size());
    const std::size_t firstIndex = mesh.indices.size();
    for (Standard_Integer i = 1; i <= nodes; ++i) {
      const gp_Pnt p = triangulation->Node(i).Transformed(trsf);
      mesh.positions.emplace_back(p.X(), p.Y(), p.Z());
    }
    for (Standard_Integer t = 1; t <= triangulation->NbTriangles(); ++t) {
      Standard_Integer a = 0, b = 0, c = 0;
      triangulation->Triangle(t).Get(a, b, c);
      if (a < 1 || b < 1 || c < 1 || a > nodes || b > nodes || c > nodes || a == b || b == c || a == c) continue;
      if (flip) std::swap(b, c);
      for (const Standard_Integer v : {a, b, c}) mesh.indices.push_back(first + static_cast<std::uint32_t>(v - 1));
    }
    mesh.normals.resize(mesh.positions.size());
    if (triangulation->HasNormals()) {
      for (Standard_Integer i = 1; i <= nodes; ++i) {
        gp_Dir n = triangulation->Normal(i).Transformed(trsf);
        if (reversed) n.Reverse();
        mesh.normals[first + static_cast<std::size_t>(i - 1)] = glm::vec3(n.X(), n.Y(), n.Z());
      }
    } else {
      smoothFaceNormals(mesh, first, firstIndex);
    }
    int style = -1;
    if (!faceStyle.IsEmpty()) faceStyle.Find(face, style);
    vertexStyle.resize(mesh.positions.size(), -1);
    std::fill(vertexStyle.begin() + first, vertexStyle.end(), style);
  }
  const bool anyStyled = std::any_of(vertexStyle.begin(), vertexStyle.end(), [](int s) { return s >= 0; });
  if (anyStyled) part.vertexStyle = std::move(vertexStyle);
  return part;
}

// The styles of a part's sub-shapes (solids, shells, faces) as a map face → style index; larger
// sub-shapes first so that a face's own style overrides its solid's.
TopTools_DataMapOfShapeInteger faceStyles(const Walker& walker, const TDF_Label& part, std::vector<glm::vec4>& styles) {
  TopTools_DataMapOfShapeInteger map;
  TDF_LabelSequence subs;
  if (!XCAFDoc_ShapeTool::GetSubShapes(part, subs)) return map;
  std::vector<std::pair<TopoDS_Shape, glm::vec4>> styled;
  for (Standard_Integer i = 1; i <= subs.Length(); ++i) {
    const auto color = walker.ownColor(subs.Value(i));
    TopoDS_Shape sub;
    if (color && XCAFDoc_ShapeTool::GetShape(subs.Value(i), sub) && !sub.IsNull()) styled.emplace_back(sub, *color);
  }
  std::stable_sort(styled.begin(), styled.end(),
                   [](const auto& a, const auto& b) { return a.first.ShapeType() < b.first.ShapeType(); });
  for (const auto& [sub, color] : styled) {
    const auto index = static_cast<int>(styles.size());
    styles.push_back(color);
    for (TopExp_Explorer faces(sub, TopAbs_FACE); faces.More(); faces.Next()) map.Bind(faces.Current(), index);
  }
  return map;
}

// The mesh and material colour of one instance of `part`. Faces with a style of their own become
// per-vertex colours (the rest of the part in the instance's colour, the material white) unless
// all faces share one style, which then is the material colour.
std::pair<std::shared_ptr<const Mesh>, glm::vec4> instanceLook(PartMesh& part, const glm::vec4& instanceColor) {
  if (!part.plain && part.vertexStyle.empty()) part.plain = std::make_shared<const Mesh>(part.mesh);
  if (part.vertexStyle.empty()) return {part.plain, instanceColor};
  const int firstStyle = part.vertexStyle.front();
  const bool uniform =
      std::all_of(part.vertexStyle.begin(), part.vertexStyle.end(), [&](int s) { return s == firstStyle; });
  if (uniform && firstStyle >= 0) {
    if (!part.plain) part.plain = std::make_shared<const Mesh>(part.mesh);
    return {part.plain, part.styles[static_cast<std::size_t>(firstStyle)]};
  }
  const bool all = std::none_of(part.vertexStyle.begin(), part.vertexStyle.end(), [](int s) { return s < 0; });
  // The colour baked into unstyled faces is part of what the mesh shares.
  const std::array<float, 4> key =
      all ? std::array<float, 4>{-1.0f, -1.0f, -1.0f, -1.0f}
          : std::array<float, 4>{instanceColor.r, instanceColor.g, instanceColor.b, instanceColor.a};
  std::shared_ptr<const Mesh>& mesh = part.shared[key];
  if (!mesh) {
    auto colored = std::make_shared<Mesh>(part.mesh);
    colored->colors.reserve(colored->positions.size());
    for (const int s : part.vertexStyle)
      colored->colors.push_back(s >= 0 ? part.styles[static_cast<std::size_t>(s)] : instanceColor);
    mesh = std::move(colored);
  }
  return {mesh, glm::vec4(1.0f)};
}

// ---- reading -------------------------------------------------------------------------------------

// The first failure Open CASCADE's parser recorded in the model (syntax, parameter counts and
// types), as a phrase; "" when none.
std::string firstParseFailure(const Handle(StepData_StepModel) & model) {
  auto phrase = [](std::string s) {
    for (const char* prefix : {"Undefined Parsing: ", "ERR StepFile : "})
      if (s.rfind(prefix, 0) == 0) s.erase(0, std::char_traits<char>::length(prefix));
    if (!s.empty()) s[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(s[0])));
    return cleanName(s);
  };
  if (const Handle(Interface_Check)& global = model->GlobalCheck(Standard_True);
      !global.IsNull() && global->HasFailed())
    return phrase(global->CFail(1));
  for (Standard_Integer i = 1; i <= model->NbEntities(); ++i) {
    const Handle(Interface_Check)& check = model->Check(i, Standard_True);
    if (check.IsNull() || !check->HasFailed()) continue;
    const Standard_Integer id = model->IdentLabel(model->Value(i));
    return (id > 0 ? "entity #" + std::to_string(id) + ": " : std::string()) + phrase(check->CFail(1));
  }
  return {};
}

// Geometry the transfer cannot survive or silently drops, found by a bug hunt: a vertex's
// CARTESIAN_POINT of fewer than 3 coordinates (a segmentation fault in the transfer), a point of
// none or more than 3, a DIRECTION of none, more than 3 or all-zero ratios (the faces on a zero
// one were dropped without a word). 2D points and directions are valid (parameter-space curves).
// (Open CASCADE's parser keeps the first 3 of a point written with 4, so n > 3 does not see it.)
std::string firstGeometryFault(const Handle(StepData_StepModel) & model) {
  const auto at = [&](const Handle(Standard_Transient) & entity) {
    const Standard_Integer id = model->IdentLabel(entity);
    return id > 0 ? "entity #" + std::to_string(id) + ": " : std::string();
  };
  for (Standard_Integer i = 1; i <= model->NbEntities(); ++i) {
    const Handle(Standard_Transient)& entity = model->Value(i);
    if (const Handle(StepGeom_CartesianPoint) point = Handle(StepGeom_CartesianPoint)::DownCast(entity);
        !point.IsNull()) {
      const Standard_Integer n = point->NbCoordinates();
      if (n < 1 || n > 3) return at(entity) + "a point of " + std::to_string(n) + " coordinates";
    } else if (const Handle(StepGeom_Direction) direction = Handle(StepGeom_Direction)::DownCast(entity);
               !direction.IsNull()) {
      const Standard_Integer n = direction->NbDirectionRatios();
      if (n < 1 || n > 3) return at(entity) + "a direction of " + std::to_string(n) + " ratios";
      bool zero = true;
      for (Standard_Integer k = 1; k <= n; ++k) zero = zero && direction->DirectionRatiosValue(k) == 0.0;
      if (zero) return at(entity) + "a direction of zero length";
    } else if (const Handle(StepShape_VertexPoint) vertex = Handle(StepShape_VertexPoint)::DownCast(entity);
               !vertex.IsNull()) {
      const Handle(StepGeom_CartesianPoint) at3 = Handle(StepGeom_CartesianPoint)::DownCast(vertex->VertexGeometry());
      if (!at3.IsNull() && at3->NbCoordinates() != 3)
        return at(entity) + "a vertex at a point of " + std::to_string(at3->NbCoordinates()) +
               " coordinates (expected 3)";
    }
  }
  return {};
}

// The faces of the file's shells (ADVANCED_FACE, FACE_SURFACE; an ORIENTED_FACE's face once):
// what the transfer should make.
std::size_t shellFaces(const Handle(Interface_InterfaceModel) & model) {
  std::set<const Standard_Transient*> faces;
  for (Standard_Integer i = 1; !model.IsNull() && i <= model->NbEntities(); ++i) {
    const Handle(StepShape_ConnectedFaceSet) shell = Handle(StepShape_ConnectedFaceSet)::DownCast(model->Value(i));
    if (shell.IsNull() || shell->CfsFaces().IsNull()) continue;
    for (Standard_Integer k = 1; k <= shell->NbCfsFaces(); ++k) {
      Handle(StepShape_Face) face = shell->CfsFacesValue(k);
      if (const Handle(StepShape_OrientedFace) oriented = Handle(StepShape_OrientedFace)::DownCast(face);
          !oriented.IsNull())
        face = oriented->FaceElement();
      if (!Handle(StepShape_FaceSurface)::DownCast(face).IsNull()) faces.insert(face.get());
    }
  }
  return faces.size();
}

// A read-only stream over bytes already in memory (std::istringstream would copy them).
class MemoryBuffer final : public std::streambuf {
 public:
  explicit MemoryBuffer(const std::string& bytes) {
    char* begin = const_cast<char*>(bytes.data());  // never written: no put area
    setg(begin, begin, begin + bytes.size());
  }
};

std::string readFile(const std::filesystem::path& path, const std::string& name) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(name, "cannot open file for reading");
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw Error(name, "read error");
  return bytes;
}

// Real numbers of magnitude 1e100 or more are infinite to Open CASCADE (Precision::Infinite() is
// 2e100) and no CAD model has them; in a B-spline's knots, Open CASCADE 7.6's shape healing
// loops forever on one (found by fuzzing). Such a file is refused: "" when there is none, else
// where the first one is; so is an entity id beyond 32 bits. Strings, comments, keywords and
// enumerations are skipped.
std::string firstHugeNumber(const std::string& text) {
  std::size_t line = 1;
  const std::size_t n = text.size();
  auto isDigit = [&](std::size_t i) { return i < n && std::isdigit(static_cast<unsigned char>(text[i])) != 0; };
  auto isWord = [&](std::size_t i) {
    return i < n && (std::isalnum(static_cast<unsigned char>(text[i])) != 0 || text[i] == '_');
  };
  for (std::size_t i = 0; i < n;) {
    const char c = text[i];
    if (c == '\n') {
      ++line;
      ++i;
    } else if (c == '\'' || c == '"') {  // string ('' is a quote inside it) or binary literal
      for (++i; i < n; ++i) {
        if (text[i] == '\n') ++line;
        if (text[i] == c) {
          if (c == '\'' && i + 1 < n && text[i + 1] == '\'') {
            ++i;
            continue;
          }
          break;
        }
      }
      ++i;
    } else if (c == '/' && i + 1 < n && text[i + 1] == '*') {
      const std::size_t end = text.find("*/", i + 2);
      const std::size_t stop = end == std::string::npos ? n : end + 2;
      line += static_cast<std::size_t>(std::count(text.begin() + static_cast<std::ptrdiff_t>(i),
                                                  text.begin() + static_cast<std::ptrdiff_t>(stop), '\n'));
      i = stop;
    } else if (c == '#' && isDigit(i + 1)) {
      // An entity id: Open CASCADE keeps them in a 32-bit int, and one beyond (#2147483648)
      // made its model dereference a null entity (found by fuzzing).
      const std::size_t start = i;
      std::uint64_t id = 0;
      for (++i; isDigit(i); ++i)
        id = std::min<std::uint64_t>(id * 10 + static_cast<std::uint64_t>(text[i] - '0'), 1ULL << 40);
      if (id > static_cast<std::uint64_t>(std::numeric_limits<std::int32_t>::max()))
        return "line " + std::to_string(line) + ": entity id " +
               text.substr(start, std::min<std::size_t>(i - start, 24)) + " out of range";
      for (; isWord(i);) ++i;
    } else if (c == '#' || std::isalpha(static_cast<unsigned char>(c)) != 0 || c == '_') {
      for (++i; isWord(i);) ++i;
    } else if (c == '.' && i + 1 < n && std::isalpha(static_cast<unsigned char>(text[i + 1])) != 0) {
      for (++i; isWord(i);) ++i;  // enumeration .NAME.
      if (i < n && text[i] == '.') ++i;
    } else if (isDigit(i) || ((c == '+' || c == '-') && isDigit(i + 1))) {
      const std::size_t start = i;
      if (c == '+' || c == '-') ++i;
      while (isDigit(i)) ++i;
      if (i < n && text[i] == '.')
        for (++i; isDigit(i);) ++i;
      if (i < n && (text[i] == 'E' || text[i] == 'e')) {
        std::size_t j = i + 1;
        if (j < n && (text[j] == '+' || text[j] == '-')) ++j;
        if (isDigit(j)) {
          for (i = j; isDigit(i);) ++i;
        }
      }
      const std::string token = text.substr(start, i - start);
      const double value = std::strtod(token.c_str(), nullptr);
      if (!(std::fabs(value) < 1e100)) return "line " + std::to_string(line) + ": number " + token + " out of range";
    } else {
      ++i;
    }
  }
  return {};
}

// Parses the file into the reader's session. Open CASCADE's own ReadFile attaches the model to
// the session at once, which runs semantic checks that dereference whatever a damaged file left
// empty (a segmentation fault, found by fuzzing): so the parser is called directly, and a model
// it found fault with is refused before the session sees it.
void parse(STEPCAFControl_Reader& reader, const std::filesystem::path& path, const std::string* contents,
           const std::string& name, const QuietMessenger& messages) {
  const Handle(XSControl_WorkSession) session = reader.ChangeReader().WS();
  const Handle(StepData_Protocol) protocol = Handle(StepData_Protocol)::DownCast(session->Protocol());
  if (protocol.IsNull()) throw Error(name, "Open CASCADE's STEP reader is not available");
  std::string bytes;
  if (contents == nullptr) {
    bytes = readFile(path, name);
    contents = &bytes;
  }
  if (const std::string huge = firstHugeNumber(*contents); !huge.empty())
    throw Error(name, "not a readable STEP file (" + huge + ")");
  const Handle(StepData_StepModel) model = new StepData_StepModel;
  MemoryBuffer buffer(*contents);
  std::istream stream(&buffer);
  const Standard_Integer status = StepFile_Read(path.filename().string().c_str(), &stream, model, protocol);
  bytes.clear();
  bytes.shrink_to_fit();
  std::string why = status != 0 ? messages.failure() : std::string();
  if (why.empty()) why = firstParseFailure(model);
  if (why.empty() && status == 0) why = firstGeometryFault(model);
  // The parser catches its own Standard_OutOfMemory and reports it as a failure of the file.
  if (why.find("Standard_OutOfMemory") != std::string::npos) throw std::bad_alloc();
  if (status != 0 || !why.empty())
    throw Error(name, "not a readable STEP file" + (why.empty() ? std::string() : " (" + why + ")"));
  session->SetModel(model);
  session->InitTransferReader(4);  // what XSControl_Reader::ReadFile does after reading
}

std::vector<Object> read(const std::filesystem::path& path, const std::string* contents, const std::string& stem,
                         const std::string& name, const LoadProgress& progress, const QuietMessenger& messages,
                         std::vector<std::string>* notes) {
  progress.step(0.0);
  STEPCAFControl_Reader reader;
  reader.SetColorMode(Standard_True);
  reader.SetNameMode(Standard_True);
  reader.SetLayerMode(Standard_False);
  reader.SetPropsMode(Standard_False);
  reader.SetGDTMode(Standard_False);
  reader.SetMatMode(Standard_False);
  reader.SetViewMode(Standard_False);
  parse(reader, path, contents, name, messages);
  progress.step(0.3);
  if (reader.NbRootsForTransfer() <= 0) throw Error(name, "no shapes (the file has no product with a shape)");
  const std::size_t defined = shellFaces(reader.ChangeReader().Model());

  Handle(TDocStd_Document) doc = new TDocStd_Document("MDTV-XCAF");
  // Keep the file's length unit: Open CASCADE would convert to millimetres.
  if (const double unit = fileLengthUnitInMetres(reader.ChangeReader().Model()); unit > 0.0)
    XCAFDoc_DocumentTool::SetLengthUnit(doc, unit);
  {
    Handle(OcctProgress) transfer = new OcctProgress(progress.part(0.3, 0.55));
    const bool ok = reader.Transfer(doc, transfer->Start());
    if (transfer->cancelled()) throw LoadCancelled();
    if (!ok) {
      const std::string why = messages.failure();
      throw Error(name, "no shapes could be read from the file" + (why.empty() ? std::string() : " (" + why + ")"));
    }
  }
  progress.step(0.55);

  Walker walker(doc, stem, name);
  TDF_LabelSequence roots;
  walker.shapes()->GetFreeShapes(roots);
  if (roots.Length() == 0) throw Error(name, "no shapes (the file has no product with a shape)");
  std::vector<Instance> instances = walker.walk(roots);

  // One linear tolerance for the whole model, so parts meet without cracks of different sizes.
  Bnd_Box box;
  for (Standard_Integer i = 1; i <= roots.Length(); ++i) {
    TopoDS_Shape shape;
    if (XCAFDoc_ShapeTool::GetShape(roots.Value(i), shape) && !shape.IsNull()) BRepBndLib::Add(shape, box);
  }
  if (box.IsVoid()) throw Error(name, "no surfaces (the file's shapes are empty)");
  const double diagonal = std::sqrt(box.SquareExtent());
  if (!std::isfinite(diagonal) || diagonal <= 0.0) throw Error(name, "no surfaces (the file's shapes have no extent)");
  IMeshTools_Parameters parameters;
  parameters.Deflection = kStepRelativeDeflection * diagonal;
  parameters.Angle = kStepAngularDeflection;
  parameters.Relative = Standard_False;
  parameters.InParallel = Standard_True;

  // Parts in order of first use; each meshed once.
  std::map<std::string, std::size_t> partIndex;
  std::vector<TDF_Label> partLabels;
  for (const Instance& instance : instances)
    if (partIndex.emplace(entry(instance.part), partLabels.size()).second) partLabels.push_back(instance.part);
  std::vector<PartMesh> parts;
  parts.reserve(partLabels.size());
  std::size_t faces = 0, unmeshed = 0;
  for (std::size_t i = 0; i < partLabels.size(); ++i) {
    const double from = 0.55 + 0.45 * static_cast<double>(i) / static_cast<double>(partLabels.size());
    const double to = 0.55 + 0.45 * static_cast<double>(i + 1) / static_cast<double>(partLabels.size());
    TopoDS_Shape shape;
    XCAFDoc_ShapeTool::GetShape(partLabels[i], shape);
    if (!shape.IsNull() && TopExp_Explorer(shape, TopAbs_FACE).More()) {
      Handle(OcctProgress) meshing = new OcctProgress(progress.part(from, to));
      BRepMesh_IncrementalMesh mesher(shape, parameters, meshing->Start());
      if (meshing->cancelled()) throw LoadCancelled();
    }
    std::vector<glm::vec4> styles;
    const TopTools_DataMapOfShapeInteger styleOfFace = faceStyles(walker, partLabels[i], styles);
    parts.push_back(shape.IsNull() ? PartMesh{} : collectTriangles(shape, styleOfFace, std::move(styles), name));
    faces += parts.back().faces;
    unmeshed += parts.back().unmeshed;
    progress.step(to);
  }
  if (faces == 0) throw Error(name, "no surfaces (the file's shapes have no faces)");
  // Open CASCADE drops a face whose geometry it cannot use (a bad B-spline, parallel axes, a
  // degenerate edge) without failing the transfer; shape healing may also split a face in two, so
  // this sees a loss only where it is larger than the splits.
  if (notes != nullptr && faces < defined)
    notes->push_back(name + ": " + std::to_string(defined - faces) + " of the file's " + std::to_string(defined) +
                     " faces could not be read (damaged geometry; not drawn)");
  if (notes != nullptr && unmeshed > 0)
    notes->push_back(name + ": " + std::to_string(unmeshed) + " of " + std::to_string(faces) +
                     " faces could not be meshed (not drawn)");

  const bool palette = !walker.fileHasColors();
  std::vector<Object> objects;
  for (const Instance& instance : instances) {
    PartMesh& part = parts[partIndex.at(entry(instance.part))];
    if (part.mesh.indices.empty()) continue;  // wireframe or points only, or meshing failed
    const glm::vec4 color = instance.color ? *instance.color
                            : palette      ? kPalette[objects.size() % kPalette.size()]
                                           : kUncoloured;
    Object object;
    object.name = instance.name;
    std::tie(object.mesh, object.material.color) = instanceLook(part, color);
    object.transform = toGlm(instance.location.Transformation());
    object.visible = instance.visible;
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r)
        if (!std::isfinite(object.transform[c][r])) throw Error(name, "non-finite placement of '" + object.name + "'");
    objects.push_back(std::move(object));
  }
  if (objects.empty()) throw Error(name, "no triangles (no face of the file could be meshed)");

  // Names identify parts in the UI and scene files, so keep them unique.
  std::set<std::string> used;
  for (Object& o : objects) {
    if (used.count(o.name) != 0) {
      int n = 2;
      while (used.count(o.name + " #" + std::to_string(n)) != 0) ++n;
      o.name += " #" + std::to_string(n);
    }
    used.insert(o.name);
  }
  return objects;
}

// The whole read in this process, one at a time.
std::vector<Object> readHere(const std::filesystem::path& path, const std::string* contents, const std::string& stem,
                             const std::string& name, const LoadProgress& progress, std::vector<std::string>* notes) {
  const std::lock_guard<std::mutex> lock(occtMutex());
  const QuietMessenger messages;
  const SessionLengthUnit millimetres;
  try {
    return read(path, contents, stem, name, progress, messages, notes);
  } catch (const Standard_OutOfMemory&) {
    throw std::bad_alloc();  // the memory limit's message (child_process.hpp)
  } catch (const Standard_Failure& failure) {
    const char* what = failure.GetMessageString();
    throw Error(name, std::string("Open CASCADE failed (") + failure.DynamicType()->Name() +
                          (what != nullptr && *what != '\0' ? std::string(": ") + what : std::string()) + ")");
  }
}

}  // namespace

// Open CASCADE 7.6 crashes on some damaged files that no check above foresees (each check there
// was a crash or a hang found by a bug hunt or fuzzing): the read runs in a child process
// (child_process.hpp), whose parts come back as bytes — read once, not twice.
std::vector<Object> readStep(const std::filesystem::path& path, const std::string* contents, const std::string& stem,
                             const std::string& name, const LoadProgress& progress, std::vector<std::string>* notes) {
  // The parse reports nothing until it is done: one more second of the time limit per MiB.
  std::error_code error;
  const std::uintmax_t fileBytes = contents != nullptr ? contents->size() : std::filesystem::file_size(path, error);
  const ChildLibrary occt{"step", "Open CASCADE",
                          error ? 0 : static_cast<int>(std::min<std::uintmax_t>(fileBytes >> 20, 86400))};
  if (const std::optional<std::string> bytes = runInChild(name, occt, progress, [&](const LoadProgress& childProgress) {
        std::vector<std::string> childNotes;
        std::vector<Object> objects = readHere(path, contents, stem, name, childProgress, &childNotes);
        return packObjects(objects, childNotes);
      }))
    return unpackObjects(*bytes, notes);
  try {
    return readHere(path, contents, stem, name, progress, notes);
  } catch (const std::bad_alloc&) {
    throw Error(name, "cannot read step: Open CASCADE ran out of memory");
  }
}

}  // namespace mfr::io
