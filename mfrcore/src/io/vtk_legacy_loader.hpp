#pragma once
// Legacy .vtk POLYDATA parser (private to mfrcore/io). Our own rather than vtkPolyDataReader,
// which crashes on small corruptions (a mangled keyword line makes it read from a closed stream)
// and sizes its arrays from unchecked header counts.
#include <string>
#include <string_view>

#include "vtk_loader.hpp"

namespace mfr::io {

// ASCII and BINARY (big-endian) POLYDATA, in the classic cell layout ("POLYGONS n size") and the
// 5.1 layout (OFFSETS / CONNECTIVITY). POINTS, POLYGONS and TRIANGLE_STRIPS are read; vertices,
// lines, FIELD and METADATA blocks are skipped; POINT_DATA / CELL_DATA end the geometry, and
// their SCALARS, VECTORS, TENSORS and FIELD arrays become the soup's fields (COLOR_SCALARS its
// colours).
// Throws mfr::Error(name, reason).
PolygonSoup parseLegacyVtk(std::string_view bytes, const std::string& name);

}  // namespace mfr::io
