#pragma once
// JSON as the text mfr writes: bytes that are not UTF-8 (a name from a file in another encoding,
// a path) become U+FFFD instead of nlohmann's exception, which ended a command in "internal
// error" after all its work.
#include <string>

namespace mfr {

template <class Json>
std::string jsonText(const Json& json, int indent = -1) {
  return json.dump(indent, ' ', false, Json::error_handler_t::replace);
}

}  // namespace mfr
