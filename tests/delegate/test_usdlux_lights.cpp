// UsdLux as its specification writes it, rendered: a Lambert plane under each light type against the light's
// closed-form irradiance (normalize on and off, exposure, colour temperature, treatAsPoint, ShapingAPI's cone).
#include "hdeye/render/blackbody.h"
#include "hdeye/scene/sampleScenes.h"
#include "scene_helpers.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

using namespace hdeye;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kAlbedo = 0.5;

/// A light to place over the plane: its prim type, parameters and local-to-world transform.
struct PlacedLight {
  std::string type;
  LightParams params;
  Matrix4d transform;
};

/// `lights` over a Lambert plane (z = 0) of albedo 0.5 and an orthographic camera at `cameraHeight` looking down
/// (-z) at a `patch`-wide square at its centre (`pixels` wide). Returns the mean RGB of the plane's outgoing radiance
/// over the patch.
glm::dvec3 RenderUnderLights(const std::vector<PlacedLight>& lights, double cameraHeight, double patch = 0.02,
                             int pixels = 4, int spp = 128) {
  test::RenderStack s;
  test::AddLambertPlane(s.scene, 100, kAlbedo);
  for (std::size_t k = 0; k < lights.size(); ++k)
    s.scene.AddLight("/light" + (k ? std::to_string(k) : ""), lights[k].type, lights[k].params, lights[k].transform);
  CameraParams ortho;
  ortho.orthographic = true;
  ortho.horizontalAperture = ortho.verticalAperture = patch;
  s.scene.AddCamera("/cam", ortho, test::LookDownZ(cameraHeight));
  s.scene.AddRenderBuffer("/color", pixels, pixels, 4);
  s.delegate.Settings().samplesPerPixel = spp;
  s.pass.Execute("/cam", {{"color", "/color"}});
  glm::dvec3 sum(0);
  const RenderBuffer& b = s.Buffer("/color");
  for (int y = 0; y < pixels; ++y)
    for (int x = 0; x < pixels; ++x) sum += glm::dvec3(b.Resolved(x, y, 0), b.Resolved(x, y, 1), b.Resolved(x, y, 2));
  return sum / double(pixels * pixels);
}

/// One light at height `height` above the plane's centre, looking down (-z, so distant, rect and disk lights shine
/// onto it), `shift` moving it sideways (scene units); the camera halfway down (RenderUnderLights).
glm::dvec3 RenderUnderLight(const std::string& type, const LightParams& light, double height, double patch = 0.02,
                            int pixels = 4, int spp = 128, const glm::dvec3& shift = glm::dvec3(0)) {
  Matrix4d at = test::LookDownZ(height);
  at[3] += glm::dvec4(shift, 0);
  return RenderUnderLights({{type, light, at}}, height / 2, patch, pixels, spp);
}

/// The form factor of an a x b rectangle at height d from a point under one of its corners (Howell's catalogue,
/// C-11).
double RectCornerFormFactor(double a, double b, double d) {
  const double A = a / d, B = b / d;
  return (A / std::sqrt(1 + A * A) * std::atan(B / std::sqrt(1 + A * A)) +
          B / std::sqrt(1 + B * B) * std::atan(A / std::sqrt(1 + B * B))) /
         (2 * kPi);
}

/// Outgoing radiance of the Lambert plane under irradiance E.
double Lambert(double irradiance) { return kAlbedo * irradiance / kPi; }

void Report(const char* what, double got, double expected, const char* reference = "closed form") {
  std::printf("%-58s %.6g (%s %.6g, ratio %.5f)\n", what, got, reference, expected, got / expected);
}

}  // namespace

TEST_CASE("a distant light's intensity is the radiance of its disc, with normalize, the illuminance ", "[usdlux]") {
  LightParams sun;
  sun.intensity = 50000;  // UsdLux's fallback for a DistantLight, over its 0.53 degree disc
  sun.angle = 0.53f;
  const double half = 0.53 * kPi / 360, discSolidAngle = kPi * std::sin(half) * std::sin(half);
  const double off = RenderUnderLight(primTypes::kDistantLight, sun, 10).x;
  Report("distant 50000, angle 0.53, normalize off", off, Lambert(50000 * discSolidAngle));
  CHECK(off == Approx(Lambert(50000 * discSolidAngle)).epsilon(0.01));
  sun.intensity = 3;
  sun.normalize = true;
  const double on = RenderUnderLight(primTypes::kDistantLight, sun, 10).x;
  Report("distant 3 lux, normalize on", on, Lambert(3));
  CHECK(on == Approx(Lambert(3)).epsilon(0.01));
  sun.angle = 0;  // a parallel beam: sizeFactor 1, intensity is the illuminance either way
  sun.normalize = false;
  const double beam = RenderUnderLight(primTypes::kDistantLight, sun, 10).x;
  Report("distant angle 0 (parallel beam)", beam, Lambert(3));
  CHECK(beam == Approx(Lambert(3)).epsilon(1e-6));
}

TEST_CASE("exposure scales a light by 2^exposure ", "[usdlux]") {
  LightParams sun;
  sun.angle = 0;
  sun.intensity = 0.5f;
  sun.exposure = 2;
  const double got = RenderUnderLight(primTypes::kDistantLight, sun, 10).x;
  Report("distant 0.5 at exposure 2", got, Lambert(2));
  CHECK(got == Approx(Lambert(2)).epsilon(1e-6));
}

TEST_CASE("a sphere light below its centre gives pi L (R/d)^2, normalize divides L by 4 pi R^2 ", "[usdlux]") {
  const double R = 0.5, d = 4, L = 10;
  LightParams bulb;
  bulb.radius = float(R);
  bulb.intensity = float(L);
  const double off = RenderUnderLight(primTypes::kSphereLight, bulb, d).x;
  Report("sphere R 0.5 at 4, normalize off", off, Lambert(kPi * L * R * R / (d * d)));
  CHECK(off == Approx(Lambert(kPi * L * R * R / (d * d))).epsilon(0.01));
  bulb.normalize = true;
  const double on = RenderUnderLight(primTypes::kSphereLight, bulb, d).x;
  Report("sphere R 0.5 at 4, normalize on", on, Lambert(L / (4 * d * d)));
  CHECK(on == Approx(Lambert(L / (4 * d * d))).epsilon(0.01));
}

TEST_CASE("treatAsPoint renders the sphere's radiant intensity pi R^2 L as a point (L / 4 with normalize) ",
          "[usdlux]") {
  const double R = 0.5, d = 4, L = 10;
  LightParams point;
  point.radius = float(R);
  point.intensity = float(L);
  point.treatAsPoint = true;
  const double off = RenderUnderLight(primTypes::kSphereLight, point, d).x;
  Report("point (sphere R 0.5) at 4", off, Lambert(kPi * R * R * L / (d * d)));
  CHECK(off == Approx(Lambert(kPi * R * R * L / (d * d))).epsilon(1e-4));
  point.normalize = true;
  point.radius = 0;  // with normalize the radius does not matter, even 0
  const double on = RenderUnderLight(primTypes::kSphereLight, point, d).x;
  Report("point, radius 0, normalize on", on, Lambert(L / 4 / (d * d)));
  CHECK(on == Approx(Lambert(L / 4 / (d * d))).epsilon(1e-4));
}

TEST_CASE("a disk light facing the plane gives pi L R^2 / (R^2 + d^2), normalize divides L by pi R^2 ", "[usdlux]") {
  const double R = 1, d = 2, L = 4;
  LightParams disk;
  disk.radius = float(R);
  disk.intensity = float(L);
  const double off = RenderUnderLight(primTypes::kDiskLight, disk, d).x;
  Report("disk R 1 at 2, normalize off", off, Lambert(kPi * L * R * R / (R * R + d * d)));
  CHECK(off == Approx(Lambert(kPi * L * R * R / (R * R + d * d))).epsilon(0.01));
  disk.normalize = true;
  const double on = RenderUnderLight(primTypes::kDiskLight, disk, d).x;
  Report("disk R 1 at 2, normalize on", on, Lambert(L / (R * R + d * d)));
  CHECK(on == Approx(Lambert(L / (R * R + d * d))).epsilon(0.01));
}

TEST_CASE("a rect light facing the plane gives its four corner form factors, normalize divides L by w h ", "[usdlux]") {
  const double w = 2, h = 1, d = 1.5, L = 3;
  const double E = kPi * L * 4 * RectCornerFormFactor(w / 2, h / 2, d);
  LightParams rect;
  rect.width = float(w), rect.height = float(h), rect.intensity = float(L);
  const double off = RenderUnderLight(primTypes::kRectLight, rect, d).x;
  Report("rect 2 x 1 at 1.5, normalize off", off, Lambert(E));
  CHECK(off == Approx(Lambert(E)).epsilon(0.01));
  rect.normalize = true;
  const double on = RenderUnderLight(primTypes::kRectLight, rect, d).x;
  Report("rect 2 x 1 at 1.5, normalize on", on, Lambert(E / (w * h)));
  CHECK(on == Approx(Lambert(E / (w * h))).epsilon(0.01));
}

TEST_CASE("several lights: every one sampled at each vertex (up to eight), or one picked of more, sum their light ",
          "[usdlux]") {
  // A sphere straight above, a rect facing the plane below it and a constant dome: their closed forms add (lights are
  // transparent to one another: a BSDF-sampled ray towards the rect meets the sphere and the dome behind it too;
  // counting only the nearest light lost 9 % here). With nine lights (the sphere, the rect and seven domes sharing the
  // dome's radiance) next event estimation picks one per vertex (it lost 42 %).
  const double R = 0.5, d = 4, w = 2, h = 1, dr = 1.5, Ls = 10, Lr = 3, Ld = 0.7;
  const double expected =
      Lambert(kPi * Ls * R * R / (d * d) + kPi * Lr * 4 * RectCornerFormFactor(w / 2, h / 2, dr) + kPi * Ld);
  for (int domes : {1, 7}) {
    LightParams bulb, rect, dome;
    bulb.radius = float(R), bulb.intensity = float(Ls);
    rect.width = float(w), rect.height = float(h), rect.intensity = float(Lr);
    dome.intensity = float(Ld / domes);
    std::vector<PlacedLight> lights{{primTypes::kSphereLight, bulb, test::LookDownZ(d)},
                                    {primTypes::kRectLight, rect, test::LookDownZ(dr)}};
    for (int k = 0; k < domes; ++k) lights.push_back({primTypes::kDomeLight, dome, Matrix4d(1.0)});
    const double got = RenderUnderLights(lights, 0.5, 0.02, 4, 512).x;  // the camera under the rect
    Report(domes == 1 ? "sphere + rect + dome, every light sampled" : "sphere + rect + 7 domes, one light picked", got,
           expected, "sum of closed forms");
    CHECK(got == Approx(expected).epsilon(0.005));
  }
}

TEST_CASE("colour temperature: 6500 K is white, 3000 K is warm, both of the same luminance ", "[usdlux]") {
  LightParams sun;
  sun.angle = 0;
  sun.intensity = 2;
  sun.enableColorTemperature = true;
  sun.colorTemperature = 6500;
  const glm::dvec3 white = RenderUnderLight(primTypes::kDistantLight, sun, 10);
  sun.colorTemperature = 3000;
  const glm::dvec3 warm = RenderUnderLight(primTypes::kDistantLight, sun, 10);
  std::printf("6500 K: %.5f %.5f %.5f; 3000 K: %.5f %.5f %.5f\n", white.x, white.y, white.z, warm.x, warm.y, warm.z);
  CHECK(white.x == Approx(Lambert(2)).epsilon(1e-5));
  CHECK(white.y == Approx(Lambert(2)).epsilon(1e-5));
  CHECK(white.z == Approx(Lambert(2)).epsilon(1e-5));
  CHECK(warm.x > warm.y);
  CHECK(warm.y > warm.z);
  const auto luminance = [](const glm::dvec3& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; };
  CHECK(luminance(warm) == Approx(luminance(white)).epsilon(1e-4));
}

TEST_CASE("a blackbody's chromaticity follows the Planckian locus (Kim et al.'s cubic spline) ", "[usdlux]") {
  // Kim, Kang, Lee 2002 (the CIE's Planckian locus approximation), x(T) and y(x), 1667-25000 K.
  const auto locus = [](double T) {
    const double x = T <= 4000 ? -0.2661239e9 / (T * T * T) - 0.2343589e6 / (T * T) + 0.8776956e3 / T + 0.179910
                               : -3.0258469e9 / (T * T * T) + 2.1070379e6 / (T * T) + 0.2226347e3 / T + 0.240390;
    const double y = T <= 2222   ? -1.1063814 * x * x * x - 1.34811020 * x * x + 2.18555832 * x - 0.20219683
                     : T <= 4000 ? -0.9549476 * x * x * x - 1.37418593 * x * x + 2.09137015 * x - 0.16748867
                                 : 3.0817580 * x * x * x - 5.87338670 * x * x + 3.75112997 * x - 0.37001483;
    return glm::dvec2(x, y);
  };
  for (double T : {2000.0, 3000.0, 4000.0, 5000.0, 6500.0, 10000.0}) {
    const glm::dvec2 got = BlackbodyChromaticity(T), want = locus(T);
    std::printf("%6.0f K: xy %.4f %.4f (locus %.4f %.4f)\n", T, got.x, got.y, want.x, want.y);
    // 0.004: the multi-lobe fit of the matching functions is weakest in the red (0.0036 at 2000 K).
    CHECK(glm::length(got - want) < 0.004);
  }
  const glm::dvec3 white = BlackbodyColor(6500);
  CHECK(white.x == Approx(1).epsilon(1e-12));
  CHECK(white.z == Approx(1).epsilon(1e-12));
}

TEST_CASE("a spot light's cone: full inside, smoothstep over the softness, zero past the cone angle ", "[usdlux]") {
  // A point light 2 units above the plane with a 30 degree cone, softness 0.5 (smoothstep from 15 to 30
  // degrees): one row of pixels across the plane samples the falloff. E(x) = I S(theta) cos(theta) / r^2.
  const double d = 2, I = 1, span = 3;
  LightParams spot;
  spot.treatAsPoint = true;
  spot.normalize = true;
  spot.radius = 0;
  spot.intensity = float(4 * I);  // normalize: radiant intensity L / 4
  spot.shaping.enabled = true;
  spot.shaping.coneAngle = 30;
  spot.shaping.coneSoftness = 0.5f;
  test::RenderStack s;
  test::AddLambertPlane(s.scene, 100, kAlbedo);
  s.scene.AddLight("/spot", primTypes::kSphereLight, spot, test::LookDownZ(d));
  CameraParams ortho;
  ortho.orthographic = true;
  ortho.horizontalAperture = span;  // x from -1.5 to 1.5 (30 degrees is at x = 1.155)
  ortho.verticalAperture = span / 60;
  s.scene.AddCamera("/cam", ortho, test::LookDownZ(1));
  const int width = 120;
  s.scene.AddRenderBuffer("/color", width, 2, 4);
  s.delegate.Settings().samplesPerPixel = 1;  // a point light: pixel centres, no noise
  s.pass.Execute("/cam", {{"color", "/color"}});
  const RenderBuffer& b = s.Buffer("/color");
  const double deg = kPi / 180;
  double worst = 0;
  int inside = 0, soft = 0, outside = 0;
  for (int px = 0; px < width; ++px) {
    // Each row's pixel centre is a quarter of the vertical aperture off the axis.
    const double x = ((px + 0.5) / width - 0.5) * span, y = span / 60 / 4, rho = std::hypot(x, y);
    const double theta = std::atan(rho / d);
    const double t = std::clamp((theta - 15 * deg) / (15 * deg), 0.0, 1.0);
    const double S = theta > 30 * deg ? 0 : 1 - t * t * (3 - 2 * t), r2 = d * d + rho * rho;
    const double expected = Lambert(I * S * std::cos(theta) / r2);
    worst = std::max(worst, std::abs(b.Resolved(px, 0, 0) - expected));
    (S == 1 ? inside : S == 0 ? outside : soft)++;
  }
  std::printf("spot cone 30 deg, softness 0.5: %d px inside, %d in the falloff, %d outside; worst |error| %.2e\n",
              inside, soft, outside, worst);
  CHECK(inside > 10);
  CHECK(soft > 10);
  CHECK(outside > 10);
  CHECK(worst < 1e-5);
}

namespace {

/// One row of a Lambert plane 2 units below a point light of radiant intensity 1 shaped by `shaping` (its local
/// frame the world's), against `expected(theta, phi)`, the profile's intensity in degrees (phi as the light
/// sees it: from local +x towards +y of the direction from the plane to the light). Returns the worst relative
/// error over the pixels (float geometry and buffers: about 1e-5), printing `what`.
template <class Expected> double IesRowError(const char* what, const LightShaping& shaping, Expected expected) {
  const double d = 2, span = 6;
  LightParams point;
  point.treatAsPoint = true;
  point.normalize = true;
  point.radius = 0;
  point.intensity = 4;  // normalize: radiant intensity L / 4 = 1
  point.shaping = shaping;
  test::RenderStack s;
  test::AddLambertPlane(s.scene, 100, kAlbedo);
  s.scene.AddLight("/ies", primTypes::kSphereLight, point, test::LookDownZ(d));
  CameraParams ortho;
  ortho.orthographic = true;
  ortho.horizontalAperture = span;  // x from -3 to 3: up to 56 degrees off the axis, both sides
  ortho.verticalAperture = span / 60;
  s.scene.AddCamera("/cam", ortho, test::LookDownZ(1));
  const int width = 120;  // the aperture's aspect: square pixels
  s.scene.AddRenderBuffer("/color", width, 2, 4);
  s.delegate.Settings().samplesPerPixel = 1;
  s.pass.Execute("/cam", {{"color", "/color"}});
  const RenderBuffer& b = s.Buffer("/color");
  double worst = 0;
  for (int px = 0; px < width; ++px) {
    const double x = ((px + 0.5) / width - 0.5) * span, y = span / 60 / 4, rho = std::hypot(x, y);
    const double theta = std::atan(rho / d) * 180 / kPi, r2 = d * d + rho * rho;
    double phi = std::atan2(-y, -x) * 180 / kPi;  // towards the light: (-x, -y, d)
    if (phi < 0) phi += 360;
    const double want = Lambert(expected(theta, phi) * std::cos(theta * kPi / 180) / r2);
    worst = std::max(worst, std::abs(b.Resolved(px, 0, 0) - want) / want);
  }
  std::printf("%-58s worst relative error %.2e over %d px (0 to 56 deg)\n", what, worst, width);
  return worst;
}

/// A whole-sphere web, bilinear so its lookups are exact: I = (200 - theta) (1 + phi / 180) candela over vertical
/// angles 0, 90, 180 and horizontal 0, 180 (mirrored about the 0-180 plane).
LightShaping IesShapingForTest() {
  LightShaping s;
  s.enabled = true;
  s.coneAngle = 180;
  s.ies = ParseIes(
      "IESNA:LM-63-2002\n[TEST] a bilinear web\nTILT=NONE\n1 -1 1 3 2 1 2 0 0 0\n1 1 50\n"
      "0 90 180\n0 180\n200 110 20\n400 220 40\n");
  return s;
}

double IesForTest(double theta, double phi) {
  if (phi > 180) phi = 360 - phi;
  return (200 - theta) * (1 + phi / 180);
}

}  // namespace

TEST_CASE("an IES profile multiplies a point light by its candela at the direction's vertical and horizontal angle ",
          "[usdlux][ies]") {
  CHECK(IesRowError("IES web, angleScale 0", IesShapingForTest(), IesForTest) < 5e-5);
}

TEST_CASE("shaping:ies:angleScale looks the profile up at (theta - 180) / (1 + angleScale) + 180 ", "[usdlux][ies]") {
  LightShaping s = IesShapingForTest();
  s.iesAngleScale = 1;  // theta 0..56 reads the web at 90..118
  CHECK(IesRowError("IES web, angleScale 1", s,
                    [](double theta, double phi) { return IesForTest(90 + theta / 2, phi); }) < 5e-5);
  s.iesAngleScale = -0.5f;  // 2 theta - 180 < 0: every direction of the lower hemisphere reads vertical angle 0
  CHECK(IesRowError("IES web, angleScale -0.5", s, [](double, double phi) { return IesForTest(0, phi); }) < 5e-5);
}

TEST_CASE("shaping:ies:normalize divides the profile by its mean intensity over the sphere ", "[usdlux][ies]") {
  LightShaping s = IesShapingForTest();
  s.iesNormalize = true;
  // Mean over phi of (1 + phi / 180): 1.5; int (200 - theta) sin = 400 - 180 = 220; flux 2 pi 1.5 220 over 4 pi.
  const double mean = 1.5 * 220 / 2;
  CHECK(s.ies.MeanIntensity() == Approx(mean).epsilon(1e-12));
  CHECK(IesRowError("IES web, normalize (mean 165 cd)", s,
                    [mean](double theta, double phi) { return IesForTest(theta, phi) / mean; }) < 5e-5);
}

namespace {

/// Irradiance on a horizontal plane at a point a horizontal distance `offset` (across the axis, in line with the
/// centre along it) from below a cylinder light of radiance L, radius r and half-length a whose axis is
/// horizontal at height h. A direction at angle beta from the normal in the cross-section and gamma along the
/// axis meets the side at cross-section distance s(beta) (the near root), within the length while
/// tan(gamma) <= a / s, and cos(theta) = cos(beta) cos(gamma); so
/// E = L int cos(beta) (g0 + sin g0 cos g0) dbeta over the silhouette, tan g0 = a / s(beta) (Simpson, 2000 steps).
double CylinderIrradiance(double L, double r, double a, double h, double offset) {
  const double D = std::hypot(h, offset), centre = std::atan2(offset, h), half = std::asin(r / D);
  const auto f = [&](double beta) {
    const double uc = D * std::cos(beta - centre), s = uc - std::sqrt(std::max(0.0, r * r - (D * D - uc * uc)));
    const double g0 = std::atan(a / s);
    return std::cos(beta) * (g0 + std::sin(g0) * std::cos(g0));
  };
  const int n = 2000;
  const double lo = centre - half, step = 2 * half / n;
  double sum = f(lo) + f(lo + 2 * half);
  for (int i = 1; i < n; ++i) sum += f(lo + i * step) * (i % 2 ? 4 : 2);
  return L * sum * step / 3;
}

}  // namespace

TEST_CASE(
    "a cylinder light emits from its side: the plane's irradiance under it and beside it, normalize divides by "
    "2 pi r l ",
    "[usdlux][cylinder]") {
  const double r = 0.1, l = 2, h = 1, L = 2;
  LightParams tube;  // along the world x (its local x), 1 above the plane
  tube.radius = float(r), tube.length = float(l), tube.intensity = float(L);
  for (double offset : {0.0, 0.8}) {
    const double E = CylinderIrradiance(L, r, l / 2, h, offset);
    const double got = RenderUnderLight(primTypes::kCylinderLight, tube, h, 0.02, 4, 2048, {0, -offset, 0}).x;
    char what[80];
    std::snprintf(what, sizeof what, "cylinder r 0.1 l 2 at 1, %.1f to the side", offset);
    Report(what, got, Lambert(E));
    CHECK(got == Approx(Lambert(E)).epsilon(0.01));
  }
  tube.normalize = true;
  const double on = RenderUnderLight(primTypes::kCylinderLight, tube, h, 0.02, 4, 2048).x;
  const double E = CylinderIrradiance(L / (2 * kPi * r * l), r, l / 2, h, 0);
  Report("cylinder, normalize on", on, Lambert(E));
  CHECK(on == Approx(Lambert(E)).epsilon(0.01));
}

TEST_CASE("treatAsLine renders the cylinder as a line of 2 r L sin(angle) per unit length (L / (pi l) normalized) ",
          "[usdlux][cylinder]") {
  // Under the centre of a line of intensity K sin(alpha) per unit length: E = K (a / (h^2 + a^2) + atan(a/h) / h).
  const double r = 0.1, l = 2, h = 1, L = 2, a = l / 2;
  const auto lineE = [&](double K) { return K * (a / (h * h + a * a) + std::atan(a / h) / h); };
  LightParams line;
  line.radius = float(r), line.length = float(l), line.intensity = float(L), line.treatAsLine = true;
  const double off = RenderUnderLight(primTypes::kCylinderLight, line, h, 0.02, 4, 2048).x;
  Report("line (cylinder r 0.1 l 2) at 1", off, Lambert(lineE(2 * r * L)));
  CHECK(off == Approx(Lambert(lineE(2 * r * L))).epsilon(0.01));
  line.normalize = true;
  line.radius = 0;
  const double on = RenderUnderLight(primTypes::kCylinderLight, line, h, 0.02, 4, 2048).x;
  Report("line, radius 0, normalize on", on, Lambert(lineE(L / (kPi * l))));
  CHECK(on == Approx(Lambert(lineE(L / (kPi * l)))).epsilon(0.01));
}

TEST_CASE("a cylinder light's sampled points are what rays towards them meet, with the same pdf ",
          "[usdlux][cylinder]") {
  LightParams tube;
  tube.radius = 0.3f, tube.length = 2, tube.intensity = 5;
  Matrix4d m(1.0);  // axis along world y, centre at (1, 0, 2)
  m[0] = glm::dvec4(0, 1, 0, 0), m[1] = glm::dvec4(-1, 0, 0, 0), m[3] = glm::dvec4(1, 0, 2, 1);
  const RenderLight light = RenderLight::FromParams(
      [&] {
        LightParams p = tube;
        p.type = LightType::Cylinder;
        return p;
      }(),
      m);
  const glm::dvec3 from(0.2, 0.5, -1);
  int sampled = 0;
  for (double u1 : {0.05, 0.3, 0.6, 0.95})
    for (double u2 : {0.02, 0.4, 0.7, 0.99}) {
      const LightSample s = SampleLight(light, from, u1, u2);
      REQUIRE(s.pdf > 0);
      glm::dvec3 radiance(0);
      double pdf = 0, distance = 0;
      REQUIRE(IntersectLight(light, from, s.dir, 1e30, &radiance, &pdf, &distance));
      CHECK(distance == Approx(s.distance).epsilon(1e-9));
      CHECK(pdf == Approx(s.pdf).epsilon(1e-9));
      CHECK(radiance == s.radiance);
      ++sampled;
    }
  CHECK(sampled == 16);
  // From inside the tube nothing is sampled or met; a ray past its end cap meets nothing.
  CHECK(SampleLight(light, {1, 0, 2.1}, 0.5, 0.5).pdf == 0);
  glm::dvec3 radiance(0);
  double pdf = 0, distance = 0;
  CHECK_FALSE(IntersectLight(light, {1, 0, 2.1}, {0, 0, 1}, 1e30, &radiance, &pdf, &distance));
  CHECK_FALSE(IntersectLight(light, {1, 3, 2}, {0, -1, 0}, 1e30, &radiance, &pdf, &distance));  // along the axis
}

TEST_CASE("ShapingAPI's focus multiplies by lerp(focusTint, 1, |cos|^focus) ", "[usdlux]") {
  LightParams p;
  p.shaping.enabled = true;
  p.shaping.coneAngle = 90;
  p.shaping.focus = 4;
  p.shaping.focusTint = glm::vec3(0.5f, 0, 0);
  p.radius = 1;
  const RenderLight l = RenderLight::FromParams(p, test::LookDownZ(0));
  const double c = std::cos(0.6);
  const glm::dvec3 along = EmissionShaping(l, {0, 0, -1}), off = EmissionShaping(l, {std::sin(0.6), 0, -c});
  CHECK(along == glm::dvec3(1));
  CHECK(off.x == Approx(0.5 + 0.5 * std::pow(c, 4)).epsilon(1e-12));
  CHECK(off.y == Approx(std::pow(c, 4)).epsilon(1e-12));
  CHECK(EmissionShaping(l, {1, 0, 0.01}) == glm::dvec3(0));  // behind the 90 degree cone
}

TEST_CASE("MNEE under a line light (treatAsLine) brings the caustic of the thin cylinder it stands for ",
          "[usdlux][cylinder]") {
  // The side-lit eye's key replaced by a 6 mm tube of radius 0.5 mm at 150 mm, across the view (along y).
  auto irisLight = [](bool line) {
    test::RenderStack s;
    sampleScenes::AddSideLitEye(s.scene, 60);
    LightParams key = s.scene.GetLightParams("/World/key");
    key.intensity = 0;  // the sphere key off
    s.scene.SetLightParams("/World/key", key);
    LightParams tube;
    tube.radius = 0.5f, tube.length = 6, tube.intensity = 2000, tube.treatAsLine = line;
    const double a = 60 * kPi / 180;
    Matrix4d m(1.0);
    m[0] = glm::dvec4(0, 1, 0, 0), m[1] = glm::dvec4(-1, 0, 0, 0);
    m[3] = glm::dvec4(150 * std::sin(a), 0, 150 * std::cos(a), 1);
    s.scene.AddLight("/World/tube", primTypes::kCylinderLight, tube, m);
    return test::IrisMneeSum(s, sampleScenes::kCamera, 24, 16);
  };
  const double tube = irisLight(false), line = irisLight(true);
  Report("iris MNEE light under the line", line, tube, "0.5 mm tube");
  REQUIRE(tube > 0);
  CHECK(line == Approx(tube).epsilon(0.03));
}

TEST_CASE("MNEE under a point light (treatAsPoint) brings the caustic of the sphere it stands for ", "[usdlux]") {
  // The side-lit eye's 3 mm key at 150 mm, as a sphere and as a point of the same radiant intensity: the iris's
  // MNEE light agrees to the noise of 16 samples.
  auto irisLight = [](bool point) {
    test::RenderStack s;
    sampleScenes::AddSideLitEye(s.scene, 60);
    LightParams key = s.scene.GetLightParams("/World/key");
    key.treatAsPoint = point;
    s.scene.SetLightParams("/World/key", key);
    return test::IrisMneeSum(s, sampleScenes::kCamera, 24, 16);
  };
  const double sphere = irisLight(false), point = irisLight(true);
  Report("iris MNEE light under the point", point, sphere, "3 mm sphere");
  CHECK(point == Approx(sphere).epsilon(0.03));
}
