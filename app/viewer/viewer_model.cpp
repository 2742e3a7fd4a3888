#include "viewer_model.hpp"

#include <QFutureWatcher>
#include <QtConcurrent/QtConcurrentRun>

#include <algorithm>
#include <cmath>
#include <exception>
#include <variant>

#include "mfr/error.hpp"
#include "mfr/io/load.hpp"
#include "mfr/methods/registry.hpp"
#include "mfr/reference/composite.hpp"
#include "mfr/reference/oracle.hpp"

namespace {

// Runs `work` on the global thread pool and `done` with its result on the receiver's thread.
template <class Result, class Work, class Done>
void runInBackground(QObject* receiver, Work work, Done done) {
  auto* watcher = new QFutureWatcher<Result>(receiver);
  QObject::connect(watcher, &QFutureWatcher<Result>::finished, receiver, [watcher, done] {
    done(watcher->result());
    watcher->deleteLater();
  });
  watcher->setFuture(QtConcurrent::run(std::move(work)));
}

// The depth-complexity histogram is about the shape of the data, not the resolution: above this
// many pixels it is computed on a proportionally smaller image, so it stays interactive.
constexpr int kMaxDepthComplexityPixels = 320 * 240;

}  // namespace

ViewerModel::ViewerModel(QObject* parent) : ViewerContext(parent) {}

ViewerModel::~ViewerModel() = default;

QStringList ViewerModel::methodNames() const {
  QStringList names;
  for (const std::string& m : mfr::availableMethods()) names << QString::fromStdString(m);
  return names;
}

const mfr::MethodInfo* ViewerModel::methodInfo(const QString& method) const {
  // One instance per method, only for its (static) description; creating a method allocates no
  // GL objects until configure().
  static std::map<std::string, std::unique_ptr<mfr::Method>> described;
  const std::string name = method.toStdString();
  auto it = described.find(name);
  if (it == described.end()) {
    for (const mfr::RegistryEntry& e : mfr::methodRegistry())
      if (e.name == name) it = described.emplace(name, e.create()).first;
    if (it == described.end()) return nullptr;
  }
  return &it->second->info();
}

void ViewerModel::setMethod(const QString& method) {
  if (method == method_) return;
  method_ = method;
  emit methodChanged(method_);
}

std::map<std::string, std::string> ViewerModel::params() const {
  const auto it = params_.find(method_.toStdString());
  return it == params_.end() ? std::map<std::string, std::string>{} : it->second;
}

void ViewerModel::setParams(const std::map<std::string, std::string>& changes) {
  auto& current = params_[method_.toStdString()];
  bool changed = false;
  for (const auto& [name, value] : changes) {
    auto [it, inserted] = current.try_emplace(name, value);
    if (!inserted && it->second == value) continue;
    it->second = value;
    changed = true;
  }
  if (changed) emit paramsChanged();
}

void ViewerModel::setAllParams(std::map<std::string, std::map<std::string, std::string>> params) {
  params_ = std::move(params);
  emit paramsChanged();
}

void ViewerModel::setOperation(const QString& operation) {
  if (operation == operation_) return;
  operation_ = operation;
  emit operationChanged(operation_);
}

mfr::RenderRequest ViewerModel::renderRequest(QSize size) const {
  mfr::RenderRequest request;
  request.method = method_.toStdString();
  request.operation = operation_.toStdString();
  request.width = size.width();
  request.height = size.height();
  request.params = params();
  return request;
}

// ---- scene -------------------------------------------------------------------------------

void ViewerModel::loadSceneAsync(const QString& path) {
  const quint64 generation = ++loadGeneration_;
  loading_ = true;
  emit loadStarted(path);
  using Loaded = std::variant<mfr::Scene, QString>;
  runInBackground<Loaded>(
      this,
      [path]() -> Loaded {
        try {
          return mfr::loadScene(path.toStdString());
        } catch (const std::exception& e) {
          return QString::fromUtf8(e.what());
        }
      },
      [this, path, generation](Loaded loaded) {
        if (generation != loadGeneration_) return;  // cancelled, or superseded by a newer load
        loading_ = false;
        if (auto* message = std::get_if<QString>(&loaded)) {
          emit loadFailed(path, *message);
          return;
        }
        mfr::Scene& scene = std::get<mfr::Scene>(loaded);
        try {
          scene.validate();
        } catch (const std::exception& e) {
          emit loadFailed(path, QString::fromUtf8(e.what()));
          return;
        }
        setScene(std::move(scene), path);
      });
}

void ViewerModel::cancelLoad() {
  if (!loading_) return;
  // The loaders cannot be interrupted; the worker finishes and its result is dropped.
  ++loadGeneration_;
  loading_ = false;
  emit loadCancelled();
}

void ViewerModel::setScene(mfr::Scene scene, const QString& path) {
  scene_ = std::move(scene);
  scenePath_ = path;
  hasScene_ = true;
  ++sceneRevision_;
  updateSceneGeometry();
  camera_ = scene_.views.empty() ? scene_.view("fit") : scene_.views.front().camera;
  ++viewRevision_;
  emit sceneLoaded();
  emit sceneChanged();
  emit viewChanged();
}

void ViewerModel::updateSceneGeometry() {
  bounds_ = scene_.bounds();
  radius_ = bounds_.valid() ? scene_.boundingRadius() : 0.0;
}

void ViewerModel::sceneEdited() {
  ++sceneRevision_;
  emit sceneChanged();
}

void ViewerModel::setObjectVisible(int index, bool visible) {
  if (index < 0 || index >= static_cast<int>(scene_.objects.size())) return;
  mfr::Object& object = scene_.objects[static_cast<std::size_t>(index)];
  if (object.visible == visible) return;
  object.visible = visible;
  updateSceneGeometry();
  sceneEdited();
}

void ViewerModel::setObjectColor(int index, const QColor& rgb) {
  if (index < 0 || index >= static_cast<int>(scene_.objects.size())) return;
  glm::vec4& c = scene_.objects[static_cast<std::size_t>(index)].material.color;
  c = glm::vec4(static_cast<float>(rgb.redF()), static_cast<float>(rgb.greenF()), static_cast<float>(rgb.blueF()), c.a);
  sceneEdited();
}

void ViewerModel::setObjectOpacity(int index, double opacity) {
  if (index < 0 || index >= static_cast<int>(scene_.objects.size())) return;
  scene_.objects[static_cast<std::size_t>(index)].material.color.a = static_cast<float>(std::clamp(opacity, 0.0, 1.0));
  sceneEdited();
}

void ViewerModel::setObjectMaterial(int index, const glm::vec4& rgba) {
  if (index < 0 || index >= static_cast<int>(scene_.objects.size())) return;
  glm::vec4& c = scene_.objects[static_cast<std::size_t>(index)].material.color;
  if (c == rgba) return;
  c = rgba;
  sceneEdited();
}

// ---- camera ------------------------------------------------------------------------------

void ViewerModel::setCamera(const mfr::Camera& camera) {
  camera_ = camera;
  if (bounds_.valid()) camera_.fitDepthRange(bounds_, radius_);
  ++viewRevision_;
  emit viewChanged();
}

void ViewerModel::setRenderSize(QSize size) {
  size = size.expandedTo(QSize(1, 1));
  if (size == renderSize_) return;
  renderSize_ = size;
  ++viewRevision_;
  emit viewChanged();
}

// ---- frames ------------------------------------------------------------------------------

void ViewerModel::reportFrame(const mfr::Stats& stats) {
  stats_ = stats;
  ++framesRendered_;
  if (!renderError_.isEmpty()) {
    renderError_.clear();
    emit renderErrorChanged(renderError_);
  }
  emit frameRendered();
}

void ViewerModel::reportRenderError(const QString& message) {
  if (message == renderError_) return;
  renderError_ = message;
  emit renderErrorChanged(renderError_);
}

// ---- oracle ------------------------------------------------------------------------------

ViewerModel::OracleKey ViewerModel::currentOracleKey() const {
  std::string request = operation_.toStdString();
  for (const auto& [name, value] : params()) request += ";" + name + "=" + value;
  return {sceneRevision_, viewRevision_, renderSize_, request};
}

const QImage* ViewerModel::oracleImage() {
  const OracleKey key = currentOracleKey();
  if (oracleKey_ == key) return &oracleImage_;
  if (oracleRunning_) {
    oracleWanted_ = key;  // picked up when the running job finishes
    return nullptr;
  }
  oracleRunning_ = true;
  oracleWanted_ = key;
  struct Result {
    OracleKey key;
    mfr::RenderOutput output;
    QString error;
  };
  runInBackground<Result>(
      this,
      [scene = scene_, camera = camera_, request = renderRequest(renderSize_), key]() -> Result {
        Result r{key, {}, {}};
        try {
          r.output = mfr::render(scene, camera, request);
        } catch (const std::exception& e) {
          r.error = QString::fromUtf8(e.what());
        }
        return r;
      },
      [this](const Result& r) {
        oracleRunning_ = false;
        if (!r.error.isEmpty()) {
          reportRenderError(r.error);
        } else {
          const mfr::ImageRGBA8& img = r.output.image;
          oracleImage_ = QImage(img.pixels.data(), img.width, img.height, img.width * 4, QImage::Format_RGBA8888).copy();
          oracleStats_ = r.output.stats;
          oracleKey_ = r.key;
        }
        emit oracleImageReady();
      });
  return nullptr;
}

// ---- depth complexity ---------------------------------------------------------------------

void ViewerModel::requestDepthComplexity() {
  if (!hasScene_) return;
  if (depthRunning_) {
    depthPending_ = true;
    return;
  }
  startDepthComplexity();
}

void ViewerModel::startDepthComplexity() {
  depthRunning_ = true;
  depthPending_ = false;
  QSize size = renderSize_;
  const double pixels = static_cast<double>(size.width()) * size.height();
  if (pixels > kMaxDepthComplexityPixels) {
    const double s = std::sqrt(kMaxDepthComplexityPixels / pixels);
    size = QSize(std::max(1, static_cast<int>(size.width() * s)), std::max(1, static_cast<int>(size.height() * s)));
  }
  struct Result {
    QVector<quint64> histogram;
    QSize size;
  };
  runInBackground<Result>(
      this,
      [scene = scene_, camera = camera_, size]() -> Result {
        Result r{{}, size};
        try {
          const mfr::FragmentLists lists = mfr::castFragments(scene, camera, size.width(), size.height());
          for (std::uint64_t n : mfr::depthComplexityHistogram(lists)) r.histogram.push_back(n);
        } catch (const std::exception&) {
          // Nothing visible: an empty histogram says so.
        }
        return r;
      },
      [this](const Result& r) {
        depthRunning_ = false;
        emit depthComplexityReady(r.histogram, r.size);
        if (depthPending_) startDepthComplexity();
      });
}
