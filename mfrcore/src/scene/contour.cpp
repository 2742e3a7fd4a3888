// Isosurfaces by VTK's flying edges (Schroeder, Maynard, Geveci 2015): the field's own extractor,
// not ours to write. What is ours: placing the result in the volume's object space, orienting it, and
// the checks that keep a bad request from touching the scene.
#include "mfr/scene/contour.hpp"

#include <vtkCellArray.h>
#include <vtkDataArray.h>
#include <vtkFloatArray.h>
#include <vtkFlyingEdges3D.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "mfr/error.hpp"
#include "number_text.hpp"
#include "mfr/scene/color_map.hpp"

namespace mfr {

Mesh contourVolume(const Volume& volume, double value) {
  const VolumeGrid& grid = *volume.grid;
  vtkNew<vtkImageData> image;
  image->SetDimensions(grid.dims.x, grid.dims.y, grid.dims.z);
  image->SetOrigin(volume.origin.x, volume.origin.y, volume.origin.z);
  image->SetSpacing(volume.spacing.x, volume.spacing.y, volume.spacing.z);
  vtkNew<vtkFloatArray> samples;
  samples->SetName("values");
  // VTK's point order is ours (x fastest, then y, then z). The filter only reads its input, so the
  // grid's samples are lent to it rather than copied (save = 1: VTK does not free them).
  samples->SetArray(const_cast<float*>(grid.values.data()), static_cast<vtkIdType>(grid.values.size()), 1);
  image->GetPointData()->SetScalars(samples);

  vtkNew<vtkFlyingEdges3D> contour;
  contour->SetInputData(image);
  contour->SetValue(0, value);
  contour->ComputeNormalsOn();
  contour->ComputeGradientsOff();
  contour->ComputeScalarsOff();
  contour->InterpolateAttributesOff();
  contour->Update();
  vtkPolyData* out = contour->GetOutput();

  Mesh mesh;
  vtkPoints* points = out->GetPoints();
  vtkCellArray* polys = out->GetPolys();
  if (points == nullptr || polys == nullptr || polys->GetNumberOfCells() == 0) return mesh;
  const vtkIdType pointCount = points->GetNumberOfPoints();
  mesh.positions.resize(static_cast<std::size_t>(pointCount));
  for (vtkIdType i = 0; i < pointCount; ++i) {
    double p[3];
    points->GetPoint(i, p);
    mesh.positions[static_cast<std::size_t>(i)] = glm::vec3(p[0], p[1], p[2]);
  }
  vtkNew<vtkIdList> cell;
  mesh.indices.reserve(static_cast<std::size_t>(polys->GetNumberOfCells()) * 3);
  for (polys->InitTraversal(); polys->GetNextCell(cell) != 0;) {
    if (cell->GetNumberOfIds() != 3) continue;  // flying edges makes triangles only
    for (int c = 0; c < 3; ++c) mesh.indices.push_back(static_cast<std::uint32_t>(cell->GetId(c)));
  }

  // The gradient normals where they are usable; the surface's own smooth normals where the gradient
  // vanishes (a flat run of samples equal to the value) or the filter gave none — computed only then.
  mesh.normals.assign(mesh.positions.size(), glm::vec3(0.0f));
  std::vector<std::size_t> missing;
  vtkDataArray* normals = out->GetPointData()->GetNormals();
  const bool given =
      normals != nullptr && normals->GetNumberOfTuples() == pointCount && normals->GetNumberOfComponents() == 3;
  for (vtkIdType i = 0; i < pointCount; ++i) {
    double n[3] = {0.0, 0.0, 0.0};
    if (given) normals->GetTuple(i, n);
    const glm::dvec3 g(n[0], n[1], n[2]);
    const double length = glm::length(g);
    if (std::isfinite(length) && length > 1e-6)
      mesh.normals[static_cast<std::size_t>(i)] = glm::vec3(g / length);
    else
      missing.push_back(static_cast<std::size_t>(i));
  }
  if (!missing.empty()) {
    Mesh smooth = mesh;
    smooth.computeSmoothNormals();
    for (const std::size_t i : missing) mesh.normals[i] = smooth.normals[i];
  }

  // Orientation: VTK's normals point down the gradient (towards lower values); make the normals
  // point there whichever way a VTK version signs them (checked against the samples' own difference
  // across the surface), then wind the triangles to face the side the normals point to.
  const glm::dmat4 gridFromObject =
      glm::inverse(glm::dmat4(glm::dvec4(volume.spacing.x, 0, 0, 0), glm::dvec4(0, volume.spacing.y, 0, 0),
                              glm::dvec4(0, 0, volume.spacing.z, 0), glm::dvec4(volume.origin, 1.0)));
  double agree = 0.0;
  const double probe = 0.5 * std::min({volume.spacing.x, volume.spacing.y, volume.spacing.z});
  const std::size_t stride = std::max<std::size_t>(1, mesh.positions.size() / 4096);
  for (std::size_t i = 0; i < mesh.positions.size(); i += stride) {
    const glm::dvec3 p(mesh.positions[i]), n(mesh.normals[i]);
    const auto at = [&](const glm::dvec3& q) { return grid.sample(glm::vec3(gridFromObject * glm::dvec4(q, 1.0))); };
    agree += static_cast<double>(at(p - probe * n)) - static_cast<double>(at(p + probe * n));  // > 0: n points down
  }
  if (agree < 0.0)
    for (glm::vec3& n : mesh.normals) n = -n;
  // Flying edges winds its triangles consistently (every shared edge run both ways): turn them all
  // or none, by the majority of their agreement with the normals — per triangle, noisy samples would
  // turn single triangles against their neighbours.
  double facing = 0.0;
  for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const glm::vec3 a = mesh.positions[mesh.indices[t]], b = mesh.positions[mesh.indices[t + 1]],
                    c = mesh.positions[mesh.indices[t + 2]];
    const glm::vec3 vertexNormals =
        mesh.normals[mesh.indices[t]] + mesh.normals[mesh.indices[t + 1]] + mesh.normals[mesh.indices[t + 2]];
    facing += glm::dot(glm::cross(b - a, c - a), vertexNormals) > 0.0f ? 1.0 : -1.0;
  }
  if (facing < 0.0)
    for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) std::swap(mesh.indices[t + 1], mesh.indices[t + 2]);
  return mesh;
}

std::string contourPartName(const std::string& volumeName, double value) {
  return volumeName + " = " + shortNumberText(value);
}

glm::dvec2 contourColorRange(const std::vector<double>& values, const glm::dvec2& gridRange) {
  // Several isosurfaces span the map between the lowest and the highest value, so that they differ
  // most; one gets the map's colour at its value over the grid's range.
  if (values.size() > 1) {
    const auto [low, high] = std::minmax_element(values.begin(), values.end());
    if (*high > *low) return {*low, *high};
  }
  return gridRange;
}

std::vector<std::size_t> addContours(Scene& scene, const ContourRequest& request, const std::string& what) {
  if (request.volume >= scene.volumes.size())
    throw Error(what, scene.volumes.empty() ? "scene '" + scene.name + "' has no volume"
                                            : "no volume " + std::to_string(request.volume) + " (the scene has " +
                                                  std::to_string(scene.volumes.size()) + ")");
  if (request.values.empty()) throw Error(what, "no value given");
  if (request.values.size() > kMaxContourValues)
    throw Error(what, std::to_string(request.values.size()) + " values: at most " + std::to_string(kMaxContourValues) +
                          " isosurfaces at once");
  if (!(request.opacity >= 0.0f && request.opacity <= 1.0f)) throw Error(what, "opacity must lie in [0, 1]");
  const Volume& volume = scene.volumes[request.volume];
  const glm::vec2 range = volume.grid->range();
  const std::string rangeText = "[" + shortNumberText(range.x) + ", " + shortNumberText(range.y) + "]";
  for (const double value : request.values) {
    if (!std::isfinite(value)) throw Error(what, "the value must be a finite number");
    if (!(value > static_cast<double>(range.x) && value < static_cast<double>(range.y)))
      throw Error(what, shortNumberText(value) + " lies outside the open range " + rangeText + " of volume '" +
                            volume.name + "': no surface");
  }
  // Two values of one name (the same value twice, or closer than the name's 6 digits) would be
  // coincident surfaces, fighting in depth, that no one can tell apart by their names.
  for (std::size_t i = 0; i < request.values.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (shortNumberText(request.values[i]) == shortNumberText(request.values[j]))
        throw Error(what, request.values[i] == request.values[j]
                              ? shortNumberText(request.values[i]) + " is given twice"
                              : "values " + numberText(request.values[j]) + " and " + numberText(request.values[i]) +
                                    " are one isosurface to 6 digits: give values that differ there");
  // Nor may a value repeat an isosurface the scene has (a scene file's "contours"): two parts of one
  // name, coincident (hunt 32).
  for (const double value : request.values)
    for (const Object& o : scene.objects)
      if (o.name == contourPartName(volume.name, value))
        throw Error(what, "scene '" + scene.name + "' has isosurface '" + o.name + "' already");
  const glm::vec2 colourRange(contourColorRange(request.values, glm::dvec2(range)));
  // Every surface is made before the scene is touched, so that a failure leaves it as it was.
  std::vector<Object> parts;
  for (const double value : request.values) {
    Mesh mesh = contourVolume(volume, value);
    if (mesh.triangleCount() == 0)
      throw Error(what, "volume '" + volume.name + "' has no surface at " + shortNumberText(value));
    mesh.validate(contourPartName(volume.name, value));
    Object part;
    part.name = contourPartName(volume.name, value);
    part.mesh = std::make_shared<const Mesh>(std::move(mesh));
    part.transform = volume.transform;
    const glm::vec3 rgb = mapFieldValue(colorMap("cool-warm"), static_cast<float>(value), colourRange);
    part.material.color = glm::vec4(rgb, request.opacity);
    parts.push_back(std::move(part));
  }
  std::vector<std::size_t> indices;
  for (Object& part : parts) {
    indices.push_back(scene.objects.size());
    scene.objects.push_back(std::move(part));
  }
  addVolumeFields(scene);  // the new parts too can be coloured by any volume of the scene ("@NAME")
  return indices;
}

}  // namespace mfr
