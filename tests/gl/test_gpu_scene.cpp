// The scene upload (gl::GpuScene): meshes a previous upload holds are shared, not uploaded again,
// and a renderer whose scene was edited draws exactly what a fresh renderer draws from the edited
// scene — colours, visibility and a transform changed, one mesh replaced.
#include <gtest/gtest.h>

#include <cstring>

#include <initializer_list>
#include <memory>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "gl_fixture.hpp"
#include "image_compare.hpp"
#include "mfr/gl/gpu_scene.hpp"
#include "mfr/gpu_renderer.hpp"
#include "mfr/render.hpp"
#include "mfr/scene/primitives.hpp"
#include "mfr/scene/sample.hpp"

namespace mfr::test {
namespace {

RenderRequest request(const std::string& method, int width, int height) {
  RenderRequest r;
  r.method = method;
  r.width = width;
  r.height = height;
  return r;
}

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

// Far from the world's origin (survey and site coordinates): the GPU's float view transform lost
// the scene's detail — a unit cube 1e7 away was RMSE 0.16 from the oracle, 1e6 away 0.06 (a bug
// hunt). Coordinates are relative to the scene's centre and each mesh's own, composed in double, so
// the far scene draws as the near one, whether it is far by its parts' transforms or by its
// vertices themselves.
TEST(GpuSceneUpload, FarFromTheOriginTheSceneKeepsItsDetail) {
  context();
  const Scene near = makeSampleScene();
  const RenderRequest gpu = request("abuffer-ll", 128, 96), oracle = request("oracle", 128, 96);
  const auto offEdges = [&](const Scene& scene) {
    const Camera camera = scene.view("orbit:35:25");  // fits each scene (the sample's own iso is near the origin)
    return pixelsDifferingBy(render(scene, camera, gpu).image, render(scene, camera, oracle).image, 2);
  };
  const std::size_t nearOff = offEdges(near);
  // Far by the parts' transforms (1e7: float steps of 1 there), and by the vertices themselves
  // (1e6, where float vertices still hold the parts' shapes, coarsely; the oracle reads the same).
  Scene byTransform = near, byVertices = near;
  for (Object& o : byTransform.objects)
    o.transform = glm::translate(glm::dmat4(1.0), glm::dvec3(1.0e7, -3.0e6, 2.0e6)) * o.transform;
  for (Object& o : byVertices.objects) {
    const glm::dvec3 local = glm::dvec3(glm::inverse(o.transform) * glm::dvec4(1.0e6, -1.0e6, 5.0e5, 0.0));
    Mesh moved = *o.mesh;
    for (glm::vec3& p : moved.positions) p = glm::vec3(glm::dvec3(p) + local);
    o.mesh = std::make_shared<const Mesh>(std::move(moved));
  }
  for (const Scene* far : {&byTransform, &byVertices}) {
    SCOPED_TRACE(far == &byTransform ? "by transform" : "by vertices");
    const std::size_t farOff = offEdges(*far);
    // Measured: 1 (transform) and 89 (vertices: the coarse float parts have many more edges) of
    // 12,288 pixels, against 7,507 and 5,506 without relative coordinates; near the origin 1.
    EXPECT_LE(farOff, nearOff + 128 * 96 / 100) << "near: " << nearOff;
  }
}

// A small assembly seen up close far from the scene's centre (a 1e-4 sample 40 units along a
// 100-unit hull; near 1e-4, far 2e-3): relative to the scene's centre, every GPU method drew it
// jagged and mis-sorted, 198/255 off the oracle on 751 of 19,200 pixels (hunt 31). Relative to the
// eye, what the GPU computes in float is small wherever the eye looks.
TEST(GpuSceneUpload, ASmallPartSeenUpCloseFarFromTheScenesCentreKeepsItsDetail) {
  context();
  Scene scene = makeSampleScene();
  for (Object& o : scene.objects)
    o.transform = glm::translate(glm::dmat4(1.0), glm::dvec3(40.0, 0.0, 0.0)) *
                  glm::scale(glm::dmat4(1.0), glm::dvec3(1e-4)) * o.transform;
  Object hull;
  hull.name = "hull";
  hull.mesh = std::make_shared<const Mesh>(makeBox(glm::dvec3(100.0, 20.0, 20.0)));
  hull.transform = glm::translate(glm::dmat4(1.0), glm::dvec3(0.0, 0.0, -20.0));
  hull.material.color = glm::vec4(0.6f, 0.6f, 0.6f, 0.3f);
  scene.objects.push_back(hull);
  Camera camera;
  camera.eye = glm::dvec3(40.0003, 0.0002, 0.0004);
  camera.target = glm::dvec3(40.0, 0.0, 0.0);
  camera.nearPlane = 1e-4;
  camera.farPlane = 2e-3;
  const ImageRGBA8 exact = render(scene, camera, request("oracle", 160, 120)).image;
  for (const char* method : {"abuffer-ll", "peel-f2b", "kbuffer"}) {
    SCOPED_TRACE(method);
    const ImageRGBA8 gpu = render(scene, camera, request(method, 160, 120)).image;
    EXPECT_LE(pixelsDifferingBy(gpu, exact, 8), std::size_t{160 * 120 / 500});  // measured: 2 (old: 796 to 814)
  }
  // Orthographic from inside the hull, the far plane at its far side: a pixel is as long at every
  // depth, and the float origin is the target's depth, where the user looks, not the middle of
  // the hull's (review 29: the middle drew up to 56 pixels off).
  camera.projection = Projection::Orthographic;
  camera.eye = glm::dvec3(40.0, 0.0, 0.001);
  camera.orthoHeight = 3e-4;
  camera.nearPlane = 5e-4;
  camera.farPlane = 100.0;
  const ImageRGBA8 exactOrtho = render(scene, camera, request("oracle", 160, 120)).image;
  for (const char* method : {"abuffer-ll", "peel-f2b", "kbuffer"}) {
    SCOPED_TRACE(std::string("orthographic, ") + method);
    const ImageRGBA8 gpu = render(scene, camera, request(method, 160, 120)).image;
    EXPECT_LE(pixelsDifferingBy(gpu, exactOrtho, 8), std::size_t{160 * 120 / 500});
  }
}

// Seen from far away through an orthographic view a few hundredths high (the viewer zooms an
// orthographic view by its height and leaves the eye where it was), or through a perspective one
// 8e-5 degrees wide, small translucent parts keep their detail and order: relative to the eye,
// 1,590 to 1,911 pixels were more than 8/255 off the oracle (review 28's spheres: 1,536 of the
// 2,338 they cover, up to 234/255). The same parts seen from nearby are the control.
TEST(GpuSceneUpload, SmallPartsSeenNarrowlyFromFarAwayKeepTheirDetail) {
  context();
  Scene scene = makeSampleScene();
  for (Object& o : scene.objects) o.transform = glm::scale(glm::dmat4(1.0), glm::dvec3(0.01)) * o.transform;
  struct View {
    const char* name;
    double distance;
    Projection projection;
  };
  for (const View& v : {View{"orthographic, near", 3.7, Projection::Orthographic},
                        View{"orthographic, far", 3.7e4, Projection::Orthographic},
                        View{"perspective, far and narrow", 3.7e4, Projection::Perspective}}) {
    SCOPED_TRACE(v.name);
    Camera camera;
    camera.target = glm::dvec3(0.0);
    camera.eye = glm::normalize(glm::dvec3(3.0, 2.0, 1.0)) * v.distance;
    camera.projection = v.projection;
    camera.orthoHeight = 0.05;
    camera.fovyDegrees = glm::degrees(2.0 * std::atan(0.025 / v.distance));  // 0.05 high at the target
    camera.nearPlane = v.distance - 0.05;
    camera.farPlane = v.distance + 0.05;
    const ImageRGBA8 exact = render(scene, camera, request("oracle", 160, 120)).image;
    std::size_t covered = 0;  // pixels unlike the corner's background: 1,804 or more
    for (int y = 0; y < exact.height; ++y)
      for (int x = 0; x < exact.width; ++x) covered += std::memcmp(exact.at(x, y), exact.at(0, 0), 4) != 0 ? 1 : 0;
    EXPECT_GT(covered, std::size_t{160 * 120 / 20});
    for (const char* method : {"abuffer-ll", "peel-f2b", "kbuffer"}) {
      SCOPED_TRACE(method);
      const ImageRGBA8 gpu = render(scene, camera, request(method, 160, 120)).image;
      EXPECT_LE(pixelsDifferingBy(gpu, exact, 8), std::size_t{160 * 120 / 500});  // measured: 4 (old: 1,590 to 1,911)
    }
  }
}

// A scene scaled by 1e-19 (about the origin, so that the fit view frames it alike) draws as the
// scene itself on both renderers: the normal matrix's entries were 1e19, and its normals overflowed
// in float when normalised — up to 99/255 off on the GPU at 1e-19, every covered pixel wrong on
// both at 4e-20 (a bug hunt). Large scales alike.
TEST(GpuSceneUpload, TinyAndHugeScalesShadeAsTheSceneItself) {
  context();
  const Scene unit = makeSampleScene();
  const RenderRequest gpu = request("abuffer-ll", 96, 72), oracle = request("oracle", 96, 72);
  const Camera unitCamera = unit.view("orbit:35:25");
  const ImageRGBA8 reference = render(unit, unitCamera, oracle).image;
  for (const double scale : {1e-19, 4e-20, 1e14}) {
    SCOPED_TRACE(scale);
    Scene scaled = unit;
    for (Object& o : scaled.objects) o.transform = glm::scale(glm::dmat4(1.0), glm::dvec3(scale)) * o.transform;
    const Camera camera = scaled.view("orbit:35:25");
    const ImageRGBA8 cpu = render(scaled, camera, oracle).image;
    const ImageRGBA8 gl = render(scaled, camera, gpu).image;
    // The oracle of the scaled scene is the unit scene's (rays and depths scale alike; edge pixels
    // may round apart), and the GPU is within the oracle's usual 2/255.
    EXPECT_LE(pixelsDifferingBy(cpu, reference, 2), reference.width * reference.height / 200);
    EXPECT_LE(pixelsDifferingBy(gl, cpu, 2), reference.width * reference.height / 100);
  }
}

}  // namespace
}  // namespace mfr::test
