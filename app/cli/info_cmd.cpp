#include <algorithm>
#include <cmath>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <map>
#include <memory>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "mfr/json_text.hpp"
#include "mfr/error.hpp"
#include "mfr/io/load.hpp"
#include "mfr/io/molecule.hpp"
#include "mfr/io_util.hpp"
#include "mfr/methods/method.hpp"
#include "mfr/reference/composite.hpp"
#include "mfr/reference/oracle.hpp"
#include "mfr/render.hpp"
#include "mfr/scene/color_map.hpp"
#include "mfr/scene/measure.hpp"

namespace mfr::cli {

namespace {

// Bounds with the digits their size needs: six significant digits beyond those the coordinates
// spend on their distance from the origin, so a unit part at 1e7 reads [9999999.5 …] – [10000000.5 …]
// (printed as 1e+07 – 1e+07 before: hunt 31), while an ordinary scene reads as before. At most
// 15, the digits a double holds for sure: more printed a float's noise (0.49999999999950001).
std::string boundsText(const Bounds& b) {
  const glm::dvec3 size = b.max - b.min;
  const double extent = std::max({size.x, size.y, size.z});
  const double far = std::max({std::abs(b.min.x), std::abs(b.min.y), std::abs(b.min.z), std::abs(b.max.x),
                               std::abs(b.max.y), std::abs(b.max.z)});
  int digits = 6;
  if (extent > 0.0 && far > extent && std::isfinite(far / extent))
    digits = std::min(15, 6 + static_cast<int>(std::ceil(std::log10(far / extent))));
  std::ostringstream out;
  out.precision(digits);
  out << "[" << b.min.x << ", " << b.min.y << ", " << b.min.z << "] – [" << b.max.x << ", " << b.max.y << ", "
      << b.max.z << "]";
  return out.str();
}

// Every method render() accepts, where it runs, what it is and its parameters (name, type,
// default, range or choices): what -m and -p take.
nlohmann::ordered_json methodsJson() {
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (const std::string& name : availableMethods()) {
    const MethodInfo* info = findMethodInfo(name);
    nlohmann::ordered_json params = nlohmann::ordered_json::array();
    if (info)
      for (const ParamSpec& p : info->params) {
        static const char* const kTypes[] = {"int", "float", "bool", "choice", "text"};
        nlohmann::ordered_json param = {{"name", p.name},
                                        {"type", kTypes[static_cast<int>(p.type)]},
                                        {"default", p.defaultValue},
                                        {"help", p.help.empty() ? p.label : p.help}};
        if (p.type == ParamSpec::Type::Int || p.type == ParamSpec::Type::Float) param["range"] = {p.min, p.max};
        if (p.type == ParamSpec::Type::Choice) param["choices"] = p.choices;
        // fkb's tail and the exact tail: another default where no tail is composited.
        if (const std::string other = defaultValueFor(p, "oit"); other != p.defaultValue)
          param["default_outside_hybrid"] = other;
        if (!p.onlyWith.empty()) param["only_with"] = p.onlyWith;
        params.push_back(param);
      }
    const bool gpu = info && name != "optimal-k";
    list.push_back({{"name", name},
                    {"runs_on", gpu ? "gpu" : "cpu"},
                    {"title", info ? info->title : "Exact reference: ray-cast per-pixel fragment lists (the oracle)"},
                    {"operation", info ? info->preferredOperation : "oit"},
                    {"params", params}});
  }
  return list;
}

std::string numberText(double v) {
  std::ostringstream text;
  text << v;
  return text.str();
}

void printMethods(const nlohmann::ordered_json& methods) {
  for (const auto& m : methods) {
    std::cout << m["name"].get<std::string>() << "  (" << m["runs_on"].get<std::string>() << ") "
              << m["title"].get<std::string>() << "\n";
    std::string line;
    for (const auto& p : m["params"]) {
      std::string values;
      if (p.contains("choices"))
        for (const auto& c : p["choices"]) values += (values.empty() ? "" : "|") + c.get<std::string>();
      else if (p.contains("range"))
        values = numberText(p["range"][0].get<double>()) + ".." + numberText(p["range"][1].get<double>());
      else if (p["type"] == "bool")
        values = "true|false";
      std::string notes = values;
      if (p.contains("default_outside_hybrid"))
        notes += "; " + p["default_outside_hybrid"].get<std::string>() + " outside hybrid";
      if (p.contains("only_with")) notes += "; only with " + p["only_with"].get<std::string>();
      line += (line.empty() ? "" : ", ") + p["name"].get<std::string>() + "=" + p["default"].get<std::string>() +
              (notes.empty() ? "" : " (" + notes + ")");
    }
    if (!line.empty()) std::cout << "    -p " << line << "\n";
  }
}

}  // namespace

void addInfo(CLI::App& app) {
  struct Options {
    ReadOptions read;
    std::string scene, size = "256x256", view = "fit", json, section;
    bool methods = false, noHistogram = false;
    ContourOptions contours;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("info", "Describe a scene: parts, triangles, bounds, depth-complexity histogram");
  cmd->add_option("scene", opt->scene, "Scene: model file, .mfrscene, or @sample");
  cmd->add_flag("--methods", opt->methods, "List the available methods");
  CLI::Option* sizeOption =
      cmd->add_option("--size,-s", opt->size, "Image size for the depth-complexity histogram")->capture_default_str();
  CLI::Option* viewOption = cmd->add_option("--view", opt->view, "View for the histogram")->capture_default_str();
  cmd->add_flag("--no-histogram", opt->noHistogram, "Skip the oracle pass");
  opt->read.add(cmd);
  opt->contours.add(cmd);
  cmd->add_option("--section", opt->section,
                  std::string(kSectionHelp) +
                      "; parts are then measured as cut (a capped solid's kept volume "
                      "and its cross-section area)");
  cmd->add_option("--json", opt->json, "Also write the information as JSON");
  cmd->callback([opt, sizeOption, viewOption] {
    checkCommandFiles(
        {{"scene", opt->scene, CommandFile::Role::kScene}, {"--json", opt->json, CommandFile::Role::kOutput}});
    // Only the histogram uses them: given without one, they were dropped without a word (a bug hunt).
    for (const auto& [option, name] : {std::pair{sizeOption, "--size"}, std::pair{viewOption, "--view"}}) {
      if (option->count() == 0) continue;
      if (opt->noHistogram) throw Error(name, "only the histogram uses it, and --no-histogram skips it");
      if (opt->scene.empty()) throw Error(name, "only a scene's histogram uses it (mfr info SCENE)");
    }
    if (opt->methods) {
      const nlohmann::ordered_json methods = methodsJson();
      printMethods(methods);
      if (opt->scene.empty()) {
        if (!opt->json.empty())
          writeFileAtomically(opt->json, jsonText(nlohmann::ordered_json{{"methods", methods}}, 2) + "\n");
        return;
      }
    }
    if (opt->scene.empty()) throw Error("info", "needs a scene (or --methods)");
    const auto [w, h] = parseSize("--size", opt->size);
    Scene scene = loadScene(opt->scene, opt->read.load());
    for (const std::string& note : scene.notes) std::cerr << "note: " << note << "\n";
    opt->contours.apply(scene, -1.0);
    // The scene's bounds and the histogram's view ignore the section (Scene::bounds and fit, like
    // the clip box): the whole scene's, as without --section and as mfrview's Clip dock spans them.
    const Bounds b = scene.bounds();
    // The histogram's view, checked before anything is printed: a bad --view is one line.
    const std::optional<Camera> histogramView =
        opt->noHistogram ? std::nullopt : std::optional<Camera>(scene.view(opt->view));
    // Hidden as the scene file says: the section hides the parts it removes, which were listed as
    // hidden (a bug hunt); they are "removed by the section".
    std::vector<bool> hiddenByScene;
    for (const Object& o : scene.objects) hiddenByScene.push_back(!o.visible);
    const auto hiddenPart = [&](std::size_t i) { return i < hiddenByScene.size() && hiddenByScene[i]; };
    SectionReport section;
    applySectionOption(scene, opt->section, opt->scene, &section);
    const bool sectioned = !section.outcomes.empty();
    const auto outcome = [&](std::size_t i) { return sectioned ? section.outcomes[i] : SectionOutcome::kKept; };
    // The oracle's pass before anything is printed too: a scene it refuses (only degenerate
    // triangles: "nothing to render") is one line, not a report and then an error.
    std::optional<FragmentLists> lists;
    if (histogramView) {
      OracleOptions counting;
      counting.countsOnly = true;  // the histogram needs n(p) only
      lists = castFragments(scene, *histogramView, w, h, counting);
    }
    std::vector<SurfaceMeasures> measures;
    for (const Object& o : scene.objects) measures.push_back(measureSurface(*o.mesh, o.transform));
    nlohmann::ordered_json j;
    j["scene"] = scene.name;
    if (opt->methods) j["methods"] = methodsJson();
    j["parts"] = scene.objects.size();
    j["triangles"] = scene.triangleCount();
    j["bounds"] = {{"min", {b.min.x, b.min.y, b.min.z}}, {"max", {b.max.x, b.max.y, b.max.z}}};
    // A scene file's clip box: the histogram counts what it keeps, the measures are of whole parts;
    // said, as the section is (it was not: hunt 32).
    j["clip"] =
        scene.clipBox
            ? nlohmann::ordered_json{{"min", {scene.clipBox->min.x, scene.clipBox->min.y, scene.clipBox->min.z}},
                                     {"max", {scene.clipBox->max.x, scene.clipBox->max.y, scene.clipBox->max.z}}}
            : nlohmann::ordered_json(nullptr);
    j["views"] = scene.viewNames();
    // A molecule: its atoms and bonds as drawn (the first model, the first alternative locations).
    // A file whose bonds cannot be found (atoms packed denser than any molecule) still loads as
    // spheres: its line says why the bonds are not counted.
    std::optional<MoleculeStructure> molecule;
    std::string bondsError;
    if (isMoleculeFile(opt->scene)) {
      try {
        molecule = readMoleculeStructure(opt->scene);
        j["molecule"] = {{"atoms", molecule->atoms.size()},
                         {"bonds", molecule->bonds.size()},
                         {"models", molecule->models},
                         {"representations", opt->read.load().molecule.value_or(MoleculeStyle{}).text()}};
        // Atoms per element (PyMOL's count_atoms elem X), in the order of the periodic table.
        std::map<int, std::size_t> perElement;
        for (const MoleculeAtom& a : molecule->atoms) ++perElement[a.atomicNumber];
        nlohmann::ordered_json elements = nlohmann::ordered_json::object();
        for (const auto& [number, count] : perElement) elements[elementSymbol(number)] = count;
        j["molecule"]["elements"] = elements;
        // Atoms per part, as drawn.
        std::vector<std::size_t> perPart(molecule->parts.size(), 0);
        for (const MoleculeAtom& a : molecule->atoms) ++perPart[a.part];
        nlohmann::ordered_json atomParts = nlohmann::ordered_json::object();
        for (std::size_t p = 0; p < perPart.size(); ++p) atomParts[molecule->parts[p]] = perPart[p];
        j["molecule"]["parts"] = atomParts;
        // Secondary structure, as the cartoon draws it: per chain one letter per residue (H helix,
        // E strand, - loop), in file order.
        std::vector<std::string> letters(molecule->parts.size());
        for (const BackboneResidue& r : molecule->residues) letters[r.part] += secondaryStructureLetter(r.structure);
        nlohmann::ordered_json chains = nlohmann::ordered_json::object();
        for (std::size_t p = 0; p < letters.size(); ++p)
          if (!letters[p].empty()) chains[molecule->parts[p]] = letters[p];
        if (!molecule->residues.empty())
          j["molecule"]["secondary_structure"] = {
              {"source", molecule->secondaryStructureFromFile ? "file" : "dssp"},
              {"file_records_unmatched", molecule->secondaryStructureRecordsUnmatched},
              {"chains", chains}};
      } catch (const Error& e) {
        bondsError = e.what();
        j["molecule"] = {{"error", bondsError}};
      }
    }
    if (sectioned) {
      const SectionPlane& plane = *scene.section;
      j["section"] = {{"point", {plane.point.x, plane.point.y, plane.point.z}},
                      {"normal", {plane.normal.x, plane.normal.y, plane.normal.z}},
                      {"cut", section.cut},
                      {"capped", section.capped},
                      {"removed", section.removed},
                      {"open", section.open},
                      {"cross_section_area", section.totalCapArea()}};
    }
    nlohmann::ordered_json parts = nlohmann::ordered_json::array();
    for (const Object& o : scene.objects) {
      nlohmann::ordered_json fields = nlohmann::ordered_json::array();
      for (const std::string& f : fieldNames(*o.mesh)) {
        const FieldValues v = fieldValues(*o.mesh, f, o.name);
        const std::optional<glm::dvec2> r = finiteSpan(v.values);
        fields.push_back({{"name", f},
                          {"cell_data", v.cellData},
                          {"range", r ? nlohmann::ordered_json{r->x, r->y} : nlohmann::ordered_json()}});
      }
      const std::size_t i = static_cast<std::size_t>(&o - scene.objects.data());
      const SurfaceMeasures& m = measures[i];
      nlohmann::ordered_json part = {
          {"name", o.name},
          {"visible", !hiddenPart(i)},
          {"triangles", o.mesh->triangleCount()},
          {"area", m.area},
          {"closed", m.closed()},
          {"volume", m.closed() ? nlohmann::ordered_json(m.volume) : nlohmann::ordered_json()},
          {"boundary_edges", m.boundaryEdges},
          {"non_manifold_edges", m.nonManifoldEdges},
          {"orientation_flips", m.orientationFlips},
          {"fields", fields}};
      if (sectioned) {
        static const char* const kOutcomes[] = {"kept", "removed", "cut", "capped"};
        part["section"] = kOutcomes[static_cast<int>(outcome(i))];
        part["cross_section_area"] = section.capAreas[i];
        if (outcome(i) == SectionOutcome::kRemoved)  // nothing of it is left to measure
          for (const char* key :
               {"area", "closed", "volume", "boundary_edges", "non_manifold_edges", "orientation_flips"})
            part[key] = nullptr;
      }
      parts.push_back(std::move(part));
    }
    j["part_list"] = parts;
    const auto hidden = static_cast<std::size_t>(std::count(hiddenByScene.begin(), hiddenByScene.end(), true));
    // The total is of what is drawn; hidden parts are listed, marked, and said here (a bug hunt: the
    // list and the total disagreed without a word).
    std::cout << "scene      " << scene.name << "\nparts      " << scene.objects.size()
              << (hidden > 0 ? " (" + std::to_string(hidden) + " hidden)" : std::string()) << "\ntriangles  "
              << scene.triangleCount() << (hidden > 0 || section.removed > 0 ? " (of the visible parts)" : "")
              << "\nbounds     " << boundsText(b)
              << (scene.clipBox
                      ? "\nclip       " + boundsText(*scene.clipBox) +
                            " (the scene file's: the histogram counts what it keeps; parts are measured whole)"
                      : std::string())
              << "\nviews     ";
    for (const std::string& v : scene.viewNames()) std::cout << " " << v;
    std::cout << "\n";
    if (!bondsError.empty()) std::cout << "molecule   atoms and bonds not counted: " << bondsError << "\n";
    if (molecule)
      std::cout << "molecule   " << molecule->atoms.size() << " atoms, " << molecule->bonds.size() << " bonds"
                << (molecule->models > 1 ? " (model 1 of " + std::to_string(molecule->models) + ")" : std::string())
                << "; drawn as " << opt->read.load().molecule.value_or(MoleculeStyle{}).text() << "\n";
    if (molecule && !molecule->residues.empty()) {
      std::size_t helix = 0, strand = 0;
      for (const BackboneResidue& r : molecule->residues) {
        helix += r.structure == SecondaryStructure::Helix ? 1 : 0;
        strand += r.structure == SecondaryStructure::Strand ? 1 : 0;
      }
      std::cout << "           " << molecule->residues.size() << " polymer residues: " << helix << " helix, " << strand
                << " strand ("
                << (molecule->secondaryStructureFromFile ? "the file's HELIX/SHEET records"
                    : molecule->secondaryStructureRecordsUnmatched
                        ? "DSSP, from the backbone: the file's HELIX/SHEET records hold none of its residues"
                        : "DSSP, from the backbone")
                << ")\n";
    }
    if (sectioned) {
      const SectionPlane& plane = *scene.section;
      std::cout << "section    point " << plane.point.x << " " << plane.point.y << " " << plane.point.z << ", normal "
                << plane.normal.x << " " << plane.normal.y << " " << plane.normal.z << ": " << section.cut
                << (section.cut == 1 ? " part" : " parts") << " cut (" << section.capped << " capped), "
                << section.removed << " removed; cross-section area " << section.totalCapArea() << "\n";
    }
    const std::size_t shown = std::min<std::size_t>(scene.objects.size(), 20);
    for (std::size_t i = 0; i < shown; ++i) {
      const Object& o = scene.objects[i];
      std::cout << "  part " << i << ": " << o.name << " (" << o.mesh->triangleCount() << " triangles, rgba "
                << o.material.color.r << " " << o.material.color.g << " " << o.material.color.b << " "
                << o.material.color.a << (hiddenPart(i) ? ", hidden" : "") << ")\n";
      // Its surface in the world: area, and the volume it encloses when it is closed — as cut by the
      // section, whose cap makes a cut solid closed: the volume kept, and the cut's area.
      if (outcome(i) == SectionOutcome::kRemoved)
        std::cout << "    " << describeCut(outcome(i), 0.0) << "\n";
      else
        std::cout << "    " << describeSurface(measures[i])
                  << describeCut(outcome(i), sectioned ? section.capAreas[i] : 0.0) << "\n";
      if (!o.mesh->fields.empty()) {
        // What --color-by can use, with each field's range (cell data marked).
        std::cout << "    fields:";
        for (const std::string& f : fieldNames(*o.mesh)) {
          const FieldValues v = fieldValues(*o.mesh, f, o.name);
          std::cout << " " << f << (v.cellData ? " (cells)" : "");
          if (const std::optional<glm::dvec2> r = finiteSpan(v.values))
            std::cout << " [" << r->x << ", " << r->y << "]";
          else
            std::cout << " (no finite values)";
        }
        std::cout << "\n";
      }
    }
    if (shown < scene.objects.size()) std::cout << "  … " << scene.objects.size() - shown << " more parts\n";
    nlohmann::ordered_json volumes = nlohmann::ordered_json::array();
    for (const Volume& v : scene.volumes) {
      const glm::ivec3 d = v.grid->dims;
      const glm::vec2 range = v.grid->range();
      const Bounds vb = v.bounds();
      // The grid's steps in scene units, its transform included: a .vdb keeps its voxel size in
      // the transform, and "spacing 1 1 1" beside a default step of 0.3 contradicted itself.
      const glm::dmat4 toWorld = v.gridToWorld();
      const glm::dvec3 spacing(glm::length(glm::dvec3(toWorld[0])), glm::length(glm::dvec3(toWorld[1])),
                               glm::length(glm::dvec3(toWorld[2])));
      volumes.push_back({{"name", v.name},
                         {"dims", {d.x, d.y, d.z}},
                         {"spacing", {spacing.x, spacing.y, spacing.z}},
                         {"range", {range.x, range.y}},
                         {"bounds", {{"min", {vb.min.x, vb.min.y, vb.min.z}}, {"max", {vb.max.x, vb.max.y, vb.max.z}}}},
                         {"transfer_range", {v.transfer.low(), v.transfer.high()}},
                         {"unit_distance", v.transfer.unitDistance},
                         {"default_step", v.defaultStep()},
                         {"visible", v.visible},
                         {"field", v.field},
                         {"fields", v.fields}});
      std::cout << "  volume: " << v.name << (v.field.empty() ? "" : " [" + v.field + "]") << " (" << d.x << "x" << d.y
                << "x" << d.z << " points, spacing " << spacing.x << " " << spacing.y << " " << spacing.z << ", values "
                << range.x << " … " << range.y << ", transfer " << v.transfer.low() << " … " << v.transfer.high()
                << " per " << v.transfer.unitDistance << ", default step " << v.defaultStep()
                << (v.visible ? "" : ", hidden") << ")\n";
      if (v.fields.size() > 1) {
        std::cout << "    fields:";
        for (const std::string& f : v.fields) std::cout << " " << f << (f == v.field ? " (read)" : "");
        std::cout << "\n";
      }
    }
    j["volumes"] = volumes;
    if (lists) {
      const std::vector<std::uint64_t> hist = depthComplexityHistogram(*lists);
      j["depth_complexity"] = {{"size", opt->size},
                               {"view", opt->view},
                               {"max", lists->maxCount()},
                               {"fragments", lists->offsets.back()},
                               {"histogram", hist}};
      std::cout << "depth complexity (" << opt->size << ", view " << opt->view << "): max " << lists->maxCount() << ", "
                << lists->offsets.back() << " fragments\n";
      for (std::size_t n = 0; n < hist.size(); ++n)
        if (hist[n] > 0) std::cout << "  n=" << n << ": " << hist[n] << " pixels\n";
    }
    if (!opt->json.empty()) writeFileAtomically(opt->json, jsonText(j, 2) + "\n");
  });
}

}  // namespace mfr::cli
