#include "mfr/gl/timer.hpp"

#include <algorithm>

namespace mfr::gl {

void PassTimer::begin(const std::string& pass) {
  if (open_) end();
  Entry e{pass, createQuery(GL_TIME_ELAPSED)};
  glBeginQuery(GL_TIME_ELAPSED, e.query.id());
  entries_.push_back(std::move(e));
  open_ = true;
}

void PassTimer::end() {
  if (!open_) return;
  glEndQuery(GL_TIME_ELAPSED);
  open_ = false;
}

std::vector<std::pair<std::string, double>> PassTimer::collect() {
  end();
  std::vector<std::pair<std::string, double>> out;
  for (const Entry& e : entries_) {
    GLuint64 ns = 0;
    glGetQueryObjectui64v(e.query.id(), GL_QUERY_RESULT, &ns);
    const double ms = static_cast<double>(ns) * 1e-6;
    auto it = std::find_if(out.begin(), out.end(), [&](const auto& p) { return p.first == e.pass; });
    if (it == out.end()) out.emplace_back(e.pass, ms);
    else it->second += ms;
  }
  entries_.clear();
  return out;
}

}  // namespace mfr::gl
