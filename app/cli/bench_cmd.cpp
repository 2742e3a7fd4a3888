#include <algorithm>
#include <chrono>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "mfr/json_text.hpp"
#include "mfr/error.hpp"
#include "mfr/operation_settings.hpp"
#include "mfr/gl/context.hpp"
#include "mfr/gpu_renderer.hpp"
#include "mfr/io/load.hpp"
#include "mfr/io_util.hpp"
#include "mfr/methods/method.hpp"
#include "mfr/methods/registry.hpp"
#include "mfr/reference/composite.hpp"
#include "mfr/reference/metrics.hpp"
#include "mfr/reference/oracle.hpp"
#include "mfr/render.hpp"

namespace mfr::cli {

namespace {
// A spec's error named by the spec given: "--param budget_mib=0: …" and "--op : …" named options
// never given (a bug hunt). Other errors (the machine's memory, a frame too large) go as they are.
[[noreturn]] void throwForSpec(const std::string& spec, const Error& e) {
  std::string reason = e.what();
  if (reason.starts_with("--param "))
    reason.erase(0, 8);
  else if (reason.starts_with("--op "))
    reason.replace(0, 5, "op=");
  else if (reason.starts_with("--method "))
    reason.erase(0, 9);
  else
    throw e;
  throw Error("--methods " + spec, reason);
}

std::string mib(std::uint64_t bytes) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(2) << static_cast<double>(bytes) / (1024.0 * 1024.0);
  return s.str();
}

}  // namespace

void addBench(CLI::App& app) {
  struct Options {
    ColorByOptions colorBy;
    ContourOptions contours;
    ReadOptions read;
    std::string scene, methods, size = "512x512", view = "fit", json, label, clip, section;
    int repeat = 5, warmup = 1;
    double opacity = -1.0;
    bool noQuality = false;
    bool sequential = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "bench", "Benchmark methods side by side: per-pass median time, memory, fragments, RMSE and FLIP vs the oracle");
  cmd->add_option("scene", opt->scene, "Scene: model file, .mfrscene, @sample or @quads:N[:density[:seed]]")
      ->required();
  cmd->add_option("--methods,-m", opt->methods, "Comma-separated methods, each name[:key=value…]")->required();
  cmd->add_option("--repeat,-r", opt->repeat, "Timed frames per method")
      ->capture_default_str()
      ->check(wholeNumber())
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--warmup", opt->warmup, "Untimed frames first")
      ->capture_default_str()
      ->check(wholeNumber())
      ->check(CLI::Range(0, 100));
  cmd->add_option("--size,-s", opt->size, "Image size WxH")->capture_default_str();
  cmd->add_option("--view", opt->view, "Named view")->capture_default_str();
  cmd->add_option("--clip", opt->clip, kClipHelp);
  opt->colorBy.add(cmd);
  opt->contours.add(cmd);
  opt->read.add(cmd);
  cmd->add_option("--section", opt->section, kSectionHelp);
  cmd->add_option("--opacity", opt->opacity, "Override every object's opacity (0..1)")->check(finiteRange(0.0, 1.0));
  cmd->add_flag("--no-quality", opt->noQuality, "Skip the oracle and the RMSE/FLIP columns");
  cmd->add_flag("--sequential", opt->sequential,
                "All frames of one method, then the next, each freeing its buffers before the next starts "
                "(for methods whose buffers do not fit the GPU together); default: round-robin");
  cmd->add_option("--json", opt->json, "Write all results as JSON");
  cmd->callback([opt] {
    std::vector<CommandFile> files{{"scene", opt->scene, CommandFile::Role::kScene}};
    const auto [w, h] = parseSize("--size", opt->size);
    std::vector<RenderRequest> requests;
    const std::vector<std::string> specs = splitList(opt->methods, "--methods");
    refuseRepeats(specs, "--methods");  // one configuration timed twice, in two rows of one label (a review)
    for (const std::string& spec : specs) {
      requests.push_back(parseMethodSpec(spec, w, h));
      // The oracle's refusal comes from the registry; optimal-k, a CPU method too, would be refused
      // there as an unknown method.
      const RenderRequest& req = requests.back();
      if (req.method == "optimal-k")
        throw Error("--methods " + spec,
                    "a CPU method, not a GPU one: bench times the GPU methods (optimal-k "
                    "runs in mfr evaluate and mfr render)");
      // Named by the option given (the registry's refusal named --method).
      if (req.method == "oracle")
        throw Error("--methods " + spec, "the CPU reference, not a GPU method: bench measures every row against it");
      // The whole spec before any work, so that a typo costs no oracle and prints no half table.
      const MethodInfo* info = findMethodInfo(req.method);
      if (!info) {
        std::string gpuMethods;
        for (const std::string& m : availableMethods())
          if (m != "oracle" && m != "optimal-k") gpuMethods += (gpuMethods.empty() ? "" : ", ") + m;
        throw Error("--methods " + spec, "unknown method (available: " + gpuMethods + ")");
      }
      try {
        (void)Params(info->params, req.params, req.method);
        validateOperation(req.operation);
      } catch (const Error& e) {
        throwForSpec(spec, e);
      }
      addParameterFiles(files, "--methods " + spec, req.method, req.params);  // dkb's weights are read
    }
    if (requests.empty()) throw Error("--methods", "no method given");
    files.push_back({"--json", opt->json, CommandFile::Role::kOutput});
    checkCommandFiles(files);
    Scene scene = loadSceneWithOpacity(opt->scene, opt->opacity, opt->read);
    opt->contours.apply(scene, opt->opacity);
    opt->colorBy.apply(scene);
    applyClipOption(scene, opt->clip);
    const Camera camera = scene.view(opt->view);  // fit frames the whole scene, cut or not
    applySectionOption(scene, opt->section, opt->scene);
    requireSomethingToDraw(scene);
    for (std::size_t i = 0; i < requests.size(); ++i) {
      if (scene.volumes.empty() && (requests[i].volumeStep > 0.0 || requests[i].volumeShading.has_value()))
        throw Error("--methods " + specs[i], "step and shade are the volume's; scene '" + scene.name + "' has none");
      if (const auto unused = unusedOperationSetting(requests[i], scene))
        throw Error("--methods " + specs[i], unused->name + ": " + unused->reason);
      if (const auto unused = unusedMethodParam(requests[i]))
        throw Error("--methods " + specs[i], unused->name + ": " + unused->reason);
      opt->contours.requireKeptVolumeDrawn(requests[i], scene, "--methods " + specs[i]);
    }

    ImageRGBA8 reference;
    ImageRGBA8 csgReference;  // the oracle's CSG image, for rows with op=csg
    FragmentLists lists;      // for rows with op=zthickness (each row's own thickness)
    double oracleMs = 0.0;
    std::uint64_t totalFragments = 0;
    if (!opt->noQuality) {
      const auto t0 = std::chrono::steady_clock::now();
      lists = castFragments(scene, camera, w, h);
      reference = compositeOver(lists, scene.background);
      if (!scene.csg.empty()) csgReference = compositeCsg(lists, scene);
      oracleMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      totalFragments = lists.fragments.size();
    }
    GpuRenderer& gpu = headlessRenderer();
    gpu.setScene(scene);
    const gl::ContextInfo info = gl::queryContextInfo();

    nlohmann::ordered_json out;
    out["scene"] = scene.name;
    out["size"] = opt->size;
    out["view"] = opt->view;
    out["repeat"] = opt->repeat;
    out["order"] = opt->sequential ? "sequential: every frame of one method, then the next method"
                                   : "round-robin: frame i of every method, then frame i + 1";
    out["renderer"] = info.renderer;
    out["gl_version"] = info.version;
    out["timing"] =
        GpuRenderer::defaultFinishTiming() ? "glFinish + CPU clock per pass (llvmpipe)" : "GPU timestamp queries";
    // Not measured under --no-quality: null, not 0 (which read as a measurement).
    out["oracle_fragments"] = opt->noQuality ? nlohmann::ordered_json() : nlohmann::ordered_json(totalFragments);
    out["oracle_ms"] = opt->noQuality ? nlohmann::ordered_json() : nlohmann::ordered_json(oracleMs);
    nlohmann::ordered_json rows = nlohmann::ordered_json::array();

    // One renderer per method (sharing the scene), frames interleaved round-robin: a slow spell
    // of the machine then falls on every method alike, so the ratios between rows hold better
    // than with one method's frames after another's. The price is every method's buffers at once;
    // --sequential runs one method at a time and frees its buffers before the next.
    struct Run {
      const RenderRequest* req = nullptr;
      std::string spec;  // as given in --methods, for its errors
      std::unique_ptr<GpuRenderer> gpu;
      std::vector<std::pair<std::string, std::vector<double>>> perPass;
      std::vector<double> totals;
      RenderOutput last;
    };
    std::vector<Run> runs;
    for (const RenderRequest& req : requests) {
      Run run{&req, specs[static_cast<std::size_t>(&req - requests.data())], std::make_unique<GpuRenderer>(), {}, {},
              {}};
      run.gpu->shareScene(gpu);
      runs.push_back(std::move(run));
    }
    const auto render = [&](Run& run) {
      try {
        return run.gpu->render(camera, *run.req);
      } catch (const Error& e) {
        throwForSpec(run.spec, e);
      }
    };
    const auto frame = [&](Run& run) {
      run.last = render(run);
      run.totals.push_back(run.last.stats.totalTimeMs());
      for (const auto& timed : run.last.stats.passTimesMs) {
        const auto& pass = timed.first;  // a name, not a binding: the lambda below captures it
        const auto ms = timed.second;
        auto it = std::find_if(run.perPass.begin(), run.perPass.end(), [&](const auto& p) { return p.first == pass; });
        if (it == run.perPass.end())
          run.perPass.push_back({pass, {ms}});
        else
          it->second.push_back(ms);
      }
    };
    const auto warmUp = [&](Run& run) {
      for (int i = 0; i < opt->warmup; ++i) (void)render(run);
    };
    if (opt->sequential) {
      for (Run& run : runs) {
        warmUp(run);
        for (int i = 0; i < opt->repeat; ++i) frame(run);
        run.gpu.reset();  // its buffers go before the next method allocates
      }
    } else {
      for (Run& run : runs) warmUp(run);
      for (int i = 0; i < opt->repeat; ++i)
        for (Run& run : runs) frame(run);
    }
    // The table's head once every frame has rendered: a method that fails leaves one line, not a
    // head without rows.
    std::cout << "scene " << scene.name << ", " << opt->size << ", view " << opt->view << ", " << opt->repeat
              << " frames each (" << (opt->sequential ? "sequential" : "round-robin")
              << "), renderer: " << info.renderer << "\n";
    std::cout << std::left << std::setw(34) << "method" << std::right << std::setw(11) << "total ms" << std::setw(11)
              << "MiB alloc" << std::setw(10) << "MiB used" << std::setw(11) << "frags" << std::setw(11) << "stored"
              << std::setw(9) << "RMSE" << std::setw(9) << "FLIP"
              << "  passes (median ms)\n";
    for (Run& run : runs) {
      const RenderRequest& req = *run.req;
      const std::vector<double>& totals = run.totals;
      const auto& perPass = run.perPass;
      const RenderOutput& last = run.last;
      // The entry as given: rebuilt from the parsed request, its parameters came out sorted by name
      // (kplus-heap:k=8:culling=false read kplus-heap:culling=false:k=8).
      const std::string& label = run.spec;
      nlohmann::ordered_json row;
      row["method"] = label;
      row["median_total_ms"] = median(totals);
      nlohmann::ordered_json passes = nlohmann::ordered_json::object();
      std::ostringstream passText;
      for (const auto& [pass, v] : perPass) {
        passes[pass] = median(v);
        passText << " " << pass << "=" << std::fixed << std::setprecision(1) << median(v);
      }
      row["median_pass_ms"] = passes;
      row["bytes_allocated"] = last.stats.bytesAllocated;
      row["bytes_used"] = last.stats.bytesUsed;
      row["fragments_generated"] = last.stats.fragmentsGenerated;
      row["fragments_stored"] = last.stats.fragmentsStored;
      row["fragments_dropped"] = last.stats.fragmentsDropped;
      // How the k-buffers synchronised (spin lock or interlock) and what the spin lock lost.
      row["sync"] = last.stats.sync;
      row["lock_failures"] = last.stats.lockFailures;
      row["overflow"] = last.stats.overflow;
      row["overflow_pixels"] = last.stats.overflowPixels;  // as render's stats and evaluate's rows
      row["passes"] = last.stats.passes;
      std::string rmseText = "-", flipText = "-";
      if (!opt->noQuality) {
        // The reference of the operation the row ran ("auto": the method's own).
        const MethodInfo* rowInfo = findMethodInfo(req.method);
        const std::string op = effectiveOperation(req.operation, rowInfo, scene.hasVisibleVolume());
        const auto volumeReference = [&] {
          const std::vector<Volume> drawn = volumesAsRequested(req, scene);
          return compositeVolume(lists, camera, drawn, volumeStepOf(req, drawn), scene.background, scene.clipBox,
                                 scene.section);
        };
        const ImageRGBA8 exact =
            op == "csg" ? csgReference
            : op == "zthickness"
                ? compositeZThickness(lists, camera, zThicknessOf(req, scene.bounds()), scene.background)
            : op == "volume" ? volumeReference()
                             : reference;
        const double e = rmse(exact, last.image);
        const FlipResult f = flip(exact, last.image);
        row["rmse"] = e;
        row["flip_mean"] = f.stats.mean;
        std::ostringstream a, b;
        a << std::fixed << std::setprecision(4) << e;
        b << std::fixed << std::setprecision(4) << f.stats.mean;
        rmseText = a.str();
        flipText = b.str();
      }
      nlohmann::ordered_json notes = nlohmann::ordered_json::object();
      for (const auto& [k, v] : last.stats.notes) notes[k] = v;
      row["notes"] = notes;
      rows.push_back(row);
      std::cout << std::left << std::setw(34) << label << std::right << std::fixed << std::setprecision(1)
                << std::setw(11) << median(totals) << std::setw(11) << mib(last.stats.bytesAllocated) << std::setw(10)
                << mib(last.stats.bytesUsed) << std::setw(11) << last.stats.fragmentsGenerated << std::setw(11)
                << last.stats.fragmentsStored << std::setw(9) << rmseText << std::setw(9) << flipText << " "
                << passText.str() << (last.stats.overflow ? "  OVERFLOW" : "") << "\n";
    }
    out["results"] = rows;
    if (!opt->json.empty()) writeFileAtomically(opt->json, jsonText(out, 2) + "\n");
  });
}

}  // namespace mfr::cli
