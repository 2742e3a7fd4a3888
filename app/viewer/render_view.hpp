#pragma once
// The central OpenGL 4.5 view. GPU methods render through mfrcore's GpuRenderer::renderTo — the
// code path of `mfr render` — so the view's pixels equal the CLI's image for the same scene,
// view, size and settings. CPU methods (the oracle, …) are drawn from the images ViewerModel
// computes off the GUI thread.
//
// One pane shows the main method; compare mode adds a second pane (its own GpuRenderer, same
// camera), side by side or split. A single GPU image goes straight into the widget's
// framebuffer; everything else is drawn per pane into an offscreen RGBA8 framebuffer — the one
// `mfr render` reads back — and blitted into place. Data views (n(p), k(p)) and compare heat
// maps replace (or blend over) a pane's image; their legends and the panes' captions are child
// widgets, so the framebuffer holds only images.
//
// epoxy must come before Qt's OpenGL headers (it replaces the system GL headers).
#include <epoxy/gl.h>

#include <QColor>
#include <QEvent>
#include <QLabel>
#include <QOpenGLWidget>
#include <QPoint>

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "mfr/gpu_renderer.hpp"
#include "mfr/image.hpp"
#include "mfr/reference/probe.hpp"
#include "viewer_model.hpp"

class MapLegend;
class QTimer;
class QWindow;
class PaneCaption;
class ProbeMarker;
class SplitHandle;

// What the pixel probe found under a point of the view (RenderView::probeAt).
struct ViewProbe {
  QPointF point;                // the probed point (logical widget coordinates)
  int side = 0;                 // the pane showing it
  QSize paneSize;               // that pane's image size (device pixels)
  QString method;               // the pane's method
  bool methodHasLists = false;  // a GPU method keeping sorted lists: probe.captured says what it holds
  mfr::PixelProbe probe;        // the oracle's exact list at the pane pixel (probe.x, probe.y)
  // The colour the view shows at the point (its last frame, read from the framebuffer); unset
  // while a data view or a heat map replaces the image.
  std::optional<QColor> shown;
};

class RenderView final : public QOpenGLWidget {
  Q_OBJECT

 public:
  explicit RenderView(ViewerModel& model, QWidget* parent = nullptr);
  ~RenderView() override;

  // An image of the current scene and camera at any size with the main method, rendered
  // offscreen on this view's context exactly as `mfr render` does (GpuRenderer::render, or the
  // oracle on the CPU). Throws mfr::Error (no GL context yet, no scene, bad settings).
  mfr::ImageRGBA8 renderImage(QSize size);
  // The same with `params` merged over the method's, and the render's stats.
  mfr::RenderOutput renderOutput(QSize size, const std::map<std::string, std::string>& params);
  [[nodiscard]] bool glReady() const { return renderers_[0] != nullptr; }
  // Off: the view draws only its background, and no frame is rendered or reported. A run that
  // exports at --size and quits (mfrview --screenshot) has no one to show the window to; its first
  // frame at the window's size cost 100 s for a volume at a fine step, 60 times the export's.
  void setLiveFrames(bool on);
  [[nodiscard]] const QString& glInfo() const { return glInfo_; }
  // The image size in device pixels.
  [[nodiscard]] QSize pixelSize() const;

  // Fast navigation (on by default): while the camera is dragged or wheeled, and the last full
  // frame took longer than kNavigationFrameMs of GPU time, each pane is rendered at 1/f of its
  // width and height (f ≤ kMaxReduction, chosen from that time) and scaled up; parameters that
  // are memory for the whole image (ParamSpec::perImage: budgets, fixed pools) get the same share
  // per pixel. Such frames are previews: their Stats are not reported. The full frame follows
  // when the motion stops.
  static constexpr double kNavigationFrameMs = 40.0;
  static constexpr int kMaxReduction = 4;
  void setFastNavigation(bool on);
  [[nodiscard]] bool fastNavigation() const { return fastNavigation_; }
  [[nodiscard]] bool navigating() const { return navigating_; }
  // The reduction f of the last frame drawn (1: a full frame), and the side-0 Stats of the last
  // reduced frame.
  [[nodiscard]] int lastFrameReduction() const { return lastReduction_; }
  [[nodiscard]] const mfr::Stats& lastPreviewStats() const { return previewStats_; }

  // The data map a pane showed in its last frame (image rows top-down).
  struct DataMap {
    DataView kind = DataView::Image;
    ImageKey key;  // of the pane's frame
    int width = 0, height = 0;
    std::vector<std::uint32_t> values;  // empty when the pane has no such map (see note)
    std::uint32_t minValue = 0, maxValue = 0;
    QString note;  // why there is no map, e.g. "no k(p) for this method"
  };
  [[nodiscard]] const DataMap& dataMap(int side) const { return maps_[side == 1 ? 1 : 0]; }
  // Where a pane's image lies in the framebuffer (device pixels, top-down rows) and the part of
  // it that shows (the split layout shows each image only on its side of the line).
  [[nodiscard]] QRect paneRect(int side) const;
  [[nodiscard]] QRect paneVisibleRect(int side) const;
  // The side whose visible image holds `point` (logical widget coordinates), or -1 off every image.
  [[nodiscard]] int paneAt(QPointF point) const;
  // The device pixel under a logical point at this device-pixel ratio. A point the window system
  // gave in device pixels comes back as x / ratio less the view's offset, a hair below the
  // whole number it stands for (38.666…67 × 1.5 = 57.99999999999994): a plain floor lost one
  // column in three at 1.5 (a review).
  [[nodiscard]] static QPoint devicePixel(QPointF point, double ratio);
  // A framebuffer rectangle (device pixels) in logical widget coordinates.
  [[nodiscard]] QRectF logicalRect(const QRect& device) const;
  // The pane under `point` (logical widget coordinates), in logical coordinates: what the mouse
  // navigates, so that side by side a drag pans and the wheel zooms at the pane's own scale and
  // towards the point under the cursor in that pane.
  [[nodiscard]] QRectF navigationArea(QPointF point) const;

  // The pixel probe at `point` (logical widget coordinates): the pane that shows it, the pixel of
  // that pane's image, the oracle's exact sorted list there and — for a GPU method keeping sorted
  // lists — which of those fragments the method holds (GpuRenderer::capture of that one pixel by a
  // renderer of its own that shares the scene, so probing never changes what a method keeps
  // between frames). Throws mfr::Error (no scene, no GL yet, a point outside the view).
  ViewProbe probeAt(QPointF point);
  // The part drawn nearest the eye at `point` (logical widget coordinates), as the oracle casts
  // that one pixel: a scene object's index, or -1 where no part is drawn (the background, a
  // volume's slice, parts of opacity 0). Throws mfr::Error as probeAt does.
  [[nodiscard]] int partAt(QPointF point) const;
  // Marks the probed point with a small cross (nothing: no mark).
  void setProbeMark(std::optional<QPointF> point);

 signals:
  void glInitialized();
  // The reduction of the frames being drawn changed (f > 1: navigation previews; 1: full frames).
  void frameReductionChanged(int reduction);
  // Ctrl + left click: the user asks what lies behind this point (logical widget coordinates).
  void probeRequested(QPointF point);
  // Double click: the user asks which part this is (logical widget coordinates).
  void partPickRequested(QPointF point);

 protected:
  void initializeGL() override;
  void resizeGL(int width, int height) override;
  void paintGL() override;
  void resizeEvent(QResizeEvent* event) override;
  void focusInEvent(QFocusEvent* event) override;
  void focusOutEvent(QFocusEvent* event) override;
  void mousePressEvent(QMouseEvent* event) override;
  void mouseMoveEvent(QMouseEvent* event) override;
  void mouseReleaseEvent(QMouseEvent* event) override;
  void mouseDoubleClickEvent(QMouseEvent* event) override;
  void showEvent(QShowEvent* event) override;
  bool eventFilter(QObject* watched, QEvent* event) override;
  void wheelEvent(QWheelEvent* event) override;

 private:
  // update() with why, for the mfr.view.frames log.
  void requestFrame(const char* reason);
  // The image pixel under a point of the view: its pane, the pane's framebuffer rectangle, the
  // pixel in that pane's image and in the framebuffer. Throws mfr::Error naming `what` (no scene,
  // nothing drawable, a point off every image).
  struct PanePixel {
    int side = 0;
    QRect pane;
    QPoint pixel;
    QPoint device;
  };
  [[nodiscard]] PanePixel panePixelAt(QPointF point, const char* what) const;
  [[nodiscard]] QPointF exactPosition(const QMouseEvent& event) const;
  // An offscreen RGBA8 colour target of one pane.
  struct PaneTarget {
    GLuint texture = 0, fbo = 0;
    QSize size;
  };
  mfr::GpuRenderer& renderer(int side);
  bool uploadSceneIfChanged(int side, QStringList& errors);
  // The view's context made current for GL work outside paintGL (export, probe), released when
  // the guard goes (moved, not copied).
  class CurrentContext {
   public:
    explicit CurrentContext(RenderView& view) : view_(&view) { view.makeCurrent(); }
    CurrentContext(CurrentContext&& other) noexcept : view_(std::exchange(other.view_, nullptr)) {}
    CurrentContext(const CurrentContext&) = delete;
    CurrentContext& operator=(const CurrentContext&) = delete;
    CurrentContext& operator=(CurrentContext&&) = delete;
    ~CurrentContext() {
      if (view_) view_->doneCurrent();
    }

   private:
    RenderView* view_;
  };
  // The context current and side's scene uploaded; throws mfr::Error without a GL context yet or
  // when the scene cannot be uploaded (e.g. every object hidden).
  [[nodiscard]] CurrentContext currentWithScene(int side);
  void paintSingleImage(QStringList& errors);
  void paintPane(int side, QStringList& errors);
  PaneTarget& paneTarget(int side, QSize size) { return targetOf(targets_, side, size); }
  static PaneTarget& targetOf(std::array<PaneTarget, kSides>& targets, int side, QSize size);
  mfr::ImageRGBA8 readBack(const PaneTarget& target) const;
  mfr::ImageRGBA8 readDefaultFramebuffer(QSize size) const;
  void upload(const PaneTarget& target, const mfr::ImageRGBA8& image);
  void blitPane(int side, const PaneTarget& target);
  [[nodiscard]] int navigationReduction() const;
  bool paintReduced(int reduction, QStringList& errors);
  [[nodiscard]] mfr::RenderRequest reducedRequest(int side, QSize size, QSize full) const;
  void beginNavigation();
  void endNavigation(int settleMs);
  DataMap computeDataMap(int side, QSize size, const ImageKey& key, bool haveFrame);
  // n(p) of the current view at `size` by the main renderer's count pass, cached per scene, view
  // and size (both panes of compare mode share it); the context must be current. Throws
  // mfr::Error.
  const std::vector<std::uint32_t>& depthCounts(QSize size);
  // Answers ViewerModel::depthComplexityWanted with the histogram of depthCounts.
  void reportDepthComplexity();
  void clearToBackground();
  void releaseGl();
  void updateOverlays();
  [[nodiscard]] QString differingParams(int side) const;  // a compare caption's " k=4"

  ViewerModel& model_;
  std::array<std::unique_ptr<mfr::GpuRenderer>, kSides> renderers_;
  // Navigation previews render with renderers of their own (sharing the panes' scene buffers), so
  // a preview never changes what a method keeps between frames (e.g. pool=previous's count) or
  // reallocates the full frame's buffers.
  std::array<std::unique_ptr<mfr::GpuRenderer>, kSides> previewRenderers_;
  std::unique_ptr<mfr::GpuRenderer> probeRenderer_;  // the pixel probe's captures (shares a pane's scene)
  std::array<quint64, kSides> uploadedRevision_{0, 0};
  std::array<QString, kSides> uploadError_;
  std::array<PaneTarget, kSides> targets_;
  std::array<PaneTarget, kSides> reducedTargets_;  // navigation previews, at 1/f of the pane size
  std::array<DataMap, kSides> maps_;
  std::array<bool, kSides> paneFailed_{false, false};  // the pane's last paint had an error
  QLabel* errorNote_ = nullptr;  // over an image that cannot be rendered: why (compare panes have captions)
  // n(p) of the last view (both panes share it when their sizes agree).
  struct DepthCache {
    quint64 scene = 0, view = 0;
    QSize size;
    std::vector<std::uint32_t> values;
  } depthCache_;
  QString glInfo_;
  QPoint lastMouse_;
  // The last press as the top-level window received it, with its fraction of a logical pixel:
  // QApplication rounds a widget's mouse positions, local and global, to whole logical pixels,
  // so at a fractional scale the widget's own event lies in the next device pixel (exactPosition).
  struct WindowPress {
    QEvent::Type type = QEvent::None;
    quint64 timestamp = 0;
    QPointF position;  // in the top-level widget's coordinates
  } windowPress_;
  QWindow* watchedWindow_ = nullptr;
  enum class Drag { None, Orbit, Pan } drag_ = Drag::None;
  bool fastNavigation_ = true;
  bool liveFrames_ = true;
  bool framed_ = false;       // the framebuffer holds the frame of the current state (paintGL)
  bool sizingFrame_ = false;  // the size changes inside a frame that draws it (requestFrame: none)
  QStringList frameReasons_;  // why the next frame is drawn (mfr.view.frames); none: the window system
  bool navigating_ = false;
  QTimer* settle_ = nullptr;  // ends navigation a moment after the last drag or wheel step
  int lastReduction_ = 1;
  mfr::Stats previewStats_;

  // What the frame being painted tells the model, delivered after paintGL.
  struct Frame {
    int side = 0;
    ImageKey key;
    mfr::Stats stats;
  };
  struct Reports {
    std::vector<Frame> frames;
    std::vector<std::pair<int, std::pair<ImageKey, mfr::ImageRGBA8>>> images;
    QString error;
    bool reportError = false;
  };
  std::shared_ptr<Reports> reports_;

  std::array<PaneCaption*, kSides> captions_{};
  std::array<MapLegend*, kSides> legends_{};
  SplitHandle* splitHandle_ = nullptr;
  ProbeMarker* probeMarker_ = nullptr;
};
