#include "scene/geodesic_sphere.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <utility>

#include "mfr/error.hpp"

namespace mfr {

UnitSphere geodesicSphere(int frequency) {
  // Far more than any caller needs (a lone atom of radius 3 Å at a 0.05 Å spacing asks for 80).
  if (frequency < 1 || frequency > 4096) throw Error("geodesic sphere", "frequency must be in [1, 4096]");
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  const std::array<glm::dvec3, 12> corners = {glm::dvec3(-1, t, 0),  glm::dvec3(1, t, 0),   glm::dvec3(-1, -t, 0),
                                              glm::dvec3(1, -t, 0),  glm::dvec3(0, -1, t),  glm::dvec3(0, 1, t),
                                              glm::dvec3(0, -1, -t), glm::dvec3(0, 1, -t),  glm::dvec3(t, 0, -1),
                                              glm::dvec3(t, 0, 1),   glm::dvec3(-t, 0, -1), glm::dvec3(-t, 0, 1)};
  std::array<std::uint32_t, 60> faces = {0, 11, 5,  0, 5,  1, 0, 1, 7, 0, 7,  10, 0, 10, 11, 1, 5, 9, 5, 11,
                                         4, 11, 10, 2, 10, 7, 6, 7, 1, 8, 3,  9,  4, 3,  4,  2, 3, 2, 6, 3,
                                         6, 8,  3,  8, 9,  4, 9, 5, 2, 4, 11, 6,  2, 10, 8,  6, 7, 9, 8, 1};
  // Orientation made certain rather than trusted to the table: outward normals.
  for (std::size_t i = 0; i < faces.size(); i += 3) {
    const glm::dvec3 &a = corners[faces[i]], &b = corners[faces[i + 1]], &c = corners[faces[i + 2]];
    if (glm::dot(glm::cross(b - a, c - a), a + b + c) < 0.0) std::swap(faces[i + 1], faces[i + 2]);
  }
  // A grid point of a face is the corners weighted by whole numbers summing to the frequency; the
  // same point seen from a neighbouring face has the same corners and weights, so the sorted
  // (corner, weight) pairs name it once for the whole sphere.
  using Key = std::array<std::uint32_t, 6>;
  std::map<Key, std::uint32_t> index;
  UnitSphere s;
  s.vertices.reserve(10 * static_cast<std::size_t>(frequency) * frequency + 2);
  s.indices.reserve(60 * static_cast<std::size_t>(frequency) * frequency);
  const auto f = static_cast<std::uint32_t>(frequency);
  for (std::size_t face = 0; face < faces.size(); face += 3) {
    const std::uint32_t a = faces[face], b = faces[face + 1], c = faces[face + 2];
    const auto vertex = [&](std::uint32_t i, std::uint32_t j) {  // weight i on b, j on c
      // A weight of zero leaves its corner out of the name (an edge's points belong to two faces).
      const auto named = [](std::uint32_t corner, std::uint32_t weight) {
        return std::pair{weight > 0 ? corner : 0xffffffffU, weight};
      };
      std::array<std::pair<std::uint32_t, std::uint32_t>, 3> w = {named(a, f - i - j), named(b, i), named(c, j)};
      std::sort(w.begin(), w.end());
      Key key{};
      for (std::size_t k = 0; k < 3; ++k) {
        key[2 * k] = w[k].first;
        key[2 * k + 1] = w[k].second;
      }
      const auto [it, isNew] = index.try_emplace(key, static_cast<std::uint32_t>(s.vertices.size()));
      if (isNew)
        s.vertices.push_back(glm::normalize(static_cast<double>(f - i - j) * corners[a] +
                                            static_cast<double>(i) * corners[b] + static_cast<double>(j) * corners[c]));
      return it->second;
    };
    for (std::uint32_t i = 0; i < f; ++i)
      for (std::uint32_t j = 0; i + j < f; ++j) {
        // The triangle pointing like the face, then (except on the far edge) the one pointing back;
        // both keep the face's winding.
        s.indices.insert(s.indices.end(), {vertex(i, j), vertex(i + 1, j), vertex(i, j + 1)});
        if (i + j + 1 < f)
          s.indices.insert(s.indices.end(), {vertex(i + 1, j), vertex(i + 1, j + 1), vertex(i, j + 1)});
      }
  }
  return s;
}

}  // namespace mfr
