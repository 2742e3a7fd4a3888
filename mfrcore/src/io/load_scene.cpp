#include <algorithm>
#include <charconv>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>
#include <system_error>
#include <type_traits>
#include <vector>

#include "file_checks.hpp"
#include "invesalius_loader.hpp"
#include "mfr/error.hpp"
#include "mfr/io/load.hpp"
#include "mfr/scene/color_map.hpp"
#include "mfr/scene/sample.hpp"
#include "mfr/scene/scene_file.hpp"

namespace mfr {

void LoadProgress::step(double fraction) const {
  if (!tryStep(fraction)) throw LoadCancelled();
}

bool LoadProgress::tryStep(double fraction) const {
  return !report || report(begin + std::clamp(fraction, 0.0, 1.0) * (end - begin));
}

LoadProgress LoadProgress::part(double from, double to) const {
  return {report, begin + from * (end - begin), begin + to * (end - begin)};
}

namespace {

Scene loadSceneWithoutEndReport(const std::filesystem::path& path, const LoadOptions& options,
                                const LoadProgress& progress) {
  const std::string text = path.string();
  // A field is a volume file's to choose: a scene file names its own per volume ('field').
  if (!options.field.empty() && !isVolumeFile(path))
    throw Error(text, "field '" + options.field + "' can be chosen only for a volume file (" +
                          (path.extension() == ".mfrscene" || path.extension() == ".json"
                               ? std::string("a scene file gives each volume its own 'field'")
                               : std::string("this is not one")) +
                          ")");
  if (options.molecule && !isMoleculeFile(path))
    throw Error(text, "a molecule representation (" + options.molecule->text() +
                          ") can be chosen only for a molecule file (" +
                          (path.extension() == ".mfrscene" || path.extension() == ".json"
                               ? std::string("a scene file gives each molecule its own 'molecule'")
                               : std::string(".pdb .ent .cif .mmcif; this is not one")) +
                          ")");
  if (text == "@sample") return makeSampleScene();
  if (text == "@csg") return makeCsgSampleScene();
  if (text == "@intersect") return makeIntersectingSampleScene();
  if (text == "@volume") return makeVolumeSampleScene();
  if (text.rfind("@quads:", 0) == 0) {
    // @quads:N[:density[:seed]]
    // Each field whole: "@quads:4x", a negative or 20-digit seed (wrapped by %u) are refused.
    std::vector<std::string_view> fields;
    for (std::string_view rest = std::string_view(text).substr(7);;) {
      const std::size_t colon = rest.find(':');
      fields.push_back(rest.substr(0, colon));
      if (colon == std::string_view::npos) break;
      rest.remove_prefix(colon + 1);
    }
    const auto bad = [&] { return Error(text, "expected @quads:N[:density[:seed]] (N and seed whole numbers)"); };
    const auto whole = [&](std::string_view field, auto& value) {
      const auto [end, ec] = std::from_chars(field.data(), field.data() + field.size(), value);
      if (field.empty() || end != field.data() + field.size()) throw bad();
      // A whole number too large for its field was called "not whole" (a bug hunt): say its range.
      if (ec == std::errc::result_out_of_range) {
        const bool isSeed = std::is_unsigned_v<std::remove_reference_t<decltype(value)>>;
        if (!isSeed) throw Error("@quads", "layer count must be in [1, 4096]");
        throw Error(text, "expected @quads:N[:density[:seed]]: the seed " + std::string(field) +
                              " is beyond 4294967295 (32 bits)");
      }
      if (ec != std::errc()) throw bad();
    };
    if (fields.size() > 3) throw bad();
    int layers = 0;
    double density = 1.0;
    std::uint32_t seed = 1;
    whole(fields[0], layers);
    if (fields.size() > 1) {
      const std::string field(fields[1]);
      char* end = nullptr;
      density = field.empty() ? 0.0 : std::strtod(field.c_str(), &end);
      if (field.empty() || end != field.c_str() + field.size()) throw bad();
    }
    if (fields.size() > 2) whole(fields[2], seed);
    return makeQuadsScene(layers, density, seed);
  }
  if (!text.empty() && text[0] == '@')
    throw Error(text, "unknown built-in scene (@sample, @csg, @intersect, @volume, @quads:N[:density[:seed]])");
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  Scene scene;
  if (ext == ".mfrscene" || ext == ".json") {
    scene = readSceneFile(path, progress);
  } else {
    if (ext == ".inv3") {  // a volume with its segmented surfaces
      scene = io::loadInvesaliusScene(path, progress);
    } else {
      scene.name = path.filename().string();
      if (isVolumeFile(path)) {
        LoadOptions volume = options;
        volume.notes = &scene.notes;
        scene.volumes.push_back(loadVolume(path, volume, progress));
      } else {
        LoadOptions model{{}, options.molecule};
        model.notes = &scene.notes;
        scene.objects = loadModel(path, model, progress);
      }
    }
    for (const char* standard : {"front", "iso"}) scene.views.push_back({standard, *scene.standardView(standard)});
  }
  // The whole scene's faults name the file it came from: they named the scene's "name", which a
  // scene file may set to anything ("scene 'engine study': is 3.4641e-31 across…", a bug hunt).
  try {
    scene.validate();
  } catch (const Error& e) {
    const std::string prefix = "scene '" + scene.name + "': ", what = e.what();
    if (what.rfind(prefix, 0) != 0) throw;
    throw Error(text, what.substr(prefix.size()));
  }
  return scene;
}

}  // namespace

Scene loadScene(const std::filesystem::path& path, const LoadProgress& progress) {
  return loadScene(path, LoadOptions{}, progress);
}

Scene loadScene(const std::filesystem::path& path, const LoadOptions& options, const LoadProgress& progress) {
  progress.step(0.0);
  Scene scene = loadSceneWithoutEndReport(path, options, progress);
  // Names as UTF-8, whatever the file's encoding (JSON, Qt and messages need it; Latin-1 otherwise).
  // Parts' names are loadModel's to convert (every model file's parts come through it).
  scene.name = io::utf8Name(scene.name);
  // Not the fields: their names are the file's, to read them again by (JSON replaces what is not UTF-8).
  for (Volume& volume : scene.volumes) volume.name = io::utf8Name(volume.name);
  addVolumeFields(scene);  // a .mfrscene has them already (its color_by may use them)
  progress.step(1.0);
  return scene;
}

}  // namespace mfr
