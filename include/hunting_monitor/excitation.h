/*
 * hunting_monitor - the wheelset model driven along a track: a lateral track irregularity y_t(s) entering the
 * wheel-rail terms, and a speed profile (used by the simulator, the demo and the monitor's tests).
 *
 * The irregularity acts through the wheelset's displacement relative to the track, y_r = y - y_t(s) at the
 * distance s travelled: the conicity term and the flange force use y_r (the rolling-radius difference and the
 * flange contact depend on the position on the rail), the suspension terms keep y (relative to the bogie):
 *   x2' = -(Kx/m)(l0/l1 - 1) y - (Ky/m) y - 2 ky/(m v) x2 + 2 ky/m x3 - F_T(y_r)/m
 *   x4' = -(2 d0 kx lambda(y_r)/(I r0)) y_r - (Kx d1^2/I) x3 - (2 d0^2 kx/(I v)) x4
 * y_t is a Gaussian random process in distance with the German high-speed track alignment spectrum for low
 * disturbance, S(W) = A Wc^2 / ((W^2 + Wr^2)(W^2 + Wc^2)) with A = 2.119e-7 m rad, Wc = 0.8246 rad/m,
 * Wr = 0.0206 rad/m (one-sided, W the spatial angular frequency), times a scale, between two wavelengths: every
 * Fourier line of a 26 km periodic track (spacing 2.4e-4 rad/m, far finer than any resonance the wheelset has at
 * service speeds) with a complex Gaussian amplitude, by one inverse FFT onto a 0.1 m grid, linearly interpolated.
 * (An earlier sum of 200 sinusoids evenly spaced in wavelength left lines 0.8 Hz apart at 14 Hz and 500 km/h: the
 * lightly damped hunting mode then answered at the nearest line, not at its own frequency.)
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

typedef struct hm_track_s *hm_track;

/* A track (allocates about 2 MB) with the spectrum above times scale (>= 0) between wavelength_min_m and
 * wavelength_max_m (0.2 <= min < max <= 1000), its random amplitudes and phases from seed. HM_EINVAL for bad
 * arguments, HM_ENOMEM. */
hm_status hm_track_create(double wavelength_min_m, double wavelength_max_m, double scale, uint64_t seed,
                          hm_track *out);
void hm_track_destroy(hm_track track);
/* y_t [m] at distance s [m] (the track repeats every 26.2 km). */
double hm_track_at(const hm_track track, double s_m);
/* The alignment spectrum's shape S(W) [m^2 / (rad/m)] at wavenumber W [rad/m] (scale 1): the German high-speed one
 * for low disturbance, A Wc^2 / ((W^2 + Wr^2)(W^2 + Wc^2)). */
double hm_track_alignment_psd(double wavenumber_rad_m);

/* Its r.m.s. [m] and the one the spectrum gives over the band (they agree to the sampling of the amplitudes). */
double hm_track_rms_m(const hm_track track);
double hm_track_spectrum_rms_m(double wavelength_min_m, double wavelength_max_m, double scale);

/* Points of a piecewise-linear speed profile at most (a notched ramp of 5 s notches over 120 km/h takes 49). */
#define HM_SPEED_PROFILE_MAX 64

typedef struct {
  hm_model model;                /* vehicle; its speed is set from the profile at each evaluation */
  hm_track track;                /* borrowed; may be NULL: a perfect track */
  /* the speed: linear between the points (t [s], v [km/h]), constant before the first and after the last; the
   * distance run at each point [m] (exact: trapezoids) */
  size_t n_profile;
  double profile_t_s[HM_SPEED_PROFILE_MAX], profile_v_kmh[HM_SPEED_PROFILE_MAX], profile_s_m[HM_SPEED_PROFILE_MAX];
} hm_excited_model;

/* Fill em with a ramp from v_start to v_end over ramp_s, then steady (validates the vehicle and speeds > 0; ramp_s
 * >= 0). track is borrowed. */
hm_status hm_excited_model_init(hm_excited_model *em, const hm_vehicle *veh, const hm_track track,
                                double v_start_kmh, double v_end_kmh, double ramp_s);
/* 1 for a valid speed profile: n points (1..HM_SPEED_PROFILE_MAX), finite times increasing from 0 s, finite speeds
 * > 0 km/h; else 0. */
int hm_speed_profile_valid(const double *t_s, const double *v_kmh, size_t n);
/* The same with a profile of n points (hm_speed_profile_valid): steps are two points close in time, holds two points
 * at one speed. HM_EDOMAIN for an invalid one. */
hm_status hm_excited_model_init_profile(hm_excited_model *em, const hm_vehicle *veh, const hm_track track,
                                        const double *t_s, const double *v_kmh, size_t n);
double hm_excited_speed_kmh(const hm_excited_model *em, double t_s);
double hm_excited_distance_m(const hm_excited_model *em, double t_s);
/* Right-hand side (an hm_ode_fn with params = hm_excited_model *; the model's speed field is updated). */
hm_status hm_excited_rhs(double t, const double *x, double *dxdt, void *excited_model);

#ifdef __cplusplus
}
#endif

#endif
