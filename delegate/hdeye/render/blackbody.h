#pragma once
// The colour of a blackbody at a temperature, as UsdLuxLightAPI's colorTemperature asks: linear Rec.709 (D65
// white), normalised so that 6500 K is white (1, 1, 1) and every temperature has luminance 1.
#include <glm/glm.hpp>

namespace hdeye {

/// CIE 1931 xy chromaticity of a blackbody at `kelvin` (Planck's law integrated against the CIE 1931 2-degree
/// observer, Wyman, Sloan and Shirley's multi-lobe fit, 360-830 nm). kelvin is clamped to [1000, 40000].
glm::dvec2 BlackbodyChromaticity(double kelvin);

/// Linear Rec.709 colour of a blackbody at `kelvin` ([1000, 10000] as UsdLux allows; clamped to [1000, 40000]),
/// divided channel by channel by the 6500 K colour and then scaled to Rec.709 luminance 1.
glm::dvec3 BlackbodyColor(double kelvin);

}  // namespace hdeye
