#pragma once
// JSON as the text mfr writes: bytes that are not UTF-8 (a name from a file in another encoding,
// a path) become U+FFFD instead of nlohmann's exception, which ended a command in "internal
// error" after all its work.
#include <algorithm>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include "mfr/error.hpp"

namespace mfr {

template <class Json>
std::string jsonText(const Json& json, int indent = -1) {
  return json.dump(indent, ' ', false, Json::error_handler_t::replace);
}

// How deeply arrays and objects nest in a JSON text (0 for a bare value), counted without parsing:
// nlohmann's dump and the readers of nested values (CSG trees) recurse, and a weights file whose
// "training" nested 100,000 arrays deep overflowed the stack (a bug hunt). Weights files and
// datasets' metadata, which mfr writes out again, are refused beyond kJsonNestingLimit (scene
// files are read without recursion but for CSG trees, which have their own limit).
inline constexpr std::size_t kJsonNestingLimit = 256;
inline std::size_t jsonNestingDepth(std::string_view text) {
  std::size_t depth = 0, deepest = 0;
  bool inString = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (inString) {
      if (c == '\\')
        ++i;  // the escaped character cannot end the string
      else if (c == '"')
        inString = false;
    } else if (c == '"') {
      inString = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return deepest;
}

// Throws Error(what, prefix + "nests N levels deep (more than LIMIT)") beyond `limit`.
inline void requireJsonNesting(std::string_view text, const std::string& what, const std::string& prefix,
                               std::size_t limit = kJsonNestingLimit) {
  if (const std::size_t depth = jsonNestingDepth(text); depth > limit)
    throw Error(what,
                prefix + "nests " + std::to_string(depth) + " levels deep (more than " + std::to_string(limit) + ")");
}

// Where `text` first gives a key twice in one object ("objects[1].opacity"), if it is JSON that
// does: for JSON read by another parser (Qt's, of sessions and --plugin-settings, takes the last of
// a repeated key without a word). nullopt for JSON without a repeated key and for text that is not
// JSON (its parser says why).
std::optional<std::string> repeatedJsonKey(const std::string& text);

}  // namespace mfr
