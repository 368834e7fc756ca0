#pragma once
// Image output of the render delegate: AOV planes to a multi-channel float EXR, a beauty preview to an
// 8-bit sRGB PNG. Both writers are atomic: they write a hidden temporary file in the target's directory,
// fsync it and rename(2) it over the target, so a reader (or a crash) never sees a half-written image at
// `path`. Every failure is a std::runtime_error whose one-line message names the path and the reason.
//
// Pixel layout everywhere: row-major, top row first, x to the right; index = y * width + x.
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace hdeye {

/// How a plane is stored in an EXR: a 32-bit FLOAT or a 16-bit HALF channel.
enum class ChannelType { kFloat, kHalf };

/// A named float image plane, row-major, top row first, width*height values (of the data window).
/// The name is the EXR channel name as is: "R", "albedo.R", "N.X", "depth.Z", "primId", "irisMnee.R".
struct ImagePlane {
  std::string name;
  std::vector<float> pixels;
  ChannelType type = ChannelType::kFloat;  ///< kHalf: values beyond +-65504 (HALF_MAX) are clamped to it
};

/// One part of a multi-part EXR: its name (the header's "name" attribute) and its planes.
struct ImagePart {
  std::string name;
  std::vector<ImagePlane> planes;
};

/// Pixel bounds within the display window, inclusive, rows top down (OpenEXR's Box2i).
struct PixelWindow {
  int x0 = 0, y0 = 0, x1 = -1, y1 = -1;
};

/// Writes `planes` as one single-part scanline EXR of width x height pixels (data and display window
/// (0,0)-(width-1,height-1)): one 32-bit FLOAT channel per plane, named exactly as the plane, ZIP
/// compression. Atomic (see the top of this file); an existing file at `path` is replaced.
/// Throws std::runtime_error, writing nothing, if: width or height is not positive; `planes` is empty;
/// a plane's name is empty or repeated; a plane has not width*height values; any value is NaN or
/// infinite (a renderer must never produce them, so they are a bug to report, not data to store: the
/// message names the plane and the first bad pixel); the directory of `path` does not exist; or the
/// file cannot be written or renamed.
/// `attributes` are extra header attributes, each an OpenEXR string attribute (name, value), e.g.
/// ("eyerender:plan", the render plan's JSON); a name that is empty, repeated, or one of the header's
/// required attributes (channels, compression, dataWindow, ...) is an error, writing nothing.
void WriteExr(const std::string& path, int width, int height, const std::vector<ImagePlane>& planes,
              const std::vector<std::pair<std::string, std::string>>& attributes = {});

/// Writes `parts` as one EXR whose display window is width x height pixels and whose data window is
/// `dataWindow` (an empty one, x1 < x0: the whole display window); every plane holds the data window's
/// pixels. One part: a single-part scanline file, as WriteExr (the part's name unused); several, or
/// `multiPart`: a multi-part file (OpenEXR 2), each part a scanline image named as the part, with the
/// same `attributes`. Channels are FLOAT or HALF as each plane says. Atomic; throws like WriteExr, and
/// also for a data window outside the display window, or parts without names or with repeated ones.
void WriteExrParts(const std::string& path, int width, int height, const std::vector<ImagePart>& parts,
                   const std::vector<std::pair<std::string, std::string>>& attributes = {},
                   const PixelWindow& dataWindow = {}, bool multiPart = false);

/// Every string attribute of the EXR header at `path` (its first part), by name. Throws
/// std::runtime_error if the file is missing or not a readable EXR.
std::map<std::string, std::string> ReadExrStringAttributes(const std::string& path);

/// Reads every channel of the EXR at `path` (its first part; scanline or tiled; HALF, FLOAT or UINT
/// channels, all converted to float) as planes of *width x *height values, where the size is that of
/// the data window. Planes come in the file's channel order, which OpenEXR sorts by name: not
/// necessarily the order given to WriteExr. Throws std::runtime_error if the file is missing or not a
/// readable EXR, or has subsampled channels. `width` and `height` may be null.
std::vector<ImagePlane> ReadExr(const std::string& path, int* width, int* height);

/// Writes an 8-bit RGB PNG preview (sRGB-tagged) of linear scene-referred RGB: `rgb` holds 3 floats
/// (R, G, B) per pixel, width*height pixels. Each component x becomes
///   round(255 * LinearToSrgb(clamp(x * 2^exposure, 0, 1))),
/// i.e. the tone map is a plain clamp to [0,1] (no roll-off: values above 1 after exposure saturate to
/// 255). `exposure` is in stops. Atomic, like WriteExr. Throws std::runtime_error if the sizes are
/// wrong, exposure or any value is NaN or infinite (the message names the first bad pixel), or the file
/// cannot be written.
void WritePngPreview(const std::string& path, int width, int height, const std::vector<float>& rgb, float exposure = 0);

/// Returns the sRGB-encoded value in [0,1] of linear x (IEC 61966-2-1 piecewise curve: 12.92 x below
/// x = 0.0031308, else 1.055 x^(1/2.4) - 0.055). x is clamped to [0,1] first; NaN stays NaN.
float LinearToSrgb(float x);

}  // namespace hdeye
