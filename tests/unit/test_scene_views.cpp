// Every scene has the views "front" and "iso" (Scene::view): the commands whose default view is
// "iso" (evaluate, dataset, allocations) refused @quads:N and every scene file with views of its
// own ("view 'iso': not in scene"). A scene's own views of those names come first.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "mfr/error.hpp"
#include "mfr/io/load.hpp"
#include "test_files.hpp"

namespace {

// The unit direction the camera looks from (target → eye).
glm::dvec3 from(const mfr::Camera& c) {
  return glm::normalize(c.eye - c.target);
}

void expectFitFrom(const mfr::Scene& scene, const mfr::Camera& c, glm::dvec3 direction) {
  EXPECT_LT(glm::length(from(c) - glm::normalize(direction)), 1e-9);
  EXPECT_LT(glm::length(c.target - scene.bounds().center()), 1e-6 * (1.0 + scene.bounds().radius()))
      << "a fit-all view looks at the scene's centre";
  EXPECT_EQ(c.projection, mfr::Projection::Perspective);
}

class SceneViews : public mfr::test::TempDirTest {};

TEST_F(SceneViews, QuadsHaveAnIsoViewBesidesTheirOwnFront) {
  const mfr::Scene quads = mfr::loadScene("@quads:4");
  EXPECT_EQ(quads.viewNames(), (std::vector<std::string>{"fit", "front", "iso"}));
  EXPECT_EQ(quads.view("front").projection, mfr::Projection::Orthographic) << "the scene's own front view";
  expectFitFrom(quads, quads.view("iso"), {1.0, 0.8, 1.0});
}

TEST_F(SceneViews, AScenesOwnViewsComeFirst) {
  const std::string sphere = R"({"primitive": {"type": "sphere"}, "transform": {"translate": [3, 0, 0]}})";
  const mfr::Scene own = mfr::loadScene(
      write("own.mfrscene",
            R"({"objects": [)" + sphere + R"(], "views": [{"name": "iso", "eye": [3, 0, 9], "target": [3, 0, 0]}]})"));
  EXPECT_EQ(own.viewNames(), (std::vector<std::string>{"fit", "iso", "front"}));
  EXPECT_LT(glm::length(from(own.view("iso")) - glm::dvec3(0.0, 0.0, 1.0)), 1e-9) << "the file's own iso view";
  expectFitFrom(own, own.view("front"), {0.0, 0.0, 1.0});
  try {
    (void)own.view("top");
    ADD_FAILURE() << "an unknown view was accepted";
  } catch (const mfr::Error& e) {
    EXPECT_EQ(std::string(e.what()),
              "view 'top': not in scene 'own' (available: fit, iso, front, or orbit:AZIMUTH:ELEVATION)");
  }
  // A model file's two views are these standard ones.
  const mfr::Scene model = mfr::loadScene(write("tri.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"));
  EXPECT_EQ(model.viewNames(), (std::vector<std::string>{"fit", "front", "iso"}));
  expectFitFrom(model, model.view("iso"), {1.0, 0.8, 1.0});
  expectFitFrom(model, model.view("front"), {0.0, 0.0, 1.0});
}

// orbit:AZIMUTH:ELEVATION is read whole: sscanf's %lf skipped blanks, so "orbit: 5:0" was
// taken (a bug hunt) where no other view name is trimmed.
TEST_F(SceneViews, OrbitViewsAreReadWhole) {
  const mfr::Scene sample = mfr::loadScene("@sample");
  expectFitFrom(sample, sample.view("orbit:90:0"), {1.0, 0.0, 0.0});
  for (const std::string name : {"orbit: 5:0", "orbit:5: 0", "orbit:5:0 ", "orbit:5:0x", "orbit:5:90", "orbit:5"}) {
    try {
      (void)sample.view(name);
      ADD_FAILURE() << "'" << name << "' was taken";
    } catch (const mfr::Error& e) {
      EXPECT_EQ(std::string(e.what()),
                "view '" + name + "': expected orbit:AZIMUTH:ELEVATION in degrees, |elevation| <= 89");
    }
  }
}

}  // namespace
