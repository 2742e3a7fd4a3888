// Section planes on a real CAD assembly: the 2CylinderEngine (glTF, a primitive per material, so
// its pistons and rods are each split over two open parts) cut at z = 0 both ways. The independent
// check is volume: for every part that is capped on both sides, the kept halves and the cut-away
// halves, each a closed solid by the divergence theorem, add up to the uncut parts' volume — a
// missing, doubled or misplaced cap breaks the sum by the cap's area times its distance from the
// origin.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <set>
#include <string>

#include "mfr/io/load.hpp"
#include "mfr/scene/section.hpp"

namespace fs = std::filesystem;

namespace mfr {
namespace {

// Σ over the named, visible objects of the divergence-theorem volume in world space (a mirrored
// transform turns the winding inside out, so its sign is undone).
double worldVolume(const Scene& scene, const std::set<std::string>& names) {
  double v = 0.0;
  for (const Object& o : scene.objects) {
    if (!o.visible || !names.contains(o.name)) continue;
    const double sign = glm::determinant(glm::dmat3(o.transform)) < 0.0 ? -1.0 : 1.0;
    const Mesh& m = *o.mesh;
    for (std::size_t t = 0; t < m.triangleCount(); ++t) {
      glm::dvec3 p[3];
      for (int k = 0; k < 3; ++k)
        p[k] = glm::dvec3(o.transform * glm::dvec4(glm::dvec3(m.positions[m.indices[3 * t + k]]), 1.0));
      v += sign * glm::dot(p[0], glm::cross(p[1], p[2])) / 6.0;
    }
  }
  return v;
}

TEST(RealSection, TwoCylinderEngineHalvesAddUpToTheWhole) {
  const fs::path p = "/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb";
  ASSERT_TRUE(fs::exists(p)) << "missing " << p << " (Debian package assimp-testmodels; scripts/setup installs it)";
  Scene scene = loadScene(p);
  scene.section = SectionPlane{{0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, true};
  SectionReport upReport, downReport;
  const Scene up = sectionedScene(scene, &upReport);
  scene.section->normal = {0.0, 0.0, -1.0};
  const Scene down = sectionedScene(scene, &downReport);

  // 24 parts cross z = 0, all capped. Each piston is two primitives, open alone: capped together
  // (19 of 24 without that). nodes[65] is two closed shells that meet in the plane, mirror images:
  // the plane crosses none of its triangles and removes one shell whole, which opens nothing
  // (it was reported open before).
  for (const SectionReport* report : {&upReport, &downReport}) {
    EXPECT_EQ(report->cut, 24u);
    EXPECT_EQ(report->capped, 24u);
    EXPECT_TRUE(report->open.empty());
  }
  std::set<std::string> cut, pistons;
  for (std::size_t i = 0; i < scene.objects.size(); ++i) {
    const std::string& name = scene.objects[i].name;
    if (up.objects[i].mesh == scene.objects[i].mesh) continue;
    cut.insert(name);
    if (name.starts_with("nodes[5]/Piston")) pistons.insert(name);
  }
  ASSERT_EQ(cut.size(), 24u);
  ASSERT_TRUE(cut.contains("nodes[65]"));
  ASSERT_EQ(pistons.size(), 2u);
  for (const std::set<std::string>& parts : {cut, pistons}) {
    const double whole = worldVolume(scene, parts), kept = worldVolume(up, parts), away = worldVolume(down, parts);
    SCOPED_TRACE(parts.size());
    EXPECT_GT(whole, 0.0);
    EXPECT_GT(kept, 0.0);
    EXPECT_GT(away, 0.0);
    EXPECT_NEAR(kept + away, whole, 1e-5 * whole);
  }
}

}  // namespace
}  // namespace mfr
