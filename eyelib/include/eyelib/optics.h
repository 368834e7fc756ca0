#pragma once
// Smooth dielectric optics. Conventions (pbrt's): directions point away from the surface; `n` is a
// unit normal on the side of `wi`'s medium or the other, as stated per function; eta = n_t / n_i,
// the index of the side the light goes into over the side it comes from.
#include "eyelib/vec.h"

#include <algorithm>
#include <cmath>

namespace eyelib {

/// Mirror reflection of wo (pointing away from the surface) about the unit normal n.
template <class T> inline Vec3<T> Reflect(const Vec3<T>& wo, const Vec3<T>& n) { return -wo + 2 * glm::dot(wo, n) * n; }

/// Unpolarised Fresnel reflectance of a smooth dielectric boundary. cosThetaI is the cosine between
/// the incident direction and the normal on the incident side's convention: positive when light
/// arrives from the side the normal points into (index 1 side), negative from the other side.
/// eta = n_inside / n_outside (e.g. 1.376 for air to cornea). Returns 1 under total internal
/// reflection; never NaN for finite input.
template <class T> inline T FresnelDielectric(T cosThetaI, T eta) {
  cosThetaI = std::clamp(cosThetaI, T(-1), T(1));
  if (cosThetaI < 0) {
    eta = 1 / eta;
    cosThetaI = -cosThetaI;
  }
  const T sin2I = std::max(T(0), 1 - cosThetaI * cosThetaI);
  const T sin2T = sin2I / (eta * eta);
  if (sin2T >= 1) return 1;
  const T cosT = std::sqrt(std::max(T(0), 1 - sin2T));
  const T rParl = (eta * cosThetaI - cosT) / (eta * cosThetaI + cosT);
  const T rPerp = (cosThetaI - eta * cosT) / (cosThetaI + eta * cosT);
  return (rParl * rParl + rPerp * rPerp) / 2;
}

/// Refraction of wi (unit, pointing away from the surface, on the side n points into) through a
/// boundary with relative index eta = n_t / n_i. Returns false under total internal reflection.
/// On success *wt is unit and on the other side. If wi is on the side opposite n, pass -n.
template <class T> inline bool Refract(const Vec3<T>& wi, const Vec3<T>& n, T eta, Vec3<T>* wt) {
  const T cosI = glm::dot(n, wi);
  const T sin2I = std::max(T(0), 1 - cosI * cosI);
  const T sin2T = sin2I / (eta * eta);
  if (sin2T >= 1) return false;
  const T cosT = std::sqrt(1 - sin2T);
  *wt = glm::normalize(-wi / eta + (cosI / eta - cosT) * n);
  return true;
}

/// Critical angle (radians) for light inside a medium of index `eta` times the outside's.
template <class T> inline T CriticalAngle(T eta) { return std::asin(std::min(T(1), 1 / eta)); }

}  // namespace eyelib
