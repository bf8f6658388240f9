/*
 * hunting_monitor - streaming estimator of the dominant lateral oscillation and the standard criteria (docs/MODEL.md
 * section 5).
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
 *  - the criteria's limits depend on where the accelerometer sits (measurement_point). The standards' limits are
 *    for bogie-frame acceleration (EN 14363 sliding r.m.s. (12 - m_b/5)/2 = 5.2 m/s^2 for an 8 t bogie; peaks of
 *    8-10 m/s^2 in 0.5-10 Hz); on the wheelset, whose lateral acceleration at the hunting frequency is far larger
 *    for the same displacement, they would call a stable, lightly damped response hunting. For the wheelset the
 *    limits come from the model (docs/MODEL.md section 7): an oscillation of half the smallest unstable cycle
 *    from which the default vehicle can hunt (4.2 mm at the lower fold LPC1, so 2.1 mm) at the Hopf frequency
 *    (14.28 Hz, w^2 = 8050 1/s^2): r.m.s. 2.1e-3 x 8050 / sqrt(2) = 12 m/s^2, peak 2.1e-3 x 8050 = 17 m/s^2 in a
 *    2-20 Hz band that holds the hunting frequency; six consecutive peaks as in the bogie practice. Those
 *    acceleration limits hold the displacement to 2.1 mm at 14.3 Hz only: a bogie mode at 8 Hz reaches 3 mm with
 *    7.6 m/s^2. So (c), on the wheelset, the displacement criterion: the tracked displacement amplitude (the
 *    band-passed acceleration's amplitude over whole periods, corrected for the band's gain, over (2 pi f)^2) of a
 *    coherent oscillation (period spread at most 0.2) at or above displacement_limit_m (2.1 mm, the same half of the
 *    4.2 mm cycle) at any frequency of the 2-20 Hz band: a limit that depends neither on the frequency nor on the
 *    boundary table; on a bogie frame with a vehicle model, the wheelsets' displacement the frame's oscillation
 *    implies in the hunting mode's shape (hm_estimator_set_displacement_map below; config/monitor_bogie_frame.yaml);
 *    The identification of the hunting mode and the conicity are not here: modal.h, inversion.h, margin.h.
 * Sample rate: the filters are first designed for the configured sample_rate_hz, which is an expectation: the rate
 * is measured from the time stamps over blocks of 0.5 s of gap-free data: from regular stamps (a sensor's clock,
 * below) the reciprocal of the median stamp difference (so samples lost or delivered late do not read as another
 * rate: a count per block would), from irregular ones (receipt times in bursts) the count per time; when two
 * blocks in a row differ from the design by more than 5% the filters are redesigned for the measured rate (and
 * restarted: the bands then move by less than 5%, while every restart leaves the tracker unsettled for a second, so
 * a source whose rate wanders by a few per cent, such as a publisher loop on a loaded computer, is not restarted
 * over and over). A measured rate more than 5% from the configured one is reported (sample_rate_mismatch); one the bands
 * cannot be designed for (below 100 Hz, above 5 kHz, or with a band edge above 0.45 of it) makes the acceleration
 * invalid.
 * Lost samples: when a block's stamps are regular (95% of the differences within 0.25 periods of a whole number of
 * median differences: a sensor's own clock; receipt times in bursts are not) at a rate within 5% of the design, a
 * difference of k >= 2 periods (up to max_gap_s: a link dropping 60 ms once a second neither restarts the filters,
 * the r.m.s. window nor the identification) counts k - 1 lost samples (n_samples_lost; loss_fraction over about
 * the last 10 s) and is bridged by k - 1 linearly interpolated samples, so the filters, trackers and criteria stay on
 * their time grid (hm_estimator_last_fill tells a consumer of the same stream how many).
 * Bad input is counted and skipped, never propagated: non-finite or implausibly large samples, repeated or
 * out-of-order timestamps, gaps longer than max_gap_s (which restart the filters and trackers), speeds that are
 * non-finite, negative, above max_speed_kmh or change by more than max_speed_rate_kmh_s x dt + max_speed_jump_kmh. Outputs are never NaN.
 */
#ifndef HUNTING_MONITOR_ESTIMATOR_H
#define HUNTING_MONITOR_ESTIMATOR_H

#include <stddef.h>

#include "hunting_monitor/model.h"
#include "hunting_monitor/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Why a speed was refused (hm_estimator_push_speed). */
typedef enum {
  HM_SPEED_ACCEPTED = 0,
  HM_SPEED_NOT_FINITE = 1,   /* non-finite or negative, or its stamp not finite */
  HM_SPEED_ABOVE_MAX = 2,    /* above max_speed_kmh */
  HM_SPEED_IMPLAUSIBLE = 3,  /* changed by more than max_speed_rate_kmh_s x dt + max_speed_jump_kmh */
  HM_SPEED_NOT_AFTER = 4     /* its stamp not after the previous accepted one's */
} hm_speed_refusal;

/* "above max_speed_kmh" and so on; "" for HM_SPEED_ACCEPTED. */
const char *hm_speed_refusal_text(hm_speed_refusal r);

/* Upper bounds of the settings that size the estimator's buffers: at 5 kHz the r.m.s. ring then holds at most
 * 5000 x 1000 m / (30 km/h) = 600,000 samples (9.6 MB), the crossing ring 20 x 2 x band_high_hz crossings. */
#define HM_ESTIMATOR_MAX_TRACKING_S 20.0
#define HM_ESTIMATOR_MAX_RMS_WINDOW_M 1000.0
/* The wheelset's displacement criterion [m]: the criteria's amplitude at the default vehicle's hunting frequency
 * (above: 12 m/s^2 r.m.s. and 17 m/s^2 peaks at 14.28 Hz). */
#define HM_ESTIMATOR_WHEELSET_DISPLACEMENT_M 2.1e-3

typedef enum {
  HM_POINT_WHEELSET = 0,    /* lateral acceleration of the wheelset (axle box): the model's y'' */
  HM_POINT_BOGIE_FRAME = 1  /* lateral acceleration of the bogie frame above it: what EN 14363 / GB/T 5599 limit */
} hm_measurement_point;

typedef struct {
  hm_measurement_point measurement_point; /* sets the criteria's defaults (hm_estimator_config_criteria) */
  double sample_rate_hz;          /* expected acceleration sample rate, 100..5000 (the filters follow the measured one) */
  double band_low_hz, band_high_hz; /* hunting band, 0 < low < high < 0.45 sample rate */
  double tracking_time_s;         /* averaging time of amplitude and frequency */
  double rms_window_m;            /* sliding r.m.s. window in metres of track */
  double rms_limit_mps2;
  double peaks_band_low_hz, peaks_band_high_hz;
  double peaks_limit_mps2;
  unsigned peaks_count;
  double displacement_limit_m;    /* (c): displacement amplitude limit [m]; 0: off (the bogie frame's default) */
  double max_gap_s;               /* a longer silence restarts filters and trackers */
  double accel_timeout_s;         /* acceleration older than this is stale */
  double speed_timeout_s;         /* speed older than this is stale */
  double max_speed_kmh;
  double max_speed_rate_kmh_s;
  double max_speed_jump_kmh;      /* allowance on top of the rate for a speed sensor's noise */
  double max_accel_mps2;          /* larger samples are rejected as sensor faults */
} hm_estimator_config;

/* Defaults (config/monitor.yaml cites their sources): wheelset, 2 kHz, band 2-20 Hz, tracking 1 s, r.m.s. over 100 m
 * against 12 m/s^2, 6 peaks of 17 m/s^2 in 2-20 Hz, gaps > 0.2 s (shorter ones on a regular grid are bridged), stale after 0.2 s (acceleration) / 1 s (speed),
 * speed <= 600 km/h changing <= 30 km/h per second (plus 2 km/h of sensor noise), samples <= 500 m/s^2. */
void hm_estimator_config_default(hm_estimator_config *cfg);
/* The criteria's limits and bands for a measurement point (see above); the other fields are left as they are. */
void hm_estimator_config_criteria(hm_estimator_config *cfg, hm_measurement_point point);

/* HM_EDOMAIN with "field: reason" in why for an invalid configuration. */
hm_status hm_estimator_config_validate(const hm_estimator_config *cfg, char *why, size_t why_len);

typedef struct {
  double time_s;                  /* time of the latest accepted sample */
  double sample_rate_hz;          /* the rate the filters are designed for (the measured one once it is known) */
  double sample_rate_measured_hz; /* from the stamps, over the last half second of gap-free data (0 until then) */
  int sample_rate_mismatch;       /* measured differs from the configured sample_rate_hz by more than 5% */
  int sample_rate_supported;      /* the filters can be designed for the measured rate (else accel_valid is 0) */
  int stamps_regular;             /* the last block's stamps lay on a grid: losses are counted and bridged */
  double loss_fraction;           /* lost / (lost + received) samples over about the last 10 s */
  int accel_valid;                /* samples arrived within accel_timeout_s of `now` */
  int speed_valid;                /* a plausible speed arrived within speed_timeout_s of `now` */
  double speed_kmh;               /* last accepted speed (0 if none) */
  hm_speed_refusal speed_refused; /* with speed_valid 0: why the latest speed was refused, while its stamp lies within
                                     speed_timeout_s of `now` (HM_SPEED_ACCEPTED if it was not refused, or none came
                                     lately: a silent sensor is not one whose speeds are refused) */
  int oscillation_valid;          /* tracker settled: a full tracking time of samples and a frequency */
  double amplitude_accel_mps2;
  double frequency_hz;            /* 0 if not valid */
  double amplitude_displacement_m;/* the sensor's own, a / (2 pi f)^2; 0 if the frequency is not valid */
  double wheelset_displacement_m; /* with a displacement map (below): the wheelsets' it implies, which (c) judges; 0
                                     where it cannot tell or without a map */
  double period_spread;           /* relative standard deviation of the recent periods */
  double rms_mps2;                /* sliding r.m.s. over the window (or what is available of it) */
  int rms_window_complete;
  int rms_exceeded;
  unsigned consecutive_peaks;
  int peaks_exceeded;
  int displacement_exceeded;      /* (c) */
  /* input problems, counted since create or reset */
  unsigned long n_samples, n_rejected_nonfinite, n_rejected_range, n_rejected_order, n_gaps;
  unsigned long n_samples_lost;   /* missing from a regular grid (bridged by interpolation) */
  unsigned long n_speed_updates, n_speed_rejected;
  unsigned long n_rate_changes;   /* filter redesigns for a measured rate */
} hm_estimate;

typedef struct hm_estimator_s *hm_estimator;

/* Create for a configuration; HM_EDOMAIN with the reason in why for an invalid one, HM_ENOMEM. *out untouched on
 * failure. */
hm_status hm_estimator_create(const hm_estimator_config *cfg, hm_estimator *out, char *why, size_t why_len);
void hm_estimator_destroy(hm_estimator est);
/* Forget all state (filters, trackers, counters). */
void hm_estimator_reset(hm_estimator est);
/* The standard criteria's limits while running (rms_limit_mps2, peaks_limit_mps2, peaks_count, displacement_limit_m of cfg; its other
 * fields are ignored), validated as hm_estimator_config_validate does (HM_EDOMAIN with the reason; nothing changes
 * then). The stream's state is kept. */
hm_status hm_estimator_set_limits(hm_estimator est, const hm_estimator_config *cfg, char *why, size_t why_len);
/* The wheelset's displacement amplitude per acceleration amplitude at the sensor [m per m/s^2] at the tracked frequency
 * and speed, or a value <= 0 or not finite where it cannot be told; a vehicle model's (mode_model.h,
 * hm_mode_model_displacement_per_accel) for a sensor away from the axle box. */
typedef double (*hm_displacement_map_fn)(void *ctx, double f_hz, double speed_kmh);
/* With a map (fn not NULL) wheelset_displacement_m is the wheelsets', amp x fn(ctx, f, speed), and the displacement
 * criterion (c), with its coherence (period spread at most 0.2), judges it instead of the sensor's own (a bogie frame
 * moves a third to a thirtieth as much as its wheelsets in their hunting mode, and the standards' frame limits came
 * 3-50 s after 3 mm on a bogie that is not its description, docs/VEHICLES.md); where the map cannot tell (no valid
 * speed, a value <= 0) (c) does not judge. amplitude_displacement_m, which the alarm's amplitude rules read, stays the
 * sensor's own: a frame's ambient motion near the hunting frequency is not the mode's, and read through the mode's
 * shape it overstates the wheelsets' (2.6-4.8 mm for 1.1-2.0 mm, a review's); only a coherent oscillation is
 * taken for the mode. NULL: no map. */
void hm_estimator_set_displacement_map(hm_estimator est, hm_displacement_map_fn fn, void *ctx);
/* How many times the filters restarted (gaps, redesigns for a measured rate, resets), and the rate they are designed
 * for now: a consumer of the same stream (the modal identification) restarts with them. */
unsigned long hm_estimator_restarts(const hm_estimator est, double *design_rate_hz);

/* One acceleration sample. HM_OK if accepted; HM_EDOMAIN if rejected and counted (non-finite, out of range, or a
 * timestamp not after the previous one): the state is unchanged then. HM_EINVAL only for a NULL estimator. */
hm_status hm_estimator_push_accel(hm_estimator est, double t_s, double accel_mps2);
/* How many samples were lost (and bridged by linear interpolation) just before the latest accepted one: a consumer
 * of the same stream interpolates as many between the previous accepted sample and that one. */
unsigned hm_estimator_last_fill(const hm_estimator est);
/* One speed update [km/h]; rejected (HM_EDOMAIN) and counted if implausible. */
hm_status hm_estimator_push_speed(hm_estimator est, double t_s, double speed_kmh);
/* The estimate as of time now_s (staleness judged against it). Never NaN. */
void hm_estimator_read(const hm_estimator est, double now_s, hm_estimate *out);

#ifdef __cplusplus
}
#endif

#endif
