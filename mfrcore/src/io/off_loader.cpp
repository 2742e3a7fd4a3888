#include "off_loader.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <system_error>
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
  }
}

// CGAL sizes its arrays straight from the header counts, so absurd counts (a corrupt or
// truncated file) are rejected here against the bytes actually present.
void checkHeader(std::string_view bytes, const std::string& name, std::uint64_t& vertices, std::uint64_t& faces) {
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
      if (!toCount(nextToken(bytes, pos), c)) throw Error(name, "bad OFF header: expected vertex, face and edge counts");
  }
  vertices = counts[0];
  faces = counts[1];
  if (!binary) checkAsciiFaceSizes(bytes, pos, vertices, faces, name);
  if (vertices > 0xffffffffull || faces > 0xffffffffull ||
      vertices * vertexBytes + faces * faceBytes > bytes.size())
    throw Error(name, "OFF header declares " + std::to_string(vertices) + " vertices and " + std::to_string(faces) +
                          " faces but the file has only " + std::to_string(bytes.size()) + " bytes (truncated file?)");
  if (faces == 0) throw Error(name, "no triangles (the OFF file has no faces)");
}

}  // namespace

PolygonSoup parseOff(std::string_view bytes, const std::string& name) {
  std::uint64_t vertexCount = 0, faceCount = 0;
  checkHeader(bytes, name, vertexCount, faceCount);

  std::vector<Kernel::Point_3> points;
  std::vector<std::vector<std::size_t>> polygons;
  std::vector<CGAL::IO::Color> colors;
  std::istringstream in{std::string(bytes), std::ios::in | std::ios::binary};
  bool ok = false;
  try {
    ok = CGAL::IO::read_OFF(in, points, polygons,
                            CGAL::parameters::vertex_color_output_iterator(std::back_inserter(colors)).verbose(false));
  } catch (const std::length_error&) {
    // A binary face's corner count read as a negative 32-bit number sizes a vector past max_size().
    ok = false;
  }
  if (!ok || points.size() != vertexCount || polygons.size() != faceCount)
    throw Error(name, "malformed or truncated OFF data (header declares " + std::to_string(vertexCount) +
                          " vertices and " + std::to_string(faceCount) + " faces)");

  PolygonSoup soup;
  soup.points.reserve(points.size());
  for (const Kernel::Point_3& p : points)
    soup.points.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
  if (colors.size() == points.size()) {
    soup.colors.reserve(colors.size());
    for (const CGAL::IO::Color& c : colors)
      soup.colors.emplace_back(c.red() / 255.0f, c.green() / 255.0f, c.blue() / 255.0f, 1.0f);
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
