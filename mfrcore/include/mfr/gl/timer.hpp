#pragma once
// GPU time per named pass through GL_TIME_ELAPSED queries; results are read after the frame.
#include <string>
#include <utility>
#include <vector>

#include "mfr/gl/objects.hpp"

namespace mfr::gl {

class PassTimer {
 public:
  void begin(const std::string& pass);
  void end();
  // Waits for the queries and returns (pass, milliseconds) in order; passes with the same name
  // (e.g. peeling iterations) are summed. Clears the timer.
  std::vector<std::pair<std::string, double>> collect();

 private:
  struct Entry {
    std::string pass;
    Query query;
  };
  std::vector<Entry> entries_;
  bool open_ = false;
};

}  // namespace mfr::gl
