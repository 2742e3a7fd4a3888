// The data arrays of surface files as fields to colour by (Mesh::fields): a polydata written by
// VTK's own XML writer with point data (a scalar and a vector), cell data over vertices, lines,
// polygons of 3–5 corners and a triangle strip, and a crease that makes the loader split points.
// Every vertex's values must be the function of its position that was written, and every
// triangle's cell value that of the cell it came from (found by where the triangle lies).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkFloatArray.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkUnsignedCharArray.h>
#include <vtkPolyDataWriter.h>
#include <vtkSmartPointer.h>
#include <vtkXMLPolyDataWriter.h>

#include "mfr/error.hpp"
#include "mfr/io/load.hpp"
#include "mfr/scene/color_map.hpp"
#include "test_files.hpp"

namespace {

class VtkWrittenSurfaces : public mfr::test::TempDirTest {};

// A 6 × 4 grid of points over x in [0, 5], y in [0, 3], folded along x = 2 (z = |x − 2|: the
// faces meet at 90°, so the loader's feature-angle normals split the crease's points).
constexpr int kNx = 6, kNy = 4;
double height(double x) {
  return std::abs(x - 2.0);
}
double temperature(double x, double y, double z) {
  return 3.0 * x - 2.0 * y * y + 0.5 * z;
}

vtkSmartPointer<vtkPolyData> foldedSheet() {
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  vtkNew<vtkPoints> points;
  for (int j = 0; j < kNy; ++j)
    for (int i = 0; i < kNx; ++i) points->InsertNextPoint(i, j, height(i));
  pd->SetPoints(points);
  const auto id = [](int i, int j) { return static_cast<vtkIdType>(j * kNx + i); };
  // Cells in VTK's order: two vertices and a line first (their cell data comes first too), then
  // polygons over rows 0 and 1 — quads, except cell (1, 0) as a triangle pair and cells (3, 1) and
  // (4, 1) as one pentagon — and one strip over row 2.
  vtkNew<vtkCellArray> verts, lines, polys, strips;
  const vtkIdType v0[1] = {id(0, 0)}, v1[1] = {id(5, 3)};
  verts->InsertNextCell(1, v0);
  verts->InsertNextCell(1, v1);
  const vtkIdType line[2] = {id(0, 3), id(5, 3)};
  lines->InsertNextCell(2, line);
  vtkNew<vtkIntArray> material;  // per cell: 1000 for vertices and lines, 100·i + j for grid cell (i, j)
  material->SetName("material");
  for (int k = 0; k < 3; ++k) material->InsertNextValue(1000);
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < kNx - 1; ++i) {
      if (j == 1 && i == 4) continue;  // in the pentagon of (3, 1)
      if (j == 0 && i == 1) {
        const vtkIdType a[3] = {id(1, 0), id(2, 0), id(2, 1)}, b[3] = {id(1, 0), id(2, 1), id(1, 1)};
        polys->InsertNextCell(3, a);
        material->InsertNextValue(100 * i + j);
        polys->InsertNextCell(3, b);
        material->InsertNextValue(100 * i + j);
        continue;
      }
      if (j == 1 && i == 3) {
        // Flat: x from 3 to 5 lies on one side of the fold.
        const vtkIdType p[5] = {id(3, 1), id(4, 1), id(5, 1), id(5, 2), id(3, 2)};
        polys->InsertNextCell(5, p);
        material->InsertNextValue(100 * i + j);
        continue;
      }
      const vtkIdType q[4] = {id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)};
      polys->InsertNextCell(4, q);
      material->InsertNextValue(100 * i + j);
    }
  std::vector<vtkIdType> strip;
  for (int i = 0; i < kNx; ++i) {
    strip.push_back(id(i, 2));
    strip.push_back(id(i, 3));
  }
  strips->InsertNextCell(static_cast<vtkIdType>(strip.size()), strip.data());
  material->InsertNextValue(777);
  pd->SetVerts(verts);
  pd->SetLines(lines);
  pd->SetPolys(polys);
  pd->SetStrips(strips);
  pd->GetCellData()->SetScalars(material);  // the legacy writer's SCALARS … LOOKUP_TABLE

  vtkNew<vtkDoubleArray> temp;
  temp->SetName("temperature");
  vtkNew<vtkFloatArray> velocity;
  velocity->SetName("velocity");
  velocity->SetNumberOfComponents(3);
  vtkNew<vtkUnsignedCharArray> colors;  // colours, not a field
  colors->SetName("Colors");
  colors->SetNumberOfComponents(3);
  for (vtkIdType p = 0; p < pd->GetNumberOfPoints(); ++p) {
    double x[3];
    pd->GetPoint(p, x);
    temp->InsertNextValue(temperature(x[0], x[1], x[2]));
    velocity->InsertNextTuple3(x[1], -x[0], 2.0 * x[2]);
    colors->InsertNextTuple3(200, 100, 50);
  }
  pd->GetPointData()->AddArray(temp);
  pd->GetPointData()->SetVectors(velocity);  // VECTORS; temperature goes into a FIELD block
  pd->GetPointData()->SetScalars(colors);
  return pd;
}

// The fields of the loaded sheet against the functions written.
void expectFoldedSheetFields(const std::filesystem::path& file) {
  SCOPED_TRACE(file.filename().string());
  const std::vector<mfr::Object> parts = mfr::loadModel(file);
  ASSERT_EQ(parts.size(), 1u);
  const mfr::Mesh& mesh = *parts[0].mesh;
  ASSERT_NO_THROW(mesh.validate("folded"));
  std::vector<std::string> names = mfr::fieldNames(mesh);  // in file order, which differs by format
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"material", "temperature", "velocity", "velocity:1", "velocity:2",
                                             "velocity:magnitude"}));
  ASSERT_EQ(mesh.colors.size(), mesh.positions.size());  // the colour scalars stay colours
  // The crease split points: more vertices than the file has, each copy with its own values.
  EXPECT_GT(mesh.positions.size(), static_cast<std::size_t>(kNx * kNy));
  const mfr::FieldValues t = mfr::fieldValues(mesh, "temperature", "folded");
  const mfr::FieldValues vy = mfr::fieldValues(mesh, "velocity:1", "folded");
  const mfr::FieldValues speed = mfr::fieldValues(mesh, "velocity:magnitude", "folded");
  ASSERT_EQ(t.values.size(), mesh.positions.size());
  EXPECT_FALSE(t.cellData);
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    const glm::dvec3 p(mesh.positions[v]);
    EXPECT_FLOAT_EQ(t.values[v], static_cast<float>(temperature(p.x, p.y, p.z))) << v;
    EXPECT_FLOAT_EQ(vy.values[v], static_cast<float>(-p.x)) << v;
    EXPECT_NEAR(speed.values[v], std::sqrt(p.y * p.y + p.x * p.x + 4.0 * p.z * p.z), 1e-5) << v;
  }
  // Every triangle's material is that of the grid cell its centre lies in (the strip: 777).
  const mfr::FieldValues m = mfr::fieldValues(mesh, "material", "folded");
  EXPECT_TRUE(m.cellData);
  ASSERT_EQ(m.values.size(), mesh.triangleCount());
  std::size_t stripTriangles = 0;
  for (std::size_t tri = 0; tri < mesh.triangleCount(); ++tri) {
    glm::dvec3 c(0.0);
    for (int k = 0; k < 3; ++k)
      c += glm::dvec3(mesh.positions[mesh.indices[3 * tri + static_cast<std::size_t>(k)]]) / 3.0;
    int i = static_cast<int>(std::floor(c.x)), j = static_cast<int>(std::floor(c.y));
    if (j == 1 && i == 4) i = 3;  // the pentagon
    const float expected = j >= 2 ? 777.0f : static_cast<float>(100 * i + j);
    stripTriangles += j >= 2 ? 1 : 0;
    EXPECT_EQ(m.values[tri], expected) << "triangle " << tri << " at (" << c.x << ", " << c.y << ")";
  }
  EXPECT_EQ(stripTriangles, 2u * (kNx - 1));
  // Coloured by the cell data: the range over the triangles' cells (not the vertices' and line's).
  mfr::Object part = parts[0];
  mfr::colorByField(part, "material", "viridis");
  EXPECT_EQ(part.material.fieldColors->range, glm::dvec2(0.0, 777.0));
}

TEST_F(VtkWrittenSurfaces, PointAndCellDataBecomeFieldsOfTheMesh) {
  const vtkSmartPointer<vtkPolyData> pd = foldedSheet();
  const std::filesystem::path file = dir() / "folded.vtp";
  vtkNew<vtkXMLPolyDataWriter> writer;
  writer->SetFileName(file.string().c_str());
  writer->SetInputData(pd);
  ASSERT_EQ(writer->Write(), 1);
  expectFoldedSheetFields(file);
}

// The same sheet through VTK's legacy writer, ASCII and binary: our own legacy parser reads
// SCALARS, VECTORS, COLOR_SCALARS and cell data in VTK's cell order.
TEST_F(VtkWrittenSurfaces, LegacyVtkFilesToo) {
  const vtkSmartPointer<vtkPolyData> pd = foldedSheet();
  for (const bool binary : {false, true}) {
    const std::filesystem::path file = dir() / (binary ? "folded-binary.vtk" : "folded-ascii.vtk");
    vtkNew<vtkPolyDataWriter> writer;
    writer->SetFileName(file.string().c_str());
    writer->SetInputData(pd);
    if (binary) writer->SetFileTypeToBinary();
    ASSERT_EQ(writer->Write(), 1);
    expectFoldedSheetFields(file);
  }
}

}  // namespace
