#pragma once
// PLY parser (private to mfrcore/io). Our own rather than vtkPLYReader: VTK's reader prints to
// stderr, over-allocates from header counts and accepts truncated ASCII data, and we need every
// failure to be a one-line mfr::Error.
#include <string>
#include <string_view>

#include "vtk_loader.hpp"

namespace mfr::io {

// ASCII, binary little- and big-endian PLY: vertex x/y/z, optional nx/ny/nz and
// red/green/blue[/alpha], face vertex_indices (or vertex_index). Other elements are skipped.
// Throws mfr::Error(name, reason) for any malformed or truncated input.
PolygonSoup parsePly(std::string_view bytes, const std::string& name);

}  // namespace mfr::io
