#pragma once
// The viewer's state — scene, camera, method, parameters, last frame's Stats — and the work it
// runs off the GUI thread (loading, the oracle's exact image and depth complexity). Widgets and
// plugins observe it through ViewerContext's signals; RenderView draws it.
#include <QColor>
#include <QImage>
#include <QSize>
#include <QString>

#include <map>
#include <optional>
#include <string>

#include "mfr/render.hpp"
#include "mfr/scene/scene.hpp"
#include "viewer_plugin.hpp"

class ViewerModel final : public ViewerContext {
  Q_OBJECT

 public:
  explicit ViewerModel(QObject* parent = nullptr);
  ~ViewerModel() override;

  // ViewerContext
  [[nodiscard]] QStringList methodNames() const override;
  [[nodiscard]] const mfr::MethodInfo* methodInfo(const QString& method) const override;
  [[nodiscard]] QString method() const override { return method_; }
  void setMethod(const QString& method) override;
  [[nodiscard]] std::map<std::string, std::string> params() const override;
  void setParams(const std::map<std::string, std::string>& changes) override;
  [[nodiscard]] bool hasScene() const override { return hasScene_; }
  [[nodiscard]] const mfr::Stats& stats() const override { return stats_; }
  [[nodiscard]] QSize renderSize() const override { return renderSize_; }
  void requestDepthComplexity() override;

  // Scene. loadSceneAsync reads the file on a worker thread; the current scene stays until the
  // new one has loaded (sceneLoaded) — a failure (loadFailed) or cancelLoad() leaves it intact.
  void loadSceneAsync(const QString& path);
  void cancelLoad();
  [[nodiscard]] bool isLoading() const { return loading_; }
  void setScene(mfr::Scene scene, const QString& path);
  [[nodiscard]] const mfr::Scene& scene() const { return scene_; }
  [[nodiscard]] const QString& scenePath() const { return scenePath_; }
  [[nodiscard]] quint64 sceneRevision() const { return sceneRevision_; }
  void setObjectVisible(int index, bool visible);
  void setObjectColor(int index, const QColor& rgb);
  void setObjectOpacity(int index, double opacity);
  void setObjectMaterial(int index, const glm::vec4& rgba);

  // Camera: setCamera refits near/far around the visible objects, so navigation never clips.
  [[nodiscard]] const mfr::Camera& camera() const { return camera_; }
  void setCamera(const mfr::Camera& camera);
  [[nodiscard]] const mfr::Bounds& sceneBounds() const { return bounds_; }
  [[nodiscard]] double sceneRadius() const { return radius_; }
  void setRenderSize(QSize size);
  [[nodiscard]] quint64 viewRevision() const { return viewRevision_; }

  [[nodiscard]] QString operation() const { return operation_; }
  void setOperation(const QString& operation);
  // Parameters set per method (sessions keep those of every method the user touched).
  [[nodiscard]] const std::map<std::string, std::map<std::string, std::string>>& allParams() const { return params_; }
  void setAllParams(std::map<std::string, std::map<std::string, std::string>> params);
  [[nodiscard]] mfr::RenderRequest renderRequest(QSize size) const;

  // RenderView reports each frame (or why it could not draw one).
  void reportFrame(const mfr::Stats& stats);
  void reportRenderError(const QString& message);
  [[nodiscard]] const QString& renderError() const { return renderError_; }
  [[nodiscard]] quint64 framesRendered() const { return framesRendered_; }

  // The oracle's image of the current scene, view, size and request, or nullptr while it is
  // being computed (oracleImageReady follows). Computed off the GUI thread.
  const QImage* oracleImage();
  [[nodiscard]] const mfr::Stats& oracleStats() const { return oracleStats_; }
  // The last oracle image computed, whatever view it shows (drawn while a new one is computed).
  [[nodiscard]] const QImage& lastOracleImage() const { return oracleImage_; }
  // True while any background job runs (loading, oracle image, depth complexity).
  [[nodiscard]] bool busy() const { return loading_ || oracleRunning_ || depthRunning_; }

 signals:
  void loadStarted(const QString& path);
  void sceneLoaded();  // followed by sceneChanged
  void loadFailed(const QString& path, const QString& message);
  void loadCancelled();
  void operationChanged(const QString& operation);
  void oracleImageReady();
  void renderErrorChanged(const QString& message);

 private:
  void sceneEdited();
  void updateSceneGeometry();
  void startDepthComplexity();

  mfr::Scene scene_;
  bool hasScene_ = false;
  QString scenePath_;
  quint64 sceneRevision_ = 0;
  mfr::Bounds bounds_;
  double radius_ = 0.0;

  mfr::Camera camera_;
  QSize renderSize_{1, 1};
  quint64 viewRevision_ = 0;

  QString method_ = QStringLiteral("abuffer-ll");
  QString operation_ = QStringLiteral("oit");
  std::map<std::string, std::map<std::string, std::string>> params_;

  mfr::Stats stats_;
  QString renderError_;
  quint64 framesRendered_ = 0;

  bool loading_ = false;
  quint64 loadGeneration_ = 0;

  // Oracle image cache, keyed by what determines it.
  struct OracleKey {
    quint64 scene = 0, view = 0;
    QSize size;
    std::string request;
    bool operator==(const OracleKey&) const = default;
  };
  [[nodiscard]] OracleKey currentOracleKey() const;
  std::optional<OracleKey> oracleKey_;    // of oracleImage_
  std::optional<OracleKey> oracleWanted_; // being computed
  bool oracleRunning_ = false;
  QImage oracleImage_;
  mfr::Stats oracleStats_;

  bool depthRunning_ = false;
  bool depthPending_ = false;
};
