#include "vtk_legacy_loader.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <optional>
#include <vector>

#include "mfr/error.hpp"

namespace mfr::io {
namespace {

enum class Scalar { Int8, UInt8, Int16, UInt16, Int32, UInt32, Int64, UInt64, Float32, Float64 };

std::optional<Scalar> parseType(std::string_view t) {
  std::string s(t);
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (s == "char" || s == "vtktypeint8") return Scalar::Int8;
  if (s == "unsigned_char" || s == "vtktypeuint8") return Scalar::UInt8;
  if (s == "short" || s == "vtktypeint16") return Scalar::Int16;
  if (s == "unsigned_short" || s == "vtktypeuint16") return Scalar::UInt16;
  if (s == "int" || s == "vtktypeint32") return Scalar::Int32;
  if (s == "unsigned_int" || s == "vtktypeuint32") return Scalar::UInt32;
  if (s == "long" || s == "vtktypeint64" || s == "vtkidtype") return Scalar::Int64;
  if (s == "unsigned_long" || s == "vtktypeuint64") return Scalar::UInt64;
  if (s == "float" || s == "vtktypefloat32") return Scalar::Float32;
  if (s == "double" || s == "vtktypefloat64") return Scalar::Float64;
  return std::nullopt;
}

std::size_t sizeOf(Scalar s) {
  switch (s) {
    case Scalar::Int8:
    case Scalar::UInt8:
      return 1;
    case Scalar::Int16:
    case Scalar::UInt16:
      return 2;
    case Scalar::Int32:
    case Scalar::UInt32:
    case Scalar::Float32:
      return 4;
    case Scalar::Int64:
    case Scalar::UInt64:
    case Scalar::Float64:
      return 8;
  }
  return 1;
}

class Parser {
 public:
  Parser(std::string_view bytes, const std::string& name) : s_(bytes), name_(name) {}

  [[noreturn]] void fail(const std::string& why) const { throw Error(name_, why); }

  std::string_view line() {
    if (pos_ >= s_.size()) fail("unexpected end of file (truncated?)");
    std::size_t end = s_.find('\n', pos_);
    if (end == std::string_view::npos) end = s_.size();
    std::string_view l = s_.substr(pos_, end - pos_);
    pos_ = std::min(end + 1, s_.size());  // a last line without '\n' ends at the end (token() read past it: fuzzing)
    if (!l.empty() && l.back() == '\r') l.remove_suffix(1);
    return l;
  }

  // The next whitespace-delimited token, or empty at the end.
  std::string_view token() {
    while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_]))) ++pos_;
    const std::size_t start = pos_;
    while (pos_ < s_.size() && !std::isspace(static_cast<unsigned char>(s_[pos_]))) ++pos_;
    return s_.substr(start, pos_ - start);
  }
  std::string_view peek() {
    const std::size_t saved = pos_;
    const std::string_view t = token();
    pos_ = saved;
    return t;
  }
  std::uint64_t count(const char* what) {
    const std::string_view t = token();
    std::uint64_t v = 0;
    const auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
    if (t.empty() || ec != std::errc() || ptr != t.data() + t.size())
      fail(std::string("bad ") + what + " '" + std::string(t.substr(0, 32)) + "'");
    return v;
  }
  // Binary data starts after the line that announced it.
  void skipRestOfLine() {
    const std::size_t end = s_.find('\n', pos_);
    pos_ = end == std::string_view::npos ? s_.size() : end + 1;
  }
  [[nodiscard]] std::size_t remaining() const { return s_.size() - std::min(pos_, s_.size()); }

  // Rejects counts the rest of the file cannot hold, before anything is allocated.
  void requireValues(std::uint64_t n, std::size_t bytesEach, const char* what) const {
    if (bytesEach != 0 && n > remaining() / bytesEach + 1)
      fail(std::string("header declares ") + std::to_string(n) + " " + what + " but only " +
           std::to_string(remaining()) + " bytes follow (truncated file?)");
  }

  double value(Scalar type, bool binary) {
    if (!binary) {
      const std::string_view t = token();
      if (t.empty()) fail("unexpected end of data (truncated file?)");
      std::string_view u = t.front() == '+' ? t.substr(1) : t;
      double v = 0.0;
      const auto [ptr, ec] = std::from_chars(u.data(), u.data() + u.size(), v);
      if (ec != std::errc() || ptr != u.data() + u.size()) fail("bad number '" + std::string(t.substr(0, 32)) + "'");
      return v;
    }
    const std::size_t n = sizeOf(type);
    if (remaining() < n) fail("unexpected end of binary data (truncated file?)");
    std::array<unsigned char, 8> b{};
    std::memcpy(b.data(), s_.data() + pos_, n);
    pos_ += n;
    if constexpr (std::endian::native == std::endian::little)
      std::reverse(b.begin(), b.begin() + static_cast<std::ptrdiff_t>(n));
    switch (type) {
      case Scalar::Int8:
        return static_cast<double>(std::bit_cast<std::int8_t>(b[0]));
      case Scalar::UInt8:
        return static_cast<double>(b[0]);
      case Scalar::Int16:
        return static_cast<double>(load<std::int16_t>(b));
      case Scalar::UInt16:
        return static_cast<double>(load<std::uint16_t>(b));
      case Scalar::Int32:
        return static_cast<double>(load<std::int32_t>(b));
      case Scalar::UInt32:
        return static_cast<double>(load<std::uint32_t>(b));
      case Scalar::Int64:
        return static_cast<double>(load<std::int64_t>(b));
      case Scalar::UInt64:
        return static_cast<double>(load<std::uint64_t>(b));
      case Scalar::Float32:
        return static_cast<double>(load<float>(b));
      case Scalar::Float64:
        return load<double>(b);
    }
    return 0.0;
  }

  Scalar type(std::string_view t) {
    const auto s = parseType(t);
    if (!s) fail("unsupported data type '" + std::string(t.substr(0, 32)) + "'");
    return *s;
  }

 private:
  template <typename T>
  static T load(const std::array<unsigned char, 8>& b) {
    T v;
    std::memcpy(&v, b.data(), sizeof(T));
    return v;
  }

  std::string_view s_;
  std::size_t pos_ = 0;
  const std::string& name_;
};

std::uint32_t toId(double v, Parser& p) {
  if (!(v >= 0.0) || v > 4294967295.0 || v != static_cast<double>(static_cast<std::uint64_t>(v)))
    p.fail("bad point id " + std::to_string(v));
  return static_cast<std::uint32_t>(v);
}

// The cells of each kind the file declares, and for every soup polygon the cell it came from:
// cell data is indexed in VTK's order (vertices, lines, polygons, strips), whatever the file's.
enum CellKind { kVertices = 0, kLines = 1, kPolygons = 2, kStrips = 3 };
struct CellSources {
  std::array<std::uint64_t, 4> counts{};
  std::vector<std::pair<CellKind, std::uint64_t>> polygonCell;  // per soup polygon
  [[nodiscard]] std::uint64_t total() const { return counts[0] + counts[1] + counts[2] + counts[3]; }
  [[nodiscard]] std::uint64_t index(std::size_t polygon) const {
    const auto [kind, i] = polygonCell[polygon];
    std::uint64_t before = 0;
    for (int k = 0; k < kind; ++k) before += counts[static_cast<std::size_t>(k)];
    return before + i;
  }
};

void addCells(PolygonSoup& soup, CellSources& sources, CellKind kind, const std::vector<std::uint64_t>& offsets,
              const std::vector<std::uint32_t>& conn, Parser& p) {
  const bool strips = kind == kStrips;
  const std::uint64_t first = sources.counts[kind];
  for (std::size_t c = 0; c + 1 < offsets.size(); ++c) {
    const std::uint64_t begin = offsets[c], end = offsets[c + 1];
    if (begin > end || end > conn.size()) p.fail("cell offsets out of order or beyond the connectivity");
    if (end - begin < 3) continue;
    if (!strips) {
      soup.addPolygon(conn.data() + begin, static_cast<std::size_t>(end - begin));
      sources.polygonCell.emplace_back(kind, first + c);
      continue;
    }
    for (std::uint64_t k = begin; k + 2 < end; ++k) {
      // Every other strip triangle is wound the other way round.
      const bool odd = ((k - begin) & 1) != 0;
      const std::uint32_t t[3] = {conn[k + (odd ? 1 : 0)], conn[k + (odd ? 0 : 1)], conn[k + 2]};
      soup.addPolygon(t, 3);
      sources.polygonCell.emplace_back(kind, first + c);
    }
  }
}

// One cell block: classic "n size" followed by size values, or 5.1 "nOffsets nConn" followed by
// OFFSETS and CONNECTIVITY arrays.
void readCells(Parser& p, bool binary, PolygonSoup& soup, CellSources& sources, CellKind kind) {
  const std::uint64_t a = p.count("cell count");
  const std::uint64_t b = p.count("cell size");
  std::vector<std::uint64_t> offsets{0};
  std::vector<std::uint32_t> conn;
  if (p.peek() == "OFFSETS") {
    p.token();
    const Scalar ot = p.type(p.token());
    if (binary) p.skipRestOfLine();
    p.requireValues(a, binary ? sizeOf(ot) : 2, "offsets");
    offsets.clear();
    offsets.reserve(a);
    for (std::uint64_t i = 0; i < a; ++i) {
      const double v = p.value(ot, binary);
      if (!(v >= 0.0) || v > 9.0e15) p.fail("bad cell offset");
      offsets.push_back(static_cast<std::uint64_t>(v));
    }
    if (p.token() != "CONNECTIVITY") p.fail("expected CONNECTIVITY after OFFSETS");
    const Scalar ct = p.type(p.token());
    if (binary) p.skipRestOfLine();
    p.requireValues(b, binary ? sizeOf(ct) : 2, "connectivity entries");
    conn.reserve(b);
    for (std::uint64_t i = 0; i < b; ++i) conn.push_back(toId(p.value(ct, binary), p));
    if (offsets.empty()) offsets.push_back(0);
  } else {
    if (binary) p.skipRestOfLine();
    p.requireValues(b, binary ? 4 : 2, "cell entries");
    conn.reserve(b);
    std::uint64_t read = 0;
    for (std::uint64_t c = 0; c < a; ++c) {
      if (read >= b) p.fail("cell list longer than its declared size");
      const double n = p.value(Scalar::Int32, binary);
      ++read;
      if (!(n >= 0.0) || n > static_cast<double>(b - read)) p.fail("bad cell size");
      for (std::uint64_t k = 0; k < static_cast<std::uint64_t>(n); ++k)
        conn.push_back(toId(p.value(Scalar::Int32, binary), p));
      read += static_cast<std::uint64_t>(n);
      offsets.push_back(conn.size());
    }
  }
  if (kind == kPolygons || kind == kStrips) addCells(soup, sources, kind, offsets, conn, p);
  sources.counts[kind] += offsets.size() - 1;
}

void skipMetadata(Parser& p) {
  // METADATA blocks end with an empty line.
  p.skipRestOfLine();
  while (p.remaining() > 0 && !p.line().empty()) {
  }
}

// FIELD blocks: named arrays of "name components tuples type" and their values.
void skipField(Parser& p, bool binary) {
  p.token();  // field name
  const std::uint64_t arrays = p.count("field array count");
  for (std::uint64_t i = 0; i < arrays; ++i) {
    p.token();  // array name
    const std::uint64_t components = p.count("component count");
    const std::uint64_t tuples = p.count("tuple count");
    const Scalar t = p.type(p.token());
    if (components > (std::uint64_t{1} << 20)) p.fail("bad component count");
    if (binary) p.skipRestOfLine();
    p.requireValues(tuples, components * (binary ? sizeOf(t) : 2), "field tuples");
    for (std::uint64_t k = 0; k < components * tuples; ++k) p.value(t, binary);
    if (p.peek() == "METADATA") {
      p.token();
      skipMetadata(p);
    }
  }
}

// "%20"-style escapes in legacy array names (VTK writes spaces and other specials that way).
std::string decodeName(std::string_view t) {
  std::string out;
  for (std::size_t i = 0; i < t.size(); ++i) {
    int hex = 0;
    if (t[i] == '%' && i + 2 < t.size() &&
        std::from_chars(t.data() + i + 1, t.data() + i + 3, hex, 16).ptr == t.data() + i + 3) {
      out += static_cast<char>(hex);
      i += 2;
    } else {
      out += t[i];
    }
  }
  return out;
}

// tuples × components values of type t, the header line already consumed.
std::vector<float> readValues(Parser& p, bool binary, Scalar t, std::uint64_t tuples, std::uint64_t components) {
  if (components == 0 || components > 64) p.fail("bad component count " + std::to_string(components));
  p.requireValues(tuples, components * (binary ? sizeOf(t) : 2), "data values");
  std::vector<float> v;
  v.reserve(tuples * components);
  for (std::uint64_t k = 0; k < tuples * components; ++k) v.push_back(static_cast<float>(p.value(t, binary)));
  return v;
}

// The POINT_DATA / CELL_DATA sections after the geometry, from `keyword` on: SCALARS, VECTORS,
// TENSORS and FIELD arrays become soup fields (cell data mapped from VTK's cell order to the
// soup's polygons), point COLOR_SCALARS of 3 or 4 values the soup's colours; NORMALS,
// TEXTURE_COORDINATES, LOOKUP_TABLE and METADATA are read past; another keyword ends the reading.
void readDataSections(Parser& p, bool binary, std::string_view keyword, PolygonSoup& soup, const CellSources& sources) {
  bool cells = false;
  std::uint64_t tuples = 0;
  bool inSection = false;
  const auto add = [&](std::string name, std::uint64_t components, std::vector<float> values) {
    MeshField f{std::move(name), cells, static_cast<int>(components), {}};
    if (!cells) {
      f.values = std::move(values);
    } else {
      f.values.reserve(soup.polygonCount() * components);
      for (std::size_t poly = 0; poly < soup.polygonCount(); ++poly) {
        const std::uint64_t c = sources.index(poly);
        f.values.insert(f.values.end(), values.begin() + static_cast<std::ptrdiff_t>(c * components),
                        values.begin() + static_cast<std::ptrdiff_t>((c + 1) * components));
      }
    }
    soup.fields.push_back(std::move(f));
  };
  for (; !keyword.empty(); keyword = p.token()) {
    if (keyword == "POINT_DATA" || keyword == "CELL_DATA") {
      cells = keyword == "CELL_DATA";
      tuples = p.count(cells ? "cell data count" : "point data count");
      const std::uint64_t expected = cells ? sources.total() : soup.points.size();
      if (tuples != expected)
        p.fail(std::string(keyword) + " " + std::to_string(tuples) + " differs from the " + std::to_string(expected) +
               (cells ? " cells" : " points") + " of the file");
      inSection = true;
      continue;
    }
    if (!inSection) p.fail("unexpected keyword '" + std::string(keyword.substr(0, 32)) + "' in legacy VTK POLYDATA");
    if (keyword == "SCALARS") {
      std::string name = decodeName(p.token());
      const Scalar t = p.type(p.token());
      const std::string_view rest = p.line();  // an optional component count
      std::uint64_t components = 1;
      if (const std::size_t digit = rest.find_first_not_of(" \t"); digit != std::string_view::npos) {
        const auto [ptr, ec] = std::from_chars(rest.data() + digit, rest.data() + rest.size(), components);
        if (ec != std::errc()) p.fail("bad SCALARS component count");
      }
      if (p.peek() == "LOOKUP_TABLE") {
        p.token();
        p.token();
        p.skipRestOfLine();
      }
      add(std::move(name), components, readValues(p, binary, t, tuples, components));
    } else if (keyword == "VECTORS" || keyword == "NORMALS" || keyword == "TENSORS" || keyword == "TENSORS6") {
      std::string name = decodeName(p.token());
      const Scalar t = p.type(p.token());
      p.skipRestOfLine();
      const std::uint64_t components = keyword == "TENSORS" ? 9 : keyword == "TENSORS6" ? 6 : 3;
      std::vector<float> values = readValues(p, binary, t, tuples, components);
      if (keyword != "NORMALS") add(std::move(name), components, std::move(values));
    } else if (keyword == "TEXTURE_COORDINATES") {
      p.token();
      const std::uint64_t dim = p.count("texture dimension");
      const Scalar t = p.type(p.token());
      p.skipRestOfLine();
      readValues(p, binary, t, tuples, dim);
    } else if (keyword == "COLOR_SCALARS") {
      p.token();
      const std::uint64_t components = p.count("colour component count");
      p.skipRestOfLine();
      // Bytes in binary files, values in [0, 1] in ASCII ones.
      std::vector<float> values = readValues(p, binary, binary ? Scalar::UInt8 : Scalar::Float32, tuples, components);
      if (!cells && (components == 3 || components == 4)) {
        soup.colors.assign(tuples, glm::vec4(1.0f));
        for (std::uint64_t i = 0; i < tuples; ++i)
          for (std::uint64_t c = 0; c < components; ++c)
            soup.colors[i][static_cast<int>(c)] =
                std::clamp(values[i * components + c] / (binary ? 255.0f : 1.0f), 0.0f, 1.0f);
      }
    } else if (keyword == "LOOKUP_TABLE") {
      p.token();
      const std::uint64_t size = p.count("lookup table size");
      p.skipRestOfLine();
      readValues(p, binary, binary ? Scalar::UInt8 : Scalar::Float32, size, 4);
    } else if (keyword == "FIELD") {
      p.token();  // field name
      const std::uint64_t arrays = p.count("field array count");
      for (std::uint64_t i = 0; i < arrays; ++i) {
        std::string name = decodeName(p.token());
        const std::uint64_t components = p.count("component count");
        const std::uint64_t n = p.count("tuple count");
        const Scalar t = p.type(p.token());
        p.skipRestOfLine();
        std::vector<float> values = readValues(p, binary, t, n, components);
        if (n == tuples) add(std::move(name), components, std::move(values));  // else not per point or cell
        if (p.peek() == "METADATA") {
          p.token();
          skipMetadata(p);
        }
      }
    } else if (keyword == "METADATA") {
      skipMetadata(p);
    } else {
      // An attribute this reader does not know (GLOBAL_IDS, EDGE_FLAGS, …): the geometry and the
      // fields before it are kept; its size is unknown, so reading stops here.
      return;
    }
  }
}

}  // namespace

PolygonSoup parseLegacyVtk(std::string_view bytes, const std::string& name) {
  Parser p(bytes, name);
  if (p.line().rfind("# vtk DataFile", 0) != 0) p.fail("not a legacy VTK file (no '# vtk DataFile' header)");
  p.line();  // title
  std::string_view format = p.token();
  if (format.empty()) p.fail("unexpected end of file after the title (truncated?)");
  bool binary = false;
  if (format == "BINARY")
    binary = true;
  else if (format != "ASCII")
    p.fail("not a legacy VTK file (expected ASCII or BINARY, found '" + std::string(format.substr(0, 32)) + "')");
  if (p.token() != "DATASET") p.fail("not a legacy VTK dataset (no DATASET line)");
  const std::string_view type = p.token();
  if (type != "POLYDATA")
    p.fail("legacy VTK dataset type '" + std::string(type.substr(0, 32)) + "' is not supported (only POLYDATA)");

  PolygonSoup soup;
  CellSources sources;
  bool havePoints = false;
  std::string_view keyword;
  while (true) {
    keyword = p.token();
    if (keyword.empty() || keyword == "POINT_DATA" || keyword == "CELL_DATA") break;
    if (keyword == "POINTS") {
      const std::uint64_t n = p.count("point count");
      const Scalar t = p.type(p.token());
      if (binary) p.skipRestOfLine();
      p.requireValues(n, 3 * (binary ? sizeOf(t) : 2), "points");
      soup.points.reserve(n);
      for (std::uint64_t i = 0; i < n; ++i) {
        const double x = p.value(t, binary), y = p.value(t, binary), z = p.value(t, binary);
        soup.points.emplace_back(x, y, z);
      }
      havePoints = true;
    } else if (keyword == "POLYGONS" || keyword == "TRIANGLE_STRIPS" || keyword == "VERTICES" || keyword == "LINES") {
      const CellKind kind = keyword == "POLYGONS"          ? kPolygons
                            : keyword == "TRIANGLE_STRIPS" ? kStrips
                            : keyword == "VERTICES"        ? kVertices
                                                           : kLines;
      readCells(p, binary, soup, sources, kind);
    } else if (keyword == "FIELD") {
      skipField(p, binary);
    } else if (keyword == "METADATA") {
      skipMetadata(p);
    } else {
      p.fail("unexpected keyword '" + std::string(keyword.substr(0, 32)) + "' in legacy VTK POLYDATA");
    }
  }
  if (!havePoints) p.fail("no POINTS in legacy VTK POLYDATA");
  if (soup.polygonCount() == 0) p.fail("no triangles (no POLYGONS or TRIANGLE_STRIPS)");
  readDataSections(p, binary, keyword, soup, sources);
  return soup;
}

}  // namespace mfr::io
