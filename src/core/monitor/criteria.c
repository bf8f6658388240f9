/* The standard instability criteria (see criteria.h). */
#include "hunting_monitor/criteria.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "biquad.h"

enum { PEAK_SECTIONS = 3 };

struct hm_criteria_s {
  hm_criteria_config cfg;
  hm_biquad peak[PEAK_SECTIONS]; /* HP2 + LP4 */
  /* sliding r.m.s. over distance: ring of (x^2, metres) */
  double *sq, *dist;
  size_t cap, head, n, since_resum;
  double sum, metres;
  /* peaks */
  double p_prev, half_peak;
  unsigned consecutive;
};

hm_status hm_criteria_create(const hm_criteria_config *cfg, hm_criteria *out) {
  if (!cfg || !out || !(cfg->rms_window_m > 0.0 && cfg->rms_window_m <= 1000.0)) return HM_EINVAL;
  hm_criteria c = calloc(1, sizeof *c);
  if (!c) return HM_ENOMEM;
  c->cfg = *cfg;
  /* the window holds rms_window_m down to 30 km/h (and at least one second) at the highest supported rate */
  c->cap = (size_t)ceil(5000.0 * fmax(cfg->rms_window_m / (30.0 / 3.6), 1.0)) + 1;
  c->sq = malloc(c->cap * sizeof(double));
  c->dist = malloc(c->cap * sizeof(double));
  if (!c->sq || !c->dist) {
    hm_criteria_destroy(c);
    return HM_ENOMEM;
  }
  hm_criteria_restart(c, 2000.0);
  *out = c;
  return HM_OK;
}

void hm_criteria_destroy(hm_criteria c) {
  if (!c) return;
  free(c->sq);
  free(c->dist);
  free(c);
}

void hm_criteria_restart(hm_criteria c, double fs) {
  c->peak[0] = hm_biquad_design(1, c->cfg.peaks_band_low_hz, HM_BUTTERWORTH_Q2, fs);
  c->peak[1] = hm_biquad_design(0, c->cfg.peaks_band_high_hz, HM_BUTTERWORTH_Q4[0], fs);
  c->peak[2] = hm_biquad_design(0, c->cfg.peaks_band_high_hz, HM_BUTTERWORTH_Q4[1], fs);
  c->head = c->n = c->since_resum = 0;
  c->sum = c->metres = 0.0;
  c->p_prev = c->half_peak = 0.0;
  c->consecutive = 0;
}

/* the sliding sum over the last rms_window_m of track */
static void rms_push(hm_criteria c, double x2, double metres) {
  if (c->n == c->cap) { /* full: drop the oldest */
    const size_t old = (c->head + c->cap - c->n) % c->cap;
    c->sum -= c->sq[old];
    c->metres -= c->dist[old];
    --c->n;
  }
  c->sq[c->head] = x2;
  c->dist[c->head] = metres;
  c->head = (c->head + 1) % c->cap;
  ++c->n;
  c->sum += x2;
  c->metres += metres;
  while (c->n > 1) { /* keep just enough samples to cover the window */
    const size_t old = (c->head + c->cap - c->n) % c->cap;
    if (c->metres - c->dist[old] < c->cfg.rms_window_m) break;
    c->sum -= c->sq[old];
    c->metres -= c->dist[old];
    --c->n;
  }
  if (++c->since_resum >= c->cap) { /* bound the rounding drift of the running sums */
    c->sum = c->metres = 0.0;
    for (size_t k = 0; k < c->n; ++k) {
      const size_t i = (c->head + c->cap - c->n + k) % c->cap;
      c->sum += c->sq[i];
      c->metres += c->dist[i];
    }
    c->since_resum = 0;
  }
}

static void peaks_push(hm_criteria c, double p) {
  if ((p >= 0.0) != (c->p_prev >= 0.0)) { /* a half cycle ended */
    if (c->half_peak >= c->cfg.peaks_limit_mps2)
      ++c->consecutive;
    else
      c->consecutive = 0;
    c->half_peak = 0.0;
  }
  c->half_peak = fmax(c->half_peak, fabs(p));
  c->p_prev = p;
}

void hm_criteria_push(hm_criteria c, double band_x, double raw_a, double metres) {
  double p = raw_a;
  for (int k = 0; k < PEAK_SECTIONS; ++k) p = hm_biquad_step(&c->peak[k], p);
  rms_push(c, band_x * band_x, metres);
  peaks_push(c, p);
}

void hm_criteria_read(const hm_criteria c, hm_criteria_state *out) {
  hm_criteria_state r;
  r.rms_mps2 = c->n ? sqrt(fmax(c->sum, 0.0) / (double)c->n) : 0.0;
  r.rms_window_complete = c->metres >= c->cfg.rms_window_m * (1.0 - 1e-9); /* rounding of the running sum */
  r.rms_exceeded = r.rms_window_complete && r.rms_mps2 >= c->cfg.rms_limit_mps2;
  r.consecutive_peaks = c->consecutive;
  r.peaks_exceeded = c->consecutive >= c->cfg.peaks_count;
  *out = r;
}

void hm_criteria_set_limits(hm_criteria c, double rms_limit_mps2, double peaks_limit_mps2, unsigned peaks_count) {
  if (!c) return;
  c->cfg.rms_limit_mps2 = rms_limit_mps2;
  c->cfg.peaks_limit_mps2 = peaks_limit_mps2;
  c->cfg.peaks_count = peaks_count;
}
