#pragma once
// IES LM-63 photometric profiles (the 1986, 1991, 1995 and 2002 text formats; TILT=NONE; type C photometry):
// parsing and lookup. The profile knows nothing of lights; RenderLight applies it (UsdLuxShapingAPI's
// shaping:ies:*).
#include <string>
#include <vector>

namespace hdeye {

/// A type C photometric web: luminous intensity (candela, times the file's candela multiplier and ballast
/// factors) over vertical angles (degrees, 0 at the luminaire's nadir, 180 at its zenith) and horizontal angles
/// (degrees about the vertical axis). The horizontal set says the symmetry (LM-63): a single angle 0 is
/// rotationally symmetric, 0..90 symmetric in each quadrant, 0..180 about the 0-180 plane, 90..270 about the
/// 90-270 plane, 0..360 none.
struct IesProfile {
  std::vector<double> vertical;    ///< degrees, ascending, within [0, 180]
  std::vector<double> horizontal;  ///< degrees, ascending, within [0, 360]
  std::vector<double> candela;     ///< candela[h * vertical.size() + v]

  bool Empty() const { return candela.empty(); }

  /// Intensity (candela) towards vertical angle `verticalDeg` and horizontal angle `horizontalDeg` (any value;
  /// taken modulo 360 and folded by the set's symmetry): bilinear between the web's angles, 0 outside its
  /// vertical range. 0 for an empty profile.
  double Intensity(double verticalDeg, double horizontalDeg) const;

  /// The mean intensity (candela) over the sphere, or over the hemisphere when the vertical angles span at
  /// most 90 degrees (a downlight or an uplight file, as Karma, RenderMan and hdEmbree count it): the
  /// luminous flux over 4 pi (2 pi) sr, integrated exactly for the bilinear web. What
  /// shaping:ies:normalize divides by.
  double MeanIntensity() const;
};

/// Parses an LM-63 file's text. Throws std::invalid_argument with a short reason (no file name) for a file
/// it cannot use: missing TILT line, TILT other than NONE, photometric type other than C, counts or angles
/// out of range or not ascending, negative or non-finite values, or too few numbers.
IesProfile ParseIes(const std::string& text);

}  // namespace hdeye
