// OpenVDB volumes (.vdb) made by OpenVDB's own command-line tool, vdb_tool (Debian
// libopenvdb-tools; no real .vdb file is packaged): spheres as level sets and as fog volumes, off
// the origin and with anisotropic placement, loaded by loadVolume and checked against the sphere
// itself — where the signed distance crosses zero and the fog crosses one half, along each axis —
// and against vdb_print's report of the same file; a vector grid as its magnitude against
// vdb_tool's -length; bad files end in one error naming the file.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "mfr/io/load.hpp"
#include "mfr/io_util.hpp"
#include "mfr/scene/volume.hpp"
#include "test_files.hpp"

namespace fs = std::filesystem;

namespace mfr::test {
namespace {

class OpenVdbFiles : public TempDirTest {
 protected:
  fs::path make(const std::string& actions, const std::string& file) {
    const fs::path out = dir() / file;
    const CliResult r = runCommand("vdb_tool -quiet " + actions + " -write '" + out.string() + "'");
    EXPECT_EQ(r.exitCode, 0) << "vdb_tool (Debian libopenvdb-tools; scripts/setup installs it): " << r.out;
    return out;
  }
};

double sampleWorld(const Volume& v, const glm::dvec3& p) {
  const glm::dvec4 g = glm::inverse(v.gridToWorld()) * glm::dvec4(p, 1.0);
  return v.grid->sample(glm::vec3(g));
}

// The distance from `centre` along `dir` at which the field first crosses `level` (from below when
// rising, else from above), found by marching in steps of `step` and interpolating linearly.
double crossing(const Volume& v, const glm::dvec3& centre, const glm::dvec3& dir, double level, double reach,
                double step) {
  double previous = sampleWorld(v, centre);
  for (double t = step; t <= reach; t += step) {
    const double value = sampleWorld(v, centre + t * dir);
    if ((previous - level) * (value - level) <= 0.0 && previous != value)
      return t - step + step * (level - previous) / (value - previous);
    previous = value;
  }
  return -1.0;
}

TEST_F(OpenVdbFiles, LevelSetAndFogSpheresCrossWhereTheSphereIs) {
  const glm::dvec3 centre(1.5, -2.0, 0.75);
  const double radius = 2.0, voxel = 0.1;
  const std::string sphere = "-sphere radius=2 voxel=0.1 'center=(1.5,-2,0.75)'";
  const fs::path levelSet = make(sphere, "ls.vdb");
  const fs::path fog = make(sphere + " -ls2fog", "fog.vdb");
  const Volume ls = loadVolume(levelSet);
  const Volume fv = loadVolume(fog);
  // The same sphere made at the origin and moved by its grid's transform (not by its voxels).
  const Volume moved =
      loadVolume(make("-sphere radius=2 voxel=0.1 -transform 'translate=(1.5,-2,0.75)' vdb=0 keep=0", "moved.vdb"));
  EXPECT_NEAR(moved.gridToWorld()[3].x, 1.5 - 2.0 - 3 * voxel, 1.5 * voxel);  // the box's corner

  // vdb_print's own account of each file: the dense box is the active voxels' bounding box.
  for (const auto& [path, volume] : {std::pair{levelSet, &ls}, std::pair{fog, &fv}}) {
    const CliResult r = runCommand("vdb_print -l '" + path.string() + "'");
    ASSERT_EQ(r.exitCode, 0) << r.out;
    std::smatch m;
    ASSERT_TRUE(std::regex_search(r.out, m, std::regex(R"(Dimensions of active voxels:\s+(\d+) x (\d+) x (\d+))")))
        << r.out;
    EXPECT_EQ(volume->grid->dims, glm::ivec3(std::stoi(m[1]), std::stoi(m[2]), std::stoi(m[3])));
    const Bounds b = volume->bounds();
    EXPECT_NEAR(b.min.x, centre.x - radius, 4 * voxel);  // the narrow band reaches ~3 voxels out
    EXPECT_NEAR(b.max.y, centre.y + radius, 4 * voxel);
  }
  EXPECT_NEAR(glm::length(glm::dvec3(ls.gridToWorld()[0])), voxel,
              1e-6);  // voxel size (float in the file) on every axis
  EXPECT_NEAR(glm::length(glm::dvec3(ls.gridToWorld()[2])), voxel, 1e-6);

  // Deep inside: the level set's inside value (negative), the fog's density 1.
  EXPECT_LT(sampleWorld(ls, centre), 0.0);
  EXPECT_FLOAT_EQ(static_cast<float>(sampleWorld(fv, centre)), 1.0f);
  for (const glm::dvec3 dir : {glm::dvec3(1, 0, 0), glm::dvec3(-1, 0, 0), glm::dvec3(0, 1, 0), glm::dvec3(0, 0, -1),
                               glm::normalize(glm::dvec3(1, 1, 1))}) {
    SCOPED_TRACE(dir.x + 10 * dir.y + 100 * dir.z);
    // The signed distance is zero on the sphere (to a small fraction of a voxel). The fog is
    // OpenVDB's sdfToFogVolume: 0 on and outside the surface, rising linearly to 1 across the
    // interior band (vdb_tool's default width: 3 voxels), so one half 1.5 voxels inside.
    EXPECT_NEAR(crossing(ls, centre, dir, 0.0, 3.0, 0.01), radius, 0.2 * voxel);
    EXPECT_NEAR(crossing(moved, centre, dir, 0.0, 3.0, 0.01), radius, 0.2 * voxel);
    EXPECT_NEAR(crossing(fv, centre, dir, 0.5, 3.0, 0.01), radius - 1.5 * voxel, 0.2 * voxel);
  }
}

TEST_F(OpenVdbFiles, SceneOfAVdbFile) {
  const fs::path fog = make("-sphere radius=1 voxel=0.05 -ls2fog", "ball.vdb");
  EXPECT_TRUE(isVolumeFile(fog));
  const Scene scene = loadScene(fog);
  ASSERT_EQ(scene.volumes.size(), 1u);
  EXPECT_EQ(scene.volumes[0].name, "ball.vdb");
  EXPECT_NEAR(scene.volumes[0].transfer.high(), 1.0, 1e-6);  // grayscale over the density's range
  EXPECT_NEAR(scene.volumes[0].defaultStep(), 0.025, 1e-6);
  // mfr info gives the grid's spacing in scene units (a .vdb keeps its voxel size in its transform:
  // it said "spacing 1 1 1" beside a default step of 0.025; a bug hunt).
  const fs::path json = fog.parent_path() / "info.json";
  const CliResult r = runCli("info " + fog.string() + " --no-histogram --json " + json.string());
  ASSERT_EQ(r.exitCode, 0) << r.out;
  EXPECT_NE(r.out.find("points, spacing 0.05 0.05 0.05,"), std::string::npos) << r.out;
  const nlohmann::json j = nlohmann::json::parse(std::ifstream(json));
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(j["volumes"][0]["spacing"][a].get<double>(), 0.05, 1e-6);
}

// A vector grid (the gradient of a fog sphere, made by vdb_tool -grad) is read as its magnitude:
// voxel for voxel what vdb_tool's own -length makes of it, on the same grid and placement.
TEST_F(OpenVdbFiles, VectorGridsAreReadAsTheirMagnitude) {
  const fs::path gradient = make("-sphere radius=1 voxel=0.1 -ls2fog -grad", "grad.vdb");
  const fs::path length = make("-read '" + gradient.string() + "' -length", "length.vdb");
  const Volume v = loadVolume(gradient), reference = loadVolume(length);
  ASSERT_EQ(v.grid->dims, reference.grid->dims);
  EXPECT_EQ(v.origin, reference.origin);
  EXPECT_EQ(v.gridToWorld(), reference.gridToWorld());
  float largest = 0.0f;
  for (std::size_t i = 0; i < v.grid->values.size(); ++i) {
    EXPECT_NEAR(v.grid->values[i], reference.grid->values[i], 1e-5f * std::max(1.0f, reference.grid->values[i])) << i;
    largest = std::max(largest, reference.grid->values[i]);
  }
  EXPECT_GT(largest, 1.0f);  // the fog rises from 0 to 1 over a few voxels of 0.1: a gradient of several per unit
}

// A file of several grids — two level-set spheres of different radii, the fog of the smaller one
// and its gradient (grad_fog) — read grid by grid (LoadOptions::field and a scene file's "field"), each
// checked against the sphere it holds and against vdb_print's dimensions; the default is the first
// float grid; a grid the file lacks, or one of point data, is one line naming the file and the
// grids it has.
TEST_F(OpenVdbFiles, AnyGridOfTheFileCanBeChosen) {
  const fs::path multi = make(
      "-sphere radius=2 voxel=0.1 name=big -sphere radius=1 voxel=0.1 name=small -ls2fog keep=1 name=fog "
      "-grad keep=1",
      "multi.vdb");
  const CliResult listing = runCommand("vdb_print '" + multi.string() + "'");
  ASSERT_EQ(listing.exitCode, 0) << listing.out;
  std::map<std::string, glm::ivec3> printed;  // vdb_print: "name type (min)->(max) NxNxN ..."
  const std::regex line(R"((\w+)\s+(\w+)\s+\([^)]*\)->\([^)]*\)\s+(\d+)x(\d+)x(\d+))");
  for (auto it = std::sregex_iterator(listing.out.begin(), listing.out.end(), line); it != std::sregex_iterator(); ++it)
    printed[(*it)[1]] = glm::ivec3(std::stoi((*it)[3]), std::stoi((*it)[4]), std::stoi((*it)[5]));
  ASSERT_EQ(printed.size(), 4u) << listing.out;

  const Volume first = loadVolume(multi);
  std::vector<std::string> sorted = first.fields;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(sorted, (std::vector<std::string>{"big", "fog", "grad_fog", "small"}));
  EXPECT_EQ(first.field, first.fields.front() == "grad_fog" ? first.fields[1] : first.fields.front());
  EXPECT_EQ(first.name, "multi.vdb");

  const glm::dvec3 centre(0.0);
  const Volume big = loadVolume(multi, LoadOptions{"big"});
  const Volume small = loadVolume(multi, LoadOptions{"small"});
  const Volume fog = loadVolume(multi, LoadOptions{"fog"});
  const Volume slope = loadVolume(multi, LoadOptions{"grad_fog"});
  for (const Volume* v : {&big, &small, &fog, &slope}) {
    SCOPED_TRACE(v->field);
    ASSERT_TRUE(printed.count(v->field));
    EXPECT_EQ(v->grid->dims, printed[v->field]);
    EXPECT_EQ(v->fields, first.fields);
  }
  for (const glm::dvec3 dir : {glm::dvec3(1, 0, 0), glm::dvec3(0, -1, 0), glm::normalize(glm::dvec3(1, 1, 1))}) {
    EXPECT_NEAR(crossing(big, centre, dir, 0.0, 3.0, 0.01), 2.0, 0.02);
    EXPECT_NEAR(crossing(small, centre, dir, 0.0, 2.0, 0.01), 1.0, 0.02);
    EXPECT_NEAR(crossing(fog, centre, dir, 0.5, 2.0, 0.01), 1.0 - 0.15, 0.02);
  }
  // The gradient's magnitude: ~0 deep inside the fog, steep (about 1 / (3 voxels)) across its band.
  EXPECT_LT(sampleWorld(slope, centre), 1e-3);
  EXPECT_GT(sampleWorld(slope, glm::dvec3(0.9, 0.0, 0.0)), 2.0);

  // The scene file's "field" reads the same grid.
  write("multi.mfrscene", R"({"volumes": [{"file": "multi.vdb", "field": "small"}]})");
  const Scene scene = loadScene(dir() / "multi.mfrscene");
  ASSERT_EQ(scene.volumes.size(), 1u);
  EXPECT_EQ(scene.volumes[0].field, "small");
  EXPECT_EQ(scene.volumes[0].grid->values, small.grid->values);

  const auto expectFieldError = [](const fs::path& path, const std::string& field, const std::string& reason) {
    try {
      (void)loadVolume(path, LoadOptions{field});
      ADD_FAILURE() << "no error for grid " << field;
    } catch (const FieldNotFound& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(path.string() + ": ", 0), 0u) << what;
      EXPECT_NE(what.find(reason), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  };
  expectFieldError(multi, "Big", "no grid 'Big' (grids: ");
  expectFieldError(multi, "Big", "big (float)");
  expectFieldError(multi, "Big", "grad_fog (vec3s)");
  const fs::path points = make("-sphere radius=1 voxel=0.1 name=ls -ls2mesh keep=1 -points2vdb name=pts", "pts.vdb");
  EXPECT_EQ(loadVolume(points).field, "ls");
  EXPECT_EQ(loadVolume(points).fields, std::vector<std::string>{"ls"});  // only the grids it can read
  expectFieldError(points, "pts", "grid 'pts' holds ptdataidx32 values; a volume needs a float, double or vector grid");
}

// Two grids named "density" (a level set and its fog): each is a field of its own, by the unique
// names OpenVDB gives them, with a note saying so; the name alone reads the first. Only the first
// was readable, and OpenVDB's warning about the shared name went to stdout in colour, into the
// middle of `mfr info`'s report (a bug hunt).
TEST_F(OpenVdbFiles, GridsSharingANameAreEachReadable) {
  const fs::path file = make("-sphere radius=1 voxel=0.2 name=density -ls2fog keep=1 name=density", "shared.vdb");
  const CliResult listing = runCommand("vdb_print '" + file.string() + "'");
  ASSERT_EQ(listing.exitCode, 0) << listing.out;
  std::vector<glm::ivec3> printed;  // vdb_print, in the file's order: "density float (min)->(max) NxNxN ..."
  const std::regex line(R"(density\s+float\s+\([^)]*\)->\([^)]*\)\s+(\d+)x(\d+)x(\d+))");
  for (auto it = std::sregex_iterator(listing.out.begin(), listing.out.end(), line); it != std::sregex_iterator(); ++it)
    printed.emplace_back(std::stoi((*it)[1]), std::stoi((*it)[2]), std::stoi((*it)[3]));
  ASSERT_EQ(printed.size(), 2u) << listing.out;
  ASSERT_NE(printed[0], printed[1]) << "the test needs two grids of different sizes";

  const Scene scene = loadScene(file);
  ASSERT_EQ(scene.volumes.size(), 1u);
  const std::vector<std::string> fields = scene.volumes[0].fields;
  ASSERT_EQ(fields.size(), 2u);
  EXPECT_NE(fields[0], fields[1]);
  EXPECT_EQ(fields[1], "density[1]");
  EXPECT_EQ(scene.volumes[0].field, fields[0]);
  EXPECT_EQ(scene.volumes[0].grid->dims, printed[0]);
  ASSERT_EQ(scene.notes.size(), 1u);
  EXPECT_EQ(scene.notes[0], file.string() + ": 2 grids are named 'density'; they are fields '" + fields[0] + "', '" +
                                fields[1] + "' in the file's order");
  for (std::size_t i = 0; i < 2; ++i) {
    SCOPED_TRACE(fields[i]);
    const Volume v = loadVolume(file, LoadOptions{fields[i]});
    EXPECT_EQ(v.field, fields[i]);
    EXPECT_EQ(v.grid->dims, printed[i]);
  }
  EXPECT_EQ(loadVolume(file, LoadOptions{"density"}).grid->dims, printed[0]);

  // Nothing of OpenVDB's on stdout: the report is mfr's alone, the note on stderr.
  const CliResult out =
      runCommand("(" + std::string(MFR_CLI) + " info '" + file.string() + "' --no-histogram 2>/dev/null)");
  ASSERT_EQ(out.exitCode, 0) << out.out;
  EXPECT_EQ(out.out.rfind("scene ", 0), 0u) << out.out;
  EXPECT_EQ(out.out.find("OpenVDB"), std::string::npos) << out.out;
  EXPECT_EQ(out.out.find('\x1b'), std::string::npos) << out.out;
  const CliResult all = runCli("info '" + file.string() + "' --field 'density[1]' --no-histogram");
  ASSERT_EQ(all.exitCode, 0) << all.out;
  EXPECT_NE(all.out.find("note: " + scene.notes[0]), std::string::npos) << all.out;
  EXPECT_NE(all.out.find("[density[1]] (" + std::to_string(printed[1].x) + "x"), std::string::npos) << all.out;
}

TEST_F(OpenVdbFiles, BadFilesAreOneLineErrors) {
  const auto expectError = [](const fs::path& path, const std::string& reason) {
    expectFileError(path, reason,
                    [&] { return "a volume of " + std::to_string(loadVolume(path).grid->values.size()) + " points"; });
  };
  expectError(write("text.vdb", "not a VDB file at all, just text\n"), "not an OpenVDB file");
  // A point data grid is not a volume.
  expectError(make("-sphere radius=1 voxel=0.1 -ls2mesh -points2vdb", "points.vdb"),
              "no float, double or vector grid in the file (it has points2vdb_ls2mesh_sphere (ptdataidx32))");
  const fs::path good = make("-sphere radius=1 voxel=0.1 -ls2fog", "good.vdb");
  const std::string bytes = readFile(good);
  for (std::size_t cut = 8; cut < bytes.size(); cut += std::max<std::size_t>(1, bytes.size() / 30)) {
    SCOPED_TRACE(cut);
    const fs::path p = write("cut" + std::to_string(cut) + ".vdb", bytes.substr(0, cut));
    // Said as what it is: OpenVDB reads garbage sizes past the end, which were "out of memory"
    // (at 93 MB used) or "no float, double or vector grid", differently from run to run.
    expectError(p, p.string() + ": ");
    std::string what;
    try {
      (void)loadVolume(p);
    } catch (const Error& e) {
      what = e.what();
    }
    EXPECT_TRUE(what.find(": corrupt or truncated OpenVDB file (") != std::string::npos ||
                what.find(": the file has no grids (or is truncated)") != std::string::npos)
        << what;
  }
  // 58 bytes out of a leaf's data and the rest cut: OpenVDB's bloscFromStream overflows its heap
  // (fuzzing; mfr and mfrview aborted). The read runs in a child process now, whose crash is the
  // file's error.
  ASSERT_GT(bytes.size(), std::size_t{77917});
  const fs::path damaged = write("overflow.vdb", (bytes.substr(0, 76715) + bytes.substr(76715 + 58)).substr(0, 77917));
  std::string what;
  try {
    (void)loadVolume(damaged);
  } catch (const Error& e) {
    what = e.what();
  }
  EXPECT_TRUE(what.starts_with(damaged.string() + ": cannot read vdb: OpenVDB crashed (") ||
              what.starts_with(damaged.string() + ": corrupt or truncated OpenVDB file ("))
      << what;
  EXPECT_EQ(what.find('\n'), std::string::npos) << what;
}

}  // namespace
}  // namespace mfr::test
