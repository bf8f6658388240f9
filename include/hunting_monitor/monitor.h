/*
 * hunting_monitor - the online monitor: one object that the ROS node, `hunting estimate` and the tests share.
 *
 * It owns the streaming estimator (estimator.h), the hunting-mode identification (modal.h), the margin
 * (margin.h), the Hopf interval built from the margin's estimates, the prior and the boundary table (interval.h,
 * tables.h) and the alarm that decides levels on it (alarm.h), and holds the start-up policy:
 *  - the table: a given one must have been made for this vehicle (hm_table_check_vehicle: stiffnesses and every
 *    Hopf speed against the closed form); without one it is computed for the vehicle (table_n_conicity conicities);
 *  - the conicity fallback: the alarm's conicity_fallback, or the vehicle's own lambda(0) when that is 0 (so a
 *    fitted or worn vehicle never falls back to the default vehicle's conicity);
 *  - the table's refinement: where the table's expected interpolation error at the conicity in use
 *    (hm_table_local_error) exceeds the tolerances, the exact family there is wanted (hm_monitor_table_wanted); the
 *    caller computes it with hm_table_refine, on another thread if it likes (the table is only read), and hands
 *    the result back (hm_monitor_replace_table). The monitor itself never blocks on a computation after create;
 *  - the identification follows the estimator: restarted after a gap, redesigned for a measured sample rate, fed
 *    the same interpolated samples where the estimator bridged lost ones.
 * At a steady speed the identification's windows go to the margin with the speed's mean and range: the current
 * stretch provisionally (from min_window_s), committed in full windows (window_s) and when the stretch ends. While
 * the speed changes gradually (acceleration or braking up to about 0.5 km/h/s: the margin's max_speed_spread_kmh,
 * 12 km/h, in at least min_window_s) the stretch that reached that spread is committed whole, windows back to back;
 * the margin counts the model's change of the decay rate over the window's speed range as a systematic error. A window
 * during which an update saw a criterion met (hunting or its onset: sliding r.m.s., peaks, displacement) is not given
 * to the margin (HM_WINDOW_NONLINEAR): a hunting limit cycle is not the linear mode, and its "decay rate" of about
 * zero would read as a Hopf speed at the current speed (on the independent simulator it once read 168 km/h).
 * The track's lines (track_lines.h): each fit whose window was at least half at one speed (the chunks' means within
 * half the wavelength tolerance of the newest's) gives its lone lines, its narrow peak and its comb's fundamental, at
 * that speed, to the record of lines; its narrow peak, if its wavelength was seen at another speed, is marked a track
 * line (mode.narrow_peak_tracked) before the margin judges the window. The record is forgotten with the margin's
 * windows (a reset) and moved with them (a known time step); it is not in the state record (a restart relearns it).
 * No allocation after create.
 */
#ifndef HUNTING_MONITOR_MONITOR_H
#define HUNTING_MONITOR_MONITOR_H

#include <stddef.h>

#include "hunting_monitor/alarm.h"
#include "hunting_monitor/estimator.h"
#include "hunting_monitor/margin.h"
#include "hunting_monitor/modal.h"
#include "hunting_monitor/model.h"
#include "hunting_monitor/status.h"
#include "hunting_monitor/tables.h"
#include "hunting_monitor/track_lines.h"

/* A bogie's or car's monitor with margin.spectrum_*_hz set fits each window's spectrum by its model (spectrum_fit.h):
 * every full window, and a steady stretch's provisional window at most this often [s] (between, the stretch's last
 * fit stands for it). */
#define HM_MONITOR_SPECTRUM_EVERY_S 5.0

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
  hm_estimator_config estimator;
  hm_modal_config modal;
  hm_margin_config margin;
  hm_alarm_config alarm;
  hm_track_lines_config track_lines; /* lines told from the mode by their wavelength across speeds */
  size_t table_n_conicity; /* conicities of a table computed at start (when none is given) */
  struct {
    int refine;              /* 1: want the exact family where the interpolation would err more than below */
    double tolerance_kmh;    /* on the lowest cycle speed */
    double tolerance_m;      /* on the cycle amplitudes */
    unsigned max_curves;     /* stop refining at this many curves (memory: 5-50 kB each) */
  } table;
} hm_monitor_config;

/* Every part's defaults; 36 conicities for a computed table (as the shipped one: 0.48 km/h, 0.09 mm of measured
 * interpolation error); refinement on, 0.05 km/h, 5 um, 200 curves. */
void hm_monitor_config_default(hm_monitor_config *cfg);
/* The first invalid field as "section.field: reason". */
hm_status hm_monitor_config_validate(const hm_monitor_config *cfg, char *why, size_t why_len);

typedef struct {
  hm_estimate estimate;        /* amplitude, frequency, criteria, inputs */
  hm_mode_estimate mode;       /* the latest identification of the hunting mode (valid 0 before the first) */
  double mode_speed_kmh;       /* mean speed over its window */
  double mode_speed_spread_kmh;/* and its range */
  hm_window_verdict mode_verdict; /* whether the margin used that window */
  int mode_steady;             /* mode.valid and its window was one the margin can use (a steady speed, or one
                                  changing gradually, its range within max_speed_spread_kmh), without a criterion
                                  met: the decay rate means what it says at mode_speed_kmh (a fit over a speed
                                  changing faster is shown as not valid) */
  double line_wavelength_m;    /* a periodic excitation in that window (mode.lines_found): V / f1 [m]; 0 if none */
  hm_margin_estimate margin;   /* conicity, Hopf speed model-based and model-free, mismatch */
  hm_assessment assessment;    /* level, reason, boundaries and margins */
} hm_monitor_status;

typedef struct hm_monitor_s *hm_monitor;

/*
 * Create for a vehicle. table: one loaded from a file (the monitor takes it over, also on failure) or NULL to
 * compute it (seconds). HM_EDOMAIN with the reason in why for a bad configuration, vehicle or table (a table for
 * another vehicle), HM_ENOMEM, or the table computation's status. *out untouched on failure.
 */
hm_status hm_monitor_create(const hm_monitor_config *cfg, const hm_vehicle *veh, hm_table table, hm_monitor *out,
                            char *why, size_t why_len);
/* The same, a table to compute being computed through pfor(runner, ...) (tables.h; e.g. on every processor). */
hm_status hm_monitor_create_parallel(const hm_monitor_config *cfg, const hm_vehicle *veh, hm_table table,
                                     hm_parallel_for_fn pfor, void *runner, hm_monitor *out, char *why, size_t why_len);
/* A monitor of a bogie or a car (issue #28): its identified modes read, and its Hopf speeds and boundaries taken, by
 * that model (mode_model.h, a table of its families: hm_table_build_model, or table checked against it); with
 * HM_MODEL_WHEELSET exactly hm_monitor_create_parallel with params->bogie.wheelset. The monitor's vehicle
 * (hm_monitor_vehicle) is the wheelsets'. Takes table in every case. */
hm_status hm_monitor_create_model(const hm_monitor_config *cfg, hm_model_kind kind, const hm_car *params,
                                  hm_table table, hm_parallel_for_fn pfor, void *runner, hm_monitor *out, char *why,
                                  size_t why_len);
hm_model_kind hm_monitor_model_kind(const hm_monitor m);
/* The model's parameters (for the wheelset: hm_car_default's with its wheelset). */
void hm_monitor_model_params(const hm_monitor m, hm_car *params);
void hm_monitor_destroy(hm_monitor m);
/* Forget the stream (the time line restarted, by an unknown step): estimator, identification, the margin's windows
 * (their times are on the old line) and the alarm's hold; a held ALARM stays held with its hunted-at speed (a latch
 * carries no times that matter, hm_alarm_restart). */
void hm_monitor_reset(hm_monitor m);
/* The time line stepped by a known delta_s (a sensor clock step, a ROS time correction): the stream restarts
 * (estimator, identification), but the margin's windows and the alarm keep their ages, every time they hold moved by
 * delta_s (hm_margin_shift_time, hm_alarm_shift_time). A non-finite delta_s is hm_monitor_reset. */
void hm_monitor_time_jump(hm_monitor m, double delta_s);

/* One acceleration sample [m/s^2] at t_s; the estimator's status (rejected samples are counted there). */
hm_status hm_monitor_push_accel(hm_monitor m, double t_s, double accel_mps2);
/* One speed update [km/h]. */
hm_status hm_monitor_push_speed(hm_monitor m, double t_s, double speed_kmh);
/* Evaluate at now_s. HM_EINVAL for NULL or non-finite now; out untouched on failure. */
hm_status hm_monitor_update(hm_monitor m, double now_s, hm_monitor_status *out);

/* The settings that may change while monitoring (commissioning): the alarm's (cfg->alarm: margins, hysteresis,
 * hold time, use of the conicity estimate) and the standard criteria's limits (cfg->estimator.rms_limit_mps2,
 * peaks_limit_mps2, peaks_count); cfg's other fields are ignored (they need a new monitor). Validated as a whole
 * with the running settings (HM_EDOMAIN, "section.field: reason" in why): on failure nothing changes. The level
 * and the stream's state are kept. hm_monitor_settings gives the running configuration. */
hm_status hm_monitor_set_runtime_settings(hm_monitor m, const hm_monitor_config *cfg, char *why, size_t why_len);
void hm_monitor_settings(const hm_monitor m, hm_monitor_config *cfg);

/* The table in use (borrowed, valid until the next hm_monitor_replace_table), e.g. for reporting its range and
 * errors, or to refine (hm_table_refine only reads it). */
hm_table hm_monitor_table(const hm_monitor m);

/* 1 with the conicity in use (of the latest update, not NO_DATA) in *conicity when refinement is on, the table has
 * fewer than max_curves curves, its expected interpolation error there exceeds a tolerance, and no family failed
 * within 1e-4 of it (hm_monitor_table_failed); else 0. */
int hm_monitor_table_wanted(const hm_monitor m, double *conicity);
/* The exact family at this conicity could not be computed: it is not wanted there again (the table's interpolation
 * stays in use there) until another conicity fails. */
void hm_monitor_table_failed(hm_monitor m, double conicity);
/* Use table from the next update on. The monitor takes it over (also on failure, when it is destroyed). The table
 * it replaces goes to *replaced (the caller destroys it, e.g. on the thread that made the new one, off the
 * callbacks) or, with replaced NULL, is destroyed. HM_EDOMAIN (reason in why) for a table of another vehicle,
 * which is not used (*replaced is then NULL). */
hm_status hm_monitor_replace_table(hm_monitor m, hm_table table, hm_table *replaced, char *why, size_t why_len);

/* The vehicle the monitor was made for. */
void hm_monitor_vehicle(const hm_monitor m, hm_vehicle *veh);

/* What the monitor has learned, kept through a restart (state.h writes it as bytes): the margin's windows, misfits,
 * change state and narrow-peak verdicts, the alarm's latch and hunted-at speed, and the interval's memory of the
 * estimate's use (interval.h), with times as ages
 * before a "now" [s]. The stream (estimator, identification, the steady stretch) is not in it: it restarts. */
typedef struct {
  hm_margin_snapshot margin;
  hm_alarm_snapshot alarm;
  hm_interval_snapshot interval; /* whether the estimate was in use alone, its error's hysteresis and wait */
} hm_monitor_snapshot;

/* What m holds as of now_s (its time line); nothing is written for NULL or a non-finite now_s. */
void hm_monitor_take_snapshot(const hm_monitor m, double now_s, hm_monitor_snapshot *out);
/* Replace what m has learned by snap, its ages counted back from now_s (m's time line, which may be another than the
 * one snap was taken on): the stream restarts (as at hm_monitor_reset), then the margin, the interval and the alarm
 * take snap's (hm_margin_restore, hm_interval_restore, hm_alarm_restore; a held ALARM is held again). HM_EINVAL for NULL or a non-finite now_s,
 * HM_EDOMAIN (reason in why) for an invalid snap, checked as a whole first: m untouched on failure. */
hm_status hm_monitor_restore(hm_monitor m, double now_s, const hm_monitor_snapshot *snap, char *why, size_t why_len);

#ifdef __cplusplus
}
#endif

#endif
