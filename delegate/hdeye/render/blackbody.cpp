#include "hdeye/render/blackbody.h"

#include <algorithm>
#include <cmath>

namespace hdeye {

namespace {

/// One lobe of the multi-lobe fit: a Gaussian with different widths below and above its centre (nm).
double Lobe(double nm, double mu, double sigmaBelow, double sigmaAbove) {
  const double t = (nm - mu) / (nm < mu ? sigmaBelow : sigmaAbove);
  return std::exp(-0.5 * t * t);
}

/// CIE 1931 colour matching functions at a wavelength (nm): Wyman, Sloan, Shirley 2013, table 1.
glm::dvec3 ColorMatching(double nm) {
  return {
      1.056 * Lobe(nm, 599.8, 37.9, 31.0) + 0.362 * Lobe(nm, 442.0, 16.0, 26.7) - 0.065 * Lobe(nm, 501.1, 20.4, 26.2),
      0.821 * Lobe(nm, 568.8, 46.9, 40.5) + 0.286 * Lobe(nm, 530.9, 16.3, 31.1),
      1.217 * Lobe(nm, 437.0, 11.8, 36.0) + 0.681 * Lobe(nm, 459.0, 26.0, 13.8)};
}

/// XYZ of a blackbody (arbitrary scale): Planck's spectral radiance against the matching functions, 1 nm steps.
glm::dvec3 BlackbodyXyz(double kelvin) {
  const double T = std::clamp(kelvin, 1000.0, 40000.0);
  constexpr double kC2 = 1.4387769e-2;  // second radiation constant, m K
  glm::dvec3 xyz(0);
  for (int nm = 360; nm <= 830; ++nm) {
    const double m = nm * 1e-9;
    // Scaled by 1e-30 (m^5) so the sum stays in range; the scale cancels in every use.
    const double planck = 1.0 / (std::pow(m * 1e6, 5) * std::expm1(kC2 / (m * T)));
    xyz += planck * ColorMatching(nm);
  }
  return xyz;
}

glm::dvec3 XyzToRec709(const glm::dvec3& c) {
  return {3.2404542 * c.x - 1.5371385 * c.y - 0.4985314 * c.z, -0.9692660 * c.x + 1.8760108 * c.y + 0.0415560 * c.z,
          0.0556434 * c.x - 0.2040259 * c.y + 1.0572252 * c.z};
}

double Rec709Luminance(const glm::dvec3& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

}  // namespace

glm::dvec2 BlackbodyChromaticity(double kelvin) {
  const glm::dvec3 xyz = BlackbodyXyz(kelvin);
  const double sum = xyz.x + xyz.y + xyz.z;
  return {xyz.x / sum, xyz.y / sum};
}

glm::dvec3 BlackbodyColor(double kelvin) {
  static const glm::dvec3 kWhite = XyzToRec709(BlackbodyXyz(6500));
  // Far-red temperatures fall outside Rec.709 (negative blue): clamped at 0 before normalising.
  const glm::dvec3 rgb = glm::max(XyzToRec709(BlackbodyXyz(kelvin)) / kWhite, glm::dvec3(0));
  const double y = Rec709Luminance(rgb);
  return y > 0 ? rgb / y : glm::dvec3(1);
}

}  // namespace hdeye
