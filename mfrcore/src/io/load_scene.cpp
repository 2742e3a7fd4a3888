#include <algorithm>

#include "mfr/error.hpp"
#include "mfr/io/load.hpp"
#include "mfr/scene/sample.hpp"
#include "mfr/scene/scene_file.hpp"

namespace mfr {

Scene loadScene(const std::filesystem::path& path) {
  if (path == "@sample") return makeSampleScene();
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  Scene scene;
  if (ext == ".mfrscene" || ext == ".json") {
    scene = readSceneFile(path);
  } else {
    scene.name = path.filename().string();
    scene.objects = loadModel(path);
    Camera front;
    front.eye = {0.0, 0.0, 1.0};
    front.target = {0.0, 0.0, 0.0};
    scene.views.push_back({"front", scene.fit(front)});
    Camera iso = front;
    iso.eye = {1.0, 0.8, 1.0};
    scene.views.push_back({"iso", scene.fit(iso)});
  }
  scene.validate();
  return scene;
}

}  // namespace mfr
