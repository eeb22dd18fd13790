// Where the telemetry measures: the frame whose pose the data's x_m, y_m, z_m and
// roll/pitch/yaw (or quaternion) give, when it is not the cabin's own frame
// (docs/model-format.md "The measured frame", docs/model.md "The measured frame").
//
// FAST's SDP_PhaPos_X/Y/Z are the feed's phase centre, measured by laser trackers on the
// Stewart platform, and its SDP_SwtDPose_Y/P/R are the platform's attitude, which the A-B
// rotator tilts by up to 26 deg relative to the cabin. A model says so with
// cabin.measured_frame: a moving part k (moving_parts.h; or the cabin itself) and a point
// d (offset_m) in that part's frame. With the cabin's pose (p_c, R_c) and the part's frame
// in the cabin at the sample's joints q, (R_k(q), t_k(q)) (identity and 0 for the cabin):
//   R_m = R_c R_k(q)                                       (1) the data's attitude
//   m   = p_c + R_c (t_k(q) + R_k(q) d)                    (2) the data's position
// and back, for every statics call on the data:
//   R_c = R_m R_k(q)^T                                     (3)
//   p_c = m - R_c t_k(q) - R_m d                           (4)
// For the rotator about x then y, R_k(q) = R_x(a) R_y(b), so R_m = R_c R_x(a) R_y(b) as the
// issue states. (4) is linear in d with dp_c/dd = -R_m and dR_c/dd = 0 (5): a
// calibration's column of the offset is the statics' position partials times -R_m e_j,
// and a translation of the cabin is the towers' opposite translation
// (dT/dp_c = -sum_i dT/dB_i), which the tension gradient already has.
//
// What the data tell of d (docs/calibration.md "The measured frame"): only the cabin's
// position depends on it, and the tensions see a position only through the cables'
// geometry (1 to 3 kN per metre at FAST's scale, against 5 kN of noise per reading).
// A component whose direction R_m e_j never turns over the survey moves every sample's
// cabin by the same vector; one that turns moves them differently.
#ifndef FASTCAL_MEASURED_FRAME_H_
#define FASTCAL_MEASURED_FRAME_H_

#include <Eigen/Core>
#include <string>

#include "fastcal/moving_parts.h"
#include "fastcal/pose.h"

namespace fastcal {

struct MeasuredFrame {
  // The moving part whose frame the data's attitude is and whose frame carries the
  // measured point (an index into MovingParts::parts), or -1: the cabin itself.
  int part = -1;
  // The measured point in that frame, m (the phase centre's lever arm).
  Eigen::Vector3d offset_m = Eigen::Vector3d::Zero();

  // A part in range of `parts` and a finite offset; on failure names the key
  // ("cabin.measured_frame.offset_m: must be finite").
  bool IsValid(const MovingParts& parts, std::string* error) const;
};

// The measured frame's part frame in the cabin frame at `joints`: R_k(q) and t_k(q) of
// (1)-(4) (identity and 0 for the cabin).
struct FrameInCabin {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d origin_m = Eigen::Vector3d::Zero();
};
FrameInCabin MeasuredFrameInCabin(const MeasuredFrame& frame, const MovingParts& parts,
                                  const JointValues& joints);

// (3), (4): the cabin's pose from the data's pose (the measured frame's) at `joints`.
Pose CabinPoseFromMeasured(const MeasuredFrame& frame, const MovingParts& parts,
                           const Pose& measured, const JointValues& joints);
// (1), (2): the data's pose (the measured frame's) from the cabin's pose at `joints`.
Pose MeasuredPoseFromCabin(const MeasuredFrame& frame, const MovingParts& parts, const Pose& cabin,
                           const JointValues& joints);

// The measured frame in words for reports and summaries: "the cabin's own frame" for a
// model without one; else "stewart's frame, point (0, 0, -1.2) m in it".
std::string DescribeMeasuredFrame(const MeasuredFrame* frame, const MovingParts& parts);

}  // namespace fastcal

#endif  // FASTCAL_MEASURED_FRAME_H_
