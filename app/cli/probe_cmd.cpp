// mfr probe: what lies behind one pixel — the oracle's exact sorted list (depth, part, colour,
// facing, share of the pixel's colour) and, with --method, which of those fragments the GPU method
// holds and the colour it draws there.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "mfr/json_text.hpp"
#include "mfr/error.hpp"
#include "mfr/operation_settings.hpp"
#include "mfr/gpu_renderer.hpp"
#include "mfr/image.hpp"
#include "mfr/io_util.hpp"
#include "mfr/reference/probe.hpp"
#include "mfr/render.hpp"

namespace mfr::cli {

namespace {

// Whole numbers in digits ("1e1" was 10; a value past int was undefined behaviour).
std::pair<int, int> parsePixel(const std::string& text) {
  const auto whole = [](std::string_view t, int& v) {
    const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
    return ec == std::errc() && end == t.data() + t.size() && !t.empty();
  };
  const auto comma = text.find(',');
  int x = 0, y = 0;
  if (comma != std::string::npos && whole(std::string_view(text).substr(0, comma), x) &&
      whole(std::string_view(text).substr(comma + 1), y))
    return {x, y};
  throw Error("--pixel " + text, "expected X,Y (whole pixels, 0,0 the top-left)");
}

std::string rgba(std::uint32_t packed) {
  char text[32];
  std::snprintf(text, sizeof text, "%3u %3u %3u %3u", packed & 0xffu, (packed >> 8) & 0xffu, (packed >> 16) & 0xffu,
                packed >> 24);
  return text;
}

nlohmann::ordered_json rgbaJson(std::uint32_t packed) {
  return {packed & 0xffu, (packed >> 8) & 0xffu, (packed >> 16) & 0xffu, packed >> 24};
}

int to8(float c) {
  return static_cast<int>(std::lround(std::clamp(c, 0.0f, 1.0f) * 255.0f));
}

}  // namespace

void addProbe(CLI::App& app) {
  struct Options {
    ColorByOptions colorBy;
    ContourOptions contours;
    ReadOptions read;
    std::string scene, pixel, size = "512x512", view = "fit", method, op = "auto", json, clip, section;
    std::vector<std::string> params;
    double opacity = -1.0;
    double thickness = 0.0;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "probe", "List what lies behind one pixel: the exact sorted fragments and which of them a method holds");
  cmd->add_option("scene", opt->scene, "Scene: model file, .mfrscene, or @sample")->required();
  cmd->add_option("--pixel", opt->pixel, "X,Y in image coordinates (0,0 the top-left pixel)")->required();
  cmd->add_option("--size,-s", opt->size, "Image size WxH")->capture_default_str();
  cmd->add_option("--view", opt->view, "Named view of the scene, or 'fit'")->capture_default_str();
  cmd->add_option("--method,-m", opt->method, "Also a GPU method: which fragments it holds, the colour it draws");
  cmd->add_option("--param,-p", opt->params, "Method parameter name=value (repeatable)");
  cmd->add_option("--op", opt->op,
                  "The method's operation, as for render (auto: hybrid for fkb, vkb, dkb; zthickness for "
                  "kbuffer-zmerge; volume for a scene with a volume and a method that draws it; else oit). With "
                  "hybrid, "
                  "each fragment's share under the method's split: the held ones the core, the rest the tail")
      ->capture_default_str();
  CLI::Option* thicknessGiven =
      cmd->add_option("--thickness", opt->thickness,
                      "Operation zthickness: slab thickness in scene units (default: 1 % of the scene's diagonal)");
  cmd->add_option("--json", opt->json, "Also write the probe as JSON");
  cmd->add_option("--clip", opt->clip, kClipHelp);
  opt->colorBy.add(cmd);
  opt->contours.add(cmd);
  opt->read.add(cmd);
  cmd->add_option("--section", opt->section, kSectionHelp);
  cmd->add_option("--opacity", opt->opacity, "Override every object's opacity (0..1)")->check(finiteRange(0.0, 1.0));
  cmd->callback([opt, thicknessGiven] {
    const auto [w, h] = parseSize("--size", opt->size);
    validateImageSize("--size", w, h);
    const auto [x, y] = parsePixel(opt->pixel);
    if (x < 0 || y < 0 || x >= w || y >= h) throw Error("--pixel " + opt->pixel, "outside the " + opt->size + " image");
    RenderRequest req;
    req.width = w;
    req.height = h;
    req.params = parseParamOptions(opt->params);
    const MethodInfo* info = nullptr;
    if (!opt->method.empty()) {
      info = findMethodInfo(opt->method);
      if (info == nullptr || opt->method == "oracle" || opt->method == "optimal-k")
        throw Error("--method " + opt->method, "not a GPU method (see mfr info --methods)");
      req.method = opt->method;
    } else if (!req.params.empty()) {
      throw Error("--param", "needs --method");
    }
    std::vector<CommandFile> files{{"scene", opt->scene, CommandFile::Role::kScene}};
    addParameterFiles(files, "-p", req.method, req.params);  // dkb's weights are read
    files.push_back({"--json", opt->json, CommandFile::Role::kOutput});
    checkCommandFiles(files);
    validateOperation(opt->op);
    // What the probe does not take apart was ignored, exit 0, and with a method its colour was
    // compared with "over" (a bug hunt): csg's classification, and hybrid's split without a method.
    if (opt->op == "csg")
      throw Error("--op csg",
                  "probe lists the fragments, it does not classify them (mfr render --op csg with -m oracle "
                  "gives the exact image)");
    if (opt->op == "hybrid" && opt->method.empty())
      throw Error("--op hybrid", "needs --method (the core and the tail are the method's split)");
    req.operation = opt->op;
    req.thickness = thicknessOption(*thicknessGiven, opt->thickness);
    Scene scene = loadSceneWithOpacity(opt->scene, opt->opacity, opt->read);
    opt->contours.apply(scene, opt->opacity);
    opt->colorBy.apply(scene);
    applyClipOption(scene, opt->clip);
    const Camera camera = scene.view(opt->view);  // fit frames the whole scene, cut or not
    applySectionOption(scene, opt->section, opt->scene);
    requireSomethingToDraw(scene);
    if (const auto unused = unusedOperationSetting(req, scene)) throw Error("--" + unused->name, unused->reason);
    if (const auto unused = unusedMethodParam(req)) throw Error("--" + unused->name, unused->reason);
    opt->contours.requireKeptVolumeDrawn(req, scene);
    PixelProbe probe = probePixel(scene, camera, w, h, x, y);
    // What the method (or, without one, the oracle) does with the lists: hybrid and volume are taken apart.
    const std::string operation = effectiveOperation(req.operation, info, scene.hasVisibleVolume());

    std::optional<glm::u8vec4> methodPixel;
    if (info != nullptr) {
      const RenderOutput out = render(scene, camera, req);  // also validates the parameters
      const std::uint8_t* p = out.image.at(x, y);
      methodPixel = glm::u8vec4(p[0], p[1], p[2], p[3]);
      if (info->sortedLists) {
        GpuRenderer& gpu = headlessRenderer();
        gpu.setScene(scene);
        // Room for every fragment the oracle sees and more, so a method holding extra ones shows.
        const int room = static_cast<int>(std::min<std::size_t>(probe.fragments.size() * 2 + 64, 1u << 16));
        const CapturedLists lists = gpu.capture(camera, req, room, PixelRect{x, y, 1, 1});
        const std::uint32_t count = lists.count(x, y);
        matchCapture(probe, {lists.pixel(x, y), std::min<std::size_t>(count, static_cast<std::size_t>(room))}, count);
        if (operation == "hybrid") splitHybrid(probe, scene.background);
      }
    }
    // The operation "volume" (a volume scene's own, with or without a method): surfaces and medium.
    if (operation == "volume") splitVolume(probe, scene, camera, req);
    // "zthickness": each surface's share of the blend.
    if (operation == "zthickness") splitZThickness(probe, scene, camera, req);

    std::ostringstream text;
    text << scene.name << ", view " << opt->view << ", " << w << "x" << h << ", pixel (" << x << ", " << y
         << "): " << probe.fragments.size() << " fragment" << (probe.fragments.size() == 1 ? "" : "s");
    if (probe.edge) text << " (on a triangle edge: rasterisation may differ)";
    if (probe.depthTie) text << " (two at one depth: order undefined)";
    text << "\n";
    char line[256];
    // The method's column, as wide as its name; then, with hybrid, each fragment's share and role
    // under the method's split, or with volume, its share of the colour through the medium.
    const int methodWidth = static_cast<int>(std::max<std::size_t>(opt->method.size(), 4));
    const auto methodColumn = [&](const char* held) {
      if (!probe.captured) return std::string();
      char column[64];
      std::snprintf(column, sizeof column, "  %-*s", methodWidth, held);
      return std::string(column);
    };
    // Parts coloured by a field: each fragment's value there, in a last column.
    const bool values =
        std::any_of(probe.fragments.begin(), probe.fragments.end(), [](const ProbeFragment& f) { return f.hasValue; });
    std::snprintf(line, sizeof line, "%4s  %12s  %-24s  %-15s  %-5s  %7s%s%s%s\n", "#", "eye depth", "part", "RGBA",
                  "faces", "weight", methodColumn(opt->method.c_str()).c_str(),
                  probe.hybrid       ? "   hybrid"
                  : probe.volume     ? "   volume"
                  : probe.zthickness ? "   zthick"
                                     : "",
                  values ? "  field value" : "");
    text << line;
    nlohmann::ordered_json fragments = nlohmann::ordered_json::array(), medium = nlohmann::ordered_json::array();
    // A stretch of the volume's medium that adds to the pixel: its mean colour and share.
    const auto mediumRow = [&](std::size_t before) {
      const ProbeMedium& m = probe.medium[before];
      if (m.weight < 5e-5) return;
      const glm::vec3 mean = m.color / static_cast<float>(m.weight);
      char rgb[32];
      std::snprintf(rgb, sizeof rgb, "%3d %3d %3d", to8(mean.r), to8(mean.g), to8(mean.b));
      std::snprintf(line, sizeof line, "%4s  %12s  %-24s  %-15s  %-5s  %7s%s  %7.4f\n", "", "", "(medium)", rgb, "", "",
                    methodColumn("").c_str(), m.weight);
      text << line;
      nlohmann::ordered_json row = {
          {"before", before}, {"rgb", {m.color.r, m.color.g, m.color.b}}, {"weight", m.weight}};
      if (probe.volumeNames.size() > 1) {
        // Several volumes: each one's part of the stretch's share (their media mix where they overlap).
        nlohmann::ordered_json byVolume = nlohmann::ordered_json::object();
        for (std::size_t v = 0; v < probe.volumeNames.size(); ++v) {
          byVolume[probe.volumeNames[v]] = m.weightByVolume[v];
          if (m.weightByVolume[v] < 5e-5) continue;
          const std::string label = "(medium) " + probe.volumeNames[v];
          std::snprintf(line, sizeof line, "%4s  %12s    %-22.22s  %-15s  %-5s  %7s%s  %7.4f\n", "", "", label.c_str(),
                        "", "", "", methodColumn("").c_str(), m.weightByVolume[v]);
          text << line;
        }
        row["weight_by_volume"] = byVolume;
      }
      medium.push_back(row);
    };
    for (std::size_t i = 0; i < probe.fragments.size(); ++i) {
      const ProbeFragment& f = probe.fragments[i];
      const std::uint32_t object = f.fragment.objectId;
      const std::string part = object < scene.objects.size() ? scene.objects[object].name : "?";
      // Which side of the part the ray meets, by the part's own winding: a mirroring placement
      // reverses the winding in the world, and the outside of a mirrored sphere read "back" (a bug hunt).
      const bool mirrored =
          object < scene.objects.size() && glm::determinant(glm::dmat3(scene.objects[object].transform)) < 0.0;
      const bool front = f.fragment.frontFacing != mirrored;
      if (probe.volume) mediumRow(i);
      char share[32] = "";
      if (probe.hybrid) std::snprintf(share, sizeof share, "  %7.4f %s", f.hybridWeight, f.held ? "core" : "tail");
      if (probe.volume) std::snprintf(share, sizeof share, "  %7.4f", f.volumeWeight);
      if (probe.zthickness) std::snprintf(share, sizeof share, "  %7.4f", f.zthicknessWeight);
      std::string value;
      if (f.hasValue)
        value = "  " + scene.objects[object].material.fieldColors->field + " " + std::to_string(f.value);
      else if (values)
        value = "  -";
      std::snprintf(line, sizeof line, "%4zu  %12.6g  %-24.24s  %-15s  %-5s  %7.4f%s%s%s\n", i + 1, f.eyeDepth,
                    part.c_str(), rgba(f.fragment.color).c_str(), front ? "front" : "back", f.weight,
                    methodColumn(f.held ? "held" : "-").c_str(), share, value.c_str());
      text << line;
      nlohmann::ordered_json j;
      j["depth"] = f.fragment.depth;
      j["eye_depth"] = f.eyeDepth;
      j["object"] = object;
      j["part"] = part;
      j["rgba"] = rgbaJson(f.fragment.color);
      j["front_facing"] = front;
      j["weight"] = f.weight;
      if (probe.captured) j["held"] = f.held;
      if (probe.hybrid) j["hybrid_weight"] = f.hybridWeight;
      if (probe.volume) j["volume_weight"] = f.volumeWeight;
      if (probe.zthickness) j["zthickness_weight"] = f.zthicknessWeight;
      if (f.hasValue) {
        j["field"] = scene.objects[object].material.fieldColors->field;
        j["field_value"] = f.value;
      }
      fragments.push_back(j);
    }
    if (probe.volume) mediumRow(probe.fragments.size());
    std::snprintf(line, sizeof line, "%4s  %12s  %-24s  %-15s  %-5s  %7.4f%s", "", "", "background", "", "",
                  probe.transmittance, methodColumn("").c_str());
    text << line;
    if (probe.hybrid || probe.volume || probe.zthickness) {
      std::snprintf(line, sizeof line, "  %7.4f",
                    probe.hybrid   ? probe.hybridBackground
                    : probe.volume ? probe.volumeBackground
                                   : probe.zthicknessBackground);
      text << line;
    }
    text << "\n";
    const glm::ivec3 exact(to8(probe.exactColor.r), to8(probe.exactColor.g), to8(probe.exactColor.b));
    text << "exact colour (over): " << exact.r << " " << exact.g << " " << exact.b << "\n";
    // Under "volume" the exact colour is the surfaces' and the medium's together.
    const glm::ivec3 reference =
        probe.volume ? glm::ivec3(to8(probe.volumeColor.r), to8(probe.volumeColor.g), to8(probe.volumeColor.b))
        : probe.zthickness
            ? glm::ivec3(to8(probe.zthicknessColor.r), to8(probe.zthicknessColor.g), to8(probe.zthicknessColor.b))
            : exact;
    if (probe.zthickness) {
      text << "exact colour (zthickness " << probe.thickness << "): " << reference.r << " " << reference.g << " "
           << reference.b << " (" << probe.zthicknessBlended << " of the " << probe.fragments.size()
           << " surfaces lie within the thickness of a neighbour and blend)\n";
    }
    if (probe.volume) {
      double mediumShare = 0.0;
      std::vector<double> shareByVolume(probe.volumeNames.size(), 0.0);
      for (const ProbeMedium& m : probe.medium) {
        mediumShare += m.weight;
        for (std::size_t v = 0; v < shareByVolume.size(); ++v) shareByVolume[v] += m.weightByVolume[v];
      }
      text << "exact colour (volume: surfaces and medium): " << reference.r << " " << reference.g << " " << reference.b
           << " (the medium's share " << std::lround(100.0 * mediumShare) << " %";
      if (shareByVolume.size() > 1)
        for (std::size_t v = 0; v < shareByVolume.size(); ++v)
          text << (v == 0 ? ": " : ", ") << probe.volumeNames[v] << " " << std::lround(100.0 * shareByVolume[v])
               << " %";
      text << ")\n";
    }

    nlohmann::ordered_json j;
    j["scene"] = scene.name;
    j["view"] = opt->view;
    j["width"] = w;
    j["height"] = h;
    j["x"] = x;
    j["y"] = y;
    j["edge"] = probe.edge;
    j["depth_tie"] = probe.depthTie;
    j["fragments"] = fragments;
    j["background_weight"] = probe.transmittance;
    j["exact_rgb"] = {exact.r, exact.g, exact.b};
    if (probe.zthickness) {
      j["operation"] = "zthickness";
      j["thickness"] = probe.thickness;
      j["zthickness_rgb"] = {reference.r, reference.g, reference.b};
      j["zthickness_background_weight"] = probe.zthicknessBackground;
    }
    if (probe.volume) {
      j["operation"] = "volume";
      j["volumes"] = probe.volumeNames;
      j["medium"] = medium;
      j["volume_rgb"] = {reference.r, reference.g, reference.b};
      j["volume_background_weight"] = probe.volumeBackground;
    }
    if (methodPixel) {
      const int diff = std::max({std::abs(methodPixel->r - reference.r), std::abs(methodPixel->g - reference.g),
                                 std::abs(methodPixel->b - reference.b)});
      text << opt->method << " colour: " << int(methodPixel->r) << " " << int(methodPixel->g) << " "
           << int(methodPixel->b) << " (largest difference from exact " << diff << "/255)\n";
      nlohmann::ordered_json m;
      m["name"] = opt->method;
      m["params"] = req.params;
      m["rgb"] = {methodPixel->r, methodPixel->g, methodPixel->b};
      m["max_difference"] = diff;
      if (probe.captured) {
        text << opt->method << " holds " << probe.methodCount << " fragment" << (probe.methodCount == 1 ? "" : "s")
             << ", " << probe.heldCount() << " of the " << probe.fragments.size() << " exact ones";
        if (probe.unmatched > 0) text << "; " << probe.unmatched << " at no exact fragment's depth";
        text << "\n";
        m["holds"] = probe.methodCount;
        m["held_exact"] = probe.heldCount();
        m["unmatched"] = probe.unmatched;
        if (probe.hybrid) {
          const glm::ivec3 hybrid(to8(probe.hybridColor.r), to8(probe.hybridColor.g), to8(probe.hybridColor.b));
          const glm::ivec3 fromExact = glm::abs(hybrid - exact),
                           fromMethod = glm::abs(hybrid - glm::ivec3(*methodPixel));
          const std::size_t tail = probe.fragments.size() - probe.heldCount();
          text << "hybrid colour (core: the " << probe.heldCount() << " held, tail: the other " << tail
               << " by weighted average): " << hybrid.r << " " << hybrid.g << " " << hybrid.b
               << " (largest difference from exact " << std::max({fromExact.r, fromExact.g, fromExact.b})
               << "/255, from " << opt->method << "'s " << std::max({fromMethod.r, fromMethod.g, fromMethod.b})
               << "/255)\n";
          m["operation"] = "hybrid";
          m["hybrid_rgb"] = {hybrid.r, hybrid.g, hybrid.b};
          m["hybrid_background_weight"] = probe.hybridBackground;
        }
      } else {
        text << opt->method << " keeps no per-pixel lists (its image only)\n";
      }
      j["method"] = m;
    }
    if (!opt->json.empty()) writeFileAtomically(opt->json, jsonText(j, 2) + "\n");
    std::cout << text.str();
  });
}

}  // namespace mfr::cli
