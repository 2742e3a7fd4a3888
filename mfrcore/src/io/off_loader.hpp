#pragma once
// OFF through CGAL's polygon-soup reader (private to mfrcore/io); kept in its own translation
// unit because CGAL headers are slow to compile. CGAL reads every OFF file of the CGAL demo data
// exactly, where assimp's OFF importer drops faces of several of them.
#include <string>
#include <string_view>

#include "vtk_loader.hpp"

namespace mfr::io {

// OFF / COFF / NOFF (ASCII or BINARY) with per-vertex colours. Throws mfr::Error(name, reason).
PolygonSoup parseOff(std::string_view bytes, const std::string& name);

}  // namespace mfr::io
