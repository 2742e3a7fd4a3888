#pragma once
// How much memory this process may still take. Linux overcommits: a huge allocation succeeds and
// the process is killed later, with no message, when it touches the pages. So the allocations that
// grow with the image (the oracle's fragment lists, FLIP's planes, and the buffers of a software
// OpenGL such as llvmpipe, whose "GPU memory" is this memory) ask here first and refuse in one line.
#include <cstdint>
#include <optional>
#include <string>

namespace mfr {

// Bytes this process can still touch without swapping: Linux's MemAvailable (/proc/meminfo), at
// most what a container's cgroup memory limit leaves, and
// where the environment sets MFR_MEMORY_LIMIT_MIB, at most that limit less this process's resident
// memory. nullopt where neither is known (no /proc): nothing is refused then.
std::optional<std::uint64_t> availableHostMemory();

// Throws mfr::Error(what, "<purpose> would take N more memory; only M is available") when
// `bytes` more would not fit in availableHostMemory().
void requireHostMemory(const std::string& what, const std::string& purpose, std::uint64_t bytes);

// "1.50 GiB", "12 MiB", "512 bytes": for messages.
std::string formatMemory(std::uint64_t bytes);

}  // namespace mfr
