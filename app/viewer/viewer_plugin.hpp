#pragma once
// The mfrview plugin interface: what a plugin sees of the viewer (ViewerContext) and what it
// provides (MfrViewerPlugin). Plugins are Qt plugins loaded with QPluginLoader from the folders in
// $MFR_PLUGIN_PATH (colon-separated), the folder `plugins` beside the executable, and an installed
// tree's ../lib/mfrview/plugins (PluginManager::searchPaths).
//
// ViewerContext is abstract and its virtual functions are the whole API, so a plugin needs only
// mfrcore's headers, not its library; its signals' meta-object comes from the executable, which
// is linked with exported symbols (CMake ENABLE_EXPORTS).
#include <QJsonObject>
#include <QMap>
#include <QObject>
#include <QSize>
#include <QString>
#include <QStringList>
#include <QVector>
#include <QtPlugin>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/methods/method.hpp"
#include "mfr/methods/stats.hpp"
#include "mfr/scene/mesh.hpp"
#include "mfr/scene/volume.hpp"

class QWidget;

// What the view shows per pixel: the rendered image, or a heat map of the data behind it.
enum class DataView {
  Image,
  DepthComplexity,  // n(p): fragments per pixel, exact (GPU count pass)
  Capacity,         // k(p): the method's per-pixel capacity in the last frame
};

// The current frame against the exact image, same size: the oracle's "over" of every fragment,
// or its CSG / z-thickness / volume image (same thickness, step and transfer function) while the
// frame shows that operation.
struct FrameQuality {
  bool valid = false;  // computed for the frame now shown
  QString method;
  double rmse = 0.0;      // mfr::rmse over RGB, 8-bit values scaled to [0,1]
  double flipMean = 0.0;  // mean LDR-FLIP error, 67 pixels per degree
  double flipMax = 0.0;
  // 1.13: why there are no numbers for the frame now shown (the exact image or FLIP refused, e.g.
  // for memory): the budget panel read "computing…" for ever (a bug hunt). Empty otherwise.
  QString error;
};

class ViewerContext : public QObject {
  Q_OBJECT

 public:
  using QObject::QObject;
  ~ViewerContext() override = default;

  // Render methods: "oracle" (exact, CPU) first, then every registered GPU method, then any
  // other CPU method mfrcore offers (computed off the GUI thread, like the oracle).
  [[nodiscard]] virtual QStringList methodNames() const = 0;
  // The method's description and parameters; nullptr for CPU methods ("oracle", …) or an unknown
  // name.
  [[nodiscard]] virtual const mfr::MethodInfo* methodInfo(const QString& method) const = 0;
  // Rendered on the CPU off the GUI thread (the oracle, optimal-k …) rather than on the GPU.
  [[nodiscard]] virtual bool isCpuMethod(const QString& method) const = 0;
  [[nodiscard]] virtual QString method() const = 0;
  virtual void setMethod(const QString& method) = 0;
  // Parameter values of the current method (only those set explicitly; the rest take defaults).
  [[nodiscard]] virtual std::map<std::string, std::string> params() const = 0;
  // Merges `changes` into the current method's parameters and re-renders.
  virtual void setParams(const std::map<std::string, std::string>& changes) = 0;

  [[nodiscard]] virtual bool hasScene() const = 0;
  // 1.12: counts the scenes opened (a file read again counts too: a molecule's other
  // representation). sceneChanged comes for a new scene and for an edit alike; a panel that keeps
  // state per part tells them apart by this number, since another file's parts may have the same
  // names (the ghosting panel kept its focus and ghosting there: a bug hunt).
  [[nodiscard]] virtual quint64 sceneSerial() const = 0;
  // Stats of the last frame drawn in the view (empty before the first).
  [[nodiscard]] virtual const mfr::Stats& stats() const = 0;
  // 1.14: why the view shows no frame of the current settings (the window's one line, e.g. a
  // budget below the least setting of the method), empty while it shows one; frameErrorChanged
  // follows each change. While it is set, stats() still holds the last frame drawn, which is no
  // longer on screen (the budget panel showed its numbers beside the new budget: a bug hunt).
  [[nodiscard]] virtual QString frameError() const = 0;
  // Pixels of the image stats() describes: the view's, or in compare mode side by side the first
  // pane's (half the view's width).
  [[nodiscard]] virtual QSize imageSize() const = 0;
  // Asks for the per-pixel fragment counts n(p) of the current view at the image's size, counted
  // by the GPU's rasterisation (one count pass: what the GPU methods capture; equal to the
  // oracle's counts on every pixel whose centre is off triangle edges); depthComplexityReady
  // delivers the histogram soon after, on the GUI thread.
  virtual void requestDepthComplexity() = 0;
  // Starts (or queues) RMSE and FLIP of the current frame against the exact image, computed off
  // the GUI thread; frameQualityReady follows. frameQuality() is valid while it describes the
  // frame on screen.
  virtual void requestFrameQuality() = 0;
  [[nodiscard]] virtual FrameQuality frameQuality() const = 0;
  // The view's data mode; overImage blends the heat map over the image (empty pixels clear).
  [[nodiscard]] virtual DataView dataView() const = 0;
  [[nodiscard]] virtual bool dataViewOverImage() const = 0;
  virtual void setDataView(DataView view, bool overImage) = 0;
  // Operation of the main view: "auto", "oit", "hybrid", "csg", "zthickness" or "volume". "auto"
  // is the method's own, or "volume" on a scene with a visible volume for a method with sorted
  // lists (mfr::effectiveOperation); effectiveOperation() says which.
  [[nodiscard]] virtual QString operation() const = 0;
  virtual void setOperation(const QString& operation) = 0;
  // Whether `method` can run `operation` (1.3; the oracle runs them all; csg needs object ids, hybrid
  // a k-buffer's tail, zthickness and volume sorted lists, MethodInfo::sortedLists: not the peeling
  // methods, WBOIT, MBOIT or kbuffer-zmerge, which runs zthickness only).
  [[nodiscard]] virtual bool supportsOperation(const QString& method, const QString& operation) const = 0;
  // The scene's object names, in object-id order.
  [[nodiscard]] virtual QStringList objectNames() const = 0;
  // The scene's CSG tree as the JSON text of a scene file's "csg" value (docs/scene-format.md);
  // empty when there is none.
  [[nodiscard]] virtual QString csgTree() const = 0;
  // Replaces the tree (blank text removes it) and re-renders; returns an empty string, or the
  // one-line reason the text was refused (the tree is then unchanged).
  virtual QString setCsgTree(const QString& json) = 0;

  // Operation "zthickness" (1.3): the slab thickness in scene units, used by every pane (and by
  // the exact reference of a pane showing zthickness); 0 means zThicknessDefault().
  [[nodiscard]] virtual double zThickness() const = 0;
  // Re-renders; a negative, infinite or NaN value is ignored.
  virtual void setZThickness(double thickness) = 0;
  // The default of the current scene: 1 % of its bounding box's diagonal (mfr::zThicknessDefault).
  [[nodiscard]] virtual double zThicknessDefault() const = 0;

  // Per-object opacity (1.3), by object id (the index in objectNames()): the same edit as the
  // scene tree's Opacity column, so every pane, CPU images included, sees it. Values are clamped
  // to 0 … 1; an unknown id reads -1 and is ignored when set.
  [[nodiscard]] virtual double objectOpacity(int objectId) const = 0;
  virtual void setObjectOpacity(int objectId, double opacity) = 0;
  // Several at once (one re-render): objectId → opacity.
  virtual void setObjectOpacities(const QMap<int, double>& opacities) = 0;
  // The opacity the object had when its scene was loaded.
  [[nodiscard]] virtual double loadedObjectOpacity(int objectId) const = 0;

  // ---- Scalar volume, operation "volume" (1.4) ----
  // "The volume" is the current one of the scene's volumes (1.6: currentVolume; a new scene starts
  // at its first visible volume, else its first). Up to mfr::Scene::kMaxVisibleVolumes are drawn at
  // once, their media mixed where they overlap. Without a volume the getters read empty values and
  // the setters do nothing (setTransferFunction returns a reason).
  // The operation the main view runs now: operation() with "auto" resolved.
  [[nodiscard]] virtual QString effectiveOperation() const = 0;
  [[nodiscard]] virtual bool hasVolume() const = 0;
  [[nodiscard]] virtual QString volumeName() const = 0;
  [[nodiscard]] virtual glm::ivec3 volumeDims() const = 0;     // grid points per axis; 0 without a volume
  [[nodiscard]] virtual glm::dvec3 volumeSpacing() const = 0;  // object-space distance between points
  [[nodiscard]] virtual mfr::Bounds volumeBounds() const = 0;  // world bounds of the grid's domain
  // Smallest and largest sample (VolumeGrid::range, computed once per scene).
  [[nodiscard]] virtual glm::dvec2 volumeValueRange() const = 0;
  // 1.5: counts of the volume's finite samples in `bins` equal bins over [low, high] (sample v in
  // bin floor((v - low) / (high - low) * bins), v = high in the last); samples outside are not
  // counted. Empty without a volume, for bins < 1, or unless low < high (both finite). Computed
  // anew on each call (one pass over the grid): callers cache it.
  [[nodiscard]] virtual std::vector<std::uint64_t> volumeHistogram(double low, double high, int bins) const = 0;
  // Whether it is drawn (Volume::visible); showing it while kMaxVisibleVolumes others are shown
  // hides the first of them.
  [[nodiscard]] virtual bool volumeVisible() const = 0;
  virtual void setVolumeVisible(bool visible) = 0;
  // Gradient shading with a headlight (Volume::shading): boundaries inside the medium read as
  // surfaces; off: pure emission-absorption.
  [[nodiscard]] virtual bool volumeShading() const = 0;
  virtual void setVolumeShading(bool shading) = 0;
  // Its transfer function (every pane and the exact reference use it), and the one it had when the
  // scene was loaded.
  [[nodiscard]] virtual mfr::TransferFunction transferFunction() const = 0;
  [[nodiscard]] virtual mfr::TransferFunction loadedTransferFunction() const = 0;
  // Replaces it and re-renders; returns an empty string, or the one-line reason an invalid function
  // (fewer than two points, values not ascending or an empty range, colour or opacity outside
  // 0 … 1, a unit distance not positive) was refused; nothing changes then.
  virtual QString setTransferFunction(const mfr::TransferFunction& transfer) = 0;
  // mfr::transferPresetNames, and preset `name` over [low, high] with the given unit distance
  // (no points for an unknown name).
  [[nodiscard]] virtual QStringList transferPresetNames() const = 0;
  [[nodiscard]] virtual mfr::TransferFunction transferPreset(const QString& name, double low, double high,
                                                             double unitDistance) const = 0;
  // TransferFunction::table(): MFR_VOLUME_TF_SIZE (256) entries (rgb, extinction per scene unit)
  // evenly spaced over [low(), high()], for previews; empty for an invalid function.
  [[nodiscard]] virtual std::vector<glm::vec4> transferTable(const mfr::TransferFunction& transfer) const = 0;
  // The ray-march step of every pane (RenderRequest::volumeStep, scene units; 0 means
  // volumeStepDefault()). A new scene starts at 0; a negative, infinite or NaN value is ignored.
  [[nodiscard]] virtual double volumeStep() const = 0;
  virtual void setVolumeStep(double step) = 0;
  // Volume::defaultStep(): half the smallest world distance between grid points, the smallest over
  // the volumes drawn (the current volume's while none is; 0 without a volume).
  [[nodiscard]] virtual double volumeStepDefault() const = 0;
  // 1.6: the scene's volumes (names in scene order) and the current one, whose state the getters
  // and setters above read and edit. setCurrentVolume ignores an index out of range and emits
  // volumeChanged; it draws nothing differently.
  [[nodiscard]] virtual int volumeCount() const = 0;
  [[nodiscard]] virtual int visibleVolumeCount() const = 0;  // of them, those drawn
  [[nodiscard]] virtual QStringList volumeNames() const = 0;
  [[nodiscard]] virtual int currentVolume() const = 0;
  virtual void setCurrentVolume(int index) = 0;
  // 1.7: the current volume's named fields (Volume::fields: a .vti/.vtk file's point-data arrays,
  // a .vdb file's grids; empty for formats with one unnamed field) and the one read.
  // setVolumeField reads another field of the same file in the background, in the volume's place;
  // its transfer function becomes the default over the new samples. volumeChanged is emitted when
  // the read starts and when it ends; while it runs volumeFieldLoading() is true; a read that
  // failed leaves the volume as it was and says why in volumeFieldError() (empty otherwise).
  [[nodiscard]] virtual QStringList volumeFields() const = 0;
  [[nodiscard]] virtual QString volumeField() const = 0;
  virtual void setVolumeField(const QString& field) = 0;
  [[nodiscard]] virtual bool volumeFieldLoading() const = 0;
  [[nodiscard]] virtual QString volumeFieldError() const = 0;
  // 1.8: isosurfaces of the current volume (ParaView's Contour; mfr::addContours): parts named
  // "VOLUME = VALUE", coloured by their value, after the scene's own parts (sceneChanged, and the
  // scene tree lists them). setIsosurfaces replaces the current volume's set — an empty list removes
  // it — and hides the volume when it makes any (ParaView hides a filter's input); it returns an empty
  // string, or the one-line reason it was refused (a value outside the volume's range, more than
  // mfr::kMaxContourValues, an opacity outside 0 … 1), nothing changed then. A field read in the
  // volume's place (setVolumeField) makes its set again, over the values still inside the new range.
  [[nodiscard]] virtual std::vector<double> isosurfaceValues() const = 0;
  [[nodiscard]] virtual double isosurfaceOpacity() const = 0;  // of the current set; 0.5 without one
  virtual QString setIsosurfaces(const std::vector<double>& values, double opacity) = 0;

  // 1.10: a one-line note for the user about something taken but not as given (a session's focus
  // part the scene lacks, a value clamped to its range): the status bar shows it, and stderr
  // gets it (also for scripted runs, which have no status bar), as the session's own notes.
  void note(const QString& text) { emit noted(text); }

 signals:
  void sceneChanged();  // a new scene, or an object edited
  void viewChanged();   // camera or image size
  void methodChanged(const QString& method);
  void paramsChanged();
  void frameRendered();      // stats() describes the new frame
  void frameErrorChanged();  // 1.14: frameError()
  // histogram[n] = pixels with exactly n fragments; the image size it was computed at.
  void depthComplexityReady(const QVector<quint64>& histogram, QSize size);
  void frameQualityReady();
  void dataViewChanged();
  void operationChanged(const QString& operation);
  void zThicknessChanged(double thickness);  // zThickness(), 0 = the default
  void volumeChanged();  // 1.4: a new scene, or a volume's visibility, transfer function or step; 1.6: the current
                         // volume; 1.7: a field read started or ended
  void noted(const QString& text);  // 1.10: note()
};

class MfrViewerPlugin {
 public:
  virtual ~MfrViewerPlugin() = default;
  [[nodiscard]] virtual QString id() const = 0;    // stable key in sessions and settings
  [[nodiscard]] virtual QString name() const = 0;  // for menus and docks
  [[nodiscard]] virtual QString description() const = 0;
  // The plugin's panel; the viewer puts it into a dock widget and owns it.
  virtual QWidget* createPanel(ViewerContext& context, QWidget* parent) = 0;
  // State stored in session files (under "plugins"/id()). Settings given to loadSettings (a
  // session's, --plugin-settings') are checked against what saveSettings() writes now: every key it
  // may take should be written always, with one JSON type whatever the state (keys it does not
  // write are refused as unknown, values of another type as wrong); a key left out keeps its default.
  [[nodiscard]] virtual QJsonObject saveSettings() const = 0;
  virtual void loadSettings(const QJsonObject& settings) = 0;
  // 1.11: parameters of the current method for an image of `size` other than the view's (File →
  // Export, --screenshot at --size), merged over the view's. A plugin that sets parameters from
  // the view's image size (the budget panel) keeps its promise at the export's size: an export
  // at 800x600 drew with the k fitted to the view, 2.6 times the budget (a bug hunt). `tried` and
  // `measured` are the parameters it gave last and the stats of that render at `size` (null on
  // the first call); giving the same parameters again ends the tries. A plugin whose promise no
  // parameters can keep at `size` (a budget below the least setting) throws mfr::Error with the
  // one-line reason: no picture is written then.
  [[nodiscard]] virtual std::map<std::string, std::string> exportParams(QSize size,
                                                                        const std::map<std::string, std::string>* tried,
                                                                        const mfr::Stats* measured) const {
    (void)size, (void)tried, (void)measured;
    return {};
  }
};

// 1.1: frame quality and data views in ViewerContext (plugins built for 1.0 are refused).
// 1.2: operation, object names and the CSG tree.
// 1.3: operation zthickness and its thickness, supportsOperation, per-object opacity.
// 1.4: the scalar volume (operation volume): presence, dims, bounds, visibility, transfer function
//      (presets, table), ray-march step, shading, effectiveOperation, volumeChanged.
// 1.5: volumeHistogram (the transfer-function editor's background).
// 1.6: several volumes drawn at once: volumeCount, visibleVolumeCount, volumeNames, currentVolume,
//      setCurrentVolume.
// 1.7: a volume file's fields: volumeFields, volumeField, setVolumeField, volumeFieldLoading,
//      volumeFieldError.
// 1.8: isosurfaces of a volume: isosurfaceValues, isosurfaceOpacity, setIsosurfaces.
// 1.9: imageSize (the image stats() describes) instead of renderSize (the whole view's, which
//      side by side is two images).
// 1.10: note (and the signal noted): notes of a plugin for the status bar and stderr.
// 1.11: exportParams: a plugin's parameters for an exported image of another size.
// 1.12: sceneSerial: a new scene told from an edit of the same one.
// 1.13: FrameQuality::error, and frameQualityReady when the numbers cannot be computed.
// 1.14: frameError and frameErrorChanged: the view's frame could not be drawn.
#define MfrViewerPlugin_iid "org.mfr.ViewerPlugin/1.14"
Q_DECLARE_INTERFACE(MfrViewerPlugin, MfrViewerPlugin_iid)
