#pragma once
// Points bucketed in cubes of one size, found by a hash of the cube's integer coordinates (private
// to mfrcore). Unlike a locator whose buckets divide the points' bounding box (VTK's), one point
// far from the others does not make the buckets around the rest huge: a molecule with a stray atom
// 10⁵ Å away is searched as fast as without it.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include <glm/glm.hpp>

namespace mfr {

class PointGrid {
 public:
  // `cell` > 0: the cube's side; searches within about one cell are cheapest.
  PointGrid(const std::vector<glm::dvec3>& points, double cell) : points_(points), cell_(cell) {
    cells_.reserve(points.size());
    for (std::size_t i = 0; i < points.size(); ++i)
      cells_[key(cellOf(points[i]))].push_back(static_cast<std::uint32_t>(i));
    for (const auto& [k, members] : cells_) largest_ = std::max(largest_, members.size());
  }

  // Calls f(index, squared distance) for every point within `radius` of p (in no set order).
  template <class F>
  void forEachWithin(const glm::dvec3& p, double radius, F&& f) const {
    const glm::i64vec3 lo = cellOf(p - radius), hi = cellOf(p + radius);
    const double r2 = radius * radius;
    for (std::int64_t z = lo.z; z <= hi.z; ++z)
      for (std::int64_t y = lo.y; y <= hi.y; ++y)
        for (std::int64_t x = lo.x; x <= hi.x; ++x) {
          const auto it = cells_.find(key({x, y, z}));
          if (it == cells_.end()) continue;
          for (const std::uint32_t i : it->second) {
            const glm::dvec3 d = points_[i] - p;
            const double d2 = glm::dot(d, d);
            if (d2 <= r2) f(i, d2);
          }
        }
  }

  // The most points in one cube: how dense the densest spot is.
  [[nodiscard]] std::size_t largestCell() const { return largest_; }

 private:
  [[nodiscard]] glm::i64vec3 cellOf(const glm::dvec3& p) const {
    return {static_cast<std::int64_t>(std::floor(p.x / cell_)), static_cast<std::int64_t>(std::floor(p.y / cell_)),
            static_cast<std::int64_t>(std::floor(p.z / cell_))};
  }
  // 21 bits per axis (offset to be non-negative): cells within ±10⁶ of the origin, plenty for the
  // coordinates the loaders accept (±10⁵ Å) at cells of 0.1 Å and more.
  static std::uint64_t key(const glm::i64vec3& c) {
    constexpr std::int64_t kOffset = std::int64_t{1} << 20, kMask = (std::int64_t{1} << 21) - 1;
    return (static_cast<std::uint64_t>((c.x + kOffset) & kMask) << 42) |
           (static_cast<std::uint64_t>((c.y + kOffset) & kMask) << 21) |
           static_cast<std::uint64_t>((c.z + kOffset) & kMask);
  }

  const std::vector<glm::dvec3>& points_;
  double cell_;
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> cells_;
  std::size_t largest_ = 0;
};

}  // namespace mfr
