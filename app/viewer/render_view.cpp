#include "render_view.hpp"

#include <QMouseEvent>
#include <QOpenGLContext>
#include <QWheelEvent>

#include <cmath>
#include <exception>

#include "camera_navigator.hpp"
#include "mfr/error.hpp"
#include "mfr/gl/context.hpp"
#include "viewer_model.hpp"

RenderView::RenderView(ViewerModel& model, QWidget* parent) : QOpenGLWidget(parent), model_(model) {
  setFocusPolicy(Qt::StrongFocus);
  setMinimumSize(160, 120);
  // Any change that alters the image schedules one repaint (Qt merges repeated requests).
  const auto repaint = [this] { update(); };
  connect(&model_, &ViewerModel::sceneChanged, this, repaint);
  connect(&model_, &ViewerModel::viewChanged, this, repaint);
  connect(&model_, &ViewerModel::methodChanged, this, repaint);
  connect(&model_, &ViewerModel::paramsChanged, this, repaint);
  connect(&model_, &ViewerModel::operationChanged, this, repaint);
  connect(&model_, &ViewerModel::oracleImageReady, this, repaint);
}

RenderView::~RenderView() {
  // GL objects must be deleted with their context current.
  if (renderer_ && context()) {
    makeCurrent();
    releaseGl();
    doneCurrent();
  }
}

void RenderView::releaseGl() {
  renderer_.reset();
  if (oracleFbo_) glDeleteFramebuffers(1, &oracleFbo_);
  if (oracleTexture_) glDeleteTextures(1, &oracleTexture_);
  oracleFbo_ = oracleTexture_ = 0;
}

QSize RenderView::pixelSize() const {
  const double ratio = devicePixelRatioF();
  return {std::max(1, static_cast<int>(std::lround(width() * ratio))),
          std::max(1, static_cast<int>(std::lround(height() * ratio)))};
}

void RenderView::initializeGL() {
  const QSurfaceFormat f = context()->format();
  glInfo_ = QStringLiteral("OpenGL %1.%2 %3")
                .arg(f.majorVersion())
                .arg(f.minorVersion())
                .arg(f.profile() == QSurfaceFormat::CoreProfile ? QStringLiteral("core") : QStringLiteral("compatibility"));
  if (f.majorVersion() < 4 || (f.majorVersion() == 4 && f.minorVersion() < 5)) {
    model_.reportRenderError(tr("mfrview needs OpenGL 4.5; this display offers %1").arg(glInfo_));
    return;
  }
  glInfo_ += QStringLiteral(" — ") + QString::fromLatin1(reinterpret_cast<const char*>(glGetString(GL_RENDERER)));
  mfr::gl::installDebugOutput();
  renderer_ = std::make_unique<mfr::GpuRenderer>();
  uploadedRevision_ = 0;
  // Qt destroys the context with the window (e.g. when a dock is floated): free our objects first.
  connect(context(), &QOpenGLContext::aboutToBeDestroyed, this, [this] {
    makeCurrent();
    releaseGl();
    doneCurrent();
  });
  emit glInitialized();
}

void RenderView::resizeGL(int, int) { model_.setRenderSize(pixelSize()); }

void RenderView::uploadSceneIfChanged() {
  if (uploadedRevision_ == model_.sceneRevision()) return;
  uploadedRevision_ = model_.sceneRevision();
  uploadError_.clear();
  try {
    renderer_->setScene(model_.scene());
  } catch (const std::exception& e) {
    uploadError_ = QString::fromUtf8(e.what());  // e.g. every object hidden
    mfr::gl::discardErrors();
  }
}

void RenderView::clearToBackground() {
  const glm::vec3 bg = model_.hasScene() ? model_.scene().background : glm::vec3(0.35f);
  glBindFramebuffer(GL_FRAMEBUFFER, defaultFramebufferObject());
  glClearColor(bg.r, bg.g, bg.b, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
}

void RenderView::paintGL() {
  model_.setRenderSize(pixelSize());
  if (!renderer_ || !model_.hasScene()) {
    clearToBackground();
    return;
  }
  uploadSceneIfChanged();
  if (!uploadError_.isEmpty()) {
    clearToBackground();
    model_.reportRenderError(uploadError_);
    return;
  }
  if (model_.method() == QLatin1String("oracle")) {
    drawOracleImage();
    return;
  }
  try {
    const mfr::Stats stats = renderer_->renderTo(defaultFramebufferObject(), model_.camera(), model_.renderRequest(pixelSize()));
    model_.reportFrame(stats);
  } catch (const std::exception& e) {
    mfr::gl::discardErrors();
    clearToBackground();
    model_.reportRenderError(QString::fromUtf8(e.what()));
  }
}

void RenderView::drawOracleImage() {
  const QImage* image = model_.oracleImage();
  const bool current = image != nullptr;
  if (!image) image = &model_.lastOracleImage();  // the previous view until the new one is ready
  if (image->isNull()) {
    clearToBackground();
    return;
  }
  if (!oracleTexture_ || oracleTextureSize_ != image->size()) {
    if (oracleFbo_) glDeleteFramebuffers(1, &oracleFbo_);
    if (oracleTexture_) glDeleteTextures(1, &oracleTexture_);
    glCreateTextures(GL_TEXTURE_2D, 1, &oracleTexture_);
    glTextureStorage2D(oracleTexture_, 1, GL_RGBA8, image->width(), image->height());
    glCreateFramebuffers(1, &oracleFbo_);
    glNamedFramebufferTexture(oracleFbo_, GL_COLOR_ATTACHMENT0, oracleTexture_, 0);
    oracleTextureSize_ = image->size();
  }
  // GL rows are bottom-up: upload the top-down image flipped so the blit shows it upright.
  const QImage flipped = image->mirrored(false, true);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  glTextureSubImage2D(oracleTexture_, 0, 0, 0, flipped.width(), flipped.height(), GL_RGBA, GL_UNSIGNED_BYTE, flipped.constBits());
  clearToBackground();
  const QSize target = pixelSize();
  glBlitNamedFramebuffer(oracleFbo_, defaultFramebufferObject(), 0, 0, image->width(), image->height(), 0,
                         target.height() - image->height(), image->width(), target.height(), GL_COLOR_BUFFER_BIT,
                         GL_NEAREST);
  if (current) model_.reportFrame(model_.oracleStats());
}

mfr::ImageRGBA8 RenderView::renderImage(QSize size) {
  if (!model_.hasScene()) throw mfr::Error("export", "no scene loaded");
  const mfr::RenderRequest request = model_.renderRequest(size);
  if (request.method == "oracle") return mfr::render(model_.scene(), model_.camera(), request).image;
  if (!renderer_) throw mfr::Error("OpenGL", "the view has no OpenGL 4.5 context yet");
  makeCurrent();
  struct DoneCurrent {
    RenderView* view;
    ~DoneCurrent() { view->doneCurrent(); }
  } done{this};
  uploadSceneIfChanged();
  if (!uploadError_.isEmpty()) throw mfr::Error(model_.scene().name, uploadError_.toStdString());
  try {
    return renderer_->render(model_.camera(), request).image;
  } catch (...) {
    mfr::gl::discardErrors();
    throw;
  }
}

// ---- navigation ----------------------------------------------------------------------------

void RenderView::mousePressEvent(QMouseEvent* event) {
  lastMouse_ = event->position().toPoint();
  const bool panGesture = event->button() == Qt::MiddleButton ||
                          (event->button() == Qt::LeftButton && (event->modifiers() & Qt::ShiftModifier));
  drag_ = panGesture ? Drag::Pan : event->button() == Qt::LeftButton ? Drag::Orbit : Drag::None;
}

void RenderView::mouseMoveEvent(QMouseEvent* event) {
  if (drag_ == Drag::None || !model_.hasScene()) return;
  const QPoint pos = event->position().toPoint();
  const QPointF delta = pos - lastMouse_;
  lastMouse_ = pos;
  if (drag_ == Drag::Orbit) model_.setCamera(navigation::orbit(model_.camera(), delta, size()));
  else model_.setCamera(navigation::pan(model_.camera(), delta, size()));
}

void RenderView::mouseReleaseEvent(QMouseEvent*) { drag_ = Drag::None; }

void RenderView::wheelEvent(QWheelEvent* event) {
  if (!model_.hasScene()) return;
  const double steps = event->angleDelta().y() / 120.0;
  if (steps != 0.0) model_.setCamera(navigation::zoomAt(model_.camera(), event->position(), size(), steps));
  event->accept();
}
