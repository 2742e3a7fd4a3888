#pragma once
// Subcommands of mfr; each adds itself to the app and runs from its callback.
#include <CLI/CLI.hpp>

#include <charconv>
#include <cstdint>
#include <system_error>
#include <optional>
#include <sstream>
#include <map>
#include <string>

#include "mfr/io/load.hpp"
#include "mfr/io_util.hpp"
#include "mfr/reference/oracle.hpp"
#include "mfr/render.hpp"
#include "mfr/scene/clip_box.hpp"
#include "mfr/scene/scene.hpp"
#include "mfr/scene/section.hpp"

namespace mfr::cli {

void addRender(CLI::App& app);
void addCompare(CLI::App& app);
void addInfo(CLI::App& app);
void addBench(CLI::App& app);
void addDataset(CLI::App& app);
void addTrain(CLI::App& app);
void addEvaluate(CLI::App& app);
void addAllocations(CLI::App& app);
void addProbe(CLI::App& app);

// CommandFile and checkCommandFiles: mfr/io_util.hpp (mfrview's scripted runs check theirs too).
// The files a method's parameters name (its Text parameters: dkb's `weights`), as inputs given by
// `option`, so that checkCommandFiles refuses an output that would write over one. An unknown
// method adds nothing (it is refused elsewhere).
void addParameterFiles(std::vector<CommandFile>& files, const std::string& option, const std::string& method,
                       const std::map<std::string, std::string>& params);
// "WxH" → (w, h); throws mfr::Error naming the option.
std::pair<int, int> parseSize(const std::string& option, const std::string& text);
// The items of a list option; an empty item (a doubled or stray separator) is refused, naming the option.
std::vector<std::string> splitList(const std::string& text, const std::string& option, char separator = ',');
// Refuses an item named twice ("@sample @sample", --views iso,iso, --budgets f50,f50): the
// commands that loop over such lists did the work twice and counted it twice. Throws
// Error(option, "'item' is given twice").
void refuseRepeats(const std::vector<std::string>& items, const std::string& option);
// The same for files, spelt alike or not (./a.bin and a.bin, a link and its file: train took every
// row twice, so validation rows were training rows too; a bug hunt). Built-ins (@sample) by name.
void refuseRepeatedFiles(const std::vector<std::string>& paths, const std::string& option);
// The budget commands (dataset, evaluate, allocations) on a view of nothing: there is no budget to
// share (allocations printed "-nan %", evaluate "below what k = 1 needs" on every row, exit 0; a bug
// hunt). Throws Error(what, "nothing visible …").
void requireSomethingVisible(const FragmentLists& lists, const std::string& what);
// --field and --molecule: what to read of a file that holds several things.
struct ReadOptions {
  std::string field;                    // --field: the array or grid of a volume file
  std::optional<std::string> molecule;  // --molecule: a molecule file's representations
  void add(CLI::App* cmd);
  // The options as mfr::LoadOptions; throws mfr::Error("--molecule", reason) for a bad list.
  [[nodiscard]] LoadOptions load() const;
};
// loadScene with `read`, then every object's opacity set to `opacity` unless it is negative
// (--opacity).
Scene loadSceneWithOpacity(const std::string& path, double opacity, const ReadOptions& read = {});
// Every scene loaded (with --opacity) and every view checked before any work, so that a bad file
// or view fails at once; throws mfr::Error for an empty view list. A view whose frustum holds
// none of the scene's bounds at one of `sizes` (their aspect ratios) is refused too, as
// requireSomethingVisible refuses it later (evaluate and dataset printed rows of other views first).
std::vector<Scene> loadScenesWithViews(const std::vector<std::string>& paths, double opacity,
                                       const std::vector<std::string>& views,
                                       const std::vector<std::pair<int, int>>& sizes);
// CLI::Range lets NaN through (every comparison with it is false): a closed interval that refuses
// it, for opacities and fractions.
inline CLI::Validator finiteRange(double low, double high) {
  std::ostringstream bounds;
  bounds << "[" << low << ", " << high << "]";
  return CLI::Validator(
      [low, high, range = bounds.str()](std::string& text) -> std::string {
        double value = 0.0;
        if (!CLI::detail::lexical_cast(text, value) || !(value >= low && value <= high))
          return "'" + text + "' is not a number in " + range;
        return {};
      },
      bounds.str());
}

// Digits only, for unsigned options: CLI11 reads "-1" into an unsigned as 2^64 - 1.
inline CLI::Validator wholeNumber() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos)
          return "'" + text + "' is not a whole number (0, 1, 2, …)";
        // CLI11 clamped 2^64 and beyond to 2^64 − 1, which the dataset's metadata then recorded.
        std::uint64_t value = 0;
        if (std::from_chars(text.data(), text.data() + text.size(), value).ec != std::errc())
          return "'" + text + "' is beyond 18446744073709551615 (64 bits)";
        return {};
      },
      "");
}

// --clip: "xmin,ymin,zmin,xmax,ymax,zmax" (world units) sets scene.clipBox, "none" removes the
// scene's own; empty text leaves the scene as it is. Throws mfr::Error naming --clip.
void applyClipOption(Scene& scene, const std::string& text);
inline constexpr const char* kClipHelp =
    "Clip box xmin,ymin,zmin,xmax,ymax,zmax in world units: only what lies inside is drawn (surfaces cut "
    "open, the volume cropped); 'none' removes the scene's own";
// --section: "AXIS=VALUE" (AXIS one of x y z -x -y -z: the plane AXIS = VALUE, keeping the side the
// axis points to; "-z=0.5" keeps z <= 0.5) or "px,py,pz,nx,ny,nz" (a point and the normal of the kept
// side), each optionally followed by ":nocaps" and/or ":slice" (SectionPlane::slice); "none" removes the scene's own;
// empty text leaves the scene as it is. Then the scene is cut by its section (the option's or the scene file's; once,
// so that every renderer gets the cut scene), with a one-line note on stderr naming cut parts left without a cap
// because they are not closed; `report`, when given, gets sectionedScene's report (cleared when
// there is no section). Throws mfr::Error naming --section, or for the scene file's own section
// `sceneFile` and its key ("engine.mfrscene: section: cuts away every visible surface …").
void applySectionOption(Scene& scene, const std::string& text, const std::string& sceneFile,
                        SectionReport* report = nullptr);
inline constexpr const char* kSectionHelp =
    "Section plane: AXIS=VALUE (x, y, z, -x, -y, -z; keeps the side the axis points to) or "
    "px,py,pz,nx,ny,nz (point, normal of the kept side), optionally :nocaps and/or :slice (each volume's slice, "
    "grayscale over its transfer range); closed surfaces get caps; "
    "'none' removes the scene's own";
// --color-by FIELD [--color-map NAME] [--color-range LO,HI]: colour every part whose mesh has the
// field by it (colorByField) — before any section, so that caps get the field too.
struct ColorByOptions {
  std::string field, map, range;
  void add(CLI::App* cmd);
  // Throws mfr::Error naming the option: a map or range without --color-by, an unknown map, a bad
  // range, or a field no part has (listing the fields there are).
  void apply(Scene& scene) const;
};

// --contour [VOLUME=]V1,V2,… [--contour-opacity A] [--keep-volume]: isosurfaces of the scene's
// volume (the one named, when it has several) at the values, added as parts (addContours) — before
// --color-by, so that they can be coloured by a volume field. Their opacity: --contour-opacity, else
// --opacity, else 0.5. The volume they come from is hidden (ParaView hides a filter's input) unless
// --keep-volume. Throws mfr::Error naming the option.
// Returns, when it made isosurfaces, what --legend draws for them: the cool-warm map over
// contourColorRange, titled by the volume, ticked at their values.
struct ContourLegend {
  FieldColors colors;
  std::vector<double> ticks;
};
struct ContourOptions {
  std::string values;
  double opacity = -1.0;
  bool keepVolume = false;
  void add(CLI::App* cmd);
  std::optional<ContourLegend> apply(Scene& scene, double sceneOpacity) const;
  // After apply: throws mfr::Error naming --keep-volume (and `spec`, a bench row, when given) when
  // the request's operation does not draw the volume it keeps.
  void requireKeptVolumeDrawn(const RenderRequest& request, const Scene& scene, const std::string& spec = {}) const;
};

// --thickness (operation zthickness) as given: 0 when absent (the scene's default); throws
// mfr::Error naming --thickness for a given value that is not a positive finite length.
double thicknessOption(const CLI::Option& option, double value);
// The whole text as a finite number, or nothing ("1.5" yes; "1.5x", "", "nan", "inf" no).
std::optional<double> parseNumber(const std::string& text);
// "name" or "name:key=value:key=value" → request of w×h (a method run with several settings);
// op=… sets the operation (default "auto"). Throws mfr::Error naming --methods.
RenderRequest parseMethodSpec(const std::string& spec, int w, int h);
// The -p name=value options as a map. Throws mfr::Error("--param …") for one without a name or
// '=', and for a name given twice (the last silently won).
std::map<std::string, std::string> parseParamOptions(const std::vector<std::string>& params);
// A memory budget of mfr evaluate / mfr allocations: "3.5" MiB; "kN" the bytes of a uniform-k
// k+-buffer with the tail (fkb's layout) at k = N; "fN" the bytes with which the variable-k layout
// holds N % of the frame's fragments; "eN" N % of Σ max(1, n − 1), the slots after which hybrid
// transparency is exact everywhere; "xN" N % of Σ max(1, n − m) (fN, eN and xN resolved per frame
// by resolve()).
struct BudgetSpec {
  std::string label;
  double mib = 0.0;
  // fN: percent of Σn; eN: of Σ max(1, n − 1); xN: of Σ max(1, n − m), m(p) the final run of one
  // colour (the slots from which vkb and dkb are exact with their default bounds).
  enum class Of { Fragments, ExactSlots, ExactSlotsRuns };
  double fragmentPercent = 0.0;  // fN, eN, xN
  Of of = Of::Fragments;
  std::uint64_t bytes = 0;  // kN, fN, eN, xN: the exact byte count (0: mib as the user gave it)
  // fN, eN, xN: the bytes for a frame with Σn = total, Σ max(1, n − 1) = exactSlots and
  // Σ max(1, n − m) = exactSlotsRuns.
  void resolve(std::uint64_t total, std::uint64_t exactSlots, std::uint64_t exactSlotsRuns, std::uint64_t pixels);
  // budget_mib for the methods: exact byte counts half a byte up, so that their floor(MiB · 2^20)
  // gives back those bytes, not one less (a kN budget must hold k = N).
  [[nodiscard]] std::string paramText() const;
  [[nodiscard]] std::uint64_t byteCount() const;
};
constexpr double kLargestBudgetMiB = 65536.0;  // the budget methods' largest budget_mib (64 GiB)
// Throws mfr::Error naming --budgets.
BudgetSpec parseBudgetSpec(const std::string& item, std::uint64_t pixels);
// The comma-separated list of --budgets; throws mfr::Error for a bad item, an item given twice or
// an empty list.
std::vector<BudgetSpec> parseBudgetSpecs(const std::string& text, std::uint64_t pixels);
// Median of the values (0 for none).
double median(std::vector<double> values);

}  // namespace mfr::cli
