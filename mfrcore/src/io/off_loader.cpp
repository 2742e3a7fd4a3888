#include "off_loader.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <iterator>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <system_error>
#include <utility>
#include <vector>

#include <CGAL/IO/OFF.h>
#include <CGAL/IO/Color.h>
#include <CGAL/Simple_cartesian.h>

#include "mfr/error.hpp"

namespace mfr::io {
namespace {

using Kernel = CGAL::Simple_cartesian<double>;

// Skips whitespace and '#' comments; returns the next whitespace-delimited token.
std::string_view nextToken(std::string_view s, std::size_t& pos) {
  while (pos < s.size()) {
    if (std::isspace(static_cast<unsigned char>(s[pos]))) {
      ++pos;
    } else if (s[pos] == '#') {
      while (pos < s.size() && s[pos] != '\n') ++pos;
    } else {
      break;
    }
  }
  const std::size_t start = pos;
  while (pos < s.size() && !std::isspace(static_cast<unsigned char>(s[pos])) && s[pos] != '#') ++pos;
  return s.substr(start, pos - start);
}

bool toCount(std::string_view t, std::uint64_t& out) {
  const auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), out);
  return ec == std::errc() && ptr == t.data() + t.size() && !t.empty();
}

// CGAL sizes each polygon from its face's corner count: a count of 2·10⁹ took 15 GB and half a
// minute before the error (found by fuzzing). ASCII records are lines: after the counts, the
// vertices' lines, then one line per face, whose first number is checked against the bytes left
// (each corner needs at least two). A file laid out otherwise is left to CGAL.
void checkAsciiFaceSizes(std::string_view bytes, std::size_t pos, std::uint64_t vertices, std::uint64_t faces,
                         const std::string& name) {
  std::size_t line = bytes.find('\n', pos);  // the rest of the counts' line
  std::uint64_t records = 0;
  while (line != std::string_view::npos && records < vertices + faces) {
    const std::size_t start = line + 1;
    line = bytes.find('\n', start);
    const std::string_view text = bytes.substr(start, (line == std::string_view::npos ? bytes.size() : line) - start);
    std::size_t at = 0;
    const std::string_view first = nextToken(text, at);
    if (first.empty()) continue;  // blank or a comment
    if (records++ < vertices) continue;
    std::uint64_t corners = 0;
    if (!toCount(first, corners)) {
      // CGAL reads the count as a double: "2e9" or "+2000000000" sized a polygon as well.
      double asRead = 0.0;
      const char* begin = first.data() + (first.front() == '+' ? 1 : 0);
      const auto [end, ec] = std::from_chars(begin, first.data() + first.size(), asRead);
      if (ec != std::errc() || end != first.data() + first.size()) return;  // not a number: CGAL says what is wrong
      if (!(asRead >= 0.0) || asRead != std::floor(asRead))
        throw Error(name, "OFF face " + std::to_string(records - vertices - 1) + " declares " + std::string(first) +
                              " corners (not a count)");
      corners = asRead < 1e19 ? static_cast<std::uint64_t>(asRead) : ~std::uint64_t{0};
    }
    if (corners > (bytes.size() - start) / 2)
      throw Error(name, "OFF face " + std::to_string(records - vertices - 1) + " declares " + std::to_string(corners) +
                            " corners but only " + std::to_string(bytes.size() - start) +
                            " bytes follow (corrupt file?)");
    // Its corners on its line are whole indices: CGAL read "1.9" as 1 and went on with ".9" as
    // nothing (a bug hunt). A face laid over several lines is left to CGAL.
    for (std::uint64_t c = 0; c < corners; ++c) {
      const std::string_view corner = nextToken(text, at);
      if (corner.empty()) break;
      std::uint64_t index = 0;
      if (!toCount(corner, index))
        throw Error(name, "OFF face " + std::to_string(records - vertices - 1) + ": corner '" + std::string(corner) +
                              "' is not a vertex index");
    }
  }
}

// Every number of the vertex and face records after the counts: CGAL's scanner of a coloured file
// (COFF, CNOFF, STCOFF) read a vertex line whose coordinate did not parse ("inf", "nan", "abc",
// "1e400") and then indexed that line's colour past its end — a crash (found by fuzzing); a plain
// OFF file's came out as "malformed". Records are lines, as checkAsciiFaceSizes reads them; what
// follows the last one (an "END" line, a DOS end-of-file byte) is left alone, as CGAL leaves it.
// A number too small for a double is 0, as CGAL reads it.
void checkAsciiNumbers(std::string_view bytes, std::size_t pos, std::uint64_t records, const std::string& name) {
  std::size_t line = 1 + static_cast<std::size_t>(std::count(bytes.begin(), bytes.begin() + pos, '\n'));
  pos = bytes.find('\n', pos);  // the rest of the counts' line
  if (pos == std::string_view::npos) return;
  bool tokens = false;  // on the current line
  while (pos < bytes.size()) {
    const char c = bytes[pos];
    if (c == '\n') {
      if (tokens && --records == 0) return;
      tokens = false;
      ++line;
      ++pos;
    } else if (c == '#') {
      pos = bytes.find('\n', pos);
      if (pos == std::string_view::npos) break;
    } else if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
      ++pos;
    } else {
      const std::size_t end = std::min(bytes.find_first_of(" \t\r\n\f\v#", pos), bytes.size());
      std::string_view token = bytes.substr(pos, end - pos);
      const std::string_view spelled = token;
      if (token.size() > 1 && token.front() == '+') token.remove_prefix(1);
      double value = 0.0;
      auto [at, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
      if (ec == std::errc::result_out_of_range && at == token.data() + token.size()) {
        const std::string spelledOut(token);  // underflow is 0 (strtod says which); overflow is not a number
        value = std::strtod(spelledOut.c_str(), nullptr);
        ec = std::isinf(value) ? ec : std::errc();
      }
      if (ec != std::errc() || at != token.data() + token.size() || !std::isfinite(value)) {
        std::string shown(spelled.substr(0, 40));
        for (char& ch : shown)
          if (static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f) ch = '?';  // a NUL cut the message short
        throw Error(name, "OFF line " + std::to_string(line) + ": '" + shown + "' is not a finite number");
      }
      pos = end;
      tokens = true;
    }
  }
}

// A face's corner indices. CGAL sizes each face from the count it reads, before it reads the
// indices. A binary file's counts are not checked above (its records' length depends on the
// header's flags): a 60-byte file whose face declared 2³¹ − 1 corners took 16 GB and 70 s before
// CGAL's error. This container refuses a count that the file's bytes cannot hold.
struct TooManyCorners {
  std::size_t count;
};
class FaceCorners : public std::vector<std::size_t> {
 public:
  explicit FaceCorners(std::size_t limit = 0) : limit_(limit) {}
  void resize(std::size_t n) {
    if (n > limit_) throw TooManyCorners{n};
    std::vector<std::size_t>::resize(n);
  }

 private:
  std::size_t limit_;
};
class Faces : public std::vector<FaceCorners> {
 public:
  explicit Faces(std::size_t cornerLimit) : cornerLimit_(cornerLimit) {}
  void resize(std::size_t n) { std::vector<FaceCorners>::resize(n, FaceCorners(cornerLimit_)); }

 private:
  std::size_t cornerLimit_;
};

// CGAL sizes its arrays straight from the header counts, so absurd counts (a corrupt or
// truncated file) are rejected here against the bytes actually present.
// Returns where a binary file's vertex data starts (after its three counts), 0 for ASCII.
std::size_t checkHeader(std::string_view bytes, const std::string& name, std::uint64_t& vertices,
                        std::uint64_t& faces) {
  std::size_t pos = 0;
  const std::string_view keyword = nextToken(bytes, pos);
  if (keyword.size() < 3 || keyword.substr(keyword.size() - 3) != "OFF")
    throw Error(name, "not an OFF file (it does not start with an OFF keyword)");
  if (keyword.find('n') != std::string_view::npos) {
    const std::string_view dim = nextToken(bytes, pos);
    if (dim != "3") throw Error(name, "OFF files of dimension " + std::string(dim) + " are not supported");
  }
  std::size_t probe = pos;
  const bool binary = nextToken(bytes, probe) == "BINARY";
  std::uint64_t counts[3] = {0, 0, 0};
  std::uint64_t vertexBytes = 6, faceBytes = 2;  // "0 0 0\n", "0\n": the shortest ASCII records
  if (binary) {
    pos = bytes.find('\n', probe);
    if (pos == std::string_view::npos || bytes.size() - pos - 1 < 12) throw Error(name, "truncated binary OFF header");
    ++pos;
    for (std::uint64_t& c : counts) {
      c = 0;
      for (int k = 0; k < 4; ++k) c = c << 8 | static_cast<unsigned char>(bytes[pos++]);
    }
    vertexBytes = 12;
    faceBytes = 4;
  } else {
    for (std::uint64_t& c : counts)
      if (!toCount(nextToken(bytes, pos), c))
        throw Error(name, "bad OFF header: expected vertex, face and edge counts");
  }
  vertices = counts[0];
  faces = counts[1];
  if (!binary) {
    checkAsciiFaceSizes(bytes, pos, vertices, faces, name);
    if (vertices + faces > 0) checkAsciiNumbers(bytes, pos, vertices + faces, name);
  }
  if (vertices > 0xffffffffull || faces > 0xffffffffull ||
      vertices * vertexBytes + faces * faceBytes > bytes.size() - (binary ? pos : 0))
    throw Error(name, "OFF header declares " + std::to_string(vertices) + " vertices and " + std::to_string(faces) +
                          " faces but the file has only " + std::to_string(bytes.size()) + " bytes (truncated file?)");
  if (faces == 0) throw Error(name, "no triangles (the OFF file has no faces)");
  return binary ? pos : 0;
}

std::uint32_t bigEndian32(std::string_view bytes, std::size_t at) {
  std::uint32_t v = 0;
  for (std::size_t k = 0; k < 4; ++k) v = v << 8 | static_cast<unsigned char>(bytes[at + k]);
  return v;
}

// A binary OFF face is its corner count, the corners, then a colour: a count of 0–4 and that many
// floats (Geomview's OFF format; CGAL's own writer writes the count too). CGAL 5.5's read_OFF does
// not read the colour, so the count was taken for the next face's: a file of two triangles came
// out as one and an empty face, without an error. For a plain "OFF BINARY" file (vertices of three
// floats) laid out so, this returns the file with each face's colour taken out, for CGAL to read;
// for any other layout (CGAL's own dialect without the colour, prefixed keywords, corruption),
// nothing, and CGAL reads the file as it is.
std::optional<std::string> withoutFaceColours(std::string_view bytes, std::size_t data, std::uint64_t vertices,
                                              std::uint64_t faces) {
  if (data > bytes.size() || vertices > (bytes.size() - data) / 12) return std::nullopt;  // cut in the vertices
  std::size_t pos = data + vertices * 12;
  std::string out(bytes.substr(0, pos));
  for (std::uint64_t f = 0; f < faces; ++f) {
    if (bytes.size() - pos < 4) return std::nullopt;
    const std::uint32_t corners = bigEndian32(bytes, pos);
    const std::size_t words = (bytes.size() - pos - 4) / 4;  // for the corners and the colour count
    if (words < 1 || corners > words - 1) return std::nullopt;
    const std::size_t colourAt = pos + 4 + std::size_t{corners} * 4;
    const std::uint32_t colours = bigEndian32(bytes, colourAt);
    if (colours > 4 || bytes.size() - colourAt - 4 < std::size_t{colours} * 4) return std::nullopt;
    out.append(bytes.substr(pos, colourAt - pos));
    pos = colourAt + 4 + std::size_t{colours} * 4;
  }
  if (bytes.substr(pos).find_first_not_of(" \t\r\n") != std::string_view::npos) return std::nullopt;
  return out;
}

// Vertex colours as Geomview's OFF format spells them: a component written with a decimal point or
// an exponent is a float in [0, 1], one of digits only an integer in [0, 255]. CGAL's reader goes by
// the value, so "1.0 1.0 1.0" (white) was read as 1/255 (nearly black). Nullopt where the vertex
// lines are not one per line as x y z [normal] r g b [a] [s t]: CGAL's reading then stands.
std::optional<std::vector<glm::vec4>> asciiVertexColours(std::string_view bytes, std::uint64_t vertexCount) {
  std::size_t pos = 0;
  std::string_view keyword = nextToken(bytes, pos);
  const bool texture = keyword.starts_with("ST");
  if (texture) keyword.remove_prefix(2);
  if (keyword.starts_with("C")) keyword.remove_prefix(1);
  const bool normals = keyword.starts_with("N");
  if (normals) keyword.remove_prefix(1);
  if (keyword != "OFF") return std::nullopt;  // 4OFF, nOFF: other layouts
  for (int i = 0; i < 3; ++i)
    if (nextToken(bytes, pos).empty()) return std::nullopt;
  pos = bytes.find('\n', pos);
  std::vector<glm::vec4> out;
  std::vector<std::string_view> tokens;
  while (pos != std::string_view::npos && out.size() < vertexCount) {
    const std::size_t begin = pos + 1;
    pos = bytes.find('\n', begin);
    std::string_view line = bytes.substr(begin, pos == std::string_view::npos ? std::string_view::npos : pos - begin);
    line = line.substr(0, line.find('#'));
    tokens.clear();
    for (std::size_t at = 0;;) {
      const std::string_view t = nextToken(line, at);
      if (t.empty()) break;
      tokens.push_back(t);
    }
    if (tokens.empty()) continue;
    const std::size_t first = normals ? 6 : 3;
    std::size_t last = tokens.size();
    if (texture) {
      if (last < first + 2) return std::nullopt;
      last -= 2;
    }
    if (last != first + 3 && last != first + 4) return std::nullopt;
    bool spelledAsFloat = false;
    for (std::size_t k = first; k < last; ++k)
      spelledAsFloat = spelledAsFloat || tokens[k].find_first_of(".eE") != std::string_view::npos;
    glm::vec4 colour(1.0f);
    for (std::size_t k = first; k < first + 3; ++k) {
      double v = 0.0;
      std::string_view t = tokens[k];
      if (t.starts_with('+')) t.remove_prefix(1);
      const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
      if (ec != std::errc() || end != t.data() + t.size() || !std::isfinite(v)) return std::nullopt;
      colour[static_cast<int>(k - first)] = static_cast<float>(std::clamp(spelledAsFloat ? v : v / 255.0, 0.0, 1.0));
    }
    out.push_back(colour);
  }
  if (out.size() != vertexCount) return std::nullopt;
  return out;
}

}  // namespace

PolygonSoup parseOff(std::string_view bytes, const std::string& name) {
  std::uint64_t vertexCount = 0, faceCount = 0;
  const std::size_t binaryData = checkHeader(bytes, name, vertexCount, faceCount);
  std::optional<std::string> stripped;
  std::size_t probe = 0;
  if (binaryData > 0 && nextToken(bytes, probe) == "OFF")
    stripped = withoutFaceColours(bytes, binaryData, vertexCount, faceCount);

  std::vector<Kernel::Point_3> points;
  // Each corner takes at least 2 bytes ("0 "), in a binary file 4.
  Faces polygons(bytes.size() / 2);
  std::vector<CGAL::IO::Color> colors;
  std::istringstream in{stripped ? std::move(*stripped) : std::string(bytes), std::ios::in | std::ios::binary};
  bool ok = false;
  try {
    ok = CGAL::IO::read_OFF(in, points, polygons,
                            CGAL::parameters::vertex_color_output_iterator(std::back_inserter(colors)).verbose(false));
  } catch (const TooManyCorners& e) {
    // CGAL widens a binary count as a signed 32-bit number: -3 arrives as 2⁶⁴ − 3.
    const auto count = static_cast<std::int64_t>(e.count);
    throw Error(name, "an OFF face declares " + std::to_string(count) + " corners" +
                          (count < 0 ? " (not a count)"
                                     : ", more than the file's " + std::to_string(bytes.size()) + " bytes hold") +
                          " (corrupt file?)");
  }
  if (!ok || points.size() != vertexCount || polygons.size() != faceCount)
    throw Error(name, "malformed or truncated OFF data (header declares " + std::to_string(vertexCount) +
                          " vertices and " + std::to_string(faceCount) + " faces)");

  PolygonSoup soup;
  soup.points.reserve(points.size());
  for (const Kernel::Point_3& p : points)
    soup.points.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
  if (colors.size() == points.size()) {
    if (std::optional<std::vector<glm::vec4>> spelled =
            binaryData == 0 ? asciiVertexColours(bytes, vertexCount) : std::nullopt) {
      soup.colors = std::move(*spelled);
    } else {
      soup.colors.reserve(colors.size());
      for (const CGAL::IO::Color& c : colors)
        soup.colors.emplace_back(c.red() / 255.0f, c.green() / 255.0f, c.blue() / 255.0f, 1.0f);
    }
  }
  std::vector<std::uint32_t> polygon;
  soup.offsets.reserve(polygons.size() + 1);
  for (const std::vector<std::size_t>& f : polygons) {
    polygon.assign(f.begin(), f.end());  // ids < vertexCount ≤ 2³², checked by read_OFF
    soup.addPolygon(polygon.data(), polygon.size());
  }
  return soup;
}

}  // namespace mfr::io
