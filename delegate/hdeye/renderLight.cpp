#include "hdeye/renderLight.h"

#include <eyelib/sampling.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace hdeye {

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kInf = std::numeric_limits<double>::infinity();

using eyelib::SampleUniformCone;
using eyelib::UniformConePdf;

/// Area pdf to solid angle pdf.
double AreaToSolidAngle(double areaPdf, double distance, double cosAtLight) {
  return cosAtLight > 0 ? areaPdf * distance * distance / cosAtLight : 0;
}

double PlanarArea(const RenderLight& l) {
  return l.type == LightType::Rect ? 4 * glm::length(glm::cross(l.axisU, l.axisV)) : kPi * l.radius * l.radius;
}
}  // namespace

RenderLight RenderLight::FromParams(const LightParams& p, const glm::dmat4& m) {
  RenderLight l;
  l.type = p.type;
  l.radiance = glm::dvec3(p.color) * double(p.intensity) * std::exp2(double(p.exposure));
  l.position = glm::dvec3(m * glm::dvec4(0, 0, 0, 1));
  const glm::dvec3 x(m * glm::dvec4(1, 0, 0, 0)), y(m * glm::dvec4(0, 1, 0, 0)), z(m * glm::dvec4(0, 0, 1, 0));
  const double scale = std::max({glm::length(x), glm::length(y), glm::length(z)});
  switch (p.type) {
    case LightType::Sphere: l.radius = p.radius * scale; break;
    case LightType::Distant: {
      l.direction = glm::normalize(z);
      const double half = std::max(1e-4, double(p.angle) * kPi / 360);
      l.cosHalfAngle = std::cos(half);
      // Intensity is the irradiance on a surface facing the light: spread it over the sun's disk.
      l.radiance /= kPi * std::sin(half) * std::sin(half);
      break;
    }
    case LightType::Rect:
      l.direction = -glm::normalize(z);
      l.axisU = x * (p.width / 2.0);
      l.axisV = y * (p.height / 2.0);
      break;
    case LightType::Disk:
      l.direction = -glm::normalize(z);
      l.axisU = glm::normalize(x);
      l.axisV = glm::normalize(y);
      l.radius = p.radius * scale;
      break;
    case LightType::Dome: break;
  }
  return l;
}

LightSample SampleLight(const RenderLight& l, const glm::dvec3& p, double u1, double u2) {
  LightSample s;
  switch (l.type) {
    case LightType::Sphere: {
      const glm::dvec3 toC = l.position - p;
      const double d = glm::length(toC);
      if (!(d > l.radius)) return s;  // inside the light: not sampled
      const double sinMax = l.radius / d, cosMax = std::sqrt(std::max(0.0, 1 - sinMax * sinMax));
      s.dir = SampleUniformCone(toC / d, cosMax, u1, u2);
      // Distance to the sphere along dir (the near root).
      const double b = glm::dot(s.dir, toC), c = d * d - l.radius * l.radius;
      s.distance = b - std::sqrt(std::max(0.0, b * b - c));
      s.radiance = l.radiance;
      s.pdf = UniformConePdf(cosMax);
      return s;
    }
    case LightType::Distant:
      s.dir = SampleUniformCone(l.direction, l.cosHalfAngle, u1, u2);
      s.distance = kInf;
      s.radiance = l.radiance;
      s.pdf = UniformConePdf(l.cosHalfAngle);
      return s;
    case LightType::Dome: {
      // Uniform sphere (a constant dome gains nothing from importance sampling).
      const double z = 1 - 2 * u1, r = std::sqrt(std::max(0.0, 1 - z * z)), phi = 2 * kPi * u2;
      s.dir = {r * std::cos(phi), r * std::sin(phi), z};
      s.distance = kInf;
      s.radiance = l.radiance;
      s.pdf = 1 / (4 * kPi);
      return s;
    }
    case LightType::Rect:
    case LightType::Disk: {
      glm::dvec3 q;
      if (l.type == LightType::Rect) {
        q = l.position + (2 * u1 - 1) * l.axisU + (2 * u2 - 1) * l.axisV;
      } else {
        const double r = l.radius * std::sqrt(u1), phi = 2 * kPi * u2;
        q = l.position + r * (std::cos(phi) * l.axisU + std::sin(phi) * l.axisV);
      }
      const glm::dvec3 toQ = q - p;
      s.distance = glm::length(toQ);
      if (!(s.distance > 0)) return s;
      s.dir = toQ / s.distance;
      s.pdf = AreaToSolidAngle(1 / PlanarArea(l), s.distance, glm::dot(-s.dir, l.direction));
      if (s.pdf > 0) s.radiance = l.radiance;
      return s;
    }
  }
  return s;
}

bool IntersectLight(const RenderLight& l, const glm::dvec3& p, const glm::dvec3& dir, double maxDistance,
                    glm::dvec3* radiance, double* pdf, double* distance) {
  switch (l.type) {
    case LightType::Sphere: {
      const glm::dvec3 toC = l.position - p;
      const double d2 = glm::dot(toC, toC);
      if (!(d2 > l.radius * l.radius)) return false;
      const double b = glm::dot(dir, toC), disc = b * b - (d2 - l.radius * l.radius);
      if (disc < 0) return false;
      const double t = b - std::sqrt(disc);
      if (!(t > 0) || t >= maxDistance) return false;
      const double sinMax2 = l.radius * l.radius / d2;
      *radiance = l.radiance;
      *pdf = UniformConePdf(std::sqrt(std::max(0.0, 1 - sinMax2)));
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
      *radiance = l.radiance;
      *pdf = 1 / (4 * kPi);
      *distance = kInf;
      return true;
    case LightType::Rect:
    case LightType::Disk: {
      const double cosL = glm::dot(-dir, l.direction);
      if (!(cosL > 0)) return false;  // one-sided
      const double t = glm::dot(l.position - p, l.direction) / glm::dot(dir, l.direction);
      if (!(t > 0) || t >= maxDistance) return false;
      const glm::dvec3 q = p + t * dir - l.position;
      if (l.type == LightType::Rect) {
        const double a = glm::dot(q, l.axisU) / glm::dot(l.axisU, l.axisU), b = glm::dot(q, l.axisV) / glm::dot(l.axisV, l.axisV);
        if (std::abs(a) > 1 || std::abs(b) > 1) return false;
      } else if (glm::dot(q, q) > l.radius * l.radius) {
        return false;
      }
      *radiance = l.radiance;
      *pdf = AreaToSolidAngle(1 / PlanarArea(l), t, cosL);
      *distance = t;
      return true;
    }
  }
  return false;
}

}  // namespace hdeye
