#include "viewer_model.hpp"

#include <QRegularExpression>

#include <QFutureWatcher>
#include <QMetaMethod>
#include <QTimer>
#include <QtConcurrent/QtConcurrentRun>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <map>

#include "mfr/error.hpp"
#include "mfr/io/load.hpp"
#include "mfr/scene/clip_box.hpp"
#include "mfr/methods/registry.hpp"
#include "mfr/reference/composite.hpp"
#include "mfr/reference/oracle.hpp"
#include "mfr/scene/color_map.hpp"
#include "mfr/scene/contour.hpp"
#include "mfr/scene/scene_file.hpp"

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
// CPU images kept (panes and references of the last few views).
constexpr std::size_t kCpuCacheSize = 6;
constexpr int kLoadPollMs = 40;

bool isGpuMethod(const std::string& name) {
  const auto& registry = mfr::methodRegistry();
  return std::any_of(registry.begin(), registry.end(), [&](const mfr::RegistryEntry& e) { return e.name == name; });
}

// Error maps of one pane against the reference (both the same size).
PaneMetrics computeMetrics(const mfr::ImageRGBA8& reference, const mfr::ImageRGBA8& image) {
  PaneMetrics m;
  m.rmse = mfr::rmse(reference, image);
  const mfr::FlipResult flip = mfr::flip(reference, image);
  m.flip = flip.stats;
  m.flipMap = mfr::magma(flip.errorMap);
  const mfr::ImageF difference = mfr::absoluteDifference(reference, image);
  for (float d : difference.data) m.maxDifference = std::max(m.maxDifference, d);
  // A zero scale would be no scale: identical images show as all-zero (black) at 1/255.
  m.differenceMap = mfr::heatmap(difference, std::max(m.maxDifference, 1.0f / 255.0f));
  m.valid = true;
  return m;
}

// Volume `current` of the scene read again with another field (`read`): its name, state and the
// scene's placement stay; the grid, its own placement (a .vdb grid's box and transform) and the
// default transfer are new.
mfr::Volume withField(const mfr::Volume& current, mfr::Volume read) {
  read.name = current.name;
  read.visible = current.visible;
  read.shading = current.shading;
  read.sceneTransform = current.sceneTransform;
  read.transform = current.sceneTransform * read.transform;
  read.transfer = mfr::defaultTransfer(*read.grid, read.bounds());
  return read;
}

}  // namespace

QImage wrapImage(const mfr::ImageRGBA8& image) {
  return QImage(image.pixels.data(), image.width, image.height, image.width * 4, QImage::Format_RGBA8888);
}

struct ViewerModel::LoadState {
  std::atomic<double> fraction{0.0};
  std::atomic<bool> cancel{false};
};

ViewerModel::ViewerModel(QObject* parent) : ViewerContext(parent) {
  loadPoll_ = new QTimer(this);
  loadPoll_->setInterval(kLoadPollMs);
  connect(loadPoll_, &QTimer::timeout, this, &ViewerModel::pollLoadProgress);
}

ViewerModel::~ViewerModel() {
  if (load_) load_->cancel = true;  // the worker stops at its next progress report
}

QStringList ViewerModel::methodNames() const {
  QStringList names;
  for (const std::string& m : mfr::availableMethods()) names << QString::fromStdString(m);
  return names;
}

const mfr::MethodInfo* ViewerModel::methodInfo(const QString& method) const {
  return mfr::findMethodInfo(method.toStdString());
}

bool ViewerModel::isCpuMethod(const QString& method) const {
  const std::string name = method.toStdString();
  const std::vector<std::string> all = mfr::availableMethods();
  return std::find(all.begin(), all.end(), name) != all.end() && !isGpuMethod(name);
}

void ViewerModel::setMethodOf(int side, const QString& method) {
  QString& current = methods_[index(side)];
  if (method == current) return;
  current = method;
  if (side == 0) emit methodChanged(current);
  emit sideChanged(side);
}

void ViewerModel::setOperationOf(int side, const QString& operation) {
  QString& current = operations_[index(side)];
  if (operation == current) return;
  current = operation;
  if (side == 0) emit operationChanged(current);
  emit sideChanged(side);
}

std::map<std::string, std::string> ViewerModel::paramsOf(int side) const {
  const ParamsByMethod& all = params_[index(side)];
  const auto it = all.find(methodOf(side).toStdString());
  return it == all.end() ? std::map<std::string, std::string>{} : it->second;
}

void ViewerModel::setParamsOf(int side, const std::map<std::string, std::string>& changes) {
  auto& current = params_[index(side)][methodOf(side).toStdString()];
  bool changed = false;
  for (const auto& [name, value] : changes) {
    auto [it, inserted] = current.try_emplace(name, value);
    if (!inserted && it->second == value) continue;
    it->second = value;
    changed = true;
  }
  if (!changed) return;
  if (side == 0) emit paramsChanged();
  emit sideChanged(side);
}

void ViewerModel::setAllParamsOf(int side, ParamsByMethod params) {
  params_[index(side)] = std::move(params);
  if (side == 0) emit paramsChanged();
  emit sideChanged(side);
}

mfr::RenderRequest ViewerModel::renderRequest(int side, QSize size) const {
  mfr::RenderRequest request;
  request.method = methodOf(side).toStdString();
  request.operation = operationOf(side).toStdString();
  request.width = size.width();
  request.height = size.height();
  request.params = paramsOf(side);
  request.thickness = thickness_;
  request.volumeStep = volumeStep_;
  return request;
}

void ViewerModel::setClipBox(const std::optional<mfr::Bounds>& box) {
  try {
    mfr::validateClipBox(box, "clip box");
  } catch (const mfr::Error&) {
    return;
  }
  const auto same = [](const std::optional<mfr::Bounds>& a, const std::optional<mfr::Bounds>& b) {
    return a.has_value() == b.has_value() && (!a || (a->min == b->min && a->max == b->max));
  };
  if (same(box, scene_.clipBox)) return;
  scene_.clipBox = box;
  sceneEdited();
}

void ViewerModel::setSection(const std::optional<mfr::SectionPlane>& section) {
  try {
    mfr::validateSectionPlane(section, "section plane");
  } catch (const mfr::Error&) {
    return;
  }
  if (section == scene_.section) return;
  scene_.section = section;
  sceneEdited();
}

void ViewerModel::setZThickness(double thickness) {
  if (!std::isfinite(thickness) || thickness < 0.0 || thickness == thickness_) return;
  thickness_ = thickness;
  emit zThicknessChanged(thickness_);
  // As the renderer resolves it: "auto" is zthickness for kbuffer-zmerge (review 28).
  for (int side = 0; side < kSides; ++side)
    if (effectiveOperationOf(side) == QLatin1String("zthickness")) emit sideChanged(side);
}

double ViewerModel::zThicknessDefault() const {
  return mfr::zThicknessOf(mfr::RenderRequest{}, bounds_);  // what the renderers make of thickness 0
}

bool ViewerModel::supportsOperation(const QString& method, const QString& operation) const {
  if (method == QLatin1String("oracle")) return true;
  const mfr::MethodInfo* info = methodInfo(method);
  if (!info) return false;
  if (operation == QLatin1String("auto")) return true;
  if (isCpuMethod(method)) return operation.toStdString() == info->preferredOperation;  // optimal-k: hybrid
  // A method whose own operation is not a list operation on fragments (kbuffer-zmerge keeps merged
  // z-thickness segments) runs that one only.
  if (info->preferredOperation == "zthickness" && !info->sortedLists) return operation == QLatin1String("zthickness");
  if (operation == QLatin1String("oit")) return true;
  if (operation == QLatin1String("csg")) return info->objectPayload;
  if (operation == QLatin1String("hybrid")) {
    // The k-buffer family's tail (with its parameter "tail" on).
    return info->preferredOperation == "hybrid" ||
           std::any_of(info->params.begin(), info->params.end(),
                       [](const mfr::ParamSpec& p) { return p.name == "tail"; });
  }
  // The list operations: every method whose resolve hands each pixel's sorted list to the
  // operation; the peeling methods composite while they peel and WBOIT / MBOIT keep no lists.
  if (operation == QLatin1String("zthickness") || operation == QLatin1String("volume")) return info->sortedLists;
  return false;
}

QString ViewerModel::resolvedOperation(int side, const QString& operation) const {
  const QString method = methodOf(side);
  return QString::fromStdString(
      mfr::effectiveOperation(operation.toStdString(), method == QLatin1String("oracle") ? nullptr : methodInfo(method),
                              scene_.hasVisibleVolume()));
}

// ---- volume --------------------------------------------------------------------------------

int ViewerModel::volumeIndex() const {
  if (!hasScene_ || scene_.volumes.empty()) return -1;
  return std::clamp(currentVolume_, 0, static_cast<int>(scene_.volumes.size()) - 1);
}

int ViewerModel::volumeCount() const {
  return hasScene_ ? static_cast<int>(scene_.volumes.size()) : 0;
}

int ViewerModel::visibleVolumeCount() const {
  return hasScene_ ? static_cast<int>(std::count_if(scene_.volumes.begin(), scene_.volumes.end(),
                                                    [](const mfr::Volume& v) { return v.visible; }))
                   : 0;
}

QStringList ViewerModel::volumeNames() const {
  QStringList names;
  if (hasScene_)
    for (const mfr::Volume& v : scene_.volumes) names << QString::fromStdString(v.name);
  return names;
}

void ViewerModel::setCurrentVolume(int index) {
  if (!hasScene_ || index < 0 || index >= static_cast<int>(scene_.volumes.size()) || index == currentVolume_) return;
  currentVolume_ = index;
  emit volumeChanged();  // the panel now shows this volume; nothing is drawn differently
}

QStringList ViewerModel::volumeFields() const {
  QStringList fields;
  if (const int i = volumeIndex(); i >= 0)
    for (const std::string& f : scene_.volumes[static_cast<std::size_t>(i)].fields) fields << QString::fromStdString(f);
  return fields;
}

QString ViewerModel::volumeField() const {
  const int i = volumeIndex();
  return i < 0 ? QString() : QString::fromStdString(scene_.volumes[static_cast<std::size_t>(i)].field);
}

void ViewerModel::setVolumeField(const QString& field) {
  setVolumeFieldAt(volumeIndex(), field);
}

void ViewerModel::setVolumeFieldAt(int index, const QString& field,
                                   const std::optional<mfr::TransferFunction>& transfer) {
  if (!hasScene_ || index < 0 || index >= static_cast<int>(scene_.volumes.size()) || field.isEmpty()) return;
  const mfr::Volume& volume = scene_.volumes[static_cast<std::size_t>(index)];
  if (volume.file.empty() || field.toStdString() == volume.field) return;
  if (fieldLoad_) fieldLoad_->cancel = true;  // superseded
  auto state = std::make_shared<LoadState>();
  fieldLoad_ = state;
  fieldError_.clear();
  emit volumeChanged();
  struct Read {
    std::optional<mfr::Volume> volume;
    QString error;
  };
  runInBackground<Read>(
      this,
      [file = volume.file, name = field.toStdString(), state]() -> Read {
        Read read;
        const mfr::LoadProgress progress{[state](double) { return !state->cancel; }};
        try {
          read.volume = mfr::loadVolume(file, mfr::LoadOptions(name), progress);
        } catch (const mfr::LoadCancelled&) {
          read.error = tr("reading stopped");
        } catch (const std::exception& e) {
          read.error = QString::fromUtf8(e.what());
        }
        return read;
      },
      [this, index, state, transfer](Read read) {
        if (state != fieldLoad_) return;  // superseded by another read, or by a new scene (setScene)
        fieldLoad_.reset();
        if (!read.volume) {
          fieldError_ = read.error;
          emit volumeChanged();
          return;
        }
        mfr::Volume& current = scene_.volumes[static_cast<std::size_t>(index)];
        mfr::Volume next = withField(current, std::move(*read.volume));
        loadedTransfers_[static_cast<std::size_t>(index)] = next.transfer;
        volumeRanges_[static_cast<std::size_t>(index)] = glm::dvec2(next.grid->range());
        if (transfer) {
          try {
            transfer->validate("transfer function");
            next.transfer = *transfer;
          } catch (const std::exception&) {
            // keeps the default
          }
        }
        current = std::move(next);
        // Its isosurfaces are made again from the new samples, at the values still inside their range.
        if (IsosurfaceSet& set = isosurfaces_[static_cast<std::size_t>(index)]; !set.values.empty()) {
          const glm::dvec2 range = volumeRanges_[static_cast<std::size_t>(index)];
          std::vector<double> values;
          for (const double v : set.values)
            if (v > range.x && v < range.y) values.push_back(v);
          const double opacity = set.opacity;
          set = {};
          set.opacity = opacity;
          const bool shown = current.visible;
          if (values.empty() || !setIsosurfacesAt(index, values, opacity).isEmpty()) spliceIsosurfaces();
          if (shown) showVolume(index, true);  // making them hides the volume; it was shown
        }
        updateSceneGeometry();
        resampleVolumeFields();
        volumeEdited();
      });
}

void ViewerModel::resampleVolumeFields() {
  // The parts as loaded, without their "@" fields, sampled again (mfr::addVolumeFields).
  mfr::Scene parts;
  parts.volumes = scene_.volumes;
  for (std::size_t i = 0; i < loadedMeshes_.size() && i < scene_.objects.size(); ++i) {
    mfr::Object o;
    o.transform = scene_.objects[i].transform;
    if (loadedMeshes_[i]) {
      auto mesh = std::make_shared<mfr::Mesh>(*loadedMeshes_[i]);
      std::erase_if(mesh->fields, [](const mfr::MeshField& f) { return !f.name.empty() && f.name.front() == '@'; });
      o.mesh = std::move(mesh);
    }
    parts.objects.push_back(std::move(o));
  }
  mfr::addVolumeFields(parts);
  for (std::size_t i = 0; i < parts.objects.size(); ++i) loadedMeshes_[i] = parts.objects[i].mesh;
  // A surface shown by a volume's field shows its new values, over the same range and map.
  if (const std::optional<mfr::FieldColors> shown = fieldColoring(); shown && shown->field.starts_with('@'))
    setFieldColoring(QString::fromStdString(shown->field), QString::fromStdString(shown->map), shown->range);
}

QString ViewerModel::volumeName() const {
  const int i = volumeIndex();
  return i < 0 ? QString() : QString::fromStdString(scene_.volumes[static_cast<std::size_t>(i)].name);
}

glm::ivec3 ViewerModel::volumeDims() const {
  const int i = volumeIndex();
  if (i < 0) return glm::ivec3(0);
  const auto& grid = scene_.volumes[static_cast<std::size_t>(i)].grid;
  return grid ? grid->dims : glm::ivec3(0);
}

glm::dvec3 ViewerModel::volumeSpacing() const {
  const int i = volumeIndex();
  return i < 0 ? glm::dvec3(0.0) : scene_.volumes[static_cast<std::size_t>(i)].spacing;
}

mfr::Bounds ViewerModel::volumeBounds() const {
  const int i = volumeIndex();
  return i < 0 ? mfr::Bounds{} : scene_.volumes[static_cast<std::size_t>(i)].bounds();
}

glm::dvec2 ViewerModel::volumeValueRange() const {
  const int i = volumeIndex();
  return i < 0 || static_cast<std::size_t>(i) >= volumeRanges_.size() ? glm::dvec2(0.0)
                                                                      : volumeRanges_[static_cast<std::size_t>(i)];
}

std::vector<std::uint64_t> ViewerModel::volumeHistogram(double low, double high, int bins) const {
  const int i = volumeIndex();
  if (i < 0 || bins < 1 || !std::isfinite(low) || !std::isfinite(high) || !(low < high)) return {};
  const auto& grid = scene_.volumes[static_cast<std::size_t>(i)].grid;
  if (!grid) return {};
  std::vector<std::uint64_t> counts(static_cast<std::size_t>(bins), 0);
  for (const float sample : grid->values) {
    const double v = sample;
    // NaN fails both comparisons; infinities fall outside any finite window.
    if (!(v >= low && v <= high)) continue;
    const int bin = std::min(static_cast<int>((v - low) / (high - low) * bins), bins - 1);
    ++counts[static_cast<std::size_t>(bin)];
  }
  return counts;
}

bool ViewerModel::volumeVisible() const {
  const int i = volumeIndex();
  return i >= 0 && scene_.volumes[static_cast<std::size_t>(i)].visible;
}

// ---- isosurfaces ---------------------------------------------------------------------------

std::vector<double> ViewerModel::isosurfaceValues() const {
  return isosurfaceValuesAt(volumeIndex());
}

double ViewerModel::isosurfaceOpacity() const {
  return isosurfaceOpacityAt(volumeIndex());
}

QString ViewerModel::setIsosurfaces(const std::vector<double>& values, double opacity) {
  return setIsosurfacesAt(volumeIndex(), values, opacity);
}

std::vector<double> ViewerModel::isosurfaceValuesAt(int index) const {
  if (index < 0 || index >= static_cast<int>(isosurfaces_.size())) return {};
  return isosurfaces_[static_cast<std::size_t>(index)].values;
}

double ViewerModel::isosurfaceOpacityAt(int index) const {
  if (index < 0 || index >= static_cast<int>(isosurfaces_.size())) return 0.5;
  return isosurfaces_[static_cast<std::size_t>(index)].opacity;
}

QString ViewerModel::setIsosurfacesAt(int index, const std::vector<double>& values, double opacity) {
  if (!hasScene_ || index < 0 || index >= static_cast<int>(scene_.volumes.size()) ||
      isosurfaces_.size() != scene_.volumes.size())
    return tr("the scene has no volume");
  IsosurfaceSet& set = isosurfaces_[static_cast<std::size_t>(index)];
  if (values == set.values && opacity == set.opacity) return {};
  IsosurfaceSet next;
  next.values = values;
  next.opacity = opacity;
  if (!values.empty()) {
    // Made on a scene of this volume alone, so that a refusal leaves scene_ as it is.
    mfr::Scene scratch;
    scratch.name = scene_.name;
    scratch.volumes = {scene_.volumes[static_cast<std::size_t>(index)]};
    try {
      mfr::addContours(scratch, {0, values, static_cast<float>(opacity)}, "isosurfaces");
    } catch (const std::exception& e) {
      return QString::fromUtf8(e.what());
    }
    // Nor one the scene file made ("contours"): two coincident parts of one name (hunt 32).
    for (const mfr::Object& part : scratch.objects)
      for (std::size_t i = 0; i < loadedPartCount_ && i < scene_.objects.size(); ++i)
        if (scene_.objects[i].name == part.name)
          return tr("scene '%1' has isosurface '%2' already")
              .arg(QString::fromStdString(scene_.name), QString::fromStdString(part.name));
    next.parts = std::move(scratch.objects);
  }
  set = std::move(next);
  spliceIsosurfaces();
  if (!values.empty() && scene_.volumes[static_cast<std::size_t>(index)].visible) {
    showVolume(index, false);  // ParaView hides a filter's input; the Volume panel shows it again
    updateSceneGeometry();
    volumeEdited();
  }
  return {};
}

void ViewerModel::spliceIsosurfaces() {
  const std::size_t base = loadedPartCount_;
  // A CSG tree over an isosurface part no longer knows its primitives.
  for (const std::uint32_t primitive : scene_.csg.primitives())
    if (primitive >= base) {
      scene_.csg = {};
      break;
    }
  // What the scene tree made of the parts before: a part made again with the same name and the same
  // material as before (its value, colour range and opacity unchanged) keeps its edited colour,
  // opacity and visibility.
  struct Edited {
    mfr::Material made, now;
    bool visible = true;
  };
  std::map<std::string, Edited> edited;
  for (std::size_t i = base; i < scene_.objects.size() && i < loadedMaterials_.size(); ++i)
    edited[scene_.objects[i].name] = {loadedMaterials_[i], scene_.objects[i].material, scene_.objects[i].visible};
  // A colouring by a field the user chose (Colour by: every part that has the field) covers the new
  // parts too, as mfr render --color-by does: the colouring of a part that differs from the one it
  // was loaded or made with. A scene file's colourings of its own parts stay theirs, and the new
  // parts are coloured by value, as mfr render --contour does (hunt 32: the first part's colouring
  // was laid on every part, another map on the second bearing and on the isosurfaces).
  const std::optional<mfr::FieldColors> chosen = chosenFieldColoring();
  scene_.objects.resize(base);
  loadedMaterials_.resize(base);
  loadedMeshes_.resize(base);
  for (const IsosurfaceSet& set : isosurfaces_)
    for (const mfr::Object& part : set.parts) scene_.objects.push_back(part);
  mfr::addVolumeFields(scene_);  // the other volumes' "@NAME" fields on the new parts
  QList<int> toColour;           // the new parts, and those made again that were coloured by a field
  for (std::size_t i = base; i < scene_.objects.size(); ++i) {
    mfr::Object& part = scene_.objects[i];
    loadedMaterials_.push_back(part.material);
    loadedMeshes_.push_back(part.mesh);
    const auto it = edited.find(part.name);
    bool colour = true;
    if (it != edited.end() && it->second.made.color == part.material.color) {
      part.material = it->second.now;
      colour = part.material.fieldColors.has_value();  // not over a colour of its own
      part.material.fieldColors.reset();               // laid on again below
      part.visible = it->second.visible;
    }
    if (colour) toColour << static_cast<int>(i);
  }
  updateSceneGeometry();
  emit partsChanged();
  // Only those: laid on every part, the colouring took back colours chosen for the others (hunt 33).
  if (!chosen || !colorPartsByField(*chosen, toColour)) sceneEdited();
}

std::optional<mfr::FieldColors> ViewerModel::chosenFieldColoring() const {
  for (std::size_t i = 0; i < scene_.objects.size() && i < loadedMaterials_.size(); ++i)
    if (const auto& now = scene_.objects[i].material.fieldColors; now && now != loadedMaterials_[i].fieldColors)
      return now;
  return std::nullopt;  // none laid on: as loaded, or the colouring taken off
}

bool ViewerModel::fieldColoringsAsLoaded() const {
  if (loadedMaterials_.size() != scene_.objects.size()) return false;
  for (std::size_t i = 0; i < scene_.objects.size(); ++i)
    if (scene_.objects[i].material.fieldColors != loadedMaterials_[i].fieldColors) return false;
  return true;
}

void ViewerModel::setVolumeVisible(bool visible) {
  setVolumeVisibleAt(volumeIndex(), visible);
}

void ViewerModel::showVolume(int index, bool visible) {
  auto& volumes = scene_.volumes;
  volumes[static_cast<std::size_t>(index)].visible = visible;
  if (!visible) return;
  // At most Scene::kMaxVisibleVolumes are drawn at once: showing one more hides the first other.
  std::size_t shown = 0;
  for (const mfr::Volume& v : volumes) shown += v.visible ? 1 : 0;
  for (std::size_t i = 0; i < volumes.size() && shown > mfr::Scene::kMaxVisibleVolumes; ++i)
    if (static_cast<int>(i) != index && volumes[i].visible) {
      volumes[i].visible = false;
      --shown;
    }
}

void ViewerModel::setVolumeVisibleAt(int index, bool visible) {
  if (index < 0 || index >= static_cast<int>(scene_.volumes.size())) return;
  if (scene_.volumes[static_cast<std::size_t>(index)].visible == visible) return;
  showVolume(index, visible);
  updateSceneGeometry();
  volumeEdited();
}

bool ViewerModel::volumeShading() const {
  const int i = volumeIndex();
  return i >= 0 && scene_.volumes[static_cast<std::size_t>(i)].shading;
}

void ViewerModel::setVolumeShading(bool shading) {
  const int i = volumeIndex();
  if (i < 0 || scene_.volumes[static_cast<std::size_t>(i)].shading == shading) return;
  scene_.volumes[static_cast<std::size_t>(i)].shading = shading;
  volumeEdited();
}

void ViewerModel::setVolumeStateAt(int index, bool visible, const mfr::TransferFunction& transfer, bool shading) {
  if (index < 0 || index >= static_cast<int>(scene_.volumes.size())) return;
  scene_.volumes[static_cast<std::size_t>(index)].shading = shading;
  try {
    transfer.validate("transfer function");
    scene_.volumes[static_cast<std::size_t>(index)].transfer = transfer;
  } catch (const std::exception&) {
    // keeps the loaded one
  }
  showVolume(index, visible);
  updateSceneGeometry();
  volumeEdited();
}

mfr::TransferFunction ViewerModel::transferFunction() const {
  const int i = volumeIndex();
  return i < 0 ? mfr::TransferFunction{} : scene_.volumes[static_cast<std::size_t>(i)].transfer;
}

mfr::TransferFunction ViewerModel::loadedTransferFunction() const {
  const int i = volumeIndex();
  return i < 0 || static_cast<std::size_t>(i) >= loadedTransfers_.size()
             ? mfr::TransferFunction{}
             : loadedTransfers_[static_cast<std::size_t>(i)];
}

namespace {
bool sameTransfer(const mfr::TransferFunction& a, const mfr::TransferFunction& b) {
  if (a.unitDistance != b.unitDistance || a.points.size() != b.points.size()) return false;
  for (std::size_t i = 0; i < a.points.size(); ++i)
    if (a.points[i].value != b.points[i].value || a.points[i].color != b.points[i].color) return false;
  return true;
}
}  // namespace

QString ViewerModel::setTransferFunction(const mfr::TransferFunction& transfer) {
  const int i = volumeIndex();
  if (i < 0) return tr("the scene has no volume");
  try {
    transfer.validate("transfer function");
  } catch (const std::exception& e) {
    // "transfer function: <reason>", one line.
    return QString::fromUtf8(e.what()).split(QLatin1Char('\n')).front();
  }
  mfr::TransferFunction& current = scene_.volumes[static_cast<std::size_t>(i)].transfer;
  if (sameTransfer(current, transfer)) return {};
  current = transfer;
  volumeEdited();
  return {};
}

QStringList ViewerModel::transferPresetNames() const {
  QStringList names;
  for (const std::string& name : mfr::transferPresetNames()) names << QString::fromStdString(name);
  return names;
}

mfr::TransferFunction ViewerModel::transferPreset(const QString& name, double low, double high,
                                                  double unitDistance) const {
  try {
    return mfr::transferPreset(name.toStdString(), low, high, unitDistance);
  } catch (const std::exception&) {
    return {};
  }
}

std::vector<glm::vec4> ViewerModel::transferTable(const mfr::TransferFunction& transfer) const {
  try {
    transfer.validate("transfer function");
    return transfer.table();
  } catch (const std::exception&) {
    return {};
  }
}

void ViewerModel::setVolumeStep(double step) {
  if (!std::isfinite(step) || step < 0.0 || step == volumeStep_) return;
  volumeStep_ = step;
  emit volumeChanged();
  for (int side = 0; side < kSides; ++side)
    if (effectiveOperationOf(side) == QLatin1String("volume")) emit sideChanged(side);
}

double ViewerModel::volumeStepDefault() const {
  const int i = volumeIndex();
  if (i < 0) return 0.0;
  // What the renderers use for the volumes drawn (a request without a step of its own).
  const std::vector<mfr::Volume> drawn = scene_.visibleVolumes();
  return drawn.empty() ? scene_.volumes[static_cast<std::size_t>(i)].defaultStep()
                       : mfr::volumeStepOf(mfr::RenderRequest{}, drawn);
}

void ViewerModel::volumeEdited() {
  sceneEdited();
  emit volumeChanged();
  // "auto" may now resolve to another operation: the method panels show it.
  for (int side = 0; side < kSides; ++side) emit sideChanged(side);
}

// ---- compare mode and data views ----------------------------------------------------------

void ViewerModel::setCompareEnabled(bool enabled) {
  if (enabled == compare_) return;
  const QSize pane = paneSize();
  compare_ = enabled;
  if (!compare_) {
    cpuWanted_.erase(CpuSlot::Pane1);
    frameImage_[1].reset();
  }
  emit compareChanged();
  // Side by side the image the statistics describe is half the view: a change of image size
  // (the budget panel's histogram kept the whole view's until the camera moved: a bug hunt).
  if (paneSize() != pane) {
    ++viewRevision_;
    emit viewChanged();
  }
}

void ViewerModel::setCompareLayout(CompareLayout layout) {
  if (layout == layout_) return;
  const QSize pane = paneSize();
  layout_ = layout;
  emit compareChanged();
  if (paneSize() != pane) {
    ++viewRevision_;
    emit viewChanged();
  }
}

void ViewerModel::setCompareSplit(double split) {
  split = std::clamp(split, 0.0, 1.0);
  if (split == split_) return;
  split_ = split;
  emit compareChanged();
}

void ViewerModel::setCompareDisplay(CompareDisplay display) {
  if (display == display_) return;
  display_ = display;
  emit compareChanged();
}

QSize ViewerModel::paneSize() const {
  if (compare_ && layout_ == CompareLayout::SideBySide)
    return {std::max(1, renderSize_.width() / 2), renderSize_.height()};
  return renderSize_;
}

void ViewerModel::setDataView(DataView view, bool overImage) {
  if (view == dataView_ && overImage == dataOverImage_) return;
  dataView_ = view;
  dataOverImage_ = overImage;
  emit dataViewChanged();
}

// ---- scene -------------------------------------------------------------------------------

bool ViewerModel::setMoleculeStyle(const mfr::MoleculeStyle& style) {
  if (!moleculeStyle_ || !style.any()) return false;
  // Not while another file or session is read: this re-read superseded it, so the file asked for
  // never came and a session waiting for it was applied to this scene (a bug hunt). A re-read of
  // these representations in flight is superseded, so that quick clicks add up.
  if (loading_ && !requestedMoleculeStyle_) return false;
  // Compared with what was asked last: a change undone before its read ends is a read of its own.
  if (style == requestedMoleculeStyle_.value_or(*moleculeStyle_)) return true;
  loadSceneAsync(scenePath_, {}, style);
  keepView_ = true;
  requestedMoleculeStyle_ = style;
  return true;
}

std::vector<int> matchByName(const QStringList& entries, const QStringList& names, bool unnamedByIndex) {
  std::vector<int> match;
  // The indices of each name, in order: a scan of every name per entry made a session of 16,000
  // parts take 0.7 s here alone (a bug hunt).
  std::map<QString, std::vector<int>> indicesOf;
  for (int i = 0; i < names.size(); ++i) indicesOf[names[i]].push_back(i);
  std::map<QString, std::size_t> seen;  // entries of each name so far
  for (const QString& entry : entries) {
    const std::size_t nth = seen[entry]++;
    int index = -1;
    if (!(unnamedByIndex && entry.isEmpty()))
      if (const auto it = indicesOf.find(entry); it != indicesOf.end() && nth < it->second.size())
        index = it->second[nth];
    match.push_back(index);
  }
  if (unnamedByIndex) {
    std::vector<bool> taken(static_cast<std::size_t>(names.size()), false);
    for (int index : match)
      if (index >= 0) taken[static_cast<std::size_t>(index)] = true;
    for (int e = 0; e < entries.size(); ++e)
      if (entries[e].isEmpty() && e < names.size() && !taken[static_cast<std::size_t>(e)])
        match[static_cast<std::size_t>(e)] = e;
  }
  return match;
}

void ViewerModel::loadSceneAsync(const QString& path, const QString& field,
                                 const std::optional<mfr::MoleculeStyle>& molecule,
                                 const QList<QPair<QString, QString>>& volumeFields) {
  keepView_ = false;
  requestedMoleculeStyle_.reset();
  if (load_) {
    load_->cancel = true;  // superseded: stop the previous worker early
    ++abandonedLoads_;
  }
  auto state = std::make_shared<LoadState>();
  load_ = state;
  loading_ = true;
  loadProgress_ = 0.0;
  emit loadStarted(path);
  emit loadProgressChanged(loadProgress_);
  loadPoll_->start();
  struct Loaded {
    std::optional<mfr::Scene> scene;
    QString error;
    bool stopped = false;     // LoadCancelled
    bool fieldsRead = false;  // a volume was read again with another field
    QMap<int, QString> fieldErrors;
  };
  runInBackground<Loaded>(
      this,
      [path, field, molecule, volumeFields, state]() -> Loaded {
        Loaded loaded;
        const mfr::LoadProgress progress{[state](double fraction) {
          state->fraction = fraction;
          return !state->cancel;
        }};
        try {
          // A volume file's field is read directly: a session of `x.vdb --field temperature` did not
          // open when x.vdb's default grid could not be read (a bug hunt). A field that cannot be
          // read is the session's note; the file is then read as it is.
          const bool direct = field.isEmpty() && volumeFields.size() == 1 && !volumeFields[0].second.isEmpty() &&
                              !path.startsWith('@') && mfr::isVolumeFile(path.toStdString());
          try {
            loaded.scene = mfr::loadScene(
                path.toStdString(), mfr::LoadOptions((direct ? volumeFields[0].second : field).toStdString(), molecule),
                progress);
          } catch (const mfr::LoadCancelled&) {
            throw;
          } catch (const mfr::Error& e) {
            if (!direct) throw;
            loaded.fieldErrors[0] = QString::fromUtf8(e.what());
            loaded.scene = mfr::loadScene(path.toStdString(), mfr::LoadOptions({}, molecule), progress);
          }
          // The fields asked for, read here rather than after the scene is shown: one read at a
          // time after it, each cancelling the last, left all but the last volume on its own field
          // under the transfer function of another, and isosurfaces, a clip box and the view were
          // checked against the fields as loaded (a bug hunt).
          std::vector<mfr::Volume>& volumes = loaded.scene->volumes;
          QStringList entries, names;
          for (const auto& [name, wanted] : volumeFields) entries << name;
          for (const mfr::Volume& v : volumes) names << QString::fromStdString(v.name);
          const std::vector<int> match = matchByName(entries, names, true);
          for (int entry = 0; entry < volumeFields.size(); ++entry) {
            const int i = match[static_cast<std::size_t>(entry)];
            if (i < 0) continue;  // the session says so (applySession)
            mfr::Volume& volume = volumes[static_cast<std::size_t>(i)];
            const std::string wanted = volumeFields[entry].second.toStdString();
            if (wanted.empty() || wanted == volume.field || volume.file.empty() ||
                std::find(volume.fields.begin(), volume.fields.end(), wanted) == volume.fields.end())
              continue;  // the session says why (applySession)
            try {
              volume = withField(volume, mfr::loadVolume(volume.file, mfr::LoadOptions(wanted), progress));
              loaded.fieldsRead = true;
            } catch (const mfr::LoadCancelled&) {
              throw;
            } catch (const std::exception& e) {
              loaded.fieldErrors[i] = QString::fromUtf8(e.what());
            }
          }
        } catch (const mfr::LoadCancelled&) {
          loaded.stopped = true;
        } catch (const std::exception& e) {
          loaded.error = QString::fromUtf8(e.what());
        }
        return loaded;
      },
      [this, path, molecule, state](Loaded loaded) {
        if (state != load_) {  // cancelled, or superseded by a newer load
          --abandonedLoads_;
          lastCancelStoppedLoader_ = loaded.stopped;
          return;
        }
        pollLoadProgress();    // the loader's last report
        if (state != load_) {  // a slot of that report cancelled the load: the model stayed busy for ever
          --abandonedLoads_;
          lastCancelStoppedLoader_ = false;
          return;
        }
        loadPoll_->stop();
        load_.reset();
        loading_ = false;
        if (!loaded.error.isEmpty() || !loaded.scene) {
          keepView_ = false;
          requestedMoleculeStyle_.reset();
          emit loadFailed(path, loaded.error.isEmpty() ? tr("loading stopped") : loaded.error);
          return;
        }
        try {
          loaded.scene->validate();
        } catch (const std::exception& e) {
          emit loadFailed(path, QString::fromUtf8(e.what()));
          return;
        }
        // A molecule read again in other representations keeps the view as it is now, not as it
        // was when the read began (an orbit meanwhile was undone), and the clip box, section,
        // z-thickness and colouring by a field, which were dropped as for another file (a bug hunt).
        struct KeptView {
          mfr::Camera camera;
          std::optional<mfr::Bounds> clip;
          std::optional<mfr::SectionPlane> section;
          double thickness = 0.0;
          std::optional<mfr::FieldColors> coloring;
        };
        std::optional<KeptView> kept;
        if (keepView_) kept = KeptView{camera_, scene_.clipBox, scene_.section, thickness_, fieldColoring()};
        keepView_ = false;
        requestedMoleculeStyle_.reset();
        moleculeStyle_.reset();
        if (!path.startsWith('@') && mfr::isMoleculeFile(path.toStdString()))
          moleculeStyle_ = molecule.value_or(mfr::MoleculeStyle{});
        setScene(std::move(*loaded.scene), path, [&] {
          volumeFieldReadErrors_ = loaded.fieldErrors;
          // The parts' "@" fields sampled from the fields read (as after the Field chooser's read).
          if (loaded.fieldsRead) resampleVolumeFields();
        });
        if (kept) {
          setCamera(kept->camera);
          if (kept->clip) setClipBox(kept->clip);
          if (kept->section) setSection(kept->section);
          if (kept->thickness != 0.0) setZThickness(kept->thickness);
          if (kept->coloring && surfaceFields().contains(QString::fromStdString(kept->coloring->field)))
            setFieldColoring(QString::fromStdString(kept->coloring->field), QString::fromStdString(kept->coloring->map),
                             kept->coloring->range);
        }
      });
}

void ViewerModel::pollLoadProgress() {
  if (!load_) return;
  const double fraction = load_->fraction;
  if (fraction == loadProgress_) return;
  loadProgress_ = fraction;
  emit loadProgressChanged(loadProgress_);
}

void ViewerModel::cancelLoad() {
  if (!loading_ || !load_) return;
  load_->cancel = true;  // the loader throws LoadCancelled at its next report
  load_.reset();
  ++abandonedLoads_;
  loadPoll_->stop();
  loading_ = false;
  keepView_ = false;
  requestedMoleculeStyle_.reset();
  emit loadCancelled();
}

void ViewerModel::setScene(mfr::Scene scene, const QString& path, const std::function<void()>& prepare) {
  scene_ = std::move(scene);
  if (fieldLoad_) fieldLoad_->cancel = true;  // a field of the old scene's volume: its read is dropped
  fieldLoad_.reset();
  fieldError_.clear();
  loadedMaterials_.clear();
  loadedMeshes_.clear();
  for (const mfr::Object& o : scene_.objects) {
    loadedMaterials_.push_back(o.material);
    loadedMeshes_.push_back(o.mesh);
  }
  fieldColoringError_.clear();
  volumeFieldReadErrors_.clear();
  scenePath_ = path;
  const bool hadScene = hasScene_;
  hasScene_ = true;
  ++sceneRevision_;
  ++sceneSerial_;
  // A CPU method's last picture is of the old scene: shown "until the new one is ready", the view
  // drew the previous file for seconds under the new one's name (a bug hunt). Nothing until then.
  cpuLast_.clear();
  updateSceneGeometry(false);  // the camera is the new scene's fit view, below
  updateDrawnScene();
  // The z-thickness is a length in the old scene's units: the new one starts at its own default.
  if (thickness_ != 0.0) {
    thickness_ = 0.0;
    emit zThicknessChanged(thickness_);
  }
  // So is the volume step; the loaded transfer functions are what "As Loaded" brings back.
  volumeStep_ = 0.0;
  currentVolume_ = 0;
  for (std::size_t i = 0; i < scene_.volumes.size(); ++i)
    if (scene_.volumes[i].visible) {
      currentVolume_ = static_cast<int>(i);
      break;
    }
  loadedTransfers_.clear();
  volumeRanges_.clear();
  isosurfaces_.assign(scene_.volumes.size(), {});
  loadedPartCount_ = scene_.objects.size();
  for (const mfr::Volume& v : scene_.volumes) {
    loadedTransfers_.push_back(v.transfer);
    volumeRanges_.push_back(v.grid ? glm::dvec2(v.grid->range()) : glm::dvec2(0.0));
  }
  // The fit-all view, as mfr render's default: the first named view's direction and projection,
  // framing the whole scene. Its camera as written (a view without "fit": true) drew another
  // picture than mfr render's on the same scene (a bug hunt).
  camera_ = scene_.view("fit");
  ++viewRevision_;
  // An operation of the old scene that the new one cannot draw goes back to auto, with a note:
  // File → Open Sample after @csg with operation csg drew nothing but "operation csg: scene
  // 'sample' has no CSG tree" (a bug hunt). Not for the window's first scene: its --op is refused
  // as mfr render refuses it (scripted runs exit with it); a session sets its own after.
  std::vector<std::pair<int, QString>> dropped;  // side, "operation csg"
  if (hadScene)
    for (const int side : {0, 1}) {
      const QString operation = operations_[index(side)];
      const bool lacks = (operation == QLatin1String("csg") && scene_.csg.empty()) ||
                         (operation == QLatin1String("volume") && scene_.volumes.empty());
      if (!lacks) continue;
      dropped.emplace_back(
          side, (side == 0 ? QStringLiteral("operation %1") : QStringLiteral("compare operation %1")).arg(operation));
      setOperationOf(side, QStringLiteral("auto"));
    }
  if (prepare) prepare();
  emit sceneLoaded();
  // After sceneLoaded, whose handlers apply a session: only for a side the session left on auto.
  for (const auto& [side, what] : dropped)
    if (operations_[index(side)] == QLatin1String("auto"))
      note(QStringLiteral("%1: scene '%2' has no %3: auto is used")
               .arg(what, QString::fromStdString(scene_.name),
                    what.endsWith(QLatin1String("csg")) ? QStringLiteral("CSG tree") : QStringLiteral("volume")));
  emit sceneChanged();
  emit viewChanged();
  emit volumeChanged();
}

void ViewerModel::updateSceneGeometry(bool refitDepth) {
  const mfr::Bounds before = bounds_;
  bounds_ = scene_.bounds();
  radius_ = bounds_.valid() ? scene_.boundingRadius() : 0.0;
  // The near and far planes follow what is drawn: a volume or part shown, or a field read with a
  // box of its own, lay beyond the far plane fitted to the rest and drew clipped or not at all
  // until the camera moved (a bug hunt).
  if (refitDepth && hasScene_ && !camera_.depthRangeGiven && bounds_.valid() &&
      (before.min != bounds_.min || before.max != bounds_.max)) {
    camera_.fitDepthRange(bounds_, radius_);
    ++viewRevision_;
    emit viewChanged();
  }
}

void ViewerModel::sceneEdited() {
  ++sceneRevision_;
  updateDrawnScene();
  emit sceneChanged();
}

void ViewerModel::updateDrawnScene() {
  drawn_ = {};
  sectionReport_ = {};
  sectionError_.clear();
  if (!scene_.section) return;
  try {
    drawn_ = mfr::sectionedScene(scene_, &sectionReport_);
  } catch (const std::exception& e) {
    sectionError_ = QString::fromUtf8(e.what());
  }
}

QStringList ViewerModel::objectNames() const {
  QStringList names;
  for (const mfr::Object& o : scene_.objects) names << QString::fromStdString(o.name);
  return names;
}

QString ViewerModel::csgTree() const {
  return QString::fromStdString(mfr::csgText(scene_.csg, scene_));
}

QString ViewerModel::setCsgTree(const QString& json) {
  if (!hasScene_) return tr("no scene loaded");
  try {
    mfr::CsgTree tree = mfr::parseCsgText(json.toStdString(), scene_);
    if (mfr::csgText(tree, scene_) == mfr::csgText(scene_.csg, scene_)) return {};
    scene_.csg = std::move(tree);
  } catch (const std::exception& e) {
    return QString::fromUtf8(e.what());
  }
  sceneEdited();
  return {};
}

void ViewerModel::setObjectVisible(int index, bool visible) {
  setObjectVisibilities({{index, visible}});
}

void ViewerModel::setObjectVisibilities(const QMap<int, bool>& visible) {
  bool changed = false;
  for (auto it = visible.begin(); it != visible.end(); ++it) {
    if (it.key() < 0 || it.key() >= static_cast<int>(scene_.objects.size())) continue;
    mfr::Object& object = scene_.objects[static_cast<std::size_t>(it.key())];
    if (object.visible == it.value()) continue;
    object.visible = it.value();
    changed = true;
  }
  if (!changed) return;
  updateSceneGeometry();
  sceneEdited();
}

void ViewerModel::setObjectColor(int index, const QColor& rgb) {
  setObjectColors({index}, rgb);
}

void ViewerModel::setObjectColors(const QList<int>& indices, const QColor& rgb) {
  bool changed = false;
  for (const int index : indices) {
    if (index < 0 || index >= static_cast<int>(scene_.objects.size())) continue;
    mfr::Material& material = scene_.objects[static_cast<std::size_t>(index)].material;
    glm::vec4& c = material.color;
    c = glm::vec4(static_cast<float>(rgb.redF()), static_cast<float>(rgb.greenF()), static_cast<float>(rgb.blueF()),
                  c.a);
    material.vertexColors = false;
    material.fieldColors.reset();  // a colour chosen for the part replaces its field's colours too
    changed = true;
  }
  if (changed) sceneEdited();
}

void ViewerModel::resetObjectColor(int index) {
  resetObjectColors({index});
}

void ViewerModel::resetObjectColors(const QList<int>& indices) {
  // Under a colouring by a field the parts had before a colour was chosen for them — the one chosen
  // in the Scene dock, else their own as loaded — that colouring comes back too: it stayed off, the
  // part in its file's plain colour beside the field-coloured others (hunt 33).
  const std::optional<mfr::FieldColors> chosen = chosenFieldColoring();
  bool changed = false;
  std::vector<std::pair<mfr::FieldColors, QList<int>>> recolour;  // by colouring: one edit each
  for (const int index : indices) {
    if (!objectColorEdited(index)) continue;
    const auto i = static_cast<std::size_t>(index);
    mfr::Material& material = scene_.objects[i].material;
    material.color = glm::vec4(glm::vec3(loadedMaterials_[i].color), material.color.a);
    material.vertexColors = loadedMaterials_[i].vertexColors;
    changed = true;
    const std::optional<mfr::FieldColors>& colouring = chosen ? chosen : loadedMaterials_[i].fieldColors;
    if (material.fieldColors || !colouring) continue;
    const auto group =
        std::find_if(recolour.begin(), recolour.end(), [&](const auto& g) { return g.first == *colouring; });
    if (group == recolour.end())
      recolour.push_back({*colouring, {index}});
    else
      group->second << index;
  }
  bool edited = false;  // colorPartsByField's own scene edit
  for (const auto& [colouring, parts] : recolour) edited = colorPartsByField(colouring, parts) || edited;
  if (changed && !edited) sceneEdited();
}

bool ViewerModel::objectColorEdited(int index) const {
  if (index < 0 || index >= static_cast<int>(scene_.objects.size()) || loadedMaterials_.size() != scene_.objects.size())
    return false;
  const auto i = static_cast<std::size_t>(index);
  const mfr::Material& now = scene_.objects[i].material;
  return glm::vec3(now.color) != glm::vec3(loadedMaterials_[i].color) ||
         now.vertexColors != loadedMaterials_[i].vertexColors;
}

double ViewerModel::objectOpacity(int index) const {
  if (index < 0 || index >= static_cast<int>(scene_.objects.size())) return -1.0;
  return scene_.objects[static_cast<std::size_t>(index)].material.color.a;
}

void ViewerModel::setObjectOpacity(int index, double opacity) {
  setObjectOpacities({{index, opacity}});
}

void ViewerModel::setObjectOpacities(const QMap<int, double>& opacities) {
  bool changed = false;
  for (auto it = opacities.begin(); it != opacities.end(); ++it) {
    if (it.key() < 0 || it.key() >= static_cast<int>(scene_.objects.size()) || std::isnan(it.value())) continue;
    float& alpha = scene_.objects[static_cast<std::size_t>(it.key())].material.color.a;
    const auto value = static_cast<float>(std::clamp(it.value(), 0.0, 1.0));
    if (alpha == value) continue;
    alpha = value;
    changed = true;
  }
  if (changed) sceneEdited();
}

double ViewerModel::loadedObjectOpacity(int index) const {
  if (index < 0 || index >= static_cast<int>(loadedMaterials_.size())) return -1.0;
  return loadedMaterials_[static_cast<std::size_t>(index)].color.a;
}

void ViewerModel::setObjectStates(const std::vector<ObjectState>& states) {
  bool changed = false, visibility = false;
  for (const ObjectState& state : states) {
    if (state.index < 0 || state.index >= static_cast<int>(scene_.objects.size())) continue;
    mfr::Object& object = scene_.objects[static_cast<std::size_t>(state.index)];
    if (object.visible != state.visible) {
      object.visible = state.visible;
      visibility = changed = true;
    }
    if (object.material.color != state.color || object.material.vertexColors != state.vertexColors) {
      object.material.color = state.color;
      object.material.vertexColors = state.vertexColors;
      changed = true;
    }
  }
  if (visibility) updateSceneGeometry();
  if (changed) sceneEdited();
}

std::vector<ViewerModel::PartLook> ViewerModel::partLooks(const QList<int>& indices) const {
  std::vector<PartLook> looks;
  looks.reserve(static_cast<std::size_t>(indices.size()));
  for (const int index : indices) {
    if (index < 0 || index >= static_cast<int>(scene_.objects.size())) continue;
    const mfr::Object& object = scene_.objects[static_cast<std::size_t>(index)];
    looks.push_back({index, object.visible, object.material});
  }
  return looks;
}

void ViewerModel::setPartLooks(const std::vector<PartLook>& looks) {
  bool changed = false, visibility = false;
  for (const PartLook& look : looks) {
    if (look.index < 0 || look.index >= static_cast<int>(scene_.objects.size())) continue;
    mfr::Object& object = scene_.objects[static_cast<std::size_t>(look.index)];
    if (PartLook{look.index, object.visible, object.material} == look) continue;
    visibility = visibility || object.visible != look.visible;
    object.visible = look.visible;
    object.material = look.material;
    changed = true;
  }
  if (visibility) updateSceneGeometry();
  if (changed) sceneEdited();
}

void ViewerModel::setObjectMaterial(int index, const glm::vec4& rgba, bool vertexColors) {
  if (index < 0 || index >= static_cast<int>(scene_.objects.size())) return;
  mfr::Material& material = scene_.objects[static_cast<std::size_t>(index)].material;
  if (material.color == rgba && material.vertexColors == vertexColors) return;
  material.color = rgba;
  material.vertexColors = vertexColors;
  sceneEdited();
}

// ---- field colours ------------------------------------------------------------------------

QStringList ViewerModel::surfaceFields() const {
  QStringList fields;
  for (const std::shared_ptr<const mfr::Mesh>& mesh : loadedMeshes_)
    if (mesh)
      for (const std::string& f : mfr::fieldNames(*mesh))
        if (!fields.contains(QString::fromStdString(f))) fields << QString::fromStdString(f);
  return fields;
}

std::optional<mfr::FieldColors> ViewerModel::fieldColoring() const {
  for (const mfr::Object& o : scene_.objects)
    if (o.material.fieldColors) return o.material.fieldColors;
  return std::nullopt;
}

std::optional<ViewerModel::ColorLegend> ViewerModel::colorLegend() const {
  if (std::optional<mfr::FieldColors> colors = fieldColoring()) return ColorLegend{std::move(*colors), {}};
  // The current volume's isosurfaces, else the first volume's that has some: --contour b=… on a
  // scene whose current volume is a had no legend, where mfr render draws b's (a bug hunt).
  int index = volumeIndex();
  for (int i = 0; isosurfaceValuesAt(index).empty() && i < static_cast<int>(scene_.volumes.size()); ++i) index = i;
  std::vector<double> values = isosurfaceValuesAt(index);
  if (values.empty()) return std::nullopt;
  const auto at = static_cast<std::size_t>(index);
  const glm::dvec2 range =
      mfr::contourColorRange(values, at < volumeRanges_.size() ? volumeRanges_[at] : glm::dvec2(0.0));
  return ColorLegend{mfr::FieldColors{scene_.volumes[at].name, "cool-warm", range}, std::move(values)};
}

glm::dvec2 ViewerModel::fieldDataRange(const QString& field) const {
  std::vector<const mfr::Mesh*> meshes;
  for (const std::shared_ptr<const mfr::Mesh>& mesh : loadedMeshes_) meshes.push_back(mesh.get());
  try {
    return mfr::sharedFieldRange(meshes, field.toStdString());
  } catch (const mfr::Error&) {
    return {0.0, 1.0};  // a component the array lacks
  }
}

bool ViewerModel::setFieldColoring(const QString& field, const QString& map, const std::optional<glm::dvec2>& range) {
  if (loadedMeshes_.size() != scene_.objects.size()) return false;
  std::vector<mfr::Object> parts = scene_.objects;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    parts[i].mesh = loadedMeshes_[i];
    parts[i].material.fieldColors.reset();
  }
  if (!field.isEmpty()) {
    std::vector<mfr::Object*> pointers;
    pointers.reserve(parts.size());
    for (mfr::Object& o : parts) pointers.push_back(&o);
    try {
      mfr::colorObjectsByField(pointers, field.toStdString(), map.toStdString(), range, scene_.name);
    } catch (const mfr::Error& e) {
      fieldColoringError_ = QString::fromUtf8(e.what());
      emit sceneChanged();  // panels show the refusal
      return false;
    }
  }
  fieldColoringError_.clear();
  for (std::size_t i = 0; i < parts.size(); ++i) {
    scene_.objects[i].mesh = parts[i].mesh;
    scene_.objects[i].material.fieldColors = parts[i].material.fieldColors;
  }
  sceneEdited();
  return true;
}

bool ViewerModel::colorPartsByField(const mfr::FieldColors& colors, const QList<int>& parts) {
  if (loadedMeshes_.size() != scene_.objects.size()) return false;
  std::vector<mfr::Object> chosen;
  std::vector<std::size_t> indices;
  for (const int index : parts) {
    if (index < 0 || index >= static_cast<int>(scene_.objects.size())) continue;
    const auto i = static_cast<std::size_t>(index);
    if (!loadedMeshes_[i]) continue;
    chosen.push_back(scene_.objects[i]);
    chosen.back().mesh = loadedMeshes_[i];
    chosen.back().material.fieldColors.reset();
    indices.push_back(i);
  }
  if (chosen.empty()) return false;
  std::vector<mfr::Object*> pointers;
  pointers.reserve(chosen.size());
  for (mfr::Object& o : chosen) pointers.push_back(&o);
  try {
    mfr::colorObjectsByField(pointers, colors.field, colors.map, colors.range, scene_.name);
  } catch (const std::exception&) {
    return false;  // none of them has the field
  }
  for (std::size_t k = 0; k < chosen.size(); ++k) {
    scene_.objects[indices[k]].mesh = chosen[k].mesh;
    scene_.objects[indices[k]].material.fieldColors = chosen[k].material.fieldColors;
  }
  sceneEdited();
  return true;
}

// ---- camera ------------------------------------------------------------------------------

void ViewerModel::setCamera(const mfr::Camera& camera) {
  camera_ = camera;
  // A view's given near and far planes are kept, as mfr render keeps them.
  if (bounds_.valid() && !camera_.depthRangeGiven) camera_.fitDepthRange(bounds_, radius_);
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

void ViewerModel::reportFrame(int side, const mfr::Stats& stats) {
  stats_[index(side)] = stats;
  ++framesRendered_;
  if (side == 0)
    emit frameRendered();
  else
    emit secondaryFrameRendered();
}

void ViewerModel::reportRenderError(const QString& message) {
  if (message == renderError_) return;
  renderError_ = message;
  emit renderErrorChanged(renderError_);
  emit frameErrorChanged();
}

QString ViewerModel::drawError() const {
  if (!drawError_ || drawError_->first != sceneRevision_) {
    QString why;
    try {
      const mfr::Scene& drawn = drawnScene();
      drawn.validate();  // every part hidden: that, not the box or plane, is the reason
      if (scene_.clipBox) mfr::requireClipBoxHoldsScene(scene_, *scene_.clipBox, "clip box");
      mfr::requireSomethingToDraw(drawn);
    } catch (const std::exception& e) {
      why = QString::fromUtf8(e.what());
    }
    drawError_ = std::pair{sceneRevision_, why};
  }
  return drawError_->second;
}

QString ViewerModel::renderErrorShown() const {
  // Anywhere in the text: compare mode's "B: --op …", and "use --op hybrid (or auto)".
  static const QRegularExpression op(QStringLiteral("--op (?=\\S)")), method(QStringLiteral("--method (?=\\S)"));
  QString shown = renderError_;
  shown.replace(op, QStringLiteral("operation "));
  shown.replace(method, QStringLiteral("method "));
  return shown.replace(QLatin1String("--param "), QString());
}

ImageKey ViewerModel::imageKey(const mfr::RenderRequest& request) const {
  // The operation as it resolves: an oracle pane's "auto" is its reference's "oit", and was computed
  // twice under two keys (a review).
  const mfr::MethodInfo* info = request.method == "oracle" ? nullptr : mfr::findMethodInfo(request.method);
  const std::string operation = mfr::effectiveOperation(request.operation, info, scene_.hasVisibleVolume());
  std::string text = request.method + ";" + operation;
  for (const auto& [name, value] : request.params) text += ";" + name + "=" + value;
  if (operation == "zthickness") text += ";thickness=" + QString::number(request.thickness, 'g', 17).toStdString();
  if (operation == "volume") text += ";step=" + QString::number(request.volumeStep, 'g', 17).toStdString();
  return {sceneRevision_, viewRevision_, QSize(request.width, request.height), text};
}

ImageKey ViewerModel::frameKey(int side) const {
  return imageKey(renderRequest(side, paneSize()));
}

mfr::RenderRequest ViewerModel::referenceRequest(int side) const {
  mfr::RenderRequest request;
  request.method = "oracle";
  // Exact "over" of every fragment, whatever the pane's transparency operation; the exact CSG
  // image for a pane showing CSG, the exact z-thickness image (same thickness) for one showing
  // zthickness, the exact volume image (same step, the current transfer function: the scene's) for
  // one showing volume — "auto" resolved, so a volume scene's "auto" is measured against the volume.
  const QString operation = effectiveOperationOf(side);
  request.operation = operation == QLatin1String("csg") || operation == QLatin1String("zthickness") ||
                              operation == QLatin1String("volume")
                          ? operation.toStdString()
                          : std::string("oit");
  request.thickness = thickness_;
  request.volumeStep = volumeStep_;
  request.width = paneSize().width();
  request.height = paneSize().height();
  return request;
}

// ---- CPU images --------------------------------------------------------------------------

const CpuImage* ViewerModel::cpuImage(CpuSlot slot, const mfr::RenderRequest& request) {
  const ImageKey key = imageKey(request);
  for (const auto& cached : cpuCache_) {
    if (cached->key == key) {
      cpuLast_[slot] = cached;
      return cached.get();
    }
  }
  cpuWanted_[slot] = {key, request};
  startCpuJob();
  return nullptr;
}

const CpuImage* ViewerModel::lastCpuImage(CpuSlot slot) const {
  const auto it = cpuLast_.find(slot);
  return it == cpuLast_.end() ? nullptr : it->second.get();
}

void ViewerModel::startCpuJob() {
  if (cpuRunning_) return;
  // Panes first (what is on screen), then the reference; wishes for an older scene or view are
  // dropped (whoever still needs them asks again).
  std::optional<CpuWish> next;
  while (!cpuWanted_.empty() && !next) {
    const auto it = cpuWanted_.begin();
    CpuWish wish = it->second;
    cpuWanted_.erase(it);
    const bool current = wish.key.scene == sceneRevision_ && wish.key.view == viewRevision_;
    const bool cached =
        std::any_of(cpuCache_.begin(), cpuCache_.end(), [&](const auto& c) { return c->key == wish.key; });
    if (current && !cached) next = std::move(wish);
  }
  if (!next || !hasScene_) return;
  cpuRunning_ = true;
  runInBackground<std::shared_ptr<const CpuImage>>(
      this,
      [scene = drawnScene(), camera = camera_, wish = *next]() -> std::shared_ptr<const CpuImage> {
        auto result = std::make_shared<CpuImage>();
        result->key = wish.key;
        try {
          mfr::RenderOutput output = mfr::render(scene, camera, wish.request);
          result->image = std::move(output.image);
          result->stats = std::move(output.stats);
        } catch (const std::exception& e) {
          result->error = QString::fromUtf8(e.what());
        }
        return result;
      },
      [this](const std::shared_ptr<const CpuImage>& result) {
        cpuRunning_ = false;
        cpuCache_.push_front(result);
        while (cpuCache_.size() > kCpuCacheSize) cpuCache_.pop_back();
        emit cpuImageReady(result->key);
        updateMetrics();
        startCpuJob();
      });
}

// ---- metrics -----------------------------------------------------------------------------

bool ViewerModel::metricsWanted(int side) const {
  if (!hasScene_ || side >= paneCount()) return false;
  return compare_ || (side == 0 && qualityWanted_);
}

bool ViewerModel::metricsCurrent(int side) const {
  const PaneMetrics& m = metrics_[index(side)];
  return hasScene_ && (m.valid || !m.error.isEmpty()) && m.key == frameKey(side);
}

bool ViewerModel::wantsFrameImage(int side) const {
  if (!hasScene_ || side >= paneCount() || metricsCurrent(side)) return false;
  const auto& frame = frameImage_[index(side)];
  if (frame && frame->first == frameKey(side)) return false;
  // Once frame qualities are asked for, every main frame is kept (a read-back is cheap; drawing
  // the frame again when the request comes is not).
  // Whoever listens for the frame quality (the budget panel) will ask for it after this frame:
  // read it back now, or the view draws it again to read it (a slow method's whole cost).
  static const QMetaMethod qualitySignal = QMetaMethod::fromSignal(&ViewerContext::frameQualityReady);
  return metricsWanted(side) || (side == 0 && (keepFrameImages_ || isSignalConnected(qualitySignal)));
}

void ViewerModel::reportFrameImage(int side, const ImageKey& key, mfr::ImageRGBA8 image) {
  if (key != frameKey(side)) return;  // a frame of an older view
  frameImage_[index(side)] = std::pair{key, std::move(image)};
  updateMetrics();
}

void ViewerModel::requestFrameQuality() {
  if (!hasScene_) return;
  if (metricsCurrent(0)) {
    emit frameQualityReady();
    return;
  }
  qualityWanted_ = true;
  keepFrameImages_ = true;
  const auto& frame = frameImage_[0];
  if (frame && frame->first == frameKey(0))
    updateMetrics();
  else
    emit frameImageWanted();
}

FrameQuality ViewerModel::frameQuality() const {
  FrameQuality q;
  const PaneMetrics& m = metrics_[0];
  if (!metricsCurrent(0)) return q;
  if (!m.valid) {
    q.error = m.error;
    return q;
  }
  q.valid = true;
  q.method = m.method;
  q.rmse = m.rmse;
  q.flipMean = m.flip.mean;
  q.flipMax = m.flip.max;
  return q;
}

void ViewerModel::updateMetrics() {
  for (int side = 0; side < paneCount(); ++side) {
    if (!metricsWanted(side) || metricsCurrent(side) || metricsRunning_[index(side)]) continue;
    const auto& frame = frameImage_[index(side)];
    if (!frame || frame->first != frameKey(side)) continue;  // the view reads it back when it draws
    const CpuImage* reference = cpuImage(CpuSlot::Reference, referenceRequest(side));
    if (!reference) return;  // cpuImageReady calls again
    if (!reference->error.isEmpty()) {
      PaneMetrics failed;
      failed.key = frame->first;
      failed.method = methodOf(side);
      failed.error = reference->error;
      metrics_[index(side)] = std::move(failed);
      emit metricsReady(side);
      if (side == 0 && qualityWanted_) {  // the answer is the reason (FrameQuality::error)
        qualityWanted_ = false;
        emit frameQualityReady();
      }
      continue;
    }
    startMetrics(side, reference->image);
  }
}

void ViewerModel::startMetrics(int side, const mfr::ImageRGBA8& reference) {
  metricsRunning_[index(side)] = true;
  const auto& frame = *frameImage_[index(side)];
  runInBackground<PaneMetrics>(
      this,
      [reference, image = frame.second, key = frame.first, method = methodOf(side)]() -> PaneMetrics {
        PaneMetrics m;
        try {
          m = computeMetrics(reference, image);
        } catch (const std::exception& e) {
          m.error = QString::fromUtf8(e.what());
        }
        m.key = key;
        m.method = method;
        return m;
      },
      [this, side](PaneMetrics m) {
        metricsRunning_[index(side)] = false;
        metrics_[index(side)] = std::move(m);
        emit metricsReady(side);
        if (side == 0 && qualityWanted_ && metricsCurrent(0)) {
          qualityWanted_ = false;
          emit frameQualityReady();
        }
        updateMetrics();  // a newer frame may be waiting
      });
}

bool ViewerModel::busy() const {
  return loading_ || abandonedLoads_ > 0 || fieldLoad_ || cpuRunning_ || metricsRunning_[0] || metricsRunning_[1];
}

// ---- depth complexity ---------------------------------------------------------------------

void ViewerModel::requestDepthComplexity() {
  if (hasScene_) emit depthComplexityWanted();
}

void ViewerModel::reportDepthComplexity(const QVector<quint64>& histogram, QSize size) {
  emit depthComplexityReady(histogram, size);
}
