/*
 * hunting_monitor - track lines in the distance domain: order tracking of one window (issue #26).
 *
 * A periodic feature of the track (slabs, joints, spans, L metres apart) forces the wheelset at V / L: fixed in
 * distance, moving with the speed. Over a window whose speed changed (a ramp, a driver's notches) such a line sweeps
 * f spread_rel in frequency: spread over many bins it stands nowhere above its background and passes no line test
 * in time, yet its power still lies on the hunting mode's peak and reads as a lightly damped mode (a 16.8 m joint's
 * second harmonic across a ramp at 434 km/h: -3.0 1/s where the mode is -4.9; 5.72 m slabs on a notched ramp:
 * conicity 0.40 for a true 0.255). The hunting mode is the opposite: fixed in time, smeared in distance.
 *
 * Method, on a window of n samples at fs with the speed of each sample:
 *  - the distance s_i of each sample (trapezoidal sum of the speeds); the window resampled at n points equally spaced
 *    in distance (Catmull-Rom cubic interpolation in time), its "virtual time" the distance over the mean speed: a
 *    line of wavelength L is there a sinusoid of V_mean / L Hz, as narrow as the window allows;
 *  - the periodograms of both (rectangular window, zero-padded to nfft, the mean removed); lines.h's search for a
 *    comb and lone candidates on the distance one, between f_lo_hz and f_hi_hz;
 *  - each candidate (a comb's teeth, the lone ones) is a track line when it stands min_ratio over its background (a
 *    lone one; a comb is evidence of its own) and the harmonic F test (lines.h) says so in distance (F_d >= min_f),
 *    and it is sharper there than in time:
 *    F_d >= dominance times F_t, the F test of the time periodogram at the same frequency. A mode, fixed in time, is
 *    the other way round; at a steady speed both are the same (nothing is taken: the time-domain tests decide,
 *    modal.h). A tooth on the mode's peak whose F in time is the peak's own may fail that comparison: it stays, and
 *    the comb's spacing (comb_fundamental_hz) lets the caller ask the narrow-peak question there (modal.h). Taking
 *    such teeth whenever another tooth passed (tried) took the mode with them where it is lightly damped: a tooth
 *    amplified 30-60 times by the resonance, F 81 in distance and 10 in time, and the window read -2.4..-2.7 1/s
 *    for -1.4 (17.5 m joints at 453 km/h, conicity 0.16; review of issue #26);
 *  - each track line is subtracted from the window's time samples at its phase in distance:
 *    x_i -= 2 Re(A exp(i omega tau_i)), tau_i the sample's virtual time (by a rotation, recomputed where the speed
 *    between two samples changed: a speed held between its updates costs one sine and cosine per update).
 * The caller decides when it is worth it (modal.c: where the window's speed trend moved a line at the band's top
 * by more than two bins).
 * No allocation after create; cost per call: two real FFTs of nfft (one with the DFT in time given), the
 * interpolation (n), the line search, for each candidate (at most HM_ORDER_LINES_MAX) a median over +-0.5 Hz and two
 * harmonic F fits, and n complex rotations per track line.
 */
#ifndef HUNTING_MONITOR_ORDER_LINES_H
#define HUNTING_MONITOR_ORDER_LINES_H

#include <stddef.h>

#include "hunting_monitor/lines.h"
#include "hunting_monitor/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A comb's teeth examined at most (the lowest), and track lines taken out of one window at most (those and the lone
 * candidates, lines.h). */
#define HM_ORDER_LINES_MAX_TEETH 16
#define HM_ORDER_LINES_MAX (HM_ORDER_LINES_MAX_TEETH + HM_LINES_MAX_LONE)

typedef struct {
  double min_ratio;  /* a lone line stands at least this times its background in distance (the median about it,
                        lines.h); a comb's teeth need only be lines.h's candidates */
  double min_f;      /* the harmonic F test in distance a line must pass (lines.h) */
  double dominance;  /* and F_d at least this times F_t, the test in time at its frequency */
} hm_order_lines_config;

/* Defaults: min_ratio 25, min_f 20 (modal.h's HM_MODAL_LINE_F), dominance 8. A line swept over many bins loses most
 * of its F in time (test_modal: F 57-122 in distance, 2-7 in time). A random track's chance peaks are candidates too
 * (8 times their background) and then pass an F test easily (20-80); their F in time is an independent draw, so
 * dominance alone does not keep them (test_monitor_sim's clean ramp: F 81 in distance, 5.7 in time, 1.2 Hz from the
 * mode, its removal moved a WARN by 6 km/h). An ordinate of a smooth spectrum exceeds r times its background with
 * probability exp(-r): 25 is never reached by chance (1e-11 per bin). */
void hm_order_lines_config_default(hm_order_lines_config *cfg);
/* HM_EDOMAIN with "field: reason" in why for an invalid configuration. */
hm_status hm_order_lines_config_validate(const hm_order_lines_config *cfg, char *why, size_t why_len);

typedef struct {
  unsigned n;                                 /* track lines taken out */
  double wavelength_m[HM_ORDER_LINES_MAX];    /* each line's wavelength V / f [m] */
  double f_hz[HM_ORDER_LINES_MAX];            /* at the window's mean speed [Hz] */
  double amp_mps2[HM_ORDER_LINES_MAX];        /* amplitude [m/s^2] */
  double f_distance[HM_ORDER_LINES_MAX], f_time[HM_ORDER_LINES_MAX]; /* its F tests in distance and in time */
  double speed_mean_mps;                      /* the window's mean speed [m/s] */
  double comb_fundamental_hz;                 /* a comb's spacing found in distance [Hz] at that speed (0: none),
                                                 its teeth taken or not */
} hm_order_lines_result;

typedef struct hm_order_lines_s *hm_order_lines;

/* For windows of at most max_n samples; nfft_max a power of two >= max_n (the periodograms' zero-padding).
 * HM_EDOMAIN (reason in why) for a bad configuration or size, HM_ENOMEM. *out untouched on failure. */
hm_status hm_order_lines_create(const hm_order_lines_config *cfg, const hm_lines_config *lines_cfg, size_t max_n,
                                size_t nfft_max, hm_order_lines *out, char *why, size_t why_len);
void hm_order_lines_destroy(hm_order_lines o);

/*
 * Take the track lines out of x[0..n) (samples at fs_hz, in place), v_mps[0..n) the speed at each sample [m/s],
 * nfft a power of two in [n, nfft_max]; lines searched between f_lo_hz and f_hi_hz (at the mean speed).
 * HM_EINVAL for NULL arguments or sizes out of range; HM_EDOMAIN when a speed is not finite and positive (x and *out
 * untouched on either). out->n is 0 when nothing was taken.
 */
hm_status hm_order_lines_clean(hm_order_lines o, double *x, const double *v_mps, size_t n, double fs_hz, size_t nfft,
                               double f_lo_hz, double f_hi_hz, hm_order_lines_result *out);

/* The same with the window's DFT in time given: re[0..nfft/2], im[0..nfft/2] and pw = re^2 + im^2 of x less its mean,
 * zero-padded to nfft, as hm_fft_real gives it (a caller that has the window's periodogram saves an FFT; modal.c).
 * HM_EINVAL also for a NULL re, im or pw. */
hm_status hm_order_lines_clean_dft(hm_order_lines o, double *x, const double *v_mps, size_t n, double fs_hz,
                                   size_t nfft, double f_lo_hz, double f_hi_hz, const double *re, const double *im,
                                   const double *pw, hm_order_lines_result *out);

#ifdef __cplusplus
}
#endif

#endif
