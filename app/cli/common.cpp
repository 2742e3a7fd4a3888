#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <set>

#include "commands.hpp"
#include "mfr/budget/memory_model.hpp"
#include "mfr/error.hpp"
#include "mfr/io/load.hpp"
#include "mfr/io_util.hpp"
#include "mfr/render.hpp"
#include "mfr/reference/oracle.hpp"
#include "mfr/scene/clip_box.hpp"
#include "mfr/scene/color_map.hpp"
#include "mfr/scene/contour.hpp"
#include "mfr/list_text.hpp"
#include "mfr/operation_settings.hpp"
#include "mfr/scene/section.hpp"

namespace mfr::cli {

void addParameterFiles(std::vector<CommandFile>& files, const std::string& option, const std::string& method,
                       const std::map<std::string, std::string>& params) {
  const MethodInfo* info = findMethodInfo(method);
  if (info == nullptr) return;
  for (const ParamSpec& spec : info->params)
    if (const auto given = params.find(spec.name); spec.type == ParamSpec::Type::Text && given != params.end())
      files.push_back({option, given->second});
}

std::pair<int, int> parseSize(const std::string& option, const std::string& text) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  std::istringstream in(text);
  if (!(in >> w >> x >> h) || (x != 'x' && x != 'X') || (in >> extra))
    throw Error(option + " " + text, "expected WIDTHxHEIGHT, e.g. 800x600");
  validateImageSize(option + " " + text, w, h);
  return {w, h};
}

std::vector<std::string> splitList(const std::string& text, const std::string& option, char separator) {
  std::vector<std::string> items = mfr::text::splitList(text, separator);
  if (std::find(items.begin(), items.end(), std::string()) != items.end())
    throw Error(option + " " + text,
                std::string("an empty item ('") + separator + separator + "', or '" + separator + "' at an end)");
  return items;
}

void refuseRepeats(const std::vector<std::string>& items, const std::string& option) {
  for (std::size_t i = 0; i < items.size(); ++i)
    if (std::find(items.begin(), items.begin() + static_cast<std::ptrdiff_t>(i), items[i]) !=
        items.begin() + static_cast<std::ptrdiff_t>(i))
      throw Error(option, "'" + items[i] + "' is given twice");
}

void refuseRepeatedFiles(const std::vector<std::string>& paths, const std::string& option) {
  refuseRepeats(paths, option);
  for (std::size_t i = 0; i < paths.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (!paths[i].starts_with('@') && !paths[j].starts_with('@') && sameFile(paths[i], paths[j]))
        throw Error(option, "'" + paths[i] + "' is '" + paths[j] + "' again (one file given twice)");
}

void requireSomethingVisible(const FragmentLists& lists, const std::string& what) {
  if (lists.fragments.empty()) throw Error(what, "nothing visible (no pixel has a fragment)");
}

void ReadOptions::add(CLI::App* cmd) {
  cmd->add_option("--field", field,
                  "Volume file: the point-data array (.vti, .vtk) or grid (.vdb) to read instead of the default "
                  "(see mfr info for the file's fields)");
  cmd->add_option("--molecule", molecule,
                  "Molecule file (.pdb, .cif): how to draw it — spheres (default), sticks, ball-and-stick, cartoon "
                  "(helices, strands, loops), surface (solvent-excluded, per chain), or several joined by ',', each on "
                  "all parts or on @polymer, @ligands or @water (cartoon,sticks@ligands)");
}

LoadOptions ReadOptions::load() const {
  LoadOptions options(field);
  if (molecule) options.molecule = MoleculeStyle::parse(*molecule, "--molecule " + *molecule);
  return options;
}

Scene loadSceneWithOpacity(const std::string& path, double opacity, const ReadOptions& read) {
  Scene scene = loadScene(path, read.load());
  for (const std::string& note : scene.notes) std::cerr << "note: " << note << "\n";
  if (opacity >= 0.0)
    for (Object& o : scene.objects) o.material.color.a = static_cast<float>(opacity);
  return scene;
}

namespace {

// Whether every corner of `box` lies beyond one plane of the camera's frustum (clip space): then
// nothing in it can be seen. Each plane is a half-space of world space, behind the eye included,
// so the test never refuses a box that shows; a box that straddles planes passes.
bool outsideFrustum(const Bounds& box, const Camera& camera, double aspect) {
  if (!box.valid()) return false;
  const glm::dmat4 m = camera.projectionMatrix(aspect) * camera.viewMatrix();
  std::array<bool, 6> allOutside{true, true, true, true, true, true};
  for (int corner = 0; corner < 8; ++corner) {
    const glm::dvec4 c = m * glm::dvec4(box.corner(corner), 1.0);
    const std::array<bool, 6> outside{(c.x < -c.w), (c.x > c.w), (c.y < -c.w), (c.y > c.w), (c.z < -c.w), (c.z > c.w)};
    for (std::size_t plane = 0; plane < 6; ++plane) allOutside[plane] = allOutside[plane] && outside[plane];
  }
  return std::any_of(allOutside.begin(), allOutside.end(), [](bool b) { return b; });
}

}  // namespace

std::vector<Scene> loadScenesWithViews(const std::vector<std::string>& paths, double opacity,
                                       const std::vector<std::string>& views,
                                       const std::vector<std::pair<int, int>>& sizes) {
  if (views.empty()) throw Error("--views", "no view given");
  std::vector<Scene> scenes;
  for (const std::string& path : paths) {
    scenes.push_back(loadSceneWithOpacity(path, opacity));
    // Each view, and whether there is anything to draw, before any work: a scene of degenerate
    // triangles failed after the other scenes' rows were printed (a bug hunt).
    for (const std::string& v : views) {
      const Camera camera = scenes.back().view(v);
      checkDrawable(scenes.back(), camera, 1, 1, path);
      for (const auto& [w, h] : sizes)
        if (outsideFrustum(scenes.back().bounds(), camera, static_cast<double>(w) / h))
          throw Error(path + " view " + v, "nothing visible (the scene lies outside the view)");
    }
  }
  return scenes;
}

double thicknessOption(const CLI::Option& option, double value) {
  if (option.count() == 0) return 0.0;
  if (!(value > 0.0 && std::isfinite(value))) throw Error("--thickness", "must be a positive length in scene units");
  return value;
}

std::optional<double> parseNumber(const std::string& text) {
  return mfr::text::parseNumber(text);
}

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// "name" or "name:key=value:key=value" → request (a method may be benchmarked with several settings).
std::map<std::string, std::string> parseParamOptions(const std::vector<std::string>& params) {
  std::map<std::string, std::string> out;
  for (const std::string& p : params) {
    const auto eq = p.find('=');
    if (eq == std::string::npos || eq == 0) throw Error("--param " + p, "expected name=value");
    if (!out.emplace(p.substr(0, eq), p.substr(eq + 1)).second)
      throw Error("--param " + p, "'" + p.substr(0, eq) + "' is given twice");
  }
  return out;
}

RenderRequest parseMethodSpec(const std::string& spec, int w, int h) {
  RenderRequest r;
  r.width = w;
  r.height = h;
  r.operation = "auto";  // the method's own: hybrid for the budget methods (op=… overrides)
  bool first = true;
  std::set<std::string> keys;
  for (const std::string& part : mfr::text::splitList(spec, ':')) {
    if (first) {
      if (part.empty()) throw Error("--methods " + spec, "expected name:key=value:… (no method name)");
      r.method = part;
      first = false;
      continue;
    }
    const auto eq = part.find('=');
    if (eq == std::string::npos || eq == 0) throw Error("--methods " + spec, "expected name:key=value:…");
    // "step=1:step=2" meant one of them; the last silently won.
    if (!keys.insert(part.substr(0, eq)).second)
      throw Error("--methods " + spec, "'" + part.substr(0, eq) + "' is given twice");
    if (part.substr(0, eq) == "op") {
      r.operation = part.substr(eq + 1);
      continue;
    }
    if (part.substr(0, eq) == "step") {
      const std::optional<double> t = parseNumber(part.substr(eq + 1));
      if (!t || !(*t > 0.0) || !std::isfinite(*t))
        throw Error("--methods " + spec, "step must be a positive length in scene units");
      r.volumeStep = *t;
      continue;
    }
    if (part.substr(0, eq) == "shade") {
      const std::string v = part.substr(eq + 1);
      if (v != "0" && v != "1") throw Error("--methods " + spec, "shade must be 0 or 1");
      r.volumeShading = v == "1";
      continue;
    }
    if (part.substr(0, eq) == "thickness") {
      const std::optional<double> t = parseNumber(part.substr(eq + 1));
      if (!t || !(*t > 0.0) || !std::isfinite(*t))
        throw Error("--methods " + spec, "thickness must be a positive length in scene units");
      r.thickness = *t;
      continue;
    }
    r.params[part.substr(0, eq)] = part.substr(eq + 1);
  }
  return r;
}

BudgetSpec parseBudgetSpec(const std::string& item, std::uint64_t pixels) {
  BudgetSpec b;
  b.label = item;
  if (!item.empty() && (item[0] == 'f' || item[0] == 'e' || item[0] == 'x')) {
    const std::optional<double> percent = parseNumber(item.substr(1));
    if (!percent || !(*percent > 0.0) || *percent > 100.0)
      throw Error("--budgets " + item, item[0] == 'f' ? "expected fN with 0 < N <= 100 (% of the frame's fragments)"
                                       : item[0] == 'e'
                                           ? "expected eN with 0 < N <= 100 (% of the frame's Σ max(1, n − 1))"
                                           : "expected xN with 0 < N <= 100 (% of the frame's Σ max(1, n − m))");
    b.fragmentPercent = *percent;
    b.of = item[0] == 'f'   ? BudgetSpec::Of::Fragments
           : item[0] == 'e' ? BudgetSpec::Of::ExactSlots
                            : BudgetSpec::Of::ExactSlotsRuns;
    return b;
  }
  if (!item.empty() && item[0] == 'k') {
    const std::optional<double> k = parseNumber(item.substr(1));
    if (!k || !(*k >= 1.0) || *k > 256.0)
      throw Error("--budgets " + item, "expected kN with 1 <= N <= 256 (N may be fractional)");
    // bytes(k) = P·(8k + y) + z of fkb's layout, also for fractional k (between two uniform k).
    const KBufferMemoryModel m = kplusArrayMemoryModel(pixels);
    b.bytes = static_cast<std::uint64_t>(
        std::ceil(static_cast<double>(m.pixels) * (8.0 * *k + static_cast<double>(m.bytesPerPixel)) +
                  static_cast<double>(m.fixedBytes)));
    b.mib = static_cast<double>(b.bytes) / (1024.0 * 1024.0);
    if (b.mib > kLargestBudgetMiB)
      throw Error("--budgets " + item, "is " + std::to_string(static_cast<long long>(b.mib)) +
                                           " MiB at this size: at most " +
                                           std::to_string(static_cast<int>(kLargestBudgetMiB)) + " MiB");
    return b;
  }
  const std::optional<double> mib = parseNumber(item);
  if (!mib || *mib <= 0.0) throw Error("--budgets " + item, "expected MiB (a positive number), kN, fN, eN or xN");
  // The budget methods' largest budget_mib; beyond it byte counts would not fit their 64 bits either.
  if (*mib > kLargestBudgetMiB)
    throw Error("--budgets " + item, "at most " + std::to_string(static_cast<int>(kLargestBudgetMiB)) + " MiB");
  b.mib = *mib;
  return b;
}

std::vector<BudgetSpec> parseBudgetSpecs(const std::string& text, std::uint64_t pixels) {
  std::vector<BudgetSpec> budgets;
  const std::vector<std::string> items = splitList(text, "--budgets");
  refuseRepeats(items, "--budgets " + text);  // f50,f50 measured one case twice and counted it twice
  for (const std::string& b : items) {
    budgets.push_back(parseBudgetSpec(b, pixels));
    // Spelt otherwise (f50 and f50.0, 2 and 2.0): the same case twice as well (a bug hunt).
    const BudgetSpec& added = budgets.back();
    for (std::size_t i = 0; i + 1 < budgets.size(); ++i)
      if (budgets[i].mib == added.mib && budgets[i].bytes == added.bytes && budgets[i].of == added.of &&
          budgets[i].fragmentPercent == added.fragmentPercent)
        throw Error("--budgets " + text, "'" + b + "' is '" + budgets[i].label + "' again (one budget given twice)");
  }
  if (budgets.empty()) throw Error("--budgets", "no budget given");
  return budgets;
}

void BudgetSpec::resolve(std::uint64_t total, std::uint64_t exactSlots, std::uint64_t exactSlotsRuns,
                         std::uint64_t pixels) {
  if (!(fragmentPercent > 0.0)) return;
  const double whole = static_cast<double>(of == Of::Fragments    ? total
                                           : of == Of::ExactSlots ? exactSlots
                                                                  : exactSlotsRuns);
  const auto slots = static_cast<std::uint64_t>(std::ceil(fragmentPercent / 100.0 * whole));
  bytes = variableKLayout(pixels).bytes(slots);
  mib = static_cast<double>(bytes) / (1024.0 * 1024.0);
}

std::string BudgetSpec::paramText() const {
  // The byte count the methods floor back to: half a byte over it, to 10 decimals of MiB (1e-4
  // byte). Six decimals of the user's MiB rounded up to 1 byte over the budget (a bug hunt).
  // At the methods' largest budget_mib the half byte would cross it (every row refused, a review):
  // there the exact MiB, which floors to the same bytes.
  const double bytesNow = static_cast<double>(byteCount());
  // The shortest text that floors back to the bytes (8 MiB reads "8", not the "8.0000004768" the
  // methods' messages then showed; a bug hunt).
  for (int digits = 1; digits <= 17; ++digits)
    for (const double candidate : {bytesNow / (1024.0 * 1024.0), (bytesNow + 0.5) / (1024.0 * 1024.0)}) {
      std::ostringstream shortest;
      shortest << std::setprecision(digits) << candidate;
      const double read = std::stod(shortest.str());
      if (read <= kLargestBudgetMiB && std::floor(read * 1024.0 * 1024.0) == bytesNow &&
          shortest.str().find_first_of("eE") == std::string::npos)
        return shortest.str();
    }
  double mibText = (bytesNow + 0.5) / (1024.0 * 1024.0);
  if (mibText > kLargestBudgetMiB) mibText = bytesNow / (1024.0 * 1024.0);
  std::ostringstream s;
  s << std::fixed << std::setprecision(10) << mibText;
  return s.str();
}

std::uint64_t BudgetSpec::byteCount() const {
  return bytes ? bytes : static_cast<std::uint64_t>(std::floor(mib * 1024.0 * 1024.0));
}

void applyClipOption(Scene& scene, const std::string& text) {
  if (text.empty()) return;
  if (text == "none") {
    scene.clipBox.reset();
    return;
  }
  const Bounds box = parseClipBox(text, "--clip " + text);
  // A box that holds nothing of the scene draws an empty image, as a section plane that cuts away
  // everything would: both are refused (found by fuzzing).
  requireClipBoxHoldsScene(scene, box, "--clip " + text);
  scene.clipBox = box;
}

void ColorByOptions::add(CLI::App* cmd) {
  std::string maps;
  for (const std::string& n : colorMapNames()) maps += (maps.empty() ? "" : ", ") + n;
  cmd->add_option("--color-by", field,
                  "Colour every part that has this point-data or cell-data array by it (name, name:N for a "
                  "component, name:magnitude; see mfr info for the fields)");
  cmd->add_option("--color-map", map, "Colour map of --color-by: " + maps + " (default cool-warm)");
  cmd->add_option("--color-range", range, "Values at the ends of the colour map LO,HI (default: the field's range)");
}

void ColorByOptions::apply(Scene& scene) const {
  if (field.empty()) {
    if (!map.empty()) throw Error("--color-map " + map, "needs --color-by");
    if (!range.empty()) throw Error("--color-range " + range, "needs --color-by");
    return;
  }
  const std::string colourMap = map.empty() ? "cool-warm" : map;
  const std::vector<std::string>& maps = colorMapNames();
  if (std::find(maps.begin(), maps.end(), colourMap) == maps.end()) {
    std::string list;
    for (const std::string& n : maps) list += (list.empty() ? "" : ", ") + n;
    throw Error("--color-map " + colourMap, "unknown colour map (available: " + list + ")");
  }
  std::optional<glm::dvec2> values;
  if (!range.empty()) {
    const std::vector<std::string> items = splitList(range, "--color-range");
    std::optional<double> low, high;
    if (items.size() == 2) {
      low = parseNumber(items[0]);
      high = parseNumber(items[1]);
    }
    if (!low || !high || !(*high > *low)) throw Error("--color-range " + range, "expected LO,HI with LO < HI");
    values = glm::dvec2(*low, *high);
  }
  if (const std::optional<std::string> why = ambiguousVolumeField(scene, field))
    throw Error("--color-by " + field, *why);
  std::vector<Object*> objects;
  for (Object& o : scene.objects) objects.push_back(&o);
  try {
    colorObjectsByField(objects, field, colourMap, values, scene.name);
  } catch (const Error& e) {
    throw Error("--color-by " + field, e.what());
  }
}

void ContourOptions::add(CLI::App* cmd) {
  cmd->add_option("--contour", values,
                  "Isosurfaces of the scene's volume at these values, added as parts: V1,V2,… or VOLUME=V1,V2,… "
                  "when the scene has several volumes (at most " +
                      std::to_string(kMaxContourValues) + "); the volume itself is hidden unless --keep-volume");
  cmd->add_option("--contour-opacity", opacity, "Opacity of the --contour parts (default: --opacity, else 0.5)")
      ->check(finiteRange(0.0, 1.0));
  cmd->add_flag("--keep-volume", keepVolume, "With --contour: keep drawing the volume the isosurfaces come from");
}

std::optional<ContourLegend> ContourOptions::apply(Scene& scene, double sceneOpacity) const {
  if (values.empty()) {
    if (opacity >= 0.0) throw Error("--contour-opacity", "needs --contour");
    if (keepVolume) throw Error("--keep-volume", "needs --contour");
    // A volume alone has no surface for --opacity: it was taken and changed nothing (a bug hunt).
    if (sceneOpacity >= 0.0 && scene.objects.empty())
      throw Error("--opacity", "scene '" + scene.name +
                                   "' has no surfaces (a volume's opacity is its transfer function's; --contour "
                                   "adds isosurfaces)");
    return std::nullopt;
  }
  const std::string what = "--contour " + values;
  ContourRequest request;
  std::string list = values;
  // The last '=': values hold none, a volume's name may ('a=0.3=0.5' was read as volume 'a').
  const std::size_t eq = values.rfind('=');
  if (eq != std::string::npos) {
    const std::string name = values.substr(0, eq);
    list = values.substr(eq + 1);
    const auto it =
        std::find_if(scene.volumes.begin(), scene.volumes.end(), [&](const Volume& v) { return v.name == name; });
    if (it == scene.volumes.end()) {
      std::string names;
      for (const Volume& v : scene.volumes) names += (names.empty() ? "" : ", ") + v.name;
      throw Error(what, "no volume '" + name + "' in scene '" + scene.name + "'" +
                            (names.empty() ? std::string(" (it has none)") : " (volumes: " + names + ")"));
    }
    request.volume = static_cast<std::size_t>(it - scene.volumes.begin());
    const auto named =
        std::count_if(scene.volumes.begin(), scene.volumes.end(), [&](const Volume& v) { return v.name == name; });
    if (named > 1)
      throw Error(what, std::to_string(named) + " volumes of scene '" + scene.name + "' are named '" + name +
                            "': name them apart in the scene file");
  } else if (scene.volumes.size() > 1) {
    throw Error(what, "scene '" + scene.name + "' has " + std::to_string(scene.volumes.size()) +
                          " volumes: say which, as VOLUME=V1,V2,… (e.g. '" + scene.volumes[0].name + "=…')");
  }
  for (std::size_t start = 0;;) {  // every item, empty ones too ("0.3," is a mistake, not one value)
    const std::size_t end = list.find(',', start);
    const std::string item = list.substr(start, end == std::string::npos ? std::string::npos : end - start);
    const std::optional<double> v = parseNumber(item);
    if (!v)
      throw Error(what, (item.empty() ? std::string("an empty value") : "'" + item + "' is not a number") +
                            " (expected V1,V2,… or VOLUME=V1,V2,…)");
    request.values.push_back(*v);
    if (end == std::string::npos) break;
    start = end + 1;
  }
  request.opacity = static_cast<float>(opacity >= 0.0 ? opacity : sceneOpacity >= 0.0 ? sceneOpacity : 0.5);
  addContours(scene, request, what);
  Volume& volume = scene.volumes[request.volume];
  // Kept hidden, it is not drawn: a --keep-volume that changes nothing is refused (hunt 32).
  if (keepVolume && !volume.visible)
    throw Error("--keep-volume", "scene '" + scene.name + "' hides volume '" + volume.name +
                                     "' (\"visible\": false): there is nothing to keep drawing");
  if (!keepVolume) volume.visible = false;
  const glm::dvec2 range = contourColorRange(request.values, glm::dvec2(volume.grid->range()));
  return ContourLegend{{volume.name, "cool-warm", range}, request.values};
}

void ContourOptions::requireKeptVolumeDrawn(const RenderRequest& request, const Scene& scene,
                                            const std::string& spec) const {
  if (!keepVolume) return;
  if (const std::optional<std::string> reason = volumeNotDrawnReason(request, scene))
    throw Error(spec.empty() ? std::string("--keep-volume") : spec, (spec.empty() ? "" : "--keep-volume: ") + *reason);
}

namespace {

// `what`: the option that asked for the section, or the scene file and its key for the file's own.
void cutBySection(Scene& scene, SectionReport& report, const std::string& what) {
  report = {};
  if (!scene.section || scene.sectionCut) return;
  if (scene.section->slice && scene.volumes.empty())
    throw Error(what, "slice: scene '" + scene.name + "' has no volume");
  try {
    scene = sectionedScene(scene, &report);
  } catch (const Error& e) {
    // mfrcore names the component ("section plane: cuts away every visible surface …"); here the
    // argument or the file that gave the plane is known (neither was named: a bug hunt).
    static const std::string component = "section plane: ";
    const std::string message = e.what();
    if (message.rfind(component, 0) != 0) throw;
    throw Error(what, message.substr(component.size()));
  }
  for (const std::string& note : sectionNotes(*scene.section, report)) std::cerr << "note: " << note << "\n";
}

}  // namespace

void applySectionOption(Scene& scene, const std::string& text, const std::string& sceneFile, SectionReport* report) {
  SectionReport local;
  SectionReport& out = report ? *report : local;
  if (text == "none") {
    out = {};
    scene.section.reset();
    return;
  }
  if (text.empty()) {
    cutBySection(scene, out, sceneFile + ": section");
    return;
  }
  const std::string what = "--section " + text;
  const SectionPlane section = parseSectionPlane(text, what);
  scene.section = section;
  cutBySection(scene, out, what);
}

}  // namespace mfr::cli
