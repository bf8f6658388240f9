/*
 * hunting_monitor - a conicity from the whole spectrum a vehicle model predicts at its sensor (issue #28).
 * A measured spectrum over a band is fitted by the model's spectrum at the sensor (mode_model.h: the linearised model
 * driven by the track under each wheelset) times a factor (the track's irregularity against the model's assumed
 * spectrum) plus a white floor (the sensor's noise), by the Whittle likelihood, over the conicity: a geometric scan of
 * the range, then golden section in ln(conicity) to tol. The factor and the floor are profiled out (Fisher scoring in
 * their logarithms) at each conicity. The standard error is the likelihood's curvature's (second differences 1% of
 * the conicity apart).
 * The model's spectrum is linearised at rest first; with passes > 0 the fit is repeated linearised about the motion of
 * the wheelsets the previous fit implies (hm_mode_model_motion_rms from its factor: Gaussian equivalent linearisation,
 * hm_running) until it settles. At rest MODEL.md's flange force has no slope; at 1 mm of random motion its mean slope
 * softens the wheelsets' lateral support by about 0.5 MN/m, and a fit at rest read the default bogie's frame 2.4% low
 * 30 km/h below the Hopf speed (0.1326 for 0.1358, test_spectrum_fit) and the strong yaw dampers' 6% low (0.1273,
 * docs/VEHICLES.md).
 * The measured spectrum is a two-sided density [(m/s^2)^2 / Hz] of the sensor's acceleration (any filter's power gain
 * divided out, so that the factor and the motion are absolute), each bin with dof degrees of freedom (2 for one
 * periodogram, 2 / padding for a zero-padded one, 2 K for a mean of K). Nothing is allocated (at most
 * HM_SPECTRUM_FIT_MAX_BINS bins; the work arrays are on the stack).
 */
#ifndef HUNTING_MONITOR_SPECTRUM_FIT_H
#define HUNTING_MONITOR_SPECTRUM_FIT_H

#include <stddef.h>

#include "hunting_monitor/mode_model.h"
#include "hunting_monitor/status.h"

#ifdef __cplusplus
extern "C" {
#endif

#define HM_SPECTRUM_FIT_MAX_BINS 4096
#define HM_SPECTRUM_FIT_MAX_PASSES 8
#define HM_SPECTRUM_FIT_SHAPE_PARTS 8
/* The linearisation has settled when the motion it was made about and the one its fit implies agree to this
 * (relative); the default bogie's frame at 1 mm settles in 2-3 passes, at 1.6 mm (irregularity 1) in 4 (a review's: 2
 * passes had left it 3% of the conicity off) */
#define HM_SPECTRUM_FIT_MOTION_TOL 0.01

typedef struct {
  double conicity_min, conicity_max; /* the search's range, 0 < min < max */
  double tol;                        /* the golden section's final bracket [conicity], > 0 */
  double window_s;                   /* the periodogram's window [s] for the poles' leakage (0: none, a long mean) */
  unsigned passes;                   /* linearisations about the motion found at most, 0..HM_SPECTRUM_FIT_MAX_PASSES
                                        (0: at rest only); they stop where the motion settles */
} hm_spectrum_fit_options;

/* 0.02-0.8, tol 1e-4 (a tenth of the least standard error seen), no leakage, HM_SPECTRUM_FIT_MAX_PASSES passes. */
void hm_spectrum_fit_options_default(hm_spectrum_fit_options *o);

typedef struct {
  double conicity, conicity_se;  /* the likelihood's minimum (the last pass's) and its curvature's error */
  double conicity_at_rest;       /* the first pass's, linearised at rest (the running's effect: the difference) */
  double amplitude, noise;       /* the shape's factor and the white floor [(m/s^2)^2 / Hz] */
  double motion_rms_m;           /* the leading wheelset's rms displacement from the track the fit implies [m] */
  double neg2_log_lik;           /* -2 log L at the minimum (up to a constant) */
  size_t bins;                   /* the bins fitted */
  double deviance_per_bin;       /* 2 (x - ln x - 1) over the bins, x = psd / the fit, its mean: 2 gamma = 1.154 for a
                                    periodogram's bins the model explains (exponential about it), more where not */
  double shape_chi2;             /* the fit's shape: the bins in HM_SPECTRUM_FIT_SHAPE_PARTS equal parts, each part's
                                    mean of x against 1 in its standard error sqrt(2 / (dof m)), squared and summed:
                                    about chi2 with 5 degrees of freedom (8 parts less the 3 fitted) where the model's
                                    shape is the spectrum's, far more where it is not */
  double model_share;            /* of the fitted spectrum's power over the bins, the model's (the rest the white
                                    floor's): near 0 where the floor explains the band (noise, or a sensor that sees
                                    none of the model's motion), whatever the conicity and the shape's chi2 say */
  hm_running running;            /* the linearisation the last pass's spectrum was made about (hm_spectrum_fit_peak_z) */
} hm_spectrum_fit;

/* The fit's residual under a peak: over the bins of psd[] (the spectrum fitted, or a later one of the same band and
 * dof: f_hz rising, gaps allowed, as the monitor's window spectrum leaves them where it set lines aside) whose
 * frequencies lie in [f_lo_hz, f_hi_hz] (or the one nearest to its middle where none does), the mean of x = psd /
 * (amplitude g + noise), g the model's spectrum at the fit's conicity and linearisation, less 1, over its standard
 * error sqrt(2 / (dof m)) for m bins: about N(0, 1) where the model's spectrum is the measured one there; a peak the
 * model does not produce, one bin of m 20 times the fit, 19 / sqrt(2 m / dof) (the margin excuses no pair whose peak
 * is that narrow, margin.h). HM_EDOMAIN for bad input (a NULL pointer, f_lo_hz above f_hi_hz, the range's middle
 * outside the bins, a bin of the range negative or not finite, a fit without a positive finite amplitude, non-finite
 * values), HM_ENOCONV where the model gives no spectrum; *z untouched then. */
hm_status hm_spectrum_fit_peak_z(hm_mode_model m, double speed_kmh, const hm_sensor_point *point,
                                 const hm_spectrum_fit *fit, const double *f_hz, const double *psd, size_t n,
                                 double dof, double f_lo_hz, double f_hi_hz, double *z);

/* The conicity whose spectrum at the point explains psd[] at f_hz[] (n bins, each > 0 and finite, the frequencies
 * rising) best at the speed [km/h]. HM_EDOMAIN for bad input (n below 4 HM_SPECTRUM_FIT_SHAPE_PARTS or above
 * HM_SPECTRUM_FIT_MAX_BINS, dof below 2 / 64, options out of range), HM_ENOCONV where a pass's minimum lies at its
 * range's edge (the whole range, or 1 / 1.5 to 1.5 times the conicity before it), no conicity gives a spectrum, or the
 * linearisation did not settle within the passes; out untouched then. */
hm_status hm_spectrum_fit_conicity(hm_mode_model m, double speed_kmh, const hm_sensor_point *point, const double *f_hz,
                                   const double *psd, size_t n, double dof, const hm_spectrum_fit_options *o,
                                   hm_spectrum_fit *out);

#ifdef __cplusplus
}
#endif

#endif
