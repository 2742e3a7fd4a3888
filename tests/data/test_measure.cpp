// Surface measures (scene/measure.hpp) on real files against VTK's vtkMassProperties (its own
// area and volume integrals on the same triangles), and the isosurfaces of a real CT checked for
// what measures reveal: consistently wound, manifold, open only where the grid ends.
#include <gtest/gtest.h>

#include <vtkCleanPolyData.h>
#include <vtkClipClosedSurface.h>
#include <vtkMassProperties.h>
#include <vtkNew.h>
#include <vtkPlane.h>
#include <vtkPlaneCollection.h>
#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkTriangle.h>
#include <vtkTriangleFilter.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <string>

#include "mfr/io/load.hpp"
#include "mfr/scene/contour.hpp"
#include "mfr/scene/measure.hpp"
#include "mfr/scene/section.hpp"
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

// VTK's vtkClipClosedSurface (its own clipping and face generation) of the part's world-space
// triangles, coincident points merged first (OCCT meshes each B-rep face apart): the kept volume
// and area, and the area of the faces it generated (cells labelled non-zero).
struct VtkClip {
  double volume = 0.0, area = 0.0, faceArea = 0.0;
};
VtkClip vtkClip(const Object& o, const glm::dvec3& point, const glm::dvec3& normal) {
  vtkNew<vtkCleanPolyData> clean;
  clean->SetInputData(worldPolyData(o));
  clean->SetTolerance(1e-6);  // of the bounding box's diagonal, as measureSurface welds
  vtkNew<vtkPlane> plane;
  plane->SetOrigin(point.x, point.y, point.z);
  plane->SetNormal(normal.x, normal.y, normal.z);
  vtkNew<vtkPlaneCollection> planes;
  planes->AddItem(plane);
  vtkNew<vtkClipClosedSurface> clip;
  clip->SetInputConnection(clean->GetOutputPort());
  clip->SetClippingPlanes(planes);
  clip->SetScalarModeToLabels();
  vtkNew<vtkTriangleFilter> triangles;  // clipped triangles come out as polygons; the mass filter takes triangles
  triangles->SetInputConnection(clip->GetOutputPort());
  vtkNew<vtkMassProperties> mass;
  mass->SetInputConnection(triangles->GetOutputPort());
  mass->Update();
  VtkClip out{mass->GetVolume(), mass->GetSurfaceArea(), 0.0};
  vtkPolyData* result = triangles->GetOutput();
  vtkDataArray* labels = result->GetCellData()->GetScalars();
  for (vtkIdType c = 0; labels != nullptr && c < result->GetNumberOfCells(); ++c) {
    if (labels->GetTuple1(c) == 0.0 || result->GetCellType(c) != VTK_TRIANGLE) continue;
    double p[3][3];
    vtkIdType n = 0;
    const vtkIdType* ids = nullptr;
    result->GetCellPoints(c, n, ids);
    for (int k = 0; k < 3; ++k) result->GetPoint(ids[k], p[k]);
    out.faceArea += vtkTriangle::TriangleArea(p[0], p[1], p[2]);
  }
  return out;
}

// A section through real CAD solids (OCCT's meshes of linkrods.step and screw.step), on each axis
// a little off the centre of the bounds: every cut part is capped, and its kept volume and
// cross-section area (mfr info --section) are VTK's vtkClipClosedSurface's.
TEST(MeasureRealFiles, SectionKeptVolumesAndCrossSectionsAreVtks) {
  for (const char* file :
       {"/usr/share/opencascade/data/step/linkrods.step", "/usr/share/opencascade/data/step/screw.step"}) {
    Scene scene = load(file);
    ASSERT_FALSE(scene.objects.empty());
    const Bounds b = scene.bounds();
    std::size_t compared = 0;
    for (int axis = 0; axis < 3; ++axis) {
      SCOPED_TRACE(::testing::Message() << file << ", axis " << axis);
      glm::dvec3 point = 0.5 * (b.min + b.max), normal(0.0);
      point[axis] += 0.0123 * (b.max - b.min)[axis];
      normal[axis] = axis == 1 ? -1.0 : 1.0;
      scene.section = SectionPlane{point, normal, true};
      SectionReport report;
      const Scene cut = sectionedScene(scene, &report);
      EXPECT_TRUE(report.open.empty());
      EXPECT_GT(report.capped, 0u);
      for (std::size_t i = 0; i < cut.objects.size(); ++i) {
        if (report.outcomes[i] != SectionOutcome::kCapped) continue;
        const Object& part = cut.objects[i];
        SCOPED_TRACE(part.name);
        const SurfaceMeasures m = measureSurface(*part.mesh, part.transform);
        ASSERT_TRUE(m.closed());
        const VtkClip v = vtkClip(scene.objects[i], point, normal);
        EXPECT_NEAR(m.volume, v.volume, 1e-5 * v.volume);
        EXPECT_NEAR(m.area, v.area, 1e-5 * v.area);
        EXPECT_NEAR(report.capAreas[i], v.faceArea, 1e-5 * v.faceArea);
        ++compared;
      }
    }
    EXPECT_GT(compared, 2u);
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
