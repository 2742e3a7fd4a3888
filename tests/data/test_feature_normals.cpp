// orientAndSplitAtFeatures (scene/feature_normals.hpp) against the filter it replaced in the loaders,
// VTK's vtkPolyDataNormals with the loaders' settings, on real meshes: as the files give them, and
// with a third of their triangles reversed at random (so that the winding pass has work to do).
// Both get the same points and triangles; they must give the same triangles corner for corner
// (the same ones reversed, the same vertex copies numbered the same way) and the same normals.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <vtkCellArray.h>
#include <vtkDataArray.h>
#include <vtkNew.h>
#include <vtkPLYReader.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataNormals.h>
#include <vtkSTLReader.h>

#include "mfr/scene/feature_normals.hpp"
#include "test_files.hpp"

namespace fs = std::filesystem;

namespace {

using mfr::test::extractCgalMesh;
using mfr::test::TempDir;

struct Triangles {
  std::vector<glm::dvec3> points;
  std::vector<std::uint32_t> indices;
};

// An OFF file's polygons as fans (both sides get the same triangles, so how does not matter).
Triangles readOff(const fs::path& path) {
  std::ifstream file(path);
  std::stringstream text;  // without comments
  for (std::string line; std::getline(file, line);) text << line.substr(0, line.find('#')) << '\n';
  Triangles t;
  std::string magic;
  std::size_t nv = 0, nf = 0, ne = 0;
  text >> magic >> nv >> nf >> ne;
  EXPECT_EQ(magic, "OFF") << path;
  t.points.resize(nv);
  for (glm::dvec3& p : t.points) text >> p.x >> p.y >> p.z;
  for (std::size_t f = 0; f < nf && text; ++f) {
    std::size_t n = 0;
    text >> n;
    std::vector<std::uint32_t> ids(n);
    for (std::uint32_t& id : ids) text >> id;
    std::string rest;
    std::getline(text, rest);  // colours, if any
    for (std::size_t k = 1; k + 1 < n; ++k) t.indices.insert(t.indices.end(), {ids[0], ids[k], ids[k + 1]});
  }
  EXPECT_TRUE(text.good()) << path;
  return t;
}

Triangles fromPolyData(vtkPolyData* pd) {
  Triangles t;
  t.points.resize(static_cast<std::size_t>(pd->GetNumberOfPoints()));
  for (vtkIdType i = 0; i < pd->GetNumberOfPoints(); ++i) pd->GetPoint(i, &t.points[static_cast<std::size_t>(i)].x);
  vtkCellArray* polys = pd->GetPolys();
  vtkIdType n = 0;
  const vtkIdType* ids = nullptr;
  for (polys->InitTraversal(); polys->GetNextCell(n, ids) != 0;)
    for (vtkIdType k = 1; k + 1 < n; ++k)
      t.indices.insert(t.indices.end(), {static_cast<std::uint32_t>(ids[0]), static_cast<std::uint32_t>(ids[k]),
                                         static_cast<std::uint32_t>(ids[k + 1])});
  return t;
}

Triangles readStl(const fs::path& path) {
  vtkNew<vtkSTLReader> reader;
  reader->SetFileName(path.c_str());
  reader->MergingOn();  // as the loader reads STL
  reader->Update();
  return fromPolyData(reader->GetOutput());
}

Triangles readPlyGz(const fs::path& path, const TempDir& dir) {
  const fs::path ply = dir.path() / "mesh.ply";
  const std::string command = "gzip -dc '" + path.string() + "' > '" + ply.string() + "'";
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
  vtkNew<vtkPLYReader> reader;
  reader->SetFileName(ply.c_str());
  reader->Update();
  return fromPolyData(reader->GetOutput());
}

// Both implementations on the same triangles; returns how many triangles each reversed (VTK's
// own count is not public, so ours is returned for the caller's sanity checks).
std::size_t expectSameAsVtk(const Triangles& mesh, const std::string& what) {
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  for (const glm::dvec3& p : mesh.points) points->InsertNextPoint(p.x, p.y, p.z);
  vtkNew<vtkCellArray> polys;
  for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
    const vtkIdType ids[3] = {mesh.indices[t], mesh.indices[t + 1], mesh.indices[t + 2]};
    polys->InsertNextCell(3, ids);
  }
  vtkNew<vtkPolyData> input;
  input->SetPoints(points);
  input->SetPolys(polys);
  vtkNew<vtkPolyDataNormals> normals;
  normals->SetInputData(input);
  normals->SetFeatureAngle(30.0);
  normals->SplittingOn();
  normals->ConsistencyOn();
  normals->AutoOrientNormalsOff();
  normals->ComputePointNormalsOn();
  normals->ComputeCellNormalsOff();
  normals->Update();
  vtkPolyData* vtk = normals->GetOutput();

  const mfr::FeatureSplit ours = mfr::orientAndSplitAtFeatures(mesh.points, mesh.indices, 30.0);
  EXPECT_EQ(static_cast<vtkIdType>(ours.source.size()), vtk->GetNumberOfPoints()) << what;
  EXPECT_EQ(static_cast<vtkIdType>(ours.normals.size()), vtk->GetNumberOfPoints()) << what;
  const Triangles theirs = fromPolyData(vtk);
  EXPECT_EQ(ours.indices.size(), theirs.indices.size()) << what;
  std::size_t differentCorners = 0;
  for (std::size_t k = 0; k < std::min(ours.indices.size(), theirs.indices.size()); ++k)
    if (ours.indices[k] != theirs.indices[k] && differentCorners++ < 5)
      ADD_FAILURE() << what << ": corner " << k << " is vertex " << ours.indices[k] << ", VTK's " << theirs.indices[k];
  EXPECT_EQ(differentCorners, 0u) << what;
  // A copy is where its source is.
  for (std::size_t v = 0; v < std::min(ours.source.size(), theirs.points.size()); ++v)
    if (mesh.points[ours.source[v]] != theirs.points[v]) {
      ADD_FAILURE() << what << ": vertex " << v << " copies " << ours.source[v] << ", not where VTK's is";
      break;
    }
  vtkDataArray* vtkNormals = vtk->GetPointData()->GetNormals();
  EXPECT_NE(vtkNormals, nullptr);
  if (vtkNormals == nullptr) return ours.reversed;
  double worst = 0.0;
  for (std::size_t v = 0; v < std::min(ours.normals.size(), theirs.points.size()); ++v) {
    double n[3];
    vtkNormals->GetTuple(static_cast<vtkIdType>(v), n);
    worst = std::max(worst, glm::length(glm::dvec3(ours.normals[v]) - glm::dvec3(n[0], n[1], n[2])));
  }
  EXPECT_LT(worst, 1e-5) << what << ": largest difference of a vertex normal";
  return ours.reversed;
}

// The same triangles with about a third of them reversed, chosen by a fixed seed.
Triangles withRandomFlips(Triangles mesh) {
  std::mt19937 random(20261205);
  for (std::size_t t = 0; t < mesh.indices.size(); t += 3)
    if (random() % 3 == 0) std::swap(mesh.indices[t + 1], mesh.indices[t + 2]);
  return mesh;
}

void checkBoth(const Triangles& mesh, const std::string& what) {
  ASSERT_GT(mesh.indices.size(), 0u) << what;
  expectSameAsVtk(mesh, what);
  EXPECT_GT(expectSameAsVtk(withRandomFlips(mesh), what + " (a third reversed)"), mesh.indices.size() / 3 / 10)
      << what << ": the reversed triangles were not rewound";
}

}  // namespace

TEST(FeatureNormals, SameAsVtkOnCgalMeshes) {
  TempDir dir;
  // Smooth scans, CAD parts with creases and holes, and a mesh stored with mixed windings.
  for (const char* file : {"fandisk.off", "bunny00.off", "blobby-shuffled.off", "mech-holes-shark.off", "pinion.off",
                           "rotor_small.off", "cube-shuffled.off"})
    checkBoth(readOff(extractCgalMesh(dir, file)), file);
}

TEST(FeatureNormals, SameAsVtkOnOcctStl) {
  for (const char* file : {"bearing.stl", "head.stl"}) {
    const fs::path path = fs::path("/usr/share/opencascade/data/stl") / file;
    ASSERT_TRUE(fs::exists(path)) << path << " (Debian package occt-misc; scripts/setup installs it)";
    checkBoth(readStl(path), file);
  }
}

TEST(FeatureNormals, SameAsVtkOnTheStanfordDragon) {
  const fs::path path = fs::path(MFR_FETCHED_DATA_DIR) / "dragon" / "dragon_vrip_res3.ply.gz";
  ASSERT_TRUE(fs::exists(path)) << path << " (scripts/setup fetches it)";
  TempDir dir;
  checkBoth(readPlyGz(path, dir), "dragon_vrip_res3");
}

// Where only VTK's exact arithmetic decides (found by fuzzing against VTK): a crease of exactly 30°
// on integer coordinates (VTK compares the dot product in double: joined), and a collinear sliver
// whose normal is zero or a unit vector of rounding noise depending on the corner the cross product
// is taken at (VTK's: (c − b) × (a − b)).
TEST(FeatureNormals, SameAsVtkOnExactCreasesAndSlivers) {
  const Triangles crease{{{1, 6, -1}, {2, 6, 1}, {1, 7, -1}, {2, 7, 0}}, {0, 1, 3, 3, 2, 0}};
  expectSameAsVtk(crease, "30° crease");
  const Triangles sliver{{{2, 1, -0.071293419737075189},
                          {2, 2, 0.118756996395249},
                          {2, 1.5, 0.023731788329086914},
                          {2, 1.5, -0.97626821167091304}},
                         {0, 2, 1, 0, 1, 3}};
  expectSameAsVtk(sliver, "collinear sliver");
}
