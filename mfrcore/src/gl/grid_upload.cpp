#include "grid_upload.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <utility>
#include <vector>

namespace mfr::gl {
namespace {

double computeScale(const VolumeGrid& grid) {
  float largest = 0.0f;
  for (const float v : grid.values)
    if (std::isfinite(v)) largest = std::max(largest, std::abs(v));
  if (!(largest > 0.0f) || largest >= 0x1p-32f) return 1.0;
  return std::ldexp(1.0, -std::ilogb(largest));
}

}  // namespace

double gridValueScale(const std::shared_ptr<const VolumeGrid>& grid) {
  // By address, checked against the grid itself: an address a freed grid had may come back.
  static std::mutex mutex;
  static std::map<const VolumeGrid*, std::pair<std::weak_ptr<const VolumeGrid>, double>> known;
  const std::lock_guard<std::mutex> lock(mutex);
  if (const auto it = known.find(grid.get()); it != known.end() && it->second.first.lock() == grid)
    return it->second.second;
  std::erase_if(known, [](const auto& entry) { return entry.second.first.expired(); });
  const double scale = computeScale(*grid);
  known[grid.get()] = {grid, scale};
  return scale;
}

std::shared_ptr<Texture> uploadGrid(const std::shared_ptr<const VolumeGrid>& grid) {
  const glm::ivec3 d = grid->dims;
  auto texture = std::make_shared<Texture>(createTexture3D(GL_R32F, d.x, d.y, d.z));
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  const double scale = gridValueScale(grid);
  if (scale == 1.0) {
    glTextureSubImage3D(texture->id(), 0, 0, 0, 0, d.x, d.y, d.z, GL_RED, GL_FLOAT, grid->values.data());
  } else {
    std::vector<float> scaled(grid->values.size());
    for (std::size_t i = 0; i < scaled.size(); ++i)
      scaled[i] = static_cast<float>(static_cast<double>(grid->values[i]) * scale);
    glTextureSubImage3D(texture->id(), 0, 0, 0, 0, d.x, d.y, d.z, GL_RED, GL_FLOAT, scaled.data());
  }
  return texture;
}

}  // namespace mfr::gl
