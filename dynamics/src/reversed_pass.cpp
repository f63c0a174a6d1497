#include "fieldpath/dynamics/reversed_pass.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace fieldpath::dynamics {

std::vector<double> outputStations(const Pass& pass, const SteeringRequest& request) {
  if (!request.output_s_mm.empty()) return request.output_s_mm;
  std::vector<double> stations;
  const auto intervals = static_cast<long>(std::ceil(pass.length_mm / request.step_mm - 1e-9));
  for (long k = 0; k <= intervals; ++k)
    stations.push_back(std::min(static_cast<double>(k) * request.step_mm, pass.length_mm));
  return stations;
}

Pass reversedPass(const Pass& pass) {
  Pass back;
  back.length_mm = pass.length_mm;
  back.frameAt = [forward = pass.frameAt, length_mm = pass.length_mm](double s_mm) {
    PassFrame f = forward(length_mm - s_mm);
    f.feed = -f.feed;
    f.lead0_rad = -f.lead0_rad;
    f.tilt0_rad = -f.tilt0_rad;
    return f;
  };
  return back;
}

SteeringRequest reversedRequest(const Pass& pass, SteeringRequest request) {
  std::vector<double> stations = outputStations(pass, request);
  std::reverse(stations.begin(), stations.end());
  for (double& s_mm : stations) s_mm = std::max(0.0, pass.length_mm - s_mm);
  request.output_s_mm = std::move(stations);
  request.initial_lead_rad.reset();
  request.initial_tilt_rad.reset();
  request.initial_lead_rate_rad_per_s = 0.0;
  request.initial_tilt_rate_rad_per_s = 0.0;
  return request;
}

SteeringResult forwardOf(SteeringResult backward, const Pass& pass,
                         const SteeringRequest& request) {
  const std::vector<double> stations = outputStations(pass, request);
  std::vector<PostureSample>& samples = backward.samples;
  std::reverse(samples.begin(), samples.end());
  // The k-th sample from the end reached is the station that far from the pass's end.
  const std::size_t first = stations.size() - std::min(stations.size(), samples.size());
  for (std::size_t k = 0; k < samples.size(); ++k) {
    PostureSample& sample = samples[k];
    sample.s_mm = stations[first + k];
    const PassFrame frame = pass.frameAt(sample.s_mm);
    const Vec3 axis = sample.posture.axis;
    const auto angles = anglesOfAxis(localFrame(frame), axis);
    sample.lead_rad = angles[0];
    sample.tilt_rad = angles[1];
    sample.lead_torque = -sample.lead_torque;
    sample.tilt_torque = -sample.tilt_torque;
    sample.posture = geometry::ballEndPosture(frame.centre_mm, axis, request.ball_radius_mm);
  }
  return backward;
}

}  // namespace fieldpath::dynamics
