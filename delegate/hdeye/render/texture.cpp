#include "hdeye/render/texture.h"

#include "hdeye/image/imageWriter.h"

#include <png.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace hdeye {
namespace {

[[noreturn]] void Fail(const std::string& path, const std::string& reason) {
  throw std::runtime_error("cannot read texture " + path + ": " + reason);
}

/// sRGB-encoded value in [0,1] to linear (IEC 61966-2-1, the inverse of LinearToSrgb).
double SrgbToLinear(double v) {
  return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}

bool EndsWithNoCase(const std::string& s, const std::string& suffix) {
  if (s.size() < suffix.size()) return false;
  return std::equal(suffix.rbegin(), suffix.rend(), s.rbegin(),
                    [](char a, char b) { return std::tolower(a) == std::tolower(b); });
}

/// libpng state for one read. libpng reports errors by longjmp; everything that must survive the jump
/// lives in this struct, reached through a pointer that is not modified after setjmp, so no local of
/// the jumping frame has an indeterminate value afterwards.
struct PngRead {
  std::FILE* file = nullptr;
  png_structp png = nullptr;
  png_infop info = nullptr;
  char message[256] = {0};
  png_uint_32 width = 0, height = 0;
  int bitDepth = 0;                 // after transforms: 8 or 16
  std::vector<png_byte> bytes;      // RGB, bitDepth per channel, big-endian for 16 bits
  std::vector<png_bytep> rows;
  ~PngRead() {
    if (png) png_destroy_read_struct(&png, info ? &info : nullptr, nullptr);
    if (file) std::fclose(file);
  }
};

void PngError(png_structp png, png_const_charp message) {
  auto* read = static_cast<PngRead*>(png_get_error_ptr(png));
  std::snprintf(read->message, sizeof read->message, "%s", message ? message : "libpng error");
  png_longjmp(png, 1);
}
void PngWarning(png_structp, png_const_charp) {}  // e.g. "known incorrect sRGB profile": not fatal

/// Decodes the PNG into `read->bytes` as RGB at 8 or 16 bits per channel. Returns false (with
/// read->message set) on a libpng error. Palette, gray and low bit depths are expanded, alpha is
/// dropped (UsdUVTexture's rgb output ignores alpha; nothing is premultiplied).
bool DecodePng(PngRead* read) {
  if (setjmp(png_jmpbuf(read->png))) return false;
  png_init_io(read->png, read->file);
  png_read_info(read->png, read->info);
  const int colorType = png_get_color_type(read->png, read->info);
  png_set_expand(read->png);  // palette -> RGB, gray < 8 bits -> 8 bits, tRNS -> alpha
  if (colorType == PNG_COLOR_TYPE_GRAY || colorType == PNG_COLOR_TYPE_GRAY_ALPHA)
    png_set_gray_to_rgb(read->png);
  png_set_strip_alpha(read->png);
  png_set_interlace_handling(read->png);
  png_read_update_info(read->png, read->info);
  read->width = png_get_image_width(read->png, read->info);
  read->height = png_get_image_height(read->png, read->info);
  read->bitDepth = png_get_bit_depth(read->png, read->info);
  const std::size_t rowBytes = png_get_rowbytes(read->png, read->info);
  if (png_get_channels(read->png, read->info) != 3 || (read->bitDepth != 8 && read->bitDepth != 16) ||
      rowBytes != std::size_t(read->width) * 3 * std::size_t(read->bitDepth / 8)) {
    std::snprintf(read->message, sizeof read->message, "unexpected layout after expansion");
    return false;
  }
  read->bytes.resize(rowBytes * read->height);
  read->rows.resize(read->height);
  for (png_uint_32 y = 0; y < read->height; ++y) read->rows[y] = read->bytes.data() + y * rowBytes;
  png_read_image(read->png, read->rows.data());
  png_read_end(read->png, nullptr);
  return true;
}

std::shared_ptr<const Texture> LoadPng(const std::string& path) {
  PngRead read;
  read.file = std::fopen(path.c_str(), "rb");
  if (!read.file) Fail(path, std::strerror(errno));
  png_byte signature[8] = {0};
  if (std::fread(signature, 1, 8, read.file) != 8 || png_sig_cmp(signature, 0, 8) != 0)
    Fail(path, "not a PNG file");
  read.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &read, PngError, PngWarning);
  if (read.png) read.info = png_create_info_struct(read.png);
  if (!read.png || !read.info) Fail(path, "libpng cannot allocate its state");
  png_set_sig_bytes(read.png, 8);
  if (!DecodePng(&read)) Fail(path, read.message);

  // sRGB -> linear through a table for 8 bits; per value for 16 bits.
  std::array<float, 256> table8{};
  for (int i = 0; i < 256; ++i) table8[std::size_t(i)] = float(SrgbToLinear(i / 255.0));
  const std::size_t count = std::size_t(read.width) * read.height;
  std::vector<glm::vec3> texels(count);
  for (std::size_t i = 0; i < count; ++i)
    for (int c = 0; c < 3; ++c) {
      if (read.bitDepth == 8) {
        texels[i][c] = table8[read.bytes[3 * i + std::size_t(c)]];
      } else {
        const std::size_t b = 6 * i + 2 * std::size_t(c);
        const int v = (int(read.bytes[b]) << 8) | int(read.bytes[b + 1]);
        texels[i][c] = float(SrgbToLinear(v / 65535.0));
      }
    }
  return std::make_shared<const Texture>(int(read.width), int(read.height), std::move(texels));
}

std::shared_ptr<const Texture> LoadExr(const std::string& path) {
  int width = 0, height = 0;
  const std::vector<ImagePlane> planes = ReadExr(path, &width, &height);  // throws naming the path
  auto find = [&](const char* name) -> const ImagePlane* {
    for (const ImagePlane& p : planes)
      if (p.name == name) return &p;
    return nullptr;
  };
  std::array<const ImagePlane*, 3> rgb{find("R"), find("G"), find("B")};
  if (!rgb[0] || !rgb[1] || !rgb[2]) {
    // A luminance-only image (Y), or a file with a single channel of any name: gray.
    const ImagePlane* gray = find("Y");
    if (!gray && planes.size() == 1) gray = &planes[0];
    if (!gray) Fail(path, "no R, G, B channels and no single gray channel");
    rgb = {gray, gray, gray};
  }
  std::vector<glm::vec3> texels(std::size_t(width) * std::size_t(height));
  for (std::size_t i = 0; i < texels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const float v = rgb[std::size_t(c)]->pixels[i];
      if (!std::isfinite(v)) Fail(path, "non-finite texel value");
      texels[i][c] = v;
    }
  return std::make_shared<const Texture>(width, height, std::move(texels));
}

}  // namespace

std::shared_ptr<const Texture> Texture::Load(const std::string& path) {
  if (EndsWithNoCase(path, ".exr")) return LoadExr(path);
  if (EndsWithNoCase(path, ".png")) return LoadPng(path);
  Fail(path, "unsupported file type (expected .png or .exr)");
}

Texture::Texture(int width, int height, std::vector<glm::vec3> texels)
    : width_(width), height_(height), texels_(std::move(texels)) {
  if (width_ <= 0 || height_ <= 0 || texels_.size() != std::size_t(width_) * std::size_t(height_))
    throw std::runtime_error("texture of " + std::to_string(width_) + "x" + std::to_string(height_) +
                             " has " + std::to_string(texels_.size()) + " texels");
}

glm::vec3 Texture::Lookup(glm::vec2 uv) const {
  if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) return Texel(0, 0);
  // Texel centres sit at (x + 0.5) / width; v = 0 is the bottom edge, and row 0 is the top row.
  const double fx = double(uv.x) * width_ - 0.5;
  const double fy = (1.0 - double(uv.y)) * height_ - 0.5;
  const double x0f = std::floor(fx), y0f = std::floor(fy);
  const float tx = float(fx - x0f), ty = float(fy - y0f);
  auto wrap = [](double i, int n) {
    const double m = std::fmod(i, double(n));
    return int(m < 0 ? m + n : m);
  };
  const int x0 = wrap(x0f, width_), x1 = wrap(x0f + 1, width_);
  const int y0 = wrap(y0f, height_), y1 = wrap(y0f + 1, height_);
  const glm::vec3 top = glm::mix(Texel(x0, y0), Texel(x1, y0), tx);
  const glm::vec3 bottom = glm::mix(Texel(x0, y1), Texel(x1, y1), tx);
  return glm::mix(top, bottom, ty);
}

std::shared_ptr<const Texture> TextureCache::Get(const std::string& path) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = textures_.find(path);
  if (it != textures_.end()) return it->second;
  std::shared_ptr<const Texture> texture = Texture::Load(path);  // throws: nothing is cached
  textures_.emplace(path, texture);
  return texture;
}

}  // namespace hdeye
