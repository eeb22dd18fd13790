// The flags more than one command reads (common_flags.h), defined once, grouped by the
// command that first had them.
#include "common_flags.h"

#include "fastcal/dynamics.h"
#include "fastcal/modes.h"
#include "fastcal/wind.h"

// First calibrate's.
DEFINE_int32(residuals_every, 1,
             "calibrate, evaluate: residuals.csv keeps every K-th sample (1: all; 0: no file).");
DEFINE_string(spec, "", "calibrate: calibration spec YAML (docs/calibration.md).");
DEFINE_string(data, "",
              "Measurement CSV (docs/data-format.md); several, comma-separated, are one "
              "session each, labelled by file name.");
DEFINE_string(out, "", "Output directory (must not exist, or be empty).");
DEFINE_bool(skip_invalid_rows, false,
            "Skip dataset rows that are malformed or whose pose the model cannot solve "
            "(listed on stderr and in the report) instead of failing.");
DEFINE_bool(quiet, false, "calibrate: no per-iteration progress.");

// First columns_flag's.
DEFINE_string(columns, "",
              "A column map (docs/data-format.md, \"Column maps\"): read the telemetry export "
              "as it comes (its column names, units, time stamps, delimiter, decimal comma).");
DEFINE_string(sessions_at, "",
              "calibrate, import: cut one survey into sessions at these times "
              "(TIME[,TIME...]: time_s or ISO 8601), or at the changes of a previous "
              "calibrate's summary.json.");

// First design's.
DEFINE_double(speed_m_per_s, 0.0, "design: cabin speed between stops (m/s); 0: no duration.");

// First dynamics's.
DEFINE_string(cable_damping_ratio, "",
              "dynamics: six damping ratios, each cable's first axial mode's.");
DEFINE_string(wind, "", "dynamics: SPEED,DIRECTION_DEG, the mean wind (m/s) and where it blows.");
DEFINE_string(gust_spectrum, "kaimal", "dynamics: kaimal | davenport.");
DEFINE_double(turbulence_intensity, fastcal::WindOptions().turbulence_intensity,
              "dynamics: the gusts' sigma / mean speed.");
DEFINE_double(move_s, 60.0, "dynamics --to: the move's duration (s).");
DEFINE_double(hold_s, 120.0, "dynamics: the time after the winches stop (s).");
DEFINE_string(to_rpy, "", "dynamics --to: the end attitude roll,pitch,yaw (deg).");
DEFINE_string(summary, "", "dynamics: the summary as JSON to this file.");
DEFINE_double(damping_ratio, fastcal::DynamicsOptions().damping_ratio,
              "dynamics: the lowest mode's damping ratio (strain-rate damping).");
DEFINE_double(settle_fraction, 0.005,
              "dynamics, design: the settle band, a fraction of each quasi-static tension "
              "(design: 0, no waits after moves).");
DEFINE_double(step_s, fastcal::DynamicsOptions().max_step_s,
              "dynamics: the largest integration step (s).");

// First locate's.
DEFINE_string(lengths, "", "locate: the six unstretched lengths L1,...,L6 (m), cable 1 first.");

// First modes's.
DEFINE_int32(segments, fastcal::ModesOptions().segments,
             "modes: segments per cable (the lumped-mass chain's resolution).");

// First simulate's.
DEFINE_string(truth, "", "simulate: truth model YAML; empty = nominal FAST.");
DEFINE_double(attitude_noise_deg, 0.0, "simulate: sigma of measured - actual rpy (deg).");
DEFINE_double(position_noise_m, 0.0, "simulate: sigma of measured - actual position (m).");
DEFINE_double(tension_noise_kN, 0.0, "simulate: absolute tension noise sigma (kN).");
DEFINE_double(interval_s, 1.0, "simulate: time between samples (s).");

// First simulate_vibration's.
DEFINE_bool(vibration, false, "simulate: a free vibration at --position (docs/cli.md).");

// First solve's.
DEFINE_string(model, "", "Model YAML (docs/model-format.md); empty = nominal FAST.");
DEFINE_string(method, "exact", "exact | aas | aas-refined | compare");
DEFINE_string(position, "", "Single pose: x,y,z of the cabin frame origin (m).");
DEFINE_string(rpy, "", "Attitude roll,pitch,yaw (deg), R = Rz(yaw) Ry(pitch) Rx(roll).");
DEFINE_string(quat, "", "Attitude as unit quaternion w,x,y,z.");
DEFINE_string(attitude_law, "",
              "'focal': attitude from the focal law; 'none': R = I. Default: focal for "
              "trajectories, R = I for one --position, the file's own for --poses.");
DEFINE_double(tilt_fraction, 0.41, "Focal law: fraction of the off-axis angle.");
DEFINE_string(focal_centre, "0,0,300", "Focal law and grids: focal-sphere centre x,y,z (m).");
DEFINE_string(trajectory, "point", "point | circle | line | arc | grid | random");
DEFINE_string(from, "50,0,150", "line: first node x,y,z (m).");
DEFINE_string(to, "-50,0,150", "line: last node x,y,z (m).");
DEFINE_int32(nodes, 101, "line, arc (101), circle (360): number of nodes.");
DEFINE_string(centre, "0,0,150", "arc: centre x,y,z (m); the arc is horizontal.");
DEFINE_double(radius, 50.0, "arc: radius (m).");
DEFINE_double(start_deg, 0.0, "arc: first angle from +x toward +y (deg).");
DEFINE_double(end_deg, 180.0, "arc: last angle (deg); 360 from start = full circle.");
DEFINE_double(max_off_axis_deg, 40.0, "grid, random: largest off-axis angle (deg).");
DEFINE_double(off_axis_step_deg, 5.0, "grid: ring spacing (deg).");
DEFINE_double(azimuth_step_deg, 15.0, "grid: azimuth spacing (deg).");
DEFINE_double(focal_radius, 160.0, "grid, random: focal-sphere radius (m).");
DEFINE_int32(samples, 100, "random: number of poses.");
DEFINE_uint64(seed, 1, "random: generator seed.");
DEFINE_double(radial_spread, 0.0, "random: uniform offset along the sphere normal, +-m.");
DEFINE_string(joints, "",
              "Moving parts' joint values for every pose, the model's joint order and the "
              "columns' units (deg, m); default all 0.");
DEFINE_string(poses, "", "CSV of poses (x_m,y_m,z_m[,roll_deg,pitch_deg,yaw_deg|qw,qx,qy,qz]).");
DEFINE_string(output, "", "Output file; empty or - = stdout. Written only on success.");
DEFINE_bool(force, false, "Replace an existing output file (solve --output, simulate --out).");
DEFINE_double(max_strain, 0.05, "Model range: largest cable strain (tension / EA).");
DEFINE_double(max_length_ratio, 1.5, "Model range: largest unstretched length / chord, s0/k.");
DEFINE_double(reflector_clearance, 0.0,
              "Smallest clearance (m) of a cable from the model's reflector surface.");
DEFINE_bool(warm_start, true, "Start each trajectory node from the previous solution.");
DEFINE_bool(keep_going, false,
            "Write infeasible poses as rows with their status instead of failing.");

// First workspace's.
DEFINE_string(html, "", "workspace: also write the map as a self-contained HTML file.");
