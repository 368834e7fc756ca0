#pragma once
// The built-in sample scenes, defined once for the example program (`make render`), the baseline image
// tests and the delegate benchmark, so all three always render the same scene. Each adds prims to a
// scene delegate; callers add the render buffers they want.
#include "hdeye/scene/inMemorySceneDelegate.h"

namespace hdeye::sampleScenes {

/// The camera every sample scene adds.
inline const PrimId kCamera = "/World/cam";

/// An analytic eye in millimetres gazing at the camera (45 mm away, 100 mm lens framing the iris), a
/// sphere light (radius 3 mm, intensity 300 x keyScale) 150 mm away, `keyAngleDegrees` off the gaze
/// towards +x, and a dim dome (0.05).
void AddSideLitEye(InMemorySceneDelegate& scene, double keyAngleDegrees = 75, float keyScale = 1);

/// The ball scene's key light, for programs that aim rays at it (scene units).
inline const glm::dvec3 kBallKeyPosition{2, -2, 4};
inline constexpr float kBallKeyRadius = 0.5f;
/// The ball scene's lights.
inline const PrimId kBallKey = "/World/key", kBallSky = "/World/sky";

/// A cube refined three times by Catmull-Clark (a rounded red ball) on a grey floor, the key light
/// above (intensity 30 x keyScale), a blue-ish dome (0.3), a camera at (0, -7, 3) looking at the ball.
void AddBallOnFloor(InMemorySceneDelegate& scene, float keyScale = 1);

}  // namespace hdeye::sampleScenes
