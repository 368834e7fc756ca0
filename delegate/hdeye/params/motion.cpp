#include "hdeye/params/motion.h"

#include <algorithm>
#include <cmath>

namespace hdeye {

namespace {
bool Finite(const Matrix4d& m) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) return false;
  return true;
}

/// The segment of `times` holding `time` and the fraction along it, clamped to the ends.
std::pair<std::size_t, double> Segment(const std::vector<double>& times, double time) {
  if (times.size() < 2 || !(time > times.front())) return {0, 0.0};
  if (time >= times.back()) return {times.size() - 2, 1.0};
  const std::size_t i = std::size_t(std::upper_bound(times.begin(), times.end(), time) - times.begin()) - 1;
  return {i, (time - times[i]) / (times[i + 1] - times[i])};
}
}  // namespace

std::optional<TransformParts> DecomposeTransform(const Matrix4d& m) {
  if (!Finite(m)) return std::nullopt;
  const glm::dmat3 l(m);
  // Gram-Schmidt on the columns: l = q * u with q orthonormal and u upper triangular.
  glm::dvec3 q0 = l[0], q1 = l[1], q2 = l[2];
  glm::dmat3 u(0.0);
  u[0][0] = glm::length(q0);
  const double size = std::max({u[0][0], glm::length(l[1]), glm::length(l[2])});
  const double tiny = 1e-12 * size;
  if (!(u[0][0] > tiny)) return std::nullopt;
  q0 /= u[0][0];
  u[1][0] = glm::dot(q0, q1);
  q1 -= u[1][0] * q0;
  u[1][1] = glm::length(q1);
  if (!(u[1][1] > tiny)) return std::nullopt;
  q1 /= u[1][1];
  u[2][0] = glm::dot(q0, q2);
  q2 -= u[2][0] * q0;
  u[2][1] = glm::dot(q1, q2);
  q2 -= u[2][1] * q1;
  u[2][2] = glm::length(q2);
  if (!(u[2][2] > tiny)) return std::nullopt;
  q2 /= u[2][2];
  if (glm::dot(glm::cross(q0, q1), q2) < 0) q2 = -q2, u[2][2] = -u[2][2];  // a mirror: into the last scale
  TransformParts parts;
  parts.rotation = glm::normalize(glm::quat_cast(glm::dmat3(q0, q1, q2)));
  parts.stretch = u;
  parts.translation = glm::dvec3(m[3]);
  return parts;
}

Matrix4d ComposeTransform(const TransformParts& parts) {
  Matrix4d m(glm::mat3_cast(parts.rotation) * parts.stretch);
  m[3] = glm::dvec4(parts.translation, 1.0);
  return m;
}

TransformParts InterpolateParts(const TransformParts& a, const TransformParts& b, double u) {
  TransformParts out;
  out.translation = a.translation + u * (b.translation - a.translation);
  out.stretch = a.stretch + u * (b.stretch - a.stretch);
  glm::dquat qb = b.rotation;
  const double cosine = glm::dot(a.rotation, qb);
  if (cosine < 0) qb = -qb;
  const double c = std::abs(cosine);
  if (c > 1 - 1e-12) {
    out.rotation = glm::normalize(a.rotation + u * (qb - a.rotation));  // (nearly) identical: no angle to divide by
  } else {
    const double angle = std::acos(std::min(c, 1.0));
    const double s = std::sin(angle);
    out.rotation = glm::normalize(a.rotation * (std::sin((1 - u) * angle) / s) + qb * (std::sin(u * angle) / s));
  }
  return out;
}

TransformParts TransformMotion::PartsAt(double time) const {
  if (parts.size() == 1) return parts[0];
  const auto [i, u] = Segment(times, time);
  return InterpolateParts(parts[i], parts[i + 1], u);
}

Matrix4d TransformMotion::At(double time) const { return ComposeTransform(PartsAt(time)); }

std::optional<TransformMotion> MakeTransformMotion(const TimeSampled<Matrix4d>& samples, const std::string& what,
                                                   std::vector<std::string>* warnings) {
  auto warn = [&](const std::string& message) {
    if (warnings) warnings->push_back(what + ": " + message);
  };
  TransformMotion motion;
  double sign = 0;
  const std::size_t n = std::min(samples.times.size(), samples.values.size());
  for (std::size_t i = 0; i < n; ++i) {
    const double time = samples.times[i];
    if (!std::isfinite(time) || (!motion.times.empty() && !(time > motion.times.back()))) {
      warn("transform sample at time " + std::to_string(time) + " is not after the previous one; skipped");
      continue;
    }
    const std::optional<TransformParts> parts = DecomposeTransform(samples.values[i]);
    if (!parts) {
      warn("transform sample at time " + std::to_string(time) + " is non-finite or singular; skipped");
      continue;
    }
    const double s = parts->stretch[2][2] < 0 ? -1.0 : 1.0;
    if (sign != 0 && s != sign) {
      warn("transform sample at time " + std::to_string(time) +
           " mirrors the first one (no rigid motion passes a reflection); skipped");
      continue;
    }
    sign = s;
    TransformParts p = *parts;
    if (!motion.parts.empty() && glm::dot(motion.parts.back().rotation, p.rotation) < 0) p.rotation = -p.rotation;
    motion.times.push_back(time);
    motion.parts.push_back(p);
  }
  if (motion.parts.empty()) return std::nullopt;
  return motion;
}

std::vector<double> MotionStepTimes(const std::vector<double>& authoredTimes, double open, double close) {
  if (!(close > open) || authoredTimes.size() < 2) return {open};
  std::vector<double> inside{open};
  for (double t : authoredTimes)
    if (t > open && t < close) inside.push_back(t);
  inside.push_back(close);
  const double span = close - open, tolerance = 1e-4 * span;
  double smallest = span;
  for (std::size_t i = 1; i < inside.size(); ++i) smallest = std::min(smallest, inside[i] - inside[i - 1]);
  const double uniformGap = span / double(inside.size() - 1);
  bool uniform = true;
  for (std::size_t i = 0; i < inside.size(); ++i)
    uniform = uniform && std::abs(inside[i] - (open + i * uniformGap)) <= tolerance;
  int steps = int(inside.size());
  if (!uniform) steps = std::min(kMaxMotionSteps, int(std::ceil(span / std::max(smallest, tolerance) - 1e-9)) + 1);
  std::vector<double> out(static_cast<std::size_t>(steps));
  for (int i = 0; i < steps; ++i) out[std::size_t(i)] = i + 1 == steps ? close : open + span * i / (steps - 1);
  return out;
}

std::optional<TransformMotion> ResampleMotion(const std::vector<double>& stepTimes,
                                              const std::function<Matrix4d(double)>& world) {
  TransformMotion motion;
  for (double t : stepTimes) {
    std::optional<TransformParts> parts = DecomposeTransform(world(t));
    if (!parts) return std::nullopt;
    if (!motion.parts.empty() && glm::dot(motion.parts.back().rotation, parts->rotation) < 0)
      parts->rotation = -parts->rotation;
    motion.times.push_back(t);
    motion.parts.push_back(*parts);
  }
  if (motion.parts.empty()) return std::nullopt;
  return motion;
}

bool SamplesAllEqual(const TimeSampled<Matrix4d>& samples) {
  for (const Matrix4d& m : samples.values)
    if (m != samples.values.front()) return false;
  return true;
}

std::vector<Vec3f> PointsAt(const TimeSampled<std::vector<Vec3f>>& samples, double time) {
  if (samples.values.empty()) return {};
  if (samples.values.size() == 1 || samples.times.size() != samples.values.size()) return samples.values[0];
  const std::vector<double> times(samples.times.begin(), samples.times.end());
  const auto [i, u] = Segment(times, time);
  const std::vector<Vec3f>& a = samples.values[i];
  const std::vector<Vec3f>& b = samples.values[i + 1];
  if (a.size() != b.size()) return u < 0.5 ? a : b;
  std::vector<Vec3f> out(a.size());
  const float w = float(u);
  for (std::size_t k = 0; k < a.size(); ++k) out[k] = a[k] + w * (b[k] - a[k]);
  return out;
}

}  // namespace hdeye
