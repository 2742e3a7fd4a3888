// Operation "csg" on the GPU against the oracle: the capture's object payload (object id and
// facing per fragment) against the oracle's lists, and the CSG image against compositeCsg on the
// oracle's exact lists (whose rule tests/unit/test_csg.cpp checks against CGAL's exact Booleans).
#include <gtest/gtest.h>

#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "gl_fixture.hpp"
#include "mfr/error.hpp"
#include "mfr/reference/composite.hpp"
#include "mfr/scene/csg.hpp"
#include "mfr/scene/primitives.hpp"
#include "mfr/scene/sample.hpp"

namespace mfr::test {
namespace {

const char* const kCsgMethods[] = {"abuffer-ll", "abuffer-array", "abuffer-sbuffer"};

// Pixels whose visible CSG surface (oracle rule) is a back face: a bore's wall or floor, which
// only a correct inside/outside classification shows.
std::size_t backFacePixels(const FragmentLists& lists, const CsgTree& tree) {
  std::size_t n = 0;
  for (int y = 0; y < lists.height; ++y)
    for (int x = 0; x < lists.width; ++x) {
      const auto pixel = lists.pixel(x, y);
      const auto visible = csgVisibleFragment(tree, pixel);
      if (visible && !lists.isAmbiguous(x, y) && !pixel[*visible].frontFacing) ++n;
    }
  return n;
}

// abuffer-ll's CSG image of `scene` equals the oracle's (`expected`, composited from `oracle`)
// within 2/255 on 99.9 % of the pixels off edges.
void expectAbufferCsgEqualsTheOracles(const Scene& scene, const Camera& camera, const FragmentLists& oracle,
                                      const ImageRGBA8& expected) {
  GpuRenderer gpu;
  gpu.setScene(scene);
  RenderRequest req;
  req.method = "abuffer-ll";
  req.operation = "csg";
  req.width = oracle.width;
  req.height = oracle.height;
  const ImageComparison c = compareImages(oracle, expected, gpu.render(camera, req).image, 2);
  EXPECT_GE(c.fraction(), 0.999) << (c.compared - c.within) << " of " << c.compared << " pixels off";
}

// The capture with the object payload: every fragment's colour word is objectId·2 + facing.
TEST(CsgGpu, CapturedObjectIdsAndFacingEqualTheOracles) {
  context();
  const Scene scene = makeCsgSampleScene();
  const Camera camera = scene.view("iso");
  const int w = 96, h = 80;
  const FragmentLists oracle = castFragments(scene, camera, w, h);
  GpuRenderer gpu;
  gpu.setScene(scene);
  for (const char* method : kCsgMethods) {
    SCOPED_TRACE(method);
    RenderRequest req;
    req.method = method;
    req.operation = "csg";
    req.width = w;
    req.height = h;
    const int keep = static_cast<int>(oracle.maxCount());
    const CapturedLists lists = gpu.capture(camera, req, keep);
    std::size_t compared = 0, fragments = 0, wrong = 0;
    std::string first;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        if (oracle.isAmbiguous(x, y)) continue;
        ++compared;
        const auto expected = oracle.pixel(x, y);
        const std::size_t p = static_cast<std::size_t>(y) * w + x;
        if (lists.counts[p] != expected.size()) {
          ++wrong;
          continue;
        }
        for (std::size_t i = 0; i < expected.size(); ++i) {
          ++fragments;
          const std::uint32_t want = expected[i].objectId * 2u + (expected[i].frontFacing ? 1u : 0u);
          const std::uint32_t got = lists.fragments[p * static_cast<std::size_t>(keep) + i].color;
          if (got != want) {
            if (first.empty())
              first = "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ") fragment " + std::to_string(i) +
                      ": " + std::to_string(got) + " instead of " + std::to_string(want);
            ++wrong;
          }
        }
      }
    EXPECT_GT(compared, static_cast<std::size_t>(w * h) * 7 / 10);
    EXPECT_GT(fragments, 6000u);  // measured 8652: the solids cover much of the image, 2–8 layers deep
    EXPECT_EQ(wrong, 0u) << first;
  }
}

// The CSG image: 2/255 of the oracle's on 99.9 % of the unflagged pixels, on two views, with
// many pixels showing a bore (a back face), and different from plain OIT.
TEST(CsgGpu, ImageEqualsTheOraclesCsg) {
  context();
  const Scene scene = makeCsgSampleScene();
  GpuRenderer gpu;
  gpu.setScene(scene);
  for (const char* view : {"iso", "front"}) {
    const Camera camera = scene.view(view);
    const int w = 112, h = 96;
    const FragmentLists oracle = castFragments(scene, camera, w, h);
    const ImageRGBA8 expected = compositeCsg(oracle, scene);
    const std::size_t bores = backFacePixels(oracle, scene.csg);
    EXPECT_GT(bores, static_cast<std::size_t>(w * h / 400)) << view;  // measured: iso 199, front 62
    for (const char* method : kCsgMethods) {
      SCOPED_TRACE(std::string(view) + " " + method);
      RenderRequest req;
      req.method = method;
      req.operation = "csg";
      req.width = w;
      req.height = h;
      const RenderOutput out = gpu.render(camera, req);
      EXPECT_EQ(out.stats.operation, "csg");
      const ImageComparison c = compareImages(oracle, expected, out.image, 2);
      EXPECT_GE(c.fraction(), 0.999) << (c.compared - c.within) << " of " << c.compared << " pixels off; max "
                                     << c.maxDifference;
      // Not merely the OIT image: "over" of the same opaque solids shows the nearest surface
      // everywhere, never a bore's back face behind removed material.
      req.operation = "oit";
      const RenderOutput oit = gpu.render(camera, req);
      const ImageComparison o = compareImages(oracle, expected, oit.image, 2);
      EXPECT_LT(o.within + bores / 2, o.compared);
      // Same capture (same fragments), plus the operation's 8 bytes per pixel.
      EXPECT_EQ(out.stats.bytesAllocated, oit.stats.bytesAllocated + 8ull * w * h);
      EXPECT_EQ(out.stats.fragmentsStored, oit.stats.fragmentsStored);
    }
  }
}

// A tree whose stack is as deep as validateCsg allows (32): a right-nested union of 32 spheres.
// The GPU's bit stack was clamped at 31, so the last sphere vanished (a bug hunt).
TEST(CsgGpu, TheDeepestStackKeepsEveryOperand) {
  context();
  Scene scene;
  scene.name = "deep";
  const auto sphere = std::make_shared<const Mesh>(makeSphere(0.15, 12, 6));
  for (int i = 0; i < 32; ++i) {
    Object o;
    o.name = "s" + std::to_string(i);
    o.mesh = sphere;
    o.transform = glm::translate(glm::dmat4(1.0), {(i % 8) * 0.4 - 1.4, (i / 8) * 0.4 - 0.6, 0.0});
    o.material.color = {static_cast<float>(i % 4) / 4.0f, 0.5f, 1.0f - static_cast<float>(i % 4) / 4.0f, 1.0f};
    scene.objects.push_back(std::move(o));
  }
  CsgNode node{CsgNode::Op::Primitive, 31, {}};
  for (int i = 30; i >= 0; --i)
    node = CsgNode{CsgNode::Op::Union, 0, {CsgNode{CsgNode::Op::Primitive, static_cast<std::uint32_t>(i), {}}, node}};
  scene.csg.root = node;
  ASSERT_NO_THROW(validateCsg(scene));
  Camera camera;
  camera.eye = {0.0, 0.0, 6.0};
  camera = camera.fittedTo(scene.bounds());
  const int w = 160, h = 120;
  const FragmentLists oracle = castFragments(scene, camera, w, h);
  const ImageRGBA8 expected = compositeCsg(oracle, scene);
  // Measured with the clamp: 58 pixels off (the last sphere); without it, none.
  expectAbufferCsgEqualsTheOracles(scene, camera, oracle, expected);
}

// Mirrored drills (the cylinders are symmetric under the mirror, so the solid is the same): the
// GPU flips their facings like the oracle, and the image equals the unmirrored scene's.
TEST(CsgGpu, MirroredPartsStaySolids) {
  context();
  const Scene plain = makeCsgSampleScene();
  Scene mirrored = plain;
  for (std::size_t o : {2u, 3u})  // drill x, drill z: mirror across their own axis planes
    mirrored.objects[o].transform = mirrored.objects[o].transform * glm::scale(glm::dmat4(1.0), {-1.0, 1.0, 1.0});
  ASSERT_EQ(csgMirroredPrimitives(mirrored), 0b1100u);
  const Camera camera = plain.view("iso");
  const int w = 112, h = 96;
  const FragmentLists oracle = castFragments(mirrored, camera, w, h);
  const ImageRGBA8 expected = compositeCsg(oracle, mirrored);
  const ImageComparison same =
      compareImages(oracle, compositeCsg(castFragments(plain, camera, w, h), plain), expected, 2);
  EXPECT_GE(same.fraction(), 0.999);
  expectAbufferCsgEqualsTheOracles(mirrored, camera, oracle, expected);
}

TEST(CsgGpu, RefusesScenesWithoutATreeAndMethodsWithoutObjectIds) {
  context();
  GpuRenderer gpu;
  const Scene csg = makeCsgSampleScene();
  RenderRequest req;
  req.method = "kplus-array";
  req.operation = "csg";
  req.width = 32;
  req.height = 32;
  gpu.setScene(csg);
  try {
    gpu.render(csg.view("iso"), req);
    FAIL() << "kplus-array accepted --op csg";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("abuffer-sbuffer"), std::string::npos) << e.what();
  }
  const Scene plain = makeSampleScene();
  gpu.setScene(plain);
  req.method = "abuffer-ll";
  try {
    gpu.render(plain.view("front"), req);
    FAIL() << "a scene without a CSG tree accepted --op csg";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no CSG tree"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mfr::test
