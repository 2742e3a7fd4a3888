#include "mfr/gl/timer.hpp"

#include <algorithm>

namespace mfr::gl {

// Timestamps (glQueryCounter) rather than GL_TIME_ELAPSED: llvmpipe reported a garbage elapsed
// time (10^6 ms) for the first query of a context.
void PassTimer::begin(const std::string& pass) {
  if (open_) end();
  if (finishMode_) {
    glFinish();
    entries_.push_back(Entry{pass, Query(), Query(), 0.0});
    cpuStart_ = std::chrono::steady_clock::now();
    open_ = true;
    return;
  }
  Entry e{pass, createQuery(GL_TIMESTAMP), createQuery(GL_TIMESTAMP), 0.0};
  glQueryCounter(e.start.id(), GL_TIMESTAMP);
  entries_.push_back(std::move(e));
  open_ = true;
}

void PassTimer::end() {
  if (!open_) return;
  if (finishMode_) {
    glFinish();
    entries_.back().cpuMs =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - cpuStart_).count();
    open_ = false;
    return;
  }
  glQueryCounter(entries_.back().stop.id(), GL_TIMESTAMP);
  open_ = false;
}

std::vector<std::pair<std::string, double>> PassTimer::collect() {
  end();
  std::vector<std::pair<std::string, double>> out;
  for (const Entry& e : entries_) {
    double ms = e.cpuMs;
    if (e.start) {
      GLuint64 t0 = 0, t1 = 0;
      glGetQueryObjectui64v(e.start.id(), GL_QUERY_RESULT, &t0);
      glGetQueryObjectui64v(e.stop.id(), GL_QUERY_RESULT, &t1);
      ms = t1 > t0 ? static_cast<double>(t1 - t0) * 1e-6 : 0.0;
    }
    auto it = std::find_if(out.begin(), out.end(), [&](const auto& p) { return p.first == e.pass; });
    if (it == out.end())
      out.emplace_back(e.pass, ms);
    else
      it->second += ms;
  }
  entries_.clear();
  return out;
}

}  // namespace mfr::gl
