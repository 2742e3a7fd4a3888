#include <filesystem>
#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>
#include <optional>

#include "commands.hpp"
#include "mfr/error.hpp"
#include "mfr/operation_settings.hpp"
#include "mfr/image.hpp"
#include "mfr/io/load.hpp"
#include "mfr/io_util.hpp"
#include "mfr/gpu_renderer.hpp"
#include "mfr/legend.hpp"
#include "mfr/reference/metrics.hpp"
#include "mfr/reference/oracle.hpp"
#include "mfr/render.hpp"

namespace mfr::cli {

void addRender(CLI::App& app) {
  struct Options {
    ColorByOptions colorBy;
    ContourOptions contours;
    ReadOptions read;
    std::string scene, method = "oracle", op = "auto", size = "512x512", view = "fit", output, stats, clip, section,
                       dataView;
    std::vector<std::string> params;
    double opacity = -1.0;
    double thickness = 0.0;
    double step = 0.0;
    bool shade = false;
    bool legend = false;
    bool blend = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("render", "Render a scene with one method and write a PNG (and stats JSON)");
  cmd->add_option("scene", opt->scene, "Scene: model file, .mfrscene, or @sample")->required();
  cmd->add_option("--method,-m", opt->method, "Construction method (see mfr info --methods)")->capture_default_str();
  cmd->add_option("--op", opt->op,
                  "Operation on the sorted lists: auto (the method's own: hybrid for fkb, vkb, dkb, optimal-k; "
                  "zthickness for kbuffer-zmerge; else "
                  "oit), oit, hybrid, csg (the scene's CSG tree, opaque; oracle and the A-buffers), zthickness "
                  "(z-thickness blending: surfaces closer than --thickness blend; oracle, A-buffers, k-buffers), "
                  "volume (the scene's volume ray-marched between the sorted surfaces; auto picks it for a scene "
                  "with a volume; oracle, A-buffers, k-buffers)")
      ->capture_default_str();
  CLI::Option* thicknessGiven =
      cmd->add_option("--thickness", opt->thickness,
                      "Operation zthickness: slab thickness in scene units (default: 1 % of the scene's diagonal)");
  CLI::Option* stepOption = cmd->add_option(
      "--step", opt->step, "Operation volume: ray-march step in scene units (default: half the volume's grid spacing)");
  cmd->add_flag("--shade", opt->shade,
                "Operation volume: shade the volume by its gradient with a headlight (boundaries inside the medium "
                "read as surfaces)");
  cmd->add_flag("--legend", opt->legend,
                "Draw the colour map of --color-by (or the scene's color_by) with its field and values in the lower "
                "right corner, as ParaView's scalar bar");
  cmd->add_option("--data-view", opt->dataView,
                  "Write a per-pixel count instead of the image, as mfrview's data views (magma over 0 … its "
                  "largest value; --legend names it): depth-complexity (n(p), the fragments each pixel receives) or "
                  "capacity (k(p), the slots the method gave each pixel)")
      ->check(CLI::IsMember({"depth-complexity", "capacity"}));
  cmd->add_flag("--blend", opt->blend, "With --data-view: the map over the image, 1:1 (empty pixels show the image)");
  cmd->add_option("--clip", opt->clip, kClipHelp);
  opt->colorBy.add(cmd);
  opt->contours.add(cmd);
  opt->read.add(cmd);
  cmd->add_option("--section", opt->section, kSectionHelp);
  cmd->add_option("--size,-s", opt->size, "Image size WxH")->capture_default_str();
  cmd->add_option("--view", opt->view, "Named view of the scene, or 'fit'")->capture_default_str();
  cmd->add_option("--param,-p", opt->params, "Method parameter name=value (repeatable)");
  cmd->add_option("-o,--output", opt->output, "Output PNG")->required();
  cmd->add_option("--stats", opt->stats, "Write Stats as JSON to this file");
  cmd->add_option("--opacity", opt->opacity, "Override every object's opacity (0..1): see through opaque CAD parts")
      ->check(finiteRange(0.0, 1.0));
  cmd->callback([opt, thicknessGiven, stepOption] {
    const auto [w, h] = parseSize("--size", opt->size);
    // Both outputs checked before the work, so that a bad second path leaves no first file behind;
    // neither may be the scene, nor both one file (the JSON would replace the image just written).
    // A file a parameter names (dkb's weights) is read too.
    std::vector<CommandFile> files{{"scene", opt->scene, CommandFile::Role::kScene}};
    const std::map<std::string, std::string> named = parseParamOptions(opt->params);
    addParameterFiles(files, "-p", opt->method, named);
    files.push_back({"-o", opt->output, CommandFile::Role::kRequiredOutput});
    files.push_back({"--stats", opt->stats, CommandFile::Role::kOutput});
    checkCommandFiles(files);
    checkPngOutputName("-o", opt->output);
    RenderRequest req;
    req.method = opt->method;
    req.operation = opt->op;
    req.width = w;
    req.height = h;
    req.thickness = thicknessOption(*thicknessGiven, opt->thickness);
    if (stepOption->count() > 0 && !(opt->step > 0.0 && std::isfinite(opt->step)))
      throw Error("--step", "must be a positive length in scene units");
    req.volumeStep = opt->step;
    req.params = named;
    Scene scene = loadSceneWithOpacity(opt->scene, opt->opacity, opt->read);
    const std::optional<ContourLegend> contourLegend = opt->contours.apply(scene, opt->opacity);
    opt->colorBy.apply(scene);
    applyClipOption(scene, opt->clip);
    // fit and orbit:… frame the whole scene, cut or not (Scene::fit ignores the section), as
    // mfrview's camera does.
    const Camera camera = scene.view(opt->view);
    applySectionOption(scene, opt->section, opt->scene);
    requireSomethingToDraw(scene);
    if (stepOption->count() > 0 && scene.volumes.empty())
      throw Error("--step", "scene '" + scene.name + "' has no volume");
    if (opt->shade) {
      if (scene.volumes.empty()) throw Error("--shade", "scene '" + scene.name + "' has no volume");
      req.volumeShading = true;
    }
    if (const auto unused = unusedOperationSetting(req, scene)) throw Error("--" + unused->name, unused->reason);
    if (const auto unused = unusedMethodParam(req)) throw Error("--" + unused->name, unused->reason);
    opt->contours.requireKeptVolumeDrawn(req, scene);
    if (opt->blend && opt->dataView.empty()) throw Error("--blend", "needs --data-view");
    // A data view alone draws n(p) or k(p), not the image: a setting only the image uses was taken
    // and did nothing (hunt 32). With --blend the image is drawn under the map, and they count.
    if (!opt->dataView.empty() && !opt->blend)
      for (const auto& [given, option] :
           {std::pair{!opt->colorBy.field.empty(), "--color-by"}, std::pair{stepOption->count() > 0, "--step"},
            std::pair{opt->shade, "--shade"}, std::pair{thicknessGiven->count() > 0, "--thickness"}})
        if (given)
          throw Error(option, std::string("--data-view ") + opt->dataView + " draws " +
                                  (opt->dataView == "capacity" ? "k(p)" : "n(p)") +
                                  ", not the image: it uses nothing of this (add --blend to draw the image under it)");
    if (opt->dataView == "capacity" && opt->method == "oracle")
      throw Error("--data-view capacity", "the oracle keeps every fragment: it has no k(p) (use a method that does)");
    // --legend: the field colouring's map, else the isosurfaces' (ticked at their values).
    std::optional<ContourLegend> legend;
    if (opt->legend && !opt->dataView.empty()) {
      if (w < kMinLegendImageSize || h < kMinLegendImageSize)
        throw Error("--legend", "the image " + opt->size + " is too small for one: at least " +
                                    std::to_string(kMinLegendImageSize) + " pixels a side");
    } else if (opt->legend) {
      for (const Object& o : scene.objects)
        if (o.material.fieldColors) {
          legend = ContourLegend{*o.material.fieldColors, {}};
          break;
        }
      // One bar keys one colouring: parts coloured otherwise (a scene file's per-part color_by)
      // are said, not passed over (hunt 32).
      if (legend) {
        std::vector<std::string> others;
        for (const Object& o : scene.objects)
          if (o.material.fieldColors && *o.material.fieldColors != legend->colors) {
            const FieldColors& c = *o.material.fieldColors;
            const std::string text = "'" + o.name + "' (" + c.field + ", " + c.map + ")";
            if (std::find(others.begin(), others.end(), text) == others.end()) others.push_back(text);
          }
        if (!others.empty()) {
          std::string list;
          for (std::size_t i = 0; i < others.size() && i < 3; ++i) list += (i > 0 ? ", " : "") + others[i];
          if (others.size() > 3) list += ", … (" + std::to_string(others.size()) + " parts)";
          std::cerr << "note: --legend: the bar keys " << legend->colors.field << " (" << legend->colors.map
                    << "); also coloured otherwise: " << list << "\n";
        }
      }
      if (!legend) legend = contourLegend;
      if (!legend)
        throw Error("--legend",
                    "nothing is coloured by a field (use --color-by, or a scene's color_by) and there is "
                    "no --contour");
      if (w < kMinLegendImageSize || h < kMinLegendImageSize)
        throw Error("--legend", "the image " + opt->size + " is too small for one: at least " +
                                    std::to_string(kMinLegendImageSize) + " pixels a side");
    }
    RenderOutput out = render(scene, camera, req);
    // The GPU methods keep 32-bit window depths: GpuRenderer notes a given near and far that cannot
    // order what is drawn (the oracle casts in double precision).
    for (const auto& [key, note] : out.stats.notes)
      if (key == "depth precision") std::cerr << "note: view " << opt->view << ": " << note << "\n";
    if (!opt->dataView.empty()) {
      // n(p): the GPU's count pass for a GPU method, the oracle's lists for the CPU ones; k(p): the
      // method's own (GpuRenderer::kMap, optimal-k's allocation).
      const bool cpu = req.method == "oracle" || req.method == "optimal-k";
      const bool depth = opt->dataView == "depth-complexity";
      std::vector<std::uint32_t> counts;
      if (depth && cpu) {
        counts = std::move(out.depthComplexity);
      } else if (depth) {
        counts = headlessRenderer().depthComplexity(camera, w, h);
      } else {
        counts = cpu ? out.kMap : headlessRenderer().kMap();
      }
      if (counts.size() != static_cast<std::size_t>(w) * static_cast<std::size_t>(h))
        throw Error("--data-view capacity", "method " + req.method + " has no per-pixel capacity k(p)");
      const auto [lo, hi] = std::minmax_element(counts.begin(), counts.end());
      const std::string name = depth ? "n(p)" : "k(p)";
      out.stats.notes.emplace_back("data view", name + " " + std::to_string(*lo) + " … " + std::to_string(*hi));
      out.image = countHeatmap(counts, w, h, opt->blend ? &out.image : nullptr);
      if (opt->legend) {
        // Its text stands out from what lies under it: the map's dark end on empty pixels, not the
        // scene's background (black on black on a white scene; a bug hunt). The corner it sits in.
        const std::uint8_t* corner = out.image.at(w - 1, h - 1);
        const glm::vec3 under(corner[0] / 255.0f, corner[1] / 255.0f, corner[2] / 255.0f);
        drawColorLegend(out.image, FieldColors{name, "magma", glm::dvec2(0.0, std::max<std::uint32_t>(1, *hi))}, under);
      }
      std::cout << (depth ? "depth complexity " : "capacity ") << name << ": " << *lo << " … " << *hi << "\n";
    } else if (legend) {
      drawColorLegend(out.image, legend->colors, scene.background, legend->ticks);
    }
    // Both outputs are produced before either is written, and each is written atomically.
    std::vector<std::pair<std::filesystem::path, std::string>> outputs{
        {opt->output, encodePng(opt->output, out.image)}};
    if (!opt->stats.empty()) outputs.emplace_back(opt->stats, toJson(out.stats) + "\n");
    writeFilesAtomically(outputs);
    std::cout << opt->output << "\n";
  });
}

}  // namespace mfr::cli
