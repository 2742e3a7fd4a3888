#include "csg_panel.hpp"

#include <QCheckBox>
#include <QHBoxLayout>
#include <QJsonArray>
#include <QJsonDocument>
#include <QLabel>
#include <QListWidget>
#include <QPlainTextEdit>
#include <QPushButton>
#include <QVBoxLayout>

#include "viewer_plugin.hpp"

namespace {
// The A-buffer chosen when the current method cannot carry object ids.
const QString kCsgMethod = QStringLiteral("abuffer-sbuffer");
}  // namespace

CsgPanel::CsgPanel(ViewerContext& context, QWidget* parent) : QWidget(parent), context_(context) {
  setObjectName(QStringLiteral("csgPanel"));
  auto* layout = new QVBoxLayout(this);

  show_ = new QCheckBox(tr("Draw the tree as solids (operation csg)"));
  show_->setObjectName(QStringLiteral("csgShow"));
  show_->setToolTip(
      tr("Each pixel shows the first surface where the tree's solid begins, from its sorted fragments. "
         "Needs an A-buffer (abuffer-ll, abuffer-array, abuffer-sbuffer) or the oracle."));
  layout->addWidget(show_);

  layout->addWidget(new QLabel(tr("Parts (closed surfaces):")));
  objects_ = new QListWidget;
  objects_->setObjectName(QStringLiteral("csgObjects"));
  objects_->setMaximumHeight(140);
  layout->addWidget(objects_);
  auto* buttons = new QHBoxLayout;
  const auto addButton = [&](const QString& label, const QString& op, const QString& tip) {
    auto* b = new QPushButton(label);
    b->setObjectName(QStringLiteral("csg_") + op);
    b->setToolTip(tip);
    connect(b, &QPushButton::clicked, this, [this, op] { combineChecked(op); });
    buttons->addWidget(b);
  };
  addButton(tr("Union"), QStringLiteral("union"), tr("A new tree: the union of the checked parts"));
  addButton(tr("Intersection"), QStringLiteral("intersection"), tr("A new tree: what the checked parts share"));
  addButton(tr("Difference"), QStringLiteral("difference"),
            tr("A new tree: the first checked part minus all the other checked parts"));
  layout->addLayout(buttons);

  layout->addWidget(new QLabel(tr("Tree (JSON, as in a scene file's \"csg\"):")));
  text_ = new QPlainTextEdit;
  text_->setObjectName(QStringLiteral("csgText"));
  text_->setPlaceholderText(QStringLiteral("{\"difference\": [\"block\", {\"union\": [\"drill x\", \"drill y\"]}]}"));
  text_->setMaximumHeight(90);
  layout->addWidget(text_);
  auto* edit = new QHBoxLayout;
  auto* apply = new QPushButton(tr("Apply"));
  apply->setObjectName(QStringLiteral("csgApply"));
  auto* clear = new QPushButton(tr("Remove Tree"));
  clear->setObjectName(QStringLiteral("csgClear"));
  edit->addWidget(apply);
  edit->addWidget(clear);
  edit->addStretch();
  layout->addLayout(edit);
  error_ = new QLabel;
  error_->setObjectName(QStringLiteral("csgError"));
  error_->setWordWrap(true);
  error_->setStyleSheet(QStringLiteral("color: #b00020;"));
  layout->addWidget(error_);
  layout->addStretch();

  connect(show_, &QCheckBox::toggled, this, &CsgPanel::setShown);
  connect(apply, &QPushButton::clicked, this, &CsgPanel::applyText);
  connect(clear, &QPushButton::clicked, this, [this] {
    text_->clear();
    applyText();
  });
  connect(&context_, &ViewerContext::sceneChanged, this, &CsgPanel::sceneChanged);
  connect(&context_, &ViewerContext::operationChanged, this, [this](const QString& op) {
    const QSignalBlocker block(show_);
    show_->setChecked(op == QLatin1String("csg"));
  });
  show_->setChecked(context_.operation() == QLatin1String("csg"));
  sceneChanged();
}

void CsgPanel::sceneChanged() {
  const QStringList names = context_.hasScene() ? context_.objectNames() : QStringList{};
  // Another scene starts with nothing checked, even where its parts have the old one's names.
  if (names != names_ || context_.sceneSerial() != sceneSerial_) {
    names_ = names;
    sceneSerial_ = context_.sceneSerial();
    objects_->clear();
    for (const QString& name : names) {
      auto* item = new QListWidgetItem(name, objects_);
      item->setFlags(item->flags() | Qt::ItemIsUserCheckable);
      item->setCheckState(Qt::Unchecked);
    }
  }
  const QString tree = context_.hasScene() ? context_.csgTree() : QString();
  if (text_->toPlainText() != tree) text_->setPlainText(tree);
}

void CsgPanel::combineChecked(const QString& op) {
  QJsonArray operands;
  for (int i = 0; i < objects_->count(); ++i)
    if (objects_->item(i)->checkState() == Qt::Checked) operands.append(objects_->item(i)->text());
  if (operands.size() < 2) {
    showError(tr("Check at least two parts."));
    return;
  }
  text_->setPlainText(QString::fromUtf8(QJsonDocument(QJsonObject{{op, operands}}).toJson(QJsonDocument::Compact)));
  applyText();
}

void CsgPanel::applyText() {
  const QString error = context_.setCsgTree(text_->toPlainText());
  showError(error);
  if (error.isEmpty() && context_.csgTree().isEmpty() && show_->isChecked()) show_->setChecked(false);
}

void CsgPanel::setShown(bool on) {
  if (!on) {
    if (context_.operation() == QLatin1String("csg")) context_.setOperation(QStringLiteral("auto"));
    return;
  }
  if (context_.csgTree().isEmpty()) {
    showError(tr("The scene has no CSG tree: combine parts or write one first."));
    const QSignalBlocker block(show_);
    show_->setChecked(false);
    return;
  }
  const QString method = context_.method();
  const mfr::MethodInfo* info = context_.methodInfo(method);
  if (method != QLatin1String("oracle") && (!info || !info->objectPayload)) context_.setMethod(kCsgMethod);
  context_.setOperation(QStringLiteral("csg"));
  showError({});
}

void CsgPanel::showError(const QString& message) {
  error_->setText(message);
}

QJsonObject CsgPanel::saveSettings() const {
  return {{QStringLiteral("tree"), context_.csgTree()}};
}

void CsgPanel::loadSettings(const QJsonObject& settings) {
  // A key left out keeps the scene's tree ({} cleared it: a bug hunt); "" clears it, as saved.
  if (!settings.contains(QStringLiteral("tree"))) return;
  const QString tree = settings.value(QStringLiteral("tree")).toString();
  if (!context_.hasScene() || tree == context_.csgTree()) return;
  const QString error = context_.setCsgTree(tree);
  showError(error);
  if (!error.isEmpty()) context_.note(tr("csg: tree: %1 (the scene's tree is kept)").arg(error));
  sceneChanged();
}
