// Image output: EXR planes round-trip bit-exactly under their exact names, writes are atomic, bad input
// is rejected with a reason, and the PNG preview is the documented clamp + sRGB curve.
#include "hdeye/image/imageWriter.h"
#include "test_support.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenImageIO/imageio.h>
#include <catch2/catch.hpp>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <set>

using namespace hdeye;
using Catch::Matchers::Contains;
namespace fs = std::filesystem;

namespace {

using test::ErrorOf;
using test::ScratchDir;

std::vector<float> Ramp(size_t n, float start, float step) {
  std::vector<float> v(n);
  for (size_t i = 0; i < n; ++i) v[i] = start + step * float(i);
  return v;
}

bool SameBits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

std::map<std::string, std::vector<float>> ByName(const std::vector<ImagePlane>& planes) {
  std::map<std::string, std::vector<float>> m;
  for (const ImagePlane& p : planes) m[p.name] = p.pixels;
  return m;
}

/// Reads an 8-bit RGB PNG with OpenImageIO (another reader than the writer's code path); returns 3 bytes
/// per pixel, top row first.
std::vector<unsigned char> ReadPng(const std::string& path, int* width, int* height) {
  auto in = OIIO::ImageInput::open(path);
  REQUIRE(in);
  const OIIO::ImageSpec& spec = in->spec();
  REQUIRE(spec.nchannels == 3);
  REQUIRE(spec.format == OIIO::TypeDesc::UINT8);
  std::vector<unsigned char> bytes(std::size_t(spec.width) * spec.height * 3);
  REQUIRE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, bytes.data()));
  *width = spec.width;
  *height = spec.height;
  return bytes;
}

/// The sRGB decoding curve (IEC 61966-2-1), the inverse of the encoding under test.
double SrgbToLinear(double v) { return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4); }

/// The single byte a 1x1 preview of grey x at `exposure` stops encodes.
int PreviewByte(const ScratchDir& dir, float x, float exposure = 0) {
  const std::string path = dir / "grey.png";
  WritePngPreview(path, 1, 1, {x, x, x}, exposure);
  int w = 0, h = 0;
  const std::vector<unsigned char> bytes = ReadPng(path, &w, &h);
  return bytes.at(0);
}

}  // namespace

TEST_CASE("EXR round trip of several named float channels is bit-exact", "[image]") {
  ScratchDir dir;
  const int w = 5, h = 3;
  std::vector<float> special = {0.0f,
                                -0.0f,
                                1e-42f /* denormal */,
                                -3.5f,
                                65504.0f,
                                1e30f,
                                std::nextafter(1.0f, 2.0f),
                                0.1f,
                                1.0f / 3.0f,
                                -1e-30f,
                                std::numeric_limits<float>::min(),
                                std::numeric_limits<float>::max(),
                                std::numeric_limits<float>::lowest(),
                                123456.789f,
                                7.0f};
  const std::vector<ImagePlane> planes = {{"R", Ramp(w * h, 0.0f, 0.1f)},
                                          {"G", special},
                                          {"B", Ramp(w * h, -1.0f, 1.0f / 7.0f)},
                                          {"primId", Ramp(w * h, 0.0f, 1.0f)}};
  const std::string path = dir / "beauty.exr";
  WriteExr(path, w, h, planes);

  int rw = 0, rh = 0;
  const auto read = ByName(ReadExr(path, &rw, &rh));
  CHECK(rw == w);
  CHECK(rh == h);
  REQUIRE(read.size() == planes.size());
  for (const ImagePlane& p : planes) {
    INFO("plane " << p.name);
    REQUIRE(read.count(p.name) == 1);
    CHECK(SameBits(read.at(p.name), p.pixels));
  }
}

TEST_CASE("EXR channel names are preserved exactly, dotted layer names included", "[image]") {
  ScratchDir dir;
  const std::vector<std::string> names = {"R",       "G",      "B",          "A",     "albedo.R", "N.X",
                                          "depth.Z", "primId", "irisMnee.R", "a.b.c", "Z",        "albedo.G"};
  std::vector<ImagePlane> planes;
  for (size_t i = 0; i < names.size(); ++i) planes.push_back({names[i], Ramp(4 * 2, float(i), 0.5f)});
  const std::string path = dir / "aovs.exr";
  WriteExr(path, 4, 2, planes);

  const auto read = ByName(ReadExr(path, nullptr, nullptr));
  std::set<std::string> readNames;
  for (const auto& [name, pixels] : read) readNames.insert(name);
  CHECK(readNames == std::set<std::string>(names.begin(), names.end()));
  // Each name still carries its own data (no mix-up between "R" and "albedo.R", say).
  for (const ImagePlane& p : planes) CHECK(SameBits(read.at(p.name), p.pixels));
}

TEST_CASE("EXR is a scanline file of FLOAT channels with ZIP compression and a 0-based window", "[image]") {
  ScratchDir dir;
  const std::string path = dir / "format.exr";
  WriteExr(path, 3, 2, {{"R", Ramp(6, 0, 1)}, {"depth.Z", Ramp(6, 1, 1)}});
  Imf::InputFile in(path.c_str());
  const Imf::Header& header = in.header();
  CHECK(header.compression() == Imf::ZIP_COMPRESSION);
  CHECK_FALSE(header.hasTileDescription());
  CHECK(header.dataWindow() == Imath::Box2i({0, 0}, {2, 1}));
  CHECK(header.displayWindow() == header.dataWindow());
  int channels = 0;
  for (auto it = header.channels().begin(); it != header.channels().end(); ++it, ++channels) {
    INFO("channel " << it.name());
    CHECK(it.channel().type == Imf::FLOAT);
  }
  CHECK(channels == 2);
}

TEST_CASE("writing to an unwritable location throws and leaves no file", "[image]") {
  ScratchDir dir;
  const std::vector<ImagePlane> planes = {{"R", {1, 2, 3, 4}}};
  const std::vector<float> rgb(12, 0.5f);

  const std::string missing = dir / "no_such_dir/out.exr";
  std::string msg = ErrorOf([&] { WriteExr(missing, 2, 2, planes); });
  CHECK_THAT(msg, Contains(missing) && Contains("directory does not exist"));
  msg = ErrorOf([&] { WritePngPreview(dir / "no_such_dir/out.png", 2, 2, rgb); });
  CHECK_THAT(msg, Contains("directory does not exist"));

  // A regular file where the directory should be.
  std::ofstream(dir / "file") << "x";
  const std::string underFile = dir / "file/out.exr";
  msg = ErrorOf([&] { WriteExr(underFile, 2, 2, planes); });
  CHECK_THAT(msg, Contains(underFile) && Contains("not a directory"));

  // The target itself is a directory.
  fs::create_directory(dir.path / "sub");
  msg = ErrorOf([&] { WriteExr(dir / "sub", 2, 2, planes); });
  CHECK_THAT(msg, Contains("is a directory"));

  // A read-only directory (meaningless as root, who may write anywhere).
  fs::create_directory(dir.path / "ro");
  fs::permissions(dir.path / "ro", fs::perms::owner_read | fs::perms::owner_exec);
  if (access((dir / "ro").c_str(), W_OK) != 0) {
    msg = ErrorOf([&] { WriteExr(dir / "ro/out.exr", 2, 2, planes); });
    CHECK_THAT(msg, Contains(dir / "ro/out.exr"));
    CHECK(fs::is_empty(dir.path / "ro"));
  } else {
    WARN("running as root: the read-only directory case is skipped");
  }
  fs::permissions(dir.path / "ro", fs::perms::owner_all);

  CHECK(dir.Files() == std::set<std::string>{"file", "sub", "ro"});
  CHECK(fs::is_empty(dir.path / "sub"));
}

TEST_CASE("writing over an existing file replaces it and leaves no temporary files", "[image]") {
  ScratchDir dir;
  const std::string exr = dir / "frame.exr";
  WriteExr(exr, 2, 1, {{"R", {1, 2}}, {"G", {3, 4}}});
  WriteExr(exr, 3, 1, {{"Y", {5, 6, 7}}});
  int w = 0, h = 0;
  const std::vector<ImagePlane> read = ReadExr(exr, &w, &h);
  CHECK(w == 3);
  CHECK(h == 1);
  REQUIRE(read.size() == 1);
  CHECK(read[0].name == "Y");
  CHECK(read[0].pixels == std::vector<float>{5, 6, 7});

  const std::string png = dir / "frame.png";
  WritePngPreview(png, 1, 1, {0, 0, 0});
  WritePngPreview(png, 2, 1, {1, 1, 1, 1, 1, 1});
  const std::vector<unsigned char> bytes = ReadPng(png, &w, &h);
  CHECK(w == 2);
  CHECK(bytes == std::vector<unsigned char>(6, 255));

  CHECK(dir.Files() == std::set<std::string>{"frame.exr", "frame.png"});
}

TEST_CASE("a rejected write leaves the existing file untouched", "[image]") {
  ScratchDir dir;
  const std::string path = dir / "keep.exr";
  WriteExr(path, 2, 1, {{"R", {1, 2}}});
  CHECK_THROWS_AS(WriteExr(path, 2, 1, {{"R", {1, std::nanf("")}}}), std::runtime_error);
  const std::vector<ImagePlane> read = ReadExr(path, nullptr, nullptr);
  REQUIRE(read.size() == 1);
  CHECK(read[0].pixels == std::vector<float>{1, 2});
  CHECK(dir.Files() == std::set<std::string>{"keep.exr"});
}

TEST_CASE("EXR input with wrong sizes, duplicate names or non-finite values is rejected with the reason", "[image]") {
  ScratchDir dir;
  const std::string path = dir / "bad.exr";
  auto errorOf = [&](int w, int h, const std::vector<ImagePlane>& planes) {
    return ErrorOf([&] { WriteExr(path, w, h, planes); });
  };
  const float nan = std::nanf(""), inf = std::numeric_limits<float>::infinity();

  std::string msg = errorOf(2, 2, {{"R", {1, 2, 3, 4}}, {"albedo.R", {1, 2, 3}}});
  CHECK_THAT(msg, Contains(path) && Contains("\"albedo.R\" has 3 values, expected 4"));
  msg = errorOf(2, 2, {{"R", {1, 2, 3, 4}}, {"R", {1, 2, 3, 4}}});
  CHECK_THAT(msg, Contains(path) && Contains("duplicate plane name \"R\""));
  msg = errorOf(3, 2, {{"R", Ramp(6, 0, 1)}, {"N.X", {0, 0, 0, 0, nan, nan}}});
  CHECK_THAT(msg, Contains(path) && Contains("\"N.X\"") && Contains("non-finite") && Contains("x=1 y=1"));
  msg = errorOf(2, 1, {{"depth.Z", {inf, 0}}});
  CHECK_THAT(msg, Contains("\"depth.Z\"") && Contains("inf") && Contains("x=0 y=0"));
  msg = errorOf(2, 2, {});
  CHECK_THAT(msg, Contains("no image planes"));
  msg = errorOf(0, 2, {{"R", {}}});
  CHECK_THAT(msg, Contains("not positive"));
  msg = errorOf(1, 1, {{"", {0}}});
  CHECK_THAT(msg, Contains("empty name"));

  CHECK(msg.find('\n') == std::string::npos);
  CHECK(dir.Files().empty());
}

TEST_CASE("reading a missing or non-EXR file throws naming the path", "[image]") {
  ScratchDir dir;
  const std::string missing = dir / "missing.exr";
  CHECK_THAT(ErrorOf([&] { ReadExr(missing, nullptr, nullptr); }), Contains(missing) && Contains("does not exist"));
  const std::string text = dir / "text.exr";
  std::ofstream(text) << "not an image";
  CHECK_THAT(ErrorOf([&] { ReadExr(text, nullptr, nullptr); }), Contains("cannot read " + text));
}

TEST_CASE("PNG preview has the requested size and top-row-first layout, read back with OpenImageIO", "[image]") {
  ScratchDir dir;
  const int w = 7, h = 5;
  std::vector<float> rgb(3 * w * h, 0.0f);
  const int x = 2, y = 1;  // one red pixel
  rgb[3 * (y * w + x)] = 1.0f;
  const std::string path = dir / "preview.png";
  WritePngPreview(path, w, h, rgb);

  int rw = 0, rh = 0;
  const std::vector<unsigned char> bytes = ReadPng(path, &rw, &rh);
  CHECK(rw == w);
  CHECK(rh == h);
  REQUIRE(bytes.size() == size_t(3 * w * h));
  for (int i = 0; i < w * h; ++i) {
    INFO("pixel x=" << i % w << " y=" << i / w);
    CHECK(int(bytes[3 * i]) == (i == y * w + x ? 255 : 0));
    CHECK(int(bytes[3 * i + 1]) == 0);
    CHECK(int(bytes[3 * i + 2]) == 0);
  }
}

TEST_CASE("PNG preview maps 0 to 0, 1 to 255, 0.214 to about 128, and clamps out-of-range values", "[image]") {
  ScratchDir dir;
  CHECK(PreviewByte(dir, 0.0f) == 0);
  CHECK(PreviewByte(dir, 1.0f) == 255);
  CHECK(std::abs(PreviewByte(dir, 0.214f) - 128) <= 1);  // sRGB(0.214) = 0.49996, i.e. 127.49
  CHECK(PreviewByte(dir, 0.18f) == 118);                 // 18% grey
  CHECK(PreviewByte(dir, -2.0f) == 0);
  CHECK(PreviewByte(dir, 40.0f) == 255);
}

TEST_CASE("PNG preview rounds to the nearest 8-bit code of the sRGB curve", "[image]") {
  // Every code c, decoded to linear with the inverse curve, must encode back to c.
  std::vector<float> rgb;
  for (int c = 0; c < 256; ++c)
    for (int k = 0; k < 3; ++k) rgb.push_back(float(SrgbToLinear(c / 255.0)));
  ScratchDir dir;
  const std::string path = dir / "ramp.png";
  WritePngPreview(path, 256, 1, rgb);
  int w = 0, h = 0;
  const std::vector<unsigned char> bytes = ReadPng(path, &w, &h);
  REQUIRE(bytes.size() == 3 * 256);
  for (int c = 0; c < 256; ++c) {
    INFO("code " << c << " linear " << rgb[3 * c]);
    CHECK(int(bytes[3 * c]) == c);
  }
}

TEST_CASE("PNG preview exposure of +1 stop doubles the linear value", "[image]") {
  ScratchDir dir;
  for (float x : {0.001f, 0.01f, 0.05f, 0.107f, 0.2f, 0.3f, 0.45f}) {
    INFO("x = " << x);
    CHECK(PreviewByte(dir, x, 1.0f) == PreviewByte(dir, 2 * x));
    CHECK(PreviewByte(dir, x, -1.0f) == PreviewByte(dir, x / 2));
  }
  CHECK(std::abs(PreviewByte(dir, 0.107f, 1.0f) - 128) <= 1);
}

TEST_CASE("PNG preview with wrong sizes or non-finite values is rejected with the reason", "[image]") {
  ScratchDir dir;
  const std::string path = dir / "bad.png";
  CHECK_THAT(ErrorOf([&] { WritePngPreview(path, 2, 2, std::vector<float>(11, 0.f)); }),
             Contains(path) && Contains("has 11 values, expected 12"));
  std::vector<float> rgb(12, 0.5f);
  rgb[10] = std::nanf("");
  CHECK_THAT(ErrorOf([&] { WritePngPreview(path, 2, 2, rgb); }),
             Contains(path) && Contains("non-finite") && Contains("x=1 y=1"));
  CHECK_THAT(ErrorOf([&] { WritePngPreview(path, 2, 2, std::vector<float>(12, 0.f), INFINITY); }),
             Contains("exposure"));
  CHECK(dir.Files().empty());
}

TEST_CASE("LinearToSrgb matches the standard sRGB curve at reference points", "[image]") {
  CHECK(LinearToSrgb(0.0f) == 0.0f);
  CHECK(LinearToSrgb(1.0f) == Approx(1.0f).margin(1e-7));
  CHECK(LinearToSrgb(0.001f) == Approx(0.01292).epsilon(1e-6));      // linear segment: 12.92 x
  CHECK(LinearToSrgb(0.0031308f) == Approx(0.04045).epsilon(1e-4));  // the junction
  CHECK(LinearToSrgb(0.18f) == Approx(0.461356).epsilon(1e-5));
  CHECK(LinearToSrgb(0.5f) == Approx(0.735357).epsilon(1e-5));
  CHECK(LinearToSrgb(-1.0f) == 0.0f);
  CHECK(LinearToSrgb(2.0f) == Approx(1.0f).margin(1e-7));
  for (int c = 0; c <= 255; ++c) {
    INFO("code " << c);
    CHECK(LinearToSrgb(float(SrgbToLinear(c / 255.0))) == Approx(c / 255.0).margin(1e-6));
  }
}

TEST_CASE("LinearToSrgb is monotonic, finely and across the segment junction", "[image]") {
  // Returns the first x of a decreasing step on the grid, or -1 if there is none.
  auto firstDecrease = [](float x, const std::function<float(float)>& next, int steps) {
    float previous = LinearToSrgb(x);
    for (int i = 0; i < steps; ++i) {
      x = next(x);
      const float y = LinearToSrgb(x);
      if (y < previous) return x;
      previous = y;
    }
    return -1.0f;
  };
  CHECK(firstDecrease(
            0.0f, [](float x) { return x + 1e-6f; }, 1000000) == -1.0f);
  // Every float around the junction at 0.0031308.
  CHECK(firstDecrease(
            0.00313f, [](float x) { return std::nextafter(x, 1.0f); }, 2000) == -1.0f);
}
