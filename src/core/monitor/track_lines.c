/* Track lines by their wavelength across speeds (track_lines.h). */
#include "hunting_monitor/track_lines.h"

#include "hunting_monitor/linear.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "validate.h"

void hm_track_lines_config_default(hm_track_lines_config *cfg) {
  if (!cfg) return;
  cfg->wavelength_tol_rel = 0.01;
  cfg->min_speed_change_rel = 0.05;
  cfg->memory_s = 900.0;
}

hm_status hm_track_lines_config_validate(const hm_track_lines_config *cfg, char *why, size_t why_len) {
  if (!cfg) return HM_EINVAL;
  const double tol = cfg->wavelength_tol_rel;
  const hm_field_check f[] = {
      {"track_lines.wavelength_tol_rel", tol, HM_RULE_RANGE_OPEN, 0.0, 0.05},
      {"track_lines.min_speed_change_rel", cfg->min_speed_change_rel, HM_RULE_RANGE, 2.0 * (isfinite(tol) ? tol : 0.0),
       0.5},
      {"track_lines.memory_s", cfg->memory_s, HM_RULE_RANGE, 1.0, 1e6}};
  return hm_check_fields(f, HM_COUNT_OF(f), why, why_len);
}

hm_status hm_track_lines_init(hm_track_lines *t, const hm_track_lines_config *cfg, char *why, size_t why_len) {
  if (!t || !cfg) return HM_EINVAL;
  const hm_status st = hm_track_lines_config_validate(cfg, why, why_len);
  if (st != HM_OK) return st;
  memset(t, 0, sizeof *t);
  t->cfg = *cfg;
  return HM_OK;
}

void hm_track_lines_clear(hm_track_lines *t) {
  if (t) t->n = 0;
}

void hm_track_lines_shift_time(hm_track_lines *t, double delta_s) {
  if (!t || !isfinite(delta_s)) return;
  for (size_t k = 0; k < t->n; ++k) t->obs[k].seen_s += delta_s;
}

static int positive(double x) { return isfinite(x) && x > 0.0; }

/* |a - b| within tol of a (relative) */
static int agree(double a, double b, double tol) { return fabs(a - b) <= tol * a; }

/* The wavelength of the peak against an observation's: its own, or a whole fraction of a comb's fundamental. */
static int same_wavelength(const hm_track_line *o, double wavelength_m, double tol) {
  if (!o->comb) return agree(wavelength_m, o->wavelength_m, tol);
  const double m = round(o->wavelength_m / wavelength_m);
  return m >= 1.0 && m <= 64.0 && agree(wavelength_m, o->wavelength_m / m, tol);
}

hm_status hm_track_lines_observe(hm_track_lines *t, double now_s, double speed_kmh, double frequency_hz,
                                 double level_mps2, int comb) {
  if (!t || !isfinite(now_s) || !positive(speed_kmh) || !positive(frequency_hz) || !isfinite(level_mps2) ||
      level_mps2 < 0.0)
    return HM_EINVAL;
  const hm_track_line o = {hm_mps_from_kmh(speed_kmh) / frequency_hz, speed_kmh, frequency_hz, level_mps2, now_s,
                           comb != 0};
  const double same_speed = 0.1 * t->cfg.min_speed_change_rel;
  size_t slot = t->n, oldest = 0;
  for (size_t k = 0; k < t->n; ++k) {
    const hm_track_line *p = &t->obs[k];
    if (p->comb == o.comb && agree(speed_kmh, p->speed_kmh, same_speed) &&
        agree(o.wavelength_m, p->wavelength_m, t->cfg.wavelength_tol_rel)) {
      slot = k; /* the same line at the same speed: the latest sight of it */
      break;
    }
    if (p->seen_s < t->obs[oldest].seen_s) oldest = k;
  }
  if (slot == t->n && t->n == HM_TRACK_LINES_MAX) slot = oldest; /* full: the oldest goes */
  else if (slot == t->n) ++t->n;
  t->obs[slot] = o;
  return HM_OK;
}

int hm_track_lines_match(const hm_track_lines *t, double now_s, double speed_kmh, double frequency_hz,
                         hm_track_line *out) {
  if (!t || !isfinite(now_s) || !positive(speed_kmh) || !positive(frequency_hz)) return 0;
  const double wavelength = hm_mps_from_kmh(speed_kmh) / frequency_hz;
  const hm_track_line *best = NULL;
  for (size_t k = 0; k < t->n; ++k) {
    const hm_track_line *o = &t->obs[k];
    if (now_s - o->seen_s > t->cfg.memory_s) continue;
    const double change = fabs(o->speed_kmh - speed_kmh);
    if (change < t->cfg.min_speed_change_rel * speed_kmh) continue;
    if (!same_wavelength(o, wavelength, t->cfg.wavelength_tol_rel)) continue;
    if (!best || change > fabs(best->speed_kmh - speed_kmh)) best = o;
  }
  if (best && out) *out = *best;
  return best != NULL;
}
