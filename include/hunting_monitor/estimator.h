/*
 * hunting_monitor - streaming estimator of the dominant lateral oscillation (MODEL.md section 5).
 *
 * Input: lateral acceleration samples [m/s^2] with timestamps [s] at a nominal rate of 100 Hz..5 kHz, and speed
 * updates [km/h] at their own rate. Per sample (all memory allocated by create, none by push):
 *  - the hunting band: a 4th-order Butterworth high-pass at band_low_hz and 4th-order low-pass at band_high_hz,
 *    as a cascade of four biquads (bilinear transform with pre-warping) designed for the nominal rate;
 *  - amplitude: sqrt(2 x mean square) of the band-passed signal, the mean square a one-pole average with time
 *    constant tracking_time_s / 2 (exact for a sinusoid, ripple below 1% above 2 Hz);
 *  - frequency: up-going zero crossings of the band-passed signal (Schmitt-armed at -10% of the amplitude,
 *    linearly interpolated between samples) counted over the last tracking_time_s: f = (crossings - 1) /
 *    (t_last - t_first). Unbiased for a narrow-band oscillation such as hunting, cheap, and its spread (the
 *    relative standard deviation of the periods) says whether the oscillation is coherent. Settling time: about
 *    tracking_time_s after the oscillation starts (plus the band-pass filter's few periods);
 *  - displacement amplitude = acceleration amplitude / (2 pi f)^2;
 *  - the two standard instability criteria: (a) the sliding r.m.s. of the band-passed acceleration over the
 *    last rms_window_m of track (EN 14363 style) against rms_limit_mps2; (b) the count of consecutive half-cycle
 *    peaks of the acceleration filtered to [peaks_band_low_hz, peaks_band_high_hz] (2nd-order high-pass, 4th-order
 *    low-pass) at or above peaks_limit_mps2, against peaks_count (Chinese bogie-instability practice);
 *  - the equivalent conicity: the measured frequency and the current speed inverted through the linear model's
 *    hunting mode: with s = sigma + i w and the characteristic polynomial q(s) + g e lambda (linear.h), the
 *    lambda term is real, so Im q(sigma + i w) = 0 fixes sigma (Newton, from the last sigma) and then
 *    lambda = -Re q(sigma + i w) / (g e), applied to the frequency averaged over conicity_time_s. Valid only with
 *    enough signal, a coherent frequency (period spread below conicity_max_spread) and enough speed. Near the Hopf speed the mode frequency hardly depends on lambda
 *    (on the boundary w^2 = A3/A1 does not at all): the sensitivity S = (dlambda/lambda)/(dw/w) reaches about 15
 *    at 500 km/h for the CRH380 defaults, so a 1% frequency error is a 15% conicity error. The confidence
 *    (0..1) is therefore signal strength times 1 - (expected relative error / 10%), the expected error being S
 *    times the period spread over the square root of the number of periods averaged (0.5: about 5%).
 * Bad input is counted and skipped, never propagated: non-finite or implausibly large samples, repeated or
 * out-of-order timestamps, gaps longer than max_gap_s (which restart the filters and trackers), speeds that are
 * non-finite, negative, above max_speed_kmh or change faster than max_speed_rate_kmh_s. Outputs are never NaN.
 */
#ifndef HUNTING_MONITOR_ESTIMATOR_H
#define HUNTING_MONITOR_ESTIMATOR_H

#include <stddef.h>

#include "hunting_monitor/model.h"
#include "hunting_monitor/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Upper bounds of the settings that size the estimator's buffers: at 5 kHz the r.m.s. ring then holds at most
 * 5000 x 1000 m / (30 km/h) = 600,000 samples (9.6 MB), the crossing ring 20 x 2 x band_high_hz crossings. */
#define HM_ESTIMATOR_MAX_TRACKING_S 20.0
#define HM_ESTIMATOR_MAX_RMS_WINDOW_M 1000.0

typedef struct {
  double sample_rate_hz;          /* nominal acceleration sample rate, 100..5000 */
  double band_low_hz, band_high_hz; /* hunting band, 0 < low < high < 0.45 sample rate */
  double tracking_time_s;         /* averaging time of amplitude and frequency */
  double rms_window_m;            /* sliding r.m.s. window in metres of track */
  double rms_limit_mps2;
  double peaks_band_low_hz, peaks_band_high_hz;
  double peaks_limit_mps2;
  unsigned peaks_count;
  double conicity_min_speed_kmh;  /* below this speed no conicity is inferred */
  double conicity_min_amplitude_mps2;
  double conicity_max_spread;     /* largest relative standard deviation of the periods */
  double conicity_min, conicity_max; /* plausible range of the estimate */
  double conicity_time_s;         /* averaging time of the conicity estimate */
  double max_gap_s;               /* a longer silence restarts filters and trackers */
  double accel_timeout_s;         /* acceleration older than this is stale */
  double speed_timeout_s;         /* speed older than this is stale */
  double max_speed_kmh;
  double max_speed_rate_kmh_s;
  double max_accel_mps2;          /* larger samples are rejected as sensor faults */
} hm_estimator_config;

/* Defaults (config/monitor.yaml cites their sources): 2 kHz, band 2-20 Hz, tracking 1 s, r.m.s. over 100 m
 * against 5.2 m/s^2, 6 peaks of 8 m/s^2 in 0.5-10 Hz, conicity from 100 km/h and 0.3 m/s^2 with period spread
 * below 5% in 0.01..1.0 averaged over 10 s, gaps > 0.05 s, stale after 0.2 s (acceleration) / 1 s (speed), speed <= 600 km/h
 * changing <= 30 km/h per second, samples <= 500 m/s^2. */
void hm_estimator_config_default(hm_estimator_config *cfg);

/* HM_EDOMAIN with "field: reason" in why for an invalid configuration. */
hm_status hm_estimator_config_validate(const hm_estimator_config *cfg, char *why, size_t why_len);

typedef struct {
  double time_s;                  /* time of the latest accepted sample */
  int accel_valid;                /* samples arrived within accel_timeout_s of `now` */
  int speed_valid;                /* a plausible speed arrived within speed_timeout_s of `now` */
  double speed_kmh;               /* last accepted speed (0 if none) */
  int oscillation_valid;          /* tracker settled: a full tracking time of samples and a frequency */
  double amplitude_accel_mps2;
  double frequency_hz;            /* 0 if not valid */
  double amplitude_displacement_m;/* 0 if the frequency is not valid */
  double period_spread;           /* relative standard deviation of the recent periods */
  double rms_mps2;                /* sliding r.m.s. over the window (or what is available of it) */
  int rms_window_complete;
  int rms_exceeded;
  unsigned consecutive_peaks;
  int peaks_exceeded;
  int conicity_valid;
  double conicity;                /* 0 if never valid; the last valid value otherwise */
  double conicity_confidence;     /* 0..1 */
  double conicity_sensitivity;    /* S = (dlambda/lambda)/(dw/w) at the current speed and frequency (0 if unknown) */
  /* input problems, counted since create or reset */
  unsigned long n_samples, n_rejected_nonfinite, n_rejected_range, n_rejected_order, n_gaps;
  unsigned long n_speed_updates, n_speed_rejected;
} hm_estimate;

typedef struct hm_estimator_s *hm_estimator;

/* Create for a configuration and a vehicle (the conicity inversion uses its linear coefficients). NULL on an
 * invalid configuration or vehicle (check them first) or out of memory. */
hm_estimator hm_estimator_create(const hm_estimator_config *cfg, const hm_vehicle *veh);
void hm_estimator_destroy(hm_estimator est);
/* Forget all state (filters, trackers, counters). */
void hm_estimator_reset(hm_estimator est);

/* One acceleration sample. HM_OK if accepted; HM_EDOMAIN (non-finite or out of range) or HM_EINVAL
 * (timestamp not after the previous one) if rejected and counted; the state is unchanged then. */
hm_status hm_estimator_push_accel(hm_estimator est, double t_s, double accel_mps2);
/* One speed update [km/h]; rejected (HM_EDOMAIN) and counted if implausible. */
hm_status hm_estimator_push_speed(hm_estimator est, double t_s, double speed_kmh);
/* The estimate as of time now_s (staleness judged against it). Never NaN. */
void hm_estimator_read(const hm_estimator est, double now_s, hm_estimate *out);

#ifdef __cplusplus
}
#endif

#endif
