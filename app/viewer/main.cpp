// mfrview: the Qt 6 viewer. Besides the interactive window, command-line options make it
// scriptable: --screenshot renders the view at --size through mfrcore (the `mfr render` path),
// writes a PNG and quits; --window-screenshot grabs the whole window once everything is drawn.
// libepoxy's header before any of Qt's OpenGL ones (QOpenGLContext), which would bring GL/gl.h.
#include <epoxy/gl.h>

#include <clocale>
#include <filesystem>
#include <system_error>

#include <QApplication>
#include <QCoreApplication>
#include <QCommandLineParser>
#include <QElapsedTimer>
#include <QFileInfo>
#include <QImage>
#include <QJsonDocument>
#include <QJsonObject>
#include <QOpenGLContext>
#include <QRegularExpression>
#include <QStatusBar>
#include <QSurfaceFormat>
#include <QLayout>
#include <QTimer>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <cstring>
#include <exception>
#include <map>
#include <utility>
#include <memory>
#include <optional>
#include <thread>

#include "main_window.hpp"
#include "session.hpp"
#include "mfr/error.hpp"
#include "mfr/json_text.hpp"
#include "mfr/host_memory.hpp"
#include "mfr/image.hpp"
#include "mfr/io_util.hpp"
#include "mfr/operation_settings.hpp"
#include "mfr/render.hpp"
#include "mfr/scene/clip_box.hpp"
#include "mfr/scene/scene.hpp"
#include "mfr/scene/section.hpp"
#include "render_view.hpp"
#include "viewer_model.hpp"

namespace {

struct CommandLine {
  QString scene = QStringLiteral("@sample");
  QString session, screenshot, windowScreenshot, view, method, op;
  QString field;                                  // --field: the array or grid of a volume file
  std::optional<mfr::MoleculeStyle> molecule;     // --molecule: a molecule file's representations
  QString colorBy, colorMap;                      // --color-by, --color-map: surfaces coloured by a field
  std::optional<glm::dvec2> colorRange;           // --color-range
  std::vector<double> contour;                    // --contour: isosurfaces of the current volume
  QString contourVolume;                          // --contour NAME=…: of that volume instead
  QString contourText;                            // --contour as given, for messages
  bool legend = false;                            // --legend: the scalar bar in the --screenshot
  std::map<QString, QJsonObject> pluginSettings;  // by plugin id
  QSize size{800, 600}, windowSize;
  std::map<std::string, std::string> params;
  double thickness = 0.0;  // --thickness (operation zthickness); 0: the scene's default
  double step = 0.0;       // --step (operation volume); 0: the volume's default
  // --clip, --section: as mfr render's; "none" removes the scene's own.
  std::optional<std::optional<mfr::Bounds>> clip;
  std::optional<std::optional<mfr::SectionPlane>> section;
  QString clipText, sectionText;  // as given, for messages
};

// A scripted run waits at most this long for the scene, the first frame and background work.
constexpr int kFirstFrameSeconds = 120;

[[noreturn]] void fail(const QString& message, int code) {
  std::fprintf(stderr, "mfrview: %s\n", qPrintable(message));
  std::exit(code);
}

QSize parseSize(const QString& option, const QString& text) {
  const QStringList parts = text.toLower().split(QLatin1Char('x'));
  bool okW = false, okH = false;
  const QSize size = parts.size() == 2 ? QSize(parts[0].toInt(&okW), parts[1].toInt(&okH)) : QSize();
  if (!okW || !okH) fail(QStringLiteral("%1 %2: expected WIDTHxHEIGHT, e.g. 800x600").arg(option, text), 2);
  try {
    // The reason in mfr's words (0x0 said "expected WIDTHxHEIGHT", as if the form were wrong).
    mfr::validateImageSize((option + QLatin1Char(' ') + text).toStdString(), size.width(), size.height());
  } catch (const mfr::Error& e) {
    fail(QString::fromUtf8(e.what()), 2);
  }
  return size;
}

// Needs a QCoreApplication. `sessionArgs`: the --session option and its value, which
// takeSessionOption kept from Qt.
CommandLine parseCommandLine(const QStringList& sessionArgs) {
  QCommandLineParser parser;
  parser.setApplicationDescription(QStringLiteral("Multifragment rendering viewer"));
  parser.addHelpOption();
  parser.addVersionOption();
  parser.addPositionalArgument(QStringLiteral("scene"),
                               QStringLiteral("Model file, .mfrscene, .mfrsession or @sample (default)"));
  const QCommandLineOption method({QStringLiteral("m"), QStringLiteral("method")}, QStringLiteral("Render method."),
                                  QStringLiteral("name"));
  const QCommandLineOption op(
      QStringLiteral("op"),
      QStringLiteral("Operation: auto (the method's own; volume on a scene with a volume), oit, hybrid, "
                     "csg, zthickness or volume."),
      QStringLiteral("name"));
  const QCommandLineOption thickness(
      QStringLiteral("thickness"),
      QStringLiteral("Operation zthickness: slab thickness in scene units (default: 1 % of the scene's diagonal)."),
      QStringLiteral("length"));
  const QCommandLineOption step(
      QStringLiteral("step"),
      QStringLiteral("Operation volume: ray-march step in scene units (default: half the volume's grid spacing)."),
      QStringLiteral("length"));
  const QCommandLineOption field(
      QStringLiteral("field"),
      QStringLiteral("Volume file: the point-data array (.vti, .vtk) or grid (.vdb) to read instead of the default."),
      QStringLiteral("name"));
  const QCommandLineOption molecule(
      QStringLiteral("molecule"),
      QStringLiteral(
          "Molecule file (.pdb, .cif): spheres (default), sticks, ball-and-stick, cartoon, surface, or several joined "
          "by ',', each on all parts or on @polymer, @ligands or @water (as mfr render; the Scene panel's "
          "Molecule row)."),
      QStringLiteral("representations"));
  const QCommandLineOption colorBy(
      QStringLiteral("color-by"),
      QStringLiteral("Colour every part that has this point-data or cell-data array by it (as mfr render)."),
      QStringLiteral("field"));
  const QCommandLineOption colorMap(QStringLiteral("color-map"),
                                    QStringLiteral("Colour map of --color-by (default cool-warm)."),
                                    QStringLiteral("name"));
  const QCommandLineOption colorRange(
      QStringLiteral("color-range"),
      QStringLiteral("Values at the ends of the colour map (default: the field's range)."), QStringLiteral("lo,hi"));
  const QCommandLineOption contour(
      QStringLiteral("contour"),
      QStringLiteral("Isosurfaces of the scene's (current) volume at these values, as parts; the volume is hidden "
                     "(the Volume panel's Isosurfaces). VOLUME=v1,v2,... names the volume of a scene with several "
                     "(as mfr render)."),
      QStringLiteral("v1,v2,..."));
  const QCommandLineOption legend(
      QStringLiteral("legend"),
      QStringLiteral("--screenshot: draw the field colouring's colour map with its values into it (as mfr render)."));
  const QCommandLineOption param({QStringLiteral("p"), QStringLiteral("param")},
                                 QStringLiteral("Method parameter (repeatable)."), QStringLiteral("name=value"));
  const QCommandLineOption view(QStringLiteral("view"), QStringLiteral("Named view of the scene, or 'fit'."),
                                QStringLiteral("name"));
  const QCommandLineOption size({QStringLiteral("s"), QStringLiteral("size")},
                                QStringLiteral("Image size for --screenshot (default 800x600)."),
                                QStringLiteral("WxH"));
  const QCommandLineOption screenshot(QStringLiteral("screenshot"),
                                      QStringLiteral("Render the view at --size, write this PNG and quit."),
                                      QStringLiteral("file.png"));
  const QCommandLineOption windowScreenshot(
      QStringLiteral("window-screenshot"), QStringLiteral("Grab the whole window once drawn, write this PNG and quit."),
      QStringLiteral("file.png"));
  const QCommandLineOption windowSize(QStringLiteral("window-size"), QStringLiteral("Window size."),
                                      QStringLiteral("WxH"));
  const QCommandLineOption clip(
      QStringLiteral("clip"),
      QStringLiteral(
          "Clip box: only what lies inside is drawn (the Clip panel's box); 'none' removes the scene's own."),
      QStringLiteral("xmin,ymin,zmin,xmax,ymax,zmax"));
  const QCommandLineOption section(
      QStringLiteral("section"),
      QStringLiteral("Section plane, as mfr render's: AXIS=VALUE (x, y, z, -x, -y, -z; keeps the side the axis points "
                     "to) or px,py,pz,nx,ny,nz, optionally :nocaps and/or :slice; 'none' removes the scene's own."),
      QStringLiteral("plane"));
  const QCommandLineOption session(
      QStringLiteral("session"),
      QStringLiteral("Session file to open (the same as giving it as the scene; File > Save session writes one)."),
      QStringLiteral("file.mfrsession"));
  const QCommandLineOption pluginSettings(QStringLiteral("plugin-settings"),
                                          QStringLiteral("Settings of a plugin, as in a session file (repeatable)."),
                                          QStringLiteral("id={json}"));
  parser.addOptions({method,     op,      thickness, step,    field,         molecule, colorBy,    colorMap,
                     colorRange, contour, legend,    param,   view,          size,     screenshot, windowScreenshot,
                     windowSize, clip,    section,   session, pluginSettings});
  // Unknown options and missing values are command-line errors, exit 2 as every other (process()
  // exits 1 for them); process() then does only what parse() does not: -h, --help-all, --version.
  QStringList arguments = QCoreApplication::arguments();
  // Before a "--", which ends the options; a --session without its value goes last of the
  // options, so that the parser says "Missing value" instead of taking the next option as it.
  const bool valueMissing = !sessionArgs.isEmpty() && sessionArgs.constLast() == QStringLiteral("--session");
  qsizetype at = valueMissing ? arguments.indexOf(QStringLiteral("--")) : 1;
  if (at < 0) at = arguments.size();
  for (const QString& a : sessionArgs) arguments.insert(at++, a);
  if (!parser.parse(arguments)) fail(parser.errorText(), 2);
  parser.process(arguments);
  // An empty value is refused, as mfr refuses it: read as "not given", --screenshot '' opened the
  // interactive window and never quit.
  for (const QCommandLineOption& option :
       {method,           op,         thickness, step,    field,   molecule,      colorBy,
        colorMap,         colorRange, contour,   param,   view,    size,          screenshot,
        windowScreenshot, windowSize, clip,      section, session, pluginSettings})
    for (const QString& value : parser.values(option))
      if (value.isEmpty()) fail(QStringLiteral("--%1: an empty value").arg(option.names().constLast()), 2);

  CommandLine cl;
  if (parser.positionalArguments().size() > 1)
    fail(QStringLiteral("expected one scene, got %1").arg(parser.positionalArguments().size()), 2);
  if (!parser.positionalArguments().isEmpty()) cl.scene = parser.positionalArguments().first();
  if (parser.isSet(session)) {
    if (parser.values(session).size() > 1)
      fail(QStringLiteral("--session %1: more than one session is given").arg(parser.values(session).constLast()), 2);
    if (!parser.positionalArguments().isEmpty())
      fail(QStringLiteral("--session %1: a scene is given too (%2); give one of the two")
               .arg(parser.value(session), cl.scene),
           2);
    cl.scene = cl.session = parser.value(session);
  }
  if (MainWindow::isSessionFile(cl.scene)) cl.session = cl.scene;  // by its name or its "format"
  cl.method = parser.value(method);
  cl.op = parser.value(op);
  if (parser.isSet(thickness)) {
    bool ok = false;
    cl.thickness = parser.value(thickness).toDouble(&ok);
    if (!ok || !(cl.thickness > 0.0) || !std::isfinite(cl.thickness))
      fail(QStringLiteral("--thickness %1: must be a positive length in scene units").arg(parser.value(thickness)), 2);
  }
  if (parser.isSet(step)) {
    bool ok = false;
    cl.step = parser.value(step).toDouble(&ok);
    if (!ok || !(cl.step > 0.0) || !std::isfinite(cl.step))
      fail(QStringLiteral("--step %1: must be a positive length in scene units").arg(parser.value(step)), 2);
  }
  cl.field = parser.value(field);
  if (parser.isSet(field) && cl.field.isEmpty())
    fail(QStringLiteral("--field: expected the name of an array or grid"), 2);
  if (!cl.field.isEmpty() && !cl.session.isEmpty())
    fail(QStringLiteral("--field %1: a session keeps its volumes' own fields").arg(cl.field), 2);
  if (parser.isSet(molecule)) {
    if (!cl.session.isEmpty())
      fail(QStringLiteral("--molecule %1: a session keeps its molecule's own representations")
               .arg(parser.value(molecule)),
           2);
    try {
      cl.molecule = mfr::MoleculeStyle::parse(parser.value(molecule).toStdString(),
                                              "--molecule " + parser.value(molecule).toStdString());
    } catch (const mfr::Error& e) {
      fail(QString::fromUtf8(e.what()), 2);
    }
  }
  cl.colorBy = parser.value(colorBy);
  cl.colorMap = parser.value(colorMap);
  if ((parser.isSet(colorMap) || parser.isSet(colorRange)) && cl.colorBy.isEmpty())
    fail(QStringLiteral("--%1: needs --color-by").arg(parser.isSet(colorMap) ? "color-map" : "color-range"), 2);
  if (parser.isSet(colorRange)) {
    const QStringList ends = parser.value(colorRange).split(QLatin1Char(','));
    bool okLow = false, okHigh = false;
    const double low = ends.size() == 2 ? ends[0].toDouble(&okLow) : 0.0;
    const double high = ends.size() == 2 ? ends[1].toDouble(&okHigh) : 0.0;
    if (!okLow || !okHigh || !std::isfinite(low) || !std::isfinite(high) || !(high > low))
      fail(QStringLiteral("--color-range %1: expected LO,HI with LO < HI").arg(parser.value(colorRange)), 2);
    cl.colorRange = glm::dvec2(low, high);
  }
  cl.legend = parser.isSet(legend);
  if (parser.isSet(contour)) {
    // VOLUME=V1,… as mfr render reads it, at the last '=' (a name may hold one, values never do).
    cl.contourText = parser.value(contour);
    QString values = cl.contourText;
    if (const qsizetype eq = values.lastIndexOf(QLatin1Char('=')); eq >= 0) {
      cl.contourVolume = values.left(eq);
      values = values.mid(eq + 1);
    }
    for (const QString& item : values.split(QLatin1Char(','))) {
      bool ok = false;
      const double v = item.toDouble(&ok);
      if (!ok || !std::isfinite(v))
        fail(QStringLiteral("--contour %1: '%2' is not a number").arg(parser.value(contour), item), 2);
      cl.contour.push_back(v);
    }
  }
  try {
    if (parser.isSet(clip)) {
      const std::string text = parser.value(clip).toStdString();
      cl.clipText = parser.value(clip);
      cl.clip = text == "none" ? std::optional<mfr::Bounds>() : mfr::parseClipBox(text, "--clip " + text);
    }
    if (parser.isSet(section)) {
      const std::string text = parser.value(section).toStdString();
      cl.sectionText = parser.value(section);
      cl.section =
          text == "none" ? std::optional<mfr::SectionPlane>() : mfr::parseSectionPlane(text, "--section " + text);
    }
  } catch (const mfr::Error& e) {
    fail(QString::fromUtf8(e.what()), 2);
  }
  cl.view = parser.value(view);
  cl.screenshot = parser.value(screenshot);
  cl.windowScreenshot = parser.value(windowScreenshot);
  // Before any work, as mfr render checks -o: a name that says another format, a missing folder,
  // and an output that is the scene or session read, or the other output, by any name (a link
  // named like a PNG wrote the picture over its session; both screenshots to one file kept the
  // last; a bug hunt).
  try {
    using Role = mfr::CommandFile::Role;
    std::vector<mfr::CommandFile> files = {
        {cl.session.isEmpty() ? "scene" : "session", cl.scene.toStdString(), Role::kScene},
        {"--screenshot", cl.screenshot.toStdString(), Role::kOutput},
        {"--window-screenshot", cl.windowScreenshot.toStdString(), Role::kOutput}};
    // The scene a session names is read too (a link named like a PNG to it was written over; a
    // review). A session that cannot be read is refused later, with its own reason.
    if (!cl.session.isEmpty() && (!cl.screenshot.isEmpty() || !cl.windowScreenshot.isEmpty())) {
      try {
        files.insert(files.begin() + 1,
                     {"the session's scene", readSessionFile(cl.session).scenePath.toStdString(), Role::kScene});
      } catch (const mfr::Error&) {
      }
    }
    for (const mfr::CommandFile& output : files)
      if (output.role == Role::kOutput && !output.path.empty()) mfr::checkPngOutputName(output.option, output.path);
    mfr::checkCommandFiles(files);
  } catch (const mfr::Error& e) {
    fail(QString::fromUtf8(e.what()), 2);
  }
  // Only --screenshot's picture uses them: with --window-screenshot alone, or in the window, they
  // were taken without a word (a bug hunt).
  if (cl.screenshot.isEmpty())
    for (const auto& [option, name] : {std::pair{&size, "--size"}, std::pair{&legend, "--legend"}})
      if (parser.isSet(*option))
        fail(QStringLiteral("%1: only --screenshot uses it%2")
                 .arg(QLatin1String(name),
                      cl.windowScreenshot.isEmpty()
                          ? QString()
                          : QStringLiteral(" (--window-screenshot grabs the window at --window-size)")),
             2);
  if (parser.isSet(size)) cl.size = parseSize(QStringLiteral("--size"), parser.value(size));
  if (parser.isSet(windowSize)) cl.windowSize = parseSize(QStringLiteral("--window-size"), parser.value(windowSize));
  for (const QString& p : parser.values(param)) {
    const qsizetype eq = p.indexOf(QLatin1Char('='));
    if (eq <= 0) fail(QStringLiteral("--param %1: expected name=value").arg(p), 2);
    // -p k=4 -p k=2 meant one of them; the last silently won.
    if (!cl.params.emplace(p.left(eq).toStdString(), p.mid(eq + 1).toStdString()).second)
      fail(QStringLiteral("--param %1: '%2' is given twice").arg(p, p.left(eq)), 2);
  }
  for (const QString& p : parser.values(pluginSettings)) {
    const qsizetype eq = p.indexOf(QLatin1Char('='));
    const QJsonDocument json = eq > 0 ? QJsonDocument::fromJson(p.mid(eq + 1).toUtf8()) : QJsonDocument();
    if (!json.isObject()) fail(QStringLiteral("--plugin-settings %1: expected id={json object}").arg(p), 2);
    if (const std::optional<std::string> repeated = mfr::repeatedJsonKey(p.mid(eq + 1).toStdString()))
      fail(QStringLiteral("--plugin-settings %1: '%2' is given twice")
               .arg(p.left(eq), QString::fromStdString(*repeated)),
           2);
    // As -p: two settings of one plugin meant one of them, and the last silently won.
    if (!cl.pluginSettings.emplace(p.left(eq), json.object()).second)
      fail(QStringLiteral("--plugin-settings: plugin '%1' is given twice").arg(p.left(eq)), 2);
  }
  return cl;
}

// What a session manager hands back to Qt's -session when it restores a window: an XSMP client
// id (libSM's: hex digits, or "2" and a UUID with its hyphens) and Qt's key after '_'. A name with
// a dot or a slash, or of a file that exists, is the user's session file; and with no session
// manager running nothing hands one back.
bool isSessionManagerId(const char* value) {
  // libSM's ids are "1" and 35 hex digits, or "2" and a UUID; Qt appends "_" and its key. A word
  // the user meant as a file ("-session work", none of that name) was taken as an id (review 27).
  if (std::getenv("SESSION_MANAGER") == nullptr || (*value != '1' && *value != '2') || std::strlen(value) < 20)
    return false;
  for (const char* c = value; *c; ++c)
    if (!std::isalnum(static_cast<unsigned char>(*c)) && *c != '_' && *c != '-') return false;
  return !QFileInfo::exists(QString::fromLocal8Bit(value));
}

// QGuiApplication takes -session and --session with their value for X11 session management, so
// `mfrview --session s.mfrsession` opened @sample without a word. mfrview's own --session (two
// dashes) is taken out of argv before Qt sees it and handed to the parser; -session stays Qt's.
QStringList takeSessionOption(int& argc, char** argv) {
  QStringList taken;
  int kept = 1;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--") == 0) {  // what follows is positional
      while (i < argc) argv[kept++] = argv[i++];
      break;
    }
    if (std::strcmp(argv[i], "--session") == 0) {
      taken << QStringLiteral("--session");
      if (i + 1 < argc) taken << QString::fromLocal8Bit(argv[++i]);  // else the parser's "Missing value"
    } else if (std::strncmp(argv[i], "--session=", 10) == 0) {
      taken << QString::fromLocal8Bit(argv[i]);
    } else if (std::strcmp(argv[i], "-session") == 0 && i + 1 < argc && !isSessionManagerId(argv[i + 1])) {
      // The user's --session with one dash: Qt took it and @sample opened, exit 0 (a review; a
      // misspelt file too, and on every desktop, where a session manager runs).
      fail(QStringLiteral("-session %1: one dash is Qt's X11 session-management option (an id%2); open a session "
                          "file with --session %1")
               .arg(QString::fromLocal8Bit(argv[i + 1]), std::getenv("SESSION_MANAGER") == nullptr
                                                             ? QStringLiteral(", and no session manager runs")
                                                             : QString()),
           2);
    } else {
      argv[kept++] = argv[i];
    }
  }
  argc = kept;
  argv[argc] = nullptr;
  return taken;
}

// --help and --version need no display: answered by a QCoreApplication, which opens none.
bool mentionsHelpOrVersion(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)
    for (const char* option : {"-h", "--help", "-?", "--help-all", "-v", "--version"})
      if (std::strcmp(argv[i], option) == 0) return true;
  return false;
}

// Qt's xcb platform aborts with a paragraph (and exit 134) when there is no X server to connect
// to; the usual case, no display at all, is said in one line instead.
bool displayMissing(int argc, char** argv) {
  const QByteArray platform = qgetenv("QT_QPA_PLATFORM");
  for (int i = 1; i < argc; ++i)  // the user chose one (Qt takes -platform and --platform): Qt checks it
    if (std::strcmp(argv[i], "-platform") == 0 || std::strcmp(argv[i], "--platform") == 0) return false;
  if (!platform.isEmpty() && !platform.startsWith("xcb")) return false;
  return qEnvironmentVariableIsEmpty("DISPLAY") &&
         (!platform.isEmpty() || qEnvironmentVariableIsEmpty("WAYLAND_DISPLAY"));
}

void refuseMissingDisplay(int argc, char** argv) {
  if (!displayMissing(argc, argv)) return;
  fail(QStringLiteral("no display: DISPLAY is not set (mfrview needs X11 or Wayland with OpenGL, or xvfb-run; "
                      "mfr render needs none)"),
       1);
}

// Qt reads arguments as UTF-8 and turns other bytes into U+FFFD: a Latin-1 name (caf\xE9.obj) was
// "no such file", and as a screenshot's name wrote another file, exit 0 (a bug hunt). Refused:
// mfr takes such names as they are.
void refuseArgumentsQtCannotRead(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)
    if (QString::fromLocal8Bit(argv[i]).toLocal8Bit() != QByteArray(argv[i]))
      fail(QStringLiteral("argument '%1' is not valid UTF-8: mfrview reads names as UTF-8 (rename the file, or use "
                          "mfr, which takes any name)")
               .arg(QString::fromLocal8Bit(argv[i])),
           2);
}

}  // namespace

int main(int argc, char** argv) {
  refuseArgumentsQtCannotRead(argc, argv);
  const QStringList sessionArgs = takeSessionOption(argc, argv);
  if (mentionsHelpOrVersion(argc, argv) || displayMissing(argc, argv)) {
    QCoreApplication core(argc, argv);
    QCoreApplication::setApplicationName(QStringLiteral("mfrview"));
    QCoreApplication::setApplicationVersion(QStringLiteral(MFR_VERSION));
    // Prints the help or the version and exits; returns only where "-v" was another option's
    // value (--field -v), and the viewer starts as usual. Without a display, a command line it
    // cannot read is refused first, exit 2, as with one (mfrview --bogus said "no display").
    (void)parseCommandLine(sessionArgs);
  }
  refuseMissingDisplay(argc, argv);
  // Every GL context mfrview creates is 4.5 core, like mfrcore's headless one.
  QSurfaceFormat format;
  format.setVersion(4, 5);
  format.setProfile(QSurfaceFormat::CoreProfile);
  format.setDepthBufferSize(24);
  QSurfaceFormat::setDefaultFormat(format);

  QApplication app(argc, argv);
  // QApplication takes the user's locale for all of C's categories; mfrcore reads parameters and
  // scene numbers with std::stod, which under a comma-decimal locale (de_DE) read "0.9" as 0.
  // Qt's own widgets format numbers by QLocale, which this does not touch.
  std::setlocale(LC_NUMERIC, "C");
  QApplication::setApplicationName(QStringLiteral("mfrview"));
  QApplication::setOrganizationName(QStringLiteral("mfr"));
  // Ties the window to the installed desktop entry (its icon and name on Wayland's task bars).
  QGuiApplication::setDesktopFileName(QStringLiteral("mfrview"));
  QApplication::setApplicationVersion(QStringLiteral(MFR_VERSION));
  const CommandLine cl = parseCommandLine(sessionArgs);
  const bool scripted = !cl.screenshot.isEmpty() || !cl.windowScreenshot.isEmpty();
  try {
    (void)mfr::availableHostMemory();  // a malformed MFR_MEMORY_LIMIT_MIB is refused before any work
  } catch (const mfr::Error& e) {
    fail(QString::fromStdString(e.what()), 1);
  }
  {
    // The view is a QOpenGLWidget: on a platform without OpenGL windows (offscreen, minimal, vnc)
    // Qt would crash at the first paint instead of saying so.
    QOpenGLContext probe;
    if (!probe.create())
      fail(QStringLiteral("cannot create an OpenGL context on the Qt platform '%1' (mfrview needs a display with "
                          "OpenGL: X11 or Wayland, or xvfb-run; mfr render needs none)")
               .arg(QGuiApplication::platformName()),
           1);
  }

  // Scripted runs must not depend on (or change) what the last interactive session left behind.
  MainWindow window(MainWindow::Options{.restoreSettings = !scripted, .loadPlugins = true});
  ViewerModel& model = window.model();
  for (const auto& [id, settings] : cl.pluginSettings) {
    QStringList loaded, failed;
    for (const PluginRecord& r : window.plugins().records()) {
      if (r.plugin) loaded << r.id;
      if (!r.plugin && !r.error.isEmpty()) failed << QStringLiteral("%1: %2").arg(r.file, r.error);
    }
    // Files that failed to load are named too: a truncated plugin was not mentioned (a bug hunt).
    if (!loaded.contains(id))
      fail(QStringLiteral("--plugin-settings %1: no plugin of that id is loaded (loaded: %2%3)")
               .arg(id, loaded.isEmpty() ? QStringLiteral("none") : loaded.join(QStringLiteral(", ")),
                    failed.isEmpty() ? QString() : QStringLiteral("; failed: ") + failed.join(QStringLiteral("; "))),
           2);
    for (const PluginRecord& r : window.plugins().records())
      if (r.plugin && r.id == id)
        if (const QString problem = pluginSettingsProblem(*r.plugin, settings); !problem.isEmpty())
          fail(QStringLiteral("--plugin-settings %1: %2").arg(id, problem), 2);
  }
  if (!cl.windowSize.isEmpty()) window.resize(cl.windowSize);
  if (!cl.method.isEmpty()) {
    if (!model.methodNames().contains(cl.method))
      fail(QStringLiteral("--method %1: unknown method (available: %2)").arg(cl.method, model.methodNames().join(", ")),
           2);
    model.setMethod(cl.method);
  }
  if (!cl.op.isEmpty()) model.setOperation(cl.op);
  if (!cl.params.empty()) model.setParams(cl.params);

  // Plugins' notes on stderr as the session's own (scripted runs have no status bar), except
  // those that end a scripted run as a refusal of --plugin-settings.
  bool quietNotes = false;
  QObject::connect(&model, &ViewerContext::noted, &window, [&quietNotes, &window](const QString& text) {
    if (!quietNotes) std::cerr << "note: " << (window.notePrefix() + text).toStdString() << "\n";
  });
  // Applied once the scene has loaded: the view and, for scripted runs, the pictures.
  bool applied = false;
  // Method parameters that --plugin-settings set (the budget panel's budget_mib), by plugin: a
  // render's refusal of one names those settings, not a --param the command line lacks.
  std::map<std::string, QString> paramsOfPlugin;
  QObject::connect(&model, &ViewerModel::sceneLoaded, &window, [&] {
    if (applied) return;
    applied = true;
    // A session sets its method, operation and parameters as it loads, after the lines above ran:
    // the command line's win, as --view and --clip do (they were dropped without a word; a bug hunt).
    if (!cl.session.isEmpty()) {
      if (!cl.method.isEmpty()) model.setMethod(cl.method);
      if (!cl.op.isEmpty()) model.setOperation(cl.op);
      if (!cl.params.empty()) model.setParams(cl.params);
    }
    // What loading could not do as asked (no ligands for sticks@ligands): on stderr as mfr render
    // prints it, since a scripted run has no status bar to show it in.
    if (scripted)
      for (const std::string& note : model.scene().notes) std::cerr << "note: " << note << "\n";
    // A new scene starts at the default thickness (scene units): --thickness applies to this one.
    if (cl.thickness > 0.0) model.setZThickness(cl.thickness);
    if (cl.step > 0.0) model.setVolumeStep(cl.step);  // likewise the volume step
    // What mfr render refuses for this scene, refused here too (a box that holds nothing drew an
    // empty image with exit 0; ':slice' without a volume was dropped).
    const auto refuse = [&](const QString& message) {
      if (scripted) fail(message, 1);
      window.statusBar()->showMessage(message);
    };
    if (!cl.contour.empty()) {
      // Before --color-by, which then colours them too.
      // The named volume's (as mfr render), else the current one's (the Volume panel's).
      QString reason;
      int volume = model.currentVolume();
      const std::vector<mfr::Volume>& volumes = model.scene().volumes;
      if (!cl.contourVolume.isEmpty()) {
        const auto named = std::find_if(volumes.begin(), volumes.end(), [&](const mfr::Volume& v) {
          return QString::fromStdString(v.name) == cl.contourVolume;
        });
        QStringList names;
        for (const mfr::Volume& v : volumes) names << QString::fromStdString(v.name);
        if (named == volumes.end())
          reason = QStringLiteral("no volume '%1' in scene '%2' (%3)")
                       .arg(cl.contourVolume, QString::fromStdString(model.scene().name),
                            names.isEmpty() ? QStringLiteral("it has none")
                                            : QStringLiteral("volumes: ") + names.join(QStringLiteral(", ")));
        else
          volume = static_cast<int>(named - volumes.begin());
      }
      if (reason.isEmpty()) reason = model.setIsosurfacesAt(volume, cl.contour, 0.5);
      if (!reason.isEmpty()) {
        const QString message = QStringLiteral("--contour %1: %2").arg(cl.contourText, reason);
        if (scripted) fail(message, 1);
        window.statusBar()->showMessage(message);
      } else if (cl.view.isEmpty() && cl.session.isEmpty()) {
        // The fit view of what is drawn now, as mfr render frames it (the view framed the hidden
        // volume's box: the two programs' images differed; a bug hunt). A session's camera stays,
        // as with its other settings that --contour does not name (it was replaced; a bug hunt).
        model.setCamera(model.scene().view("fit"));
      }
    }
    if (!cl.colorBy.isEmpty() &&
        !model.setFieldColoring(cl.colorBy, cl.colorMap.isEmpty() ? QStringLiteral("cool-warm") : cl.colorMap,
                                cl.colorRange)) {
      const QString message = QStringLiteral("--color-by %1: %2").arg(cl.colorBy, model.fieldColoringError());
      if (scripted) fail(message, 1);
      window.statusBar()->showMessage(message);
    }
    // After the isosurfaces, as mfr render checks: they hide the volume and widen the bounds.
    bool clipOk = true, sectionOk = true;
    if (cl.clip && *cl.clip) {
      try {
        mfr::requireClipBoxHoldsScene(model.scene(), **cl.clip, "--clip " + cl.clipText.toStdString());
      } catch (const mfr::Error& e) {
        clipOk = false;
        refuse(QString::fromUtf8(e.what()));
      }
    }
    if (cl.section && *cl.section && (*cl.section)->slice && model.scene().volumes.empty()) {
      sectionOk = false;
      refuse(QStringLiteral("--section %1: slice: scene '%2' has no volume")
                 .arg(cl.sectionText, QString::fromStdString(model.scene().name)));
    }
    if (cl.clip && clipOk) model.setClipBox(*cl.clip);
    if (cl.section && sectionOk) model.setSection(*cl.section);
    // What the section could not do as asked, on stderr as mfr render prints it (a scripted run had
    // none of it; a bug hunt).
    if (scripted && model.section() && model.sectionError().isEmpty())
      for (const std::string& note : mfr::sectionNotes(*model.section(), model.sectionReport()))
        std::cerr << "note: " << note << "\n";
    if (!cl.view.isEmpty()) {
      try {
        model.setCamera(model.scene().view(cl.view.toStdString()));
      } catch (const std::exception& e) {
        if (scripted) fail(QString::fromUtf8(e.what()), 1);
        window.statusBar()->showMessage(QString::fromUtf8(e.what()));
      }
    }
    for (const PluginRecord& r : window.plugins().records())
      if (r.plugin && cl.pluginSettings.contains(r.id)) {
        // A value the plugin takes other than as given (out of range, a part or preset the scene
        // lacks) is its note; given on a scripted command line it is a refusal, as mfr's options.
        QString first;
        const QMetaObject::Connection noted =
            QObject::connect(&model, &ViewerContext::noted, &window, [&first](const QString& text) {
              if (first.isEmpty()) first = text;
            });
        quietNotes = scripted;
        const std::map<std::string, std::string> before = model.params();
        r.plugin->loadSettings(cl.pluginSettings.at(r.id));
        for (const auto& [name, value] : model.params())
          if (!before.contains(name) || before.at(name) != value) paramsOfPlugin[name] = r.id;
        quietNotes = false;
        QObject::disconnect(noted);
        if (first.startsWith(r.id + QStringLiteral(": "))) first = first.mid(r.id.size() + 2);
        if (scripted && !first.isEmpty()) fail(QStringLiteral("--plugin-settings %1: %2").arg(r.id, first), 2);
      }
    // The command line's thickness and step win over the plugins' settings, as over a session's
    // (a hybridvolume "step" drew instead of --step; a bug hunt).
    if (cl.thickness > 0.0) model.setZThickness(cl.thickness);
    if (cl.step > 0.0) model.setVolumeStep(cl.step);
    // --thickness and --step for an operation that does not use them, refused as by mfr render
    // (they were kept for later and drew the same image, with no word that they did nothing).
    // After the plugins' settings, which may show the volume; either side of compare mode may use them.
    if (cl.step > 0.0 && model.scene().volumes.empty()) {
      refuse(QStringLiteral("--step: scene '%1' has no volume").arg(QString::fromStdString(model.scene().name)));
    } else {
      const auto unusedOn = [&](int side) {
        mfr::RenderRequest given;
        given.method = model.methodOf(side).toStdString();
        given.operation = model.operationOf(side).toStdString();
        given.thickness = cl.thickness;
        given.volumeStep = cl.step;
        return mfr::unusedOperationSetting(given, model.scene());
      };
      std::optional<mfr::UnusedOperationSetting> unused = unusedOn(0);
      if (unused && model.compareEnabled() && !unusedOn(1)) unused.reset();
      if (unused) refuse(QString::fromStdString("--" + unused->name + ": " + unused->reason));
    }
    // A -p value that acts only with another's value the method does not have (pool_mib without
    // pool=fixed), refused as by mfr render: the command line's values, over the others in force.
    if (!cl.params.empty()) {
      mfr::RenderRequest given;
      given.method = model.method().toStdString();
      given.params = cl.params;
      if (const mfr::MethodInfo* info = mfr::findMethodInfo(given.method))
        for (const mfr::ParamSpec& spec : info->params)
          if (spec.onlyWith.empty() && !given.params.contains(spec.name) && model.params().contains(spec.name))
            given.params[spec.name] = model.params().at(spec.name);
      if (const auto unusedParam = mfr::unusedMethodParam(given))
        refuse(QString::fromStdString("--" + unusedParam->name + ": " + unusedParam->reason));
    }
  });
  // Only --screenshot: its picture is rendered at --size on its own, so the window draws nothing.
  const bool exportOnly = !cl.screenshot.isEmpty() && cl.windowScreenshot.isEmpty();
  window.view().setLiveFrames(!exportOnly);
  if (scripted) {
    QObject::connect(&model, &ViewerModel::loadFailed, &app,
                     [](const QString&, const QString& message) { fail(message, 1); });
    // Poll until the scene is loaded, a frame is drawn (for --window-screenshot) and background
    // work (oracle image, depth-complexity histogram) is done, then take the pictures and quit.
    auto* poll = new QTimer(&app);
    // Owned by the poll's slot (raw pointers leaked both; a sanitizer run).
    auto clock = std::make_shared<QElapsedTimer>();
    clock->start();
    auto settled = std::make_shared<QElapsedTimer>();  // since everything was first drawn and idle
    // The poll runs on the GUI thread, which a long live frame blocks (a volume at a step of 1e-6:
    // "timed out" came after 278 s, not 120; a bug hunt). A watchdog thread keeps the promise while
    // the run waits. Each side claims the run (exchange) before it acts: a picture is written only
    // once the watchdog has stood down, and the watchdog ends the run only before that.
    static std::atomic<bool> waiting{true};
    std::thread([] {
      for (int s = 0; s < kFirstFrameSeconds + 5 && waiting.load(); ++s)
        std::this_thread::sleep_for(std::chrono::seconds(1));
      if (waiting.exchange(false)) {  // claimed: the GUI thread writes nothing now
        std::fprintf(stderr, "mfrview: timed out waiting for the first frame (%d s)\n", kFirstFrameSeconds);
        std::_Exit(1);
      }
    }).detach();
    QObject::connect(poll, &QTimer::timeout, &app, [&, poll, clock, settled] {
      if (clock->elapsed() > 1000 * kFirstFrameSeconds)
        fail(QStringLiteral("timed out waiting for the first frame (%1 s)").arg(kFirstFrameSeconds), 1);
      // The live view may fail where the screenshot does not (a budget too small for the window's
      // size): a live error ends the wait too, and --screenshot reports its own render's errors.
      const bool drawn = exportOnly || model.framesRendered() > 0 || !model.renderError().isEmpty();
      if (!model.hasScene() || !window.view().glReady() || !drawn || model.busy()) return;
      // A whole-window picture also waits for the panels' delayed work (the budget plugin asks
      // for the depth-complexity histogram once the view has been still for a moment).
      if (!cl.windowScreenshot.isEmpty()) {
        if (!settled->isValid()) settled->start();
        if (settled->elapsed() < 1500) return;
      }
      poll->stop();
      if (!waiting.exchange(false)) return;  // the watchdog claimed the run and is ending it
      // A -p value a plugin replaced (the budget panel drives k and refits it after each frame, and
      // for an export at its size) is refused: the picture was not the one asked for, exit 0 (a bug
      // hunt). Checked on the parameters each picture is drawn with.
      const auto requireGiven = [&](const std::map<std::string, std::string>& inForce) {
        for (const auto& [name, value] : cl.params)
          if (const auto it = inForce.find(name); it != inForce.end() && it->second != value)
            fail(QStringLiteral("-p %1=%2: a plugin's settings set %1=%3 in its place (the budget panel drives it); "
                                "give one of the two")
                     .arg(QString::fromStdString(name), QString::fromStdString(value),
                          QString::fromStdString(it->second)),
                 2);
      };
      if (!cl.windowScreenshot.isEmpty()) requireGiven(model.params());
      try {
        if (!cl.screenshot.isEmpty()) {
          // As mfr render says it: a scripted run has no Statistics dock to show the note in.
          for (const auto& [key, note] : window.exportImage(cl.screenshot, cl.size, cl.legend, requireGiven).notes)
            if (key == "depth precision") std::cerr << "note: " << key << ": " << note << "\n";
        }
        if (!cl.windowScreenshot.isEmpty()) {
          // Plugins' panels update from the frame's signals; let them paint first.
          QApplication::processEvents();
          // Written as --screenshot is: PNG whatever the name, through a temporary file.
          const QImage grabbed = window.grab().toImage().convertToFormat(QImage::Format_RGBA8888);
          mfr::ImageRGBA8 image(grabbed.width(), grabbed.height());
          for (int y = 0; y < grabbed.height(); ++y)
            std::memcpy(image.at(0, y), grabbed.constScanLine(y), static_cast<std::size_t>(grabbed.width()) * 4);
          mfr::writePng(cl.windowScreenshot.toStdString(), image);
        }
      } catch (const std::exception& e) {
        QString message = QString::fromUtf8(e.what());
        static const QRegularExpression named(QStringLiteral("^--param ([A-Za-z0-9_]+)=(.*?): "));
        // A --param the command line lacks is never named: the value came from --plugin-settings,
        // else from the session (its params or its plugins' settings; a review), else a default.
        if (const QRegularExpressionMatch m = named.match(message); m.hasMatch()) {
          const std::string name = m.captured(1).toStdString();
          // Nor one it gives with another value: a plugin's settings replaced it, which is refused
          // as for a picture drawn (-p budget_mib=20 read "--param budget_mib=1: below …"; a bug hunt).
          if (const auto given = cl.params.find(name);
              given != cl.params.end() && given->second != m.captured(2).toStdString())
            requireGiven({{name, m.captured(2).toStdString()}});
          if (!cl.params.contains(name)) {
            if (const auto it = paramsOfPlugin.find(name); it != paramsOfPlugin.end())
              message = QStringLiteral("--plugin-settings %1: %2").arg(it->second, message.mid(8));
            else if (!cl.session.isEmpty())
              message = QStringLiteral("%1: %2").arg(cl.session, message.mid(8));
            else
              message = message.mid(8);
          }
        }
        fail(message, 1);
      }
      QApplication::exit(0);
    });
    poll->start(200);
  }

  window.show();
  // Asked again once the docks are laid out: the first layout gives them their size hints and
  // grew an 800-wide window to 1048 where its least width is 894 (a bug hunt).
  if (!cl.windowSize.isEmpty())
    QTimer::singleShot(0, &window, [&window, &cl] {
      window.layout()->activate();
      window.resize(cl.windowSize);
    });
  if (!cl.session.isEmpty()) {
    window.openSession(cl.session);
    // A scripted run has no one to read the message box: a bad session file ends it.
    if (scripted && !window.lastError().isEmpty()) fail(window.lastError(), 1);
  } else {
    window.openScene(cl.scene, cl.field, cl.molecule);
  }
  return QApplication::exec();
}
