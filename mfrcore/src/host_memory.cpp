#include "mfr/host_memory.hpp"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <utility>

#include "mfr/error.hpp"

namespace mfr {

namespace {

// MemAvailable from /proc/meminfo, in bytes.
std::optional<std::uint64_t> memAvailable() {
  std::ifstream in("/proc/meminfo");
  std::string key;
  std::uint64_t kib = 0;
  std::string unit;
  while (in >> key >> kib >> unit)
    if (key == "MemAvailable:") return kib * 1024;
  return std::nullopt;
}

// What a container's memory limit leaves (cgroup v2 memory.max − memory.current, or v1's
// limit_in_bytes − usage_in_bytes, as seen from inside it); nullopt without a limit. MemAvailable is
// the whole machine's and would let a limited container be killed all the same.
std::optional<std::uint64_t> cgroupLeft() {
  const auto read = [](const char* path) -> std::optional<std::uint64_t> {
    std::ifstream in(path);
    std::string text;
    if (!(in >> text) || text.empty() || text[0] < '0' || text[0] > '9') return std::nullopt;  // "max": none
    return std::strtoull(text.c_str(), nullptr, 10);
  };
  // The usage counts the page cache; its inactive part is given back before anything is killed
  // (what `docker stats` subtracts too).
  const auto inactiveFile = [](const char* path, const char* key) -> std::uint64_t {
    std::ifstream in(path);
    std::string name;
    std::uint64_t value = 0;
    while (in >> name >> value)
      if (name == key) return value;
    return 0;
  };
  struct Files {
    const char *limit, *usage, *stat, *inactive;
  };
  for (const Files& f :
       {Files{"/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory.current", "/sys/fs/cgroup/memory.stat",
              "inactive_file"},
        Files{"/sys/fs/cgroup/memory/memory.limit_in_bytes", "/sys/fs/cgroup/memory/memory.usage_in_bytes",
              "/sys/fs/cgroup/memory/memory.stat", "total_inactive_file"}}) {
    const std::optional<std::uint64_t> limit = read(f.limit), usage = read(f.usage);
    // v1 writes "no limit" as a page-rounded 2^63.
    if (!limit || !usage || *limit >= (std::uint64_t{1} << 62)) continue;
    const std::uint64_t inactive = inactiveFile(f.stat, f.inactive);
    const std::uint64_t used = *usage > inactive ? *usage - inactive : 0;
    return *limit > used ? *limit - used : 0;
  }
  return std::nullopt;
}

// This process's resident memory (second field of /proc/self/statm, in pages).
std::optional<std::uint64_t> residentBytes() {
  std::ifstream in("/proc/self/statm");
  std::uint64_t size = 0, resident = 0;
  if (!(in >> size >> resident)) return std::nullopt;
  const long page = sysconf(_SC_PAGESIZE);
  return resident * static_cast<std::uint64_t>(page > 0 ? page : 4096);
}

// MFR_MEMORY_LIMIT_MIB as bytes; nullopt when unset. A value that is not a positive whole number
// is refused rather than ignored: a limit that silently does nothing is worse than none.
std::optional<std::uint64_t> environmentLimit() {
  const char* text = std::getenv("MFR_MEMORY_LIMIT_MIB");
  if (text == nullptr || *text == '\0') return std::nullopt;
  const auto refuse = [&] {
    return Error("MFR_MEMORY_LIMIT_MIB", "'" + std::string(text) + "' is not a positive whole number of MiB");
  };
  if (*text < '0' || *text > '9') throw refuse();  // strtoull would take a sign or blanks
  errno = 0;
  char* end = nullptr;
  const unsigned long long mib = std::strtoull(text, &end, 10);
  if (errno != 0 || *end != '\0' || mib == 0) throw refuse();
  if (mib > (UINT64_MAX >> 20))
    throw Error("MFR_MEMORY_LIMIT_MIB",
                "'" + std::string(text) + "' MiB is more bytes than 2^64: at most " + std::to_string(UINT64_MAX >> 20));
  return static_cast<std::uint64_t>(mib) << 20;
}

struct Available {
  std::optional<std::uint64_t> bytes;
  bool byLimit = false;  // MFR_MEMORY_LIMIT_MIB, not the machine, decides
};

Available available() {
  Available a{memAvailable()};
  if (const std::optional<std::uint64_t> left = cgroupLeft()) a.bytes = a.bytes ? std::min(*a.bytes, *left) : *left;
  if (const std::optional<std::uint64_t> limit = environmentLimit()) {
    const std::uint64_t used = residentBytes().value_or(0);
    const std::uint64_t left = limit > used ? *limit - used : 0;
    a.byLimit = !a.bytes || left < *a.bytes;
    a.bytes = a.byLimit ? left : a.bytes;
  }
  return a;
}

}  // namespace

std::optional<std::uint64_t> availableHostMemory() {
  return available().bytes;
}

std::string formatMemory(std::uint64_t bytes) {
  char text[64];
  if (bytes >= (std::uint64_t{1} << 30))
    std::snprintf(text, sizeof text, "%.2f GiB", static_cast<double>(bytes) / static_cast<double>(1u << 30));
  else if (bytes >= (std::uint64_t{1} << 20))
    std::snprintf(text, sizeof text, "%.0f MiB", static_cast<double>(bytes) / static_cast<double>(1u << 20));
  else
    std::snprintf(text, sizeof text, "%llu bytes", static_cast<unsigned long long>(bytes));
  return text;
}

void requireHostMemory(const std::string& what, const std::string& purpose, std::uint64_t bytes) {
  const Available a = available();
  if (!a.bytes || bytes <= *a.bytes) return;
  throw Error(what, purpose + " would take " + formatMemory(bytes) + " more memory; only " + formatMemory(*a.bytes) +
                        " is available" +
                        (a.byLimit ? " under MFR_MEMORY_LIMIT_MIB=" + std::string(std::getenv("MFR_MEMORY_LIMIT_MIB"))
                                   : std::string()));
}

}  // namespace mfr
