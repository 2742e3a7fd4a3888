// mfrview GUI tests (QtTest): the real MainWindow with its docks and the budget plugin, on an X
// server with Mesa llvmpipe. Each test function is one ctest test (tests/app/CMakeLists.txt).
#include <QCheckBox>
#include <QComboBox>
#include <QDockWidget>
#include <QDoubleSpinBox>
#include <QLineEdit>
#include <QMessageBox>
#include <QProcess>
#include <QSlider>
#include <QSpinBox>
#include <QStandardPaths>
#include <QSurfaceFormat>
#include <QTemporaryDir>
#include <QTreeWidget>
#include <QtTest>

#include <algorithm>
#include <cstdlib>

#include "camera_navigator.hpp"
#include "main_window.hpp"
#include "mfr/image.hpp"
#include "mfr/methods/registry.hpp"
#include "render_view.hpp"
#include "viewer_model.hpp"

namespace {

constexpr int kTimeoutMs = 120000;
constexpr double kMiB = 1024.0 * 1024.0;

// Waits until no new frame has been drawn for a moment and no background work runs: the
// budget plugin's corrections and the oracle's image arrive asynchronously.
void settle(ViewerModel& model) {
  QElapsedTimer clock;
  clock.start();
  quint64 frames = model.framesRendered();
  int quiet = 0;
  while (quiet < 3 && clock.elapsed() < kTimeoutMs) {
    QTest::qWait(150);
    if (model.framesRendered() != frames || model.busy()) {
      frames = model.framesRendered();
      quiet = 0;
    } else {
      ++quiet;
    }
  }
}

// Largest per-channel difference of two same-size images; -1 when the sizes differ.
int maxChannelDifference(const mfr::ImageRGBA8& a, const mfr::ImageRGBA8& b) {
  if (a.width != b.width || a.height != b.height) return -1;
  int diff = 0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i) diff = std::max(diff, std::abs(a.pixels[i] - b.pixels[i]));
  return diff;
}

mfr::ImageRGBA8 fromQImage(const QImage& image) {
  const QImage rgba = image.convertToFormat(QImage::Format_RGBA8888);
  mfr::ImageRGBA8 out(rgba.width(), rgba.height());
  for (int y = 0; y < rgba.height(); ++y)
    std::copy_n(rgba.constScanLine(y), rgba.width() * 4, out.at(0, y));
  return out;
}

// Runs a program; returns its exit code (output kept for failure messages).
int runProgram(const QString& program, const QStringList& args, QString* output) {
  QProcess p;
  p.setProcessChannelMode(QProcess::MergedChannels);
  p.start(program, args);
  if (!p.waitForFinished(kTimeoutMs)) return -1;
  *output = QString::fromUtf8(p.readAll());
  return p.exitStatus() == QProcess::NormalExit ? p.exitCode() : -1;
}

}  // namespace

class ViewerTest : public QObject {
  Q_OBJECT

 public:
  static void initMain() {
    QSurfaceFormat format;
    format.setVersion(4, 5);
    format.setProfile(QSurfaceFormat::CoreProfile);
    QSurfaceFormat::setDefaultFormat(format);
  }

 private:
  std::unique_ptr<MainWindow> openWindow(const QString& scene = QStringLiteral("@sample")) {
    auto w = std::make_unique<MainWindow>(MainWindow::Options{.restoreSettings = false, .loadPlugins = true});
    w->resize(1100, 700);
    w->show();
    if (!QTest::qWaitForWindowExposed(w.get())) return nullptr;
    if (!scene.isEmpty()) {
      w->openScene(scene);
      if (!QTest::qWaitFor([&] { return w->model().hasScene() && w->model().framesRendered() > 0; }, kTimeoutMs)) return nullptr;
      settle(w->model());
    }
    return w;
  }

 private slots:
  void initTestCase() { QStandardPaths::setTestModeEnabled(true); }

  void openSample() {
    auto w = openWindow();
    QVERIFY(w);
    ViewerModel& m = w->model();
    QCOMPARE(m.scene().objects.size(), std::size_t{6});
    QVERIFY2(m.renderError().isEmpty(), qPrintable(m.renderError()));
    QCOMPARE(QString::fromStdString(m.stats().method), m.method());
    QVERIFY(m.stats().bytesAllocated > 0);
    QVERIFY(m.stats().fragmentsGenerated > 0);
    QCOMPARE(w->findChild<QTreeWidget*>("sceneTree")->topLevelItemCount(), 6);
    QVERIFY(w->findChild<QTreeWidget*>("statsTree")->topLevelItemCount() >= 4);
    // The budget plugin is found through MFR_PLUGIN_PATH and its panel is docked.
    QVERIFY2(w->findChild<QDockWidget*>("plugin-budget"), "budget plugin not loaded");
    QVERIFY(w->findChild<QSlider*>("budgetSlider"));
  }

  void switchMethods() {
    auto w = openWindow();
    QVERIFY(w);
    ViewerModel& m = w->model();
    auto* combo = w->findChild<QComboBox*>("methodCombo");
    QVERIFY(combo);
    QCOMPARE(combo->count(), static_cast<int>(mfr::methodRegistry().size()) + 1);  // + oracle
    for (int i = 0; i < combo->count(); ++i) {
      const QString name = combo->itemData(i).toString();
      combo->setCurrentIndex(i);
      QCOMPARE(m.method(), name);
      QTRY_VERIFY_WITH_TIMEOUT(QString::fromStdString(m.stats().method) == name, kTimeoutMs);
      QVERIFY2(m.renderError().isEmpty(), qPrintable(name + ": " + m.renderError()));
      QVERIFY2(m.stats().fragmentsGenerated > 0, qPrintable(name));
      // One generated editor per parameter, of the type its ParamSpec asks for.
      if (const mfr::MethodInfo* info = m.methodInfo(name)) {
        for (const mfr::ParamSpec& spec : info->params) {
          QWidget* editor = w->findChild<QWidget*>(QStringLiteral("param-") + QString::fromStdString(spec.name));
          QVERIFY2(editor, qPrintable(name + ": no editor for " + QString::fromStdString(spec.name)));
          switch (spec.type) {
            case mfr::ParamSpec::Type::Int: QVERIFY(qobject_cast<QSpinBox*>(editor)); break;
            case mfr::ParamSpec::Type::Float: QVERIFY(qobject_cast<QDoubleSpinBox*>(editor)); break;
            case mfr::ParamSpec::Type::Bool: QVERIFY(qobject_cast<QCheckBox*>(editor)); break;
            case mfr::ParamSpec::Type::Choice: QVERIFY(qobject_cast<QComboBox*>(editor)); break;
            case mfr::ParamSpec::Type::Text: QVERIFY(qobject_cast<QLineEdit*>(editor)); break;
          }
        }
      }
    }
    // A generated editor drives the method: k of the k-buffer.
    combo->setCurrentIndex(combo->findData(QStringLiteral("kbuffer")));
    auto* k = w->findChild<QSpinBox*>("param-k");
    QVERIFY(k);
    k->setValue(3);
    QTRY_VERIFY_WITH_TIMEOUT(m.stats().method == "kbuffer" && m.stats().kMax == 3, kTimeoutMs);
  }

  void budgetSliderFollowsMemory() {
    auto w = openWindow();
    QVERIFY(w);
    ViewerModel& m = w->model();
    auto* slider = w->findChild<QSlider*>("budgetSlider");
    QVERIFY(slider);
    const double pixels = static_cast<double>(m.renderSize().width()) * m.renderSize().height();
    for (const QString method : {"kplus-array", "abuffer-ll", "abuffer-array", "kplus-dynamic", "kbuffer"}) {
      m.setMethod(method);
      settle(m);
      quint64 previous = 0;
      for (int budget : {8, 16, 32, 64}) {
        slider->setValue(budget);
        settle(m);
        const mfr::Stats& s = m.stats();
        QCOMPARE(QString::fromStdString(s.method), method);
        QVERIFY2(m.renderError().isEmpty(), qPrintable(m.renderError()));
        const double allocated = static_cast<double>(s.bytesAllocated);
        qInfo("%s at %d MiB (%.0f pixels): %.2f MiB allocated, %.1f %% of fragments captured", qPrintable(method), budget,
              pixels, allocated / kMiB, 100.0 * static_cast<double>(s.fragmentsStored) / static_cast<double>(s.fragmentsGenerated));
        QVERIFY2(allocated <= budget * kMiB, qPrintable(QStringLiteral("%1 over budget: %2 MiB > %3 MiB").arg(method).arg(allocated / kMiB).arg(budget)));
        QVERIFY2(s.bytesAllocated >= previous, "memory does not follow the budget");
        // Fixed-structure methods use most of the budget (one k step of 8 B/pixel at most left).
        if (method == "kplus-array" || method == "abuffer-array" || method == "kbuffer")
          QVERIFY(allocated > budget * kMiB - 8.0 * pixels - 1.0 * kMiB);
        if (method == "abuffer-ll") QVERIFY(allocated > 0.9 * budget * kMiB);
        previous = s.bytesAllocated;
      }
    }
  }

  void badFileKeepsScene() {
    auto w = openWindow();
    QVERIFY(w);
    ViewerModel& m = w->model();
    const std::string sceneName = m.scene().name;
    QTemporaryDir dir;
    const QString broken = dir.filePath("broken.stl");
    QFile f(broken);
    QVERIFY(f.open(QIODevice::WriteOnly));
    f.write("solid nothing\n  facet normal 0 0 1\n    outer loop\n      vertex 0 0\n");
    f.close();
    for (const QString& path : {broken, dir.filePath("missing.ply")}) {
      w->openScene(path);
      QTRY_VERIFY_WITH_TIMEOUT(!m.isLoading(), kTimeoutMs);
      QVERIFY2(w->lastError().contains(QFileInfo(path).fileName()), qPrintable(w->lastError()));
      auto* box = w->findChild<QMessageBox*>("errorBox");
      QVERIFY(box && box->isVisible());
      QVERIFY(box->text().contains(QFileInfo(path).fileName()));
      box->close();
      QTest::qWait(50);
      QCOMPARE(m.scene().name, sceneName);
      QCOMPARE(m.scene().objects.size(), std::size_t{6});
    }
    // The scene still renders.
    const quint64 frames = m.framesRendered();
    m.setCamera(navigation::orbit(m.camera(), QPointF(20, 0), m.renderSize()));
    QTRY_VERIFY_WITH_TIMEOUT(m.framesRendered() > frames, kTimeoutMs);
    QVERIFY(m.renderError().isEmpty());
  }

  void sessionRoundTrip() {
    QTemporaryDir dir;
    const QString sessionPath = dir.filePath("test.mfrsession");
    const QSize size(240, 180);
    mfr::ImageRGBA8 before;
    {
      auto w = openWindow();
      QVERIFY(w);
      ViewerModel& m = w->model();
      m.setMethod("kbuffer");
      m.setParams({{"k", "5"}});
      m.setCamera(navigation::orbit(m.camera(), QPointF(37, -21), QSize(400, 300)));
      m.setObjectVisible(1, false);
      m.setObjectMaterial(2, glm::vec4(0.2f, 0.6f, 0.9f, 0.45f));
      settle(m);
      before = w->view().renderImage(size);
      w->saveSession(sessionPath);
    }
    auto w = openWindow(QString());
    QVERIFY(w);
    w->openSession(sessionPath);
    ViewerModel& m = w->model();
    QTRY_VERIFY_WITH_TIMEOUT(m.hasScene() && m.method() == "kbuffer" && m.framesRendered() > 0, kTimeoutMs);
    settle(m);
    QCOMPARE(m.params().at("k"), std::string("5"));
    QVERIFY(!m.scene().objects[1].visible);
    const mfr::ImageRGBA8 after = w->view().renderImage(size);
    QCOMPARE(maxChannelDifference(before, after), 0);
  }

  // `mfrview --screenshot` and `mfr render` with the same scene, view, size and settings.
  void viewerScreenshotEqualsCli() {
    QTemporaryDir dir;
    const QList<QStringList> cases{
        {"--method", "abuffer-ll", "--view", "iso"},
        {"--method", "kbuffer", "-p", "k=6", "--view", "front"},
        {"--method", "kplus-dynamic", "-p", "budget_mib=2"},
        {"--method", "wboit", "--view", "iso"},
        {"--method", "peel-dual", "--view", "iso"},
        {"--method", "oracle", "--view", "iso"},
    };
    int worst = 0;
    for (const QStringList& c : cases) {
      const QString viewerPng = dir.filePath("viewer.png"), cliPng = dir.filePath("cli.png");
      QString out;
      const QStringList common = QStringList{"--size", "200x150"} + c;
      QCOMPARE(runProgram(MFRVIEW, QStringList{"@sample", "--screenshot", viewerPng} + common, &out), 0);
      QCOMPARE(runProgram(MFR_CLI, QStringList{"render", "@sample", "-o", cliPng} + common, &out), 0);
      const int diff = maxChannelDifference(mfr::readPng(viewerPng.toStdString()), mfr::readPng(cliPng.toStdString()));
      qInfo("%s: max channel difference %d", qPrintable(c.join(' ')), diff);
      QVERIFY2(diff >= 0 && diff <= 1, qPrintable(c.join(' ')));
      worst = std::max(worst, diff);
    }
    qInfo("viewer --screenshot vs mfr render: max channel difference %d over %lld cases", worst, static_cast<long long>(cases.size()));
  }

  // The live widget's framebuffer (GpuRenderer::renderTo into QOpenGLWidget's FBO) against the
  // CLI at the widget's size.
  void widgetEqualsCli() {
    auto w = openWindow();
    QVERIFY(w);
    ViewerModel& m = w->model();
    w->view().setFixedSize(256, 192);
    QTRY_COMPARE_WITH_TIMEOUT(m.renderSize(), QSize(256, 192), kTimeoutMs);
    QTemporaryDir dir;
    int worst = 0;
    for (const auto& [method, param] : {std::pair{"kplus-array", "k=6"}, std::pair{"abuffer-ll", ""}, std::pair{"mboit", ""}}) {
      m.setMethod(method);
      m.setAllParams({});
      if (*param) m.setParams({{"k", "6"}});
      m.setCamera(m.scene().view("iso"));
      settle(m);
      QCOMPARE(QString::fromStdString(m.stats().method), QString(method));
      const mfr::ImageRGBA8 widget = fromQImage(w->view().grabFramebuffer());
      const QString cliPng = dir.filePath("cli.png");
      QStringList args{"render", "@sample", "--method", method, "--view", "iso", "--size", "256x192", "-o", cliPng};
      if (*param) args << "-p" << param;
      QString out;
      QCOMPARE(runProgram(MFR_CLI, args, &out), 0);
      const int diff = maxChannelDifference(widget, mfr::readPng(cliPng.toStdString()));
      qInfo("widget vs mfr render, %s: max channel difference %d", method, diff);
      QVERIFY2(diff >= 0 && diff <= 1, method);
      worst = std::max(worst, diff);
    }
    qInfo("widget vs mfr render: max channel difference %d", worst);
  }

  void navigation() {
    mfr::Camera c;
    c.eye = {0, 0, 5};
    c.target = {0, 0, 0};
    const QSize view(400, 300);
    const mfr::Camera o = navigation::orbit(c, QPointF(100, 40), view);
    QCOMPARE(qRound(glm::length(o.eye - o.target) * 1e6), qRound(5e6));  // orbit keeps the distance
    QVERIFY(glm::length(o.eye - c.eye) > 0.1);
    const mfr::Camera p = navigation::pan(c, QPointF(50, 0), view);
    QVERIFY(p.target.x < 0 && p.eye.x < 0);  // dragging right moves the scene right
    const mfr::Camera centreZoom = navigation::zoomAt(c, QPointF(200, 150), view, 1.0);
    QVERIFY(glm::length(centreZoom.eye - centreZoom.target) < 5.0);
    QVERIFY(glm::length(centreZoom.target) < 1e-12);  // zoom at the centre keeps the target
    const mfr::Camera ortho = navigation::toggledProjection(c);
    QCOMPARE(ortho.projection, mfr::Projection::Orthographic);
    const mfr::Camera back = navigation::toggledProjection(ortho);
    QVERIFY(glm::length(back.eye - c.eye) < 1e-9);  // the round trip keeps the framing
  }
};

QTEST_MAIN(ViewerTest)
#include "test_viewer.moc"
