// Textures through OpenImageIO: formats and bit depths (JPEG, grayscale and CMYK JPEG, 16-bit PNG, EXR), UDIM,
// UsdUVTexture's wrap modes, scale, bias, fallback and colour spaces, unreadable files, footprint filtering
// (the ray cone), and the material inputs they drive in renders (emission, normal maps, cut-outs). Every image
// is written here, by OpenImageIO (libjpeg for the CMYK JPEG, which OIIO 2.4 cannot write).
#include "hdeye/hd/renderIndex.h"
#include "hdeye/image/imageWriter.h"
#include "hdeye/pass/renderPass.h"
#include "hdeye/prims/renderBuffer.h"
#include "hdeye/prims/renderDelegate.h"
#include "hdeye/render/materialShading.h"
#include "hdeye/render/rayCone.h"
#include "hdeye/render/renderLight.h"
#include "hdeye/render/texture.h"
#include "hdeye/scene/inMemorySceneDelegate.h"
#include "hdeye/scene/sampleScenes.h"
#include "scene_helpers.h"
#include "test_support.h"

#include <OpenImageIO/imageio.h>
#include <jpeglib.h>
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>

using namespace hdeye;

namespace {

using test::ErrorOf;
using test::ScratchDir;

constexpr double kPi = 3.14159265358979323846;

/// The sRGB decoding curve (IEC 61966-2-1), written out independently of the code under test.
double SrgbDecode(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }

/// Writes float pixels (row 0 at the top) quantised to `type`, in the format the extension names.
void WriteImage(const std::string& path, int w, int h, int channels, const std::vector<float>& pixels,
                OIIO::TypeDesc type = OIIO::TypeDesc::UINT8, const std::string& wrapmodes = "") {
  REQUIRE(pixels.size() == std::size_t(w) * h * channels);
  auto out = OIIO::ImageOutput::create(path);
  REQUIRE(out);
  OIIO::ImageSpec spec(w, h, channels, type);
  if (!wrapmodes.empty()) spec.attribute("wrapmodes", wrapmodes);
  REQUIRE(out->open(path, spec));
  REQUIRE(out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()));
  REQUIRE(out->close());
}

/// w x h pixels of `channels`, left half `left`, right half `right` (first channel only; others copy it).
std::vector<float> Halves(int w, int h, int channels, float left, float right) {
  std::vector<float> p(std::size_t(w) * h * channels);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < channels; ++c) p[(std::size_t(y) * w + x) * channels + c] = x < w / 2 ? left : right;
  return p;
}

/// A CMYK JPEG through libjpeg (Adobe convention: 0 is full ink), every pixel the given ink bytes.
void WriteCmykJpeg(const std::string& path, int w, int h, const unsigned char ink[4]) {
  std::FILE* file = std::fopen(path.c_str(), "wb");
  REQUIRE(file);
  jpeg_compress_struct c;
  jpeg_error_mgr err;
  c.err = jpeg_std_error(&err);
  jpeg_create_compress(&c);
  jpeg_stdio_dest(&c, file);
  c.image_width = JDIMENSION(w), c.image_height = JDIMENSION(h);
  c.input_components = 4;
  c.in_color_space = JCS_CMYK;
  jpeg_set_defaults(&c);
  jpeg_set_quality(&c, 95, TRUE);
  c.write_Adobe_marker = TRUE;
  jpeg_start_compress(&c, TRUE);
  std::vector<unsigned char> row(std::size_t(w) * 4);
  for (int x = 0; x < w; ++x) std::copy(ink, ink + 4, &row[std::size_t(x) * 4]);
  while (c.next_scanline < c.image_height) {
    JSAMPROW rows[1] = {row.data()};
    jpeg_write_scanlines(&c, rows, 1);
  }
  jpeg_finish_compress(&c);
  jpeg_destroy_compress(&c);
  std::fclose(file);
}

/// An n x n 8-bit gray checker of one-texel cells, 0 and 1.
void WriteOneTexelChecker(const std::string& path, int n) {
  std::vector<float> p(std::size_t(n) * n);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) p[std::size_t(y) * n + x] = float((x + y) % 2);
  WriteImage(path, n, n, 1, p);
}

TextureParams Params(const std::string& file, TextureColorSpace space = TextureColorSpace::Auto) {
  TextureParams p;
  p.file = file;
  p.colorSpace = space;
  p.wrapS = p.wrapT = TextureWrap::Repeat;
  return p;
}

glm::vec4 At(const Texture& t, float s, float u) { return t.Lookup({s, u}, TextureFootprint{}, nullptr); }

}  // namespace

// ---------------------------------------------------------------------------------------------
// Formats and colour spaces

TEST_CASE("a JPEG texture decodes from sRGB under auto, with t = 0 at the bottom row", "[texture]") {
  ScratchDir dir;
  const int n = 32;
  std::vector<float> p(n * n * 3);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const glm::vec3 c = y < n / 2 ? glm::vec3(0.8f, 0.2f, 0.2f) : glm::vec3(0.2f, 0.2f, 0.8f);  // top red
      for (int k = 0; k < 3; ++k) p[(y * n + x) * 3 + k] = c[k];
    }
  WriteImage(dir / "a.jpg", n, n, 3, p);
  const auto t = Texture::Open(Params(dir / "a.jpg"));
  REQUIRE(t->Valid());
  CHECK(t->Srgb());
  const glm::vec4 top = At(*t, 0.5f, 0.75f), bottom = At(*t, 0.5f, 0.25f);
  INFO("top " << top.r << " " << top.g << " " << top.b << ", bottom " << bottom.r << " " << bottom.g << " "
              << bottom.b);
  CHECK(top.r == Approx(SrgbDecode(0.8)).margin(0.02));
  CHECK(top.b == Approx(SrgbDecode(0.2)).margin(0.02));
  CHECK(bottom.b == Approx(SrgbDecode(0.8)).margin(0.02));
  CHECK(top.a == 1);
}

TEST_CASE("a 16-bit PNG keeps its precision: raw under auto, decoded under sRGB", "[texture]") {
  ScratchDir dir;
  const float v = 32769.0f / 65535.0f;  // not representable in 8 bits
  WriteImage(dir / "a.png", 4, 4, 3, std::vector<float>(48, v), OIIO::TypeDesc::UINT16);
  const auto raw = Texture::Open(Params(dir / "a.png"));
  REQUIRE(raw->Valid());
  CHECK_FALSE(raw->Srgb());
  CHECK(At(*raw, 0.3f, 0.6f).g == Approx(v).margin(2e-6));
  const auto srgb = Texture::Open(Params(dir / "a.png", TextureColorSpace::Srgb));
  CHECK(At(*srgb, 0.3f, 0.6f).g == Approx(SrgbDecode(v)).margin(2e-6));
}

TEST_CASE("8-bit colour is sRGB under auto, 8-bit gray raw, and raw and sRGB force either", "[texture]") {
  ScratchDir dir;
  const float code = 128.0f / 255.0f;
  WriteImage(dir / "rgb.png", 4, 4, 3, std::vector<float>(48, code));
  WriteImage(dir / "gray.jpg", 8, 8, 1, std::vector<float>(64, code));
  const auto rgb = Texture::Open(Params(dir / "rgb.png"));
  CHECK(At(*rgb, 0.5f, 0.5f).r == Approx(SrgbDecode(code)).margin(1e-6));
  CHECK(At(*Texture::Open(Params(dir / "rgb.png", TextureColorSpace::Raw)), 0.5f, 0.5f).r == Approx(code).margin(1e-6));
  const auto gray = Texture::Open(Params(dir / "gray.jpg"));
  REQUIRE(gray->Valid());
  CHECK(gray->Channels() == 1);
  const glm::vec4 g = At(*gray, 0.5f, 0.5f);
  CHECK(g.r == Approx(code).margin(2.0 / 255));  // JPEG's quantisation
  CHECK(g.r == g.g);
  CHECK(g.g == g.b);
  CHECK(g.a == 1);
  CHECK(At(*Texture::Open(Params(dir / "gray.jpg", TextureColorSpace::Srgb)), 0.5f, 0.5f).r ==
        Approx(SrgbDecode(g.r)).margin(1e-5));
}

TEST_CASE("a CMYK JPEG reads as RGB: no ink is white, full black ink is black", "[texture]") {
  ScratchDir dir;
  const unsigned char none[4] = {255, 255, 255, 255}, black[4] = {255, 255, 255, 0};  // Adobe: inverted ink
  WriteCmykJpeg(dir / "white.jpg", 16, 16, none);
  WriteCmykJpeg(dir / "black.jpg", 16, 16, black);
  const auto white = Texture::Open(Params(dir / "white.jpg", TextureColorSpace::Raw));
  const auto dark = Texture::Open(Params(dir / "black.jpg", TextureColorSpace::Raw));
  REQUIRE(white->Valid());
  REQUIRE(dark->Valid());
  CHECK(white->Channels() == 3);
  const glm::vec4 w = At(*white, 0.5f, 0.5f), k = At(*dark, 0.5f, 0.5f);
  INFO("no ink " << w.r << " " << w.g << " " << w.b << ", black ink " << k.r << " " << k.g << " " << k.b);
  CHECK(w.r == Approx(1).margin(0.02));
  CHECK(w.b == Approx(1).margin(0.02));
  CHECK(k.g == Approx(0).margin(0.02));
}

TEST_CASE("an EXR texture is read as linear floats, HDR values kept", "[texture]") {
  ScratchDir dir;
  WriteExr(
      dir / "t.exr", 4, 4,
      {{"R", std::vector<float>(16, 2.5f)}, {"G", std::vector<float>(16, 0.25f)}, {"B", std::vector<float>(16, 7)}});
  const glm::vec4 c = At(*Texture::Open(Params(dir / "t.exr")), 0.4f, 0.7f);
  CHECK(c.r == Approx(2.5f));
  CHECK(c.g == Approx(0.25f));
  CHECK(c.b == Approx(7));
}

// ---------------------------------------------------------------------------------------------
// UsdUVTexture's parameters

TEST_CASE(
    "UDIM tiles are picked by 1001 + floor(s) + 10 floor(t), t running up each tile, and a missing tile "
    "gives the fallback",
    "[texture]") {
  ScratchDir dir;
  const glm::vec3 colours[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const int tiles[3] = {1001, 1002, 1011};
  for (int i = 0; i < 3; ++i) {
    std::vector<float> p;
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 8; ++x)  // the tile's top half brighter, so t's direction shows
        for (int c = 0; c < 3; ++c) p.push_back(colours[i][c] * (y < 4 ? 1.0f : 0.5f));
    WriteImage(dir / ("tex." + std::to_string(tiles[i]) + ".exr"), 8, 8, 3, p, OIIO::TypeDesc::FLOAT);
  }
  TextureParams params = Params(dir / "tex.<UDIM>.exr");
  params.fallback = {0.1f, 0.2f, 0.3f, 1};
  const auto t = Texture::Open(params);
  REQUIRE(t->Valid());
  CHECK(At(*t, 0.5f, 0.75f).r == Approx(1));    // 1001, upper half
  CHECK(At(*t, 0.5f, 0.25f).r == Approx(0.5));  // 1001, lower half
  CHECK(At(*t, 1.5f, 0.75f).g == Approx(1));    // 1002
  CHECK(At(*t, 0.5f, 1.75f).b == Approx(1));    // 1011, upper half
  CHECK(At(*t, 0.5f, 1.25f).b == Approx(0.5));
  CHECK(At(*t, 2.5f, 0.5f) == params.fallback);  // 1003 is not in the set
  const auto none = Texture::Open(Params(dir / "none.<UDIM>.exr"));
  CHECK_FALSE(none->Valid());
  CHECK_THAT(none->Error(), Catch::Contains("none.<UDIM>.exr") && Catch::Contains("UDIM"));
}

TEST_CASE(
    "wrap modes repeat, mirror, clamp and black follow UsdUVTexture outside [0, 1], and useMetadata takes the "
    "file's wrapmodes, else black",
    "[texture]") {
  ScratchDir dir;
  WriteImage(dir / "h.exr", 8, 8, 1, Halves(8, 8, 1, 0.25f, 0.75f), OIIO::TypeDesc::FLOAT);
  WriteImage(dir / "periodic.exr", 8, 8, 1, Halves(8, 8, 1, 0.25f, 0.75f), OIIO::TypeDesc::FLOAT, "periodic,periodic");
  auto with = [&](const std::string& file, TextureWrap wrap) {
    TextureParams p = Params(dir / file);
    p.wrapS = p.wrapT = wrap;
    return Texture::Open(p);
  };
  const float s = 1.25f, t = 0.5f;  // a quarter into the next period, in the left half
  CHECK(At(*with("h.exr", TextureWrap::Repeat), s, t).r == Approx(0.25f));
  CHECK(At(*with("h.exr", TextureWrap::Mirror), s, t).r == Approx(0.75f));  // mirrored: s = 0.75
  CHECK(At(*with("h.exr", TextureWrap::Clamp), s, t).r == Approx(0.75f));   // the rightmost texels
  CHECK(At(*with("h.exr", TextureWrap::Black), s, t).r == 0);
  CHECK(At(*with("h.exr", TextureWrap::Black), 0.25f, -0.5f).r == 0);  // t outside too
  CHECK(At(*with("h.exr", TextureWrap::UseMetadata), s, t).r == 0);    // no metadata: black
  CHECK(At(*with("periodic.exr", TextureWrap::UseMetadata), s, t).r == Approx(0.25f));
}

TEST_CASE("scale and bias apply after decoding, and the fallback comes back as authored", "[texture]") {
  ScratchDir dir;
  const float code = 200.0f / 255.0f;
  WriteImage(dir / "a.png", 4, 4, 3, std::vector<float>(48, code));
  TextureParams p = Params(dir / "a.png");
  p.scale = {2, 2, 2, 1};
  p.bias = {-1, -1, -1, 0};
  const glm::vec4 v = At(*Texture::Open(p), 0.5f, 0.5f);
  CHECK(v.r == Approx(2 * SrgbDecode(code) - 1).margin(1e-6));
  CHECK(v.a == 1);
  p.file = dir / "missing.png";
  p.fallback = {0.25f, 0.5f, 0.75f, 1};
  CHECK(At(*Texture::Open(p), 0.5f, 0.5f) == p.fallback);
}

TEST_CASE(
    "a texture that cannot be read is invalid, says why in one line naming the file, and looks up its "
    "fallback (magenta unless set)",
    "[texture]") {
  ScratchDir dir;
  { std::ofstream(dir / "junk.png") << "not a png"; }
  { std::ofstream(dir / "text.tif") << "not a tiff either"; }
  // A truncated PNG: its header reads, its pixels do not.
  std::vector<float> noise(256 * 256 * 3);
  for (std::size_t i = 0; i < noise.size(); ++i) noise[i] = float((i * 7919) % 251) / 250.0f;
  WriteImage(dir / "good.png", 256, 256, 3, noise);
  // A truncated JPEG: libjpeg decodes it without failing (grey where the bytes ran out), only warning.
  WriteImage(dir / "good.jpg", 256, 256, 3, noise);
  for (const std::string ext : {"png", "jpg"}) {
    std::ifstream in(dir / ("good." + ext), std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream(dir / ("cut." + ext), std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  }
  for (const std::string name : {"missing.png", "junk.png", "text.tif", "cut.png", "cut.jpg"}) {
    INFO(name);
    const auto t = Texture::Open(Params(dir / name));
    CHECK_FALSE(t->Valid());
    CHECK_THAT(t->Error(), Catch::Contains(dir / name));
    CHECK(t->Error().find('\n') == std::string::npos);
    CHECK(At(*t, 0.5f, 0.5f) == glm::vec4(1, 0, 1, 1));
    CHECK(TextureProblem(dir / name) == t->Error());
    CHECK_THAT(ErrorOf([&] { Texture::Load(dir / name); }), Catch::Contains(dir / name));
  }
  CHECK_THAT(TextureProblem(dir / "missing.png"), Catch::Contains("file not found"));
  CHECK_THAT(TextureProblem(dir / "cut.png"), Catch::Contains("decoded"));
  CHECK_THAT(TextureProblem(dir / "cut.jpg"), Catch::Contains("Premature end of JPEG file"));
  CHECK(TextureProblem(dir / "good.png").empty());
  CHECK(TextureProblem(dir / "good.jpg").empty());

  TextureCache cache;
  const auto a = cache.Get(dir / "good.png");
  CHECK(a == cache.Get(dir / "good.png"));
  CHECK(a != cache.Get(Params(dir / "good.png", TextureColorSpace::Raw)));  // other parameters: another texture
}

// ---------------------------------------------------------------------------------------------
// Footprints

TEST_CASE("a lookup over a wide footprint averages a one-texel checker to its mean, and a point lookup does not",
          "[texture]") {
  ScratchDir dir;
  const int n = 256;
  WriteOneTexelChecker(dir / "checker.png", n);
  const auto t = Texture::Open(Params(dir / "checker.png"));
  TextureFootprint wide;
  wide.dstDx = {0.1f, 0}, wide.dstDy = {0, 0.1f};
  for (float s : {0.2f, 0.5f, 0.77f}) {
    const float filtered = t->Lookup({s, 0.4f}, wide, CurrentTextureThread()).r;
    const float point = At(*t, (std::floor(s * n) + 0.5f) / n, (std::floor(0.4f * n) + 0.5f) / n).r;
    INFO("s " << s << ": filtered " << filtered << ", point " << point);
    CHECK(filtered == Approx(0.5).margin(0.02));
    CHECK((point < 0.05f || point > 0.95f));
  }
  // Anisotropic: a footprint long in s and short in t still averages.
  TextureFootprint thin;
  thin.dstDx = {0.2f, 0}, thin.dstDy = {0, 0.01f};
  CHECK(t->Lookup({0.5f, 0.5f}, thin, nullptr).r == Approx(0.5).margin(0.05));
}

TEST_CASE("the ray cone's footprint is its width over the st scale, stretched by 1/cos along the ray", "[texture]") {
  // A plane z = 0 with st = (x, y) / 10: dp/ds = (10, 0, 0), dp/dt = (0, 10, 0).
  const StFrame frame = TriangleStFrame({0, 0, 0}, {10, 0, 0}, {0, 10, 0}, {0, 0}, {1, 0}, {0, 1});
  REQUIRE(frame.valid);
  CHECK(frame.dpds.x == Approx(10));
  CHECK(frame.dpdt.y == Approx(10));
  const TextureFootprint head = FootprintOnSurface(0.5, {0, 0, -1}, {0, 0, 1}, frame);
  CHECK(glm::length(head.dstDx) == Approx(0.05));
  CHECK(glm::length(head.dstDy) == Approx(0.05));
  // 60 degrees off the normal in the xz plane: across the ray (y) unchanged, along it (x) doubled.
  const glm::dvec3 d = glm::normalize(glm::dvec3(std::sin(kPi / 3), 0, -std::cos(kPi / 3)));
  const TextureFootprint slant = FootprintOnSurface(0.5, d, {0, 0, 1}, frame);
  CHECK(std::abs(slant.dstDx.y) == Approx(0.05));
  CHECK(std::abs(slant.dstDy.x) == Approx(0.1));
  CHECK_FALSE(TriangleStFrame({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0}, {0, 0}, {0, 0}).valid);  // collapsed st
  const RayCone cone{0.01, 0.002};
  CHECK(cone.WidthAt(10) == Approx(0.03));
  CHECK(cone.AfterBounce(10, true).spread == Approx(0.002));
  CHECK(cone.AfterBounce(10, false).spread == Approx(0.002 + kRoughSpreadWidening));
}

// ---------------------------------------------------------------------------------------------
// Material inputs

namespace {

/// A material context whose given inputs are bound to opened textures.
struct TexturedMaterial {
  SurfaceMaterial material;
  MaterialTextures textures;
  void Bind(MaterialInput input, const TextureInput& t) {
    textures[std::size_t(input)] = {Texture::Open(t.texture), t};
    material.params.Texture(input) = t;
    material.textures = &textures;
  }
};

TextureInput Input(const std::string& file, int channel) {
  TextureInput t;
  t.texture = Params(file, TextureColorSpace::Raw);
  t.channel = channel;
  return t;
}

}  // namespace

TEST_CASE(
    "textured roughness, metallic, opacity, ior, diffuseColor, specularColor, clearcoat and clearcoatRoughness "
    "take the texel of their channel, and "
    "UsdTransform2d scales, rotates and translates st",
    "[texture][material]") {
  ScratchDir dir;
  // RGBA halves: left (0.2, 0.4, 0.6, 0.8), right (0.9, 0.7, 0.5, 0.3).
  std::vector<float> p;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x)
      for (float c : x < 4 ? std::vector<float>{0.2f, 0.4f, 0.6f, 0.8f} : std::vector<float>{0.9f, 0.7f, 0.5f, 0.3f})
        p.push_back(c);
  WriteImage(dir / "rgba.exr", 8, 8, 4, p, OIIO::TypeDesc::FLOAT);
  TexturedMaterial t;
  t.Bind(MaterialInput::Roughness, Input(dir / "rgba.exr", 0));
  t.Bind(MaterialInput::Metallic, Input(dir / "rgba.exr", 1));
  t.Bind(MaterialInput::Opacity, Input(dir / "rgba.exr", 3));
  TextureInput ior = Input(dir / "rgba.exr", 2);
  ior.texture.scale = glm::vec4(2);
  t.Bind(MaterialInput::Ior, ior);
  t.Bind(MaterialInput::DiffuseColor, Input(dir / "rgba.exr", -1));
  t.Bind(MaterialInput::SpecularColor, Input(dir / "rgba.exr", -1));
  t.Bind(MaterialInput::Clearcoat, Input(dir / "rgba.exr", 3));
  t.Bind(MaterialInput::ClearcoatRoughness, Input(dir / "rgba.exr", 1));
  t.material.params.useSpecularWorkflow = true;
  TextureSite site;
  site.st = {0.25, 0.5};
  const glm::dvec3 n(0, 0, 1);
  SurfaceShading left = ShadeMaterial(t.material, glm::dvec3(0.18), n, n, site);
  CHECK(left.bsdf.roughness == Approx(0.2));
  CHECK(left.bsdf.metallic == Approx(0.4));
  CHECK(left.bsdf.opacity == Approx(0.8));
  CHECK(left.bsdf.ior == Approx(1.2));
  CHECK(left.bsdf.albedo.b == Approx(0.6));
  CHECK(left.bsdf.specularWorkflow);
  CHECK(left.bsdf.specularColor.g == Approx(0.4));
  CHECK(left.bsdf.clearcoat == Approx(0.8));
  CHECK(left.bsdf.clearcoatRoughness == Approx(0.4));
  // opacityThreshold: opacity becomes a mask (present at 0.8 >= 0.5, opaque), absent on the right (0.3).
  t.material.params.opacityThreshold = 0.5f;
  left = ShadeMaterial(t.material, glm::dvec3(0.18), n, n, site);
  CHECK(left.present);
  CHECK(left.bsdf.opacity == 1);
  site.st = {0.75, 0.5};
  CHECK_FALSE(ShadeMaterial(t.material, glm::dvec3(0.18), n, n, site).present);

  // UsdTransform2d on roughness: st' = R(90 deg) (st * (2, 1)) + (0.5, 0). st = (0.25, 0.2) -> (0.5, 0.2)
  // -> rotated (-0.2, 0.5) -> (0.3, 0.5): the left half. Without the transform, st = (0.6, ...) would be right.
  TextureInput moved = Input(dir / "rgba.exr", 0);
  moved.scale = {2, 1};
  moved.rotation = 90;
  moved.translation = {0.5f, 0};
  t.Bind(MaterialInput::Roughness, moved);
  site.st = {0.25, 0.2};
  CHECK(ShadeMaterial(t.material, glm::dvec3(0.18), n, n, site).bsdf.roughness == Approx(0.2));
  moved.rotation = 0;  // (0.5, 0.2) + (0.5, 0) = (1.0, 0.2): repeat wraps to s = 0, between the halves' texels
  moved.translation = {0.25f, 0};  // (0.75, 0.2): right
  t.Bind(MaterialInput::Roughness, moved);
  CHECK(ShadeMaterial(t.material, glm::dvec3(0.18), n, n, site).bsdf.roughness == Approx(0.9));
}

namespace {

/// A quad of half-size h at height z (facing +z) with st = (x + h, y + h) / 2h over it.
void AddTexturedQuad(InMemorySceneDelegate& scene, const PrimId& id, double h, double z, double xShift,
                     const PrimId& material) {
  MeshTopology quad;
  std::vector<Vec3f> points;
  test::Quad(h, &quad, &points);
  for (Vec3f& p : points) p.z = float(z), p.x += float(xShift);
  scene.AddMesh(id, quad, points, Matrix4d(1.0), material);
  scene.SetPrimvar(id, "st", Primvar{Interpolation::Vertex, 2, {0, 0, 1, 0, 1, 1, 0, 1}});
}

/// An orthographic camera at height z looking down -z over a square of half-size h.
void AddTopCamera(InMemorySceneDelegate& scene, double h, double z) {
  CameraParams ortho;
  ortho.orthographic = true;
  ortho.horizontalAperture = ortho.verticalAperture = float(2 * h);
  scene.AddCamera("/cam", ortho, test::LookDownZ(z));
}

/// A 2 x 2 quad at z = 0 that emits `texture` (raw values) and reflects nothing, as "/quad" with material "/mat".
void AddEmissiveQuad(InMemorySceneDelegate& scene, const std::string& texture) {
  MaterialParams m;
  m.diffuseColor = glm::vec3(0);
  m.Texture(MaterialInput::EmissiveColor).texture = Params(texture, TextureColorSpace::Raw);
  scene.AddMaterial("/mat", m);
  AddTexturedQuad(scene, "/quad", 1, 0, 0, "/mat");
}

struct TextureScene : test::RenderStack {
  RenderStats Render(int spp) {
    delegate.Settings().samplesPerPixel = spp;
    return pass.Execute("/cam", {{"color", "/color"}});
  }
  /// Mean and variance over pixels of channel 0 in columns [x0, x1) and rows [y0, y1) (y1 < 0: every row).
  std::pair<double, double> Stats(int x0, int x1, int y0 = 0, int y1 = -1) {
    RenderBuffer& b = Buffer("/color");
    double sum = 0, sum2 = 0;
    int n = 0;
    for (int y = y0; y < (y1 < 0 ? b.Height() : y1); ++y)
      for (int x = x0; x < x1; ++x) {
        const double v = b.Resolved(x, y, 0);
        sum += v, sum2 += v * v, ++n;
      }
    const double mean = sum / n;
    return {mean, sum2 / n - mean * mean};
  }
};

}  // namespace

TEST_CASE("a mip-mapped checker seen from afar renders with far less pixel variance than point sampling at equal spp",
          "[texture][render]") {
  // Emission from a 512^2 one-texel checker on a quad filling a 32^2 image: each pixel covers 16^2 texels. The
  // filtered lookup returns about their mean, 0.5; point sampling, a bilinear blend of the texels around each sample.
  ScratchDir dir;
  const int n = 512;
  WriteOneTexelChecker(dir / "checker.png", n);
  double variance[2], mean[2];
  for (int filtered = 0; filtered < 2; ++filtered) {
    TextureScene s;
    AddEmissiveQuad(s.scene, dir / "checker.png");
    AddTopCamera(s.scene, 1, 5);
    s.scene.AddRenderBuffer("/color", 32, 32, 4);
    s.delegate.Settings().textureFiltering = filtered == 1;
    REQUIRE(s.Render(4).nonFiniteSamples == 0);
    std::tie(mean[filtered], variance[filtered]) = s.Stats(0, 32);
  }
  std::printf("checker from afar, 4 spp: point sampled mean %.4f variance %.5f; filtered mean %.4f variance %.6f\n",
              mean[0], variance[0], mean[1], variance[1]);
  CHECK(mean[1] == Approx(0.5).margin(0.02));
  CHECK(variance[0] > 0.004);  // bilinear over a one-texel checker has variance 1/36; 4 samples a pixel: 1/144
  CHECK(variance[1] < variance[0] / 50);
}

TEST_CASE("a textured plane in focus is as sharp through a lens as through a pinhole", "[texture][render]") {
  // A checker of 4 texels across a quad about 30 pixels wide, at the focus distance: each lens point sees it as
  // the pinhole does, so the texture footprint must be the pixel's there, not the lens's aperture (OpenUSD's Mipmap
  // stage at fStop 100 read its coarse MIP levels).
  ScratchDir dir;
  WriteOneTexelChecker(dir / "checker.png", 4);
  double variance[2], mean[2];
  for (int withLens = 0; withLens < 2; ++withLens) {
    TextureScene s;
    AddEmissiveQuad(s.scene, dir / "checker.png");
    CameraParams camera;
    if (withLens) camera.fStop = 2, camera.focusDistance = 5;  // a 2.5-unit aperture
    s.scene.AddCamera("/cam", camera, test::LookDownZ(5));
    s.scene.AddRenderBuffer("/color", 32, 32, 4);
    REQUIRE(s.Render(8).nonFiniteSamples == 0);
    std::tie(mean[withLens], variance[withLens]) = s.Stats(6, 26, 6, 26);
  }
  std::printf("checker in focus: pinhole mean %.4f variance %.5f; lens mean %.4f variance %.5f\n", mean[0], variance[0],
              mean[1], variance[1]);
  CHECK(variance[0] > 0.05);               // the checks resolved
  CHECK(variance[1] > 0.9 * variance[0]);  // 0.70 when the lens offset widened the footprint
  CHECK(mean[1] == Approx(mean[0]).margin(0.03));
}

TEST_CASE("renders with filtered textures are the same for 1 and 2 threads", "[texture][render]") {
  ScratchDir dir;
  std::vector<float> p(64 * 64 * 3);
  for (std::size_t i = 0; i < p.size(); ++i) p[i] = float((i * 2654435761u) % 1000) / 1000.0f;
  WriteImage(dir / "noise.jpg", 64, 64, 3, p);
  std::vector<float> images[2];
  for (int threads = 1; threads <= 2; ++threads) {
    TextureScene s;
    MaterialParams m;
    m.Texture(MaterialInput::DiffuseColor).texture = Params(dir / "noise.jpg");
    m.Texture(MaterialInput::Roughness).texture = Params(dir / "noise.jpg");
    m.Texture(MaterialInput::Roughness).channel = 1;
    s.scene.AddMaterial("/mat", m);
    AddTexturedQuad(s.scene, "/quad", 1, 0, 0, "/mat");
    CameraParams lens;
    Matrix4d camera = test::LookDownZ(3);
    s.scene.AddCamera("/cam", lens, camera);
    LightParams dome;
    s.scene.AddLight("/dome", primTypes::kDomeLight, dome);
    s.scene.AddRenderBuffer("/color", 24, 24, 4);
    s.delegate.Settings().threads = threads;
    s.Render(4);
    RenderBuffer& b = s.Buffer("/color");
    for (int y = 0; y < 24; ++y)
      for (int x = 0; x < 24; ++x)
        for (int c = 0; c < 3; ++c) images[threads - 1].push_back(b.Resolved(x, y, c));
  }
  CHECK(images[0] == images[1]);
}

TEST_CASE(
    "a tangent-space normal map tilts the shading normal along dp/ds: a plane lit at 60 degrees doubles "
    "where the map faces the light, and goes black where it faces away",
    "[texture][render]") {
  ScratchDir dir;
  const double b = kPi / 3;
  // Tangent-space normals stored raw in [0, 1] (scale 2, bias -1): left half tilted +60 deg about t (towards
  // +s, the light), right half -60 deg.
  std::vector<float> p;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {  // 64 wide: the bicubic blend across the middle stays within 0.04 in s
      const double tilt = x < 32 ? b : -b;
      for (double c : {std::sin(tilt), 0.0, std::cos(tilt)}) p.push_back(float(0.5 * c + 0.5));
    }
  WriteImage(dir / "normal.exr", 64, 64, 3, p, OIIO::TypeDesc::FLOAT);
  double means[2][2];
  for (int mapped = 0; mapped < 2; ++mapped) {
    TextureScene s;
    MaterialParams m;
    m.diffuseColor = glm::vec3(0.5f);
    m.ior = 1;  // Lambert
    if (mapped) {
      TextureInput& normal = m.Texture(MaterialInput::Normal);
      normal.texture = Params(dir / "normal.exr", TextureColorSpace::Raw);
      normal.texture.scale = {2, 2, 2, 1};
      normal.texture.bias = {-1, -1, -1, 0};
    }
    s.scene.AddMaterial("/mat", m);
    AddTexturedQuad(s.scene, "/quad", 1, 0, 0, "/mat");
    AddTopCamera(s.scene, 1, 5);
    LightParams sun;
    sun.angle = 0.5f;
    // A distant light shines along its -z: rotate +z towards (sin b, 0, cos b), about y by +b.
    const Matrix4d rotate(glm::dvec4(std::cos(b), 0, -std::sin(b), 0), glm::dvec4(0, 1, 0, 0),
                          glm::dvec4(std::sin(b), 0, std::cos(b), 0), glm::dvec4(0, 0, 0, 1));
    s.scene.AddLight("/sun", primTypes::kDistantLight, sun, rotate);
    s.scene.AddRenderBuffer("/color", 16, 16, 4);
    s.delegate.Settings().maxDepth = 1;
    REQUIRE(s.Render(16).nonFiniteSamples == 0);
    means[mapped][0] = s.Stats(1, 7).first;  // away from the map's halfway column
    means[mapped][1] = s.Stats(9, 15).first;
  }
  std::printf("normal map: unmapped %.5f %.5f, mapped towards the light %.5f, away %.5f\n", means[0][0], means[0][1],
              means[1][0], means[1][1]);
  CHECK(means[0][0] > 0);
  CHECK(means[1][0] / means[0][0] == Approx(1 / std::cos(b)).epsilon(0.02));  // cos 0 over cos 60
  CHECK(means[1][1] == Approx(0).margin(1e-6));                               // 120 degrees from the light
}

TEST_CASE("a normal map on an instanced mesh tilts along the instance's dp/ds, as on the same mesh drawn once",
          "[texture][render][instancer]") {
  ScratchDir dir;
  // Every texel tilted 45 degrees about t, towards +s; the quad's s runs along its object x.
  const double tilt = kPi / 4;
  std::vector<float> p;
  for (int k = 0; k < 8 * 8; ++k)
    for (double c : {std::sin(tilt), 0.0, std::cos(tilt)}) p.push_back(float(0.5 * c + 0.5));
  WriteImage(dir / "tilt.exr", 8, 8, 3, p, OIIO::TypeDesc::FLOAT);
  // A quarter turn about z: object x (s) points along world y.
  const Matrix4d quarter(glm::dvec4(0, 1, 0, 0), glm::dvec4(-1, 0, 0, 0), glm::dvec4(0, 0, 1, 0),
                         glm::dvec4(0, 0, 0, 1));
  glm::dvec3 normals[2];
  for (int instanced = 0; instanced < 2; ++instanced) {
    TextureScene s;
    MaterialParams m;
    TextureInput& normal = m.Texture(MaterialInput::Normal);
    normal.texture = Params(dir / "tilt.exr", TextureColorSpace::Raw);
    normal.texture.scale = {2, 2, 2, 1};
    normal.texture.bias = {-1, -1, -1, 0};
    s.scene.AddMaterial("/mat", m);
    MeshTopology quad;
    std::vector<Vec3f> points;
    test::Quad(1, &quad, &points);
    if (instanced) {
      s.scene.AddInstancer("/inst", {quarter});
      s.scene.AddMesh("/inst/quad", quad, points, Matrix4d(1.0), "/mat", "/inst");
    } else {
      s.scene.AddMesh("/quad", quad, points, quarter, "/mat");
    }
    s.scene.SetPrimvar(instanced ? "/inst/quad" : "/quad", "st",
                       Primvar{Interpolation::Vertex, 2, {0, 0, 1, 0, 1, 1, 0, 1}});
    AddTopCamera(s.scene, 1, 5);
    s.scene.AddRenderBuffer("/color", 8, 8, 4);
    s.scene.AddRenderBuffer("/normal", 8, 8, 3);
    s.delegate.Settings().samplesPerPixel = 1;
    s.pass.Execute("/cam", {{"color", "/color"}, {"normal", "/normal"}});
    const RenderBuffer& b = s.Buffer("/normal");
    normals[instanced] = glm::dvec3(b.Resolved(4, 4, 0), b.Resolved(4, 4, 1), b.Resolved(4, 4, 2));
  }
  const glm::dvec3 expected(0, std::sin(tilt), std::cos(tilt));
  INFO("drawn once " << normals[0].x << " " << normals[0].y << " " << normals[0].z << ", instanced " << normals[1].x
                     << " " << normals[1].y << " " << normals[1].z);
  CHECK(glm::length(normals[0] - expected) < 1e-3);
  CHECK(glm::length(normals[1] - normals[0]) < 1e-6);
}

TEST_CASE("an opacityThreshold cut-out lets camera rays and shadow rays through where opacity is below it",
          "[texture][render]") {
  ScratchDir dir;
  WriteImage(dir / "mask.png", 64, 64, 1, Halves(64, 64, 1, 0, 1));  // s < 0.5: opacity 0
  MaterialParams card;
  card.diffuseColor = glm::vec3(0);
  card.opacityThreshold = 0.5f;
  TextureInput& opacity = card.Texture(MaterialInput::Opacity);
  opacity.texture = Params(dir / "mask.png", TextureColorSpace::Raw);
  opacity.texture.wrapS = opacity.texture.wrapT = TextureWrap::Clamp;
  opacity.channel = 0;

  SECTION("camera rays: an emissive floor shows through the cut-out half of a card above it") {
    TextureScene s;
    MaterialParams glow;
    glow.diffuseColor = glm::vec3(0);
    glow.emissiveColor = glm::vec3(1);
    s.scene.AddMaterial("/glow", glow);
    s.scene.AddMaterial("/cardMat", card);
    AddTexturedQuad(s.scene, "/floor", 1, 0, 0, "/glow");
    AddTexturedQuad(s.scene, "/card", 1, 1, 0, "/cardMat");
    AddTopCamera(s.scene, 1, 5);
    s.scene.AddRenderBuffer("/color", 16, 16, 4);
    s.Render(1);
    const double left = s.Stats(0, 7).first, right = s.Stats(9, 16).first;
    std::printf("cut-out seen by the camera: left %.4f right %.4f\n", left, right);
    CHECK(left == Approx(1).margin(1e-4));
    CHECK(right == 0);
  }
  SECTION("shadow rays: the card's cut-out half casts no shadow") {
    // The card sits 1 above the floor, shifted +1 in x; the sun comes from 45 degrees towards +x, so the card's
    // cut-out half shades floor x in [-1, 0] (the image's left half) and its opaque half x in [0, 1]. The
    // camera is below the card.
    double lit[2];
    for (int withCard = 0; withCard < 2; ++withCard) {
      TextureScene s;
      MaterialParams floor;
      floor.diffuseColor = glm::vec3(0.5f);
      floor.ior = 1;
      s.scene.AddMaterial("/floorMat", floor);
      s.scene.AddMaterial("/cardMat", card);
      AddTexturedQuad(s.scene, "/floor", 1, 0, 0, "/floorMat");
      if (withCard) AddTexturedQuad(s.scene, "/card", 1, 1, 1, "/cardMat");
      AddTopCamera(s.scene, 1, 0.5);
      LightParams sun;
      sun.angle = 0.5f;
      const double b = kPi / 4;
      const Matrix4d rotate(glm::dvec4(std::cos(b), 0, -std::sin(b), 0), glm::dvec4(0, 1, 0, 0),
                            glm::dvec4(std::sin(b), 0, std::cos(b), 0), glm::dvec4(0, 0, 0, 1));
      s.scene.AddLight("/sun", primTypes::kDistantLight, sun, rotate);
      s.scene.AddRenderBuffer("/color", 16, 16, 4);
      s.delegate.Settings().maxDepth = 1;
      s.Render(8);
      lit[withCard] = s.Stats(1, 7).first;
      if (withCard) {
        const double shadowed = s.Stats(9, 15).first;
        std::printf("cut-out shadow: floor without card %.5f, under the cut-out %.5f, under the opaque half %.5f\n",
                    lit[0], lit[1], shadowed);
        CHECK(shadowed == Approx(0).margin(1e-6));
      }
    }
    CHECK(lit[0] > 0);
    CHECK(lit[1] == Approx(lit[0]).epsilon(1e-6));
  }
}

TEST_CASE(
    "a rect light's texture shows upright to a viewer facing it (UsdLux: the image's first texel at local "
    "+x, +y), and its sampled and intersected radiance agree",
    "[texture][light]") {
  ScratchDir dir;
  // Quadrants: top-left red, top-right green, bottom-left blue, bottom-right white (row 0 at the top).
  std::vector<float> p;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      const glm::vec3 c =
          y < 4 ? (x < 4 ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0)) : (x < 4 ? glm::vec3(0, 0, 1) : glm::vec3(1, 1, 1));
      p.insert(p.end(), {c.r, c.g, c.b});
    }
  WriteImage(dir / "quads.exr", 8, 8, 3, p, OIIO::TypeDesc::FLOAT);
  LightParams params;
  params.type = LightType::Rect;
  params.width = params.height = 2;
  params.intensity = 3;
  params.textureFile = dir / "quads.exr";
  const RenderLight light = RenderLight::FromParams(
      params, Matrix4d(1.0), nullptr, Texture::Open(TextureParams::Image(dir / "quads.exr", TextureWrap::Clamp)));
  // The light emits along -z: seen from below, looking up +z, local +x is on the viewer's left.
  auto seen = [&](double x, double y) {
    glm::dvec3 radiance(0);
    double pdf = 0, distance = 0;
    REQUIRE(IntersectLight(light, {x, y, -1}, {0, 0, 1}, 1e30, &radiance, &pdf, &distance));
    return radiance;
  };
  CHECK(seen(0.5, 0.5) == glm::dvec3(3, 0, 0));   // +x, +y: the image's top-left, red
  CHECK(seen(-0.5, 0.5) == glm::dvec3(0, 3, 0));  // the viewer's top-right: green
  CHECK(seen(0.5, -0.5) == glm::dvec3(0, 0, 3));  // bottom-left: blue
  CHECK(seen(-0.5, -0.5) == glm::dvec3(3, 3, 3));
  // A sampled point's radiance is what a ray to it finds.
  for (double u1 : {0.1, 0.4, 0.8})
    for (double u2 : {0.2, 0.7}) {
      const glm::dvec3 from(0.3, -0.2, -2);
      const LightSample s = SampleLight(light, from, u1, u2);
      REQUIRE(s.pdf > 0);
      glm::dvec3 radiance(0);
      double pdf = 0, distance = 0;
      REQUIRE(IntersectLight(light, from, s.dir, 1e30, &radiance, &pdf, &distance));
      CHECK(glm::length(radiance - s.radiance) < 1e-6);
      CHECK(pdf == Approx(s.pdf).epsilon(1e-9));
    }
}

namespace {

/// The iris's MNEE light (the irisMnee AOV summed over a 24 x 24 image, 32 spp) of the side-lit eye with its key
/// replaced by a `width` x 6 mm rect light of radiance 300 at 150 mm, 60 degrees off the eye's axis, facing
/// the eye, its centre `shift` mm along its local x; `texture` on it if not empty.
double IrisMneeUnderRect(double width, double shift, const std::string& texture) {
  test::RenderStack s;
  sampleScenes::AddSideLitEye(s.scene, 60);
  LightParams key = s.scene.GetLightParams("/World/key");
  key.intensity = 0;  // the sphere key off
  s.scene.SetLightParams("/World/key", key);
  const double a = 60 * kPi / 180;
  const glm::dvec3 z(std::sin(a), 0, std::cos(a)), x = glm::normalize(glm::cross(glm::dvec3(0, 1, 0), z)),
                                                   y = glm::cross(z, x), centre = 150.0 * z + shift * x;
  Matrix4d m(1.0);  // local -z towards the eye
  m[0] = glm::dvec4(x, 0), m[1] = glm::dvec4(y, 0), m[2] = glm::dvec4(z, 0), m[3] = glm::dvec4(centre, 1);
  LightParams rect;
  rect.width = float(width);
  rect.height = 6;
  rect.intensity = 300;
  rect.textureFile = texture;
  s.scene.AddLight("/World/rect", primTypes::kRectLight, rect, m);
  return test::IrisMneeSum(s, sampleScenes::kCamera, 24, 32);
}

}  // namespace

TEST_CASE(
    "MNEE evaluates a rect light's texture at the solved light point: a half-black texture gives the caustic "
    "of the lit half alone",
    "[texture][light][mnee]") {
  ScratchDir dir;
  // The image's left half white: UsdLux puts it at local +x (RenderLight::rectImage).
  WriteImage(dir / "half.exr", 64, 8, 3, Halves(64, 8, 3, 1, 0), OIIO::TypeDesc::FLOAT);
  const double whole = IrisMneeUnderRect(6, 0, ""), textured = IrisMneeUnderRect(6, 0, dir / "half.exr"),
               half = IrisMneeUnderRect(3, 1.5, "");
  std::printf("iris MNEE light: untextured 6 x 6 rect %.4f, half-black texture %.4f, the lit 3 x 6 half alone %.4f\n",
              whole, textured, half);
  REQUIRE(whole > 0);
  CHECK(textured == Approx(half).epsilon(0.03));
  CHECK(half < 0.8 * whole);  // the check above can tell the lit half from the whole rect
}
