// The scene upload (gl::GpuScene): meshes a previous upload holds are shared, not uploaded again,
// and a renderer whose scene was edited draws exactly what a fresh renderer draws from the edited
// scene — colours, visibility and a transform changed, one mesh replaced.
#include <gtest/gtest.h>

#include <initializer_list>
#include <memory>

#include <glm/gtc/matrix_transform.hpp>

#include "gl_fixture.hpp"
#include "image_compare.hpp"
#include "mfr/gl/gpu_scene.hpp"
#include "mfr/gpu_renderer.hpp"
#include "mfr/scene/sample.hpp"

namespace mfr::test {
namespace {

TEST(GpuSceneUpload, EditsShareTheMeshesAndDrawLikeAFreshUpload) {
  context();
  const Scene original = makeSampleScene();
  ASSERT_GE(original.objects.size(), 3u);
  const gl::GpuScene first(original);
  EXPECT_GT(first.bytes(), 0u);
  EXPECT_EQ(first.uploadedBytes(), first.bytes());

  // Colours, one part hidden, one moved: the same meshes.
  Scene edited = original;
  edited.objects[0].material.color = {0.9f, 0.1f, 0.1f, 0.6f};
  edited.objects[1].visible = false;
  edited.objects[2].transform = glm::translate(edited.objects[2].transform, {0.2, -0.1, 0.05});
  const gl::GpuScene second(edited, &first);
  EXPECT_EQ(second.uploadedBytes(), 0u);
  EXPECT_GT(second.bytes(), 0u);
  EXPECT_LT(second.bytes(), first.bytes());  // the hidden part's mesh is not drawn
  EXPECT_EQ(second.triangleCount(), original.triangleCount() - original.objects[1].mesh->triangleCount());

  // One mesh replaced by an equal copy: only that one is uploaded.
  Scene replaced = edited;
  replaced.objects[3].mesh = std::make_shared<const Mesh>(*edited.objects[3].mesh);
  const gl::GpuScene third(replaced, &second);
  EXPECT_GT(third.uploadedBytes(), 0u);
  EXPECT_LT(third.uploadedBytes(), third.bytes());

  // A renderer that saw the original and then each edit draws what a fresh one draws.
  const Camera camera = original.view("iso");
  RenderRequest req;
  req.method = "abuffer-ll";
  req.width = 96;
  req.height = 80;
  GpuRenderer reused;
  reused.setScene(original);
  (void)reused.render(camera, req);
  for (const Scene* scene : std::initializer_list<const Scene*>{&edited, &replaced, &original}) {
    reused.setScene(*scene);
    GpuRenderer fresh;
    fresh.setScene(*scene);
    const ImageRGBA8 a = reused.render(camera, req).image, b = fresh.render(camera, req).image;
    EXPECT_EQ(maxRgbDifference(a, b), 0);
  }
  // And the edit shows: the edited scene's image is not the original's.
  GpuRenderer before, after;
  before.setScene(original);
  after.setScene(edited);
  EXPECT_GT(maxRgbDifference(before.render(camera, req).image, after.render(camera, req).image), 20);
}

}  // namespace
}  // namespace mfr::test
