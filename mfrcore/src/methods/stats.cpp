#include "mfr/methods/stats.hpp"

#include <nlohmann/json.hpp>

#include "mfr/json_text.hpp"

namespace mfr {

std::string toJson(const Stats& s, int indent) {
  nlohmann::ordered_json j;
  j["method"] = s.method;
  j["operation"] = s.operation;
  j["sync"] = s.sync;
  j["bytes_allocated"] = s.bytesAllocated;
  j["bytes_used"] = s.bytesUsed;
  j["fragments_generated"] = s.fragmentsGenerated;
  j["fragments_stored"] = s.fragmentsStored;
  j["fragments_dropped"] = s.fragmentsDropped;
  j["overflow"] = s.overflow;
  j["overflow_pixels"] = s.overflowPixels;
  j["lock_failures"] = s.lockFailures;
  j["passes"] = s.passes;
  j["k_min"] = s.kMin;
  j["k_max"] = s.kMax;
  nlohmann::ordered_json times = nlohmann::ordered_json::object();
  for (const auto& [pass, ms] : s.passTimesMs) times[pass] = ms;
  j["pass_times_ms"] = times;
  j["total_time_ms"] = s.totalTimeMs();
  nlohmann::ordered_json notes = nlohmann::ordered_json::object();
  for (const auto& [k, v] : s.notes) notes[k] = v;
  j["notes"] = notes;
  return jsonText(j, indent);
}

}  // namespace mfr
