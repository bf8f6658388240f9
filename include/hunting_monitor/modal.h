/*
 * hunting_monitor - online identification of the hunting mode (frequency, decay rate, damping ratio) from the
 * ambient response of the lateral acceleration to the track (issue #9; docs/MODEL.md sections 2 and 5).
 *
 * Method: a parametric fit of the spectrum of the last window_s of acceleration, by Whittle's likelihood.
 *  - The signal is high-passed (2nd-order Butterworth at 2 Hz: drift and curving), low-passed (4th-order at 0.3 of
 *    the decimated rate: anti-aliasing) and decimated to about decimated_rate_hz; the window's periodogram
 *    I_k (rectangular window, zero-padded to a power of two) is taken over [band_low_hz, band_high_hz].
 *  - The spectral model (whittle.h, private) is one lightly damped mode, or two (the likelihood chooses), over a
 *    smooth numerator and white sensor noise:
 *        S(w) = exp(c0 + c1 u + c2 u^2 + c3 u^3) [P(s1, w) + rho P(s2, w)] + N,  s = sigma + i w0, u = ln(w / w_ref),
 *    P the pole pair's Lorentzian widened by the window's leakage (2 / T: a line and a mode far narrower than 1 / T
 *    are its sigma = 0). The mode is the hunting pair of the linear model; the numerator takes what is smooth across
 *    the band: the second, heavily damped pair of the same model (damping ratio about 0.6 at the same frequency), the
 *    s^2 of acceleration, the filters and the colour of the track excitation, which differs between tracks and is
 *    not known. A second pair holds a resonance the numerator cannot, 1-3 Hz wide beside the mode (a bogie frame's,
 *    the installation's): chosen when 2 (L1 - L2) over the independent ordinates exceeds HM_MODAL_TWO_PAIR_LR and its
 *    less damped pair is the one pair's peak (inside its width, its top, above the other pair), so that a chance bump
 *    is not a mode. The hunting mode is the less damped pair: averaged with a broad resonance at its frequency a
 *    single pair reads -2.5 1/s for a mode of -0.56 (issue #26). The two pairs are fitted from the last fit's where
 *    that held something (a ratio above half HM_MODAL_TWO_PAIR_LR_WEAK), and from two splits of the one pair every
 *    fifth fit. Only a converged two-pair fit is chosen; an unfinished one (screened out after a few steps or out of
 *    steps: a broad resonance and the numerator's cubic make a ridge the scoring crosses slowly) is a lower bound on
 *    the ratio: it can be the weak alternative (decay_rate_alt_1_s, unless line-like), and the next fit goes on from
 *    it.
 *  - Track lines are taken out in distance first where the window's speed moved them (order_lines.h: a line that
 *    swept many bins stands nowhere above its background, yet lies on the mode's peak; sharper in distance than in
 *    time, it is subtracted from the samples at its phase in distance). A reading as narrow as a line with such a
 *    line taken out inside its peak (its residue, or the mode near its Hopf speed) is the narrow-peak question below,
 *    its line fitted at the peak's strongest bin.
 *  - Lines are not the mode (issues #18, #26). A comb of lines at multiples of V / L (rail joints, bridge spans,
 *    slabs; lines.h, searched over 2.5 Hz to 0.3 of the decimated rate, two teeth where only two fit) is reported and
 *    its bins are left out. A lone candidate line is a line when a harmonic F test says so (one sinusoid explains its
 *    main lobe, lines.h; F >= HM_MODAL_LINE_F): set aside and reported (lone_lines), unless the mode sits on it (within
 *    three of its half-widths |sigma| + 2 / T; others there are the mode's own peak, not set aside) while as narrow
 *    as a line: then a line and the mode near its Hopf speed look alike in this window (a mode narrower
 *    than about 1 / T is, over T seconds, a sinusoid) and both readings are given, the mode's and line_reading
 *    without it (narrow_peak): the margin decides with the model and what it knows (margin.h). A candidate that swept
 *    more than a bin in the window (its frequency times the speed's relative spread above 1 / T: a track line on a
 *    ramp is no fixed sinusoid and fails the F test) is that question under a reading as narrow as a line whatever
 *    its F; and every other lone candidate outside the mode's peak (three half-widths, two frequency errors) is left
 *    out of the fit when the reading is not line-narrow (a 20.8 Hz slab line sweeping 0.3 Hz beside a mode of -3.5
 *    1/s at 14.1 Hz had read it as -1.5: test_modal).
 *  - A reading is valid when converged, lightly damped (damping ratio below 0.5), a peak (over 3 times the band's
 *    mean, and ln(bins) more over the few bins a narrow one covers: the largest of 650 chance ordinates reaches 6.5),
 *    inside the band, and informative (the decay rate's standard error at most HM_MODAL_INFORMATIVE_SE_1_S +
 *    HM_MODAL_INFORMATIVE_REL |sigma|). With min_peak_prominence set (0, off, by default), a resonance too broad for
 *    the band's mean (a_e = |sigma| + 2 / T above B / (6 pi) for a band B rad/s wide: holding half the band's power it
 *    would stand below 3 times the mean; 2.7 1/s over 5-13 Hz) is a peak too when the fitted spectrum at its frequency
 *    stands min_peak_prominence (plus the same chance term) times above the larger of its least values below and above
 *    it, the spectrum falling to the band's edges on both sides (peak_prominence, HM_MODAL_PROMINENCE_EDGE_REL): a
 *    bogie frame's 8 Hz mode of -5 to -9 1/s over 5-13 Hz stands 2.1-3.4 times above the band's mean and 9-15 times
 *    above its sides, while white, 1/f^2, f^2, low- or high-passed noise has no dip on both sides (test_modal's
 *    a_broad_mode_in_a_narrow_band). Known limits: noise band-limited with steep skirts (a plateau 7-10 Hz, 4th- or
 *    8th-order edges) is a hump too and reads as a mode of -8 to -11 1/s in 10-50% of windows; two broad modes in the
 *    band (-6 1/s at 7 and 10 Hz) read one of them at -4.6 in a quarter of the windows (the two-pair fit not chosen).
 *  - Whittle's log-likelihood  -sum(ln S_k + I_k / S_k)  is maximised by Fisher scoring with Levenberg damping
 *    (J = d ln S / d theta, step (J'J + mu D)^-1 J'(I/S - 1)), warm-started from the previous fit (a decay rate at
 *    its bound 0 held there: an active set); converged when the objective changes by less than tol relative
 *    (failure: HM_ENOCONV after max_iter). The standard errors are the square roots of the diagonal of (J'J)^-1,
 *    Whittle's asymptotic covariance, scaled by nfft / n: the bins of a periodogram zero-padded from n to nfft points
 *    are not independent (about n of them are).
 *  - A stationary spectrum gives |sigma| but not its sign: the decay rate reported is -|sigma|. Growth (sigma > 0) is
 *    seen by the amplitude tracker and the alarm, not here.
 * Why not an AR model of the acceleration: the second mode at the same frequency and the double zero at DC of
 * acceleration are not all-pole; on the exact spectrum of the default vehicle at 420 km/h, AR(10)/AR(20) fits of the
 * decimated acceleration give a decay rate of -3.8 1/s where the model's eigenvalue is -6.33 (40% off), the peak fit
 * -6.1..-6.8 depending on the excitation's colour. A quadratic background left the decay rate 10% small in magnitude
 * at 420-460 km/h on the independent simulator, the cubic 5%. Bias and spread on both simulators: see README.
 *
 * Cost: per sample three biquads and a decimation counter; per fit (every fit_interval_s) one real FFT of the window
 * (4096 points at 100 Hz and 40 s, as one complex FFT of 2048), the line search and the F test of its lone
 * candidates, a few scoring steps of one pair from a warm start, the two-pair fit from its warm start where it held
 * something (and from two splits of the one pair every fifth fit, a start given up after a few steps when it cannot
 * reach the choice), and with a narrow peak the line reading's fits; each scoring step one pass over the band's bins
 * in blocks the compiler vectorises (whittle.h). No allocation after create.
 */
#ifndef HUNTING_MONITOR_MODAL_H
#define HUNTING_MONITOR_MODAL_H

#include <stddef.h>

#include "hunting_monitor/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
  double window_s;          /* identification window [s] (longest data used) */
  double min_window_s;      /* fits start once this much data is in [s] */
  double decimated_rate_hz; /* target rate after decimation [Hz]; the band must lie below 0.4 of it */
  double band_low_hz, band_high_hz; /* fitted band [Hz] (the hunting frequency must lie well inside) */
  double fit_interval_s;    /* a new fit after this much new data [s] */
  double tol;               /* relative change of the objective that ends the scoring (1e-7: the held-out campaign's
                             * last Hopf speeds within 1.6e-4 of their standard errors of 1e-10's in 9 of 10
                             * recordings, in half the steps) */
  unsigned max_iter;        /* scoring step limit */
  int reject_lines;         /* 1: leave the bins of a periodic track excitation (a comb of lines, lines.h) out, and
                               on a ramp take the track's lines out in distance first (order_lines.h) */
  double line_candidate_ratio;   /* lines.h: a candidate line is this far above its local background */
  double line_min_fundamental_hz;/* lines.h: the comb's lowest spacing [Hz] */
  unsigned line_min_harmonics;   /* lines.h: candidates on a comb needed to declare it */
  double min_peak_prominence;    /* 0 (off), or (2-100) a broad reading is a peak too when the fitted spectrum at
                                    its frequency stands this many times above its least values on both sides
                                    (peak_prominence): a broad mode filling a narrow band, a bogie frame's over
                                    5-13 Hz */
} hm_modal_config;

/* Defaults: 40 s window (fits from 20 s), 100 Hz, band 6-22 Hz, a fit every second, tol 1e-7, 80 steps; lines
 * rejected (ratio 8, spacing from 1.5 Hz, three harmonics). */
void hm_modal_config_default(hm_modal_config *cfg);
/* HM_EDOMAIN with "field: reason" in why for an invalid configuration. */
hm_status hm_modal_config_validate(const hm_modal_config *cfg, char *why, size_t why_len);

/* Lone lines reported at most. */
#define HM_MODAL_MAX_LONE 4

/* One reading of the window: the hunting mode as the fit sees it over a set of bins. */
typedef struct {
  int valid;                   /* converged, the mode inside the band, lightly damped, a peak, and informative */
  int informative;             /* the decay rate's standard error is at most HM_MODAL_INFORMATIVE_SE_1_S plus
                                  HM_MODAL_INFORMATIVE_REL of |sigma| (a fit that cannot tell the damping is no mode) */
  double frequency_hz, frequency_se_hz;        /* damped natural frequency w0 / 2 pi */
  double decay_rate_1_s, decay_rate_se_1_s;    /* sigma = -|Re s| [1/s] (negative: decaying) */
  double damping_ratio, damping_ratio_se;      /* -sigma / |s| */
  double peak_to_mean;         /* the mode's spectral peak over the band's mean level (valid needs > 3) */
  double peak_prominence;      /* the fitted spectrum at the mode's frequency over the larger of its least values
                                  below and above it in the band (1 with none on a side, or rising towards a
                                  side's edge: HM_MODAL_PROMINENCE_EDGE_REL); NAN where not measured
                                  (min_peak_prominence 0, or a reading narrow enough for the band's mean), 0 in a
                                  reading not made (no fit) */
  unsigned poles;              /* pole pairs the likelihood chose: 1, or 2 (a second resonance beside the mode) */
  double second_frequency_hz, second_decay_rate_1_s; /* the other pair of two (0 with one) */
  double two_pair_lr;          /* 2 (L1 - L2) over the independent ordinates: two pairs are chosen above
                                  HM_MODAL_TWO_PAIR_LR when their fit converged (0 when none was tried or none ended
                                  below the one pair; an unfinished fit gives a lower bound) */
  double decay_rate_alt_1_s;   /* with one pair chosen but two telling a mode beside another resonance at a likelihood
                                  ratio above HM_MODAL_TWO_PAIR_LR_WEAK (their fit converged; or unfinished, at any
                                  ratio above it, its mode no narrower than 1 / T): the two pairs' mode's decay rate
                                  (0: none).
                                  The evidence cannot choose: the margin counts the difference as an error of the
                                  decay rate (a broad resonance averaged with the mode reads it more damped) */
  double peak_core_z;          /* the periodogram's excess over the fit within half the mode's width of its frequency,
                                  in standard deviations: a narrower resonance inside the fitted peak (the mode
                                  beside a broad one, averaged with it) shows as a large positive value */
  unsigned iterations;         /* scoring steps of the fits of this reading */
} hm_mode_reading;

typedef struct {
  int valid;                   /* the fit converged with the mode inside the band */
  double window_s;             /* data in the window [s] */
  double frequency_hz, frequency_se_hz;        /* damped natural frequency w0 / 2 pi */
  double decay_rate_1_s, decay_rate_se_1_s;    /* sigma = -|Re s| [1/s] (negative: decaying) */
  double damping_ratio, damping_ratio_se;      /* -sigma / |s| */
  double peak_to_mean;         /* the mode's spectral peak over the band's mean level (valid needs > 3) */
  double peak_prominence;      /* as in hm_mode_reading */
  unsigned iterations;         /* scoring steps of this fit */
  int informative;             /* as in hm_mode_reading */
  unsigned poles;              /* as in hm_mode_reading */
  double second_frequency_hz, second_decay_rate_1_s, two_pair_lr, peak_core_z, decay_rate_alt_1_s;
  /* a periodic excitation of the track found in the window (lines.h), whose bins the fit left out */
  int lines_found;
  double line_fundamental_hz;  /* the comb's spacing: V / L for a pattern every L metres */
  unsigned line_harmonics;     /* candidate lines on it */
  double line_strongest_hz;    /* its strongest line and that line's acceleration amplitude [m/s^2] */
  double line_strongest_mps2;
  double band_excluded_fraction; /* of the band's bins left out of the fit */
  /* track lines taken out of the window's samples in distance before anything else (order_lines.h; only where the
   * window's speed trend moved a line at band_high_hz by more than two bins and every sample's speed was given,
   * hm_modal_set_speed): how many, and the strongest's wavelength [m], frequency at the window's mean speed [Hz] and
   * amplitude [m/s^2] */
  unsigned order_lines;
  double order_line_wavelength_m, order_line_hz, order_line_mps2;
  /* lone lines in the band (candidates of lines.h on no comb) that the mode's fit does not explain: left out of the
   * fit, strongest first, with their acceleration amplitudes */
  unsigned lone_lines;
  double lone_line_hz[HM_MODAL_MAX_LONE], lone_line_mps2[HM_MODAL_MAX_LONE];
  /* the mode sits on a lone candidate and is as narrow as a line (|sigma| at most 10 / T plus two standard errors: a
   * line's reading, the window's leakage aside, with room for a line that swept on a ramp; a lightly damped mode
   * passes too: -0.91 +- 0.26 1/s in a 20.2 s window against 1.02, the campaign's bogie_unstable_349): a
   * line and the hunting mode near its Hopf speed look alike in one window. The reading above takes it for the mode;
   * line_reading is the window with it (and every lone line) left out. Which one holds is the margin's to decide,
   * with the model and what is known (margin.h). */
  int narrow_peak;
  double narrow_peak_hz, narrow_peak_mps2;
  hm_mode_reading line_reading;
  /* line_reading again with the line's skirt left out too where the line lies inside that reading's peak (+-0.5 Hz
   * about it, lines.h's background_halfwidth_hz: a strong line on a vehicle that is not linear keeps a skirt the
   * subtraction of one sinusoid leaves); line_reading itself where it does not. For a peak known for a line only
   * (narrow_peak_tracked: a narrow mode's own core is no skirt) */
  hm_mode_reading line_reading_wide;
  /* the narrow peak's envelope (envelope.h, private): the window demodulated at narrow_peak_hz over a band of
   * max(HM_MODAL_ENVELOPE_BAND_HZ, 2 f spread + 4 / T) (a line's sweep on a ramp inside it), its ratio <|z|^4> /
   * <|z|^2>^2 (2 for a mode, a Gaussian process; near 1 for a line holding the band), and the ratio a line would give
   * that held the band's power above the continuum beside the peak (the line search's local background, which holds
   * a narrow mode's own skirt: for a mode the two are close). Reported, not used: in one window they tell a line from
   * a mode only where the peak holds most of the band (docs/TESTS.md). NAN, NAN when not measured. */
  double narrow_peak_envelope_ratio, narrow_peak_line_ratio;
  /* set by the caller that tracks lines across windows (monitor.h, track_lines.h), 0 from the fit: the narrow peak's
   * wavelength V / f [m] in a window at one steady speed, and 1 when that wavelength was seen at another steady speed
   * (a track line, not the mode) */
  int narrow_peak_tracked;
  double narrow_peak_wavelength_m;
  /* how the mode's peak moved with the speed (order tracking, with the speed's change over the window given): one
   * pair fitted to each half of the last window_s, d ln f / d ln V = ln(f2 / f1) / ln(V2 / V1) and its standard error from
   * the halves' frequency errors. A track line's frequency is V / L (1); the model's hunting frequency changes far
   * less with the speed (0.2-0.3 for the default vehicle, margin.h compares). NAN when not measured (the halves'
   * speeds within HM_MODAL_TRACK_MIN_LOG of each other, or a half's fit failed or left the peak). */
  double speed_tracking, speed_tracking_se;
  /* set by the caller with a vehicle model (monitor.h; spectrum_fit.h), 0 from the fit: the conicity whose spectrum at
   * the sensor explains the window's (margin.h's spectrum band), its standard error, the one the model at rest would
   * have read, the leading wheelset's rms displacement from the track the fit implies [m], the fit's shape against
   * the spectrum's (spectrum_fit.h's shape_chi2) and the model's share of the fitted power */
  int spectrum_valid;           /* 1 fitted, 0 not asked, -1 asked and failed (no spectrum, or no fit: a misfit) */
  double spectrum_conicity, spectrum_conicity_se, spectrum_conicity_at_rest, spectrum_motion_rms_m;
  double spectrum_shape_chi2, spectrum_model_share;
  /* and its residual under the reading's peaks (spectrum_fit.h's hm_spectrum_fit_peak_z over f -+ max(|sigma| / 2 pi,
   * HM_MODAL_PEAK_MIN_HALFWIDTH / T) of the window's spectrum): the first pair's and the second's (NAN: not measured) */
  double spectrum_peak_z, spectrum_second_peak_z;
} hm_mode_estimate;

/* The least half-width of the range spectrum_peak_z is measured over, times the window's length T [Hz s]: 2 / T, a
 * few bins of the window's periodogram (a narrower pair's peak is averaged with the bins beside it: margin.h) */
#define HM_MODAL_PEAK_MIN_HALFWIDTH 2.0

/* The window's halves' speeds must differ by at least this in ln(V2 / V1) for speed_tracking: a line then moves 1% of
 * its frequency, 0.14 Hz at 14 Hz, 3 bins of a 20 s half. */
#define HM_MODAL_TRACK_MIN_LOG 0.01

/* A lone candidate is a line when its harmonic F statistic (lines.h) is at least this (F(2, 12) beyond it: 1.5e-4). */
#define HM_MODAL_LINE_F 20.0
/* ... and for one the mode sits on while as narrow as a line (F(2, 12) beyond it: 5e-3; a mode at -0.1 to -0.56 1/s
 * reached 4-14 on its own peak, a weak line fitted as a mode of -0.23 1/s 11.7). */
#define HM_MODAL_LINE_F_ON_MODE 8.0
/* The narrow peak's envelope is read over at least this band [Hz] (narrow_peak_envelope_ratio): the filter's 20-40
 * independent values in a window. */
#define HM_MODAL_ENVELOPE_BAND_HZ 1.0
/* With min_peak_prominence set, a reading's fitted spectrum must fall to the band's edges on both sides: its value at
 * a side's outermost bin at most this times its least value on that side (peak_prominence 1 otherwise). A rise
 * towards the edge is another resonance beyond the dip: with a 14 Hz mode leaking into a 5-13 Hz band the broad 8.5
 * Hz mode of -7 1/s read -4.6 in 33 of 60 windows the prominence alone admitted, none with this (test_modal). */
#define HM_MODAL_PROMINENCE_EDGE_REL 1.1
/* A reading is informative when decay_rate_se <= HM_MODAL_INFORMATIVE_SE_1_S + HM_MODAL_INFORMATIVE_REL |sigma|. */
#define HM_MODAL_INFORMATIVE_SE_1_S 0.5
#define HM_MODAL_INFORMATIVE_REL 0.5
/* A warm start whose pair's spectral peak lies below this times the band's mean level is no mode: cold starts are
 * tried beside it (the better likelihood kept). */
#define HM_MODAL_WARM_MIN_PEAK 1.0
/* Two pole pairs are chosen when 2 (L1 - L2), over the independent ordinates, exceeds this: the three more parameters'
 * chi-square beyond its 0.02% point, and about BIC's 3 ln(n) for the 600-700 bins of a band (the narrower pair may sit
 * anywhere: at 12 a chance bump on a broad mode's flank was read as a mode of -0.6 1/s in 0.5% of single-pole windows
 * and one such window of a campaign's ramp as a conicity change to 0.28). */
#define HM_MODAL_TWO_PAIR_LR 20.0
/* ... and between this and HM_MODAL_TWO_PAIR_LR (the chi-square's 5% point), or above this where the two-pair fit is
 * unfinished, the two pairs' mode is an alternative reading (decay_rate_alt_1_s). */
#define HM_MODAL_TWO_PAIR_LR_WEAK 8.0

/* The reading as the window's estimate (its fields copied; the window's lines kept), and the estimate's own reading. */
void hm_mode_estimate_use_reading(hm_mode_estimate *e, const hm_mode_reading *r);
/* The reading beside a narrow peak taken for a line: line_reading_wide for a peak known for a track line
 * (narrow_peak_tracked), else line_reading. */
const hm_mode_reading *hm_mode_estimate_beside_line(const hm_mode_estimate *e);
void hm_mode_estimate_reading(const hm_mode_estimate *e, hm_mode_reading *r);

typedef struct hm_modal_s *hm_modal;

/* Create for an input sample rate [Hz] (100..5000). HM_EDOMAIN (reason in why) for a bad configuration or a rate
 * the configuration cannot be decimated from; HM_ENOMEM. *out untouched on failure. */
hm_status hm_modal_create(const hm_modal_config *cfg, double sample_rate_hz, hm_modal *out, char *why,
                          size_t why_len);
void hm_modal_destroy(hm_modal m);
/* Forget the window (after a gap); the next fit starts cold. */
void hm_modal_reset(hm_modal m);
/* A new input rate (the estimator measured one): resets. HM_EDOMAIN if it cannot be used (state unchanged). No
 * allocation. */
hm_status hm_modal_set_rate(hm_modal m, double sample_rate_hz);

/* |H(f)|^2 of the filters before the window (the high- and low-pass above) at the current input rate, for f_hz [Hz]
 * (NAN for a negative or non-finite one); modal is an hm_modal (void: mode_model.h's gain callback). */
double hm_modal_filter_power_gain(const void *modal, double f_hz);

/* The power gain below which a bin is left out of hm_modal_window_spectrum (the filters' stopband: dividing it out
 * would raise the sensor's noise there 1000-fold). */
#define HM_MODAL_SPECTRUM_MIN_GAIN 1e-3

/* The last fit's window (the whole window hm_modal_fit read, after its lines were set aside): its periodogram over
 * [low_hz, high_hz] without the bins set aside for lines, as the sensor's two-sided acceleration density [(m/s^2)^2 /
 * Hz] (|X_k|^2 / (n fd), the filters' power gain divided out; bins below HM_MODAL_SPECTRUM_MIN_GAIN left out), at most
 * cap bins into f_hz[] and psd[]; *n the bins, *dof each one's degrees of freedom (2 n / nfft: the zero padding's
 * bins are not independent), *window_s the window's length [s]. HM_EDOMAIN for a band outside (0, fd / 2) or more
 * bins than cap, HM_ENOCONV where no window is kept (no fit yet, or since a reset) or the band holds fewer than 8
 * bins; the outputs untouched then. */
hm_status hm_modal_window_spectrum(const hm_modal m, double low_hz, double high_hz, double *f_hz, double *psd,
                                   size_t cap, size_t *n, double *dof, double *window_s);

/* One acceleration sample [m/s^2] at the input rate (finite: the caller validates). */
void hm_modal_push(hm_modal m, double accel_mps2);
/* The speed [m/s] from now on, kept with each sample (the track lines' order tracking, order_lines.h); not finite
 * or not positive: unknown (the default until one is given; a reset or a new rate keeps it). */
void hm_modal_set_speed(hm_modal m, double v_mps);
/* 1 when enough new data for a fit is in (fit_interval_s since the last one, min_window_s in all). */
int hm_modal_fit_due(const hm_modal m);
/* Fit the newest max_window_s of the window (at most window_s; the caller passes less when only the newest part was
 * at a steady speed), whose speed ranged over speed_spread_rel of its mean (0 if unknown: lines of the track, which move
 * with the speed, are left out that much wider, lines.h); over the last window_s (the whole window, where the peak's
 * movement is measured: speed_tracking) the newer half's mean speed was halves_speed_ratio times the older half's (1,
 * or 0 if unknown: not measured). HM_OK with out->valid set or cleared (mode
 * outside the band, fewer than min_window_s of data); HM_ENOCONV if the scoring did not converge (out untouched);
 * HM_EINVAL for max_window_s <= 0. */
hm_status hm_modal_fit(hm_modal m, double max_window_s, double speed_spread_rel, double halves_speed_ratio,
                       hm_mode_estimate *out);

#ifdef __cplusplus
}
#endif

#endif
