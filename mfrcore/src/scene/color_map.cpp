#include "mfr/scene/color_map.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>

#include <vtkColorTransferFunction.h>
#include <vtkNew.h>

#include "common/bindings.h"
#include "mfr/error.hpp"
#include "mfr/reference/metrics.hpp"

namespace mfr {
namespace {

struct Stop {
  double x;
  double r, g, b;
};

// The table of a map given by stops, interpolated by VTK's colour transfer function in `space`
// (VTK_CTF_RGB, _HSV, _LAB, _DIVERGING): the colour science is VTK's, as in ParaView.
ColorMap sampled(std::string name, const std::vector<Stop>& stops, int space, glm::vec3 nan) {
  vtkNew<vtkColorTransferFunction> f;
  f->SetColorSpace(space);
  f->HSVWrapOff();  // hue from blue down to red through green, not through magenta
  for (const Stop& s : stops) f->AddRGBPoint(s.x, s.r, s.g, s.b);
  ColorMap map{std::move(name), {}, nan};
  map.table.resize(MFR_COLOR_MAP_SIZE);
  for (int i = 0; i < MFR_COLOR_MAP_SIZE; ++i) {
    double rgb[3];
    f->GetColor(static_cast<double>(i) / (MFR_COLOR_MAP_SIZE - 1), rgb);
    map.table[static_cast<std::size_t>(i)] = glm::clamp(glm::vec3(rgb[0], rgb[1], rgb[2]), 0.0f, 1.0f);
  }
  return map;
}

std::vector<ColorMap> makeMaps() {
  std::vector<ColorMap> maps;
  // ParaView's "Cool to Warm": Moreland's end points, interpolated in his Msh space.
  maps.push_back(sampled("cool-warm",
                         {{0.0, 0.231372549, 0.298039216, 0.752941176}, {1.0, 0.705882353, 0.015686275, 0.149019608}},
                         VTK_CTF_DIVERGING, {1.0f, 1.0f, 0.0f}));
  // matplotlib's viridis at nine evenly spaced entries (#440154 … #FDE725), in CIELAB between them.
  const auto hex = [](double x, unsigned rgb) {
    return Stop{x, ((rgb >> 16) & 0xFF) / 255.0, ((rgb >> 8) & 0xFF) / 255.0, (rgb & 0xFF) / 255.0};
  };
  maps.push_back(
      sampled("viridis",
              {hex(0.0, 0x440154), hex(0.125, 0x472D7B), hex(0.25, 0x3B528B), hex(0.375, 0x2C728E), hex(0.5, 0x21908C),
               hex(0.625, 0x27AD81), hex(0.75, 0x5DC863), hex(0.875, 0xAADC32), hex(1.0, 0xFDE725)},
              VTK_CTF_LAB, {1.0f, 0.0f, 0.0f}));
  // matplotlib's magma, all 256 entries (the table FLIP's error maps use).
  ColorMap magma{"magma", {}, {0.0f, 1.0f, 0.0f}};
  static_assert(MFR_COLOR_MAP_SIZE == 256, "magma has 256 entries");
  for (int i = 0; i < MFR_COLOR_MAP_SIZE; ++i) magma.table.push_back(magmaEntry(i));
  maps.push_back(std::move(magma));
  // ParaView's "Blue to Red Rainbow": hue from 2/3 to 0 at full saturation and value.
  maps.push_back(sampled("rainbow", {{0.0, 0.0, 0.0, 1.0}, {1.0, 1.0, 0.0, 0.0}}, VTK_CTF_HSV,
                         {0.498039216f, 0.498039216f, 0.498039216f}));
  maps.push_back(sampled("grayscale", {{0.0, 0.0, 0.0, 0.0}, {1.0, 1.0, 1.0, 1.0}}, VTK_CTF_RGB, {1.0f, 0.0f, 0.0f}));
  return maps;
}

const std::vector<ColorMap>& maps() {
  static const std::vector<ColorMap> all = makeMaps();
  return all;
}

std::string list(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

}  // namespace

const std::vector<std::string>& colorMapNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const ColorMap& m : maps()) n.push_back(m.name);
    return n;
  }();
  return names;
}

int colorMapIndex(const std::string& name) {
  const std::vector<ColorMap>& all = maps();
  for (std::size_t i = 0; i < all.size(); ++i)
    if (all[i].name == name) return static_cast<int>(i);
  throw Error("colour map " + name, "unknown colour map (available: " + list(colorMapNames()) + ")");
}

const ColorMap& colorMap(const std::string& name) {
  return maps()[static_cast<std::size_t>(colorMapIndex(name))];
}

glm::vec3 mapFieldValue(const ColorMap& map, float value, const glm::vec2& range) {
  if (std::isnan(value)) return map.nanColor;
  const float span = range.y - range.x;
  float t = span > 0.0f && std::isfinite(span) ? std::clamp((value - range.x) / span, 0.0f, 1.0f) : 0.5f;
  if (std::isnan(t)) t = 0.5f;  // an infinite value in an infinite range: never an index out of the table
  const float x = t * static_cast<float>(MFR_COLOR_MAP_SIZE - 1);
  const int i = std::min(static_cast<int>(x), MFR_COLOR_MAP_SIZE - 2);
  const glm::vec3 a = map.table[static_cast<std::size_t>(i)], b = map.table[static_cast<std::size_t>(i) + 1];
  return glm::mix(a, b, x - static_cast<float>(i));
}

float boundFieldValue(float value, const glm::vec2& range) {
  if (std::isnan(value)) return value;
  const float band = static_cast<float>(MFR_COLOR_MAP_BAND) * (range.y - range.x);
  return std::clamp(value, range.x - band, range.y + band);
}

int fieldComponent(const std::string& base, const std::string& which, int components, const std::string& what) {
  if (which == "magnitude") return -1;
  const bool digits = !which.empty() && which.size() < 4 &&
                      std::all_of(which.begin(), which.end(), [](char c) { return c >= '0' && c <= '9'; });
  if (digits && std::stoi(which) < components) return std::stoi(which);
  throw FieldNotFound(what, "array '" + base + "' has " + std::to_string(components) + " component" +
                                (components == 1 ? "" : "s") + " (" + base + ":0 … " + base + ":" +
                                std::to_string(components - 1) + ", or " + base + ":magnitude)");
}

std::vector<std::string> fieldNames(const Mesh& mesh) {
  std::vector<std::string> names;
  for (const MeshField& f : mesh.fields) {
    names.push_back(f.name);
    for (int c = 1; c < f.components; ++c) names.push_back(f.name + ":" + std::to_string(c));
    if (f.components > 1) names.push_back(f.name + ":magnitude");
  }
  return names;
}

FieldValues fieldValues(const Mesh& mesh, const std::string& field, const std::string& what) {
  const auto find = [&](const std::string& name) -> const MeshField* {
    for (const MeshField& f : mesh.fields)
      if (f.name == name) return &f;
    return nullptr;
  };
  const MeshField* array = find(field);
  int component = 0;  // -1: the magnitude
  if (array == nullptr) {
    const std::size_t colon = field.rfind(':');
    if (colon != std::string::npos && colon > 0) array = find(field.substr(0, colon));
    if (array != nullptr)
      component = fieldComponent(field.substr(0, colon), field.substr(colon + 1), array->components, what);
  }
  if (array == nullptr) {
    const std::vector<std::string> names = fieldNames(mesh);
    throw FieldNotFound(what, "no point-data or cell-data array '" + field + "' (" +
                                  (names.empty() ? std::string("it has none") : "fields: " + list(names)) + ")");
  }
  const auto n = static_cast<std::size_t>(array->components);
  FieldValues out{std::vector<float>(array->values.size() / n), array->cellData};
  for (std::size_t t = 0; t < out.values.size(); ++t) {
    if (component >= 0) {
      out.values[t] = array->values[t * n + static_cast<std::size_t>(component)];
    } else {
      double sum = 0.0;
      for (std::size_t c = 0; c < n; ++c) sum += double(array->values[t * n + c]) * array->values[t * n + c];
      out.values[t] = static_cast<float>(std::sqrt(sum));
    }
  }
  return out;
}

std::optional<glm::dvec2> finiteSpan(const std::vector<float>& values) {
  double low = std::numeric_limits<double>::infinity(), high = -low;
  for (const float v : values)
    if (std::isfinite(v)) {
      low = std::min(low, double(v));
      high = std::max(high, double(v));
    }
  if (!(low <= high)) return std::nullopt;
  return glm::dvec2(low, high);
}

glm::dvec2 fieldRange(const std::vector<float>& values) {
  const std::optional<glm::dvec2> span = finiteSpan(values);
  if (!span) return {0.0, 1.0};
  // A constant: one step either side that floats tell apart from it (1e8 ± 1 is 1e8 as a float,
  // and the renderers refused the range the user never gave).
  // A span of a few float steps is a constant too: an isosurface coloured by its own volume
  // (0.5 ± 6e-8 from rounding) spread that noise over the whole map, in speckles that the oracle
  // and the GPU drew apart (RMSE 0.01–0.035, a bug hunt).
  const double magnitude = std::max(std::abs(span->x), std::abs(span->y));
  if (span->y - span->x <= magnitude * 0x1p-20) {
    const double centre = span->x + 0.5 * (span->y - span->x);
    const double step = std::max(1.0, std::abs(centre) * 0x1p-20);
    const double largest = std::numeric_limits<float>::max();
    return {std::max(centre - step, -largest), std::min(centre + step, largest)};
  }
  return *span;
}

namespace {

// The renderers map in single precision (shaders, mapFieldValue): both ends and their span must be
// finite floats.
bool usableColorRange(const glm::dvec2& range) {
  const auto low = static_cast<float>(range.x), high = static_cast<float>(range.y);
  return std::isfinite(range.x) && std::isfinite(range.y) && range.x < range.y && std::isfinite(low) &&
         std::isfinite(high) && std::isfinite(high - low) && high > low;
}
constexpr const char* kColorRangeRule =
    "colour range must be two finite values, low < high, within single precision (±3.4e38, distinct as floats)";

}  // namespace

void colorByField(Object& object, const std::string& field, const std::string& map,
                  const std::optional<glm::dvec2>& range) {
  const std::string what = object.name.empty() ? std::string("object") : object.name;
  if (!object.mesh) throw Error(what, "has no mesh to colour");
  colorMapIndex(map);  // an unknown name throws
  if (range && !usableColorRange(*range)) throw Error(what, kColorRangeRule);
  const Mesh& source = *object.mesh;
  FieldValues values = fieldValues(source, field, what);
  auto mesh = std::make_shared<Mesh>();
  if (!values.cellData) {
    *mesh = source;
    mesh->scalars = values.values;
  } else {
    // Corners of its own for every triangle, so that its value is constant across it.
    const std::size_t corners = source.indices.size();
    mesh->positions.reserve(corners);
    for (std::size_t c = 0; c < corners; ++c) {
      const std::uint32_t v = source.indices[c];
      mesh->positions.push_back(source.positions[v]);
      if (!source.normals.empty()) mesh->normals.push_back(source.normals[v]);
      if (!source.colors.empty()) mesh->colors.push_back(source.colors[v]);
      mesh->indices.push_back(static_cast<std::uint32_t>(c));
      mesh->scalars.push_back(values.values[c / 3]);
    }
    for (const MeshField& f : source.fields) {
      if (f.cellData) {
        mesh->fields.push_back(f);
        continue;
      }
      MeshField corner{f.name, false, f.components, {}};
      const auto n = static_cast<std::size_t>(f.components);
      corner.values.reserve(corners * n);
      for (std::size_t c = 0; c < corners; ++c)
        for (std::size_t k = 0; k < n; ++k) corner.values.push_back(f.values[source.indices[c] * n + k]);
      mesh->fields.push_back(std::move(corner));
    }
  }
  object.mesh = std::move(mesh);
  object.material.fieldColors = FieldColors{field, map, range ? *range : fieldRange(values.values)};
}

float VolumeFieldSampler::at(const glm::dvec3& objectPoint) const {
  // Each sample stands for the voxel around it: surfaces extracted from the volume reach a little
  // beyond its first and last samples.
  const glm::dvec3 g(objectToGrid * glm::dvec4(objectPoint, 1.0));
  const glm::dvec3 last(grid->dims - 1);
  const bool inside =
      glm::all(glm::greaterThanEqual(g, glm::dvec3(-0.5))) && glm::all(glm::lessThanEqual(g, last + 0.5));
  return inside ? grid->sample(glm::vec3(g)) : std::numeric_limits<float>::quiet_NaN();
}

VolumeFieldSampler VolumeFieldSampler::of(const Volume& volume, const glm::dmat4& objectTransform) {
  return {volume.grid, glm::inverse(volume.gridToWorld()) * objectTransform};
}

MeshField VolumeFieldSampler::atVertices(const std::string& name, const Mesh& mesh) const {
  MeshField f{name, false, 1, {}};
  f.values.reserve(mesh.positions.size());
  for (const glm::vec3& p : mesh.positions) f.values.push_back(at(glm::dvec3(p)));
  return f;
}

std::string volumeFieldName(const Scene& scene, std::size_t v) {
  const Volume& volume = scene.volumes.at(v);
  return "@" + (volume.name.empty() ? "volume " + std::to_string(v) : volume.name);
}

std::optional<std::string> ambiguousVolumeField(const Scene& scene, const std::string& field) {
  std::size_t named = 0;
  for (std::size_t v = 0; v < scene.volumes.size(); ++v) named += volumeFieldName(scene, v) == field;
  if (named < 2) return std::nullopt;
  return "'" + field + "' is the field of " + std::to_string(named) +
         " volumes (give them names to tell them apart; it meant the first)";
}

std::optional<VolumeFieldSampler> volumeFieldSampler(const Scene& scene, const Object& object) {
  const std::optional<FieldColors>& field = object.material.fieldColors;
  if (!field || field->field.empty() || field->field.front() != '@' || !object.mesh ||
      object.mesh->scalars.size() != object.mesh->positions.size())
    return std::nullopt;
  for (std::size_t v = 0; v < scene.volumes.size(); ++v) {
    const Volume& volume = scene.volumes[v];
    if (volume.grid && volumeFieldName(scene, v) == field->field)
      return VolumeFieldSampler::of(volume, object.transform);
  }
  return std::nullopt;
}

void addVolumeFields(Scene& scene) {
  for (Object& o : scene.objects) {
    if (!o.mesh) continue;
    std::shared_ptr<Mesh> mesh;
    for (std::size_t v = 0; v < scene.volumes.size(); ++v) {
      const Volume& volume = scene.volumes[v];
      if (!volume.grid) continue;
      const std::string name = volumeFieldName(scene, v);
      if (hasField(mesh ? *mesh : *o.mesh, name)) continue;
      if (!mesh) mesh = std::make_shared<Mesh>(*o.mesh);
      mesh->fields.push_back(VolumeFieldSampler::of(volume, o.transform).atVertices(name, *mesh));
    }
    if (mesh) o.mesh = std::move(mesh);
  }
}

bool hasField(const Mesh& mesh, const std::string& field) {
  const std::size_t colon = field.rfind(':');
  for (const MeshField& f : mesh.fields)
    if (f.name == field || (colon != std::string::npos && f.name == field.substr(0, colon))) return true;
  return false;
}

glm::dvec2 sharedFieldRange(const std::vector<const Mesh*>& meshes, const std::string& field) {
  std::vector<float> ends;  // each mesh's smallest and largest finite value
  for (const Mesh* mesh : meshes) {
    if (mesh == nullptr || !hasField(*mesh, field)) continue;
    if (const std::optional<glm::dvec2> span = finiteSpan(fieldValues(*mesh, field, "").values)) {
      ends.push_back(static_cast<float>(span->x));
      ends.push_back(static_cast<float>(span->y));
    }
  }
  return fieldRange(ends);
}

std::size_t colorObjectsByField(const std::vector<Object*>& objects, const std::string& field, const std::string& map,
                                const std::optional<glm::dvec2>& range, const std::string& what) {
  colorMapIndex(map);
  if (range && !usableColorRange(*range)) throw Error(what, kColorRangeRule);
  std::vector<Object*> having;
  std::vector<const Mesh*> meshes;
  std::vector<std::string> available;
  for (Object* o : objects) {
    if (o == nullptr || !o->mesh) continue;
    if (!hasField(*o->mesh, field)) {
      for (const std::string& n : fieldNames(*o->mesh))
        if (std::find(available.begin(), available.end(), n) == available.end()) available.push_back(n);
      continue;
    }
    (void)fieldValues(*o->mesh, field, o->name);  // a component the array lacks throws here, naming the part
    having.push_back(o);
    meshes.push_back(o->mesh.get());
  }
  if (having.empty()) {
    // Blamed on the array, these were puzzling: a volume alone has no surface to colour, and
    // "@NAME" names a volume, not an array.
    if (std::none_of(objects.begin(), objects.end(), [](const Object* o) { return o != nullptr && o->mesh; }))
      throw FieldNotFound(what, "no surfaces to colour (--contour adds isosurfaces of a volume)");
    if (field.starts_with('@')) {
      std::vector<std::string> volumes;
      for (const std::string& n : available)
        if (n.starts_with('@')) volumes.push_back(n);
      throw FieldNotFound(
          what, "no volume '" + field.substr(1) + "' to sample (" +
                    (volumes.empty() ? std::string("the scene has none") : "volumes: " + list(volumes)) + ")");
    }
    throw FieldNotFound(what, "no point-data or cell-data array '" + field + "' (" +
                                  (available.empty() ? std::string("it has none") : "fields: " + list(available)) +
                                  ")");
  }
  const glm::dvec2 shared = range ? *range : sharedFieldRange(meshes, field);
  for (Object* o : having) colorByField(*o, field, map, shared);
  return having.size();
}

}  // namespace mfr
