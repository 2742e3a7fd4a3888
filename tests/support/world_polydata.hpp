#pragma once
// A part's triangles in the world as VTK polydata, for the data tests that hold mfr's geometry up
// to VTK's own algorithms (vtkMassProperties, cell locators). Only tests/data links VTK.
#include <vtkCellArray.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>

#include "mfr/scene/scene.hpp"

namespace mfr::test {

inline vtkSmartPointer<vtkPolyData> worldPolyData(const Object& o) {
  vtkNew<vtkPoints> points;
  for (const glm::vec3& p : o.mesh->positions) {
    const glm::dvec3 w(o.transform * glm::dvec4(glm::dvec3(p), 1.0));
    points->InsertNextPoint(w.x, w.y, w.z);
  }
  vtkNew<vtkCellArray> triangles;
  for (std::size_t t = 0; t + 2 < o.mesh->indices.size(); t += 3) {
    const vtkIdType ids[3] = {o.mesh->indices[t], o.mesh->indices[t + 1], o.mesh->indices[t + 2]};
    triangles->InsertNextCell(3, ids);
  }
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  poly->SetPoints(points);
  poly->SetPolys(triangles);
  return poly;
}

}  // namespace mfr::test
