#include "mfr/io_util.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <mutex>
#include <fstream>
#include <random>
#include <sstream>
#include <system_error>
#include <utility>
#include <vector>

#include "mfr/error.hpp"
#include "mfr/host_memory.hpp"

namespace mfr {

bool sameFile(const std::string& a, const std::string& b) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) {
    const bool same = fs::equivalent(a, b, ec);
    if (!ec) return same;
  }
  const fs::path pa = fs::weakly_canonical(fs::absolute(a, ec), ec);
  const fs::path pb = fs::weakly_canonical(fs::absolute(b, ec), ec);
  return !ec && pa == pb;
}

void checkCommandFiles(const std::vector<CommandFile>& files) {
  using Role = CommandFile::Role;
  const auto output = [](const CommandFile& f) { return f.role == Role::kOutput || f.role == Role::kRequiredOutput; };
  for (const CommandFile& f : files) {
    if (f.role == Role::kRequiredOutput && f.path.empty()) throw Error(f.option, "empty file name");
    if (output(f) && !f.path.empty()) checkOutputPath(f.path);
  }
  const auto file = [](const CommandFile& f) {
    return !f.path.empty() && !(f.role == Role::kScene && f.path.front() == '@');  // a built-in scene
  };
  for (std::size_t j = 0; j < files.size(); ++j)
    for (std::size_t i = 0; i < j; ++i) {
      const CommandFile &a = files[i], &b = files[j];
      if (!(output(a) || output(b)) || !file(a) || !file(b) || !sameFile(a.path, b.path)) continue;
      throw Error(b.option + " " + b.path,
                  "is the same file as " + a.option + " (" + a.path + ")" +
                      (output(a) && output(b) ? ": both would be written to it"
                                              : ": the command would write over what it reads"));
    }
}

std::string readFile(const std::filesystem::path& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) throw Error(path.string(), "no such file");
  if (std::filesystem::is_directory(status)) throw Error(path.string(), "is a directory, not a file");
  // /dev/zero never ends and a pipe may never be written: read, they grew memory without bound or
  // waited forever (a bug hunt: -p weights=/dev/zero, mfr train /dev/zero).
  if (!std::filesystem::is_regular_file(status)) throw Error(path.string(), "not a regular file (a device or pipe)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path.string(), std::string("cannot open (") + std::strerror(errno) + ")");
  // Read whole: asked of the host's memory first (a 2 GB scene file under MFR_MEMORY_LIMIT_MIB=500
  // took 4.2 GB through a string stream, or ended in "internal error: std::bad_alloc"; a bug hunt),
  // and read straight into one string of the file's size.
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) throw Error(path.string(), "cannot tell its size (" + ec.message() + ")");
  // (From 64 MiB: a small file is not what exhausts memory, and the work it feeds is checked.)
  if (size >= (std::uintmax_t{64} << 20))
    requireHostMemory(path.string(), "reading the file (" + formatMemory(size) + ")", size);
  std::string data(static_cast<std::size_t>(size), '\0');
  in.read(data.data(), static_cast<std::streamsize>(size));
  if (in.bad()) throw Error(path.string(), "read error");
  data.resize(static_cast<std::size_t>(in.gcount()));  // shorter if it shrank meanwhile
  return data;
}

namespace {

// Where an output is written: the file a symbolic link names (the link stays a link, as when a
// program opens it for writing; a rename over the link replaced it with a plain file). Throws for a
// link that names no file, or a loop.
std::filesystem::path outputTarget(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_symlink(std::filesystem::symlink_status(path, ec))) return path;
  std::filesystem::path target = std::filesystem::canonical(path, ec);
  if (ec) throw Error(path.string(), "a link to a missing file or a loop of links (" + ec.message() + ")");
  return target;
}

// A file created and removed in `dir`: whether outputs can be written there at all (a folder can
// exist and refuse files: /proc, a read-only mount, another user's), checked before any work.
void checkFolderTakesFiles(const std::filesystem::path& dir, const std::filesystem::path& output) {
  std::filesystem::path probe = dir / (".mfr-write-check-" + std::to_string(::getpid()) + "-" +
                                       std::to_string(std::random_device{}() & 0xFFFFFF));
  // O_EXCL: a name someone placed there (a link) is never followed or truncated.
  const int fd = ::open(probe.c_str(), O_CREAT | O_EXCL | O_WRONLY | O_CLOEXEC, 0600);
  if (fd < 0) throw Error(output.string(), std::string("cannot write in its folder (") + std::strerror(errno) + ")");
  ::close(fd);
  ::unlink(probe.c_str());
}

}  // namespace

namespace {
// The longest file name the folder takes, in bytes (NAME_MAX, 255 on Linux's file systems).
std::size_t nameMax(const std::filesystem::path& dir) {
  const long most = ::pathconf(dir.c_str(), _PC_NAME_MAX);
  return most > 0 ? static_cast<std::size_t>(most) : 255;
}
}  // namespace

void checkOutputPath(const std::filesystem::path& given) {
  if (given.empty()) throw Error("output", "empty file name");
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(given, ec);
  if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status))
    throw Error(given.string(), std::filesystem::is_directory(status)
                                    ? "is a folder, not a file"
                                    : "exists and is not a regular file (a device or pipe): not replaced");
  const std::filesystem::path path = outputTarget(given);
  const std::filesystem::path dir = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  if (!std::filesystem::is_directory(dir, ec)) throw Error(given.string(), "folder does not exist");
  // Refused here, before the work, not by the write after it.
  const std::size_t nameBytes = path.filename().native().size();
  if (const std::size_t most = nameMax(dir); nameBytes > most)
    throw Error(given.string(), "file name too long (" + std::to_string(nameBytes) + " bytes; the folder takes " +
                                    std::to_string(most) + " at most)");
  checkFolderTakesFiles(dir, given);
}

namespace {

constexpr std::array<int, 3> kHeldSignals{SIGINT, SIGTERM, SIGHUP};
// Bit i: kHeldSignals[i] arrived while held. Every one is kept, not the first only: a SIGHUP that
// nohup ignores, then a SIGTERM, lost the SIGTERM (a review). A handler may store to a lock-free
// atomic only, and another thread's destructor reads it.
std::atomic<unsigned> heldSignals{0};
static_assert(std::atomic<unsigned>::is_always_lock_free);
extern "C" void holdSignal(int signal) {
  for (std::size_t i = 0; i < kHeldSignals.size(); ++i)
    if (kHeldSignals[i] == signal) heldSignals.fetch_or(1u << i, std::memory_order_relaxed);
}
std::mutex heldMutex;
int heldDepth = 0;                                                    // guarded by heldMutex
std::array<struct sigaction, kHeldSignals.size()> previousActions{};  // guarded by heldMutex
std::array<bool, kHeldSignals.size()> caught{};                       // guarded by heldMutex

}  // namespace

TerminationSignalsHeld::TerminationSignalsHeld() {
  const std::lock_guard lock(heldMutex);
  if (heldDepth++ > 0) return;
  heldSignals.store(0);
  struct sigaction hold {};
  hold.sa_handler = holdSignal;
  sigemptyset(&hold.sa_mask);
  hold.sa_flags = SA_RESTART;  // a write or rename interrupted goes on
  for (std::size_t i = 0; i < kHeldSignals.size(); ++i) {
    ::sigaction(kHeldSignals[i], nullptr, &previousActions[i]);
    // An ignored signal stays ignored (nohup's SIGHUP, a background job's SIGINT).
    caught[i] = previousActions[i].sa_handler != SIG_IGN;
    if (caught[i]) ::sigaction(kHeldSignals[i], &hold, nullptr);
  }
}

TerminationSignalsHeld::~TerminationSignalsHeld() {
  const std::lock_guard lock(heldMutex);
  if (--heldDepth > 0) return;
  for (std::size_t i = 0; i < kHeldSignals.size(); ++i)
    if (caught[i]) ::sigaction(kHeldSignals[i], &previousActions[i], nullptr);
  const unsigned arrived = heldSignals.exchange(0);
  // As if each had come now: the first whose action is the default ends the process.
  for (std::size_t i = 0; i < kHeldSignals.size(); ++i)
    if ((arrived & (1u << i)) != 0) std::raise(kHeldSignals[i]);
}

namespace {

// A finished temporary beside its output, renamed over it by commit().
struct Temporary {
  std::filesystem::path given, target, tmp;
};

Temporary writeTemporary(const std::filesystem::path& given, std::string_view bytes) {
  checkOutputPath(given);
  Temporary t{given, outputTarget(given), {}};  // a link's file, not the link
  // Temporary beside the target (same file system), renamed over it only when complete. Its name
  // is the target's, shortened so that the suffix fits the folder's longest name: a name of 234 to
  // 255 bytes, valid, was refused as "File name too long" after the render (a bug hunt).
  const std::string suffix =
      ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(std::random_device{}() & 0xFFFFFF);
  std::string name = t.target.filename().native();
  const std::filesystem::path dir = t.target.has_parent_path() ? t.target.parent_path() : std::filesystem::path(".");
  name.resize(std::min(name.size(), nameMax(dir) > suffix.size() ? nameMax(dir) - suffix.size() : 0));
  t.tmp = t.target.parent_path() / (name + suffix);
  std::ofstream out(t.tmp, std::ios::binary | std::ios::trunc);
  if (!out) throw Error(given.string(), std::string("cannot write (") + std::strerror(errno) + ")");
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) {
    std::error_code ec;
    std::filesystem::remove(t.tmp, ec);
    throw Error(given.string(), "write failed (disk full?)");
  }
  return t;
}

void commit(const Temporary& t) {
  std::error_code ec;
  std::filesystem::rename(t.tmp, t.target, ec);
  if (ec) {
    const std::string why = ec.message();  // before remove() reuses ec
    std::filesystem::remove(t.tmp, ec);
    throw Error(t.given.string(), "cannot replace file (" + why + ")");
  }
}

}  // namespace

void writeFileAtomically(const std::filesystem::path& given, std::string_view bytes) {
  const TerminationSignalsHeld held;  // Ctrl-C mid-write left the temporary (a bug hunt)
  commit(writeTemporary(given, bytes));
}

void writeFilesAtomically(const std::vector<std::pair<std::filesystem::path, std::string>>& files) {
  // Held until every output is renamed: a signal between two renames left the new PNG beside a
  // temporary and the old JSON (a bug hunt).
  const TerminationSignalsHeld held;
  std::vector<Temporary> written;
  try {
    for (const auto& [path, bytes] : files) written.push_back(writeTemporary(path, bytes));
  } catch (...) {
    std::error_code ec;
    for (const Temporary& t : written) std::filesystem::remove(t.tmp, ec);
    throw;
  }
  for (std::size_t i = 0; i < written.size(); ++i) {
    try {
      commit(written[i]);
    } catch (...) {
      std::error_code ec;
      for (std::size_t j = i + 1; j < written.size(); ++j) std::filesystem::remove(written[j].tmp, ec);
      throw;
    }
  }
}

}  // namespace mfr
