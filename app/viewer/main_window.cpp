#include "main_window.hpp"

#include <QAction>
#include <QActionGroup>
#include <QApplication>
#include <QCloseEvent>
#include <QDockWidget>
#include <QDragEnterEvent>
#include <QDropEvent>
#include <QFileDialog>
#include <QFileInfo>
#include <QHeaderView>
#include <QInputDialog>
#include <QJsonDocument>
#include <QJsonObject>
#include <QJsonValue>
#include <QLabel>
#include <QMenuBar>
#include <QMessageBox>
#include <QMimeData>
#include <QProgressBar>
#include <QPushButton>
#include <QAbstractSlider>
#include <QAbstractSpinBox>
#include <QComboBox>
#include <QScrollArea>
#include <QScrollBar>
#include <QSettings>
#include <QStatusBar>
#include <QTableWidget>
#include <QTimer>
#include <QUndoStack>
#include <QToolBar>
#include <QVBoxLayout>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <iostream>
#include <exception>
#include <filesystem>

#include "camera_navigator.hpp"
#include "clip_panel.hpp"
#include "compare_panel.hpp"
#include "mfr/error.hpp"
#include "mfr/scene/clip_box.hpp"
#include "mfr/image.hpp"
#include "mfr/legend.hpp"
#include "mfr/io/load.hpp"
#include "method_panel.hpp"
#include "probe_panel.hpp"
#include "render_view.hpp"
#include "scene_tree_panel.hpp"
#include "stats_panel.hpp"
#include "viewer_model.hpp"

namespace {

constexpr int kMaxRecentFiles = 10;
// Renders of an export at most: a plugin's first guess, then refits from what a render measured.
constexpr int kMaxExportFits = 6;
const QString kSessionSuffix = QStringLiteral(".mfrsession");

QString sceneFileFilter() {
  QStringList patterns{QStringLiteral("*.mfrscene")};
  for (const std::string& ext : mfr::supportedModelExtensions())
    patterns << QStringLiteral("*") + QString::fromStdString(ext);
  QStringList volumes;
  for (const std::string& ext : mfr::supportedVolumeExtensions()) {
    volumes << QStringLiteral("*") + QString::fromStdString(ext);
    if (!patterns.contains(volumes.back())) patterns << volumes.back();
  }
  return QObject::tr("Scenes, models and volumes (%1);;Volumes (%2);;mfrview sessions (*.mfrsession);;All files (*)")
      .arg(patterns.join(' '), volumes.join(' '));
}

}  // namespace

namespace {

// A panel that scrolls vertically in its dock: the panels' combined heights (the method panel's
// parameter rows, the budget panel's histogram) then no longer set the window's minimum height or
// squeeze the image. Never sideways: the dock stays as wide as the panel needs, so no row is cut.
class VerticalScroll final : public QScrollArea {
 public:
  explicit VerticalScroll(QWidget* panel) {
    setWidgetResizable(true);
    setFrameShape(QFrame::NoFrame);
    setHorizontalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
    setWidget(panel);
  }
  // A panel that rebuilds its rows (the method panel, per method) may need another width: the
  // dock must ask again, which a scroll area does not do by itself.
  bool eventFilter(QObject* watched, QEvent* event) override {
    if (watched == widget() && event->type() == QEvent::LayoutRequest) updateGeometry();
    return QScrollArea::eventFilter(watched, event);
  }
  // The panel's own wish, not QScrollArea's (capped at 24 lines): docks laid out by resizeDocks
  // give a panel the height it asks for when there is room.
  [[nodiscard]] QSize sizeHint() const override {
    if (!widget()) return QScrollArea::sizeHint();
    const QSize panel = widget()->sizeHint();
    return {panel.width() + verticalScrollBar()->sizeHint().width(), panel.height()};
  }
  [[nodiscard]] QSize minimumSizeHint() const override {
    const QSize least = QScrollArea::minimumSizeHint();
    const int panelWidth = widget() ? widget()->minimumSizeHint().width() : 0;
    return {std::max(least.width(), panelWidth + verticalScrollBar()->sizeHint().width()), least.height()};
  }
};

// Spin boxes size themselves to the longest number their range allows (±1e30 with six decimals:
// about 300 px) and combo boxes to their longest entry; in a dock either sets the window's minimum
// width. Capped here for every panel, plugins' included.
void narrowControls(QWidget* panel) {
  constexpr int kWidestSpinBox = 120;
  for (QAbstractSpinBox* box : panel->findChildren<QAbstractSpinBox*>())
    if (box->minimumSizeHint().width() > kWidestSpinBox) box->setMinimumWidth(kWidestSpinBox);
  constexpr int kWidestComboBox = 160;
  for (QComboBox* combo : panel->findChildren<QComboBox*>())
    if (combo->minimumSizeHint().width() > kWidestComboBox) {
      combo->setSizeAdjustPolicy(QComboBox::AdjustToMinimumContentsLengthWithIcon);
      combo->setMinimumWidth(kWidestComboBox);
    }
}

// Controls whose value the wheel changes: sliders, spin boxes and combo boxes — not scroll bars,
// which is how scroll areas (the dock's own, a tree's, a table's) take the wheel.
bool wheelChangesValue(QObject* object) {
  if (qobject_cast<QScrollBar*>(object)) return false;
  return qobject_cast<QAbstractSlider*>(object) || qobject_cast<QAbstractSpinBox*>(object) ||
         qobject_cast<QComboBox*>(object);
}

// Such a control takes the focus by click or tab only, not by the wheel passing over it.
void noWheelFocus(QWidget* widget) {
  if (widget->focusPolicy() == Qt::WheelFocus) widget->setFocusPolicy(Qt::StrongFocus);
}

// The wheel over a dock scrolls the dock, unless the control under it has the focus (clicked or
// tabbed to): a slider, spin box or combo box in a panel must not change the scene because the
// wheel passed over it on the way down.
class DockWheelGuard final : public QObject {
 public:
  using QObject::QObject;

 protected:
  bool eventFilter(QObject* watched, QEvent* event) override {
    if (event->type() != QEvent::Wheel && event->type() != QEvent::Polish) return false;
    if (!wheelChangesValue(watched)) return false;
    auto* widget = static_cast<QWidget*>(watched);
    if (!inDock(widget)) return false;
    if (event->type() == QEvent::Polish) {  // rows a panel adds later (the method panel's, per method)
      noWheelFocus(widget);
      return false;
    }
    if (widget->hasFocus()) return false;
    event->ignore();  // on to the parents: the dock's scroll area scrolls
    return true;
  }

 private:
  static bool inDock(const QWidget* widget) {
    for (const QWidget* w = widget->parentWidget(); w; w = w->parentWidget())
      if (dynamic_cast<const VerticalScroll*>(w)) return true;
    return false;
  }
};

QWidget* scrolled(QWidget* panel) {
  auto* scroll = new VerticalScroll(panel);
  narrowControls(panel);
  // The controls there already: narrowControls' size queries polished them before they were in a
  // dock, so the guard's Polish handler saw them outside one.
  for (QWidget* child : panel->findChildren<QWidget*>())
    if (wheelChangesValue(child)) noWheelFocus(child);
  return scroll;
}

}  // namespace

MainWindow::MainWindow(Options options, QWidget* parent) : QMainWindow(parent), options_(options) {
  setObjectName(QStringLiteral("mfrviewMainWindow"));
  model_ = new ViewerModel(this);
  view_ = new RenderView(*model_, this);
  view_->setObjectName(QStringLiteral("renderView"));
  setCentralWidget(view_);
  setAcceptDrops(true);
  setDockOptions(QMainWindow::AnimatedDocks | QMainWindow::AllowTabbedDocks);
  setCorner(Qt::BottomLeftCorner, Qt::LeftDockWidgetArea);
  setCorner(Qt::BottomRightCorner, Qt::RightDockWidgetArea);

  qApp->installEventFilter(new DockWheelGuard(this));
  buildMenus();
  buildDocks();
  if (options_.loadPlugins) {
    plugins_.loadAll();
    buildPluginDocks();
  }
  buildStatusBar();

  connect(model_, &ViewerModel::loadStarted, this, [this](const QString& path) {
    loadProgress_->setValue(0);
    loadProgress_->show();
    cancelLoad_->show();
    statusBar()->showMessage(tr("Loading %1…").arg(path));
  });
  connect(model_, &ViewerModel::loadProgressChanged, this,
          [this](double fraction) { loadProgress_->setValue(static_cast<int>(std::lround(fraction * 1000.0))); });
  const auto loadEnded = [this] {
    loadProgress_->hide();
    cancelLoad_->hide();
  };
  connect(model_, &ViewerModel::sceneLoaded, this, [this, loadEnded] {
    loadEnded();
    lastError_.clear();
    // What loading could not do as asked (a cartoon of a structure without chains) follows.
    QString message = tr("Loaded %1 — %2 objects, %3 triangles")
                          .arg(model_->scenePath())
                          .arg(model_->scene().objects.size())
                          .arg(model_->scene().triangleCount());
    if (const std::size_t volumes = model_->scene().volumes.size(); volumes > 0)
      message += volumes == 1 ? tr(", 1 volume") : tr(", %1 volumes").arg(volumes);
    for (const std::string& note : model_->scene().notes)
      message += QStringLiteral("; ") + QString::fromStdString(note);
    statusBar()->showMessage(message, model_->scene().notes.empty() ? 8000 : 20000);
    addRecentFile(model_->scenePath());
    rebuildNamedViews();
    updateTitle();
    // A scene that brings a CSG tree puts the CSG panel (plugin "csg") in front: its switch is
    // how to see the tree as solids.
    if (!model_->scene().csg.empty())
      if (auto* csgDock = findChild<QDockWidget*>(QStringLiteral("plugin-csg"))) csgDock->raise();
    // The intersecting-surfaces sample is about z-thickness blending: the Ghosting panel (plugin
    // "ghosting") has its switch and thickness.
    if (model_->scenePath() == QLatin1String("@intersect"))
      if (auto* ghostDock = findChild<QDockWidget*>(QStringLiteral("plugin-ghosting"))) ghostDock->raise();
    // A scene with a volume: the Volume panel (plugin "hybridvolume") has its transfer function and step.
    if (!model_->scene().volumes.empty())
      if (auto* volumeDock = findChild<QDockWidget*>(QStringLiteral("plugin-hybridvolume"))) volumeDock->raise();
    if (pendingSession_) {
      QStringList notes = applySession(*pendingSession_, *model_);
      // Settings of a plugin that is not loaded (not installed here) were dropped without a word.
      for (const QString& id : pendingSession_->plugins.keys())
        if (std::none_of(plugins_.records().begin(), plugins_.records().end(),
                         [&](const PluginRecord& r) { return r.plugin && r.id == id; }))
          notes << QStringLiteral("plugins.%1: no plugin of that id is loaded (its settings are left out)").arg(id);
      if (!notes.isEmpty()) {
        // Also for scripted runs (--screenshot), which have no status bar to read.
        for (const QString& note : notes)
          std::cerr << "note: " << QFileInfo(pendingSessionFile_).fileName().toStdString() << ": " << note.toStdString()
                    << "\n";
        statusBar()->showMessage(
            QFileInfo(pendingSessionFile_).fileName() + QStringLiteral(": ") + notes.join(QStringLiteral("; ")), 20000);
      }
      if (model_->compareEnabled()) compareDock_->show();
      notePrefix_ = QFileInfo(pendingSessionFile_).fileName() + QStringLiteral(": plugins.");
      for (const PluginRecord& r : plugins_.records())
        if (r.plugin && pendingSession_->plugins.contains(r.id))
          r.plugin->loadSettings(pendingSession_->plugins.value(r.id).toObject());
      notePrefix_.clear();
      addRecentFile(pendingSessionFile_);
      pendingSession_.reset();
    }
  });
  connect(model_, &ViewerModel::loadFailed, this, [this, loadEnded](const QString& path, const QString& message) {
    loadEnded();
    pendingSession_.reset();
    showError(tr("Cannot open %1").arg(QFileInfo(path).fileName()), message);
  });
  connect(model_, &ViewerModel::loadCancelled, this, [this, loadEnded] {
    loadEnded();
    pendingSession_.reset();
    statusBar()->showMessage(tr("Loading cancelled; the current scene stays."), 5000);
  });
  connect(model_, &ViewerModel::frameRendered, this, &MainWindow::updateFrameInfo);
  // Plugins' notes (ViewerContext::note) in the status bar; main() also writes them to stderr.
  connect(model_, &ViewerContext::noted, this, [this](const QString& note) {
    const QString text = notePrefix_ + note;
    const QString shown = statusBar()->currentMessage();
    statusBar()->showMessage(shown.isEmpty() ? text : shown + QStringLiteral("; ") + text, 20000);
  });
  // A frame that cannot be drawn: its reason in the status bar, no frame info of the last frame
  // drawn; a frame drawn again takes the reason away (it stayed: a bug hunt).
  connect(model_, &ViewerModel::renderErrorChanged, this, [this](const QString& message) {
    const QString prefix = tr("Cannot render: ");
    if (!message.isEmpty()) {
      statusBar()->showMessage(prefix + model_->renderErrorShown());
      if (model_->mainPaneFailed()) frameInfo_->setText(tr("no frame"));
    } else if (statusBar()->currentMessage().startsWith(prefix)) {
      statusBar()->clearMessage();
    }
  });

  resize(1400, 900);
  if (options_.restoreSettings) {
    QSettings settings;
    restoreGeometry(settings.value(QStringLiteral("window/geometry")).toByteArray());
    restoredLayout_ = restoreState(settings.value(QStringLiteral("window/state")).toByteArray());
    const QString method = settings.value(QStringLiteral("method")).toString();
    if (model_->methodNames().contains(method)) model_->setMethod(method);
  }
  rebuildRecentFiles();
  updateTitle();
}

MainWindow::~MainWindow() = default;

// ---- menus ---------------------------------------------------------------------------------

void MainWindow::buildMenus() {
  QMenu* file = menuBar()->addMenu(tr("&File"));
  file->addAction(tr("&Open…"), QKeySequence::Open, this, &MainWindow::chooseFileToOpen);
  recentMenu_ = file->addMenu(tr("Open &Recent"));
  file->addAction(tr("Open &Sample"), this, [this] { openScene(QStringLiteral("@sample")); });
  file->addSeparator();
  file->addAction(tr("Save Session &As…"), QKeySequence::SaveAs, this, &MainWindow::chooseSessionToSave);
  file->addAction(tr("&Export Image…"), QKeySequence(Qt::CTRL | Qt::Key_E), this, &MainWindow::chooseImageToExport);
  file->addSeparator();
  file->addAction(tr("&Quit"), QKeySequence::Quit, this, &QWidget::close);

  viewMenu_ = menuBar()->addMenu(tr("&View"));
  viewMenu_->addAction(tr("&Fit All"), QKeySequence(Qt::Key_F), this, [this] {
    if (model_->hasScene()) model_->setCamera(model_->scene().fit(model_->camera()));
  });
  QMenu* standard = viewMenu_->addMenu(tr("&Standard Views"));
  using navigation::StandardView;
  int key = Qt::Key_1;
  for (StandardView v : {StandardView::Front, StandardView::Back, StandardView::Left, StandardView::Right,
                         StandardView::Top, StandardView::Bottom, StandardView::Iso}) {
    QAction* a = standard->addAction(navigation::standardViewName(v), this, [this, v] {
      if (model_->hasScene()) model_->setCamera(navigation::standardView(v, model_->scene(), model_->camera()));
    });
    a->setShortcut(QKeySequence(key++));
  }
  namedViewsMenu_ = viewMenu_->addMenu(tr("Scene &Views"));
  QAction* ortho = viewMenu_->addAction(tr("&Orthographic Projection"));
  ortho->setCheckable(true);
  ortho->setShortcut(QKeySequence(Qt::Key_O));
  connect(ortho, &QAction::triggered, this,
          [this] { model_->setCamera(navigation::toggledProjection(model_->camera())); });
  connect(model_, &ViewerModel::viewChanged, ortho,
          [this, ortho] { ortho->setChecked(model_->camera().projection == mfr::Projection::Orthographic); });
  QAction* fast = viewMenu_->addAction(tr("Fast &Navigation (Reduced Frames While Moving)"));
  fast->setObjectName(QStringLiteral("fastNavigationAction"));
  fast->setCheckable(true);
  fast->setChecked(view_->fastNavigation());
  connect(fast, &QAction::toggled, this, [this](bool on) {
    view_->setFastNavigation(on);
    if (options_.restoreSettings) QSettings().setValue(QStringLiteral("view/fastNavigation"), on);
  });
  if (options_.restoreSettings)
    fast->setChecked(QSettings().value(QStringLiteral("view/fastNavigation"), true).toBool());
  connect(view_, &RenderView::frameReductionChanged, this, [this](int reduction) {
    static const QString prefix = tr("Moving:");
    if (reduction > 1)
      statusBar()->showMessage(
          tr("%1 frames at 1/%2 of the resolution until the view stops").arg(prefix).arg(reduction));
    else if (statusBar()->currentMessage().startsWith(prefix))
      statusBar()->clearMessage();
  });
  viewMenu_->addSeparator();
  buildCompareAndDataViewActions();
  viewMenu_->addSeparator();
  panelsMenu_ = viewMenu_->addMenu(tr("&Panels"));

  QMenu* help = menuBar()->addMenu(tr("&Help"));
  help->addAction(tr("&Plugins…"), this, &MainWindow::showPluginsDialog);
  help->addAction(tr("&Navigation"), this, [this] {
    QMessageBox::information(this, tr("Navigation"),
                             tr("<table>"
                                "<tr><td>Left drag</td><td>orbit (trackball)</td></tr>"
                                "<tr><td>Middle or Shift + left drag</td><td>pan</td></tr>"
                                "<tr><td>Wheel</td><td>zoom to the cursor</td></tr>"
                                "<tr><td>F</td><td>fit all</td></tr>"
                                "<tr><td>1 … 7</td><td>front, back, left, right, top, bottom, isometric</td></tr>"
                                "<tr><td>O</td><td>perspective / orthographic</td></tr>"
                                "<tr><td>C</td><td>compare mode on / off</td></tr>"
                                "<tr><td>S</td><td>compare layout: side by side / split</td></tr>"
                                "<tr><td>D</td><td>compare heat map: images / FLIP / |difference|</td></tr>"
                                "<tr><td>I, N, K</td><td>image, depth complexity n(p), capacity k(p)</td></tr>"
                                "<tr><td>B</td><td>data map blended over the image</td></tr></table>"
                                "<p>While you drag or wheel, a slow method is drawn at a reduced resolution; the "
                                "full frame follows when the view stops (View → Fast Navigation).</p>"));
  });
  help->addAction(tr("&About mfrview"), this, [this] {
    QMessageBox::about(this, tr("About mfrview"),
                       tr("<b>mfrview</b> — multifragment rendering viewer.<br>%1").arg(view_->glInfo()));
  });
}

void MainWindow::buildCompareAndDataViewActions() {
  QToolBar* toolbar = addToolBar(tr("View"));
  toolbar->setObjectName(QStringLiteral("viewToolBar"));
  toolbar->setToolButtonStyle(Qt::ToolButtonTextOnly);

  QAction* compare = viewMenu_->addAction(tr("&Compare Two Methods"));
  compare->setObjectName(QStringLiteral("actionCompare"));
  compare->setCheckable(true);
  compare->setShortcut(QKeySequence(Qt::Key_C));
  compare->setToolTip(tr("Two methods with one camera, against the exact image (C)"));
  connect(compare, &QAction::triggered, this, [this](bool on) {
    model_->setCompareEnabled(on);
    if (on) {
      compareDock_->show();
      compareDock_->raise();
    }
  });
  QAction* layout = viewMenu_->addAction(tr("Compare &Layout: Side by Side / Split"));
  layout->setObjectName(QStringLiteral("actionCompareLayout"));
  layout->setShortcut(QKeySequence(Qt::Key_S));
  connect(layout, &QAction::triggered, this, [this] {
    model_->setCompareLayout(model_->compareLayout() == CompareLayout::SideBySide ? CompareLayout::Split
                                                                                  : CompareLayout::SideBySide);
  });
  QAction* heat = viewMenu_->addAction(tr("Compare &Heat Map: Images / FLIP / |Difference|"));
  heat->setObjectName(QStringLiteral("actionCompareDisplay"));
  heat->setShortcut(QKeySequence(Qt::Key_D));
  connect(heat, &QAction::triggered, this, [this] {
    model_->setCompareDisplay(static_cast<CompareDisplay>((static_cast<int>(model_->compareDisplay()) + 1) % 3));
  });
  connect(model_, &ViewerModel::compareChanged, this, [this, compare, layout, heat] {
    compare->setChecked(model_->compareEnabled());
    layout->setEnabled(model_->compareEnabled());
    heat->setEnabled(model_->compareEnabled());
  });
  layout->setEnabled(false);
  heat->setEnabled(false);
  toolbar->addAction(compare);

  QMenu* dataMenu = viewMenu_->addMenu(tr("&Data View"));
  auto* group = new QActionGroup(this);
  const auto addView = [&](const QString& text, const QString& name, DataView view, Qt::Key key) {
    QAction* a = dataMenu->addAction(text);
    a->setObjectName(name);
    a->setCheckable(true);
    a->setShortcut(QKeySequence(key));
    group->addAction(a);
    connect(a, &QAction::triggered, this, [this, view] { model_->setDataView(view, model_->dataViewOverImage()); });
    connect(model_, &ViewerModel::dataViewChanged, a, [this, a, view] { a->setChecked(model_->dataView() == view); });
    a->setChecked(model_->dataView() == view);
    toolbar->addAction(a);
    return a;
  };
  addView(tr("&Image"), QStringLiteral("actionViewImage"), DataView::Image, Qt::Key_I);
  addView(tr("Depth Complexity &n(p)"), QStringLiteral("actionViewDepthComplexity"), DataView::DepthComplexity,
          Qt::Key_N);
  addView(tr("Capacity &k(p)"), QStringLiteral("actionViewCapacity"), DataView::Capacity, Qt::Key_K);
  dataMenu->addSeparator();
  QAction* over = dataMenu->addAction(tr("&Blend Map Over Image"));
  over->setObjectName(QStringLiteral("actionViewOverImage"));
  over->setCheckable(true);
  over->setShortcut(QKeySequence(Qt::Key_B));
  connect(over, &QAction::triggered, this, [this](bool on) { model_->setDataView(model_->dataView(), on); });
  connect(model_, &ViewerModel::dataViewChanged, over, [this, over] { over->setChecked(model_->dataViewOverImage()); });
  toolbar->addAction(over);
}

void MainWindow::buildDocks() {
  const auto dock = [this](const QString& title, const QString& name, QWidget* panel, Qt::DockWidgetArea area) {
    auto* d = new QDockWidget(title, this);
    d->setObjectName(name);
    d->setWidget(scrolled(panel));
    addDockWidget(area, d);
    panelsMenu_->addAction(d->toggleViewAction());
    return d;
  };
  auto* sceneTree = new SceneTreePanel(*model_);
  QDockWidget* scene = dock(tr("Scene"), QStringLiteral("sceneDock"), sceneTree, Qt::LeftDockWidgetArea);
  // Edit: the Scene dock's edits of parts, undone and redone (a text field with the focus keeps
  // its own Ctrl+Z).
  auto* edit = new QMenu(tr("&Edit"), this);
  menuBar()->insertMenu(viewMenu_->menuAction(), edit);
  QAction* undo = sceneTree->undoStack()->createUndoAction(edit);
  undo->setObjectName(QStringLiteral("undoAction"));
  undo->setShortcut(QKeySequence::Undo);
  QAction* redo = sceneTree->undoStack()->createRedoAction(edit);
  redo->setObjectName(QStringLiteral("redoAction"));
  redo->setShortcut(QKeySequence::Redo);
  edit->addActions({undo, redo});
  QDockWidget* clip = dock(tr("Clip"), QStringLiteral("clipDock"), new ClipPanel(*model_), Qt::LeftDockWidgetArea);
  tabifyDockWidget(scene, clip);
  scene->raise();
  QDockWidget* method =
      dock(tr("Method"), QStringLiteral("methodDock"), new MethodPanel(*model_), Qt::LeftDockWidgetArea);
  compareDock_ = dock(tr("Compare"), QStringLiteral("compareDock"), new ComparePanel(*model_), Qt::LeftDockWidgetArea);
  tabifyDockWidget(method, compareDock_);
  method->raise();
  QDockWidget* stats =
      dock(tr("Statistics"), QStringLiteral("statsDock"), new StatsPanel(*model_), Qt::RightDockWidgetArea);
  auto* probePanel = new ProbePanel(*model_, *view_);
  QDockWidget* probe = dock(tr("Probe"), QStringLiteral("probeDock"), probePanel, Qt::RightDockWidgetArea);
  tabifyDockWidget(stats, probe);
  stats->raise();
  // A probe brings its dock to the front (Ctrl + click is the only way to start one).
  connect(view_, &RenderView::probeRequested, probe, [probe] {
    probe->show();
    probe->raise();
  });
  // Which part is this: a double click on the view, or on a fragment's row in the Probe dock,
  // selects the part's row in the Scene dock and names it in the status bar.
  const auto pick = [this, scene, sceneTree](int part) {
    // A Probe row of parts since changed (isosurfaces removed) may name none.
    if (part >= static_cast<int>(model_->scene().objects.size())) part = -1;
    sceneTree->selectPart(part);
    if (part < 0) {
      statusBar()->showMessage(tr("No part there"), 5000);
      return;
    }
    scene->show();
    scene->raise();
    const std::string& name = model_->scene().objects[static_cast<std::size_t>(part)].name;
    statusBar()->showMessage(tr("Part %1 of %2: %3")
                                 .arg(part)
                                 .arg(model_->scene().objects.size())
                                 .arg(name.empty() ? tr("(no name)") : QString::fromStdString(name)),
                             8000);
  };
  connect(view_, &RenderView::partPickRequested, this, [this, pick](QPointF point) {
    try {
      pick(view_->partAt(point));
    } catch (const std::exception& e) {
      statusBar()->showMessage(QString::fromUtf8(e.what()), 5000);
    }
  });
  connect(probePanel, &ProbePanel::partChosen, this, pick);
  // The image gets most of the window; panels start narrow (users widen them as they like).
  // Deferred until the window has its size, or the layout overrides it.
  QTimer::singleShot(0, this, [this, scene, stats] {
    if (restoredLayout_) return;
    resizeDocks({scene, stats}, {330, 360}, Qt::Horizontal);
    // The plugin panels scroll, so nothing makes room for them any more: the one in front gets the
    // height its panel asks for (the budget panel's histogram in sight), the statistics the rest.
    for (QDockWidget* d : findChildren<QDockWidget*>())
      if (d->objectName().startsWith(QStringLiteral("plugin-")) && !d->visibleRegion().isEmpty()) {
        const int total = stats->height() + d->height();
        const int wanted = std::clamp(d->widget()->sizeHint().height() + 40, total / 2, total - 200);
        resizeDocks({stats, d}, {total - wanted, wanted}, Qt::Vertical);
        break;
      }
  });
}

void MainWindow::buildPluginDocks() {
  // Plugin panels share one tabbed dock under the statistics, the first plugin's tab in front, so
  // each new plugin does not take height from the others (or width from the image).
  QDockWidget* first = nullptr;
  for (const PluginRecord& r : plugins_.records()) {
    if (!r.plugin) continue;
    auto* d = new QDockWidget(r.name, this);
    d->setObjectName(QStringLiteral("plugin-") + r.id);
    d->setWidget(scrolled(r.plugin->createPanel(*model_, d)));
    addDockWidget(Qt::RightDockWidgetArea, d);
    if (first)
      tabifyDockWidget(first, d);
    else
      first = d;
    panelsMenu_->addAction(d->toggleViewAction());
  }
  if (first) first->raise();
}

void MainWindow::buildStatusBar() {
  loadProgress_ = new QProgressBar;
  loadProgress_->setObjectName(QStringLiteral("loadProgress"));
  loadProgress_->setRange(0, 1000);  // the loader's fraction done (mfr::LoadProgress)
  loadProgress_->setFormat(QStringLiteral("%p %"));
  loadProgress_->setMaximumWidth(160);
  loadProgress_->hide();
  cancelLoad_ = new QPushButton(tr("Cancel"));
  cancelLoad_->setObjectName(QStringLiteral("cancelLoad"));
  cancelLoad_->hide();
  connect(cancelLoad_, &QPushButton::clicked, model_, &ViewerModel::cancelLoad);
  frameInfo_ = new QLabel;
  frameInfo_->setObjectName(QStringLiteral("frameInfo"));
  statusBar()->addPermanentWidget(loadProgress_);
  statusBar()->addPermanentWidget(cancelLoad_);
  statusBar()->addPermanentWidget(frameInfo_);
}

void MainWindow::rebuildNamedViews() {
  namedViewsMenu_->clear();
  for (const mfr::NamedView& v : model_->scene().views) {
    const mfr::Camera camera = v.camera;
    namedViewsMenu_->addAction(QString::fromStdString(v.name), this, [this, camera] { model_->setCamera(camera); });
  }
  namedViewsMenu_->setEnabled(!model_->scene().views.empty());
}

void MainWindow::rebuildRecentFiles() {
  recentMenu_->clear();
  const QStringList recent = QSettings().value(QStringLiteral("recentFiles")).toStringList();
  for (const QString& path : recent) recentMenu_->addAction(path, this, [this, path] { open(path); });
  recentMenu_->setEnabled(!recent.isEmpty());
}

void MainWindow::addRecentFile(const QString& path) {
  // A scripted run (--screenshot) filled the user's Open Recent with its files (a bug hunt).
  if (path.isEmpty() || !options_.restoreSettings) return;
  QSettings settings;
  QStringList recent = settings.value(QStringLiteral("recentFiles")).toStringList();
  recent.removeAll(path);
  recent.prepend(path);
  while (recent.size() > kMaxRecentFiles) recent.removeLast();
  settings.setValue(QStringLiteral("recentFiles"), recent);
  rebuildRecentFiles();
}

// ---- files -------------------------------------------------------------------------------

void MainWindow::open(const QString& path) {
  if (isSessionFile(path))
    openSession(path);
  else
    openScene(path);
}

// A session by its name, or by what it says it is ("format": "mfrview-session"): one opened with
// --session under another name went to Open Recent, which read it as a scene file (a bug hunt).
// Only a small regular file whose name says no scene, model or volume format (a glTF is JSON too,
// and was parsed twice), and that starts as a JSON object, is read to tell.
bool MainWindow::isSessionFile(const QString& path) {
  if (path.endsWith(kSessionSuffix, Qt::CaseInsensitive)) return true;
  // By its content whatever its name (a session saved as s.gltf opened as a model, and went to
  // Open Recent as one), cheaply: a file is parsed only if it starts as JSON and names the format
  // (a glTF is JSON too, and was parsed once to tell and again to load).
  std::error_code ec;
  const std::filesystem::path file(QFile::encodeName(path).toStdString());
  if (!std::filesystem::is_regular_file(file, ec) ||
      std::filesystem::file_size(file, ec) > (std::uintmax_t{16} << 20) || ec)
    return false;
  QFile f(path);
  if (!f.open(QIODevice::ReadOnly)) return false;
  // The first character that is not white space (a session indented by 256 spaces was missed: review 27).
  char c = ' ';
  while (f.getChar(&c) && std::isspace(static_cast<unsigned char>(c))) {
  }
  if (c != '{' || !f.seek(0)) return false;
  const QByteArray bytes = f.readAll();
  if (!bytes.contains("\"mfrview-session\"")) return false;
  const QJsonDocument doc = QJsonDocument::fromJson(bytes);
  return doc.isObject() &&
         doc.object().value(QStringLiteral("format")) == QJsonValue(QStringLiteral("mfrview-session"));
}

void MainWindow::openScene(const QString& path, const QString& field,
                           const std::optional<mfr::MoleculeStyle>& molecule) {
  pendingSession_.reset();
  // Built-ins stay as typed; files are remembered by absolute path.
  model_->loadSceneAsync(path.startsWith('@') ? path : QFileInfo(path).absoluteFilePath(), field, molecule);
}

void MainWindow::openSession(const QString& path) {
  try {
    Session session = readSessionFile(path);
    // The plugins' settings as the rest of the session: a wrong type or an unknown key is one
    // line naming the file and key, before anything loads (they were read as defaults).
    for (const PluginRecord& r : plugins_.records())
      if (r.plugin && session.plugins.contains(r.id)) {
        const QJsonValue settings = session.plugins.value(r.id);
        const QString problem = settings.isObject() ? pluginSettingsProblem(*r.plugin, settings.toObject())
                                                    : QStringLiteral("expected an object");
        if (!problem.isEmpty())
          throw mfr::Error(path.toStdString(), QStringLiteral("plugins.%1: %2").arg(r.id, problem).toStdString());
      }
    const QString scene = session.scenePath;
    // The volumes' fields are read with the scene (ViewerModel::loadSceneAsync).
    QList<QPair<QString, QString>> fields;
    for (const Session::VolumeState& v : session.volumes) fields.append({v.name, v.field});
    model_->loadSceneAsync(scene, {}, session.molecule, fields);
    pendingSession_ = std::move(session);  // after loadSceneAsync, which cannot finish before we return
    pendingSessionFile_ = QFileInfo(path).absoluteFilePath();
  } catch (const std::exception& e) {
    showError(tr("Cannot open session %1").arg(QFileInfo(path).fileName()), QString::fromUtf8(e.what()));
  }
}

void MainWindow::saveSession(const QString& path) {
  Session session = captureSession(*model_);
  for (const PluginRecord& r : plugins_.records())
    if (r.plugin) session.plugins.insert(r.id, r.plugin->saveSettings());
  writeSessionFile(path, session);
  addRecentFile(QFileInfo(path).absoluteFilePath());
}

MainWindow::ExportRender MainWindow::renderForExport(QSize size) {
  // Plugins' parameters for this size (the budget panel's k or pool, fitted to the view's): a
  // first guess, then a refit from what that render measured, a few times at most.
  const auto pluginParams = [&](const std::map<std::string, std::string>* tried, const mfr::Stats* measured) {
    std::map<std::string, std::string> params;
    for (const PluginRecord& r : plugins_.records())
      if (r.plugin)
        for (const auto& [name, value] : r.plugin->exportParams(size, tried, measured)) params[name] = value;
    return params;
  };
  ExportRender render;
  render.pluginParams = pluginParams(nullptr, nullptr);
  render.output = view_->renderOutput(size, render.pluginParams);
  for (int tries = 1; !render.pluginParams.empty(); ++tries) {
    std::map<std::string, std::string> refit = pluginParams(&render.pluginParams, &render.output.stats);
    if (refit == render.pluginParams) break;  // the plugins keep what the last render measured
    // Never a picture the plugins did not settle on (it could be one over the budget).
    if (tries == kMaxExportFits)
      throw mfr::Error("export", QStringLiteral("the plugins' parameters for %1x%2 did not settle in %3 renders")
                                     .arg(size.width())
                                     .arg(size.height())
                                     .arg(kMaxExportFits)
                                     .toStdString());
    render.pluginParams = std::move(refit);
    render.output = view_->renderOutput(size, render.pluginParams);
  }
  return render;
}

mfr::Stats MainWindow::exportImage(const QString& path, QSize size, bool legend, const ExportCheck& check) {
  mfr::requireSomethingToDraw(model_->drawnScene());  // as mfr render refuses it, before --legend
  std::optional<ViewerModel::ColorLegend> shown;
  if (legend) {
    // The field colouring's map, else the isosurfaces' (ViewerModel::colorLegend; as mfr render
    // --legend).
    shown = model_->colorLegend();
    if (!shown)
      throw mfr::Error("--legend",
                       "nothing is coloured by a field (use --color-by, or a scene's color_by) and there are no "
                       "isosurfaces");
    if (size.width() < mfr::kMinLegendImageSize || size.height() < mfr::kMinLegendImageSize)
      throw mfr::Error("--legend", QStringLiteral("the image %1x%2 is too small for one: at least %3 pixels a side")
                                       .arg(size.width())
                                       .arg(size.height())
                                       .arg(mfr::kMinLegendImageSize)
                                       .toStdString());
  }
  ExportRender render = renderForExport(size);
  if (check) {
    std::map<std::string, std::string> params = model_->params();
    for (const auto& [name, value] : render.pluginParams) params[name] = value;
    check(params);
  }
  mfr::ImageRGBA8 image = std::move(render.output.image);
  if (shown) mfr::drawColorLegend(image, shown->colors, model_->scene().background, shown->ticks);
  mfr::writePng(path.toStdString(), image);
  return std::move(render.output.stats);
}

void MainWindow::chooseFileToOpen() {
  const QString path = QFileDialog::getOpenFileName(this, tr("Open"), QString(), sceneFileFilter());
  if (!path.isEmpty()) open(path);
}

void MainWindow::chooseSessionToSave() {
  QString path =
      QFileDialog::getSaveFileName(this, tr("Save Session"), QString(), tr("mfrview sessions (*.mfrsession)"));
  if (path.isEmpty()) return;
  if (!path.endsWith(kSessionSuffix)) path += kSessionSuffix;
  try {
    saveSession(path);
    statusBar()->showMessage(tr("Saved %1").arg(path), 5000);
  } catch (const std::exception& e) {
    showError(tr("Cannot save the session"), QString::fromUtf8(e.what()));
  }
}

void MainWindow::chooseImageToExport() {
  bool ok = false;
  const QSize current = model_->renderSize();
  const QString sizeText =
      QInputDialog::getText(this, tr("Export Image"), tr("Size (width × height, pixels):"), QLineEdit::Normal,
                            QStringLiteral("%1x%2").arg(current.width()).arg(current.height()), &ok);
  if (!ok) return;
  const QStringList parts = sizeText.split(QLatin1Char('x'));
  const QSize size = parts.size() == 2 ? QSize(parts[0].trimmed().toInt(), parts[1].trimmed().toInt()) : QSize();
  if (size.width() <= 0 || size.height() <= 0 || size.width() > 16384 || size.height() > 16384) {
    showError(tr("Cannot export"), tr("size %1: expected WIDTHxHEIGHT, e.g. 1920x1080").arg(sizeText));
    return;
  }
  QString path =
      QFileDialog::getSaveFileName(this, tr("Export Image"), QStringLiteral("mfrview.png"), tr("PNG images (*.png)"));
  if (path.isEmpty()) return;
  if (!path.endsWith(QStringLiteral(".png"), Qt::CaseInsensitive)) path += QStringLiteral(".png");
  try {
    // As on screen: the legend of a field colouring or of the isosurfaces, when it fits.
    const bool legend = model_->colorLegend().has_value() && size.width() >= mfr::kMinLegendImageSize &&
                        size.height() >= mfr::kMinLegendImageSize;
    (void)exportImage(path, size, legend);
    statusBar()->showMessage(tr("Wrote %1").arg(path), 5000);
  } catch (const std::exception& e) {
    showError(tr("Cannot export the image"), QString::fromUtf8(e.what()));
  }
}

void MainWindow::showError(const QString& title, const QString& message) {
  lastError_ = message;
  statusBar()->showMessage(message);
  // Window-modal and non-blocking: loading finishes from the event loop, and tests can read it.
  auto* box = new QMessageBox(QMessageBox::Warning, title, message, QMessageBox::Ok, this);
  box->setObjectName(QStringLiteral("errorBox"));
  box->setInformativeText(
      model_->hasScene() ? tr("The current scene (%1) stays open.").arg(QString::fromStdString(model_->scene().name))
                         : QString());
  box->setAttribute(Qt::WA_DeleteOnClose);
  box->open();
}

void MainWindow::showPluginsDialog() {
  QDialog dialog(this);
  dialog.setWindowTitle(tr("Plugins"));
  auto* layout = new QVBoxLayout(&dialog);
  layout->addWidget(new QLabel(tr("Searched: %1").arg(PluginManager::searchPaths().join(QStringLiteral(", ")))));
  auto* table = new QTableWidget(static_cast<int>(plugins_.records().size()), 4);
  table->setHorizontalHeaderLabels({tr("Plugin"), tr("Id"), tr("Status"), tr("File")});
  int row = 0;
  for (const PluginRecord& r : plugins_.records()) {
    table->setItem(row, 0, new QTableWidgetItem(r.plugin ? r.name : QFileInfo(r.file).fileName()));
    table->setItem(row, 1, new QTableWidgetItem(r.id));
    table->setItem(
        row, 2, new QTableWidgetItem(r.plugin ? tr("loaded — %1").arg(r.description) : tr("failed: %1").arg(r.error)));
    table->setItem(row, 3, new QTableWidgetItem(r.file));
    ++row;
  }
  table->horizontalHeader()->setStretchLastSection(true);
  table->resizeColumnsToContents();
  table->setEditTriggers(QAbstractItemView::NoEditTriggers);
  layout->addWidget(table);
  dialog.resize(820, 260);
  dialog.exec();
}

void MainWindow::updateTitle() {
  setWindowTitle(model_->hasScene() ? tr("%1 — mfrview").arg(QString::fromStdString(model_->scene().name))
                                    : tr("mfrview"));
}

void MainWindow::updateFrameInfo() {
  const mfr::Stats& s = model_->stats();
  const QSize size = model_->paneSize();  // the image the statistics describe
  frameInfo_->setText(tr("%1  ·  %2×%3  ·  %4 ms  ·  %5")
                          .arg(QString::fromStdString(s.method))
                          .arg(size.width())
                          .arg(size.height())
                          .arg(s.totalTimeMs(), 0, 'f', 1)
                          .arg(formatBytes(s.bytesAllocated)));
}

// ---- window events -------------------------------------------------------------------------

void MainWindow::closeEvent(QCloseEvent* event) {
  if (options_.restoreSettings) {
    QSettings settings;
    settings.setValue(QStringLiteral("window/geometry"), saveGeometry());
    settings.setValue(QStringLiteral("window/state"), saveState());
    settings.setValue(QStringLiteral("method"), model_->method());
  }
  event->accept();
}

void MainWindow::dragEnterEvent(QDragEnterEvent* event) {
  if (event->mimeData()->hasUrls() && !event->mimeData()->urls().isEmpty() &&
      event->mimeData()->urls().first().isLocalFile())
    event->acceptProposedAction();
}

void MainWindow::dropEvent(QDropEvent* event) {
  const QList<QUrl> urls = event->mimeData()->urls();
  if (urls.isEmpty() || !urls.first().isLocalFile()) return;
  open(urls.first().toLocalFile());
  event->acceptProposedAction();
}
