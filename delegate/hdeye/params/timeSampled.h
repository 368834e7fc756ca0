#pragma once
// A value sampled over the shutter (the role of Hydra's HdTimeSampleArray): the samples a scene delegate returns
// for a motion-blurred transform, point set or instancer. Times are in frames relative to the frame being
// rendered (UsdGeomCamera's shutter convention).
#include <vector>

namespace hdeye {

/// `values[i]` holds at `times[i]` (frames relative to the frame); times ascending, one value per time. One
/// sample is a static value; none means "not authored" to whoever asked.
template <class T> struct TimeSampled {
  std::vector<float> times;
  std::vector<T> values;
  bool Static() const { return values.size() <= 1; }
};

}  // namespace hdeye
