#include "render_view.hpp"

#include <QLoggingCategory>
#include <QMouseEvent>
#include <QWindow>
#include <QOpenGLContext>
#include <QScopedValueRollback>
#include <QTimer>
#include <QWheelEvent>

#include <algorithm>
#include <cmath>
#include <exception>
#include <optional>

#include "camera_navigator.hpp"
#include "mfr/error.hpp"
#include "mfr/gl/context.hpp"
#include "mfr/reference/metrics.hpp"
#include "mfr/scene/csg.hpp"
#include "view_overlays.hpp"

namespace {

const char* sideName(int side) {
  return side == 0 ? "A" : "B";
}

// The heat map of a data map (magma over 0 … max); over `image` (same size) it is blended 1:1
// where the value is non-zero and leaves the image alone where it is zero.
mfr::ImageRGBA8 colourise(const RenderView::DataMap& map, const mfr::ImageRGBA8* image) {
  return mfr::countHeatmap(map.values, map.width, map.height, image);
}

}  // namespace

RenderView::RenderView(ViewerModel& model, QWidget* parent) : QOpenGLWidget(parent), model_(model) {
  setFocusPolicy(Qt::StrongFocus);
  // The framebuffer keeps the last frame between paints: Qt repaints the view under its captions,
  // legends and notes whenever one of them changes (each a full frame of a slow method, three
  // times per compare-mode view change: a review), and such a paint, asked for by nothing that
  // changes the picture, shows the frame there is (paintGL).
  setUpdateBehavior(QOpenGLWidget::PartialUpdate);
  // A framebuffer made anew holds nothing. Qt makes one when the size changes (resizeGL follows)
  // and when the window moves to a screen of another pixel ratio, where it calls no resizeGL: the
  // next paint found its frame "drawn" and left the view empty (review 28).
  connect(this, &QOpenGLWidget::resized, this, [this] {
    framed_ = false;
    update();
  });
  setMinimumSize(160, 120);
  // Any change that alters the image schedules one repaint (Qt merges repeated requests).
  const auto repaint = [this](const char* reason) { return [this, reason] { requestFrame(reason); }; };
  connect(&model_, &ViewerModel::sceneChanged, this, repaint("scene"));
  connect(&model_, &ViewerModel::viewChanged, this, repaint("view"));
  connect(&model_, &ViewerModel::sideChanged, this, repaint("side"));
  connect(&model_, &ViewerModel::compareChanged, this, repaint("compare"));
  connect(&model_, &ViewerModel::dataViewChanged, this, repaint("data view"));
  // Only a pane of a CPU method draws CPU images, and only its own: the reference of the metrics
  // comes for every frame while they are wanted (the budget panel's quality, compare mode), and a
  // frame drawn again for it changed nothing and cost as much as the view change.
  connect(&model_, &ViewerModel::cpuImageReady, this, [this](const ImageKey& key) {
    for (int side = 0; side < model_.paneCount(); ++side)
      if (model_.isCpuMethod(model_.methodOf(side)) && model_.frameKey(side) == key) return requestFrame("cpu image");
  });
  // A requested frame quality needs the frame on the CPU: draw it once more and read it back
  // (the widget's framebuffer is not kept between paints).
  connect(&model_, &ViewerModel::frameImageWanted, this, repaint("frame image wanted"));
  // Counted on the GPU between frames (queued: the request may come from inside a paint's report).
  connect(&model_, &ViewerModel::depthComplexityWanted, this, &RenderView::reportDepthComplexity, Qt::QueuedConnection);
  connect(&model_, &ViewerModel::metricsReady, this, [this] {
    // Heat maps are drawn into the image; the captions are widgets.
    if (model_.compareEnabled() && model_.compareDisplay() != CompareDisplay::Images)
      requestFrame("metrics");
    else
      updateOverlays();
  });

  for (int side = 0; side < kSides; ++side) {
    captions_[side] = new PaneCaption(this);
    captions_[side]->setObjectName(QStringLiteral("paneCaption%1").arg(sideName(side)));
    captions_[side]->hide();
    legends_[side] = new MapLegend(this);
    legends_[side]->setObjectName(QStringLiteral("mapLegend%1").arg(sideName(side)));
    legends_[side]->hide();
  }
  settle_ = new QTimer(this);
  settle_->setSingleShot(true);
  connect(settle_, &QTimer::timeout, this, [this] {
    navigating_ = false;
    if (lastReduction_ > 1) requestFrame("navigation settled");  // the full frame of where the motion stopped
  });

  errorNote_ = new QLabel(this);
  errorNote_->setObjectName(QStringLiteral("renderErrorNote"));
  errorNote_->setWordWrap(true);
  errorNote_->setAlignment(Qt::AlignCenter);
  errorNote_->setAttribute(Qt::WA_TransparentForMouseEvents);  // the view still orbits under it
  errorNote_->setStyleSheet(QStringLiteral(
      "QLabel { background: rgba(255, 255, 255, 230); color: #202020; border: 1px solid #c04030; padding: 10px; }"));
  errorNote_->hide();
  splitHandle_ = new SplitHandle(this);
  splitHandle_->setObjectName(QStringLiteral("splitHandle"));
  splitHandle_->hide();
  probeMarker_ = new ProbeMarker(this);
  probeMarker_->setObjectName(QStringLiteral("probeMarker"));
  probeMarker_->hide();
  connect(splitHandle_, &SplitHandle::dragged, this,
          [this](int x) { model_.setCompareSplit(static_cast<double>(x) / std::max(1, width())); });
}

RenderView::~RenderView() {
  // The context's aboutToBeDestroyed comes from ~QOpenGLWidget, after this destructor: its slot
  // would call releaseGl on destroyed members (UBSan's vptr check at every close; a sanitizer run).
  if (context()) disconnect(context(), &QOpenGLContext::aboutToBeDestroyed, this, nullptr);
  // GL objects must be deleted with their context current.
  if (renderers_[0] && context()) {
    makeCurrent();
    releaseGl();
    doneCurrent();
  }
}

void RenderView::releaseGl() {
  probeRenderer_.reset();
  for (auto& r : previewRenderers_) r.reset();  // they share the scene buffers of renderers_
  for (auto& r : renderers_) r.reset();
  for (auto* targets : {&targets_, &reducedTargets_})
    for (PaneTarget& t : *targets) {
      if (t.fbo) glDeleteFramebuffers(1, &t.fbo);
      if (t.texture) glDeleteTextures(1, &t.texture);
      t = {};
    }
  depthCache_ = {};
}

QSize RenderView::pixelSize() const {
  const double ratio = devicePixelRatioF();
  return {std::max(1, static_cast<int>(std::lround(width() * ratio))),
          std::max(1, static_cast<int>(std::lround(height() * ratio)))};
}

void RenderView::initializeGL() {
  framed_ = false;  // a new context (a dock floated): its framebuffer holds nothing yet
  const QSurfaceFormat f = context()->format();
  glInfo_ =
      QStringLiteral("OpenGL %1.%2 %3")
          .arg(f.majorVersion())
          .arg(f.minorVersion())
          .arg(f.profile() == QSurfaceFormat::CoreProfile ? QStringLiteral("core") : QStringLiteral("compatibility"));
  if (f.majorVersion() < 4 || (f.majorVersion() == 4 && f.minorVersion() < 5)) {
    model_.reportRenderError(tr("mfrview needs OpenGL 4.5; this display offers %1").arg(glInfo_));
    return;
  }
  glInfo_ += QStringLiteral(" — ") + QString::fromLatin1(reinterpret_cast<const char*>(glGetString(GL_RENDERER)));
  mfr::gl::installDebugOutput();
  renderers_[0] = std::make_unique<mfr::GpuRenderer>();
  uploadedRevision_ = {0, 0};
  // Qt destroys the context with the window (e.g. when a dock is floated): free our objects first.
  connect(context(), &QOpenGLContext::aboutToBeDestroyed, this, [this] {
    makeCurrent();
    releaseGl();
    doneCurrent();
  });
  emit glInitialized();
}

void RenderView::resizeGL(int, int) {
  framed_ = false;  // a new framebuffer, empty
  // QOpenGLWidget paints right after this: the new size's viewChanged needs no second frame.
  const QScopedValueRollback inFrame(sizingFrame_, true);
  model_.setRenderSize(pixelSize());
}

// QWidget repaints a widget that gains or loses focus, for a focus frame; the view draws none,
// and clicking into it from a dock cost a full frame.
void RenderView::focusInEvent(QFocusEvent*) {}
void RenderView::focusOutEvent(QFocusEvent*) {}

void RenderView::resizeEvent(QResizeEvent* event) {
  QOpenGLWidget::resizeEvent(event);
  updateOverlays();
}

mfr::GpuRenderer& RenderView::renderer(int side) {
  auto& r = renderers_[side == 1 ? 1 : 0];
  if (!r) {
    r = std::make_unique<mfr::GpuRenderer>();  // the second pane's, on first use
    uploadedRevision_[1] = 0;
  }
  return *r;
}

bool RenderView::uploadSceneIfChanged(int side, QStringList& errors) {
  const std::size_t i = side == 1 ? 1 : 0;
  mfr::GpuRenderer& r = renderer(side);
  if (uploadedRevision_[i] != model_.sceneRevision()) {
    uploadedRevision_[i] = model_.sceneRevision();
    uploadError_[i].clear();
    try {
      // A clip box and section that leave nothing say so, as mfr render and the export refuse
      // them (a flat box drew an empty view without a word: a bug hunt).
      if (const QString why = model_.drawError(); !why.isEmpty()) throw mfr::Error(why.toStdString());
      r.setScene(model_.drawnScene());
    } catch (const std::exception& e) {
      uploadError_[i] = QString::fromUtf8(e.what());  // e.g. every object hidden
      mfr::gl::discardErrors();
    }
  }
  if (uploadError_[i].isEmpty()) return true;
  errors << uploadError_[i];
  return false;
}

void RenderView::clearToBackground() {
  const glm::vec3 bg = model_.hasScene() ? model_.scene().background : glm::vec3(0.35f);
  glBindFramebuffer(GL_FRAMEBUFFER, defaultFramebufferObject());
  glClearColor(bg.r, bg.g, bg.b, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
}

// Each frame the window draws, for whoever asks (QT_LOGGING_RULES="mfr.view.frames.debug=true"):
// what a slow interaction or a scripted run spends its time on.
Q_LOGGING_CATEGORY(lcViewFrames, "mfr.view.frames", QtWarningMsg)

void RenderView::requestFrame(const char* reason) {
  if (sizingFrame_) return;
  framed_ = false;
  if (const QString r = QLatin1String(reason); !frameReasons_.contains(r)) frameReasons_.append(r);
  update();
}

void RenderView::setLiveFrames(bool on) {
  if (on == liveFrames_) return;
  liveFrames_ = on;
  requestFrame("live frames");
}

void RenderView::paintGL() {
  if (framed_) {
    // Nothing asked for this frame: Qt repaints the widgets over the view. The framebuffer holds
    // the last frame, which still shows what there is.
    qCDebug(lcViewFrames, "no frame: nothing changed (the window system repainted; the last frame stands)");
    return;
  }
  framed_ = true;  // until requestFrame or a resize
  const QStringList reasons = std::exchange(frameReasons_, {});
  {
    const QScopedValueRollback inFrame(sizingFrame_, true);  // this frame draws the new size
    model_.setRenderSize(pixelSize());
  }
  if (!liveFrames_) {
    clearToBackground();
    maps_ = {};
    return;
  }
  QStringList errors;
  reports_ = std::make_shared<Reports>();
  const int wanted = navigationReduction();
  const int reduction = wanted > 1 && paintReduced(wanted, errors) ? wanted : 1;
  if (reduction > 1) {
    // A navigation preview: drawn, not reported (its Stats describe a smaller image).
  } else if (!renderers_[0] || !model_.hasScene()) {
    clearToBackground();
    maps_ = {};
  } else if (!model_.compareEnabled() && model_.dataView() == DataView::Image && !model_.isCpuMethod(model_.method())) {
    maps_ = {};
    paintSingleImage(errors);
  } else {
    clearToBackground();
    for (int side = 0; side < model_.paneCount(); ++side) paintPane(side, errors);
    if (!model_.compareEnabled()) maps_[1] = {};
  }
  if (reduction != lastReduction_) {
    lastReduction_ = reduction;
    QMetaObject::invokeMethod(
        this, [this, reduction] { emit frameReductionChanged(reduction); }, Qt::QueuedConnection);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, defaultFramebufferObject());
  qCDebug(lcViewFrames, "frame %dx%d, 1/%d (%s)", pixelSize().width(), pixelSize().height(), reduction,
          qUtf8Printable(reasons.isEmpty() ? QStringLiteral("window system") : reasons.join(", ")));
  errors.removeDuplicates();
  reports_->error = errors.join(QStringLiteral("; "));
  reports_->reportError = renderers_[0] != nullptr;
  // Observers of the model may repaint other widgets at once (QProgressBar does), which makes
  // the window's compositing context current in the middle of our GL work: deliver the frame's
  // news after paintGL.
  QMetaObject::invokeMethod(
      this,
      [this, reports = std::move(reports_)] {
        // A frame whose settings changed meanwhile is not reported: its Stats would be read
        // against the new parameters (the budget panel fits memory models to them).
        for (const Frame& f : reports->frames)
          if (f.key == model_.frameKey(f.side)) model_.reportFrame(f.side, f.stats);
        for (auto& [side, image] : reports->images) model_.reportFrameImage(side, image.first, std::move(image.second));
        if (reports->reportError) model_.reportRenderError(reports->error);
        updateOverlays();
      },
      Qt::QueuedConnection);
}

// The main method straight into the widget's framebuffer, as GpuRenderer::render does into its
// own: the pixels `mfr render` writes.
void RenderView::paintSingleImage(QStringList& errors) {
  if (!uploadSceneIfChanged(0, errors)) {
    clearToBackground();
    return;
  }
  const QSize size = pixelSize();
  try {
    const mfr::Stats stats =
        renderer(0).renderTo(defaultFramebufferObject(), model_.camera(), model_.renderRequest(0, size));
    reports_->frames.push_back({0, model_.frameKey(0), stats});
    if (model_.wantsFrameImage(0))
      reports_->images.emplace_back(0, std::pair{model_.frameKey(0), readDefaultFramebuffer(size)});
  } catch (const std::exception& e) {
    mfr::gl::discardErrors();
    clearToBackground();
    errors << QString::fromUtf8(e.what());
  }
}

void RenderView::paintPane(int side, QStringList& errors) {
  const qsizetype errorsBefore = errors.size();
  const QSize size = model_.paneSize();
  const ImageKey key = model_.frameKey(side);
  const mfr::RenderRequest request = model_.renderRequest(side, size);
  const QString prefix = model_.compareEnabled() ? QStringLiteral("%1: ").arg(sideName(side)) : QString();
  const std::size_t i = side == 1 ? 1 : 0;
  PaneTarget& target = paneTarget(side, size);

  std::optional<mfr::ImageRGBA8> image;  // the pane's image on the CPU, when needed
  bool inTexture = false;                // `target` holds this frame (GPU methods)
  if (const QString why = model_.drawError(); !why.isEmpty() && model_.isCpuMethod(model_.methodOf(side))) {
    errors << prefix + why;  // as the GPU methods' upload says it
  } else if (model_.isCpuMethod(model_.methodOf(side))) {
    const ViewerModel::CpuSlot slot = ViewerModel::paneSlot(side);
    const CpuImage* cpu = model_.cpuImage(slot, request);
    const bool current = cpu != nullptr;
    if (!cpu) cpu = model_.lastCpuImage(slot);  // the previous view until the new one is ready
    if (cpu && !cpu->error.isEmpty()) {
      errors << prefix + cpu->error;
    } else if (cpu && cpu->image.width == size.width() && cpu->image.height == size.height()) {
      image = cpu->image;
      if (current) {
        reports_->frames.push_back({side, key, cpu->stats});
        if (model_.wantsFrameImage(side)) reports_->images.emplace_back(side, std::pair{key, cpu->image});
      }
    }
  } else if (uploadSceneIfChanged(side, errors)) {
    try {
      const mfr::Stats stats = renderer(side).renderTo(target.fbo, model_.camera(), request);
      inTexture = true;
      reports_->frames.push_back({side, key, stats});
    } catch (const std::exception& e) {
      mfr::gl::discardErrors();
      errors << prefix + QString::fromUtf8(e.what());
    }
  }

  const bool heat = model_.compareEnabled() && model_.compareDisplay() != CompareDisplay::Images;
  const bool mapView = !heat && model_.dataView() != DataView::Image;
  if (inTexture && (model_.wantsFrameImage(side) || (mapView && model_.dataViewOverImage()))) {
    image = readBack(target);
    if (model_.wantsFrameImage(side)) reports_->images.emplace_back(side, std::pair{key, *image});
  }

  maps_[i] = {};
  const mfr::ImageRGBA8* shown = nullptr;
  mfr::ImageRGBA8 composed;
  if (heat) {
    const PaneMetrics& m = model_.metrics(side);
    if (model_.metricsCurrent(side) && m.valid)
      shown = model_.compareDisplay() == CompareDisplay::FlipError ? &m.flipMap : &m.differenceMap;
  } else if (mapView) {
    maps_[i] = computeDataMap(side, size, key, inTexture);
    if (!maps_[i].values.empty()) {
      composed = colourise(maps_[i], model_.dataViewOverImage() && image ? &*image : nullptr);
      shown = &composed;
    }
  }
  if (!shown && image && !inTexture) shown = &*image;
  if (shown) upload(target, *shown);
  if (shown || inTexture) blitPane(side, target);
  paneFailed_[i] = errors.size() > errorsBefore;
}

RenderView::DataMap RenderView::computeDataMap(int side, QSize size, const ImageKey& key, bool haveFrame) {
  DataMap map;
  map.kind = model_.dataView();
  map.key = key;
  map.width = size.width();
  map.height = size.height();
  if (map.kind == DataView::DepthComplexity) {
    try {
      map.values = depthCounts(size);
    } catch (const std::exception& e) {
      map.note = QString::fromUtf8(e.what());
      return map;
    }
  } else {
    // k(p) belongs to the frame just rendered by this pane's renderer.
    if (haveFrame) map.values = renderer(side).kMap();
    if (map.values.size() != static_cast<std::size_t>(size.width()) * size.height()) {
      map.values.clear();
      map.note = tr("no k(p) for this method");
      return map;
    }
  }
  const auto [lo, hi] = std::minmax_element(map.values.begin(), map.values.end());
  map.minValue = *lo;
  map.maxValue = *hi;
  return map;
}

const std::vector<std::uint32_t>& RenderView::depthCounts(QSize size) {
  const bool cached = depthCache_.scene == model_.sceneRevision() && depthCache_.view == model_.viewRevision() &&
                      depthCache_.size == size && !depthCache_.values.empty();
  if (!cached) {
    QStringList errors;
    if (!uploadSceneIfChanged(0, errors)) throw mfr::Error("depth complexity", errors.join("; ").toStdString());
    try {
      depthCache_ = {model_.sceneRevision(), model_.viewRevision(), size,
                     renderer(0).depthComplexity(model_.camera(), size.width(), size.height())};
    } catch (...) {
      mfr::gl::discardErrors();
      depthCache_ = {};
      throw;
    }
  }
  return depthCache_.values;
}

void RenderView::reportDepthComplexity() {
  if (!renderers_[0] || !model_.hasScene()) return;
  const QSize size = model_.paneSize();  // the image of the statistics (half the view side by side)
  QVector<quint64> histogram;
  makeCurrent();
  try {
    for (std::uint32_t n : depthCounts(size)) {
      if (n >= static_cast<std::uint32_t>(histogram.size())) histogram.resize(n + 1);
      ++histogram[n];
    }
  } catch (const std::exception&) {
    histogram.clear();  // nothing visible: an empty histogram says so
  }
  doneCurrent();
  model_.reportDepthComplexity(histogram, size);
}

RenderView::PaneTarget& RenderView::targetOf(std::array<PaneTarget, kSides>& targets, int side, QSize size) {
  PaneTarget& t = targets[side == 1 ? 1 : 0];
  if (t.texture && t.size == size) return t;
  if (t.fbo) glDeleteFramebuffers(1, &t.fbo);
  if (t.texture) glDeleteTextures(1, &t.texture);
  glCreateTextures(GL_TEXTURE_2D, 1, &t.texture);
  glTextureStorage2D(t.texture, 1, GL_RGBA8, size.width(), size.height());
  glCreateFramebuffers(1, &t.fbo);
  glNamedFramebufferTexture(t.fbo, GL_COLOR_ATTACHMENT0, t.texture, 0);
  t.size = size;
  return t;
}

// Like GpuRenderer::render's read-back: the texture's rows, flipped to top-down.
mfr::ImageRGBA8 RenderView::readBack(const PaneTarget& target) const {
  mfr::ImageRGBA8 image(target.size.width(), target.size.height());
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glGetTextureImage(target.texture, 0, GL_RGBA, GL_UNSIGNED_BYTE, static_cast<GLsizei>(image.pixels.size()),
                    image.pixels.data());
  mfr::flipVertically(image);
  return image;
}

mfr::ImageRGBA8 RenderView::readDefaultFramebuffer(QSize size) const {
  mfr::ImageRGBA8 image(size.width(), size.height());
  glBindFramebuffer(GL_READ_FRAMEBUFFER, defaultFramebufferObject());
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, size.width(), size.height(), GL_RGBA, GL_UNSIGNED_BYTE, image.pixels.data());
  mfr::flipVertically(image);
  return image;
}

void RenderView::upload(const PaneTarget& target, const mfr::ImageRGBA8& image) {
  if (image.width != target.size.width() || image.height != target.size.height()) return;
  // GL rows are bottom-up: upload the top-down image flipped so the blit shows it upright.
  mfr::ImageRGBA8 flipped = image;
  mfr::flipVertically(flipped);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  glTextureSubImage2D(target.texture, 0, 0, 0, image.width, image.height, GL_RGBA, GL_UNSIGNED_BYTE,
                      flipped.pixels.data());
}

QRect RenderView::paneRect(int side) const {
  const QSize full = pixelSize();
  if (!model_.compareEnabled() || model_.compareLayout() == CompareLayout::Split) return {QPoint(0, 0), full};
  const QSize pane = model_.paneSize();
  return {QPoint(side == 1 ? pane.width() : 0, 0), pane};
}

QRectF RenderView::logicalRect(const QRect& device) const {
  const double ratio = devicePixelRatioF();
  return {device.x() / ratio, device.y() / ratio, device.width() / ratio, device.height() / ratio};
}

QPoint RenderView::devicePixel(QPointF point, double ratio) {
  constexpr double kRoundingSlack = 1e-6;  // of a device pixel: far above the error, far below a real offset
  return {static_cast<int>(std::floor(point.x() * ratio + kRoundingSlack)),
          static_cast<int>(std::floor(point.y() * ratio + kRoundingSlack))};
}

int RenderView::paneAt(QPointF point) const {
  const QPoint device = devicePixel(point, devicePixelRatioF());
  int found = -1;
  for (int side = 0; side < model_.paneCount(); ++side)
    if (paneVisibleRect(side).contains(device)) found = side;
  return found;
}

QRectF RenderView::navigationArea(QPointF point) const {
  int side = paneAt(point);
  // Off every image (the odd last column side by side, a point dragged past the edge): the pane
  // on that side of the middle.
  if (side < 0)
    side = model_.compareEnabled() && model_.compareLayout() != CompareLayout::Split &&
                   point.x() >= logicalRect(paneRect(1)).left()
               ? 1
               : 0;
  return logicalRect(paneRect(side));
}

QRect RenderView::paneVisibleRect(int side) const {
  const QRect pane = paneRect(side);
  if (!model_.compareEnabled() || model_.compareLayout() != CompareLayout::Split) return pane;
  const int splitX = static_cast<int>(std::lround(model_.compareSplit() * pane.width()));
  return side == 0 ? QRect(0, 0, splitX, pane.height()) : QRect(splitX, 0, pane.width() - splitX, pane.height());
}

void RenderView::blitPane(int side, const PaneTarget& target) {
  const QRect pane = paneRect(side), shown = paneVisibleRect(side);
  if (shown.isEmpty()) return;
  const int fullHeight = pixelSize().height();
  // Source: pane-local columns; rows flip from top-down rectangles to GL's bottom-up ones. A
  // navigation preview's target is smaller than the pane: its coordinates scale, and it is
  // filtered.
  const double sx = static_cast<double>(target.size.width()) / pane.width();
  const double sy = static_cast<double>(target.size.height()) / pane.height();
  const auto scaled = [](int v, double s) { return static_cast<int>(std::lround(v * s)); };
  const int sx0 = scaled(shown.left() - pane.left(), sx), sx1 = scaled(shown.left() - pane.left() + shown.width(), sx);
  const int sy0 = scaled(pane.height() - (shown.top() - pane.top() + shown.height()), sy);
  const int sy1 = scaled(pane.height() - (shown.top() - pane.top()), sy);
  const int dy0 = fullHeight - (shown.top() + shown.height()), dy1 = dy0 + shown.height();
  const bool same = target.size == pane.size();
  glBlitNamedFramebuffer(target.fbo, defaultFramebufferObject(), sx0, sy0, sx1, sy1, shown.left(), dy0,
                         shown.left() + shown.width(), dy1, GL_COLOR_BUFFER_BIT, same ? GL_NEAREST : GL_LINEAR);
}

// ---- navigation previews -------------------------------------------------------------------

void RenderView::setFastNavigation(bool on) {
  fastNavigation_ = on;
  if (!on && lastReduction_ > 1) requestFrame("fast navigation");
}

int RenderView::navigationReduction() const {
  if (!navigating_ || !fastNavigation_ || !renderers_[0] || !model_.hasScene()) return 1;
  // Images only: data maps and heat maps are computed at the full size, CPU panes off the GUI thread.
  if (model_.dataView() != DataView::Image) return 1;
  if (model_.compareEnabled() && model_.compareDisplay() != CompareDisplay::Images) return 1;
  for (int side = 0; side < model_.paneCount(); ++side)
    if (model_.isCpuMethod(model_.methodOf(side))) return 1;
  double fullFrameMs = 0.0;  // the last full frame's GPU time, all panes (previews are not reported)
  for (int side = 0; side < model_.paneCount(); ++side) fullFrameMs += model_.statsOf(side).totalTimeMs();
  const double f = std::ceil(std::sqrt(fullFrameMs / kNavigationFrameMs));
  return static_cast<int>(std::clamp(f, 1.0, static_cast<double>(kMaxReduction)));
}

mfr::RenderRequest RenderView::reducedRequest(int side, QSize size, QSize full) const {
  mfr::RenderRequest request = model_.renderRequest(side, size);
  const double share =
      static_cast<double>(size.width()) * size.height() / (static_cast<double>(full.width()) * full.height());
  if (const mfr::MethodInfo* info = model_.methodInfo(model_.methodOf(side)))
    for (const mfr::ParamSpec& spec : info->params) {
      if (!spec.perImage) continue;
      const auto it = request.params.find(spec.name);
      const std::string& text = it != request.params.end() ? it->second : spec.defaultValue;
      bool ok = false;
      const double value = QString::fromStdString(text).toDouble(&ok);
      if (ok) request.params[spec.name] = QString::number(value * share, 'g', 12).toStdString();
    }
  return request;
}

// Every pane at 1/reduction of its size, scaled up. False when a pane cannot be drawn so (the
// caller then draws the full frame, which reports why).
bool RenderView::paintReduced(int reduction, QStringList& errors) {
  clearToBackground();
  for (int side = 0; side < model_.paneCount(); ++side) {
    if (!uploadSceneIfChanged(side, errors)) return false;
    const QSize full = model_.paneSize();
    const QSize size((full.width() + reduction - 1) / reduction, (full.height() + reduction - 1) / reduction);
    PaneTarget& target = targetOf(reducedTargets_, side, size);
    auto& preview = previewRenderers_[side == 1 ? 1 : 0];
    try {
      if (!preview) preview = std::make_unique<mfr::GpuRenderer>();
      preview->shareScene(renderer(side));
      const mfr::Stats stats = preview->renderTo(target.fbo, model_.camera(), reducedRequest(side, size, full));
      if (side == 0) previewStats_ = stats;
    } catch (const std::exception&) {
      mfr::gl::discardErrors();
      return false;
    }
    blitPane(side, target);
  }
  return true;
}

void RenderView::beginNavigation() {
  navigating_ = true;
  settle_->stop();
}

void RenderView::endNavigation(int settleMs) {
  settle_->start(settleMs);
}

// ---- overlays ------------------------------------------------------------------------------

// " k=4 tail=true": the parameters in which this pane's method differs from the other pane's, when
// both panes run the same method (what a same-method comparison is about); values as set or default.
QString RenderView::differingParams(int side) const {
  const QString method = model_.methodOf(side);
  const mfr::MethodInfo* info = model_.methodInfo(method);
  if (!info || model_.methodOf(1 - side) != method) return {};
  const std::map<std::string, std::string> mine = model_.paramsOf(side), other = model_.paramsOf(1 - side);
  const auto value = [this](int of, const std::map<std::string, std::string>& set, const mfr::ParamSpec& spec) {
    const auto it = set.find(spec.name);
    return it == set.end() ? mfr::defaultValueFor(spec, model_.effectiveOperationOf(of).toStdString()) : it->second;
  };
  QString text;
  for (const mfr::ParamSpec& spec : info->params)
    if (value(side, mine, spec) != value(1 - side, other, spec))
      text += QStringLiteral(" %1=%2").arg(QString::fromStdString(spec.name),
                                           QString::fromStdString(value(side, mine, spec)));
  return text;
}

void RenderView::updateOverlays() {
  const double ratio = devicePixelRatioF();
  // A frame that cannot be rendered leaves the view empty: say why there, not only in the status
  // bar, whose next message would hide it.
  if (!model_.compareEnabled() && model_.hasScene() && !model_.renderError().isEmpty()) {
    errorNote_->setText(tr("Cannot render:\n%1").arg(model_.renderErrorShown()));
    errorNote_->setFixedWidth(std::clamp(width() - 24, 80, 520));
    errorNote_->adjustSize();
    errorNote_->move(std::max(0, (width() - errorNote_->width()) / 2),
                     std::max(0, (height() - errorNote_->height()) / 2));
    errorNote_->show();
    errorNote_->raise();
  } else {
    errorNote_->hide();
  }
  const bool compare = model_.compareEnabled() && model_.hasScene();
  const bool split = compare && model_.compareLayout() == CompareLayout::Split;
  const bool heat = compare && model_.compareDisplay() != CompareDisplay::Images;
  for (int side = 0; side < kSides; ++side) {
    const bool shown = side < model_.paneCount() && model_.hasScene();
    const QRectF logical = logicalRect(split ? paneRect(side) : paneVisibleRect(side));
    const QRect area(static_cast<int>(logical.x()), static_cast<int>(logical.y()), static_cast<int>(logical.width()),
                     static_cast<int>(logical.height()));  // truncated, as the captions were placed
    // Captions: which method, and how far it is from the exact image.
    PaneCaption* caption = captions_[side];
    if (compare && shown) {
      const PaneMetrics& m = model_.metrics(side);
      QString operation = model_.operationOf(side);
      if (operation == QLatin1String("zthickness"))
        operation += QStringLiteral(" %1").arg(
            model_.zThickness() > 0.0 ? model_.zThickness() : model_.zThicknessDefault(), 0, 'g', 4);
      const QString effective = model_.effectiveOperationOf(side);
      if (effective != model_.operationOf(side)) operation += QStringLiteral(" → ") + effective;
      if (effective == QLatin1String("volume"))
        operation += QStringLiteral(", step %1")
                         .arg(model_.volumeStep() > 0.0 ? model_.volumeStep() : model_.volumeStepDefault(), 0, 'g', 4);
      QStringList lines{
          QStringLiteral("%1 · %2 (%3)")
              .arg(QLatin1String(sideName(side)), model_.methodOf(side) + differingParams(side), operation)};
      if (paneFailed_[side])
        lines << tr("cannot render (see the status bar)");
      else if (!model_.metricsCurrent(side))
        lines << tr("RMSE, FLIP: computing…");
      else if (!m.valid)
        lines << tr("no metrics: %1").arg(m.error);
      else
        lines << tr("RMSE %1").arg(m.rmse, 0, 'f', 5) << tr("FLIP %1").arg(m.flip.mean, 0, 'f', 4);
      // Within its pane (half the view when split), so the two captions never overlap.
      const int room = std::max(40, (split ? width() / 2 : area.width()) - 12 - 2 * caption->margin());
      for (QString& line : lines) line = caption->fontMetrics().elidedText(line, Qt::ElideRight, room);
      caption->setText(lines.join(QLatin1Char('\n')));
      caption->adjustSize();
      const int x = split && side == 1 ? area.right() - caption->width() - 6 : area.left() + 6;
      caption->move(std::max(0, x), area.top() + 6);
      caption->show();
    } else {
      caption->hide();
    }
    // Legends: the scale of whatever heat map the pane shows.
    MapLegend* legend = legends_[side];
    bool legendShown = false;
    if (shown && heat) {
      const PaneMetrics& m = model_.metrics(side);
      const bool flip = model_.compareDisplay() == CompareDisplay::FlipError;
      const QString title = flip ? tr("%1: FLIP error vs exact").arg(QLatin1String(sideName(side)))
                                 : tr("%1: |difference| vs exact").arg(QLatin1String(sideName(side)));
      if (!model_.metricsCurrent(side) || !m.valid)
        legend->setNote(title, tr("computing…"));
      else if (flip)
        legend->setMap(title, 1.0, tr("mean %1 · max %2").arg(m.flip.mean, 0, 'f', 4).arg(m.flip.max, 0, 'f', 3));
      else
        legend->setMap(
            title, std::max(m.maxDifference, 1.0f / 255.0f),
            tr("max %1 (%2 of 255)").arg(m.maxDifference, 0, 'f', 4).arg(std::lround(m.maxDifference * 255.0f)));
      legendShown = true;
    } else if (shown && maps_[side].kind != DataView::Image) {
      const DataMap& map = maps_[side];
      const QString title = map.kind == DataView::DepthComplexity
                                ? tr("n(p): fragments per pixel (exact)")
                                : tr("k(p): capacity of %1").arg(model_.methodOf(side));
      if (map.values.empty())
        legend->setNote(title, map.note);
      else
        legend->setMap(title, std::max<std::uint32_t>(1, map.maxValue),
                       tr("min %1 · max %2").arg(map.minValue).arg(map.maxValue));
      legendShown = true;
    } else if (const std::optional<ViewerModel::ColorLegend> colors = model_.colorLegend(); shown && colors) {
      // The colour legend of the field the surfaces show (Scene dock, Colour by), else of the
      // volume's isosurfaces (Volume panel), ticked at their values.
      const mfr::FieldColors& field = colors->colors;
      QString text = QString::fromStdString(field.map);
      if (!colors->ticks.empty()) {
        QStringList values;
        for (const double v : colors->ticks) values << QString::number(v, 'g', 4);
        text = tr("isosurfaces at %1").arg(values.join(QStringLiteral(", ")));
      }
      legend->setFieldMap(QString::fromStdString(field.field), QString::fromStdString(field.map), field.range.x,
                          field.range.y, text, colors->ticks);
      legendShown = true;
    }
    if (legendShown) {
      const int x = split && side == 1 ? area.right() - legend->width() - 6 : area.left() + 6;
      legend->move(std::max(0, x), std::max(0, area.bottom() - legend->height() - 6));
      legend->show();
    } else {
      legend->hide();
    }
  }
  if (split) {
    const int x = static_cast<int>(paneVisibleRect(1).left() / ratio);
    splitHandle_->setGeometry(x - SplitHandle::kWidth / 2, 0, SplitHandle::kWidth, height());
    splitHandle_->show();
    splitHandle_->raise();
  } else {
    splitHandle_->hide();
  }
}

// ---- export --------------------------------------------------------------------------------

RenderView::CurrentContext RenderView::currentWithScene(int side) {
  if (!renderers_[0]) throw mfr::Error("OpenGL", "the view has no OpenGL 4.5 context yet");
  CurrentContext current(*this);
  QStringList errors;
  if (!uploadSceneIfChanged(side, errors)) throw mfr::Error(model_.scene().name, errors.join("; ").toStdString());
  return current;
}

mfr::ImageRGBA8 RenderView::renderImage(QSize size) {
  return renderOutput(size, {}).image;
}

mfr::RenderOutput RenderView::renderOutput(QSize size, const std::map<std::string, std::string>& params) {
  if (!model_.hasScene()) throw mfr::Error("export", "no scene loaded");
  mfr::RenderRequest request = model_.renderRequest(0, size);
  for (const auto& [name, value] : params) request.params[name] = value;
  if (const QString why = model_.drawError(); !why.isEmpty()) throw mfr::Error(why.toStdString());
  if (model_.isCpuMethod(model_.method())) return mfr::render(model_.drawnScene(), model_.camera(), request);
  // What mfr render refuses (a scene of degenerate triangles, a singular camera) is refused here too.
  mfr::checkDrawable(model_.drawnScene(), model_.camera(), size.width(), size.height());
  const CurrentContext current = currentWithScene(0);
  try {
    return renderer(0).render(model_.camera(), request);
  } catch (...) {
    mfr::gl::discardErrors();
    throw;
  }
}

// ---- pixel probe ---------------------------------------------------------------------------

RenderView::PanePixel RenderView::panePixelAt(QPointF point, const char* what) const {
  if (!model_.hasScene()) throw mfr::Error(what, "no scene loaded");
  if (const QString why = model_.drawError(); !why.isEmpty()) throw mfr::Error(why.toStdString());
  const QPoint device = devicePixel(point, devicePixelRatioF());
  PanePixel at;
  at.device = device;
  at.side = paneAt(point);
  if (at.side < 0) throw mfr::Error(what, "the point is not on an image");
  at.pane = paneRect(at.side);
  at.pixel = device - at.pane.topLeft();
  return at;
}

int RenderView::partAt(QPointF point) const {
  const PanePixel at = panePixelAt(point, "pick");
  const mfr::PixelProbe probe = mfr::probePixel(model_.drawnScene(), model_.camera(), at.pane.width(), at.pane.height(),
                                                at.pixel.x(), at.pixel.y());
  // The drawn scene's ids: a section's volume slices come after the scene's parts, and a slice
  // in front hides what lies behind it (the part behind was picked: a review).
  const auto part = [&](const mfr::Fragment& f) {
    return f.objectId < model_.scene().objects.size() ? static_cast<int>(f.objectId) : -1;
  };
  // With the operation csg the pixel shows the surface the classification keeps, not the nearest
  // fragment (a ball cut away, or a drill's hole, was picked where the block or nothing shows).
  const mfr::Scene& drawn = model_.drawnScene();
  if (model_.effectiveOperationOf(at.side) == QLatin1String("csg") && !drawn.csg.empty()) {
    std::vector<mfr::Fragment> sorted;
    sorted.reserve(probe.fragments.size());
    for (const mfr::ProbeFragment& f : probe.fragments) sorted.push_back(f.fragment);
    const std::optional<std::size_t> visible =
        mfr::csgVisibleFragment(drawn.csg, sorted, mfr::csgMirroredPrimitives(drawn));
    return visible ? part(sorted[*visible]) : -1;
  }
  for (const mfr::ProbeFragment& f : probe.fragments)
    if ((f.fragment.color >> 24) != 0) return part(f.fragment);
  return -1;
}

ViewProbe RenderView::probeAt(QPointF point) {
  const PanePixel at = panePixelAt(point, "probe");
  const QPoint device = at.device;
  ViewProbe result;
  result.point = point;
  result.side = at.side;
  const QRect pane = at.pane;
  result.paneSize = pane.size();
  result.method = model_.methodOf(result.side);
  const QPoint pixel = at.pixel;
  result.probe =
      mfr::probePixel(model_.drawnScene(), model_.camera(), pane.width(), pane.height(), pixel.x(), pixel.y());
  const bool showsImage = model_.dataView() == DataView::Image &&
                          (!model_.compareEnabled() || model_.compareDisplay() == CompareDisplay::Images);
  if (showsImage && renderers_[0]) {
    // What the last frame left in the widget's framebuffer (GL rows bottom-up).
    const CurrentContext current(*this);
    std::uint8_t rgba[4] = {0, 0, 0, 0};
    glBindFramebuffer(GL_READ_FRAMEBUFFER, defaultFramebufferObject());
    glReadPixels(device.x(), pixelSize().height() - 1 - device.y(), 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, rgba);
    result.shown = QColor(rgba[0], rgba[1], rgba[2]);
  }

  // The operation "volume": surfaces and the medium before, between and behind them.
  if (model_.effectiveOperationOf(result.side) == QLatin1String("volume"))
    mfr::splitVolume(result.probe, model_.drawnScene(), model_.camera(),
                     model_.renderRequest(result.side, pane.size()));
  // The operation "zthickness": each surface's share of the blend.
  if (model_.effectiveOperationOf(result.side) == QLatin1String("zthickness"))
    mfr::splitZThickness(result.probe, model_.drawnScene(), model_.camera(),
                         model_.renderRequest(result.side, pane.size()));

  const mfr::MethodInfo* info = model_.isCpuMethod(result.method) ? nullptr : model_.methodInfo(result.method);
  result.methodHasLists = info != nullptr && info->sortedLists;
  if (!result.methodHasLists) return result;
  const CurrentContext current = currentWithScene(result.side);
  try {
    if (!probeRenderer_) probeRenderer_ = std::make_unique<mfr::GpuRenderer>();
    probeRenderer_->shareScene(renderer(result.side));
    // Room for every exact fragment and more, so a method holding extra ones shows them.
    const int room = static_cast<int>(std::min<std::size_t>(result.probe.fragments.size() * 2 + 64, 1u << 16));
    const mfr::CapturedLists lists =
        probeRenderer_->capture(model_.camera(), model_.renderRequest(result.side, pane.size()), room,
                                mfr::PixelRect{pixel.x(), pixel.y(), 1, 1});
    const std::uint32_t count = lists.count(pixel.x(), pixel.y());
    mfr::matchCapture(result.probe,
                      {lists.pixel(pixel.x(), pixel.y()), std::min<std::size_t>(count, static_cast<std::size_t>(room))},
                      count);
    if (model_.effectiveOperationOf(result.side) == QLatin1String("hybrid"))
      mfr::splitHybrid(result.probe, model_.drawnScene().background);
  } catch (...) {
    mfr::gl::discardErrors();
    throw;
  }
  return result;
}

void RenderView::setProbeMark(std::optional<QPointF> point) {
  if (!point) {
    probeMarker_->hide();
    return;
  }
  probeMarker_->setCentre(point->toPoint());
  probeMarker_->show();
  probeMarker_->raise();
}

// ---- navigation ----------------------------------------------------------------------------

void RenderView::mousePressEvent(QMouseEvent* event) {
  lastMouse_ = event->position().toPoint();
  if (event->button() == Qt::LeftButton && (event->modifiers() & Qt::ControlModifier)) {
    drag_ = Drag::None;  // a probe, not the start of an orbit
    emit probeRequested(exactPosition(*event));
    return;
  }
  const bool panGesture = event->button() == Qt::MiddleButton ||
                          (event->button() == Qt::LeftButton && (event->modifiers() & Qt::ShiftModifier));
  drag_ = panGesture ? Drag::Pan : event->button() == Qt::LeftButton ? Drag::Orbit : Drag::None;
  if (drag_ != Drag::None) beginNavigation();
}

void RenderView::mouseMoveEvent(QMouseEvent* event) {
  if (drag_ == Drag::None || !model_.hasScene()) return;
  const QPoint pos = event->position().toPoint();
  const QPointF delta = pos - lastMouse_;
  lastMouse_ = pos;
  const QSize area = navigationArea(pos).size().toSize();
  if (drag_ == Drag::Orbit)
    model_.setCamera(navigation::orbit(model_.camera(), delta, area));
  else
    model_.setCamera(navigation::pan(model_.camera(), delta, area));
}

void RenderView::mouseReleaseEvent(QMouseEvent*) {
  if (drag_ != Drag::None) endNavigation(150);
  drag_ = Drag::None;
}

// A plain left double click picks; any other is the press it is (a second pan, zoom or probe
// started quickly after the first was swallowed: a review).
void RenderView::mouseDoubleClickEvent(QMouseEvent* event) {
  if (event->button() != Qt::LeftButton || event->modifiers() != Qt::NoModifier) {
    mousePressEvent(event);
    return;
  }
  drag_ = Drag::None;  // not the start of an orbit
  emit partPickRequested(exactPosition(*event));
}

// The point under the cursor, with its fraction of a logical pixel: at a fractional scale a
// rounded point lies in the next device pixel (scale 2: no odd row or column could be probed or
// picked; a bug hunt). QApplication rounds the positions of the event a widget gets (a review);
// the top-level window's own event, seen by eventFilter, keeps the fraction.
QPointF RenderView::exactPosition(const QMouseEvent& event) const {
  if (windowPress_.type != event.type() || windowPress_.timestamp != event.timestamp()) return event.position();
  const QPointF local = windowPress_.position - mapTo(window(), QPointF(0, 0));
  // The same press (within the rounding), or another's.
  return std::abs(local.x() - event.position().x()) <= 0.5 && std::abs(local.y() - event.position().y()) <= 0.5
             ? local
             : event.position();
}

void RenderView::showEvent(QShowEvent* event) {
  QOpenGLWidget::showEvent(event);
  QWindow* top = window()->windowHandle();
  if (top == watchedWindow_ || top == nullptr) return;
  if (watchedWindow_) watchedWindow_->removeEventFilter(this);
  watchedWindow_ = top;
  top->installEventFilter(this);
  connect(top, &QObject::destroyed, this, [this, top] {
    if (watchedWindow_ == top) watchedWindow_ = nullptr;
  });
}

bool RenderView::eventFilter(QObject* watched, QEvent* event) {
  if (watched == watchedWindow_ &&
      (event->type() == QEvent::MouseButtonPress || event->type() == QEvent::MouseButtonDblClick)) {
    const auto* press = static_cast<const QMouseEvent*>(event);
    windowPress_ = {event->type(), press->timestamp(), press->position()};
  }
  return QOpenGLWidget::eventFilter(watched, event);
}

void RenderView::wheelEvent(QWheelEvent* event) {
  if (!model_.hasScene()) return;
  const double steps = event->angleDelta().y() / 120.0;
  if (steps != 0.0) {
    beginNavigation();
    endNavigation(300);  // wheel steps come apart: the motion has stopped when none follows soon
    const QRectF area = navigationArea(event->position());
    model_.setCamera(
        navigation::zoomAt(model_.camera(), event->position() - area.topLeft(), area.size().toSize(), steps));
  }
  event->accept();
}
