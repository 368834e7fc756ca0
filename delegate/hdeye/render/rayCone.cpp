#include "hdeye/render/rayCone.h"

#include <algorithm>
#include <cmath>

namespace hdeye {

StFrame TriangleStFrame(const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& p2, const glm::dvec2& st0,
                        const glm::dvec2& st1, const glm::dvec2& st2) {
  // [dp1 dp2] = [dpds dpdt] [dst1 dst2]: invert the 2x2 st matrix.
  const glm::dvec3 dp1 = p1 - p0, dp2 = p2 - p0;
  const glm::dvec2 d1 = st1 - st0, d2 = st2 - st0;
  const double det = d1.x * d2.y - d1.y * d2.x;
  StFrame f;
  if (!(std::fabs(det) > 1e-20) || !std::isfinite(det)) return f;
  f.dpds = (dp1 * d2.y - dp2 * d1.y) / det;
  f.dpdt = (dp2 * d1.x - dp1 * d2.x) / det;
  f.valid = std::isfinite(glm::dot(f.dpds, f.dpds)) && std::isfinite(glm::dot(f.dpdt, f.dpdt));
  return f;
}

TextureFootprint FootprintOnSurface(double width, const glm::dvec3& dir, const glm::dvec3& n, const StFrame& frame) {
  TextureFootprint fp;
  if (!frame.valid || !(width > 0) || !std::isfinite(width)) return fp;
  // The footprint's axes on the surface: across the ray (width) and along its projection, stretched
  // by 1/|cos| (capped at 20: OIIO's anisotropy limit is 32, and grazing footprints are unbounded).
  const double cosTheta = std::max(0.05, std::fabs(glm::dot(dir, n)));
  glm::dvec3 across = glm::cross(dir, n);
  const double l = glm::length(across);
  across = l > 1e-12 ? across / l : glm::normalize(frame.dpds - glm::dot(frame.dpds, n) * n);
  const glm::dvec3 along = glm::cross(n, across);
  // A surface vector v = a dpds + b dpdt maps to (a, b) in st: least squares against the two tangents.
  const double ss = glm::dot(frame.dpds, frame.dpds), tt = glm::dot(frame.dpdt, frame.dpdt),
               st = glm::dot(frame.dpds, frame.dpdt);
  const double det = ss * tt - st * st;
  if (!(det > 0) || !std::isfinite(det)) return fp;
  auto toSt = [&](const glm::dvec3& v) {
    const double vs = glm::dot(v, frame.dpds), vt = glm::dot(v, frame.dpdt);
    return glm::vec2(float((tt * vs - st * vt) / det), float((ss * vt - st * vs) / det));
  };
  fp.dstDx = toSt(across * width);
  fp.dstDy = toSt(along * (width / cosTheta));
  for (float c : {fp.dstDx.x, fp.dstDx.y, fp.dstDy.x, fp.dstDy.y})
    if (!std::isfinite(c)) return TextureFootprint{};
  return fp;
}

}  // namespace hdeye
