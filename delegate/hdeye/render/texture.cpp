#include "hdeye/render/texture.h"

#include <OpenImageIO/imagecache.h>
#include <OpenImageIO/imageio.h>
#include <OpenImageIO/texture.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <system_error>

namespace hdeye {
namespace {

namespace oiio = OIIO;

/// Most probes along an anisotropic footprint (OIIO's default is 32). 8 keeps grazing views sharp enough
/// for path tracing, where many samples per pixel average the rest, at a fraction of the lookups.
constexpr int kMaxAnisotropy = 8;

/// The process-wide TextureSystem, configured once. automip: files without MIP levels get them built
/// in memory (a PNG or JPEG is then filtered like a .tx). unassociatedalpha: UsdUVTexture's rgb and a
/// are independent outputs, so PNG colour must not be premultiplied by its alpha.
oiio::TextureSystem* System() {
  static oiio::TextureSystem* system = [] {
    oiio::TextureSystem* ts = oiio::TextureSystem::create(/*shared=*/true);
    ts->attribute("automip", 1);
    ts->attribute("unassociatedalpha", 1);
    ts->attribute("failure_retries", 0);
    ts->attribute("max_memory_MB", 2048.0f);
    return ts;
  }();
  return system;
}

oiio::TextureOpt::Wrap ToOiio(TextureWrap w) {
  switch (w) {
    case TextureWrap::Black: return oiio::TextureOpt::WrapBlack;
    case TextureWrap::Clamp: return oiio::TextureOpt::WrapClamp;
    case TextureWrap::Repeat: return oiio::TextureOpt::WrapPeriodic;
    case TextureWrap::Mirror: return oiio::TextureOpt::WrapMirror;
    case TextureWrap::UseMetadata: break;
  }
  return oiio::TextureOpt::WrapDefault;  // the file's "wrapmodes", else black
}

/// sRGB-encoded value to linear (IEC 61966-2-1). Values outside [0, 1] (bicubic overshoot) keep the curve's sign.
float SrgbToLinear(float v) {
  const float a = std::fabs(v);
  const float l = a <= 0.04045f ? a / 12.92f : std::pow((a + 0.055f) / 1.055f, 2.4f);
  return std::copysign(l, v);
}

/// The first line of OIIO's pending error (clearing it), shortened so a warning stays one line.
std::string PendingError(const std::string& otherwise) {
  std::string e = System()->geterror();
  e = e.substr(0, e.find('\n'));
  if (e.empty()) return otherwise;
  return e.size() > 160 ? e.substr(0, 157) + "..." : e;
}

bool SaysLinear(const std::string& colorSpace) {
  std::string s = colorSpace;
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return s == "linear" || s == "scene_linear" || s == "lin_srgb" || s == "lin_rec709" || s == "raw";
}

/// For a JPEG, the decoder's complaint about its bytes, else "". libjpeg decodes a truncated or corrupt
/// stream without failing (it pads what is missing with grey and only warns, "Premature end of JPEG file"),
/// and OIIO's ImageCache drops that warning; an ImageInput keeps it in its error. Other formats' decoders
/// fail outright, which DecodeAll sees, so only JPEGs pay for this second decode.
std::string TruncationWarning(const std::string& file) {
  auto in = oiio::ImageInput::open(file);
  if (!in || std::string(in->format_name()) != "jpeg") {
    if (!in) oiio::geterror();  // the cache read it; drop the global error this open left
    return "";
  }
  const oiio::ImageSpec& spec = in->spec();
  std::vector<unsigned char> pixels(std::size_t(spec.width) * spec.height * std::size_t(spec.nchannels));
  const bool read = in->read_image(0, 0, 0, spec.nchannels, oiio::TypeUInt8, pixels.data());
  std::string e = in->geterror();
  e = e.substr(0, e.find('\n'));
  if (read && e.empty()) return "";
  if (e.empty()) e = "its pixels cannot be decoded";
  return e.size() > 160 ? e.substr(0, 157) + "..." : e;
}

/// Reads every texel of `file`'s coarsest MIP level (which OIIO builds from all of the finest, or reads
/// from a .tx): "" if they decode, else why not.
std::string DecodeAll(oiio::TextureSystem* ts, oiio::ustring file) {
  int levels = 1;
  ts->get_texture_info(file, 0, oiio::ustring("miplevels"), oiio::TypeInt, &levels);
  const int level = std::max(0, levels - 1);
  oiio::ImageCache* cache = ts->imagecache();
  oiio::ImageSpec coarse;
  if (!cache->get_imagespec(file, coarse, 0, level)) return PendingError("no MIP level");
  std::vector<float> pixels(std::size_t(coarse.width) * coarse.height * std::size_t(coarse.nchannels));
  if (!cache->get_pixels(file, 0, level, coarse.x, coarse.x + coarse.width, coarse.y, coarse.y + coarse.height, 0, 1,
                         oiio::TypeFloat, pixels.data()))
    return PendingError("its pixels cannot be decoded");
  return TruncationWarning(file.string());
}

/// DecodeAll's answer for `file`, computed once per process: the shared cache keeps what it decoded, and
/// a second read of a broken file need not fail again.
std::string KnownDecodeError(oiio::TextureSystem* ts, oiio::ustring file) {
  static std::mutex mutex;
  static std::unordered_map<std::string, std::string> known;
  std::lock_guard<std::mutex> lock(mutex);
  auto it = known.find(file.string());
  if (it == known.end()) it = known.emplace(file.string(), DecodeAll(ts, file)).first;
  return it->second;
}

}  // namespace

struct TextureThread {};  // only ever a reinterpreted OIIO::TextureSystem::Perthread

TextureThread* CurrentTextureThread() { return reinterpret_cast<TextureThread*>(System()->get_perthread_info()); }

std::shared_ptr<const Texture> Texture::Open(const TextureParams& params) {
  std::shared_ptr<Texture> texture(new Texture());
  texture->params_ = params;
  texture->OpenFile();
  return texture;
}

std::shared_ptr<const Texture> Texture::Load(const std::string& path) {
  std::shared_ptr<const Texture> texture = Open(TextureParams::Image(path));
  if (!texture->Valid()) throw std::runtime_error(texture->Error());
  return texture;
}

Texture::~Texture() = default;  // the handle belongs to the shared TextureSystem

void Texture::OpenFile() {
  oiio::TextureSystem* ts = System();
  const std::string& file = params_.file;
  auto fail = [&](const std::string& reason) { error_ = "cannot read texture " + file + ": " + reason; };
  if (file.empty()) return fail("no file name");
  const oiio::ustring name(file);
  udim_ = ts->is_udim(name);
  std::vector<oiio::ustring> files{name};
  if (udim_) {
    int nu = 0, nv = 0;
    files.clear();
    ts->inventory_udim(name, files, nu, nv);
    files.erase(std::remove(files.begin(), files.end(), oiio::ustring()), files.end());
    if (files.empty()) return fail("no UDIM tile matches the pattern");
  }
  for (const oiio::ustring& f : files) {
    std::error_code ec;
    if (!std::filesystem::exists(f.string(), ec))
      return fail(udim_ ? "tile " + f.string() + " not found" : "file not found");
    int exists = 0;
    ts->get_texture_info(f, 0, oiio::ustring("exists"), oiio::TypeInt, &exists);
    if (!exists) return fail(PendingError("not an image OpenImageIO can read"));
    const oiio::ImageSpec* spec = ts->imagespec(f, 0);
    if (!spec || spec->width <= 0 || spec->height <= 0 || spec->nchannels <= 0)
      return fail(PendingError("no image in the file"));
    if (f == files.front()) {
      width_ = spec->width, height_ = spec->height, channels_ = std::min(4, spec->nchannels);
      const bool eightBit = spec->format.basetype == oiio::TypeDesc::UINT8;
      switch (params_.colorSpace) {
        case TextureColorSpace::Raw: srgb_ = false; break;
        case TextureColorSpace::Srgb: srgb_ = true; break;
        case TextureColorSpace::Auto:
          srgb_ = eightBit && channels_ >= 3 && !SaysLinear(spec->get_string_attribute("oiio:ColorSpace"));
          break;
      }
    }
    // Decode every texel now, so a truncated or corrupted file is found here rather than as holes at
    // render time.
    const std::string broken = KnownDecodeError(ts, f);
    if (!broken.empty()) return fail(broken);
  }
  handle_ = ts->get_texture_handle(name);
  if (!handle_) return fail(PendingError("OpenImageIO gave no handle"));
}

glm::vec4 Texture::Decode(const float raw[4]) const {
  glm::vec4 c;
  switch (channels_) {
    case 1: c = glm::vec4(raw[0], raw[0], raw[0], 1); break;
    case 2: c = glm::vec4(raw[0], raw[0], raw[0], raw[1]); break;
    case 3: c = glm::vec4(raw[0], raw[1], raw[2], 1); break;
    default: c = glm::vec4(raw[0], raw[1], raw[2], raw[3]); break;
  }
  if (srgb_)
    for (int i = 0; i < 3; ++i) c[i] = SrgbToLinear(c[i]);
  c = c * params_.scale + params_.bias;
  for (int i = 0; i < 4; ++i)
    if (!std::isfinite(c[i])) c[i] = 0;
  return c;
}

glm::vec4 Texture::Lookup(glm::vec2 st, const TextureFootprint& footprint, TextureThread* thread) const {
  if (!Valid() || !std::isfinite(st.x) || !std::isfinite(st.y)) return params_.fallback;
  oiio::TextureSystem* ts = System();
  oiio::TextureOpt opt;
  // Bilinear within a level (OIIO's default bicubic is a B-spline, which blurs even at the finest level):
  // a point lookup at a texel centre returns that texel, and the MIP filter does the averaging.
  opt.interpmode = oiio::TextureOpt::InterpBilinear;
  opt.anisotropic = kMaxAnisotropy;
  opt.swrap = ToOiio(params_.wrapS);
  opt.twrap = ToOiio(params_.wrapT);
  // OIIO's t runs down the image, USD's up. A UDIM set flips within each tile so that the tile row
  // stays floor(t) (tile 1011 holds USD t in [1, 2)); a single image flips about t = 1/2.
  float t = 1 - st.y;
  if (udim_) {
    const float row = std::floor(st.y);
    t = row + (1 - (st.y - row));
  }
  float raw[4] = {0, 0, 0, 1};
  const bool ok =
      ts->texture(reinterpret_cast<oiio::TextureSystem::TextureHandle*>(handle_),
                  reinterpret_cast<oiio::TextureSystem::Perthread*>(thread), opt, st.x, t, footprint.dstDx.x,
                  -footprint.dstDx.y, footprint.dstDy.x, -footprint.dstDy.y, channels_, raw);
  if (!ok) {  // a UDIM tile the set does not have, or a tile that failed to read
    if (ts->has_error()) ts->geterror();
    return params_.fallback;
  }
  return Decode(raw);
}

glm::vec3 Texture::Lookup(glm::vec2 st) const { return glm::vec3(Lookup(st, TextureFootprint{}, nullptr)); }

std::vector<glm::vec3> Texture::Texels() const {
  if (!Valid() || udim_) return {};
  std::vector<float> raw(std::size_t(width_) * std::size_t(height_) * std::size_t(channels_));
  oiio::ImageSpec spec;
  const oiio::ustring name(params_.file);
  if (!System()->imagecache()->get_imagespec(name, spec, 0, 0) ||
      !System()->imagecache()->get_pixels(name, 0, 0, spec.x, spec.x + width_, spec.y, spec.y + height_, 0, 1, 0,
                                          channels_, oiio::TypeFloat, raw.data())) {
    PendingError("");
    return {};
  }
  std::vector<glm::vec3> texels(std::size_t(width_) * std::size_t(height_));
  float px[4] = {0, 0, 0, 1};
  for (std::size_t i = 0; i < texels.size(); ++i) {
    for (int c = 0; c < channels_; ++c) px[c] = raw[i * std::size_t(channels_) + std::size_t(c)];
    texels[i] = glm::vec3(Decode(px));
  }
  return texels;
}

std::shared_ptr<const Texture> TextureCache::Get(const TextureParams& params) {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<std::shared_ptr<const Texture>>& variants = textures_[params.file];
  for (const auto& t : variants)
    if (t->Params() == params) return t;
  variants.push_back(Texture::Open(params));
  return variants.back();
}

std::string TextureProblem(const std::string& file) { return Texture::Open(TextureParams::Image(file))->Error(); }

}  // namespace hdeye
