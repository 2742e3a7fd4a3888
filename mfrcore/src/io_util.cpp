#include "mfr/io_util.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>
#include <system_error>

#include "mfr/error.hpp"

namespace mfr {

std::string readFile(const std::filesystem::path& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) throw Error(path.string(), "no such file");
  if (std::filesystem::is_directory(status)) throw Error(path.string(), "is a directory, not a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path.string(), std::string("cannot open (") + std::strerror(errno) + ")");
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw Error(path.string(), "read error");
  return ss.str();
}

void checkOutputPath(const std::filesystem::path& path) {
  if (path.empty()) throw Error("output", "empty file name");
  const std::filesystem::path dir = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) throw Error(path.string(), "folder does not exist");
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status))
    throw Error(path.string(), std::filesystem::is_directory(status)
                                   ? "is a folder, not a file"
                                   : "exists and is not a regular file (a device or pipe): not replaced");
}

void writeFileAtomically(const std::filesystem::path& path, std::string_view bytes) {
  checkOutputPath(path);
  std::error_code ec;
  // Temporary beside the target (same file system), renamed over it only when complete.
  std::filesystem::path tmp = path;
  tmp += ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(std::random_device{}() & 0xFFFFFF);
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw Error(path.string(), std::string("cannot write (") + std::strerror(errno) + ")");
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) {
      std::filesystem::remove(tmp, ec);
      throw Error(path.string(), "write failed (disk full?)");
    }
  }
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    const std::string why = ec.message();  // before remove() reuses ec
    std::filesystem::remove(tmp, ec);
    throw Error(path.string(), "cannot replace file (" + why + ")");
  }
}

}  // namespace mfr
