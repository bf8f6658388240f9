/* Streaming estimator of the dominant lateral oscillation and the standard criteria
 * (see estimator.h). No allocation after create. */
#include "hunting_monitor/estimator.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hunting_monitor/linear.h"
#include "biquad.h"
#include "select.h"
#include "hunting_monitor/criteria.h"
#include "validate.h"

enum { BAND_SECTIONS = 4 };

struct hm_estimator_s {
  hm_estimator_config cfg;
  hm_displacement_map_fn disp_map; /* the wheelset's displacement per acceleration (NULL: the sensor's own) */
  void *disp_ctx;
  hm_biquad band[BAND_SECTIONS];    /* HP4 + LP4 */
  hm_criteria criteria;           /* the standard criteria on the same samples */
  /* sample history */
  int have_sample;
  double t_last, t_start;        /* last accepted sample, start of the current run (after a gap) */
  double x_prev;                 /* previous band-passed value */
  double ms;                     /* mean square of the band-passed signal */
  double ms_dt, ms_gain;         /* its one-pole gain 1 - exp(-dt / (tracking_time / 2)) and the dt it is for */
  /* zero crossings: a ring of up-crossing times, with the running sum of x^2 and the sample count at each */
  double *cross, *cross_sum, *cross_count;
  double sum_sq, count;          /* running sum of x^2 and number of samples since the restart */
  size_t cross_cap, cross_head, cross_n;
  int armed;
  /* speed */
  int have_speed;
  double speed_kmh, t_speed;
  hm_speed_refusal speed_refusal; /* the latest speed's (HM_SPEED_ACCEPTED once one is accepted) */
  double t_refused;               /* when it came: the later of its stamp and the latest acceleration sample's (a
                                     stamp not after the previous one, or not finite, still arrives now) */
  /* the tracked oscillation as of the last crossing (the crossing ring changes only there) */
  double trk_f, trk_spread, trk_amp;
  hm_estimate counters;          /* only the counters are used */
  /* sample rate: the filters are designed for design_rate_hz; the rate is measured as the reciprocal of the median
   * stamp difference over blocks of RATE_BLOCK_S (so lost or late samples do not read as another rate); two blocks
   * in a row off by more than RATE_REDESIGN_TOL redesign them */
  double design_rate_hz, measured_rate_hz;
  double blk_t0;
  double *blk_dt;                /* the block's stamp differences (scratch for the median) */
  size_t blk_n, blk_cap;
  int off_blocks;
  int stamps_regular;            /* the last block's stamps lay on a grid (losses can be counted and bridged) */
  unsigned long n_restarts;      /* filter restarts (gaps, redesigns, resets) */
  /* lost samples: stamp differences of k >= 2 periods on a regular grid; bridged by k - 1 interpolated samples */
  double a_prev;                 /* the previous accepted sample */
  unsigned last_fill;            /* samples interpolated before the latest accepted one */
  double blk_lost, blk_got;      /* this block's lost and received samples */
  double loss_lost, loss_got;    /* the same, averaged over about LOSS_MEMORY_S */
};

enum { RATE_BLOCKS_TO_REDESIGN = 2 };
static const double RATE_BLOCK_S = 0.5, RATE_REDESIGN_TOL = 0.05, RATE_MISMATCH_TOL = 0.05;
/* a block's stamps are regular when this fraction of its differences lie within GRID_TOL periods of a whole number
 * (1 or more) of median differences: a sensor's own clock, not receipt times in bursts */
static const double GRID_FRACTION = 0.95, GRID_TOL = 0.25;
/* the block buffer holds RATE_BLOCK_S at this rate (a faster stream ends its blocks early) */
static const double RATE_BLOCK_MAX_HZ = 10000.0;
static const double LOSS_MEMORY_S = 10.0;

void hm_estimator_config_criteria(hm_estimator_config *c, hm_measurement_point point) {
  c->measurement_point = point;
  if (point == HM_POINT_BOGIE_FRAME) { /* the standards' own limits, for the signal they were written for */
    c->rms_limit_mps2 = 5.2;
    c->peaks_band_low_hz = 0.5;
    c->peaks_band_high_hz = 10.0;
    c->peaks_limit_mps2 = 8.0;
    c->displacement_limit_m = 0.0; /* the frame's displacement is not the wheelset's */
  } else { /* the wheelset: from the model (estimator.h) */
    c->rms_limit_mps2 = 12.0;
    c->peaks_band_low_hz = 2.0;
    c->peaks_band_high_hz = 20.0;
    c->peaks_limit_mps2 = 17.0;
    c->displacement_limit_m = HM_ESTIMATOR_WHEELSET_DISPLACEMENT_M;
  }
  c->peaks_count = 6;
}

void hm_estimator_config_default(hm_estimator_config *c) {
  c->sample_rate_hz = 2000.0;
  c->band_low_hz = 2.0;
  c->band_high_hz = 20.0;
  c->tracking_time_s = 1.0;
  c->rms_window_m = 100.0;
  hm_estimator_config_criteria(c, HM_POINT_WHEELSET);
  c->max_gap_s = 0.2;
  c->accel_timeout_s = 0.2;
  c->speed_timeout_s = 1.0;
  c->max_speed_kmh = 600.0;
  c->max_speed_rate_kmh_s = 30.0;
  c->max_speed_jump_kmh = 2.0;
  c->max_accel_mps2 = 500.0;
}

hm_status hm_estimator_config_validate(const hm_estimator_config *c, char *why, size_t len) {
  if (!c) return HM_EINVAL;
  const double fs = c->sample_rate_hz;
  /* the upper ends of tracking_time_s, rms_window_m and the gaps bound the buffers sized from them (estimator.h
   * states the memory they bound) */
  const hm_field_check f[] = {
      {"sample_rate_hz", fs, HM_RULE_RANGE, 100.0, 5000.0},
      {"band_low_hz", c->band_low_hz, HM_RULE_POSITIVE, 0.0, 0.0},
      {"tracking_time_s", c->tracking_time_s, HM_RULE_RANGE_OPEN, 0.0, HM_ESTIMATOR_MAX_TRACKING_S},
      {"rms_window_m", c->rms_window_m, HM_RULE_RANGE_OPEN, 0.0, HM_ESTIMATOR_MAX_RMS_WINDOW_M},
      {"rms_limit_mps2", c->rms_limit_mps2, HM_RULE_POSITIVE, 0.0, 0.0},
      {"peaks_band_low_hz", c->peaks_band_low_hz, HM_RULE_POSITIVE, 0.0, 0.0},
      {"peaks_limit_mps2", c->peaks_limit_mps2, HM_RULE_POSITIVE, 0.0, 0.0},
      {"max_gap_s", c->max_gap_s, HM_RULE_RANGE_OPEN, 0.0, 10.0},
      {"accel_timeout_s", c->accel_timeout_s, HM_RULE_RANGE_OPEN, 0.0, 60.0},
      {"speed_timeout_s", c->speed_timeout_s, HM_RULE_RANGE_OPEN, 0.0, 60.0},
      {"max_speed_kmh", c->max_speed_kmh, HM_RULE_POSITIVE, 0.0, 0.0},
      {"max_speed_rate_kmh_s", c->max_speed_rate_kmh_s, HM_RULE_POSITIVE, 0.0, 0.0},
      {"max_accel_mps2", c->max_accel_mps2, HM_RULE_POSITIVE, 0.0, 0.0},
      {"max_speed_jump_kmh", c->max_speed_jump_kmh, HM_RULE_RANGE, 0.0, 100.0},
      {"peaks_count", (double)c->peaks_count, HM_RULE_RANGE, 1.0, 1000.0},
      {"displacement_limit_m", c->displacement_limit_m, HM_RULE_RANGE, 0.0, 0.05}};
  const hm_status st = hm_check_fields(f, HM_COUNT_OF(f), why, len);
  if (st != HM_OK) return st;
  if (!(c->band_high_hz > c->band_low_hz) || !(c->band_high_hz < 0.45 * fs))
    return hm_reject(why, len, "band_high_hz", "must be above band_low_hz and below 0.45 sample_rate_hz",
                     c->band_high_hz);
  if (!(c->peaks_band_high_hz > c->peaks_band_low_hz) || !(c->peaks_band_high_hz < 0.45 * fs))
    return hm_reject(why, len, "peaks_band_high_hz", "must be above peaks_band_low_hz and below 0.45 sample_rate_hz",
                     c->peaks_band_high_hz);
  if (c->tracking_time_s * c->band_low_hz < 1.0)
    return hm_reject(why, len, "tracking_time_s", "must hold at least one period of band_low_hz", c->tracking_time_s);
  if (c->measurement_point != HM_POINT_WHEELSET && c->measurement_point != HM_POINT_BOGIE_FRAME)
    return hm_reject(why, len, "measurement_point", "must be wheelset or bogie_frame", (double)c->measurement_point);
  if (c->max_gap_s < 2.0 / fs) return hm_reject(why, len, "max_gap_s", "must be at least two sample periods", c->max_gap_s);
  return HM_OK;
}

/* Filters, trackers and the r.m.s. window restart (after a gap or at reset); speed and counters stay. */
static void restart_signal(hm_estimator e) {
  const hm_estimator_config *c = &e->cfg;
  e->n_restarts++;
  const double fs = e->design_rate_hz;
  e->band[0] = hm_biquad_design(1, c->band_low_hz, HM_BUTTERWORTH_Q4[0], fs);
  e->band[1] = hm_biquad_design(1, c->band_low_hz, HM_BUTTERWORTH_Q4[1], fs);
  e->band[2] = hm_biquad_design(0, c->band_high_hz, HM_BUTTERWORTH_Q4[0], fs);
  e->band[3] = hm_biquad_design(0, c->band_high_hz, HM_BUTTERWORTH_Q4[1], fs);
  e->have_sample = 0;
  e->x_prev = 0.0;
  e->ms = 0.0;
  e->ms_dt = NAN; /* (the gain computed at the first sample) */
  e->cross_head = e->cross_n = 0;
  e->sum_sq = e->count = 0.0;
  e->trk_f = e->trk_amp = 0.0;
  e->trk_spread = 1.0;
  e->armed = 0;
  hm_criteria_restart(e->criteria, fs);
  e->blk_n = 0;
  e->blk_lost = e->blk_got = 0.0;
  e->off_blocks = 0;
  e->last_fill = 0;
}

/* The rate the filters can be designed for: the bands below 0.45 of it, and 100..5000 Hz. */
static int rate_supported(const hm_estimator_config *c, double fs) {
  return fs >= 100.0 && fs <= 5000.0 && c->band_high_hz < 0.45 * fs && c->peaks_band_high_hz < 0.45 * fs;
}

/* The end of a rate block (at the sample at t): the share of differences on the grid of the median difference says
 * whether the stamps are regular; the rate is then the median's (lost samples do not change it), else the block's
 * mean; the block's losses enter the averaged loss fraction. */
static void end_block(hm_estimator e, double t) {
  int regular = 0;
  double period = 0.0;
  const double mean_period = e->blk_n > 0 ? (t - e->blk_t0) / (double)e->blk_n : 0.0;
  if (e->blk_n >= 8) {
    size_t on_grid = 0;
    period = hm_select_kth(e->blk_dt, e->blk_n, e->blk_n / 2);
    for (size_t k = 0; k < e->blk_n; ++k) {
      const double q = e->blk_dt[k] / period, r = floor(q + 0.5);
      if (r >= 1.0 && fabs(q - r) <= GRID_TOL) ++on_grid;
    }
    regular = (double)on_grid >= GRID_FRACTION * (double)e->blk_n;
  }
  /* irregular stamps (receipt times, which come in bursts): their median is no period; their mean is */
  if (!regular) period = mean_period;
  const double decay = exp(-RATE_BLOCK_S / LOSS_MEMORY_S);
  e->loss_lost = decay * e->loss_lost + e->blk_lost;
  e->loss_got = decay * e->loss_got + e->blk_got;
  e->blk_n = 0;
  e->blk_lost = e->blk_got = 0.0;
  if (!(period > 0.0)) return;
  e->measured_rate_hz = 1.0 / period;
  e->stamps_regular = regular;
  const int off = fabs(e->measured_rate_hz / e->design_rate_hz - 1.0) > RATE_REDESIGN_TOL;
  e->off_blocks = off ? e->off_blocks + 1 : 0;
  if (e->off_blocks >= RATE_BLOCKS_TO_REDESIGN && rate_supported(&e->cfg, e->measured_rate_hz)) {
    e->design_rate_hz = e->measured_rate_hz;
    e->counters.n_rate_changes++;
    restart_signal(e); /* the filters' state belongs to the old design */
  }
}

/* Called per accepted sample after a first one, with no gap since the last: the block's stamp differences, and a
 * redesign on a lasting change (the stream at another rate than configured: filters designed for the wrong
 * rate put the band elsewhere, issue #9 item 5). */
static void measure_rate(hm_estimator e, double t) {
  if (e->blk_n == 0) e->blk_t0 = e->t_last;
  e->blk_dt[e->blk_n++] = t - e->t_last;
  if (t - e->blk_t0 >= RATE_BLOCK_S || e->blk_n == e->blk_cap) end_block(e, t);
}

/* Samples lost before one arriving dt after the last: k - 1 for a difference of k >= 2 periods of a confirmed grid
 * (regular stamps at a measured rate within RATE_REDESIGN_TOL of the design), else 0. */
static unsigned lost_before(const hm_estimator e, double dt) {
  if (!e->stamps_regular || !(e->measured_rate_hz > 0.0) ||
      fabs(e->measured_rate_hz / e->design_rate_hz - 1.0) > RATE_REDESIGN_TOL)
    return 0;
  const double k = floor(dt * e->design_rate_hz + 0.5);
  return k >= 2.0 ? (unsigned)(k - 1.0) : 0;
}

hm_status hm_estimator_create(const hm_estimator_config *cfg, hm_estimator *out, char *why, size_t why_len) {
  if (!cfg || !out) return HM_EINVAL;
  const hm_status st = hm_estimator_config_validate(cfg, why, why_len);
  if (st != HM_OK) return st;
  hm_estimator e = calloc(1, sizeof *e);
  if (!e) return HM_ENOMEM;
  e->cfg = *cfg;
  /* crossings in one tracking time at the top of the band, with room to spare */
  e->cross_cap = (size_t)ceil(cfg->band_high_hz * cfg->tracking_time_s * 2.0) + 8;
  e->cross = malloc(e->cross_cap * sizeof(double));
  e->cross_sum = malloc(e->cross_cap * sizeof(double));
  e->cross_count = malloc(e->cross_cap * sizeof(double));
  e->blk_cap = (size_t)ceil(RATE_BLOCK_S * RATE_BLOCK_MAX_HZ);
  e->blk_dt = malloc(e->blk_cap * sizeof(double));
  const hm_criteria_config cc = {cfg->rms_window_m,       cfg->rms_limit_mps2,     cfg->peaks_band_low_hz,
                                 cfg->peaks_band_high_hz, cfg->peaks_limit_mps2, cfg->peaks_count};
  if (!e->cross || !e->cross_sum || !e->cross_count || !e->blk_dt || hm_criteria_create(&cc, &e->criteria) != HM_OK) {
    hm_estimator_destroy(e);
    return HM_ENOMEM;
  }
  hm_estimator_reset(e);
  *out = e;
  return HM_OK;
}

hm_status hm_estimator_set_limits(hm_estimator e, const hm_estimator_config *cfg, char *why, size_t len) {
  if (!e || !cfg) return HM_EINVAL;
  hm_estimator_config c = e->cfg;
  c.rms_limit_mps2 = cfg->rms_limit_mps2;
  c.peaks_limit_mps2 = cfg->peaks_limit_mps2;
  c.peaks_count = cfg->peaks_count;
  c.displacement_limit_m = cfg->displacement_limit_m;
  const hm_status st = hm_estimator_config_validate(&c, why, len);
  if (st != HM_OK) return st;
  e->cfg = c;
  hm_criteria_set_limits(e->criteria, c.rms_limit_mps2, c.peaks_limit_mps2, c.peaks_count);
  return HM_OK;
}

void hm_estimator_set_displacement_map(hm_estimator e, hm_displacement_map_fn fn, void *ctx) {
  if (!e) return;
  e->disp_map = fn;
  e->disp_ctx = fn ? ctx : NULL;
}

unsigned long hm_estimator_restarts(const hm_estimator e, double *design_rate_hz) {
  if (!e) return 0;
  if (design_rate_hz) *design_rate_hz = e->design_rate_hz;
  return e->n_restarts;
}

void hm_estimator_destroy(hm_estimator e) {
  if (!e) return;
  free(e->cross);
  free(e->cross_sum);
  free(e->cross_count);
  free(e->blk_dt);
  hm_criteria_destroy(e->criteria);
  free(e);
}

void hm_estimator_reset(hm_estimator e) {
  if (!e) return;
  e->design_rate_hz = e->cfg.sample_rate_hz;
  e->measured_rate_hz = 0.0;
  e->stamps_regular = 0;
  e->loss_lost = e->loss_got = 0.0;
  restart_signal(e);
  e->have_speed = 0;
  e->speed_kmh = 0.0;
  e->t_speed = 0.0;
  e->speed_refusal = HM_SPEED_ACCEPTED;
  e->t_refused = 0.0;
  memset(&e->counters, 0, sizeof e->counters);
}

/* ---- the tracker ---- */

/* Amplitude of the oscillation at frequency f from mean square ms: sqrt(2 ms) corrected for the band-pass
 * filter's gain there (a 4th-order Butterworth at 20 Hz already attenuates 15 Hz by 3%); uncorrected if f is
 * unknown. */
static double amplitude_from(const hm_estimator e, double ms, double f) {
  double gain = 1.0;
  if (f > 0.0)
    for (int k = 0; k < BAND_SECTIONS; ++k) gain *= hm_biquad_gain(&e->band[k], 2.0 * HM_PI * f / e->design_rate_hz);
  return sqrt(2.0 * fmax(ms, 0.0)) / fmax(gain, 1e-3);
}

static double amplitude(const hm_estimator e) { return amplitude_from(e, e->ms, 0.0); }

/* Frequency from the up-crossings within the last tracking time, the periods' relative spread, and (if ms is
 * not NULL) the mean square over those whole periods (free of the one-pole average's ripple). */
static double crossing_frequency(const hm_estimator e, double *spread, double *ms) {
  const size_t cap = e->cross_cap;
  if (e->cross_n < 3) {
    *spread = 1.0;
    return 0.0;
  }
  const double t_last = e->cross[(e->cross_head + cap - 1) % cap];
  size_t first = e->cross_n; /* index (0 = oldest) of the first crossing inside the window */
  for (size_t k = 0; k < e->cross_n; ++k)
    if (e->cross[(e->cross_head + cap - e->cross_n + k) % cap] >= t_last - e->cfg.tracking_time_s) {
      first = k;
      break;
    }
  const size_t m = e->cross_n - first;
  if (m < 3) {
    *spread = 1.0;
    return 0.0;
  }
  const double t_first = e->cross[(e->cross_head + cap - e->cross_n + first) % cap];
  const double mean = (t_last - t_first) / (double)(m - 1);
  double var = 0.0;
  for (size_t k = first + 1; k < e->cross_n; ++k) {
    const double d = e->cross[(e->cross_head + cap - e->cross_n + k) % cap] -
                     e->cross[(e->cross_head + cap - e->cross_n + k - 1) % cap] - mean;
    var += d * d;
  }
  *spread = sqrt(var / (double)(m - 1)) / mean;
  if (ms) {
    const size_t i_first = (e->cross_head + cap - e->cross_n + first) % cap, i_last = (e->cross_head + cap - 1) % cap;
    const double n = e->cross_count[i_last] - e->cross_count[i_first];
    if (n > 0.0) *ms = (e->cross_sum[i_last] - e->cross_sum[i_first]) / n;
  }
  return 1.0 / mean;
}

/* The tracked oscillation: frequency, spread, and the amplitude over whole periods (the running one-pole
 * mean square until there are periods to average over). */
static double tracked(const hm_estimator e, double *spread, double *amp) {
  double ms = e->ms;
  const double f = crossing_frequency(e, spread, &ms);
  *amp = amplitude_from(e, ms, f);
  return f;
}

/* One sample on the filters' time grid (dt after the previous one): band-pass, trackers and criteria. */
static void process(hm_estimator e, double t, double dt, double a) {
  double x = a;
  for (int k = 0; k < BAND_SECTIONS; ++k) x = hm_biquad_step(&e->band[k], x);
  /* mean square with time constant tracking_time / 2 */
  if (dt != e->ms_dt) /* (dt is the filters' grid's: an exp once, not a sample) */
    e->ms_dt = dt, e->ms_gain = 1.0 - exp(-dt / (0.5 * e->cfg.tracking_time_s));
  e->ms += e->ms_gain * (x * x - e->ms);
  /* up-crossings, armed once the signal went below -10% of the amplitude */
  const double h = fmax(0.1 * amplitude(e), 1e-9);
  if (x < -h) e->armed = 1;
  e->sum_sq += x * x;
  e->count += 1.0;
  if (e->armed && e->x_prev < 0.0 && x >= 0.0) {
    const double tc = t - dt * x / (x - e->x_prev);
    e->cross[e->cross_head] = tc;
    e->cross_sum[e->cross_head] = e->sum_sq;
    e->cross_count[e->cross_head] = e->count;
    e->cross_head = (e->cross_head + 1) % e->cross_cap;
    if (e->cross_n < e->cross_cap) ++e->cross_n;
    e->armed = 0;
    e->trk_f = tracked(e, &e->trk_spread, &e->trk_amp);
  }
  e->x_prev = x;
  const int speed_ok = e->have_speed && t - e->t_speed <= e->cfg.speed_timeout_s;
  hm_criteria_push(e->criteria, x, a, speed_ok ? hm_mps_from_kmh(e->speed_kmh) * dt : 0.0);
}

hm_status hm_estimator_push_accel(hm_estimator e, double t, double a) {
  if (!e) return HM_EINVAL;
  if (!isfinite(t) || !isfinite(a)) {
    e->counters.n_rejected_nonfinite++;
    return HM_EDOMAIN;
  }
  if (fabs(a) > e->cfg.max_accel_mps2) {
    e->counters.n_rejected_range++;
    return HM_EDOMAIN;
  }
  if (e->have_sample && t <= e->t_last) {
    e->counters.n_rejected_order++;
    return HM_EDOMAIN; /* bad data, not caller misuse */
  }
  e->last_fill = 0;
  if (e->have_sample && t - e->t_last > e->cfg.max_gap_s) {
    e->counters.n_gaps++;
    restart_signal(e);
  }
  double dt = 1.0 / e->design_rate_hz;
  if (e->have_sample) {
    /* lost samples on a regular grid are bridged by linear interpolation, so the filters stay on their time grid */
    const unsigned lost = lost_before(e, t - e->t_last);
    dt = (t - e->t_last) / (double)(lost + 1);
    for (unsigned j = 1; j <= lost; ++j)
      process(e, e->t_last + j * dt, dt, e->a_prev + (a - e->a_prev) * (double)j / (double)(lost + 1));
    e->counters.n_samples_lost += lost;
    e->blk_lost += lost;
    measure_rate(e, t); /* may redesign and restart the filters */
    e->last_fill = e->have_sample ? lost : 0;
  }
  if (!e->have_sample) e->t_start = t;
  e->have_sample = 1;
  e->t_last = t;
  e->a_prev = a;
  e->counters.n_samples++;
  e->blk_got += 1.0;
  process(e, t, dt, a);
  return HM_OK;
}

unsigned hm_estimator_last_fill(const hm_estimator e) { return e ? e->last_fill : 0; }

const char *hm_speed_refusal_text(hm_speed_refusal r) {
  switch (r) {
    case HM_SPEED_ACCEPTED: return "";
    case HM_SPEED_NOT_FINITE: return "not finite or negative (the speed or its stamp)";
    case HM_SPEED_ABOVE_MAX: return "above max_speed_kmh";
    case HM_SPEED_IMPLAUSIBLE: return "changing faster than max_speed_rate_kmh_s";
    case HM_SPEED_NOT_AFTER: return "stamped not after the previous one";
  }
  return "refused";
}

hm_status hm_estimator_push_speed(hm_estimator e, double t, double v) {
  if (!e) return HM_EINVAL;
  e->counters.n_speed_updates++;
  const hm_estimator_config *c = &e->cfg;
  hm_speed_refusal why = !(isfinite(t) && isfinite(v) && v >= 0.0) ? HM_SPEED_NOT_FINITE
                         : v > c->max_speed_kmh                    ? HM_SPEED_ABOVE_MAX
                                                                   : HM_SPEED_ACCEPTED;
  if (why == HM_SPEED_ACCEPTED && e->have_speed) {
    const double dt = t - e->t_speed;
    const int fresh = dt <= c->speed_timeout_s;
    if (!(dt > 0.0))
      why = HM_SPEED_NOT_AFTER;
    else if (fresh && !(fabs(v - e->speed_kmh) <= c->max_speed_rate_kmh_s * dt + c->max_speed_jump_kmh))
      why = HM_SPEED_IMPLAUSIBLE;
  }
  e->speed_refusal = why;
  e->t_refused = isfinite(t) && (!e->have_sample || t > e->t_last) ? t : e->t_last;
  if (why != HM_SPEED_ACCEPTED) {
    e->counters.n_speed_rejected++;
    return HM_EDOMAIN;
  }
  e->have_speed = 1;
  e->speed_kmh = v;
  e->t_speed = t;
  return HM_OK;
}

void hm_estimator_read(const hm_estimator e, double now, hm_estimate *out) {
  if (!e || !out) return;
  const hm_estimator_config *c = &e->cfg;
  hm_estimate r = e->counters;
  r.time_s = e->have_sample ? e->t_last : 0.0;
  r.sample_rate_hz = e->design_rate_hz;
  r.sample_rate_measured_hz = e->measured_rate_hz;
  r.sample_rate_mismatch = e->measured_rate_hz > 0.0 && fabs(e->measured_rate_hz / c->sample_rate_hz - 1.0) > RATE_MISMATCH_TOL;
  r.sample_rate_supported = e->measured_rate_hz == 0.0 || rate_supported(c, e->measured_rate_hz);
  r.stamps_regular = e->stamps_regular;
  {
    const double lost = e->loss_lost + e->blk_lost, got = e->loss_got + e->blk_got;
    r.loss_fraction = lost + got > 0.0 ? lost / (lost + got) : 0.0;
  }
  r.accel_valid = e->have_sample && isfinite(now) && now - e->t_last <= c->accel_timeout_s && now >= e->t_last - 1.0 &&
                  r.sample_rate_supported;
  r.speed_valid = e->have_speed && isfinite(now) && now - e->t_speed <= c->speed_timeout_s;
  r.speed_kmh = e->have_speed ? e->speed_kmh : 0.0;
  /* a refusal is told while it is recent (speeds still arrive), not after the speeds stopped */
  r.speed_refused = !r.speed_valid && isfinite(now) && now - e->t_refused <= c->speed_timeout_s
                        ? e->speed_refusal
                        : HM_SPEED_ACCEPTED;
  const double f = e->have_sample ? e->trk_f : 0.0, spread = e->trk_spread, amp = e->trk_amp;
  const int settled = e->have_sample && e->t_last - e->t_start >= c->tracking_time_s;
  r.oscillation_valid = settled && f > 0.0;
  r.amplitude_accel_mps2 = e->have_sample ? (r.oscillation_valid ? amp : amplitude(e)) : 0.0;
  r.frequency_hz = r.oscillation_valid ? f : 0.0;
  r.period_spread = r.oscillation_valid ? spread : 1.0;
  const double w = 2.0 * HM_PI * r.frequency_hz;
  r.amplitude_displacement_m = r.oscillation_valid ? r.amplitude_accel_mps2 / (w * w) : 0.0;
  double judged_m = r.amplitude_displacement_m; /* what (c) judges: the sensor's own, or the wheelsets' by the map */
  r.wheelset_displacement_m = 0.0;
  if (e->disp_map) {
    const double s = r.oscillation_valid && r.speed_valid ? e->disp_map(e->disp_ctx, r.frequency_hz, r.speed_kmh) : 0.0;
    r.wheelset_displacement_m = s > 0.0 && isfinite(s) ? r.amplitude_accel_mps2 * s : 0.0;
    judged_m = r.wheelset_displacement_m;
  }
  hm_criteria_state k;
  hm_criteria_read(e->criteria, &k);
  r.rms_mps2 = k.rms_mps2;
  r.rms_window_complete = k.rms_window_complete;
  r.rms_exceeded = k.rms_exceeded;
  r.consecutive_peaks = k.consecutive_peaks;
  r.peaks_exceeded = k.peaks_exceeded;
  r.displacement_exceeded = c->displacement_limit_m > 0.0 && r.oscillation_valid && r.period_spread <= 0.2 &&
                            judged_m >= c->displacement_limit_m;
  *out = r;
}
