/*
 * hunting_monitor - the wheelset model driven along a track: a lateral track irregularity y_t(s) entering the
 * wheel-rail terms, and a speed profile (used by the simulator, the demo and the monitor's tests).
 *
 * The irregularity acts through the wheelset's displacement relative to the track, y_r = y - y_t(s) at the
 * distance s travelled: the conicity term and the flange force use y_r (the rolling-radius difference and the
 * flange contact depend on the position on the rail), the suspension terms keep y (relative to the bogie):
 *   x2' = -(Kx/m)(l0/l1 - 1) y - (Ky/m) y - 2 ky/(m v) x2 + 2 ky/m x3 - F_T(y_r)/m
 *   x4' = -(2 d0 kx lambda(y_r)/(I r0)) y_r - (Kx d1^2/I) x3 - (2 d0^2 kx/(I v)) x4
 * y_t is a sum of sinusoids in distance with random phases whose amplitudes follow the German high-speed
 * track alignment spectrum for low disturbance, S(W) = A Wc^2 / ((W^2 + Wr^2)(W^2 + Wc^2)) with A = 2.119e-7 m rad,
 * Wc = 0.8246 rad/m, Wr = 0.0206 rad/m (one-sided, W the spatial angular frequency), times a scale.
 */
#ifndef HUNTING_MONITOR_EXCITATION_H
#define HUNTING_MONITOR_EXCITATION_H

#include <stddef.h>
#include <stdint.h>

#include "hunting_monitor/model.h"
#include "hunting_monitor/status.h"

#ifdef __cplusplus
extern "C" {
#endif

#define HM_IRREGULARITY_MAX_TERMS 256

typedef struct {
  size_t n;
  double amplitude_m[HM_IRREGULARITY_MAX_TERMS];
  double wavenumber_rad_m[HM_IRREGULARITY_MAX_TERMS];
  double phase_rad[HM_IRREGULARITY_MAX_TERMS];
} hm_irregularity;

/* n terms (1..256) evenly spaced in wavelength between wavelength_min_m and wavelength_max_m, amplitudes from
 * the spectrum times sqrt(scale) (scale 1: the low-disturbance spectrum), phases from seed. */
hm_status hm_irregularity_generate(hm_irregularity *irr, size_t n, double wavelength_min_m, double wavelength_max_m,
                                   double scale, uint64_t seed);
/* y_t at distance s [m]. */
double hm_irregularity_at(const hm_irregularity *irr, double s_m);

typedef struct {
  hm_model model;                /* vehicle; its speed is set from the profile at each evaluation */
  const hm_irregularity *irr;    /* may be NULL: a perfect track */
  double v_start_kmh, v_end_kmh; /* speed ramps linearly from v_start to v_end over ramp_s, then stays */
  double ramp_s;
} hm_excited_model;

/* Fill em (validates the vehicle and speeds > 0; ramp_s >= 0). irr is borrowed. */
hm_status hm_excited_model_init(hm_excited_model *em, const hm_vehicle *veh, const hm_irregularity *irr,
                                double v_start_kmh, double v_end_kmh, double ramp_s);
double hm_excited_speed_kmh(const hm_excited_model *em, double t_s);
double hm_excited_distance_m(const hm_excited_model *em, double t_s);
/* Right-hand side (an hm_ode_fn with params = hm_excited_model *; the model's speed field is updated). */
hm_status hm_excited_rhs(double t, const double *x, double *dxdt, void *excited_model);

#ifdef __cplusplus
}
#endif

#endif
