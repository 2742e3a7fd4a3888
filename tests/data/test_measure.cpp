// Surface measures (scene/measure.hpp) on real files against VTK's vtkMassProperties (its own
// area and volume integrals on the same triangles), and the isosurfaces of a real CT checked for
// what measures reveal: consistently wound, manifold, open only where the grid ends.
#include <gtest/gtest.h>

#include <vtkMassProperties.h>
#include <vtkNew.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <string>

#include "mfr/io/load.hpp"
#include "mfr/scene/contour.hpp"
#include "mfr/scene/measure.hpp"
#include "world_polydata.hpp"

namespace fs = std::filesystem;

namespace mfr::test {
namespace {

struct VtkMass {
  double area = 0.0, volume = 0.0;
};

// vtkMassProperties of the part's world-space triangles.
VtkMass vtkMass(const Object& o) {
  vtkNew<vtkMassProperties> mass;
  mass->SetInputData(worldPolyData(o));
  mass->Update();
  return {mass->GetSurfaceArea(), mass->GetVolume()};
}

Scene load(const fs::path& path) {
  EXPECT_TRUE(fs::exists(path)) << "missing " << path << " (scripts/setup installs it)";
  return loadScene(path);
}

// OCCT's meshes of B-rep solids are closed; their volume and area are VTK's.
TEST(MeasureRealFiles, StepSolidsAreClosedWithVtksVolumeAndArea) {
  for (const char* file :
       {"/usr/share/opencascade/data/step/linkrods.step", "/usr/share/opencascade/data/step/screw.step"}) {
    SCOPED_TRACE(file);
    const Scene scene = load(file);
    ASSERT_FALSE(scene.objects.empty());
    std::size_t closed = 0;
    for (const Object& o : scene.objects) {
      const SurfaceMeasures m = measureSurface(*o.mesh, o.transform);
      const VtkMass v = vtkMass(o);
      EXPECT_NEAR(m.area, v.area, 1e-9 * v.area) << o.name;
      if (!m.closed()) continue;
      ++closed;
      // vtkMassProperties reports |volume|; a mirrored part keeps its own sign here.
      EXPECT_GT(m.volume, 0.0) << o.name;
      EXPECT_NEAR(m.volume, v.volume, 1e-6 * v.volume) << o.name;
    }
    EXPECT_EQ(closed, scene.objects.size());  // measured: every part of both files
  }
}

// InVesalius's two surfaces: areas as VTK computes them (InVesalius itself reports VTK's volume);
// mfr's isosurfaces of the CT at the masks' thresholds: each shared edge wound both ways, no edge of
// three triangles, and open only along the CT's box (where the head runs out of the scan).
TEST(MeasureRealFiles, CraniumSurfacesAndIsosurfaces) {
  Scene scene = load("/usr/share/doc/invesalius-examples/examples/Cranium.inv3");
  ASSERT_EQ(scene.objects.size(), 2u);
  for (const Object& o : scene.objects) {
    const SurfaceMeasures m = measureSurface(*o.mesh, o.transform);
    EXPECT_NEAR(m.area, vtkMass(o).area, 1e-6 * m.area) << o.name;
  }
  const std::vector<std::size_t> added = addContours(scene, {0, {226.0, -142.0}, 0.5f}, "test");
  const Volume& v = scene.volumes[0];
  const glm::dvec3 last(v.grid->dims - 1);
  for (const std::size_t i : added) {
    const Object& o = scene.objects[i];
    SCOPED_TRACE(o.name);
    const SurfaceMeasures m = measureSurface(*o.mesh, o.transform);
    EXPECT_EQ(m.orientationFlips, 0u);
    EXPECT_EQ(m.nonManifoldEdges, 0u);
    EXPECT_GT(m.boundaryEdges, 0u);
    // Every vertex of a boundary edge on a face of the grid's box.
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
    const Mesh& mesh = *o.mesh;
    for (std::size_t t = 0; t < mesh.indices.size(); t += 3)
      for (int e = 0; e < 3; ++e) {
        const std::uint32_t a = mesh.indices[t + e], b = mesh.indices[t + (e + 1) % 3];
        ++edges[{std::min(a, b), std::max(a, b)}];
      }
    std::size_t inside = 0;
    for (const auto& [edge, count] : edges) {
      if (count != 1) continue;
      for (const std::uint32_t vertex : {edge.first, edge.second}) {
        const glm::dvec3 g = (glm::dvec3(mesh.positions[vertex]) - v.origin) / v.spacing;
        const bool onFace = glm::any(glm::lessThan(glm::abs(g), glm::dvec3(1e-3))) ||
                            glm::any(glm::lessThan(glm::abs(g - last), glm::dvec3(1e-3)));
        inside += !onFace;
      }
    }
    EXPECT_EQ(inside, 0u);
    EXPECT_NEAR(m.area, vtkMass(o).area, 1e-6 * m.area);
  }
}

}  // namespace
}  // namespace mfr::test
