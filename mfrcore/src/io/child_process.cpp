// A loader's library run in a child process (child_process.hpp). The child reports over a pipe in
// records — a tag byte, a 64-bit length, the bytes: 'P' progress (a double), 'R' the result, 'E'
// an mfr::Error's message, 'F' a FieldNotFound's, 'M' out of memory, 'X' any other exception —
// and leaves by _exit.
#include "child_process.hpp"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <fstream>
#include <map>
#include <new>
#include <stdexcept>
#include <type_traits>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "mfr/error.hpp"
#include "mfr/host_memory.hpp"

namespace mfr::io {
namespace {

// The pipe's ends and the child, closed and reaped (killed first if still running) on every way
// out of runInChild.
class ChildGuard {
 public:
  ChildGuard() = default;
  ChildGuard(const ChildGuard&) = delete;
  ChildGuard& operator=(const ChildGuard&) = delete;
  ~ChildGuard() {
    closeRead();
    closeWrite();
    if (pid > 0) {
      kill(pid, SIGKILL);
      reap();
    }
  }
  void closeRead() {
    if (fds[0] >= 0) close(fds[0]);
    fds[0] = -1;
  }
  void closeWrite() {
    if (fds[1] >= 0) close(fds[1]);
    fds[1] = -1;
  }
  // Waits for the child; its status.
  int reap() {
    int status = 0;
    while (pid > 0 && waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    pid = -1;
    return status;
  }
  int fds[2] = {-1, -1};
  pid_t pid = -1;
};

// Writes all of `size` bytes; false when the pipe is gone.
bool writeAll(int fd, const void* data, std::size_t size) {
  const char* at = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t n = write(fd, at, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    at += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

bool writeRecord(int fd, char tag, const std::string& bytes) {
  const std::uint64_t size = bytes.size();
  return writeAll(fd, &tag, 1) && writeAll(fd, &size, sizeof size) && writeAll(fd, bytes.data(), bytes.size());
}

constexpr std::size_t kRecordHeader = 1 + sizeof(std::uint64_t);

// The child's side: runs `work`, writes its records and never returns. noexcept: an exception
// that escaped would unwind the parent's copied stack in the child; it aborts instead (a crash).
[[noreturn]] void childMain(int fd, pid_t parent, std::uint64_t memoryLimit,
                            const std::function<std::string(const LoadProgress&)>& work) noexcept {
  // Dies with the parent: a hung child outlived a killed mfr or mfrview.
  prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (getppid() != parent) _exit(1);
  const int null = open("/dev/null", O_WRONLY | O_CLOEXEC);
  if (null >= 0) {  // the library's and the C++ runtime's last words ("terminate called …")
    dup2(null, 1);
    dup2(null, 2);
  }
  // Only the pipe's write end (as fd 3) and 0–2 stay open: another thread's child must not hold
  // this pipe (its end of file would wait for that child), nor this child the parent's sockets.
  if (fd != 3) {
    dup2(fd, 3);
    fd = 3;
  }
  close_range(4, ~0U, 0);
  prctl(PR_SET_DUMPABLE, 0);  // no core file, no crash report (apport, systemd-coredump)
  const rlimit noCore{0, 0};
  setrlimit(RLIMIT_CORE, &noCore);
  if (memoryLimit > 0) {
    const rlimit memory{memoryLimit, memoryLimit};
    setrlimit(RLIMIT_AS, &memory);
  }
  LoadProgress progress;
  double reported = -1.0;
  progress.report = [fd, &reported](double fraction) {
    if (fraction > reported) {  // reports only move forward; the parent needs no repeats
      reported = fraction;
      std::string bytes(sizeof fraction, '\0');
      std::memcpy(bytes.data(), &fraction, sizeof fraction);
      writeRecord(fd, 'P', bytes);
    }
    return true;  // the parent cancels by killing the child
  };
  char tag = 'R';
  std::string bytes;
  try {
    bytes = work(progress);
  } catch (const std::bad_alloc&) {
    tag = 'M';
    bytes.clear();
  } catch (const FieldNotFound& error) {
    tag = 'F';
    bytes = error.what();
  } catch (const Error& error) {
    tag = 'E';
    bytes = error.what();
  } catch (const std::exception& error) {
    tag = 'X';
    bytes = error.what();
  } catch (...) {
    tag = 'X';
    bytes.clear();
  }
  writeRecord(fd, tag, bytes);
  _exit(0);
}

}  // namespace

int importSeconds(const std::string& name) {
  const char* text = std::getenv("MFR_IMPORT_TIMEOUT_S");
  if (text == nullptr || *text == '\0') return 120;
  // Digits only, as MFR_MEMORY_LIMIT_MIB: strtol took " 5" and "+5" where that one is refused (a bug hunt).
  const std::string given(text);
  if (given.find_first_not_of("0123456789") != std::string::npos)
    throw Error(name, "MFR_IMPORT_TIMEOUT_S=" + given + ": expected whole seconds, 1 to 86400");
  char* end = nullptr;
  errno = 0;
  const long seconds = std::strtol(text, &end, 10);
  if (errno != 0 || *end != '\0' || seconds < 1 || seconds > 86400)
    throw Error(name, std::string("MFR_IMPORT_TIMEOUT_S=") + text + ": expected whole seconds, 1 to 86400");
  return static_cast<int>(seconds);
}

std::optional<std::string> runInChild(const std::string& name, const ChildLibrary& library,
                                      const LoadProgress& progress,
                                      const std::function<std::string(const LoadProgress&)>& work) {
  const int seconds = importSeconds(name) + std::max(library.graceSeconds, 0);
  std::uint64_t limit = 0;
  const std::optional<std::uint64_t> available = availableHostMemory();
  if (available) {
    long pages = 0;
    std::ifstream statm("/proc/self/statm");
    statm >> pages;  // the address space already mapped (libraries, buffers) counts against RLIMIT_AS
    limit = *available + static_cast<std::uint64_t>(std::max(pages, 0L)) * static_cast<std::uint64_t>(getpagesize());
  }
  ChildGuard job;
  // Close-on-exec: a program another thread starts meanwhile must not hold the write end open
  // (a child another thread forks closes it first thing, in childMain).
  if (pipe2(job.fds, O_CLOEXEC) != 0) return std::nullopt;
  const pid_t parent = getpid();
  job.pid = fork();
  if (job.pid < 0) return std::nullopt;
  if (job.pid == 0) {
    // Only this thread lives on in the child: it works, reports and leaves by _exit.
    close(job.fds[0]);
    childMain(job.fds[1], parent, limit, work);
  }
  job.closeWrite();

  std::string buffer;    // what the child wrote and this side has not yet taken apart
  std::size_t used = 0;  // of buffer, the records already taken
  char finalTag = '\0';
  std::string finalBytes;
  bool progressed = false, timedOut = false;
  double reached = 0.0;  // the child's last report: repeated while waiting, so a cancel is heard
  auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(seconds);
  for (bool open = true; open && finalTag == '\0';) {
    pollfd p{job.fds[0], POLLIN, 0};
    const int ready = poll(&p, 1, 100);
    if (ready > 0) {
      char chunk[65536];
      const ssize_t n = read(job.fds[0], chunk, sizeof chunk);
      if (n > 0) {
        buffer.append(chunk, static_cast<std::size_t>(n));
        // Bytes arriving are progress too (a large result takes a while through the pipe).
        deadline = std::chrono::steady_clock::now() + std::chrono::seconds(seconds);
      } else if (n == 0 || errno != EINTR) {
        open = false;  // the child closed its end: it is done (or dead)
      }
    } else if (ready < 0 && errno != EINTR) {
      open = false;
    }
    // Every whole record so far.
    while (finalTag == '\0' && buffer.size() - used >= kRecordHeader) {
      std::uint64_t size = 0;
      std::memcpy(&size, buffer.data() + used + 1, sizeof size);
      const char tag = buffer[used];
      if (buffer.size() - used - kRecordHeader < size) {
        // A result arriving: room for all of it at once, not the doublings of append (the parent
        // held a large model up to three times while receiving it).
        if (tag != 'P' && buffer.capacity() < used + kRecordHeader + size) {
          try {
            buffer.reserve(used + kRecordHeader + static_cast<std::size_t>(size));
          } catch (const std::exception&) {
            // append says so if it really does not fit
          }
        }
        break;
      }
      const char* payload = buffer.data() + used + kRecordHeader;
      if (tag == 'P' && size == sizeof(double)) {
        double fraction = 0.0;
        std::memcpy(&fraction, payload, sizeof fraction);
        progressed = true;
        deadline = std::chrono::steady_clock::now() + std::chrono::seconds(seconds);
        reached = std::max(reached, std::clamp(fraction, 0.0, 1.0));
        if (!progress.tryStep(reached)) {
          kill(job.pid, SIGKILL);
          throw LoadCancelled();  // the guard reaps the child
        }
      } else {
        // The last record: its bytes moved out of the buffer, not copied.
        finalTag = tag;
        buffer.erase(0, used + kRecordHeader);
        buffer.resize(static_cast<std::size_t>(size));
        finalBytes = std::move(buffer);
        buffer = std::string();
        used = 0;
        break;
      }
      used += kRecordHeader + static_cast<std::size_t>(size);
    }
    if (used > (1u << 20) && used * 2 > buffer.size()) {  // keep the buffer to what is unread
      buffer.erase(0, used);
      used = 0;
    }
    if (finalTag != '\0') break;
    if (!progress.tryStep(reached)) {
      kill(job.pid, SIGKILL);
      throw LoadCancelled();
    }
    if (std::chrono::steady_clock::now() > deadline) {
      timedOut = true;
      kill(job.pid, SIGKILL);
      break;
    }
  }
  buffer.clear();
  buffer.shrink_to_fit();
  job.closeRead();
  const int status = job.reap();
  const std::string& format = library.format;
  const std::string memory = formatMemory(available.value_or(0));
  if (timedOut)
    throw Error(name, "cannot read " + format + ": " + library.library +
                          (progressed ? " made no progress for " : " did not finish in ") + std::to_string(seconds) +
                          " s (corrupt or truncated file?)");
  if (finalTag == 'M')
    throw Error(name, "cannot read " + format + ": " + library.library + " needed more than the " + memory +
                          " available (a corrupt file, or one too large for this machine)");
  if (finalTag == 'E') throw Error(finalBytes);
  if (finalTag == 'F') throw FieldNotFound(finalBytes);
  if (finalTag == 'R') return finalBytes;
  // Killed or stopped from outside (the kernel's out-of-memory killer sends SIGKILL) is no fault of
  // the file, and was blamed on it ("crashed (Killed; corrupt or truncated file?)").
  if (finalTag == '\0' && WIFSIGNALED(status) &&
      (WTERMSIG(status) == SIGKILL || WTERMSIG(status) == SIGTERM || WTERMSIG(status) == SIGINT ||
       WTERMSIG(status) == SIGHUP))
    throw Error(
        name, "cannot read " + format + ": the process reading it with " + library.library +
                  " was stopped from outside (" + std::string(strsignal(WTERMSIG(status))) +
                  (WTERMSIG(status) == SIGKILL ? ": by the system when memory ran out, or by another program)" : ")"));
  if (finalTag == '\0' && WIFSIGNALED(status))
    throw Error(name, "cannot read " + format + ": " + library.library + " crashed (" +
                          std::string(strsignal(WTERMSIG(status))) + "; corrupt or truncated file?)");
  throw Error(name, "cannot read " + format + ": " + library.library +
                        (finalTag == 'X' ? " failed" + (finalBytes.empty() ? std::string() : " (" + finalBytes + ")")
                                         : std::string(" ended without a result (corrupt or truncated file?)")));
}

// ---- objects as bytes ------------------------------------------------------------------------

namespace {

constexpr std::uint64_t kNoMesh = ~std::uint64_t{0};

}  // namespace

std::string packObjects(const std::vector<Object>& objects, const std::vector<std::string>& notes) {
  std::map<const Mesh*, std::uint64_t> index;
  std::vector<const Mesh*> meshes;
  for (const Object& o : objects)
    if (o.mesh && index.emplace(o.mesh.get(), meshes.size()).second) meshes.push_back(o.mesh.get());
  Packer out;
  out.value(static_cast<std::uint64_t>(meshes.size()));
  for (const Mesh* mesh : meshes) {
    out.array(mesh->positions);
    out.array(mesh->normals);
    out.array(mesh->colors);
    out.array(mesh->indices);
    out.value(static_cast<std::uint64_t>(mesh->fields.size()));
    for (const MeshField& field : mesh->fields) {
      out.text(field.name);
      out.value(field.cellData);
      out.value(field.components);
      out.array(field.values);
    }
    out.array(mesh->scalars);
  }
  out.value(static_cast<std::uint64_t>(objects.size()));
  for (const Object& o : objects) {
    out.text(o.name);
    out.value(o.mesh ? index.at(o.mesh.get()) : kNoMesh);
    out.value(o.transform);
    out.value(o.material.color);
    out.value(o.material.vertexColors);
    out.value(o.material.fieldColors.has_value());
    if (o.material.fieldColors) {
      out.text(o.material.fieldColors->field);
      out.text(o.material.fieldColors->map);
      out.value(o.material.fieldColors->range);
    }
    out.value(o.visible);
  }
  out.value(static_cast<std::uint64_t>(notes.size()));
  for (const std::string& note : notes) out.text(note);
  return std::move(out.bytes);
}

std::vector<Object> unpackObjects(const std::string& bytes, std::vector<std::string>* notes) {
  Unpacker in(bytes);
  std::vector<std::shared_ptr<const Mesh>> meshes(
      static_cast<std::size_t>(std::min<std::uint64_t>(in.value<std::uint64_t>(), bytes.size())));
  for (auto& shared : meshes) {
    auto mesh = std::make_shared<Mesh>();
    mesh->positions = in.array<glm::vec3>();
    mesh->normals = in.array<glm::vec3>();
    mesh->colors = in.array<glm::vec4>();
    mesh->indices = in.array<std::uint32_t>();
    const auto fields = in.value<std::uint64_t>();
    if (fields > bytes.size()) Unpacker::fail();
    for (std::uint64_t f = 0; f < fields; ++f) {
      MeshField field;
      field.name = in.text();
      field.cellData = in.value<bool>();
      field.components = in.value<int>();
      field.values = in.array<float>();
      mesh->fields.push_back(std::move(field));
    }
    mesh->scalars = in.array<float>();
    shared = std::move(mesh);
  }
  const auto count = in.value<std::uint64_t>();
  if (count > bytes.size()) Unpacker::fail();
  std::vector<Object> objects(static_cast<std::size_t>(count));
  for (Object& o : objects) {
    o.name = in.text();
    const auto mesh = in.value<std::uint64_t>();
    if (mesh != kNoMesh) {
      if (mesh >= meshes.size()) Unpacker::fail();
      o.mesh = meshes[static_cast<std::size_t>(mesh)];
    }
    o.transform = in.value<glm::dmat4>();
    o.material.color = in.value<glm::vec4>();
    o.material.vertexColors = in.value<bool>();
    if (in.value<bool>()) {
      FieldColors colors;
      colors.field = in.text();
      colors.map = in.text();
      colors.range = in.value<glm::dvec2>();
      o.material.fieldColors = std::move(colors);
    }
    o.visible = in.value<bool>();
  }
  const auto noteCount = in.value<std::uint64_t>();
  if (noteCount > bytes.size()) Unpacker::fail();
  std::vector<std::string> read(static_cast<std::size_t>(noteCount));
  for (std::string& note : read) note = in.text();
  if (!in.done()) Unpacker::fail();
  if (notes != nullptr) notes->insert(notes->end(), read.begin(), read.end());
  return objects;
}

}  // namespace mfr::io
