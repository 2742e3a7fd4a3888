#include "mfr/image.hpp"

#include <png.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "mfr/error.hpp"
#include "mfr/host_memory.hpp"
#include "mfr/io_util.hpp"

namespace mfr {
namespace {

struct PngErrorState {
  std::string message;
  // Set when the image would not fit the memory available: the file is not corrupt, and the
  // refusal reads as the other memory refusals do ("corrupt PNG (…only 0 bytes is available)"
  // blamed a valid file; a bug hunt).
  std::uint64_t bytesNeeded = 0;
  std::string pixels;  // "800x800"
};

[[noreturn]] void pngError(png_structp png, png_const_charp msg) {
  auto* state = static_cast<PngErrorState*>(png_get_error_ptr(png));
  if (state) state->message = msg;
  png_longjmp(png, 1);
}
void pngWarning(png_structp, png_const_charp) {}

struct MemoryReader {
  const std::string* data;
  std::size_t offset = 0;
};

void readFromMemory(png_structp png, png_bytep out, png_size_t length) {
  auto* r = static_cast<MemoryReader*>(png_get_io_ptr(png));
  if (r->offset + length > r->data->size()) png_error(png, "file is truncated");
  std::copy_n(r->data->data() + r->offset, length, out);
  r->offset += length;
}

void writeToString(png_structp png, png_bytep data, png_size_t length) {
  static_cast<std::string*>(png_get_io_ptr(png))->append(reinterpret_cast<const char*>(data), length);
}
void flushNothing(png_structp) {}

}  // namespace

// Decodes with libpng into *image (rows points into its pixels); only trivially destructible
// locals live across setjmp. Returns false with state->message set on failure.
static bool decodePng(const std::string* bytes, ImageRGBA8* image, std::vector<png_bytep>* rows, PngErrorState* state) {
  // Before libpng's structs exist: it may throw (a malformed MFR_MEMORY_LIMIT_MIB), and nothing
  // that throws may run between their creation and their destruction.
  const std::optional<std::uint64_t> available = availableHostMemory();
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, state, pngError, pngWarning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    png_destroy_read_struct(&png, &info, nullptr);
    state->message = "out of memory";
    return false;
  }
  MemoryReader reader{bytes};
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    return false;
  }
  png_set_read_fn(png, &reader, readFromMemory);
  png_read_info(png, info);
  const png_uint_32 w = png_get_image_width(png, info), h = png_get_image_height(png, info);
  if (w == 0 || h == 0 || w > 65536 || h > 65536) png_error(png, "unsupported image size");
  // The header alone decides the allocation, so a corrupt one of a few bytes could ask for 16 GiB
  // and the decoder would fill it before finding the data short. Deflate shrinks at most about
  // 1032 : 1, so the filtered rows cannot be more than that many times the file.
  const double rowBytes =
      1.0 + std::ceil(static_cast<double>(w) * png_get_channels(png, info) * png_get_bit_depth(png, info) / 8.0);
  char reason[160];
  if (rowBytes * h > 1100.0 * static_cast<double>(bytes->size())) {
    std::snprintf(reason, sizeof reason, "its header's %ux%u pixels cannot fit in its %zu bytes", w, h, bytes->size());
    png_error(png, reason);
  }
  const std::uint64_t rgba = std::uint64_t{w} * h * 4;
  if (available && rgba > *available) {
    state->bytesNeeded = rgba;
    std::snprintf(reason, sizeof reason, "%ux%u", w, h);
    state->pixels = reason;
    png_error(png, "not enough memory");
  }
  // Normalise every colour type to 8-bit RGBA.
  png_set_expand(png);
  png_set_strip_16(png);
  png_set_gray_to_rgb(png);
  png_set_add_alpha(png, 0xFF, PNG_FILLER_AFTER);
  png_read_update_info(png, info);
  image->width = static_cast<int>(w);
  image->height = static_cast<int>(h);
  image->pixels.resize(static_cast<std::size_t>(w) * h * 4);
  rows->resize(h);
  for (png_uint_32 y = 0; y < h; ++y) (*rows)[y] = image->pixels.data() + static_cast<std::size_t>(y) * w * 4;
  png_read_image(png, rows->data());
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  return true;
}

ImageRGBA8 readPng(const std::filesystem::path& path) {
  const std::string bytes = readFile(path);
  if (bytes.size() < 8 || png_sig_cmp(reinterpret_cast<png_const_bytep>(bytes.data()), 0, 8) != 0)
    throw Error(path.string(), "not a PNG file");
  ImageRGBA8 image;
  std::vector<png_bytep> rows;
  PngErrorState state;
  if (!decodePng(&bytes, &image, &rows, &state)) {
    if (state.bytesNeeded > 0) {
      requireHostMemory(path.string(), "decoding its " + state.pixels + " pixels", state.bytesNeeded);
      throw Error(path.string(), "decoding its " + state.pixels + " pixels would take " +
                                     formatMemory(state.bytesNeeded) + ": more memory than is available");
    }
    throw Error(path.string(), "corrupt PNG (" + state.message + ")");
  }
  return image;
}

// Encodes with libpng; only trivially destructible locals live across setjmp (longjmp safety).
// Returns false with state.message set on failure.
static bool encodePng(const ImageRGBA8& image, const png_const_bytep* rows, std::string* encoded,
                      PngErrorState* state) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, state, pngError, pngWarning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    png_destroy_write_struct(&png, &info);
    state->message = "out of memory";
    return false;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_set_write_fn(png, encoded, writeToString, flushNothing);
  png_set_IHDR(png, info, static_cast<png_uint_32>(image.width), static_cast<png_uint_32>(image.height), 8,
               PNG_COLOR_TYPE_RGBA, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_compression_level(png, 6);
  png_write_info(png, info);
  png_write_rows(png, const_cast<png_bytepp>(rows), static_cast<png_uint_32>(image.height));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

std::string encodePng(const std::filesystem::path& path, const ImageRGBA8& image) {
  if (image.empty()) throw Error(path.string(), "cannot write an empty image");
  std::vector<png_const_bytep> rows(static_cast<std::size_t>(image.height));
  for (int y = 0; y < image.height; ++y) rows[static_cast<std::size_t>(y)] = image.at(0, y);
  std::string encoded;
  PngErrorState state;
  if (!encodePng(image, rows.data(), &encoded, &state))
    throw Error(path.string(), "PNG encoding failed (" + state.message + ")");
  return encoded;
}

void checkPngOutputName(const std::string& option, const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  // Suffixes of other raster and page formats an image could be asked in (.jp2, .heic, .avif and
  // others were taken and given PNG bytes; a bug hunt).
  static constexpr std::pair<const char*, const char*> kOtherFormats[] = {
      {".jpg", "JPEG"},         {".jpeg", "JPEG"},     {".jpe", "JPEG"},    {".jfif", "JPEG"},
      {".jp2", "JPEG 2000"},    {".j2k", "JPEG 2000"}, {".jxl", "JPEG XL"}, {".bmp", "BMP"},
      {".gif", "GIF"},          {".tif", "TIFF"},      {".tiff", "TIFF"},   {".webp", "WebP"},
      {".heic", "HEIF"},        {".heif", "HEIF"},     {".avif", "AVIF"},   {".ppm", "PPM"},
      {".pgm", "PGM"},          {".pbm", "PBM"},       {".pnm", "PNM"},     {".exr", "OpenEXR"},
      {".hdr", "Radiance HDR"}, {".tga", "TGA"},       {".dds", "DDS"},     {".ico", "ICO"},
      {".psd", "Photoshop"},    {".svg", "SVG"},       {".pdf", "PDF"},     {".eps", "PostScript"},
      {".ps", "PostScript"}};
  for (const auto& [suffix, format] : kOtherFormats)
    if (ext == suffix)
      throw Error(option + " " + path.string(), std::string("the name says ") + format +
                                                    ", but the image is written as PNG, the one format mfr writes: "
                                                    "name it .png");
}

void writePng(const std::filesystem::path& path, const ImageRGBA8& image) {
  writeFileAtomically(path, encodePng(path, image));
}

void flipVertically(ImageRGBA8& image) {
  const std::size_t stride = static_cast<std::size_t>(image.width) * 4;
  for (int y = 0; y < image.height / 2; ++y)
    std::swap_ranges(image.pixels.begin() + static_cast<std::ptrdiff_t>(y * stride),
                     image.pixels.begin() + static_cast<std::ptrdiff_t>((y + 1) * stride),
                     image.pixels.begin() + static_cast<std::ptrdiff_t>((image.height - 1 - y) * stride));
}

}  // namespace mfr
