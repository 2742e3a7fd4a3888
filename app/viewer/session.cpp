#include "session.hpp"

#include <QDir>
#include <QFile>
#include <QFileInfo>
#include <QJsonArray>
#include <QJsonDocument>
#include <QSaveFile>

#include <algorithm>
#include <cmath>

#include "mfr/error.hpp"
#include "mfr/io_util.hpp"
#include "mfr/json_text.hpp"
#include "mfr/render.hpp"
#include "mfr/scene/clip_box.hpp"
#include "mfr/scene/color_map.hpp"
#include "viewer_model.hpp"

namespace {

QJsonArray vec3(const glm::dvec3& v) {
  return {v.x, v.y, v.z};
}

using ParamsByMethod = std::map<std::string, std::map<std::string, std::string>>;

QJsonObject paramsToJson(const ParamsByMethod& params) {
  QJsonObject json;
  for (const auto& [method, values] : params) {
    QJsonObject p;
    for (const auto& [name, value] : values) p.insert(QString::fromStdString(name), QString::fromStdString(value));
    json.insert(QString::fromStdString(method), p);
  }
  return json;
}

// Enum values by their names in session files.
const std::map<QString, CompareLayout> kLayouts{{"side-by-side", CompareLayout::SideBySide},
                                                {"split", CompareLayout::Split}};
const std::map<QString, CompareDisplay> kDisplays{{"images", CompareDisplay::Images},
                                                  {"flip", CompareDisplay::FlipError},
                                                  {"difference", CompareDisplay::Difference}};
const std::map<QString, DataView> kDataViews{
    {"image", DataView::Image}, {"depth-complexity", DataView::DepthComplexity}, {"capacity", DataView::Capacity}};

template <class Enum>
QString nameOf(const std::map<QString, Enum>& names, Enum value) {
  for (const auto& [name, v] : names)
    if (v == value) return name;
  return {};
}

class Reader {
 public:
  explicit Reader(QString file) : file_(std::move(file)) {}
  [[noreturn]] void fail(const QString& where, const QString& reason) const {
    throw mfr::Error((file_ + ": " + where).toStdString(), reason.toStdString());
  }
  glm::dvec3 vec3(const QJsonObject& o, const QString& key, const QString& where) const {
    const QJsonArray a = o.value(key).toArray();
    if (a.size() != 3 || !a[0].isDouble() || !a[1].isDouble() || !a[2].isDouble())
      fail(where + "." + key, QStringLiteral("expected [x, y, z]"));
    return {a[0].toDouble(), a[1].toDouble(), a[2].toDouble()};
  }
  template <class Enum>
  Enum choice(const QJsonObject& o, const QString& key, const QString& where, const std::map<QString, Enum>& names,
              Enum fallback) const {
    if (!o.contains(key)) return fallback;
    const auto it = names.find(o.value(key).toString());
    if (it == names.end()) {
      QStringList known;
      for (const auto& entry : names) known << entry.first;
      fail(where + "." + key, QStringLiteral("expected one of %1").arg(known.join(QStringLiteral(", "))));
    }
    return it->second;
  }
  ParamsByMethod params(const QJsonObject& json, const QString& where) const {
    ParamsByMethod out;
    const std::vector<std::string> known = mfr::availableMethods();
    for (auto m = json.begin(); m != json.end(); ++m) {
      // Parameters of a method mfrview does not have, or not an object of them, were taken and never used.
      if (std::find(known.begin(), known.end(), m.key().toStdString()) == known.end())
        fail(where + "." + m.key(), QStringLiteral("unknown method '%1'").arg(m.key()));
      if (!m.value().isObject()) fail(where + "." + m.key(), QStringLiteral("expected an object of name: value"));
      auto& values = out[m.key().toStdString()];
      const QJsonObject p = m.value().toObject();
      for (auto v = p.begin(); v != p.end(); ++v) {
        if (!v.value().isString())
          fail(where + "." + m.key() + "." + v.key(), QStringLiteral("expected a string value"));
        values[v.key().toStdString()] = v.value().toString().toStdString();
      }
      // Checked as a render checks them, but named by the file's key: a bad value was the render's
      // "--param pool_mib=abc: expected a number", an option never given (a bug hunt).
      if (const mfr::MethodInfo* info = mfr::findMethodInfo(m.key().toStdString())) {
        try {
          (void)mfr::Params(info->params, values, m.key().toStdString());
        } catch (const mfr::Error& e) {
          QString why = QString::fromUtf8(e.what());
          if (why.startsWith(QStringLiteral("--param "))) why = why.mid(8);
          why.replace(QLatin1Char('\n'), QLatin1Char(' '));  // a value of several lines: one line here
          fail(where + "." + m.key(), why);
        }
      }
    }
    return out;
  }
  double number(const QJsonObject& o, const QString& key, const QString& where, double fallback) const {
    if (!o.contains(key)) return fallback;
    if (!o.value(key).isDouble()) fail(where + "." + key, QStringLiteral("expected a number"));
    return o.value(key).toDouble();
  }
  // A value in [0, 1] (a colour channel, an opacity).
  double unit(const QJsonValue& v, const QString& where) const {
    if (!v.isDouble() || !(v.toDouble() >= 0.0 && v.toDouble() <= 1.0))
      fail(where, QStringLiteral("expected a number in [0, 1]"));
    return v.toDouble();
  }
  // true or false ("no" was read as true: every non-boolean was).
  bool boolean(const QJsonObject& o, const QString& key, const QString& where, bool fallback) const {
    if (!o.contains(key)) return fallback;
    if (!o.value(key).isBool()) fail(where + "." + key, QStringLiteral("expected true or false"));
    return o.value(key).toBool();
  }
  QString string(const QJsonObject& o, const QString& key, const QString& where) const {
    if (!o.contains(key) || o.value(key).isNull()) return {};
    if (!o.value(key).isString()) fail(where.isEmpty() ? key : where + "." + key, QStringLiteral("expected a string"));
    return o.value(key).toString();
  }
  // An optional object or array at o[key] (`path` names it): absent or null is empty; another JSON
  // type is refused. They were read as empty: "compare": "yes" or "volumes": {…} dropped their
  // settings without a word (a bug hunt).
  QJsonObject objectAt(const QJsonObject& o, const QString& key, const QString& path) const {
    if (!o.contains(key) || o.value(key).isNull()) return {};
    if (!o.value(key).isObject()) fail(path, QStringLiteral("expected an object"));
    return o.value(key).toObject();
  }
  QJsonArray arrayAt(const QJsonObject& o, const QString& key, const QString& path) const {
    if (!o.contains(key) || o.value(key).isNull()) return {};
    if (!o.value(key).isArray()) fail(path, QStringLiteral("expected an array"));
    return o.value(key).toArray();
  }
  QJsonObject object(const QJsonValue& v, const QString& where) const {
    if (!v.isObject()) fail(where, QStringLiteral("expected an object"));
    return v.toObject();
  }
  // A method the viewer draws with, or an operation (empty: not given).
  QString method(const QJsonObject& o, const QString& key, const QString& where) const {
    QString name = string(o, key, where);
    const std::vector<std::string> known = mfr::availableMethods();  // the oracle and optimal-k too
    if (!name.isEmpty() && std::find(known.begin(), known.end(), name.toStdString()) == known.end())
      fail(where.isEmpty() ? key : where + "." + key, QStringLiteral("unknown method '%1'").arg(name));
    return name;
  }
  QString operation(const QJsonObject& o, const QString& key, const QString& where) const {
    QString name = string(o, key, where);
    if (!name.isEmpty()) try {
        mfr::validateOperation(name.toStdString());
      } catch (const mfr::Error&) {
        fail(where.isEmpty() ? key : where + "." + key, QStringLiteral("unknown operation '%1' (available: %2)")
                                                            .arg(name, QString::fromStdString(mfr::operationNames())));
      }
    return name;
  }

 private:
  QString file_;
};

}  // namespace

Session captureSession(const ViewerModel& model) {
  Session s;
  s.scenePath = model.scenePath();
  s.molecule = model.moleculeStyle();
  s.camera = model.camera();
  s.method = model.method();
  s.operation = model.operation();
  s.thickness = model.zThickness();
  s.volumeStep = model.volumeStep();
  s.hasClip = true;
  s.clip = model.clipBox();
  s.hasSection = true;
  s.section = model.section();
  // One colouring is saved, for every part that has its field: the Colour by chosen. Colourings as
  // the scene file gave them, which may differ per part, are left to it (hunt 32: the first part's
  // colouring came back on every part).
  s.hasColorBy = !model.fieldColoringsAsLoaded();
  s.colorBy = model.fieldColoring();
  for (std::size_t i = 0; i < model.scene().volumes.size(); ++i) {
    const mfr::Volume& v = model.scene().volumes[i];
    s.volumes.push_back({QString::fromStdString(v.name), v.visible, v.transfer, v.shading,
                         QString::fromStdString(v.field), model.isosurfaceValuesAt(static_cast<int>(i)),
                         model.isosurfaceOpacityAt(static_cast<int>(i))});
  }
  s.params = model.allParams();
  for (const mfr::Object& o : model.scene().objects) {
    s.objects.push_back({QString::fromStdString(o.name), o.visible, o.material.color, o.material.vertexColors,
                         s.hasColorBy ? std::optional<bool>(o.material.fieldColors.has_value()) : std::nullopt});
  }
  s.compare.enabled = model.compareEnabled();
  s.compare.layout = model.compareLayout();
  s.compare.split = model.compareSplit();
  s.compare.display = model.compareDisplay();
  s.compare.method = model.methodOf(1);
  s.compare.operation = model.operationOf(1);
  s.compare.params = model.allParamsOf(1);
  s.dataView = model.dataView();
  s.dataOverImage = model.dataViewOverImage();
  return s;
}

QStringList applySession(const Session& session, ViewerModel& model) {
  QStringList notes;
  // A misspelt key ("mehtod") was ignored without a word (a bug hunt).
  for (const QString& key : session.unknownKeys) notes << QStringLiteral("%1: no such key (left out)").arg(key);
  // The isosurfaces first: their parts are among the session's objects. What the viewer refuses
  // (a value outside the volume's range, too many) is a note, as for parts the scene lacks: the
  // whole set vanished without a word (a bug hunt).
  // Volumes by name, as objects: the settings of one went to another when a scene file's volumes
  // were reordered (a bug hunt).
  QStringList entries, names;
  for (const Session::VolumeState& v : session.volumes) entries << v.name;
  for (const mfr::Volume& v : model.scene().volumes) names << QString::fromStdString(v.name);
  const std::vector<int> volumeOf = matchByName(entries, names, true);
  QStringList unmatchedVolumes;
  for (std::size_t i = 0; i < session.volumes.size(); ++i)
    if (volumeOf[i] < 0) unmatchedVolumes << QStringLiteral("'%1'").arg(session.volumes[i].name);
  if (!unmatchedVolumes.isEmpty())
    notes << (unmatchedVolumes.size() == 1
                  ? QStringLiteral("the session's volume %1 is no volume of the scene: left out")
                  : QStringLiteral("the session's volumes %1 are no volumes of the scene: left out"))
                 .arg(unmatchedVolumes.join(QStringLiteral(", ")));
  for (std::size_t i = 0; i < session.volumes.size(); ++i)
    if (volumeOf[i] >= 0)
      if (const QString reason =
              model.setIsosurfacesAt(volumeOf[i], session.volumes[i].isosurfaces, session.volumes[i].isosurfaceOpacity);
          !reason.isEmpty())
        notes << QStringLiteral("volumes[%1].isosurfaces: %2 (left out)").arg(i).arg(reason);
  // Objects by name: the n-th entry of a name goes to the scene's n-th part of that name, so a
  // scene file that gained, lost or reordered parts keeps the overrides of the parts it still has
  // (by index, a changed count dropped them all, and a renamed part took another's state).
  QStringList objectEntries, partNames;
  for (const Session::ObjectState& o : session.objects) objectEntries << o.name;
  for (const mfr::Object& part : model.scene().objects) partNames << QString::fromStdString(part.name);
  const std::vector<int> partOf = matchByName(objectEntries, partNames);
  QStringList unmatched;
  std::vector<ViewerModel::ObjectState> states;
  states.reserve(session.objects.size());
  for (std::size_t e = 0; e < session.objects.size(); ++e) {
    const Session::ObjectState& o = session.objects[e];
    if (partOf[e] < 0) {
      unmatched << QStringLiteral("'%1'").arg(o.name);
      continue;
    }
    states.push_back({partOf[e], o.visible, o.color, o.vertexColors});
  }
  model.setObjectStates(states);
  if (!unmatched.isEmpty())
    notes << (unmatched.size() == 1 ? QStringLiteral("the session's object %1 is no part of the scene: left out")
                                    : QStringLiteral("the session's objects %1 are no part of the scene: left out"))
                 .arg(unmatched.join(QStringLiteral(", ")));
  model.setAllParams(session.params);
  model.setZThickness(session.thickness);
  if (session.hasSection) {
    std::optional<mfr::SectionPlane> section = session.section;
    if (section && section->slice && model.scene().volumes.empty()) {
      notes << QStringLiteral("section.slice: scene '%1' has no volume (the plane cuts, no slice is drawn)")
                   .arg(QString::fromStdString(model.scene().name));
      section->slice = false;
    }
    model.setSection(section);
  }
  // A field this scene lacks is a note, as parts it lacks (it was dropped without a word).
  if (session.hasColorBy &&
      !model.setFieldColoring(session.colorBy ? QString::fromStdString(session.colorBy->field) : QString(),
                              session.colorBy ? QString::fromStdString(session.colorBy->map) : QString(),
                              session.colorBy ? std::optional<glm::dvec2>(session.colorBy->range) : std::nullopt))
    notes << QStringLiteral("color_by %1: %2 (not applied)")
                 .arg(session.colorBy ? QString::fromStdString(session.colorBy->field) : QString(),
                      model.fieldColoringError());
  // Parts the session's colouring does not cover: a colour chosen for them over it.
  if (session.hasColorBy && session.colorBy) {
    QList<int> plain;
    for (std::size_t e = 0; e < session.objects.size(); ++e)
      if (session.objects[e].fieldColored == false && partOf[e] >= 0) plain << partOf[e];
    std::vector<ViewerModel::PartLook> looks = model.partLooks(plain);
    for (ViewerModel::PartLook& look : looks) look.material.fieldColors.reset();
    model.setPartLooks(looks);
  }
  for (std::size_t i = 0; i < session.volumes.size(); ++i)
    if (const int index = volumeOf[i]; index >= 0) {
      const Session::VolumeState& v = session.volumes[i];
      model.setVolumeStateAt(index, v.visible, v.transfer, v.shading);
      // Another field of the file: read in the background; the session's function follows it.
      // A field the file lacks, or any other field of a volume made in memory, is a note (it was
      // left out without a word).
      const mfr::Volume& volume = model.scene().volumes[static_cast<std::size_t>(index)];
      if (v.field.isEmpty() || v.field.toStdString() == volume.field) continue;  // read with the scene
      if (volume.file.empty() ||
          std::find(volume.fields.begin(), volume.fields.end(), v.field.toStdString()) == volume.fields.end()) {
        QStringList fields;
        for (const std::string& f : volume.fields) fields << QString::fromStdString(f);
        notes << QStringLiteral("volumes[%1].field: volume '%2' has no field '%3' (%4; left out)")
                     .arg(i)
                     .arg(QString::fromStdString(volume.name), v.field,
                          volume.file.empty() || fields.isEmpty()
                              ? QStringLiteral("it has one field")
                              : QStringLiteral("fields: ") + fields.join(QStringLiteral(", ")));
        continue;
      }
      // Read with the scene (openSession asks loadSceneAsync for the session's fields): it failed.
      // Left on its own field, blank under the session's function, with exit 0 (a bug hunt).
      if (const QString why = model.volumeFieldReadError(index); !why.isEmpty()) {
        notes << QStringLiteral("volumes[%1].field: %2 (left out)").arg(i).arg(why);
        continue;
      }
      model.setVolumeFieldAt(index, v.field, v.transfer);
    }
  // The clip box once the volumes are shown as the session shows them: one that held only a volume
  // hidden in the scene file was refused (a bug hunt). A box that holds nothing of the scene drew
  // an empty image; mfr render refuses it.
  bool clipHolds = true;
  if (session.hasClip && session.clip) {
    try {
      mfr::requireClipBoxHoldsScene(model.scene(), *session.clip, "clip");
    } catch (const mfr::Error& e) {
      clipHolds = false;
      notes << QString::fromUtf8(e.what()) + QStringLiteral(" (not applied)");
    }
  }
  if (session.hasClip && clipHolds) model.setClipBox(session.clip);
  // What only a volume uses, on a scene without one: notes (taken without a word; mfr render
  // refuses --step and --section …:slice there).
  if (model.scene().volumes.empty() && session.volumeStep > 0.0)
    notes << QStringLiteral("volume_step: scene '%1' has no volume (left out)")
                 .arg(QString::fromStdString(model.scene().name));
  else
    model.setVolumeStep(session.volumeStep);
  // An operation this scene cannot draw is a note, as parts it lacks: the first frame failed with
  // "--op csg: …", naming an option never given (a bug hunt).
  const auto drawable = [&](const QString& operation, const QString& key) {
    const mfr::Scene& scene = model.scene();
    QString lacks;
    // A tree the CSG panel made is in the plugin's settings, loaded after this (a review).
    const bool treeInSettings =
        !session.plugins.value(QStringLiteral("csg")).toObject().value(QStringLiteral("tree")).toString().isEmpty();
    if (operation == QLatin1String("csg") && scene.csg.empty() && !treeInSettings)
      lacks = QStringLiteral("no CSG tree");
    if (operation == QLatin1String("volume") && scene.volumes.empty()) lacks = QStringLiteral("no volume");
    if (lacks.isEmpty()) return true;
    notes << QStringLiteral("%1: %2: scene '%3' has %4 (left out)")
                 .arg(key, operation, QString::fromStdString(scene.name), lacks);
    return false;
  };
  if (!session.operation.isEmpty() && drawable(session.operation, QStringLiteral("operation")))
    model.setOperation(session.operation);
  if (!session.method.isEmpty()) model.setMethod(session.method);
  model.setAllParamsOf(1, session.compare.params);
  if (!session.compare.operation.isEmpty() && drawable(session.compare.operation, QStringLiteral("compare.operation")))
    model.setOperationOf(1, session.compare.operation);
  if (!session.compare.method.isEmpty()) model.setMethodOf(1, session.compare.method);
  model.setCompareLayout(session.compare.layout);
  model.setCompareSplit(session.compare.split);
  model.setCompareDisplay(session.compare.display);
  model.setCompareEnabled(session.compare.enabled);
  model.setDataView(session.dataView, session.dataOverImage);
  model.setCamera(session.camera);
  return notes;
}

QJsonObject sessionToJson(const Session& s) {
  QJsonObject camera{
      {"eye", vec3(s.camera.eye)},
      {"target", vec3(s.camera.target)},
      {"up", vec3(s.camera.up)},
      {"projection", s.camera.projection == mfr::Projection::Orthographic ? "orthographic" : "perspective"},
      {"fovy_degrees", s.camera.fovyDegrees},
      {"ortho_height", s.camera.orthoHeight},
      {"near", s.camera.nearPlane},
      {"far", s.camera.farPlane}};
  // Planes a named view gave are kept on reload; fitted ones are fitted again (the scene may have
  // changed since).
  if (s.camera.depthRangeGiven) camera.insert(QStringLiteral("near_far_given"), true);
  const QJsonObject compare{{"enabled", s.compare.enabled},
                            {"layout", nameOf(kLayouts, s.compare.layout)},
                            {"split", s.compare.split},
                            {"display", nameOf(kDisplays, s.compare.display)},
                            {"method", s.compare.method},
                            {"operation", s.compare.operation},
                            {"params", paramsToJson(s.compare.params)}};
  const QJsonObject dataView{{"mode", nameOf(kDataViews, s.dataView)}, {"over_image", s.dataOverImage}};
  QJsonArray volumes;
  for (const Session::VolumeState& v : s.volumes) {
    QJsonArray points;
    for (const mfr::TransferPoint& p : v.transfer.points)
      points.append(QJsonArray{p.value, p.color.r, p.color.g, p.color.b, p.color.a});
    QJsonObject volume{{"name", v.name},
                       {"visible", v.visible},
                       {"shading", v.shading},
                       {"field", v.field},
                       {"transfer", QJsonObject{{"unit_distance", v.transfer.unitDistance}, {"points", points}}}};
    if (!v.isosurfaces.empty()) {
      QJsonArray values;
      for (const double value : v.isosurfaces) values.append(value);
      volume.insert("isosurfaces", QJsonObject{{"values", values}, {"opacity", v.isosurfaceOpacity}});
    }
    volumes.append(volume);
  }
  QJsonArray objects;
  for (const Session::ObjectState& o : s.objects) {
    QJsonObject object{{"name", o.name},
                       {"visible", o.visible},
                       {"color", QJsonArray{o.color.r, o.color.g, o.color.b}},
                       {"opacity", o.color.a},
                       {"vertex_colors", o.vertexColors}};
    if (o.fieldColored) object.insert("field_colored", *o.fieldColored);
    objects.append(object);
  }
  QJsonObject json{
      {"format", "mfrview-session"},
      {"version", 1},
      {"scene", s.scenePath},
      {"camera", camera},
      {"method", s.method},
      {"operation", s.operation},
      {"thickness", s.thickness},
      {"volume_step", s.volumeStep},
      {"volumes", volumes},
      {"params", paramsToJson(s.params)},
      {"objects", objects},
      {"compare", compare},
      {"data_view", dataView},
      {"plugins", s.plugins},
      {"clip", s.clip ? QJsonValue(QJsonObject{{"min", QJsonArray{s.clip->min.x, s.clip->min.y, s.clip->min.z}},
                                               {"max", QJsonArray{s.clip->max.x, s.clip->max.y, s.clip->max.z}}})
                      : QJsonValue(QJsonValue::Null)},
      {"section", s.section ? QJsonValue(QJsonObject{
                                  {"point", QJsonArray{s.section->point.x, s.section->point.y, s.section->point.z}},
                                  {"normal", QJsonArray{s.section->normal.x, s.section->normal.y, s.section->normal.z}},
                                  {"caps", s.section->caps},
                                  {"slice", s.section->slice}})
                            : QJsonValue(QJsonValue::Null)},
  };
  if (s.hasColorBy)
    json.insert("color_by", s.colorBy
                                ? QJsonValue(QJsonObject{{"field", QString::fromStdString(s.colorBy->field)},
                                                         {"map", QString::fromStdString(s.colorBy->map)},
                                                         {"range", QJsonArray{s.colorBy->range.x, s.colorBy->range.y}}})
                                : QJsonValue(QJsonValue::Null));
  if (s.molecule) json.insert("molecule", QString::fromStdString(s.molecule->text()));
  return json;
}

Session sessionFromJson(const QJsonObject& json, const QString& file) {
  const Reader r(file);
  if (json.value("format").toString() != QLatin1String("mfrview-session"))
    r.fail(QStringLiteral("format"),
           QStringLiteral("not an mfrview session (expected \"format\": \"mfrview-session\")"));
  // Version 1 is the only one yet; a later one may mean keys that this viewer would misread.
  if (json.contains("version") && json.value("version") != QJsonValue(1))
    r.fail(QStringLiteral("version"), QStringLiteral("expected 1 (a session of a newer mfrview, or not a number)"));
  Session s;
  s.scenePath = r.string(json, "scene", {});
  if (s.scenePath.isEmpty()) r.fail(QStringLiteral("scene"), QStringLiteral("missing scene path"));
  if (json.contains("molecule")) {
    if (!json.value("molecule").isString())
      r.fail(QStringLiteral("molecule"), QStringLiteral("expected representations such as \"surface,sticks\""));
    try {
      s.molecule = mfr::MoleculeStyle::parse(json.value("molecule").toString().toStdString(), "molecule");
    } catch (const mfr::Error& e) {
      r.fail(QStringLiteral("molecule"), QString::fromUtf8(e.what()).mid(QStringLiteral("molecule: ").size()));
    }
  }
  const QJsonObject cam = json.value("camera").toObject();
  s.camera.eye = r.vec3(cam, "eye", "camera");
  s.camera.target = r.vec3(cam, "target", "camera");
  s.camera.up = r.vec3(cam, "up", "camera");
  // Another JSON type (a number 3) read as the default, perspective.
  const QString projection = cam.contains("projection") && !cam.value("projection").isString()
                                 ? QString()
                                 : cam.value("projection").toString(QStringLiteral("perspective"));
  if (projection != QLatin1String("perspective") && projection != QLatin1String("orthographic"))
    r.fail(QStringLiteral("camera.projection"), QStringLiteral("expected perspective or orthographic"));
  s.camera.projection =
      projection == QLatin1String("orthographic") ? mfr::Projection::Orthographic : mfr::Projection::Perspective;
  s.camera.fovyDegrees = r.number(cam, "fovy_degrees", "camera", s.camera.fovyDegrees);
  s.camera.orthoHeight = r.number(cam, "ortho_height", "camera", s.camera.orthoHeight);
  s.camera.nearPlane = r.number(cam, "near", "camera", s.camera.nearPlane);
  s.camera.farPlane = r.number(cam, "far", "camera", s.camera.farPlane);
  s.camera.depthRangeGiven = r.boolean(cam, "near_far_given", QStringLiteral("camera"), false);
  // As a scene file's views are checked (a fovy of -40 drew the view upside down; 0 was "projection
  // is singular" naming neither the file nor the key).
  if (!(s.camera.fovyDegrees > 0.0 && s.camera.fovyDegrees < 180.0))
    r.fail(QStringLiteral("camera.fovy_degrees"), QStringLiteral("must be in (0, 180) degrees"));
  if (!(s.camera.orthoHeight > 0.0))
    r.fail(QStringLiteral("camera.ortho_height"), QStringLiteral("must be a positive height in scene units"));
  if (!(s.camera.nearPlane > 0.0)) r.fail(QStringLiteral("camera.near"), QStringLiteral("must be positive"));
  if (!(s.camera.farPlane > s.camera.nearPlane))
    r.fail(QStringLiteral("camera.far"), QStringLiteral("must be greater than near"));
  // As a scene file's views are (it failed the first frame: "camera: projection is singular",
  // without the file).
  if (const auto defect = s.camera.frameDefect())
    r.fail(defect->key.empty() ? QStringLiteral("camera")
                               : QStringLiteral("camera.") + QString::fromStdString(defect->key),
           QString::fromStdString(defect->reason));
  if (s.camera.projectionSingular())
    r.fail(QStringLiteral("camera"),
           QStringLiteral("its projection is singular (near and far planes too far apart, or too large a scene)"));
  s.method = r.method(json, "method", {});
  s.operation = r.operation(json, "operation", {});
  // Optional (sessions written before the operation zthickness have none: the default).
  if (json.contains("thickness") && !json.value("thickness").isDouble())
    r.fail(QStringLiteral("thickness"), QStringLiteral("expected a number"));
  s.thickness = json.value("thickness").toDouble(0.0);
  if (!std::isfinite(s.thickness) || s.thickness < 0.0)
    r.fail(QStringLiteral("thickness"), QStringLiteral("expected a length >= 0 in scene units (0: the default)"));
  // Optional (sessions written before the operation volume have neither).
  if (json.contains("volume_step") && !json.value("volume_step").isDouble())
    r.fail(QStringLiteral("volume_step"), QStringLiteral("expected a number"));
  s.volumeStep = json.value("volume_step").toDouble(0.0);
  if (!std::isfinite(s.volumeStep) || s.volumeStep < 0.0)
    r.fail(QStringLiteral("volume_step"), QStringLiteral("expected a length >= 0 in scene units (0: the default)"));
  if (json.contains("clip")) {
    s.hasClip = true;
    if (!json.value("clip").isNull()) {
      if (!json.value("clip").isObject()) r.fail(QStringLiteral("clip"), QStringLiteral("expected null or {min, max}"));
      const QJsonObject clip = json.value("clip").toObject();
      mfr::Bounds box;
      box.min = r.vec3(clip, "min", "clip");
      box.max = r.vec3(clip, "max", "clip");
      if (!box.valid()) r.fail(QStringLiteral("clip"), QStringLiteral("min must not exceed max on any axis"));
      try {
        mfr::requireClipBoxInFloatRange(box, "clip");
      } catch (const mfr::Error& e) {
        r.fail(QStringLiteral("clip"), QString::fromUtf8(e.what()).mid(QStringLiteral("clip: ").size()));
      }
      s.clip = box;
    }
  }
  if (json.contains("section")) {
    s.hasSection = true;
    if (!json.value("section").isNull()) {
      if (!json.value("section").isObject())
        r.fail(QStringLiteral("section"), QStringLiteral("expected null or {point, normal, caps, slice}"));
      const QJsonObject section = json.value("section").toObject();
      mfr::SectionPlane plane;
      plane.point = r.vec3(section, "point", "section");
      plane.normal = r.vec3(section, "normal", "section");
      if (!(glm::length(plane.normal) > 1e-12))
        r.fail(QStringLiteral("section"), QStringLiteral("the normal must not be zero (a length above 1e-12)"));
      // mfr refuses it; the viewer drew the scene uncut.
      if (!std::isfinite(glm::length(plane.normal)))
        r.fail(QStringLiteral("section"), QStringLiteral("the normal is too long to normalise (under 1e150)"));
      if (section.contains("caps") && !section.value("caps").isBool())
        r.fail(QStringLiteral("section"), QStringLiteral("caps: expected true or false"));
      plane.caps = section.value("caps").toBool(true);
      if (section.contains("slice") && !section.value("slice").isBool())
        r.fail(QStringLiteral("section"), QStringLiteral("slice: expected true or false"));
      plane.slice = section.value("slice").toBool(false);
      s.section = plane;
    }
  }
  if (json.contains("color_by")) {
    s.hasColorBy = true;
    if (!json.value("color_by").isNull()) {
      const QJsonObject c = json.value("color_by").toObject();
      const QJsonArray range = c.value("range").toArray();
      if (!json.value("color_by").isObject() || !c.value("field").isString() || c.value("field").toString().isEmpty() ||
          !c.value("map").isString() || range.size() != 2 || !range[0].isDouble() || !range[1].isDouble() ||
          !(range[1].toDouble() > range[0].toDouble()))
        r.fail(QStringLiteral("color_by"), QStringLiteral("expected null or {field, map, range: [low, high]}"));
      const std::vector<std::string>& maps = mfr::colorMapNames();
      if (std::find(maps.begin(), maps.end(), c.value("map").toString().toStdString()) == maps.end())
        r.fail(QStringLiteral("color_by.map"),
               QStringLiteral("unknown colour map '%1'").arg(c.value("map").toString()));
      s.colorBy = mfr::FieldColors{c.value("field").toString().toStdString(),
                                   c.value("map").toString().toStdString(),
                                   {range[0].toDouble(), range[1].toDouble()}};
    }
  }
  const QJsonArray volumes = r.arrayAt(json, "volumes", QStringLiteral("volumes"));
  for (qsizetype i = 0; i < volumes.size(); ++i) {
    const QString at = QStringLiteral("volumes[%1]").arg(i);
    const QJsonObject v = r.object(volumes[i], at);
    const QString where = at + QStringLiteral(".transfer");
    const QJsonObject t = r.object(v.value("transfer"), where);
    Session::VolumeState state{r.string(v, "name", at),
                               r.boolean(v, "visible", at, true),
                               {},
                               r.boolean(v, "shading", at, false),
                               r.string(v, "field", at),
                               {},
                               0.5};
    state.transfer.unitDistance = r.number(t, "unit_distance", where, 1.0);
    const QJsonArray points = r.arrayAt(t, "points", where + QStringLiteral(".points"));
    for (qsizetype j = 0; j < points.size(); ++j) {
      const QJsonArray p = points[j].toArray();
      if (p.size() != 5 || !std::all_of(p.begin(), p.end(), [](const QJsonValue& x) { return x.isDouble(); }))
        r.fail(where + QStringLiteral(".points[%1]").arg(j), QStringLiteral("expected [value, r, g, b, a]"));
      state.transfer.points.push_back(
          {p[0].toDouble(), glm::vec4(glm::dvec4(p[1].toDouble(), p[2].toDouble(), p[3].toDouble(), p[4].toDouble()))});
    }
    try {
      state.transfer.validate("transfer function");
    } catch (const std::exception& e) {
      r.fail(where, QString::fromUtf8(e.what()));
    }
    // Optional (sessions written before isosurfaces have none); the viewer checks the values.
    if (v.contains("isosurfaces")) {
      const QString isoAt = at + QStringLiteral(".isosurfaces");
      const QJsonObject iso = r.objectAt(v, "isosurfaces", isoAt);
      const QJsonArray values = r.arrayAt(iso, "values", isoAt + QStringLiteral(".values"));
      for (qsizetype j = 0; j < values.size(); ++j) {
        if (!values[j].isDouble())
          r.fail(isoAt + QStringLiteral(".values[%1]").arg(j), QStringLiteral("expected a number"));
        state.isosurfaces.push_back(values[j].toDouble());
      }
      state.isosurfaceOpacity = r.number(iso, "opacity", isoAt, 0.5);
    }
    s.volumes.push_back(std::move(state));
  }
  s.params = r.params(r.objectAt(json, "params", QStringLiteral("params")), QStringLiteral("params"));
  // Optional (sessions written before compare mode have neither).
  const QJsonObject compare = r.objectAt(json, "compare", QStringLiteral("compare"));
  s.compare.enabled = r.boolean(compare, "enabled", QStringLiteral("compare"), false);
  s.compare.layout = r.choice(compare, "layout", "compare", kLayouts, CompareLayout::SideBySide);
  // The panel's slider holds 0 ... 1; a 7 was clamped to 1 without a word.
  s.compare.split =
      r.unit(compare.contains("split") ? compare.value("split") : QJsonValue(0.5), QStringLiteral("compare.split"));
  s.compare.display = r.choice(compare, "display", "compare", kDisplays, CompareDisplay::Images);
  s.compare.method = r.method(compare, "method", QStringLiteral("compare"));
  s.compare.operation = r.operation(compare, "operation", QStringLiteral("compare"));
  s.compare.params =
      r.params(r.objectAt(compare, "params", QStringLiteral("compare.params")), QStringLiteral("compare.params"));
  const QJsonObject dataView = r.objectAt(json, "data_view", QStringLiteral("data_view"));
  s.dataView = r.choice(dataView, "mode", "data_view", kDataViews, DataView::Image);
  s.dataOverImage = r.boolean(dataView, "over_image", QStringLiteral("data_view"), false);
  const QJsonArray objects = r.arrayAt(json, "objects", QStringLiteral("objects"));
  for (qsizetype i = 0; i < objects.size(); ++i) {
    const QString at = QStringLiteral("objects[%1]").arg(i);
    const QJsonObject o = r.object(objects[i], at);
    const QJsonArray c = o.value("color").toArray();
    if (c.size() != 3) r.fail(at + QStringLiteral(".color"), QStringLiteral("expected [r, g, b]"));
    glm::dvec4 rgba(1.0);
    for (int k = 0; k < 3; ++k) rgba[k] = r.unit(c[k], at + QStringLiteral(".color[%1]").arg(k));
    rgba.a = o.contains("opacity") ? r.unit(o.value("opacity"), at + QStringLiteral(".opacity")) : 1.0;
    // vertex_colors: absent in sessions written before it existed, when colours always multiplied.
    s.objects.push_back(
        {r.string(o, "name", at), r.boolean(o, "visible", at, true), glm::vec4(rgba),
         r.boolean(o, "vertex_colors", at, true),
         o.contains("field_colored") ? std::optional<bool>(r.boolean(o, "field_colored", at, true)) : std::nullopt});
  }
  if (json.contains("plugins") && !json.value("plugins").isObject())
    r.fail(QStringLiteral("plugins"), QStringLiteral("expected an object of plugin id: settings"));
  s.plugins = json.value("plugins").toObject();
  static const QStringList kKeys{"format",    "version",   "scene",       "molecule", "camera",  "method",
                                 "operation", "thickness", "volume_step", "volumes",  "params",  "objects",
                                 "compare",   "data_view", "plugins",     "clip",     "section", "color_by"};
  for (auto it = json.begin(); it != json.end(); ++it)
    if (!kKeys.contains(it.key())) s.unknownKeys << it.key();
  return s;
}

Session readSessionFile(const QString& path) {
  // As mfr reads files: a pipe waited for ever (the window frozen) and /dev/zero grew memory
  // until it ran out (a bug hunt).
  const QByteArray bytes = QByteArray::fromStdString(mfr::readFile(QFile::encodeName(path).toStdString()));
  QJsonParseError error{};
  const QJsonDocument doc = QJsonDocument::fromJson(bytes, &error);
  if (error.error != QJsonParseError::NoError)
    throw mfr::Error(
        path.toStdString(),
        QStringLiteral("JSON error at byte %1: %2").arg(error.offset).arg(error.errorString()).toStdString());
  // Qt's parser keeps the last of a key given twice: a second "objects" dropped the first without
  // a word, as scene files did before they refused it (a bug hunt).
  if (const std::optional<std::string> repeated = mfr::repeatedJsonKey(bytes.toStdString()))
    throw mfr::Error(path.toStdString(), *repeated + ": given twice (the keys of a JSON object must differ)");
  Session s = sessionFromJson(doc.object(), path);
  // Built-ins (@sample) and absolute paths stay; relative ones are relative to the session file.
  if (!s.scenePath.startsWith('@') && QFileInfo(s.scenePath).isRelative())
    s.scenePath = QFileInfo(path).dir().absoluteFilePath(s.scenePath);
  return s;
}

void writeSessionFile(const QString& path, const Session& session) {
  const mfr::TerminationSignalsHeld held;  // Ctrl-C mid-write leaves no temporary
  QSaveFile f(path);                       // temporary + rename: never a half-written session
  if (!f.open(QIODevice::WriteOnly)) throw mfr::Error(path.toStdString(), f.errorString().toStdString());
  f.write(QJsonDocument(sessionToJson(session)).toJson(QJsonDocument::Indented));
  if (!f.commit()) throw mfr::Error(path.toStdString(), f.errorString().toStdString());
}
