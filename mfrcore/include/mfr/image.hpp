#pragma once
// Images as the product stores and exchanges them: 8-bit RGBA (sRGB-encoded display values) and
// float images for metrics. Row 0 is the top row (as in PNG); GL read-back flips once on arrival.
#include <cstdint>
#include <filesystem>
#include <vector>

namespace mfr {

struct ImageRGBA8 {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> pixels;  // width*height*4, row-major, top row first

  ImageRGBA8() = default;
  ImageRGBA8(int w, int h) : width(w), height(h), pixels(static_cast<std::size_t>(w) * h * 4, 0) {}
  [[nodiscard]] std::uint8_t* at(int x, int y) { return &pixels[(static_cast<std::size_t>(y) * width + x) * 4]; }
  [[nodiscard]] const std::uint8_t* at(int x, int y) const {
    return &pixels[(static_cast<std::size_t>(y) * width + x) * 4];
  }
  [[nodiscard]] bool empty() const { return width == 0 || height == 0; }
};

// Single- or multi-channel float image (linear or not: the user of the type says which).
struct ImageF {
  int width = 0;
  int height = 0;
  int channels = 1;
  std::vector<float> data;

  ImageF() = default;
  ImageF(int w, int h, int c, float fill = 0.0f)
      : width(w), height(h), channels(c), data(static_cast<std::size_t>(w) * h * c, fill) {}
  [[nodiscard]] float& at(int x, int y, int c = 0) {
    return data[(static_cast<std::size_t>(y) * width + x) * channels + c];
  }
  [[nodiscard]] float at(int x, int y, int c = 0) const {
    return data[(static_cast<std::size_t>(y) * width + x) * channels + c];
  }
};

// PNG through libpng. readPng accepts 8/16-bit gray, gray+alpha, RGB, RGBA and palette files
// (converted to RGBA8). writePng writes to a temporary file and renames it, so a failure never
// leaves a half-written output. Both throw mfr::Error naming the file.
ImageRGBA8 readPng(const std::filesystem::path& path);
void writePng(const std::filesystem::path& path, const ImageRGBA8& image);
// The PNG file's bytes, for writeFilesAtomically (errors name `path`).
std::string encodePng(const std::filesystem::path& path, const ImageRGBA8& image);
// Refuses an output name whose extension names another image format (x.jpg, x.TIFF, x.exr …):
// mfr writes PNG only, and a PNG behind a .jpg name misleads every program that trusts the name.
// Other names (x.png, x, x.out) are taken. Throws mfr::Error naming `option` and the path.
void checkPngOutputName(const std::string& option, const std::filesystem::path& path);

// Flip rows in place (GL's bottom-up read-back to our top-down order).
void flipVertically(ImageRGBA8& image);

}  // namespace mfr
