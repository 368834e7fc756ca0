#pragma once
// How one texture is read (UsdUVTexture's inputs), as a value: what a material or light carries. Opening and looking
// it up is the renderer's (render/texture.h, over OpenImageIO).
#include <glm/glm.hpp>

#include <string>

namespace hdeye {

/// UsdUVTexture's wrapS / wrapT. UseMetadata takes the file's own wrap metadata (OIIO's "wrapmodes",
/// which maketx writes), black when the file has none.
enum class TextureWrap { UseMetadata, Black, Clamp, Repeat, Mirror };

/// UsdUVTexture's sourceColorSpace. Auto: the file's colour-space metadata if it says linear, else sRGB
/// for 8-bit images of 3 or 4 channels and raw for everything else (single-channel masks, 16-bit and
/// float images), as Hydra's Storm decides.
enum class TextureColorSpace { Auto, Raw, Srgb };

/// How one texture is read: UsdUVTexture's inputs. Values are RGBA; a 1-channel file gives (g, g, g, 1),
/// a 2-channel one (g, g, g, a), a 3-channel one alpha 1.
struct TextureParams {
  std::string file;  ///< an image path; "<UDIM>" in it names a UDIM set (tile 1001 + u + 10 v)
  TextureWrap wrapS = TextureWrap::UseMetadata, wrapT = TextureWrap::UseMetadata;
  TextureColorSpace colorSpace = TextureColorSpace::Auto;
  glm::vec4 scale{1, 1, 1, 1};  ///< result = decoded texel * scale + bias
  glm::vec4 bias{0, 0, 0, 0};
  glm::vec4 fallback{1, 0, 1, 1};  ///< returned as is where the file cannot be read (magenta: visible)

  /// A plain colour image (iris, dome): repeat in s, `wrapT` in t, colour space auto, magenta fallback.
  static TextureParams Image(std::string file, TextureWrap wrapT = TextureWrap::Repeat);
  bool operator==(const TextureParams& o) const;
};

}  // namespace hdeye
