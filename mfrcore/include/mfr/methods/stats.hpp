#pragma once
// What every construction method reports about one frame.
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace mfr {

struct Stats {
  std::string method;
  std::string operation;
  std::string sync;                      // "none", "spinlock", "interlock", …
  std::uint64_t bytesAllocated = 0;      // GPU memory the method allocated for this frame
  std::uint64_t bytesUsed = 0;           // of which holding fragments or per-pixel state in use
  std::uint64_t fragmentsGenerated = 0;  // fragments rasterised (all passes' capture of unique ones)
  std::uint64_t fragmentsStored = 0;     // fragments kept in the structure
  std::uint64_t fragmentsDropped = 0;    // fragments lost to a full structure (overflow)
  std::uint64_t overflowPixels = 0;      // pixels that lost fragments to a full structure
  std::uint64_t lockFailures = 0;        // spin-lock retries exhausted
  std::uint32_t passes = 0;              // geometry passes (peeling iterations, …)
  std::uint32_t kMin = 0, kMax = 0;      // per-pixel capacity range where meaningful
  bool overflow = false;
  std::vector<std::pair<std::string, double>> passTimesMs;  // per-pass GPU time
  std::vector<std::pair<std::string, std::string>> notes;   // e.g. ("k chosen", "eq. 6 with R_h=0.9")

  // The value of note `key`, or nullptr when the method wrote none.
  [[nodiscard]] const std::string* note(const std::string& key) const {
    for (const auto& [k, v] : notes)
      if (k == key) return &v;
    return nullptr;
  }
  [[nodiscard]] double totalTimeMs() const {
    double t = 0;
    for (const auto& p : passTimesMs) t += p.second;
    return t;
  }
};

// JSON text of the stats (nlohmann-json), stable key names documented in docs/methods.md.
std::string toJson(const Stats& stats, int indent = 2);

}  // namespace mfr
