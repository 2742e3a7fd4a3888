// mfrview GUI tests (QtTest): the real MainWindow with its docks and the budget plugin, on an X
// server with Mesa llvmpipe. Each test function is one ctest test (tests/app/CMakeLists.txt).
#include <QAction>
#include <QCheckBox>
#include <QColorDialog>
#include <QComboBox>
#include <QDockWidget>
#include <QDoubleSpinBox>
#include <QHeaderView>
#include <QInputDialog>
#include <QJsonArray>
#include <QLineEdit>
#include <QLabel>
#include <QListWidget>
#include <QMessageBox>
#include <QPlainTextEdit>
#include <QFile>
#include <QProcess>
#include <QProgressBar>
#include <QRegularExpression>
#include <QScrollArea>
#include <QScrollBar>
#include <QPushButton>
#include <QScopeGuard>
#include <QSignalSpy>
#include <QSlider>
#include <QSpinBox>
#include <QStatusBar>
#include <QStandardPaths>
#include <QSurfaceFormat>
#include <QStyledItemDelegate>
#include <QTableWidget>
#include <QTemporaryDir>
#include <QTreeWidget>
#include <QtTest>

#include <algorithm>
#include <charconv>
#include <system_error>
#include <cmath>
#include <functional>
#include <map>
#include <set>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <vector>
#include <fstream>

#include <sys/stat.h>
#include <unistd.h>

#include "camera_navigator.hpp"
#include "main_window.hpp"
#include "probe_panel.hpp"
#include "session.hpp"
#include "mfr/scene/sample.hpp"
#include "mfr/scene/color_map.hpp"
#include "mfr/scene/measure.hpp"
#include "mfr/scene/section.hpp"
#include "mfr/image.hpp"
#include "mfr/io/load.hpp"
#include "mfr/methods/registry.hpp"
#include "mfr/reference/composite.hpp"
#include "mfr/reference/metrics.hpp"
#include "mfr/reference/oracle.hpp"
#include "mfr/render.hpp"
#include "mfr/scene/scene_file.hpp"
#include "render_view.hpp"
#include "view_overlays.hpp"
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

// Counts the size hints an item view asks for: filling rows should ask for each a few times, not
// once per row for every changed cell (what made thousands of rows freeze the window).
class SizeHintCounter final : public QStyledItemDelegate {
 public:
  using QStyledItemDelegate::QStyledItemDelegate;
  QSize sizeHint(const QStyleOptionViewItem& option, const QModelIndex& index) const override {
    ++calls;
    return QStyledItemDelegate::sizeHint(option, index);
  }
  mutable long long calls = 0;
};

// The pixel of `area` with the longest list whose order is defined (no edge, no depth tie), or
// (-1, -1) when there is none.
QPoint deepestPixel(const mfr::FragmentLists& lists, const QRect& area) {
  QPoint deep(-1, -1);
  for (int y = area.top(); y <= area.bottom(); ++y)
    for (int x = area.left(); x <= area.right(); ++x)
      if (!lists.isAmbiguous(x, y) && (deep.x() < 0 || lists.count(x, y) > lists.count(deep.x(), deep.y())))
        deep = QPoint(x, y);
  return deep;
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
  for (int y = 0; y < rgba.height(); ++y) std::copy_n(rgba.constScanLine(y), rgba.width() * 4, out.at(0, y));
  return out;
}

mfr::ImageRGBA8 crop(const mfr::ImageRGBA8& image, const QRect& r) {
  mfr::ImageRGBA8 out(r.width(), r.height());
  for (int y = 0; y < r.height(); ++y) std::copy_n(image.at(r.x(), r.y() + y), r.width() * 4, out.at(0, y));
  return out;
}

// The exact image (oracle, "over" of every fragment) of the model's scene and camera.
mfr::ImageRGBA8 exactImage(const ViewerModel& m, QSize size) {
  mfr::RenderRequest request;
  request.width = size.width();
  request.height = size.height();
  return mfr::render(m.scene(), m.camera(), request).image;
}

// A binary STL of `triangles` small triangles in rows (a flat strip), for loading tests.
void writeBinaryStl(const QString& path, int triangles) {
  QByteArray data(80, '\0');
  const auto append = [&data](const void* p, int n) { data.append(static_cast<const char*>(p), n); };
  const auto count = static_cast<quint32>(triangles);
  append(&count, 4);
  for (int i = 0; i < triangles; ++i) {
    const float x = static_cast<float>(i % 400) * 0.01f, y = static_cast<float>(i / 400) * 0.01f;
    const float v[12] = {0, 0, 1, x, y, 0, x + 0.01f, y, 0, x, y + 0.01f, 0};
    append(v, sizeof v);
    const quint16 attributes = 0;
    append(&attributes, 2);
  }
  QFile f(path);
  if (f.open(QIODevice::WriteOnly)) f.write(data);
}

// A .mfrscene of `objects` copies of one model file (and one primitive, which loads no file).
// One object per model file (a file placed twice is read once), and a ball.
void writeSceneFile(const QString& path, const QStringList& models) {
  QString json = QStringLiteral("{\"name\": \"%1\", \"objects\": [").arg(QFileInfo(path).baseName());
  for (int i = 0; i < models.size(); ++i)
    json += QStringLiteral("{\"name\": \"part %1\", \"file\": \"%2\", \"transform\": {\"translate\": [0, 0, %1]}},")
                .arg(i)
                .arg(QFileInfo(models[i]).fileName());
  json += QStringLiteral("{\"name\": \"ball\", \"primitive\": {\"type\": \"sphere\", \"radius\": 0.5}}]}");
  QFile f(path);
  if (f.open(QIODevice::WriteOnly)) f.write(json.toUtf8());
}

// A small volume scene for the transfer-function editor tests, written into `dir`: blob.vti (20³
// points, spacing 0.1, a Gaussian blob with values in (0, 1)), a translucent ball beside it, the view
// "iso", and `transfer` as the volume's transfer function (numbers written to round-trip exactly).
QString writeBlobScene(const QTemporaryDir& dir, const QString& name, const mfr::TransferFunction& transfer) {
  const QString vti = dir.filePath(QStringLiteral("blob.vti"));
  if (!QFile::exists(vti)) {
    constexpr int n = 20;
    QString values;
    for (int k = 0; k < n; ++k)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          const double dx = 0.1 * i - 0.95, dy = 0.1 * j - 0.95, dz = 0.1 * k - 0.95;
          values += QString::number(std::exp(-(dx * dx + dy * dy + dz * dz) / (2 * 0.35 * 0.35)), 'g', 9) + ' ';
        }
    QFile f(vti);
    if (!f.open(QIODevice::WriteOnly)) return {};
    f.write(QStringLiteral("<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"0.1\" "
                           "byte_order=\"LittleEndian\">\n<ImageData WholeExtent=\"0 19 0 19 0 19\" Origin=\"0 0 0\" "
                           "Spacing=\"0.1 0.1 0.1\">\n<Piece Extent=\"0 19 0 19 0 19\"><PointData><DataArray "
                           "type=\"Float32\" Name=\"blob\" format=\"ascii\">%1</DataArray></PointData><CellData>"
                           "</CellData></Piece>\n</ImageData>\n</VTKFile>\n")
                .arg(values)
                .toUtf8());
  }
  QJsonArray points;
  for (const mfr::TransferPoint& p : transfer.points)
    points.append(QJsonArray{p.value, p.color.r, p.color.g, p.color.b, p.color.a});
  const QJsonObject ball{{"name", "ball"},
                         {"primitive", QJsonObject{{"type", "sphere"}, {"radius", 0.35}}},
                         {"color", QJsonArray{0.9, 0.3, 0.2}},
                         {"opacity", 0.5},
                         {"transform", QJsonObject{{"translate", QJsonArray{1.5, 1.3, 1.4}}}}};
  const QJsonObject volume{{"name", "blob"},
                           {"file", "blob.vti"},
                           {"transfer", QJsonObject{{"points", points}, {"unit_distance", transfer.unitDistance}}}};
  const QJsonObject iso{
      {"name", "iso"}, {"eye", QJsonArray{4.0, 3.0, 5.0}}, {"target", QJsonArray{0.95, 0.95, 0.95}}, {"fit", true}};
  const QJsonObject scene{
      {"name", "blob"}, {"objects", QJsonArray{ball}}, {"volumes", QJsonArray{volume}}, {"views", QJsonArray{iso}}};
  const QString path = dir.filePath(name);
  QFile f(path);
  if (!f.open(QIODevice::WriteOnly)) return {};
  f.write(QJsonDocument(scene).toJson());
  return path;
}

// The blob scene's function as loaded: transparent black at 0, opaque warm white at 1.
mfr::TransferFunction blobTransfer() {
  mfr::TransferFunction t;
  t.unitDistance = 0.2;
  t.points = {{0.0, {0.0f, 0.0f, 0.2f, 0.0f}}, {1.0, {1.0f, 0.9f, 0.6f, 0.8f}}};
  return t;
}

// The Volume panel's transfer-function editor, reached through its meta-object (the plugin is not
// linked into the tests): its value↔pixel mapping and what it shows.
struct EditorProbe {
  QWidget* editor = nullptr;

  [[nodiscard]] double call(const char* name, double arg) const {
    double result = std::nan("");
    QMetaObject::invokeMethod(editor, name, Qt::DirectConnection, Q_RETURN_ARG(double, result), Q_ARG(double, arg));
    return result;
  }
  [[nodiscard]] double x(double value) const { return call("xForValue", value); }
  [[nodiscard]] double y(double opacity) const { return call("yForOpacity", opacity); }
  [[nodiscard]] double value(double x) const { return call("valueForX", x); }
  [[nodiscard]] double opacity(double y) const { return call("opacityForY", y); }
  // The pixel nearest (value, opacity).
  [[nodiscard]] QPoint at(double value, double opacity) const {
    return {static_cast<int>(std::lround(x(value))), static_cast<int>(std::lround(y(opacity)))};
  }
  [[nodiscard]] QPoint at(const mfr::TransferPoint& p) const { return at(p.value, p.color.a); }
  [[nodiscard]] QRectF plot() const {
    QRectF r;
    QMetaObject::invokeMethod(editor, "plotRect", Qt::DirectConnection, Q_RETURN_ARG(QRectF, r));
    return r;
  }
  // One pixel's worth of value (over the function's range) and of opacity.
  [[nodiscard]] double valuePixel(const mfr::TransferFunction& t) const {
    return (t.high() - t.low()) / plot().width();
  }
  [[nodiscard]] double opacityPixel() const { return 1.0 / plot().height(); }
  [[nodiscard]] int selected() const {
    int index = -2;
    QMetaObject::invokeMethod(editor, "selectedPoint", Qt::DirectConnection, Q_RETURN_ARG(int, index));
    return index;
  }
  [[nodiscard]] QList<quint64> histogram() const {
    QList<quint64> counts;
    QMetaObject::invokeMethod(editor, "histogramCounts", Qt::DirectConnection, Q_RETURN_ARG(QList<quint64>, counts));
    return counts;
  }
  void drag(const QPoint& from, const QPoint& to) const {
    QTest::mousePress(editor, Qt::LeftButton, {}, from);
    // Through a point halfway, as a hand would: the editor follows every move.
    QTest::mouseMove(editor, (from + to) / 2);
    QTest::mouseMove(editor, to);
    QTest::mouseRelease(editor, Qt::LeftButton, {}, to);
  }
};

// Counts of the grid's values in `bins` equal bins over [low, high], computed here as
// ViewerContext::volumeHistogram documents it (v = high in the last bin, values outside skipped).
std::vector<std::uint64_t> histogramOf(const mfr::VolumeGrid& grid, double low, double high, int bins) {
  std::vector<std::uint64_t> counts(static_cast<std::size_t>(bins), 0);
  const double width = (high - low) / bins;
  for (const float value : grid.values) {
    const double v = value;
    if (v < low || v > high) continue;
    // By the bin width rather than the documented (v - low) / (high - low) · bins: the tests use
    // power-of-two widths, where both are exact, so any difference is the viewer's.
    int b = static_cast<int>(std::floor((v - low) / width));
    b = std::clamp(b, 0, bins - 1);
    ++counts[static_cast<std::size_t>(b)];
  }
  return counts;
}

bool samePoints(const mfr::TransferFunction& a, const mfr::TransferFunction& b) {
  if (a.points.size() != b.points.size() || a.unitDistance != b.unitDistance) return false;
  for (std::size_t i = 0; i < a.points.size(); ++i)
    if (a.points[i].value != b.points[i].value || a.points[i].color != b.points[i].color) return false;
  return true;
}

bool ascending(const mfr::TransferFunction& t) {
  for (std::size_t i = 1; i < t.points.size(); ++i)
    if (!(t.points[i].value > t.points[i - 1].value)) return false;
  return true;
}

// Every fraction a loader reports; optionally cancels at report number `cancelAt` (1-based).
struct ProgressRecorder {
  std::vector<double> fractions;
  std::size_t cancelAt = 0;
  mfr::LoadProgress progress() {
    return {[this](double f) {
      fractions.push_back(f);
      return cancelAt == 0 || fractions.size() < cancelAt;
    }};
  }
  [[nodiscard]] bool monotonic() const { return std::is_sorted(fractions.begin(), fractions.end()); }
};

// A stats note's number, read back exactly (notes are the shortest text of the double, written by
// std::to_chars; from_chars reads it whatever the locale); NaN when the note is missing or not a
// number, which compares unequal to anything.
double numberOf(const std::string& note) {
  double v = 0.0;
  const auto [end, ec] = std::from_chars(note.data(), note.data() + note.size(), v);
  return ec == std::errc() && end == note.data() + note.size() && !note.empty() ? v : std::nan("");
}

// Runs a program; returns its exit code (output kept for failure messages).
// The loaded plugin of that id, or null.
MfrViewerPlugin* loadedPlugin(const MainWindow& window, const QString& id) {
  for (const PluginRecord& r : window.plugins().records())
    if (r.plugin && r.id == id) return r.plugin;
  return nullptr;
}

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
  // The sum of a Probe dock column's "N %" cells (fragments and background).
  static double columnPercent(const QTableWidget& table, int column) {
    double total = 0.0;
    for (int i = 0; i < table.rowCount(); ++i)
      total += table.item(i, column)->text().remove(QStringLiteral(" %")).toDouble();
    return total;
  }

  // The view at `size`, abuffer-ll from the scene's "iso" view, settled and drawn without error.
  static bool showAbufferIso(MainWindow& w, QSize size) {
    ViewerModel& m = w.model();
    w.view().setFixedSize(size);
    if (!QTest::qWaitFor([&] { return m.renderSize() == size; }, kTimeoutMs)) return false;
    m.setMethod("abuffer-ll");
    m.setCamera(m.scene().view("iso"));
    settle(m);
    if (!m.renderError().isEmpty()) qWarning("render error: %s", qPrintable(m.renderError()));
    return m.renderError().isEmpty();
  }

  // A 12³ .vti (spacing 0.1 from the origin) with two point-data arrays, each a function of the
  // grid index (i, j, k). Returns false when it cannot be written.
  static bool writeTwoArrayVti(const QString& path, const QString& firstName,
                               const std::function<double(int, int, int)>& first, const QString& secondName,
                               const std::function<double(int, int, int)>& second) {
    constexpr int n = 12;
    QString a, b;
    for (int k = 0; k < n; ++k)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          a += QString::number(first(i, j, k), 'g', 9) + ' ';
          b += QString::number(second(i, j, k), 'g', 9) + ' ';
        }
    QFile f(path);
    if (!f.open(QIODevice::WriteOnly)) return false;
    f.write(QStringLiteral("<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"0.1\" "
                           "byte_order=\"LittleEndian\">\n<ImageData WholeExtent=\"0 11 0 11 0 11\" "
                           "Origin=\"0 0 0\" Spacing=\"0.1 0.1 0.1\">\n<Piece Extent=\"0 11 0 11 0 11\">"
                           "<PointData><DataArray type=\"Float32\" Name=\"%1\" format=\"ascii\">%2</DataArray>"
                           "<DataArray type=\"Float32\" Name=\"%3\" format=\"ascii\">%4</DataArray></PointData>"
                           "<CellData></CellData></Piece>\n</ImageData>\n</VTKFile>\n")
                .arg(firstName, a, secondName, b)
                .toUtf8());
    return true;
  }

  // Saves w's session to `path` and opens it in a new window whose view is `size` (null when no
  // window could be made).
  std::unique_ptr<MainWindow> reopenedSession(MainWindow& w, const QString& path, QSize size) {
    w.saveSession(path);
    auto again = openWindow(QString());
    if (!again) return again;
    again->view().setFixedSize(size);
    again->openSession(path);
    return again;
  }

  // A window on `scene` whose view is `size` device pixels, a point of the widget one pixel of the
  // image (null when no such window could be made).
  std::unique_ptr<MainWindow> openFixedView(QSize size, const QString& scene = QStringLiteral("@sample")) {
    auto w = openWindow(scene);
    if (!w) return w;
    w->view().setFixedSize(size);
    if (!QTest::qWaitFor([&] { return w->model().renderSize() == size; }, kTimeoutMs) ||
        w->view().devicePixelRatioF() != 1.0)
      return nullptr;
    return w;
  }

  std::unique_ptr<MainWindow> openWindow(const QString& scene = QStringLiteral("@sample")) {
    auto w = std::make_unique<MainWindow>(MainWindow::Options{.restoreSettings = false, .loadPlugins = true});
    w->resize(1100, 700);
    w->show();
    if (!QTest::qWaitForWindowExposed(w.get())) return nullptr;
    if (!scene.isEmpty()) {
      w->openScene(scene);
      if (!QTest::qWaitFor([&] { return w->model().hasScene() && w->model().framesRendered() > 0; }, kTimeoutMs))
        return nullptr;
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
    // The Opacity cell's editor keeps the column's three decimals: opened and closed with Enter
    // it changes nothing (0.004 became 0, 0.125 became 0.13: a bug hunt), and 0.125 can be typed.
    auto* tree = w->findChild<QTreeWidget*>("sceneTree");
    w->findChild<QDockWidget*>("sceneDock")->raise();
    m.setObjectOpacity(0, 0.004);
    const auto edit = [&](const char* typed) {
      tree->editItem(tree->topLevelItem(0), 2);
      auto* editor = tree->findChild<QDoubleSpinBox*>();
      QVERIFY(editor);
      if (typed) {
        editor->selectAll();
        QTest::keyClicks(editor, typed);
      }
      QTest::keyClick(editor, Qt::Key_Return);
      QTRY_VERIFY(!tree->findChild<QDoubleSpinBox*>());
    };
    edit(nullptr);
    QVERIFY2(std::abs(m.objectOpacity(0) - 0.004) < 1e-6, qPrintable(QString::number(m.objectOpacity(0))));
    edit("0.125");
    QVERIFY2(std::abs(m.objectOpacity(0) - 0.125) < 1e-6, qPrintable(QString::number(m.objectOpacity(0))));
  }

  void switchMethods() {
    auto w = openWindow();
    QVERIFY(w);
    ViewerModel& m = w->model();
    auto* combo = w->findChild<QComboBox*>("methodCombo");
    QVERIFY(combo);
    QCOMPARE(combo->count(), static_cast<int>(mfr::availableMethods().size()));  // oracle, GPU methods, optimal-k
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
            case mfr::ParamSpec::Type::Int:
              QVERIFY(qobject_cast<QSpinBox*>(editor));
              break;
            case mfr::ParamSpec::Type::Float:
              QVERIFY(qobject_cast<QDoubleSpinBox*>(editor));
              break;
            case mfr::ParamSpec::Type::Bool:
              QVERIFY(qobject_cast<QCheckBox*>(editor));
              break;
            case mfr::ParamSpec::Type::Choice:
              QVERIFY(qobject_cast<QComboBox*>(editor));
              break;
            case mfr::ParamSpec::Type::Text:
              QVERIFY(qobject_cast<QLineEdit*>(editor));
              break;
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
    // A float parameter takes and shows small values and exponents: mboit's bias of the paper,
    // 5e-7, showed and was taken as 0.000 (three decimals: a bug hunt).
    combo->setCurrentIndex(combo->findData(QStringLiteral("mboit")));
    auto* bias = w->findChild<QDoubleSpinBox*>("param-bias");
    QVERIFY(bias);
    bias->setFocus();
    bias->selectAll();
    QTest::keyClicks(bias, "5e-7");
    QTest::keyClick(bias, Qt::Key_Return);
    QCOMPARE(m.params().at("bias"), std::string("5e-07"));
    QCOMPARE(bias->text(), QStringLiteral("5e-07"));
    m.setParams({{"bias", "0.00000025"}});
    QCOMPARE(bias->value(), 2.5e-7);
    QCOMPARE(bias->text(), QStringLiteral("2.5e-07"));
    // A value that cannot render is named as the panel names it, not by mfr's --param option,
    // which no one typed here; the model keeps mfr's words for scripted runs.
    m.setMethod(QStringLiteral("fkb"));
    m.setParams({{"budget_mib", "0.01"}});
    QTRY_VERIFY_WITH_TIMEOUT(!m.renderError().isEmpty(), kTimeoutMs);
    QVERIFY2(m.renderError().startsWith("--param budget_mib=0.01: below what k = 1 needs"),
             qPrintable(m.renderError()));
    const QString shown = w->statusBar()->currentMessage();
    QVERIFY2(shown.startsWith("Cannot render: budget_mib=0.01: below what k = 1 needs"), qPrintable(shown));
    auto* note = w->findChild<QLabel*>("renderErrorNote");
    QVERIFY(note);
    QTRY_VERIFY_WITH_TIMEOUT(note->isVisible(), kTimeoutMs);
    QVERIFY2(note->text().startsWith("Cannot render:\nbudget_mib=0.01: below"), qPrintable(note->text()));
    // The budget panel shows no numbers of the k-buffer's last frame as fkb's.
    auto* bar = w->findChild<QProgressBar*>("memoryBar");
    auto* captured = w->findChild<QLabel*>("capturedLabel");
    QVERIFY(bar && captured);
    QCOMPARE(m.stats().method, std::string("kbuffer"));
    QCOMPARE(bar->format(), QStringLiteral("no frame of fkb"));
    QCOMPARE(captured->text(), QStringLiteral("—"));
    // Nor the Statistics dock or the status bar's frame info; a frame drawn again clears the reason.
    auto* statsTree = w->findChild<QTreeWidget*>("statsTree");
    auto* frameInfo = w->findChild<QLabel*>("frameInfo");
    QVERIFY(statsTree && frameInfo);
    QCOMPARE(statsTree->topLevelItemCount(), 1);
    QCOMPARE(statsTree->topLevelItem(0)->text(0), QStringLiteral("No frame"));
    QVERIFY(statsTree->topLevelItem(0)->text(1).startsWith("budget_mib=0.01: below"));
    QCOMPARE(frameInfo->text(), QStringLiteral("no frame"));
    m.setParams({{"budget_mib", "64"}});
    QTRY_VERIFY_WITH_TIMEOUT(m.renderError().isEmpty() && m.stats().method == "fkb", kTimeoutMs);
    QVERIFY2(!w->statusBar()->currentMessage().startsWith("Cannot render"),
             qPrintable(w->statusBar()->currentMessage()));
    QVERIFY(frameInfo->text().startsWith("fkb"));
    QVERIFY(statsTree->topLevelItemCount() > 1);
    // An operation and the parameter it needs, by the panel's names too.
    m.setMethod(QStringLiteral("kplus-array"));
    m.setParams({{"tail", "false"}});
    m.setOperation(QStringLiteral("hybrid"));
    QTRY_VERIFY_WITH_TIMEOUT(!m.renderError().isEmpty(), kTimeoutMs);
    QCOMPARE(m.renderError(), QStringLiteral("--op hybrid: needs --param tail=true with method kplus-array"));
    QCOMPARE(w->statusBar()->currentMessage(),
             QStringLiteral("Cannot render: operation hybrid: needs tail=true with method kplus-array"));
    // Within the text too (a review): optimal-k's refusal of another operation.
    m.setMethod(QStringLiteral("optimal-k"));
    m.setOperation(QStringLiteral("oit"));
    QTRY_VERIFY_WITH_TIMEOUT(m.renderError().contains("use --op hybrid"), kTimeoutMs);
    QVERIFY2(w->statusBar()->currentMessage().contains("use operation hybrid (or auto)") &&
                 !w->statusBar()->currentMessage().contains("--"),
             qPrintable(w->statusBar()->currentMessage()));
    m.setOperation(QStringLiteral("auto"));
  }

  void budgetSliderFollowsMemory() {
    auto w = openWindow();
    QVERIFY(w);
    ViewerModel& m = w->model();
    auto* slider = w->findChild<QSlider*>("budgetSlider");
    QVERIFY(slider);
    const double pixels = static_cast<double>(m.renderSize().width()) * m.renderSize().height();
    for (const QString method :
         {"kplus-array", "abuffer-ll", "abuffer-array", "kplus-dynamic", "kbuffer", "fkb", "vkb", "dkb"}) {
      m.setMethod(method);
      settle(m);
      quint64 previous = 0;
      // The budget methods, where the budget binds (every fragment fits from ~17 MiB on here).
      const bool budgetMethod = method == "fkb" || method == "vkb" || method == "dkb";
      const std::vector<int> budgets = budgetMethod ? std::vector<int>{8, 12, 16} : std::vector<int>{8, 16, 32, 64};
      for (int budget : budgets) {
        slider->setValue(budget);
        settle(m);
        const mfr::Stats& s = m.stats();
        QCOMPARE(QString::fromStdString(s.method), method);
        QVERIFY2(m.renderError().isEmpty(), qPrintable(m.renderError()));
        const double allocated = static_cast<double>(s.bytesAllocated);
        qInfo("%s at %d MiB (%.0f pixels): %.2f MiB allocated, %.1f %% of fragments captured", qPrintable(method),
              budget, pixels, allocated / kMiB,
              100.0 * static_cast<double>(s.fragmentsStored) / static_cast<double>(s.fragmentsGenerated));
        QVERIFY2(allocated <= budget * kMiB,
                 qPrintable(
                     QStringLiteral("%1 over budget: %2 MiB > %3 MiB").arg(method).arg(allocated / kMiB).arg(budget)));
        QVERIFY2(s.bytesAllocated >= previous, "memory does not follow the budget");
        // Fixed-structure methods use most of the budget (one k step of 8 B/pixel at most left).
        if (method == "kplus-array" || method == "abuffer-array" || method == "kbuffer")
          QVERIFY(allocated > budget * kMiB - 8.0 * pixels - 1.0 * kMiB);
        if (method == "abuffer-ll") QVERIFY(allocated > 0.9 * budget * kMiB);
        // The variable-k buffers use the whole budget unless every fragment already fits.
        if ((method == "vkb" || method == "dkb") && s.fragmentsStored < s.fragmentsGenerated)
          QVERIFY(allocated > 0.99 * budget * kMiB);
        if (budgetMethod) QCOMPARE(QString::fromStdString(s.operation), QStringLiteral("hybrid"));
        // The panel shows where the frame becomes exact: the variable-k methods' own note.
        auto* exactAt = w->findChild<QLabel*>("budgetExactAt");
        QVERIFY(exactAt);
        if (method == "vkb" || method == "dkb") {
          const auto note =
              std::find_if(s.notes.begin(), s.notes.end(), [](const auto& kv) { return kv.first == "exact at"; });
          QVERIFY(note != s.notes.end());
          QTRY_COMPARE_WITH_TIMEOUT(
              exactAt->text(),
              QString::fromStdString(note->second).replace(QStringLiteral(">= "), QStringLiteral("≥ ")), kTimeoutMs);
          QVERIFY(exactAt->text().contains(QStringLiteral("MiB")));
        } else {
          QTRY_COMPARE_WITH_TIMEOUT(exactAt->text(), QStringLiteral("—"), kTimeoutMs);
        }
        previous = s.bytesAllocated;
      }
    }
  }

  // A budget the method cannot draw at: the panel shows no numbers of the last frame, which is no
  // longer on screen ("15.3 of 16 MiB", its k, RMSE and FLIP beside a budget of 1 MiB: a bug
  // hunt), and says why in the bar's tooltip (plugin interface 1.14: frameError); a budget that
  // draws brings them back.
  void budgetPanelShowsNoFrameItCouldNotDraw() {
    auto w = openWindow();
    QVERIFY(w);
    ViewerModel& m = w->model();
    auto* slider = w->findChild<QSlider*>("budgetSlider");
    auto* bar = w->findChild<QProgressBar*>("memoryBar");
    auto* captured = w->findChild<QLabel*>("capturedLabel");
    auto* rmse = w->findChild<QLabel*>("budgetRmse");
    QVERIFY(slider && bar && captured && rmse);
    // The RMSE label says what it measures, then why it has no number (the reason alone replaced
    // the description, which then stayed empty from the first measured frame on; a bug hunt).
    const QString rmseMeans = rmse->toolTip();
    QVERIFY2(rmseMeans.startsWith(QStringLiteral("Root-mean-square RGB error")), qPrintable(rmseMeans));
    m.setMethod(QStringLiteral("vkb"));
    slider->setValue(16);
    settle(m);
    QTRY_VERIFY_WITH_TIMEOUT(rmse->text() != QStringLiteral("—") && rmse->text() != QStringLiteral("computing…"),
                             kTimeoutMs);
    QVERIFY(m.frameError().isEmpty());
    QVERIFY2(bar->format().contains(QStringLiteral(" of 16 MiB (")), qPrintable(bar->format()));
    slider->setValue(1);
    QTRY_VERIFY_WITH_TIMEOUT(!m.frameError().isEmpty(), kTimeoutMs);
    QVERIFY2(m.frameError().startsWith("budget_mib=1: below what vkb needs"), qPrintable(m.frameError()));
    QCOMPARE(m.stats().method, std::string("vkb"));  // the last frame's, still
    QCOMPARE(bar->format(), QStringLiteral("no frame of vkb"));
    QCOMPARE(bar->toolTip(), m.frameError());
    QCOMPARE(bar->value(), 0);
    QCOMPARE(captured->text(), QStringLiteral("—"));
    QCOMPARE(rmse->text(), QStringLiteral("—"));
    QCOMPARE(rmse->toolTip(), rmseMeans + QLatin1Char('\n') + m.frameError());
    slider->setValue(16);
    QTRY_VERIFY_WITH_TIMEOUT(m.frameError().isEmpty() && bar->format().contains(QStringLiteral(" of 16 MiB (")),
                             kTimeoutMs);
    QVERIFY(captured->text() != QStringLiteral("—"));
    QVERIFY(bar->toolTip().isEmpty());
    QTRY_VERIFY_WITH_TIMEOUT(rmse->text() != QStringLiteral("—") && rmse->text() != QStringLiteral("computing…"),
                             kTimeoutMs);
    QCOMPARE(rmse->toolTip(), rmseMeans);
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
      m.setObjectColor(3, QColor(200, 40, 40));  // a chosen colour replaces per-vertex colours
      QVERIFY(!m.scene().objects[3].material.vertexColors);
      settle(m);
      before = w->view().renderImage(size);
      // Compare mode with the second method's own parameters, and the data view.
      m.setMethodOf(1, "kplus-array");
      m.setParamsOf(1, {{"k", "3"}});
      m.setCompareLayout(CompareLayout::Split);
      m.setCompareSplit(0.25);
      m.setCompareDisplay(CompareDisplay::Difference);
      m.setCompareEnabled(true);
      m.setDataView(DataView::Capacity, true);
      w->saveSession(sessionPath);
    }
    auto w = openWindow(QString());
    QVERIFY(w);
    w->view().setFixedSize(size);  // compare mode comes back on: keep its exact images small
    w->openSession(sessionPath);
    ViewerModel& m = w->model();
    QTRY_VERIFY_WITH_TIMEOUT(m.hasScene() && m.method() == "kbuffer" && m.framesRendered() > 0, kTimeoutMs);
    settle(m);
    QCOMPARE(m.params().at("k"), std::string("5"));
    QVERIFY(!m.scene().objects[1].visible);
    QVERIFY(m.scene().objects[2].material.vertexColors);
    QVERIFY(!m.scene().objects[3].material.vertexColors);
    QVERIFY(m.compareEnabled());
    QCOMPARE(m.methodOf(1), QStringLiteral("kplus-array"));
    QCOMPARE(m.paramsOf(1).at("k"), std::string("3"));
    QCOMPARE(m.compareLayout(), CompareLayout::Split);
    QCOMPARE(m.compareSplit(), 0.25);
    QCOMPARE(m.compareDisplay(), CompareDisplay::Difference);
    QVERIFY(m.dataView() == DataView::Capacity && m.dataViewOverImage());
    QVERIFY(w->findChild<QAction*>("actionCompare")->isChecked());
    const mfr::ImageRGBA8 after = w->view().renderImage(size);
    QCOMPARE(maxChannelDifference(before, after), 0);
  }

  // A session's values of the wrong type or range are one line naming the file and the key: they
  // were read as something else without a word ("visible": "no" as visible, a colour of [1, 0, "x"]
  // as black, opacity 5, "method": 3 as the current method, version 99 as 1; found by a bug hunt).
  // An empty value was "not given": --screenshot '' opened the interactive window and never quit
  // (a bug hunt), -m '' drew the default method. A -p name given twice kept the last without a
  // word. Each is one line and exit 2, as mfr refuses them.
  void emptyAndRepeatedOptionsAreRefused() {
    QTemporaryDir dir;
    const QString png = dir.filePath(QStringLiteral("empty.png"));
    // A name that is not UTF-8 (Latin-1 "caf\xE9.png"): Qt read it as "caf\uFFFD.png" and wrote
    // the screenshot there, exit 0 (a bug hunt). Passed as bytes through the shell.
    {
      QProcess p;
      p.setProcessChannelMode(QProcess::MergedChannels);
      p.setWorkingDirectory(dir.path());
      p.start(QStringLiteral("sh"),
              {QStringLiteral("-c"), QStringLiteral("exec \"$0\" @sample --screenshot \"$(printf 'caf\\351.png')\""),
               QStringLiteral(MFRVIEW)});
      QVERIFY(p.waitForFinished(kTimeoutMs));
      QCOMPARE(p.exitCode(), 2);
      QCOMPARE(QString::fromUtf8(p.readAll()).trimmed().split(QLatin1Char('\n')).constLast(),
               QStringLiteral("mfrview: argument 'caf\uFFFD.png' is not valid UTF-8: mfrview reads names as UTF-8 "
                              "(rename the file, or use mfr, which takes any name)"));
      QCOMPARE(QDir(dir.path()).entryList(QDir::Files), QStringList{});
    }
    for (const QString& option :
         {QStringLiteral("--screenshot"), QStringLiteral("--window-screenshot"), QStringLiteral("-m"),
          QStringLiteral("--op"), QStringLiteral("--view"), QStringLiteral("--color-by"), QStringLiteral("--size")}) {
      QStringList args{QStringLiteral("@sample"), option, QString()};
      if (!option.endsWith(QStringLiteral("screenshot"))) args << QStringLiteral("--screenshot") << png;
      QString out;
      QCOMPARE(runProgram(MFRVIEW, args, &out), 2);
      const QString name = option == QStringLiteral("-m") ? QStringLiteral("method") : option.mid(2);
      QCOMPARE(out.trimmed().split(QLatin1Char('\n')).constLast(),
               QStringLiteral("mfrview: --%1: an empty value").arg(name));
    }
    QString out;
    QCOMPARE(
        runProgram(MFRVIEW,
                   {"@sample", "-m", "kplus-array", "-p", "k=4", "-p", "k=2", "--size", "32x32", "--screenshot", png},
                   &out),
        2);
    QCOMPARE(out.trimmed().split(QLatin1Char('\n')).constLast(),
             QStringLiteral("mfrview: --param k=2: 'k' is given twice"));
    QVERIFY(!QFile::exists(png));
    // An unknown option and a missing value are command-line errors too: exit 2, as the docs say
    // (Qt's parser exited 1 for them; a bug hunt).
    for (const auto& [args, line] : QList<std::pair<QStringList, QString>>{
             {{"@sample", "--bogus", "--screenshot", png}, "mfrview: Unknown option 'bogus'."},
             {{"@sample", "--screenshot", png, "--size"}, "mfrview: Missing value after '--size'."},
             // Options of --screenshot alone were taken without a word (a bug hunt).
             {{"@sample", "--window-screenshot", png, "-s", "320x240"},
              "mfrview: --size: only --screenshot uses it (--window-screenshot grabs the window at --window-size)"},
             {{"@sample", "--window-screenshot", png, "--legend"},
              "mfrview: --legend: only --screenshot uses it (--window-screenshot grabs the window at "
              "--window-size)"}}) {
      QCOMPARE(runProgram(MFRVIEW, args, &out), 2);
      QCOMPARE(out.trimmed().split(QLatin1Char('\n')).constLast(), line);
      QVERIFY(!QFile::exists(png));
    }
  }

  // --session FILE opens the session as the positional FILE does: Qt's QGuiApplication took
  // --session and its value for X11 session management, and mfrview drew @sample (exit 0; noted
  // by a session, fixed by taking the option out of argv before Qt sees it).
  void sessionOptionOpensTheSession() {
    QTemporaryDir dir;
    const QString sessionPath = dir.filePath("k.mfrsession");
    {
      auto w = openWindow(QStringLiteral("@csg"));
      QVERIFY(w);
      ViewerModel& m = w->model();
      m.setMethod("kbuffer");
      m.setParams({{"k", "2"}});
      m.setCamera(navigation::orbit(m.camera(), QPointF(37, -21), QSize(400, 300)));
      settle(m);
      w->saveSession(sessionPath);
    }
    const QString positional = dir.filePath("positional.png"), option = dir.filePath("option.png"),
                  joined = dir.filePath("joined.png"), sample = dir.filePath("sample.png");
    QString out;
    QCOMPARE(runProgram(MFRVIEW, {sessionPath, "--size", "64x48", "--screenshot", positional}, &out), 0);
    QCOMPARE(runProgram(MFRVIEW, {"--session", sessionPath, "--size", "64x48", "--screenshot", option}, &out), 0);
    QCOMPARE(runProgram(MFRVIEW, {"--size", "64x48", "--session=" + sessionPath, "--screenshot", joined}, &out), 0);
    QCOMPARE(runProgram(MFRVIEW, {"--size", "64x48", "--screenshot", sample}, &out), 0);
    const mfr::ImageRGBA8 expected = mfr::readPng(positional.toStdString());
    QCOMPARE(maxChannelDifference(expected, mfr::readPng(option.toStdString())), 0);
    // A session under another name is one by what it says ("format"), wherever it is opened from:
    // Open Recent read such a file as a scene (a bug hunt). A scripted run, with a settings folder
    // of its own here, leaves the user's settings (Open Recent) as they were (it added its files).
    const QString renamed = dir.filePath("k.json"), renamedPng = dir.filePath("renamed.png");
    QVERIFY(QFile::copy(sessionPath, renamed));
    QVERIFY(MainWindow::isSessionFile(renamed) && MainWindow::isSessionFile(sessionPath));
    // Whatever the name says (a review: named like a model, it was read as one), and a model that
    // is JSON too is not one.
    const QString likeAModel = dir.filePath("k.gltf");
    QVERIFY(QFile::copy(sessionPath, likeAModel));
    QVERIFY(MainWindow::isSessionFile(likeAModel));
    // However much white space comes first (the first 256 bytes were looked at: review 27).
    const QString indented = dir.filePath("indented.json");
    {
      QFile from(sessionPath), to(indented);
      QVERIFY(from.open(QIODevice::ReadOnly) && to.open(QIODevice::WriteOnly));
      to.write(QByteArray(300, ' ') + "\n\t" + from.readAll());
    }
    QVERIFY(MainWindow::isSessionFile(indented));
    const QString gltf = dir.filePath("empty.gltf");
    {
      QFile f(gltf);
      QVERIFY(f.open(QIODevice::WriteOnly));
      f.write(R"({"asset": {"version": "2.0"}, "extras": {"format": "mfrview-scene"}})");
    }
    QVERIFY(!MainWindow::isSessionFile(gltf));
    QVERIFY(!MainWindow::isSessionFile(QStringLiteral("@csg")) && !MainWindow::isSessionFile(dir.path()));
    const QString config = dir.filePath("config");
    const QByteArray userConfig = qgetenv("XDG_CONFIG_HOME");
    qputenv("XDG_CONFIG_HOME", QFile::encodeName(config));
    const int renamedExit = runProgram(MFRVIEW, {renamed, "--size", "64x48", "--screenshot", renamedPng}, &out);
    qputenv("XDG_CONFIG_HOME", userConfig);
    QCOMPARE(renamedExit, 0);
    QCOMPARE(maxChannelDifference(expected, mfr::readPng(renamedPng.toStdString())), 0);
    QDirIterator written(config, QDir::Files, QDirIterator::Subdirectories);
    while (written.hasNext()) {
      QFile settings(written.next());
      QVERIFY(settings.open(QIODevice::ReadOnly));
      QVERIFY2(!settings.readAll().contains("recentFiles"), qPrintable(settings.fileName()));
    }
    QCOMPARE(maxChannelDifference(expected, mfr::readPng(joined.toStdString())), 0);
    QVERIFY(maxChannelDifference(expected, mfr::readPng(sample.toStdString())) > 8);  // not the default scene
    const QString png = dir.filePath("refused.png");
    // -session is refused on a desktop, where a session manager runs (it was refused only where
    // none ran, a review): a file's name is no session manager's id.
    const QByteArray userSessionManager = qgetenv("SESSION_MANAGER");
    const auto restoreSessionManager = qScopeGuard([&] {
      if (userSessionManager.isNull())
        qunsetenv("SESSION_MANAGER");
      else
        qputenv("SESSION_MANAGER", userSessionManager);
    });
    qputenv("SESSION_MANAGER", "local/mfr-test:@/tmp/.ICE-unix/1,unix/mfr-test:/tmp/.ICE-unix/1");
    for (const auto& [args, line] : QList<std::pair<QStringList, QString>>{
             {{"@sample", "--session", sessionPath, "--screenshot", png},
              QStringLiteral("mfrview: --session %1: a scene is given too (@sample); give one of the two")
                  .arg(sessionPath)},
             {{"--session", sessionPath, "--session", sessionPath, "--screenshot", png},
              QStringLiteral("mfrview: --session %1: more than one session is given").arg(sessionPath)},
             {{"--session=", "--screenshot", png}, QStringLiteral("mfrview: --session: an empty value")},
             {{"--screenshot", png, "--session"}, QStringLiteral("mfrview: Missing value after '--session'.")},
             // One dash is Qt's option (an X11 session id): it opened @sample, exit 0 (a review).
             {{"-session", sessionPath, "--screenshot", png},
              QStringLiteral("mfrview: -session %1: one dash is Qt's X11 session-management option (an id); open a "
                             "session file with --session %1")
                  .arg(sessionPath)},
             {{"-session", "typo.mfrsession", "--screenshot", png},
              QStringLiteral("mfrview: -session typo.mfrsession: one dash is Qt's X11 session-management option (an "
                             "id); open a session file with --session typo.mfrsession")}}) {
      QCOMPARE(runProgram(MFRVIEW, args, &out), 2);
      QCOMPARE(out.trimmed().split(QLatin1Char('\n')).constLast(), line);
      QVERIFY(!QFile::exists(png));
    }
    // A file named like an id (no dot, no slash) is still the user's file; with no session manager
    // nothing hands Qt an id at all.
    QVERIFY(QFile::copy(sessionPath, dir.filePath("plain")));
    const QString cwd = QDir::currentPath();
    QDir::setCurrent(dir.path());
    const auto back = qScopeGuard([&] { QDir::setCurrent(cwd); });
    QCOMPARE(runProgram(MFRVIEW, {"-session", "plain", "--screenshot", png}, &out), 2);
    QVERIFY2(out.contains("mfrview: -session plain: one dash is Qt's"), qPrintable(out));
    // A word that names no file and is no session manager's id is a mistyped --session too (review 27).
    QCOMPARE(runProgram(MFRVIEW, {"-session", "work", "--screenshot", png}, &out), 2);
    QVERIFY2(out.contains("mfrview: -session work: one dash is Qt's"), qPrintable(out));
    // A session manager's own id goes to Qt: libSM's are "2" and a UUID (hyphens), Qt adds its key
    // (they were refused, so no desktop could restore the window; a review).
    const QString smId = QStringLiteral("23d0f1f03-288f-4d21-a140-1edd450bdbc2_1733598000_123456");
    QCOMPARE(runProgram(MFRVIEW, {"-session", smId, "--size", "64x48", "--screenshot", png}, &out), 0);
    QVERIFY2(!out.contains("one dash"), qPrintable(out));
    QVERIFY(QFile::remove(png));
    qunsetenv("SESSION_MANAGER");
    QCOMPARE(runProgram(MFRVIEW, {"-session", "10d4f54d2f000162937474200000016010007_1", "--screenshot", png}, &out),
             2);
    QCOMPARE(out.trimmed().split(QLatin1Char('\n')).constLast(),
             QStringLiteral("mfrview: -session 10d4f54d2f000162937474200000016010007_1: one dash is Qt's X11 "
                            "session-management option (an id, and no session manager runs); open a session file "
                            "with --session 10d4f54d2f000162937474200000016010007_1"));
    QVERIFY(!QFile::exists(png));
    // A screenshot is never written over the session or scene read, nor both to one file, by any
    // name: a link named like a PNG wrote the picture over its session, exit 0 (a bug hunt), as
    // mfr render refuses its own outputs over its inputs.
    const QString link = dir.filePath("link.png");
    QVERIFY(QFile::link(sessionPath, link));
    QFile sessionFile(sessionPath);
    QVERIFY(sessionFile.open(QIODevice::ReadOnly));
    const QByteArray sessionBytes = sessionFile.readAll();
    sessionFile.close();
    const QString twice = dir.filePath("twice.png");
    for (const auto& [args, line] : QList<std::pair<QStringList, QString>>{
             {{sessionPath, "--size", "64x48", "--screenshot", link},
              QStringLiteral("mfrview: --screenshot %1: is the same file as session (%2): the command would write "
                             "over what it reads")
                  .arg(link, sessionPath)},
             {{"--session", link, "--size", "64x48", "--window-screenshot", sessionPath},
              QStringLiteral("mfrview: --window-screenshot %1: is the same file as session (%2): the command would "
                             "write over what it reads")
                  .arg(sessionPath, link)},
             {{"@sample", "--size", "64x48", "--screenshot", twice, "--window-screenshot", twice},
              QStringLiteral("mfrview: --window-screenshot %1: is the same file as --screenshot (%1): both would be "
                             "written to it")
                  .arg(twice)}}) {
      QCOMPARE(runProgram(MFRVIEW, args, &out), 2);
      QCOMPARE(out.trimmed().split(QLatin1Char('\n')).constLast(), line);
      QVERIFY(sessionFile.open(QIODevice::ReadOnly));
      QCOMPARE(sessionFile.readAll(), sessionBytes);
      sessionFile.close();
      QVERIFY(!QFile::exists(twice));
    }
    // Nor over the scene file a session names (a review).
    const QString model = dir.filePath("model.stl"), modelSession = dir.filePath("model.mfrsession");
    const QByteArray stl =
        "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
        "endloop\nendfacet\nendsolid t\n";
    QFile modelFile(model);
    QVERIFY(modelFile.open(QIODevice::WriteOnly) && modelFile.write(stl) == stl.size());
    modelFile.close();
    QFile modelSessionFile(modelSession);
    QVERIFY(modelSessionFile.open(QIODevice::WriteOnly));
    modelSessionFile.write(QByteArray(sessionBytes).replace("\"@csg\"", "\"model.stl\""));
    modelSessionFile.close();
    QCOMPARE(readSessionFile(modelSession).scenePath, model);
    const QString modelLink = dir.filePath("model-link.png");
    QVERIFY(QFile::link(model, modelLink));
    QCOMPARE(runProgram(MFRVIEW, {modelSession, "--size", "64x48", "--screenshot", modelLink}, &out), 2);
    QCOMPARE(out.trimmed().split(QLatin1Char('\n')).constLast(),
             QStringLiteral("mfrview: --screenshot %1: is the same file as the session's scene (%2): the command "
                            "would write over what it reads")
                 .arg(modelLink, model));
    QVERIFY(modelFile.open(QIODevice::ReadOnly));
    QCOMPARE(modelFile.readAll(), stl);
  }

  // mfrview took a --clip box that holds nothing of the scene (an empty image, exit 0) and
  // dropped ':slice' on a scene without a volume, both of which mfr render refuses (a bug hunt).
  // The same line now, from both programs.
  void clipAndSliceRefusedAsByMfr() {
    QTemporaryDir dir;
    const QString png = dir.filePath(QStringLiteral("refused.png"));
    // Also a thickness or step the render's operation does not use (they were kept and did nothing),
    // and a section (with a clip box) that leaves nothing to draw: mfrview wrote a blank picture,
    // exit 0 (a bug hunt).
    for (const auto& [scene, options] : QList<std::pair<QString, QStringList>>{
             {"@sample", {"--clip", "5,5,5,6,6,6"}},
             {"@sample", {"--section", "z=0:slice"}},
             {"@sample", {"-m", "abuffer-ll", "--op", "oit", "--thickness", "0.1"}},
             {"@sample", {"-m", "kplus-array", "--thickness", "0.1"}},
             {"@sample", {"-m", "abuffer-ll", "--step", "0.1"}},
             {"@volume", {"-m", "abuffer-ll", "--section", "x=5"}},
             {"@volume", {"-m", "abuffer-ll", "--section", "x=5:slice"}},
             {"@sample", {"-m", "abuffer-ll", "--clip", "0.5,0.5,0.5,1,1,1", "--section", "-x=0"}}}) {
      QString viewer, cli;
      QCOMPARE(runProgram(MFRVIEW, QStringList{scene, "--size", "32x32", "--screenshot", png} + options, &viewer), 1);
      QCOMPARE(runProgram(MFR_CLI, QStringList{"render", scene, "-s", "32x32", "-o", png} + options, &cli), 1);
      const QString viewerLine = viewer.trimmed().split(QLatin1Char('\n')).constLast();
      const QString cliLine = cli.trimmed().split(QLatin1Char('\n')).constLast();
      QVERIFY2(viewerLine.startsWith(QStringLiteral("mfrview: ")) && cliLine.startsWith(QStringLiteral("mfr: ")),
               qPrintable(viewerLine + " | " + cliLine));
      QCOMPARE(viewerLine.mid(9), cliLine.mid(5));
      QVERIFY(!QFile::exists(png));
    }
    // A box that holds part of the scene, and a slice of a volume, are drawn.
    QString out;
    QCOMPARE(runProgram(MFRVIEW, {"@sample", "--size", "32x32", "--screenshot", png, "--clip", "0,0,0,6,6,6"}, &out),
             0);
    QCOMPARE(runProgram(MFRVIEW, {"@volume", "--size", "32x32", "--screenshot", png, "--section", "z=0:slice"}, &out),
             0);
    // On a scene with a volume a step is the volume's; under --op oit it is refused as by mfr.
    QString viewer, cli;
    const QStringList oitStep{"-m", "abuffer-ll", "--op", "oit", "--step", "0.1"};
    QCOMPARE(runProgram(MFRVIEW, QStringList{"@volume", "--size", "32x32", "--screenshot", png} + oitStep, &viewer), 1);
    QCOMPARE(runProgram(MFR_CLI, QStringList{"render", "@volume", "-s", "32x32", "-o", png} + oitStep, &cli), 1);
    QCOMPARE(viewer.trimmed().split(QLatin1Char('\n')).constLast(),
             QStringLiteral("mfrview: --step: only operation volume uses it; this render's operation is oit"));
    QCOMPARE(cli.trimmed().split(QLatin1Char('\n')).constLast(),
             QStringLiteral("mfr: --step: only operation volume uses it; this render's operation is oit"));
    // A size of 0x0 is refused for its reason, in mfr's words (mfrview said "expected WIDTHxHEIGHT").
    QCOMPARE(runProgram(MFRVIEW, {"@sample", "--size", "0x0", "--screenshot", png}, &viewer), 2);
    QCOMPARE(runProgram(MFR_CLI, {"render", "@sample", "-s", "0x0", "-o", png}, &cli), 1);
    QCOMPARE(viewer.trimmed().split(QLatin1Char('\n')).constLast(),
             QStringLiteral("mfrview: --size 0x0: image size must be positive (got 0x0)"));
    QCOMPARE(cli.trimmed().split(QLatin1Char('\n')).constLast(),
             QStringLiteral("mfr: --size 0x0: image size must be positive (got 0x0)"));
  }

  // Plugin settings were read as defaults when of a wrong type ("budget_mib": "2" rendered at
  // 16 MiB) and a misspelt key was ignored, from --plugin-settings and from sessions alike (a bug
  // hunt). Both are one line now, naming the plugin and the key; settings of the right types load.
  void pluginSettingsAreCheckedAsTheRest() {
    QTemporaryDir dir;
    const QString png = dir.filePath(QStringLiteral("p.png"));
    const QList<std::pair<QString, QString>> cases{
        {R"(budget={"budget_mib":"2"})", "--plugin-settings budget: 'budget_mib': a string, expected a number"},
        {R"(budget={"budget_mb":2})", "--plugin-settings budget: unknown key 'budget_mb' (known: budget_mib, driving)"},
        {R"(hybridvolume={"window":[0,"x"]})",
         "--plugin-settings hybridvolume: 'window'[1]: a string, expected a number"},
        {R"(ghosting={"ghost":1})", "--plugin-settings ghosting: 'ghost': a number, expected a boolean"},
        // Qt's parser kept the last of a repeated key without a word (a bug hunt).
        {R"(budget={"budget_mib":2,"budget_mib":3})", "--plugin-settings budget: 'budget_mib' is given twice"},
    };
    for (const auto& [setting, message] : cases) {
      QString out;
      QCOMPARE(
          runProgram(MFRVIEW, {"@volume", "--size", "32x32", "--screenshot", png, "--plugin-settings", setting}, &out),
          2);
      QCOMPARE(out.trimmed().split(QLatin1Char('\n')).constLast(), QStringLiteral("mfrview: ") + message);
      QVERIFY(!QFile::exists(png));
    }
    // Values of the right type that a plugin cannot take as given: its note, which on a scripted
    // command line is a refusal (they were defaults or clamps without a word: a bug hunt).
    const QList<std::tuple<QString, QString, QString>> values{
        {"@volume", R"(budget={"budget_mib":3.7})",
         "--plugin-settings budget: budget_mib 3.7 is not a whole number of MiB in 1 … 4096: 4 is used"},
        {"@volume", R"(hybridvolume={"volume":99})",
         "--plugin-settings hybridvolume: volume 99: the scene has 1 (volume 0 is shown)"},
        {"@volume", R"(hybridvolume={"step":-1})",
         "--plugin-settings hybridvolume: step -1: must be a positive length in scene units, or 0 for the default (the "
         "step is kept)"},
        {"@volume", R"(hybridvolume={"preset":"nope"})",
         "--plugin-settings hybridvolume: preset 'nope': no such preset (custom is used)"},
        {"@volume", R"(hybridvolume={"window":[5,1]})",
         "--plugin-settings hybridvolume: window [5, 1]: low must be below high (the window is kept)"},
        // A window the viewer's transfer function refuses was shown in the panel only (a bug hunt).
        {"@volume", R"(hybridvolume={"window":[0,1e308]})",
         "--plugin-settings hybridvolume: transfer function: transfer function point 1 lies beyond a float's range"},
        {"@sample", R"(ghosting={"focus":["nope","tangle"]})",
         "--plugin-settings ghosting: no part 'nope' in this scene to focus on"},
        {"@csg", QStringLiteral("csg={\"tree\":\"{\\\"union\\\":[\\\"block\\\",\\\"nope\\\"]}\"}"),
         "--plugin-settings csg: tree: "},
        // Dropped, read as the current volume, or as 1, without a word (a bug hunt).
        {"@sample", R"(hybridvolume={"preset":"bone"})",
         "--plugin-settings hybridvolume: the scene has no volume (the settings are left out)"},
        {"@volume", R"(hybridvolume={"volume":1.5})",
         "--plugin-settings hybridvolume: volume 1.5: the scene has 1 (volume 0 is shown)"},
        {"@volume", R"(hybridvolume={"base":{"points":[[0,0,0,0,0],[1,1,1,1,1],[0.5,1,1]]}})",
         "--plugin-settings hybridvolume: base.points[2]: expected [value, r, g, b, a] (the volume's own function is "
         "kept)"},
        {"@volume", R"(hybridvolume={"base":{"unit_distance":"x","points":[[0,0,0,0,0],[1,1,1,1,1]]}})",
         "--plugin-settings hybridvolume: base.unit_distance: expected a number"},
    };
    for (const auto& [scene, setting, message] : values) {
      QString out;
      QCOMPARE(runProgram(MFRVIEW, {scene, "--size", "32x32", "--screenshot", png, "--plugin-settings", setting}, &out),
               2);
      const QStringList lines = out.trimmed().split(QLatin1Char('\n'));
      QVERIFY2(lines.constLast().startsWith(QStringLiteral("mfrview: ") + message), qPrintable(out));
      QVERIFY2(!out.contains(QStringLiteral("note: ")), qPrintable(out));  // one line, not a note and a refusal
      QVERIFY(!QFile::exists(png));
    }
    // A plugin file that failed to load is named when settings find no plugin of their id (a
    // truncated plugin was not mentioned: a bug hunt).
    {
      const QString folder = dir.filePath(QStringLiteral("junk"));
      QVERIFY(QDir().mkpath(folder));
      QFile junk(folder + QStringLiteral("/mfrview_nosuch.so"));
      QVERIFY(junk.open(QIODevice::WriteOnly));
      junk.write("not an ELF object");
      junk.close();
      const QByteArray before = qgetenv("MFR_PLUGIN_PATH");
      qputenv("MFR_PLUGIN_PATH", folder.toUtf8());
      QString out;
      const int code = runProgram(
          MFRVIEW, {"@sample", "--size", "32x32", "--screenshot", png, "--plugin-settings", "nosuch={}"}, &out);
      qputenv("MFR_PLUGIN_PATH", before);
      QCOMPARE(code, 2);
      QVERIFY2(out.contains(QStringLiteral("no plugin of that id is loaded (loaded: ")) &&
                   out.contains(QStringLiteral("; failed: ") + folder + QStringLiteral("/mfrview_nosuch.so: ")),
               qPrintable(out));
      QVERIFY(!QFile::exists(png));
    }
    // --step is checked after the plugins' settings, which may turn the volume on (it was refused
    // though then used: a review); without them, wboit's "oit" does not use it.
    {
      QString out;
      QCOMPARE(runProgram(MFRVIEW,
                          {"@volume", "--size", "32x32", "--screenshot", png, "-m", "wboit", "--step", "0.05",
                           "--plugin-settings", R"(hybridvolume={"show":true})"},
                          &out),
               0);
      QFile::remove(png);
      QCOMPARE(runProgram(MFRVIEW, {"@volume", "--size", "32x32", "--screenshot", png, "-m", "wboit", "--step", "0.05"},
                          &out),
               1);
      QVERIFY2(out.contains("mfrview: --step: only operation volume uses it"), qPrintable(out));
      QVERIFY(!QFile::exists(png));
    }
    // A session's plugin settings: the same check, naming the file.
    const auto session = [&](const QJsonObject& budget) {
      const QString path = dir.filePath(QStringLiteral("s.mfrsession"));
      QFile f(path);
      if (!f.open(QIODevice::WriteOnly)) return QString();
      f.write(QJsonDocument(QJsonObject{{"format", "mfrview-session"},
                                        {"version", 1},
                                        {"scene", "@sample"},
                                        {"camera", QJsonObject{{"eye", QJsonArray{3, 2, 4}},
                                                               {"target", QJsonArray{0, 0, 0}},
                                                               {"up", QJsonArray{0, 1, 0}}}},
                                        {"method", "fkb"},
                                        {"plugins", QJsonObject{{"budget", budget}}}})
                  .toJson());
      return path;
    };
    QString out;
    const QString bad = session(QJsonObject{{"budget_mib", "2"}});
    QCOMPARE(runProgram(MFRVIEW, {bad, "--size", "32x32", "--screenshot", png}, &out), 1);
    QCOMPARE(out.trimmed().split(QLatin1Char('\n')).constLast(),
             QStringLiteral("mfrview: %1: plugins.budget: 'budget_mib': a string, expected a number").arg(bad));
    QVERIFY(!QFile::exists(png));
    // Settings of the right types are not refused.
    const QString good = session(QJsonObject{{"budget_mib", 2}, {"driving", true}});
    QCOMPARE(runProgram(MFRVIEW, {good, "--size", "32x32", "--screenshot", png}, &out), 0);
    QVERIFY(QFile::exists(png));
    // Settings of a plugin that is not loaded are a note (they were dropped without a word).
    {
      QFile f(dir.filePath(QStringLiteral("s.mfrsession")));
      QVERIFY(f.open(QIODevice::ReadWrite));
      QJsonObject json = QJsonDocument::fromJson(f.readAll()).object();
      QJsonObject plugins = json.value("plugins").toObject();
      plugins.insert("nope", QJsonObject{{"x", 1}});
      json.insert("plugins", plugins);
      json.insert("mehtod", "wboit");  // a misspelt key was ignored without a word
      f.resize(0);
      f.write(QJsonDocument(json).toJson());
    }
    QCOMPARE(runProgram(MFRVIEW, {good, "--size", "32x32", "--screenshot", png}, &out), 0);
    QVERIFY2(
        out.contains("note: s.mfrsession: plugins.nope: no plugin of that id is loaded (its settings are left out)"),
        qPrintable(out));
    QVERIFY2(out.contains("note: s.mfrsession: mehtod: no such key (left out)"), qPrintable(out));
    // In a session, a value taken other than as given is a note on stderr, and the run goes on.
    QFile::remove(png);
    const QString clamped = session(QJsonObject{{"budget_mib", 5000}});
    QCOMPARE(runProgram(MFRVIEW, {clamped, "--size", "32x32", "--screenshot", png}, &out), 0);
    // It names the session file and key, as the session's own notes (it named neither: a review).
    QVERIFY2(out.contains("note: s.mfrsession: plugins.budget: budget_mib 5000 is not a whole number of MiB in 1 … "
                          "4096: 4096 is used"),
             qPrintable(out));
    QVERIFY(QFile::exists(png));
    // --method, --op and -p beside a session win over the session's own, as --view does (the
    // session's fkb was drawn instead, exit 0; a bug hunt).
    const QString cliPng = dir.filePath("cli.png"), sessionPng = dir.filePath("session.png");
    QCOMPARE(runProgram(MFRVIEW, {good, "--size", "64x48", "--view", "iso", "--screenshot", sessionPng}, &out), 0);
    QCOMPARE(runProgram(MFRVIEW,
                        {good, "--size", "64x48", "--view", "iso", "--screenshot", png, "--method", "kbuffer", "-p",
                         "k=2", "--op", "oit"},
                        &out),
             0);
    QCOMPARE(runProgram(MFR_CLI,
                        {"render", "@sample", "-s", "64x48", "--view", "iso", "-o", cliPng, "--method", "kbuffer", "-p",
                         "k=2", "--op", "oit"},
                        &out),
             0);
    const mfr::ImageRGBA8 overridden = mfr::readPng(png.toStdString());
    QVERIFY(maxChannelDifference(overridden, mfr::readPng(cliPng.toStdString())) <= 1);
    QVERIFY(maxChannelDifference(overridden, mfr::readPng(sessionPng.toStdString())) > 8);
  }

  void badSessionValuesAreRefused() {
    const QJsonObject good{
        {"format", "mfrview-session"},
        {"version", 1},
        {"scene", "@sample"},
        {"camera",
         QJsonObject{{"eye", QJsonArray{3, 2, 4}}, {"target", QJsonArray{0, 0, 0}}, {"up", QJsonArray{0, 1, 0}}}},
        {"method", "abuffer-ll"},
        {"objects", QJsonArray{QJsonObject{{"name", "tangle"}, {"color", QJsonArray{1, 0, 0}}}}}};
    (void)sessionFromJson(good, "s.mfrsession");  // throws if the base is bad
    // The viewer's CPU methods are methods of sessions too (the first strict reader refused them).
    for (const char* cpu : {"oracle", "optimal-k"}) {
      QJsonObject json = good;
      json.insert("method", cpu);
      json.insert("compare", QJsonObject{{"method", cpu}});
      QCOMPARE(sessionFromJson(json, "s.mfrsession").method, QString(cpu));
    }
    const auto with = [&](const QString& key, const QJsonValue& value) {
      QJsonObject json = good;
      json.insert(key, value);
      return json;
    };
    const auto camera = [&](const QJsonObject& extra) {
      QJsonObject c = good.value("camera").toObject();
      for (auto it = extra.begin(); it != extra.end(); ++it) c.insert(it.key(), it.value());
      return c;
    };
    const auto object = [](const QJsonObject& extra) {
      QJsonObject o{{"name", "tangle"}, {"color", QJsonArray{1, 0, 0}}};
      for (auto it = extra.begin(); it != extra.end(); ++it) o.insert(it.key(), it.value());
      return QJsonArray{o};
    };
    const QList<std::pair<QJsonObject, QString>> cases{
        {with("objects", object({{"visible", "no"}})), "s.mfrsession: objects[0].visible: expected true or false"},
        {with("objects", object({{"color", QJsonArray{1, 0, "x"}}})),
         "s.mfrsession: objects[0].color[2]: expected a number in [0, 1]"},
        {with("objects", object({{"opacity", 5}})), "s.mfrsession: objects[0].opacity: expected a number in [0, 1]"},
        {with("objects", QJsonArray{7}), "s.mfrsession: objects[0]: expected an object"},
        {with("method", 3), "s.mfrsession: method: expected a string"},
        {with("method", "nosuch"), "s.mfrsession: method: unknown method 'nosuch'"},
        {with("operation", "xyz"), "s.mfrsession: operation: unknown operation 'xyz'"},
        {with("version", 99), "s.mfrsession: version: expected 1"},
        // Another JSON type where an object or array belongs was read as empty (a bug hunt).
        {with("compare", "yes"), "s.mfrsession: compare: expected an object"},
        {with("volumes", QJsonObject{}), "s.mfrsession: volumes: expected an array"},
        {with("params", QJsonArray{1, 2}), "s.mfrsession: params: expected an object"},
        {with("data_view", "capacity"), "s.mfrsession: data_view: expected an object"},
        // A parameter's bad value named --param, an option never given (a bug hunt).
        {with("params", QJsonObject{{"abuffer-ll", QJsonObject{{"pool_mib", "abc"}}}}),
         "s.mfrsession: params.abuffer-ll: pool_mib=abc: expected a number"},
        {with("compare", QJsonObject{{"params", QJsonObject{{"kbuffer", QJsonObject{{"k", "0"}}}}}}),
         "s.mfrsession: compare.params.kbuffer: k=0: out of range [1, 256]"},
        {with("compare", QJsonObject{{"enabled", 1}}), "s.mfrsession: compare.enabled: expected true or false"},
        // Taken before (a bug hunt): a negative fovy drew the view upside down, a negative height
        // and an overflowing section normal drew it uncut, an unknown map was dropped.
        {with("camera", camera({{"fovy_degrees", -40}})),
         "s.mfrsession: camera.fovy_degrees: must be in (0, 180) degrees"},
        {with("camera", camera({{"projection", "orthographic"}, {"ortho_height", -3}})),
         "s.mfrsession: camera.ortho_height: must be a positive height in scene units"},
        {with("camera", camera({{"near", 2}, {"far", 1}})), "s.mfrsession: camera.far: must be greater than near"},
        {with("camera", camera({{"near_far_given", "yes"}})),
         "s.mfrsession: camera.near_far_given: expected true or false"},
        // A number was read as perspective, and a split of 7 was clamped to 1 without a word.
        {with("camera", camera({{"projection", 3}})),
         "s.mfrsession: camera.projection: expected perspective or orthographic"},
        // A degenerate camera failed the first frame without the file's name (a bug hunt).
        {with("camera", camera({{"eye", QJsonArray{0, 0, 0}}})), "s.mfrsession: camera: eye and target coincide"},
        {with("camera", camera({{"up", QJsonArray{3, 2, 4}}})),
         "s.mfrsession: camera.up: parallel to the view direction"},
        {with("camera", camera({{"near", 1e-300}, {"far", 1e300}})),
         "s.mfrsession: camera: its projection is singular"},
        {with("compare", QJsonObject{{"split", 7}}), "s.mfrsession: compare.split: expected a number in [0, 1]"},
        {with("compare", QJsonObject{{"split", "0.5"}}), "s.mfrsession: compare.split: expected a number in [0, 1]"},
        {with("section", QJsonObject{{"point", QJsonArray{0, 0, 0}}, {"normal", QJsonArray{1e200, 1e200, 0}}}),
         "s.mfrsession: section: the normal is too long to normalise (under 1e150)"},
        {with("color_by", QJsonObject{{"field", "b"}, {"map", "badmap"}, {"range", QJsonArray{0, 1}}}),
         "s.mfrsession: color_by.map: unknown colour map 'badmap'"},
        {with("params", QJsonObject{{"nosuch", QJsonObject{{"k", "4"}}}}),
         "s.mfrsession: params.nosuch: unknown method 'nosuch'"},
        {with("params", QJsonObject{{"kbuffer", 3}}),
         "s.mfrsession: params.kbuffer: expected an object of name: value"},
        {with("plugins", 3), "s.mfrsession: plugins: expected an object of plugin id: settings"},
        {with("volumes",
              QJsonArray{QJsonObject{{"transfer", QJsonObject{{"points", QJsonArray{QJsonArray{0, 0, 0, 0, 0},
                                                                                    QJsonArray{1, "a", 1, 1, 1}}}}}}}),
         "s.mfrsession: volumes[0].transfer.points[1]: expected [value, r, g, b, a]"},
    };
    for (const auto& [json, message] : cases) {
      try {
        (void)sessionFromJson(json, "s.mfrsession");
        QFAIL(qPrintable("accepted, expected: " + message));
      } catch (const mfr::Error& e) {
        QVERIFY2(QString::fromUtf8(e.what()).startsWith(message), e.what());
      }
    }
    // A key given twice in the file (Qt's parser kept the last: a second "objects" dropped the
    // first without a word), as scene files refuse it.
    QTemporaryDir dir;
    const QString twice = dir.filePath(QStringLiteral("twice.mfrsession"));
    {
      QFile f(twice);
      QVERIFY(f.open(QIODevice::WriteOnly));
      f.write(R"({"format": "mfrview-session", "version": 1, "scene": "@sample",
                  "camera": {"eye": [3, 2, 4], "target": [0, 0, 0], "up": [0, 1, 0], "near": 1, "near": 2}})");
    }
    try {
      (void)readSessionFile(twice);
      QFAIL("a repeated key was accepted");
    } catch (const mfr::Error& e) {
      QCOMPARE(QString::fromUtf8(e.what()),
               twice + QStringLiteral(": camera.near: given twice (the keys of a JSON object must differ)"));
    }
    // A pipe and a device are refused before any read (a FIFO froze the window, /dev/zero read
    // until memory ran out: a bug hunt).
    const QString fifo = dir.filePath(QStringLiteral("fifo.mfrsession"));
    QCOMPARE(::mkfifo(QFile::encodeName(fifo).constData(), 0600), 0);
    for (const QString& special : {fifo, QStringLiteral("/dev/zero")}) {
      try {
        (void)readSessionFile(special);
        QFAIL(qPrintable(special + " was read"));
      } catch (const mfr::Error& e) {
        QCOMPARE(QString::fromUtf8(e.what()), special + QStringLiteral(": not a regular file (a device or pipe)"));
      }
    }
  }

  // A session's objects go to the parts of the same name, whatever their order and count: by index,
  // a scene with one part more dropped every override, and a renamed part took another's state.
  // Names the scene lacks are a note.
  void sessionObjectsMatchPartsByName() {
    auto w = openWindow();
    QVERIFY(w);
    ViewerModel& m = w->model();
    const std::vector<mfr::Object>& parts = m.scene().objects;
    QCOMPARE(parts[5].name, std::string("tangle"));
    QCOMPARE(parts[1].name, std::string("middle shell"));
    Session session = captureSession(m);
    session.objects = {{"tangle", false, glm::vec4(1, 0, 0, 0.5f), false, std::nullopt},
                       {"nosuch", false, glm::vec4(0, 1, 0, 1), false, std::nullopt},
                       {"middle shell", true, glm::vec4(0, 0, 1, 0.25f), false, std::nullopt}};
    const QStringList notes = applySession(session, m);
    QVERIFY(!parts[5].visible);
    QCOMPARE(parts[5].material.color, glm::vec4(1, 0, 0, 0.5f));
    QCOMPARE(parts[1].material.color, glm::vec4(0, 0, 1, 0.25f));
    QVERIFY(parts[0].visible && parts[2].visible);  // not named: as the file has them
    QCOMPARE(notes, QStringList{"the session's object 'nosuch' is no part of the scene: left out"});
    // A field the scene lacks is a note too (it was dropped without a word: a bug hunt).
    Session coloured = captureSession(m);
    coloured.hasColorBy = true;
    coloured.colorBy = mfr::FieldColors{"nope", "viridis", glm::dvec2(0.0, 1.0)};
    const QStringList colourNotes = applySession(coloured, m);
    QCOMPARE(colourNotes.size(), 1);
    QVERIFY2(colourNotes[0].startsWith(QStringLiteral("color_by nope: ")) &&
                 colourNotes[0].endsWith(QStringLiteral(" (not applied)")),
             qPrintable(colourNotes.join('|')));
  }

  // A session's part overrides are one scene edit: one per part made every panel walk every part
  // per part, so opening a session of 8,000 edited parts took 34 s, against 1.3 s without the
  // edits (a bug hunt). Counted by the scene edits announced, not timed.
  void sessionAppliesManyPartsInOneEdit() {
    constexpr int kParts = 60;
    auto w = openWindow(QString());
    QVERIFY(w);
    ViewerModel& m = w->model();
    w->view().setFixedSize(160, 120);
    m.setMethod("wboit");
    w->openScene(QStringLiteral("@quads:%1").arg(kParts));
    QTRY_VERIFY_WITH_TIMEOUT(m.hasScene() && m.framesRendered() > 0, kTimeoutMs);
    settle(m);
    Session session = captureSession(m);
    QCOMPARE(static_cast<int>(session.objects.size()), kParts);
    for (std::size_t i = 0; i < session.objects.size(); ++i) {
      session.objects[i].visible = i % 3 != 0;
      session.objects[i].color = glm::vec4(0.2f, 0.4f, 0.6f, 0.3f);
    }
    int edits = 0;
    const QMetaObject::Connection counting = connect(&m, &ViewerModel::sceneChanged, [&edits] { ++edits; });
    const QStringList notes = applySession(session, m);
    disconnect(counting);
    QVERIFY2(notes.isEmpty(), qPrintable(notes.join('|')));
    QVERIFY2(edits <= 3, qPrintable(QStringLiteral("%1 scene edits").arg(edits)));
    for (int i = 0; i < kParts; ++i) {
      const mfr::Object& part = m.scene().objects[static_cast<std::size_t>(i)];
      QCOMPARE(part.visible, i % 3 != 0);
      QCOMPARE(part.material.color, glm::vec4(0.2f, 0.4f, 0.6f, 0.3f));
    }
    // Parts of one name still go to the n-th part of that name (matched through an index now).
    const std::vector<int> match = matchByName({"b", "a", "b", "c", "", "b"}, {"a", "b", "x", "b", ""}, true);
    QCOMPARE(match, (std::vector<int>{1, 0, 3, -1, 4, -1}));
  }

  // What the session's scene cannot use is a note and left out: an operation it cannot draw (the
  // first frame failed naming --op, an option never given), the volume step and a slice without a
  // volume, a volume field the volume lacks (all taken without a word before; a bug hunt).
  void sessionSettingsTheSceneCannotUseAreNotes() {
    auto w = openWindow();
    QVERIFY(w);
    ViewerModel& m = w->model();
    Session session = captureSession(m);
    const QString operation = m.operation();
    session.operation = QStringLiteral("csg");
    session.compare.operation = QStringLiteral("volume");
    session.volumeStep = 0.5;
    session.hasSection = true;
    session.section = mfr::SectionPlane{};
    session.section->normal = {1.0, 0.0, 0.0};
    session.section->slice = true;
    const QStringList notes = applySession(session, m);
    QCOMPARE(notes, (QStringList{"section.slice: scene 'sample' has no volume (the plane cuts, no slice is drawn)",
                                 "volume_step: scene 'sample' has no volume (left out)",
                                 "operation: csg: scene 'sample' has no CSG tree (left out)",
                                 "compare.operation: volume: scene 'sample' has no volume (left out)"}));
    QCOMPARE(m.operation(), operation);
    QVERIFY(m.section() && !m.section()->slice);
    QCOMPARE(m.volumeStep(), 0.0);
    // A session the viewer saves on a scene without a volume, after a volume scene left the Volume
    // panel's state behind, opens again without a note (its Volume settings are the panel's own
    // there; a review), and its operation csg with the CSG panel's tree is no "no CSG tree" note.
    {
      QTemporaryDir dir;
      auto before = openWindow(QStringLiteral("@volume"));
      QVERIFY(before);
      before->openScene(QStringLiteral("@sample"));
      QTRY_VERIFY_WITH_TIMEOUT(before->model().hasScene() && before->model().scene().name == "sample", kTimeoutMs);
      settle(before->model());
      const QString path = dir.filePath(QStringLiteral("plain.mfrsession")), png = dir.filePath("plain.png");
      before->saveSession(path);
      QString out;
      QCOMPARE(runProgram(MFRVIEW, {path, "--size", "32x32", "--screenshot", png}, &out), 0);
      QVERIFY2(!out.contains(QStringLiteral("note:")), qPrintable(out));
      Session csg = captureSession(m);
      csg.operation = QStringLiteral("csg");
      csg.plugins.insert(QStringLiteral("csg"), QJsonObject{{"tree", R"({"union":["outer shell","middle shell"]})"}});
      QVERIFY2(!applySession(csg, m).join('|').contains(QStringLiteral("CSG")), "a tree in the plugin's settings");
      QCOMPARE(m.operation(), QStringLiteral("csg"));
    }
    auto v = openWindow(QStringLiteral("@volume"));
    QVERIFY(v);
    Session field = captureSession(v->model());
    QCOMPARE(field.volumes.size(), std::size_t{1});
    field.volumes[0].field = QStringLiteral("nope");
    QCOMPARE(applySession(field, v->model()),
             QStringList{"volumes[0].field: volume 'field' has no field 'nope' (it has one field; left out)"});
  }

  // A session's volume fields are read with its scene, by volume name (a bug hunt): with two volumes
  // on other fields than their own, one read cancelled the other, and the first volume drew its own
  // field under the other's transfer function — nothing; volumes of a reordered scene file took each
  // other's settings; a field that could not be read left a blank picture with exit 0 and no word;
  // a session of a volume file whose default field cannot be read did not open. Each picture equals
  // mfr render of the scene the session describes.
  void sessionVolumeFieldsAreReadWithTheScene() {
    QTemporaryDir dir;
    // f.vti: arrays "bad" (NaN, so it cannot be read; the file's default), "a" in [0, 0.5] and "b" in
    // [10, 20].
    {
      constexpr int n = 6;
      const auto array = [](const QString& name, const std::function<QString(int, int, int)>& value) {
        QString values;
        for (int k = 0; k < n; ++k)
          for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) values += value(i, j, k) + ' ';
        return QStringLiteral("<DataArray type=\"Float32\" Name=\"%1\" format=\"ascii\">%2</DataArray>")
            .arg(name, values);
      };
      QFile f(dir.filePath(QStringLiteral("f.vti")));
      QVERIFY(f.open(QIODevice::WriteOnly));
      f.write(
          QStringLiteral("<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"0.1\" "
                         "byte_order=\"LittleEndian\">\n<ImageData WholeExtent=\"0 5 0 5 0 5\" Origin=\"0 0 0\" "
                         "Spacing=\"0.2 0.2 0.2\">\n<Piece Extent=\"0 5 0 5 0 5\"><PointData>%1%2%3</PointData>"
                         "<CellData></CellData></Piece>\n</ImageData>\n</VTKFile>\n")
              .arg(array("bad", [](int i, int, int) { return i == 2 ? QStringLiteral("nan") : QStringLiteral("1"); }),
                   array("a", [](int i, int, int) { return QString::number(0.1 * i); }),
                   array("b", [](int, int, int k) { return QString::number(10 + 2 * k); }))
              .toUtf8());
    }
    const std::string vti = dir.filePath(QStringLiteral("f.vti")).toStdString();
    const mfr::Volume b = mfr::loadVolume(vti, mfr::LoadOptions("b"));
    const mfr::TransferFunction transferB = mfr::defaultTransfer(*b.grid, b.bounds());
    const auto scene = [&](const QString& name, const QString& volumes) {
      const QString path = dir.filePath(name);
      QFile f(path);
      if (f.open(QIODevice::WriteOnly)) f.write(QStringLiteral("{\"volumes\": [%1]}").arg(volumes).toUtf8());
      return path;
    };
    const QString va = QStringLiteral("{\"name\": \"va\", \"file\": \"f.vti\", \"field\": \"%1\"%2}");
    const QString vb = QStringLiteral(
        "{\"name\": \"vb\", \"file\": \"f.vti\", \"field\": \"%1\", \"transform\": "
        "{\"translate\": [2, 0, 0]}%2}");
    const QString two = scene(QStringLiteral("two.mfrscene"), va.arg("a", "") + ", " + vb.arg("a", ""));
    // The session: both volumes on field b, with b's default transfer function (as the viewer saves
    // them after choosing b in the Field chooser), seen from the scene's fit view.
    const auto volumeState = [&](const QString& name, const QString& field, bool visible) {
      Session::VolumeState v;
      v.name = name;
      v.field = field;
      v.visible = visible;
      v.transfer = transferB;
      return v;
    };
    Session session;
    session.scenePath = two;
    session.camera = mfr::loadScene(two.toStdString()).view("fit");
    session.method = QStringLiteral("abuffer-ll");
    session.volumes = {volumeState("va", "b", true), volumeState("vb", "b", true)};
    const auto expectSame = [&](const Session& s, const QString& cliScene, const QStringList& cliOptions,
                                const QString& note) {
      const QString path = dir.filePath(QStringLiteral("s.mfrsession")), png = dir.filePath(QStringLiteral("v.png")),
                    cliPng = dir.filePath(QStringLiteral("c.png"));
      writeSessionFile(path, s);
      QString out, cli;
      QCOMPARE(runProgram(MFRVIEW, {path, "--size", "96x64", "--screenshot", png}, &out), 0);
      QVERIFY2(note.isEmpty() ? !out.contains(QStringLiteral("note:")) : out.contains(note), qPrintable(out));
      QCOMPARE(runProgram(MFR_CLI,
                          QStringList{"render", cliScene, "-m", "abuffer-ll", "-s", "96x64", "-o", cliPng} + cliOptions,
                          &cli),
               0);
      const int diff = maxChannelDifference(mfr::readPng(png.toStdString()), mfr::readPng(cliPng.toStdString()));
      QVERIFY2(diff >= 0 && diff <= 1, qPrintable(QStringLiteral("%1: difference %2").arg(cliScene).arg(diff)));
    };
    expectSame(session, scene(QStringLiteral("twob.mfrscene"), va.arg("b", "") + ", " + vb.arg("b", "")), {}, {});
    // The scene file's volumes reordered: the settings go by name.
    Session swapped = session;
    swapped.scenePath = scene(QStringLiteral("swapped.mfrscene"), vb.arg("a", "") + ", " + va.arg("a", ""));
    swapped.volumes = {volumeState("va", "b", true), volumeState("vb", "a", true)};
    {
      const mfr::Volume a = mfr::loadVolume(vti, mfr::LoadOptions("a"));
      swapped.volumes[1].transfer = mfr::defaultTransfer(*a.grid, a.bounds());
    }
    expectSame(swapped, scene(QStringLiteral("swappedb.mfrscene"), vb.arg("a", "") + ", " + va.arg("b", "")), {}, {});
    // A field that cannot be read: a note naming the key and why, the volume on its own field.
    Session bad = session;
    bad.volumes = {volumeState("va", "bad", true), volumeState("vb", "b", true)};
    bad.volumes[0].transfer = swapped.volumes[1].transfer;  // field a's
    expectSame(bad, scene(QStringLiteral("bada.mfrscene"), va.arg("a", "") + ", " + vb.arg("b", "")), {},
               QStringLiteral("note: s.mfrsession: volumes[0].field: ") + QString::fromStdString(vti) +
                   QStringLiteral(": volume has a non-finite value"));
    // The volume file itself, whose default field cannot be read, on field b.
    Session file = session;
    file.scenePath = QString::fromStdString(vti);
    file.camera = mfr::loadScene(vti, mfr::LoadOptions("b")).view("fit");
    file.volumes = {volumeState("f.vti", "b", true)};
    expectSame(file, QString::fromStdString(vti), {"--field", "b"}, {});
  }

  // The view and the checks follow what is drawn (a bug hunt): a volume shown that the scene file
  // hides lay beyond the far plane fitted to the rest and drew nothing until the camera moved; a
  // session's clip box around that volume was refused as holding nothing; --contour replaced a
  // session's camera with the fit view; a scripted run left out the section's notes.
  void viewFollowsWhatIsDrawn() {
    QTemporaryDir dir;
    const QString hidden = dir.filePath(QStringLiteral("far.mfrscene"));
    {
      QFile f(hidden);
      QVERIFY(f.open(QIODevice::WriteOnly));
      f.write(R"({"objects": [{"name": "ball", "primitive": {"type": "sphere", "radius": 0.5}},
                  {"name": "sheet", "primitive": {"type": "plane", "width": 1, "height": 1},
                   "transform": {"rotate": {"axis": [1, 0, 0], "degrees": 90}}}],
                  "volumes": [{"name": "blob", "file": "blob.vti", "visible": false,
                               "transform": {"translate": [0, 0, -8]}}]})");
    }
    writeBlobScene(dir, QStringLiteral("blob.mfrscene"), blobTransfer());  // writes blob.vti
    auto w = openWindow(hidden);
    QVERIFY(w);
    ViewerModel& m = w->model();
    const double farBefore = m.camera().farPlane;
    m.setVolumeVisibleAt(0, true);
    // The volume's far corner, (1.9, 1.9, -6.1), lies within the far plane now.
    const glm::dvec3 corner(1.9, 1.9, -8.0);
    const double reach = glm::dot(corner - m.camera().eye, m.camera().forward());
    QVERIFY2(
        m.camera().farPlane >= reach && farBefore < reach,
        qPrintable(
            QStringLiteral("far %1 (before %2), corner at %3").arg(m.camera().farPlane).arg(farBefore).arg(reach)));
    settle(m);
    Session session = captureSession(m);
    session.hasClip = true;
    session.clip = mfr::Bounds{glm::dvec3(-0.5, -0.5, -8.5), glm::dvec3(2.5, 2.5, -5.5)};  // the volume alone
    session.camera = m.scene().view("orbit:30:20");
    const QString path = dir.filePath(QStringLiteral("s.mfrsession")), png = dir.filePath(QStringLiteral("s.png"));
    writeSessionFile(path, session);
    QString out;
    QCOMPARE(runProgram(MFRVIEW, {path, "--size", "64x48", "--screenshot", png}, &out), 0);
    QVERIFY2(!out.contains(QStringLiteral("note:")), qPrintable(out));
    // --contour keeps the session's camera, as a session's own isosurfaces do (the volume hidden, as
    // --contour hides it).
    Session withIsosurfaces = session;
    withIsosurfaces.clip.reset();
    withIsosurfaces.volumes[0].visible = false;
    withIsosurfaces.volumes[0].isosurfaces = {0.5};
    const QString isoPath = dir.filePath(QStringLiteral("iso.mfrsession")),
                  isoPng = dir.filePath(QStringLiteral("iso.png"));
    writeSessionFile(isoPath, withIsosurfaces);
    QCOMPARE(runProgram(MFRVIEW, {isoPath, "--size", "64x48", "--screenshot", isoPng, "-m", "abuffer-ll"}, &out), 0);
    withIsosurfaces.volumes[0].isosurfaces.clear();
    writeSessionFile(path, withIsosurfaces);
    QCOMPARE(runProgram(MFRVIEW, {path, "--size", "64x48", "--screenshot", png, "-m", "abuffer-ll", "--contour", "0.5"},
                        &out),
             0);
    const int diff = maxChannelDifference(mfr::readPng(png.toStdString()), mfr::readPng(isoPng.toStdString()));
    QVERIFY2(diff >= 0 && diff <= 1, qPrintable(QStringLiteral("difference %1").arg(diff)));
    // The section's notes, as mfr render prints them.
    QCOMPARE(runProgram(MFRVIEW, {hidden, "--size", "64x48", "--screenshot", png, "--section", "x=0.1"}, &out), 0);
    QVERIFY2(out.contains(QStringLiteral("note: section: 1 of 2 cut parts have no cap (not closed surfaces): sheet")),
             qPrintable(out));
  }

  // Given planes whose 32-bit window depth cannot order what is drawn: mfr render said so, mfrview
  // drew the misordered layers without a word (a note of an earlier session). The Statistics dock
  // lists the note, a scripted run prints it as mfr render does; a near plane of 0.01 gets none.
  void givenDepthRangesTooCoarseAreNoted() {
    QTemporaryDir dir;
    const auto scene = [&](const QString& name, const char* near) {
      const QString path = dir.filePath(name);
      QFile f(path);
      if (!f.open(QIODevice::WriteOnly)) return QString();
      f.write(QByteArray(R"({"sample": true, "objects": [], "views": [{"name": "v", "eye": [0, 0, 5], "near": )") +
              near + R"(, "far": 6}]})");
      return path;
    };
    const QString coarse = scene("coarse.mfrscene", "1e-5"), fine = scene("fine.mfrscene", "0.01");
    QVERIFY(!coarse.isEmpty() && !fine.isEmpty());
    const QString png = dir.filePath("n.png");
    const QString expected = QStringLiteral("note: depth precision: near 1e-05 and far 6 resolve depths only 0.2");
    QString out;
    QCOMPARE(
        runProgram(MFRVIEW, {coarse, "--view", "v", "-m", "abuffer-ll", "--size", "96x72", "--screenshot", png}, &out),
        0);
    QVERIFY2(out.contains(expected), qPrintable(out));
    QCOMPARE(
        runProgram(MFRVIEW, {fine, "--view", "v", "-m", "abuffer-ll", "--size", "96x72", "--screenshot", png}, &out),
        0);
    QVERIFY2(!out.contains(QStringLiteral("depth precision")), qPrintable(out));

    auto w = openWindow(coarse);
    QVERIFY(w);
    ViewerModel& m = w->model();
    m.setCamera(m.scene().view("v"));
    settle(m);
    const auto noted = [&m] {
      for (const auto& [key, value] : m.stats().notes)
        if (key == "depth precision") return true;
      return false;
    };
    QVERIFY(noted());
    m.setCamera(m.scene().view("fit"));  // fitted planes: no note
    settle(m);
    QVERIFY(!noted());
  }

  // A named view's own near and far planes (a cut-away view) are kept, as mfr render keeps them:
  // setCamera fitted them to the scene, so mfrview drew the whole sphere (a bug hunt). They hold
  // until the camera moves, and a session keeps them.
  void givenNearFarPlanesAreKept() {
    QTemporaryDir dir;
    const QString scene = dir.filePath(QStringLiteral("cut.mfrscene"));
    {
      QFile f(scene);
      QVERIFY(f.open(QIODevice::WriteOnly));
      // The sphere's front lies 4 from the eye: a near plane at 4.5 cuts its cap away.
      f.write(R"({"objects": [{"name": "ball", "primitive": {"type": "sphere", "radius": 1},
                               "color": [1, 0, 0], "opacity": 0.5}],
                  "views": [{"name": "whole", "eye": [0, 0, 5]},
                            {"name": "cut", "eye": [0, 0, 5], "near": 4.5}]})");
    }
    QString out;
    const QString cut = dir.filePath("cut.png"), whole = dir.filePath("whole.png");
    for (const auto& [view, png] : {std::pair{"cut", cut}, std::pair{"whole", whole}})
      QCOMPARE(
          runProgram(MFR_CLI, {"render", scene, "--view", view, "-m", "abuffer-ll", "-s", "64x48", "-o", png}, &out),
          0);
    // The cut is visible: the references differ.
    QVERIFY(maxChannelDifference(mfr::readPng(cut.toStdString()), mfr::readPng(whole.toStdString())) > 20);
    const QString shot = dir.filePath("shot.png");
    QCOMPARE(runProgram(MFRVIEW, {scene, "--view", "cut", "-m", "abuffer-ll", "--size", "64x48", "--screenshot", shot},
                        &out),
             0);
    int diff = maxChannelDifference(mfr::readPng(shot.toStdString()), mfr::readPng(cut.toStdString()));
    QVERIFY2(diff >= 0 && diff <= 1, qPrintable(QStringLiteral("--view cut: difference %1").arg(diff)));

    auto w = openWindow(scene);
    QVERIFY(w);
    ViewerModel& m = w->model();
    m.setCamera(m.scene().view("cut"));
    QCOMPARE(m.camera().nearPlane, 4.5);
    // Showing what was drawn anew keeps them too.
    m.setObjectVisible(0, false);
    m.setObjectVisible(0, true);
    QCOMPARE(m.camera().nearPlane, 4.5);
    // A session keeps them; the saved file says so.
    settle(m);
    Session session = captureSession(m);
    const QString path = dir.filePath(QStringLiteral("cut.mfrsession"));
    writeSessionFile(path, session);
    QVERIFY(readSessionFile(path).camera.depthRangeGiven);
    QCOMPARE(runProgram(MFRVIEW, {path, "-m", "abuffer-ll", "--size", "64x48", "--screenshot", shot}, &out), 0);
    diff = maxChannelDifference(mfr::readPng(shot.toStdString()), mfr::readPng(cut.toStdString()));
    QVERIFY2(diff >= 0 && diff <= 1, qPrintable(QStringLiteral("session: difference %1").arg(diff)));
    // Moving the camera fits them again, so navigating never clips the scene: each gesture, the
    // projection toggled, a standard view and fit.
    const mfr::Camera cutView = m.scene().view("cut");
    const QSize view = m.renderSize();
    for (const mfr::Camera& moved :
         {navigation::orbit(cutView, QPointF(1, 0), view), navigation::pan(cutView, QPointF(1, 0), view),
          navigation::zoomAt(cutView, QPointF(10, 10), view, 1.0), navigation::toggledProjection(cutView),
          navigation::standardView(navigation::StandardView::Front, m.scene(), cutView), m.scene().fit(cutView)}) {
      m.setCamera(cutView);
      QCOMPARE(m.camera().nearPlane, 4.5);
      m.setCamera(moved);
      QVERIFY(!m.camera().depthRangeGiven);
      QVERIFY2(m.camera().nearPlane < 4.0, qPrintable(QString::number(m.camera().nearPlane)));
    }
    // A fitted camera's session fits again on reload.
    QVERIFY(!captureSession(m).camera.depthRangeGiven);
  }

  // A budget in force holds for a picture of another size than the view's: the k fitted to the
  // view was used for the export, so --screenshot's picture changed with --window-size and took up
  // to 2.6 times the budget (a bug hunt). The k expected is the largest whose bytes at the
  // export's size (mfr render --stats) fit the budget.
  void budgetHoldsAtTheExportSize() {
    QTemporaryDir dir;
    QString out;
    const double budget = 2.0 * 1024 * 1024;
    int expectedK = 0;
    for (int k = 1; k <= 6; ++k) {
      const QString png = dir.filePath(QStringLiteral("k%1.png").arg(k)), stats = dir.filePath("stats.json");
      QCOMPARE(runProgram(MFR_CLI,
                          {"render", "@sample", "-m", "kplus-array", "-p", QStringLiteral("k=%1").arg(k), "-s",
                           "320x240", "-o", png, "--stats", stats},
                          &out),
               0);
      QFile f(stats);
      QVERIFY(f.open(QIODevice::ReadOnly));
      if (QJsonDocument::fromJson(f.readAll()).object().value("bytes_allocated").toDouble() <= budget) expectedK = k;
    }
    QCOMPARE(expectedK, 2);  // measured: k = 2 takes 1,536,032 bytes, k = 3 2,150,432
    for (const char* window : {"1100x700", "1500x1000"}) {
      const QString png = dir.filePath(QStringLiteral("shot-%1.png").arg(window));
      QCOMPARE(
          runProgram(MFRVIEW,
                     {"@sample", "-m", "kplus-array", "--plugin-settings", R"(budget={"budget_mib":2,"driving":true})",
                      "--window-size", window, "--size", "320x240", "--screenshot", png},
                     &out),
          0);
      QVERIFY2(maxChannelDifference(mfr::readPng(png.toStdString()),
                                    mfr::readPng(dir.filePath("k2.png").toStdString())) <= 1,
               window);
    }
    // In the viewer itself, for methods whose bytes per slot are not the panel's first guess (8 per
    // pixel: kpeel's are 16, kbuffer-zmerge's 12; the tries swung over and under the budget: a
    // review) and for a pool: the export's bytes fit, and for slots one more would not.
    auto w = openWindow();
    QVERIFY(w);
    ViewerModel& m = w->model();
    MfrViewerPlugin* panel = loadedPlugin(*w, QStringLiteral("budget"));
    QVERIFY(panel);
    const QSize exportSize(320, 240);
    QVERIFY(m.imageSize() != exportSize);
    for (const auto& [method, param] : std::vector<std::pair<QString, std::string>>{
             {"kpeel", "k"}, {"kbuffer-zmerge", "k"}, {"kplus-array", "k"}, {"abuffer-ll", "pool_mib"}}) {
      m.setMethod(method);
      panel->loadSettings(QJsonObject{{"budget_mib", 8}, {"driving", true}});
      settle(m);
      const MainWindow::ExportRender render = w->renderForExport(exportSize);
      const double budgetBytes = 8.0 * 1024 * 1024;
      QVERIFY2(static_cast<double>(render.output.stats.bytesAllocated) <= budgetBytes, qPrintable(method));
      QVERIFY2(render.pluginParams.contains(param), qPrintable(method));
      if (param == "k") {
        const long long k = std::stoll(render.pluginParams.at(param));
        const mfr::RenderOutput more = w->view().renderOutput(exportSize, {{param, std::to_string(k + 1)}});
        QVERIFY2(static_cast<double>(more.stats.bytesAllocated) > budgetBytes, qPrintable(method));
      }
    }
    w.reset();

    // -p of the parameter the budget drives was replaced by the budget's k, exit 0 (a bug hunt).
    const QString png = dir.filePath("conflict.png");
    QCOMPARE(runProgram(MFRVIEW,
                        {"@sample", "-m", "kplus-array", "-p", "k=7", "--plugin-settings",
                         R"(budget={"budget_mib":2,"driving":true})", "--size", "320x240", "--screenshot", png},
                        &out),
             2);
    QVERIFY2(out.contains("mfrview: -p k=7: a plugin's settings set k="), qPrintable(out));
    QVERIFY(!QFile::exists(png));
    // The same when the render of the plugin's value fails: the -p given is named, not the value
    // the plugin put in its place (dkb -p budget_mib=20 read "--param budget_mib=1: below what dkb
    // needs", exit 1; a bug hunt).
    QCOMPARE(runProgram(MFRVIEW,
                        {"@sample", "-m", "dkb", "-p", "budget_mib=20", "--plugin-settings",
                         R"(budget={"budget_mib":1,"driving":true})", "--size", "320x240", "--screenshot", png},
                        &out),
             2);
    QCOMPARE(out.trimmed().split(QLatin1Char('\n')).constLast(),
             QStringLiteral("mfrview: -p budget_mib=20: a plugin's settings set budget_mib=1 in its place (the budget "
                            "panel drives it); give one of the two"));
    QVERIFY(!QFile::exists(png));
    // A budget below the least k or pool at the export's size: no picture, rather than one over
    // the budget (k = 1 at 800x600 takes 5.5 MiB; written with exit 0: a bug hunt).
    for (const auto& [method, knob] : {std::pair{"kplus-array", "k=1 ("}, std::pair{"abuffer-ll", "pool_mib="}}) {
      const QString tight = dir.filePath(QStringLiteral("tight-%1.png").arg(method));
      QCOMPARE(runProgram(MFRVIEW,
                          {"@sample", "-m", method, "--plugin-settings", R"(budget={"budget_mib":1,"driving":true})",
                           "--size", "800x600", "--screenshot", tight},
                          &out),
               1);
      QVERIFY2(out.contains(
                   QStringLiteral("mfrview: budget 1 MiB: below what %1 needs at 800x600 with %2").arg(method, knob)),
               qPrintable(out));
      QVERIFY(!QFile::exists(tight));
    }
  }

  // `mfrview --screenshot` renders only its picture: the window draws no frame (a volume at a
  // fine step spent 100 s on the window's first frame, 60 times the picture's; a bug hunt). A
  // budget in force is fitted at the export's size even where that is the view's own size, which
  // the view has measured nothing at: the panel's first guess (8 bytes a slot) gave kpeel (16) k = 17,
  // twice the budget. A budget the picture cannot keep names --plugin-settings, which set
  // it, not a --param the command line lacks.
  void screenshotDrawsNoLiveFrame() {
    auto w = openWindow(QString());
    QVERIFY(w);
    ViewerModel& m = w->model();
    w->view().setLiveFrames(false);
    m.setMethod(QStringLiteral("kpeel"));
    w->openScene(QStringLiteral("@sample"));
    QVERIFY(QTest::qWaitFor([&] { return m.hasScene() && w->view().glReady() && !m.busy(); }, kTimeoutMs));
    MfrViewerPlugin* panel = loadedPlugin(*w, QStringLiteral("budget"));
    QVERIFY(panel);
    panel->loadSettings(QJsonObject{{"budget_mib", 32}, {"driving", true}});
    QTest::qWait(500);
    QCOMPARE(m.framesRendered(), 0);
    const QSize own = m.imageSize();
    QVERIFY(own.width() > 100);
    MainWindow::ExportRender render;
    try {
      render = w->renderForExport(own);
    } catch (const std::exception& e) {
      QFAIL(e.what());
    }
    const double budgetBytes = 32.0 * 1024 * 1024;
    QVERIFY2(static_cast<double>(render.output.stats.bytesAllocated) <= budgetBytes,
             qPrintable(QString::number(render.output.stats.bytesAllocated)));
    QVERIFY(render.pluginParams.contains("k"));
    const long long k = std::stoll(render.pluginParams.at("k"));
    const mfr::RenderOutput more = w->view().renderOutput(own, {{"k", std::to_string(k + 1)}});
    QVERIFY(static_cast<double>(more.stats.bytesAllocated) > budgetBytes);
    QCOMPARE(m.framesRendered(), 0);
    // Turned on again, the window draws.
    w->view().setLiveFrames(true);
    QVERIFY(QTest::qWaitFor([&] { return m.framesRendered() > 0; }, kTimeoutMs));
    w.reset();

    QTemporaryDir dir;
    QString out;
    const QString png = dir.filePath("fkb.png");
    QCOMPARE(runProgram(MFRVIEW,
                        {"@sample", "-m", "fkb", "--plugin-settings", R"(budget={"budget_mib":1,"driving":true})",
                         "--size", "800x600", "--screenshot", png},
                        &out),
             1);
    QVERIFY2(out.contains("mfrview: --plugin-settings budget: budget_mib=1: below what k = 1 needs at 800x600"),
             qPrintable(out));
    QVERIFY(!QFile::exists(png));
    // Given on the command line, it is named as mfr render names it.
    QCOMPARE(runProgram(MFRVIEW,
                        {"@sample", "-m", "fkb", "-p", "budget_mib=1", "--size", "800x600", "--screenshot", png}, &out),
             1);
    QVERIFY2(out.contains("mfrview: --param budget_mib=1: below what k = 1 needs at 800x600"), qPrintable(out));
    // Set by a session: the session is named (it said "--param budget_mib=0.5"; a review).
    const QString sessionPath = dir.filePath("fkb.mfrsession");
    {
      auto s = openWindow();
      QVERIFY(s);
      s->model().setMethod(QStringLiteral("fkb"));
      s->model().setParams({{"budget_mib", "0.5"}});
      writeSessionFile(sessionPath, captureSession(s->model()));
    }
    QCOMPARE(runProgram(MFRVIEW, {sessionPath, "--size", "800x600", "--screenshot", png}, &out), 1);
    QVERIFY2(
        out.contains(QStringLiteral("mfrview: %1: budget_mib=0.5: below what k = 1 needs at 800x600").arg(sessionPath)),
        qPrintable(out));
    QVERIFY(!out.contains("--param"));
    // The window itself draws no frame for --screenshot, and does for --window-screenshot (the
    // frames Qt's logging category reports).
    qputenv("QT_LOGGING_RULES", "mfr.view.frames.debug=true");
    QCOMPARE(runProgram(MFRVIEW, {"@sample", "-m", "abuffer-ll", "--size", "64x48", "--screenshot", png}, &out), 0);
    const bool framesWithScreenshot = out.contains("mfr.view.frames: frame ");
    const QString window = dir.filePath("window.png");
    QCOMPARE(
        runProgram(MFRVIEW, {"@sample", "-m", "abuffer-ll", "--window-size", "900x600", "--window-screenshot", window},
                   &out),
        0);
    qunsetenv("QT_LOGGING_RULES");
    QVERIFY2(!framesWithScreenshot, "--screenshot drew window frames");
    QVERIFY2(out.contains("mfr.view.frames: frame "), qPrintable(out));
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
        // The clip box and section plane as the command lines give them.
        {"--method", "abuffer-ll", "--view", "iso", "--clip", "-2,-2,-2,0.3,2,0.5"},
        {"--method", "abuffer-ll", "--view", "iso", "--section", "0.1,0,0,1,0.5,0.2"},
        {"--method", "oracle", "--view", "iso", "--section", "-y=0.2:nocaps"},
        // fit and orbit:… frame the whole scene, cut or not (mfr render framed the kept half).
        {"--method", "abuffer-ll", "--section", "z=0"},
        {"--method", "abuffer-ll", "--view", "orbit:30:20", "--section", "z=0"},
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
    qInfo("viewer --screenshot vs mfr render: max channel difference %d over %lld cases", worst,
          static_cast<long long>(cases.size()));
    {
      // Without --view both start from the fit-all view, also where the scene's first view is a
      // camera of its own (the viewer drew that camera as written, mfr render fitted it).
      const QString scene = dir.filePath("views.mfrscene");
      QFile file(scene);
      QVERIFY(file.open(QIODevice::WriteOnly));
      file.write(R"({"objects": [{"primitive": {"type": "box"}, "opacity": 0.5},
                                  {"primitive": {"type": "sphere", "radius": 0.4}, "color": [0.9, 0.2, 0.2],
                                   "transform": {"translate": [1.5, 0, 0]}}],
                     "views": [{"name": "close", "eye": [0.2, 0.3, 1.2], "target": [0, 0, 0]},
                               {"name": "side", "eye": [5, 0, 0], "target": [0, 0, 0], "fit": true}]})");
      file.close();
      const QString viewerPng = dir.filePath("viewer.png"), cliPng = dir.filePath("cli.png"),
                    closePng = dir.filePath("close.png");
      QString out;
      const QStringList common{"--size", "120x90", "--method", "abuffer-ll"};
      QCOMPARE(runProgram(MFRVIEW, QStringList{scene, "--screenshot", viewerPng} + common, &out), 0);
      QCOMPARE(runProgram(MFR_CLI, QStringList{"render", scene, "-o", cliPng} + common, &out), 0);
      QCOMPARE(runProgram(MFR_CLI, QStringList{"render", scene, "-o", closePng, "--view", "close"} + common, &out), 0);
      const mfr::ImageRGBA8 viewer = mfr::readPng(viewerPng.toStdString());
      QVERIFY(maxChannelDifference(viewer, mfr::readPng(cliPng.toStdString())) <= 1);
      QVERIFY(maxChannelDifference(viewer, mfr::readPng(closePng.toStdString())) >
              16);  // the camera as written differs
    }
    {
      // A screenshot's name that says another format is refused before any work, as mfr's -o.
      const QString jpg = dir.filePath("shot.jpg");
      QString out;
      QCOMPARE(runProgram(MFRVIEW, {"@sample", "--screenshot", jpg, "--size", "64x48"}, &out), 2);
      QVERIFY2(out.contains("--screenshot " + jpg + ": the name says JPEG"), qPrintable(out));
      QVERIFY(!QFile::exists(jpg));
    }
    // What mfr render refuses, the screenshot refuses too, writing nothing (a scene of degenerate
    // triangles was an empty PNG and exit 0; found by fuzzing).
    const QString flat = dir.filePath("flat.obj"), flatPng = dir.filePath("flat.png");
    {
      QFile file(flat);
      QVERIFY(file.open(QIODevice::WriteOnly));
      file.write("v 0 0 0\nv 1 1 1\nv 2 2 2\nf 1 2 3\n");
    }
    QString out;
    // A plane or box the command line cannot read: the same one line as mfr's, exit 2.
    QCOMPARE(runProgram(MFRVIEW, {"@sample", "--screenshot", flatPng, "--section", "w=1"}, &out), 2);
    QVERIFY2(out.contains("--section w=1: expected AXIS=VALUE with AXIS one of x, y, z, -x, -y, -z and a number"),
             qPrintable(out));
    QCOMPARE(runProgram(MFRVIEW, {"@sample", "--screenshot", flatPng, "--clip", "1,1,1,0,0,0"}, &out), 2);
    QVERIFY2(out.contains("--clip 1,1,1,0,0,0: min must not exceed max on any axis"), qPrintable(out));
    // Settings for a plugin that is not there were dropped without a word.
    QCOMPARE(runProgram(MFRVIEW, {"@sample", "--screenshot", flatPng, "--plugin-settings", "nope={}"}, &out), 2);
    QVERIFY2(out.contains("--plugin-settings nope: no plugin of that id is loaded (loaded: "), qPrintable(out));
    // Two settings of one plugin: refused as -p refuses a parameter given twice (the last won).
    QCOMPARE(runProgram(MFRVIEW,
                        {"@sample", "--screenshot", flatPng, "--plugin-settings", R"(budget={"budget_mib":2})",
                         "--plugin-settings", R"(budget={"budget_mib":3})"},
                        &out),
             2);
    QVERIFY2(out.contains("--plugin-settings: plugin 'budget' is given twice"), qPrintable(out));
    QVERIFY(!QFile::exists(flatPng));
    for (const char* method : {"abuffer-ll", "oracle"}) {
      QCOMPARE(runProgram(MFRVIEW, {flat, "--screenshot", flatPng, "--size", "64x64", "--method", method}, &out), 1);
      QVERIFY2(out.contains("nothing to render (its one visible triangle is degenerate: no area)"), qPrintable(out));
      QVERIFY(!QFile::exists(flatPng));
      QCOMPARE(runProgram(MFR_CLI, {"render", flat, "-o", flatPng, "--size", "64x64", "--method", method}, &out), 1);
    }
  }

  // Without a display, --version and --help answer (Qt's xcb platform aborted them, exit 134) and
  // anything else is refused in one line instead of Qt's paragraph and an abort.
  void viewerWithoutADisplay() {
    const auto run = [](const QStringList& args, QString* out) {
      QProcess viewer;
      QProcessEnvironment env = QProcessEnvironment::systemEnvironment();
      env.remove(QStringLiteral("DISPLAY"));
      env.remove(QStringLiteral("WAYLAND_DISPLAY"));
      env.remove(QStringLiteral("QT_QPA_PLATFORM"));
      viewer.setProcessEnvironment(env);
      viewer.setProcessChannelMode(QProcess::MergedChannels);
      viewer.start(MFRVIEW, args);
      if (!viewer.waitForFinished(kTimeoutMs)) return -1;
      *out = QString::fromUtf8(viewer.readAll());
      return viewer.exitStatus() == QProcess::NormalExit ? viewer.exitCode() : -2;
    };
    QString out;
    QCOMPARE(run({QStringLiteral("--version")}, &out), 0);
    QVERIFY2(out.startsWith(QStringLiteral("mfrview ")), qPrintable(out));
    QCOMPARE(run({QStringLiteral("--help")}, &out), 0);
    QVERIFY2(out.contains(QStringLiteral("--screenshot")), qPrintable(out));
    QCOMPARE(run({QStringLiteral("@sample")}, &out), 1);
    const QStringList lines = out.split(QLatin1Char('\n'), Qt::SkipEmptyParts);
    QVERIFY2(lines.size() == 1 && lines[0].startsWith(QStringLiteral("mfrview: no display: DISPLAY is not set")),
             qPrintable(out));
    // A command line mfrview cannot read is said as such, exit 2, display or not (it said "no
    // display").
    QCOMPARE(run({QStringLiteral("--bogus")}, &out), 2);
    QVERIFY2(out.startsWith(QStringLiteral("mfrview: Unknown option 'bogus'")), qPrintable(out));
    QCOMPARE(run({QStringLiteral("--size"), QStringLiteral("10x")}, &out), 2);
    QVERIFY2(!out.contains(QStringLiteral("no display")), qPrintable(out));
  }

  // Under a comma-decimal locale (de_DE), QApplication's setlocale made mfrcore's std::stod read
  // "0.9" as 0: mboit's overestimation=0.9 bias=0.3 drew the image of 0 and 0 (RMSE 0.054 from
  // mfr render's). The locale is built with localedef into a temporary folder (LOCPATH).
  void viewerReadsNumbersInAnyLocale() {
    QTemporaryDir dir;
    QString out;
    QCOMPARE(runProgram(QStringLiteral("localedef"), {"-i", "de_DE", "-f", "UTF-8", dir.filePath("de_DE.UTF-8")}, &out),
             0);
    const QStringList common{"--size", "96x72", "--method", "mboit", "-p", "overestimation=0.9", "-p", "bias=0.3"};
    const QString viewerPng = dir.filePath("viewer.png"), cliPng = dir.filePath("cli.png"),
                  plainPng = dir.filePath("plain.png");
    QProcess viewer;
    QProcessEnvironment env = QProcessEnvironment::systemEnvironment();
    env.insert("LOCPATH", dir.path());
    env.insert("LC_ALL", "de_DE.UTF-8");
    viewer.setProcessEnvironment(env);
    viewer.setProcessChannelMode(QProcess::MergedChannels);
    viewer.start(MFRVIEW, QStringList{"@sample", "--screenshot", viewerPng} + common);
    QVERIFY(viewer.waitForFinished(kTimeoutMs));
    QVERIFY2(viewer.exitCode() == 0, viewer.readAll().constData());
    QCOMPARE(runProgram(MFR_CLI, QStringList{"render", "@sample", "-o", cliPng} + common, &out), 0);
    QCOMPARE(runProgram(MFR_CLI, {"render", "@sample", "-o", plainPng, "--size", "96x72", "--method", "mboit"}, &out),
             0);
    const mfr::ImageRGBA8 v = mfr::readPng(viewerPng.toStdString()), c = mfr::readPng(cliPng.toStdString());
    QVERIFY(maxChannelDifference(v, c) >= 0 && maxChannelDifference(v, c) <= 1);
    QVERIFY(maxChannelDifference(c, mfr::readPng(plainPng.toStdString())) > 8);  // the parameters show
  }

  // Operation "csg" on the built-in CSG sample: the viewer's screenshot equals mfr render's, and
  // the frame's quality is measured against the oracle's CSG image (against its "over" image the
  // opaque drilled block would be far off).
  void csgOperation() {
    QTemporaryDir dir;
    const QString viewerPng = dir.filePath("viewer.png"), cliPng = dir.filePath("cli.png");
    const QStringList common{"--size", "200x150", "--method", "abuffer-sbuffer", "--op", "csg", "--view", "iso"};
    QString out;
    QCOMPARE(runProgram(MFRVIEW, QStringList{"@csg", "--screenshot", viewerPng} + common, &out), 0);
    QCOMPARE(runProgram(MFR_CLI, QStringList{"render", "@csg", "-o", cliPng} + common, &out), 0);
    const int diff = maxChannelDifference(mfr::readPng(viewerPng.toStdString()), mfr::readPng(cliPng.toStdString()));
    QVERIFY2(diff >= 0 && diff <= 1, qPrintable(QString::number(diff)));

    auto w = openWindow(QStringLiteral("@csg"));
    QVERIFY(w);
    ViewerModel& m = w->model();
    m.setMethod("abuffer-sbuffer");
    m.setOperation(QStringLiteral("csg"));
    m.setCamera(m.scene().view("iso"));
    settle(m);
    QCOMPARE(QString::fromStdString(m.stats().operation), QStringLiteral("csg"));
    m.requestFrameQuality();
    QTRY_VERIFY_WITH_TIMEOUT(m.frameQuality().valid, kTimeoutMs);
    qInfo("@csg abuffer-sbuffer csg: RMSE %.6f against the oracle's CSG", m.frameQuality().rmse);
    QVERIFY(m.frameQuality().rmse < 0.02);
  }

  // The CSG plugin: the built-in tree shown, the switch choosing an A-buffer and the operation,
  // a new tree from checked parts, a refused tree leaving the scene alone, removal; every image
  // against the oracle's CSG of the model's scene.
  void csgPanel() {
    auto w = openWindow(QStringLiteral("@csg"));
    QVERIFY(w);
    ViewerModel& m = w->model();
    auto* panel = w->findChild<QWidget*>("csgPanel");
    QVERIFY(panel);
    auto* text = w->findChild<QPlainTextEdit*>("csgText");
    auto* show = w->findChild<QCheckBox*>("csgShow");
    auto* error = w->findChild<QLabel*>("csgError");
    QVERIFY(text && show && error);
    QVERIFY2(text->toPlainText().contains("drill x"), qPrintable(text->toPlainText()));
    const auto oracleCsg = [&] {
      mfr::RenderRequest request;
      request.operation = "csg";
      request.width = m.renderSize().width();
      request.height = m.renderSize().height();
      return mfr::render(m.scene(), m.camera(), request).image;
    };

    m.setMethod("kplus-array");  // cannot carry object ids: the switch picks an A-buffer
    m.setCamera(m.scene().view("iso"));
    show->setChecked(true);
    QCOMPARE(m.operation(), QStringLiteral("csg"));
    QCOMPARE(m.method(), QStringLiteral("abuffer-sbuffer"));
    settle(m);
    const mfr::ImageRGBA8 drilled = w->view().renderImage(m.renderSize());
    QVERIFY(mfr::rmse(oracleCsg(), drilled) < 0.02);

    for (int i = 0; i < 4; ++i) {
      QListWidgetItem* item = w->findChild<QListWidget*>("csgObjects")->item(i);
      item->setCheckState(item->text() == "block" || item->text() == "drill x" ? Qt::Checked : Qt::Unchecked);
    }
    w->findChild<QPushButton*>("csg_difference")->click();
    QCOMPARE(QString::fromStdString(mfr::csgText(m.scene().csg, m.scene())),
             QStringLiteral("{\"difference\":[\"block\",\"drill x\"]}"));
    QVERIFY(error->text().isEmpty());
    settle(m);
    const mfr::ImageRGBA8 block = w->view().renderImage(m.renderSize());
    QVERIFY(mfr::rmse(oracleCsg(), block) < 0.02);
    QVERIFY(mfr::rmse(drilled, block) > 0.02);  // the ball no longer rounds the corners

    // Sessions keep the edited tree and the operation.
    QTemporaryDir dir;
    const QString sessionPath = dir.filePath("csg.mfrsession");
    w->saveSession(sessionPath);
    {
      auto again = openWindow(QString());
      QVERIFY(again);
      again->openSession(sessionPath);
      ViewerModel& a = again->model();
      QTRY_VERIFY_WITH_TIMEOUT(a.hasScene() && a.framesRendered() > 0, kTimeoutMs);
      QTRY_COMPARE_WITH_TIMEOUT(QString::fromStdString(mfr::csgText(a.scene().csg, a.scene())),
                                QStringLiteral("{\"difference\":[\"block\",\"drill x\"]}"), kTimeoutMs);
      QCOMPARE(a.operation(), QStringLiteral("csg"));
      QVERIFY(again->findChild<QCheckBox*>("csgShow")->isChecked());
    }

    text->setPlainText(QStringLiteral("{\"union\": [\"block\"]}"));
    w->findChild<QPushButton*>("csgApply")->click();
    QVERIFY2(error->text().contains("at least 2"), qPrintable(error->text()));
    QCOMPARE(QString::fromStdString(mfr::csgText(m.scene().csg, m.scene())),
             QStringLiteral("{\"difference\":[\"block\",\"drill x\"]}"));

    // Settings without "tree" keep the scene's tree (`--plugin-settings csg={}` cleared it: a bug hunt).
    MfrViewerPlugin* csgPlugin = loadedPlugin(*w, QStringLiteral("csg"));
    QVERIFY(csgPlugin);
    csgPlugin->loadSettings(QJsonObject{});
    QCOMPARE(QString::fromStdString(mfr::csgText(m.scene().csg, m.scene())),
             QStringLiteral("{\"difference\":[\"block\",\"drill x\"]}"));

    w->findChild<QPushButton*>("csgClear")->click();
    QVERIFY(m.scene().csg.empty());
    QVERIFY(!show->isChecked());
    QCOMPARE(m.operation(), QStringLiteral("auto"));

    // Another scene without a tree while the switch is on: operation auto, with a note, and a
    // frame (the view said "operation csg: scene 'sample' has no CSG tree": a bug hunt).
    w->openScene(QStringLiteral("@csg"));
    QTRY_VERIFY_WITH_TIMEOUT(!m.scene().csg.empty() && m.sceneSerial() > 0, kTimeoutMs);
    show->setChecked(true);
    QCOMPARE(m.operation(), QStringLiteral("csg"));
    QStringList notes;
    connect(&m, &ViewerContext::noted, this, [&notes](const QString& note) { notes << note; });
    const quint64 serial = m.sceneSerial();
    w->openScene(QStringLiteral("@sample"));
    QTRY_VERIFY_WITH_TIMEOUT(m.sceneSerial() > serial, kTimeoutMs);
    QCOMPARE(m.operation(), QStringLiteral("auto"));
    QVERIFY(!show->isChecked());
    QCOMPARE(notes, QStringList{"operation csg: scene 'sample' has no CSG tree: auto is used"});
    settle(m);
    QVERIFY2(m.renderError().isEmpty(), qPrintable(m.renderError()));
  }

  // Operation "zthickness" on the intersecting-surfaces sample: `mfrview --screenshot` equals
  // `mfr render` (an explicit thickness and the default one) and differs from "over"; the live
  // frame notes its thickness, is measured against the oracle's z-thickness image of the same
  // thickness (compare mode: the oracle's own pane is then exact), and every method the viewer
  // says can run zthickness does, the others refuse it.
  void zthicknessOperation() {
    QTemporaryDir dir;
    const auto png = [&](const QString& name) { return dir.filePath(name); };
    QString out;
    const QList<QStringList> cases{
        {"--method", "abuffer-ll", "--op", "zthickness", "--thickness", "0.05", "--view", "iso"},
        {"--method", "kbuffer", "-p", "k=16", "--op", "zthickness", "--view", "front"},
    };
    for (const QStringList& c : cases) {
      const QStringList common = QStringList{"--size", "200x150"} + c;
      QCOMPARE(runProgram(MFRVIEW, QStringList{"@intersect", "--screenshot", png("viewer.png")} + common, &out), 0);
      QCOMPARE(runProgram(MFR_CLI, QStringList{"render", "@intersect", "-o", png("cli.png")} + common, &out), 0);
      const mfr::ImageRGBA8 viewer = mfr::readPng(png("viewer.png").toStdString());
      const int diff = maxChannelDifference(viewer, mfr::readPng(png("cli.png").toStdString()));
      qInfo("@intersect %s: viewer vs mfr render max channel difference %d", qPrintable(c.join(' ')), diff);
      QVERIFY2(diff >= 0 && diff <= 1, qPrintable(c.join(' ') + ": " + QString::number(diff)));
      QStringList oit = common;
      oit[oit.indexOf("zthickness")] = "oit";
      if (const qsizetype t = oit.indexOf("--thickness"); t >= 0) oit.remove(t, 2);  // oit takes none
      QCOMPARE(runProgram(MFR_CLI, QStringList{"render", "@intersect", "-o", png("oit.png")} + oit, &out), 0);
      const double fromOit = mfr::rmse(viewer, mfr::readPng(png("oit.png").toStdString()));
      qInfo("  RMSE against --op oit: %.5f", fromOit);
      QVERIFY(fromOit > 0.005);
    }
    // A thickness the CLI would refuse ends a scripted viewer run too.
    QCOMPARE(runProgram(MFRVIEW, {"@intersect", "--screenshot", png("bad.png"), "--op", "zthickness", "--thickness=-1"},
                        &out),
             2);
    QVERIFY2(out.contains("--thickness"), qPrintable(out));

    auto w = openWindow(QStringLiteral("@intersect"));
    QVERIFY(w);
    ViewerModel& m = w->model();
    w->view().setFixedSize(240, 160);
    QTRY_COMPARE_WITH_TIMEOUT(m.renderSize(), QSize(240, 160), kTimeoutMs);
    m.setMethod("abuffer-ll");
    m.setCamera(m.scene().view("iso"));
    auto* operation = w->findChild<QComboBox*>("operationCombo");
    auto* thickness = w->findChild<QDoubleSpinBox*>("zThickness");
    QVERIFY(operation && thickness);
    operation->setCurrentIndex(operation->findData(QStringLiteral("zthickness")));
    QCOMPARE(m.operation(), QStringLiteral("zthickness"));
    thickness->setValue(0.05);
    QCOMPARE(m.zThickness(), 0.05);
    QCOMPARE(m.renderRequest(QSize(8, 8)).thickness, 0.05);
    settle(m);
    QVERIFY2(m.renderError().isEmpty(), qPrintable(m.renderError()));
    QCOMPARE(QString::fromStdString(m.stats().operation), QStringLiteral("zthickness"));
    const auto note = [&m]() -> std::string {
      for (const auto& [name, value] : m.stats().notes)
        if (name == "z-thickness") return value;
      return {};
    };
    QCOMPARE(numberOf(note()), 0.05);
    // The default (thickness 0) is 1 % of the diagonal, as the renderers make it.
    const mfr::Bounds b = m.scene().bounds();
    QVERIFY(std::abs(m.zThicknessDefault() - 0.01 * glm::length(b.max - b.min)) < 1e-12);
    m.setZThickness(0.0);
    settle(m);
    QCOMPARE(numberOf(note()), m.zThicknessDefault());
    QVERIFY(thickness->specialValueText().contains("default"));
    m.setZThickness(0.05);

    // Frame quality against the oracle's z-thickness image of the same thickness.
    const auto oracle = [&m](const std::string& op, QSize size) {
      mfr::RenderRequest request;
      request.operation = op;
      request.thickness = m.zThickness();
      request.width = size.width();
      request.height = size.height();
      return mfr::render(m.scene(), m.camera(), request).image;
    };
    QCOMPARE(m.referenceRequest(0).operation, std::string("zthickness"));
    QCOMPARE(m.referenceRequest(0).thickness, 0.05);
    settle(m);
    m.requestFrameQuality();
    QTRY_VERIFY_WITH_TIMEOUT(m.frameQuality().valid, kTimeoutMs);
    const mfr::ImageRGBA8 frame = w->view().renderImage(m.renderSize());
    const double exact = mfr::rmse(oracle("zthickness", m.renderSize()), frame);
    const double fromOit = mfr::rmse(oracle("oit", m.renderSize()), frame);
    qInfo("@intersect abuffer-ll zthickness 0.05: frame quality RMSE %.6f (recomputed %.6f; against oit %.6f)",
          m.frameQuality().rmse, exact, fromOit);
    QVERIFY(std::abs(m.frameQuality().rmse - exact) < 1e-9);
    QVERIFY(std::abs(m.frameQuality().rmse - fromOit) > 1e-4);

    // Compare mode: side B the oracle with zthickness, measured against itself: exact.
    m.setOperationOf(1, QStringLiteral("zthickness"));
    m.setMethodOf(1, QStringLiteral("oracle"));
    m.setCompareEnabled(true);
    settle(m);
    QTRY_VERIFY_WITH_TIMEOUT(m.metricsCurrent(0) && m.metricsCurrent(1), kTimeoutMs);
    QVERIFY2(m.metrics(0).valid && m.metrics(1).valid, qPrintable(m.metrics(0).error + m.metrics(1).error));
    qInfo("compare: abuffer-ll RMSE %.6f, oracle RMSE %.6f", m.metrics(0).rmse, m.metrics(1).rmse);
    QCOMPARE(m.metrics(1).rmse, 0.0);
    QVERIFY(std::abs(m.metrics(0).rmse -
                     mfr::rmse(oracle("zthickness", m.paneSize()), crop(fromQImage(w->view().grabFramebuffer()),
                                                                        QRect(QPoint(0, 0), m.paneSize())))) < 1e-9);
    // Another thickness is another image, re-rendered and re-measured.
    const PaneMetrics before = m.metrics(0);
    m.setZThickness(0.3);
    QVERIFY(!m.metricsCurrent(0) && !m.metricsCurrent(1));
    settle(m);
    QTRY_VERIFY_WITH_TIMEOUT(m.metricsCurrent(0) && m.metricsCurrent(1), kTimeoutMs);
    QCOMPARE(m.metrics(1).rmse, 0.0);
    QVERIFY(m.metrics(0).key != before.key);
    m.setCompareEnabled(false);

    // supportsOperation says which methods can run it: exactly those that do.
    w->view().setFixedSize(96, 64);
    QTRY_COMPARE_WITH_TIMEOUT(m.renderSize(), QSize(96, 64), kTimeoutMs);
    for (const mfr::RegistryEntry& e : mfr::methodRegistry()) {
      const QString name = QString::fromStdString(e.name);
      m.setMethod(name);
      settle(m);
      const bool supported = m.supportsOperation(name, QStringLiteral("zthickness"));
      qInfo("%s: supports zthickness %d; render error: %s", e.name.c_str(), supported, qPrintable(m.renderError()));
      QVERIFY2(m.renderError().isEmpty() == supported, qPrintable(name + ": " + m.renderError()));
      if (supported) QCOMPARE(QString::fromStdString(m.stats().operation), QStringLiteral("zthickness"));
    }
    QVERIFY(m.supportsOperation(QStringLiteral("oracle"), QStringLiteral("zthickness")));
    // kbuffer-zmerge's own operation is zthickness: on "auto" the method panel shows the Thickness
    // row (it showed it only for an operation set to "zthickness"; review 28), and another
    // thickness draws the view again.
    auto* thicknessBox = w->findChild<QDoubleSpinBox*>(QStringLiteral("zThickness"));
    QVERIFY(thicknessBox);
    m.setMethod(QStringLiteral("oracle"));
    m.setOperationOf(0, QStringLiteral("auto"));
    m.setOperationOf(1, QStringLiteral("oit"));  // the hidden side B's zthickness would draw the view too
    settle(m);
    QVERIFY(!thicknessBox->isVisibleTo(thicknessBox->window()));
    m.setMethod(QStringLiteral("kbuffer-zmerge"));
    settle(m);
    QCOMPARE(m.effectiveOperationOf(0), QStringLiteral("zthickness"));
    QVERIFY(thicknessBox->isVisibleTo(thicknessBox->window()));
    const quint64 drawn = m.framesRendered();
    m.setZThickness(0.11);
    QTRY_VERIFY_WITH_TIMEOUT(m.framesRendered() > drawn, kTimeoutMs);
  }

  // The Ghosting plugin on @intersect: the blend switch (picking an A-buffer for a method without
  // sorted lists, and back), the thickness slider and spin box driving the frame's z-thickness,
  // ghosting of the parts not in focus (and their opacities back), and its settings in sessions.
  // Parts of one name keep their own focus and ghosted opacity through saved settings (by the
  // name alone the second part took the first's), and ghosted values of another type or range,
  // names the scene lacks and a ghost opacity between the slider's hundredths are notes (taken
  // without a word: a string read as 0, 5 clamped, 0.025 drawn as 0.03; a bug hunt).
  void ghostingKeepsPartsOfOneNameApart() {
    QTemporaryDir dir;
    const QString scene = dir.filePath("dup.mfrscene");
    {
      QFile f(scene);
      QVERIFY(f.open(QIODevice::WriteOnly));
      f.write(R"({"objects": [
        {"name": "dup", "primitive": {"type": "sphere", "radius": 0.5}, "opacity": 0.8},
        {"name": "dup", "primitive": {"type": "box", "size": [1, 1, 1]}, "opacity": 0.7,
         "transform": {"translate": [1.5, 0, 0]}},
        {"name": "ball", "primitive": {"type": "sphere", "radius": 0.4}, "opacity": 0.9,
         "transform": {"translate": [-1.5, 0, 0]}}]})");
    }
    auto w = openWindow(scene);
    QVERIFY(w);
    ViewerModel& m = w->model();
    MfrViewerPlugin* ghosting = loadedPlugin(*w, QStringLiteral("ghosting"));
    QVERIFY(ghosting);
    QStringList notes;
    connect(&m, &ViewerContext::noted, this, [&notes](const QString& text) { notes << text; });
    ghosting->loadSettings(QJsonObject{{"focus", QJsonArray{"dup#1"}}, {"ghost", true}, {"ghost_opacity", 0.2}});
    QVERIFY2(notes.isEmpty(), qPrintable(notes.join('|')));
    QVERIFY(std::abs(m.objectOpacity(0) - 0.2) < 1e-6);  // the first "dup": ghosted
    QVERIFY(std::abs(m.objectOpacity(1) - 0.7) < 1e-6);  // the second: the focus
    const QJsonObject saved = ghosting->saveSettings();
    QCOMPARE(saved.value("focus").toArray(), QJsonArray{"dup#1"});
    const QJsonObject before = saved.value("ghosted").toObject();
    QCOMPARE(before.keys(), (QStringList{"ball", "dup"}));  // the focus "dup#1" is not ghosted
    QVERIFY(std::abs(before.value("dup").toDouble() - 0.8) < 1e-6);
    // The saved settings give the same state again: ghosting off restores each part's own opacity.
    ghosting->loadSettings(saved);
    w->findChild<QCheckBox*>("ghostOthers")->setChecked(false);
    QVERIFY(std::abs(m.objectOpacity(0) - 0.8) < 1e-6);
    QVERIFY(std::abs(m.objectOpacity(2) - 0.9) < 1e-6);
    ghosting->loadSettings(QJsonObject{{"focus", QJsonArray{"ball"}},
                                       {"ghost", true},
                                       {"ghost_opacity", 0.025},
                                       {"ghosted", QJsonObject{{"dup", "x"}, {"dup#1", 5}, {"nosuch", 0.5}}}});
    QCOMPARE(notes, (QStringList{"ghosting: ghost_opacity 0.025 is not a whole hundredth: 0.03 is used",
                                 "ghosting: ghosted 'dup': expected an opacity in 0 … 1 (left out)",
                                 "ghosting: ghosted 'dup#1': expected an opacity in 0 … 1 (left out)",
                                 "ghosting: ghosted: no part 'nosuch' in this scene (left out)"}));
    // A part named "dup#1" beside two "dup"s: the second "dup" is "dup#2", and each keeps its focus.
    // (The file spells '#' as \u0023: moc misreads a '#' inside a raw string.)
    const auto writeDups = [&dir](const QString& name, double first, double hashed, double second) {
      QFile f(dir.filePath(name));
      if (!f.open(QIODevice::WriteOnly)) return false;
      f.write(QStringLiteral(R"({"objects": [
        {"name": "dup", "primitive": {"type": "sphere", "radius": 0.5}, "opacity": %1},
        {"name": "dup\u00231", "primitive": {"type": "sphere", "radius": 0.3}, "opacity": %2,
         "transform": {"translate": [0, 1.5, 0]}},
        {"name": "dup", "primitive": {"type": "box", "size": [1, 1, 1]}, "opacity": %3,
         "transform": {"translate": [1.5, 0, 0]}}]})")
                  .arg(first)
                  .arg(hashed)
                  .arg(second)
                  .toUtf8());
      return true;
    };
    QVERIFY(writeDups("taken.mfrscene", 0.8, 0.6, 0.7));
    auto t = openWindow(dir.filePath("taken.mfrscene"));
    QVERIFY(t);
    MfrViewerPlugin* ghostingT = loadedPlugin(*t, QStringLiteral("ghosting"));
    QVERIFY(ghostingT);
    ghostingT->loadSettings(QJsonObject{{"focus", QJsonArray{"dup#2"}}, {"ghost", true}, {"ghost_opacity", 0.2}});
    QVERIFY(std::abs(t->model().objectOpacity(0) - 0.2) < 1e-6);
    QVERIFY(std::abs(t->model().objectOpacity(1) - 0.2) < 1e-6);  // "dup#1", the part of that name: ghosted
    QVERIFY(std::abs(t->model().objectOpacity(2) - 0.7) < 1e-6);  // the second "dup": the focus
    const QJsonObject savedT = ghostingT->saveSettings();
    QCOMPARE(savedT.value("focus").toArray(), QJsonArray{"dup#2"});
    QCOMPARE(savedT.value("ghosted").toObject().keys(), (QStringList{"dup", "dup#1"}));
    // Another file whose parts have the same names starts with nothing in focus and ghosting off:
    // the panel kept both, and turning ghosting off then gave its parts the old file's opacities.
    QVERIFY(writeDups("other.mfrscene", 0.5, 0.4, 0.3));
    t->openScene(dir.filePath("other.mfrscene"));
    QTRY_COMPARE_WITH_TIMEOUT(t->model().scenePath(), dir.filePath("other.mfrscene"), kTimeoutMs);
    auto* ghostOthers = t->findChild<QCheckBox*>("ghostOthers");
    auto* ghostParts = t->findChild<QListWidget*>("ghostParts");
    QVERIFY(ghostOthers && ghostParts);
    QVERIFY(!ghostOthers->isChecked());
    for (int i = 0; i < ghostParts->count(); ++i) QCOMPARE(ghostParts->item(i)->checkState(), Qt::Unchecked);
    const QJsonObject savedOther = ghostingT->saveSettings();
    QCOMPARE(savedOther.value("ghost").toBool(), false);
    QVERIFY(savedOther.value("ghosted").toObject().isEmpty());
    ghostOthers->setChecked(true);
    ghostOthers->setChecked(false);
    for (const auto& [id, opacity] : {std::pair{0, 0.5}, std::pair{1, 0.4}, std::pair{2, 0.3}})
      QVERIFY2(std::abs(t->model().objectOpacity(id) - opacity) < 1e-6,
               qPrintable(QStringLiteral("part %1: %2").arg(id).arg(t->model().objectOpacity(id))));
  }

  // A loaded opacity scale is drawn as given, not at the slider's nearest step (2 drew as
  // 2.00373, 3 as 2.99348; a bug hunt); moving the slider takes its own steps again.
  void volumePanelKeepsTheGivenOpacityScale() {
    auto w = openWindow(QStringLiteral("@volume"));
    QVERIFY(w);
    MfrViewerPlugin* volume = loadedPlugin(*w, QStringLiteral("hybridvolume"));
    QVERIFY(volume);
    const double unit = w->model().scene().volumes[0].transfer.unitDistance;
    for (const double scale : {2.0, 3.0, 0.37}) {
      volume->loadSettings(QJsonObject{{"opacity_scale", scale}});
      QCOMPARE(volume->saveSettings().value("opacity_scale").toDouble(), scale);
      QVERIFY(std::abs(w->model().scene().volumes[0].transfer.unitDistance - unit / scale) <= 1e-12 * unit);
    }
    auto* slider = w->findChild<QSlider*>("hvOpacity");
    QVERIFY(slider);
    slider->setValue(slider->value() + 10);
    QVERIFY(std::abs(volume->saveSettings().value("opacity_scale").toDouble() - 0.37) > 1e-3);
  }

  void ghostingPanel() {
    auto w = openWindow(QStringLiteral("@intersect"));
    QVERIFY(w);
    ViewerModel& m = w->model();
    w->view().setFixedSize(200, 150);
    QTRY_COMPARE_WITH_TIMEOUT(m.renderSize(), QSize(200, 150), kTimeoutMs);
    QVERIFY2(w->findChild<QDockWidget*>("plugin-ghosting"), "ghosting plugin not loaded");
    auto* blend = w->findChild<QCheckBox*>("ghostBlend");
    auto* slider = w->findChild<QSlider*>("ghostThicknessSlider");
    auto* units = w->findChild<QDoubleSpinBox*>("ghostThickness");
    auto* parts = w->findChild<QListWidget*>("ghostParts");
    auto* ghost = w->findChild<QCheckBox*>("ghostOthers");
    auto* opacity = w->findChild<QSlider*>("ghostOpacity");
    auto* restore = w->findChild<QPushButton*>("ghostRestore");
    QVERIFY(blend && slider && units && parts && ghost && opacity && restore);
    const auto note = [&m]() -> std::string {
      for (const auto& [name, value] : m.stats().notes)
        if (name == "z-thickness") return value;
      return {};
    };

    // The switch: wboit keeps no lists, so the panel takes abuffer-ll; off, both come back.
    m.setMethod("wboit");
    m.setOperation("oit");
    m.setCamera(m.scene().view("iso"));
    QVERIFY(!blend->isChecked());
    blend->setChecked(true);
    QCOMPARE(m.operation(), QStringLiteral("zthickness"));
    QCOMPARE(m.method(), QStringLiteral("abuffer-ll"));
    settle(m);
    QVERIFY2(m.renderError().isEmpty(), qPrintable(m.renderError()));
    QCOMPARE(QString::fromStdString(m.stats().operation), QStringLiteral("zthickness"));
    QCOMPARE(numberOf(note()), m.zThicknessDefault());
    QCOMPARE(units->value(), std::round(m.zThicknessDefault() * 1e6) / 1e6);  // shown at the default
    const mfr::ImageRGBA8 thin = w->view().renderImage(m.renderSize());
    blend->setChecked(false);
    QCOMPARE(m.operation(), QStringLiteral("oit"));
    QCOMPARE(m.method(), QStringLiteral("wboit"));
    // On again, then the Method panel's operation clears it: the next on keeps abuffer-ll, and
    // its off keeps it too (a stale "previous method" brought wboit back: a bug hunt).
    blend->setChecked(true);
    m.setOperation("oit");
    QVERIFY(!blend->isChecked());
    QCOMPARE(m.method(), QStringLiteral("abuffer-ll"));
    blend->setChecked(true);
    QCOMPARE(m.method(), QStringLiteral("abuffer-ll"));
    blend->setChecked(false);
    QCOMPARE(m.method(), QStringLiteral("abuffer-ll"));
    QCOMPARE(m.operation(), QStringLiteral("oit"));
    // A method with sorted lists is kept; the operation menu's zthickness checks the switch.
    m.setMethod("kplus-array");
    blend->setChecked(true);
    QCOMPARE(m.method(), QStringLiteral("kplus-array"));
    m.setOperation("auto");
    QVERIFY(!blend->isChecked());
    m.setOperation("zthickness");
    QVERIFY(blend->isChecked());
    m.setMethod("abuffer-ll");

    // Thickness: the log slider in % of the diagonal, the spin box in scene units.
    const double diagonal = m.zThicknessDefault() / 0.01;
    slider->setValue(slider->maximum());  // 10 %
    QVERIFY(std::abs(m.zThickness() - 0.1 * diagonal) < 1e-9 * diagonal);
    QCOMPARE(m.renderRequest(QSize(8, 8)).thickness, m.zThickness());
    settle(m);
    QCOMPARE(numberOf(note()), m.zThickness());
    const mfr::ImageRGBA8 thick = w->view().renderImage(m.renderSize());
    qInfo("thickness 1 %% vs 10 %% of the diagonal: RMSE %.5f", mfr::rmse(thin, thick));
    QVERIFY(mfr::rmse(thin, thick) > 0.002);
    slider->setValue(0);  // 0.05 %
    QVERIFY(std::abs(m.zThickness() - 0.0005 * diagonal) < 1e-9 * diagonal);
    units->setValue(0.04);
    QCOMPARE(m.zThickness(), 0.04);
    const int expected =
        static_cast<int>(std::lround(std::log(0.04 / diagonal * 100.0 / 0.05) / std::log(200.0) * 1000.0));
    QCOMPARE(slider->value(), expected);
    settle(m);
    QCOMPARE(numberOf(note()), 0.04);
    w->findChild<QPushButton*>("ghostThicknessDefault")->click();
    QCOMPARE(m.zThickness(), 0.0);
    m.setZThickness(0.04);
    QCOMPARE(units->value(), 0.04);

    // Ghosting: "design" in focus, every other part at the slider's opacity; a part edited before
    // gets its own opacity back when ghosting goes off; Restore brings the loaded ones.
    const QStringList names = m.objectNames();
    std::vector<double> loaded;
    for (int i = 0; i < names.size(); ++i) loaded.push_back(m.objectOpacity(i));
    QCOMPARE(parts->count(), static_cast<int>(names.size()));
    const int design = static_cast<int>(names.indexOf("design")), ring = static_cast<int>(names.indexOf("ring"));
    QVERIFY(design >= 0 && ring >= 0);
    m.setObjectOpacity(ring, 0.6);
    parts->item(design)->setCheckState(Qt::Checked);
    const quint64 revision = m.sceneRevision();
    ghost->setChecked(true);
    QCOMPARE(m.sceneRevision(), revision + 1);  // one edit for all parts: one re-render
    const auto opacities = [&] {
      std::vector<double> now;
      for (int i = 0; i < names.size(); ++i) now.push_back(m.objectOpacity(i));
      return now;
    };
    const auto allOthersAt = [&](double value) {
      for (int i = 0; i < names.size(); ++i)
        if (i != design && std::abs(m.objectOpacity(i) - value) > 1e-6) return false;
      return std::abs(m.objectOpacity(design) - loaded[static_cast<std::size_t>(design)]) < 1e-6;
    };
    QVERIFY(allOthersAt(0.15));
    QCOMPARE(opacity->value(), 15);
    opacity->setValue(40);
    QVERIFY(allOthersAt(0.40));
    settle(m);
    const mfr::ImageRGBA8 ghosted = w->view().renderImage(m.renderSize());
    QVERIFY(mfr::rmse(ghosted, thick) > 0.002);
    // "ring" into focus: its own opacity (0.6) back at once.
    parts->item(ring)->setCheckState(Qt::Checked);
    QVERIFY(std::abs(m.objectOpacity(ring) - 0.6) < 1e-6);
    parts->item(ring)->setCheckState(Qt::Unchecked);
    QVERIFY(std::abs(m.objectOpacity(ring) - 0.4) < 1e-6);
    ghost->setChecked(false);
    for (int i = 0; i < names.size(); ++i)
      QVERIFY(std::abs(m.objectOpacity(i) - (i == ring ? 0.6 : loaded[static_cast<std::size_t>(i)])) < 1e-6);
    ghost->setChecked(true);
    restore->click();
    QVERIFY(!ghost->isChecked());
    for (int i = 0; i < names.size(); ++i)
      QVERIFY(std::abs(m.objectOpacity(i) - loaded[static_cast<std::size_t>(i)]) < 1e-6);
    // The scene tree shows the panel's edits.
    m.setObjectOpacity(ring, 0.6);
    ghost->setChecked(true);
    auto* tree = w->findChild<QTreeWidget*>("sceneTree");
    QCOMPARE(tree->topLevelItem(ring)->data(2, Qt::EditRole).toDouble(), 0.4);

    // Sessions: the thickness, the operation, the focus, ghosting with its opacity (and what the
    // ghosted parts had before); the plugin's settings are its saveSettings.
    const std::vector<double> ghostedOpacities = opacities();
    QTemporaryDir dir;
    const QString sessionPath = dir.filePath("ghost.mfrsession");
    w->saveSession(sessionPath);
    {
      auto again = openWindow(QString());
      QVERIFY(again);
      again->openSession(sessionPath);
      ViewerModel& a = again->model();
      QTRY_VERIFY_WITH_TIMEOUT(a.hasScene() && a.framesRendered() > 0, kTimeoutMs);
      auto* ghost2 = again->findChild<QCheckBox*>("ghostOthers");
      auto* parts2 = again->findChild<QListWidget*>("ghostParts");
      QTRY_VERIFY_WITH_TIMEOUT(ghost2->isChecked(), kTimeoutMs);
      QCOMPARE(a.operation(), QStringLiteral("zthickness"));
      QCOMPARE(a.zThickness(), 0.04);
      QVERIFY(again->findChild<QCheckBox*>("ghostBlend")->isChecked());
      QCOMPARE(again->findChild<QDoubleSpinBox*>("ghostThickness")->value(), 0.04);
      QCOMPARE(again->findChild<QSlider*>("ghostOpacity")->value(), 40);
      QCOMPARE(parts2->item(design)->checkState(), Qt::Checked);
      QCOMPARE(parts2->item(ring)->checkState(), Qt::Unchecked);
      for (int i = 0; i < names.size(); ++i)
        QVERIFY(std::abs(a.objectOpacity(i) - ghostedOpacities[static_cast<std::size_t>(i)]) < 1e-6);
      // Ghosting off there gives every part the opacity it had before ghosting (ring: 0.6).
      ghost2->setChecked(false);
      for (int i = 0; i < names.size(); ++i)
        QVERIFY(std::abs(a.objectOpacity(i) - (i == ring ? 0.6 : loaded[static_cast<std::size_t>(i)])) < 1e-6);
      MfrViewerPlugin* ghosting = loadedPlugin(*again, QStringLiteral("ghosting"));
      QVERIFY(ghosting);
      const QJsonObject settings = ghosting->saveSettings();
      QCOMPARE(settings.value("ghost").toBool(true), false);
      QCOMPARE(settings.value("focus").toArray(), QJsonArray{"design"});
    }
  }

  // Operation "volume" on the built-in volume sample: `mfrview --screenshot` equals `mfr render`
  // exactly (an explicit step, the default step, "auto" resolving to volume; three methods) and
  // differs from "over"; bad steps end a scripted run; the live frame notes its step, the method
  // panel's Step row drives it, and the frame quality is measured against the oracle's volume
  // image with the same step and the current transfer function (compare mode: the oracle's own
  // pane is exact).
  void volumeOperation() {
    QTemporaryDir dir;
    const auto png = [&](const QString& name) { return dir.filePath(name); };
    QString out;
    const QList<QStringList> cases{
        {"--method", "abuffer-ll", "--op", "volume", "--step", "0.02", "--view", "iso"},
        {"--method", "kbuffer", "-p", "k=16", "--op", "volume", "--view", "front"},
        {"--method", "abuffer-sbuffer", "--op", "auto", "--step", "0.03", "--view", "iso"},
    };
    for (const QStringList& c : cases) {
      const QStringList common = QStringList{"--size", "200x150"} + c;
      QCOMPARE(runProgram(MFRVIEW, QStringList{"@volume", "--screenshot", png("viewer.png")} + common, &out), 0);
      QCOMPARE(runProgram(MFR_CLI, QStringList{"render", "@volume", "-o", png("cli.png")} + common, &out), 0);
      const mfr::ImageRGBA8 viewer = mfr::readPng(png("viewer.png").toStdString());
      const int diff = maxChannelDifference(viewer, mfr::readPng(png("cli.png").toStdString()));
      qInfo("@volume %s: viewer vs mfr render max channel difference %d", qPrintable(c.join(' ')), diff);
      QVERIFY2(diff == 0, qPrintable(c.join(' ') + ": " + QString::number(diff)));
      QStringList oit = common;
      oit[oit.indexOf("--op") + 1] = "oit";
      if (const qsizetype t = oit.indexOf("--step"); t >= 0) oit.remove(t, 2);  // oit takes none
      QCOMPARE(runProgram(MFR_CLI, QStringList{"render", "@volume", "-o", png("oit.png")} + oit, &out), 0);
      const double fromOit = mfr::rmse(viewer, mfr::readPng(png("oit.png").toStdString()));
      qInfo("  RMSE against --op oit: %.5f", fromOit);
      QVERIFY(fromOit > 0.005);
    }
    // The step matters: another step, another image (the viewer passes it on).
    QCOMPARE(
        runProgram(MFRVIEW,
                   {"@volume", "--screenshot", png("a.png"), "--size", "200x150", "--op", "volume", "--step", "0.2"},
                   &out),
        0);
    QCOMPARE(
        runProgram(MFRVIEW, {"@volume", "--screenshot", png("b.png"), "--size", "200x150", "--op", "volume"}, &out), 0);
    QVERIFY(maxChannelDifference(mfr::readPng(png("a.png").toStdString()), mfr::readPng(png("b.png").toStdString())) >
            0);
    // Steps the CLI would refuse end a scripted viewer run too, with a one-line error.
    for (const QString& bad : {QStringLiteral("--step=0"), QStringLiteral("--step=-1"), QStringLiteral("--step=nan")}) {
      QCOMPARE(runProgram(MFRVIEW, {"@volume", "--screenshot", png("bad.png"), "--op", "volume", bad}, &out), 2);
      QVERIFY2(out.contains("mfrview: --step"), qPrintable(out));
    }

    auto w = openWindow(QStringLiteral("@volume"));
    QVERIFY(w);
    ViewerModel& m = w->model();
    w->view().setFixedSize(200, 150);
    QTRY_COMPARE_WITH_TIMEOUT(m.renderSize(), QSize(200, 150), kTimeoutMs);
    m.setMethod("abuffer-ll");
    m.setCamera(m.scene().view("iso"));
    const auto note = [&m](const char* key) -> std::string {
      for (const auto& [name, value] : m.stats().notes)
        if (name == key) return value;
      return {};
    };
    // "auto" on a volume scene runs volume, and the panel says so.
    auto* operation = w->findChild<QComboBox*>("operationCombo");
    auto* step = w->findChild<QDoubleSpinBox*>("volumeStep");
    QVERIFY(operation && step);
    QCOMPARE(m.operation(), QStringLiteral("auto"));
    settle(m);
    QCOMPARE(QString::fromStdString(m.stats().operation), QStringLiteral("volume"));
    QCOMPARE(m.effectiveOperation(), QStringLiteral("volume"));
    QVERIFY2(operation->itemText(0).contains("volume"), qPrintable(operation->itemText(0)));
    QVERIFY(step->isVisibleTo(w.get()));
    operation->setCurrentIndex(operation->findData(QStringLiteral("volume")));
    QCOMPARE(m.operation(), QStringLiteral("volume"));
    step->setValue(0.02);
    QCOMPARE(m.volumeStep(), 0.02);
    QCOMPARE(m.renderRequest(QSize(8, 8)).volumeStep, 0.02);
    settle(m);
    QVERIFY2(m.renderError().isEmpty(), qPrintable(m.renderError()));
    QCOMPARE(numberOf(note("volume step")), 0.02);
    QVERIFY(std::stoull(note("volume (bytes)")) >= 96ull * 96 * 96 * 4);
    // The default (step 0) is the volume's defaultStep(), as the renderers make it.
    QCOMPARE(m.volumeStepDefault(), m.scene().visibleVolumes().at(0).defaultStep());
    w->findChild<QPushButton*>("volumeStepDefault")->click();
    QCOMPARE(m.volumeStep(), 0.0);
    settle(m);
    QCOMPARE(numberOf(note("volume step")), m.volumeStepDefault());
    QVERIFY(step->specialValueText().contains("default"));
    // Another operation hides the row.
    m.setOperation("oit");
    QVERIFY(!step->isVisibleTo(w.get()));
    m.setOperation("volume");
    m.setVolumeStep(0.02);

    // Frame quality against the oracle's volume image of the same step and transfer function.
    const auto oracle = [&m](const std::string& op, QSize size) {
      mfr::RenderRequest request;
      request.operation = op;
      request.volumeStep = m.volumeStep();
      request.width = size.width();
      request.height = size.height();
      return mfr::render(m.scene(), m.camera(), request).image;
    };
    QCOMPARE(m.referenceRequest(0).operation, std::string("volume"));
    QCOMPARE(m.referenceRequest(0).volumeStep, 0.02);
    settle(m);
    m.requestFrameQuality();
    QTRY_VERIFY_WITH_TIMEOUT(m.frameQuality().valid, kTimeoutMs);
    const mfr::ImageRGBA8 frame = w->view().renderImage(m.renderSize());
    const double quality = m.frameQuality().rmse;
    const double exact = mfr::rmse(oracle("volume", m.renderSize()), frame);
    const double fromOit = mfr::rmse(oracle("oit", m.renderSize()), frame);
    qInfo("@volume abuffer-ll volume 0.02: frame quality RMSE %.6f (recomputed %.6f; against oit %.6f)", quality, exact,
          fromOit);
    QVERIFY(quality < 0.002);
    QVERIFY(std::abs(quality - exact) < 1e-9);
    QVERIFY(fromOit > 0.005);
    // Another transfer function: another frame, measured against the oracle with the new one.
    const mfr::ImageRGBA8 oldOracle = oracle("volume", m.renderSize());
    const mfr::TransferFunction loaded = m.transferFunction();
    QVERIFY(m.setTransferFunction(mfr::transferPreset("fire", 0.0, 1.2, loaded.unitDistance)).isEmpty());
    QVERIFY(!m.metricsCurrent(0));
    settle(m);
    m.requestFrameQuality();
    QTRY_VERIFY_WITH_TIMEOUT(m.frameQuality().valid, kTimeoutMs);
    const mfr::ImageRGBA8 fire = w->view().renderImage(m.renderSize());
    qInfo("fire: frame quality RMSE %.6f (against the old transfer function's oracle %.6f)", m.frameQuality().rmse,
          mfr::rmse(oldOracle, fire));
    // Measured against the new oracle: against the old one the same frame is > 0.01 off (both
    // values are the surfaces' edge pixels alone, so they may equal the first frame's).
    QVERIFY(m.frameQuality().rmse < 0.002);
    QVERIFY(std::abs(m.frameQuality().rmse - mfr::rmse(oracle("volume", m.renderSize()), fire)) < 1e-9);
    QVERIFY(mfr::rmse(oldOracle, fire) > 0.01);

    // Compare mode: side B the oracle with volume (auto resolves to it), measured against itself.
    m.setMethodOf(1, QStringLiteral("oracle"));
    m.setCompareEnabled(true);
    settle(m);
    QTRY_VERIFY_WITH_TIMEOUT(m.metricsCurrent(0) && m.metricsCurrent(1), kTimeoutMs);
    QVERIFY2(m.metrics(0).valid && m.metrics(1).valid, qPrintable(m.metrics(0).error + m.metrics(1).error));
    QCOMPARE(m.referenceRequest(1).operation, std::string("volume"));
    QCOMPARE(m.metrics(1).rmse, 0.0);
    // Another step re-renders and re-measures both panes.
    const PaneMetrics before = m.metrics(0);
    m.setVolumeStep(0.04);
    QVERIFY(!m.metricsCurrent(0) && !m.metricsCurrent(1));
    settle(m);
    QTRY_VERIFY_WITH_TIMEOUT(m.metricsCurrent(0) && m.metricsCurrent(1), kTimeoutMs);
    QCOMPARE(m.metrics(1).rmse, 0.0);
    QVERIFY(m.metrics(0).key != before.key);
    QVERIFY(m.metrics(0).rmse < 0.002);
    m.setCompareEnabled(false);
  }

  // supportsOperation(method, "volume") is what each method does with the operation: every method
  // it admits renders the volume, every other one refuses it (sorted lists, MethodInfo::sortedLists).
  void volumeSupport() {
    auto w = openWindow(QStringLiteral("@volume"));
    QVERIFY(w);
    ViewerModel& m = w->model();
    w->view().setFixedSize(96, 64);
    QTRY_COMPARE_WITH_TIMEOUT(m.renderSize(), QSize(96, 64), kTimeoutMs);
    m.setOperation(QStringLiteral("volume"));
    int supportedCount = 0, refusedCount = 0;
    for (const mfr::RegistryEntry& e : mfr::methodRegistry()) {
      const QString name = QString::fromStdString(e.name);
      m.setMethod(name);
      settle(m);
      const bool supported = m.supportsOperation(name, QStringLiteral("volume"));
      qInfo("%s: supports volume %d; render error: %s", e.name.c_str(), supported, qPrintable(m.renderError()));
      QVERIFY2(m.renderError().isEmpty() == supported, qPrintable(name + ": " + m.renderError()));
      if (supported) {
        QCOMPARE(QString::fromStdString(m.stats().operation), QStringLiteral("volume"));
        ++supportedCount;
      } else {
        ++refusedCount;
      }
      QCOMPARE(supported, m.methodInfo(name)->sortedLists);
    }
    QVERIFY(supportedCount > 0 && refusedCount > 0);
    QVERIFY(m.supportsOperation(QStringLiteral("oracle"), QStringLiteral("volume")));
    QVERIFY(!m.supportsOperation(QStringLiteral("no-such-method"), QStringLiteral("volume")));
  }

  // The probe on @volume (operation auto → volume): the Volume column gives each surface's share
  // through the medium, the summary the colour with the medium and the medium's share, which add
  // up to 100 % with the column; that colour is the oracle's volume image at the pixel.
  void volumeProbe() {
    auto w = openWindow(QStringLiteral("@volume"));
    QVERIFY(w);
    ViewerModel& m = w->model();
    RenderView& view = w->view();
    view.setFixedSize(96, 64);
    QTRY_COMPARE_WITH_TIMEOUT(m.renderSize(), QSize(96, 64), kTimeoutMs);
    m.setMethod(QStringLiteral("abuffer-ll"));
    settle(m);
    auto* table = w->findChild<QTableWidget*>("probeTable");
    auto* summary = w->findChild<QLabel*>("probeSummary");
    QVERIFY(table && summary);
    const QPoint pixel(48, 32);
    QTest::mouseClick(&view, Qt::LeftButton, Qt::ControlModifier, pixel);
    QTRY_VERIFY2_WITH_TIMEOUT(summary->text().contains(QStringLiteral("with the volume")), qPrintable(summary->text()),
                              20000);
    QVERIFY(!table->isColumnHidden(ProbePanel::VolumeShare));
    QVERIFY(table->isColumnHidden(ProbePanel::HybridShare));
    const QRegularExpression share(
        QStringLiteral("(#[0-9a-f]{6}) with the volume \\(the medium's share ([0-9.]+) %\\)"));
    const QRegularExpressionMatch match = share.match(summary->text());
    QVERIFY2(match.hasMatch(), qPrintable(summary->text()));
    double total = match.captured(2).toDouble();
    QVERIFY2(total > 10.0, qPrintable(summary->text()));  // the ray crosses the medium
    total += columnPercent(*table, ProbePanel::VolumeShare);
    QVERIFY2(std::abs(total - 100.0) < 0.1 * table->rowCount() + 0.1, qPrintable(QString::number(total)));
    mfr::RenderRequest oracle;
    oracle.method = "oracle";
    oracle.operation = "volume";
    oracle.width = 96;
    oracle.height = 64;
    const mfr::ImageRGBA8 exact = mfr::render(m.scene(), m.camera(), oracle).image;
    const std::uint8_t* at = exact.at(pixel.x(), pixel.y());
    QCOMPARE(match.captured(1), QColor(at[0], at[1], at[2]).name());
  }

  // The Probe dock under the operation zthickness on @intersect: the share of each surface in the
  // blend (its column adds up with the background's to 100 %), and the exact colour named in the
  // summary is the oracle's zthickness image at the pixel.
  void zthicknessProbe() {
    auto w = openWindow(QStringLiteral("@intersect"));
    QVERIFY(w);
    ViewerModel& m = w->model();
    RenderView& view = w->view();
    view.setFixedSize(96, 64);
    QTRY_COMPARE_WITH_TIMEOUT(m.renderSize(), QSize(96, 64), kTimeoutMs);
    m.setMethod(QStringLiteral("abuffer-ll"));
    m.setOperation(QStringLiteral("zthickness"));
    m.setZThickness(0.2);
    settle(m);
    auto* table = w->findChild<QTableWidget*>("probeTable");
    auto* summary = w->findChild<QLabel*>("probeSummary");
    QVERIFY(table && summary);
    const QPoint pixel(48, 30);
    QTest::mouseClick(&view, Qt::LeftButton, Qt::ControlModifier, pixel);
    QTRY_VERIFY2_WITH_TIMEOUT(summary->text().contains(QStringLiteral("with z-thickness 0.2")),
                              qPrintable(summary->text()), 20000);
    QVERIFY(!table->isColumnHidden(ProbePanel::ZThicknessShare));
    QVERIFY(table->isColumnHidden(ProbePanel::VolumeShare));
    QVERIFY(table->rowCount() >= 3);  // two surfaces or more, and the background
    double total = 0.0;
    total += columnPercent(*table, ProbePanel::ZThicknessShare);
    QVERIFY2(std::abs(total - 100.0) < 0.1 * table->rowCount() + 0.1, qPrintable(QString::number(total)));
    const QRegularExpressionMatch match =
        QRegularExpression(QStringLiteral("(#[0-9a-f]{6}) with z-thickness")).match(summary->text());
    QVERIFY2(match.hasMatch(), qPrintable(summary->text()));
    // Back to "over": the column goes.
    m.setOperation(QStringLiteral("oit"));
    settle(m);
    QTRY_VERIFY_WITH_TIMEOUT(table->isColumnHidden(ProbePanel::ZThicknessShare), 20000);
    // Last (mfr::render makes its own context current on this thread): the library's exact image.
    mfr::RenderRequest oracle;
    oracle.method = "oracle";
    oracle.operation = "zthickness";
    oracle.thickness = 0.2;
    oracle.width = 96;
    oracle.height = 64;
    const mfr::ImageRGBA8 exact = mfr::render(m.scene(), m.camera(), oracle).image;
    const std::uint8_t* at = exact.at(pixel.x(), pixel.y());
    QCOMPARE(match.captured(1), QColor(at[0], at[1], at[2]).name());
  }

  // The Volume plugin on @volume: the show switch (abuffer-sbuffer for a method without sorted
  // lists, and back), presets, window and opacity scale changing the transfer function and the
  // image, the preview, the step controls and the info line from the frame's notes, refusals of
  // invalid functions, As Loaded, and its settings in sessions.
  void volumePanel() {
    auto w = openWindow(QStringLiteral("@volume"));
    QVERIFY(w);
    ViewerModel& m = w->model();
    w->view().setFixedSize(200, 150);
    QTRY_COMPARE_WITH_TIMEOUT(m.renderSize(), QSize(200, 150), kTimeoutMs);
    QVERIFY2(w->findChild<QDockWidget*>("plugin-hybridvolume"), "hybridvolume plugin not loaded");
    auto* show = w->findChild<QCheckBox*>("hvShow");
    auto* preset = w->findChild<QComboBox*>("hvPreset");
    auto* windowMin = w->findChild<QDoubleSpinBox*>("hvWindowMin");
    auto* windowMax = w->findChild<QDoubleSpinBox*>("hvWindowMax");
    auto* opacity = w->findChild<QSlider*>("hvOpacity");
    auto* asLoaded = w->findChild<QPushButton*>("hvAsLoaded");
    auto* preview = w->findChild<QLabel*>("hvPreview");
    auto* error = w->findChild<QLabel*>("hvError");
    auto* stepSlider = w->findChild<QSlider*>("hvStepSlider");
    auto* step = w->findChild<QDoubleSpinBox*>("hvStep");
    auto* stepDefault = w->findChild<QPushButton*>("hvStepDefault");
    auto* info = w->findChild<QLabel*>("hvInfo");
    QVERIFY(show && preset && windowMin && windowMax && opacity && asLoaded && preview && error && stepSlider && step &&
            stepDefault && info);
    const auto note = [&m](const char* key) -> std::string {
      for (const auto& [name, value] : m.stats().notes)
        if (name == key) return value;
      return {};
    };
    const auto previewImage = [&] { return preview->pixmap().toImage(); };
    m.setCamera(m.scene().view("iso"));
    // The scene's own function, shown as Custom over its own range; "auto" already runs volume.
    QVERIFY(show->isChecked());
    QCOMPARE(preset->currentData().toString(), QStringLiteral("Custom"));
    QCOMPARE(windowMin->value(), m.transferFunction().low());
    QCOMPARE(windowMax->value(), m.transferFunction().high());

    // The switch: wboit keeps no lists, so the panel takes abuffer-sbuffer; off, both come back
    // and the volume is hidden.
    m.setMethod("wboit");
    m.setOperation("oit");
    QVERIFY(!show->isChecked());
    show->setChecked(true);
    QCOMPARE(m.method(), QStringLiteral("abuffer-sbuffer"));
    QCOMPARE(m.operation(), QStringLiteral("volume"));
    QVERIFY(m.volumeVisible());
    settle(m);
    QVERIFY2(m.renderError().isEmpty(), qPrintable(m.renderError()));
    QCOMPARE(QString::fromStdString(m.stats().operation), QStringLiteral("volume"));
    show->setChecked(false);
    QCOMPARE(m.method(), QStringLiteral("wboit"));
    QCOMPARE(m.operation(), QStringLiteral("oit"));
    QVERIFY(!m.volumeVisible());
    QVERIFY(!m.scene().hasVisibleVolume());
    settle(m);
    QVERIFY(note("volume step").empty());
    // A method with sorted lists is kept.
    m.setMethod("abuffer-ll");
    show->setChecked(true);
    QCOMPARE(m.method(), QStringLiteral("abuffer-ll"));
    QCOMPARE(m.effectiveOperation(), QStringLiteral("volume"));
    settle(m);
    QVERIFY2(info->text().contains("96×96×96") && info->text().contains("MiB"), qPrintable(info->text()));
    QVERIFY2(info->text().contains(QString::number(std::stod(note("volume step")), 'g', 5)), qPrintable(info->text()));
    const mfr::ImageRGBA8 original = w->view().renderImage(m.renderSize());
    const QImage originalPreview = previewImage();
    const mfr::TransferFunction loaded = m.loadedTransferFunction();

    // Preset: the function over the window, another image and preview.
    preset->setCurrentIndex(preset->findData(QStringLiteral("fire")));
    {
      const mfr::TransferFunction expected =
          mfr::transferPreset("fire", windowMin->value(), windowMax->value(), loaded.unitDistance);
      const mfr::TransferFunction now = m.transferFunction();
      QCOMPARE(now.points.size(), expected.points.size());
      for (std::size_t i = 0; i < now.points.size(); ++i) {
        QCOMPARE(now.points[i].value, expected.points[i].value);
        QVERIFY(now.points[i].color == expected.points[i].color);
      }
    }
    settle(m);
    const mfr::ImageRGBA8 fire = w->view().renderImage(m.renderSize());
    qInfo("loaded vs fire: RMSE %.5f", mfr::rmse(original, fire));
    QVERIFY(mfr::rmse(original, fire) > 0.005);
    QVERIFY(previewImage() != originalPreview);
    // Window: the function's range follows it.
    windowMax->setValue(0.6);
    QCOMPARE(m.transferFunction().high(), 0.6);
    settle(m);
    const mfr::ImageRGBA8 narrow = w->view().renderImage(m.renderSize());
    QVERIFY(mfr::rmse(fire, narrow) > 0.002);
    // Opacity scale: the extinction times the scale (unit distance divided by it).
    opacity->setValue(opacity->maximum());
    QVERIFY(std::abs(m.transferFunction().unitDistance - loaded.unitDistance / 20.0) < 1e-12);
    settle(m);
    const mfr::ImageRGBA8 dense = w->view().renderImage(m.renderSize());
    QVERIFY(mfr::rmse(narrow, dense) > 0.002);

    // Invalid functions are refused with one line, and nothing changes.
    const mfr::TransferFunction current = m.transferFunction();
    const quint64 revision = m.sceneRevision();
    const auto unchanged = [&] {
      const mfr::TransferFunction now = m.transferFunction();
      if (now.points.size() != current.points.size() || now.unitDistance != current.unitDistance) return false;
      for (std::size_t i = 0; i < now.points.size(); ++i)
        if (now.points[i].value != current.points[i].value || now.points[i].color != current.points[i].color)
          return false;
      return m.sceneRevision() == revision;
    };
    QString reason = m.setTransferFunction(mfr::TransferFunction{});
    QVERIFY2(reason.contains("two points") && !reason.contains('\n'), qPrintable(reason));
    QVERIFY(unchanged());
    mfr::TransferFunction unsorted = current;
    std::swap(unsorted.points.front(), unsorted.points.back());
    reason = m.setTransferFunction(unsorted);
    QVERIFY2(reason.contains("ascend"), qPrintable(reason));
    QVERIFY(unchanged());
    mfr::TransferFunction negative = current;
    negative.points[1].color.a = -0.5f;
    reason = m.setTransferFunction(negative);
    QVERIFY2(reason.contains("[0, 1]"), qPrintable(reason));
    QVERIFY(unchanged());
    mfr::TransferFunction badUnit = current;
    badUnit.unitDistance = 0.0;
    QVERIFY(!m.setTransferFunction(badUnit).isEmpty());
    QVERIFY(unchanged());
    // The panel's window the wrong way round: refused there, shown in its error line.
    const QJsonArray windowBefore =
        loadedPlugin(*w, QStringLiteral("hybridvolume"))->saveSettings().value("window").toArray();
    windowMin->setValue(0.9);
    QVERIFY(error->isVisibleTo(w.get()) && !error->text().isEmpty());
    QVERIFY(unchanged());
    // A session saved meanwhile has the window drawn, not the refused one (a session of it gave
    // a note and another panel on reload: a bug hunt).
    QCOMPARE(loadedPlugin(*w, QStringLiteral("hybridvolume"))->saveSettings().value("window").toArray(), windowBefore);
    windowMin->setValue(0.0);
    QVERIFY(!error->isVisibleTo(w.get()));

    // Step: spin box, slider (10× the default at its end), Default; the frame notes it.
    step->setValue(0.03);
    QCOMPARE(m.volumeStep(), 0.03);
    settle(m);
    QCOMPARE(numberOf(note("volume step")), 0.03);
    QVERIFY2(info->text().contains("0.03"), qPrintable(info->text()));
    stepSlider->setValue(stepSlider->maximum());
    QVERIFY(std::abs(m.volumeStep() - 10.0 * m.volumeStepDefault()) < 1e-12);
    stepDefault->click();
    QCOMPARE(m.volumeStep(), 0.0);
    QVERIFY(std::abs(step->value() - m.volumeStepDefault()) < 1e-6);
    // The method panel's Step row shows the same step.
    m.setVolumeStep(0.025);
    QCOMPARE(w->findChild<QDoubleSpinBox*>("volumeStep")->value(), 0.025);
    QCOMPARE(step->value(), 0.025);

    // Shading: the switch sets Volume::shading, the frame says so, the image changes, and the
    // frame quality is measured against the oracle's shaded image (the same scene).
    auto* shade = w->findChild<QCheckBox*>("hvShade");
    QVERIFY(shade && !shade->isChecked() && !m.volumeShading());
    settle(m);
    const mfr::ImageRGBA8 unshaded = w->view().renderImage(m.renderSize());
    QCOMPARE(note("volume shading"), std::string("off"));
    shade->setChecked(true);
    QVERIFY(m.volumeShading());
    QVERIFY(m.scene().visibleVolumes().at(0).shading);
    settle(m);
    QCOMPARE(note("volume shading"), std::string("on"));
    const mfr::ImageRGBA8 shadedFrame = w->view().renderImage(m.renderSize());
    qInfo("unshaded vs shaded: RMSE %.5f", mfr::rmse(unshaded, shadedFrame));
    QVERIFY(mfr::rmse(unshaded, shadedFrame) > 0.002);
    m.requestFrameQuality();
    QTRY_VERIFY_WITH_TIMEOUT(m.frameQuality().valid, kTimeoutMs);
    {
      mfr::RenderRequest request;
      request.method = "oracle";
      request.operation = "volume";
      request.volumeStep = m.volumeStep();
      request.width = m.renderSize().width();
      request.height = m.renderSize().height();
      const double exact = mfr::rmse(mfr::render(m.scene(), m.camera(), request).image, shadedFrame);
      qInfo("shaded frame quality RMSE %.6f (recomputed %.6f)", m.frameQuality().rmse, exact);
      QVERIFY(std::abs(m.frameQuality().rmse - exact) < 1e-9);
      QVERIFY(exact < 0.002);
    }

    // Sessions: the transfer function, the panel's preset, window and scale, the step, shading.
    preset->setCurrentIndex(preset->findData(QStringLiteral("bone")));
    windowMax->setValue(1.1);
    opacity->setValue(700);
    settle(m);
    const mfr::TransferFunction saved = m.transferFunction();
    const mfr::ImageRGBA8 before = w->view().renderImage(m.renderSize());
    QTemporaryDir dir;
    const QString sessionPath = dir.filePath("volume.mfrsession");
    w->saveSession(sessionPath);
    {
      auto again = openWindow(QString());
      QVERIFY(again);
      again->view().setFixedSize(200, 150);
      again->openSession(sessionPath);
      ViewerModel& a = again->model();
      QTRY_VERIFY_WITH_TIMEOUT(a.hasScene() && a.framesRendered() > 0, kTimeoutMs);
      QTRY_COMPARE_WITH_TIMEOUT(a.volumeStep(), 0.025, kTimeoutMs);
      settle(a);
      const mfr::TransferFunction restored = a.transferFunction();
      QCOMPARE(restored.points.size(), saved.points.size());
      QCOMPARE(restored.unitDistance, saved.unitDistance);
      for (std::size_t i = 0; i < saved.points.size(); ++i) {
        QCOMPARE(restored.points[i].value, saved.points[i].value);
        QVERIFY(restored.points[i].color == saved.points[i].color);
      }
      QCOMPARE(again->findChild<QComboBox*>("hvPreset")->currentData().toString(), QStringLiteral("bone"));
      QCOMPARE(again->findChild<QDoubleSpinBox*>("hvWindowMax")->value(), 1.1);
      QCOMPARE(again->findChild<QSlider*>("hvOpacity")->value(), 700);
      QCOMPARE(again->findChild<QDoubleSpinBox*>("hvStep")->value(), 0.025);
      QVERIFY(again->findChild<QCheckBox*>("hvShow")->isChecked());
      QVERIFY(a.volumeShading());
      QVERIFY(again->findChild<QCheckBox*>("hvShade")->isChecked());
      QCOMPARE(maxChannelDifference(before, again->view().renderImage(a.renderSize())), 0);
    }
    // The viewer's own session keys ("volume_step", "volumes") restore the step and the function
    // without the plugin's settings too.
    {
      QFile file(sessionPath);
      QVERIFY(file.open(QIODevice::ReadOnly));
      QJsonObject json = QJsonDocument::fromJson(file.readAll()).object();
      QCOMPARE(json.value("volume_step").toDouble(), 0.025);
      json.remove("plugins");
      const QString bare = dir.filePath("bare.mfrsession");
      QFile out(bare);
      QVERIFY(out.open(QIODevice::WriteOnly));
      out.write(QJsonDocument(json).toJson());
      out.close();
      auto again = openWindow(QString());
      QVERIFY(again);
      again->openSession(bare);
      ViewerModel& a = again->model();
      QTRY_VERIFY_WITH_TIMEOUT(a.hasScene() && a.framesRendered() > 0, kTimeoutMs);
      settle(a);
      QCOMPARE(a.volumeStep(), 0.025);
      QVERIFY(a.volumeShading());  // the session's "volumes" carry it
      const mfr::TransferFunction restored = a.transferFunction();
      QCOMPARE(restored.points.size(), saved.points.size());
      QCOMPARE(restored.unitDistance, saved.unitDistance);
      for (std::size_t i = 0; i < saved.points.size(); ++i) QCOMPARE(restored.points[i].value, saved.points[i].value);
    }

    // As Loaded: the scene's own function, Custom over its own range again (at the default step:
    // the original image exactly).
    stepDefault->click();
    shade->setChecked(false);
    asLoaded->click();
    {
      const mfr::TransferFunction now = m.transferFunction();
      QCOMPARE(now.points.size(), loaded.points.size());
      QCOMPARE(now.unitDistance, loaded.unitDistance);
      for (std::size_t i = 0; i < now.points.size(); ++i) QCOMPARE(now.points[i].value, loaded.points[i].value);
    }
    QCOMPARE(preset->currentData().toString(), QStringLiteral("Custom"));
    QCOMPARE(windowMax->value(), loaded.high());
    settle(m);
    QCOMPARE(maxChannelDifference(original, w->view().renderImage(m.renderSize())), 0);
    QVERIFY(previewImage() == originalPreview);

    // The scene tree lists the volume with its grid size; unchecking it hides the volume.
    auto* tree = w->findChild<QTreeWidget*>("sceneTree");
    const int row = static_cast<int>(m.scene().objects.size());
    QCOMPARE(tree->topLevelItemCount(), row + 1);
    QVERIFY(tree->topLevelItem(row)->text(0).contains("field"));
    QCOMPARE(tree->topLevelItem(row)->text(1), QStringLiteral("96×96×96"));
    tree->topLevelItem(row)->setCheckState(0, Qt::Unchecked);
    QVERIFY(!m.volumeVisible());
    QVERIFY(!show->isChecked());

    // A scene without a volume: no step or transfer strip of the last one stays (a bug hunt).
    QVERIFY(!preview->pixmap().isNull());
    w->openScene(QStringLiteral("@sample"));
    QTRY_VERIFY_WITH_TIMEOUT(m.hasScene() && !m.hasVolume() && !m.isLoading(), kTimeoutMs);
    QVERIFY(!step->isEnabled());
    QCOMPARE(step->text(), QStringLiteral("—"));
    QVERIFY(preview->pixmap().isNull());
  }

  // The Volume panel's transfer-function editor on a small .vti scene, driven by synthesised mouse
  // and key events at positions from its own value↔pixel mapping: a click adds a point at the
  // clicked value and opacity, a drag moves it, a drag past a neighbour stops short of it, the ends
  // keep their values, removal never leaves fewer than two points, keys and the point's spin boxes
  // edit it, a double click sets its colour, a preset becomes Custom when edited; the histogram is
  // the grid's; the edited image differs from the loaded one and equals `mfr render` of a scene
  // file with the same points.
  void transferFunctionEditor() {
    QTemporaryDir dir;
    const QString scenePath = writeBlobScene(dir, "blob.mfrscene", blobTransfer());
    QVERIFY(!scenePath.isEmpty());
    auto w = openWindow(scenePath);
    QVERIFY(w);
    ViewerModel& m = w->model();
    QVERIFY2(w->findChild<QDockWidget*>("plugin-hybridvolume"), "hybridvolume plugin not loaded");
    const QSize size(200, 150);
    w->view().setFixedSize(size);
    QTRY_COMPARE_WITH_TIMEOUT(m.renderSize(), size, kTimeoutMs);
    m.setMethod("abuffer-ll");
    m.setOperation("volume");
    m.setVolumeStep(0.02);
    m.setCamera(m.scene().view("iso"));
    auto* preset = w->findChild<QComboBox*>("hvPreset");
    auto* error = w->findChild<QLabel*>("hvError");
    auto* pointValue = w->findChild<QDoubleSpinBox*>("hvPointValue");
    auto* pointOpacity = w->findChild<QDoubleSpinBox*>("hvPointOpacity");
    auto* pointRed = w->findChild<QDoubleSpinBox*>("hvPointRed");
    EditorProbe probe{w->findChild<QWidget*>("hvTransferEditor")};
    QVERIFY(preset && error && pointValue && pointOpacity && pointRed && probe.editor);
    QTRY_VERIFY_WITH_TIMEOUT(probe.editor->isVisible(), kTimeoutMs);  // the panel comes to the front
    qInfo("editor %dx%d, plot %.0fx%.0f", probe.editor->width(), probe.editor->height(), probe.plot().width(),
          probe.plot().height());
    QVERIFY(probe.plot().width() >= 100 && probe.plot().height() >= 60);
    const mfr::TransferFunction loaded = m.transferFunction();
    QVERIFY(samePoints(loaded, blobTransfer()));
    // A pixel's worth of value and opacity, now (the dock may change the editor's size).
    const auto dv = [&] { return probe.valuePixel(m.transferFunction()); };
    const auto da = [&] { return probe.opacityPixel(); };
    QCOMPARE(probe.x(0.0), probe.plot().left());
    QCOMPARE(probe.x(1.0), probe.plot().right());
    settle(m);
    const mfr::ImageRGBA8 loadedImage = w->view().renderImage(size);

    // The histogram: the viewer's counts are the grid's, outside values skipped, and the editor
    // shows them over the function's range.
    const mfr::VolumeGrid& grid = *m.scene().visibleVolumes().at(0).grid;
    const std::vector<std::uint64_t> all = histogramOf(grid, 0.0, 1.0, 128);
    QVERIFY(m.volumeHistogram(0.0, 1.0, 128) == all);
    std::uint64_t total = 0;
    for (const std::uint64_t c : all) total += c;
    QCOMPARE(total, static_cast<std::uint64_t>(grid.values.size()));  // every value lies in [0, 1]
    const std::vector<std::uint64_t> middle = histogramOf(grid, 0.25, 0.75, 8);
    QVERIFY(m.volumeHistogram(0.25, 0.75, 8) == middle);
    QVERIFY(std::count(middle.begin(), middle.end(), 0u) == 0);
    QVERIFY(m.volumeHistogram(1.0, 0.0, 8).empty() && m.volumeHistogram(0.0, 1.0, 0).empty());
    QCOMPARE(probe.histogram(), QList<quint64>(all.begin(), all.end()));

    // A click on empty space adds a point there, interpolating the colour; the ends stay.
    QTest::mouseClick(probe.editor, Qt::LeftButton, {}, probe.at(0.4, 0.7));
    mfr::TransferFunction t = m.transferFunction();
    QCOMPARE(t.points.size(), std::size_t{3});
    qInfo("click at (0.4, 0.7) added (%.6f, %.6f); a pixel is %.6f in value, %.6f in opacity", t.points[1].value,
          t.points[1].color.a, dv(), da());
    QVERIFY(std::abs(t.points[1].value - 0.4) <= dv());
    QVERIFY(std::abs(t.points[1].color.a - 0.7) <= da());
    {
      const double f = t.points[1].value;  // the loaded function is linear over [0, 1]
      const glm::vec4 expected = glm::mix(loaded.points[0].color, loaded.points[1].color, static_cast<float>(f));
      for (int c = 0; c < 3; ++c) QVERIFY(std::abs(t.points[1].color[c] - expected[c]) < 1e-6f);
    }
    QCOMPARE(t.points.front().value, 0.0);
    QCOMPARE(t.points.back().value, 1.0);
    QCOMPARE(t.unitDistance, loaded.unitDistance);
    QCOMPARE(probe.selected(), 1);
    QVERIFY(std::abs(pointValue->value() - t.points[1].value) < 1e-6 && pointValue->isEnabled());
    QVERIFY(std::abs(pointOpacity->value() - t.points[1].color.a) < 1e-4);
    QVERIFY(!error->isVisibleTo(w.get()));
    settle(m);
    const mfr::ImageRGBA8 added = w->view().renderImage(size);
    qInfo("loaded vs one point added: RMSE %.5f", mfr::rmse(loadedImage, added));
    QVERIFY(mfr::rmse(loadedImage, added) > 0.002);

    // A drag moves it.
    probe.drag(probe.at(t.points[1]), probe.at(0.55, 0.3));
    t = m.transferFunction();
    QCOMPARE(t.points.size(), std::size_t{3});
    qInfo("dragged to (%.6f, %.6f)", t.points[1].value, t.points[1].color.a);
    QVERIFY(std::abs(t.points[1].value - 0.55) <= dv());
    QVERIFY(std::abs(t.points[1].color.a - 0.3) <= da());
    // Past a neighbour (and out of the plot): it stops short of it, the values still ascend.
    QTest::mouseClick(probe.editor, Qt::LeftButton, {}, probe.at(0.8, 0.5));
    t = m.transferFunction();
    QCOMPARE(t.points.size(), std::size_t{4});
    const double neighbour = t.points[2].value;
    probe.drag(probe.at(t.points[1]), probe.at(1.3, 0.2));
    t = m.transferFunction();
    qInfo("dragged past %.6f: now %.9f", neighbour, t.points[1].value);
    QCOMPARE(t.points.size(), std::size_t{4});
    QVERIFY(ascending(t));
    QCOMPARE(t.points[2].value, neighbour);
    QVERIFY(t.points[1].value > neighbour - dv() && t.points[1].value < neighbour);
    probe.drag(probe.at(t.points[1]), probe.at(-0.5, 0.25));  // and the other way, past the first
    t = m.transferFunction();
    QVERIFY(ascending(t));
    QVERIFY(t.points[1].value > 0.0 && t.points[1].value < dv());
    QCOMPARE(t.points.front().value, 0.0);
    // The ends move only vertically.
    probe.drag(probe.at(t.points.back()), probe.at(0.6, 0.5));
    t = m.transferFunction();
    QCOMPARE(t.points.back().value, 1.0);
    QVERIFY(std::abs(t.points.back().color.a - 0.5) <= da());
    QVERIFY(ascending(t));

    // Keys and spin boxes on the selected point.
    QTest::mouseClick(probe.editor, Qt::LeftButton, {}, probe.at(t.points[2]));
    QCOMPARE(probe.selected(), 2);
    const mfr::TransferPoint before = t.points[2];
    QTest::keyClick(probe.editor, Qt::Key_Right);
    QTest::keyClick(probe.editor, Qt::Key_Up);
    t = m.transferFunction();
    QVERIFY(std::abs(t.points[2].value - (before.value + dv())) < 1e-9);
    QVERIFY(std::abs(t.points[2].color.a - (before.color.a + da())) < 1e-6);
    pointValue->setValue(0.7);
    pointOpacity->setValue(0.65);
    pointRed->setValue(0.125);
    t = m.transferFunction();
    QCOMPARE(t.points[2].value, 0.7);
    QCOMPARE(t.points[2].color.a, 0.65f);
    QCOMPARE(t.points[2].color.r, 0.125f);
    QCOMPARE(t.points[2].color.g, before.color.g);
    pointValue->setValue(5.0);  // clamped below the last point
    t = m.transferFunction();
    QVERIFY(t.points[2].value < 1.0 && ascending(t));
    QVERIFY(std::abs(pointValue->value() - t.points[2].value) < 1e-6);
    pointValue->setValue(0.7);

    // A double click: the colour dialog for the point.
    QTest::mouseDClick(probe.editor, Qt::LeftButton, {}, probe.at(m.transferFunction().points[2]));
    QTest::mouseRelease(probe.editor, Qt::LeftButton, {}, probe.at(m.transferFunction().points[2]));
    auto* dialog = probe.editor->findChild<QColorDialog*>("hvPointColorDialog");
    QVERIFY(dialog);
    dialog->setCurrentColor(QColor(0, 255, 0));
    dialog->accept();
    t = m.transferFunction();
    QVERIFY(glm::vec3(t.points[2].color) == glm::vec3(0.0f, 1.0f, 0.0f));
    QCOMPARE(t.points[2].color.a, 0.65f);

    // The edited image is `mfr render`'s of a scene file with the same points.
    settle(m);
    QVERIFY2(m.renderError().isEmpty(), qPrintable(m.renderError()));
    const mfr::ImageRGBA8 edited = w->view().renderImage(size);
    QVERIFY(mfr::rmse(added, edited) > 0.002);
    {
      const QString cliScene = writeBlobScene(dir, "edited.mfrscene", m.transferFunction());
      const QString cliPng = dir.filePath("cli.png");
      QString out;
      QCOMPARE(runProgram(MFR_CLI,
                          {"render", cliScene, "-o", cliPng, "--size", "200x150", "--method", "abuffer-ll", "--op",
                           "volume", "--step", "0.02", "--view", "iso"},
                          &out),
               0);
      const int diff = maxChannelDifference(edited, mfr::readPng(cliPng.toStdString()));
      qInfo("edited transfer function: viewer vs mfr render max channel difference %d", diff);
      QCOMPARE(diff, 0);
    }

    // Removal: right clicks on every point, Delete on the selected one; never fewer than two,
    // and the ends stay.
    for (int round = 0; round < 3; ++round) {
      t = m.transferFunction();
      for (const mfr::TransferPoint& p : t.points) QTest::mouseClick(probe.editor, Qt::RightButton, {}, probe.at(p));
    }
    t = m.transferFunction();
    QCOMPARE(t.points.size(), std::size_t{2});
    QCOMPARE(t.points.front().value, 0.0);
    QCOMPARE(t.points.back().value, 1.0);
    QVERIFY(!error->isVisibleTo(w.get()));  // no function of fewer points was even tried
    QTest::mouseClick(probe.editor, Qt::LeftButton, {}, probe.at(0.5, 0.5));
    QCOMPARE(m.transferFunction().points.size(), std::size_t{3});
    QTest::keyClick(probe.editor, Qt::Key_Delete);
    QCOMPARE(m.transferFunction().points.size(), std::size_t{2});
    for (const mfr::TransferPoint& p : m.transferFunction().points) {
      QTest::mouseClick(probe.editor, Qt::LeftButton, {}, probe.at(p));
      QVERIFY(probe.selected() >= 0);
      QTest::keyClick(probe.editor, Qt::Key_Delete);
      QTest::keyClick(probe.editor, Qt::Key_Backspace);
    }
    QCOMPARE(m.transferFunction().points.size(), std::size_t{2});
    QVERIFY(!error->isVisibleTo(w.get()));

    // A preset edited becomes Custom with the edit; its other points stay.
    preset->setCurrentIndex(preset->findData(QStringLiteral("fire")));
    const mfr::TransferFunction fire = m.transferFunction();
    QCOMPARE(fire.points.size(), std::size_t{4});
    QTest::mouseClick(probe.editor, Qt::LeftButton, {}, probe.at(0.5, 0.9));
    t = m.transferFunction();
    QCOMPARE(preset->currentData().toString(), QStringLiteral("Custom"));
    QCOMPARE(t.points.size(), std::size_t{5});
    QCOMPARE(t.unitDistance, fire.unitDistance);
    for (std::size_t i = 0, j = 0; i < t.points.size(); ++i) {
      if (std::abs(t.points[i].value - 0.5) <= dv()) continue;  // the new one
      QCOMPARE(t.points[i].value, fire.points[j].value);
      QVERIFY(t.points[i].color == fire.points[j].color);
      ++j;
    }
    // A new window stretches the edited points onto it, and the editor shows them.
    auto* windowMax = w->findChild<QDoubleSpinBox*>("hvWindowMax");
    windowMax->setValue(0.5);
    t = m.transferFunction();
    QCOMPARE(t.points.size(), std::size_t{5});
    QCOMPARE(t.high(), 0.5);
    QVERIFY(ascending(t));
    QVERIFY(std::abs(probe.x(0.5) - probe.plot().right()) < 1e-9);
    const std::vector<std::uint64_t> lower = histogramOf(grid, 0.0, 0.5, 128);
    QCOMPARE(probe.histogram(), QList<quint64>(lower.begin(), lower.end()));
    // As Loaded: the scene's own function again.
    w->findChild<QPushButton*>("hvAsLoaded")->click();
    QVERIFY(samePoints(m.transferFunction(), loaded));
    QCOMPARE(probe.x(1.0), probe.plot().right());
  }

  // A session saved after editing points with the mouse (and a window and an opacity scale)
  // restores the same points and the same image: through the viewer's "volumes" and the panel's
  // settings together, and through the panel's settings alone.
  void transferFunctionEditorSession() {
    QTemporaryDir dir;
    const QString scenePath = writeBlobScene(dir, "blob.mfrscene", blobTransfer());
    QVERIFY(!scenePath.isEmpty());
    const QSize size(200, 150);
    const QString sessionPath = dir.filePath("edited.mfrsession");
    mfr::TransferFunction saved;
    mfr::ImageRGBA8 before;
    {
      auto w = openWindow(scenePath);
      QVERIFY(w);
      ViewerModel& m = w->model();
      w->view().setFixedSize(size);
      QTRY_COMPARE_WITH_TIMEOUT(m.renderSize(), size, kTimeoutMs);
      m.setMethod("abuffer-ll");
      m.setCamera(m.scene().view("iso"));
      EditorProbe probe{w->findChild<QWidget*>("hvTransferEditor")};
      QVERIFY(probe.editor);
      QTRY_VERIFY_WITH_TIMEOUT(probe.editor->isVisible(), kTimeoutMs);
      QTest::mouseClick(probe.editor, Qt::LeftButton, {}, probe.at(0.3, 0.05));
      QTest::mouseClick(probe.editor, Qt::LeftButton, {}, probe.at(0.6, 0.75));
      probe.drag(probe.at(m.transferFunction().points[1]), probe.at(0.45, 0.15));
      probe.drag(probe.at(m.transferFunction().points.back()), probe.at(1.0, 0.35));
      w->findChild<QSlider*>("hvOpacity")->setValue(640);
      QCOMPARE(m.transferFunction().points.size(), std::size_t{4});
      QVERIFY(!samePoints(m.transferFunction(), blobTransfer()));
      settle(m);
      saved = m.transferFunction();
      before = w->view().renderImage(size);
      w->saveSession(sessionPath);
    }
    const auto restore = [&](const QString& path) {
      auto w = openWindow(QString());
      QVERIFY(w);
      w->view().setFixedSize(size);
      w->openSession(path);
      ViewerModel& m = w->model();
      QTRY_VERIFY_WITH_TIMEOUT(m.hasScene() && m.framesRendered() > 0, kTimeoutMs);
      settle(m);
      const mfr::TransferFunction restored = m.transferFunction();
      QCOMPARE(restored.points.size(), saved.points.size());
      QVERIFY(samePoints(restored, saved));
      QCOMPARE(w->findChild<QComboBox*>("hvPreset")->currentData().toString(), QStringLiteral("Custom"));
      QCOMPARE(w->findChild<QSlider*>("hvOpacity")->value(), 640);
      QCOMPARE(maxChannelDifference(before, w->view().renderImage(size)), 0);
    };
    restore(sessionPath);
    if (QTest::currentTestFailed()) return;
    // The panel's settings alone (no "volumes"): its saved points give the same function.
    QFile file(sessionPath);
    QVERIFY(file.open(QIODevice::ReadOnly));
    QJsonObject json = QJsonDocument::fromJson(file.readAll()).object();
    QVERIFY(json.contains("volumes"));
    json.remove("volumes");
    const QString pluginOnly = dir.filePath("plugin-only.mfrsession");
    QFile out(pluginOnly);
    QVERIFY(out.open(QIODevice::WriteOnly));
    out.write(QJsonDocument(json).toJson());
    out.close();
    restore(pluginOnly);
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
    for (const auto& [method, param] :
         {std::pair{"kplus-array", "k=6"}, std::pair{"abuffer-ll", ""}, std::pair{"mboit", ""}}) {
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

  // Compare mode: two methods, one camera; each pane is the CLI's image of its settings, and the
  // metrics are those of the pixels on screen against the exact image.
  void compareMode() {
    auto w = openWindow();
    QVERIFY(w);
    ViewerModel& m = w->model();
    w->view().setFixedSize(320, 200);
    QTRY_COMPARE_WITH_TIMEOUT(m.renderSize(), QSize(320, 200), kTimeoutMs);
    m.setMethod("abuffer-ll");
    m.setCamera(m.scene().view("iso"));
    auto* compare = w->findChild<QAction*>("actionCompare");
    QVERIFY(compare);
    QCOMPARE(compare->shortcut(), QKeySequence(Qt::Key_C));
    compare->trigger();
    QVERIFY(m.compareEnabled());
    // The second method through its own generated panel: its k is not the first method's.
    auto* methodB = w->findChild<QComboBox*>("methodComboB");
    QVERIFY(methodB);
    methodB->setCurrentIndex(methodB->findData(QStringLiteral("kplus-array")));
    QCOMPARE(m.methodOf(1), QStringLiteral("kplus-array"));
    auto* kB = w->findChild<QSpinBox*>("param-k-B");
    QVERIFY(kB);
    kB->setValue(1);
    QCOMPARE(m.paramsOf(1).at("k"), std::string("1"));
    QVERIFY(!m.allParamsOf(0).contains("kplus-array"));
    QCOMPARE(m.paneSize(), QSize(160, 200));
    settle(m);
    QTRY_VERIFY_WITH_TIMEOUT(m.metricsCurrent(0) && m.metricsCurrent(1), kTimeoutMs);
    const PaneMetrics exactA = m.metrics(0), k1 = m.metrics(1);
    QVERIFY2(exactA.valid && k1.valid, qPrintable(exactA.error + k1.error));
    qInfo("side by side 160x200: abuffer-ll RMSE %.6f FLIP %.5f; kplus-array k=1 RMSE %.6f FLIP %.5f", exactA.rmse,
          exactA.flip.mean, k1.rmse, k1.flip.mean);
    QVERIFY(exactA.rmse <= 1.0 / 255.0);  // an exact method differs only by rounding
    QVERIFY(exactA.flip.mean < 0.02);
    QVERIFY(k1.rmse > 0.05 && k1.rmse > 10.0 * exactA.rmse);
    QVERIFY(k1.flip.mean > 0.1 && k1.flip.mean > 5.0 * exactA.flip.mean);

    // The halves on screen: the CLI's images, and the very pixels the metrics describe.
    QTemporaryDir dir;
    const auto cli = [&](const QStringList& settings, QSize size) {
      const QString png = dir.filePath(QStringLiteral("cli-%1.png").arg(settings.join('_')));
      QString out;
      const QStringList args =
          QStringList{"render", "@sample", "--view",
                      "iso",    "--size",  QStringLiteral("%1x%2").arg(size.width()).arg(size.height()),
                      "-o",     png} +
          settings;
      if (runProgram(MFR_CLI, args, &out) != 0) qWarning("%s", qPrintable(out));
      return mfr::readPng(png.toStdString());
    };
    const QStringList settingsA{"--method", "abuffer-ll"}, settingsB1{"--method", "kplus-array", "-p", "k=1"};
    mfr::ImageRGBA8 screen = fromQImage(w->view().grabFramebuffer());
    const mfr::ImageRGBA8 left = crop(screen, QRect(0, 0, 160, 200)), right = crop(screen, QRect(160, 0, 160, 200));
    const int diffA = maxChannelDifference(left, cli(settingsA, QSize(160, 200)));
    const int diffB = maxChannelDifference(right, cli(settingsB1, QSize(160, 200)));
    qInfo("side by side vs mfr render: max channel difference A %d, B %d", diffA, diffB);
    QVERIFY(diffA >= 0 && diffA <= 1);
    QVERIFY(diffB >= 0 && diffB <= 1);
    const mfr::ImageRGBA8 exact = exactImage(m, QSize(160, 200));
    QVERIFY(std::abs(mfr::rmse(exact, left) - exactA.rmse) < 1e-9);
    QVERIFY(std::abs(mfr::rmse(exact, right) - k1.rmse) < 1e-9);
    QVERIFY(std::abs(mfr::flip(exact, right).stats.mean - k1.flip.mean) < 1e-9);
    // The panel and the captions show the same numbers.
    auto* table = w->findChild<QTableWidget*>("compareMetrics");
    QVERIFY(table);
    QCOMPARE(table->item(1, 1)->text(), QString::number(k1.rmse, 'f', 5));
    QVERIFY(w->findChild<PaneCaption*>("paneCaptionB")->text().contains(QString::number(k1.rmse, 'f', 5)));

    // Live: a better k on side B, better numbers; side A untouched.
    kB->setValue(2);
    settle(m);
    QTRY_VERIFY_WITH_TIMEOUT(m.metricsCurrent(0) && m.metricsCurrent(1), kTimeoutMs);
    const PaneMetrics k2 = m.metrics(1);
    qInfo("kplus-array k=2 RMSE %.6f FLIP %.5f", k2.rmse, k2.flip.mean);
    QVERIFY(k2.valid && k2.rmse < k1.rmse && k2.rmse > exactA.rmse);
    QCOMPARE(m.metrics(0).rmse, exactA.rmse);

    // Split: both full size, side A left of the line and side B right of it.
    m.setCompareLayout(CompareLayout::Split);
    m.setCompareSplit(0.5);
    QCOMPARE(m.paneSize(), QSize(320, 200));
    settle(m);
    QTRY_VERIFY_WITH_TIMEOUT(m.metricsCurrent(0) && m.metricsCurrent(1), kTimeoutMs);
    screen = fromQImage(w->view().grabFramebuffer());
    const QStringList settingsB2{"--method", "kplus-array", "-p", "k=2"};
    const mfr::ImageRGBA8 fullA = cli(settingsA, QSize(320, 200)), fullB = cli(settingsB2, QSize(320, 200));
    const QRect leftPart(0, 0, 160, 200), rightPart(160, 0, 160, 200);
    const int splitA = maxChannelDifference(crop(screen, leftPart), crop(fullA, leftPart));
    const int splitB = maxChannelDifference(crop(screen, rightPart), crop(fullB, rightPart));
    qInfo("split vs mfr render: max channel difference A %d, B %d; RMSE A %.6f B %.6f", splitA, splitB,
          m.metrics(0).rmse, m.metrics(1).rmse);
    QVERIFY(splitA >= 0 && splitA <= 1);
    QVERIFY(splitB >= 0 && splitB <= 1);
    QVERIFY(m.metrics(0).rmse <= 1.0 / 255.0 && m.metrics(1).rmse > 10.0 * m.metrics(0).rmse);

    // The FLIP heat map of each side (magma of the per-pixel error), computed here from the CLI's
    // images: exactly what the view shows when those images are identical to its own.
    m.setCompareDisplay(CompareDisplay::FlipError);
    // The Compare dock's Show follows the display however it was set (it kept "Images").
    auto* display = w->findChild<QComboBox*>("compareDisplay");
    QVERIFY(display);
    QCOMPARE(display->currentData().toInt(), static_cast<int>(CompareDisplay::FlipError));
    settle(m);
    screen = fromQImage(w->view().grabFramebuffer());
    const mfr::ImageRGBA8 exactFull = exactImage(m, QSize(320, 200));
    const mfr::ImageRGBA8 heatA = mfr::magma(mfr::flip(exactFull, fullA).errorMap);
    const mfr::ImageRGBA8 heatB = mfr::magma(mfr::flip(exactFull, fullB).errorMap);
    const int heatDiffA = maxChannelDifference(crop(screen, leftPart), crop(heatA, leftPart));
    const int heatDiffB = maxChannelDifference(crop(screen, rightPart), crop(heatB, rightPart));
    qInfo("FLIP heat maps vs FLIP of the CLI images: max channel difference A %d, B %d", heatDiffA, heatDiffB);
    if (splitA == 0 && splitB == 0) {
      QCOMPARE(heatDiffA, 0);
      QCOMPARE(heatDiffB, 0);
    }
    QVERIFY(w->findChild<MapLegend*>("mapLegendB")->isVisible());
  }

  // n(p) equals the oracle's exact counts; k(p) of the memory-aware S-buffer is min(n(p), k);
  // methods without a per-pixel capacity say so.
  void depthComplexityAndCapacityMaps() {
    auto w = openWindow();
    QVERIFY(w);
    ViewerModel& m = w->model();
    w->view().setFixedSize(200, 150);
    QTRY_COMPARE_WITH_TIMEOUT(m.renderSize(), QSize(200, 150), kTimeoutMs);
    m.setMethod("kplus-sbuffer");
    m.setParams({{"k", "3"}});
    m.setCamera(m.scene().view("iso"));
    w->findChild<QAction*>("actionViewDepthComplexity")->trigger();
    QCOMPARE(m.dataView(), DataView::DepthComplexity);
    settle(m);
    const RenderView::DataMap n = w->view().dataMap(0);
    QCOMPARE(n.kind, DataView::DepthComplexity);
    QVERIFY(n.key == m.frameKey(0));
    QCOMPARE(n.values.size(), std::size_t{200 * 150});
    const mfr::FragmentLists oracle = mfr::castFragments(m.scene(), m.camera(), 200, 150);
    std::size_t compared = 0, equal = 0;
    std::uint32_t deepest = 0;
    for (int y = 0; y < 150; ++y)
      for (int x = 0; x < 200; ++x) {
        if (oracle.isAmbiguous(x, y)) continue;
        ++compared;
        equal += n.values[oracle.index(x, y)] == oracle.count(x, y);
        deepest = std::max(deepest, oracle.count(x, y));
      }
    qInfo("n(p): %zu of %zu unambiguous pixels equal the oracle's counts; max %u (oracle %u)", equal, compared,
          n.maxValue, deepest);
    QVERIFY(compared > std::size_t{200 * 150 / 2});
    QCOMPARE(equal, compared);
    QVERIFY(deepest > 8 && n.maxValue >= deepest);
    auto* legend = w->findChild<MapLegend*>("mapLegendA");
    QVERIFY(legend && legend->isVisible());
    QVERIFY2(legend->text().contains(QStringLiteral("max %1").arg(n.maxValue)), qPrintable(legend->text()));
    // On screen: the magma colour of each oracle count on the legend's scale.
    mfr::ImageF counts(200, 150, 1);
    for (int y = 0; y < 150; ++y)
      for (int x = 0; x < 200; ++x) counts.at(x, y) = static_cast<float>(oracle.count(x, y));
    const mfr::ImageRGBA8 expectedColours = mfr::heatmap(counts, static_cast<float>(n.maxValue));
    const mfr::ImageRGBA8 screen = fromQImage(w->view().grabFramebuffer());
    std::size_t colourMismatches = 0;
    for (int y = 0; y < 150; ++y)
      for (int x = 0; x < 200; ++x)
        if (!oracle.isAmbiguous(x, y) && std::memcmp(screen.at(x, y), expectedColours.at(x, y), 3) != 0)
          ++colourMismatches;
    QCOMPARE(colourMismatches, std::size_t{0});

    w->findChild<QAction*>("actionViewCapacity")->trigger();
    settle(m);
    const RenderView::DataMap k = w->view().dataMap(0);
    QCOMPARE(k.kind, DataView::Capacity);
    QCOMPARE(k.values.size(), n.values.size());
    std::size_t wrong = 0;
    for (std::size_t i = 0; i < k.values.size(); ++i) wrong += k.values[i] != std::min<std::uint32_t>(n.values[i], 3);
    qInfo("k(p) of kplus-sbuffer k=3: %zu of %zu pixels differ from min(n(p), 3); range %u … %u", wrong,
          k.values.size(), k.minValue, k.maxValue);
    QCOMPARE(wrong, std::size_t{0});
    QCOMPARE(k.minValue, 0u);
    QCOMPARE(k.maxValue, 3u);

    // The budget panel's switch: k(p) blended over the image (empty pixels show the image).
    auto* overlay = w->findChild<QCheckBox*>("budgetKMapOverlay");
    QVERIFY(overlay);
    overlay->setChecked(true);
    QVERIFY(m.dataView() == DataView::Capacity && m.dataViewOverImage());
    settle(m);
    const mfr::ImageRGBA8 blended = fromQImage(w->view().grabFramebuffer());
    const mfr::ImageRGBA8 image = w->view().renderImage(QSize(200, 150));
    std::size_t emptyShowImage = 0, empty = 0;
    for (std::size_t i = 0; i < k.values.size(); ++i) {
      if (k.values[i] != 0) continue;
      ++empty;
      emptyShowImage += std::memcmp(&blended.pixels[i * 4], &image.pixels[i * 4], 3) == 0;
    }
    QVERIFY(empty > 0);
    QCOMPARE(emptyShowImage, empty);
    QVERIFY(maxChannelDifference(blended, image) > 32);  // and elsewhere the map shows

    m.setMethod("abuffer-ll");
    settle(m);
    QVERIFY(w->view().dataMap(0).values.empty());
    QCOMPARE(w->view().dataMap(0).note, QStringLiteral("no k(p) for this method"));
    QCOMPARE(legend->text(), QStringLiteral("no k(p) for this method"));
    QVERIFY(m.renderError().isEmpty());
  }

  // Loading reports real progress (mfr::LoadProgress) and stops when cancelled; the viewer's
  // status bar shows it and its Cancel button keeps the current scene.
  void loadProgressAndCancel() {
    QTemporaryDir dir;
    const QString small = dir.filePath("small.stl"), big = dir.filePath("big.stl");
    writeBinaryStl(small, 2000);
    writeBinaryStl(big, 150000);
    // Copies, each read: a scene file reads a file it places several times once.
    QStringList smallFiles, bigFiles;
    for (int i = 0; i < 8; ++i) {
      if (i < 4) {
        smallFiles << dir.filePath(QStringLiteral("small-%1.stl").arg(i));
        QVERIFY(QFile::copy(small, smallFiles.constLast()));
      }
      bigFiles << dir.filePath(QStringLiteral("big-%1.stl").arg(i));
      QVERIFY(QFile::copy(big, bigFiles.constLast()));
    }
    const QString smallScene = dir.filePath("small.mfrscene"), bigScene = dir.filePath("big.mfrscene");
    writeSceneFile(smallScene, smallFiles);
    writeSceneFile(bigScene, bigFiles);

    // mfrcore: per object, non-decreasing, from 0 to 1; false stops the loader at that report.
    ProgressRecorder all;
    const mfr::Scene loaded = mfr::loadScene(smallScene.toStdString(), all.progress());
    QCOMPARE(loaded.objects.size(), std::size_t{5});
    QVERIFY(all.monotonic());
    QVERIFY(all.fractions.size() >= 10);  // start and end of each object, at least
    QCOMPARE(all.fractions.front(), 0.0);
    QCOMPARE(all.fractions.back(), 1.0);
    ProgressRecorder stop;
    stop.cancelAt = 3;
    QVERIFY_THROWS_EXCEPTION(mfr::LoadCancelled, mfr::loadScene(smallScene.toStdString(), stop.progress()));
    QCOMPARE(stop.fractions.size(), std::size_t{3});
    // assimp: its import progress, then each mesh; cancelling during the import stops it.
    const QString gltf = dir.filePath("two.gltf");
    {
      QFile f(gltf);
      QVERIFY(f.open(QIODevice::WriteOnly));
      f.write(R"({"asset": {"version": "2.0"},
        "buffers": [{"byteLength": 44, "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIAAAA="}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36, "target": 34962},
                        {"buffer": 0, "byteOffset": 36, "byteLength": 6, "target": 34963}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
                      {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}],
        "meshes": [{"name": "a", "primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]},
                   {"name": "b", "primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "nodes": [{"mesh": 0, "name": "A"}, {"mesh": 1, "name": "B", "translation": [2, 0, 0]}],
        "scenes": [{"nodes": [0, 1]}], "scene": 0})");
    }
    ProgressRecorder assimp;
    QCOMPARE(mfr::loadModel(gltf.toStdString(), assimp.progress()).size(), std::size_t{2});
    QVERIFY(assimp.monotonic());
    QVERIFY(assimp.fractions.size() >= 5);  // start, import, two meshes, end
    QCOMPARE(assimp.fractions.back(), 1.0);
    ProgressRecorder assimpStop;
    assimpStop.cancelAt = 2;  // the first report from inside assimp's import
    QVERIFY_THROWS_EXCEPTION(mfr::LoadCancelled, mfr::loadModel(gltf.toStdString(), assimpStop.progress()));
    QCOMPARE(assimpStop.fractions.size(), std::size_t{2});

    // The viewer: the status bar's bar follows the loader to 1.
    auto w = openWindow();
    QVERIFY(w);
    ViewerModel& m = w->model();
    QSignalSpy progress(&m, &ViewerModel::loadProgressChanged);
    w->openScene(smallScene);
    QTRY_VERIFY_WITH_TIMEOUT(!m.isLoading() && m.scenePath() == QFileInfo(smallScene).absoluteFilePath(), kTimeoutMs);
    std::vector<double> seen;
    for (const QList<QVariant>& args : progress) seen.push_back(args.at(0).toDouble());
    QVERIFY(!seen.empty() && std::is_sorted(seen.begin(), seen.end()));
    QCOMPARE(seen.back(), 1.0);
    QCOMPARE(m.loadProgress(), 1.0);
    QCOMPARE(m.scene().objects.size(), std::size_t{5});
    settle(m);

    // Cancel from the status bar as soon as the big scene reports progress.
    auto* cancel = w->findChild<QPushButton*>("cancelLoad");
    auto* bar = w->findChild<QProgressBar*>("loadProgress");
    QVERIFY(cancel && bar);
    QSignalSpy cancelled(&m, &ViewerModel::loadCancelled);
    QSignalSpy loadedSpy(&m, &ViewerModel::sceneLoaded);
    bool clicked = false;
    double barAtCancel = -1.0;
    const QMetaObject::Connection c = connect(&m, &ViewerModel::loadProgressChanged, this, [&](double fraction) {
      if (clicked || fraction <= 0.0) return;
      clicked = true;
      barAtCancel = bar->value() / 1000.0;
      QVERIFY(cancel->isVisible());
      QTest::mouseClick(cancel, Qt::LeftButton);
    });
    w->openScene(bigScene);
    QTRY_VERIFY_WITH_TIMEOUT(!m.busy(), kTimeoutMs);  // the cancelled worker has stopped too
    disconnect(c);
    QVERIFY(clicked);
    qInfo("cancelled at %.3f of the load; the loader stopped early: %s", barAtCancel,
          m.lastCancelStoppedLoader() ? "yes" : "no");
    QVERIFY(barAtCancel > 0.0 && barAtCancel < 1.0);
    QCOMPARE(cancelled.count(), 1);
    QCOMPARE(loadedSpy.count(), 0);
    QVERIFY(!bar->isVisible());
    QVERIFY(m.lastCancelStoppedLoader());  // LoadCancelled inside mfr::loadScene, not a dropped result
    QCOMPARE(m.scenePath(), QFileInfo(smallScene).absoluteFilePath());
    QCOMPARE(m.scene().objects.size(), std::size_t{5});
    // A cancel at the loader's last report (a slot of loadProgressChanged(1)): the scene was set all
    // the same and the model stayed busy for ever (found when loads got faster).
    // A scene that loads within one poll of the loader's progress: its 1 comes with the result.
    const QString tiny = dir.filePath("tiny.mfrscene");
    {
      QFile f(tiny);
      QVERIFY(f.open(QIODevice::WriteOnly));
      f.write(R"({"objects": [{"primitive": {"type": "sphere", "radius": 1}}]})");
    }
    const QMetaObject::Connection atEnd = connect(&m, &ViewerModel::loadProgressChanged, this, [&](double fraction) {
      if (fraction == 1.0) m.cancelLoad();
    });
    w->openScene(tiny);
    QTRY_VERIFY_WITH_TIMEOUT(!m.busy(), kTimeoutMs);
    disconnect(atEnd);
    QCOMPARE(cancelled.count(), 2);
    QCOMPARE(loadedSpy.count(), 0);
    QCOMPARE(m.scenePath(), QFileInfo(smallScene).absoluteFilePath());
    const quint64 frames = m.framesRendered();
    m.setCamera(navigation::orbit(m.camera(), QPointF(15, 5), m.renderSize()));
    QTRY_VERIFY_WITH_TIMEOUT(m.framesRendered() > frames, kTimeoutMs);
    QVERIFY(m.renderError().isEmpty());
  }

  // The budget panel: methods from the registry, quality against the exact image, R_h.
  // The exact image of a frame refused for memory: the Memory budget panel read "computing…" for
  // ever and the plugin heard nothing (a bug hunt). frameQualityReady comes with the reason, and
  // the panel shows it. MFR_MEMORY_LIMIT_MIB a little above what the process holds lets WBOIT draw
  // and refuses the oracle's lists.
  void frameQualityThatCannotBeComputedSaysWhy() {
    auto w = openWindow();
    QVERIFY(w);
    ViewerModel& m = w->model();
    m.setMethod(QStringLiteral("wboit"));
    settle(m);
    long pages = 0, residentPages = 0;
    {
      std::ifstream statm("/proc/self/statm");
      statm >> pages >> residentPages;
    }
    const long residentMiB = residentPages * sysconf(_SC_PAGESIZE) / (1024 * 1024);
    qputenv("MFR_MEMORY_LIMIT_MIB", QByteArray::number(static_cast<qlonglong>(residentMiB + 24)));
    const auto unset = qScopeGuard([] { qunsetenv("MFR_MEMORY_LIMIT_MIB"); });
    QSignalSpy ready(&m, &ViewerContext::frameQualityReady);
    m.setCamera(navigation::orbit(m.camera(), QPointF(3, 0), m.renderSize()));  // a frame not yet measured
    QTRY_VERIFY_WITH_TIMEOUT(m.framesRendered() > 0 && m.renderError().isEmpty(), kTimeoutMs);
    settle(m);
    m.requestFrameQuality();
    QTRY_VERIFY_WITH_TIMEOUT(ready.count() > 0, kTimeoutMs);
    const FrameQuality q = m.frameQuality();
    QVERIFY(!q.valid);
    QVERIFY2(q.error.contains("MFR_MEMORY_LIMIT_MIB"), qPrintable(q.error));
    QTRY_COMPARE_WITH_TIMEOUT(w->findChild<QLabel*>("budgetRmse")->text(), QStringLiteral("not computed"), kTimeoutMs);
    QCOMPARE(w->findChild<QLabel*>("budgetFlip")->text(), q.error);
  }

  void budgetPanelQualityAndRobustness() {
    auto w = openWindow();
    QVERIFY(w);
    ViewerModel& m = w->model();
    w->view().setFixedSize(240, 180);
    QTRY_COMPARE_WITH_TIMEOUT(m.renderSize(), QSize(240, 180), kTimeoutMs);
    auto* combo = w->findChild<QComboBox*>("budgetMethodCombo");
    QVERIFY(combo);
    // Offered: every registered method with a memory parameter (budget_mib first of all: fkb,
    // vkb and dkb join when the registry has them), CPU methods besides the oracle on demand.
    for (const mfr::RegistryEntry& e : mfr::methodRegistry()) {
      const mfr::MethodInfo* info = m.methodInfo(QString::fromStdString(e.name));
      QVERIFY(info);
      const bool hasBudget = std::any_of(info->params.begin(), info->params.end(),
                                         [](const mfr::ParamSpec& p) { return p.name == "budget_mib"; });
      if (hasBudget) QVERIFY2(combo->findData(QString::fromStdString(e.name)) >= 0, e.name.c_str());
    }
    for (int i = 0; i < combo->count(); ++i) QVERIFY(m.methodNames().contains(combo->itemData(i).toString()));
    QVERIFY(combo->findData(QStringLiteral("oracle")) < 0);
    QCOMPARE(combo->findData(QStringLiteral("optimal-k")) >= 0, m.methodNames().contains(QStringLiteral("optimal-k")));
    for (const QString& name : m.methodNames())
      if (name != QLatin1String("oracle") && m.isCpuMethod(name))
        QVERIFY2(combo->findData(name) >= 0, qPrintable(name));

    const int dynamic = combo->findData(QStringLiteral("kplus-dynamic"));
    QVERIFY(dynamic >= 0);
    combo->setCurrentIndex(dynamic);
    emit combo->activated(dynamic);
    QCOMPARE(m.method(), QStringLiteral("kplus-dynamic"));
    settle(m);
    // Measured once the view rests, against the exact image of the same size.
    QTRY_VERIFY_WITH_TIMEOUT(m.frameQuality().valid, kTimeoutMs);
    const FrameQuality q = m.frameQuality();
    const mfr::ImageRGBA8 frame = w->view().renderImage(m.renderSize());
    const mfr::ImageRGBA8 exact = exactImage(m, m.renderSize());
    qInfo("kplus-dynamic R_h=0.95: RMSE %.6f FLIP %.5f (k %u)", q.rmse, q.flipMean, m.stats().kMax);
    QVERIFY(std::abs(mfr::rmse(exact, frame) - q.rmse) < 1e-9);
    QVERIFY(std::abs(mfr::flip(exact, frame).stats.mean - q.flipMean) < 1e-9);
    QCOMPARE(w->findChild<QLabel*>("budgetRmse")->text(), QString::number(q.rmse, 'f', 5));
    QVERIFY(w->findChild<QLabel*>("budgetFlip")->text().startsWith(QString::number(q.flipMean, 'f', 4)));

    // R_h drives the method's robustness: a lower ratio picks a smaller k and costs quality.
    auto* robustness = w->findChild<QDoubleSpinBox*>("budgetRobustness");
    QVERIFY(robustness && robustness->isVisible());
    QCOMPARE(robustness->value(), 0.95);
    const std::uint32_t k95 = m.stats().kMax;
    robustness->setValue(0.5);
    QCOMPARE(m.params().at("robustness"), std::string("0.5"));
    settle(m);
    QTRY_VERIFY_WITH_TIMEOUT(m.frameQuality().valid, kTimeoutMs);
    qInfo("kplus-dynamic R_h=0.5: RMSE %.6f FLIP %.5f (k %u)", m.frameQuality().rmse, m.frameQuality().flipMean,
          m.stats().kMax);
    QVERIFY(m.stats().kMax < k95);
    QVERIFY(m.frameQuality().rmse > q.rmse);

    m.setMethod("abuffer-ll");
    QVERIFY(!robustness->isVisible());
  }

  // The pixel probed or picked is the device pixel clicked at any scale: the window system's
  // device position comes as x / ratio in the window, less the view's offset; a plain floor of
  // that times the ratio lost one column in three at 1.5 (a review: device x 700 probed 57, not 58).
  void devicePixelsAtFractionalScales() {
    for (const double ratio : {1.0, 1.25, 1.5, 1.75, 2.0, 2.5, 3.0})
      for (const int offset : {0, 4, 12, 428, 1000}) {  // logical, whole device pixels at each ratio
        const double deviceOffset = offset * ratio;
        if (deviceOffset != std::floor(deviceOffset)) continue;
        for (int x = static_cast<int>(deviceOffset); x < 4000; ++x) {
          const double local = x / ratio - offset;  // as QHighDpi and mapTo give it
          const QPoint at = RenderView::devicePixel(QPointF(local, (x + 0.5) / ratio), ratio);
          if (at.x() != x - static_cast<int>(deviceOffset) || at.y() != x)
            QFAIL(qPrintable(QStringLiteral("ratio %1, offset %2: device x %3 gave column %4, row %5")
                                 .arg(ratio)
                                 .arg(offset)
                                 .arg(x)
                                 .arg(at.x())
                                 .arg(at.y())));
        }
      }
  }

  // Each change draws one frame, with every plugin loaded (GPU frames are drawn on the GUI thread:
  // each extra one froze the window for a slow method's whole time). Three causes, from a bug
  // hunt: the budget panel's first quality request drew the frame again to read it back; the
  // exact image behind the quality, when it came, drew the GPU frame again; and the budget
  // panel's longer numbers after a frame widened its dock, narrowing the view, which drew again.
  // Giving the view the keyboard focus drew one more.
  void eachChangeDrawsOneFrame() {
    auto w = std::make_unique<MainWindow>(MainWindow::Options{.restoreSettings = false, .loadPlugins = true});
    w->resize(1100, 700);
    w->show();
    QVERIFY(QTest::qWaitForWindowExposed(w.get()));
    ViewerModel& m = w->model();
    QVERIFY(w->findChild<QDockWidget*>("plugin-budget"));
    w->findChild<QDockWidget*>("plugin-budget")->raise();
    QList<QSize> sizes;  // of every frame the view reported
    connect(&m, &ViewerContext::frameRendered, this, [&] { sizes << m.renderSize(); });
    w->openScene(QStringLiteral("@sample"));
    QTRY_VERIFY_WITH_TIMEOUT(m.hasScene() && m.framesRendered() > 0, kTimeoutMs);
    QTRY_VERIFY_WITH_TIMEOUT(m.frameQuality().valid, kTimeoutMs);  // the budget panel asked for it
    settle(m);
    QVERIFY(!sizes.isEmpty());
    QCOMPARE(sizes.count(sizes.first()), sizes.size());  // the panels' numbers moved no dock
    QCOMPARE(sizes.size(), 1);

    const quint64 before = m.framesRendered();
    m.setCamera(navigation::orbit(m.camera(), QPointF(25, -10), m.renderSize()));
    QTRY_VERIFY_WITH_TIMEOUT(m.framesRendered() > before && m.frameQuality().valid, kTimeoutMs);
    settle(m);
    QCOMPARE(m.framesRendered() - before, quint64{1});
    // Side by side with the oracle: two frames, the change's (pane A reported) and the one when the
    // oracle's image comes (both panes reported). The reference of the metrics is that same image
    // (an oracle pane's "auto" was keyed apart from its reference's "oit" and computed twice), its
    // arrival redrew the view again, and so did each caption's update underneath: 8 reports (a
    // review).
    m.setMethodOf(1, QStringLiteral("oracle"));
    m.setCompareEnabled(true);
    QTRY_VERIFY_WITH_TIMEOUT(m.metricsCurrent(0) && m.metricsCurrent(1), kTimeoutMs);
    settle(m);
    const quint64 compared = m.framesRendered();
    m.setCamera(navigation::orbit(m.camera(), QPointF(-20, 5), m.renderSize()));
    QTRY_VERIFY_WITH_TIMEOUT(m.metricsCurrent(0) && m.metricsCurrent(1), kTimeoutMs);
    settle(m);
    QCOMPARE(m.framesRendered() - compared, quint64{3});
    m.setCompareEnabled(false);
    settle(m);

    // The keyboard focus moving into the view and out again draws nothing.
    auto* filter = w->findChild<QLineEdit*>("sceneFilter");
    QVERIFY(filter);
    w->activateWindow();
    QVERIFY(QTest::qWaitForWindowActive(w.get()));
    filter->setFocus();
    QTRY_VERIFY(filter->hasFocus());
    const quint64 focused = m.framesRendered();
    w->view().setFocus();
    QTRY_VERIFY(w->view().hasFocus());
    filter->setFocus();
    QTRY_VERIFY(filter->hasFocus());
    settle(m);
    QCOMPARE(m.framesRendered(), focused);
    // A repaint that nothing asked for draws nothing; a framebuffer made anew (Qt makes one when
    // the window moves to a screen of another pixel ratio, calling no resizeGL) is drawn again.
    w->view().update();
    settle(m);
    QCOMPARE(m.framesRendered(), focused);
    emit w->view().resized();
    QTRY_COMPARE_WITH_TIMEOUT(m.framesRendered(), focused + 1, kTimeoutMs);
  }

  // Fast navigation: while the camera is dragged, a slow method is drawn at a fraction of the
  // size (its budget scaled with the pixels, nothing reported); when the drag ends the full frame
  // of the new camera follows and is reported. Off, every frame is full.
  void fastNavigation() {
    auto w = openWindow();
    QVERIFY(w);
    ViewerModel& m = w->model();
    RenderView& view = w->view();
    view.setFixedSize(640, 480);
    QTRY_COMPARE_WITH_TIMEOUT(m.renderSize(), QSize(640, 480), kTimeoutMs);
    m.setMethod(QStringLiteral("vkb"));
    m.setAllParams({});
    m.setParams({{"budget_mib", "12"}});
    settle(m);
    QCOMPARE(QString::fromStdString(m.stats().method), QStringLiteral("vkb"));
    const double fullMs = m.stats().totalTimeMs();
    qInfo("vkb full frame at 640x480: %.1f ms of pass time", fullMs);
    QVERIFY2(fullMs > RenderView::kNavigationFrameMs, "the full frame is too fast to need previews here");
    const int expected = std::min(RenderView::kMaxReduction,
                                  static_cast<int>(std::ceil(std::sqrt(fullMs / RenderView::kNavigationFrameMs))));
    const std::uint64_t fullBytes = m.stats().bytesAllocated;
    QVERIFY(fullBytes <= static_cast<std::uint64_t>(12 * kMiB));

    for (const bool fast : {true, false}) {
      w->findChild<QAction*>("fastNavigationAction")->setChecked(fast);
      QCOMPARE(view.fastNavigation(), fast);
      const quint64 framesBefore = m.framesRendered();
      const mfr::Camera before = m.camera();
      const QPoint centre(view.width() / 2, view.height() / 2);
      QTest::mousePress(&view, Qt::LeftButton, {}, centre);
      QTest::mouseMove(&view, centre + QPoint(40, 10));
      QTRY_VERIFY_WITH_TIMEOUT(glm::length(m.camera().eye - before.eye) > 1e-6, kTimeoutMs);
      // Draw the frame of the moved camera while the button is still down.
      const QImage during = view.grabFramebuffer();
      QCOMPARE(during.size(), view.pixelSize());
      if (fast) {
        QCOMPARE(view.lastFrameReduction(), expected);
        QVERIFY(expected > 1);
        QCOMPARE(m.framesRendered(), framesBefore);  // previews are not reported
        // The preview is the same picture, coarser: FLIP against the full frame of this camera.
        const mfr::ImageRGBA8 full = view.renderImage(view.pixelSize());
        const double flip = mfr::flip(full, fromQImage(during)).stats.mean;
        qInfo("preview at 1/%d: FLIP %.4f against the full frame", expected, flip);
        QVERIFY(flip < 0.15);
        // The budget followed the pixels: the same share of 12 MiB as of the pixels (within the
        // method's fixed bytes), never more.
        const mfr::Stats& preview = view.lastPreviewStats();
        const QSize small((view.pixelSize().width() + expected - 1) / expected,
                          (view.pixelSize().height() + expected - 1) / expected);
        const double share = static_cast<double>(small.width()) * small.height() /
                             (static_cast<double>(view.pixelSize().width()) * view.pixelSize().height());
        qInfo("preview budget: %.3f MiB allocated of %.3f MiB", preview.bytesAllocated / kMiB, 12 * share);
        QVERIFY(preview.bytesAllocated <= static_cast<std::uint64_t>(12 * kMiB * share) + 1);
        QVERIFY(preview.bytesAllocated >= static_cast<std::uint64_t>(0.95 * 12 * kMiB * share));
      } else {
        QCOMPARE(view.lastFrameReduction(), 1);
        QTRY_VERIFY_WITH_TIMEOUT(m.framesRendered() > framesBefore, kTimeoutMs);
      }
      QTest::mouseRelease(&view, Qt::LeftButton, {}, centre + QPoint(40, 10));
      // The full frame of where the drag stopped follows and is reported.
      QTRY_VERIFY_WITH_TIMEOUT(!view.navigating() && view.lastFrameReduction() == 1, kTimeoutMs);
      settle(m);
      QVERIFY(m.framesRendered() > framesBefore);
      QCOMPARE(m.stats().bytesAllocated, fullBytes);
      QCOMPARE(m.frameKey(0).view, m.viewRevision());
    }

    // Previews leave a method's memory of earlier frames alone: the linked-list A-buffer sizing
    // its pool from the previous frame's count must not size the first full frame after a drag
    // from a preview's (a quarter or less of the fragments: that frame would overflow).
    w->findChild<QAction*>("fastNavigationAction")->setChecked(true);
    m.setMethod(QStringLiteral("abuffer-ll"));
    m.setAllParams({});
    m.setParams({{"pool", "previous"}});
    settle(m);
    m.setCamera(m.camera());  // one more full frame: its pool comes from a full frame's count
    settle(m);
    QVERIFY(!m.stats().overflow);
    const double llMs = m.stats().totalTimeMs();
    qInfo("abuffer-ll (pool=previous) full frame at 640x480: %.1f ms of pass time", llMs);
    QVERIFY2(llMs > RenderView::kNavigationFrameMs, "the full frame is too fast to need previews here");
    {
      const QPoint centre(view.width() / 2, view.height() / 2);
      QTest::mousePress(&view, Qt::LeftButton, {}, centre);
      QTest::mouseMove(&view, centre + QPoint(-30, 0));
      (void)view.grabFramebuffer();
      QVERIFY(view.lastFrameReduction() > 1);
      // The first full frame after the drag (later ones would have healed a bad pool).
      std::optional<mfr::Stats> first;
      const auto connection = connect(&m, &ViewerModel::frameRendered, this, [&] {
        if (!first) first = m.stats();
      });
      QTest::mouseRelease(&view, Qt::LeftButton, {}, centre + QPoint(-30, 0));
      QTRY_VERIFY_WITH_TIMEOUT(first.has_value(), kTimeoutMs);
      disconnect(connection);
      QCOMPARE(QString::fromStdString(first->method), QStringLiteral("abuffer-ll"));
      QVERIFY2(!first->overflow && first->fragmentsDropped == 0,
               qPrintable(QStringLiteral("%1 fragments dropped").arg(first->fragmentsDropped)));
      settle(m);
    }
  }

  // The budget panel's depth-complexity histogram: every pixel of the image, counted on the GPU;
  // against the oracle's counts of the same view it differs only by pixels on triangle edges.
  void depthHistogram() {
    auto w = openWindow();
    QVERIFY(w);
    ViewerModel& m = w->model();
    w->view().setFixedSize(240, 180);
    QTRY_COMPARE_WITH_TIMEOUT(m.renderSize(), QSize(240, 180), kTimeoutMs);
    m.setCamera(m.scene().view("iso"));
    settle(m);
    QSignalSpy ready(&m, &ViewerModel::depthComplexityReady);
    m.requestDepthComplexity();
    QTRY_VERIFY_WITH_TIMEOUT(!ready.isEmpty(), kTimeoutMs);
    const QList<QVariant> args = ready.takeLast();
    const auto histogram = args.at(0).value<QVector<quint64>>();
    const QSize size = args.at(1).toSize();
    QCOMPARE(size, QSize(240, 180));  // the image's own size, no longer a reduced copy
    quint64 pixels = 0;
    for (quint64 c : histogram) pixels += c;
    QCOMPARE(pixels, static_cast<quint64>(240 * 180));
    const mfr::FragmentLists lists = mfr::castFragments(m.scene(), m.camera(), size.width(), size.height());
    std::vector<quint64> oracle;
    std::size_t ambiguous = 0;
    for (int y = 0; y < size.height(); ++y)
      for (int x = 0; x < size.width(); ++x) {
        const std::size_t n = lists.count(x, y);
        if (n >= oracle.size()) oracle.resize(n + 1);
        ++oracle[n];
        ambiguous += lists.isAmbiguous(x, y);
      }
    quint64 distance = 0;
    for (std::size_t n = 0; n < std::max<std::size_t>(oracle.size(), histogram.size()); ++n) {
      const quint64 a = n < oracle.size() ? oracle[n] : 0,
                    b = n < static_cast<std::size_t>(histogram.size()) ? histogram[n] : 0;
      distance += a > b ? a - b : b - a;
    }
    qInfo("histogram: %zu bins, L1 distance to the oracle's %llu pixels (%zu pixels on edges)",
          static_cast<std::size_t>(histogram.size()), static_cast<unsigned long long>(distance), ambiguous);
    QVERIFY(histogram.size() > 10);      // the sample is deep
    QVERIFY(distance <= 2 * ambiguous);  // only edge pixels may differ…
    QVERIFY(distance <= pixels / 100);   // …and few of them do (10 of 43,200 when measured)
    // The budget panel's histogram follows the image it describes: side by side, the pane's, at
    // once (it kept the whole view's size until the camera moved: a bug hunt), and says when
    // nothing is visible (it read "computing…" for ever).
    auto* widget = w->findChild<QWidget*>("depthHistogram");
    QVERIFY(widget);
    QTRY_COMPARE_WITH_TIMEOUT(widget->accessibleName(), QStringLiteral("Depth complexity n(p), GPU count (240×180)"),
                              10000);
    m.setCompareEnabled(true);
    QTRY_COMPARE_WITH_TIMEOUT(widget->accessibleName(), QStringLiteral("Depth complexity n(p), GPU count (120×180)"),
                              10000);
    m.setCompareEnabled(false);
    for (int i = 0; i < static_cast<int>(m.scene().objects.size()); ++i) m.setObjectVisible(i, false);
    QTRY_COMPARE_WITH_TIMEOUT(widget->accessibleName(), QStringLiteral("Depth complexity: nothing visible"), 10000);
  }

  // A part given a colour of its own shows that colour instead of its file's per-vertex colours
  // (a molecule's element colours); resetting brings the file's colours back, pixel for pixel.
  void resetColour() {
    auto w = openWindow(QStringLiteral("/usr/share/pymol/data/demo/pept.pdb"));
    QVERIFY(w);
    ViewerModel& m = w->model();
    w->view().setFixedSize(200, 150);
    QTRY_COMPARE_WITH_TIMEOUT(m.renderSize(), QSize(200, 150), kTimeoutMs);
    settle(m);
    QVERIFY(!m.scene().objects.empty() && !m.scene().objects[0].mesh->colors.empty());
    QVERIFY(!m.objectColorEdited(0));
    const mfr::ImageRGBA8 before = fromQImage(w->view().grabFramebuffer());
    m.setObjectColor(0, QColor(30, 60, 200));
    QVERIFY(m.objectColorEdited(0));
    QVERIFY(!m.scene().objects[0].material.vertexColors);
    settle(m);
    const mfr::ImageRGBA8 recoloured = fromQImage(w->view().grabFramebuffer());
    QVERIFY(maxChannelDifference(before, recoloured) > 50);  // element colours gone
    const float opacity = m.scene().objects[0].material.color.a;
    m.resetObjectColor(0);
    QVERIFY(!m.objectColorEdited(0));
    QVERIFY(m.scene().objects[0].material.vertexColors);
    QCOMPARE(m.scene().objects[0].material.color.a, opacity);
    settle(m);
    QCOMPARE(maxChannelDifference(before, fromQImage(w->view().grabFramebuffer())), 0);
  }

  // The Scene dock's filter and selection (a bug hunt's "no multi-select or search for thousands of
  // parts"): the filter hides rows, not parts; the selection's actions change the selected parts that
  // the filter shows, each action in one scene edit; names are not editable.
  void sceneDockFiltersAndEditsTheSelection() {
    auto w = openWindow();
    QVERIFY(w);
    ViewerModel& m = w->model();
    w->view().setFixedSize(160, 120);
    w->findChild<QDockWidget*>("sceneDock")->raise();
    auto* tree = w->findChild<QTreeWidget*>("sceneTree");
    auto* filter = w->findChild<QLineEdit*>("sceneFilter");
    auto* count = w->findChild<QLabel*>("sceneFilterCount");
    QVERIFY(tree && filter && count);
    QCOMPARE(tree->topLevelItemCount(), 6);  // outer, middle, inner shell, ring A, ring B, tangle
    const auto shownRows = [&] {
      QList<int> rows;
      for (int r = 0; r < tree->topLevelItemCount(); ++r)
        if (!tree->topLevelItem(r)->isHidden()) rows << r;
      return rows;
    };
    const auto visibleParts = [&] {
      QList<int> parts;
      for (std::size_t i = 0; i < m.scene().objects.size(); ++i)
        if (m.scene().objects[i].visible) parts << static_cast<int>(i);
      return parts;
    };
    const auto action = [&](const char* name) {
      auto* a = w->findChild<QAction*>(name);
      return a;
    };
    // Plain text anywhere in the name, case ignored; * and ? match the whole name.
    filter->setText("SHELL");
    QCOMPARE(shownRows(), (QList<int>{0, 1, 2}));
    QCOMPARE(count->text(), QStringLiteral("3 of 6"));
    filter->setText("r*");
    QCOMPARE(shownRows(), (QList<int>{3, 4}));
    filter->setText("ring ?");
    QCOMPARE(shownRows(), (QList<int>{3, 4}));
    filter->setText("*a");
    QCOMPARE(shownRows(), (QList<int>{3}));
    filter->setText("ring.");  // not a regular expression
    QCOMPARE(shownRows(), QList<int>{});
    // Select all under a filter, hide: only the shown rows' parts, in one edit.
    filter->setText("shell");
    tree->selectAll();
    QVERIFY(action("hidePartsAction")->isEnabled());
    int edits = 0;
    QMetaObject::Connection counting = connect(&m, &ViewerModel::sceneChanged, [&edits] { ++edits; });
    const QList<int> all{0, 1, 2, 3, 4, 5};
    std::vector<std::vector<ViewerModel::PartLook>> looks{m.partLooks(all)};  // after each edit, for Undo
    action("hidePartsAction")->trigger();
    looks.push_back(m.partLooks(all));
    QCOMPARE(edits, 1);
    QCOMPARE(visibleParts(), (QList<int>{3, 4, 5}));
    // Space on the tree toggles the selection as one box: all hidden → all shown.
    w->activateWindow();
    QVERIFY(QTest::qWaitForWindowActive(w.get()));
    tree->setFocus();
    QTest::keyClick(tree, Qt::Key_Space);
    QCOMPARE(edits, 2);
    looks.push_back(m.partLooks(all));
    QCOMPARE(visibleParts(), (QList<int>{0, 1, 2, 3, 4, 5}));
    // The rows hidden by the filter keep their check boxes in step with the parts.
    filter->clear();
    QCOMPARE(shownRows().size(), 6);
    QVERIFY(!count->isVisible());
    tree->clearSelection();
    QVERIFY(!action("hidePartsAction")->isEnabled());
    tree->topLevelItem(3)->setSelected(true);
    tree->topLevelItem(4)->setSelected(true);
    action("showOnlyPartsAction")->trigger();
    looks.push_back(m.partLooks(all));
    QCOMPARE(visibleParts(), (QList<int>{3, 4}));
    QCOMPARE(tree->topLevelItem(0)->checkState(0), Qt::Unchecked);
    QCOMPARE(tree->topLevelItem(3)->checkState(0), Qt::Checked);
    action("showAllPartsAction")->trigger();
    looks.push_back(m.partLooks(all));
    QCOMPARE(visibleParts(), (QList<int>{0, 1, 2, 3, 4, 5}));
    QCOMPARE(edits, 4);
    // Colour and opacity of the selection, answered in their dialogs.
    const auto answer = [](const std::function<bool(QWidget*)>& reply) {
      auto* timer = new QTimer;
      QObject::connect(timer, &QTimer::timeout, [timer, reply] {
        if (QWidget* dialog = QApplication::activeModalWidget(); dialog && reply(dialog)) timer->deleteLater();
      });
      timer->start(20);
    };
    const glm::vec4 ringB = m.scene().objects[4].material.color;
    answer([](QWidget* dialog) {
      auto* colours = qobject_cast<QColorDialog*>(dialog);
      if (!colours) return false;
      colours->setCurrentColor(QColor(255, 0, 0));
      colours->accept();
      return true;
    });
    action("colourPartsAction")->trigger();
    QCOMPARE(edits, 5);
    looks.push_back(m.partLooks(all));
    QCOMPARE(glm::vec3(m.scene().objects[3].material.color), glm::vec3(1, 0, 0));
    QCOMPARE(glm::vec3(m.scene().objects[4].material.color), glm::vec3(1, 0, 0));
    QCOMPARE(m.scene().objects[4].material.color.a, ringB.a);  // the opacity stays
    QCOMPARE(glm::vec3(m.scene().objects[5].material.color), glm::vec3(0.85f, 0.45f, 0.85f));
    QCOMPARE(tree->topLevelItem(4)->text(1), QStringLiteral("#ff0000"));
    QVERIFY(action("resetColourAction")->isEnabled());
    action("resetColourAction")->trigger();
    looks.push_back(m.partLooks(all));
    QCOMPARE(m.scene().objects[4].material.color, ringB);
    QVERIFY(!m.objectColorEdited(3) && !m.objectColorEdited(4));
    QVERIFY(!action("resetColourAction")->isEnabled());
    answer([](QWidget* dialog) {
      auto* input = qobject_cast<QInputDialog*>(dialog);
      if (!input) return false;
      input->setDoubleValue(0.125);
      input->accept();
      return true;
    });
    action("opacityPartsAction")->trigger();
    QCOMPARE(m.objectOpacity(3), 0.125);
    QCOMPARE(m.objectOpacity(4), 0.125);
    QCOMPARE(m.objectOpacity(5), static_cast<double>(0.4f));
    QCOMPARE(edits, 7);
    looks.push_back(m.partLooks(all));
    disconnect(counting);
    // Edit ▸ Undo takes the seven steps back one at a time, each in one scene edit, to the parts as
    // loaded (colours with their vertex colours, opacities, visibility); Redo takes them forward.
    auto* undo = action("undoAction");
    auto* redo = action("redoAction");
    QVERIFY(undo && redo);
    QCOMPARE(undo->text(), QStringLiteral("Undo Opacity of 2 parts"));
    edits = 0;
    counting = connect(&m, &ViewerModel::sceneChanged, [&edits] { ++edits; });
    for (std::size_t step = looks.size() - 1; step > 0; --step) {
      QVERIFY(undo->isEnabled());
      undo->trigger();
      QVERIFY2(m.partLooks(all) == looks[step - 1], qPrintable(QString::number(step)));
    }
    QVERIFY(!undo->isEnabled());
    QCOMPARE(edits, 7);
    QCOMPARE(redo->text(), QStringLiteral("Redo Hide 3 parts"));
    for (std::size_t step = 1; step < looks.size(); ++step) {
      redo->trigger();
      QVERIFY2(m.partLooks(all) == looks[step], qPrintable(QString::number(step)));
    }
    QVERIFY(!redo->isEnabled());
    // Ctrl+Z from the view; a new edit drops what could be redone.
    w->view().setFocus();
    QTest::keyClick(&w->view(), Qt::Key_Z, Qt::ControlModifier);
    QVERIFY(m.partLooks(all) == looks[looks.size() - 2]);
    tree->clearSelection();
    tree->topLevelItem(5)->setCheckState(0, Qt::Unchecked);
    QVERIFY(!m.scene().objects[5].visible);
    QVERIFY(!redo->isEnabled());
    QCOMPARE(undo->text(), QStringLiteral("Undo Hide tangle"));
    // A step puts back only what it changed: an opacity set since by others (the ghosting panel
    // sets opacities through ViewerContext, not as steps) stays when the hide is undone and redone
    // (review 28: the whole look came back, opacity and all).
    m.setObjectOpacity(5, 0.3);
    undo->trigger();
    QVERIFY(m.scene().objects[5].visible);
    QCOMPARE(m.scene().objects[5].material.color.a, 0.3f);
    redo->trigger();
    QVERIFY(!m.scene().objects[5].visible);
    QCOMPARE(m.scene().objects[5].material.color.a, 0.3f);
    disconnect(counting);
    // Fit the view to ring A: the camera looks at its box's centre from nearer than fit all, in
    // the same direction; near and far still hold the whole scene.
    const mfr::Camera before = m.scene().fit(m.camera());
    m.setCamera(before);
    tree->clearSelection();
    tree->topLevelItem(3)->setSelected(true);
    action("fitPartsAction")->trigger();
    mfr::Scene ringA;
    ringA.objects.push_back(m.scene().objects[3]);
    const glm::dvec3 centre = ringA.bounds().center();
    QVERIFY(glm::length(m.camera().target - centre) < 1e-9);
    QVERIFY(glm::length(m.camera().eye - m.camera().target) < glm::length(before.eye - before.target));
    const glm::dvec3 d0 = glm::normalize(before.eye - before.target);
    QVERIFY(glm::length(glm::normalize(m.camera().eye - m.camera().target) - d0) < 1e-9);
    QVERIFY(m.camera().farPlane >= glm::length(m.camera().eye - m.scene().bounds().center()));
    // A name is not edited in place (its editor renamed the row, not the part).
    tree->editItem(tree->topLevelItem(0), 0);
    QVERIFY(!tree->findChild<QLineEdit*>());
    // Another scene's parts are other parts: the history goes with the old ones.
    QVERIFY(undo->isEnabled());
    w->openScene(QStringLiteral("@csg"));
    QTRY_VERIFY_WITH_TIMEOUT(!m.isLoading() && m.scene().name == "csg", kTimeoutMs);
    QVERIFY(!undo->isEnabled() && !redo->isEnabled());
  }

  // Which part is this: a double click on the view selects, in the Scene dock, the part the oracle
  // finds nearest the eye at that pixel (parts of opacity 0 left out); the background clears the
  // selection; a double click on a fragment's row of the Probe dock selects that fragment's part.
  void pickingAPartSelectsItsRow() {
    auto w = openFixedView(QSize(200, 150));  // widget points are image pixels
    QVERIFY(w);
    ViewerModel& m = w->model();
    RenderView& view = w->view();
    m.setMethod("wboit");
    m.setCamera(m.scene().view("iso"));
    m.setObjectOpacity(0, 0.0);                         // the outer shell: drawn, of opacity 0, so not picked
    m.setObjectVisibilities({{1, false}, {2, false}});  // the rings and the tangle show
    settle(m);
    auto* tree = w->findChild<QTreeWidget*>("sceneTree");
    QVERIFY(tree);
    const auto selectedRows = [&] {
      QList<int> rows;
      for (QTreeWidgetItem* item : tree->selectedItems()) rows << tree->indexOfTopLevelItem(item);
      return rows;
    };
    const mfr::FragmentLists oracle = mfr::castFragments(m.scene(), m.camera(), 200, 150);
    const auto expected = [&](QPoint p) {
      for (const mfr::Fragment& f : oracle.pixel(p.x(), p.y()))
        if ((f.color >> 24) != 0) return static_cast<int>(f.objectId);
      return -1;
    };
    // One unambiguous pixel per part that is nearest somewhere.
    std::map<int, QPoint> pixels;
    for (int y = 2; y < 148; y += 3)
      for (int x = 2; x < 198; x += 3)
        if (!oracle.isAmbiguous(x, y) && expected(QPoint(x, y)) >= 0)
          pixels.emplace(expected(QPoint(x, y)), QPoint(x, y));
    QVERIFY2(pixels.size() >= 3, qPrintable(QString::number(pixels.size())));
    QVERIFY(!pixels.contains(0));
    tree->topLevelItem(0)->setSelected(true);
    for (const auto& [part, pixel] : pixels) {
      QTest::mouseDClick(&view, Qt::LeftButton, Qt::NoModifier, pixel);
      QCOMPARE(selectedRows(), QList<int>{part});
      QVERIFY(w->statusBar()->currentMessage().contains(QString::fromStdString(m.scene().objects[part].name)));
    }
    QTest::mouseDClick(&view, Qt::LeftButton, Qt::NoModifier, QPoint(1, 1));  // background
    QCOMPARE(selectedRows(), QList<int>{});
    QCOMPARE(w->statusBar()->currentMessage(), QStringLiteral("No part there"));
    // A filter that hides the picked part's row is cleared, so the row shows.
    auto* filter = w->findChild<QLineEdit*>("sceneFilter");
    filter->setText("no such part");
    QTest::mouseDClick(&view, Qt::LeftButton, Qt::NoModifier, pixels.begin()->second);
    QCOMPARE(filter->text(), QString());
    QCOMPARE(selectedRows(), QList<int>{pixels.begin()->first});
    // The Probe dock's rows: each selects its fragment's part.
    auto* table = w->findChild<QTableWidget*>("probeTable");
    QVERIFY(table);
    const QPoint deep = deepestPixel(oracle, QRect(60, 40, 80, 70));
    QVERIFY(deep.x() >= 0);
    const auto list = oracle.pixel(deep.x(), deep.y());
    // A point within the pixel but nearer its right and bottom edges probes that pixel (the rounded
    // point probed the next one: at scale 2 no odd row or column could be probed; a bug hunt).
    // Pressed as the window system gives a click at a fractional scale: a position between integers
    // to the top-level window, which QApplication rounds for the widget (a review).
    const auto ctrlPress = [&](QPointF at) {
      const QPointF inWindow = at + view.mapTo(w.get(), QPointF(0, 0));
      QMouseEvent press(QEvent::MouseButtonPress, inWindow, view.mapToGlobal(at), Qt::LeftButton, Qt::LeftButton,
                        Qt::ControlModifier);
      QCoreApplication::sendEvent(w->windowHandle(), &press);
      QMouseEvent release(QEvent::MouseButtonRelease, inWindow, view.mapToGlobal(at), Qt::LeftButton, Qt::NoButton,
                          Qt::ControlModifier);
      QCoreApplication::sendEvent(w->windowHandle(), &release);
    };
    ctrlPress(QPointF(deep) + QPointF(0.75, 0.75));
    QTRY_COMPARE_WITH_TIMEOUT(table->rowCount(), static_cast<int>(list.size()) + 1, 20000);
    auto* summary = w->findChild<QLabel*>("probeSummary");
    QVERIFY2(summary->text().startsWith(QStringLiteral("Pixel (%1, %2) ").arg(deep.x()).arg(deep.y())),
             qPrintable(summary->text()));
    std::set<int> seen;
    for (int row = 0; row < static_cast<int>(list.size()); ++row) {
      const int part = static_cast<int>(list[static_cast<std::size_t>(row)].objectId);
      if (!seen.insert(part).second) continue;
      table->scrollToItem(table->item(row, ProbePanel::Part));
      const QPoint at = table->visualItemRect(table->item(row, ProbePanel::Part)).center();
      // A real double click's first press: QTest's double click alone is taken as a press by the
      // table (it opens no double click on a row not pressed before).
      QTest::mouseClick(table->viewport(), Qt::LeftButton, Qt::NoModifier, at);
      QTest::mouseDClick(table->viewport(), Qt::LeftButton, Qt::NoModifier, at);
      QCOMPARE(selectedRows(), QList<int>{part});
    }
    QVERIFY(seen.size() >= 2);
  }

  // The pick follows what is drawn, not the nearest fragment: with the operation csg the surface
  // the classification keeps (a cut-away ball, or a drill's hole showing the background, was
  // picked; a review), checked against the oracle's CSG image (its pixel is a fragment of the part
  // picked, and the background where nothing is picked); an opaque volume slice in front hides the
  // part behind it (that part was picked).
  void pickingFollowsWhatIsDrawn() {
    auto w = openFixedView(QSize(160, 120), QStringLiteral("@csg"));
    QVERIFY(w);
    ViewerModel& m = w->model();
    RenderView& view = w->view();
    m.setMethod("abuffer-sbuffer");
    m.setOperation(QStringLiteral("csg"));
    m.setCamera(m.scene().view("front"));
    settle(m);
    const mfr::FragmentLists lists = mfr::castFragments(m.drawnScene(), m.camera(), 160, 120);
    const mfr::ImageRGBA8 csg = mfr::compositeCsg(lists, m.drawnScene());
    const glm::vec3 bg = m.scene().background;
    const auto rgbAt = [&](int x, int y) {
      const std::size_t i = (static_cast<std::size_t>(y) * 160 + x) * 4;
      return glm::ivec3(csg.pixels[i], csg.pixels[i + 1], csg.pixels[i + 2]);
    };
    const glm::ivec3 background(glm::round(bg * 255.0f));
    int checked = 0, notNearest = 0, holes = 0;
    for (int y = 4; y < 120; y += 7)
      for (int x = 4; x < 160; x += 7) {
        if (lists.isAmbiguous(x, y) || lists.count(x, y) == 0) continue;
        const int part = view.partAt(QPointF(x + 0.5, y + 0.5));
        const glm::ivec3 shown = rgbAt(x, y);
        if (part < 0) {
          QCOMPARE(shown, background);
          ++holes;
        } else {
          bool found = false;  // the image's colour is a fragment of the part picked
          for (const mfr::Fragment& f : lists.pixel(x, y))
            found = found || (static_cast<int>(f.objectId) == part &&
                              glm::ivec3(f.color & 0xFF, (f.color >> 8) & 0xFF, (f.color >> 16) & 0xFF) == shown);
          QVERIFY2(found, qPrintable(QStringLiteral("pixel %1,%2: part %3").arg(x).arg(y).arg(part)));
        }
        notNearest += part != static_cast<int>(lists.pixel(x, y).front().objectId) ? 1 : 0;
        ++checked;
      }
    QVERIFY2(checked > 100 && notNearest > 5 && holes > 0,
             qPrintable(QStringLiteral("%1 %2 %3").arg(checked).arg(notNearest).arg(holes)));
    // A volume's opaque slice in front of a part: nothing is picked there.
    w->openScene(QStringLiteral("@volume"));
    QTRY_VERIFY_WITH_TIMEOUT(m.hasScene() && m.scene().name == "volume" && !m.busy(), kTimeoutMs);
    m.setMethod("abuffer-sbuffer");
    m.setOperation(QStringLiteral("auto"));
    m.setCamera(m.scene().view("front"));
    m.setSection(mfr::parseSectionPlane("-z=0.9:slice", "test"));
    settle(m);
    const std::size_t parts = m.scene().objects.size();
    const mfr::FragmentLists sliced = mfr::castFragments(m.drawnScene(), m.camera(), 160, 120);
    int slices = 0;
    for (int y = 4; y < 120; y += 5)
      for (int x = 4; x < 160; x += 5) {
        const auto list = sliced.pixel(x, y);
        if (sliced.isAmbiguous(x, y) || list.size() < 2 || list.front().objectId < parts) continue;
        const bool partBehind = std::any_of(list.begin(), list.end(), [&](const mfr::Fragment& f) {
          return f.objectId < parts && (f.color >> 24) != 0;
        });
        if (!partBehind) continue;
        QCOMPARE(view.partAt(QPointF(x + 0.5, y + 0.5)), -1);
        ++slices;
      }
    QVERIFY2(slices > 0, "no pixel with a slice in front of a part");
  }

  // Edits made while another scene loads do not land on the wrong scene (a bug hunt): a Molecule
  // box clicked while a file was read re-read the molecule instead, so the file never came (and a
  // session waiting for it was applied to the molecule); a part's colour dialog open across a load
  // recoloured the new scene's part of that index, and the tree kept the old scene's rows.
  void editsDuringALoadDoNotLandOnTheNextScene() {
    auto w = openWindow(QStringLiteral("/usr/share/pymol/data/demo/pept.pdb"));
    QVERIFY(w);
    ViewerModel& m = w->model();
    w->view().setFixedSize(160, 120);
    w->findChild<QDockWidget*>("sceneDock")->raise();
    auto* sticks = w->findChild<QCheckBox*>("moleculeSticks");
    QVERIFY(sticks && sticks->isVisible() && !sticks->isChecked());
    w->openScene(QStringLiteral("@sample"));
    QVERIFY(m.isLoading());
    sticks->click();  // refused: the box shows the molecule's representations again
    QVERIFY(!sticks->isChecked());
    QTRY_VERIFY_WITH_TIMEOUT(!m.isLoading() && m.scene().name == "sample", kTimeoutMs);
    settle(m);
    // A colour dialog open while another scene loads: the choice is dropped, the rows are the new scene's.
    auto* tree = w->findChild<QTreeWidget*>("sceneTree");
    const mfr::Scene csgScene = mfr::makeCsgSampleScene();
    bool loaded = false;
    auto* timer = new QTimer(w.get());
    connect(timer, &QTimer::timeout, [&, timer] {
      auto* dialog = qobject_cast<QColorDialog*>(QApplication::activeModalWidget());
      if (!dialog) return;
      timer->stop();
      w->openScene(QStringLiteral("@csg"));
      loaded = QTest::qWaitFor([&] { return !m.isLoading() && m.scene().name == "csg"; }, kTimeoutMs);
      dialog->setCurrentColor(QColor(255, 0, 255));
      dialog->accept();
    });
    timer->start(20);
    const QRect cell = tree->visualItemRect(tree->topLevelItem(1));
    QTest::mouseClick(tree->viewport(), Qt::LeftButton, Qt::NoModifier,
                      QPoint(tree->header()->sectionViewportPosition(1) + 8, cell.center().y()));
    QTRY_VERIFY_WITH_TIMEOUT(loaded && !QApplication::activeModalWidget(), kTimeoutMs);
    QApplication::processEvents();
    QCOMPARE(m.scene().objects[1].material.color, csgScene.objects[1].material.color);
    QCOMPARE(tree->topLevelItemCount(), static_cast<int>(csgScene.objects.size()));
    for (int i = 0; i < tree->topLevelItemCount(); ++i)
      QCOMPARE(tree->topLevelItem(i)->text(0),
               QString::fromStdString(csgScene.objects[static_cast<std::size_t>(i)].name));
    // Nor does a click whose rows are rebuilt before its dialog opens (a load's end already
    // queued behind the click: the dialog offered the old part, and the choice recoloured the new
    // scene's part of that index; a review).
    bool opened = false;
    auto* watch = new QTimer(w.get());
    connect(watch, &QTimer::timeout, [&] {
      if (auto* dialog = qobject_cast<QColorDialog*>(QApplication::activeModalWidget())) {
        opened = true;
        dialog->reject();
      }
    });
    watch->start(20);
    const QRect row = tree->visualItemRect(tree->topLevelItem(1));
    QTest::mouseClick(tree->viewport(), Qt::LeftButton, Qt::NoModifier,
                      QPoint(tree->header()->sectionViewportPosition(1) + 8, row.center().y()));
    m.setScene(mfr::makeSampleScene(), QStringLiteral("@sample"));
    QTest::qWait(300);
    watch->stop();
    QVERIFY(!opened);
    QCOMPARE(tree->topLevelItemCount(), static_cast<int>(mfr::makeSampleScene().objects.size()));
    // A CPU method's picture of the old scene is not shown under the new one while the new one is
    // computed (the view drew the previous file for seconds; a bug hunt).
    m.setMethod(QStringLiteral("oracle"));
    settle(m);
    QVERIFY(m.lastCpuImage(ViewerModel::paneSlot(0)) != nullptr);
    bool stale = true;
    QString statistics;  // nor its numbers (they stood until the new frame)
    auto* statsTree = w->findChild<QTreeWidget*>("statsTree");
    QVERIFY(statsTree && statsTree->topLevelItemCount() > 1);
    const QMetaObject::Connection checking = connect(&m, &ViewerModel::sceneLoaded, [&] {
      const CpuImage* last = m.lastCpuImage(ViewerModel::paneSlot(0));
      stale = last != nullptr && last->key.scene != m.sceneRevision();
      statistics.clear();
      for (int i = 0; i < statsTree->topLevelItemCount(); ++i)
        statistics += statsTree->topLevelItem(i)->text(0) + ": " + statsTree->topLevelItem(i)->text(1) + "; ";
    });
    w->openScene(QStringLiteral("@sample"));
    QTRY_VERIFY_WITH_TIMEOUT(!m.isLoading() && m.scene().name == "sample", kTimeoutMs);
    disconnect(checking);
    QVERIFY(!stale);
    QCOMPARE(statistics, QStringLiteral("Frame: being computed for this scene; "));
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
    // A standard view of a scene with nothing visible turns about the target at its distance (the
    // fit of nothing put the eye 1 unit from the origin: a bug hunt).
    mfr::Scene hidden = mfr::makeSampleScene();
    for (mfr::Object& part : hidden.objects) part.visible = false;
    mfr::Camera far = c;
    far.eye = {2, 3, 40};
    far.target = {2, 3, 0};
    const mfr::Camera right = navigation::standardView(navigation::StandardView::Right, hidden, far);
    QVERIFY(glm::length(right.target - far.target) < 1e-12);
    QVERIFY(glm::length(right.eye - glm::dvec3(42, 3, 0)) < 1e-9);
  }

  // Side by side, the mouse navigates the pane under it: a pan drag moves the scene as far as the
  // cursor in either pane, and the wheel zooms towards the point under the cursor in that pane
  // (both used the whole view's size and centre: a pan moved pane A's scene 2/3 as far as the
  // cursor here, and the wheel zoomed towards another point: a bug hunt). Points go to pane
  // pixels by the camera's own matrices, as the panes are rendered.
  void sideBySideNavigationFollowsThePane() {
    auto w = openWindow();
    QVERIFY(w);
    ViewerModel& m = w->model();
    RenderView& view = w->view();
    view.setFixedSize(400, 300);
    QTRY_COMPARE_WITH_TIMEOUT(m.renderSize(), QSize(400, 300), kTimeoutMs);
    QCOMPARE(view.devicePixelRatioF(), 1.0);
    m.setCompareLayout(CompareLayout::SideBySide);
    m.setCompareEnabled(true);
    QCOMPARE(m.paneSize(), QSize(200, 300));
    const QSizeF pane(200.0, 300.0);
    const auto toPane = [&pane](const mfr::Camera& c, const glm::dvec3& p) {
      const glm::dvec4 clip = c.projectionMatrix(pane.width() / pane.height()) * c.viewMatrix() * glm::dvec4(p, 1.0);
      return QPointF((clip.x / clip.w * 0.5 + 0.5) * pane.width(), (0.5 - clip.y / clip.w * 0.5) * pane.height());
    };
    const auto fromPane = [&pane](const mfr::Camera& c, QPointF at) {
      const glm::dmat4 inverse = glm::inverse(c.projectionMatrix(pane.width() / pane.height()) * c.viewMatrix());
      const glm::dvec4 p =
          inverse * glm::dvec4(at.x() / pane.width() * 2.0 - 1.0, 1.0 - at.y() / pane.height() * 2.0, 0.0, 1.0);
      return glm::dvec3(p) / p.w;
    };
    for (const bool ortho : {false, true}) {
      mfr::Camera start = m.scene().view("iso");
      if (ortho) start = navigation::toggledProjection(start);
      for (const int side : {0, 1}) {
        m.setCamera(start);
        const QPoint offset(side == 1 ? 200 : 0, 0);
        // A pan drag of (40, 30) in the pane: the target under the pane's centre follows it.
        const glm::dvec3 target = start.target;
        const QPointF before = toPane(m.camera(), target);
        QTest::mousePress(&view, Qt::MiddleButton, {}, offset + QPoint(100, 150));
        QTest::mouseMove(&view, offset + QPoint(120, 165));
        QTest::mouseMove(&view, offset + QPoint(140, 180));
        QTest::mouseRelease(&view, Qt::MiddleButton, {}, offset + QPoint(140, 180));
        const QPointF moved = toPane(m.camera(), target) - before;
        QVERIFY2(
            std::abs(moved.x() - 40.0) < 0.5 && std::abs(moved.y() - 30.0) < 0.5,
            qPrintable(QStringLiteral("ortho %1, side %2: %3, %4").arg(ortho).arg(side).arg(moved.x()).arg(moved.y())));
        // Three wheel steps in at (150, 60) in the pane: the point under it stays under it.
        m.setCamera(start);
        const QPointF cursor(150.0, 60.0);
        const glm::dvec3 under = fromPane(m.camera(), cursor);
        const QPointF at = QPointF(offset) + cursor;
        QWheelEvent wheel(at, view.mapToGlobal(at), QPoint(), QPoint(0, 360), Qt::NoButton, Qt::NoModifier,
                          Qt::NoScrollPhase, false);
        QApplication::sendEvent(&view, &wheel);
        const QPointF after = toPane(m.camera(), under);
        QVERIFY2(glm::length(m.camera().eye - start.eye) > 1e-3, "the wheel did not zoom");
        QVERIFY2(
            std::abs(after.x() - cursor.x()) < 0.5 && std::abs(after.y() - cursor.y()) < 0.5,
            qPrintable(QStringLiteral("ortho %1, side %2: %3, %4").arg(ortho).arg(side).arg(after.x()).arg(after.y())));
      }
    }
  }

  // Ghosting set every part's opacity in one scene edit, yet the Scene panel froze for 7 s at 1,000
  // parts (22 s at 4,000): its columns sized to contents re-measured every row at every changed
  // cell (a bug hunt; the Probe dock's table fills the same way). Counted by the size hints asked
  // for, not timed: a few per row, where it was one per row per changed cell.
  void manyRowsFillWithoutRemeasuringEachRow() {
    constexpr int kParts = 300;
    auto w = openWindow(QString());  // a small view and a cheap method before the deep scene
    QVERIFY(w);
    ViewerModel& m = w->model();
    RenderView& view = w->view();
    view.setFixedSize(160, 120);
    m.setMethod("wboit");
    w->openScene(QStringLiteral("@quads:%1").arg(kParts));
    QTRY_VERIFY_WITH_TIMEOUT(m.hasScene() && m.framesRendered() > 0, kTimeoutMs);
    QCOMPARE(m.renderSize(), QSize(160, 120));
    m.setCamera(m.scene().view("front"));
    settle(m);
    auto* tree = w->findChild<QTreeWidget*>("sceneTree");
    QVERIFY(tree);
    QCOMPARE(tree->topLevelItemCount(), kParts);
    w->findChild<QDockWidget*>("sceneDock")->raise();  // a hidden view measures nothing
    QTRY_VERIFY_WITH_TIMEOUT(tree->isVisible(), kTimeoutMs);
    QTest::qWait(500);
    SizeHintCounter treeHints;  // on every column: the Opacity column has a delegate of its own
    std::vector<QAbstractItemDelegate*> treeDelegates;
    for (int c = 0; c < tree->columnCount(); ++c) {
      treeDelegates.push_back(tree->itemDelegateForColumn(c));
      tree->setItemDelegateForColumn(c, &treeHints);
    }
    // Ghosting: one scene edit sets every other part's opacity.
    auto* ghost = w->findChild<QCheckBox*>("ghostOthers");
    QVERIFY(ghost);
    w->findChild<QDockWidget*>("plugin-ghosting")->raise();  // where the user ticks it
    QTest::qWait(500);
    QVERIFY(tree->isVisible());
    ghost->setChecked(true);
    QCOMPARE(tree->topLevelItem(kParts - 1)->data(2, Qt::EditRole).toDouble(), 0.15);  // the ghost opacity
    QApplication::processEvents();  // the columns' one measurement, deferred
    QVERIFY2(treeHints.calls < 20 * kParts, qPrintable(QStringLiteral("%1 size hints").arg(treeHints.calls)));
    // Edits that change no row measure nothing again (each measured every column again: a slider
    // dragged over a section plane or a ghost opacity re-measured the tree at every step; a review).
    treeHints.calls = 0;
    const glm::vec4 colour = m.scene().objects[0].material.color;
    for (int i = 0; i < 5; ++i) m.setObjectColor(0, QColor::fromRgbF(colour.r, colour.g, colour.b));  // no new value
    QApplication::processEvents();
    QVERIFY2(treeHints.calls < kParts, qPrintable(QStringLiteral("%1 size hints").arg(treeHints.calls)));
    for (int c = 0; c < tree->columnCount(); ++c) tree->setItemDelegateForColumn(c, treeDelegates[c]);
  }

  // The Probe dock: Ctrl + click lists the oracle's exact fragments behind the pixel (parts in
  // depth order, shares summing to 100 %), which of them the method holds (a k-buffer's k nearest,
  // an A-buffer's all), follows the method without another click, does not orbit, and clears.
  void pixelProbe() {
    auto w = openFixedView(QSize(200, 150));  // widget points are image pixels
    QVERIFY(w);
    ViewerModel& m = w->model();
    RenderView& view = w->view();
    m.setMethod("kplus-array");
    m.setParams({{"k", "2"}});
    m.setCamera(m.scene().view("iso"));
    settle(m);
    const mfr::FragmentLists oracle = mfr::castFragments(m.scene(), m.camera(), 200, 150);
    const QPoint pixel = deepestPixel(oracle, QRect(70, 50, 60, 50));  // near the middle
    QVERIFY(pixel.x() >= 0);
    const auto list = oracle.pixel(pixel.x(), pixel.y());
    const int n = static_cast<int>(list.size());
    QVERIFY2(n >= 4, "the probed list must be longer than k");

    auto* table = w->findChild<QTableWidget*>("probeTable");
    auto* summary = w->findChild<QLabel*>("probeSummary");
    QVERIFY(table && summary);
    const glm::dvec3 eyeBefore = m.camera().eye;
    // A probe of this small view takes milliseconds: a failure should not wait the usual timeout.
    constexpr int kProbeTimeoutMs = 20000;
    QTest::mouseClick(&view, Qt::LeftButton, Qt::ControlModifier, pixel);
    QTRY_COMPARE_WITH_TIMEOUT(table->rowCount(), n + 1, kProbeTimeoutMs);
    QCOMPARE(m.camera().eye, eyeBefore);  // a probe, not an orbit
    const auto checkRows = [&](int held) {
      double share = 0.0;
      for (int i = 0; i < n; ++i) {
        const std::uint32_t id = list[static_cast<std::size_t>(i)].objectId;
        QCOMPARE(table->item(i, ProbePanel::Part)->text(), QString::fromStdString(m.scene().objects[id].name));
        QCOMPARE(table->item(i, ProbePanel::Held)->text(),
                 i < held ? QStringLiteral("held") : QStringLiteral("dropped"));
        if (i > 0)
          QVERIFY(table->item(i, ProbePanel::EyeDepth)->text().toDouble() >
                  table->item(i - 1, ProbePanel::EyeDepth)->text().toDouble());
        share += table->item(i, ProbePanel::Share)->text().remove(QStringLiteral(" %")).toDouble();
      }
      QCOMPARE(table->item(n, ProbePanel::Part)->text(), QStringLiteral("background"));
      share += table->item(n, ProbePanel::Share)->text().remove(QStringLiteral(" %")).toDouble();
      QVERIFY2(std::abs(share - 100.0) < 0.1 * (n + 1), qPrintable(QString::number(share)));
    };
    checkRows(2);
    QVERIFY2(summary->text().contains(QStringLiteral("kplus-array holds 2 of them")), qPrintable(summary->text()));
    QVERIFY(table->isColumnHidden(ProbePanel::HybridShare));  // "oit": no split to show
    // The shown colour is the method's image at the pixel (its `mfr render` path).
    const mfr::ImageRGBA8 image = view.renderImage(QSize(200, 150));
    const std::uint8_t* at = image.at(pixel.x(), pixel.y());
    const QString shown = QColor(at[0], at[1], at[2]).name();
    QVERIFY2(summary->text().contains(QStringLiteral("shown %1").arg(shown)),
             qPrintable(summary->text() + " / " + shown));
    auto* mark = w->findChild<QWidget*>("probeMarker");
    QVERIFY(mark && mark->isVisible());
    QCOMPARE(mark->geometry().center(), pixel);

    // The probe follows the method (after its next full frame), without another click.
    m.setMethod("abuffer-ll");
    QTRY_VERIFY2_WITH_TIMEOUT(summary->text().contains(QStringLiteral("abuffer-ll holds %1 of them").arg(n)),
                              qPrintable(summary->text()), kProbeTimeoutMs);
    checkRows(n);
    {  // An exact method: what the view shows there is its image, the exact colour up to edges.
      const mfr::ImageRGBA8 exactImage = view.renderImage(QSize(200, 150));
      const std::uint8_t* px = exactImage.at(pixel.x(), pixel.y());
      const std::uint8_t* mirrored = exactImage.at(pixel.x(), 149 - pixel.y());
      QVERIFY(std::memcmp(px, mirrored, 3) != 0);  // a read from the wrong row would show
      const QString shownExact = QColor(px[0], px[1], px[2]).name();
      QVERIFY2(summary->text().contains(QStringLiteral("shown %1").arg(shownExact)),
               qPrintable(summary->text() + " / " + shownExact));
    }
    // A budget method resolves with hybrid: its core and tail, each fragment's share of the colour it
    // draws (summing to 100 %), and that colour — the one the view shows, to 8-bit rounding.
    m.setMethod("dkb");
    m.setParams({{"budget_mib", "1.5"}});
    QTRY_VERIFY2_WITH_TIMEOUT(summary->text().contains(QStringLiteral("Hybrid colour")), qPrintable(summary->text()),
                              kProbeTimeoutMs);
    QVERIFY(!table->isColumnHidden(ProbePanel::HybridShare));
    {
      double share = 0.0;
      int core = 0;
      for (int i = 0; i <= n; ++i)
        share += table->item(i, ProbePanel::HybridShare)->text().remove(QStringLiteral(" %")).toDouble();
      for (int i = 0; i < n; ++i) {
        const QString role = table->item(i, ProbePanel::Held)->text();
        QVERIFY2(role == QStringLiteral("core") || role == QStringLiteral("tail"), qPrintable(role));
        core += role == QStringLiteral("core") ? 1 : 0;
      }
      QVERIFY2(std::abs(share - 100.0) < 0.1 * (n + 1), qPrintable(QString::number(share)));
      QVERIFY2(core >= 1 && core < n, qPrintable(QStringLiteral("core %1 of %2: ").arg(core).arg(n) + summary->text()));
      const QRegularExpression colours(QStringLiteral("shown (#[0-9a-f]{6}).*Hybrid colour (#[0-9a-f]{6})"));
      const QRegularExpressionMatch match = colours.match(summary->text());
      QVERIFY2(match.hasMatch(), qPrintable(summary->text()));
      const QColor drawn(match.captured(1)), hybrid(match.captured(2));
      QVERIFY2(std::abs(drawn.red() - hybrid.red()) <= 2 && std::abs(drawn.green() - hybrid.green()) <= 2 &&
                   std::abs(drawn.blue() - hybrid.blue()) <= 2,
               qPrintable(summary->text()));
    }

    // A method without lists: the exact list only.
    m.setMethod("wboit");
    QTRY_VERIFY2_WITH_TIMEOUT(summary->text().contains(QStringLiteral("wboit keeps no per-pixel lists")),
                              qPrintable(summary->text()), kProbeTimeoutMs);
    QCOMPARE(table->item(0, ProbePanel::Held)->text(), QStringLiteral("—"));

    // Empty space: only the background, all of the colour.
    QTest::mouseClick(&view, Qt::LeftButton, Qt::ControlModifier, QPoint(1, 1));
    QTRY_COMPARE_WITH_TIMEOUT(table->rowCount(), 1, kProbeTimeoutMs);
    QCOMPARE(oracle.count(1, 1), 0u);
    QCOMPARE(table->item(0, ProbePanel::Share)->text(), QStringLiteral("100.0 %"));

    // Every part hidden: no frame, and the probe says why (it kept the last frame's list).
    QTest::mouseClick(&view, Qt::LeftButton, Qt::ControlModifier, pixel);
    QTRY_COMPARE_WITH_TIMEOUT(table->rowCount(), n + 1, kProbeTimeoutMs);
    for (int i = 0; i < static_cast<int>(m.scene().objects.size()); ++i) m.setObjectVisible(i, false);
    QTRY_COMPARE_WITH_TIMEOUT(table->rowCount(), 0, kProbeTimeoutMs);
    QVERIFY2(summary->text().startsWith(QStringLiteral("Probe: scene 'sample': nothing to render")),
             qPrintable(summary->text()));
    for (int i = 0; i < static_cast<int>(m.scene().objects.size()); ++i) m.setObjectVisible(i, true);

    w->findChild<QPushButton*>("probeClear")->click();
    QCOMPARE(table->rowCount(), 0);
    QVERIFY(!mark->isVisible());
  }

  // The Clip dock: the switch and the sliders set the model's clip box (faces at the sliders'
  // fractions of the scene's bounds), the view then equals `mfr render --clip` of that box, a
  // session brings the box back, and switching it off draws the whole scene again.
  void clipBox() {
    QTemporaryDir dir;
    auto w = openWindow();
    QVERIFY(w);
    ViewerModel& m = w->model();
    w->view().setFixedSize(200, 150);
    QTRY_COMPARE_WITH_TIMEOUT(m.renderSize(), QSize(200, 150), kTimeoutMs);
    m.setMethod("abuffer-ll");
    m.setCamera(m.scene().view("iso"));
    settle(m);
    const mfr::ImageRGBA8 whole = w->view().renderImage(QSize(200, 150));
    auto* enabled = w->findChild<QCheckBox*>("clipEnabled");
    auto* minX = w->findChild<QSlider*>("clipMinX");
    auto* maxZ = w->findChild<QSlider*>("clipMaxZ");
    QVERIFY(enabled && minX && maxZ);
    QVERIFY(!m.clipBox());
    QVERIFY(!minX->isEnabled());
    enabled->setChecked(true);
    QVERIFY(m.clipBox().has_value());
    minX->setValue(400);
    maxZ->setValue(650);
    const mfr::Bounds b = m.scene().bounds();
    QVERIFY(m.clipBox().has_value());
    const mfr::Bounds box = *m.clipBox();
    QCOMPARE(box.min.x, b.min.x + (b.max.x - b.min.x) * 400 / 1000);
    QCOMPARE(box.max.z, b.min.z + (b.max.z - b.min.z) * 650 / 1000);
    QCOMPARE(box.min.y, b.min.y);
    QCOMPARE(box.max.x, b.max.x);
    // Dragging the lower face past the upper one pushes it along: never an inverted box.
    auto* minZ = w->findChild<QSlider*>("clipMinZ");
    minZ->setValue(700);
    QCOMPARE(maxZ->value(), 700);
    QVERIFY(m.clipBox()->min.z <= m.clipBox()->max.z);
    // Such a flat box holds nothing: the view says so, in mfr render's words (it drew an empty
    // frame without a word: a bug hunt).
    QTRY_VERIFY_WITH_TIMEOUT(!m.renderError().isEmpty(), kTimeoutMs);
    QVERIFY2(m.renderError().startsWith("clip box: holds nothing of scene 'sample' (a flat box"),
             qPrintable(m.renderError()));
    // The CPU methods say so too (the oracle drew an empty view: a review), and an export refuses.
    m.setMethod("oracle");
    QTRY_VERIFY_WITH_TIMEOUT(m.renderError().startsWith("clip box: holds nothing"), kTimeoutMs);
    QVERIFY_THROWS_EXCEPTION(mfr::Error, w->view().renderImage(QSize(40, 30)));
    m.setMethod("abuffer-ll");
    minZ->setValue(0);
    maxZ->setValue(650);
    settle(m);
    const mfr::ImageRGBA8 cut = w->view().renderImage(QSize(200, 150));
    QVERIFY(maxChannelDifference(cut, whole) > 50);
    // The same box through the command line: the same pixels.
    const mfr::Bounds c = *m.clipBox();
    const QString boxText =
        QString::asprintf("%.17g,%.17g,%.17g,%.17g,%.17g,%.17g", c.min.x, c.min.y, c.min.z, c.max.x, c.max.y, c.max.z);
    const QString cliPng = dir.filePath("cli.png");
    QString out;
    QCOMPARE(runProgram(MFR_CLI,
                        {"render", "@sample", "--size", "200x150", "--view", "iso", "-m", "abuffer-ll", "--clip",
                         boxText, "-o", cliPng},
                        &out),
             0);
    const int diff = maxChannelDifference(mfr::readPng(cliPng.toStdString()), cut);
    qInfo("clip box %s: viewer vs mfr render max channel difference %d", qPrintable(boxText), diff);
    QCOMPARE(diff, 0);

    // Sessions keep the box.
    const QString sessionPath = dir.filePath("clip.mfrsession");
    writeSessionFile(sessionPath, captureSession(m));
    enabled->setChecked(false);
    QVERIFY(!m.clipBox());
    QVERIFY(!minX->isEnabled());
    settle(m);
    QCOMPARE(maxChannelDifference(w->view().renderImage(QSize(200, 150)), whole), 0);
    applySession(readSessionFile(sessionPath), m);
    QVERIFY(m.clipBox().has_value());
    QCOMPARE(m.clipBox()->min.x, c.min.x);
    QCOMPARE(m.clipBox()->max.z, c.max.z);
    QVERIFY(enabled->isChecked());
    QCOMPARE(minX->value(), 400);
    settle(m);
    QCOMPARE(maxChannelDifference(w->view().renderImage(QSize(200, 150)), cut), 0);
  }

  // A scene's function that is a preset over its range (written out point by point here, as an
  // InVesalius project's "bone" over its window arrives) shows as that preset with that window;
  // the blob's own two-point function stays Custom.
  // Two volumes drawn at once: the blob and a moved copy with another function. The Volume panel
  // offers a chooser; the controls edit the chosen volume only; hiding one keeps the other drawn
  // with the operation volume; the frame is the renderers' mixture; a session keeps the choice.
  void severalVolumes() {
    QTemporaryDir dir;
    const QString onePath = writeBlobScene(dir, "one.mfrscene", blobTransfer());
    QVERIFY(!onePath.isEmpty());
    QJsonObject json = [&] {
      QFile f(onePath);
      f.open(QIODevice::ReadOnly);
      return QJsonDocument::fromJson(f.readAll()).object();
    }();
    QJsonArray volumes = json["volumes"].toArray();
    QJsonObject second = volumes[0].toObject();
    second["name"] = "moved";
    second["transform"] = QJsonObject{{"translate", QJsonArray{0.8, 0.3, 0.0}}};
    second["transfer"] = QJsonObject{{"preset", "fire"}, {"range", QJsonArray{0.0, 1.0}}, {"unit_distance", 0.3}};
    volumes.append(second);
    json["volumes"] = volumes;
    const QString path = dir.filePath("two.mfrscene");
    {
      QFile f(path);
      QVERIFY(f.open(QIODevice::WriteOnly));
      f.write(QJsonDocument(json).toJson());
    }
    auto w = openWindow(path);
    QVERIFY(w);
    ViewerModel& m = w->model();
    const QSize size(160, 120);
    QVERIFY(showAbufferIso(*w, size));
    auto* choice = w->findChild<QComboBox*>("hvVolume");
    auto* show = w->findChild<QCheckBox*>("hvShow");
    auto* preset = w->findChild<QComboBox*>("hvPreset");
    auto* info = w->findChild<QLabel*>("hvInfo");
    QVERIFY(choice && show && preset && info);
    QVERIFY(choice->isVisibleTo(w.get()));
    QCOMPARE(choice->count(), 2);
    QCOMPARE(choice->itemText(1), QStringLiteral("moved"));
    QCOMPARE(m.volumeCount(), 2);
    QCOMPARE(m.visibleVolumeCount(), 2);
    QCOMPARE(m.currentVolume(), 0);
    QCOMPARE(QString::fromStdString(m.stats().operation), QStringLiteral("volume"));
    const auto note = [&m](const char* key) -> std::string {
      for (const auto& [name, value] : m.stats().notes)
        if (name == key) return value;
      return {};
    };
    QCOMPARE(note("volumes"), std::string("2"));
    // The frame, checked at the end against the library (mfr::render's headless context is made
    // current on this thread, so it comes after the windows' last frames).
    const mfr::ImageRGBA8 both = w->view().renderImage(size);
    const mfr::RenderRequest request = m.renderRequest(size);
    const mfr::Scene bothScene = m.scene();
    const mfr::Camera camera = m.camera();

    // Choosing the second volume: the panel shows and edits it; the first keeps its function.
    const mfr::TransferFunction firstBefore = m.scene().volumes[0].transfer;
    choice->setCurrentIndex(1);
    QCOMPARE(m.currentVolume(), 1);
    QCOMPARE(m.volumeName(), QStringLiteral("moved"));
    QVERIFY2(info->text().startsWith(QStringLiteral("moved:")), qPrintable(info->text()));
    QCOMPARE(preset->currentData().toString(), QStringLiteral("fire"));
    preset->setCurrentIndex(preset->findData(QStringLiteral("cool-warm")));
    settle(m);
    QCOMPARE(m.scene().volumes[0].transfer.points.size(), firstBefore.points.size());
    for (std::size_t i = 0; i < firstBefore.points.size(); ++i)
      QVERIFY(m.scene().volumes[0].transfer.points[i].color == firstBefore.points[i].color);
    QVERIFY(!(m.scene().volumes[1].transfer.points.front().color ==
              mfr::transferPreset("fire", 0.0, 1.0, 0.3).points.front().color));
    // Its opacity scale is its own: the first volume and back finds the preset and scale as they
    // were, and the same scale gives the same function (the scaled function became the base at 1×
    // and the scale compounded: 400× at the slider's end; a bug hunt).
    auto* opacity = w->findChild<QSlider*>("hvOpacity");
    QVERIFY(opacity);
    opacity->setValue(opacity->maximum());
    const double scaledUnit = m.scene().volumes[1].transfer.unitDistance;
    QVERIFY(std::abs(scaledUnit - 0.3 / 20.0) < 1e-9);
    choice->setCurrentIndex(0);
    QCOMPARE(m.currentVolume(), 0);
    choice->setCurrentIndex(1);
    QCOMPARE(opacity->value(), opacity->maximum());
    QCOMPARE(preset->currentData().toString(), QStringLiteral("cool-warm"));
    opacity->setValue(opacity->maximum() - 10);
    opacity->setValue(opacity->maximum());
    QCOMPARE(m.scene().volumes[1].transfer.unitDistance, scaledUnit);
    opacity->setValue(opacity->minimum() + (opacity->maximum() - opacity->minimum()) / 2);  // 1×
    QVERIFY(std::abs(m.scene().volumes[1].transfer.unitDistance - 0.3) < 1e-9);
    // Hiding it leaves the first drawn, still by the operation volume.
    show->setChecked(false);
    QVERIFY(!m.scene().volumes[1].visible);
    QVERIFY(m.scene().volumes[0].visible);
    QCOMPARE(m.effectiveOperation(), QStringLiteral("volume"));
    settle(m);
    QCOMPARE(note("volumes"), std::string("1"));
    show->setChecked(true);
    settle(m);
    QCOMPARE(note("volumes"), std::string("2"));

    // A session keeps the chosen volume and both functions.
    const mfr::ImageRGBA8 before = w->view().renderImage(size);
    const QString sessionPath = dir.filePath("two.mfrsession");
    auto again = reopenedSession(*w, sessionPath, size);
    QVERIFY(again);
    ViewerModel& a = again->model();
    QTRY_VERIFY_WITH_TIMEOUT(a.hasScene() && a.framesRendered() > 0, kTimeoutMs);
    settle(a);
    QCOMPARE(a.currentVolume(), 1);
    QCOMPARE(again->findChild<QComboBox*>("hvVolume")->currentIndex(), 1);
    QCOMPARE(again->findChild<QComboBox*>("hvPreset")->currentData().toString(), QStringLiteral("cool-warm"));
    QCOMPARE(maxChannelDifference(before, again->view().renderImage(a.renderSize())), 0);
    // The mixture the library draws (the same request through mfr::render), unlike the first
    // volume alone.
    QCOMPARE(maxChannelDifference(mfr::render(bothScene, camera, request).image, both), 0);
    mfr::Scene firstOnly = bothScene;
    firstOnly.volumes[1].visible = false;
    QVERIFY(maxChannelDifference(mfr::render(firstOnly, camera, request).image, both) > 40);
  }

  // A volume file with two arrays, in a scene that moves it: the Volume panel's Field reads the
  // other array in the background, in the same place (the frame equals mfr render of a scene file
  // naming that field, run as a separate program); the scene tree names it; a field the file lacks
  // leaves the volume as it was with the reason shown; a session brings the field and its
  // transfer function back.
  void volumeField() {
    QTemporaryDir dir;
    QVERIFY(writeTwoArrayVti(
        dir.filePath("two.vti"), QStringLiteral("ramp"), [](int i, int, int) { return i; }, QStringLiteral("ring"),
        [](int i, int j, int k) {
          const double r = std::hypot(i - 5.5, j - 5.5, k - 5.5);
          return std::exp(-(r - 4.0) * (r - 4.0));
        }));
    const auto writeScene = [&](const QString& name, const QString& field) {
      QJsonObject volume{{"file", "two.vti"}, {"transform", QJsonObject{{"translate", QJsonArray{0.4, -0.2, 0.1}}}}};
      if (!field.isEmpty()) volume["field"] = field;
      const QJsonObject ball{{"primitive", QJsonObject{{"type", "sphere"}, {"radius", 0.3}}},
                             {"color", QJsonArray{0.2, 0.4, 0.9}},
                             {"opacity", 0.5}};
      const QJsonObject iso{{"name", "iso"}, {"eye", QJsonArray{3.0, 2.0, 4.0}}, {"fit", true}};
      QFile f(dir.filePath(name));
      if (!f.open(QIODevice::WriteOnly)) return QString();
      f.write(
          QJsonDocument(
              QJsonObject{{"objects", QJsonArray{ball}}, {"volumes", QJsonArray{volume}}, {"views", QJsonArray{iso}}})
              .toJson());
      return dir.filePath(name);
    };
    const QString path = writeScene("ramp.mfrscene", QString());
    const QString ringPath = writeScene("ring.mfrscene", QStringLiteral("ring"));
    QVERIFY(!path.isEmpty() && !ringPath.isEmpty());
    auto w = openWindow(path);
    QVERIFY(w);
    ViewerModel& m = w->model();
    const QSize size(160, 120);
    QVERIFY(showAbufferIso(*w, size));
    auto* field = w->findChild<QComboBox*>("hvField");
    auto* fieldNote = w->findChild<QLabel*>("hvFieldNote");
    auto* info = w->findChild<QLabel*>("hvInfo");
    QVERIFY(field && fieldNote && info);
    QVERIFY(field->isVisibleTo(w.get()));
    QCOMPARE(field->count(), 2);
    QCOMPARE(field->currentText(), QStringLiteral("ramp"));
    QCOMPARE(m.volumeFields(), (QStringList{"ramp", "ring"}));
    QVERIFY2(info->text().contains(QStringLiteral("field ramp (of ramp, ring)")), qPrintable(info->text()));
    const mfr::ImageRGBA8 rampFrame = w->view().renderImage(size);
    const mfr::Bounds before = m.volumeBounds();

    emit field->activated(1);  // as a user's choice
    QVERIFY(m.volumeFieldLoading());
    QTRY_VERIFY_WITH_TIMEOUT(!m.volumeFieldLoading(), kTimeoutMs);
    QVERIFY2(m.volumeFieldError().isEmpty(), qPrintable(m.volumeFieldError()));
    QCOMPARE(m.volumeField(), QStringLiteral("ring"));
    QCOMPARE(field->currentText(), QStringLiteral("ring"));
    QVERIFY(!fieldNote->isVisibleTo(w.get()));
    QVERIFY(m.volumeValueRange().y < 1.01 && m.volumeValueRange().y > 0.9);  // ring: exp(-d²) peaks at 1
    QCOMPARE(m.volumeBounds().min, before.min);                              // the scene's translation kept
    QCOMPARE(m.volumeBounds().max, before.max);
    auto* tree = w->findChild<QTreeWidget*>("sceneTree");
    QVERIFY(tree);
    QVERIFY(!tree->findItems(QStringLiteral("two.vti [ring] (volume)"), Qt::MatchExactly).isEmpty());
    settle(m);
    const mfr::ImageRGBA8 ringFrame = w->view().renderImage(size);
    QVERIFY(maxChannelDifference(ringFrame, rampFrame) > 40);
    const QString cliPng = dir.filePath("cli.png");
    QString out;
    QCOMPARE(
        runProgram(MFR_CLI,
                   {"render", ringPath, "--size", "160x120", "--view", "iso", "-m", "abuffer-ll", "-o", cliPng}, &out),
        0);
    QCOMPARE(maxChannelDifference(mfr::readPng(cliPng.toStdString()), ringFrame), 0);

    // A field the file lacks: the reason, and the volume as it was.
    m.setVolumeField(QStringLiteral("rings"));
    QTRY_VERIFY_WITH_TIMEOUT(!m.volumeFieldLoading(), kTimeoutMs);
    QVERIFY2(
        m.volumeFieldError().contains(QStringLiteral("no point-data or cell-data array 'rings' (arrays: ramp, ring)")),
        qPrintable(m.volumeFieldError()));
    QVERIFY(fieldNote->isVisibleTo(w.get()));
    QCOMPARE(fieldNote->text(), m.volumeFieldError());
    QCOMPARE(m.volumeField(), QStringLiteral("ring"));
    settle(m);
    QCOMPARE(maxChannelDifference(w->view().renderImage(size), ringFrame), 0);

    // A session: the field and the function edited after it was read.
    auto* preset = w->findChild<QComboBox*>("hvPreset");
    QVERIFY(preset);
    preset->setCurrentIndex(preset->findData(QStringLiteral("fire")));
    settle(m);
    const mfr::ImageRGBA8 fire = w->view().renderImage(size);
    QVERIFY(maxChannelDifference(fire, ringFrame) > 20);
    const QString sessionPath = dir.filePath("field.mfrsession");
    auto again = reopenedSession(*w, sessionPath, size);
    QVERIFY(again);
    ViewerModel& a = again->model();
    QTRY_VERIFY_WITH_TIMEOUT(a.hasScene() && a.volumeField() == QStringLiteral("ring") && !a.volumeFieldLoading(),
                             kTimeoutMs);
    settle(a);
    QCOMPARE(again->findChild<QComboBox*>("hvField")->currentText(), QStringLiteral("ring"));
    QCOMPARE(maxChannelDifference(fire, again->view().renderImage(a.renderSize())), 0);

    // mfrview --field opens a volume file's other array: the pixels of mfr render --field.
    const QString vti = dir.filePath("two.vti"), viewerPng = dir.filePath("viewer.png");
    const QStringList common{"--size", "96x72", "--view", "iso", "-m", "abuffer-ll"};
    QCOMPARE(runProgram(MFRVIEW, QStringList{vti, "--field", "ring", "--screenshot", viewerPng} + common, &out), 0);
    QCOMPARE(runProgram(MFR_CLI, QStringList{"render", vti, "--field", "ring", "-o", cliPng} + common, &out), 0);
    QCOMPARE(maxChannelDifference(mfr::readPng(viewerPng.toStdString()), mfr::readPng(cliPng.toStdString())), 0);
    QVERIFY(runProgram(MFRVIEW, QStringList{vti, "--field", "rings", "--screenshot", viewerPng} + common, &out) != 0);
    const QString last = out.trimmed().split(QLatin1Char('\n')).last();  // after any Qt platform chatter
    QVERIFY2(last.startsWith(QStringLiteral("mfrview: ") + vti) &&
                 last.contains(QStringLiteral("no point-data or cell-data array 'rings' (arrays: ramp, ring)")),
             qPrintable(out));

    // Isosurfaces follow a field read in the volume's place: made again from the new samples (each
    // vertex samples to the value in the new grid), values outside the new range dropped.
    const std::size_t parts = m.scene().objects.size();
    const auto isoValuesInVolume = [&] {  // the volume's samples at the isosurface's vertices
      std::vector<float> values;
      const mfr::Object& o = m.scene().objects.at(parts);
      const mfr::Volume& v = m.scene().volumes.at(0);
      const glm::dmat4 toGrid = glm::inverse(v.gridToWorld()) * o.transform;
      for (const glm::vec3& p : o.mesh->positions)
        values.push_back(v.grid->sample(glm::vec3(toGrid * glm::dvec4(glm::dvec3(p), 1.0))));
      return values;
    };
    QVERIFY(m.setIsosurfaces({0.5}, 0.4).isEmpty());  // on ring
    QCOMPARE(m.scene().objects.size(), parts + 1);
    m.setVolumeField(QStringLiteral("ramp"));
    QTRY_VERIFY_WITH_TIMEOUT(!m.volumeFieldLoading() && m.volumeField() == QStringLiteral("ramp"), kTimeoutMs);
    QCOMPARE(m.isosurfaceValues(), std::vector<double>{0.5});
    QCOMPARE(m.scene().objects.size(), parts + 1);
    for (const float v : isoValuesInVolume()) QVERIFY2(std::abs(v - 0.5f) < 1e-4f, qPrintable(QString::number(v)));
    QVERIFY(m.setIsosurfaces({0.5, 5.0}, 0.4).isEmpty());  // 5: inside ramp's 0 … 11 only
    QCOMPARE(m.scene().objects.size(), parts + 2);
    m.setVolumeField(QStringLiteral("ring"));
    QTRY_VERIFY_WITH_TIMEOUT(!m.volumeFieldLoading() && m.volumeField() == QStringLiteral("ring"), kTimeoutMs);
    QCOMPARE(m.isosurfaceValues(), std::vector<double>{0.5});
    QCOMPARE(m.scene().objects.size(), parts + 1);
    for (const float v : isoValuesInVolume()) QVERIFY2(std::abs(v - 0.5f) < 1e-4f, qPrintable(QString::number(v)));
  }

  void ghostingFollowsIsosurfaces() {
    // The Ghosting panel while isosurfaces come and go: the scene's own parts keep their focus and
    // ghosting, new isosurfaces are ghosted too, an isosurface in focus stays so while others are
    // removed, and ghosting off gives every part its own opacity; another scene starts unghosted.
    auto w = openWindow(QStringLiteral("@volume"));
    QVERIFY(w);
    ViewerModel& m = w->model();
    auto* parts = w->findChild<QListWidget*>("ghostParts");
    auto* ghost = w->findChild<QCheckBox*>("ghostOthers");
    QVERIFY(parts && ghost);
    const int loaded = static_cast<int>(m.objectNames().size());
    QVERIFY2(loaded >= 2, "needs a part in focus and a ghosted one");
    std::vector<double> own;
    for (int i = 0; i < loaded; ++i) own.push_back(m.objectOpacity(i));
    const auto opacityIs = [&m](int id, double value) { return std::abs(m.objectOpacity(id) - value) < 1e-6; };
    parts->item(0)->setCheckState(Qt::Checked);
    ghost->setChecked(true);
    QVERIFY(opacityIs(0, own[0]) && opacityIs(1, 0.15));

    QVERIFY(m.setIsosurfaces({0.3, 0.6}, 0.25).isEmpty());
    QCOMPARE(parts->count(), loaded + 2);
    QVERIFY(ghost->isChecked());
    QCOMPARE(parts->item(0)->checkState(), Qt::Checked);
    QVERIFY(opacityIs(0, own[0]));
    for (int id = 1; id < loaded + 2; ++id) QVERIFY2(opacityIs(id, 0.15), qPrintable(parts->item(id)->text()));
    // "field = 0.6" into focus: its own 0.25; removing "field = 0.3" keeps it so.
    QCOMPARE(parts->item(loaded + 1)->text(), QStringLiteral("field = 0.6"));
    parts->item(loaded + 1)->setCheckState(Qt::Checked);
    QVERIFY(opacityIs(loaded + 1, 0.25));
    QVERIFY(m.setIsosurfaces({0.6}, 0.25).isEmpty());
    QCOMPARE(parts->count(), loaded + 1);
    QCOMPARE(parts->item(loaded)->text(), QStringLiteral("field = 0.6"));
    QCOMPARE(parts->item(loaded)->checkState(), Qt::Checked);
    QVERIFY(opacityIs(loaded, 0.25) && opacityIs(1, 0.15) && ghost->isChecked());
    // Ghosting off: each part's own opacity, the loaded ones and the isosurface's.
    ghost->setChecked(false);
    for (int id = 0; id < loaded; ++id) QVERIFY(opacityIs(id, own[static_cast<std::size_t>(id)]));
    QVERIFY(opacityIs(loaded, 0.25));

    // Another scene: nothing in focus, nothing ghosted.
    ghost->setChecked(true);
    w->openScene(QStringLiteral("@intersect"));
    QTRY_VERIFY_WITH_TIMEOUT(!m.isLoading() && m.scenePath() == QStringLiteral("@intersect"), kTimeoutMs);
    QVERIFY(!ghost->isChecked());
    QCOMPARE(parts->count(), static_cast<int>(m.objectNames().size()));
    for (int id = 0; id < parts->count(); ++id) QCOMPARE(parts->item(id)->checkState(), Qt::Unchecked);
  }

  // A scene file's own colourings by a field, another map per part, stay theirs when isosurfaces
  // are added (the first part's was laid on every part and on the isosurfaces) and when a session
  // is saved and reopened (the first part's came back on every part): the pixels of mfr render
  // (hunt 32).
  void sceneFileColouringsStayTheirs() {
    QTemporaryDir dir;
    QVERIFY(writeTwoArrayVti(
        dir.filePath("v.vti"), "a", [](int i, int j, int k) { return i + j + k; }, "b",
        [](int i, int, int) { return i; }));
    const QString scene = dir.filePath("s.mfrscene");
    {
      QFile f(scene);
      QVERIFY(f.open(QIODevice::WriteOnly));
      f.write(R"({"objects": [
        {"name": "p", "primitive": {"type": "sphere", "radius": 0.25}, "transform": {"translate": [0.3, 0.55, 0.55]},
         "color_by": {"field": "@v", "map": "viridis", "range": [0, 33]}, "opacity": 0.6},
        {"name": "q", "primitive": {"type": "sphere", "radius": 0.25}, "transform": {"translate": [0.8, 0.55, 0.55]},
         "color_by": {"field": "@v", "map": "magma", "range": [0, 33]}, "opacity": 0.6}],
       "volumes": [{"name": "v", "file": "v.vti", "visible": false}]})");
    }
    const QStringList common{"--size", "96x72", "--view", "iso", "-m", "abuffer-ll"};
    const QString cli = dir.filePath("cli.png"), viewer = dir.filePath("viewer.png"), plain = dir.filePath("plain.png");
    QString out;
    QCOMPARE(runProgram(MFR_CLI, QStringList{"render", scene, "--contour", "16.5", "-o", cli} + common, &out), 0);
    QCOMPARE(runProgram(MFRVIEW, QStringList{scene, "--contour", "16.5", "--screenshot", viewer} + common, &out), 0);
    QCOMPARE(maxChannelDifference(mfr::readPng(cli.toStdString()), mfr::readPng(viewer.toStdString())), 0);
    QCOMPARE(runProgram(MFR_CLI, QStringList{"render", scene, "-o", plain} + common, &out), 0);
    const mfr::ImageRGBA8 expected = mfr::readPng(plain.toStdString());
    QVERIFY(maxChannelDifference(expected, mfr::readPng(cli.toStdString())) > 20);  // the isosurface shows
    auto w = openWindow(scene);
    QVERIFY(w);
    const QSize size(96, 72);
    QVERIFY(showAbufferIso(*w, size));
    QCOMPARE(maxChannelDifference(expected, w->view().renderImage(size)), 0);
    auto again = reopenedSession(*w, dir.filePath("s.mfrsession"), size);
    QVERIFY(again);
    ViewerModel& a = again->model();
    QTRY_VERIFY_WITH_TIMEOUT(a.hasScene() && a.scene().objects.size() == 2, kTimeoutMs);
    settle(a);
    QCOMPARE(maxChannelDifference(expected, again->view().renderImage(size)), 0);
    QVERIFY(a.scene().objects[1].material.fieldColors && a.scene().objects[1].material.fieldColors->map == "magma");
  }

  // A colour chosen for one part over a colouring by a field stays through what else recolours by
  // that field — the Data Range button on the range there is, isosurfaces added, a session saved
  // and reopened — and Reset Colour brings the field's colours back (hunt 33: each of the first
  // three laid the colouring on every part again, the chosen colour lost, and Reset left the part
  // in its file's plain colour).
  void chosenColoursOverAFieldColouring() {
    QTemporaryDir dir;
    auto w = openWindow(QStringLiteral("@volume"));
    QVERIFY(w);
    ViewerModel& m = w->model();
    const QSize size(96, 72);
    QVERIFY(showAbufferIso(*w, size));
    int sphere = -1;
    for (std::size_t i = 0; i < m.scene().objects.size(); ++i)
      if (m.scene().objects[i].name == "sphere") sphere = static_cast<int>(i);
    QVERIFY(sphere >= 0);
    const auto part = [&](int i) -> const mfr::Object& { return m.scene().objects[static_cast<std::size_t>(i)]; };
    auto* colorBy = w->findChild<QComboBox*>("colorByField");
    auto* map = w->findChild<QComboBox*>("colorByMap");
    auto* dataRange = w->findChild<QPushButton*>("colorRangeReset");
    QVERIFY(colorBy && map && dataRange);
    const int at = colorBy->findData(QStringLiteral("@field"));
    QVERIFY(at > 0);
    colorBy->setCurrentIndex(at);
    emit colorBy->activated(at);  // as a user's choice
    settle(m);
    QVERIFY(part(sphere).material.fieldColors && part(sphere).material.fieldColors->field == "@field");
    const mfr::FieldColors colouring = *part(sphere).material.fieldColors;
    m.setObjectColor(sphere, QColor(255, 0, 0));
    QVERIFY(!part(sphere).material.fieldColors);
    const glm::vec4 red = part(sphere).material.color;
    // Data Range over the range there is: nothing changes.
    QTest::mouseClick(dataRange, Qt::LeftButton);
    settle(m);
    QVERIFY(!part(sphere).material.fieldColors);
    QCOMPARE(part(sphere).material.color, red);
    // Isosurfaces added: the new part takes the colouring, the sphere keeps its colour.
    const std::size_t before = m.scene().objects.size();
    QCOMPARE(m.setIsosurfaces({0.3}, 0.5), QString());
    settle(m);
    QCOMPARE(m.scene().objects.size(), before + 1);
    QVERIFY(!part(sphere).material.fieldColors);
    QCOMPARE(part(sphere).material.color, red);
    QVERIFY(m.scene().objects.back().material.fieldColors == colouring);
    const mfr::ImageRGBA8 frame = w->view().renderImage(size);
    // A session brings the same back.
    auto again = reopenedSession(*w, dir.filePath("chosen.mfrsession"), size);
    QVERIFY(again);
    ViewerModel& a = again->model();
    QTRY_VERIFY_WITH_TIMEOUT(a.hasScene() && a.scene().objects.size() == before + 1, kTimeoutMs);
    settle(a);
    QVERIFY(!a.scene().objects[static_cast<std::size_t>(sphere)].material.fieldColors);
    QVERIFY(a.scene().objects.back().material.fieldColors == colouring);
    QCOMPARE(maxChannelDifference(frame, again->view().renderImage(size)), 0);
    again.reset();
    // Reset Colour to the File's: the field's colours again.
    m.resetObjectColors({sphere});
    settle(m);
    QVERIFY(part(sphere).material.fieldColors == colouring);
  }

  void isosurfaces() {
    // The Volume panel's Isosurfaces: parts "field = V" in the scene tree, the volume hidden, the
    // pixels of mfr render --contour; refusals leave the scene as it was; sessions keep them.
    QTemporaryDir dir;
    auto w = openWindow(QStringLiteral("@volume"));
    QVERIFY(w);
    ViewerModel& m = w->model();
    const QSize size(160, 120);
    QVERIFY(showAbufferIso(*w, size));
    const std::size_t loaded = m.scene().objects.size();
    auto* values = w->findChild<QLineEdit*>("hvIsoValues");
    auto* opacity = w->findChild<QDoubleSpinBox*>("hvIsoOpacity");
    auto* apply = w->findChild<QPushButton*>("hvIsoApply");
    auto* note = w->findChild<QLabel*>("hvIsoNote");
    auto* show = w->findChild<QCheckBox*>("hvShow");
    auto* tree = w->findChild<QTreeWidget*>("sceneTree");
    QVERIFY(values && opacity && apply && note && show && tree);
    QVERIFY(m.volumeVisible());
    const mfr::ImageRGBA8 volumeFrame = w->view().renderImage(size);

    values->setText(QStringLiteral("0.3, 0.6"));
    opacity->setValue(0.25);
    QTest::mouseClick(apply, Qt::LeftButton);
    QCOMPARE(m.scene().objects.size(), loaded + 2);
    QCOMPARE(QString::fromStdString(m.scene().objects[loaded].name), QStringLiteral("field = 0.3"));
    QCOMPARE(QString::fromStdString(m.scene().objects[loaded + 1].name), QStringLiteral("field = 0.6"));
    QCOMPARE(m.isosurfaceValues(), (std::vector<double>{0.3, 0.6}));
    const QList<QTreeWidgetItem*> rows = tree->findItems(QStringLiteral("field = 0.6"), Qt::MatchExactly);
    QCOMPARE(rows.size(), 1);
    // The Triangles cell's tooltip measures the part as mfr info does (area, closed, volume).
    const QString measured = rows[0]->data(3, Qt::ToolTipRole).toString();
    QVERIFY2(measured.startsWith(QStringLiteral("area ")) && measured.contains(QStringLiteral(", closed, volume ")),
             qPrintable(measured));
    QVERIFY(!m.volumeVisible());
    QVERIFY(!show->isChecked());
    QVERIFY2(note->text().contains(QStringLiteral("2 isosurfaces")), qPrintable(note->text()));
    settle(m);
    QVERIFY2(m.renderError().isEmpty(), qPrintable(m.renderError()));
    const mfr::ImageRGBA8 isoFrame = w->view().renderImage(size);
    QVERIFY(maxChannelDifference(isoFrame, volumeFrame) > 20);
    // The view's legend: the isosurfaces' map, ticked at their values (what Export Image draws).
    auto* legend = w->findChild<MapLegend*>("mapLegendA");
    QVERIFY(legend);
    QTRY_VERIFY_WITH_TIMEOUT(legend->isVisible(), kTimeoutMs);
    QCOMPARE(legend->title(), QStringLiteral("field"));
    QCOMPARE(legend->mapName(), QStringLiteral("cool-warm"));
    QCOMPARE(legend->ticks(), (std::vector<double>{0.3, 0.6}));
    QVERIFY2(legend->text().contains(QStringLiteral("0.3, 0.6")), qPrintable(legend->text()));
    QVERIFY(m.colorLegend() && m.colorLegend()->colors.range == glm::dvec2(0.3, 0.6));
    const QString cliPng = dir.filePath("cli.png");
    QString out;
    QCOMPARE(runProgram(MFR_CLI,
                        {"render", "@volume", "--contour", "0.3,0.6", "--contour-opacity", "0.25", "--size", "160x120",
                         "--view", "iso", "-m", "abuffer-ll", "-o", cliPng},
                        &out),
             0);
    QCOMPARE(maxChannelDifference(mfr::readPng(cliPng.toStdString()), isoFrame), 0);
    QCOMPARE(runProgram(MFR_CLI, {"info", "@volume", "--no-histogram", "--contour", "0.3,0.6"}, &out), 0);
    QVERIFY2(out.contains(QStringLiteral("    ") + measured + QStringLiteral("\n")), qPrintable(out + measured));

    // Refused: a value outside the volume's range, a word; the isosurfaces stay as they were.
    values->setText(QStringLiteral("0.3, 5"));
    QTest::mouseClick(apply, Qt::LeftButton);
    QVERIFY2(note->text().contains(QStringLiteral("5 lies outside the open range")), qPrintable(note->text()));
    QCOMPARE(values->text(), QStringLiteral("0.3, 5"));  // the user's text stays, to be mended
    values->setText(QStringLiteral("0.3 abc"));
    QTest::mouseClick(apply, Qt::LeftButton);
    QCOMPARE(note->text(), QStringLiteral("'abc' is not a number"));
    QCOMPARE(m.scene().objects.size(), loaded + 2);
    QCOMPARE(m.isosurfaceValues(), (std::vector<double>{0.3, 0.6}));

    // A session brings them back, with their pixels.
    const QString sessionPath = dir.filePath("iso.mfrsession");
    auto again = reopenedSession(*w, sessionPath, size);
    QVERIFY(again);
    ViewerModel& a = again->model();
    QTRY_VERIFY_WITH_TIMEOUT(a.hasScene() && a.scene().objects.size() == loaded + 2, kTimeoutMs);
    settle(a);
    QCOMPARE(a.isosurfaceValues(), (std::vector<double>{0.3, 0.6}));
    QCOMPARE(a.isosurfaceOpacity(), 0.25);
    QCOMPARE(maxChannelDifference(isoFrame, again->view().renderImage(a.renderSize())), 0);
    again.reset();

    // Parts made again unchanged keep what the scene tree did to them; a new one has the set's look.
    const auto partIndex = [&](const char* name) {
      for (std::size_t i = 0; i < m.scene().objects.size(); ++i)
        if (m.scene().objects[i].name == name) return static_cast<int>(i);
      return -1;
    };
    m.setObjectColor(partIndex("field = 0.3"), QColor(0, 255, 0));
    m.setObjectVisible(partIndex("field = 0.6"), false);
    const glm::vec4 green = m.scene().objects[static_cast<std::size_t>(partIndex("field = 0.3"))].material.color;
    values->setText(QStringLiteral("0.3, 0.45, 0.6"));  // the same colour range: 0.3 and 0.6 unchanged
    QTest::mouseClick(apply, Qt::LeftButton);
    QCOMPARE(m.scene().objects.size(), loaded + 3);
    QCOMPARE(m.scene().objects[static_cast<std::size_t>(partIndex("field = 0.3"))].material.color, green);
    QVERIFY(!m.scene().objects[static_cast<std::size_t>(partIndex("field = 0.6"))].visible);
    QVERIFY(m.scene().objects[static_cast<std::size_t>(partIndex("field = 0.45"))].visible);
    values->setText(QStringLiteral("0.3, 0.9"));  // another range: 0.3 made again as it was, 0.9 new
    QTest::mouseClick(apply, Qt::LeftButton);
    QCOMPARE(m.scene().objects.size(), loaded + 2);
    QCOMPARE(m.scene().objects[static_cast<std::size_t>(partIndex("field = 0.3"))].material.color, green);
    opacity->setValue(0.5);  // another opacity: every part made anew, edits gone
    QTest::mouseClick(apply, Qt::LeftButton);
    QVERIFY(m.scene().objects[static_cast<std::size_t>(partIndex("field = 0.3"))].material.color != green);

    // Empty: none again; Show volume draws the volume as before.
    values->clear();
    QTest::mouseClick(apply, Qt::LeftButton);
    QCOMPARE(m.scene().objects.size(), loaded);
    QVERIFY(tree->findItems(QStringLiteral("field = 0.6"), Qt::MatchExactly).isEmpty());
    show->setChecked(true);
    settle(m);
    QVERIFY(!m.colorLegend());
    QTRY_VERIFY_WITH_TIMEOUT(!legend->isVisible(), kTimeoutMs);
    QCOMPARE(maxChannelDifference(w->view().renderImage(size), volumeFrame), 0);

    // mfrview --contour: the pixels of mfr render --contour (opacity 0.5 in both).
    const QString viewerPng = dir.filePath("viewer.png");
    const QStringList common{"--size", "96x72", "--view", "iso", "-m", "abuffer-ll"};
    QCOMPARE(runProgram(MFRVIEW, QStringList{"@volume", "--contour", "0.45", "--screenshot", viewerPng} + common, &out),
             0);
    QCOMPARE(runProgram(MFR_CLI, QStringList{"render", "@volume", "--contour", "0.45", "-o", cliPng} + common, &out),
             0);
    QCOMPARE(maxChannelDifference(mfr::readPng(viewerPng.toStdString()), mfr::readPng(cliPng.toStdString())), 0);
    // Without --view both frame what is drawn, the isosurface (mfrview framed the hidden volume's
    // box: a bug hunt).
    {
      // A volume alone, a peak at its centre: the isosurface is far smaller than the box.
      const QString peak = dir.filePath("peak.vtk");
      QFile file(peak);
      QVERIFY(file.open(QIODevice::WriteOnly));
      file.write(
          "# vtk DataFile Version 3.0\npeak\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 3 3 3\n"
          "ORIGIN -1 -1 -1\nSPACING 1 1 1\nPOINT_DATA 27\nSCALARS v float 1\nLOOKUP_TABLE default\n"
          "0 0 0 0 0 0 0 0 0  0 0 0 0 1 0 0 0 0  0 0 0 0 0 0 0 0 0\n");
      file.close();
      const QStringList fit{"--size", "96x72", "-m", "abuffer-ll", "--contour", "0.5"};
      QCOMPARE(runProgram(MFRVIEW, QStringList{peak, "--screenshot", viewerPng} + fit, &out), 0);
      QCOMPARE(runProgram(MFR_CLI, QStringList{"render", peak, "-o", cliPng} + fit, &out), 0);
      QCOMPARE(maxChannelDifference(mfr::readPng(viewerPng.toStdString()), mfr::readPng(cliPng.toStdString())), 0);
    }
    // --legend: the isosurfaces' map, as mfr render --legend draws it.
    QStringList larger = common;
    larger[1] = QStringLiteral("200x150");
    QCOMPARE(runProgram(MFRVIEW,
                        QStringList{"@volume", "--contour", "0.3,0.6", "--legend", "--screenshot", viewerPng} + larger,
                        &out),
             0);
    QCOMPARE(
        runProgram(MFR_CLI, QStringList{"render", "@volume", "--contour", "0.3,0.6", "--legend", "-o", cliPng} + larger,
                   &out),
        0);
    QCOMPARE(maxChannelDifference(mfr::readPng(viewerPng.toStdString()), mfr::readPng(cliPng.toStdString())), 0);
    // The legend of --contour VOLUME=… on a volume other than the first: mfrview refused it ("nothing
    // is coloured by a field … no isosurfaces"; it looked at the current volume only; a bug hunt).
    {
      const QString two = dir.filePath("ab.mfrscene");
      QFile file(two);
      QVERIFY(file.open(QIODevice::WriteOnly));
      file.write(R"({"volumes": [{"name": "a", "file": "peak.vtk"},
                                  {"name": "b", "file": "peak.vtk", "transform": {"translate": [3, 0, 0]}}]})");
      file.close();
      const QStringList contourB{"--contour", "b=0.4,0.6", "--legend"};
      QCOMPARE(runProgram(MFRVIEW, QStringList{two, "--screenshot", viewerPng} + contourB + larger, &out), 0);
      QCOMPARE(runProgram(MFR_CLI, QStringList{"render", two, "-o", cliPng} + contourB + larger, &out), 0);
      QCOMPARE(maxChannelDifference(mfr::readPng(viewerPng.toStdString()), mfr::readPng(cliPng.toStdString())), 0);
    }
    QVERIFY(runProgram(MFRVIEW, QStringList{"@volume", "--contour", "7", "--screenshot", viewerPng} + common, &out) !=
            0);
    QVERIFY2(out.contains(QStringLiteral("--contour 7: isosurfaces: 7 lies outside the open range")), qPrintable(out));
    // VOLUME=V1,… as mfr render takes it (mfrview said "'field=0.4' is not a number").
    QCOMPARE(
        runProgram(MFRVIEW, QStringList{"@volume", "--contour", "field=0.4", "--screenshot", viewerPng} + common, &out),
        0);
    QCOMPARE(
        runProgram(MFR_CLI, QStringList{"render", "@volume", "--contour", "field=0.4", "-o", cliPng} + common, &out),
        0);
    QCOMPARE(maxChannelDifference(mfr::readPng(viewerPng.toStdString()), mfr::readPng(cliPng.toStdString())), 0);
    QVERIFY(runProgram(MFRVIEW, QStringList{"@volume", "--contour", "nope=0.4", "--screenshot", viewerPng} + common,
                       &out) != 0);
    QVERIFY2(out.contains(QStringLiteral("--contour nope=0.4: no volume 'nope' in scene 'volume' (volumes: field)")),
             qPrintable(out));
    // A session's isosurfaces the viewer refuses, and a clip box that holds nothing, are notes
    // naming the file and key; both were dropped without a word (a bug hunt).
    QTemporaryDir isoDir;
    const QString isoSession = isoDir.filePath(QStringLiteral("iso.mfrsession"));
    {
      QFile file(isoSession);
      QVERIFY(file.open(QIODevice::WriteOnly));
      file.write(QJsonDocument(
                     QJsonObject{
                         {"format", "mfrview-session"},
                         {"version", 1},
                         {"scene", "@volume"},
                         {"camera", QJsonObject{{"eye", QJsonArray{3, 2, 4}},
                                                {"target", QJsonArray{0, 0, 0}},
                                                {"up", QJsonArray{0, 1, 0}}}},
                         {"clip", QJsonObject{{"min", QJsonArray{10, 10, 10}}, {"max", QJsonArray{11, 11, 11}}}},
                         {"volumes", QJsonArray{QJsonObject{
                                         {"transfer", QJsonObject{{"points", QJsonArray{QJsonArray{0, 0, 0, 0, 0},
                                                                                        QJsonArray{1, 1, 1, 1, 0.5}}}}},
                                         {"isosurfaces", QJsonObject{{"values", QJsonArray{7}}}}}}}})
                     .toJson());
    }
    QCOMPARE(runProgram(MFRVIEW, QStringList{isoSession, "--screenshot", viewerPng} + common, &out), 0);
    const QString name = QStringLiteral("iso.mfrsession");
    QVERIFY2(out.contains(QStringLiteral("note: %1: volumes[0].isosurfaces: ").arg(name)) &&
                 out.contains(QStringLiteral("7 lies outside the open range")) &&
                 out.contains(QStringLiteral("(left out)")),
             qPrintable(out));
    QVERIFY2(
        out.contains(QStringLiteral("note: %1: clip: ").arg(name)) && out.contains(QStringLiteral("(not applied)")),
        qPrintable(out));
  }

  void colorByField() {
    // A sheet with point data "pressure" (x + y²/4, −2 … 3) and cell data "zone" (1 left, 2 right).
    QTemporaryDir dir;
    {
      constexpr int n = 9;
      QString points, pressure, connectivity, offsets, zone;
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          const double x = -2.0 + 4.0 * i / (n - 1), y = -2.0 + 4.0 * j / (n - 1);
          points += QStringLiteral("%1 %2 %3 ").arg(x).arg(y).arg(0.3 * std::sin(x));
          pressure += QString::number(x + y * y / 4.0) + ' ';
        }
      int quads = 0;
      for (int j = 0; j + 1 < n; ++j)
        for (int i = 0; i + 1 < n; ++i) {
          const int a = j * n + i;
          connectivity += QStringLiteral("%1 %2 %3 %4 ").arg(a).arg(a + 1).arg(a + 1 + n).arg(a + n);
          offsets += QString::number(4 * ++quads) + ' ';
          zone += QString::number(i < (n - 1) / 2 ? 1 : 2) + ' ';
        }
      QFile f(dir.filePath("sheet.vtp"));
      QVERIFY(f.open(QIODevice::WriteOnly));
      f.write(QStringLiteral("<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\" "
                             "byte_order=\"LittleEndian\"><PolyData><Piece NumberOfPoints=\"%1\" NumberOfPolys=\"%2\">"
                             "<PointData><DataArray type=\"Float32\" Name=\"pressure\" format=\"ascii\">%3</DataArray>"
                             "</PointData><CellData><DataArray type=\"Int32\" Name=\"zone\" format=\"ascii\">%4"
                             "</DataArray></CellData><Points><DataArray type=\"Float32\" NumberOfComponents=\"3\" "
                             "format=\"ascii\">%5</DataArray></Points><Polys><DataArray type=\"Int32\" "
                             "Name=\"connectivity\" format=\"ascii\">%6</DataArray><DataArray type=\"Int32\" "
                             "Name=\"offsets\" format=\"ascii\">%7</DataArray></Polys></Piece></PolyData></VTKFile>\n")
                  .arg(n * n)
                  .arg(quads)
                  .arg(pressure, zone, points, connectivity, offsets)
                  .toUtf8());
    }
    {
      const QJsonObject sheet{{"file", "sheet.vtp"}, {"opacity", 0.7}};
      const QJsonObject iso{{"name", "iso"}, {"eye", QJsonArray{1.0, -2.0, 4.0}}, {"fit", true}};
      QFile f(dir.filePath("sheet.mfrscene"));
      QVERIFY(f.open(QIODevice::WriteOnly));
      f.write(QJsonDocument(QJsonObject{{"objects", QJsonArray{sheet}}, {"views", QJsonArray{iso}}}).toJson());
    }
    const QString scene = dir.filePath("sheet.mfrscene");
    auto w = openWindow(scene);
    QVERIFY(w);
    ViewerModel& m = w->model();
    const QSize size(160, 120);
    QVERIFY(showAbufferIso(*w, size));
    auto* colorBy = w->findChild<QComboBox*>("colorByField");
    auto* map = w->findChild<QComboBox*>("colorByMap");
    auto* low = w->findChild<QDoubleSpinBox*>("colorRangeLow");
    auto* high = w->findChild<QDoubleSpinBox*>("colorRangeHigh");
    auto* dataRange = w->findChild<QPushButton*>("colorRangeReset");
    auto* note = w->findChild<QLabel*>("colorByNote");
    auto* legend = w->findChild<MapLegend*>("mapLegendA");
    QVERIFY(colorBy && map && low && high && dataRange && note && legend);
    QVERIFY(colorBy->isVisibleTo(w.get()));
    QCOMPARE(m.surfaceFields(), (QStringList{"pressure", "zone"}));
    QCOMPARE(colorBy->count(), 3);
    QCOMPARE(colorBy->currentIndex(), 0);  // the parts' own colours
    QVERIFY(!map->isEnabled());
    QVERIFY(!legend->isVisible());
    const mfr::ImageRGBA8 plain = w->view().renderImage(size);

    // The frame equals mfr render of the same scene with the same colouring, in a separate process.
    const auto expectCli = [&](const QStringList& colouring, const mfr::ImageRGBA8& frame) {
      const QString png = dir.filePath("cli.png");
      QString out;
      if (runProgram(MFR_CLI,
                     QStringList{"render", scene, "--size", "160x120", "--view", "iso", "-m", "abuffer-ll", "-o", png} +
                         colouring,
                     &out) != 0)
        return 256;
      return maxChannelDifference(mfr::readPng(png.toStdString()), frame);
    };
    colorBy->setCurrentIndex(1);
    emit colorBy->activated(1);  // as a user's choice
    QVERIFY(m.fieldColoring());
    QCOMPARE(m.fieldColoring()->field, std::string("pressure"));
    QCOMPARE(m.fieldColoring()->range, glm::dvec2(-2.0, 3.0));
    QCOMPARE(low->value(), -2.0);
    QCOMPARE(high->value(), 3.0);
    QVERIFY(map->isEnabled());
    settle(m);
    const mfr::ImageRGBA8 pressure = w->view().renderImage(size);
    QVERIFY(maxChannelDifference(pressure, plain) > 60);
    QCOMPARE(expectCli({"--color-by", "pressure"}, pressure), 0);
    QVERIFY(legend->isVisible());
    QCOMPARE(legend->title(), QStringLiteral("pressure"));
    QCOMPARE(legend->mapName(), QStringLiteral("cool-warm"));
    auto* tree = w->findChild<QTreeWidget*>("sceneTree");
    QVERIFY(tree && tree->topLevelItemCount() == 1);
    QCOMPARE(tree->topLevelItem(0)->text(1), QStringLiteral("pressure"));
    // The Probe dock gives the field's value under the pixel: mfr probe's at the same pixel.
    {
      auto* table = w->findChild<QTableWidget*>("probeTable");
      QVERIFY(table);
      QVERIFY(table->isColumnHidden(ProbePanel::FieldValue));
      const QPoint pixel(80, 60);
      QTest::mouseClick(&w->view(), Qt::LeftButton, Qt::ControlModifier, pixel);
      QTRY_VERIFY_WITH_TIMEOUT(!table->isColumnHidden(ProbePanel::FieldValue), 20000);
      const QString shown = table->item(0, ProbePanel::FieldValue)->text();
      QVERIFY2(shown.startsWith(QStringLiteral("pressure ")), qPrintable(shown));
      const QString json = dir.filePath("probe.json");
      QString out;
      QCOMPARE(runProgram(MFR_CLI,
                          {"probe", scene, "--size", "160x120", "--view", "iso", "--pixel", "80,60", "--color-by",
                           "pressure", "--json", json},
                          &out),
               0);
      QFile f(json);
      QVERIFY(f.open(QIODevice::ReadOnly));
      const QJsonObject first =
          QJsonDocument::fromJson(f.readAll()).object().value("fragments").toArray()[0].toObject();
      QCOMPARE(shown, QStringLiteral("pressure %1").arg(first.value("field_value").toDouble(), 0, 'g', 6));
    }

    map->setCurrentIndex(map->findText(QStringLiteral("viridis")));
    emit map->activated(map->currentIndex());
    low->setValue(0.0);  // applies [0, 3]
    settle(m);
    const mfr::ImageRGBA8 viridis = w->view().renderImage(size);
    QCOMPARE(m.fieldColoring()->range, glm::dvec2(0.0, 3.0));
    QCOMPARE(legend->mapName(), QStringLiteral("viridis"));
    QCOMPARE(expectCli({"--color-by", "pressure", "--color-map", "viridis", "--color-range", "0,3"}, viridis), 0);

    // An empty range is refused with its reason; the colouring stays.
    low->setValue(5.0);
    QVERIFY(note->isVisibleTo(w.get()));
    QVERIFY2(note->text().contains(QStringLiteral("low < high")), qPrintable(note->text()));
    QCOMPARE(m.fieldColoring()->range, glm::dvec2(0.0, 3.0));
    dataRange->click();
    QCOMPARE(m.fieldColoring()->range, glm::dvec2(-2.0, 3.0));
    QVERIFY(!note->isVisibleTo(w.get()));
    QCOMPARE(low->value(), -2.0);

    // Cell data, then a session round trip.
    colorBy->setCurrentIndex(2);
    emit colorBy->activated(2);
    settle(m);
    const mfr::ImageRGBA8 zone = w->view().renderImage(size);
    QCOMPARE(expectCli({"--color-by", "zone", "--color-map", "viridis"}, zone), 0);
    const QString sessionPath = dir.filePath("colour.mfrsession");
    auto again = reopenedSession(*w, sessionPath, size);
    QVERIFY(again);
    ViewerModel& a = again->model();
    QTRY_VERIFY_WITH_TIMEOUT(a.hasScene() && a.fieldColoring().has_value(), kTimeoutMs);
    settle(a);
    QCOMPARE(a.fieldColoring()->field, std::string("zone"));
    QCOMPARE(again->findChild<QComboBox*>("colorByField")->currentText(), QStringLiteral("zone"));
    QCOMPARE(maxChannelDifference(zone, again->view().renderImage(a.renderSize())), 0);

    // A colour chosen for the part replaces the field's colours (the Colour column's picker).
    m.setObjectColor(0, QColor(200, 40, 40));
    settle(m);
    QVERIFY(!m.fieldColoring());
    QCOMPARE(colorBy->currentIndex(), 0);
    QVERIFY(maxChannelDifference(zone, w->view().renderImage(size)) > 60);
    m.resetObjectColor(0);

    // Back to the parts' own colours: the first frame again.
    colorBy->setCurrentIndex(0);
    emit colorBy->activated(0);
    settle(m);
    QVERIFY(!m.fieldColoring());
    QCOMPARE(maxChannelDifference(plain, w->view().renderImage(size)), 0);
    QVERIFY(!legend->isVisible());
    // The greyed range keeps no earlier colouring's values (another file's B-factors stayed; a bug hunt).
    QVERIFY(!low->isEnabled());
    QCOMPARE(low->value(), 0.0);
    QCOMPARE(high->value(), 0.0);

    // mfrview --color-by: the pixels of mfr render --color-by; a field the parts lack is one line.
    const QString viewerPng = dir.filePath("viewer.png"), cliPng = dir.filePath("cli-options.png");
    const QStringList common{"--size",
                             "96x72",
                             "--view",
                             "iso",
                             "-m",
                             "abuffer-ll",
                             "--color-by",
                             "pressure",
                             "--color-map",
                             "magma",
                             "--color-range=-1,2"};
    QString out;
    QCOMPARE(runProgram(MFRVIEW, QStringList{scene, "--screenshot", viewerPng} + common, &out), 0);
    QCOMPARE(runProgram(MFR_CLI, QStringList{"render", scene, "-o", cliPng} + common, &out), 0);
    QCOMPARE(maxChannelDifference(mfr::readPng(viewerPng.toStdString()), mfr::readPng(cliPng.toStdString())), 0);
    QVERIFY(runProgram(MFRVIEW, QStringList{scene, "--color-by", "nope", "--screenshot", viewerPng}, &out) != 0);
    const QString last = out.trimmed().split(QLatin1Char('\n')).last();
    QVERIFY2(last.startsWith(QStringLiteral("mfrview: --color-by nope: ")) &&
                 last.contains(QStringLiteral("no point-data or cell-data array 'nope' (fields: pressure, zone)")),
             qPrintable(out));
    // --legend: the scalar bar in the screenshot, the pixels of mfr render --legend (and another
    // picture than without it); refused without a field colouring.
    QStringList larger = common;
    larger[1] = QStringLiteral("200x150");  // room for the legend
    QCOMPARE(runProgram(MFRVIEW, QStringList{scene, "--screenshot", viewerPng, "--legend"} + larger, &out), 0);
    QCOMPARE(runProgram(MFR_CLI, QStringList{"render", scene, "-o", cliPng, "--legend"} + larger, &out), 0);
    const mfr::ImageRGBA8 withLegend = mfr::readPng(viewerPng.toStdString());
    QCOMPARE(maxChannelDifference(withLegend, mfr::readPng(cliPng.toStdString())), 0);
    QCOMPARE(runProgram(MFR_CLI, QStringList{"render", scene, "-o", cliPng} + larger, &out), 0);
    QVERIFY(maxChannelDifference(withLegend, mfr::readPng(cliPng.toStdString())) > 100);
    QVERIFY(runProgram(MFRVIEW, QStringList{scene, "--legend", "--screenshot", viewerPng}, &out) != 0);
    QVERIFY2(out.contains(QStringLiteral("mfrview: --legend: nothing is coloured by a field")), qPrintable(out));
  }

  void colorByVolumeField() {
    // A sphere inside a volume of two arrays: "ramp" (value = x index) and "half" (x index / 2).
    QTemporaryDir dir;
    {
      QVERIFY(writeTwoArrayVti(
          dir.filePath("two.vti"), QStringLiteral("ramp"), [](int i, int, int) { return i; }, QStringLiteral("half"),
          [](int i, int, int) { return i / 2.0; }));
      const QJsonObject ball{{"primitive", QJsonObject{{"type", "sphere"}, {"radius", 0.3}}},
                             {"transform", QJsonObject{{"translate", QJsonArray{0.55, 0.55, 0.55}}}},
                             {"opacity", 0.8}};
      const QJsonObject iso{{"name", "iso"}, {"eye", QJsonArray{3.0, 2.0, 4.0}}, {"fit", true}};
      for (const QString& field : {QStringLiteral("ramp"), QStringLiteral("half")}) {
        QFile scene(dir.filePath(field + ".mfrscene"));
        QVERIFY(scene.open(QIODevice::WriteOnly));
        scene.write(
            QJsonDocument(QJsonObject{{"objects", QJsonArray{ball}},
                                      {"volumes", QJsonArray{QJsonObject{
                                                      {"file", "two.vti"}, {"field", field}, {"visible", false}}}},
                                      {"views", QJsonArray{iso}}})
                .toJson());
      }
    }
    auto w = openWindow(dir.filePath("ramp.mfrscene"));
    QVERIFY(w);
    ViewerModel& m = w->model();
    const QSize size(120, 96);
    QVERIFY(showAbufferIso(*w, size));
    QVERIFY(m.surfaceFields().contains(QStringLiteral("@two.vti")));
    // The sphere spans x from 0.25 to 0.85: ramp values 2.5 … 8.5.
    const glm::dvec2 ramp = m.fieldDataRange(QStringLiteral("@two.vti"));
    QVERIFY2(std::abs(ramp.x - 2.5) < 0.05 && std::abs(ramp.y - 8.5) < 0.05,
             qPrintable(QStringLiteral("%1 %2").arg(ramp.x).arg(ramp.y)));
    QVERIFY(m.setFieldColoring(QStringLiteral("@two.vti"), QStringLiteral("viridis"), glm::dvec2(0.0, 10.0)));
    settle(m);
    const mfr::ImageRGBA8 byRamp = w->view().renderImage(size);
    // Another array of the volume: the surface's samples follow it, over the same map and range.
    m.setVolumeField(QStringLiteral("half"));
    QTRY_VERIFY_WITH_TIMEOUT(!m.volumeFieldLoading(), kTimeoutMs);
    QCOMPARE(m.volumeField(), QStringLiteral("half"));
    const glm::dvec2 half = m.fieldDataRange(QStringLiteral("@two.vti"));
    QVERIFY2(std::abs(half.x - 1.25) < 0.05 && std::abs(half.y - 4.25) < 0.05,
             qPrintable(QStringLiteral("%1 %2").arg(half.x).arg(half.y)));
    QVERIFY(m.fieldColoring());
    QCOMPARE(m.fieldColoring()->range, glm::dvec2(0.0, 10.0));
    settle(m);
    const mfr::ImageRGBA8 byHalf = w->view().renderImage(size);
    QVERIFY(maxChannelDifference(byHalf, byRamp) > 30);
    const QString png = dir.filePath("cli.png");
    QString out;
    QCOMPARE(
        runProgram(MFR_CLI,
                   {"render", dir.filePath("half.mfrscene"), "--size", "120x96", "--view", "iso", "-m", "abuffer-ll",
                    "--color-by", "@two.vti", "--color-map", "viridis", "--color-range", "0,10", "-o", png},
                   &out),
        0);
    QCOMPARE(maxChannelDifference(mfr::readPng(png.toStdString()), byHalf), 0);
  }

  void volumePanelNamesAPresetFunction() {
    QTemporaryDir dir;
    auto w = openWindow(QString());
    QVERIFY(w);
    const mfr::TransferFunction fire = mfr::transferPreset("fire", 0.125, 0.875, 0.2);
    w->openScene(writeBlobScene(dir, "fire.mfrscene", fire));
    ViewerModel& m = w->model();
    QTRY_VERIFY_WITH_TIMEOUT(m.hasScene() && m.framesRendered() > 0, kTimeoutMs);
    settle(m);
    auto* preset = w->findChild<QComboBox*>("hvPreset");
    QVERIFY(preset);
    QCOMPARE(preset->currentData().toString(), QStringLiteral("fire"));
    QCOMPARE(w->findChild<QDoubleSpinBox*>("hvWindowMin")->value(), 0.125);
    QCOMPARE(w->findChild<QDoubleSpinBox*>("hvWindowMax")->value(), 0.875);
    QCOMPARE(m.transferFunction().points.size(), fire.points.size());  // nothing re-applied
    w->openScene(writeBlobScene(dir, "blob.mfrscene", blobTransfer()));
    QTRY_VERIFY_WITH_TIMEOUT(m.hasScene() && m.framesRendered() > 0 && m.transferFunction().points.size() == 2,
                             kTimeoutMs);
    settle(m);
    QCOMPARE(preset->currentData().toString(), QStringLiteral("Custom"));
  }

  // The panels scroll in their docks, so they set neither the window's least size (it fits a
  // 1280×720 screen with every plugin loaded) nor, at the default size, most of its width.
  void windowFitsASmallScreen() {
    auto w = openWindow();
    QVERIFY(w);
    w->model().setMethod("vkb");  // the most parameter rows, and the budget panel's histogram
    settle(w->model());
    const QSize least = w->minimumSizeHint().expandedTo(w->minimumSize());
    QVERIFY2(least.width() <= 1000 && least.height() <= 640,
             qPrintable(QStringLiteral("%1 x %2").arg(least.width()).arg(least.height())));
    // At 1440 × 900 the image gets at least 45 % of the width (it had 34 % when the panels' least
    // widths added up).
    w->resize(1440, 900);
    QTRY_VERIFY2_WITH_TIMEOUT(w->view().width() >= 648, qPrintable(QString::number(w->view().width())), 20000);
    // --window-size below that least size opens the window at it, not at the docks' size hints
    // (800 × 500 opened 1048 wide: a bug hunt); one above it is the size asked for.
    QTemporaryDir dir;
    QString out;
    for (const auto& [asked, widest] : {std::pair{QSize(800, 500), 1000}, std::pair{QSize(1100, 700), 1100}}) {
      const QString png = dir.filePath(QStringLiteral("window.png"));
      const QString size = QStringLiteral("%1x%2").arg(asked.width()).arg(asked.height());
      QCOMPARE(runProgram(MFRVIEW, {"@sample", "-m", "vkb", "--window-size", size, "--window-screenshot", png}, &out),
               0);
      const mfr::ImageRGBA8 shot = mfr::readPng(png.toStdString());
      QVERIFY2(shot.width >= asked.width() && shot.width <= widest && shot.height == asked.height(),
               qPrintable(QStringLiteral("%1: %2 x %3").arg(size).arg(shot.width).arg(shot.height)));
    }
  }

  // A control of the Clip dock changes what it shows and nothing else: a file's plane and box need
  // not sit on slider steps (and the box may reach past the bounds), and a flag, the side or
  // another axis's slider must leave them as they are. The wheel passing over an unfocused slider
  // changes nothing.
  void clipControlsChangeOnlyWhatTheyShow() {
    auto w = openWindow();
    QVERIFY(w);
    ViewerModel& m = w->model();
    const mfr::SectionPlane plane{{0.1234567, 0.0, 0.0}, {1.0, 0.0, 0.0}, true, false};
    const mfr::Bounds box{{-5.0, -5.0, -5.0}, {5.0, 5.0, 5.0}};
    m.setSection(plane);
    m.setClipBox(box);
    auto* caps = w->findChild<QCheckBox*>("sectionCaps");
    auto* flip = w->findChild<QCheckBox*>("sectionFlip");
    auto* minX = w->findChild<QSlider*>("clipMinX");
    auto* minY = w->findChild<QSlider*>("clipMinY");
    QVERIFY(caps && flip && minX && minY);
    QVERIFY(caps->isChecked() && caps->isEnabled());
    caps->setChecked(false);
    QVERIFY(m.section() && !m.section()->caps);
    QCOMPARE(m.section()->point, plane.point);
    QCOMPARE(m.section()->normal, plane.normal);
    QVERIFY(m.clipBox());
    QCOMPARE(m.clipBox()->min, box.min);
    QCOMPARE(m.clipBox()->max, box.max);
    flip->setChecked(!flip->isChecked());
    QCOMPARE(m.section()->point, plane.point);
    QCOMPARE(m.section()->normal, -plane.normal);
    QCOMPARE(m.clipBox()->max, box.max);
    // One face moved: every other face keeps its value, the same axis's other face included.
    minY->setValue(500);
    const mfr::Bounds b = m.scene().bounds();
    QCOMPARE(m.clipBox()->min.y, b.min.y + (b.max.y - b.min.y) * 500 / 1000);
    QCOMPARE(m.clipBox()->max.y, box.max.y);
    QCOMPARE(m.clipBox()->min.x, box.min.x);
    QCOMPARE(m.clipBox()->max.z, box.max.z);
    QCOMPARE(m.section()->point, plane.point);
    // A face pushed by the other: both at the slider's place.
    auto* maxY = w->findChild<QSlider*>("clipMaxY");
    QVERIFY(maxY);
    maxY->setValue(300);
    QCOMPARE(minY->value(), 300);
    QCOMPARE(m.clipBox()->min.y, b.min.y + (b.max.y - b.min.y) * 300 / 1000);
    QCOMPARE(m.clipBox()->max.y, m.clipBox()->min.y);
    QCOMPARE(m.clipBox()->min.x, box.min.x);
    // A plane of its own normal (Custom): Flip turns it round and shows it, and back.
    const glm::dvec3 tilted = glm::normalize(glm::dvec3(1.0, 1.0, 0.0));
    m.setSection(mfr::SectionPlane{plane.point, tilted, true, false});
    QVERIFY(!flip->isChecked());
    flip->setChecked(true);
    QCOMPARE(m.section()->normal, -tilted);
    QCOMPARE(m.section()->point, plane.point);
    QVERIFY(flip->isChecked());
    flip->setChecked(false);
    QCOMPARE(m.section()->normal, tilted);
    // The wheel over an unfocused slider: nothing moves.
    const mfr::Bounds before = *m.clipBox();
    const int position = minX->value();
    QVERIFY(!minX->hasFocus());
    const QPointF at(minX->width() / 2.0, minX->height() / 2.0);
    QWheelEvent wheel(at, minX->mapToGlobal(at), QPoint(), QPoint(0, -120), Qt::NoButton, Qt::NoModifier,
                      Qt::NoScrollPhase, false);
    QApplication::sendEvent(minX, &wheel);
    QCOMPARE(minX->value(), position);
    QCOMPARE(m.clipBox()->min, before.min);
    QCOMPARE(m.clipBox()->max, before.max);
    // ... while the wheel over the dock still scrolls it (its scroll area hands the wheel to its
    // scroll bar, a slider the guard must let through).
    auto* dock = w->findChild<QDockWidget*>("clipDock");
    QVERIFY(dock);
    dock->raise();
    w->resize(1000, 600);
    QScrollArea* scroll = nullptr;
    for (QWidget* p = minX->parentWidget(); p && !scroll; p = p->parentWidget()) scroll = qobject_cast<QScrollArea*>(p);
    QVERIFY(scroll);
    QTRY_VERIFY_WITH_TIMEOUT(scroll->verticalScrollBar()->maximum() > 0, 10000);
    QCOMPARE(scroll->verticalScrollBar()->value(), 0);
    const QPointF middle(scroll->viewport()->width() / 2.0, scroll->viewport()->height() / 2.0);
    QWheelEvent down(middle, scroll->viewport()->mapToGlobal(middle), QPoint(), QPoint(0, -120), Qt::NoButton,
                     Qt::NoModifier, Qt::NoScrollPhase, false);
    QApplication::sendEvent(scroll->viewport(), &down);
    QVERIFY(scroll->verticalScrollBar()->value() > 0);
  }

  void sectionPlane() {
    QTemporaryDir dir;
    auto w = openWindow();
    QVERIFY(w);
    ViewerModel& m = w->model();
    w->view().setFixedSize(200, 150);
    QTRY_COMPARE_WITH_TIMEOUT(m.renderSize(), QSize(200, 150), kTimeoutMs);
    m.setMethod("abuffer-ll");
    m.setCamera(m.scene().view("iso"));
    settle(m);
    const mfr::ImageRGBA8 whole = w->view().renderImage(QSize(200, 150));
    auto* enabled = w->findChild<QCheckBox*>("sectionEnabled");
    auto* axis = w->findChild<QComboBox*>("sectionAxis");
    auto* offset = w->findChild<QSlider*>("sectionOffset");
    auto* flip = w->findChild<QCheckBox*>("sectionFlip");
    auto* caps = w->findChild<QCheckBox*>("sectionCaps");
    QVERIFY(enabled && axis && offset && flip && caps);
    QVERIFY(!m.section());
    QVERIFY(!offset->isEnabled());
    enabled->setChecked(true);
    QVERIFY(m.section().has_value());
    auto* slice = w->findChild<QCheckBox*>("sectionSlice");
    QVERIFY(slice && !slice->isEnabled());  // no volume to slice here (app.sectionVolumeSlice)
    axis->setCurrentIndex(0);
    offset->setValue(400);
    flip->setChecked(true);
    const mfr::Bounds b = m.scene().bounds();
    QVERIFY(m.section().has_value());
    const mfr::SectionPlane plane = *m.section();
    QCOMPARE(plane.normal, glm::dvec3(-1.0, 0.0, 0.0));
    // The report line counts what sectionedScene does.
    mfr::SectionReport report;
    (void)mfr::sectionedScene(m.scene(), &report);
    QVERIFY(report.cut > 0);
    auto* reportLabel = w->findChild<QLabel*>("sectionReport");
    QVERIFY(reportLabel);
    QVERIFY2(reportLabel->text().startsWith(QStringLiteral("%1 part").arg(report.cut)),
             qPrintable(reportLabel->text()));
    QVERIFY2(reportLabel->text().contains(QStringLiteral("%1 capped").arg(report.capped)),
             qPrintable(reportLabel->text()));
    QVERIFY(report.totalCapArea() > 0.0);
    QVERIFY2(reportLabel->text().contains(QStringLiteral("cross-section %1").arg(report.totalCapArea(), 0, 'g', 6)),
             qPrintable(reportLabel->text()));
    // A capped part's Triangles tooltip measures it as cut (mfr info --section), then the whole part.
    {
      const auto capped =
          std::find_if(report.capAreas.begin(), report.capAreas.end(), [](double a) { return a > 0.0; });
      QVERIFY(capped != report.capAreas.end());
      const auto i = static_cast<std::size_t>(capped - report.capAreas.begin());
      const mfr::Object& cutPart = m.drawnScene().objects[i];
      const mfr::Object& wholePart = m.scene().objects[i];
      const QList<QTreeWidgetItem*> rows =
          w->findChild<QTreeWidget*>("sceneTree")
              ->findItems(QString::fromStdString(wholePart.name), Qt::MatchExactly | Qt::MatchRecursive);
      QVERIFY(!rows.isEmpty());
      const QString expected =
          QString::fromStdString(mfr::describeSurface(mfr::measureSurface(*cutPart.mesh, cutPart.transform)) +
                                 mfr::describeCut(mfr::SectionOutcome::kCapped, *capped) + "\nwhole part: " +
                                 mfr::describeSurface(mfr::measureSurface(*wholePart.mesh, wholePart.transform)));
      QCOMPARE(rows[0]->data(3, Qt::ToolTipRole).toString(), expected);
      QVERIFY(expected.contains(QStringLiteral("; cut, cross-section area ")));
    }
    QCOMPARE(reportLabel->toolTip().isEmpty(), report.open.empty());
    QCOMPARE(plane.point.x, b.min.x + (b.max.x - b.min.x) * 400 / 1000);
    QVERIFY(plane.caps);
    settle(m);
    const mfr::ImageRGBA8 cut = w->view().renderImage(QSize(200, 150));
    QVERIFY(maxChannelDifference(cut, whole) > 50);
    // Caps change the picture: the cut parts are closed again.
    caps->setChecked(false);
    QVERIFY(!m.section()->caps);
    settle(m);
    QVERIFY(maxChannelDifference(w->view().renderImage(QSize(200, 150)), cut) > 20);
    caps->setChecked(true);
    // The same plane through the command line: the same pixels.
    const QString planeText = QString::asprintf("%.17g,%.17g,%.17g,%.17g,%.17g,%.17g", plane.point.x, plane.point.y,
                                                plane.point.z, plane.normal.x, plane.normal.y, plane.normal.z);
    const QString cliPng = dir.filePath("cli.png");
    QString out;
    QCOMPARE(runProgram(MFR_CLI,
                        {"render", "@sample", "--size", "200x150", "--view", "iso", "-m", "abuffer-ll", "--section",
                         planeText, "-o", cliPng},
                        &out),
             0);
    settle(m);
    const int diff = maxChannelDifference(mfr::readPng(cliPng.toStdString()), cut);
    qInfo("section %s: viewer vs mfr render max channel difference %d", qPrintable(planeText), diff);
    QCOMPARE(diff, 0);
    // The exact reference (a CPU image from the model's cut scene) too.
    const QString oraclePng = dir.filePath("oracle.png");
    QCOMPARE(
        runProgram(MFR_CLI,
                   {"render", "@sample", "--size", "200x150", "--view", "iso", "--section", planeText, "-o", oraclePng},
                   &out),
        0);
    m.setMethod("oracle");
    settle(m);
    QCOMPARE(maxChannelDifference(mfr::readPng(oraclePng.toStdString()), w->view().renderImage(QSize(200, 150))), 0);
    m.setMethod("abuffer-ll");

    // Sessions keep the plane; a file's own oblique normal shows as "Custom".
    const QString sessionPath = dir.filePath("section.mfrsession");
    writeSessionFile(sessionPath, captureSession(m));
    enabled->setChecked(false);
    QVERIFY(!m.section());
    settle(m);
    QCOMPARE(maxChannelDifference(w->view().renderImage(QSize(200, 150)), whole), 0);
    applySession(readSessionFile(sessionPath), m);
    QVERIFY(m.section().has_value());
    QCOMPARE(*m.section(), plane);
    QVERIFY(enabled->isChecked() && flip->isChecked());
    QCOMPARE(offset->value(), 400);
    settle(m);
    QCOMPARE(maxChannelDifference(w->view().renderImage(QSize(200, 150)), cut), 0);
    m.setSection(mfr::SectionPlane{b.center(), {1.0, 1.0, 0.0}, true});
    QCOMPARE(axis->currentText(), QStringLiteral("Custom"));
    QCOMPARE(offset->value(), 500);
    offset->setValue(600);
    QVERIFY(m.section()->normal.x > 0.7 && m.section()->normal.y > 0.7);
    // Align to view: through the target, facing away from the eye; the near half is gone.
    enabled->setChecked(false);
    auto* align = w->findChild<QPushButton*>("sectionAlign");
    QVERIFY(align);
    align->click();
    QVERIFY(m.section().has_value() && enabled->isChecked());
    QCOMPARE(axis->currentText(), QStringLiteral("Custom"));
    QCOMPARE(m.section()->point, m.camera().target);
    QVERIFY(glm::length(m.section()->normal - m.camera().forward()) < 1e-12);
    settle(m);
    QVERIFY(maxChannelDifference(w->view().renderImage(QSize(200, 150)), whole) > 50);
  }

  void sectionVolumeSlice() {
    // Volume slice: each volume's samples on the plane (SectionPlane::slice), the pixels of mfr
    // render --section …:slice, counted in the report line, kept by sessions.
    QTemporaryDir dir;
    auto w = openWindow(QStringLiteral("@volume"));
    QVERIFY(w);
    ViewerModel& m = w->model();
    const QSize size(160, 120);
    QVERIFY(showAbufferIso(*w, size));
    auto* enabled = w->findChild<QCheckBox*>("sectionEnabled");
    auto* axis = w->findChild<QComboBox*>("sectionAxis");
    auto* offset = w->findChild<QSlider*>("sectionOffset");
    auto* flip = w->findChild<QCheckBox*>("sectionFlip");
    auto* slice = w->findChild<QCheckBox*>("sectionSlice");
    auto* reportLabel = w->findChild<QLabel*>("sectionReport");
    QVERIFY(enabled && axis && offset && flip && slice && reportLabel);
    QVERIFY(!slice->isEnabled());  // no plane yet
    enabled->setChecked(true);
    axis->setCurrentIndex(2);
    offset->setValue(550);
    flip->setChecked(true);
    QVERIFY(slice->isEnabled());
    QVERIFY(!m.section()->slice);
    settle(m);
    const mfr::ImageRGBA8 plain = w->view().renderImage(size);
    slice->setChecked(true);
    QVERIFY(m.section()->slice);
    QVERIFY2(reportLabel->text().endsWith(QStringLiteral("; 1 volume slice")), qPrintable(reportLabel->text()));
    settle(m);
    QVERIFY2(m.renderError().isEmpty(), qPrintable(m.renderError()));
    const mfr::ImageRGBA8 sliced = w->view().renderImage(size);
    QVERIFY(maxChannelDifference(sliced, plain) > 50);
    const mfr::SectionPlane plane = *m.section();
    const QString planeText =
        QString::asprintf("%.17g,%.17g,%.17g,%.17g,%.17g,%.17g:slice", plane.point.x, plane.point.y, plane.point.z,
                          plane.normal.x, plane.normal.y, plane.normal.z);
    const QString cliPng = dir.filePath("cli.png");
    QString out;
    QCOMPARE(runProgram(MFR_CLI,
                        {"render", "@volume", "--size", "160x120", "--view", "iso", "-m", "abuffer-ll", "--section",
                         planeText, "-o", cliPng},
                        &out),
             0);
    QCOMPARE(maxChannelDifference(mfr::readPng(cliPng.toStdString()), sliced), 0);
    // The Probe dock names the slice (a part of the drawn scene only) and gives the volume's value.
    const mfr::Scene& drawn = m.drawnScene();
    QCOMPARE(drawn.objects.size(), m.scene().objects.size() + 1);
    QCOMPARE(QString::fromStdString(drawn.objects.back().name), QStringLiteral("field slice"));
    const auto sliceId = static_cast<std::uint32_t>(drawn.objects.size() - 1);
    const mfr::FragmentLists lists = mfr::castFragments(drawn, m.camera(), size.width(), size.height());
    QPoint onSlice(-1, -1);
    for (int y = 30; y < 90 && onSlice.x() < 0; ++y)
      for (int x = 40; x < 120 && onSlice.x() < 0; ++x)
        if (!lists.isAmbiguous(x, y) && lists.count(x, y) > 0 && lists.pixel(x, y)[0].objectId == sliceId)
          onSlice = QPoint(x, y);
    QVERIFY(onSlice.x() >= 0);
    auto* table = w->findChild<QTableWidget*>("probeTable");
    QVERIFY(table);
    QTest::mouseClick(&w->view(), Qt::LeftButton, Qt::ControlModifier, onSlice);
    QTRY_VERIFY_WITH_TIMEOUT(table->rowCount() > 1 && table->item(0, ProbePanel::Part) &&
                                 table->item(0, ProbePanel::Part)->text() == QStringLiteral("field slice"),
                             20000);
    QVERIFY2(table->item(0, ProbePanel::FieldValue)->text().startsWith(QStringLiteral("@field ")),
             qPrintable(table->item(0, ProbePanel::FieldValue)->text()));
    // A session keeps it.
    const QString sessionPath = dir.filePath("slice.mfrsession");
    writeSessionFile(sessionPath, captureSession(m));
    slice->setChecked(false);
    QVERIFY(!m.section()->slice);
    applySession(readSessionFile(sessionPath), m);
    QCOMPARE(*m.section(), plane);
    QVERIFY(slice->isChecked());
    settle(m);
    QCOMPARE(maxChannelDifference(w->view().renderImage(size), sliced), 0);
  }
  // A molecule's representations (the Scene dock's Molecule row): hidden for other scenes; a
  // change re-reads the file with them and keeps the camera; the image equals mfr render's with
  // --molecule and that camera; a session keeps them; mfrview --molecule too.
  void moleculeRepresentations() {
    const QString pept = QStringLiteral("/usr/share/pymol/data/demo/pept.pdb");
    QVERIFY2(QFileInfo::exists(pept), "missing pept.pdb (Debian package pymol-data)");
    auto w = openWindow();
    QVERIFY(w);
    auto* row = w->findChild<QWidget*>("moleculeRow");
    auto* spheres = w->findChild<QCheckBox*>("moleculeSpheres");
    auto* sticks = w->findChild<QCheckBox*>("moleculeSticks");
    auto* surface = w->findChild<QCheckBox*>("moleculeSurface");
    QVERIFY(row && spheres && sticks && surface);
    QVERIFY(!row->isVisibleTo(w.get()));  // @sample is not a molecule
    ViewerModel& m = w->model();
    QVERIFY(!m.moleculeStyle());
    w->openScene(pept);
    QTRY_VERIFY_WITH_TIMEOUT(m.scenePath() == pept && m.framesRendered() > 0, kTimeoutMs);
    QVERIFY(row->isVisibleTo(w.get()));
    QVERIFY(spheres->isChecked() && !sticks->isChecked() && !surface->isChecked());
    QCOMPARE(m.scene().objects.size(), std::size_t{1});
    const QSize size(160, 120);
    QVERIFY(showAbufferIso(*w, size));
    const mfr::Camera camera = m.camera();
    // Sticks and surface instead of spheres: the file is read again, the camera stays.
    sticks->setChecked(true);
    QTRY_VERIFY_WITH_TIMEOUT(m.moleculeStyle() && m.moleculeStyle()->sticks, kTimeoutMs);
    surface->setChecked(true);
    spheres->setChecked(false);
    QTRY_VERIFY_WITH_TIMEOUT(!m.isLoading() && m.moleculeStyle() && m.moleculeStyle()->text() == "sticks,surface",
                             kTimeoutMs);
    QStringList names;
    for (const mfr::Object& o : m.scene().objects) names << QString::fromStdString(o.name);
    QCOMPARE(names, (QStringList{"chain E sticks", "chain E surface"}));
    QCOMPARE(m.camera().eye, camera.eye);
    QCOMPARE(m.camera().target, camera.target);
    // The cartoon: a part of its own between the sticks and the surface; untick it again.
    auto* cartoon = w->findChild<QCheckBox*>("moleculeCartoon");
    QVERIFY(cartoon && !cartoon->isChecked());
    cartoon->setChecked(true);
    QTRY_VERIFY_WITH_TIMEOUT(!m.isLoading() && m.moleculeStyle()->text() == "sticks,cartoon,surface", kTimeoutMs);
    names.clear();
    for (const mfr::Object& o : m.scene().objects) names << QString::fromStdString(o.name);
    QCOMPARE(names, (QStringList{"chain E sticks", "chain E cartoon", "chain E surface"}));
    cartoon->setChecked(false);
    QTRY_VERIFY_WITH_TIMEOUT(!m.isLoading() && m.moleculeStyle()->text() == "sticks,surface", kTimeoutMs);
    // The view is kept as it is when the read ends, with the clip box, the section, the z-thickness
    // and the colouring by a field (an orbit during the read was undone, and the rest dropped as for
    // another file: a bug hunt).
    {
      const mfr::Bounds b = m.scene().bounds();
      const mfr::Bounds box{b.min, b.min + (b.max - b.min) * 0.8};
      const mfr::SectionPlane plane{b.center(), {0.0, 0.0, 1.0}, true, false};
      m.setClipBox(box);
      m.setSection(plane);
      m.setZThickness(0.25);
      QVERIFY2(m.surfaceFields().contains("b_factor"), qPrintable(m.surfaceFields().join(',')));
      QVERIFY(m.setFieldColoring("b_factor", "viridis", glm::dvec2(0.0, 50.0)));
      cartoon->setChecked(true);
      const mfr::Camera orbited = navigation::orbit(m.camera(), QPointF(40, 0), size);
      m.setCamera(orbited);
      QTRY_VERIFY_WITH_TIMEOUT(!m.isLoading() && m.moleculeStyle()->text() == "sticks,cartoon,surface", kTimeoutMs);
      QCOMPARE(m.camera().eye, orbited.eye);
      QVERIFY(m.clipBox() && m.clipBox()->min == box.min && m.clipBox()->max == box.max);
      QVERIFY(m.section() && m.section()->point == plane.point && m.section()->normal == plane.normal);
      QCOMPARE(m.zThickness(), 0.25);
      QVERIFY(m.fieldColoring() && m.fieldColoring()->field == "b_factor" && m.fieldColoring()->map == "viridis" &&
              m.fieldColoring()->range == glm::dvec2(0.0, 50.0));
      m.setClipBox(std::nullopt);
      m.setSection(std::nullopt);
      m.setZThickness(0.0);
      QVERIFY(m.setFieldColoring(QString()));
      cartoon->setChecked(false);
      QTRY_VERIFY_WITH_TIMEOUT(!m.isLoading() && m.moleculeStyle()->text() == "sticks,surface", kTimeoutMs);
      m.setCamera(camera);
    }
    // Sticks on the chain only (--molecule sticks@polymer): partly checked; a click draws them on all.
    m.setMoleculeStyle(mfr::MoleculeStyle::parse("sticks@polymer,surface", "test"));
    QTRY_VERIFY_WITH_TIMEOUT(!m.isLoading() && m.moleculeStyle()->text() == "sticks@polymer,surface", kTimeoutMs);
    QCOMPARE(sticks->checkState(), Qt::PartiallyChecked);
    QCOMPARE(surface->checkState(), Qt::Checked);
    sticks->setCheckState(Qt::Checked);
    QTRY_VERIFY_WITH_TIMEOUT(!m.isLoading() && m.moleculeStyle()->text() == "sticks,surface", kTimeoutMs);
    QVERIFY(!sticks->isTristate());
    // None at all is not taken: the last one stays checked.
    sticks->setChecked(false);
    QTRY_VERIFY_WITH_TIMEOUT(!m.isLoading() && m.moleculeStyle()->text() == "surface", kTimeoutMs);
    surface->setChecked(false);
    QVERIFY(surface->isChecked());
    QCOMPARE(m.moleculeStyle()->text(), std::string("surface"));
    // Ticked and unticked again before the re-read ends: what is drawn in the end is what is ticked.
    sticks->setChecked(true);
    sticks->setChecked(false);
    QTRY_VERIFY_WITH_TIMEOUT(!m.isLoading(), kTimeoutMs);
    QCOMPARE(m.moleculeStyle()->text(), std::string("surface"));
    QVERIFY(!sticks->isChecked());
    QCOMPARE(m.scene().objects.size(), std::size_t{1});
    sticks->setChecked(true);
    QTRY_VERIFY_WITH_TIMEOUT(!m.isLoading() && m.moleculeStyle()->text() == "sticks,surface", kTimeoutMs);
    settle(m);
    const mfr::ImageRGBA8 shown = w->view().renderImage(size);
    // mfr render with the same representations and camera draws the same image.
    QTemporaryDir dir;
    const QString scene = dir.filePath("pept.mfrscene"), cliPng = dir.filePath("cli.png");
    {
      const mfr::Camera c = m.camera();
      const QJsonObject view{{"name", "here"},
                             {"eye", QJsonArray{c.eye.x, c.eye.y, c.eye.z}},
                             {"target", QJsonArray{c.target.x, c.target.y, c.target.z}},
                             {"up", QJsonArray{c.up.x, c.up.y, c.up.z}},
                             {"fovy", c.fovyDegrees},
                             {"near", c.nearPlane},
                             {"far", c.farPlane}};
      const QJsonObject object{{"file", pept}, {"molecule", "surface,sticks"}};
      QFile f(scene);
      QVERIFY(f.open(QIODevice::WriteOnly));
      f.write(QJsonDocument(QJsonObject{{"objects", QJsonArray{object}}, {"views", QJsonArray{view}}}).toJson());
    }
    QString out;
    QCOMPARE(
        runProgram(MFR_CLI, {"render", scene, "--view", "here", "-m", "abuffer-ll", "--size", "160x120", "-o", cliPng},
                   &out),
        0);
    const int diff = maxChannelDifference(shown, mfr::readPng(cliPng.toStdString()));
    qInfo("viewer sticks,surface vs mfr render: max channel difference %d", diff);
    QVERIFY2(diff >= 0 && diff <= 1, qPrintable(out));
    // A session keeps them.
    const QString sessionPath = dir.filePath("pept.mfrsession");
    w->saveSession(sessionPath);
    QFile saved(sessionPath);
    QVERIFY(saved.open(QIODevice::ReadOnly));
    QCOMPARE(QJsonDocument::fromJson(saved.readAll()).object().value("molecule").toString(),
             QStringLiteral("sticks,surface"));
    auto again = reopenedSession(*w, sessionPath, size);
    QVERIFY(again);
    QTRY_VERIFY_WITH_TIMEOUT(again->model().hasScene() && again->model().framesRendered() > 0, kTimeoutMs);
    QCOMPARE(again->model().moleculeStyle()->text(), std::string("sticks,surface"));
    QCOMPARE(again->model().scene().objects.size(), std::size_t{2});
    // mfrview --molecule: the same parts; a bad list or a file that is no molecule is refused.
    const QString viewerPng = dir.filePath("viewer.png");
    QCOMPARE(runProgram(MFRVIEW, {pept, "--molecule", "sticks", "--screenshot", viewerPng, "--size", "64x48"}, &out),
             0);
    QCOMPARE(runProgram(MFRVIEW, {pept, "--molecule", "cartoon", "--screenshot", viewerPng, "--size", "64x48"}, &out),
             0);
    QCOMPARE(runProgram(MFRVIEW, {pept, "--molecule", "ribbon", "--screenshot", viewerPng, "--size", "64x48"}, &out),
             2);
    QVERIFY2(out.contains("--molecule ribbon: unknown representation 'ribbon'"), qPrintable(out));
    QCOMPARE(
        runProgram(MFRVIEW, {"@sample", "--molecule", "sticks", "--screenshot", viewerPng, "--size", "64x48"}, &out),
        1);
    QVERIFY2(out.contains("can be chosen only for a molecule file"), qPrintable(out));
  }
};

QTEST_MAIN(ViewerTest)
#include "test_viewer.moc"
