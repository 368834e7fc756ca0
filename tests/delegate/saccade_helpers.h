#pragma once
// The saccade the motion-blur tests and bench_motion_blur render: an analytic eye (mm) turning about its eyeball's
// centre, and a key light on a circle about the eye in the plane of the turn.
#include "hdeye/params/primParams.h"

#include <glm/gtc/matrix_transform.hpp>

#include <cmath>

namespace test {

/// The eye turned `degrees` about +y through its eyeball's centre, 13 mm behind the corneal apex.
inline hdeye::Matrix4d EyeTurn(double degrees) {
  const double a = degrees * 3.14159265358979323846 / 180;
  return glm::translate(hdeye::Matrix4d(1.0), glm::dvec3(0, 0, -13)) *
         glm::rotate(hdeye::Matrix4d(1.0), a, glm::dvec3(0, 1, 0)) *
         glm::translate(hdeye::Matrix4d(1.0), glm::dvec3(0, 0, 13));
}

/// A light `distance` mm from the apex, `degrees` off the resting gaze (+z) towards +x.
inline hdeye::Matrix4d KeyAt(double degrees, double distance) {
  const double a = degrees * 3.14159265358979323846 / 180;
  return glm::translate(hdeye::Matrix4d(1.0), glm::dvec3(distance * std::sin(a), 0, distance * std::cos(a)));
}

}  // namespace test
