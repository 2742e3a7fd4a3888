#include <sstream>

#include "commands.hpp"
#include "mfr/error.hpp"
#include "mfr/render.hpp"

namespace mfr::cli {

std::pair<int, int> parseSize(const std::string& option, const std::string& text) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  std::istringstream in(text);
  if (!(in >> w >> x >> h) || (x != 'x' && x != 'X') || (in >> extra))
    throw Error(option + " " + text, "expected WIDTHxHEIGHT, e.g. 800x600");
  validateImageSize(option + " " + text, w, h);
  return {w, h};
}

std::vector<std::string> splitList(const std::string& text) {
  std::vector<std::string> out;
  std::string item;
  std::istringstream in(text);
  while (std::getline(in, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

}  // namespace mfr::cli
