// A molecule on the GPU against the oracle: per-vertex element colours times the white material
// (and --opacity's alpha), and a part's own colour replacing the element colours
// (Material::vertexColors false), fragment by fragment. pept.pdb (Debian package pymol-data,
// shared/DATA.md): 107 atoms, 34,240 triangles.
#include <gtest/gtest.h>

#include <filesystem>

#include "gl_fixture.hpp"
#include "mfr/io/load.hpp"

namespace mfr::test {
namespace {

const char* const kPept = "/usr/share/pymol/data/demo/pept.pdb";

void expectGpuEqualsOracle(const Scene& scene, const std::string& method) {
  SCOPED_TRACE(method);
  RenderRequest req;
  req.method = method;
  req.width = 72;
  req.height = 56;
  expectGpuMatchesOracle(scene, scene.view("fit"), req);
}

// Red and blue of a packed fragment colour (R in the low byte).
int red(std::uint32_t c) {
  return static_cast<int>(c & 0xFF);
}
int blue(std::uint32_t c) {
  return static_cast<int>((c >> 16) & 0xFF);
}

TEST(MoleculeOnGpu, ElementColoursAndReplacedColoursMatchTheOracle) {
  ASSERT_TRUE(std::filesystem::exists(kPept)) << "test data missing: run scripts/setup (pymol-data)";
  Scene scene = loadScene(kPept);
  for (Object& o : scene.objects) o.material.color.a = 0.4f;  // as --opacity 0.4 does
  // Element colours: oxygens (red) and nitrogens (blue) both appear among the fragments.
  {
    const FragmentLists lists = castFragments(scene, scene.view("fit"), 72, 56);
    std::size_t reddish = 0, bluish = 0;
    for (const Fragment& f : lists.fragments) {
      reddish += red(f.color) > 3 * blue(f.color) + 20;
      bluish += blue(f.color) > 3 * red(f.color) + 20;
    }
    EXPECT_GT(reddish, 0u);
    EXPECT_GT(bluish, 0u);
  }
  for (const char* method : {"abuffer-ll", "peel-dual"}) expectGpuEqualsOracle(scene, method);

  // A colour of the part's own (0.2, 0.4, 0.9) replaces them: every fragment is that colour, lit.
  for (Object& o : scene.objects) {
    o.material.color = glm::vec4(0.2f, 0.4f, 0.9f, 0.4f);
    o.material.vertexColors = false;
  }
  const FragmentLists lists = castFragments(scene, scene.view("fit"), 72, 56);
  ASSERT_FALSE(lists.fragments.empty());
  for (const Fragment& f : lists.fragments) {
    const double r = red(f.color), b = blue(f.color);
    ASSERT_NEAR(b / r, 4.5, 4.5 * 2.0 / r + 0.05) << "fragment colour " << std::hex << f.color;
  }
  for (const char* method : {"abuffer-ll", "peel-dual"}) expectGpuEqualsOracle(scene, method);
}

}  // namespace
}  // namespace mfr::test
