// orientAndSplitAtFeatures (scene/feature_normals.hpp) on meshes whose answer is known by
// construction, including the shapes that made VTK's filter quadratic (a vertex with 200,000
// triangles, an edge with 100,000). tests/data/test_feature_normals.cpp compares it with VTK's
// filter on real meshes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <fstream>
#include <numbers>
#include <set>
#include <vector>

#include "mfr/io/load.hpp"
#include "mfr/scene/feature_normals.hpp"
#include "test_files.hpp"

namespace {

glm::dvec3 faceNormal(const std::vector<glm::dvec3>& p, const std::vector<std::uint32_t>& idx, std::size_t t) {
  return glm::normalize(glm::cross(p[idx[3 * t + 1]] - p[idx[3 * t]], p[idx[3 * t + 2]] - p[idx[3 * t]]));
}

// A disc in z = 0 as a fan of `n` triangles around vertex 0, every other one wound clockwise.
void fan(std::size_t n, std::vector<glm::dvec3>& points, std::vector<std::uint32_t>& indices) {
  points.assign(1, glm::dvec3(0.0));
  for (std::size_t i = 0; i < n; ++i) {
    const double a = 2.0 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(n);
    points.emplace_back(std::cos(a), std::sin(a), 0.0);
  }
  for (std::size_t i = 0; i < n; ++i) {
    const auto b = static_cast<std::uint32_t>(1 + i), c = static_cast<std::uint32_t>(1 + (i + 1) % n);
    if (i % 2 == 0)
      indices.insert(indices.end(), {0, b, c});
    else
      indices.insert(indices.end(), {0, c, b});
  }
}

// The unit cube's corners (corner i at (i & 1, i >> 1 & 1, i >> 2 & 1)) and its faces as quads wound
// counter-clockwise seen from outside.
std::vector<glm::dvec3> unitCubeCorners() {
  std::vector<glm::dvec3> p;
  for (int i = 0; i < 8; ++i) p.emplace_back(i & 1, (i >> 1) & 1, (i >> 2) & 1);
  return p;
}
constexpr std::uint32_t kCubeQuads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                            {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};

}  // namespace

TEST(FeatureNormals, CubeIsRewoundOutwardAndSplitAtEveryEdge) {
  const std::vector<glm::dvec3> p = unitCubeCorners();
  // The first triangle of each quad is kept, the second reversed for odd faces, so the rewinding
  // must fix three faces' halves.
  std::vector<std::uint32_t> idx;
  for (int f = 0; f < 6; ++f) {
    const auto& q = kCubeQuads[f];
    idx.insert(idx.end(), {q[0], q[1], q[2]});
    if (f % 2 == 1)
      idx.insert(idx.end(), {q[3], q[2], q[0]});
    else
      idx.insert(idx.end(), {q[0], q[2], q[3]});
  }
  const mfr::FeatureSplit s = mfr::orientAndSplitAtFeatures(p, idx, 30.0);
  EXPECT_EQ(s.reversed, 3u);
  ASSERT_EQ(s.source.size(), 24u);  // each corner, once per face meeting there
  std::vector<glm::dvec3> positions;
  for (const std::uint32_t v : s.source) positions.push_back(p[v]);
  for (std::size_t t = 0; t < 12; ++t) {
    const glm::dvec3 n = faceNormal(positions, s.indices, t);
    const glm::dvec3 centre = (positions[s.indices[3 * t]] + positions[s.indices[3 * t + 2]]) * 0.5;
    EXPECT_GT(glm::dot(n, centre - glm::dvec3(0.5)), 0.49) << "triangle " << t << " faces inward";
    for (int k = 0; k < 3; ++k)
      EXPECT_LT(glm::length(glm::dvec3(s.normals[s.indices[3 * t + k]]) - n), 1e-6) << "triangle " << t;
  }
}

// One triangle listed first and wound against the other eleven: VTK's rule keeps the seed's winding
// and turns the cube inside out; the loaders' majority rule keeps the file's (a bug hunt: such an
// STL measured volume −1 and drew its near faces as back faces).
TEST(FeatureNormals, MajorityWindingKeepsWhatMostTrianglesSay) {
  const std::vector<glm::dvec3> p = unitCubeCorners();
  std::vector<std::uint32_t> idx;
  for (const auto& q : kCubeQuads) idx.insert(idx.end(), {q[0], q[1], q[2], q[0], q[2], q[3]});
  std::swap(idx[1], idx[2]);  // the first triangle reversed
  const auto outward = [&](const mfr::FeatureSplit& s) {
    std::vector<glm::dvec3> positions;
    for (const std::uint32_t v : s.source) positions.push_back(p[v]);
    int count = 0;
    for (std::size_t t = 0; t < 12; ++t) {
      const glm::dvec3 centre = (positions[s.indices[3 * t]] + positions[s.indices[3 * t + 2]]) * 0.5;
      count += glm::dot(faceNormal(positions, s.indices, t), centre - glm::dvec3(0.5)) > 0.0;
    }
    return count;
  };
  const mfr::FeatureSplit majority = mfr::orientAndSplitAtFeatures(p, idx, 30.0, true);
  EXPECT_EQ(majority.reversed, 1u);
  EXPECT_EQ(outward(majority), 12);
  const mfr::FeatureSplit seed = mfr::orientAndSplitAtFeatures(p, idx, 30.0, false);
  EXPECT_EQ(seed.reversed, 11u);
  EXPECT_EQ(outward(seed), 0);
}

TEST(FeatureNormals, FanOfTwoHundredThousandTrianglesStaysOneRegion) {
  std::vector<glm::dvec3> p;
  std::vector<std::uint32_t> idx;
  fan(200000, p, idx);
  const mfr::FeatureSplit s = mfr::orientAndSplitAtFeatures(p, idx, 30.0);
  EXPECT_EQ(s.reversed, 100000u);
  EXPECT_EQ(s.source.size(), p.size());  // flat: nothing split
  for (std::size_t v = 0; v < s.normals.size(); ++v) ASSERT_EQ(s.normals[v], glm::vec3(0, 0, 1)) << "vertex " << v;
}

TEST(FeatureNormals, EdgeSharedByOneHundredThousandTrianglesSeparatesThem) {
  // Pages of a book: triangles (0, 1, page) around the spine 0–1, every third one reversed.
  const std::uint32_t pages = 100000;
  std::vector<glm::dvec3> p{{0, 0, 0}, {0, 0, 1}};
  std::vector<std::uint32_t> idx;
  for (std::uint32_t i = 0; i < pages; ++i) {
    const double a = 2.0 * std::numbers::pi * i / pages;
    p.emplace_back(std::cos(a), std::sin(a), 0.5);
    if (i % 3 == 1)
      idx.insert(idx.end(), {1, 0, 2 + i});
    else
      idx.insert(idx.end(), {0, 1, 2 + i});
  }
  const mfr::FeatureSplit s = mfr::orientAndSplitAtFeatures(p, idx, 30.0);
  // Every page is reached from the first across the spine, so each runs it from 1 to 0.
  std::set<std::uint32_t> spineCopies;
  for (std::uint32_t t = 0; t < pages; ++t) {
    const std::uint32_t* c = &s.indices[3 * t];
    std::size_t from1 = 3, from0 = 3;
    for (std::size_t k = 0; k < 3; ++k) {
      if (s.source[c[k]] == 1) from1 = k;
      if (s.source[c[k]] == 0) from0 = k;
    }
    ASSERT_TRUE(from0 < 3 && from1 < 3) << "page " << t;
    EXPECT_EQ((from0 + 1) % 3 == from1, t == 0) << "page " << t;
    spineCopies.insert(c[from0]);
    spineCopies.insert(c[from1]);
  }
  // A non-manifold edge is a crease: every page has its own copy of both spine vertices.
  EXPECT_EQ(spineCopies.size(), 2u * pages);
  EXPECT_EQ(s.source.size(), p.size() + 2u * (pages - 1));
}

TEST(FeatureNormals, DegenerateTrianglesGetNoEdgeAndZeroNormals) {
  const std::vector<glm::dvec3> p{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 1, 0}};
  // A repeated corner, three collinear corners, and one good triangle sharing an edge with both.
  const std::vector<std::uint32_t> idx{0, 0, 1, 0, 1, 2, 0, 1, 3};
  const mfr::FeatureSplit s = mfr::orientAndSplitAtFeatures(p, idx, 30.0);
  ASSERT_EQ(s.indices.size(), idx.size());
  for (const glm::vec3& n : s.normals) EXPECT_TRUE(std::isfinite(n.x) && std::isfinite(n.y) && std::isfinite(n.z));
  // The good triangle is rewound from the first (across the edge 0–1, which all three share), and
  // that edge is a crease, so its corners keep its own normal, unmixed with the zero ones.
  for (int k = 6; k < 9; ++k) EXPECT_EQ(s.normals[s.indices[k]], glm::vec3(0, 0, -1)) << "corner " << k;
  EXPECT_EQ(s.reversed, 2u);
}

TEST(FeatureNormals, LoaderReadsAPrismWithFanCapsOfTwoHundredThousandTriangles) {
  // The file that took VTK's filter minutes (any mfr command on it): a 200,000-sided prism whose
  // ends are fans around their centres. Written as binary PLY.
  const std::uint32_t n = 200000;
  std::string body;
  const auto put = [&body](const auto& value) { body.append(reinterpret_cast<const char*>(&value), sizeof value); };
  for (int z = 0; z < 2; ++z) {
    put(0.0f), put(0.0f), put(static_cast<float>(z));
    for (std::uint32_t i = 0; i < n; ++i) {
      const double a = 2.0 * std::numbers::pi * i / n;
      put(static_cast<float>(std::cos(a))), put(static_cast<float>(std::sin(a))), put(static_cast<float>(z));
    }
  }
  const auto face = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    put(static_cast<std::uint8_t>(3)), put(a), put(b), put(c);
  };
  const std::uint32_t top = n + 1;
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint32_t j = (i + 1) % n;
    face(0, 1 + j, 1 + i);                // bottom, facing -z
    face(top, top + 1 + i, top + 1 + j);  // top, facing +z
    face(1 + i, 1 + j, top + 1 + j);      // side
    face(1 + i, top + 1 + j, top + 1 + i);
  }
  const std::string header = "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(2 * (n + 1)) +
                             "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                             std::to_string(4 * n) + "\nproperty list uchar int vertex_indices\nend_header\n";
  mfr::test::TempDir dir;
  const auto objects = mfr::loadModel(dir.write("prism.ply", header + body));
  ASSERT_EQ(objects.size(), 1u);
  const mfr::Mesh& mesh = *objects[0].mesh;
  EXPECT_EQ(mesh.triangleCount(), 4u * n);
  // The rims are creases (90°): each rim vertex is in a cap and in the side; the side is smooth.
  EXPECT_EQ(mesh.positions.size(), 2u * (n + 1) + 2u * n);
  std::size_t up = 0, down = 0;
  for (const glm::vec3& normal : mesh.normals) {
    up += normal == glm::vec3(0, 0, 1) ? 1 : 0;
    down += normal == glm::vec3(0, 0, -1) ? 1 : 0;
  }
  EXPECT_EQ(up, n + 1u);
  EXPECT_EQ(down, n + 1u);
}
