// The measured frame's pose against the cabin's: (1)-(4) of measured_frame.h,
//   R_m = R_c R_k(q),  m = p_c + R_c (t_k(q) + R_k(q) d);
//   R_c = R_m R_k(q)^T, p_c = m - R_c t_k(q) - R_m d.
#include "fastcal/measured_frame.h"

#include "fastcal/internal/number_text.h"

namespace fastcal {

bool MeasuredFrame::IsValid(const MovingParts& parts, std::string* error) const {
  const auto fail = [&](const std::string& key, const std::string& why) {
    if (error != nullptr) *error = "cabin.measured_frame." + key + ": " + why;
    return false;
  };
  if (part < -1 || part >= static_cast<int>(parts.parts.size())) {
    return fail("part", "must be cabin or one of the model's cabin.moving_parts");
  }
  if (!offset_m.allFinite()) return fail("offset_m", "must be finite");
  return true;
}

FrameInCabin MeasuredFrameInCabin(const MeasuredFrame& frame, const MovingParts& parts,
                                  const JointValues& joints) {
  FrameInCabin out;
  if (frame.part < 0) return out;
  PartFrames frames;
  parts.FramesAt(joints, &frames);
  out.rotation = frames[frame.part].rotation;
  out.origin_m = frames[frame.part].origin_m;
  return out;
}

Pose CabinPoseFromMeasured(const MeasuredFrame& frame, const MovingParts& parts,
                           const Pose& measured, const JointValues& joints) {
  const FrameInCabin f = MeasuredFrameInCabin(frame, parts, joints);
  Pose cabin;
  cabin.rotation = measured.rotation * f.rotation.transpose();            // (3)
  cabin.position_m = measured.position_m - cabin.rotation * f.origin_m -  // (4)
                     measured.rotation * frame.offset_m;
  return cabin;
}

Pose MeasuredPoseFromCabin(const MeasuredFrame& frame, const MovingParts& parts, const Pose& cabin,
                           const JointValues& joints) {
  const FrameInCabin f = MeasuredFrameInCabin(frame, parts, joints);
  Pose measured;
  measured.rotation = cabin.rotation * f.rotation;  // (1)
  measured.position_m =
      cabin.position_m + cabin.rotation * (f.origin_m + f.rotation * frame.offset_m);  // (2)
  return measured;
}

std::string DescribeMeasuredFrame(const MeasuredFrame* frame, const MovingParts& parts) {
  if (frame == nullptr) return "the cabin's own frame (origin at the centre of its anchor points)";
  const auto num = [](double v) { return internal::FormatDouble("%.6g", v); };
  const std::string point = "(" + num(frame->offset_m.x()) + ", " + num(frame->offset_m.y()) +
                            ", " + num(frame->offset_m.z()) + ") m";
  if (frame->part < 0) return "a point " + point + " of the cabin's frame, with its attitude";
  return "a point " + point + " of " + parts.parts[frame->part].name +
         "'s frame, with that frame's attitude (the cabin's follows from the joints)";
}

}  // namespace fastcal
