#include "hdeye/params/textureParams.h"

#include <utility>

namespace hdeye {

TextureParams TextureParams::Image(std::string file, TextureWrap wrapT) {
  TextureParams p;
  p.file = std::move(file);
  p.wrapS = TextureWrap::Repeat;
  p.wrapT = wrapT;
  return p;
}

bool TextureParams::operator==(const TextureParams& o) const {
  return file == o.file && wrapS == o.wrapS && wrapT == o.wrapT && colorSpace == o.colorSpace && scale == o.scale &&
         bias == o.bias && fallback == o.fallback;
}

}  // namespace hdeye
