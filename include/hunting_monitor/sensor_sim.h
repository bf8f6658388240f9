/*
 * hunting_monitor - the sensor streams of a simulated run: the nonlinear wheelset model (model.h), or any model
 * (system.h: a bogie, a car) with an accelerometer where it is (a sensor point: an axle box, the frame, the carbody),
 * driven along a speed profile over a random track (excitation.h; a model's wheelsets meet it one after another at
 * their spacing), integrated by Dormand-Prince 5(4) (integrate.h), sampled like an accelerometer (the lateral
 * acceleration there at a fixed rate, plus white Gaussian noise; the wheelset's is its axle box, y'' = x2' of
 * MODEL.md's equations) and a speedometer. One implementation for `hunting simulate`, hunting_sim_node and the tests.
 *
 * Sample k of a stream is taken at t = k / rate exactly (no accumulated drift), from the integrator's dense
 * output; speed samples due at or before an acceleration sample are delivered first. The noise comes from one
 * generator seeded with noise_seed, the track from track_seed: a run is reproducible bit for bit.
 */
#ifndef HUNTING_MONITOR_SENSOR_SIM_H
#define HUNTING_MONITOR_SENSOR_SIM_H

#include <stddef.h>
#include <stdint.h>

#include "hunting_monitor/excitation.h"
#include "hunting_monitor/model.h"
#include "hunting_monitor/status.h"
#include "hunting_monitor/system.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
  double v_start_kmh, v_end_kmh;  /* the speed ramps linearly from v_start to v_end over ramp_s, then stays */
  double ramp_s;
  /* or, with n_profile >= 1, the speed profile instead (excitation.h): linear between the points, times from 0 */
  size_t n_profile;
  double profile_t_s[HM_SPEED_PROFILE_MAX], profile_v_kmh[HM_SPEED_PROFILE_MAX];
  double irregularity_scale;      /* power of the German low-disturbance spectrum times this (0: a perfect track) */
  double wavelength_min_m, wavelength_max_m; /* the irregularity's band: 3 and 120 m */
  uint64_t track_seed;            /* the track's random amplitudes */
  uint64_t noise_seed;            /* the sensor noise */
  double accel_rate_hz;           /* acceleration samples per second: 2000 */
  double accel_noise_mps2;        /* standard deviation of the acceleration's white noise: 0.05 m/s^2 */
  double speed_rate_hz;           /* speed samples per second: 10 */
  double rtol, atol;              /* integration tolerances: 1e-8, 1e-11 */
  double max_step_s;              /* largest integration step (0: none): 2e-3 s, so that a step cannot pass over
                                     the track's shortest waves (3 m take 19 ms at 560 km/h) unseen */
} hm_sensor_sim_config;

void hm_sensor_sim_config_default(hm_sensor_sim_config *cfg);

/* Where the samples go. Each callback may be NULL; a nonzero return stops the run at that sample. */
typedef struct {
  /* measured = true + noise [m/s^2]; x the true state (the wheelset's (y [m], dy/dt [m/s], psi [rad], dpsi/dt
   * [rad/s]); a system's hm_sensor_sim_dim states) */
  int (*accel)(void *ctx, double t_s, double measured_mps2, double true_mps2, const double *x);
  int (*speed)(void *ctx, double t_s, double speed_kmh);
  void *ctx;
} hm_sensor_sink;

typedef struct hm_sensor_sim_s *hm_sensor_sim;

/* A run at t = 0 from state x0 (NULL: at rest). Validates the vehicle and every setting (speeds > 0, ramp >= 0,
 * scale >= 0, band within 0.2..1000 m, rates in (0, 1e6], noise >= 0, rtol > 0, atol >= 0, max step >= 0, x0
 * finite); HM_EDOMAIN with the reason in why (may be NULL: "field: reason (got value)" for a setting, a sentence for
 * the profile or x0), HM_EINVAL for a NULL argument, HM_ENOMEM. Allocates the track (about 2 MB when scale > 0). */
hm_status hm_sensor_sim_create(const hm_vehicle *veh, const hm_sensor_sim_config *cfg, const double x0[4],
                               hm_sensor_sim *out, char *why, size_t why_len);
/* A run of the system sys (its model kept by the caller) with the accelerometer at point; x0 of sys->dim states or
 * NULL; the same checks and errors (HM_EINVAL also for an invalid system or a point off it). */
hm_status hm_sensor_sim_create_system(const hm_system *sys, const hm_sensor_point *point,
                                      const hm_sensor_sim_config *cfg, const double *x0, hm_sensor_sim *out,
                                      char *why, size_t why_len);
void hm_sensor_sim_destroy(hm_sensor_sim sim);
/* The state dimension: 4 for the wheelset. */
size_t hm_sensor_sim_dim(const hm_sensor_sim sim);

/* Integrate to t_end_s (>= the current time), delivering every sample with time <= t_end_s not delivered yet.
 * HM_OK also when a callback stopped the run (then not to be resumed: samples of the last step are lost); the
 * integrator's error otherwise (the state and time stay where they were), or the model's when a sample's
 * acceleration could not be computed (HM_ENONFINITE: no sample is delivered for it). */
hm_status hm_sensor_sim_run(hm_sensor_sim sim, double t_end_s, const hm_sensor_sink *sink);

/* The current time [s] and true state (hm_sensor_sim_dim values). */
double hm_sensor_sim_time(const hm_sensor_sim sim);
void hm_sensor_sim_state(const hm_sensor_sim sim, double *x);
/* Replace the state now (a disturbance, such as a lateral kick); HM_EINVAL if not finite. */
hm_status hm_sensor_sim_set_state(hm_sensor_sim sim, const double *x);
/* The speed [km/h] of the profile at t. */
double hm_sensor_sim_speed_kmh(const hm_sensor_sim sim, double t_s);
/* The track's r.m.s. irregularity [m] (0 on a perfect track). */
double hm_sensor_sim_track_rms_m(const hm_sensor_sim sim);

#ifdef __cplusplus
}
#endif

#endif
