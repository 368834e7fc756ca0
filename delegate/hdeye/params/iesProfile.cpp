#include "hdeye/params/iesProfile.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

namespace hdeye {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kAngleTolerance = 1e-3;  // degrees: files print angles with a few decimals
// Far beyond any real web (the largest in the wild are 361 x 181): a corrupt count must not allocate gigabytes.
constexpr long kMaxValues = 4'000'000;

bool Near(double a, double b) { return std::abs(a - b) <= kAngleTolerance; }

/// The numbers after the TILT line: separated by whitespace or commas, across lines.
class NumberReader {
 public:
  explicit NumberReader(const std::string& text) {
    std::string cleaned = text;
    std::replace(cleaned.begin(), cleaned.end(), ',', ' ');
    in_.str(cleaned);
  }
  double Next(const char* what) {
    std::string token;
    if (!(in_ >> token)) throw std::invalid_argument(std::string("the file ends before its ") + what);
    char* end = nullptr;
    const double v = std::strtod(token.c_str(), &end);
    if (end == token.c_str() || *end != '\0' || !std::isfinite(v))
      throw std::invalid_argument(std::string("'") + token.substr(0, 20) + "' is not a number (" + what + ")");
    return v;
  }
  long Count(const char* what, long lo, long hi) {
    const double v = Next(what);
    if (v != std::floor(v) || v < double(lo) || v > double(hi))
      throw std::invalid_argument(std::string(what) + " " + std::to_string(v) + " is out of range");
    return long(v);
  }

 private:
  std::istringstream in_;
};

/// The text after the header: from the line after TILT=NONE. Throws for a missing TILT line or another tilt.
std::string AfterTilt(const std::string& text) {
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(pos, end - pos);
    const std::size_t first = line.find_first_not_of(" \t\r");
    line = first == std::string::npos ? "" : line.substr(first);
    std::string upper = line.substr(0, std::min<std::size_t>(line.size(), 5));
    for (char& c : upper) c = char(std::toupper(static_cast<unsigned char>(c)));
    if (upper == "TILT=") {
      std::string value = line.substr(5);
      value.erase(value.find_last_not_of(" \t\r") + 1);
      for (char& c : value) c = char(std::toupper(static_cast<unsigned char>(c)));
      if (value != "NONE")
        throw std::invalid_argument("TILT=" + value.substr(0, 40) + " is not supported (TILT=NONE only)");
      return text.substr(std::min(end + 1, text.size()));
    }
    pos = end + 1;
  }
  throw std::invalid_argument("no TILT= line (not an IES LM-63 file)");
}

std::vector<double> Angles(NumberReader& in, long n, double lo, double hi, const char* what) {
  std::vector<double> a(static_cast<std::size_t>(n));
  for (double& v : a) {
    v = in.Next(what);
    if (v < lo - kAngleTolerance || v > hi + kAngleTolerance)
      throw std::invalid_argument(std::string(what) + " " + std::to_string(v) + " is outside [" +
                                  std::to_string(int(lo)) + ", " + std::to_string(int(hi)) + "]");
    v = std::clamp(v, lo, hi);
  }
  for (std::size_t i = 1; i < a.size(); ++i)
    if (!(a[i] > a[i - 1])) throw std::invalid_argument(std::string(what) + " are not ascending");
  return a;
}

/// Index i and fraction t with the value between a[i] and a[i + 1] (a.size() >= 2, x clamped to the range).
void Bracket(const std::vector<double>& a, double x, std::size_t* i, double* t) {
  x = std::clamp(x, a.front(), a.back());
  const std::size_t hi = std::size_t(std::upper_bound(a.begin(), a.end(), x) - a.begin());
  *i = std::min(hi == 0 ? 0 : hi - 1, a.size() - 2);
  *t = (x - a[*i]) / (a[*i + 1] - a[*i]);
}

}  // namespace

IesProfile ParseIes(const std::string& text) {
  NumberReader in(AfterTilt(text));
  in.Next("number of lamps");
  in.Next("lumens per lamp");  // -1: absolute photometry; the candela values are what the renderer uses either way
  const double multiplier = in.Next("candela multiplier");
  const long nv = in.Count("number of vertical angles", 2, 100000);
  const long nh = in.Count("number of horizontal angles", 1, 100000);
  if (nv * nh > kMaxValues) throw std::invalid_argument("the web has too many angles");
  const long type = in.Count("photometric type", 1, 3);
  if (type != 1)
    throw std::invalid_argument(std::string("type ") + (type == 2 ? "B" : "A") +
                                " photometry is not supported (type C only)");
  in.Next("units type");
  in.Next("width");
  in.Next("length");
  in.Next("height");
  const double ballast = in.Next("ballast factor");
  // LM-63-1995: the ballast-lamp photometric factor; LM-63-2002: "future use", written as 1.
  const double ballastLamp = in.Next("ballast-lamp factor");
  in.Next("input watts");
  const double factor = multiplier * ballast * ballastLamp;
  if (!(factor >= 0) || !std::isfinite(factor))
    throw std::invalid_argument("candela multiplier x ballast factors " + std::to_string(factor) + " is negative");

  IesProfile p;
  p.vertical = Angles(in, nv, 0, 180, "vertical angles");
  p.horizontal = Angles(in, nh, 0, 360, "horizontal angles");
  const double h0 = p.horizontal.front(), h1 = p.horizontal.back();
  const bool known =
      nh == 1 || (Near(h0, 0) && (Near(h1, 90) || Near(h1, 180) || Near(h1, 360))) || (Near(h0, 90) && Near(h1, 270));
  if (!known)
    throw std::invalid_argument("horizontal angles " + std::to_string(h0) + " to " + std::to_string(h1) +
                                " are none of LM-63's sets (0, 0-90, 0-180, 90-270, 0-360)");
  p.candela.resize(std::size_t(nv * nh));
  for (double& c : p.candela) {
    c = in.Next("candela values") * factor;
    if (c < 0) throw std::invalid_argument("a candela value is negative");
  }
  return p;
}

double IesProfile::Intensity(double verticalDeg, double horizontalDeg) const {
  if (Empty() || !std::isfinite(verticalDeg) || !std::isfinite(horizontalDeg)) return 0;
  if (verticalDeg < vertical.front() - kAngleTolerance || verticalDeg > vertical.back() + kAngleTolerance) return 0;
  const std::size_t nv = vertical.size();
  std::size_t vi;
  double vt;
  Bracket(vertical, verticalDeg, &vi, &vt);
  const auto column = [&](std::size_t h) { return candela[h * nv + vi] * (1 - vt) + candela[h * nv + vi + 1] * vt; };
  if (horizontal.size() == 1) return column(0);
  // Fold the horizontal angle into the set's range by its symmetry.
  double phi = std::fmod(horizontalDeg, 360.0);
  if (phi < 0) phi += 360;
  const double h0 = horizontal.front(), h1 = horizontal.back();
  if (Near(h0, 90)) {  // 90..270: symmetric about the 90-270 plane
    if (phi < 90) phi = 180 - phi;
    if (phi > 270) phi = 540 - phi;
  } else if (Near(h1, 90)) {  // 0..90: each quadrant a mirror of the first
    if (phi > 180) phi = 360 - phi;
    if (phi > 90) phi = 180 - phi;
  } else if (Near(h1, 180)) {  // 0..180: symmetric about the 0-180 plane
    if (phi > 180) phi = 360 - phi;
  }
  std::size_t hi;
  double ht;
  Bracket(horizontal, phi, &hi, &ht);
  return column(hi) * (1 - ht) + column(hi + 1) * ht;
}

double IesProfile::MeanIntensity() const {
  if (Empty()) return 0;
  const std::size_t nv = vertical.size(), nh = horizontal.size();
  // The mean over the horizontal angles at each vertical angle (the folded web's mean over the whole circle is
  // its mean over the set's range); the bilinear web is linear in each, so this is exact.
  std::vector<double> ring(nv, 0.0);
  for (std::size_t v = 0; v < nv; ++v) {
    if (nh == 1) {
      ring[v] = candela[v];
      continue;
    }
    double sum = 0;
    for (std::size_t h = 0; h + 1 < nh; ++h)
      sum += 0.5 * (candela[h * nv + v] + candela[(h + 1) * nv + v]) * (horizontal[h + 1] - horizontal[h]);
    ring[v] = sum / (horizontal.back() - horizontal.front());
  }
  // Integral of the piecewise-linear ring(theta) sin(theta) dtheta, exactly per interval [a, b]:
  // int (A + B (theta - a)) sin = A (cos a - cos b) + B (sin b - sin a - (b - a) cos b).
  double integral = 0;
  for (std::size_t v = 0; v + 1 < nv; ++v) {
    const double a = vertical[v] * kPi / 180, b = vertical[v + 1] * kPi / 180;
    const double A = ring[v], B = (ring[v + 1] - ring[v]) / (b - a);
    integral += A * (std::cos(a) - std::cos(b)) + B * (std::sin(b) - std::sin(a) - (b - a) * std::cos(b));
  }
  const double flux = 2 * kPi * integral;
  // hdEmbree's test for a whole-sphere web: a vertical span past 90 degrees by more than 0.1 rad.
  const bool sphere = (vertical.back() - vertical.front()) * kPi / 180 > kPi / 2 + 0.1;
  return flux / (sphere ? 4 * kPi : 2 * kPi);
}

}  // namespace hdeye
