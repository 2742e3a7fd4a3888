#include "ply_loader.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <optional>
#include <utility>
#include <vector>

#include "mfr/error.hpp"

namespace mfr::io {
namespace {

enum class Encoding { Ascii, BinaryLittleEndian, BinaryBigEndian };
enum class Type { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

std::optional<Type> parseType(std::string_view s) {
  if (s == "char" || s == "int8") return Type::Int8;
  if (s == "uchar" || s == "uint8") return Type::UInt8;
  if (s == "short" || s == "int16") return Type::Int16;
  if (s == "ushort" || s == "uint16") return Type::UInt16;
  if (s == "int" || s == "int32") return Type::Int32;
  if (s == "uint" || s == "uint32") return Type::UInt32;
  if (s == "float" || s == "float32") return Type::Float32;
  if (s == "double" || s == "float64") return Type::Float64;
  return std::nullopt;
}

std::size_t sizeOf(Type t) {
  switch (t) {
    case Type::Int8:
    case Type::UInt8:
      return 1;
    case Type::Int16:
    case Type::UInt16:
      return 2;
    case Type::Int32:
    case Type::UInt32:
    case Type::Float32:
      return 4;
    case Type::Float64:
      return 8;
  }
  return 1;
}

// Scale that maps an integer colour channel to [0,1]; floats are taken as they are.
double colorScale(Type t) {
  switch (t) {
    case Type::Int8:
    case Type::UInt8:
      return 1.0 / 255.0;
    case Type::Int16:
    case Type::UInt16:
      return 1.0 / 65535.0;
    default:
      return 1.0;
  }
}

// The values an integer type holds, for ASCII data (binary data holds nothing else).
std::optional<std::pair<double, double>> integerRange(Type t) {
  switch (t) {
    case Type::Int8:
      return std::pair{-128.0, 127.0};
    case Type::UInt8:
      return std::pair{0.0, 255.0};
    case Type::Int16:
      return std::pair{-32768.0, 32767.0};
    case Type::UInt16:
      return std::pair{0.0, 65535.0};
    case Type::Int32:
      return std::pair{-2147483648.0, 2147483647.0};
    case Type::UInt32:
      return std::pair{0.0, 4294967295.0};
    default:
      return std::nullopt;
  }
}

struct Property {
  std::string name;
  bool list = false;
  Type countType = Type::UInt8;
  Type type = Type::Float32;
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
};

std::vector<std::string_view> words(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    const std::size_t start = i;
    while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

// Reads the values of the data section, ASCII or binary, and fails with the element and item
// where the data ran out or was malformed.
class Reader {
 public:
  Reader(std::string_view data, Encoding encoding, const std::string& name)
      : data_(data), encoding_(encoding), name_(name) {}

  void setContext(const std::string& element, std::uint64_t item) {
    element_ = &element;
    item_ = item;
  }
  [[nodiscard]] std::size_t remaining() const { return data_.size() - pos_; }

  // `whole`: an ASCII value must be a whole number in the type's range (colours: scaled by it).
  double read(Type t, bool whole = false) { return encoding_ == Encoding::Ascii ? readAscii(t, whole) : readBinary(t); }

  [[noreturn]] void fail(const std::string& what) const {
    throw Error(name_,
                what + " in PLY element '" + (element_ ? *element_ : std::string("?")) + "' " + std::to_string(item_));
  }

 private:
  // A colour of an integer type is a whole number in its range: "nan", 300 or −1 for a uchar colour
  // came out as NaN shading or a silent clamp (fuzzing). Other properties are data the loader
  // keeps as read (a `uint flags` of −1 refused the file; a review).
  double readAscii(Type t, bool whole) {
    while (pos_ < data_.size() && std::isspace(static_cast<unsigned char>(data_[pos_]))) ++pos_;
    if (pos_ == data_.size()) fail("unexpected end of data (truncated file?)");
    std::size_t end = pos_;
    while (end < data_.size() && !std::isspace(static_cast<unsigned char>(data_[end]))) ++end;
    const char* first = data_.data() + pos_;
    const char* last = data_.data() + end;
    if (*first == '+') ++first;  // from_chars rejects an explicit plus sign
    double value = 0.0;
    const auto [ptr, ec] = std::from_chars(first, last, value);
    const std::string token(data_.substr(pos_, std::min<std::size_t>(end - pos_, 32)));
    if (ec != std::errc() || ptr != last) fail("bad number '" + token + "'");
    if (const auto range = whole ? integerRange(t) : std::nullopt;
        range && !(value >= range->first && value <= range->second && value == std::floor(value)))
      fail("'" + token + "' is not a whole number in [" + std::to_string(static_cast<long long>(range->first)) + ", " +
           std::to_string(static_cast<long long>(range->second)) + "] (its property's type)");
    pos_ = end;
    return value;
  }

  double readBinary(Type t) {
    const std::size_t n = sizeOf(t);
    if (remaining() < n) fail("unexpected end of data (truncated file?)");
    std::array<unsigned char, 8> b{};
    std::memcpy(b.data(), data_.data() + pos_, n);
    pos_ += n;
    const bool swap = (encoding_ == Encoding::BinaryBigEndian) != (std::endian::native == std::endian::big);
    if (swap) std::reverse(b.begin(), b.begin() + static_cast<std::ptrdiff_t>(n));
    switch (t) {
      case Type::Int8:
        return static_cast<double>(std::bit_cast<std::int8_t>(b[0]));
      case Type::UInt8:
        return static_cast<double>(b[0]);
      case Type::Int16:
        return static_cast<double>(load<std::int16_t>(b));
      case Type::UInt16:
        return static_cast<double>(load<std::uint16_t>(b));
      case Type::Int32:
        return static_cast<double>(load<std::int32_t>(b));
      case Type::UInt32:
        return static_cast<double>(load<std::uint32_t>(b));
      case Type::Float32:
        return static_cast<double>(load<float>(b));
      case Type::Float64:
        return load<double>(b);
    }
    return 0.0;
  }

  template <typename T>
  static T load(const std::array<unsigned char, 8>& b) {
    T v;
    std::memcpy(&v, b.data(), sizeof(T));
    return v;
  }

  std::string_view data_;
  std::size_t pos_ = 0;
  Encoding encoding_;
  const std::string& name_;
  const std::string* element_ = nullptr;
  std::uint64_t item_ = 0;
};

struct Header {
  Encoding encoding = Encoding::Ascii;
  std::vector<Element> elements;
  std::size_t dataStart = 0;
};

Header parseHeader(std::string_view bytes, const std::string& name) {
  if (bytes.size() < 4 || bytes.substr(0, 3) != "ply" || (bytes[3] != '\n' && bytes[3] != '\r'))
    throw Error(name, "not a PLY file (it does not start with 'ply')");
  Header h;
  bool haveFormat = false;
  std::size_t pos = 0;
  int lineNo = 0;
  while (true) {
    if (pos >= bytes.size()) throw Error(name, "PLY header has no end_header line");
    std::size_t end = bytes.find('\n', pos);
    if (end == std::string_view::npos) end = bytes.size();
    std::string_view line = bytes.substr(pos, end - pos);
    pos = end + 1;
    ++lineNo;
    if (lineNo == 1) continue;  // "ply"
    const std::vector<std::string_view> w = words(line);
    const auto bad = [&](const std::string& why) {
      std::string shown(line.substr(0, 60));
      for (char& c : shown)
        if (!std::isprint(static_cast<unsigned char>(c))) c = '?';
      throw Error(name, "bad PLY header line " + std::to_string(lineNo) + " '" + shown + "': " + why);
    };
    if (w.empty()) continue;
    if (w[0] == "end_header") {
      h.dataStart = std::min(pos, bytes.size());
      break;
    }
    if (w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "format") {
      if (w.size() < 2) bad("missing format");
      if (w[1] == "ascii")
        h.encoding = Encoding::Ascii;
      else if (w[1] == "binary_little_endian")
        h.encoding = Encoding::BinaryLittleEndian;
      else if (w[1] == "binary_big_endian")
        h.encoding = Encoding::BinaryBigEndian;
      else
        bad("unknown format");
      haveFormat = true;
    } else if (w[0] == "element") {
      if (w.size() != 3) bad("expected 'element <name> <count>'");
      Element e;
      e.name = std::string(w[1]);
      const auto [ptr, ec] = std::from_chars(w[2].data(), w[2].data() + w[2].size(), e.count);
      if (ec != std::errc() || ptr != w[2].data() + w[2].size()) bad("bad element count");
      h.elements.push_back(std::move(e));
    } else if (w[0] == "property") {
      if (h.elements.empty()) bad("property before any element");
      Property p;
      if (w.size() == 5 && w[1] == "list") {
        const auto ct = parseType(w[2]);
        const auto it = parseType(w[3]);
        if (!ct || !it) bad("unknown property type");
        if (*ct == Type::Float32 || *ct == Type::Float64) bad("list count must be an integer type");
        p.list = true;
        p.countType = *ct;
        p.type = *it;
        p.name = std::string(w[4]);
      } else if (w.size() == 3) {
        const auto t = parseType(w[1]);
        if (!t) bad("unknown property type");
        p.type = *t;
        p.name = std::string(w[2]);
      } else {
        bad("expected 'property <type> <name>' or 'property list <type> <type> <name>'");
      }
      h.elements.back().properties.push_back(std::move(p));
    }
    // Other lines carry no structure; old writers (Blender 2.4x) put comments there without the
    // "comment" keyword, so they are skipped like comments.
  }
  if (!haveFormat) throw Error(name, "PLY header has no format line");
  return h;
}

// Bytes one item of an element needs at least: rejects absurd header counts before anything is
// allocated or looped over.
std::size_t minimumItemBytes(const Element& e, Encoding encoding) {
  std::size_t n = 0;
  for (const Property& p : e.properties) n += encoding == Encoding::Ascii ? 2 : sizeOf(p.list ? p.countType : p.type);
  return n;
}

std::uint32_t toIndex(double v, Reader& reader) {
  if (!(v >= 0.0) || v > 4294967295.0 || v != std::floor(v)) reader.fail("bad vertex index " + std::to_string(v));
  return static_cast<std::uint32_t>(v);
}

}  // namespace

PolygonSoup parsePly(std::string_view bytes, const std::string& name) {
  const Header h = parseHeader(bytes, name);
  const std::string_view data = bytes.substr(h.dataStart);

  const Element* vertexElement = nullptr;
  const Element* faceElement = nullptr;
  for (const Element& e : h.elements) {
    if (e.name == "vertex" && !vertexElement) vertexElement = &e;
    if (e.name == "face" && !faceElement) faceElement = &e;
  }
  if (vertexElement == nullptr) throw Error(name, "PLY has no vertex element");

  // Which property of the vertex element feeds which attribute.
  auto find = [](const Element& e, std::initializer_list<const char*> names) -> int {
    for (const char* n : names)
      for (std::size_t i = 0; i < e.properties.size(); ++i)
        if (!e.properties[i].list && e.properties[i].name == n) return static_cast<int>(i);
    return -1;
  };
  const int px = find(*vertexElement, {"x"}), py = find(*vertexElement, {"y"}), pz = find(*vertexElement, {"z"});
  if (px < 0 || py < 0 || pz < 0) throw Error(name, "PLY vertex element lacks x, y or z");
  const int nx = find(*vertexElement, {"nx"}), ny = find(*vertexElement, {"ny"}), nz = find(*vertexElement, {"nz"});
  const int cr = find(*vertexElement, {"red", "diffuse_red", "r"});
  const int cg = find(*vertexElement, {"green", "diffuse_green", "g"});
  const int cb = find(*vertexElement, {"blue", "diffuse_blue", "b"});
  const int ca = find(*vertexElement, {"alpha", "diffuse_alpha", "a"});
  const bool hasNormals = nx >= 0 && ny >= 0 && nz >= 0;
  const bool hasColors = cr >= 0 && cg >= 0 && cb >= 0;
  // Every other scalar property is a field to colour by (MeshLab's "quality", a scanner's
  // "confidence" or "intensity"): per vertex, and per face for the face element's scalars.
  struct FieldProperty {
    std::size_t property;
    std::size_t field;
  };
  std::vector<FieldProperty> vertexFields, faceFields;
  PolygonSoup soup;
  for (std::size_t i = 0; i < vertexElement->properties.size(); ++i) {
    const int index = static_cast<int>(i);
    if (vertexElement->properties[i].list || index == px || index == py || index == pz ||
        (hasNormals && (index == nx || index == ny || index == nz)) ||
        (hasColors && (index == cr || index == cg || index == cb || index == ca)))
      continue;
    vertexFields.push_back({i, soup.fields.size()});
    soup.fields.push_back(MeshField{vertexElement->properties[i].name, false, 1, {}});
  }

  int faceList = -1;
  if (faceElement != nullptr) {
    for (std::size_t i = 0; i < faceElement->properties.size(); ++i) {
      const Property& p = faceElement->properties[i];
      if (p.list && (p.name == "vertex_indices" || p.name == "vertex_index")) faceList = static_cast<int>(i);
    }
    if (faceList < 0) throw Error(name, "PLY face element has no vertex_indices list");
  }
  if (faceElement == nullptr || faceElement->count == 0) throw Error(name, "no triangles (the PLY file has no faces)");
  for (std::size_t i = 0; i < faceElement->properties.size(); ++i)
    if (!faceElement->properties[i].list) {
      faceFields.push_back({i, soup.fields.size()});
      soup.fields.push_back(MeshField{faceElement->properties[i].name, true, 1, {}});
    }

  // Header counts against the data size, before anything is allocated.
  {
    std::size_t needed = 0;
    for (const Element& e : h.elements) {
      const std::size_t per = minimumItemBytes(e, h.encoding);
      if (per == 0) continue;
      if (e.count > (data.size() + 1) / per || needed + e.count * per > data.size() + 1)
        throw Error(name, "PLY header declares " + std::to_string(e.count) + " '" + e.name + "' items but only " +
                              std::to_string(data.size()) + " bytes of data follow (truncated file?)");
      needed += e.count * per;
    }
  }

  soup.points.reserve(vertexElement->count);
  if (hasNormals) soup.normals.reserve(vertexElement->count);
  if (hasColors) soup.colors.reserve(vertexElement->count);
  soup.offsets.reserve(faceElement->count + 1);
  soup.ids.reserve(3 * faceElement->count);

  Reader reader(data, h.encoding, name);
  std::vector<double> values;
  std::vector<std::uint32_t> polygon;
  for (const Element& e : h.elements) {
    if (e.properties.empty()) continue;
    values.assign(e.properties.size(), 0.0);
    const bool isVertex = &e == vertexElement;
    const bool isFace = &e == faceElement;
    for (std::uint64_t item = 0; item < e.count; ++item) {
      reader.setContext(e.name, item);
      for (std::size_t pi = 0; pi < e.properties.size(); ++pi) {
        const Property& p = e.properties[pi];
        if (!p.list) {
          const auto index = static_cast<int>(pi);
          values[pi] =
              reader.read(p.type, isVertex && hasColors && (index == cr || index == cg || index == cb || index == ca));
          continue;
        }
        const double countValue = reader.read(p.countType);
        if (!(countValue >= 0.0) || countValue != std::floor(countValue)) reader.fail("bad list length");
        const auto count = static_cast<std::uint64_t>(countValue);
        // A list cannot be longer than the data left (each entry takes at least one byte).
        if (count > reader.remaining())
          reader.fail("unexpected end of data (truncated file?): a list of " + std::to_string(count) + " entries");
        const bool keep = isFace && static_cast<int>(pi) == faceList;
        if (keep) polygon.clear();
        for (std::uint64_t k = 0; k < count; ++k) {
          const double v = reader.read(p.type);
          if (keep) polygon.push_back(toIndex(v, reader));
        }
        if (keep) soup.addPolygon(polygon.data(), polygon.size());
      }
      if (isFace)
        for (const FieldProperty& f : faceFields)
          soup.fields[f.field].values.push_back(static_cast<float>(values[f.property]));
      if (isVertex) {
        for (const FieldProperty& f : vertexFields)
          soup.fields[f.field].values.push_back(static_cast<float>(values[f.property]));
        soup.points.emplace_back(values[static_cast<std::size_t>(px)], values[static_cast<std::size_t>(py)],
                                 values[static_cast<std::size_t>(pz)]);
        if (hasNormals)
          soup.normals.emplace_back(values[static_cast<std::size_t>(nx)], values[static_cast<std::size_t>(ny)],
                                    values[static_cast<std::size_t>(nz)]);
        if (hasColors) {
          const auto channel = [&](int index) {
            const auto i = static_cast<std::size_t>(index);
            // std::clamp passes NaN through: NaN shading, exit 0 (fuzzing).
            if (!std::isfinite(values[i])) reader.fail("non-finite colour '" + e.properties[i].name + "'");
            return static_cast<float>(std::clamp(values[i] * colorScale(e.properties[i].type), 0.0, 1.0));
          };
          soup.colors.emplace_back(channel(cr), channel(cg), channel(cb), ca >= 0 ? channel(ca) : 1.0f);
        }
      }
    }
  }
  return soup;
}

}  // namespace mfr::io
