#pragma once
// Session files (.mfrsession, JSON): the scene's path, camera, method and operation (with the
// z-thickness and the volume step), the scene's volumes (visibility, transfer function), the
// parameters of every method the user set, per-object overrides, compare mode (with the second
// method's own parameters), the data view and each plugin's settings.
// Doubles are written shortest-round-trip, so a reloaded session renders the same image.
#include <QJsonObject>
#include <QString>
#include <QStringList>

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "mfr/scene/camera.hpp"
#include "viewer_model.hpp"

struct Session {
  struct ObjectState {
    QString name;
    bool visible = true;
    glm::vec4 color{1.0f};     // RGB + opacity, the material's floats exactly
    bool vertexColors = true;  // Material::vertexColors: false once a colour was chosen for the part
    // Whether the session's "color_by" colours this part ("field_colored", written with it): a
    // colour chosen for one part over a colouring by a field came back field-coloured (hunt 33).
    std::optional<bool> fieldColored;
  };
  QString scenePath;
  // A molecule file's representations ("molecule": "surface,sticks"; absent: the default spheres).
  std::optional<mfr::MoleculeStyle> molecule;
  mfr::Camera camera;
  QString method;
  QString operation;
  double thickness = 0.0;   // operation zthickness, scene units, both sides; 0 = the scene's default
  double volumeStep = 0.0;  // operation volume, scene units, both sides; 0 = the volume's default
  // The clip box ("clip": null or {min, max}); hasClip false: the session has no "clip" key (written
  // before it existed), so the scene keeps its own.
  bool hasClip = false;
  std::optional<mfr::Bounds> clip;
  // The section plane ("section": null or {point, normal, caps}); hasSection false: no "section" key
  // (an older session), so the scene keeps its own.
  bool hasSection = false;
  std::optional<mfr::SectionPlane> section;
  // Surfaces coloured by a field ("color_by": null or {field, map, range}); hasColorBy false: no key
  // (an older session), so the scene keeps its own colouring.
  bool hasColorBy = false;
  std::optional<mfr::FieldColors> colorBy;
  struct VolumeState {
    QString name;
    bool visible = true;
    mfr::TransferFunction transfer;
    bool shading = false;             // Volume::shading
    QString field;                    // Volume::field: the array or grid read ("" for formats without names)
    std::vector<double> isosurfaces;  // the values of the isosurfaces made in the viewer (none: empty)
    double isosurfaceOpacity = 0.5;
  };
  std::vector<VolumeState> volumes;                                  // by volume index
  std::map<std::string, std::map<std::string, std::string>> params;  // per method
  std::vector<ObjectState> objects;                                  // matched to parts by name
  struct CompareState {
    bool enabled = false;
    CompareLayout layout = CompareLayout::SideBySide;
    double split = 0.5;
    CompareDisplay display = CompareDisplay::Images;
    QString method, operation;  // side 1; empty: unchanged
    std::map<std::string, std::map<std::string, std::string>> params;
  } compare;
  DataView dataView = DataView::Image;
  bool dataOverImage = false;
  QJsonObject plugins;  // by plugin id
  // Top-level keys no session has (a misspelt "mehtod"): applySession notes them. Not an error:
  // a later viewer's session may add keys this one can leave out.
  QStringList unknownKeys;
};

// The model's current state (plugins filled in by the caller).
Session captureSession(const ViewerModel& model);
// Camera, method, parameters and object overrides onto the loaded scene. Objects are matched by
// name (the n-th entry of a name to the n-th part of that name); parts the session does not name
// keep the file's state. Returns notes for the user (the session's objects the scene lacks).
QStringList applySession(const Session& session, ViewerModel& model);

QJsonObject sessionToJson(const Session& session);
// Throws mfr::Error("<file>: <json path>", reason) for malformed content.
Session sessionFromJson(const QJsonObject& json, const QString& file);

// Read/write with paths: relative scene paths resolve against the session file's folder.
// Throw mfr::Error naming the file.
Session readSessionFile(const QString& path);
void writeSessionFile(const QString& path, const Session& session);
