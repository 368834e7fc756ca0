// The random-walk subsurface scattering kernel: albedo inversion, spectral-MIS free flights, Fresnel
// boundary, teleportation cylinder. See random_walk_sss.h.
#include "eyelib/random_walk_sss.h"

#include "eyelib/eye_constants.h"
#include "eyelib/optics.h"
#include "eyelib/sampling.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>

namespace eyelib {

namespace {

using V3 = Vec3<double>;

double Clamp01(double a) { return std::isnan(a) ? 0.0 : std::clamp(a, 0.0, 1.0); }

// A uniform sample strictly inside [0, 1): a caller's generator that returns 1 (or NaN) must not
// produce an infinite free flight.
double Draw(SssRandom random) {
  const double u = random();
  if (!(u >= 0)) return 0;                      // NaN or negative
  return u < 1 ? u : std::nextafter(1.0, 0.0);  // -log1p(-u) <= 36.7
}

// Henyey-Greenstein around the propagation direction d (unit); g = 0 is the uniform sphere.
V3 SamplePhase(const V3& d, double g, double u1, double u2) {
  double cosT;
  if (std::abs(g) < 1e-3) {
    cosT = 1 - 2 * u1;
  } else {
    const double s = (1 - g * g) / (1 - g + 2 * g * u1);
    cosT = (1 + g * g - s * s) / (2 * g);
  }
  cosT = std::clamp(cosT, -1.0, 1.0);
  const double sinT = std::sqrt(std::max(0.0, 1 - cosT * cosT));
  const double phi = 2 * paper::kPi * u2;
  V3 t, b;
  OrthonormalBasis(d, &t, &b);
  return glm::normalize(cosT * d + sinT * (std::cos(phi) * t + std::sin(phi) * b));
}

// Per-channel factors exp(-(sigma_t_c - m) t), with m the smallest sigma_t among the channels the walk
// can still choose; dividing numerator and denominator of every MIS weight by exp(-m t) keeps them from
// underflowing together (0 / 0) on long flights. Channels with zero probability get 0: their weight is
// already 0 and must stay 0, never 0 * Inf.
V3 RelativeTransmittance(const SssMedium& m, const V3& prob, double t) {
  double minSigma = std::numeric_limits<double>::infinity();
  for (int c = 0; c < 3; ++c)
    if (prob[c] > 0) minSigma = std::min(minSigma, m.sigmaT[c]);
  V3 tr(0.0);
  for (int c = 0; c < 3; ++c)
    if (prob[c] > 0) tr[c] = std::exp(-(m.sigmaT[c] - minSigma) * t);
  return tr;
}

bool ValidMedium(const SssMedium& m) {
  for (int c = 0; c < 3; ++c) {
    if (!std::isfinite(m.sigmaT[c]) || !(m.sigmaT[c] > 0)) return false;
    if (!(m.albedo[c] >= 0 && m.albedo[c] <= 1)) return false;
  }
  return true;
}

bool FiniteNonNegative(const V3& w) { return IsFinite(w) && w.x >= 0 && w.y >= 0 && w.z >= 0; }

}  // namespace

const char* ToString(WalkStatus status) {
  switch (status) {
    case WalkStatus::Exited: return "exited";
    case WalkStatus::Absorbed: return "absorbed";
    case WalkStatus::Capped: return "capped";
    case WalkStatus::Invalid: return "invalid";
  }
  return "?";
}

double SingleScatteringAlbedo(double surfaceAlbedo) {
  const double A = Clamp01(surfaceAlbedo);
  return 1 - std::exp(A * (-5.09406 + A * (2.61188 - A * 4.31805)));
}

double ExtinctionCoefficient(double surfaceAlbedo, double meanFreePath) {
  const double A = Clamp01(surfaceAlbedo);
  // s >= 1.028 on [0, 1] (its minimum is at A = 0.943), so sigma_t is finite once d is bounded below.
  const double s = 1.9 - A + 3.5 * (A - 0.8) * (A - 0.8);
  const double d = std::isfinite(meanFreePath) ? std::max(meanFreePath, 1e-9) : 1e9;
  return 1 / (s * d);
}

SssMedium SssMediumFromArtist(const V3& surfaceAlbedo, const V3& meanFreePath) {
  SssMedium m;
  for (int c = 0; c < 3; ++c) {
    m.albedo[c] = SingleScatteringAlbedo(surfaceAlbedo[c]);
    m.sigmaT[c] = ExtinctionCoefficient(surfaceAlbedo[c], meanFreePath[c]);
  }
  return m;
}

std::string ValidateSssArtistParams(const V3& surfaceAlbedo, const V3& meanFreePath) {
  static const char* kChannel[3] = {"r", "g", "b"};
  std::ostringstream msg;
  for (int c = 0; c < 3; ++c) {
    if (!(surfaceAlbedo[c] >= 0 && surfaceAlbedo[c] <= 1)) {
      msg << "surface albedo." << kChannel[c] << " = " << surfaceAlbedo[c] << " is not in [0, 1]";
      return msg.str();
    }
    if (!std::isfinite(meanFreePath[c]) || !(meanFreePath[c] > 0) || meanFreePath[c] > kMaxMeanFreePathMm) {
      msg << "mean free path." << kChannel[c] << " = " << meanFreePath[c] << " mm is not in (0, " << kMaxMeanFreePathMm
          << "] mm";
      return msg.str();
    }
  }
  return {};
}

WalkResult RandomWalkSss(const SssMedium& medium, const RandomWalkSettings& settings, const V3& entryPoint,
                         const V3& inwardDir, const SssBoundary& boundary, SssRandom random) {
  WalkResult r;
  if (!ValidMedium(medium) || !IsFinite(entryPoint) || !IsFinite(inwardDir) || !boundary || !random ||
      !(settings.ior >= 1) || !std::isfinite(settings.ior) || !(std::abs(settings.g) < 1) ||
      glm::dot(inwardDir, inwardDir) == 0)
    return r;  // Invalid
  const bool teleport = settings.teleport && settings.cylinder.Valid();

  V3 p = entryPoint, d = glm::normalize(inwardDir), w(1.0);
  for (r.steps = 0; r.steps < std::max(0, settings.maxSteps); ++r.steps) {
    // Channel probabilities proportional to throughput (spectral MIS, balance heuristic).
    const double wSum = w.x + w.y + w.z;
    if (!(wSum > 0)) {
      r.status = WalkStatus::Absorbed;
      r.weight = V3(0.0);
      return r;
    }
    const V3 prob = w / wSum;
    const double uc = Draw(random);
    const int c = uc < prob.x ? 0 : (uc < prob.x + prob.y || prob.z == 0 ? 1 : 2);
    const double flight = -std::log1p(-Draw(random)) / medium.sigmaT[c];  // mm, finite: u < 1

    // The nearest of: the boundary, the cylinder, the scattering point.
    double tHit = 0;
    V3 normal(0.0);
    bool hit = boundary(p, d, flight, &tHit, &normal);
    if (hit && (!std::isfinite(tHit) || !(tHit >= 0) || !IsFinite(normal) || glm::dot(normal, normal) == 0)) {
      r.status = WalkStatus::Invalid;  // a broken callback answer: report it, do not guess
      r.weight = V3(0.0);
      return r;
    }
    hit = hit && tHit <= flight;  // a callback that ignores tMax: the flight ends first
    const double tEvent = hit ? tHit : flight;
    std::optional<CylinderCrossing> crossing;
    if (teleport) crossing = settings.cylinder.FirstCrossing(p, d, tEvent);

    if (crossing || hit) {
      // Surviving a distance t: each channel's transmittance over the mixture's probability of a flight
      // longer than t.
      const double t = crossing ? crossing->t : tHit;
      const V3 tr = RelativeTransmittance(medium, prob, t);
      const double mix = glm::dot(prob, tr);
      w = w * tr / mix;  // mix >= the chosen-min channel's prob > 0
      if (crossing) {
        // Lossless redirection: w is not touched (see teleportation_cylinder.h).
        const TeleportedState s = TeleportationCylinder::Teleport(crossing->point, d);
        p = s.point;
        d = s.dir;
        ++r.teleports;
        continue;
      }
      p = p + tHit * d;
      const V3 nOut = glm::dot(normal, d) >= 0 ? glm::normalize(normal) : -glm::normalize(normal);
      const double cosOut = glm::dot(d, nOut);  // >= 0: moving out of the medium
      // Reflectance from inside: the light arrives from the side opposite nOut (negative cosine).
      const double F = FresnelDielectric(-cosOut, settings.ior);
      V3 wt;
      if (Draw(random) >= F && Refract(-d, -nOut, 1 / settings.ior, &wt)) {
        r.status = WalkStatus::Exited;
        r.exitPoint = p;
        r.exitDir = wt;
        r.weight = FiniteNonNegative(w) ? w : V3(0.0);
        return r;
      }
      d = glm::normalize(d - 2 * cosOut * nOut);  // internal reflection, total or Fresnel
      ++r.internalReflections;
      continue;
    }

    // Scattering at distance `flight`: albedo times transmittance over the mixture's flight pdf.
    p = p + flight * d;
    const V3 tr = RelativeTransmittance(medium, prob, flight);
    const double mixPdf = glm::dot(prob, medium.sigmaT * tr);
    const V3 collided = w * medium.sigmaT * tr / mixPdf;
    r.absorbed += collided * (V3(1.0) - medium.albedo);
    w = collided * medium.albedo;
    d = SamplePhase(d, settings.g, Draw(random), Draw(random));

    const double wMax = std::max({w.x, w.y, w.z});
    if (settings.rouletteWeight > 0 && wMax < settings.rouletteWeight) {
      const double survive = wMax / settings.rouletteWeight;
      if (Draw(random) >= survive) {
        r.status = WalkStatus::Absorbed;
        r.weight = V3(0.0);
        return r;
      }
      w /= survive;
    }
    if (!FiniteNonNegative(w)) {
      r.status = WalkStatus::Invalid;
      r.weight = V3(0.0);
      return r;
    }
  }
  r.status = WalkStatus::Capped;
  r.weight = FiniteNonNegative(w) ? w : V3(0.0);
  return r;
}

}  // namespace eyelib
