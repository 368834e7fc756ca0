#include "hdeye/image/imageWriter.h"

#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfMultiPartOutputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfOutputPart.h>
#include <OpenEXR/ImfPartType.h>
#include <OpenEXR/ImfStdIO.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenImageIO/imageio.h>

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>
#include <stdexcept>

namespace hdeye {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void Fail(const std::string& verb, const std::string& path, const std::string& reason) {
  throw std::runtime_error("cannot " + verb + " " + path + ": " + reason);
}

/// Checks the image size and that `values` holds `components` floats per pixel, all finite. Returns
/// an empty string if the data is good, else the reason, naming `what` and the first bad pixel.
std::string CheckPixels(const std::string& what, int width, int height, int components,
                        const std::vector<float>& values) {
  const size_t expected = size_t(width) * size_t(height) * size_t(components);
  if (values.size() != expected) {
    std::ostringstream s;
    s << what << " has " << values.size() << " values, expected " << expected << " (" << width << "x" << height
      << (components > 1 ? "x" + std::to_string(components) : "") << ")";
    return s.str();
  }
  const auto bad = std::find_if(values.begin(), values.end(), [](float v) { return !std::isfinite(v); });
  if (bad == values.end()) return {};
  const size_t pixel = size_t(bad - values.begin()) / size_t(components);
  std::ostringstream s;
  s << what << " has a non-finite value (" << *bad << ") at pixel x=" << pixel % size_t(width)
    << " y=" << pixel / size_t(width);
  return s.str();
}

/// Writes the file at `path` atomically: `write(tmp)` writes a complete file at the temporary path
/// `tmp` (a hidden name in the same directory, so the rename cannot cross file systems) and throws on
/// failure; the file is then fsync'ed and renamed over `path`. On any failure the temporary file is
/// removed and a runtime_error naming `path` is thrown.
void WriteAtomically(const std::string& path, const std::function<void(const std::string&)>& write) {
  const fs::path target(path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::exists(dir, ec)) Fail("write", path, "directory does not exist");
  if (!fs::is_directory(dir, ec)) Fail("write", path, dir.string() + " is not a directory");
  if (fs::is_directory(target, ec)) Fail("write", path, "it is a directory");
  if (!target.has_filename()) Fail("write", path, "no file name");

  static std::atomic<unsigned> counter{0};
  const std::string tmp =
      (dir / ("." + target.filename().string() + ".tmp." + std::to_string(getpid()) + "." + std::to_string(counter++)))
          .string();
  try {
    write(tmp);
    // Flush the data to disk before the rename, so that after a crash `path` holds either the old
    // file or the complete new one, never an empty one. fsync applies to the file, whichever fd.
    const int fd = open(tmp.c_str(), O_RDONLY);
    if (fd < 0 || fsync(fd) != 0) {
      const int err = errno;
      if (fd >= 0) close(fd);
      throw std::runtime_error(std::string("fsync failed (") + std::strerror(err) + ")");
    }
    close(fd);
    if (std::rename(tmp.c_str(), path.c_str()) != 0)
      throw std::runtime_error(std::string("rename failed (") + std::strerror(errno) + ")");
  } catch (const std::exception& e) {
    fs::remove(tmp, ec);
    Fail("write", path, e.what());
  }
}

}  // namespace

namespace {

/// Fails (writing nothing) unless every plane of `part` has a unique non-empty name and width x height finite values.
void CheckPlanes(const std::string& path, int width, int height, const ImagePart& part) {
  if (part.planes.empty()) Fail("write", path, "no image planes given");
  std::set<std::string> names;
  for (const ImagePlane& plane : part.planes) {
    if (plane.name.empty()) Fail("write", path, "a plane has an empty name");
    if (!names.insert(plane.name).second) Fail("write", path, "duplicate plane name \"" + plane.name + "\"");
    const std::string bad = CheckPixels("plane \"" + plane.name + "\"", width, height, 1, plane.pixels);
    if (!bad.empty()) Fail("write", path, bad);
  }
}

void CheckAttributes(const std::string& path, const std::vector<std::pair<std::string, std::string>>& attributes) {
  // The attributes every header has; an extra attribute of the same name would replace them.
  const Imf::Header required(1, 1);
  std::set<std::string> attributeNames;
  for (const auto& [name, value] : attributes) {
    if (name.empty()) Fail("write", path, "a header attribute has an empty name");
    if (!attributeNames.insert(name).second) Fail("write", path, "duplicate header attribute \"" + name + "\"");
    if (required.find(name) != required.end() || name == "name" || name == "type")
      Fail("write", path, "header attribute \"" + name + "\" is one of OpenEXR's required attributes");
  }
}

/// A part's header and frame buffer over `floats` and `halves` (its FLOAT and HALF planes: OpenEXR's writer
/// does not convert, so a HALF channel needs half pixels; beyond +-HALF_MAX they are clamped to it).
struct PartBuffers {
  Imf::Header header;
  Imf::FrameBuffer frameBuffer;
  std::vector<std::vector<Imath::half>> halves;
};

PartBuffers MakePart(const Imath::Box2i& display, const Imath::Box2i& data, const ImagePart& part,
                     const std::vector<std::pair<std::string, std::string>>& attributes, bool named) {
  PartBuffers out{Imf::Header(display, data), {}, {}};
  out.header.compression() = Imf::ZIP_COMPRESSION;
  if (named) {
    out.header.setName(part.name);
    out.header.setType(Imf::SCANLINEIMAGE);
  }
  for (const auto& [name, value] : attributes) out.header.insert(name, Imf::StringAttribute(value));
  constexpr float kHalfMax = 65504.0f;
  out.halves.reserve(part.planes.size());  // no reallocation: the frame buffer points into them
  for (const ImagePlane& plane : part.planes) {
    const bool half = plane.type == ChannelType::kHalf;
    out.header.channels().insert(plane.name, Imf::Channel(half ? Imf::HALF : Imf::FLOAT));
    if (!half) {
      // OpenEXR's Slice takes a non-const pointer for reading and writing alike; it only reads here.
      auto* base = const_cast<float*>(plane.pixels.data());
      out.frameBuffer.insert(plane.name, Imf::Slice::Make(Imf::FLOAT, base, data));
      continue;
    }
    auto& halves = out.halves.emplace_back(plane.pixels.size());
    for (std::size_t i = 0; i < halves.size(); ++i) halves[i] = std::clamp(plane.pixels[i], -kHalfMax, kHalfMax);
    out.frameBuffer.insert(plane.name, Imf::Slice::Make(Imf::HALF, halves.data(), data));
  }
  return out;
}

/// Writes the parts through our own ofstream, not a file name: ~OutputFile writes the line offset table and
/// swallows any error there, so the stream state is the only way to learn that the write failed.
void WriteParts(const std::string& tmp, std::vector<PartBuffers>& parts, int rows, bool multiPart) {
  std::ofstream file(tmp, std::ios::binary | std::ios::trunc);
  if (!file) throw std::runtime_error("cannot create temporary file " + tmp + " (" + std::strerror(errno) + ")");
  {
    Imf::StdOFStream stream(file, tmp.c_str());
    if (!multiPart) {
      Imf::OutputFile out(stream, parts[0].header);
      out.setFrameBuffer(parts[0].frameBuffer);
      out.writePixels(rows);
    } else {
      std::vector<Imf::Header> headers;
      for (const PartBuffers& part : parts) headers.push_back(part.header);
      Imf::MultiPartOutputFile out(stream, headers.data(), int(headers.size()));
      for (std::size_t i = 0; i < parts.size(); ++i) {
        Imf::OutputPart part(out, int(i));
        part.setFrameBuffer(parts[i].frameBuffer);
        part.writePixels(rows);
      }
    }
  }
  file.close();
  if (file.fail()) throw std::runtime_error("error writing temporary file " + tmp);
}

}  // namespace

void WriteExrParts(const std::string& path, int width, int height, const std::vector<ImagePart>& parts,
                   const std::vector<std::pair<std::string, std::string>>& attributes, const PixelWindow& dataWindow,
                   bool multiPart) {
  if (width <= 0 || height <= 0)
    Fail("write", path, "image size " + std::to_string(width) + "x" + std::to_string(height) + " is not positive");
  if (parts.empty()) Fail("write", path, "no image parts given");
  const Imath::Box2i display({0, 0}, {width - 1, height - 1});
  const bool whole = dataWindow.x1 < dataWindow.x0 || dataWindow.y1 < dataWindow.y0;
  const Imath::Box2i data =
      whole ? display : Imath::Box2i({dataWindow.x0, dataWindow.y0}, {dataWindow.x1, dataWindow.y1});
  if (data.min.x < 0 || data.min.y < 0 || data.max.x >= width || data.max.y >= height)
    Fail("write", path,
         "the data window is outside the " + std::to_string(width) + "x" + std::to_string(height) + " display window");
  multiPart = multiPart || parts.size() > 1;
  std::set<std::string> partNames;
  for (const ImagePart& part : parts) {
    CheckPlanes(path, data.max.x - data.min.x + 1, data.max.y - data.min.y + 1, part);
    if (multiPart && (part.name.empty() || !partNames.insert(part.name).second))
      Fail("write", path, "a part of a multi-part file needs a name of its own (\"" + part.name + "\")");
  }
  CheckAttributes(path, attributes);
  WriteAtomically(path, [&](const std::string& tmp) {
    // Reserved: a reallocation may copy a PartBuffers (Imf::Header's move is not noexcept), and its frame buffer
    // would then point into the old copy's half pixels.
    std::vector<PartBuffers> buffers;
    buffers.reserve(parts.size());
    for (const ImagePart& part : parts) buffers.push_back(MakePart(display, data, part, attributes, multiPart));
    WriteParts(tmp, buffers, data.max.y - data.min.y + 1, multiPart);
  });
}

void WriteExr(const std::string& path, int width, int height, const std::vector<ImagePlane>& planes,
              const std::vector<std::pair<std::string, std::string>>& attributes) {
  WriteExrParts(path, width, height, {ImagePart{"", planes}}, attributes);
}

std::vector<ImagePlane> ReadExr(const std::string& path, int* width, int* height) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) Fail("read", path, "file does not exist");
  try {
    Imf::InputFile in(path.c_str());
    const Imath::Box2i dataWindow = in.header().dataWindow();
    const int w = dataWindow.max.x - dataWindow.min.x + 1;
    const int h = dataWindow.max.y - dataWindow.min.y + 1;
    std::vector<ImagePlane> planes;
    for (auto it = in.header().channels().begin(); it != in.header().channels().end(); ++it) {
      if (it.channel().xSampling != 1 || it.channel().ySampling != 1)
        throw std::runtime_error(std::string("channel \"") + it.name() + "\" is subsampled");
      planes.push_back({it.name(), std::vector<float>(size_t(w) * size_t(h))});
    }
    Imf::FrameBuffer frameBuffer;
    for (ImagePlane& plane : planes)
      frameBuffer.insert(plane.name, Imf::Slice::Make(Imf::FLOAT, plane.pixels.data(), dataWindow));
    in.setFrameBuffer(frameBuffer);
    in.readPixels(dataWindow.min.y, dataWindow.max.y);
    if (width) *width = w;
    if (height) *height = h;
    return planes;
  } catch (const std::exception& e) {  // OpenEXR's Iex exceptions derive from std::exception
    Fail("read", path, e.what());
  }
}

std::map<std::string, std::string> ReadExrStringAttributes(const std::string& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) Fail("read", path, "file does not exist");
  try {
    Imf::InputFile in(path.c_str());
    std::map<std::string, std::string> out;
    for (auto it = in.header().begin(); it != in.header().end(); ++it)
      if (const auto* a = dynamic_cast<const Imf::StringAttribute*>(&it.attribute())) out[it.name()] = a->value();
    return out;
  } catch (const std::exception& e) {
    Fail("read", path, e.what());
  }
}

void WritePngPreview(const std::string& path, int width, int height, const std::vector<float>& rgb, float exposure) {
  if (width <= 0 || height <= 0)
    Fail("write", path, "image size " + std::to_string(width) + "x" + std::to_string(height) + " is not positive");
  if (!std::isfinite(exposure)) Fail("write", path, "exposure is not finite");
  const std::string bad = CheckPixels("rgb", width, height, 3, rgb);
  if (!bad.empty()) Fail("write", path, bad);

  const float scale = std::exp2(exposure);
  std::vector<unsigned char> bytes(rgb.size());
  for (size_t i = 0; i < rgb.size(); ++i)
    bytes[i] = static_cast<unsigned char>(std::lround(255.0f * LinearToSrgb(rgb[i] * scale)));

  WriteAtomically(path, [&](const std::string& tmp) {
    // By format name: the temporary file's name has no .png extension for OIIO to go by.
    auto out = OIIO::ImageOutput::create("png");
    if (!out) throw std::runtime_error("OpenImageIO has no PNG writer (" + OIIO::geterror() + ")");
    OIIO::ImageSpec spec(width, height, 3, OIIO::TypeDesc::UINT8);
    spec.attribute("oiio:ColorSpace", "sRGB");
    if (!out->open(tmp, spec) || !out->write_image(OIIO::TypeDesc::UINT8, bytes.data()) || !out->close())
      throw std::runtime_error("cannot write temporary file " + tmp + " (" + out->geterror() + ")");
  });
}

float LinearToSrgb(float x) {
  const double v = std::clamp(double(x), 0.0, 1.0);
  return float(v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055);
}

}  // namespace hdeye
