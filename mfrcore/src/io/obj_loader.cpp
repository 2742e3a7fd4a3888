#include "obj_loader.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <map>
#include <system_error>
#include <unordered_map>
#include <utility>

#include "mfr/error.hpp"

namespace mfr::io {
namespace {

namespace fs = std::filesystem;

// .mtl files bigger than this are not material libraries.
constexpr std::uintmax_t kMaxMtlBytes = 64u << 20;

std::vector<std::string_view> words(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    if (i < line.size() && line[i] == '#') break;
    const std::size_t start = i;
    while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

bool parseDouble(std::string_view t, double& v) {
  if (!t.empty() && t.front() == '+') t.remove_prefix(1);
  const auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  return ec == std::errc() && ptr == t.data() + t.size() && !t.empty();
}

bool parseInt(std::string_view t, std::int64_t& v) {
  if (!t.empty() && t.front() == '+') t.remove_prefix(1);
  const auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  return ec == std::errc() && ptr == t.data() + t.size() && !t.empty();
}

// Material colours from .mtl files: Kd, and opacity from d (or 1 − Tr).
// Empty `why` when read; else why not (the file is then skipped: only colours are lost). A value
// taken other than as written (outside 0 … 1: clamped; not finite: the default) is in `taken`
// (`Kd nan` and `d 7` were taken without a word: a bug hunt).
std::map<std::string, glm::vec4> readMaterials(const fs::path& file, std::string& why,
                                               std::vector<std::string>& taken) {
  std::map<std::string, glm::vec4> out;
  std::error_code ec;
  why.clear();
  if (!fs::exists(file, ec)) {
    why = "not found";
    return out;
  }
  if (!fs::is_regular_file(file, ec)) {
    why = "not a file";
    return out;
  }
  const std::uintmax_t size = fs::file_size(file, ec);
  if (ec || size > kMaxMtlBytes) {
    why = ec ? "unreadable" : "larger than 64 MiB";
    return out;
  }
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    why = "unreadable";
    return out;
  }
  std::string line;
  std::string current;
  while (std::getline(in, line)) {
    const std::vector<std::string_view> w = words(line);
    if (w.empty()) continue;
    if (w[0] == "newmtl" && w.size() >= 2) {
      current = std::string(w[1]);
      out.emplace(current, glm::vec4(0.8f, 0.8f, 0.8f, 1.0f));
      continue;
    }
    if (current.empty()) continue;
    glm::vec4& c = out[current];
    double v[3];
    const auto check = [&](const double* values, int n) {
      const bool finite = std::all_of(values, values + n, [](double x) { return std::isfinite(x); });
      const bool inRange = std::all_of(values, values + n, [](double x) { return x >= 0.0 && x <= 1.0; });
      if (!finite || !inRange)
        taken.push_back("material '" + current + "': '" + line.substr(0, 64) + "'" +
                        (finite ? ": outside 0 … 1 (clamped)" : ": not a number (ignored)"));
      return finite;
    };
    // `Kd r` is MTL's grey: g and b equal to r (a review: it was noted as "not a number").
    const bool grey = w[0] == "Kd" && w.size() == 2 && parseDouble(w[1], v[0]);
    if (grey) v[1] = v[2] = v[0];
    if (w[0] == "Kd" &&
        (grey || (w.size() >= 4 && parseDouble(w[1], v[0]) && parseDouble(w[2], v[1]) && parseDouble(w[3], v[2])))) {
      if (check(v, 3)) c = glm::vec4(glm::clamp(glm::vec3(v[0], v[1], v[2]), 0.0f, 1.0f), c.a);
    } else if (w[0] == "d" && w.size() >= 2 && parseDouble(w.back(), v[0])) {
      if (check(v, 1)) c.a = static_cast<float>(std::clamp(v[0], 0.0, 1.0));
    } else if (w[0] == "Tr" && w.size() >= 2 && parseDouble(w.back(), v[0])) {
      if (check(v, 1)) c.a = static_cast<float>(1.0 - std::clamp(v[0], 0.0, 1.0));
    } else if (w[0] == "Kd" || w[0] == "d" || w[0] == "Tr") {
      // `Kd abc` was dropped without a word where `Kd nan` was noted (fuzzing); `Kd spectral
      // file.rfl` and `Kd xyz x y z` are MTL too, and not read.
      const bool otherSpace = w[0] == "Kd" && w.size() >= 2 && (w[1] == "spectral" || w[1] == "xyz");
      taken.push_back("material '" + current + "': '" + line.substr(0, 64) + "'" +
                      (otherSpace ? ": not an RGB colour (ignored)" : ": not a number (ignored)"));
    }
  }
  return out;
}

struct Corner {
  std::uint32_t v;
  std::int64_t vn;  // −1 when the corner has none
};

struct RawPart {
  std::string material;
  std::vector<Corner> corners;
  std::vector<std::uint32_t> offsets{0};
};

}  // namespace

std::vector<ObjPart> parseObj(std::string_view bytes, const fs::path& directory, const std::string& name,
                              std::vector<std::string>* notes) {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> vertexColors;
  bool allColored = true;
  std::vector<glm::vec3> normals;
  std::vector<RawPart> parts(1);
  std::map<std::string, std::size_t> partOf{{"", 0}};
  std::size_t notSurfaces = 0;  // l and p elements, and faces of fewer than 3 corners
  bool libraryNamed = false;    // no mtllib: material names are only names, and no note is due
  bool libraryUnread = false;
  std::size_t current = 0;
  std::map<std::string, glm::vec4> materials;
  std::vector<Corner> face;

  std::size_t pos = 0;
  std::size_t lineNo = 0;
  while (pos < bytes.size()) {
    std::size_t end = bytes.find('\n', pos);
    if (end == std::string_view::npos) end = bytes.size();
    const std::string_view line = bytes.substr(pos, end - pos);
    pos = end + 1;
    ++lineNo;
    const std::vector<std::string_view> w = words(line);
    if (w.empty()) continue;
    const auto fail = [&](const std::string& why) -> void {
      throw Error(name, "line " + std::to_string(lineNo) + ": " + why);
    };
    const auto number = [&](std::string_view t) {
      double v = 0.0;
      if (!parseDouble(t, v)) fail("malformed number '" + std::string(t.substr(0, 32)) + "'");
      if (!std::isfinite(v)) fail("non-finite coordinate");
      return v;
    };

    if (w[0] == "v") {
      if (w.size() < 4) fail("vertex with fewer than 3 coordinates");
      positions.emplace_back(number(w[1]), number(w[2]), number(w[3]));
      // "v x y z r g b" is the common vertex-colour extension; "v x y z w" is not colour.
      if (w.size() == 7)
        vertexColors.emplace_back(number(w[4]), number(w[5]), number(w[6]));
      else
        allColored = false;
      for (std::size_t k = 4; k < w.size() && w.size() != 7; ++k) number(w[k]);
    } else if (w[0] == "vn") {
      if (w.size() < 4) fail("normal with fewer than 3 components");
      normals.emplace_back(number(w[1]), number(w[2]), number(w[3]));
    } else if (w[0] == "f") {
      face.clear();
      for (std::size_t k = 1; k < w.size(); ++k) {
        const std::string_view t = w[k];
        const std::size_t s1 = t.find('/');
        std::int64_t v = 0;
        if (!parseInt(t.substr(0, s1), v) || v == 0)
          fail("malformed face corner '" + std::string(t.substr(0, 32)) + "'");
        // Negative indices count back from the last vertex defined so far.
        const std::int64_t vi = v < 0 ? static_cast<std::int64_t>(positions.size()) + v : v - 1;
        if (vi < 0 || vi >= static_cast<std::int64_t>(positions.size()))
          fail("face refers to vertex " + std::to_string(v) + " but there are " + std::to_string(positions.size()) +
               " vertices");
        std::int64_t ni = -1;
        if (s1 != std::string_view::npos) {
          const std::size_t s2 = t.find('/', s1 + 1);
          if (s2 != std::string_view::npos && s2 + 1 < t.size()) {
            std::int64_t n = 0;
            if (!parseInt(t.substr(s2 + 1), n) || n == 0)
              fail("malformed face corner '" + std::string(t.substr(0, 32)) + "'");
            ni = n < 0 ? static_cast<std::int64_t>(normals.size()) + n : n - 1;
            // Normals are optional: an index that leads nowhere loses the normal, not the face.
            if (ni < 0) ni = -1;
          }
        }
        face.push_back({static_cast<std::uint32_t>(vi), ni});
      }
      if (face.size() < 3) {  // points and edges are no surface
        ++notSurfaces;
        continue;
      }
      RawPart& part = parts[current];
      part.corners.insert(part.corners.end(), face.begin(), face.end());
      part.offsets.push_back(static_cast<std::uint32_t>(part.corners.size()));
    } else if (w[0] == "usemtl") {
      const std::string material = w.size() >= 2 ? std::string(w[1]) : std::string();
      auto [it, added] = partOf.emplace(material, parts.size());
      if (added) {
        parts.emplace_back();
        parts.back().material = material;
      }
      current = it->second;
    } else if (w[0] == "mtllib") {
      libraryNamed = libraryNamed || w.size() > 1;
      // Several libraries by the format, one name per word; but Blender writes the name of
      // "my model.mtl" as it is, spaces included: the rest of the line, when it names a file and
      // the words do not (a bug hunt: two libraries 'my' and 'model.mtl' not found).
      std::vector<std::string> libraries;
      for (std::size_t k = 1; k < w.size(); ++k) libraries.emplace_back(w[k]);
      if (libraries.size() > 1) {
        std::string whole(line.substr(static_cast<std::size_t>(w[1].data() - line.data())));
        while (!whole.empty() && std::isspace(static_cast<unsigned char>(whole.back()))) whole.pop_back();
        std::error_code ec;
        const bool wordsExist = std::all_of(libraries.begin(), libraries.end(), [&](const std::string& l) {
          return std::filesystem::is_regular_file(directory / l, ec);
        });
        if (!wordsExist && std::filesystem::is_regular_file(directory / whole, ec)) libraries = {whole};
      }
      for (const std::string& library : libraries) {
        std::string why;
        std::vector<std::string> taken;
        for (auto& [key, c] : readMaterials(directory / library, why, taken)) materials.emplace(key, c);
        libraryUnread = libraryUnread || !why.empty();
        if (!why.empty() && notes != nullptr)
          notes->push_back(name + ": material library '" + library + "' " + why +
                           " (its materials get the default colour)");
        if (notes != nullptr)
          for (const std::string& t : taken) notes->push_back(name + ": " + library + ": " + t);
      }
    }
    // vt, vp, g, o, s and the free-form statements carry nothing we draw; l and p are counted.
    else if (w[0] == "l" || w[0] == "p") {
      ++notSurfaces;
    }
  }
  // Lines and points were dropped without a word (a bug hunt).
  if (notSurfaces > 0 && notes != nullptr)
    notes->push_back(name + ": " + std::to_string(notSurfaces) +
                     (notSurfaces == 1 ? " line or point element (l, p, or a face of fewer than 3 corners) is"
                                       : " line or point elements (l, p, or faces of fewer than 3 corners) are") +
                     " not a surface: left out");

  std::vector<ObjPart> out;
  std::vector<std::string> undefined;
  for (RawPart& raw : parts) {
    if (raw.corners.empty()) continue;
    const bool withNormals = std::all_of(raw.corners.begin(), raw.corners.end(), [&](const Corner& c) {
      return c.vn >= 0 && static_cast<std::size_t>(c.vn) < normals.size();
    });
    const bool withColors = allColored && vertexColors.size() == positions.size();
    ObjPart part;
    part.material = raw.material;
    if (auto m = materials.find(raw.material); m != materials.end())
      part.color = m->second;
    else if (!raw.material.empty())
      undefined.push_back(raw.material);
    // Each part gets the vertices it uses; with normals, a vertex is a (position, normal) pair.
    std::unordered_map<std::uint64_t, std::uint32_t> index;
    part.soup.ids.reserve(raw.corners.size());
    for (const Corner& c : raw.corners) {
      const std::uint64_t key = withNormals ? (std::uint64_t{c.v} << 32 | static_cast<std::uint64_t>(c.vn)) : c.v;
      auto [it, added] = index.emplace(key, static_cast<std::uint32_t>(part.soup.points.size()));
      if (added) {
        part.soup.points.push_back(positions[c.v]);
        if (withNormals) part.soup.normals.push_back(normals[static_cast<std::size_t>(c.vn)]);
        if (withColors) part.soup.colors.emplace_back(glm::clamp(vertexColors[c.v], 0.0f, 1.0f), 1.0f);
      }
      part.soup.ids.push_back(it->second);
    }
    part.soup.offsets = std::move(raw.offsets);
    out.push_back(std::move(part));
  }
  // One note for the materials the libraries, all read, do not define (when one was not read, its
  // note above already says why parts are grey).
  if (!undefined.empty() && libraryNamed && !libraryUnread && notes != nullptr) {
    std::string list;
    for (std::size_t i = 0; i < undefined.size() && i < 5; ++i) list += (i > 0 ? ", '" : "'") + undefined[i] + "'";
    if (undefined.size() > 5) list += " and " + std::to_string(undefined.size() - 5) + " more";
    notes->push_back(name + ": " + std::to_string(undefined.size()) + " material" + (undefined.size() == 1 ? "" : "s") +
                     " defined in no material library (" + list + "): the default colour");
  }
  if (out.empty()) {
    if (positions.empty()) throw Error(name, "no triangles (no vertices or faces: is this an OBJ file?)");
    throw Error(name, "no triangles (the OBJ file has no faces)");
  }
  return out;
}

}  // namespace mfr::io
