#pragma once
// The GPU copy of a volume grid: GpuScene's field colouring and GpuRenderer's volume operation
// share one R32F texture per grid. A grid whose largest magnitude is below 2^-32 is uploaded
// scaled by a power of two to about 1, and every range compared with its samples (the transfer
// window, the colour map's range) is scaled alike: GPUs flush subnormal floats, and a volume of
// values near 1e-37 drew blank where the oracle drew it (a bug hunt: RMSE 0.25 at 1e-37, 0.003 at
// 1e-35). A power of two is exact, so the GPU's arithmetic stays the oracle's.
#include <memory>

#include "mfr/gl/objects.hpp"
#include "mfr/scene/volume.hpp"

namespace mfr::gl {

// 1, or the power of two that brings the grid's largest finite magnitude into [1, 2) when it is
// below 2^-32 (a double: 2^149 for the smallest subnormal). One pass over the samples the first
// time a grid is asked for; remembered while the grid lives (every upload of an edited scene asks
// again, and grids are immutable).
double gridValueScale(const std::shared_ptr<const VolumeGrid>& grid);

// The grid's samples times gridValueScale(grid), as a 3D R32F texture.
std::shared_ptr<Texture> uploadGrid(const std::shared_ptr<const VolumeGrid>& grid);

}  // namespace mfr::gl
