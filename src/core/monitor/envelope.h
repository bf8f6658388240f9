/* The envelope of a narrow peak: a line's, steady, or a mode's, a Gaussian process's (private to the core).
 *
 * Within one window a line and a mode narrower than the window resolves make the same peak (modal.h's narrow-peak
 * question). Their envelopes differ (issue #26's "envelope statistics"): a mode driven by the track is a Gaussian
 * narrow-band process, its envelope Rayleigh; a line's is steady. The signal demodulated at the peak and band-limited
 * (z), the ratio r = <|z|^4> / <|z|^2>^2 is 2 for a Gaussian process (|z|^2 exponential) and, for a line of power L
 * over a Gaussian rest of power P in the band, (L^2 + 4 L P + 2 P^2) / (L + P)^2 (E|z|^4 = L^2 + 4 L P + E|w|^4 with
 * E|w|^4 = 2 P^2 for a circular Gaussian w): 1 for a pure line. A line of steady amplitude whose frequency sweeps inside
 * the band keeps r near 1; a line whose amplitude changes does not (a track line crossing a resonance on a ramp, its
 * forced response following the resonance: r 2.4-3.9 measured, above a Gaussian mode's). What r can tell in one
 * window is limited by the process, not the filter: a mode of decay rate sigma gives about |sigma| T / pi independent
 * envelope values over T seconds, 2-4 for the modes that reach the narrow-peak question (|sigma| T up to about 10),
 * where even a mode's r has a median of 1.7-1.9 (measured; docs/TESTS.md). The identification reports r and the
 * ratio a line would give (modal.h); nothing decides on them yet.
 */
#ifndef HM_ENVELOPE_H
#define HM_ENVELOPE_H

#include <stddef.h>

#include "hunting_monitor/status.h"

typedef struct {
  double ratio;       /* <|z|^4> / <|z|^2>^2 over the filter's outputs (every eighth of its length) */
  double band_power;  /* <|z|^2> [(units of x)^2]: a line of amplitude A gives A^2 / 4 */
} hm_envelope_stats;

/* The doubles hm_envelope_stats_of needs as work: 2 n and the filter's length, round(1.5 fs_hz / bandwidth_hz) - 1;
 * 0 for rates that are not positive. */
size_t hm_envelope_work_size(size_t n, double fs_hz, double bandwidth_hz);

/* x[0..n) sampled at fs_hz, its mean removed, demodulated at f_hz (z = x e^{-i 2 pi f t}) and low-passed by a
 * Hann-weighted moving mean of equivalent noise bandwidth bandwidth_hz (1.5 fs / (its length + 1)), unit gain at f_hz,
 * in work[0..work_len) (hm_envelope_work_size). HM_EINVAL for NULL pointers or too little work; HM_EDOMAIN for
 * non-finite or non-positive rates, f_hz at or above fs_hz / 2, a band wider than f_hz or than fs_hz / 2 - f_hz (an
 * image would pass), a record shorter than twice the filter, or no power; out untouched then. The filter's outputs
 * every eighth of its length: costs 2 n trigonometric calls and about 16 n multiply-adds (a 40 s window at 100 Hz:
 * 8000 and 64000). */
hm_status hm_envelope_stats_of(const double *x, size_t n, double fs_hz, double f_hz, double bandwidth_hz,
                               double *work, size_t work_len, hm_envelope_stats *out);

/* The ratio a line gives whose power is kappa (>= 0) times the Gaussian rest's in the band:
 * (kappa^2 + 4 kappa + 2) / (kappa + 1)^2; 2 for kappa 0 (no line), 1 as kappa grows. NAN for a kappa that is not. */
double hm_envelope_line_ratio(double kappa);

#endif
