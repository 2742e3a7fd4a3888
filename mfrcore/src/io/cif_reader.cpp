#include "cif_reader.hpp"

#include <cctype>
#include <optional>
#include <string_view>
#include <utility>
#include <vector>

#include "mfr/error.hpp"

namespace mfr::io {
namespace {

namespace cif = gemmi::cif;

enum class Kind { Value, Tag, Data, Global, Loop, Save, Stop };

struct Token {
  Kind kind = Kind::Value;
  std::string text;  // raw value, tag, block or frame name
  int line = 0;
};

bool isWhite(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r';
}
// gemmi's nonblank_ch: printable ASCII but space.
bool isNonBlank(char c) {
  return c >= '!' && c <= '~';
}

bool startsWithNoCase(std::string_view s, std::string_view prefix) {
  if (s.size() < prefix.size()) return false;
  for (std::size_t i = 0; i < prefix.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(s[i])) != prefix[i]) return false;
  return true;
}

class Lexer {
 public:
  Lexer(const std::string& text, const std::string& name) : text_(text), name_(name) {}

  // The next token, or nothing at the end of the text.
  std::optional<Token> next() {
    skipWhiteAndComments();
    if (pos_ >= text_.size()) return std::nullopt;
    Token token;
    token.line = line_;
    const std::size_t start = pos_;
    const char c = text_[pos_];
    if (c == '\'' || c == '"') {
      // Ends at the same quote followed by white space, '#' or the end; never crosses a line.
      for (std::size_t i = pos_ + 1;; ++i) {
        if (i >= text_.size() || text_[i] == '\n' || text_[i] == '\r')
          fail(std::string("unterminated ") + (c == '\'' ? "'string'" : "\"string\""));
        if (text_[i] == c && (i + 1 == text_.size() || isWhite(text_[i + 1]) || text_[i + 1] == '#')) {
          pos_ = i + 1;
          break;
        }
      }
      token.text = text_.substr(start, pos_ - start);
      return token;
    }
    if (c == ';' && atLineStart(pos_)) {
      // A text field: up to the next line that starts with ';', both semicolons kept.
      for (std::size_t i = pos_ + 1;; ++i) {
        if (i >= text_.size()) fail("unterminated text field");
        if (text_[i] == '\n') ++line_;
        if (text_[i] == ';' && atLineStart(i)) {
          pos_ = i + 1;
          break;
        }
      }
      token.text = text_.substr(start, pos_ - start);
      return token;
    }
    while (pos_ < text_.size() && !isWhite(text_[pos_])) {
      if (!isNonBlank(text_[pos_]))
        fail("unexpected byte " + std::to_string(static_cast<unsigned char>(text_[pos_])) + " (not printable ASCII)");
      ++pos_;
    }
    token.text = text_.substr(start, pos_ - start);
    const std::string_view word = token.text;
    if (word[0] == '_') {
      if (word.size() == 1) fail("empty tag '_'");
      token.kind = Kind::Tag;
    } else if (startsWithNoCase(word, "data_")) {
      token.kind = Kind::Data;
      token.text = token.text.substr(5);
    } else if (startsWithNoCase(word, "save_")) {
      token.kind = Kind::Save;
      token.text = token.text.substr(5);
    } else if (startsWithNoCase(word, "loop_")) {
      if (word.size() != 5) fail("unexpected '" + token.text + "'");
      token.kind = Kind::Loop;
    } else if (startsWithNoCase(word, "stop_")) {
      if (word.size() != 5) fail("unexpected '" + token.text + "'");
      token.kind = Kind::Stop;
    } else if (startsWithNoCase(word, "global_")) {
      if (word.size() != 7) fail("unexpected '" + token.text + "'");
      token.kind = Kind::Global;
    } else if (word[0] == '$') {
      fail("unexpected '" + token.text + "' (save frame references are not values)");
    }
    return token;
  }

  [[noreturn]] void fail(const std::string& reason) const { failAt(line_, reason); }
  [[noreturn]] void failAt(int line, const std::string& reason) const {
    throw Error(name_, "line " + std::to_string(line) + ": " + reason);
  }

 private:
  bool atLineStart(std::size_t i) const { return i == 0 || text_[i - 1] == '\n' || text_[i - 1] == '\r'; }

  void skipWhiteAndComments() {
    while (pos_ < text_.size()) {
      const char c = text_[pos_];
      if (c == '\n') {
        ++line_;
        ++pos_;
      } else if (isWhite(c)) {
        ++pos_;
      } else if (c == '#') {
        while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
      } else {
        break;
      }
    }
  }

  const std::string& text_;
  const std::string& name_;
  std::size_t pos_ = 0;
  int line_ = 1;
};

}  // namespace

cif::Document readCif(const std::string& text, const std::string& name) {
  Lexer lexer(text, name);
  cif::Document doc;
  doc.source = name;
  std::vector<cif::Item>* items = nullptr;  // of the current block or save frame
  bool inFrame = false;
  std::optional<Token> token = lexer.next();
  if (!token) lexer.fail("no CIF content (only white space and comments)");
  while (token) {
    switch (token->kind) {
      case Kind::Data:
      case Kind::Global:
        if (inFrame) lexer.fail("save frame not closed before a new data block");
        doc.blocks.emplace_back(token->kind == Kind::Global ? std::string() : token->text);
        if (token->kind == Kind::Data && doc.blocks.back().name.empty()) doc.blocks.back().name = "#";  // as gemmi
        items = &doc.blocks.back().items;
        token = lexer.next();
        continue;
      default:
        break;
    }
    if (items == nullptr) lexer.fail("expected block header (data_) before '" + token->text + "'");
    switch (token->kind) {
      case Kind::Tag: {
        cif::Item& item = items->emplace_back(std::string(token->text));
        item.line_number = token->line;
        std::optional<Token> value = lexer.next();
        if (!value || value->kind != Kind::Value) lexer.failAt(token->line, token->text + " has no value");
        item.pair[1] = std::move(value->text);
        token = lexer.next();
        break;
      }
      case Kind::Loop: {
        cif::Item& item = items->emplace_back(cif::LoopArg{});
        item.line_number = token->line;
        cif::Loop& loop = item.loop;
        token = lexer.next();
        while (token && token->kind == Kind::Tag) {
          loop.tags.push_back(std::move(token->text));
          token = lexer.next();
        }
        if (loop.tags.empty()) lexer.fail("loop_ without tags");
        while (token && token->kind == Kind::Value) {
          loop.values.push_back(std::move(token->text));
          token = lexer.next();
        }
        if (loop.values.size() % loop.tags.size() != 0)
          lexer.failAt(item.line_number, "loop of " + loop.tags[0] + " … has " + std::to_string(loop.values.size()) +
                                             " values, not a multiple of its " + std::to_string(loop.tags.size()) +
                                             " tags (truncated or corrupt?)");
        if (token && token->kind == Kind::Stop) token = lexer.next();
        break;
      }
      case Kind::Save:
        if (!token->text.empty()) {
          if (inFrame) lexer.fail("save_" + token->text + " inside another save frame");
          cif::Item& item = items->emplace_back(cif::FrameArg{token->text});
          item.line_number = token->line;
          items = &item.frame.items;
          inFrame = true;
        } else {
          if (!inFrame) lexer.fail("save_ without an open save frame");
          items = &doc.blocks.back().items;
          inFrame = false;
        }
        token = lexer.next();
        break;
      case Kind::Stop:
        lexer.fail("stop_ outside a loop");
      case Kind::Value:
        lexer.fail("value '" + token->text.substr(0, 40) + "' without a tag");
      case Kind::Data:
      case Kind::Global:
        break;  // handled above
    }
  }
  if (inFrame) lexer.fail("save frame not closed at the end of the file");
  cif::check_for_duplicates(doc);
  return doc;
}

}  // namespace mfr::io
