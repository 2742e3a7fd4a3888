// Scalar volume files: VTK's image readers (.vti, legacy .vtk STRUCTURED_POINTS, MetaImage, NRRD)
// and CGAL's ImageIO (INRIMAGE, also gzip-compressed). Both check what the header declares before
// the samples are read, so a huge or truncated file fails early, and whatever goes wrong leaves
// as one mfr::Error("<path>", "<one-line reason>").
#include "volume_loader.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <mutex>
#include <new>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <unistd.h>
#include <zlib.h>

#include <CGAL/ImageIO.h>
#include <CGAL/ImageIO/inr.h>
#include <glm/gtc/matrix_transform.hpp>
#include <vtkAlgorithm.h>
#include <vtkCallbackCommand.h>
#include <vtkCellData.h>
#include <vtkCommand.h>
#include <vtkDataArray.h>
#include <vtkDataArraySelection.h>
#include <vtkDataObject.h>
#include <vtkDataSetAttributes.h>
#include <vtkFieldData.h>
#include <vtkImageData.h>
#include <vtkInformation.h>
#include <vtkMatrix3x3.h>
#include <vtkMetaImageReader.h>
#include <vtkNew.h>
#include <vtkNrrdReader.h>
#include <vtkObjectFactory.h>
#include <vtkPointData.h>
#include <vtkSmartPointer.h>
#include <vtkStreamingDemandDrivenPipeline.h>
#include <vtkStructuredPointsReader.h>
#include <vtkXMLImageDataReader.h>

#include "mfr/error.hpp"
#include "mfr/host_memory.hpp"
#include "mfr/scene/color_map.hpp"
#include "file_checks.hpp"
#include "invesalius_loader.hpp"
#include "openvdb_loader.hpp"
#include "number_text.hpp"
#include "vtk_loader.hpp"

namespace mfr::io {
namespace {

namespace fs = std::filesystem;

// VolumeGrid::validate's limits; checked before any sample is read.
constexpr std::int64_t kMaxPointsPerAxis = VolumeGrid::kMaxPointsPerAxis;

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

struct Extension {
  const char* ext;
  VolumeFormat format;
};

constexpr std::array<Extension, 10> kExtensions{{{".inr.gz", VolumeFormat::Inrimage},
                                                 {".nrrd", VolumeFormat::Nrrd},
                                                 {".nhdr", VolumeFormat::Nrrd},
                                                 {".vti", VolumeFormat::Vti},
                                                 {".vtk", VolumeFormat::LegacyVtk},
                                                 {".mhd", VolumeFormat::MetaImage},
                                                 {".mha", VolumeFormat::MetaImage},
                                                 {".inr", VolumeFormat::Inrimage},
                                                 {".inv3", VolumeFormat::Invesalius},
                                                 {".vdb", VolumeFormat::OpenVdb}}};

std::optional<VolumeFormat> formatByName(const fs::path& path) {
  const std::string name = lower(path.filename().string());
  for (const Extension& e : kExtensions) {
    const std::string ext = e.ext;
    if (name.size() > ext.size() && endsWith(name, ext)) return e.format;
  }
  return std::nullopt;
}

// The DATASET type of a legacy .vtk file (upper case), or "" when its first lines do not say.
// Layout: "# vtk DataFile Version x.y", a title line, ASCII | BINARY, "DATASET <type>".
std::string legacyDataset(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return {};
  std::string line;
  for (int i = 0; i < 8 && std::getline(in, line); ++i) {
    if (line.size() > 1024) line.resize(1024);
    std::string upper = line;
    std::transform(upper.begin(), upper.end(), upper.begin(),
                   [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
    if (i == 0 && upper.rfind("# VTK DATAFILE", 0) != 0) return {};
    if (i < 2) continue;  // the title may say anything
    const std::size_t at = upper.find("DATASET");
    if (at == std::string::npos) continue;
    std::size_t p = at + 7;
    while (p < upper.size() && std::isspace(static_cast<unsigned char>(upper[p]))) ++p;
    std::size_t q = p;
    while (q < upper.size() && !std::isspace(static_cast<unsigned char>(upper[q]))) ++q;
    return upper.substr(p, q - p);
  }
  return {};
}

std::string dimsText(const std::array<std::int64_t, 3>& d) {
  return std::to_string(d[0]) + "x" + std::to_string(d[1]) + "x" + std::to_string(d[2]);
}

std::size_t pointCount(const glm::ivec3& dims) {
  return static_cast<std::size_t>(dims.x) * static_cast<std::size_t>(dims.y) * static_cast<std::size_t>(dims.z);
}

// ---------------------------------------------------------------------------------------------
// VTK

// Formats whose fields have names in the file, so that one can be chosen (LoadOptions::field).
bool hasNamedFields(VolumeFormat format) {
  return format == VolumeFormat::Vti || format == VolumeFormat::LegacyVtk || format == VolumeFormat::OpenVdb;
}

// MetaImage and NRRD name no arrays, but a sample may have several components (a vector, a
// colour): that one array is then called this, so that a component or the magnitude can be chosen
// ("components:1", "components:magnitude") as a .vti array's can.
constexpr const char* kComponentsField = "components";
bool hasComponentFields(VolumeFormat format) {
  return format == VolumeFormat::MetaImage || format == VolumeFormat::Nrrd;
}

const char* formatLabel(VolumeFormat format) {
  switch (format) {
    case VolumeFormat::Vti:
      return "VTK image data (.vti)";
    case VolumeFormat::LegacyVtk:
      return "legacy VTK structured points";
    case VolumeFormat::MetaImage:
      return "MetaImage";
    case VolumeFormat::Nrrd:
      return "NRRD";
    case VolumeFormat::Inrimage:
      return "INRIMAGE";
    case VolumeFormat::Invesalius:
      return "InVesalius project";
    case VolumeFormat::OpenVdb:
      return "OpenVDB";
  }
  return "volume";
}

// What the NRRD header says that vtkNrrdReader (VTK 9.1) does not read: see checkNrrdHeader.
struct NrrdOrientation {
  std::optional<std::array<glm::dvec3, 3>> directions;  // of the three spatial axes, in order
  // The grid as the header gives it, for a file of 3 axes (components 1) or of 4 axes with the
  // components first: what NrrdReader puts in place of vtkNrrdReader's reading.
  struct Layout {
    int components = 1;
    std::array<int, 3> sizes{};
    std::array<double, 3> spacing{1.0, 1.0, 1.0};  // as vtkNrrdReader reads it (lengths of directions)
  };
  std::optional<Layout> layout;
};

// NRRD marks which axis holds a vector's components only in "kinds", which vtkNrrdReader ignores:
// it guesses components from a first axis of 9 or fewer samples (or a first spacing of 0), so an
// ordinary 8×8×8 scalar grid came out as an 8-component 2D image and was refused; and a "space"
// field before "sizes" (teem's, ITK's and Slicer's order) makes it cut "sizes" to three values,
// so a 4-axis vector file came out as a flat image. This reader reads the header as vtkNrrdReader
// does, then sets the components and the grid as checkNrrdHeader read them.
class NrrdReader : public vtkNrrdReader {
 public:
  static NrrdReader* New();
  void setLayout(const NrrdOrientation::Layout& layout) { layout_ = layout; }
  vtkTypeMacro(NrrdReader, vtkNrrdReader)

 protected:
  NrrdReader() = default;
  ~NrrdReader() override = default;
  int ReadHeader(vtkCharArray* headerBuffer) override {
    if (vtkNrrdReader::ReadHeader(headerBuffer) == 0) return 0;
    if (layout_) {
      NumberOfScalarComponents = layout_->components;
      FileDimensionality = 3;
      for (std::size_t a = 0; a < 3; ++a) {
        DataExtent[2 * a] = 0;
        DataExtent[2 * a + 1] = layout_->sizes[a] - 1;
        DataSpacing[a] = layout_->spacing[a];
      }
    }
    return 1;
  }

 private:
  std::optional<NrrdOrientation::Layout> layout_;
};
vtkStandardNewMacro(NrrdReader)

vtkSmartPointer<vtkAlgorithm> makeReader(VolumeFormat format, const std::string& file, const NrrdOrientation& nrrd) {
  switch (format) {
    case VolumeFormat::Vti: {
      auto r = vtkSmartPointer<vtkXMLImageDataReader>::New();
      r->SetFileName(file.c_str());
      return r;
    }
    case VolumeFormat::LegacyVtk: {
      auto r = vtkSmartPointer<vtkStructuredPointsReader>::New();
      r->SetFileName(file.c_str());
      r->ReadAllScalarsOn();
      return r;
    }
    case VolumeFormat::MetaImage: {
      auto r = vtkSmartPointer<vtkMetaImageReader>::New();
      r->SetFileName(file.c_str());
      return r;
    }
    case VolumeFormat::Nrrd: {
      auto r = vtkSmartPointer<NrrdReader>::New();
      r->SetFileName(file.c_str());
      if (nrrd.layout) r->setLayout(*nrrd.layout);
      return r;
    }
    case VolumeFormat::Inrimage:
    case VolumeFormat::Invesalius:
    case VolumeFormat::OpenVdb:
      break;
  }
  return nullptr;
}

// Passes VTK's progress on (never backwards: readers restart it per array) and aborts the reader
// when the load is cancelled.
struct ProgressRelay {
  const LoadProgress* progress = nullptr;
  bool cancelled = false;
  double last = 0.0;

  static void callback(vtkObject* caller, unsigned long, void* clientData, void*) {
    auto* self = static_cast<ProgressRelay*>(clientData);
    auto* algorithm = vtkAlgorithm::SafeDownCast(caller);
    if (self == nullptr || algorithm == nullptr || self->cancelled) return;
    self->last = std::max(self->last, std::clamp(algorithm->GetProgress(), 0.0, 1.0));
    if (!self->progress->tryStep(0.1 + 0.6 * self->last)) {
      self->cancelled = true;
      algorithm->AbortExecuteOn();
    }
  }
};

// MetaIO (inside vtkMetaImageReader) reports problems such as a missing or short data file on
// std::cerr, and the reader returns the image anyway. While a MetaImage file is read, std::cerr
// goes into a string (one read at a time), which then decides and explains the failure.
class CerrCapture {
 public:
  CerrCapture() : lock_(mutex()), previous_(std::cerr.rdbuf(buffer_.rdbuf())) {}
  ~CerrCapture() { std::cerr.rdbuf(previous_); }
  CerrCapture(const CerrCapture&) = delete;
  CerrCapture& operator=(const CerrCapture&) = delete;

  [[nodiscard]] std::string text() const { return buffer_.str(); }

 private:
  static std::mutex& mutex() {
    static std::mutex m;
    return m;
  }
  std::unique_lock<std::mutex> lock_;
  std::ostringstream buffer_;
  std::streambuf* previous_;
};

// vtkNrrdReader trusts its header: a header whose last line has no newline makes it loop forever
// (reading one data file name after another until memory runs out), an empty "data file" or
// spacings without sizes index an empty vector, a file pattern goes to snprintf as the format,
// and ASCII data is read without checking the stream (a short file gives garbage). This looks at
// the header as vtkNrrdReader will see it — the first 4 MiB up to a NUL byte, cut after the first
// blank line — and refuses those cases before the reader runs.
//
// It also returns the orientation, which vtkNrrdReader (VTK 9.1) reads only in part: of "space
// directions" it keeps each vector's length as the spacing and drops its direction. Axis a of the
// grid steps by directions[a] in the file's space from "space origin" (the NRRD format's definition).
// And it says which axis holds components and how large the grid is (NrrdReader, above).

// The value of "space directions": one entry per axis, "(x,y,z)" (spaces allowed inside) or
// "none" (a non-spatial axis, nothing here). Throws mfr::Error(name, …) for anything else.
std::vector<std::optional<glm::dvec3>> nrrdDirections(const std::string& text, const std::string& name) {
  std::vector<std::optional<glm::dvec3>> out;
  const auto fail = [&] {
    throw Error(name, "NRRD 'space directions' must be vectors (x,y,z) or none, one per axis (got '" + text + "')");
  };
  std::size_t p = 0;
  while (true) {
    p = text.find_first_not_of(" \t", p);
    if (p == std::string::npos) break;
    if (text.compare(p, 4, "none") == 0) {
      out.emplace_back(std::nullopt);
      p += 4;
      continue;
    }
    const std::size_t close = text.find(')', p);
    if (text[p] != '(' || close == std::string::npos) fail();
    std::istringstream in(text.substr(p + 1, close - p - 1));
    glm::dvec3 v;
    char c1 = 0, c2 = 0;
    if (!(in >> v.x >> c1 >> v.y >> c2 >> v.z) || c1 != ',' || c2 != ',' || !(in >> std::ws).eof()) fail();
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) fail();
    out.emplace_back(v);
    p = close + 1;
  }
  return out;
}

// The most components an array of a volume file may declare: a 3×3 tensor has 9; a corrupt count
// (2^31) made VTK's readers allocate without bound.
constexpr long long kMaxComponents = 4096;

// vtkStructuredPointsReader allocates a FIELD array of the size its header line declares before
// reading it ("names 1 2000000000 string": killed at 12 GB; "FIELD FieldData 2147483647": no end;
// found by fuzzing). Every line that looks like a FIELD header or a FIELD array's header (name,
// components, tuples, type) is checked against the file's size (a value takes at least a byte, a
// bit an eighth).
// Lines longer than a header are data and skipped.
void checkLegacyVtkFieldCounts(const fs::path& path, const std::string& name) {
  std::error_code ec;
  const auto size = static_cast<long long>(fs::file_size(path, ec));
  if (ec) return;  // the reader says what is wrong
  std::ifstream in(path, std::ios::binary);
  std::string chunk(1 << 16, '\0'), line;
  bool longLine = false;
  static const std::set<std::string> kTypes = {
      "bit",  "unsigned_char", "char",   "unsigned_short", "short",     "unsigned_int", "int",          "unsigned_long",
      "long", "float",         "double", "string",         "vtkIdType", "vtktypeint64", "vtktypeuint64"};
  const auto check = [&](const std::string& text) {
    std::istringstream words(text);
    std::vector<std::string> w;
    for (std::string word; words >> word && w.size() < 5;) w.push_back(word);
    const auto count = [](const std::string& t) -> long long {
      if (t.empty() || t.size() > 19 ||
          !std::all_of(t.begin(), t.end(), [](unsigned char c) { return std::isdigit(c); }))
        return -1;
      return std::stoll(t);
    };
    if (w.size() == 3 && w[0] == "FIELD") {
      const long long arrays = count(w[2]);
      if (arrays < 0 || arrays > 4096 || arrays > size)
        throw Error(name, "FIELD '" + w[1] + "' declares " + w[2].substr(0, 24) + " arrays (at most 4096)");
    } else if (w.size() == 4 && kTypes.count(w[3]) > 0) {
      const long long components = count(w[1]), tuples = count(w[2]);
      const long long room = w[3] == "bit" ? 8 * size : size;  // a bit array packs eight values a byte
      if (components < 1 || components > kMaxComponents || tuples < 0 || tuples > room || components * tuples > room)
        throw Error(name, "array '" + w[0].substr(0, 64) + "' declares " + w[1].substr(0, 24) + " components × " +
                              w[2].substr(0, 24) + " values, more than the file's " + std::to_string(size) + " bytes");
    }
  };
  while (in) {
    in.read(chunk.data(), static_cast<std::streamsize>(chunk.size()));
    for (std::size_t i = 0; i < static_cast<std::size_t>(in.gcount()); ++i) {
      const char c = chunk[i];
      if (c == '\n') {
        if (!longLine) check(line);
        line.clear();
        longLine = false;
      } else if (!longLine) {
        line += c;
        longLine = line.size() > 256;
      }
    }
  }
  if (!longLine) check(line);
}

// vtkMetaImageReader loops forever on a negative or huge NDims and reads zeros for 0 channels:
// the header's keys are checked first (up to ElementDataFile, its last key). Returns the grid's
// axis directions from TransformMatrix (or its synonyms Rotation, Orientation), which VTK 9.1's
// reader never sets: a rotated image loaded unrotated without a word (a bug hunt). As ITK reads
// it, the matrix's consecutive triples are the directions of the x, y and z axes.
std::optional<glm::dmat3> checkMetaImageHeader(const fs::path& path, const std::string& name) {
  std::optional<glm::dmat3> direction;
  std::ifstream in(path, std::ios::binary);
  std::string line;
  std::uint64_t channels = 1, elementBytes = 8;
  double points = 0;  // DimSize's product (larger grids are refused later, by their dimensions)
  for (int lines = 0; lines < 4096 && std::getline(in, line); ++lines) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::size_t eq = line.find('=');
    if (eq == std::string::npos) continue;
    std::string key = line.substr(0, eq), value = line.substr(eq + 1);
    const auto trim = [](std::string& t) {
      t.erase(0, t.find_first_not_of(" \t"));
      t.erase(t.find_last_not_of(" \t") + 1);
    };
    trim(key);
    trim(value);
    const auto integer = [&]() -> std::optional<long> {
      char* end = nullptr;
      errno = 0;
      const long v = std::strtol(value.c_str(), &end, 10);
      if (value.empty() || errno != 0 || end == nullptr || *end != '\0') return std::nullopt;
      return v;
    };
    if (key == "NDims" && integer() != 3L)
      throw Error(name, "MetaImage NDims = " + value.substr(0, 32) + ": only 3-dimensional images are volumes");
    if (key == "ElementNumberOfChannels" && !(integer().value_or(0) >= 1))
      throw Error(name, "MetaImage ElementNumberOfChannels = " + value.substr(0, 32) + ": needs a positive count");
    // 2^31 − 1 channels of a 2×2×2 image: VTK allocated 16 GiB before it found 130 bytes of file,
    // past MFR_MEMORY_LIMIT_MIB (a bug hunt). NRRD and VTI refuse the same bound.
    if (key == "ElementNumberOfChannels" && integer().value_or(0) > kMaxComponents)
      throw Error(name, "MetaImage ElementNumberOfChannels = " + value.substr(0, 32) + ": at most " +
                            std::to_string(kMaxComponents) + " components");
    if (key == "ElementNumberOfChannels") channels = static_cast<std::uint64_t>(integer().value_or(1));
    if (key == "ElementType") {
      elementBytes = value.find("CHAR") != std::string::npos                             ? 1
                     : value.find("SHORT") != std::string::npos                          ? 2
                     : value == "MET_INT" || value == "MET_UINT" || value == "MET_FLOAT" ? 4
                                                                                         : 8;
    }
    if (key == "DimSize") {
      std::istringstream sizes(value);
      points = 1;
      for (double d = 0; sizes >> d;) {
        // VTK reads each size as an int: 4294967312 came out as 2147483648 in the message.
        if (d > VolumeGrid::kMaxPointsPerAxis)
          throw Error(name, "MetaImage DimSize = " + value.substr(0, 64) + ": larger than " +
                                std::to_string(VolumeGrid::kMaxPointsPerAxis) + " points per axis");
        points *= d > 0 ? d : 0;
      }
    }
    if (key == "TransformMatrix" || key == "Rotation" || key == "Orientation") {
      std::istringstream numbers(value);
      std::vector<double> m;
      for (std::string word; numbers >> word && m.size() < 10;) {
        char* end = nullptr;
        const double v = std::strtod(word.c_str(), &end);
        if (end == word.c_str() || *end != '\0' || !std::isfinite(v))
          throw Error(name, "MetaImage " + key + " = " + value.substr(0, 64) + ": expected 9 finite numbers");
        m.push_back(v);
      }
      if (m.size() != 9) throw Error(name, "MetaImage " + key + " = " + value.substr(0, 64) + ": expected 9 numbers");
      glm::dmat3 d;
      for (int a = 0; a < 3; ++a) d[a] = glm::dvec3(m[3 * a], m[3 * a + 1], m[3 * a + 2]);
      // Relative to the axes' lengths: a flat grid has no inside to draw.
      const double scale = glm::length(d[0]) * glm::length(d[1]) * glm::length(d[2]);
      if (!(std::abs(glm::determinant(d)) > 1e-9 * scale))
        throw Error(name, "MetaImage " + key + " = " + value.substr(0, 64) +
                              ": the axes are not independent (the grid would be flat)");
      direction = d;
    }
    if (key == "ElementDataFile") {
      // What VTK allocates for the samples, and the grid's floats, asked for before it does.
      if (points > 0 && points <= static_cast<double>(VolumeGrid::kMaxPoints))
        requireHostMemory(name, "its samples (" + std::to_string(channels) + " channels)",
                          static_cast<std::uint64_t>(points) * (channels * elementBytes + sizeof(float)));
      return direction;
    }
  }
  return direction;
}

NrrdOrientation checkNrrdHeader(const fs::path& path, const std::string& name) {
  NrrdOrientation orientation;
  std::ifstream in(path, std::ios::binary);
  std::string text(0x400000 - 1, '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<std::size_t>(in.gcount()));
  text.resize(std::min(text.find('\0'), text.size()));
  for (std::size_t p = text.find('\n', 1); p != std::string::npos; p = text.find('\n', p + 1)) {
    if (p + 1 < text.size() && text[p + 1] == '\n') {
      text.resize(p + 2);
      break;
    }
    if (p + 2 < text.size() && text[p + 1] == '\r' && text[p + 2] == '\n') {
      text.resize(p + 3);
      break;
    }
  }
  if (text.rfind("NRRD", 0) != 0) throw Error(name, "not a NRRD file (it does not start with NRRD)");
  if (text.back() != '\n') throw Error(name, "NRRD header does not end (no blank line after it, or a NUL byte in it)");
  std::istringstream lines(text);
  std::string line;
  std::getline(lines, line);  // the magic
  long dimension = 0;
  std::vector<long> sizes;
  std::vector<double> spacings;
  std::vector<std::string> kinds;
  std::vector<std::optional<glm::dvec3>> directions;
  std::string type, encoding = "raw", dataFile;
  long byteSkip = 0;
  while (std::getline(lines, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) break;
    const std::size_t colon = line.find(": ");
    if (line[0] == '#' || colon == std::string::npos) continue;
    const std::string field = line.substr(0, colon);
    std::istringstream value(line.substr(colon + 2));
    std::vector<std::string> tokens;
    for (std::string t; value >> t;) tokens.push_back(t);
    if (field == "dimension") {
      // The array's; "space" and "space dimension" are the space's (a 4D vector file has
      // "dimension: 4" and "space: LPS").
      dimension = tokens.empty() ? 0 : std::atol(tokens[0].c_str());
    } else if (field == "sizes") {
      if (dimension < 1 || dimension > 16) throw Error(name, "NRRD 'sizes' without a valid 'dimension' before it");
      if (static_cast<long>(tokens.size()) != dimension)
        throw Error(name, "NRRD 'sizes' has " + std::to_string(tokens.size()) + " values for dimension " +
                              std::to_string(dimension));
      sizes.clear();
      for (const std::string& t : tokens) {
        if (t.find_first_not_of("0123456789") != std::string::npos || std::atol(t.c_str()) < 1)
          throw Error(name, "NRRD 'sizes' must be positive integers (got '" + t + "')");
        sizes.push_back(std::atol(t.c_str()));
      }
    } else if (field == "spacings") {
      spacings.clear();
      for (const std::string& t : tokens) spacings.push_back(std::atof(t.c_str()));  // as VTK reads them
    } else if (field == "kinds") {
      kinds = tokens;
    } else if (field == "space directions") {
      directions = nrrdDirections(line.substr(colon + 2), name);
      // One entry per axis, three of them spatial; VTK took two vectors for three axes without a word.
      if (dimension >= 1 && static_cast<long>(directions.size()) != dimension)
        throw Error(name, "NRRD 'space directions' has " + std::to_string(directions.size()) +
                              " entries for dimension " + std::to_string(dimension));
      if (std::count_if(directions.begin(), directions.end(), [](const auto& v) { return v.has_value(); }) != 3)
        throw Error(name, "NRRD 'space directions' must give 3 spatial axes (vectors; 'none' for others)");
      std::vector<glm::dvec3> spatial;
      for (const auto& v : directions)
        if (v) spatial.push_back(*v);
      if (!(std::abs(glm::determinant(glm::dmat3(spatial[0], spatial[1], spatial[2]))) > 0.0))
        throw Error(name, "NRRD 'space directions' are not independent (the grid would be flat)");
      spacings.clear();  // VTK's spacings are the vectors' lengths
      for (const auto& v : directions) spacings.push_back(v ? glm::length(*v) : 0.0);
    } else if (field == "space origin") {
      // VTK read "(0,0" as the origin without a word.
      std::vector<std::optional<glm::dvec3>> origin;
      try {
        origin = nrrdDirections(line.substr(colon + 2), name);
      } catch (const Error&) {
        origin.clear();
      }
      if (origin.size() != 1 || !origin[0])
        throw Error(name, "NRRD 'space origin' must be one vector (x,y,z) (got '" + line.substr(colon + 2) + "')");
    } else if (field == "encoding") {
      encoding = tokens.empty() ? std::string() : lower(tokens[0]);
      if (encoding == "ascii" || encoding == "txt" || encoding == "text")
        throw Error(name, "NRRD with ASCII encoding is not supported (use raw or gzip)");
    } else if (field == "data file" || field == "datafile") {
      if (tokens.empty()) throw Error(name, "NRRD 'data file' is empty");
      if (tokens.size() > 1 || tokens[0] == "LIST")
        throw Error(name, "NRRD data split into several files is not supported");
      dataFile = line.substr(colon + 2);
    } else if (field == "type") {
      type = lower(line.substr(colon + 2));
    } else if (field == "byte skip" || field == "byteskip") {
      byteSkip = tokens.empty() ? 0 : std::atol(tokens[0].c_str());
    }
  }
  if (sizes.empty()) throw Error(name, "NRRD header has no 'sizes'");

  // Which axes are spatial. NRRD's "kinds" says it ("domain", "space" and "time" are axes of the
  // grid; "vector", "RGB-color", "3-vector", "list", … hold components; "???" and "none" say
  // nothing); so does a "none" in "space directions". vtkNrrdReader reads a 4D file's first axis
  // as components, and a 3D file's first axis too when it has 9 or fewer samples or spacing 0.
  const auto spatialKind = [&](std::size_t axis) -> std::optional<bool> {
    if (axis >= kinds.size()) return std::nullopt;
    const std::string k = lower(kinds[axis]);
    if (k == "???" || k == "none") return std::nullopt;
    return k == "domain" || k == "space" || k == "time";
  };
  const auto spatialAxis = [&](std::size_t axis) -> std::optional<bool> {
    if (axis < directions.size()) return directions[axis].has_value();
    return spatialKind(axis);
  };
  if (sizes.size() > 4)
    throw Error(name, "NRRD of " + std::to_string(sizes.size()) +
                          " axes: a volume has 3 spatial axes and at most one of components");
  // Sizes VTK takes as int; anything near that is no volume (at most 2048 points per axis, 4096
  // components) and was cut to 32 bits ("4294967301" read as 5).
  for (const long n : sizes)
    if (n > 1000000) throw Error(name, "NRRD 'sizes' value " + std::to_string(n) + " is too large for a volume");
  // A raw detached data file shorter than the header's samples: VTK said "File operation failed:
  // 18446744073709551460" (a bug hunt). Its size is checked here, naming both files.
  if (!dataFile.empty() && encoding == "raw" && byteSkip >= 0) {
    static const std::map<std::string, std::uint64_t> kTypeBytes{
        {"float", 4},          {"double", 8},    {"uchar", 1},   {"unsigned char", 1},
        {"uint8", 1},          {"uint8_t", 1},   {"char", 1},    {"signed char", 1},
        {"int8", 1},           {"int8_t", 1},    {"short", 2},   {"ushort", 2},
        {"unsigned short", 2}, {"int16", 2},     {"uint16", 2},  {"int16_t", 2},
        {"uint16_t", 2},       {"int", 4},       {"uint", 4},    {"unsigned int", 4},
        {"int32", 4},          {"uint32", 4},    {"int32_t", 4}, {"uint32_t", 4},
        {"longlong", 8},       {"ulonglong", 8}, {"int64", 8},   {"uint64", 8},
        {"int64_t", 8},        {"uint64_t", 8}};
    const auto bytes = kTypeBytes.find(type);
    if (bytes != kTypeBytes.end()) {
      double need = static_cast<double>(bytes->second);  // in double: 4 axes of 10^6 pass a uint64
      for (const long n : sizes) need *= static_cast<double>(std::max(n, 0L));
      need += static_cast<double>(byteSkip);
      const fs::path data = dataFile.front() == '/' ? fs::path(dataFile) : path.parent_path() / dataFile;
      std::error_code ec;
      const std::uintmax_t have = fs::file_size(data, ec);
      if (ec) throw Error(name, "NRRD data file '" + dataFile + "': " + ec.message());
      if (static_cast<double>(have) < need)
        throw Error(name, "NRRD data file '" + dataFile + "' holds " + std::to_string(have) +
                              " bytes; the header's sizes and type need " + numberText(need));
    }
  }
  const auto spacingOf = [&](std::size_t axis) { return axis < spacings.size() ? spacings[axis] : 1.0; };
  NrrdOrientation::Layout layout;
  if (sizes.size() == 4) {
    const bool componentsFirst =
        spatialAxis(0) != true && spatialAxis(1) != false && spatialAxis(2) != false && spatialAxis(3) != false;
    if (!componentsFirst) {
      std::string given;
      for (const std::string& k : kinds) given += (given.empty() ? "" : " ") + k;
      throw Error(name, "NRRD of 4 axes whose vector components are not on the first axis (kinds: " +
                            (given.empty() ? "not given" : given) + "; space directions: " +
                            (directions.empty() ? "not given" : "'none' elsewhere") + "): not supported");
    }
    if (sizes[0] > kMaxComponents)
      throw Error(name, "NRRD vector of " + std::to_string(sizes[0]) + " components (at most " +
                            std::to_string(kMaxComponents) + ")");
    if (directions.size() == 4)
      orientation.directions = std::array<glm::dvec3, 3>{*directions[1], *directions[2], *directions[3]};
    layout.components = static_cast<int>(sizes[0]);
    for (std::size_t a = 0; a < 3; ++a) {
      layout.sizes[a] = static_cast<int>(sizes[a + 1]);
      layout.spacing[a] = spacingOf(a + 1);
    }
    orientation.layout = layout;
  } else if (sizes.size() == 3 && spatialKind(0) != false) {
    // Components on a later axis ("kinds: space space RGB-color") would be read as a grid axis.
    if (spatialKind(1) == false || spatialKind(2) == false)
      throw Error(name, "NRRD of 3 axes whose components are not on the first axis: not supported");
    if (directions.size() == 3)
      orientation.directions = std::array<glm::dvec3, 3>{*directions[0], *directions[1], *directions[2]};
    for (std::size_t a = 0; a < 3; ++a) {
      layout.sizes[a] = static_cast<int>(sizes[a]);
      layout.spacing[a] = spacingOf(a);
    }
    orientation.layout = layout;
  }
  return orientation;
}

// The numeric arrays of an image's point or cell data, by name, in file order.
std::vector<std::string> arrayNames(vtkFieldData* data) {
  std::vector<std::string> names;
  if (data != nullptr)
    for (int i = 0; i < data->GetNumberOfArrays(); ++i)
      if (vtkDataArray* a = data->GetArray(i); a != nullptr && a->GetName() != nullptr)
        names.emplace_back(a->GetName());
  return names;
}

// The other ways to read an array of several components (a vector or tensor): "name" is its
// first component, "name:N" component N, "name:magnitude" the length of each tuple.
std::vector<std::string> componentFields(vtkDataArray* a) {
  std::vector<std::string> names;
  const int n = a != nullptr && a->GetName() != nullptr ? a->GetNumberOfComponents() : 1;
  for (int c = 1; c < n; ++c) names.push_back(std::string(a->GetName()) + ":" + std::to_string(c));
  if (n > 1) names.push_back(std::string(a->GetName()) + ":magnitude");
  return names;
}

// What a volume file can be read as: its point arrays, then its cell arrays (a name that is both
// reads the point array), each followed by its components.
std::vector<std::string> fieldNames(vtkImageData* image) {
  std::vector<std::string> names;
  for (vtkFieldData* data :
       {static_cast<vtkFieldData*>(image->GetPointData()), static_cast<vtkFieldData*>(image->GetCellData())})
    for (const std::string& n : arrayNames(data)) {
      if (std::find(names.begin(), names.end(), n) != names.end()) continue;
      names.push_back(n);
      for (std::string& c : componentFields(data->GetArray(n.c_str()))) names.push_back(std::move(c));
    }
  return names;
}

struct SampleArray {
  static constexpr int kMagnitude = -1;
  vtkDataArray* array = nullptr;
  bool cells = false;  // cell data: one sample per cell, at its centre
  int component = 0;   // kMagnitude: the tuple's length
};

// The array named `field` ("name", "name:N", "name:magnitude"; point data first), if any.
std::optional<SampleArray> namedArray(vtkPointData* pd, vtkCellData* cd, const std::string& field,
                                      const std::string& name) {
  const auto find = [&](const std::string& arrayName) -> std::optional<SampleArray> {
    if (vtkDataArray* a = pd != nullptr ? pd->GetArray(arrayName.c_str()) : nullptr; a != nullptr)
      return SampleArray{a, false};
    if (vtkDataArray* a = cd != nullptr ? cd->GetArray(arrayName.c_str()) : nullptr; a != nullptr)
      return SampleArray{a, true};
    return std::nullopt;
  };
  if (std::optional<SampleArray> whole = find(field)) return whole;
  const std::size_t colon = field.rfind(':');
  if (colon == std::string::npos || colon == 0) return std::nullopt;
  const std::string base = field.substr(0, colon), which = field.substr(colon + 1);
  std::optional<SampleArray> array = find(base);
  if (!array) return std::nullopt;
  const int component = fieldComponent(base, which, array->array->GetNumberOfComponents(), name);
  array->component = component < 0 ? SampleArray::kMagnitude : component;
  return array;
}

// The sample array: the one named `field` (point data first); else the point data's active
// scalars, else its first array; else likewise the cell data's.
SampleArray sampleArray(vtkImageData* image, const std::string& name, const std::string& field) {
  vtkPointData* pd = image->GetPointData();
  vtkCellData* cd = image->GetCellData();
  if (!field.empty()) {
    if (std::optional<SampleArray> named = namedArray(pd, cd, field, name)) return *named;
    std::string list;
    for (const std::string& n : arrayNames(pd)) list += (list.empty() ? "" : ", ") + n;
    std::string cellList;
    for (const std::string& n : arrayNames(cd)) cellList += (cellList.empty() ? "" : ", ") + n;
    throw FieldNotFound(name, "no point-data or cell-data array '" + field + "' (" +
                                  (list.empty() && cellList.empty() ? std::string("it has none")
                                   : list.empty()                   ? "cell data: " + cellList
                                   : cellList.empty()               ? "arrays: " + list
                                                                    : "arrays: " + list + "; cell data: " + cellList) +
                                  ")");
  }
  for (vtkDataSetAttributes* data : {static_cast<vtkDataSetAttributes*>(pd), static_cast<vtkDataSetAttributes*>(cd)}) {
    if (data == nullptr) continue;
    const bool cells = data == cd;
    if (vtkDataArray* s = data->GetScalars(); s != nullptr) return {s, cells};
    for (int i = 0; i < data->GetNumberOfArrays(); ++i)
      if (vtkDataArray* a = data->GetArray(i); a != nullptr) return {a, cells};
  }
  throw Error(name, "image has no point-data or cell-data scalar array");
}

// VTK 9.1's XML image reader crashes on a DataArray of type String in the point or cell data:
// such arrays (text, never samples) are found in the XML, which comes before any appended binary
// data, and left unread. (name, whether it is cell data); FieldData's are refused, as VTK cannot
// be told to skip them. The ImageData's Origin, Spacing and Direction must be finite numbers.
std::vector<std::pair<std::string, bool>> xmlStringArrays(const fs::path& path, const std::string& name) {
  const std::vector<std::string> tags = vtkXmlTags(path, nullptr);
  std::error_code sizeError;
  const std::uintmax_t fileBytes = fs::file_size(path, sizeError);
  std::vector<std::pair<std::string, bool>> found;
  enum class Section { kNone, kPoints, kCells, kField } section = Section::kNone;
  // Extents as 6 whole numbers (x0 x1 y0 y1 z0 z1), when they are.
  using Extent = std::array<long long, 6>;
  const auto extentOf = [](const std::string& text) -> std::optional<Extent> {
    std::istringstream numbers(text);
    Extent e{};
    for (long long& v : e)
      if (!(numbers >> v)) return std::nullopt;
    return e;
  };
  std::optional<Extent> whole;
  std::vector<Extent> pieces;
  for (const std::string& tagText : tags) {
    const std::string_view tag(tagText);
    const auto is = [&](std::string_view element) { return isVtkXmlElement(tag, element); };
    if (is("ImageData"))
      for (const char* key : {"Origin", "Spacing", "Direction"}) {
        // VTK reads a value it cannot parse (nan, 1e309) as its default and says nothing.
        const std::string text = vtkXmlAttribute(tag, key);
        if (text.empty()) continue;
        std::istringstream numbers(text);
        std::string number;
        int count = 0;
        while (numbers >> number) {
          char* end = nullptr;
          const double value = std::strtod(number.c_str(), &end);
          if (end == number.c_str() || *end != '\0' || !std::isfinite(value))
            throw Error(name, std::string("ImageData ") + key + " '" + text.substr(0, 64) + "' is not finite numbers");
          ++count;
        }
        if (count != (std::string_view(key) == "Direction" ? 9 : 3))
          throw Error(name, std::string("ImageData ") + key + " '" + text.substr(0, 64) + "' has " +
                                std::to_string(count) + " numbers");
      }
    if (is("ImageData")) whole = extentOf(vtkXmlAttribute(tag, "WholeExtent"));
    if (is("Piece"))
      if (const std::optional<Extent> e = extentOf(vtkXmlAttribute(tag, "Extent"))) pieces.push_back(*e);
    if (is("PointData")) section = Section::kPoints;
    if (is("CellData")) section = Section::kCells;
    if (is("FieldData")) section = Section::kField;
    if (is("/PointData") || is("/CellData") || is("/FieldData")) section = Section::kNone;
    // VTK allocates what these declare before it reads a value (2^31 components: 12 GB, then
    // killed; found by fuzzing).
    if (is("DataArray"))
      checkVtkXmlDataArray(tag, kMaxComponents, static_cast<long long>(VolumeGrid::kMaxPoints),
                           sizeError ? ~std::uintmax_t{0} : fileBytes, name);
    if (!is("DataArray") || vtkXmlAttribute(tag, "type") != "String") continue;
    if (section == Section::kField)
      throw Error(name,
                  "field data array '" + vtkXmlAttribute(tag, "Name") + "' holds text, which VTK's reader cannot skip");
    if (section != Section::kNone) found.emplace_back(vtkXmlAttribute(tag, "Name"), section == Section::kCells);
  }
  // Pieces that leave points of the WholeExtent out: VTK reads them into a grid of the whole
  // extent and leaves the rest as it was allocated (two reads of one file drew different images; a
  // bug hunt). Points, not cells (pieces need not share their boundary points), by the pieces'
  // own boundaries on each axis: every box between them must lie in some piece. Empty pieces
  // (x1 < x0: more pieces than cells) hold nothing.
  std::erase_if(pieces, [](const Extent& e) { return e[1] < e[0] || e[3] < e[2] || e[5] < e[4]; });
  if (whole && !pieces.empty() && pieces.size() <= 32) {
    const auto text = [](const Extent& e) {
      std::string t;
      for (const long long v : e) t += (t.empty() ? "" : " ") + std::to_string(v);
      return t;
    };
    for (const Extent& piece : pieces)
      for (int a = 0; a < 3; ++a)
        if (piece[2 * a] < (*whole)[2 * a] || piece[2 * a + 1] > (*whole)[2 * a + 1])
          throw Error(name, "Piece Extent '" + text(piece) + "' is not inside the WholeExtent '" + text(*whole) + "'");
    std::array<std::vector<long long>, 3> cuts;  // half-open point ranges [lo, hi + 1) per axis
    for (int a = 0; a < 3; ++a) {
      cuts[a] = {(*whole)[2 * a], (*whole)[2 * a + 1] + 1};
      for (const Extent& piece : pieces) {
        cuts[a].push_back(piece[2 * a]);
        cuts[a].push_back(piece[2 * a + 1] + 1);
      }
      std::sort(cuts[a].begin(), cuts[a].end());
      cuts[a].erase(std::unique(cuts[a].begin(), cuts[a].end()), cuts[a].end());
    }
    long long missing = 0;
    for (std::size_t i = 0; i + 1 < cuts[0].size(); ++i)
      for (std::size_t j = 0; j + 1 < cuts[1].size(); ++j)
        for (std::size_t k = 0; k + 1 < cuts[2].size(); ++k) {
          const std::array<long long, 3> at{cuts[0][i], cuts[1][j], cuts[2][k]};
          const bool covered = std::any_of(pieces.begin(), pieces.end(), [&](const Extent& e) {
            for (int a = 0; a < 3; ++a)
              if (at[a] < e[2 * a] || at[a] > e[2 * a + 1]) return false;
            return true;
          });
          if (!covered)
            missing += (cuts[0][i + 1] - cuts[0][i]) * (cuts[1][j + 1] - cuts[1][j]) * (cuts[2][k + 1] - cuts[2][k]);
        }
    if (missing > 0) {
      long long total = 1;
      for (int a = 0; a < 3; ++a) total *= (*whole)[2 * a + 1] - (*whole)[2 * a] + 1;
      throw Error(name, "its pieces leave out " + std::to_string(missing) + " of the " + std::to_string(total) +
                            " points of the WholeExtent '" + text(*whole) + "' (VTK would leave them unset)");
    }
  }
  return found;
}

}  // namespace

// The declared size, before anything is allocated for it.
void checkDims(const std::array<std::int64_t, 3>& d, const std::string& name) {
  for (const std::int64_t n : d) {
    if (n < 2) throw Error(name, "volume needs at least 2 points per axis (the file declares " + dimsText(d) + ")");
    if (n > kMaxPointsPerAxis)
      throw Error(name, "volume of " + dimsText(d) + " points is larger than " + std::to_string(kMaxPointsPerAxis) +
                            " points per axis");
  }
  if (static_cast<std::size_t>(d[0]) * static_cast<std::size_t>(d[1]) * static_cast<std::size_t>(d[2]) >
      VolumeGrid::kMaxPoints)
    throw Error(name, "volume of " + dimsText(d) + " points is larger than 2^30 points (4 GiB of samples)");
}

Volume readVolumeWithVtk(VolumeFormat format, const fs::path& path, const std::string& name, const std::string& field,
                         const LoadProgress& progress) {
  const std::string label = formatLabel(format);
  NrrdOrientation nrrd;
  if (format == VolumeFormat::Nrrd) nrrd = checkNrrdHeader(path, name);
  std::optional<glm::dmat3> metaDirection;  // MetaImage's TransformMatrix, which VTK drops
  if (format == VolumeFormat::MetaImage) metaDirection = checkMetaImageHeader(path, name);
  if (format == VolumeFormat::LegacyVtk) checkLegacyVtkFieldCounts(path, name);
  if (format == VolumeFormat::Vti) checkVtkXmlFileEnd(path, nullptr, name);
  VtkMessages messages;  // before the reader: VTK's output window goes quiet
  std::optional<CerrCapture> metaIo;
  if (format == VolumeFormat::MetaImage) metaIo.emplace();
  const std::string file = path.string();
  vtkSmartPointer<vtkAlgorithm> reader = makeReader(format, file, nrrd);
  if (!reader) throw Error(name, "internal error: no VTK reader for " + label);
  ProgressRelay relay{&progress};
  vtkNew<vtkCallbackCommand> onProgress;
  onProgress->SetCallback(&ProgressRelay::callback);
  onProgress->SetClientData(&relay);
  reader->AddObserver(vtkCommand::ProgressEvent, onProgress);

  // Reading the samples, the readers report short or unreadable data as warnings ("Error reading
  // binary data!", "File operation failed") and return what they have: warnings fail there.
  // Header warnings (NRRD's unknown fields) do not.
  bool readingData = false;
  const auto failed = [&] {
    return reader->GetErrorCode() != 0 || messages.hasError() || (readingData && messages.hasWarning()) ||
           (metaIo && !metaIo->text().empty());
  };
  const auto fail = [&](const std::string& what) {
    std::string reason = messages.reason();
    if (reason.empty() && metaIo) reason = oneLine(metaIo->text());
    throw Error(name, what + (reason.empty() ? "" : ": " + reason));
  };

  // The header first: the extent it declares is checked before the samples are allocated.
  reader->UpdateInformation();
  if (failed()) fail("cannot read " + label + " header");
  vtkInformation* info = reader->GetOutputInformation(0);
  if (info == nullptr || !info->Has(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()))
    fail("cannot read " + label + " header (no extent)");
  int extent[6];
  info->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent);
  const std::array<std::int64_t, 3> declared{std::int64_t{extent[1]} - extent[0] + 1,
                                             std::int64_t{extent[3]} - extent[2] + 1,
                                             std::int64_t{extent[5]} - extent[4] + 1};
  checkDims(declared, name);
  const auto points = static_cast<std::uint64_t>(declared[0] * declared[1] * declared[2]);
  // A legacy file is not compressed: its samples take at least a bit per cell (cell data of
  // bit scalars, the least there can be), and VTK allocated the whole grid before it found a file
  // far too short (a 400-byte file declaring 10^9 points took 8 GB).
  if (format == VolumeFormat::LegacyVtk) {
    std::error_code error;
    const std::uintmax_t bytes = fs::file_size(path, error);
    const std::uint64_t cells = static_cast<std::uint64_t>((declared[0] - 1) * (declared[1] - 1) * (declared[2] - 1));
    if (!error && bytes < cells / 8)
      throw Error(name, "the file's " + std::to_string(bytes) + " bytes cannot hold the samples of the " +
                            dimsText(declared) + " points its DIMENSIONS declare (a truncated file?)");
  }
  // VTK's array in the file's type and the grid's floats, asked for before either is allocated.
  {
    std::uint64_t sampleBytes = 4;  // not declared: a float, the usual (a guard, not an exact count)
    if (vtkInformation* scalars = vtkDataObject::GetActiveFieldInformation(
            info, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS);
        scalars != nullptr && scalars->Has(vtkDataObject::FIELD_ARRAY_TYPE())) {
      const int components = scalars->Has(vtkDataObject::FIELD_NUMBER_OF_COMPONENTS())
                                 ? std::max(1, scalars->Get(vtkDataObject::FIELD_NUMBER_OF_COMPONENTS()))
                                 : 1;
      sampleBytes = static_cast<std::uint64_t>(
                        std::max(1, vtkDataArray::GetDataTypeSize(scalars->Get(vtkDataObject::FIELD_ARRAY_TYPE())))) *
                    static_cast<std::uint64_t>(components);
    }
    requireHostMemory(name, "its " + dimsText(declared) + " samples", points * (sampleBytes + sizeof(float)));
  }
  if (auto* xml = vtkXMLImageDataReader::SafeDownCast(reader))
    for (const auto& [array, cells] : xmlStringArrays(path, name)) {
      if (!field.empty() && (field == array || field.rfind(array + ":", 0) == 0))
        throw Error(name, "array '" + array + "' holds text, not numbers");
      (cells ? xml->GetCellDataArraySelection() : xml->GetPointDataArraySelection())->DisableArray(array.c_str());
    }
  progress.step(0.1);

  messages.clear();
  readingData = true;
  reader->Update();
  if (relay.cancelled) throw LoadCancelled();
  if (failed()) fail("cannot read " + label);
  vtkImageData* image = vtkImageData::SafeDownCast(reader->GetOutputDataObject(0));
  if (image == nullptr) fail("cannot read " + label + " (no image data)");
  int dims[3];
  image->GetDimensions(dims);
  const std::array<std::int64_t, 3> got{dims[0], dims[1], dims[2]};
  if (got != declared)
    fail("cannot read " + label + " (read " + dimsText(got) + " points of the " + dimsText(declared) + " declared)");
  bool namedFields = hasNamedFields(format);
  if (hasComponentFields(format)) {
    vtkDataArray* const scalars = image->GetPointData() != nullptr ? image->GetPointData()->GetScalars() : nullptr;
    if (scalars != nullptr && scalars->GetNumberOfComponents() > 1) {
      scalars->SetName(kComponentsField);
      namedFields = true;
    } else if (!field.empty()) {
      throw FieldNotFound(name, label + " files have one unnamed field (this one has one component); field '" + field +
                                    "' cannot be chosen");
    }
  }
  const SampleArray sample = sampleArray(image, name, field);
  vtkDataArray* const array = sample.array;
  const bool cells = sample.cells;
  // Cell data: a grid of the cells' centres, one fewer per axis.
  const int less = cells ? 1 : 0;
  const glm::ivec3 gridDims(dims[0] - less, dims[1] - less, dims[2] - less);
  if (cells) {
    try {
      checkDims({gridDims.x, gridDims.y, gridDims.z}, name);
    } catch (const Error&) {
      throw Error(name, "cell-data array '" + std::string(array->GetName() ? array->GetName() : "") + "' of " +
                            dimsText({gridDims.x, gridDims.y, gridDims.z}) +
                            " cells: a volume needs at least 2 cells per axis");
    }
  }
  const std::size_t n = pointCount(gridDims);
  if (array->GetNumberOfComponents() < 1 || array->GetNumberOfTuples() != static_cast<vtkIdType>(n))
    throw Error(name, "scalar array '" + std::string(array->GetName() ? array->GetName() : "") + "' has " +
                          std::to_string(array->GetNumberOfTuples()) + " values for " + std::to_string(n) +
                          (cells ? " cells" : " points") + " (truncated?)");
  progress.step(0.7);

  auto grid = std::make_shared<VolumeGrid>();
  grid->dims = gridDims;
  grid->values.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto t = static_cast<vtkIdType>(i);
    if (sample.component == SampleArray::kMagnitude) {
      double sum = 0.0;
      for (int c = 0; c < array->GetNumberOfComponents(); ++c)
        sum += array->GetComponent(t, c) * array->GetComponent(t, c);
      grid->values[i] = static_cast<float>(std::sqrt(sum));
    } else {
      grid->values[i] = static_cast<float>(array->GetComponent(t, sample.component));
    }
    if ((i + 1) % kProgressChunk == 0) progress.step(0.7 + 0.25 * static_cast<double>(i + 1) / static_cast<double>(n));
  }

  // VTK: point (i, j, k) of the extent is at origin + D·(spacing ⊙ (i, j, k)), D the direction
  // matrix. Our grid counts from the extent's first point with positive spacings; the rest (the
  // start of the extent, signs of spacings, D) goes into origin and transform.
  double o[3], s[3];
  image->GetOrigin(o);
  image->GetSpacing(s);
  glm::dmat3 direction(1.0);
  if (vtkMatrix3x3* m = image->GetDirectionMatrix(); m != nullptr)
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) direction[c][r] = m->GetElement(r, c);
  if (metaDirection) direction = *metaDirection;
  int start[3];
  image->GetExtent(extent);
  start[0] = extent[0];
  start[1] = extent[2];
  start[2] = extent[4];
  // NRRD: the directions VTK dropped (it may also misread their lengths: "( -3, 0, 0.5 )" with
  // spaces gives a spacing of 0). Only when the grid is the header's three spatial axes.
  const bool nrrdOriented = nrrd.directions && nrrd.layout && nrrd.layout->sizes[0] == gridDims.x &&
                            nrrd.layout->sizes[1] == gridDims.y && nrrd.layout->sizes[2] == gridDims.z &&
                            extent[0] == 0 && extent[2] == 0 && extent[4] == 0;
  if (nrrdOriented)
    for (int a = 0; a < 3; ++a) s[a] = glm::length((*nrrd.directions)[static_cast<std::size_t>(a)]);
  glm::dvec3 spacing, first;
  glm::dmat3 axes = direction;
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(s[a]) || s[a] == 0.0 || !std::isfinite(o[a]))
      throw Error(name, "spacing must be non-zero and finite, the origin finite (spacing " + std::to_string(s[0]) +
                            " " + std::to_string(s[1]) + " " + std::to_string(s[2]) + ")");
    spacing[a] = std::abs(s[a]);
    first[a] = s[a] * (start[a] + 0.5 * less);  // a cell's centre is half a spacing in
    if (s[a] < 0.0) axes[a] = -axes[a];
  }
  Volume volume;
  volume.grid = std::move(grid);
  if (namedFields) {  // not MetaImage's and NRRD's one component: VTK's readers name it, not the file
    volume.field = !field.empty() ? field : array->GetName() != nullptr ? array->GetName() : "";
    volume.fields = fieldNames(image);
  }
  volume.origin = glm::dvec3(o[0], o[1], o[2]) + direction * first;
  volume.spacing = spacing;
  if (nrrdOriented)
    for (int a = 0; a < 3; ++a) axes[a] = (*nrrd.directions)[static_cast<std::size_t>(a)] / spacing[a];
  if (axes != glm::dmat3(1.0))
    volume.transform = glm::translate(glm::dmat4(1.0), volume.origin) * glm::dmat4(axes) *
                       glm::translate(glm::dmat4(1.0), -volume.origin);
  return volume;
}

// ---------------------------------------------------------------------------------------------
// CGAL ImageIO

namespace {

// ImageIO keeps its list of formats in globals that it fills on first use.
std::mutex& imageIoMutex() {
  static std::mutex m;
  return m;
}

// The magic bytes of an INRIMAGE file, read through zlib (which passes uncompressed bytes through).
void checkInrimageMagic(const fs::path& path, const std::string& name, bool gz) {
  if (gz) {
    std::ifstream in(path, std::ios::binary);
    unsigned char magic[2] = {0, 0};
    in.read(reinterpret_cast<char*>(magic), 2);
    if (in.gcount() != 2 || magic[0] != 0x1f || magic[1] != 0x8b)
      throw Error(name, "not a gzip file (bad magic bytes)");
  }
  gzFile f = gzopen(path.c_str(), "rb");
  if (f == nullptr) throw Error(name, "cannot open file for reading");
  const std::unique_ptr<gzFile_s, int (*)(gzFile)> closer(f, gzclose);
  static constexpr std::string_view kMagic = "#INRIMAGE-4#{";
  char head[16] = {};
  const int got = gzread(f, head, static_cast<unsigned>(kMagic.size()));
  if (got < 0) throw Error(name, "corrupt gzip data");
  // A .gz cut inside its first bytes decompresses to fewer than the magic's: truncated, not
  // another format (a bug hunt: the first 100 bytes of liver.inr.gz were "not an INRIMAGE file").
  const bool shortRead = static_cast<std::size_t>(got) < kMagic.size();
  if (gz && shortRead &&
      kMagic.substr(0, static_cast<std::size_t>(got)) == std::string_view(head, static_cast<std::size_t>(got)))
    throw Error(name, "truncated or corrupt gzip data (it ends before the INRIMAGE header)");
  if (std::string_view(head, static_cast<std::size_t>(got)) != kMagic)
    throw Error(name, "not an INRIMAGE file (it does not start with #INRIMAGE-4#{)");
}

}  // namespace

Volume readInrimage(const fs::path& path, const std::string& name, const LoadProgress& progress) {
  const bool gz = endsWith(lower(path.filename().string()), ".gz");
  checkInrimageMagic(path, name, gz);
  // ImageIO reads standard input for the names "-" and "<".
  const std::string file = fs::absolute(path).string();

  std::lock_guard<std::mutex> lock(imageIoMutex());
  // ImageIO's own readers, without _readImageHeader's search over formats, which prints each
  // failure to stderr: open (through zlib), then the INRIMAGE header reader, which does not.
  const std::unique_ptr<_image, void (*)(_image*)> im(_initImage(), _freeImage);
  if (!im) throw Error(name, "out of memory");
  _openReadImage(im.get(), file.c_str());
  if (im->fd == nullptr || im->openMode == OM_CLOSE) throw Error(name, "cannot open file for reading");
  if (readInrimageHeader(file.c_str(), im.get()) < 0) throw Error(name, "corrupt or unsupported INRIMAGE header");

  // ImageIO's header check passed: positive sizes and voxel sizes, a known word kind. It reads the
  // sizes as unsigned: XDIM=-16 came out as 2^64 − 16, named as "9223372036854775807x16x16".
  for (const auto& [key, size] :
       {std::pair{"XDIM", im->xdim}, std::pair{"YDIM", im->ydim}, std::pair{"ZDIM", im->zdim}})
    if (size > static_cast<std::size_t>(INT64_MAX))
      throw Error(name, std::string("INRIMAGE ") + key + " is negative (" +
                            std::to_string(static_cast<std::int64_t>(size)) + "): a size must be a positive count");
  const std::array<std::int64_t, 3> declared{static_cast<std::int64_t>(std::min<std::size_t>(im->xdim, INT64_MAX)),
                                             static_cast<std::int64_t>(std::min<std::size_t>(im->ydim, INT64_MAX)),
                                             static_cast<std::int64_t>(std::min<std::size_t>(im->zdim, INT64_MAX))};
  checkDims(declared, name);
  if (im->vdim < 1 || im->vdim > 64)
    throw Error(name, "unsupported number of components per voxel (" + std::to_string(im->vdim) + ")");
  if (!(im->vx > 0.0) || !(im->vy > 0.0) || !(im->vz > 0.0) || !std::isfinite(im->vx) || !std::isfinite(im->vy) ||
      !std::isfinite(im->vz))
    throw Error(name, "voxel size (VX, VY, VZ) must be positive and finite");
  const std::size_t wdim = im->wdim;
  const bool isFloat = im->wordKind == WK_FLOAT;
  const bool isSigned = im->sign == SGN_SIGNED;
  if (isFloat ? (wdim != 4 && wdim != 8)
              : (im->wordKind != WK_FIXED || (wdim != 1 && wdim != 2 && wdim != 4 && wdim != 8)))
    throw Error(name,
                "unsupported voxel type (" + std::to_string(8 * wdim) + "-bit " + (isFloat ? "float" : "fixed") + ")");

  const glm::ivec3 dims(static_cast<int>(declared[0]), static_cast<int>(declared[1]), static_cast<int>(declared[2]));
  const std::size_t n = pointCount(dims);
  const std::uint64_t bytes = static_cast<std::uint64_t>(n) * im->vdim * wdim;
  // Uncompressed: the file must hold all the samples its header declares.
  if (gzdirect(im->fd) == 1) {
    const z_off_t headerEnd = gztell(im->fd);
    std::error_code ec;
    const std::uintmax_t size = fs::file_size(path, ec);
    if (!ec && headerEnd >= 0 && size - static_cast<std::uintmax_t>(headerEnd) < bytes)
      throw Error(name, "truncated INRIMAGE file (" + std::to_string(size - static_cast<std::uintmax_t>(headerEnd)) +
                            " of " + std::to_string(bytes) + " bytes of voxel data)");
  }
  // The samples and the grid's floats, asked for before they are read: a 1 MB .inr.gz of zeros
  // declaring 1024^3 voxels took 5 GB past MFR_MEMORY_LIMIT_MIB (a bug hunt).
  requireHostMemory(name, "its " + dimsText(declared) + " samples",
                    bytes + static_cast<std::uint64_t>(n) * sizeof(float));
  progress.step(0.1);
  if (_readImageData(im.get()) < 0)
    throw Error(name, gz ? "truncated or corrupt INRIMAGE data (gzip stream ends early or is damaged)"
                         : "truncated INRIMAGE file (cannot read " + std::to_string(bytes) + " bytes of voxel data)");
  progress.step(0.7);

  auto grid = std::make_shared<VolumeGrid>();
  grid->dims = dims;
  const std::size_t stride = im->vdim * wdim;  // interlaced components: the first one
  const void* data = im->data;
  if (isFloat) {
    if (wdim == 4)
      convertSamples<float>(data, n, stride, grid->values, progress);
    else
      convertSamples<double>(data, n, stride, grid->values, progress);
  } else if (isSigned) {
    if (wdim == 1)
      convertSamples<std::int8_t>(data, n, stride, grid->values, progress);
    else if (wdim == 2)
      convertSamples<std::int16_t>(data, n, stride, grid->values, progress);
    else if (wdim == 4)
      convertSamples<std::int32_t>(data, n, stride, grid->values, progress);
    else
      convertSamples<std::int64_t>(data, n, stride, grid->values, progress);
  } else {
    if (wdim == 1)
      convertSamples<std::uint8_t>(data, n, stride, grid->values, progress);
    else if (wdim == 2)
      convertSamples<std::uint16_t>(data, n, stride, grid->values, progress);
    else if (wdim == 4)
      convertSamples<std::uint32_t>(data, n, stride, grid->values, progress);
    else
      convertSamples<std::uint64_t>(data, n, stride, grid->values, progress);
  }

  Volume volume;
  volume.grid = std::move(grid);
  volume.origin = glm::dvec3(im->tx, im->ty, im->tz);
  volume.spacing = glm::dvec3(im->vx, im->vy, im->vz);
  return volume;
}

std::optional<VolumeFormat> volumeFormat(const fs::path& path) {
  const std::optional<VolumeFormat> format = formatByName(path);
  if (format == VolumeFormat::LegacyVtk && legacyDataset(path) != "STRUCTURED_POINTS") return std::nullopt;
  return format;
}

}  // namespace mfr::io

namespace mfr {

Volume loadVolume(const std::filesystem::path& path, const LoadProgress& progress) {
  return loadVolume(path, LoadOptions{}, progress);
}

Volume loadVolume(const std::filesystem::path& path, const LoadOptions& options, const LoadProgress& progress) {
  const std::string name = path.string();
  return io::withFileErrors(name, [&] {
    progress.step(0.0);
    io::checkReadable(path, name, "volume");
    const std::optional<io::VolumeFormat> format = io::formatByName(path);
    if (!format) {
      std::string list;
      for (const std::string& ext : supportedVolumeExtensions()) list += (list.empty() ? "" : " ") + ext;
      const std::string ext = path.extension().string();
      throw Error(name, "unsupported volume file type '" + (ext.empty() ? path.filename().string() : io::lower(ext)) +
                            "' (supported: " + list + ")");
    }
    if (*format == io::VolumeFormat::LegacyVtk) {
      const std::string dataset = io::legacyDataset(path);
      if (dataset.empty()) throw Error(name, "not a legacy VTK file (no '# vtk DataFile' header with a DATASET line)");
      if (dataset != "STRUCTURED_POINTS")
        throw Error(name, "legacy VTK DATASET " + dataset + " is not a volume (expected STRUCTURED_POINTS)");
    }
    if (!options.field.empty() && !io::hasNamedFields(*format) && !io::hasComponentFields(*format))
      throw FieldNotFound(name, std::string(io::formatLabel(*format)) + " files have one unnamed field; field '" +
                                    options.field + "' cannot be chosen");
    Volume volume;
    switch (*format) {
      case io::VolumeFormat::Inrimage:
        volume = io::readInrimage(path, name, progress);
        break;
      case io::VolumeFormat::Invesalius:
        volume = io::readInvesaliusProject(path, name, false, progress).volume;
        break;
      case io::VolumeFormat::OpenVdb:
        volume = io::readOpenVdb(path, name, options.field, progress, options.notes);
        break;
      default:
        volume = io::readVolumeWithVtk(*format, path, name, options.field, progress);
        break;
    }
    volume.name = path.filename().string();
    volume.file = path;
    volume.grid->validate(name);
    // Formats that store no display settings get the default; an InVesalius project has its own.
    if (volume.transfer.points.empty()) volume.transfer = defaultTransfer(*volume.grid, volume.bounds());
    volume.validate();
    progress.step(1.0);
    return volume;
  });
}

std::vector<std::string> supportedVolumeExtensions() {
  std::set<std::string> out;
  for (const io::Extension& e : io::kExtensions) out.insert(e.ext);
  return {out.begin(), out.end()};
}

bool isVolumeFile(const std::filesystem::path& path) {
  return io::volumeFormat(path).has_value();
}

}  // namespace mfr
