#include "hdeye/render/renderLight.h"

#include "hdeye/render/blackbody.h"
#include "hdeye/render/sampleDirections.h"

#include <eyelib/sampling.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace hdeye {

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kInf = std::numeric_limits<double>::infinity();

using eyelib::UniformConePdf;

// sin^2 of a sphere's angular radius below which it is sampled as its centre (1e-5 rad: the point limit's
// relative error, of order the angle, is then below the sampling noise of any render).
constexpr double kPointLimitSin2 = 1e-10;

/// Area pdf to solid angle pdf.
double AreaToSolidAngle(double areaPdf, double distance, double cosAtLight) {
  return cosAtLight > 0 ? areaPdf * distance * distance / cosAtLight : 0;
}

double PlanarArea(const RenderLight& l) {
  return l.type == LightType::Rect ? 4 * glm::length(glm::cross(l.axisU, l.axisV)) : kPi * l.radius * l.radius;
}

/// Density over a cylinder light's side of the point SampleLight picks from p: uniform along its length
/// and over the arc of its cross-section p sees, of half-angle acos(r / rho), rho p's distance from the axis.
/// 0 from inside the cylinder (rho <= r).
double CylinderAreaPdf(const RenderLight& l, const glm::dvec3& p) {
  const glm::dvec3 toP = p - l.position, perp = toP - glm::dot(toP, l.axisU) * l.axisU;
  const double rho = glm::length(perp);
  if (!(rho > l.radius) || !(l.radius > 0) || !(l.halfLength > 0)) return 0;
  return 1 / (2 * std::acos(l.radius / rho) * l.radius * 2 * l.halfLength);
}

/// UsdLux's sizeFactor of a distant light of half-angle theta (radians): what normalize divides by, so that
/// its radiance times sizeFactor is the illuminance of a surface facing it.
double DistantSizeFactor(double theta) {
  if (!(theta > 0)) return 1;
  const double s2 = std::sin(theta) * std::sin(theta);
  return theta <= kPi / 2 ? kPi * s2 : kPi * (2 - s2);
}

ShapingRt ShapingOf(const LightShaping& s) {
  ShapingRt r;
  if (!s.enabled) return r;
  r.enabled = true;
  r.cutoff = std::clamp(double(s.coneAngle), 0.0, 180.0) * kPi / 180;
  r.smoothStart = r.cutoff * (1 - std::clamp(double(s.coneSoftness), 0.0, 1.0));
  r.focus = s.focus > 0 ? double(s.focus) : 0.0;
  r.focusTint = glm::dvec3(s.focusTint);
  if (!s.ies.Empty()) {
    r.iesProfileScale = std::max(0.0, 1.0 + double(s.iesAngleScale));
    const double mean = s.ies.MeanIntensity();
    // A profile that is dark everywhere has no shape to normalize: it stays dark.
    r.iesFactor = s.iesNormalize ? (mean > 0 ? 1 / mean : 0.0) : 1.0;
    r.ies = std::make_shared<const IesProfile>(s.ies);
  }
  return r;
}

double Luminance(const glm::vec3& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

/// The rotation part of m's upper 3x3 (Gram-Schmidt on its columns, keeping the handedness of a
/// right-handed frame); identity if degenerate.
glm::dmat3 RotationOf(const glm::dmat4& m) {
  glm::dvec3 x(m[0]), y(m[1]);
  const double lx = glm::length(x);
  if (!(lx > 0) || !std::isfinite(lx)) return glm::dmat3(1.0);
  x /= lx;
  y -= glm::dot(y, x) * x;
  const double ly = glm::length(y);
  if (!(ly > 0) || !std::isfinite(ly)) return glm::dmat3(1.0);
  y /= ly;
  return glm::dmat3(x, y, glm::cross(x, y));
}

// The dome's lat-long parameterisation (see DomeTexture in renderLight.h).
glm::dvec3 LatLongToDirection(const glm::dvec2& uv) {
  const double lat = kPi * (uv.y - 0.5), lon = kPi * (1 - 2 * uv.x);
  return {std::cos(lat) * std::sin(lon), std::sin(lat), std::cos(lat) * std::cos(lon)};
}
/// (u, v) in [0, 1]^2 of a unit local direction; *cosLat = sin(theta) = the lat-long Jacobian factor.
glm::dvec2 DirectionToLatLong(const glm::dvec3& d, double* cosLat) {
  *cosLat = std::sqrt(d.x * d.x + d.z * d.z);
  const double lat = std::asin(std::clamp(d.y, -1.0, 1.0)), lon = std::atan2(d.x, d.z);
  double u = 0.5 - lon / (2 * kPi);
  if (u >= 1) u -= 1;
  if (u < 0) u = 0;
  return {u, std::clamp(0.5 + lat / kPi, 0.0, 1.0)};
}
/// Solid-angle pdf from the (u, v) density: d omega = 2 pi^2 sin(theta) du dv.
double UvToSolidAngle(double pdfUv, double cosLat) { return cosLat > 1e-12 ? pdfUv / (2 * kPi * kPi * cosLat) : 0; }
/// Radiance of a rect light at local point a axisU + b axisV (a, b in [-1, 1]; see RenderLight::rectImage).
glm::dvec3 RectRadiance(const RenderLight& l, double a, double b) {
  if (!l.rectImage) return l.radiance;
  return l.radiance * glm::dvec3(l.rectImage->Lookup(glm::vec2(float((1 - a) / 2), float((1 + b) / 2))));
}

/// Radiance of the textured dome at (u, v): clamped at the poles (repeat would blend the two poles).
glm::dvec3 DomeRadiance(const RenderLight& l, glm::dvec2 uv) {
  const Texture& image = *l.dome->image;
  const double halfTexel = 0.5 / image.Height();
  uv.y = std::clamp(uv.y, halfTexel, 1 - halfTexel);
  return l.radiance * glm::dvec3(image.Lookup(glm::vec2(uv)));
}
}  // namespace

std::shared_ptr<const DomeTexture> DomeTexture::Build(std::shared_ptr<const Texture> image) {
  if (!image) throw std::invalid_argument("DomeTexture::Build: no image");
  const std::vector<glm::vec3> texels = image->Texels();
  if (texels.empty())
    throw std::invalid_argument("DomeTexture::Build: " +
                                (image->Valid() ? std::string("a UDIM set is no lat-long image") : image->Error()));
  const int w = image->Width(), h = image->Height();
  std::vector<double> luminance(std::size_t(w) * std::size_t(h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      luminance[std::size_t(y) * w + x] = std::max(0.0, Luminance(texels[std::size_t(y) * w + x]));
  // Distribution row r is image row h-1-r (v = 0 at the bottom).
  std::vector<double> weights(luminance.size());
  for (int r = 0; r < h; ++r) {
    const int y = h - 1 - r;
    const double sinTheta = std::cos(kPi * ((r + 0.5) / h - 0.5));
    for (int x = 0; x < w; ++x) {
      double m = 0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int yy = std::clamp(y + dy, 0, h - 1), xx = (x + dx + w) % w;
          m = std::max(m, luminance[std::size_t(yy) * w + xx]);
        }
      weights[std::size_t(r) * w + x] = m * sinTheta;
    }
  }
  auto dome = std::make_shared<DomeTexture>();
  dome->image = std::move(image);
  dome->distribution = Distribution2D(w, h, weights);
  return dome;
}

RenderLight RenderLight::FromParams(const LightParams& p, const glm::dmat4& m, std::shared_ptr<const DomeTexture> dome,
                                    std::shared_ptr<const Texture> rectImage) {
  RenderLight l;
  l.type = p.type;
  glm::dvec3 color(p.color);
  if (p.enableColorTemperature) color *= BlackbodyColor(p.colorTemperature);
  l.radiance = color * double(p.intensity) * std::exp2(double(p.exposure));
  l.position = glm::dvec3(m * glm::dvec4(0, 0, 0, 1));
  const glm::dvec3 x(m * glm::dvec4(1, 0, 0, 0)), y(m * glm::dvec4(0, 1, 0, 0)), z(m * glm::dvec4(0, 0, 1, 0));
  const double scale = std::max({glm::length(x), glm::length(y), glm::length(z)});
  if (p.type != LightType::Dome && p.type != LightType::Distant) {
    l.direction = -glm::normalize(z);
    const glm::dmat3 frame = RotationOf(m);
    l.frameX = frame[0];
    l.frameY = frame[1];
    l.shaping = ShapingOf(p.shaping);
  }
  double sizeFactor = 1;  // UsdLux's, for normalize
  switch (p.type) {
    case LightType::Sphere:
      l.radius = p.radius * scale;
      sizeFactor = 4 * kPi * l.radius * l.radius;
      if (p.treatAsPoint) {
        // The sphere's radiant intensity in any direction (its silhouette pi r^2 times its radiance); with
        // normalize, L / 4 at any radius.
        l.radiance *= p.normalize ? 0.25 : kPi * l.radius * l.radius;
        l.radius = 0;
        l.delta = true;
        sizeFactor = 1;
      }
      break;
    case LightType::Distant: {
      l.direction = glm::normalize(z);
      const double half = std::clamp(double(p.angle) * kPi / 360, 0.0, kPi);
      l.cosHalfAngle = std::cos(half);
      l.delta = !(half > 0);
      sizeFactor = DistantSizeFactor(half);
      break;
    }
    case LightType::Rect:
      l.axisU = x * (p.width / 2.0);
      l.axisV = y * (p.height / 2.0);
      l.rectImage = std::move(rectImage);
      sizeFactor = PlanarArea(l);
      break;
    case LightType::Disk:
      l.axisU = glm::normalize(x);
      l.axisV = glm::normalize(y);
      l.radius = p.radius * scale;
      sizeFactor = PlanarArea(l);
      break;
    case LightType::Cylinder:
      l.axisU = glm::normalize(x);
      l.radius = p.radius * std::max(glm::length(y), glm::length(z));
      l.halfLength = p.length * glm::length(x) / 2;
      sizeFactor = 2 * kPi * l.radius * 2 * l.halfLength;
      if (p.treatAsLine) {
        // Per unit length, what the cylinder sends broadside on (its width 2 r times L); with normalize,
        // 2 r L / (2 pi r l) at any radius.
        l.radiance *= p.normalize ? 1 / (kPi * 2 * l.halfLength) : 2 * l.radius;
        l.delta = true;
        sizeFactor = 1;
      }
      break;
    case LightType::Dome:
      if (!p.textureFile.empty()) {
        if (!dome) {
          auto image = Texture::Open(TextureParams::Image(p.textureFile, TextureWrap::Clamp));
          if (!image->Valid()) throw std::runtime_error(image->Error());
          dome = DomeTexture::Build(std::move(image));
        }
        l.dome = std::move(dome);
        // +90 degrees about x takes the +y pole to +z (columns: the images of x, y, z).
        const glm::dmat3 poleZ(glm::dvec3(1, 0, 0), glm::dvec3(0, 0, 1), glm::dvec3(0, -1, 0));
        l.domeToWorld = p.domePoleZ ? RotationOf(m) * poleZ : RotationOf(m);
      }
      break;
  }
  // A zero-size light has nothing to divide by: it stays dark rather than infinite.
  if (p.normalize && sizeFactor != 1) l.radiance = sizeFactor > 0 ? l.radiance / sizeFactor : glm::dvec3(0);
  // An intensity x 2^exposure (or its normalized value) past double's range has no finite radiance to render:
  // the light is off (the scene delegate reports such lights).
  if (!std::isfinite(l.radiance.x + l.radiance.y + l.radiance.z)) l.radiance = glm::dvec3(0);
  return l;
}

glm::dvec3 EmissionShaping(const RenderLight& l, const glm::dvec3& emitDir) {
  const ShapingRt& s = l.shaping;
  if (!s.enabled) return glm::dvec3(1);
  const double cosOff = std::clamp(glm::dot(emitDir, l.direction), -1.0, 1.0), offAxis = std::acos(cosOff);
  if (offAxis > s.cutoff) return glm::dvec3(0);
  double cone = 1;
  if (s.cutoff > s.smoothStart && offAxis > s.smoothStart) {
    const double t = (offAxis - s.smoothStart) / (s.cutoff - s.smoothStart);
    cone = 1 - t * t * (3 - 2 * t);
  }
  if (s.ies) {
    cone *= IesShaping(s, {glm::dot(emitDir, l.frameX), glm::dot(emitDir, l.frameY), -cosOff});
    if (cone == 0) return glm::dvec3(0);
  }
  if (!(s.focus > 0)) return glm::dvec3(cone);
  const double focus = std::pow(std::abs(cosOff), s.focus);
  return cone * (s.focusTint + (glm::dvec3(1) - s.focusTint) * focus);
}

double IesShaping(const ShapingRt& s, const glm::dvec3& localEmitDir) {
  if (!s.ies) return 1;
  const glm::dvec3 w = -localEmitDir;
  const double theta = std::acos(std::clamp(w.z, -1.0, 1.0)) * 180 / kPi;
  double phi = std::atan2(w.y, w.x) * 180 / kPi;
  if (phi < 0) phi += 360;
  // angleScale scales about theta = 180 degrees (RenderMan's profile scale); a scale of 0 (angleScale -1)
  // squeezes every direction but the back onto vertical angle 0.
  const double thetaIes =
      s.iesProfileScale > 0 ? std::clamp((theta - 180) / s.iesProfileScale + 180, 0.0, 180.0) : (theta < 180 ? 0 : 180);
  return s.ies->Intensity(thetaIes, phi) * s.iesFactor;
}

glm::dvec3 EmitterNormal(const RenderLight& l, const glm::dvec3& y) {
  if (l.type == LightType::Sphere) return glm::normalize(y - l.position);
  if (l.type == LightType::Cylinder) {
    const glm::dvec3 q = y - l.position;
    return glm::normalize(q - glm::dot(q, l.axisU) * l.axisU);
  }
  return l.direction;
}

glm::dvec3 EmittedRadiance(const RenderLight& l, const glm::dvec3& y, const glm::dvec3& emitDir) {
  glm::dvec3 radiance = l.radiance;
  if (l.type == LightType::Cylinder && l.delta)
    radiance *= 2 * l.halfLength * glm::length(glm::cross(emitDir, l.axisU));
  if (l.type == LightType::Rect && l.rectImage) {
    const glm::dvec3 q = y - l.position;
    const double a = glm::dot(q, l.axisU) / glm::dot(l.axisU, l.axisU),
                 b = glm::dot(q, l.axisV) / glm::dot(l.axisV, l.axisV);
    radiance = RectRadiance(l, std::clamp(a, -1.0, 1.0), std::clamp(b, -1.0, 1.0));
  }
  return radiance * EmissionShaping(l, emitDir);
}

namespace {

/// A sphere light (or, delta, a point) sampled from p: the cone it subtends, or its centre when that cone is too
/// narrow.
void SampleSphereLight(const RenderLight& l, const glm::dvec3& p, double u1, double u2, LightSample* s) {
  const glm::dvec3 toC = l.position - p;
  const double d = glm::length(toC);
  if (!std::isfinite(d)) return;
  if (l.delta) {  // a point: intensity / d^2 from its one direction
    if (!(d > 0)) return;
    s->dir = toC / d;
    s->distance = d;
    s->radiance = l.radiance * EmissionShaping(l, -s->dir) / (d * d);
    if (!std::isfinite(s->radiance.x + s->radiance.y + s->radiance.z)) {  // too near
      *s = LightSample{};
      return;
    }
    s->pdf = 1;
    s->delta = true;
    return;
  }
  if (!(d > l.radius)) return;  // inside the light: not sampled
  // The cone's 1 - cos = sin^2 / (1 + cos) (OneMinusCosFromSin2) and its pdf 1 / (2 pi (1 - cos)) as two
  // divisions side by side, after the one reciprocal of d that also makes the unit direction.
  const double invD = 1 / d, sinT = l.radius * invD, sin2 = sinT * sinT;
  const double onePlusCos = 1 + std::sqrt(std::max(0.0, 1 - sin2));
  const double cone = sin2 / onePlusCos, pdf = onePlusCos / (2 * kPi * sin2);
  // A zero radius (or one whose cone underflows) emits nothing: UsdLux intensity is radiance.
  if (!(cone > 0) || !std::isfinite(pdf)) return;
  s->pdf = pdf;
  const glm::dvec3 w = toC * invD;
  if (sin2 < kPointLimitSin2) {
    s->dir = w;
    s->distance = d;
    s->radiance = l.radiance * EmissionShaping(l, -s->dir);
    s->pointLimit = true;
    return;
  }
  s->dir = SampleConeAbout(w, cone, u1, u2);
  // Distance to the sphere along dir (the near root).
  const double b = glm::dot(s->dir, toC), c = d * d - l.radius * l.radius;
  s->distance = b - std::sqrt(std::max(0.0, b * b - c));
  s->radiance = l.radiance * EmissionShaping(l, -s->dir);
}

/// A distant light sampled: its cone of directions (delta: its one direction).
void SampleDistantLight(const RenderLight& l, double u1, double u2, LightSample* s) {
  if (l.delta) {  // a parallel beam: its irradiance from one direction
    s->dir = l.direction, s->distance = kInf, s->radiance = l.radiance, s->pdf = 1, s->delta = true;
    return;
  }
  s->dir = SampleConeAbout(l.direction, 1 - l.cosHalfAngle, u1, u2);
  s->distance = kInf;
  s->radiance = l.radiance;
  s->pdf = UniformConePdf(l.cosHalfAngle);
}

/// A dome light sampled: by its image's luminance x sin(theta), or uniformly over the sphere for a constant dome.
void SampleDomeLight(const RenderLight& l, double u1, double u2, LightSample* s) {
  if (l.dome) {
    // Importance sampling by luminance x sin(theta) over the lat-long image.
    double pdfUv = 0;
    const glm::dvec2 uv = l.dome->distribution.Sample(u1, u2, &pdfUv);
    const glm::dvec3 local = LatLongToDirection(uv);
    s->pdf = UvToSolidAngle(pdfUv, std::cos(kPi * (uv.y - 0.5)));
    if (!(s->pdf > 0) || !std::isfinite(s->pdf)) {
      *s = LightSample{};
      return;
    }
    s->dir = glm::normalize(l.domeToWorld * local);
    s->distance = kInf;
    s->radiance = DomeRadiance(l, uv);
    return;
  }
  // Uniform sphere (a constant dome gains nothing from importance sampling).
  const double z = 1 - 2 * u1, r = std::sqrt(std::max(0.0, 1 - z * z));
  double sinPhi, cosPhi;
  SinCos2Pi(u2, &sinPhi, &cosPhi);
  s->dir = {r * cosPhi, r * sinPhi, z};
  s->distance = kInf;
  s->radiance = l.radiance;
  s->pdf = 1 / (4 * kPi);
}

/// A cylinder light (or, delta, a line) sampled from p: a point on its axis, then on the arc of the side p sees.
void SampleCylinderLight(const RenderLight& l, const glm::dvec3& p, double u1, double u2, LightSample* s) {
  if (!(l.halfLength > 0)) return;
  const double along = (2 * u1 - 1) * l.halfLength;
  glm::dvec3 q = l.position + along * l.axisU;
  double pdfArea = 0;
  glm::dvec3 normal(0);
  if (!l.delta) {
    // A point on the arc of the side p sees (CylinderAreaPdf): the half-angle acos(r / rho) about the
    // direction from the axis towards p.
    pdfArea = CylinderAreaPdf(l, p);
    if (!(pdfArea > 0)) return;  // inside the light, or a zero radius: nothing to sample
    const glm::dvec3 toP = p - l.position, perp = toP - glm::dot(toP, l.axisU) * l.axisU;
    const double rho = glm::length(perp), phi = (2 * u2 - 1) * std::acos(l.radius / rho);
    const glm::dvec3 e1 = perp / rho, e2 = glm::cross(l.axisU, e1);
    normal = std::cos(phi) * e1 + std::sin(phi) * e2;
    q += l.radius * normal;
  }
  const glm::dvec3 toQ = q - p;
  s->distance = glm::length(toQ);
  if (!(s->distance > 0) || !std::isfinite(s->distance)) {
    *s = LightSample{};
    return;
  }
  s->dir = toQ / s->distance;
  if (l.delta) {  // a line: one point of it stands for its whole length (EmittedRadiance)
    s->radiance = EmittedRadiance(l, q, -s->dir) / (s->distance * s->distance);
    if (!std::isfinite(s->radiance.x + s->radiance.y + s->radiance.z)) {  // on the line
      *s = LightSample{};
      return;
    }
    s->pdf = 1;
    s->delta = true;
    return;
  }
  s->pdf = AreaToSolidAngle(pdfArea, s->distance, glm::dot(-s->dir, normal));
  if (!std::isfinite(s->pdf)) {
    *s = LightSample{};
    return;
  }
  if (s->pdf > 0) s->radiance = l.radiance * EmissionShaping(l, -s->dir);
}

/// A rect or disk light sampled from p: a uniform point on its area.
void SamplePlanarLight(const RenderLight& l, const glm::dvec3& p, double u1, double u2, LightSample* s) {
  if (!(PlanarArea(l) > 0)) return;  // a zero width, height or radius emits nothing
  glm::dvec3 q;
  glm::dvec3 radiance = l.radiance;
  if (l.type == LightType::Rect) {
    q = l.position + (2 * u1 - 1) * l.axisU + (2 * u2 - 1) * l.axisV;
    radiance = RectRadiance(l, 2 * u1 - 1, 2 * u2 - 1);
  } else {
    const double r = l.radius * std::sqrt(u1);
    double sinPhi, cosPhi;
    SinCos2Pi(u2, &sinPhi, &cosPhi);
    q = l.position + r * (cosPhi * l.axisU + sinPhi * l.axisV);
  }
  const glm::dvec3 toQ = q - p;
  s->distance = glm::length(toQ);
  if (!(s->distance > 0) || !std::isfinite(s->distance)) return;
  s->dir = toQ / s->distance;
  s->pdf = AreaToSolidAngle(1 / PlanarArea(l), s->distance, glm::dot(-s->dir, l.direction));
  if (!std::isfinite(s->pdf)) {  // too small to sample from here: it overflows
    *s = LightSample{};
    return;
  }
  if (s->pdf > 0) s->radiance = radiance * EmissionShaping(l, -s->dir);
}

}  // namespace

LightSample SampleLight(const RenderLight& l, const glm::dvec3& p, double u1, double u2) {
  // The samplers fill `s` in place (cleared where nothing is sampled), so it is built in the caller's slot: a
  // `return LightSample{}` among them made it a stack copy, read back with loads straddling its stores.
  LightSample s;
  switch (l.type) {
    case LightType::Sphere: SampleSphereLight(l, p, u1, u2, &s); break;
    case LightType::Distant: SampleDistantLight(l, u1, u2, &s); break;
    case LightType::Dome: SampleDomeLight(l, u1, u2, &s); break;
    case LightType::Cylinder: SampleCylinderLight(l, p, u1, u2, &s); break;
    case LightType::Rect:
    case LightType::Disk: SamplePlanarLight(l, p, u1, u2, &s); break;
  }
  return s;
}

bool IntersectLight(const RenderLight& l, const glm::dvec3& p, const glm::dvec3& dir, double maxDistance,
                    glm::dvec3* radiance, double* pdf, double* distance) {
  if (l.delta) return false;
  switch (l.type) {
    case LightType::Sphere: {
      const glm::dvec3 toC = l.position - p;
      const double d2 = glm::dot(toC, toC);
      if (!(d2 > l.radius * l.radius)) return false;
      const double b = glm::dot(dir, toC), disc = b * b - (d2 - l.radius * l.radius);
      if (disc < 0) return false;
      const double t = b - std::sqrt(disc);
      if (!(t > 0) || t >= maxDistance) return false;
      *radiance = l.radiance * EmissionShaping(l, -dir);
      // 1 / (2 pi (1 - cos)) = (1 + cos) / (2 pi sin^2) = (d2 + d sqrt(d2 - r^2)) / (2 pi r^2): one division.
      const double r2 = l.radius * l.radius;
      *pdf = (d2 + std::sqrt(d2) * std::sqrt(d2 - r2)) / (2 * kPi * r2);
      *distance = t;
      return true;
    }
    case LightType::Distant:
      if (maxDistance < kInf || glm::dot(dir, l.direction) < l.cosHalfAngle) return false;
      *radiance = l.radiance;
      *pdf = UniformConePdf(l.cosHalfAngle);
      *distance = kInf;
      return true;
    case LightType::Dome:
      if (maxDistance < kInf) return false;
      *distance = kInf;
      if (l.dome) {
        double cosLat = 0;
        // The rotation is orthonormal: its transpose is its inverse.
        const glm::dvec2 uv = DirectionToLatLong(glm::normalize(glm::transpose(l.domeToWorld) * dir), &cosLat);
        *radiance = DomeRadiance(l, uv);
        *pdf = UvToSolidAngle(l.dome->distribution.Pdf(uv), cosLat);
        return true;
      }
      *radiance = l.radiance;
      *pdf = 1 / (4 * kPi);
      return true;
    case LightType::Cylinder: {
      // The side's outside only (the caps do not emit): the near root of the infinite cylinder, within the length.
      const double pdfArea = CylinderAreaPdf(l, p);
      if (!(pdfArea > 0)) return false;
      const glm::dvec3 o = p - l.position, op = o - glm::dot(o, l.axisU) * l.axisU,
                       dp = dir - glm::dot(dir, l.axisU) * l.axisU;
      const double a = glm::dot(dp, dp), b = glm::dot(op, dp), c = glm::dot(op, op) - l.radius * l.radius;
      const double disc = b * b - a * c;
      if (!(a > 0) || disc < 0) return false;
      const double t = (-b - std::sqrt(disc)) / a;
      if (!(t > 0) || t >= maxDistance) return false;
      const glm::dvec3 hit = o + t * dir;
      const double along = glm::dot(hit, l.axisU);
      if (std::abs(along) > l.halfLength) return false;
      const double cosL = -glm::dot(dir, (hit - along * l.axisU) / l.radius);
      if (!(cosL > 0)) return false;
      *radiance = l.radiance * EmissionShaping(l, -dir);
      *pdf = AreaToSolidAngle(pdfArea, t, cosL);
      *distance = t;
      return true;
    }
    case LightType::Rect:
    case LightType::Disk: {
      const double cosL = glm::dot(-dir, l.direction);
      if (!(cosL > 0) || !(PlanarArea(l) > 0)) return false;  // one-sided; a zero-area light is never hit
      const double t = glm::dot(l.position - p, l.direction) / glm::dot(dir, l.direction);
      if (!(t > 0) || t >= maxDistance) return false;
      const glm::dvec3 q = p + t * dir - l.position;
      *radiance = l.radiance;
      if (l.type == LightType::Rect) {
        const double a = glm::dot(q, l.axisU) / glm::dot(l.axisU, l.axisU),
                     b = glm::dot(q, l.axisV) / glm::dot(l.axisV, l.axisV);
        if (std::abs(a) > 1 || std::abs(b) > 1) return false;
        *radiance = RectRadiance(l, a, b);
      } else if (glm::dot(q, q) > l.radius * l.radius) {
        return false;
      }
      *radiance *= EmissionShaping(l, -dir);
      *pdf = AreaToSolidAngle(1 / PlanarArea(l), t, cosL);
      *distance = t;
      return true;
    }
  }
  return false;
}

}  // namespace hdeye
