#include "grid_upload.hpp"

#include <cmath>
#include <vector>

namespace mfr::gl {

double gridValueScale(const VolumeGrid& grid) {
  float largest = 0.0f;
  for (const float v : grid.values)
    if (std::isfinite(v)) largest = std::max(largest, std::abs(v));
  if (!(largest > 0.0f) || largest >= 0x1p-32f) return 1.0;
  return std::ldexp(1.0, -std::ilogb(largest));
}

std::shared_ptr<Texture> uploadGrid(const VolumeGrid& grid) {
  const glm::ivec3 d = grid.dims;
  auto texture = std::make_shared<Texture>(createTexture3D(GL_R32F, d.x, d.y, d.z));
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  const double scale = gridValueScale(grid);
  if (scale == 1.0) {
    glTextureSubImage3D(texture->id(), 0, 0, 0, 0, d.x, d.y, d.z, GL_RED, GL_FLOAT, grid.values.data());
  } else {
    std::vector<float> scaled(grid.values.size());
    for (std::size_t i = 0; i < scaled.size(); ++i)
      scaled[i] = static_cast<float>(static_cast<double>(grid.values[i]) * scale);
    glTextureSubImage3D(texture->id(), 0, 0, 0, 0, d.x, d.y, d.z, GL_RED, GL_FLOAT, scaled.data());
  }
  return texture;
}

}  // namespace mfr::gl
