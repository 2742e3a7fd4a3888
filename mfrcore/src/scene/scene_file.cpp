// The .mfrscene format: see docs/scene-format.md. Every error names the file and the JSON path.
#include "mfr/scene/scene_file.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <system_error>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include "common/bindings.h"
#include "mfr/error.hpp"
#include "mfr/host_memory.hpp"
#include "mfr/io/load.hpp"
#include "mfr/io_util.hpp"
#include "mfr/json_text.hpp"
#include "mfr/scene/clip_box.hpp"
#include "mfr/scene/color_map.hpp"
#include "mfr/scene/contour.hpp"
#include "mfr/scene/csg.hpp"
#include "mfr/scene/primitives.hpp"
#include "mfr/scene/sample.hpp"

namespace mfr {
namespace {

using nlohmann::json;

// A key given twice in one JSON object: nlohmann keeps the last, and a second "objects" array
// dropped the first without a word (a bug hunt). `where` is the key's path ("objects[1].opacity").
struct RepeatedKey {
  std::string where;
};
// A number beyond double precision, at `where` (it was said without saying where; a bug hunt).
struct NumberOutOfRange {
  std::string where;
};

// Parses `text` as JSON, throwing RepeatedKey for a key given twice in one object and
// NumberOutOfRange for a number beyond a double.
json parseWithoutRepeatedKeys(const std::string& text) {
  struct Level {
    bool object = false;
    std::set<std::string> keys;
    std::string key;        // an object's current key
    std::size_t index = 0;  // an array's current element
  };
  std::vector<Level> levels;
  // The path of the value being read: each level's current key or element.
  const auto here = [&levels] {
    std::string where;
    for (std::size_t i = 0; i < levels.size(); ++i)
      where +=
          levels[i].object ? (where.empty() ? "" : ".") + levels[i].key : "[" + std::to_string(levels[i].index) + "]";
    return where;
  };
  try {
    return json::parse(text, [&](int, json::parse_event_t event, json& parsed) {
      switch (event) {
        case json::parse_event_t::object_start:
        case json::parse_event_t::array_start:
          levels.push_back({event == json::parse_event_t::object_start, {}, {}, 0});
          break;
        case json::parse_event_t::key: {
          Level& level = levels.back();
          level.key = parsed.get<std::string>();
          if (!level.keys.insert(level.key).second) throw RepeatedKey{here()};
          break;
        }
        case json::parse_event_t::object_end:
        case json::parse_event_t::array_end:
        case json::parse_event_t::value:
          if (event != json::parse_event_t::value) levels.pop_back();
          if (!levels.empty() && !levels.back().object) ++levels.back().index;
          break;
      }
      return true;
    });
  } catch (const json::out_of_range&) {
    throw NumberOutOfRange{here()};
  }
}

class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& where, const std::string& reason) const {
    // A top-level key is named alone ("name: …", not "top level.name: …").
    const std::string at = where.rfind("top level.", 0) == 0 ? where.substr(10) : where;
    throw Error(file_, at + ": " + reason);
  }
  // An error whose message already says where in the file ("volumes[0].contours: …").
  [[noreturn]] void fail(const Error& e) const { throw Error(file_, e.what()); }

  double number(const json& j, const std::string& where) const {
    if (!j.is_number()) fail(where, "expected a number");
    const double v = j.get<double>();
    if (!std::isfinite(v)) fail(where, "not a finite number");
    return v;
  }
  double number(const json& obj, const char* key, const std::string& where, double fallback) const {
    return obj.contains(key) ? number(obj[key], where + "." + key) : fallback;
  }
  double positive(const json& obj, const char* key, const std::string& where, double fallback) const {
    const double v = number(obj, key, where, fallback);
    if (!(v > 0)) fail(where + "." + key, "must be > 0");
    return v;
  }
  int integer(const json& obj, const char* key, const std::string& where, int fallback, int lo, int hi) const {
    if (!obj.contains(key)) return fallback;
    const json& j = obj[key];
    if (!j.is_number_integer()) fail(where + "." + key, "expected an integer");
    const long long v = j.get<long long>();
    if (v < lo || v > hi)
      fail(where + "." + key, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return static_cast<int>(v);
  }
  bool flag(const json& obj, const char* key, const std::string& where, bool fallback) const {
    if (!obj.contains(key)) return fallback;
    if (!obj[key].is_boolean()) fail(where + "." + key, "expected true or false");
    return obj[key].get<bool>();
  }
  glm::dvec3 vec3(const json& j, const std::string& where) const {
    if (!j.is_array() || j.size() != 3) fail(where, "expected an array of 3 numbers");
    return {number(j[0], where + "[0]"), number(j[1], where + "[1]"), number(j[2], where + "[2]")};
  }
  std::string string(const json& obj, const char* key, const std::string& where, const std::string& fallback) const {
    if (!obj.contains(key)) return fallback;
    if (!obj[key].is_string()) fail(where + "." + key, "expected a string");
    return obj[key].get<std::string>();
  }
  const json& object(const json& j, const std::string& where) const {
    if (!j.is_object()) fail(where, "expected an object");
    return j;
  }
  // An object with only these keys: a misspelt one ("colour") would otherwise be dropped without a
  // word and the scene drawn without it.
  const json& object(const json& j, const std::string& where, std::initializer_list<const char*> keys) const {
    object(j, where);
    for (const auto& item : j.items()) {
      if (std::any_of(keys.begin(), keys.end(), [&](const char* k) { return item.key() == k; })) continue;
      std::string list;
      for (const char* k : keys) list += (list.empty() ? "" : ", ") + std::string(k);
      fail(where == "top level" ? item.key() : where + "." + item.key(), "unknown key (expected " + list + ")");
    }
    return j;
  }

 private:
  std::string file_;
};

// A placement every renderer can draw: affine (a projective last row would send points through
// infinity, which no renderer here divides by), not flattening (a zero determinant leaves no
// surface facing anywhere), and within ±1e15 (beyond, the view's projection degenerates and the
// image comes out empty).
void checkTransform(const Reader& r, const glm::dmat4& m, const std::string& where) {
  constexpr double kLargest = 1e15;
  for (int col = 0; col < 4; ++col)
    for (int row = 0; row < 4; ++row)
      if (!(std::abs(m[col][row]) <= kLargest)) r.fail(where, "entries beyond ±1e15 cannot be drawn");
  const double det = glm::determinant(glm::dmat3(m));
  if (!(std::abs(det) > 1e-300) || !std::isfinite(det)) r.fail(where, "singular: it flattens the object");
  if (m[0][3] != 0.0 || m[1][3] != 0.0 || m[2][3] != 0.0 || m[3][3] != 1.0)
    r.fail(where, "projective: the last row must be 0, 0, 0, 1");
}

glm::dmat4 parseTransform(const Reader& r, const json& t, const std::string& where) {
  r.object(t, where, {"matrix", "translate", "rotate", "scale"});
  if (t.contains("matrix")) {
    for (const char* other : {"translate", "rotate", "scale"})
      if (t.contains(other)) r.fail(where + "." + other, "not with 'matrix' (the matrix is the whole transform)");
    const json& m = t["matrix"];
    if (!m.is_array() || m.size() != 16) r.fail(where + ".matrix", "expected 16 numbers (row-major)");
    glm::dmat4 out(1.0);
    for (int row = 0; row < 4; ++row)
      for (int col = 0; col < 4; ++col)
        out[col][row] =
            r.number(m[static_cast<std::size_t>(row) * 4 + static_cast<std::size_t>(col)], where + ".matrix");
    checkTransform(r, out, where + ".matrix");
    return out;
  }
  glm::dmat4 out(1.0);
  if (t.contains("translate")) out = glm::translate(out, r.vec3(t["translate"], where + ".translate"));
  if (t.contains("rotate")) {
    const json& rot = t["rotate"];
    if (rot.is_object()) {
      r.object(rot, where + ".rotate", {"axis", "degrees"});
      // Both: {} was no rotation without a word.
      for (const char* key : {"axis", "degrees"})
        if (!rot.contains(key))
          r.fail(where + ".rotate." + key, "missing (a rotation is {\"axis\": [x, y, z], \"degrees\": d})");
      const glm::dvec3 axis = r.vec3(rot["axis"], where + ".rotate.axis");
      if (glm::length(axis) == 0.0) r.fail(where + ".rotate.axis", "zero axis");
      out = glm::rotate(out, glm::radians(r.number(rot["degrees"], where + ".rotate.degrees")), glm::normalize(axis));
    } else {
      // Euler angles in degrees, applied X, then Y, then Z (world = Rz·Ry·Rx·p).
      const glm::dvec3 e = glm::radians(r.vec3(rot, where + ".rotate"));
      out = glm::rotate(out, e.z, glm::dvec3(0, 0, 1));
      out = glm::rotate(out, e.y, glm::dvec3(0, 1, 0));
      out = glm::rotate(out, e.x, glm::dvec3(1, 0, 0));
    }
  }
  if (t.contains("scale")) {
    const json& s = t["scale"];
    const glm::dvec3 v = s.is_array() ? r.vec3(s, where + ".scale") : glm::dvec3(r.number(s, where + ".scale"));
    if (v.x == 0 || v.y == 0 || v.z == 0) r.fail(where + ".scale", "zero scale");
    out = glm::scale(out, v);
  }
  checkTransform(r, out, where);
  return out;
}

Mesh parsePrimitive(const Reader& r, const json& p, const std::string& where) {
  r.object(p, where);
  // Sizes within ±1e15, as transforms' entries: past float's range the mesh is inf and NaN (a
  // plane of width 1e300 measured "closed" with area NaN).
  constexpr double kLargest = 1e15;
  const auto size = [&](const char* key, double fallback) {
    const double v = r.positive(p, key, where, fallback);
    if (v > kLargest) r.fail(where + "." + key, "must be at most 1e15");
    return v;
  };
  // Each count is bounded, but together they can ask for 10^10 vertices (a hairball of 10,000
  // tubes of 4,096 segments, 256 sides): refused in one line before any is made, as the oracle's
  // and the GPU's allocations are (host_memory.hpp). About 64 bytes per vertex: its position and
  // normal, two triangles' indices, and the growth of the vectors that hold them.
  const auto requireVertices = [&](double vertices) {
    constexpr double kBytesPerVertex = 64.0;
    try {
      requireHostMemory(where, "its " + std::to_string(static_cast<std::uint64_t>(vertices)) + " vertices",
                        static_cast<std::uint64_t>(std::min(vertices * kBytesPerVertex, 1.8e19)));
    } catch (const Error& e) {
      r.fail(e);  // "file: objects[i].primitive: its N vertices would take …"
    }
  };
  const std::string type = r.string(p, "type", where, "");
  if (type == "sphere") r.object(p, where, {"type", "radius", "slices", "stacks"});
  if (type == "box") r.object(p, where, {"type", "size"});
  if (type == "cylinder") r.object(p, where, {"type", "radius", "height", "slices"});
  if (type == "torus") r.object(p, where, {"type", "major_radius", "minor_radius", "major_segments", "minor_segments"});
  if (type == "plane") r.object(p, where, {"type", "width", "height"});
  if (type == "tube") r.object(p, where, {"type", "path", "radius", "sides"});
  if (type == "hairball") r.object(p, where, {"type", "radius", "tube_radius", "count", "seed", "segments", "sides"});
  if (type == "sphere") {
    const double radius = size("radius", 1.0);
    const int slices = r.integer(p, "slices", where, 48, 3, 4096), stacks = r.integer(p, "stacks", where, 24, 2, 4096);
    requireVertices((slices + 1.0) * (stacks + 1.0));
    return makeSphere(radius, slices, stacks);
  }
  if (type == "box") {
    const glm::dvec3 box = p.contains("size") ? r.vec3(p["size"], where + ".size") : glm::dvec3(1.0);
    if (box.x <= 0 || box.y <= 0 || box.z <= 0) r.fail(where + ".size", "must be > 0");
    if (std::max({box.x, box.y, box.z}) > kLargest) r.fail(where + ".size", "must be at most 1e15");
    return makeBox(box);
  }
  if (type == "cylinder")
    return makeCylinder(size("radius", 0.5), size("height", 1.0), r.integer(p, "slices", where, 48, 3, 4096));
  if (type == "torus") {
    const double major = size("major_radius", 1.0);
    const double minor = size("minor_radius", 0.25);
    if (minor >= major) r.fail(where + ".minor_radius", "must be smaller than major_radius");
    const int majorSegments = r.integer(p, "major_segments", where, 64, 3, 4096);
    const int minorSegments = r.integer(p, "minor_segments", where, 24, 3, 4096);
    requireVertices((majorSegments + 1.0) * (minorSegments + 1.0));
    return makeTorus(major, minor, majorSegments, minorSegments);
  }
  if (type == "plane") return makePlane(size("width", 1.0), size("height", 1.0));
  if (type == "tube") {
    if (!p.contains("path") || !p["path"].is_array() || p["path"].size() < 2)
      r.fail(where + ".path", "expected an array of at least 2 points");
    std::vector<glm::dvec3> path;
    for (std::size_t i = 0; i < p["path"].size(); ++i)
      path.push_back(r.vec3(p["path"][i], where + ".path[" + std::to_string(i) + "]"));
    for (std::size_t i = 0; i < path.size(); ++i)
      if (std::max({std::abs(path[i].x), std::abs(path[i].y), std::abs(path[i].z)}) > kLargest)
        r.fail(where + ".path[" + std::to_string(i) + "]", "coordinates must be within ±1e15");
    for (std::size_t i = 1; i < path.size(); ++i)
      if (path[i] == path[i - 1]) r.fail(where + ".path[" + std::to_string(i) + "]", "repeats the previous point");
    // A path that turns straight back has no direction at the turn (makeTube's "repeated path
    // point" named no point: a bug hunt).
    for (std::size_t i = 2; i < path.size(); ++i)
      if (path[i] == path[i - 2])
        r.fail(where + ".path[" + std::to_string(i) + "]",
               "returns to path[" + std::to_string(i - 2) + "]: the tube has no direction at path[" +
                   std::to_string(i - 1) + "], where it turns straight back");
    const double radius = size("radius", 0.05);
    const int sides = r.integer(p, "sides", where, 12, 3, 1024);
    requireVertices(static_cast<double>(path.size()) * (sides + 1.0) + 2.0 * (sides + 1.0));
    return makeTube(path, radius, sides);
  }
  if (type == "hairball") {
    const double radius = size("radius", 1.0);
    const double tube = size("tube_radius", 0.02);
    if (tube >= radius) r.fail(where + ".tube_radius", "must be smaller than radius");
    const int count = r.integer(p, "count", where, 20, 1, 10000);
    const auto seed = static_cast<std::uint32_t>(r.integer(p, "seed", where, 1, 0, 1 << 30));
    const int segments = r.integer(p, "segments", where, 64, 2, 4096), sides = r.integer(p, "sides", where, 10, 3, 256);
    requireVertices(count * ((segments + 1.0) * (sides + 1.0) + 2.0 * (sides + 1.0)));
    return makeHairball(count, radius, tube, seed, segments, sides);
  }
  r.fail(where + ".type", "unknown primitive '" + type + "' (sphere, box, cylinder, torus, plane, tube, hairball)");
}

glm::vec4 parseColor(const Reader& r, const json& o, const std::string& where, glm::vec4 color) {
  if (o.contains("color")) {
    const json& c = o["color"];
    if (!c.is_array() || (c.size() != 3 && c.size() != 4)) r.fail(where + ".color", "expected 3 or 4 numbers in [0,1]");
    for (std::size_t i = 0; i < c.size(); ++i) {
      const double v = r.number(c[i], where + ".color");
      if (v < 0 || v > 1) r.fail(where + ".color", "components must be in [0,1]");
      color[static_cast<int>(i)] = static_cast<float>(v);
    }
  }
  if (o.contains("opacity")) {
    const double a = r.number(o["opacity"], where + ".opacity");
    if (a < 0 || a > 1) r.fail(where + ".opacity", "must be in [0,1]");
    color.a = static_cast<float>(a);
  }
  return color;
}

// An object's "color_by": "field" or {"field", "map", "range"}, applied to each part whose mesh has
// the field (colorByField); at least one must.
void parseColorBy(const Reader& r, const Scene& scene, const json& o, const std::string& where,
                  const std::vector<Object*>& parts, const std::string& what) {
  if (!o.contains("color_by")) return;
  const std::string at = where + ".color_by";
  const json& c = o["color_by"];
  std::string field, map = "cool-warm";
  std::optional<glm::dvec2> range;
  if (c.is_string()) {
    field = c.get<std::string>();
  } else {
    r.object(c, at, {"field", "map", "range"});
    field = r.string(c, "field", at, "");
    map = r.string(c, "map", at, map);
    if (c.contains("range")) {
      const json& v = c["range"];
      if (!v.is_array() || v.size() != 2) r.fail(at + ".range", "expected [low, high]");
      range = glm::dvec2(r.number(v[0], at + ".range[0]"), r.number(v[1], at + ".range[1]"));
      if (!(range->y > range->x)) r.fail(at + ".range", "high must be greater than low");
    }
  }
  if (field.empty()) r.fail(at, "expected the name of a point-data or cell-data array of the file");
  // "@vol.vtk" of a file listed twice without names meant the first volume, silently (a bug hunt).
  if (const std::optional<std::string> why = ambiguousVolumeField(scene, field)) r.fail(at, *why);
  const auto& names = colorMapNames();
  if (std::find(names.begin(), names.end(), map) == names.end()) {
    std::string list;
    for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
    r.fail(at + ".map", "unknown colour map '" + map + "' (" + list + ")");
  }
  try {
    colorObjectsByField(parts, field, map, range, what);
  } catch (const Error& e) {
    r.fail(at, e.what());
  }
}

Camera parseView(const Reader& r, const json& v, const std::string& where, const Bounds& bounds, double radius) {
  r.object(v, where, {"name", "eye", "target", "up", "projection", "fovy", "height", "fit", "near", "far"});
  Camera c;
  if (v.contains("eye")) c.eye = r.vec3(v["eye"], where + ".eye");
  if (v.contains("target")) c.target = r.vec3(v["target"], where + ".target");
  if (v.contains("up")) c.up = r.vec3(v["up"], where + ".up");
  if (const auto defect = c.frameDefect())
    r.fail(defect->key.empty() ? where : where + "." + defect->key, defect->reason);
  const std::string proj = r.string(v, "projection", where, "perspective");
  if (proj == "orthographic")
    c.projection = Projection::Orthographic;
  else if (proj != "perspective")
    r.fail(where + ".projection", "must be 'perspective' or 'orthographic'");
  c.fovyDegrees = r.number(v, "fovy", where, c.fovyDegrees);
  if (c.fovyDegrees <= 0 || c.fovyDegrees >= 180) r.fail(where + ".fovy", "must be in (0, 180) degrees");
  c.orthoHeight = r.positive(v, "height", where, c.orthoHeight);
  if (r.flag(v, "fit", where, false))
    c = c.fittedTo(bounds, radius);
  else
    c.fitDepthRange(bounds, radius);
  if (v.contains("near") || v.contains("far")) {
    c.nearPlane = r.positive(v, "near", where, c.nearPlane);
    c.farPlane = r.positive(v, "far", where, c.farPlane);
    if (c.farPlane <= c.nearPlane) r.fail(where + ".far", "must be greater than near");
    c.depthRangeGiven = true;
  }
  // What the renderers would refuse at the first frame ("camera: projection is singular", naming
  // neither the file nor the view), said here: near 1e-30 with far 1e30, say.
  if (c.projectionSingular())
    r.fail(where, "its projection is singular (near and far planes too far apart, or too large a scene)");
  return c;
}

// A volume's "transfer": {"preset", "range", "unit_distance"} or {"points", "unit_distance"}; the
// defaults (data range, diagonal / 50) come from the loaded volume's defaultTransfer().
TransferFunction parseTransfer(const Reader& r, const json& t, const std::string& where, const Volume& volume) {
  r.object(t, where, {"preset", "points", "range", "unit_distance"});
  const TransferFunction fallback = volume.transfer;
  const double unitDistance = r.positive(t, "unit_distance", where, fallback.unitDistance);
  if (t.contains("preset") == t.contains("points")) r.fail(where, "needs exactly one of 'preset' or 'points'");
  TransferFunction tf;
  if (t.contains("preset")) {
    const std::string preset = r.string(t, "preset", where, "");
    const auto& names = transferPresetNames();
    if (std::find(names.begin(), names.end(), preset) == names.end()) {
      std::string list;
      for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
      r.fail(where + ".preset", "unknown preset '" + preset + "' (" + list + ")");
    }
    double low = fallback.low(), high = fallback.high();
    if (t.contains("range")) {
      const json& range = t["range"];
      if (!range.is_array() || range.size() != 2) r.fail(where + ".range", "expected [low, high]");
      low = r.number(range[0], where + ".range[0]");
      high = r.number(range[1], where + ".range[1]");
      if (!(high > low)) r.fail(where + ".range", "high must be greater than low");
    }
    tf = transferPreset(preset, low, high, unitDistance);
  } else {
    if (t.contains("range")) r.fail(where + ".range", "only with 'preset' (the points give their own values)");
    const json& points = t["points"];
    if (!points.is_array() || points.size() < 2) r.fail(where + ".points", "expected an array of at least 2 points");
    tf.unitDistance = unitDistance;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const std::string at = where + ".points[" + std::to_string(i) + "]";
      const json& p = points[i];
      if (!p.is_array() || p.size() != 5) r.fail(at, "expected [value, r, g, b, a]");
      TransferPoint point;
      point.value = r.number(p[0], at + "[0]");
      for (std::size_t c = 1; c < 5; ++c) {
        const double v = r.number(p[c], at + "[" + std::to_string(c) + "]");
        if (v < 0 || v > 1) r.fail(at + "[" + std::to_string(c) + "]", "colour and opacity must be in [0,1]");
        point.color[static_cast<int>(c - 1)] = static_cast<float>(v);
      }
      if (i > 0 && point.value < tf.points.back().value)
        r.fail(at + "[0]", "values must ascend (" + std::to_string(point.value) + " after " +
                               std::to_string(tf.points.back().value) + ")");
      tf.points.push_back(point);
    }
    if (!(tf.high() > tf.low())) r.fail(where + ".points", "the last value must be greater than the first");
  }
  return tf;
}

Volume parseVolume(const Reader& r, const json& j, const std::string& where, const std::filesystem::path& baseDir,
                   std::vector<std::string>& notes, const LoadProgress& progress) {
  const json& v =
      r.object(j, where, {"file", "name", "transform", "visible", "shading", "field", "transfer", "contours"});
  if (!v.contains("file")) r.fail(where, "needs 'file' (a volume file)");
  const std::string file = r.string(v, "file", where, "");
  if (file.find('\0') != std::string::npos) r.fail(where + ".file", "contains a NUL character (\\u0000)");
  const glm::dmat4 xf =
      v.contains("transform") ? parseTransform(r, v["transform"], where + ".transform") : glm::dmat4(1.0);
  if (v.contains("visible") && !v["visible"].is_boolean()) r.fail(where + ".visible", "expected true or false");
  if (v.contains("shading") && !v["shading"].is_boolean()) r.fail(where + ".shading", "expected true or false");
  LoadOptions options;
  if (v.contains("field")) {
    options.field = r.string(v, "field", where, "");
    if (options.field.empty()) r.fail(where + ".field", "expected the name of an array or grid of the file");
  }
  options.notes = &notes;
  Volume volume;
  try {
    volume = loadVolume(baseDir / file, options, progress);  // its errors name the volume file
  } catch (const LoadCancelled&) {
    throw;
  } catch (const FieldNotFound& e) {
    r.fail(where + ".field", e.what());
  } catch (const Error& e) {
    r.fail(where + ".file", e.what());
  }
  volume.name = r.string(v, "name", where, volume.name);
  volume.transform = xf * volume.transform;
  volume.sceneTransform = xf;
  volume.visible = r.flag(v, "visible", where, true);
  volume.shading = r.flag(v, "shading", where, false);
  // The defaults are relative to where the volume now is: its world diagonal.
  volume.transfer = defaultTransfer(*volume.grid, volume.bounds());
  if (v.contains("transfer")) volume.transfer = parseTransfer(r, v["transfer"], where + ".transfer", volume);
  try {
    volume.validate();
  } catch (const Error& e) {
    r.fail(where, e.what());
  }
  return volume;
}

// A volume's "contours": [values…] or {"values": [values…], "opacity": a} — isosurfaces added as
// parts (scene/contour.hpp).
ContourRequest parseContours(const Reader& r, const json& j, const std::string& where, std::size_t volume) {
  ContourRequest request;
  request.volume = volume;
  const json* values = &j;
  if (j.is_object()) {
    for (const auto& item : j.items())
      if (item.key() != "values" && item.key() != "opacity")
        r.fail(where + "." + item.key(), "unknown key (expected values, opacity)");
    if (!j.contains("values")) r.fail(where, "needs 'values' (the isosurfaces' values)");
    values = &j["values"];
    const double opacity = r.number(j, "opacity", where, request.opacity);
    if (opacity < 0.0 || opacity > 1.0) r.fail(where + ".opacity", "must be in [0, 1]");
    request.opacity = static_cast<float>(opacity);
  }
  if (!values->is_array()) r.fail(where, "expected an array of values or {\"values\": [...], \"opacity\": a}");
  for (std::size_t i = 0; i < values->size(); ++i)
    request.values.push_back(r.number((*values)[i], where + "[" + std::to_string(i) + "]"));
  return request;
}

// A CSG node: an object's name, or {"union" | "intersection" | "difference": [≥ 2 nodes]}. A tree
// nested d levels deep has at least d + 1 leaves, so 2d + 1 program words: deeper than the program
// holds is refused here, before a recursion as deep as the file (a crash at 100,000 levels).
CsgNode parseCsgNode(const Reader& r, const json& j, const std::string& where, const Scene& scene,
                     std::size_t depth = 0) {
  if (depth > MFR_CSG_MAX_PROGRAM / 2)
    r.fail("csg", "nested more than " + std::to_string(MFR_CSG_MAX_PROGRAM / 2) +
                      " levels deep (a CSG program holds at most " + std::to_string(MFR_CSG_MAX_PROGRAM) + " words)");
  CsgNode node;
  if (j.is_string()) {
    const std::string name = j.get<std::string>();
    std::size_t matches = 0;
    for (std::size_t i = 0; i < scene.objects.size(); ++i)
      if (scene.objects[i].name == name) {
        node.object = static_cast<std::uint32_t>(i);
        ++matches;
      }
    if (matches == 0) r.fail(where, "no object named '" + name + "'");
    if (matches > 1) r.fail(where, std::to_string(matches) + " objects are named '" + name + "' (must be unique)");
    return node;
  }
  static const char* const kExpected =
      "expected an object's name or an object with one key: union, intersection or difference";
  if (!j.is_object() || j.size() != 1) r.fail(where, kExpected);
  const std::string key = j.begin().key();
  if (key == "union")
    node.op = CsgNode::Op::Union;
  else if (key == "intersection")
    node.op = CsgNode::Op::Intersection;
  else if (key == "difference")
    node.op = CsgNode::Op::Difference;
  else
    r.fail(where + "." + key, std::string("unknown CSG operator (") + kExpected + ")");
  const json& operands = j.begin().value();
  if (!operands.is_array() || operands.size() < 2)
    r.fail(where + "." + key, "expected an array of at least 2 operands");
  for (std::size_t i = 0; i < operands.size(); ++i)
    node.children.push_back(
        parseCsgNode(r, operands[i], where + "." + key + "[" + std::to_string(i) + "]", scene, depth + 1));
  return node;
}

}  // namespace

std::optional<std::string> repeatedJsonKey(const std::string& text) {
  if (jsonNestingDepth(text) > kJsonNestingLimit) return std::nullopt;
  try {
    (void)parseWithoutRepeatedKeys(text);
  } catch (const RepeatedKey& repeated) {
    return repeated.where;
  } catch (...) {  // not JSON, or a number out of range: the caller's parser says why
  }
  return std::nullopt;
}

namespace {
json csgJson(const CsgNode& node, const Scene& scene) {
  if (node.op == CsgNode::Op::Primitive) return scene.objects.at(node.object).name;
  json operands = json::array();
  for (const CsgNode& child : node.children) operands.push_back(csgJson(child, scene));
  const char* key = node.op == CsgNode::Op::Union          ? "union"
                    : node.op == CsgNode::Op::Intersection ? "intersection"
                                                           : "difference";
  return json{{key, operands}};
}
}  // namespace

CsgTree parseCsgText(const std::string& text, const Scene& scene) {
  if (text.find_first_not_of(" \t\r\n") == std::string::npos) return {};
  json j;
  try {
    j = json::parse(text);
  } catch (const json::parse_error& e) {
    throw Error("CSG tree", std::string("not JSON: ") + e.what());
  }
  const Reader r("CSG tree");
  Scene checked = scene;
  checked.csg.root = parseCsgNode(r, j, "csg", scene);
  validateCsg(checked);
  return checked.csg;
}

std::string csgText(const CsgTree& tree, const Scene& scene) {
  return tree.empty() ? std::string() : jsonText(csgJson(*tree.root, scene));
}

Scene parseSceneFile(const std::string& text, const std::filesystem::path& baseDir, const std::string& name,
                     const LoadProgress& progress) {
  json doc;
  try {
    doc = parseWithoutRepeatedKeys(text);
  } catch (const RepeatedKey& repeated) {
    throw Error(name, repeated.where + ": given twice (the keys of a JSON object must differ)");
  } catch (const NumberOutOfRange& number) {
    throw Error(name, (number.where.empty() ? std::string() : number.where + ": ") +
                          "JSON number out of range (beyond double precision)");
  } catch (const json::parse_error& e) {
    // Byte offset → line and column, which is what an editor shows.
    std::size_t line = 1, col = 1;
    for (std::size_t i = 0; i + 1 < e.byte && i < text.size(); ++i) {
      if (text[i] == '\n') {
        ++line;
        col = 1;
      } else {
        ++col;
      }
    }
    throw Error(name, "JSON syntax error at line " + std::to_string(line) + ", column " + std::to_string(col));
  }
  const Reader r(name);
  r.object(doc, "top level", {"name", "background", "sample", "objects", "volumes", "views", "csg", "clip", "section"});
  // The sample first, so that the file's own name and background replace the sample's.
  Scene scene = r.flag(doc, "sample", "top level", false) ? makeSampleScene() : Scene();
  scene.name = r.string(doc, "name", "top level", std::filesystem::path(name).stem().string());
  if (doc.contains("background")) {
    // In [0,1] like a colour: [-5, 0.5, 0.5] was composited as it is (a red sphere over it came out
    // (0, 32, 32)).
    const glm::dvec3 background = r.vec3(doc["background"], "background");
    for (int i = 0; i < 3; ++i)
      if (!(background[i] >= 0.0 && background[i] <= 1.0)) r.fail("background", "components must be in [0,1]");
    scene.background = glm::vec3(background);
  }
  // The checks --clip shares (scene/clip_box.hpp), their "clip: …" as the file's key.
  const auto clipCheck = [&](const auto& check) {
    try {
      check();
    } catch (const Error& e) {
      r.fail("clip", std::string(e.what()).substr(std::string("clip: ").size()));
    }
  };
  if (doc.contains("clip")) {
    const json& clip = r.object(doc["clip"], "clip", {"min", "max"});
    if (!clip.contains("min") || !clip.contains("max")) r.fail("clip", "expected \"min\" and \"max\" corners");
    Bounds box;
    box.min = r.vec3(clip["min"], "clip.min");
    box.max = r.vec3(clip["max"], "clip.max");
    if (!box.valid()) r.fail("clip", "min must not exceed max on any axis");
    clipCheck([&] { requireClipBoxInFloatRange(box, "clip"); });
    scene.clipBox = box;
  }
  if (doc.contains("section")) {
    const json& section = r.object(doc["section"], "section", {"point", "normal", "caps", "slice"});
    if (!section.contains("point") || !section.contains("normal"))
      r.fail("section", "expected \"point\" and \"normal\"");
    SectionPlane plane;
    plane.point = r.vec3(section["point"], "section.point");
    plane.normal = r.vec3(section["normal"], "section.normal");
    // Scene::validate's bound, said here with the file and key (it named neither: a bug hunt).
    if (!(glm::length(plane.normal) > 1e-12)) r.fail("section.normal", "must not be zero (a length above 1e-12)");
    if (!std::isfinite(glm::length(plane.normal))) r.fail("section.normal", "too long to normalise (under 1e150)");
    if (section.contains("caps")) {
      if (!section["caps"].is_boolean()) r.fail("section.caps", "expected true or false");
      plane.caps = section["caps"].get<bool>();
    }
    if (section.contains("slice")) {
      if (!section["slice"].is_boolean()) r.fail("section.slice", "expected true or false");
      plane.slice = section["slice"].get<bool>();
    }
    scene.section = plane;
  }

  // One equal part of the progress per object and per volume.
  const auto items = [&](const char* key) { return doc.contains(key) && doc[key].is_array() ? doc[key].size() : 0; };
  const std::size_t objectCount = items("objects"), itemCount = objectCount + items("volumes");
  const auto itemProgress = [&](std::size_t item) {
    const double count = static_cast<double>(itemCount);
    return progress.part(static_cast<double>(item) / count, static_cast<double>(item + 1) / count);
  };

  // An object's color_by, applied once the volumes are loaded (it may name one: "@NAME").
  struct ColorBy {
    const json* object;
    std::string where;
    std::size_t first, last;  // its parts in scene.objects
    std::string what;
  };
  std::vector<ColorBy> colorBy;
  // Model files already read, by path and molecule representations: objects placing one file many
  // times share its meshes, as a glTF's or STEP's instances do (each read it again and kept a copy:
  // 16 placements of a 500k-triangle part took 12× the time and 2.6× the memory; a bug hunt).
  std::map<std::pair<std::string, std::string>, std::vector<Object>> modelsRead;
  if (doc.contains("objects")) {
    const json& objects = doc["objects"];
    if (!objects.is_array()) r.fail("objects", "expected an array");
    for (std::size_t i = 0; i < objects.size(); ++i) {
      const LoadProgress objectProgress = itemProgress(i);
      objectProgress.step(0.0);
      const std::string where = "objects[" + std::to_string(i) + "]";
      const json& o =
          r.object(objects[i], where,
                   {"name", "file", "primitive", "transform", "color", "opacity", "visible", "molecule", "color_by"});
      const std::string objName = r.string(o, "name", where, "object " + std::to_string(i));
      const glm::dmat4 xf =
          o.contains("transform") ? parseTransform(r, o["transform"], where + ".transform") : glm::dmat4(1.0);
      const bool visible = r.flag(o, "visible", where, true);
      if (o.contains("file") == o.contains("primitive")) r.fail(where, "needs exactly one of 'file' or 'primitive'");
      if (o.contains("primitive")) {
        if (o.contains("molecule"))
          r.fail(where + ".molecule", "only a molecule file (.pdb .ent .cif .mmcif) has representations");
        Object obj;
        obj.name = objName;
        try {
          obj.mesh = std::make_shared<const Mesh>(parsePrimitive(r, o["primitive"], where + ".primitive"));
        } catch (const Error& e) {
          if (std::string(e.what()).rfind(name, 0) == 0) throw;
          r.fail(where + ".primitive", e.what());
        }
        obj.transform = xf;
        obj.material.color = parseColor(r, o, where, obj.material.color);
        obj.visible = visible;
        colorBy.push_back({&o, where, scene.objects.size(), scene.objects.size() + 1, objName});
        scene.objects.push_back(std::move(obj));
      } else {
        const std::string fileName = r.string(o, "file", where, "");
        if (fileName.empty()) r.fail(where + ".file", "expected the name of a model file");
        // A NUL ends the name the system sees: "a.obj\u0000.stl" failed as "a.obj?.stl: a.obj", no reason given.
        if (fileName.find('\0') != std::string::npos) r.fail(where + ".file", "contains a NUL character (\\u0000)");
        const std::filesystem::path file = baseDir / fileName;
        LoadOptions options;
        if (o.contains("molecule")) {
          const std::string style = r.string(o, "molecule", where, "");
          try {
            options.molecule = MoleculeStyle::parse(style, "molecule");
          } catch (const Error& e) {
            r.fail(where + ".molecule", std::string(e.what()).substr(std::string("molecule: ").size()));
          }
          if (!isMoleculeFile(file))
            r.fail(where + ".molecule", "only a molecule file (.pdb .ent .cif .mmcif) has representations");
        }
        options.notes = &scene.notes;
        // The file by its folder, links resolved, and its name as given: a link is read through
        // its own name and folder (an OBJ's mtllib, a glTF's buffers lie beside the link, not its
        // target: two links to one OBJ beside two .mtl files took the first one's colours; a review).
        std::error_code canonicalError;
        const std::filesystem::path folder = std::filesystem::weakly_canonical(
            file.has_parent_path() ? file.parent_path() : std::filesystem::path("."), canonicalError);
        const std::pair<std::string, std::string> modelKey{
            canonicalError ? file.string() : (folder / file.filename()).string(),
            o.contains("molecule") ? o["molecule"].dump() : ""};
        std::vector<Object> parts;
        try {
          if (const auto read = modelsRead.find(modelKey); read != modelsRead.end())
            parts = read->second;  // the meshes shared, each object's own transform and material below
          else
            parts = modelsRead.emplace(modelKey, loadModel(file, options, objectProgress)).first->second;
        } catch (const LoadCancelled&) {
          throw;
        } catch (const Error& e) {
          // Its errors name the model file; this names the scene file and the key as well.
          std::string ext = file.extension().string();
          std::transform(ext.begin(), ext.end(), ext.begin(),
                         [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
          if (ext == ".mfrscene") r.fail(where + ".file", "a scene file cannot include another scene (.mfrscene)");
          r.fail(where + ".file", e.what());
        }
        colorBy.push_back(
            {&o, where, scene.objects.size(), scene.objects.size() + parts.size(), file.filename().string()});
        for (Object& part : parts) {
          part.name = parts.size() == 1 ? objName : objName + "/" + part.name;
          part.transform = xf * part.transform;
          part.material.color = parseColor(r, o, where, part.material.color);
          if (o.contains("color")) part.material.vertexColors = false;  // replaces the file's colours
          part.visible = visible;
        }
        for (Object& part : parts) scene.objects.push_back(std::move(part));
      }
      objectProgress.step(1.0);
    }
  }
  if (doc.contains("volumes")) {
    const json& volumes = doc["volumes"];
    if (!volumes.is_array()) r.fail("volumes", "expected an array");
    const std::size_t firstVolume = scene.volumes.size();
    for (std::size_t i = 0; i < volumes.size(); ++i) {
      const std::string where = "volumes[" + std::to_string(i) + "]";
      Volume volume = parseVolume(r, volumes[i], where, baseDir, scene.notes, itemProgress(objectCount + i));
      if (volume.visible && scene.visibleVolumes().size() >= Scene::kMaxVisibleVolumes)
        r.fail(where + ".visible", std::to_string(Scene::kMaxVisibleVolumes) +
                                       " volumes are visible already: at most that many can be drawn at once "
                                       "(set \"visible\": false)");
      // A name given is how --contour NAME=… and a part's "@NAME" field find the volume: two alike
      // would silently mean the first.
      if (volumes[i].is_object() && volumes[i].contains("name"))
        for (std::size_t k = firstVolume; k < scene.volumes.size(); ++k)
          if (scene.volumes[k].name == volume.name)
            r.fail(where + ".name", "'" + volume.name + "' is volumes[" + std::to_string(k - firstVolume) +
                                        "]'s name too (names must be unique)");
      scene.volumes.push_back(std::move(volume));
    }
    // Isosurfaces once every volume is there (a part's "@NAME" fields name them all).
    for (std::size_t i = 0; i < volumes.size(); ++i) {
      if (!volumes[i].contains("contours")) continue;
      const std::string where = "volumes[" + std::to_string(i) + "].contours";
      const ContourRequest request = parseContours(r, volumes[i]["contours"], where, firstVolume + i);
      try {
        addContours(scene, request, where);
      } catch (const Error& e) {
        r.fail(e);
      }
    }
  }
  addVolumeFields(scene);
  for (const ColorBy& c : colorBy) {
    std::vector<Object*> parts;
    for (std::size_t i = c.first; i < c.last; ++i) parts.push_back(&scene.objects[i]);
    parseColorBy(r, scene, *c.object, c.where, parts, c.what);
  }
  if (doc.contains("csg")) {
    scene.csg.root = parseCsgNode(r, doc["csg"], "csg", scene);
    try {
      validateCsg(scene);  // closed meshes, limits
    } catch (const Error& e) {
      r.fail("csg", e.what());
    }
  }
  // A box that holds nothing drew an empty image with exit 0, where --clip refuses it (a bug hunt).
  if (scene.clipBox) clipCheck([&] { requireClipBoxHoldsScene(scene, *scene.clipBox, "clip"); });
  const Bounds bounds = scene.bounds();
  const double radius = scene.boundingRadius();
  if (doc.contains("views")) {
    const json& views = doc["views"];
    if (!views.is_array()) r.fail("views", "expected an array");
    scene.views.clear();
    for (std::size_t i = 0; i < views.size(); ++i) {
      const std::string where = "views[" + std::to_string(i) + "]";
      const std::string viewName = r.string(views[i], "name", where, "view " + std::to_string(i));
      // An empty name was listed among the views and could never be chosen (a bug hunt).
      if (viewName.empty()) r.fail(where + ".name", "must not be empty");
      if (viewName == "fit") r.fail(where + ".name", "'fit' is reserved for the fit-all view");
      // --view orbit:A:E is the orbit syntax: a view of such a name hid it (a bug hunt).
      if (viewName.rfind("orbit:", 0) == 0)
        r.fail(where + ".name", "'" + viewName + "': names beginning 'orbit:' are --view's orbit syntax");
      // --view finds the first of a name: a second view of it could never be shown.
      for (std::size_t j = 0; j < scene.views.size(); ++j)
        if (scene.views[j].name == viewName)
          r.fail(where + ".name", "'" + viewName + "' is the name of views[" + std::to_string(j) + "] too");
      scene.views.push_back({viewName, parseView(r, views[i], where, bounds, radius)});
    }
  }
  return scene;
}

Scene readSceneFile(const std::filesystem::path& path, const LoadProgress& progress) {
  return parseSceneFile(readFile(path), path.parent_path(), path.string(), progress);
}

}  // namespace mfr
