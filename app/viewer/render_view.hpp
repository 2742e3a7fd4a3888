#pragma once
// The central OpenGL 4.5 view. GPU methods render through mfrcore's GpuRenderer::renderTo into
// the widget's framebuffer — the code path of `mfr render` — so the widget's pixels equal the
// CLI's image for the same scene, view, size and settings. The oracle is drawn from the CPU
// image ViewerModel computes off the GUI thread.
//
// epoxy must come before Qt's OpenGL headers (it replaces the system GL headers).
#include <epoxy/gl.h>

#include <QOpenGLWidget>
#include <QPoint>

#include <memory>

#include "mfr/gpu_renderer.hpp"
#include "mfr/image.hpp"

class ViewerModel;

class RenderView final : public QOpenGLWidget {
  Q_OBJECT

 public:
  explicit RenderView(ViewerModel& model, QWidget* parent = nullptr);
  ~RenderView() override;

  // An image of the current scene and camera at any size, rendered offscreen on this view's
  // context exactly as `mfr render` does (GpuRenderer::render, or the oracle on the CPU).
  // Throws mfr::Error (no GL context yet, no scene, bad settings).
  mfr::ImageRGBA8 renderImage(QSize size);
  [[nodiscard]] bool glReady() const { return renderer_ != nullptr; }
  [[nodiscard]] const QString& glInfo() const { return glInfo_; }
  // The image size in device pixels.
  [[nodiscard]] QSize pixelSize() const;

 signals:
  void glInitialized();

 protected:
  void initializeGL() override;
  void resizeGL(int width, int height) override;
  void paintGL() override;
  void mousePressEvent(QMouseEvent* event) override;
  void mouseMoveEvent(QMouseEvent* event) override;
  void mouseReleaseEvent(QMouseEvent* event) override;
  void wheelEvent(QWheelEvent* event) override;

 private:
  void uploadSceneIfChanged();
  void drawOracleImage();
  void clearToBackground();
  void releaseGl();

  ViewerModel& model_;
  std::unique_ptr<mfr::GpuRenderer> renderer_;
  quint64 uploadedRevision_ = 0;
  QString uploadError_;
  QString glInfo_;
  QPoint lastMouse_;
  enum class Drag { None, Orbit, Pan } drag_ = Drag::None;
  // Texture + read framebuffer through which the oracle's CPU image is blitted.
  GLuint oracleTexture_ = 0, oracleFbo_ = 0;
  QSize oracleTextureSize_;
};
