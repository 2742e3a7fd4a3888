#include "file_checks.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <unistd.h>

#include "mfr/error.hpp"

namespace mfr::io {

namespace fs = std::filesystem;

void checkReadable(const fs::path& path, const std::string& name, std::string_view kind) {
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (st.type() == fs::file_type::not_found) throw Error(name, "no such file");
  if (ec) throw Error(name, "cannot access file: " + ec.message());
  if (fs::is_directory(st)) throw Error(name, "is a directory, not a " + std::string(kind) + " file");
  // FIFOs and devices would block or never end.
  if (!fs::is_regular_file(st)) throw Error(name, "not a regular file");
  if (::access(path.c_str(), R_OK) != 0) throw Error(name, std::string("cannot read file: ") + std::strerror(errno));
  std::ifstream probe(path, std::ios::binary);
  if (!probe) throw Error(name, "cannot open file for reading");
  if (fs::file_size(path, ec) == 0 && !ec) throw Error(name, "empty file");
}

std::string oneLine(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r' || c == '\t') c = ' ';
  s.erase(std::unique(s.begin(), s.end(), [](char a, char b) { return a == ' ' && b == ' '; }), s.end());
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

}  // namespace mfr::io
