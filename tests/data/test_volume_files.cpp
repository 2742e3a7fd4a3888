// Scalar volumes from real files and from VTK's own writers. CGAL's demo images (libcgal-dev's
// data.tar.gz, extracted by scripts/setup into .testdata/cgal/data/images) are compared value by
// value with an independent INRIMAGE reader written here from the format's description; files
// written with vtkXMLImageDataWriter, vtkMetaImageWriter and vtkStructuredPointsWriter must come
// back exactly (samples, origin, spacing). A missing file is a failure, not a skip.
#include <gtest/gtest.h>
#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkMetaImageWriter.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkSmartPointer.h>
#include <vtkShortArray.h>
#include <vtkStructuredPointsWriter.h>
#include <vtkUnsignedCharArray.h>
#include <vtkXMLImageDataWriter.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "mfr/error.hpp"
#include "mfr/io/load.hpp"
#include "mfr/scene/volume.hpp"
#include "test_files.hpp"

namespace fs = std::filesystem;

namespace {

using mfr::test::readTestFile;

// The fetched test data: $MFR_TESTDATA_DIR, else the source tree's .testdata (scripts/setup).
fs::path testData() {
  const char* env = std::getenv("MFR_TESTDATA_DIR");
  return env != nullptr && *env != '\0' ? fs::path(env) : fs::path(MFR_FETCHED_DATA_DIR);
}

fs::path cgalImage(const std::string& name) {
  const fs::path p = testData() / "cgal" / "data" / "images" / name;
  if (!fs::exists(p))
    ADD_FAILURE() << "missing " << p << " (from libcgal-dev's data.tar.gz; scripts/setup extracts it)";
  return p;
}

// ---- an independent INRIMAGE reader -------------------------------------------------------------
// The header is text: "#INRIMAGE-4#{", lines KEY=VALUE, padding, "##}\n", its length a multiple
// of 256 bytes. Then XDIM·YDIM·ZDIM·VDIM samples of PIXSIZE bits, x fastest, vector components
// interlaced, byte order by CPU (decm, alpha, pc: little endian; sun, sgi: big endian).
struct Inrimage {
  int dims[3] = {0, 0, 0};
  int vdim = 1;
  double voxel[3] = {1.0, 1.0, 1.0};
  std::vector<double> values;  // first component of every voxel
};

Inrimage parseInrimage(const std::string& bytes) {
  Inrimage im;
  EXPECT_EQ(bytes.rfind("#INRIMAGE-4#{\n", 0), 0u);
  const std::size_t end = bytes.find("##}\n");
  if (end == std::string::npos) {
    ADD_FAILURE() << "no end of header";
    return im;
  }
  const std::size_t headerSize = end + 4;
  EXPECT_EQ(headerSize % 256, 0u);
  std::map<std::string, std::string> fields;
  std::istringstream lines(bytes.substr(0, end));
  for (std::string line; std::getline(lines, line);)
    if (const std::size_t eq = line.find('='); eq != std::string::npos && line[0] != '#')
      fields[line.substr(0, eq)] = line.substr(eq + 1);
  im.dims[0] = std::stoi(fields.at("XDIM"));
  im.dims[1] = std::stoi(fields.at("YDIM"));
  im.dims[2] = std::stoi(fields.at("ZDIM"));
  if (fields.count("VDIM")) im.vdim = std::stoi(fields.at("VDIM"));
  im.voxel[0] = std::stod(fields.at("VX"));
  im.voxel[1] = std::stod(fields.at("VY"));
  im.voxel[2] = std::stod(fields.at("VZ"));
  const std::string type = fields.at("TYPE");
  const int bits = std::stoi(fields.at("PIXSIZE"));
  const std::string cpu = fields.at("CPU");
  const bool big = cpu == "sun" || cpu == "sgi";
  const std::size_t bytesPerSample = static_cast<std::size_t>(bits / 8);
  const std::size_t n = static_cast<std::size_t>(im.dims[0]) * static_cast<std::size_t>(im.dims[1]) *
                        static_cast<std::size_t>(im.dims[2]);
  if (bytes.size() < headerSize + n * static_cast<std::size_t>(im.vdim) * bytesPerSample) {
    ADD_FAILURE() << "file shorter than its header says";
    return im;
  }
  im.values.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    unsigned char b[8] = {};
    std::memcpy(b, bytes.data() + headerSize + i * static_cast<std::size_t>(im.vdim) * bytesPerSample, bytesPerSample);
    if (big) std::reverse(b, b + bytesPerSample);  // to little endian, the machine's order
    if (type == "float" && bits == 32) {
      float f;
      std::memcpy(&f, b, 4);
      im.values[i] = f;
    } else if (type == "float" && bits == 64) {
      double d;
      std::memcpy(&d, b, 8);
      im.values[i] = d;
    } else if (type == "unsigned fixed" && bits == 8) {
      im.values[i] = b[0];
    } else if (type == "unsigned fixed" && bits == 16) {
      im.values[i] = b[0] | (b[1] << 8);
    } else if (type == "signed fixed" && bits == 16) {
      im.values[i] = static_cast<std::int16_t>(b[0] | (b[1] << 8));
    } else {
      ADD_FAILURE() << "type " << type << " " << bits << " not handled by the test reader";
      return im;
    }
  }
  return im;
}

void expectSameAsIndependentReader(const mfr::Volume& v, const Inrimage& want) {
  ASSERT_TRUE(v.grid);
  ASSERT_EQ(v.grid->dims, glm::ivec3(want.dims[0], want.dims[1], want.dims[2]));
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(v.spacing[a], want.voxel[a], 1e-12) << "axis " << a;
  EXPECT_EQ(v.origin, glm::dvec3(0.0));
  ASSERT_EQ(v.grid->values.size(), want.values.size());
  std::size_t mismatches = 0;
  for (std::size_t i = 0; i < want.values.size(); ++i)
    if (v.grid->values[i] != static_cast<float>(want.values[i]) && ++mismatches <= 5)
      ADD_FAILURE() << "sample " << i << ": " << v.grid->values[i] << " != " << want.values[i];
  EXPECT_EQ(mismatches, 0u);
}

// ---- CGAL's demo images -------------------------------------------------------------------------

TEST(VolumeFiles, CgalSkullInrimage) {
  const fs::path p = cgalImage("skull_2.9.inr");
  const Inrimage want = parseInrimage(readTestFile(p));
  ASSERT_EQ(want.dims[0], 64);
  const mfr::Volume v = mfr::loadVolume(p);
  EXPECT_EQ(v.name, "skull_2.9.inr");
  expectSameAsIndependentReader(v, want);
  EXPECT_NEAR(v.spacing.x, 3.943050, 1e-12);
  EXPECT_NEAR(v.spacing.z, 3.650790, 1e-12);
  // Default transfer: grayscale over the data range, unit distance the diagonal / 50.
  const auto [lo, hi] = std::minmax_element(want.values.begin(), want.values.end());
  EXPECT_EQ(v.grid->range(), glm::vec2(static_cast<float>(*lo), static_cast<float>(*hi)));
  EXPECT_LT(*lo, *hi);
  EXPECT_DOUBLE_EQ(v.transfer.low(), static_cast<float>(*lo));
  EXPECT_DOUBLE_EQ(v.transfer.high(), static_cast<float>(*hi));
  const double diagonal = glm::length(63.0 * glm::dvec3(3.943050, 3.943050, 3.650790));
  EXPECT_NEAR(v.transfer.unitDistance, diagonal / 50.0, 1e-9);
  EXPECT_NO_THROW(v.validate());
}

TEST(VolumeFiles, CgalLiverGzippedInrimage) {
  const fs::path p = cgalImage("liver.inr.gz");
  const Inrimage want = parseInrimage(readTestFile(p));
  ASSERT_EQ(want.dims[0], 438);
  ASSERT_EQ(want.dims[1], 353);
  ASSERT_EQ(want.dims[2], 165);
  const mfr::Volume v = mfr::loadVolume(p);
  EXPECT_EQ(v.name, "liver.inr.gz");
  expectSameAsIndependentReader(v, want);
  // A checksum as well: the sum of the 8-bit samples.
  double wantSum = 0.0, gotSum = 0.0;
  for (const double x : want.values) wantSum += x;
  for (const float x : v.grid->values) gotSum += x;
  EXPECT_EQ(gotSum, wantSum);
  EXPECT_GT(wantSum, 0.0);
}

TEST(VolumeFiles, LoadSceneOnTheSkull) {
  const fs::path p = cgalImage("skull_2.9.inr");
  const mfr::Scene scene = mfr::loadScene(p);
  EXPECT_TRUE(scene.objects.empty());
  ASSERT_EQ(scene.volumes.size(), 1u);
  ASSERT_EQ(scene.views.size(), 2u);
  EXPECT_EQ(scene.views[0].name, "front");
  EXPECT_EQ(scene.views[1].name, "iso");
  EXPECT_NO_THROW(scene.validate());
  const mfr::Bounds b = scene.bounds();
  EXPECT_NEAR(b.max.x - b.min.x, 63 * 3.943050, 1e-9);
  EXPECT_NEAR(b.max.z - b.min.z, 63 * 3.650790, 1e-9);
}

TEST(VolumeFiles, TruncatedCopiesOfTheSkull) {
  const std::string whole = readTestFile(cgalImage("skull_2.9.inr"));
  ASSERT_EQ(whole.size(), 256 + 64u * 64 * 64 * 4);
  const mfr::test::TempDir dir;
  const auto write = [&](const std::string& name, const std::string& bytes) { return dir.write(name, bytes); };
  const auto expectError = [](const fs::path& p, const std::string& reason) {
    const std::string what = [&]() -> std::string {
      try {
        (void)mfr::loadVolume(p);
      } catch (const mfr::Error& e) {
        return e.what();
      }
      return "(loaded)";
    }();
    EXPECT_EQ(what.rfind(p.string() + ": ", 0), 0u) << what;
    EXPECT_NE(what.find(reason), std::string::npos) << what;
  };
  expectError(write("header.inr", whole.substr(0, 256)), "truncated INRIMAGE file (0 of 1048576 bytes");
  expectError(write("half.inr", whole.substr(0, 256 + 524288)), "truncated INRIMAGE file (524288 of 1048576 bytes");
  expectError(write("last-byte.inr", whole.substr(0, whole.size() - 1)), "truncated INRIMAGE file (1048575 of");
  std::string corrupt = whole;
  corrupt.replace(corrupt.find("TYPE=float"), 10, "TYPE=fl0at");
  expectError(write("corrupt.inr", corrupt), "corrupt or unsupported INRIMAGE header");
}

// ---- files written by VTK ------------------------------------------------------------------------

class VtkWrittenVolumes : public mfr::test::TempDirTest {};

constexpr int kNx = 7, kNy = 5, kNz = 4;

double analytic(int i, int j, int k) {
  return std::sin(0.7 * i) + 0.1 * j * j - 1.3 * k + 0.01 * i * j * k;
}

template <typename Array>
vtkSmartPointer<vtkImageData> image(const double origin[3], const double spacing[3], int components,
                                    double (*value)(int, int, int)) {
  auto im = vtkSmartPointer<vtkImageData>::New();
  im->SetDimensions(kNx, kNy, kNz);
  im->SetOrigin(origin[0], origin[1], origin[2]);
  im->SetSpacing(spacing[0], spacing[1], spacing[2]);
  vtkNew<Array> a;
  a->SetName("field");
  a->SetNumberOfComponents(components);
  a->SetNumberOfTuples(kNx * kNy * kNz);
  vtkIdType t = 0;
  for (int k = 0; k < kNz; ++k)
    for (int j = 0; j < kNy; ++j)
      for (int i = 0; i < kNx; ++i, ++t)
        for (int c = 0; c < components; ++c) a->SetComponent(t, c, c == 0 ? value(i, j, k) : 1000.0 + c);
  im->GetPointData()->SetScalars(a);
  return im;
}

// Every sample equals the first component as the array stored it (its type's rounding), as float.
void expectImage(const mfr::Volume& v, vtkImageData* im, const double origin[3], const double spacing[3]) {
  ASSERT_TRUE(v.grid);
  ASSERT_EQ(v.grid->dims, glm::ivec3(kNx, kNy, kNz));
  EXPECT_EQ(v.origin, glm::dvec3(origin[0], origin[1], origin[2]));
  EXPECT_EQ(v.spacing, glm::dvec3(spacing[0], spacing[1], spacing[2]));
  EXPECT_EQ(v.transform, glm::dmat4(1.0));
  vtkDataArray* a = im->GetPointData()->GetScalars();
  vtkIdType t = 0;
  for (int k = 0; k < kNz; ++k)
    for (int j = 0; j < kNy; ++j)
      for (int i = 0; i < kNx; ++i, ++t)
        ASSERT_EQ(v.grid->at(i, j, k), static_cast<float>(a->GetComponent(t, 0))) << i << " " << j << " " << k;
}

TEST_F(VtkWrittenVolumes, XmlImageDataFloat) {
  const double origin[3] = {-1.5, 2.0, 0.25}, spacing[3] = {0.5, 0.25, 2.0};
  auto im = image<vtkFloatArray>(origin, spacing, 1, analytic);
  const fs::path p = dir() / "field.vti";
  vtkNew<vtkXMLImageDataWriter> w;
  w->SetFileName(p.c_str());
  w->SetInputData(im);
  ASSERT_EQ(w->Write(), 1);
  expectImage(mfr::loadVolume(p), im, origin, spacing);
}

TEST_F(VtkWrittenVolumes, XmlImageDataVectorsTakeTheFirstComponent) {
  const double origin[3] = {0.0, 0.0, 0.0}, spacing[3] = {1.0, 1.0, 1.0};
  auto im = image<vtkDoubleArray>(origin, spacing, 3, analytic);
  const fs::path p = dir() / "vectors.vti";
  vtkNew<vtkXMLImageDataWriter> w;
  w->SetFileName(p.c_str());
  w->SetInputData(im);
  w->SetDataModeToAscii();
  ASSERT_EQ(w->Write(), 1);
  const mfr::Volume v = mfr::loadVolume(p);
  EXPECT_LT(v.grid->range().y, 100.0f);  // not the 1001, 1002 of the other components
  // ASCII keeps full double precision only approximately: compare to float rounding.
  vtkDataArray* a = im->GetPointData()->GetScalars();
  for (vtkIdType t = 0; t < a->GetNumberOfTuples(); ++t)
    ASSERT_NEAR(v.grid->values[static_cast<std::size_t>(t)], a->GetComponent(t, 0), 1e-5) << t;
}

TEST_F(VtkWrittenVolumes, XmlImageDataExtentAndDirection) {
  // Extent 3…9 × -2…2 × 1…4 and a direction matrix turning x into y: point (i, j, k) of the
  // extent is at origin + D·(spacing ⊙ (i, j, k)).
  vtkNew<vtkImageData> im;
  im->SetExtent(3, 3 + kNx - 1, -2, -2 + kNy - 1, 1, 1 + kNz - 1);
  im->SetOrigin(1.0, 2.0, 3.0);
  im->SetSpacing(0.5, 0.25, 2.0);
  im->SetDirectionMatrix(0, -1, 0, 1, 0, 0, 0, 0, 1);
  vtkNew<vtkFloatArray> a;
  a->SetName("f");
  a->SetNumberOfTuples(kNx * kNy * kNz);
  for (vtkIdType t = 0; t < a->GetNumberOfTuples(); ++t) a->SetValue(t, static_cast<float>(t));
  im->GetPointData()->SetScalars(a);
  const fs::path p = dir() / "placed.vti";
  vtkNew<vtkXMLImageDataWriter> w;
  w->SetFileName(p.c_str());
  w->SetInputData(im);
  ASSERT_EQ(w->Write(), 1);
  const mfr::Volume v = mfr::loadVolume(p);
  ASSERT_EQ(v.grid->dims, glm::ivec3(kNx, kNy, kNz));
  EXPECT_EQ(v.grid->at(1, 0, 0), 1.0f);
  const glm::dmat4 toWorld = v.gridToWorld();
  for (const glm::ivec3 g : {glm::ivec3(0, 0, 0), glm::ivec3(6, 0, 0), glm::ivec3(0, 4, 0), glm::ivec3(6, 4, 3)}) {
    double want[3];
    im->TransformIndexToPhysicalPoint(g.x + 3, g.y - 2, g.z + 1, want);
    const glm::dvec3 got(toWorld * glm::dvec4(glm::dvec3(g), 1.0));
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], 1e-12) << g.x << " " << g.y << " " << g.z << " axis " << c;
  }
}

// Cell data written by VTK's own writers, placed by an extent and a direction matrix: each sample
// is its cell's value, at the mean of the cell's eight corners as VTK places them
// (TransformIndexToPhysicalPoint); the legacy writer's CELL_DATA the same.
TEST_F(VtkWrittenVolumes, CellDataAtTheCellCentres) {
  vtkNew<vtkImageData> im;
  im->SetExtent(3, 3 + kNx - 1, -2, -2 + kNy - 1, 1, 1 + kNz - 1);
  im->SetOrigin(1.0, 2.0, 3.0);
  im->SetSpacing(0.5, 0.25, 2.0);
  im->SetDirectionMatrix(0, -1, 0, 1, 0, 0, 0, 0, 1);
  vtkNew<vtkFloatArray> points, cells;
  points->SetName("f");
  points->SetNumberOfTuples(kNx * kNy * kNz);
  for (vtkIdType t = 0; t < points->GetNumberOfTuples(); ++t) points->SetValue(t, static_cast<float>(t));
  cells->SetName("pressure");
  cells->SetNumberOfTuples((kNx - 1) * (kNy - 1) * (kNz - 1));
  for (vtkIdType t = 0; t < cells->GetNumberOfTuples(); ++t)
    cells->SetValue(
        t, static_cast<float>(analytic(static_cast<int>(t % (kNx - 1)), static_cast<int>(t / (kNx - 1) % (kNy - 1)),
                                       static_cast<int>(t / ((kNx - 1) * (kNy - 1))))));
  im->GetPointData()->SetScalars(points);
  im->GetCellData()->AddArray(cells);
  const fs::path p = dir() / "cells.vti";
  vtkNew<vtkXMLImageDataWriter> w;
  w->SetFileName(p.c_str());
  w->SetInputData(im);
  ASSERT_EQ(w->Write(), 1);
  const mfr::Volume v = mfr::loadVolume(p, mfr::LoadOptions{"pressure"});
  ASSERT_EQ(v.grid->dims, glm::ivec3(kNx - 1, kNy - 1, kNz - 1));
  EXPECT_EQ(v.fields, (std::vector<std::string>{"f", "pressure"}));
  const glm::dmat4 toWorld = v.gridToWorld();
  for (int k = 0; k < kNz - 1; ++k)
    for (int j = 0; j < kNy - 1; ++j)
      for (int i = 0; i < kNx - 1; ++i) {
        ASSERT_EQ(v.grid->at(i, j, k), static_cast<float>(analytic(i, j, k))) << i << " " << j << " " << k;
        glm::dvec3 centre(0.0);
        for (int corner = 0; corner < 8; ++corner) {
          double q[3];
          im->TransformIndexToPhysicalPoint(i + 3 + (corner & 1), j - 2 + (corner >> 1 & 1), k + 1 + (corner >> 2), q);
          centre += glm::dvec3(q[0], q[1], q[2]) / 8.0;
        }
        const glm::dvec3 got(toWorld * glm::dvec4(i, j, k, 1.0));
        for (int c = 0; c < 3; ++c) ASSERT_NEAR(got[c], centre[c], 1e-12) << i << " " << j << " " << k << " axis " << c;
      }

  // Legacy VTK (no direction matrix): CELL_DATA read by default when there is no point data.
  vtkNew<vtkImageData> plain;
  plain->SetDimensions(kNx, kNy, kNz);
  plain->SetOrigin(-1.0, 0.5, 2.0);
  plain->SetSpacing(0.5, 0.25, 2.0);
  plain->GetCellData()->SetScalars(cells);
  const fs::path legacy = dir() / "cells.vtk";
  vtkNew<vtkStructuredPointsWriter> lw;
  lw->SetFileName(legacy.c_str());
  lw->SetInputData(plain);
  ASSERT_EQ(lw->Write(), 1);
  const mfr::Volume l = mfr::loadVolume(legacy);
  EXPECT_EQ(l.field, "pressure");
  ASSERT_EQ(l.grid->dims, glm::ivec3(kNx - 1, kNy - 1, kNz - 1));
  ASSERT_EQ(l.grid->values.size(), v.grid->values.size());
  for (std::size_t i = 0; i < l.grid->values.size(); ++i)  // the legacy writer's ASCII: 6 digits
    ASSERT_NEAR(l.grid->values[i], v.grid->values[i], 1e-5f * std::max(1.0f, std::abs(v.grid->values[i]))) << i;
  EXPECT_EQ(l.origin, glm::dvec3(-1.0 + 0.25, 0.5 + 0.125, 2.0 + 1.0));
}

TEST_F(VtkWrittenVolumes, MetaImageShort) {
  const double origin[3] = {10.0, -20.0, 30.5}, spacing[3] = {0.75, 1.5, 3.0};
  auto im = image<vtkShortArray>(origin, spacing, 1,
                                 [](int i, int j, int k) { return 300.0 * i - 1000.0 * j + 7.0 * k - 5000; });
  for (const char* name : {"field.mhd", "field.mha"}) {
    const fs::path p = dir() / name;
    vtkNew<vtkMetaImageWriter> w;
    w->SetFileName(p.c_str());
    if (p.extension() == ".mhd") w->SetRAWFileName((dir() / "field.raw").c_str());
    w->SetCompression(false);
    w->SetInputData(im);
    w->Write();
    ASSERT_TRUE(fs::exists(p)) << name;
    expectImage(mfr::loadVolume(p), im, origin, spacing);
  }
}

TEST_F(VtkWrittenVolumes, LegacyStructuredPoints) {
  const double origin[3] = {0.5, 0.0, -4.0}, spacing[3] = {2.0, 0.125, 1.0};
  auto doubles = image<vtkDoubleArray>(origin, spacing, 1, analytic);
  auto bytes = image<vtkUnsignedCharArray>(origin, spacing, 1,
                                           [](int i, int j, int k) { return 1.0 * (i * 31 + j * 7 + k * 50); });
  for (auto [name, im, binary] :
       {std::tuple{"doubles.vtk", doubles.Get(), true}, std::tuple{"bytes.vtk", bytes.Get(), false}}) {
    const fs::path p = dir() / name;
    vtkNew<vtkStructuredPointsWriter> w;
    w->SetFileName(p.c_str());
    w->SetInputData(im);
    if (binary) w->SetFileTypeToBinary();
    ASSERT_EQ(w->Write(), 1);
    EXPECT_TRUE(mfr::isVolumeFile(p));
    expectImage(mfr::loadVolume(p), im, origin, spacing);
  }
}

}  // namespace
