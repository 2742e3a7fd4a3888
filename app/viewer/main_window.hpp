#pragma once
// mfrview's main window: the render view in the centre, docks for the scene, the method, the
// statistics and each plugin; menus for files, sessions, views and plugins.
#include <QMainWindow>

#include <functional>
#include <map>
#include <optional>
#include <string>

#include "plugin_manager.hpp"
#include "session.hpp"

class QAction;
class QDockWidget;
class QLabel;
class QMenu;
class QProgressBar;
class QPushButton;
class RenderView;
class ViewerModel;

class MainWindow final : public QMainWindow {
  Q_OBJECT

 public:
  struct Options {
    bool restoreSettings = true;  // window layout, recent files and last method from QSettings
    bool loadPlugins = true;
  };
  explicit MainWindow(Options options, QWidget* parent = nullptr);
  MainWindow() : MainWindow(Options{}) {}
  ~MainWindow() override;

  // Starts loading a model, .mfrscene, built-in (@sample) or .mfrsession file.
  void open(const QString& path);  // a session (isSessionFile) or a scene
  [[nodiscard]] static bool isSessionFile(const QString& path);
  // `field`: the array or grid of a volume file (mfr::LoadOptions::field); empty: its default.
  // `molecule`: a molecule file's representations (mfr::LoadOptions::molecule); none: spheres.
  void openScene(const QString& path, const QString& field = {},
                 const std::optional<mfr::MoleculeStyle>& molecule = {});
  void openSession(const QString& path);
  // Throws mfr::Error naming the file.
  void saveSession(const QString& path);
  // Renders the current view at `size` (see RenderView::renderImage) and writes a PNG; with
  // `legend`, the field colouring's scalar bar — else the current volume's isosurfaces' — drawn
  // into it as mfr render --legend does (throws mfr::Error when there is neither or the image is too
  // small for one).
  // `check` (if any) sees the parameters the picture is drawn with before it is written.
  using ExportCheck = std::function<void(const std::map<std::string, std::string>& params)>;
  // Returns the render's statistics (its notes: a depth precision too coarse for given planes).
  mfr::Stats exportImage(const QString& path, QSize size, bool legend = false, const ExportCheck& check = {});
  // The render exportImage writes: the view's method at `size`, with the plugins' parameters for
  // that size (MfrViewerPlugin::exportParams), refitted until they settle; throws mfr::Error when
  // they do not within a few renders.
  struct ExportRender {
    mfr::RenderOutput output;
    std::map<std::string, std::string> pluginParams;
  };
  ExportRender renderForExport(QSize size);

  [[nodiscard]] ViewerModel& model() { return *model_; }
  [[nodiscard]] RenderView& view() { return *view_; }
  [[nodiscard]] const PluginManager& plugins() const { return plugins_; }
  // The last load error shown to the user (empty when the last load succeeded).
  [[nodiscard]] const QString& lastError() const { return lastError_; }
  // While a session's plugin settings are applied, "FILE: plugins.": their notes (which begin with
  // the plugin's id) are prefixed with it, as the session's own notes name the file and key.
  [[nodiscard]] const QString& notePrefix() const { return notePrefix_; }

 protected:
  void closeEvent(QCloseEvent* event) override;
  void dragEnterEvent(QDragEnterEvent* event) override;
  void dropEvent(QDropEvent* event) override;

 private:
  void buildMenus();
  void buildCompareAndDataViewActions();
  void buildDocks();
  void buildPluginDocks();
  void buildStatusBar();
  void rebuildNamedViews();
  void rebuildRecentFiles();
  void addRecentFile(const QString& path);
  void showError(const QString& title, const QString& message);
  void showPluginsDialog();
  void chooseFileToOpen();
  void chooseSessionToSave();
  void chooseImageToExport();
  void updateTitle();
  void updateFrameInfo();

  Options options_;
  ViewerModel* model_ = nullptr;
  RenderView* view_ = nullptr;
  PluginManager plugins_;
  QMenu* viewMenu_ = nullptr;
  QMenu* namedViewsMenu_ = nullptr;
  QMenu* recentMenu_ = nullptr;
  QMenu* panelsMenu_ = nullptr;
  QDockWidget* compareDock_ = nullptr;
  QLabel* frameInfo_ = nullptr;
  QProgressBar* loadProgress_ = nullptr;
  QPushButton* cancelLoad_ = nullptr;
  QString lastError_;
  bool restoredLayout_ = false;
  std::optional<Session> pendingSession_;  // applied once its scene has loaded
  QString pendingSessionFile_;
  QString notePrefix_;
};
