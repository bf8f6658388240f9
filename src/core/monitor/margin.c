/* Distance to the Hopf speed from identified hunting modes, model-based and model-free (see margin.h). */
#include "hunting_monitor/margin.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hunting_monitor/linear.h"
#include "validate.h"

typedef struct {
  double t_end_s, speed_kmh;
  double window_s;              /* its length [s] */
  double sigma, sigma_stat;     /* decay rate and its statistical error [1/s] */
  double lambda, lambda_se;     /* the window's conicity and its total error */
  double lambda_stat, lambda_sys; /* the statistical and systematic parts of that error */
  unsigned poles;               /* the reading's pole pairs (modal.h; 0: not known, a restored window) */
} window;

struct hm_margin_s {
  hm_margin_config cfg;
  hm_vehicle veh;
  hm_linear_coef coef;
  hm_mode_model model;          /* a bogie's or car's (hm_margin_set_model; borrowed), NULL: the wheelset's closed forms */
  double lambda0;               /* the vehicle's lambda(0): the model-free line's curvature is taken there */
  window w[HM_MARGIN_MAX_WINDOWS];
  size_t head, n;
  double last_end_s;
  window pending;               /* the current steady stretch, not yet committed */
  int have_pending;
  double misfit_t[HM_MARGIN_MAX_WINDOWS]; /* end times of misfit windows (ring) */
  size_t misfit_head, misfit_n;
  int pending_misfit;           /* the current stretch is a misfit so far */
  double pending_misfit_t;
  unsigned long n_changes;
  double last_change_s;
  size_t since_change;          /* windows stored since the last change (the one that showed it included) */
  double prior_low, prior_high; /* the conicities the wheels may have worn to (hm_margin_set_prior); 0, 0: none */
  hm_narrow_verdict narrow;     /* what the latest window's narrow peak was taken for */
  double narrow_hz, narrow_at_s, ambiguous_at_s;
  /* the last used reading of each decomposition (one pole pair, two: index poles - 1) in the stretch that starts at
   * its start_s (a stretch's provisional window is read again at every fit, monitor.h; across_fits) */
  struct {
    int valid;
    double start_s, lambda;
  } last[2];
  /* the latest weak alternative (modal.h's decay_rate_alt_1_s) read in the stretch that starts at start_s: a later
   * reading of the same stretch keeps it as its own alternative (stretch_alternative) */
  struct {
    int valid;
    double start_s, sigma;
  } alt;
};

const char *hm_window_verdict_text(hm_window_verdict v) {
  switch (v) {
    case HM_WINDOW_USED: return "used";
    case HM_WINDOW_MODE_INVALID: return "no mode identified";
    case HM_WINDOW_SPEED_VARIED: return "the speed varied: shown, not used";
    case HM_WINDOW_TOO_SLOW: return "below the margin's minimum speed";
    case HM_WINDOW_OVERLAPS: return "overlaps a window already used";
    case HM_WINDOW_NO_INVERSION: return "no conicity explains it";
    case HM_WINDOW_MISFIT: return "the model cannot explain its decay rate and frequency together";
    case HM_WINDOW_CHANGE: return "the conicity changed: the windows held were dropped, this one kept";
    case HM_WINDOW_NONLINEAR: return "a criterion was met during it: hunting is not the linear mode";
    case HM_WINDOW_AMBIGUOUS:
      return "a narrow peak: a line, or the mode at its Hopf speed at a conicity nothing else supports: not used";
    case HM_WINDOW_TRACKS_SPEED: return "its peak moved with the speed like a track line, not like the mode: not used";
    case HM_WINDOW_TRACK_LINE:
      return "its narrow peak is a track line seen at another speed, and the mode beside it is not explained: not used";
    case HM_WINDOW_READING_MISFIT:
      return "its pole pairs misfit where the model's whole spectrum explains it and their peaks: not used, not a misfit";
  }
  return "?";
}

void hm_margin_config_default(hm_margin_config *c) {
  c->frequency_model_error = 0.01;
  c->decay_rate_model_error = 0.05;
  c->max_speed_spread_kmh = 12.0;
  c->min_speed_kmh = 200.0;
  c->memory_s = 900.0;
  c->min_speed_span_kmh = 20.0;
  c->max_extrapolation_kmh = 150.0;
  c->interval_z = 2.0;
  c->max_misfit_chi2 = 9.0;
  c->change_z = 4.0;
  c->spectrum_low_hz = c->spectrum_high_hz = 0.0;
  c->spectrum_model_error = 0.02;
  c->spectrum_max_shape_chi2 = 30.0;
  c->spectrum_conicity = 1;
}

hm_status hm_margin_config_validate(const hm_margin_config *c, char *why, size_t len) {
  if (!c) return HM_EINVAL;
  const hm_field_check f[] = {
      {"frequency_model_error", c->frequency_model_error, HM_RULE_RANGE, 0.0, 0.5},
      {"decay_rate_model_error", c->decay_rate_model_error, HM_RULE_RANGE, 0.0, 1.0},
      {"max_speed_spread_kmh", c->max_speed_spread_kmh, HM_RULE_RANGE, 0.0, 200.0},
      {"min_speed_kmh", c->min_speed_kmh, HM_RULE_RANGE, 0.0, 1000.0},
      {"memory_s", c->memory_s, HM_RULE_RANGE, 1.0, 1e6},
      {"min_speed_span_kmh", c->min_speed_span_kmh, HM_RULE_RANGE, 1.0, 1000.0},
      {"max_extrapolation_kmh", c->max_extrapolation_kmh, HM_RULE_RANGE, 1.0, 1000.0},
      {"interval_z", c->interval_z, HM_RULE_RANGE, 0.5, 10.0},
      {"max_misfit_chi2", c->max_misfit_chi2, HM_RULE_RANGE, 1.0, 1e6},
      {"change_z", c->change_z, HM_RULE_RANGE, 1.0, 100.0},
      {"spectrum_low_hz", c->spectrum_low_hz, HM_RULE_OFF_OR_RANGE, 0.5, 200.0},
      {"spectrum_high_hz", c->spectrum_high_hz, HM_RULE_OFF_OR_RANGE, 1.0, 500.0},
      {"spectrum_model_error", c->spectrum_model_error, HM_RULE_RANGE, 0.0, 0.5},
      {"spectrum_max_shape_chi2", c->spectrum_max_shape_chi2, HM_RULE_RANGE, 1.0, 1e6},
      {"spectrum_conicity", (double)c->spectrum_conicity, HM_RULE_FLAG, 0.0, 0.0}};
  const hm_status st = hm_check_fields(f, HM_COUNT_OF(f), why, len);
  if (st != HM_OK) return st;
  if ((c->spectrum_low_hz == 0.0) != (c->spectrum_high_hz == 0.0) ||
      (c->spectrum_low_hz > 0.0 && !(c->spectrum_high_hz >= 2.0 * c->spectrum_low_hz)))
    return hm_reject(why, len, "spectrum_high_hz", "must be 0 with spectrum_low_hz 0 (off), else at least twice it",
                     c->spectrum_high_hz);
  return HM_OK;
}

hm_status hm_margin_create(const hm_margin_config *cfg, const hm_vehicle *veh, hm_margin *out, char *why, size_t len) {
  if (!cfg || !veh || !out) return HM_EINVAL;
  hm_status st = hm_margin_config_validate(cfg, why, len);
  if (st == HM_OK) st = hm_vehicle_validate(veh, why, len);
  if (st != HM_OK) return st;
  hm_margin m = calloc(1, sizeof *m);
  if (!m) return HM_ENOMEM;
  m->cfg = *cfg;
  m->veh = *veh;
  hm_linear_coef_from_vehicle(veh, &m->coef);
  hm_conicity_eval(&veh->conicity, 0.0, &m->lambda0, NULL);
  hm_margin_reset(m);
  *out = m;
  return HM_OK;
}

void hm_margin_destroy(hm_margin m) { free(m); }

const char *hm_narrow_verdict_text(hm_narrow_verdict v) {
  switch (v) {
    case HM_NARROW_NONE: return "none";
    case HM_NARROW_MODE: return "the hunting mode near its Hopf speed";
    case HM_NARROW_LINE: return "a line beside the mode";
    case HM_NARROW_AMBIGUOUS: return "a line or the mode at its Hopf speed: not used";
  }
  return "?";
}

void hm_margin_shift_time(hm_margin m, double delta_s) {
  if (!m || !isfinite(delta_s)) return;
  for (size_t k = 0; k < m->n; ++k) m->w[(m->head + HM_MARGIN_MAX_WINDOWS - 1 - k) % HM_MARGIN_MAX_WINDOWS].t_end_s += delta_s;
  for (size_t k = 0; k < m->misfit_n; ++k) m->misfit_t[k] += delta_s;
  m->pending.t_end_s += delta_s;
  m->pending_misfit_t += delta_s;
  m->last[0].start_s += delta_s;
  m->last[1].start_s += delta_s;
  m->alt.start_s += delta_s;
  m->last_end_s += delta_s;
  if (m->n_changes) m->last_change_s += delta_s;
  if (m->narrow_at_s != 0.0) m->narrow_at_s += delta_s;
  if (m->ambiguous_at_s != 0.0) m->ambiguous_at_s += delta_s;
}

hm_narrow_verdict hm_margin_last_narrow(const hm_margin m) { return m ? m->narrow : HM_NARROW_NONE; }

void hm_margin_set_prior(hm_margin m, double conicity_low, double conicity_high) {
  if (!m) return;
  const int ok = isfinite(conicity_low) && isfinite(conicity_high) && conicity_low > 0.0 && conicity_high > conicity_low;
  m->prior_low = ok ? conicity_low : 0.0;
  m->prior_high = ok ? conicity_high : 0.0;
}

void hm_margin_reset(hm_margin m) {
  if (!m) return;
  m->narrow = HM_NARROW_NONE;
  m->narrow_hz = m->narrow_at_s = m->ambiguous_at_s = 0.0;
  m->since_change = 0;
  m->head = m->n = 0;
  m->last_end_s = -INFINITY;
  m->have_pending = 0;
  m->misfit_head = m->misfit_n = 0;
  m->pending_misfit = 0;
  m->n_changes = 0;
  m->last_change_s = 0.0;
  m->last[0].valid = m->last[1].valid = 0;
  m->alt.valid = 0;
}

double hm_margin_hopf_kmh(const hm_margin m, double conicity) {
  if (!m) return HM_LINEAR_NO_HOPF_KMH;
  return m->model ? hm_mode_model_hopf_kmh(m->model, conicity) : hm_linear_hopf_kmh(&m->veh, conicity);
}

void hm_margin_set_model(hm_margin m, hm_mode_model model) {
  if (m) m->model = model;
}

/* The vehicle's model: the conicity from a mode (inversion.h's closed form for the wheelset; for a bogie or car
 * mode_model.h's, against the model's own reading of as many pole pairs at the sensor where one is set, else its
 * roots) and its hunting root (the least-damped one) at a conicity and speed. */
static hm_status invert(const hm_margin m, unsigned poles, double speed_kmh, double sigma, double e_sigma, double f_hz,
                        double e_f, hm_conicity_inversion *inv) {
  return m->model ? hm_mode_model_invert_reading(m->model, poles, speed_kmh, sigma, e_sigma, f_hz, e_f, 1e-9, 60, inv)
                  : hm_conicity_from_mode(&m->coef, speed_kmh, sigma, e_sigma, f_hz, e_f, 1e-9, 60, inv);
}

static hm_status hunting_root(const hm_margin m, double speed_kmh, double conicity, double *sigma, double *omega) {
  return m->model ? hm_mode_model_least_damped(m->model, conicity, speed_kmh, sigma, omega)
                  : hm_hunting_root(&m->coef, speed_kmh, conicity, sigma, omega);
}

/* The model's root that a measured mode (decay rate, frequency) follows: a bogie has several in the band, and the
 * least-damped one may be its frame's at 8 Hz where the axle box shows the wheelsets' at 14 (the wheelset: its one
 * hunting root). */
static hm_status root_near(const hm_margin m, double speed_kmh, double conicity, double sigma_ref, double f_ref_hz,
                           double *sigma, double *omega) {
  if (!m->model) return hm_hunting_root(&m->coef, speed_kmh, conicity, sigma, omega);
  double f;
  hm_status st = hm_mode_model_root(m->model, conicity, speed_kmh, sigma_ref, 1.0, f_ref_hz, 0.5, sigma, &f);
  if (st == HM_OK) *omega = 2.0 * HM_PI * f;
  return st;
}

/* With a model read at its sensor (mode_model.h) one pair's reading and two pairs' are different quantities (on a
 * bogie's axle box -6.4 and -2.7 1/s in one window): the model-free line takes the windows of one kind only. */
static int reads_by_model(const hm_margin m) { return m->model && hm_mode_model_has_sensor(m->model); }

/* The latest weak alternative decay rate (modal.h) read in the stretch of a window of window_s seconds ending at
 * t_end (0: none), for a primary reading without one of its own (a stretch is read again at every fit while it grows,
 * and the likelihood ratio of a mode beside a broader resonance wanders about HM_MODAL_TWO_PAIR_LR_WEAK from fit to
 * fit: the campaign's broad_386, the mode -1.57 1/s beside one of -5.75, read one pair -2.4 to -2.6 with the
 * alternative -1.74 to -1.85 for three fits at ratios 9-10, then without it at 6-7.5: the interval's error went with
 * it). */
static double stretch_alternative(const hm_margin m, double t_end, double window_s) {
  return m->alt.valid && fabs(m->alt.start_s - (t_end - window_s)) <= HM_MARGIN_SAME_STRETCH_S ? m->alt.sigma : 0.0;
}

/* A reading the stretch's alternative belongs to: one pole pair, no narrow peak (a narrow peak's reading is another
 * resonance than the broad one whose alternative it was: given its error it would pass as the mode, a review found). */
static int takes_alternative(const hm_mode_estimate *mode) { return mode->poles == 1 && !mode->narrow_peak; }

/* Remember a used one-pair reading's weak alternative for its stretch (stretch_alternative). */
static void note_alternative(hm_margin m, double t_end, const hm_mode_estimate *mode, hm_window_verdict v) {
  if (v != HM_WINDOW_USED || !takes_alternative(mode) || !(mode->decay_rate_alt_1_s < 0.0)) return;
  m->alt.valid = 1;
  m->alt.start_s = t_end - mode->window_s;
  m->alt.sigma = mode->decay_rate_alt_1_s;
}

/* A reading's checks and inversion into *w (a window of window_s seconds; stretch_alt: the stretch's weak alternative
 * decay rate for a reading without its own, 0 for none); the verdict says whether it can be used. */
static hm_window_verdict prepare_reading(const hm_margin m, double t_end, double speed_kmh, double spread_kmh,
                                         double window_s, const hm_mode_reading *mode, double stretch_alt, window *w) {
  const hm_margin_config *c = &m->cfg;
  if (!mode->valid) return HM_WINDOW_MODE_INVALID;
  if (spread_kmh > c->max_speed_spread_kmh) return HM_WINDOW_SPEED_VARIED;
  if (speed_kmh < c->min_speed_kmh) return HM_WINDOW_TOO_SLOW;
  if (t_end - window_s < m->last_end_s - 1e-9) return HM_WINDOW_OVERLAPS;
  /* statistical and systematic errors of the measured mode (the leakage of a T s window: about 1 / T) */
  double sys_sigma = c->decay_rate_model_error * fabs(mode->decay_rate_1_s) + 1.0 / fmax(window_s, 1.0);
  /* a second reading the likelihood could not rule out (modal.h: a broad resonance beside the mode), in this fit or
   * an earlier one of the stretch: the difference is an error of the decay rate */
  const double alt = mode->decay_rate_alt_1_s < 0.0 ? mode->decay_rate_alt_1_s : stretch_alt;
  if (alt < 0.0) sys_sigma = hypot(sys_sigma, mode->decay_rate_1_s - alt);
  /* a decay rate at its bound 0 (a line's reading, or a mode narrower than the window resolves) inverted just below */
  const double sigma = fmin(mode->decay_rate_1_s, -1e-6);
  const double sys_f = c->frequency_model_error * mode->frequency_hz;
  double e_sigma = hypot(mode->decay_rate_se_1_s, sys_sigma);
  const double e_f = hypot(mode->frequency_se_hz, sys_f);
  hm_conicity_inversion inv;
  if (invert(m, mode->poles, speed_kmh, sigma, e_sigma, mode->frequency_hz, e_f, &inv) != HM_OK)
    return HM_WINDOW_NO_INVERSION;
  /* the speed's range over the window: the fit averages the decay rates along it; the model's change over half the
   * range, at the conicity found, is a systematic error (on a ramp at 0.5 km/h/s, 12 km/h in 24 s, 0.4 1/s near the
   * Hopf speed of conicity 0.16), and the inversion is repeated with it */
  double s_lo, s_hi, w_unused;
  const double f_m = mode->frequency_hz;
  if (spread_kmh > 0.0 &&
      root_near(m, speed_kmh - 0.5 * spread_kmh, inv.conicity, sigma, f_m, &s_lo, &w_unused) == HM_OK &&
      root_near(m, speed_kmh + 0.5 * spread_kmh, inv.conicity, sigma, f_m, &s_hi, &w_unused) == HM_OK) {
    sys_sigma = hypot(sys_sigma, 0.5 * fabs(s_hi - s_lo));
    e_sigma = hypot(mode->decay_rate_se_1_s, sys_sigma);
    if (invert(m, mode->poles, speed_kmh, sigma, e_sigma, mode->frequency_hz, e_f, &inv) != HM_OK)
      return HM_WINDOW_NO_INVERSION;
  }
  w->t_end_s = t_end;
  if (!(inv.chi2 <= c->max_misfit_chi2)) return HM_WINDOW_MISFIT;
  /* the systematic part of the conicity's error: the weighted sensitivities applied to the systematic errors */
  const double js = inv.dsigma_dconicity / (e_sigma * e_sigma), jf = inv.dfrequency_dconicity / (e_f * e_f);
  const double info = inv.dsigma_dconicity * js + inv.dfrequency_dconicity * jf;
  const double lambda_sys = hypot(js * sys_sigma, jf * sys_f) / info;
  w->t_end_s = t_end;
  w->speed_kmh = speed_kmh;
  w->window_s = window_s;
  w->poles = mode->poles;
  w->sigma = sigma;
  w->sigma_stat = mode->decay_rate_se_1_s;
  w->lambda = inv.conicity;
  w->lambda_se = inv.conicity_se;
  w->lambda_sys = fmin(lambda_sys, inv.conicity_se);
  w->lambda_stat = sqrt(fmax(inv.conicity_se * inv.conicity_se - w->lambda_sys * w->lambda_sys, 0.0));
  return HM_WINDOW_USED;
}

/* The model's whole spectrum explains the window (fitted, its share of the power and its shape's chi2 within bounds). */
static int spectrum_explains(const hm_margin m, const hm_mode_estimate *mode) {
  return mode->spectrum_valid > 0 && mode->spectrum_conicity > 0.0 && mode->spectrum_conicity_se > 0.0 &&
         isfinite(mode->spectrum_conicity_se) && mode->spectrum_model_share >= HM_MARGIN_SPECTRUM_MIN_SHARE &&
         mode->spectrum_shape_chi2 <= m->cfg.spectrum_max_shape_chi2;
}

/* ... and a pair's peak: the fit's residual under it (modal.h's spectrum_peak_z) within HM_MARGIN_READING_LOCAL_Z. */
static int spectrum_explains_peak(double z) {
  return fabs(z) <= HM_MARGIN_READING_LOCAL_Z; /* (NAN: not measured, not explained) */
}

/* The window's pole pairs misfit (v HM_WINDOW_MISFIT) where the spectrum, which gives the conicity, explains the
 * window and each pair's peak: the reading's failing (HM_WINDOW_READING_MISFIT, margin.h). */
static int reading_failed(const hm_margin m, const hm_mode_estimate *mode) {
  /* a pair narrower than the residual's range (|sigma| / 2 pi below HM_MODAL_PEAK_MIN_HALFWIDTH / T, modal.h) has its
   * peak averaged with the bins beside it: never excused (a review's 8.1 Hz pair at -0.05 1/s, 20 times the fit, read
   * at z 4-6 over 20 s) */
  const double narrow = 2.0 * HM_PI * HM_MODAL_PEAK_MIN_HALFWIDTH / fmax(mode->window_s, 1.0);
  return m->cfg.spectrum_conicity && spectrum_explains(m, mode) && (mode->poles == 1 || mode->poles == 2) &&
         fabs(mode->decay_rate_1_s) >= narrow && spectrum_explains_peak(mode->spectrum_peak_z) &&
         (mode->poles < 2 ||
          (fabs(mode->second_decay_rate_1_s) >= narrow && spectrum_explains_peak(mode->spectrum_second_peak_z)));
}

/* A window whose mode the model explains (its reading inverted within max_misfit_chi2) takes its conicity from the
 * model's whole spectrum where that was fitted (spectrum_fit.h; a vehicle model, the spectrum's band set, no narrow
 * peak in the window): the reading's pole pairs hold a small part of what the spectrum tells (a frame's 8 Hz mode
 * gave conicity errors of 0.007-0.014 a window, the spectrum 0.0006-0.003). Its systematic error is
 * spectrum_model_error of the conicity (the model's own spectrum fitted back over a bogie frame's 4-22 Hz scattered by
 * 1.2% 30 km/h below the Hopf speed, where the curvature gave 0.5%: docs/VEHICLES.md). Where the model misses the
 * spectrum's shape (shape_chi2 above spectrum_max_shape_chi2: a vehicle that is not the model, whose frame's spectrum
 * a wrong conicity would be made to explain), where the model carries less than HM_MARGIN_SPECTRUM_MIN_SHARE of the
 * fitted power (the white floor explains the band: noise fits any conicity) or where the fit failed, the window is a
 * misfit: HM_WINDOW_MISFIT, else v unchanged; a window whose pole pairs misfit (v HM_WINDOW_MISFIT) is
 * HM_WINDOW_READING_MISFIT where reading_failed says so (spectrum_conicity 1). With spectrum_conicity 0 that test is
 * all the fit does, and the pairs' misfit, theirs being the conicity, counts (an axle box, where a description whose frame is off still
 * explains the wheelsets' spectrum and the spectrum's narrow interval would hold a Hopf speed the description has
 * wrong: docs/VEHICLES.md). */
static hm_window_verdict use_spectrum(const hm_margin m, const hm_mode_estimate *mode, window *w, hm_window_verdict v) {
  if ((v != HM_WINDOW_USED && v != HM_WINDOW_MISFIT) || mode->narrow_peak || !reads_by_model(m) ||
      !(m->cfg.spectrum_high_hz > 0.0) || mode->spectrum_valid == 0)
    return v;
  if (v == HM_WINDOW_MISFIT) return reading_failed(m, mode) ? HM_WINDOW_READING_MISFIT : v;
  if (!spectrum_explains(m, mode)) return HM_WINDOW_MISFIT;
  if (!m->cfg.spectrum_conicity) return v; /* (the test alone: the pairs' reading gives the conicity, its misfit counts) */
  w->lambda = mode->spectrum_conicity;
  w->lambda_stat = mode->spectrum_conicity_se;
  w->lambda_sys = m->cfg.spectrum_model_error * mode->spectrum_conicity;
  w->lambda_se = hypot(w->lambda_stat, w->lambda_sys);
  return v;
}

/* The estimate of the windows held at t (their inverse-variance mean; conicity_valid 0 without any). */
static void model_based(const hm_margin m, const window *const *ws, size_t n, hm_margin_estimate *r);
static size_t held(const hm_margin m, double now, const window **ws);

/* What is known of the conicity at a window's end: the windows held (their estimate), else the prior's range. */
static void known(const hm_margin m, double t_end, double *lo, double *hi, double *se, int *from_windows) {
  const window *ws[HM_MARGIN_MAX_WINDOWS];
  const size_t n = held(m, t_end, ws);
  hm_margin_estimate r;
  memset(&r, 0, sizeof r);
  model_based(m, ws, n, &r);
  *from_windows = r.conicity_valid;
  *lo = *hi = r.conicity;
  *se = r.conicity_se;
  if (!r.conicity_valid) *lo = m->prior_low, *hi = m->prior_high, *se = 0.0;
}

/* A window's conicity that what is known supports: within change_z combined standard errors of the windows held,
 * or without any, the prior's range within interval_z of its error (or no prior given). */
static int supported(const hm_margin m, const window *w) {
  double lo, hi, se;
  int from_windows;
  known(m, w->t_end_s, &lo, &hi, &se, &from_windows);
  if (from_windows) return fabs(w->lambda - lo) <= m->cfg.change_z * hypot(w->lambda_se, se);
  const double z = m->cfg.interval_z * w->lambda_se;
  return hi <= 0.0 || (w->lambda + z >= lo && w->lambda - z <= hi);
}

/* A narrow peak's conicity that what is known supports as the mode at its Hopf speed. A line and that mode give the
 * same conicity (the one whose Hopf speed is the current speed), so the support must be informative: within
 * interval_z (not change_z) combined standard errors of the windows held, and inside the prior's range as well unless
 * the windows know the conicity better than the prior (a window of 0.29 +- 0.05 held would support 0.44: a 13.9 Hz
 * sinusoid at 273 km/h, WARN 75 km/h below a Hopf speed of 350). */
static int supports_narrow(const hm_margin m, const window *w) {
  double lo, hi, se;
  int from_windows;
  known(m, w->t_end_s, &lo, &hi, &se, &from_windows);
  const double z = m->cfg.interval_z;
  const int in_prior = m->prior_high <= 0.0 || (w->lambda + z * w->lambda_se >= m->prior_low &&
                                                w->lambda - z * w->lambda_se <= m->prior_high);
  if (!from_windows) return in_prior;
  const int agrees = fabs(w->lambda - lo) <= z * hypot(w->lambda_se, se);
  const int windows_know_better = m->prior_high <= 0.0 || 2.0 * z * se <= m->prior_high - m->prior_low;
  return agrees && (windows_know_better || in_prior);
}

/* A window's conicity above what is known (beyond change_z combined errors of the windows held, or interval_z of its
 * own above the prior's range): its Hopf speed lower, the cautious direction. */
static int cautious(const hm_margin m, const window *w) {
  double lo, hi, se;
  int from_windows;
  known(m, w->t_end_s, &lo, &hi, &se, &from_windows);
  if (from_windows) return w->lambda - hi > m->cfg.change_z * hypot(w->lambda_se, se);
  return hi > 0.0 && w->lambda - m->cfg.interval_z * w->lambda_se > hi;
}

/* The window's peak moved with the speed as a track line does (modal.h's speed_tracking) and not as the model's
 * hunting mode at conicity lambda: three standard errors above the model's d ln f / d ln V (from the hunting root at
 * V -+ 2%) and at least half a line's 1 (margin.h). */
static int tracks_speed(const hm_margin m, double speed_kmh, double lambda, const hm_mode_estimate *mode) {
  const double k = mode->speed_tracking, se = mode->speed_tracking_se;
  if (!isfinite(k) || !(se > 0.0) || !(lambda > 0.0)) return 0;
  const double v1 = 0.98 * speed_kmh, v2 = 1.02 * speed_kmh;
  double s1, w1, s2, w2;
  const double sg = mode->decay_rate_1_s, f = mode->frequency_hz;
  if (root_near(m, v1, lambda, sg, f, &s1, &w1) != HM_OK || root_near(m, v2, lambda, sg, f, &s2, &w2) != HM_OK ||
      !(w1 > 0.0 && w2 > 0.0))
    return 0;
  const double k_model = log(w2 / w1) / log(v2 / v1);
  return k - k_model >= 3.0 * se && k >= 0.5;
}

/* A window's checks and inversion into *w. A narrow peak (modal.h) is the hunting mode near its Hopf speed when the
 * model can produce it at this speed and what is known supports its conicity (supports_narrow); else a line when the reading without
 * it is a mode of its own (the model cannot produce the narrow one, or the window held a second resonance beside it,
 * or that mode lies over 1 Hz away) that what is known supports; else it cannot be told (HM_WINDOW_AMBIGUOUS: a
 * line at the hunting frequency reads as the mode at its Hopf speed, a sinusoid at 14 Hz at 400 km/h as a conicity
 * of 0.22 where the prior says 0.11-0.17). *narrow says which. */
static hm_window_verdict prepare(const hm_margin m, double t_end, double speed_kmh, double spread_kmh,
                                 const hm_mode_estimate *mode, window *w, hm_narrow_verdict *narrow) {
  hm_mode_reading primary;
  hm_mode_estimate_reading(mode, &primary);
  const hm_window_verdict v =
      use_spectrum(m, mode, w, prepare_reading(m, t_end, speed_kmh, spread_kmh, mode->window_s, &primary,
                                               takes_alternative(mode) ? stretch_alternative(m, t_end, mode->window_s)
                                                                       : 0.0,
                                               w));
  *narrow = HM_NARROW_NONE;
  if (v == HM_WINDOW_USED || v == HM_WINDOW_MISFIT || v == HM_WINDOW_NO_INVERSION) {
    double lo, hi, se; /* the model's slope at the window's conicity, or (none found) at what is known */
    int from_windows;
    known(m, t_end, &lo, &hi, &se, &from_windows);
    if (tracks_speed(m, speed_kmh, v == HM_WINDOW_USED ? w->lambda : 0.5 * (lo + hi), mode))
      return HM_WINDOW_TRACKS_SPEED;
  }
  if (!mode->narrow_peak) return v;
  const int tracked = mode->narrow_peak_tracked; /* a track line by its wavelength across speeds: never the mode */
  if (!tracked && v == HM_WINDOW_USED && supports_narrow(m, w)) return *narrow = HM_NARROW_MODE, v;
  window wl;
  const hm_window_verdict vl =
      prepare_reading(m, t_end, speed_kmh, spread_kmh, mode->window_s, hm_mode_estimate_beside_line(mode), 0.0, &wl);
  const int impossible = v == HM_WINDOW_MISFIT || v == HM_WINDOW_NO_INVERSION;
  const int beside = primary.poles == 2 || fabs(mode->line_reading.frequency_hz - primary.frequency_hz) > 1.0;
  /* the mode beside it, where what is known supports it, or where it is the cautious reading (wheels worn beyond the
   * prior: it lowers the interval, alarm.h) */
  if (vl == HM_WINDOW_USED && (impossible || beside || tracked) && (supported(m, &wl) || cautious(m, &wl))) {
    *w = wl;
    return *narrow = HM_NARROW_LINE, vl;
  }
  /* a known line and a reading beside it that what is known does not support: the line's remains (its skirt beside
   * the bins left out) pull that reading toward it; no evidence against the model */
  if (tracked) return *narrow = HM_NARROW_LINE, HM_WINDOW_TRACK_LINE;
  if (impossible && vl != HM_WINDOW_USED) return *narrow = HM_NARROW_LINE, vl; /* a line and no mode beside it */
  if (v != HM_WINDOW_USED && v != HM_WINDOW_MISFIT && v != HM_WINDOW_NO_INVERSION) return v; /* not for this reason */
  return *narrow = HM_NARROW_AMBIGUOUS, HM_WINDOW_AMBIGUOUS;
}

/* The stretch's readings from fit to fit (margin.h, issue #26): a stretch at one speed is read again at every fit
 * while it grows, and the likelihood may choose one pole pair at one fit and two at the next (a mode beside a broader
 * resonance: a bogie's axle box read 0.145 +- 0.009 with one pair and 0.115 +- 0.011 with two, a second apart, and the
 * one pair's reading gave a WARN 64 km/h below the truth). Where the stretch has been read in the other decomposition,
 * the difference of the two conicities is an error of the window's (systematic: the same data read two ways); a
 * used reading is remembered for its decomposition. */
static void across_fits(hm_margin m, hm_window_verdict v, window *w) {
  if (v != HM_WINDOW_USED || (w->poles != 1 && w->poles != 2)) return;
  const double start = w->t_end_s - w->window_s;
  const int k = (int)w->poles - 1, other = 1 - k;
  if (m->last[other].valid && fabs(m->last[other].start_s - start) <= HM_MARGIN_SAME_STRETCH_S) {
    w->lambda_sys = hypot(w->lambda_sys, w->lambda - m->last[other].lambda);
    w->lambda_se = hypot(w->lambda_stat, w->lambda_sys);
  }
  m->last[k].valid = 1;
  m->last[k].start_s = start;
  m->last[k].lambda = w->lambda;
}

/* Keep a window (the ring drops the oldest beyond its size); any provisional one is superseded. */
static void store(hm_margin m, const window *w) {
  m->w[m->head] = *w;
  m->head = (m->head + 1) % HM_MARGIN_MAX_WINDOWS;
  if (m->n < HM_MARGIN_MAX_WINDOWS) ++m->n;
  m->last_end_s = w->t_end_s;
  m->have_pending = 0;
  ++m->since_change;
}

static void misfit_push(hm_margin m, double t) {
  m->misfit_t[m->misfit_head] = t;
  m->misfit_head = (m->misfit_head + 1) % HM_MARGIN_MAX_WINDOWS;
  if (m->misfit_n < HM_MARGIN_MAX_WINDOWS) ++m->misfit_n;
}

/* The windows held (newest first) within memory_s of now; their count. */
static size_t held(const hm_margin m, double now, const window **ws) {
  size_t n = 0;
  for (size_t k = 0; k < m->n; ++k) {
    const window *w = &m->w[(m->head + HM_MARGIN_MAX_WINDOWS - 1 - k) % HM_MARGIN_MAX_WINDOWS];
    if (isfinite(now) && now - w->t_end_s > m->cfg.memory_s) continue;
    ws[n++] = w;
  }
  return n;
}

/* A window whose conicity is more than change_z combined standard errors from the mean of those held: the
 * conicity changed. The windows held are dropped and the new one is kept, committed (it is the evidence of the
 * change: issue #27; the alarm takes the more cautious of it and the prior until a second window agrees). */
static int changed(hm_margin m, const window *w) {
  const window *ws[HM_MARGIN_MAX_WINDOWS];
  const size_t n = held(m, w->t_end_s, ws);
  hm_margin_estimate r;
  memset(&r, 0, sizeof r);
  model_based(m, ws, n, &r);
  if (!r.conicity_valid || fabs(w->lambda - r.conicity) <= m->cfg.change_z * hypot(w->lambda_se, r.conicity_se))
    return 0;
  m->head = m->n = 0;
  m->have_pending = 0;
  m->n_changes++;
  m->last_change_s = w->t_end_s;
  m->since_change = 0;
  store(m, w);
  return 1;
}

/* What the window's narrow peak was taken for, remembered for the estimate. */
static void note_narrow(hm_margin m, double t_end, const hm_mode_estimate *mode, hm_narrow_verdict narrow) {
  m->narrow = narrow;
  m->narrow_hz = mode->narrow_peak ? mode->narrow_peak_hz : 0.0;
  m->narrow_at_s = t_end;
  if (narrow == HM_NARROW_AMBIGUOUS) m->ambiguous_at_s = t_end;
}

hm_status hm_margin_add_window(hm_margin m, double t_end, double speed_kmh, double spread_kmh,
                               const hm_mode_estimate *mode, hm_window_verdict *verdict) {
  if (!m || !mode || !verdict || !isfinite(t_end) || !isfinite(speed_kmh) || !isfinite(spread_kmh)) return HM_EINVAL;
  window w;
  hm_narrow_verdict narrow;
  *verdict = prepare(m, t_end, speed_kmh, spread_kmh, mode, &w, &narrow);
  across_fits(m, *verdict, &w);
  note_alternative(m, t_end, mode, *verdict);
  note_narrow(m, t_end, mode, narrow);
  m->pending_misfit = 0; /* a committed window ends the stretch's provisional one */
  if (*verdict == HM_WINDOW_MISFIT) misfit_push(m, t_end);
  if (*verdict != HM_WINDOW_USED) return HM_OK;
  if (changed(m, &w)) *verdict = HM_WINDOW_CHANGE;
  else store(m, &w);
  return HM_OK;
}

hm_status hm_margin_set_pending(hm_margin m, double t_end, double speed_kmh, double spread_kmh,
                                const hm_mode_estimate *mode, hm_window_verdict *verdict) {
  if (!m || !mode || !verdict || !isfinite(t_end) || !isfinite(speed_kmh) || !isfinite(spread_kmh)) return HM_EINVAL;
  window w;
  hm_narrow_verdict narrow;
  *verdict = prepare(m, t_end, speed_kmh, spread_kmh, mode, &w, &narrow);
  across_fits(m, *verdict, &w);
  note_alternative(m, t_end, mode, *verdict);
  note_narrow(m, t_end, mode, narrow);
  m->pending_misfit = *verdict == HM_WINDOW_MISFIT;
  m->pending_misfit_t = t_end;
  if (*verdict == HM_WINDOW_USED && changed(m, &w)) *verdict = HM_WINDOW_CHANGE; /* committed, as evidence */
  m->have_pending = *verdict == HM_WINDOW_USED;
  if (m->have_pending) m->pending = w;
  return HM_OK;
}

void hm_margin_commit_pending(hm_margin m) {
  if (!m) return;
  if (m->pending_misfit) misfit_push(m, m->pending_misfit_t);
  m->pending_misfit = 0;
  if (!m->have_pending) return;
  store(m, &m->pending);
}

/* (a): inverse-variance mean of the windows' conicities; systematic errors do not average out. */
static void model_based(const hm_margin m, const window *const *ws, size_t n, hm_margin_estimate *r) {
  double sw = 0.0, swl = 0.0, sw2stat = 0.0, swsys = 0.0;
  for (size_t k = 0; k < n; ++k) {
    const double wk = 1.0 / (ws[k]->lambda_se * ws[k]->lambda_se);
    sw += wk;
    swl += wk * ws[k]->lambda;
    sw2stat += wk * wk * ws[k]->lambda_stat * ws[k]->lambda_stat;
    swsys += wk * ws[k]->lambda_sys;
  }
  if (n == 0 || !(sw > 0.0)) return;
  r->conicity_valid = 1;
  r->conicity = swl / sw;
  r->conicity_se = hypot(sqrt(sw2stat) / sw, swsys / sw);
  /* windows that disagree more than their errors say widen the interval (the Birge ratio) */
  r->birge_ratio = 1.0;
  if (n > 1) {
    double chi2 = 0.0;
    for (size_t k = 0; k < n; ++k) {
      const double d = (ws[k]->lambda - r->conicity) / ws[k]->lambda_se;
      chi2 += d * d;
    }
    r->birge_ratio = sqrt(chi2 / (double)(n - 1));
    if (r->birge_ratio > 1.0) r->conicity_se *= r->birge_ratio;
  }
  const double z = m->cfg.interval_z;
  r->hopf_model_valid = 1;
  r->hopf_model_kmh = hm_margin_hopf_kmh(m, r->conicity);
  r->conicity_low = fmax(r->conicity - z * r->conicity_se, 1e-6);
  r->conicity_high = r->conicity + z * r->conicity_se;
  r->hopf_model_low_kmh = hm_margin_hopf_kmh(m, r->conicity_high);
  r->hopf_model_high_kmh = hm_margin_hopf_kmh(m, r->conicity_low);
}

/* P(|T| <= t) for Student's t with nu degrees of freedom (Abramowitz & Stegun 26.7.3-4: finite sums in theta). */
static double student_t_central(double t, unsigned nu) {
  const double th = atan(t / sqrt((double)nu)), c = cos(th), s = sin(th);
  double sum = 0.0, term;
  if (nu % 2 == 1) {
    if (nu == 1) return 2.0 * th / HM_PI;
    term = c;
    sum = c;
    for (unsigned k = 3; k + 2 <= nu; k += 2) sum += (term *= c * c * (double)(k - 1) / (double)k);
    return 2.0 / HM_PI * (th + s * sum);
  }
  term = 1.0;
  sum = 1.0;
  for (unsigned k = 2; k + 2 <= nu; k += 2) sum += (term *= c * c * (double)(k - 1) / (double)k);
  return s * sum;
}

/* The t quantile with the two-sided coverage of +-z standard normal deviations, by bisection. */
static double student_t_for_z(double z, unsigned nu) {
  const double p = erf(z / sqrt(2.0));
  double lo = z, hi = 1e4;
  for (int it = 0; it < 200 && hi - lo > 1e-10 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    if (student_t_central(mid, nu) < p) lo = mid;
    else hi = mid;
  }
  return 0.5 * (lo + hi);
}

/* The model's decay rate [1/s] at x = 1000 / v (v in km/h) and the vehicle's lambda(0); NAN if it cannot be found. */
static double model_sigma(const hm_margin m, double x) {
  double sg, om;
  return hunting_root(m, 1000.0 / x, m->lambda0, &sg, &om) == HM_OK ? sg : NAN;
}

/* (b): weighted least squares of sigma on x = 1000 / v; the zero of the line with Fieller's interval, widened by the
 * line's curvature error. */
static void model_free(const hm_margin m, const window *const *all, size_t n_all, hm_margin_estimate *r) {
  const hm_margin_config *c = &m->cfg;
  const window *ws[HM_MARGIN_MAX_WINDOWS + 1];
  size_t n = 0;
  const int by_kind = reads_by_model(m);
  size_t kinds[3] = {0, 0, 0};
  for (size_t k = 0; k < n_all; ++k) kinds[all[k]->poles <= 2 ? all[k]->poles : 0]++;
  const unsigned kind = kinds[2] > kinds[1] ? 2 : 1; /* the windows' more frequent reading (restored ones: either) */
  double v_lo = INFINITY, v_hi = -INFINITY;
  for (size_t k = 0; k < n_all; ++k)
    if (!by_kind || all[k]->poles == 0 || all[k]->poles == kind) {
      ws[n++] = all[k];
      v_lo = fmin(v_lo, all[k]->speed_kmh), v_hi = fmax(v_hi, all[k]->speed_kmh);
    }
  if (n < 2 || v_hi - v_lo < c->min_speed_span_kmh) return;
  double s0 = 0.0, s1 = 0.0, s2 = 0.0, t0 = 0.0, t1 = 0.0;
  for (size_t k = 0; k < n; ++k) {
    const double wk = 1.0 / (ws[k]->sigma_stat * ws[k]->sigma_stat), x = 1000.0 / ws[k]->speed_kmh;
    s0 += wk, s1 += wk * x, s2 += wk * x * x, t0 += wk * ws[k]->sigma, t1 += wk * x * ws[k]->sigma;
  }
  const double det = s0 * s2 - s1 * s1;
  if (!(det > 0.0)) return;
  const double beta = (s0 * t1 - s1 * t0) / det, alpha = (s2 * t0 - s1 * t1) / det;
  double var_a = s2 / det, var_b = s0 / det, cov_ab = -s1 / det;
  double q = c->interval_z; /* the stated errors: normal quantiles */
  if (n > 2) { /* scale by the residual variance when there are degrees of freedom (never below the stated errors) */
    double chi2 = 0.0;
    for (size_t k = 0; k < n; ++k) {
      const double d = (ws[k]->sigma - alpha - beta * 1000.0 / ws[k]->speed_kmh) / ws[k]->sigma_stat;
      chi2 += d * d;
    }
    const double f = chi2 / (double)(n - 2);
    if (f > 1.0) { /* the errors estimated from the residuals: Student's t with n - 2 degrees of freedom */
      var_a *= f, var_b *= f, cov_ab *= f;
      q = student_t_for_z(c->interval_z, (unsigned)(n - 2));
    }
  }
  /* Fieller: the x where |alpha + beta x| <= q sd(alpha + beta x), a x^2 + b x + cc <= 0 */
  const double qq = q * q, a = beta * beta - qq * var_b, b = 2.0 * (alpha * beta - qq * cov_ab);
  const double cc = alpha * alpha - qq * var_a, disc = b * b - 4.0 * a * cc;
  if (!(beta < 0.0) || !(a > 0.0) || !(disc >= 0.0)) return; /* no significant approach to zero with speed */
  const double xh = -alpha / beta;
  double x1 = (-b - sqrt(disc)) / (2.0 * a), x2 = (-b + sqrt(disc)) / (2.0 * a);
  if (!(xh > 0.0) || !isfinite(x1) || !isfinite(x2)) return;
  /* the line's own error: the model's sigma(x) against its chord through the windows' speeds, at the zero */
  /* (not for a model read at its sensor: its least-damped root need not be the mode read, nor its curve the reading's) */
  const double xa = 1000.0 / v_hi, xb = 1000.0 / v_lo;
  const double sa = by_kind ? NAN : model_sigma(m, xa), sb = by_kind ? NAN : model_sigma(m, xb);
  const double sh = by_kind ? NAN : model_sigma(m, xh);
  if (isfinite(sa) && isfinite(sb) && isfinite(sh) && xb > xa) {
    const double gap = sh - (sa + (sb - sa) * (xh - xa) / (xb - xa)), dx = fabs(gap / beta);
    x1 -= dx;
    x2 += dx;
  }
  const double vh = 1000.0 / xh;
  if (vh > v_hi + c->max_extrapolation_kmh) return;
  r->hopf_free_valid = 1;
  r->hopf_free_kmh = vh;
  r->hopf_free_low_kmh = 1000.0 / x2;
  r->hopf_free_high_kmh = x1 > 1000.0 / HM_LINEAR_NO_HOPF_KMH ? 1000.0 / x1 : HM_LINEAR_NO_HOPF_KMH;
}

void hm_margin_read(const hm_margin m, double now, hm_margin_estimate *out) {
  if (!m || !out) return;
  hm_margin_estimate r;
  memset(&r, 0, sizeof r);
  const window *ws[HM_MARGIN_MAX_WINDOWS];
  size_t n = held(m, now, ws);
  r.speed_min_kmh = INFINITY;
  r.speed_max_kmh = -INFINITY;
  for (size_t k = 0; k < n; ++k) {
    r.speed_min_kmh = fmin(r.speed_min_kmh, ws[k]->speed_kmh);
    r.speed_max_kmh = fmax(r.speed_max_kmh, ws[k]->speed_kmh);
  }
  if (m->have_pending && n < HM_MARGIN_MAX_WINDOWS) { /* the current stretch counts, provisionally */
    ws[n++] = &m->pending;
    r.speed_min_kmh = fmin(r.speed_min_kmh, m->pending.speed_kmh);
    r.speed_max_kmh = fmax(r.speed_max_kmh, m->pending.speed_kmh);
  }
  r.n_windows = (unsigned)n;
  if (n == 0) r.speed_min_kmh = r.speed_max_kmh = 0.0;
  r.birge_ratio = 1.0;
  r.interval_z = m->cfg.interval_z;
  model_based(m, ws, n, &r);
  model_free(m, ws, n, &r);
  for (size_t k = 0; k < m->misfit_n; ++k)
    r.n_misfits += !(isfinite(now) && now - m->misfit_t[k] > m->cfg.memory_s);
  r.n_misfits += (unsigned)m->pending_misfit;
  r.n_changes = m->n_changes;
  r.last_change_s = m->last_change_s;
  r.windows_since_change = (unsigned)(m->n_changes ? m->since_change + (size_t)m->have_pending : (size_t)n);
  r.narrow = m->narrow;
  r.narrow_peak_hz = m->narrow_hz;
  r.narrow_at_s = m->narrow_at_s;
  r.ambiguous_at_s = m->ambiguous_at_s;
  /* an estimate outside the prior's range by more than interval_z of its error */
  if (r.conicity_valid && m->prior_high > 0.0)
    r.outside_prior = r.conicity_low > m->prior_high ? 1 : r.conicity_high < m->prior_low ? -1 : 0;
  /* a window whose mode is lightly damped (|sigma| at most HM_MARGIN_NEAR_DECAY_1_S): instability is near, whatever
   * the model says of it (margin.h) */
  for (size_t k = 0; k < n; ++k) r.near_evidence |= fabs(ws[k]->sigma) <= HM_MARGIN_NEAR_DECAY_1_S;
  r.model_mismatch = (r.hopf_model_valid && r.hopf_free_valid &&
                      (r.hopf_model_high_kmh < r.hopf_free_low_kmh || r.hopf_free_high_kmh < r.hopf_model_low_kmh)) ||
                     r.n_misfits >= 2;
  *out = r;
}

/* ---- what the margin has learned, kept through a restart (margin.h's hm_margin_snapshot; state.h) ---- */

void hm_margin_take_snapshot(const hm_margin m, double now, hm_margin_snapshot *out) {
  if (!m || !out || !isfinite(now)) return;
  hm_margin_snapshot s;
  memset(&s, 0, sizeof s);
  const window *ws[HM_MARGIN_MAX_WINDOWS + 1];
  size_t n = held(m, now, ws); /* newest first */
  if (m->have_pending) { /* committed, as a gap would commit it; the oldest goes where the ring is full */
    memmove(ws + 1, ws, n * sizeof ws[0]);
    ws[0] = &m->pending;
    n = n < HM_MARGIN_MAX_WINDOWS ? n + 1 : HM_MARGIN_MAX_WINDOWS;
  }
  for (size_t k = 0; k < n; ++k) {
    const window *w = ws[n - 1 - k];
    hm_margin_window *o = &s.windows[k];
    o->age_s = fmax(now - w->t_end_s, 0.0);
    o->speed_kmh = w->speed_kmh;
    o->window_s = w->window_s;
    o->sigma_1_s = w->sigma;
    o->sigma_stat_1_s = w->sigma_stat;
    o->conicity = w->lambda;
    o->conicity_se = w->lambda_se;
    o->conicity_stat = w->lambda_stat;
    o->conicity_sys = w->lambda_sys;
  }
  s.n_windows = (unsigned)n;
  for (size_t k = 0; k < m->misfit_n; ++k)
    if (now - m->misfit_t[k] <= m->cfg.memory_s) s.misfit_age_s[s.n_misfits++] = fmax(now - m->misfit_t[k], 0.0);
  if (m->pending_misfit && s.n_misfits < HM_MARGIN_MAX_WINDOWS)
    s.misfit_age_s[s.n_misfits++] = fmax(now - m->pending_misfit_t, 0.0);
  s.n_changes = m->n_changes;
  s.last_change_age_s = m->n_changes ? fmax(now - m->last_change_s, 0.0) : 0.0;
  s.windows_since_change = (unsigned)(m->since_change + (size_t)m->have_pending);
  s.narrow = m->narrow;
  s.narrow_peak_hz = m->narrow_hz;
  s.narrow_age_s = m->narrow_at_s != 0.0 ? fmax(now - m->narrow_at_s, 0.0) : INFINITY;
  s.ambiguous_age_s = m->ambiguous_at_s > 0.0 ? fmax(now - m->ambiguous_at_s, 0.0) : INFINITY;
  *out = s;
}

/* x in [lo, hi] (NaN is not) */
static int in_range(double x, double lo, double hi) { return x >= lo && x <= hi; }

/* What is wrong with a kept window, or NULL. */
static const char *window_fault(const hm_margin_window *w) {
  if (!(isfinite(w->age_s) && w->age_s >= 0.0)) return "age_s: finite and >= 0";
  if (!(w->speed_kmh > 0.0 && w->speed_kmh <= 2000.0)) return "speed_kmh: in (0, 2000]";
  if (!(w->window_s > 0.0 && w->window_s <= 3600.0)) return "window_s: in (0, 3600]";
  if (!in_range(w->sigma_1_s, -1e4, 0.0)) return "sigma_1_s: in [-1e4, 0]";
  if (!in_range(w->sigma_stat_1_s, 1e-12, 1e4)) return "sigma_stat_1_s: in [1e-12, 1e4]";
  if (!(w->conicity > 0.0 && w->conicity <= 100.0)) return "conicity: in (0, 100]";
  if (!in_range(w->conicity_se, 1e-12, 100.0)) return "conicity_se: in [1e-12, 100]";
  if (!in_range(w->conicity_stat, 0.0, 100.0) || !in_range(w->conicity_sys, 0.0, 100.0))
    return "conicity_stat, conicity_sys: in [0, 100]";
  return NULL;
}

hm_status hm_margin_snapshot_validate(const hm_margin_snapshot *s, char *why, size_t len) {
  if (!s) return HM_EINVAL;
  const char *field = NULL;
  char where[48] = "";
  if (s->n_windows > HM_MARGIN_MAX_WINDOWS) field = "n_windows: at most 64";
  for (unsigned k = 0; !field && k < s->n_windows; ++k)
    if ((field = window_fault(&s->windows[k])) != NULL) snprintf(where, sizeof where, "window %u ", k);
  if (!field && s->n_misfits > HM_MARGIN_MAX_WINDOWS) field = "n_misfits: at most 64";
  for (unsigned k = 0; !field && k < s->n_misfits; ++k)
    if (!(isfinite(s->misfit_age_s[k]) && s->misfit_age_s[k] >= 0.0)) field = "misfit_age_s: finite and >= 0";
  if (!field && s->n_changes && !(isfinite(s->last_change_age_s) && s->last_change_age_s >= 0.0))
    field = "last_change_age_s: finite and >= 0";
  if (!field && !((unsigned)s->narrow <= HM_NARROW_AMBIGUOUS)) field = "narrow: a narrow-peak verdict (0..3)";
  if (!field && !in_range(s->narrow_peak_hz, 0.0, 1e4)) field = "narrow_peak_hz: in [0, 1e4]";
  if (!field && !(s->narrow_age_s >= 0.0 && s->ambiguous_age_s >= 0.0))
    field = "narrow_age_s, ambiguous_age_s: >= 0 (INFINITY: none)";
  if (!field) return HM_OK;
  if (why && len) snprintf(why, len, "margin: %s%s", where, field);
  return HM_EDOMAIN;
}

hm_status hm_margin_restore(hm_margin m, double now, const hm_margin_snapshot *s, char *why, size_t len) {
  if (!m || !s || !isfinite(now)) return HM_EINVAL;
  const hm_status st = hm_margin_snapshot_validate(s, why, len);
  if (st != HM_OK) return st;
  hm_margin_reset(m);
  for (unsigned k = 0; k < s->n_windows; ++k) {
    const hm_margin_window *o = &s->windows[k];
    const window w = {now - o->age_s, o->speed_kmh, o->window_s, o->sigma_1_s, o->sigma_stat_1_s,
                      o->conicity, o->conicity_se, o->conicity_stat, o->conicity_sys, 0};
    store(m, &w);
  }
  for (unsigned k = 0; k < s->n_misfits; ++k) misfit_push(m, now - s->misfit_age_s[k]);
  m->n_changes = s->n_changes;
  m->last_change_s = s->n_changes ? now - s->last_change_age_s : 0.0;
  m->since_change = s->windows_since_change;
  m->narrow = s->narrow;
  m->narrow_hz = s->narrow_peak_hz;
  m->narrow_at_s = isfinite(s->narrow_age_s) ? now - s->narrow_age_s : 0.0;
  /* 0 means none here: an ambiguous peak from before the new line's zero is kept at its smallest positive time (its
   * WATCH then lasts at most that much longer) */
  if (isfinite(s->ambiguous_age_s)) m->ambiguous_at_s = fmax(now - s->ambiguous_age_s, nextafter(0.0, 1.0));
  return HM_OK;
}
