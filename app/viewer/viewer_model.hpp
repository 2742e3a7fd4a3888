#pragma once
// The viewer's state — scene, camera, the method of each pane, parameters, last frames' Stats,
// compare mode, the data view — and the work it runs off the GUI thread: loading (with progress
// and cancel), CPU images (the oracle and any other CPU method), depth-complexity histograms
// and image metrics. Widgets and plugins observe it through ViewerContext's signals (and the
// model's own); RenderView draws it.
//
// Sides: side 0 is the main method (ViewerContext's method()); side 1 is the second method of
// compare mode. Each side has its own method, operation and parameters per method.
#include <QColor>
#include <QImage>
#include <QList>
#include <QMap>
#include <QSize>
#include <QString>

#include <array>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "mfr/scene/section.hpp"
#include "mfr/image.hpp"
#include "mfr/io/load.hpp"
#include "mfr/reference/metrics.hpp"
#include "mfr/render.hpp"
#include "mfr/scene/scene.hpp"
#include "viewer_plugin.hpp"

class QTimer;

constexpr int kSides = 2;

enum class CompareLayout { SideBySide, Split };
// What each pane shows in compare mode: its image, or its error against the exact image.
enum class CompareDisplay { Images, FlipError, Difference };

// What determines an image: scene and view revisions, size, and the request (method, operation,
// parameters) as text.
struct ImageKey {
  quint64 scene = 0, view = 0;
  QSize size;
  std::string request;
  bool operator==(const ImageKey&) const = default;
};

// An image computed on the CPU by mfr::render (the oracle, or another CPU method).
struct CpuImage {
  ImageKey key;
  mfr::ImageRGBA8 image;
  mfr::Stats stats;
  QString error;  // why there is no image
};

// One pane's frame against the exact image of the same size.
struct PaneMetrics {
  ImageKey key;
  bool valid = false;
  QString method;
  QString error;
  double rmse = 0.0;
  mfr::FlipStats flip;
  float maxDifference = 0.0f;     // largest per-pixel |difference| (the difference map's scale)
  mfr::ImageRGBA8 flipMap;        // magma of the FLIP error, 0 … 1
  mfr::ImageRGBA8 differenceMap;  // magma of |difference| / maxDifference
};

// A QImage sharing the pixels of `image` (which must outlive it).
QImage wrapImage(const mfr::ImageRGBA8& image);

// Entries to things by name: the n-th entry of a name goes to the n-th thing of that name, so that a
// session keeps its settings for what a scene file still has after it gained, lost or reordered
// things (by index, a renamed or moved one took another's settings). With `unnamedByIndex` an
// entry without a name (a hand-written session's volume) goes by its index, if no named entry took
// that thing. -1: no thing for the entry. Sessions match their objects and volumes with it.
std::vector<int> matchByName(const QStringList& entries, const QStringList& names, bool unnamedByIndex = false);

class ViewerModel final : public ViewerContext {
  Q_OBJECT

 public:
  using ParamsByMethod = std::map<std::string, std::map<std::string, std::string>>;

  explicit ViewerModel(QObject* parent = nullptr);
  ~ViewerModel() override;

  // ViewerContext (side 0)
  [[nodiscard]] QStringList methodNames() const override;
  [[nodiscard]] const mfr::MethodInfo* methodInfo(const QString& method) const override;
  [[nodiscard]] QString method() const override { return methodOf(0); }
  void setMethod(const QString& method) override { setMethodOf(0, method); }
  [[nodiscard]] std::map<std::string, std::string> params() const override { return paramsOf(0); }
  void setParams(const std::map<std::string, std::string>& changes) override { setParamsOf(0, changes); }
  [[nodiscard]] bool hasScene() const override { return hasScene_; }
  [[nodiscard]] quint64 sceneSerial() const override { return sceneSerial_; }
  [[nodiscard]] QString frameError() const override { return mainPaneFailed() ? renderErrorShown() : QString(); }
  [[nodiscard]] const mfr::Stats& stats() const override { return stats_[0]; }
  [[nodiscard]] QSize renderSize() const { return renderSize_; }  // the whole view's pixels
  [[nodiscard]] QSize imageSize() const override { return paneSize(); }
  void requestDepthComplexity() override;
  void requestFrameQuality() override;
  [[nodiscard]] FrameQuality frameQuality() const override;
  [[nodiscard]] DataView dataView() const override { return dataView_; }
  [[nodiscard]] bool dataViewOverImage() const override { return dataOverImage_; }
  void setDataView(DataView view, bool overImage) override;

  // Methods rendered on the CPU by mfr::render (listed by mfr::availableMethods() but not GPU
  // methods of the registry): "oracle", and e.g. "optimal-k" once mfrcore has it.
  [[nodiscard]] bool isCpuMethod(const QString& method) const override;

  // Per side (0: main, 1: compare).
  [[nodiscard]] QString methodOf(int side) const { return methods_[index(side)]; }
  void setMethodOf(int side, const QString& method);
  [[nodiscard]] QString operationOf(int side) const { return operations_[index(side)]; }
  void setOperationOf(int side, const QString& operation);
  [[nodiscard]] std::map<std::string, std::string> paramsOf(int side) const;
  void setParamsOf(int side, const std::map<std::string, std::string>& changes);
  // Parameters set per method (sessions keep those of every method the user touched).
  [[nodiscard]] const ParamsByMethod& allParamsOf(int side) const { return params_[index(side)]; }
  void setAllParamsOf(int side, ParamsByMethod params);
  [[nodiscard]] mfr::RenderRequest renderRequest(int side, QSize size) const;
  [[nodiscard]] const mfr::Stats& statsOf(int side) const { return stats_[index(side)]; }

  // Side-0 shorthands.
  [[nodiscard]] QString operation() const override { return operationOf(0); }
  void setOperation(const QString& operation) override { setOperationOf(0, operation); }
  [[nodiscard]] QStringList objectNames() const override;
  [[nodiscard]] QString csgTree() const override;
  QString setCsgTree(const QString& json) override;
  [[nodiscard]] bool supportsOperation(const QString& method, const QString& operation) const override;
  // The z-thickness of every pane (RenderRequest::thickness; 0 = the scene's default). A new
  // scene (setScene) starts at 0.
  // The scene's clip box (mfr::Scene::clipBox; a scene file's "clip" as loaded). Setting it is a
  // scene edit (sceneChanged): every renderer and the oracle draw only what lies inside. A box with
  // min > max on an axis, or a non-finite corner, is ignored.
  [[nodiscard]] const std::optional<mfr::Bounds>& clipBox() const { return scene_.clipBox; }
  void setClipBox(const std::optional<mfr::Bounds>& box);
  // The scene's section plane (mfr::Scene::section; a scene file's "section" as loaded). Setting it is
  // a scene edit: the renderers and the oracle draw the scene cut by it (closed parts capped). A
  // plane with a zero or non-finite normal or point is ignored.
  [[nodiscard]] const std::optional<mfr::SectionPlane>& section() const { return scene_.section; }
  void setSection(const std::optional<mfr::SectionPlane>& section);
  [[nodiscard]] double zThickness() const override { return thickness_; }
  void setZThickness(double thickness) override;
  [[nodiscard]] double zThicknessDefault() const override;
  // The operation a side runs now: its operation with "auto" resolved for its method and the scene
  // (mfr::effectiveOperation).
  [[nodiscard]] QString effectiveOperationOf(int side) const { return resolvedOperation(side, operationOf(side)); }
  // What `operation` would mean for the side's method on this scene.
  [[nodiscard]] QString resolvedOperation(int side, const QString& operation) const;
  [[nodiscard]] QString effectiveOperation() const override { return effectiveOperationOf(0); }

  // The scalar volume (ViewerContext 1.4, volumeHistogram 1.5); the step is shared by both sides.
  // A new scene (setScene) starts at step 0 (the default).
  [[nodiscard]] bool hasVolume() const override { return volumeIndex() >= 0; }
  [[nodiscard]] QString volumeName() const override;
  [[nodiscard]] glm::ivec3 volumeDims() const override;
  [[nodiscard]] glm::dvec3 volumeSpacing() const override;
  [[nodiscard]] mfr::Bounds volumeBounds() const override;
  [[nodiscard]] glm::dvec2 volumeValueRange() const override;
  [[nodiscard]] std::vector<std::uint64_t> volumeHistogram(double low, double high, int bins) const override;
  [[nodiscard]] bool volumeVisible() const override;
  void setVolumeVisible(bool visible) override;
  [[nodiscard]] bool volumeShading() const override;
  void setVolumeShading(bool shading) override;
  [[nodiscard]] mfr::TransferFunction transferFunction() const override;
  [[nodiscard]] mfr::TransferFunction loadedTransferFunction() const override;
  QString setTransferFunction(const mfr::TransferFunction& transfer) override;
  [[nodiscard]] QStringList transferPresetNames() const override;
  [[nodiscard]] mfr::TransferFunction transferPreset(const QString& name, double low, double high,
                                                     double unitDistance) const override;
  [[nodiscard]] std::vector<glm::vec4> transferTable(const mfr::TransferFunction& transfer) const override;
  [[nodiscard]] double volumeStep() const override { return volumeStep_; }
  void setVolumeStep(double step) override;
  [[nodiscard]] double volumeStepDefault() const override;
  // 1.6: the scene's volumes, and which one "the volume" of the getters and setters above is.
  [[nodiscard]] int volumeCount() const override;
  [[nodiscard]] int visibleVolumeCount() const override;
  [[nodiscard]] QStringList volumeNames() const override;
  [[nodiscard]] int currentVolume() const override { return volumeIndex(); }
  void setCurrentVolume(int index) override;
  // 1.7: the current volume's fields.
  [[nodiscard]] QStringList volumeFields() const override;
  [[nodiscard]] QString volumeField() const override;
  void setVolumeField(const QString& field) override;
  [[nodiscard]] bool volumeFieldLoading() const override { return fieldLoad_ != nullptr; }
  [[nodiscard]] QString volumeFieldError() const override { return fieldError_; }
  // 1.8: the current volume's isosurfaces.
  [[nodiscard]] std::vector<double> isosurfaceValues() const override;
  [[nodiscard]] double isosurfaceOpacity() const override;
  QString setIsosurfaces(const std::vector<double>& values, double opacity) override;
  // Volume `index`'s isosurfaces (sessions; setIsosurfaces is the current volume's case).
  QString setIsosurfacesAt(int index, const std::vector<double>& values, double opacity);
  [[nodiscard]] std::vector<double> isosurfaceValuesAt(int index) const;
  [[nodiscard]] double isosurfaceOpacityAt(int index) const;
  // Volume `index` re-read from its file with `field`, in the background (a new scene, or another
  // field read before it ends, supersedes it), placed as before; its transfer function becomes
  // `transfer` when that is valid (a session's), else the default over the new samples. Nothing
  // happens for the field it has, or a volume not read from a file.
  void setVolumeFieldAt(int index, const QString& field, const std::optional<mfr::TransferFunction>& transfer = {});
  // Every volume of the scene by index (the scene tree, sessions); showing one more than
  // Scene::kMaxVisibleVolumes hides the first other visible one.
  void setVolumeVisibleAt(int index, bool visible);
  // A session's volume state: visibility and transfer function (an invalid one is ignored).
  void setVolumeStateAt(int index, bool visible, const mfr::TransferFunction& transfer, bool shading);
  // The index of "the volume" (setCurrentVolume; a new scene starts at its first visible volume,
  // else its first); -1 without volumes.
  [[nodiscard]] int volumeIndex() const;

  [[nodiscard]] const ParamsByMethod& allParams() const { return allParamsOf(0); }
  void setAllParams(ParamsByMethod params) { setAllParamsOf(0, std::move(params)); }
  [[nodiscard]] mfr::RenderRequest renderRequest(QSize size) const { return renderRequest(0, size); }

  // Scene. loadSceneAsync reads the file on a worker thread, reporting loadProgressChanged; the
  // current scene stays until the new one has loaded (sceneLoaded) — a failure (loadFailed) or
  // cancelLoad() leaves it intact. cancelLoad also stops the loader at its next progress report.
  // `molecule`: the representations of a molecule file (mfr::LoadOptions::molecule).
  // `volumeFields`: (volume name, field) pairs, matched to the scene's volumes by matchByName: the
  // field to read for each (empty: its own), read
  // with the scene, so that what depends on the fields (isosurfaces, bounds, the view) sees them —
  // a session's; a field that cannot be read leaves the volume as loaded, the reason in
  // volumeFieldReadError.
  void loadSceneAsync(const QString& path, const QString& field = {},
                      const std::optional<mfr::MoleculeStyle>& molecule = {},
                      const QList<QPair<QString, QString>>& volumeFields = {});
  // Why the field loadSceneAsync was asked to read for the scene's volume `index` could not be read; empty when
  // it was read or not asked for.
  [[nodiscard]] QString volumeFieldReadError(int index) const { return volumeFieldReadErrors_.value(index); }
  // A molecule file's representations (PyMOL's show): the scene's own (spheres unless it was
  // loaded with others), none when the scene is not a molecule file. setMoleculeStyle re-reads
  // the file in the background with `style`, keeping the camera (sceneLoaded follows; colours and
  // opacities chosen for parts start again from the file's).
  [[nodiscard]] std::optional<mfr::MoleculeStyle> moleculeStyle() const { return moleculeStyle_; }
  // False, changing nothing, while another file or session is read (or for no molecule).
  bool setMoleculeStyle(const mfr::MoleculeStyle& style);
  void cancelLoad();
  [[nodiscard]] bool isLoading() const { return loading_; }
  [[nodiscard]] double loadProgress() const { return loadProgress_; }  // of the current or last load
  // True when the last cancelled (or superseded) load's worker stopped inside the loader
  // (LoadCancelled) rather than finishing first (its scene was then dropped).
  [[nodiscard]] bool lastCancelStoppedLoader() const { return lastCancelStoppedLoader_; }
  // `prepare` runs once the scene is in place, before sceneLoaded (whose handlers apply a session).
  void setScene(mfr::Scene scene, const QString& path, const std::function<void()>& prepare = {});
  [[nodiscard]] const mfr::Scene& scene() const { return scene_; }
  // What the renderers draw: scene() cut by its section plane (mfr::sectionedScene, made once per
  // scene edit, not by each renderer), or scene() itself without one. When the cut fails (it leaves
  // nothing visible) this is scene() uncut and sectionError() says why; renderers then report it.
  [[nodiscard]] const mfr::Scene& drawnScene() const {
    return scene_.section && sectionError_.isEmpty() ? drawn_ : scene_;
  }
  [[nodiscard]] const mfr::SectionReport& sectionReport() const { return sectionReport_; }
  // Why drawnScene() draws nothing, in mfr render's words (every part hidden; a clip box that
  // holds nothing of the scene; a clip box and section that leave nothing), or empty: every
  // method's frame and export says so instead of an empty picture. Computed once per revision.
  [[nodiscard]] QString drawError() const;
  [[nodiscard]] const QString& sectionError() const { return sectionError_; }
  [[nodiscard]] const QString& scenePath() const { return scenePath_; }
  [[nodiscard]] quint64 sceneRevision() const { return sceneRevision_; }
  void setObjectVisible(int index, bool visible);
  // A colour chosen for a part replaces its file's per-vertex colours (Material::vertexColors) and
  // a field colouring of it.
  void setObjectColor(int index, const QColor& rgb);
  // The colour the part had when its scene was loaded (its file's per-vertex colours, e.g. a
  // molecule's element colours, included); the opacity stays as it is.
  void resetObjectColor(int index);
  // The same for several parts (the Scene dock's selection) in one scene edit: one edit per part
  // makes every panel walk every part per part. Indices out of range are skipped.
  void setObjectVisibilities(const QMap<int, bool>& visible);
  void setObjectColors(const QList<int>& indices, const QColor& rgb);
  void resetObjectColors(const QList<int>& indices);
  [[nodiscard]] bool objectColorEdited(int index) const;
  [[nodiscard]] double objectOpacity(int index) const override;
  void setObjectOpacity(int index, double opacity) override;
  void setObjectOpacities(const QMap<int, double>& opacities) override;
  [[nodiscard]] double loadedObjectOpacity(int index) const override;
  void setObjectMaterial(int index, const glm::vec4& rgba, bool vertexColors = true);
  // Visibility and material of several parts in one scene edit (a session's objects): one edit per
  // part made every panel walk every part per part, quadratic (34 s for 8,000 parts; a bug hunt).
  struct ObjectState {
    int index = -1;
    bool visible = true;
    glm::vec4 color{1.0f};
    bool vertexColors = true;
  };
  void setObjectStates(const std::vector<ObjectState>& states);
  // Visibility and the whole material (colour, opacity, vertex and field colours) of parts: what
  // the Scene dock's Undo puts back. setPartLooks makes one scene edit, of the parts that differ
  // (none: no edit); indices out of range are skipped.
  struct PartLook {
    int index = -1;
    bool visible = true;
    mfr::Material material;
    bool operator==(const PartLook&) const = default;
  };
  [[nodiscard]] std::vector<PartLook> partLooks(const QList<int>& indices) const;
  void setPartLooks(const std::vector<PartLook>& looks);

  // Surfaces coloured by a field (ParaView's "Color by"; mfr::colorObjectsByField on the meshes as
  // loaded): every part whose mesh has the field, one colour map, one range. The fields the parts
  // have, in first-seen order; the colouring shown (that of the first coloured part); the field's
  // range over the parts that have it.
  [[nodiscard]] QStringList surfaceFields() const;
  [[nodiscard]] std::optional<mfr::FieldColors> fieldColoring() const;
  // Every part is coloured by a field as it was loaded or made (a scene file's own colourings, which
  // may differ per part; none): a session need not say, and the scene file brings them back.
  [[nodiscard]] bool fieldColoringsAsLoaded() const;
  // The colouring by a field laid on in the Scene dock: that of a part coloured otherwise than as
  // loaded (a part given a colour of its own has none, and is passed over); none if there is none.
  [[nodiscard]] std::optional<mfr::FieldColors> chosenFieldColoring() const;
  // What the colour legend shows (the view's corner, Export Image): the field colouring's map; else
  // the current volume's isosurfaces' — cool-warm over contourColorRange, ticked at their values, as
  // mfr render --contour … --legend draws it; else nothing.
  struct ColorLegend {
    mfr::FieldColors colors;
    std::vector<double> ticks;  // empty: the range's ends and middle
  };
  [[nodiscard]] std::optional<ColorLegend> colorLegend() const;
  [[nodiscard]] glm::dvec2 fieldDataRange(const QString& field) const;
  // Colours only `parts` (those whose mesh has the field) by `colors`, leaving every other part as
  // it is; false, and nothing changed, when none has it. One scene edit.
  bool colorPartsByField(const mfr::FieldColors& colors, const QList<int>& parts);
  // An empty field: every part back to its own colour. No range: the field's data range. Returns
  // false, leaving the scene as it was, when refused (fieldColoringError() says why).
  bool setFieldColoring(const QString& field, const QString& map = QStringLiteral("cool-warm"),
                        const std::optional<glm::dvec2>& range = std::nullopt);
  [[nodiscard]] const QString& fieldColoringError() const { return fieldColoringError_; }

  // Camera: setCamera refits near/far around the visible objects, so navigation never clips,
  // unless the camera's planes were given (camera.depthRangeGiven: a named view's near/far).
  [[nodiscard]] const mfr::Camera& camera() const { return camera_; }
  void setCamera(const mfr::Camera& camera);
  [[nodiscard]] const mfr::Bounds& sceneBounds() const { return bounds_; }
  [[nodiscard]] double sceneRadius() const { return radius_; }
  void setRenderSize(QSize size);
  [[nodiscard]] quint64 viewRevision() const { return viewRevision_; }

  // Compare mode: two panes (side 0 and side 1) with one camera, side by side (each half the
  // width) or split (both full size; side 0 left of the split line, side 1 right of it).
  [[nodiscard]] bool compareEnabled() const { return compare_; }
  void setCompareEnabled(bool enabled);
  [[nodiscard]] CompareLayout compareLayout() const { return layout_; }
  void setCompareLayout(CompareLayout layout);
  [[nodiscard]] double compareSplit() const { return split_; }  // 0 … 1 of the width
  void setCompareSplit(double split);
  [[nodiscard]] CompareDisplay compareDisplay() const { return display_; }
  void setCompareDisplay(CompareDisplay display);
  [[nodiscard]] int paneCount() const { return compare_ ? 2 : 1; }
  // Image size of each pane: half the view's width (rounded down) side by side, else all of it.
  [[nodiscard]] QSize paneSize() const;

  // RenderView counts n(p) on the GPU when depthComplexityWanted asks, and reports the histogram.
  void reportDepthComplexity(const QVector<quint64>& histogram, QSize size);

  // RenderView reports each pane's frame (or why it could not draw one).
  void reportFrame(int side, const mfr::Stats& stats);
  void reportFrame(const mfr::Stats& stats) { reportFrame(0, stats); }
  void reportRenderError(const QString& message);
  [[nodiscard]] const QString& renderError() const { return renderError_; }
  // The error as the window shows it: a parameter, the operation and the method by the names the
  // Method panel and the plugins give them, not by mfr's options (--param, --op, --method) that the
  // user of the window never typed ("--op hybrid: needs --param tail=true …" reads "operation
  // hybrid: needs tail=true …").
  [[nodiscard]] QString renderErrorShown() const;
  // The render error is (also) the main pane's: side by side, pane B's alone leaves A's frame.
  [[nodiscard]] bool mainPaneFailed() const {
    return !renderError_.isEmpty() && !renderError_.startsWith(QLatin1String("B: "));
  }
  [[nodiscard]] quint64 framesRendered() const { return framesRendered_; }

  // What the pane of `side` shows now, and its exact reference image (the oracle's "over", or its
  // CSG / z-thickness / volume image, same thickness or step, for a pane showing that operation,
  // "auto" resolved).
  [[nodiscard]] ImageKey frameKey(int side) const;
  [[nodiscard]] mfr::RenderRequest referenceRequest(int side) const;
  // Metrics are computed for both panes in compare mode, and for side 0 when a frame quality was
  // requested. The view reads a frame back only when wantsFrameImage says so.
  [[nodiscard]] bool wantsFrameImage(int side) const;
  void reportFrameImage(int side, const ImageKey& key, mfr::ImageRGBA8 image);
  [[nodiscard]] const PaneMetrics& metrics(int side) const { return metrics_[index(side)]; }
  // metrics(side) describes the frame the pane shows now.
  [[nodiscard]] bool metricsCurrent(int side) const;

  // CPU images by purpose: each slot wants one image at a time (a newer request replaces an
  // older one not yet started); one job runs at a time, newest wishes first.
  enum class CpuSlot { Pane0, Pane1, Reference };
  // The image for `request` at the current scene and view, or nullptr while it is computed
  // (cpuImageReady follows).
  const CpuImage* cpuImage(CpuSlot slot, const mfr::RenderRequest& request);
  // The last image delivered for the slot, whatever view it shows (drawn while the next one is
  // computed); nullptr before the first.
  [[nodiscard]] const CpuImage* lastCpuImage(CpuSlot slot) const;
  [[nodiscard]] static CpuSlot paneSlot(int side) { return side == 0 ? CpuSlot::Pane0 : CpuSlot::Pane1; }

  // True while any background job runs (loading — also a cancelled load's worker until it stops —,
  // CPU images, depth complexity, metrics).
  [[nodiscard]] bool busy() const;

 signals:
  void loadStarted(const QString& path);
  void loadProgressChanged(double fraction);
  void sceneLoaded();  // followed by sceneChanged
  void loadFailed(const QString& path, const QString& message);
  void loadCancelled();
  void sideChanged(int side);               // method, operation or parameters of a side
  void compareChanged();                    // enabled, layout, split or display
  void secondaryFrameRendered();            // statsOf(1) describes the new frame
  void cpuImageReady(const ImageKey& key);  // the image of that key is in the cache
  void metricsReady(int side);
  void frameImageWanted();       // a frame quality was requested: the view reads back what it shows
  void depthComplexityWanted();  // requestDepthComplexity: the view counts n(p) on the GPU
  void renderErrorChanged(const QString& message);
  void partsChanged();  // parts added or removed (isosurfaces), followed by sceneChanged

 private:
  [[nodiscard]] static std::size_t index(int side) { return side == 1 ? 1 : 0; }
  [[nodiscard]] ImageKey imageKey(const mfr::RenderRequest& request) const;
  [[nodiscard]] bool metricsWanted(int side) const;
  void sceneEdited();
  // The drawn scene's bounds; with `refitDepth`, the view's near and far planes follow them when
  // they change (not when the planes were given).
  void updateSceneGeometry(bool refitDepth = true);
  void spliceIsosurfaces();  // scene_'s parts after the loaded ones: isosurfaces_'s, in volume order
  // After another field of a volume was read: the parts' "@NAME" fields sampled anew (and the
  // colouring by one of them redrawn).
  void resampleVolumeFields();
  void updateDrawnScene();  // drawn_ and the section report from scene_
  void startCpuJob();
  void updateMetrics();
  void startMetrics(int side, const mfr::ImageRGBA8& reference);
  void pollLoadProgress();
  void volumeEdited();

  mfr::Scene scene_;
  mfr::Scene drawn_;  // scene_ cut by its section (drawnScene())
  mfr::SectionReport sectionReport_;
  QString sectionError_;
  std::vector<mfr::Material> loadedMaterials_;  // of scene_'s objects as loaded, for resetObjectColor
  // scene_'s meshes as loaded: what setFieldColoring colours (not a mesh coloured before).
  std::vector<std::shared_ptr<const mfr::Mesh>> loadedMeshes_;
  QString fieldColoringError_;
  bool hasScene_ = false;
  QString scenePath_;
  std::optional<mfr::MoleculeStyle> moleculeStyle_;
  bool keepView_ = false;  // the load is setMoleculeStyle's re-read: keep the view as it is when it ends
  std::optional<mfr::MoleculeStyle> requestedMoleculeStyle_;  // setMoleculeStyle's, while it loads
  quint64 sceneRevision_ = 0;
  quint64 sceneSerial_ = 0;                                       // scenes opened (setScene)
  mutable std::optional<std::pair<quint64, QString>> drawError_;  // drawError() of a scene revision
  mfr::Bounds bounds_;
  double radius_ = 0.0;

  mfr::Camera camera_;
  QSize renderSize_{1, 1};
  quint64 viewRevision_ = 0;

  std::array<QString, kSides> methods_{QStringLiteral("abuffer-ll"), QStringLiteral("kplus-array")};
  std::array<QString, kSides> operations_{QStringLiteral("auto"), QStringLiteral("auto")};
  std::array<ParamsByMethod, kSides> params_;
  double thickness_ = 0.0;                              // operation zthickness, scene units; 0 = mfr::zThicknessDefault
  double volumeStep_ = 0.0;                             // operation volume, scene units; 0 = the volume's defaultStep()
  int currentVolume_ = 0;                               // volumeIndex() of the scene's volumes
  void showVolume(int index, bool visible);             // keeps at most kMaxVisibleVolumes shown
  std::vector<mfr::TransferFunction> loadedTransfers_;  // of scene_'s volumes as loaded
  std::vector<glm::dvec2> volumeRanges_;                // of scene_'s volumes' grids
  // Isosurfaces made in the viewer, per volume: their values, opacity and parts (made once, spliced
  // into scene_.objects after its first loadedPartCount_ parts, the scene's own).
  struct IsosurfaceSet {
    std::vector<double> values;
    double opacity = 0.5;
    std::vector<mfr::Object> parts;
  };
  std::vector<IsosurfaceSet> isosurfaces_;
  std::size_t loadedPartCount_ = 0;

  bool compare_ = false;
  CompareLayout layout_ = CompareLayout::SideBySide;
  double split_ = 0.5;
  CompareDisplay display_ = CompareDisplay::Images;
  DataView dataView_ = DataView::Image;
  bool dataOverImage_ = false;

  std::array<mfr::Stats, kSides> stats_;
  QString renderError_;
  quint64 framesRendered_ = 0;

  // Loading: the worker writes progress and reads the cancel flag of its own state.
  struct LoadState;
  std::shared_ptr<LoadState> load_;
  std::shared_ptr<LoadState> fieldLoad_;  // setVolumeFieldAt's read in progress
  QString fieldError_;
  QMap<int, QString> volumeFieldReadErrors_;  // loadSceneAsync's volumeFields that could not be read
  bool loading_ = false;
  double loadProgress_ = 0.0;
  bool lastCancelStoppedLoader_ = false;
  int abandonedLoads_ = 0;  // cancelled or superseded loads whose workers still run
  QTimer* loadPoll_ = nullptr;

  // CPU images.
  struct CpuWish {
    ImageKey key;
    mfr::RenderRequest request;
  };
  std::map<CpuSlot, CpuWish> cpuWanted_;
  std::deque<std::shared_ptr<const CpuImage>> cpuCache_;  // newest first
  std::map<CpuSlot, std::shared_ptr<const CpuImage>> cpuLast_;
  bool cpuRunning_ = false;

  // Metrics.
  bool qualityWanted_ = false;
  bool keepFrameImages_ = false;
  std::array<std::optional<std::pair<ImageKey, mfr::ImageRGBA8>>, kSides> frameImage_;
  std::array<PaneMetrics, kSides> metrics_;
  std::array<bool, kSides> metricsRunning_{false, false};
};
