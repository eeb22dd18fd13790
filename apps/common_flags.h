// The flags more than one command reads, declared once (issue 54: each command's own
// flags are defined in its own file; these in common_flags.cc).
#ifndef FASTCAL_APPS_COMMON_FLAGS_H_
#define FASTCAL_APPS_COMMON_FLAGS_H_

#include <gflags/gflags.h>

DECLARE_string(attitude_law);
DECLARE_double(attitude_noise_deg);
DECLARE_double(azimuth_step_deg);
DECLARE_string(cable_damping_ratio);
DECLARE_string(centre);
DECLARE_string(columns);
DECLARE_double(damping_ratio);
DECLARE_string(data);
DECLARE_double(end_deg);
DECLARE_string(focal_centre);
DECLARE_double(focal_radius);
DECLARE_bool(force);
DECLARE_string(from);
DECLARE_string(gust_spectrum);
DECLARE_double(hold_s);
DECLARE_string(html);
DECLARE_double(interval_s);
DECLARE_string(joints);
DECLARE_bool(keep_going);
DECLARE_string(lengths);
DECLARE_double(max_length_ratio);
DECLARE_double(max_off_axis_deg);
DECLARE_double(max_strain);
DECLARE_string(method);
DECLARE_string(model);
DECLARE_double(move_s);
DECLARE_int32(nodes);
DECLARE_double(off_axis_step_deg);
DECLARE_string(out);
DECLARE_string(output);
DECLARE_string(poses);
DECLARE_string(position);
DECLARE_double(position_noise_m);
DECLARE_string(quat);
DECLARE_bool(quiet);
DECLARE_double(radial_spread);
DECLARE_double(radius);
DECLARE_double(reflector_clearance);
DECLARE_int32(residuals_every);
DECLARE_string(rpy);
DECLARE_int32(samples);
DECLARE_uint64(seed);
DECLARE_int32(segments);
DECLARE_string(sessions_at);
DECLARE_double(settle_fraction);
DECLARE_bool(skip_invalid_rows);
DECLARE_string(spec);
DECLARE_double(speed_m_per_s);
DECLARE_double(start_deg);
DECLARE_double(step_s);
DECLARE_string(summary);
DECLARE_double(tension_noise_kN);
DECLARE_double(tilt_fraction);
DECLARE_string(to);
DECLARE_string(to_rpy);
DECLARE_string(trajectory);
DECLARE_string(truth);
DECLARE_double(turbulence_intensity);
DECLARE_bool(vibration);
DECLARE_bool(warm_start);
DECLARE_string(wind);

#endif  // FASTCAL_APPS_COMMON_FLAGS_H_
