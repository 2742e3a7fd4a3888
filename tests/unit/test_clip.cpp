// The clip box (Scene::clipBox) in the oracle: what lies outside is not cast, pixels where a clip
// face crosses a surface within the edge epsilon are flagged like triangle edges, and the .mfrscene
// "clip" key — checked against hand-worked orthographic geometry.
#include <gtest/gtest.h>

#include <limits>
#include <memory>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "mfr/error.hpp"
#include "mfr/io/load.hpp"
#include "mfr/reference/oracle.hpp"
#include "mfr/scene/clip_box.hpp"
#include "mfr/scene/primitives.hpp"
#include "test_files.hpp"

namespace mfr {
namespace {

void addPlane(Scene& scene, const std::string& name, double z, const glm::vec4& color) {
  Object o;
  o.name = name;
  o.mesh = std::make_shared<const Mesh>(makePlane(20.0, 20.0));
  o.transform = glm::translate(glm::dmat4(1.0), {0.0, 0.0, z});
  o.material.color = color;
  scene.objects.push_back(std::move(o));
}

// Planes facing the camera at z = 0, −2 and −5; orthographic camera from z = 10 showing
// 10.667 × 8 world units on 64 × 48 pixels: pixel column c has its centre at
// x = ((c + 0.5)/32 − 1)·16/3.
Scene planes() {
  Scene s;
  s.name = "planes";
  addPlane(s, "z0", 0.0, {1.0f, 0.0f, 0.0f, 0.5f});
  addPlane(s, "z-2", -2.0, {0.0f, 0.0f, 1.0f, 0.5f});
  addPlane(s, "z-5", -5.0, {0.0f, 1.0f, 0.0f, 0.5f});
  return s;
}

Camera orthoCamera() {
  Camera c;
  c.eye = {0.0, 0.0, 10.0};
  c.projection = Projection::Orthographic;
  c.orthoHeight = 8.0;
  c.nearPlane = 1.0;
  c.farPlane = 20.0;
  return c;
}

double columnX(int c) {
  return ((c + 0.5) / 32.0 - 1.0) * 16.0 / 3.0;
}

TEST(OracleClip, OnlyWhatLiesInsideTheBoxIsCast) {
  Scene scene = planes();
  Bounds box;
  // x from between columns 20 and 21 on; z from −3 to 1: the plane at z = −5 is cut away.
  box.min = {0.5 * (columnX(20) + columnX(21)), -100.0, -3.0};
  box.max = {100.0, 100.0, 1.0};
  const FragmentLists all = castFragments(scene, orthoCamera(), 64, 48);
  EXPECT_EQ(all.count(10, 10), 3u);
  EXPECT_EQ(all.count(40, 30), 3u);
  scene.clipBox = box;
  const FragmentLists lists = castFragments(scene, orthoCamera(), 64, 48);
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x) {
      if (all.isAmbiguous(x, y)) continue;  // on the planes' diagonals both triangles are hit
      const std::uint32_t want = x <= 20 ? 0u : 2u;
      ASSERT_EQ(lists.count(x, y), want) << x << "," << y;
      if (want == 2) {
        EXPECT_EQ(lists.pixel(x, y)[0].objectId, 0u);
        EXPECT_EQ(lists.pixel(x, y)[1].objectId, 1u);
      }
      // Half a pixel from the face the clip adds no ambiguity (the planes' own diagonals keep theirs).
      if (x == 20 || x == 21) {
        EXPECT_EQ(lists.isEdge(x, y), all.isEdge(x, y)) << x << "," << y;
      }
    }
}

TEST(OracleClip, PixelsOnAClipFaceAreFlaggedLikeEdges) {
  Scene scene = planes();
  const FragmentLists all = castFragments(scene, orthoCamera(), 64, 48);
  Bounds box;
  box.min = {columnX(20), -100.0, -100.0};  // the face through column 20's centres
  box.max = {100.0, 100.0, 100.0};
  scene.clipBox = box;
  const FragmentLists lists = castFragments(scene, orthoCamera(), 64, 48);
  for (int y = 0; y < 48; ++y) {
    EXPECT_TRUE(lists.isEdge(20, y)) << y;
    EXPECT_EQ(lists.count(19, y), 0u) << y;
    if (!all.isAmbiguous(21, y)) {
      EXPECT_EQ(lists.count(21, y), 3u) << y;
    }
    EXPECT_EQ(lists.isEdge(22, y), all.isEdge(22, y)) << y;
  }
  // A face parallel to the planes and through one of them: that plane's pixels are all on it.
  box.min = {-100.0, -100.0, -2.0};
  scene.clipBox = box;
  const FragmentLists onPlane = castFragments(scene, orthoCamera(), 64, 48);
  EXPECT_TRUE(onPlane.isEdge(40, 30));
  box.min.z = -1.0;  // between the planes: nothing ambiguous, one plane left
  scene.clipBox = box;
  const FragmentLists between = castFragments(scene, orthoCamera(), 64, 48);
  EXPECT_FALSE(all.isEdge(40, 30));
  EXPECT_FALSE(between.isEdge(40, 30));
  EXPECT_EQ(between.count(40, 30), 1u);
}

TEST(OracleClip, ValidationRefusesInvertedAndNonFiniteBoxes) {
  Scene scene = planes();
  Bounds box;
  box.min = {0.0, 0.0, 0.0};
  box.max = {1.0, -1.0, 1.0};
  scene.clipBox = box;
  EXPECT_THROW(scene.validate(), Error);
  box.max = {1.0, 1.0, std::numeric_limits<double>::infinity()};
  scene.clipBox = box;
  EXPECT_THROW(scene.validate(), Error);
  box.max = {1.0, 1.0, 1.0};
  scene.clipBox = box;
  EXPECT_NO_THROW(scene.validate());
}

// A scene flat on an axis (a plane) is held by a box that covers it there, even a flat one (the
// viewer's Clip dock starts at the scene's bounds and refused them: a review); a flat box beside
// it, or one on a solid scene, still holds nothing.
TEST(ClipBoxHoldsScene, AFlatSceneIsHeldByABoxFlatWhereItIs) {
  Scene scene;
  scene.name = "sheet";
  Object sheet;
  sheet.mesh = std::make_shared<Mesh>(makePlane(2.0, 2.0));
  scene.objects.push_back(sheet);
  const Bounds b = scene.bounds();
  ASSERT_EQ(b.min.z, b.max.z);
  EXPECT_NO_THROW(requireClipBoxHoldsScene(scene, b, "clip box"));
  EXPECT_NO_THROW(requireClipBoxHoldsScene(scene, Bounds{{-0.5, -0.5, 0.0}, {0.5, 0.5, 0.0}}, "clip box"));
  EXPECT_NO_THROW(requireClipBoxHoldsScene(scene, Bounds{{-0.5, -0.5, -1.0}, {0.5, 0.5, 1.0}}, "clip box"));
  EXPECT_THROW(requireClipBoxHoldsScene(scene, Bounds{{-0.5, -0.5, 0.5}, {0.5, 0.5, 0.5}}, "clip box"), Error);
  EXPECT_THROW(requireClipBoxHoldsScene(scene, Bounds{{-0.5, 0.0, 0.0}, {0.5, 0.0, 0.0}}, "clip box"), Error);
  scene.objects[0].mesh = std::make_shared<Mesh>(makeBox(glm::dvec3(2.0)));
  EXPECT_THROW(requireClipBoxHoldsScene(scene, Bounds{{-0.5, -0.5, 0.0}, {0.5, 0.5, 0.0}}, "clip box"), Error);
}

using SceneFileClip = test::TempDirTest;

TEST_F(SceneFileClip, ClipKeyAndItsErrors) {
  const std::string objects = R"("objects": [{"primitive": {"type": "box"}}])";
  const Scene scene =
      loadScene(write("c.mfrscene", "{" + objects + R"(, "clip": {"min": [-1, -2, -3], "max": [1, 2, 0.5]}})"));
  ASSERT_TRUE(scene.clipBox.has_value());
  EXPECT_EQ(scene.clipBox->min, glm::dvec3(-1, -2, -3));
  EXPECT_EQ(scene.clipBox->max, glm::dvec3(1, 2, 0.5));
  EXPECT_FALSE(loadScene(write("n.mfrscene", "{" + objects + "}")).clipBox.has_value());
  const std::pair<std::string, std::string> bad[] = {
      {R"("clip": [1, 2])", "clip: expected an object"},
      {R"("clip": {"min": [0, 0, 0]})", "clip: expected \"min\" and \"max\""},
      {R"("clip": {"min": [0, 0], "max": [1, 1, 1]})", "clip.min: expected an array of 3 numbers"},
      {R"("clip": {"min": [0, 0, 0], "max": [1, "a", 1]})", "clip.max[1]"},
      {R"("clip": {"min": [0, 2, 0], "max": [1, 1, 1]})", "clip: min must not exceed max"},
      // A flat box drew an empty image; one beyond a float's range drew nothing on the GPU and
      // everything in the oracle (a bug hunt).
      {R"("clip": {"min": [0, -1, -1], "max": [0, 1, 1]})", "clip: holds nothing of scene 'bad' (a flat box"},
      {R"("clip": {"min": [-1e39, 0, 0], "max": [1, 1, 1]})", "clip: a corner lies beyond a float's range (±3.4e38)"},
  };
  for (const auto& [json, mention] : bad) {
    SCOPED_TRACE(json);
    const std::filesystem::path path = write("bad.mfrscene", "{" + objects + ", " + json + "}");
    test::expectFileError(path, mention, [&] { return loadScene(path).name; });
  }
}

}  // namespace
}  // namespace mfr
