/* fastcal's C interface: the statics of FAST's cable robot for a control loop.
 *
 * The same solvers as the C++ library (fastcal/statics.h, fastcal/locate.h), behind opaque
 * handles, for controllers that are not C++ (C, LabVIEW, MATLAB, a PLC runtime, Python
 * through ctypes). docs/embedding.md has the examples, the guarantees and the latency.
 *
 * The guarantees of a solve, once a handle is created:
 *  - no heap allocation, no lock, nothing thrown: every failure is a status (int) and a
 *    message kept in the handle (fastcal_solver_error), written into a fixed buffer;
 *  - a bounded number of iterations (docs/embedding.md, "A bounded time"): Newton from
 *    the last solve of the handle (warm), else from the paper's AAS (cold), else the
 *    continuation from the home pose, each with its own cap.
 * A handle is not thread-safe: one handle per thread (each keeps its own warm start). A
 * call on a handle another call is still using (two threads sharing one) returns
 * FASTCAL_ERROR_BUSY at once, with its outputs zeroed and the handle untouched: the other
 * call's answer is never mixed into this one's (one atomic flag; no lock, no wait).
 *
 * Outputs may overlap inputs (e.g. fastcal_solve_pose(s, buf, buf + 3, NULL, buf, NULL)):
 * every input is copied before any output is written.
 *
 * Units at this edge: positions m, angles deg (roll, pitch, yaw: R = Rz(yaw) Ry(pitch)
 * Rx(roll), frame to global), forces and tensions kN, lengths m; joint values in the
 * model's joint order and the joint columns' units (deg revolute, m prismatic).
 *
 * Poses, in and out, are the data's: those of the model's measured frame when it declares
 * one (cabin.measured_frame, docs/model-format.md: FAST's feed phase centre and Stewart
 * platform attitude, SDP_PhaPos and SDP_SwtDPose), else the cabin's own frame. The
 * cabin's pose then follows from the joints (fastcal_cabin_pose gives it).
 *
 * Statuses: 0 ok; 1..12 the statics' own (fastcal_status_name: "invalid_input",
 * "no_equilibrium", ...; StaticsStatus of fastcal/statics.h, same numbers); 100..102 a
 * control cycle's limits; negative: the call itself was wrong (a NULL handle or array, a
 * handle whose model did not load, a handle in use). On any status but 0 and 100..102, every output
 * the caller gave is zeroed (never NaN, never left as it was; a struct's status and
 * cable set); `cable` fields count from 0 (an index into the arrays), messages name
 * cables 1 to 6 as operators do.
 *
 * Warm starts: solve, solve_full and control_cycle share one (the last ok solve of the
 * handle, a limit status included); locate keeps its own. A failure leaves them as they
 * were: no reset is needed after one. The answer does not depend on the start (to the
 * solver's 1e-12), only its cost does.
 *
 * The header is C89; the examples of docs/embedding.md are C99. */
#ifndef FASTCAL_FASTCAL_H_
#define FASTCAL_FASTCAL_H_

#ifdef __cplusplus
extern "C" {
#endif

/* FASTCAL_VERSION ("0.2.0"), FASTCAL_VERSION_MAJOR, _MINOR, _PATCH: the version this
 * header belongs to. The library's soname changes with the minor version (0.x). */
#include "fastcal/version.h"

#if defined(_WIN32)
#if defined(FASTCAL_C_BUILD) /* set while building libfastcal_c itself */
#define FASTCAL_C_API __declspec(dllexport)
#else
#define FASTCAL_C_API __declspec(dllimport)
#endif
#else
#define FASTCAL_C_API __attribute__((visibility("default")))
#endif

#define FASTCAL_NUM_CABLES 6
#define FASTCAL_MAX_JOINTS 8

enum fastcal_status {
  FASTCAL_OK = 0,
  /* 1..12: the statics' own (StaticsStatus of fastcal/statics.h, same numbers). */
  FASTCAL_INVALID_INPUT = 1, /* a pose or joint value that is not finite or not plausible */
  FASTCAL_VERTICAL_CABLE = 2,
  FASTCAL_NO_EQUILIBRIUM = 3,      /* no equilibrium with every cable pulling */
  FASTCAL_SAGGING_CABLE = 4,       /* beyond the model's range: s0/k too large */
  FASTCAL_OVERSTRETCHED_CABLE = 5, /* beyond it: strain over the model's max_strain */
  FASTCAL_REFLECTOR_CONTACT = 6,   /* a cable touches the reflector */
  FASTCAL_SINGULAR = 7,
  FASTCAL_CATENARY_FAILED = 8,
  FASTCAL_NOT_CONVERGED = 9, /* out of iterations (the bound of a solve's time) */
  FASTCAL_INACCURATE = 10,
  FASTCAL_ATTACHMENT_BEYOND_CABLE = 11,
  FASTCAL_UNSUPPORTED_MODEL = 12,
  /* A control cycle's limits (fastcal_cycle_limits): the statics are ok and its numbers
   * filled, but a cable's tension or clearance is outside them. */
  FASTCAL_BELOW_MIN_TENSION = 100,
  FASTCAL_ABOVE_MAX_TENSION = 101,
  FASTCAL_INSIDE_REFLECTOR_MARGIN = 102,
  /* The call itself. */
  FASTCAL_ERROR_NULL_ARGUMENT = -1, /* a NULL handle or a required array NULL */
  FASTCAL_ERROR_NO_MODEL = -2,      /* the handle's model did not load (its error says why) */
  FASTCAL_ERROR_BAD_LIMITS = -3,    /* fastcal_cycle_limits out of range */
  FASTCAL_ERROR_INTERNAL = -4,      /* a C++ exception was caught: a defect, please report */
  FASTCAL_ERROR_BUSY = -5           /* another call is using the handle (another thread):
                                       nothing done; fastcal_solver_error is that call's */
};

/* The library's version, "major.minor.patch" (FASTCAL_VERSION of fastcal/version.h). */
FASTCAL_C_API const char* fastcal_version(void);
/* The short code of a status: "ok", "no_equilibrium", "below_min_tension",
 * "null_argument", ...; "unknown" for a number that is none. Static storage. */
FASTCAL_C_API const char* fastcal_status_name(int status);

typedef struct fastcal_solver fastcal_solver;

/* A solver for the model in `model_path` (a fastcal model YAML, e.g. a calibration's
 * model_calibrated.yaml), or the nominal FAST model for NULL. Exact statics (Newton to
 * 1e-12), the model's checks (strain, sag, reflector). Returns NULL only when out of
 * memory; a model that does not load still gives a handle, whose fastcal_solver_error
 * names the file and what is wrong, and whose solves return FASTCAL_ERROR_NO_MODEL
 * (as sqlite3_open does: the message needs a handle). Allocates; not for the cycle. */
FASTCAL_C_API fastcal_solver* fastcal_solver_create(const char* model_path);
/* The last failure of this handle's calls, or "" after a success. Valid until the next
 * call on the handle. For NULL: a message saying the handle is NULL. */
FASTCAL_C_API const char* fastcal_solver_error(const fastcal_solver* s);
/* The number of joint values the model's moving parts take (0 without), in order. */
FASTCAL_C_API int fastcal_solver_num_joints(const fastcal_solver* s);
/* The data column of joint `j` ("rotator_a_deg"), or NULL out of range. */
FASTCAL_C_API const char* fastcal_solver_joint_name(const fastcal_solver* s, int j);
/* Forget the warm start: the next solve and locate start cold. */
FASTCAL_C_API void fastcal_solver_reset(fastcal_solver* s);
FASTCAL_C_API void fastcal_solver_destroy(fastcal_solver* s);

/* The statics of one pose: lower-end (cabin) tensions in kN and unstretched lengths in
 * m, warm from this handle's last successful solve. `joints`: the moving parts' values,
 * an array of at least fastcal_solver_num_joints(s) values in the model's order, or NULL
 * for all at zero (check fastcal_solver_num_joints once at start-up: NULL on a model
 * with joints is not an error). A joint outside the range the model file states for it
 * is invalid input. tension_kN or unstretched_m may be NULL (not written then). Returns
 * 0 (ok) or a status; on failure the outputs are zero, never NaN. */
FASTCAL_C_API int fastcal_solve_pose(fastcal_solver* s, const double position_m[3],
                                     const double rpy_deg[3], const double* joints,
                                     double tension_kN[6], double unstretched_m[6]);

/* Everything a solve gives. */
typedef struct fastcal_statics {
  double tension_kN[6];         /* lower-end (cabin) tension |F_i| */
  double upper_tension_kN[6];   /* at the tower top */
  double force_kN[6][3];        /* on cable i at its lower end, global frame (the cabin
                                   feels minus this) */
  double unstretched_m[6];      /* s0_i, the model's unstretched length */
  double error_estimate;        /* largest relative tension error a Newton step would fix */
  double reflector_clearance_m; /* smallest cable clearance (+inf: none could reach it) */
  int status;                   /* as returned */
  int cable;                    /* 0-based cable a failure concerns, or -1 */
  int iterations;               /* Newton iterations (all starts) */
  int continuation;             /* 1: the warm and cold starts failed; followed from home */
} fastcal_statics;

/* fastcal_solve_pose with every output. */
FASTCAL_C_API int fastcal_solve_pose_full(fastcal_solver* s, const double position_m[3],
                                          const double rpy_deg[3], const double* joints,
                                          fastcal_statics* out);

/* The pose at which the cabin hangs with unstretched lengths `unstretched_m` (the
 * model's s0, as the solves return them; from encoder readings: fastcal_locate_winch),
 * warm from this handle's last locate; the lower-end tensions there. `joints` as for a
 * solve. Returns 0 or a status (no_equilibrium: the lengths cannot hold the cabin).
 * tension_kN may be NULL. Where several equilibria share the lengths (cables near
 * slack), the one returned is the one found from the start; `fastcal locate` on the
 * command line searches for the others. */
FASTCAL_C_API int fastcal_locate(fastcal_solver* s, const double unstretched_m[6],
                                 const double* joints, double position_m[3], double rpy_deg[3],
                                 double tension_kN[6]);
/* The same from the winch encoders' readings (what fastcal_control_cycle's
 * winch_length_m commands): each minus the model's length_offset_m, then located. */
FASTCAL_C_API int fastcal_locate_winch(fastcal_solver* s, const double winch_length_m[6],
                                       const double* joints, double position_m[3],
                                       double rpy_deg[3], double tension_kN[6]);
/* The cabin's own pose (its anchor plane's centre, its attitude) where the model's measured
 * frame has `position_m`, `rpy_deg` at `joints` (as for a solve; NULL: all zero): the same
 * pose without a measured frame. 0, or a status as a solve's (invalid_input naming the
 * value); the outputs are zero on failure. No allocation: callable in the cycle. */
FASTCAL_C_API int fastcal_cabin_pose(fastcal_solver* s, const double position_m[3],
                                     const double rpy_deg[3], const double* joints,
                                     double cabin_position_m[3], double cabin_rpy_deg[3]);

/* The model's encoder offsets (m) and tension sensors' gains and biases (kN), as the
 * control cycle applies them: winch = s0 + offset, reading = gain * tension + bias. Any
 * array may be NULL. 0, or -1/-2 for a NULL handle or one without a model. */
FASTCAL_C_API int fastcal_solver_sensors(const fastcal_solver* s, double length_offset_m[6],
                                         double sensor_gain[6], double sensor_bias_kN[6]);

/* The limits a control cycle checks beyond the model's own range. Start from
 * fastcal_default_cycle_limits() and change what you need: a zeroed struct is refused
 * (max_tension_kN must exceed min_tension_kN). */
typedef struct fastcal_cycle_limits {
  double min_tension_kN;            /* every lower-end tension at least this */
  double max_tension_kN;            /* and at most this (upper-end tensions too) */
  double min_reflector_clearance_m; /* every cable this far from the reflector */
} fastcal_cycle_limits;
/* The defaults: 50 kN, +infinity (the model states no rated load: set the cables'),
 * 5 m (docs/embedding.md says why). */
FASTCAL_C_API fastcal_cycle_limits fastcal_default_cycle_limits(void);

/* What the winches and tension sensors should show at a planned pose. */
typedef struct fastcal_cycle {
  double winch_length_m[6];     /* the encoders' readings to command: s0 + length_offset_m */
  double unstretched_m[6];      /* s0, the model's */
  double tension_kN[6];         /* lower-end tension, true */
  double sensor_reading_kN[6];  /* what each tension sensor should read (gain, bias) */
  double upper_tension_kN[6];   /* at the tower top */
  double error_estimate;        /* the statics' relative error estimate */
  double reflector_clearance_m; /* smallest cable clearance: +inf where no cable dips
                                   toward the reflector (the cap) */
  double min_tension_margin_kN; /* min over cables of tension - min_tension_kN */
  double max_tension_margin_kN; /* min over cables of max_tension_kN - max(lower, upper):
                                   +inf with the default limits (no maximum) */
  int status;                   /* as returned */
  int cable;                    /* 0-based cable a failure or limit concerns, or -1 */
} fastcal_cycle;

/* One control cycle: at the planned pose (and joints), the winch lengths to pay out and
 * the expected tensions, with the model's checks (strain, sag, reflector) and `limits`
 * (NULL: fastcal_default_cycle_limits()). Warm from the handle's last solve. A limit
 * broken returns FASTCAL_BELOW_MIN_TENSION, FASTCAL_ABOVE_MAX_TENSION or
 * FASTCAL_INSIDE_REFLECTOR_MARGIN with every number filled (the controller decides); a
 * statics failure returns its status with the numbers zero. */
FASTCAL_C_API int fastcal_control_cycle(fastcal_solver* s, const double position_m[3],
                                        const double rpy_deg[3], const double* joints,
                                        const fastcal_cycle_limits* limits, fastcal_cycle* out);

#ifdef __cplusplus
}
#endif

#endif /* FASTCAL_FASTCAL_H_ */
