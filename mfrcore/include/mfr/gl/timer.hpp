#pragma once
// GPU time per named pass through timestamp queries; results are read after the frame.
#include <chrono>
#include <string>
#include <utility>
#include <vector>

#include "mfr/gl/objects.hpp"

namespace mfr::gl {

// Two modes: GPU timestamp queries (real GPUs), or glFinish + CPU clock around each pass
// ("finish" mode). llvmpipe executes deferred, so its timestamps do not bracket the work: there
// the renderer uses finish mode, which measures what a user waits for.
class PassTimer {
 public:
  explicit PassTimer(bool finishMode = false) : finishMode_(finishMode) {}
  void begin(const std::string& pass);
  void end();
  // Waits for the queries and returns (pass, milliseconds) in order; passes with the same name
  // (e.g. peeling iterations) are summed. Clears the timer.
  std::vector<std::pair<std::string, double>> collect();

 private:
  struct Entry {
    std::string pass;
    Query start;
    Query stop;
    double cpuMs = 0.0;
  };
  bool finishMode_ = false;
  std::chrono::steady_clock::time_point cpuStart_;
  std::vector<Entry> entries_;
  bool open_ = false;
};

}  // namespace mfr::gl
