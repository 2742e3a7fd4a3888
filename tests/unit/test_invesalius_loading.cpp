// InVesalius 3 projects (.inv3) made here: property lists and raw matrices written from the
// format's description, packed by GNU tar (not by the libarchive the loader reads with), loaded by
// loadScene / loadVolume — values, axis order, spacing, surfaces with their colour, transparency,
// visibility and order — and bad projects, each ending in one mfr::Error naming the file.
// tests/data/test_invesalius.cpp reads the real Cranium.inv3.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "mfr/error.hpp"
#include "mfr/io/load.hpp"
#include "mfr/io_util.hpp"
#include "mfr/scene/volume.hpp"
#include "test_files.hpp"

namespace fs = std::filesystem;

namespace mfr::test {
namespace {

class InvesaliusLoading : public TempDirTest {
 protected:
  // Packs `files` (name → bytes) into dir()/<archive> as InVesalius does: a gzip-compressed tar
  // whose members sit in one temporary folder.
  fs::path pack(const std::map<std::string, std::string>& files, const std::string& archive = "project.inv3") {
    const fs::path folder = dir() / "tmpproject";
    fs::remove_all(folder);
    fs::create_directories(folder);
    for (const auto& [name, bytes] : files) write("tmpproject/" + name, bytes);
    const fs::path out = dir() / archive;
    const CliResult r = runCommand("tar czf '" + out.string() + "' -C '" + dir().string() + "' tmpproject");
    EXPECT_EQ(r.exitCode, 0) << r.out;
    return out;
  }
};

std::string plist(const std::string& dictBody) {
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
         "<!DOCTYPE plist PUBLIC \"-//Apple Computer//DTD PLIST 1.0//EN\" "
         "\"http://www.apple.com/DTDs/PropertyList-1.0.dtd\">\n"
         "<plist version=\"1.0\">\n<dict>\n" +
         dictBody + "</dict>\n</plist>\n";
}

// main.plist for a matrix of numpy shape (z, y, x), with the given spacing (x, y, z) and surfaces.
std::string mainPlist(const std::string& dtype, int nz, int ny, int nx, const std::string& spacing = "0.5 0.75 2",
                      const std::map<std::string, std::string>& surfaces = {}, const std::string& extra = "") {
  std::string sp;
  for (std::size_t a = 0, b; a < spacing.size(); a = b + 1) {
    b = spacing.find(' ', a);
    if (b == std::string::npos) b = spacing.size();
    sp += "<real>" + spacing.substr(a, b - a) + "</real>";
  }
  std::string surf;
  for (const auto& [key, file] : surfaces) surf += "<key>" + key + "</key><string>" + file + "</string>\n";
  return plist("<key>matrix</key><dict><key>dtype</key><string>" + dtype +
               "</string><key>filename</key><string>matrix.dat</string><key>shape</key><array><integer>" +
               std::to_string(nz) + "</integer><integer>" + std::to_string(ny) + "</integer><integer>" +
               std::to_string(nx) + "</integer></array></dict>\n<key>name</key><string>Test CT</string>\n" +
               "<key>spacing</key><array>" + sp + "</array>\n<key>surfaces</key><dict>" + surf + "</dict>\n" +
               "<key>window_level</key><real>40.0</real><key>window_width</key><real>400</real>\n" + extra);
}

// Distinct at every point and exact in every dtype used below.
int field(int i, int j, int k) {
  return i + 5 * j + 20 * k;
}

template <typename T>
std::string matrix(int nx, int ny, int nz, int offset = 0) {
  std::string out;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const T v = static_cast<T>(field(i, j, k) + offset);
        char b[sizeof(T)];
        std::memcpy(b, &v, sizeof(T));  // little-endian, as the machines running the tests
        out.append(b, sizeof(T));
      }
  return out;
}

// A tetrahedron as VTK XML PolyData (ASCII), translated by t.
std::string tetrahedronVtp(double t = 0.0) {
  std::string pts;
  // The arrays themselves: pointers into temporaries outlived them (a sanitizer run).
  for (const std::array<double, 3>& p : {std::array<double, 3>{0, 0, 0}, std::array<double, 3>{1, 0, 0},
                                         std::array<double, 3>{0, 1, 0}, std::array<double, 3>{0, 0, 1}})
    pts += std::to_string(p[0] + t) + " " + std::to_string(p[1] + t) + " " + std::to_string(p[2] + t) + " ";
  return "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
         "<PolyData><Piece NumberOfPoints=\"4\" NumberOfPolys=\"4\">\n"
         "<Points><DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"ascii\">" +
         pts +
         "</DataArray></Points>\n"
         "<Polys><DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">0 2 1 0 1 3 0 3 2 1 2 3</DataArray>"
         "<DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">3 6 9 12</DataArray></Polys>\n"
         "</Piece></PolyData></VTKFile>\n";
}

std::string surfacePlist(const std::string& name, const std::string& vtp, const std::string& colour,
                         double transparency, bool visible) {
  return plist("<key>colour</key><array>" + colour + "</array><key>name</key><string>" + name +
               "</string><key>polydata</key><string>" + vtp + "</string><key>transparency</key><real>" +
               std::to_string(transparency) + "</real><key>visible</key>" + (visible ? "<true/>" : "<false/>") + "\n");
}

void expectSceneError(const fs::path& path, const std::string& reason) {
  expectFileError(path, reason,
                  [&] { return "a scene of " + std::to_string(loadScene(path).objects.size()) + " parts"; });
}

TEST_F(InvesaliusLoading, MatrixAxesSpacingAndSurfaces) {
  const std::string colourA = "<real>0.25</real><integer>1</integer><real>0.5</real>";
  const std::string colourB = "<real>1.0</real><real>0.0</real><real>0.0</real>";
  // Keys "10" and "2": numeric order puts surface 2 first although "10" < "2" as text.
  const fs::path path = pack({{"main.plist", mainPlist("int16", 3, 4, 5, "0.5 0.75 2",
                                                       {{"10", "surface_10.plist"}, {"2", "surface_2.plist"}})},
                              {"matrix.dat", matrix<std::int16_t>(5, 4, 3, -1000)},
                              {"mask_0.dat", std::string(64, '\x7f')},
                              {"surface_2.plist", surfacePlist("Skin", "surface_2.vtp", colourA, 0.75, true)},
                              {"surface_2.vtp", tetrahedronVtp()},
                              {"surface_10.plist", surfacePlist("Bone", "surface_10.vtp", colourB, 0.0, false)},
                              {"surface_10.vtp", tetrahedronVtp(2.0)}});
  const Scene scene = loadScene(path);
  ASSERT_EQ(scene.volumes.size(), 1u);
  const Volume& v = scene.volumes[0];
  EXPECT_EQ(v.name, "Test CT");
  EXPECT_EQ(v.grid->dims, glm::ivec3(5, 4, 3));  // numpy shape (z, y, x) → x fastest
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 5; ++i) ASSERT_EQ(v.grid->at(i, j, k), float(field(i, j, k) - 1000)) << i << j << k;
  EXPECT_EQ(v.spacing, glm::dvec3(0.5, 0.75, 2.0));
  EXPECT_EQ(v.origin, glm::dvec3(0.0));
  // Mirrored in y into the frame of InVesalius's surfaces.
  EXPECT_EQ(v.transform, glm::dmat4(glm::dvec4(1, 0, 0, 0), glm::dvec4(0, -1, 0, 0), glm::dvec4(0, 0, 1, 0),
                                    glm::dvec4(0, 0, 0, 1)));
  // The window (level 40, width 400) places the "bone" preset over [level − width, level + 2 width].
  EXPECT_DOUBLE_EQ(v.transfer.low(), -360.0);
  EXPECT_DOUBLE_EQ(v.transfer.high(), 840.0);

  ASSERT_EQ(scene.objects.size(), 2u);
  EXPECT_EQ(scene.objects[0].name, "Skin");
  EXPECT_EQ(scene.objects[0].material.color, glm::vec4(0.25f, 1.0f, 0.5f, 0.25f));
  EXPECT_TRUE(scene.objects[0].visible);
  EXPECT_FALSE(scene.objects[0].material.vertexColors);
  EXPECT_EQ(scene.objects[1].name, "Bone");
  EXPECT_EQ(scene.objects[1].material.color, glm::vec4(1.0f, 0.0f, 0.0f, 1.0f));
  EXPECT_FALSE(scene.objects[1].visible);
  EXPECT_EQ(scene.objects[0].mesh->indices.size(), 12u);
  EXPECT_FLOAT_EQ(scene.objects[1].mesh->bounds().min.x, 2.0f);
  EXPECT_GE(scene.views.size(), 2u);

  // As a volume file: the matrix alone, with the project's transfer function.
  EXPECT_TRUE(isVolumeFile(path));
  const Volume alone = loadVolume(path);
  EXPECT_EQ(alone.grid->values, v.grid->values);
  EXPECT_DOUBLE_EQ(alone.transfer.low(), -360.0);
  const std::vector<std::string> ext = supportedVolumeExtensions();
  EXPECT_NE(std::find(ext.begin(), ext.end(), ".inv3"), ext.end());
}

TEST_F(InvesaliusLoading, Dtypes) {
  const auto check = [&](const std::string& dtype, const std::string& data, int offset) {
    SCOPED_TRACE(dtype);
    const fs::path path = pack({{"main.plist", mainPlist(dtype, 2, 3, 4)}, {"matrix.dat", data}}, dtype + ".inv3");
    const Volume v = loadVolume(path);
    ASSERT_EQ(v.grid->dims, glm::ivec3(4, 3, 2));
    for (int k = 0; k < 2; ++k)
      for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 4; ++i) ASSERT_EQ(v.grid->at(i, j, k), float(field(i, j, k) + offset));
  };
  check("uint8", matrix<std::uint8_t>(4, 3, 2, 7), 7);
  check("int8", matrix<std::int8_t>(4, 3, 2, -60), -60);
  check("uint16", matrix<std::uint16_t>(4, 3, 2, 60000), 60000);
  check("int32", matrix<std::int32_t>(4, 3, 2, -100000), -100000);
  check("float32", matrix<float>(4, 3, 2, -3), -3);
  check("float64", matrix<double>(4, 3, 2, 1 << 20), 1 << 20);
}

TEST_F(InvesaliusLoading, BadProjects) {
  const std::string good = matrix<std::int16_t>(4, 3, 2);
  expectSceneError(write("text.inv3", "just some text, not an archive\n"), "not an InVesalius project");
  expectSceneError(pack({{"matrix.dat", good}}, "nomain.inv3"), "project has no main.plist");
  expectSceneError(pack({{"main.plist", "<plist><dict><key>a</key>"}, {"matrix.dat", good}}, "xml.inv3"),
                   "not a property list");
  expectSceneError(pack({{"main.plist", plist("<key>name</key><string>x</string>")}}, "nomatrix.inv3"),
                   "missing key 'matrix'");
  expectSceneError(pack({{"main.plist", mainPlist("complex64", 2, 3, 4)}, {"matrix.dat", good}}, "dtype.inv3"),
                   "unsupported matrix dtype 'complex64'");
  expectSceneError(
      pack({{"main.plist", mainPlist("int16", 2, 3, 4)}, {"matrix.dat", good.substr(0, 30)}}, "short.inv3"),
      "(truncated)");
  expectSceneError(pack({{"main.plist", mainPlist("int16", 2, 3, 4)}}, "nodata.inv3"), "project has no matrix.dat");
  expectSceneError(pack({{"main.plist", mainPlist("int16", 1, 3, 4)}, {"matrix.dat", good}}, "thin.inv3"),
                   "at least 2 points");
  // Declared far beyond the limits: refused before anything is allocated for it.
  expectSceneError(pack({{"main.plist", mainPlist("int16", 2000, 2000, 2000)}, {"matrix.dat", good}}, "huge.inv3"),
                   "larger than 2^30 points");
  expectSceneError(pack({{"main.plist", mainPlist("int16", 2, 3, 4, "1 0 1")}, {"matrix.dat", good}}, "sp.inv3"),
                   "spacing must be positive");
  expectSceneError(pack({{"main.plist", mainPlist("int16", 2, 3, 4, "1 1")}, {"matrix.dat", good}}, "sp2.inv3"),
                   "key 'spacing' needs 3 numbers");
  expectSceneError(
      pack({{"main.plist", mainPlist("int16", 2, 3, 4, "1 1 1", {{"0", "surface_0.plist"}})}, {"matrix.dat", good}},
           "nosurf.inv3"),
      "project has no surface_0.plist");
  expectSceneError(pack({{"main.plist", mainPlist("int16", 2, 3, 4, "1 1 1", {{"0", "surface_0.plist"}})},
                         {"matrix.dat", good},
                         {"surface_0.plist",
                          surfacePlist("S", "surface_0.vtp", "<real>1</real><real>1</real><real>1</real>", 0.0, true)},
                         {"surface_0.vtp", "<VTKFile type=\"PolyData\"><PolyData><Piece"}},
                        "badvtp.inv3"),
                   "surface_0.vtp");
  std::string deep;
  for (int i = 0; i < 100; ++i) deep += "<array>";
  expectSceneError(pack({{"main.plist", plist("<key>x</key>" + deep)}, {"matrix.dat", good}}, "deep.inv3"),
                   "main.plist");
}

TEST_F(InvesaliusLoading, TruncatedArchivesNeverCrash) {
  const fs::path path =
      pack({{"main.plist", mainPlist("int16", 6, 7, 8)}, {"matrix.dat", matrix<std::int16_t>(8, 7, 6)}});
  const std::string bytes = readFile(path);
  // Every cut ends in an error naming the file (a gzip tar cut anywhere is damaged).
  for (std::size_t cut = 0; cut < bytes.size(); cut += std::max<std::size_t>(1, bytes.size() / 40)) {
    const fs::path cutPath = write("cut" + std::to_string(cut) + ".inv3", bytes.substr(0, cut));
    SCOPED_TRACE(cut);
    if (cut == 0)
      expectSceneError(cutPath, "empty file");
    else
      expectSceneError(cutPath, cutPath.string());
  }
}

}  // namespace
}  // namespace mfr::test
