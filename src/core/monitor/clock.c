/* One time line for a stamped sensor and its receiver (clock.h). */
#include "hunting_monitor/clock.h"

#include <math.h>
#include <stdio.h>

#include "validate.h"

void hm_clock_config_default(hm_clock_config *cfg) {
  if (!cfg) return;
  cfg->window_s = 10.0;
  cfg->max_step_s = 1.0;
  cfg->confirm_s = 1.0;
}

hm_status hm_clock_config_validate(const hm_clock_config *cfg, char *why, size_t why_len) {
  if (!cfg) return HM_EINVAL;
  const hm_field_check f[] = {{"clock.window_s", cfg->window_s, HM_RULE_RANGE_OPEN, 0.0, 3600.0},
                              {"clock.max_step_s", cfg->max_step_s, HM_RULE_RANGE_OPEN, 0.0, 3600.0},
                              {"clock.confirm_s", cfg->confirm_s, HM_RULE_RANGE_OPEN, 0.0, 60.0}};
  return hm_check_fields(f, HM_COUNT_OF(f), why, why_len);
}

/* The offset and the window start again from one sample's receipt - stamp. */
static void anchor(hm_clock *c, double d, double receipt_s) {
  c->have_offset = 1;
  c->offset_s = d;
  c->latency_s = 0.0;
  c->block_min_s[0] = d;
  c->block_start_s = receipt_s;
  c->n_blocks = 1;
  c->newest = 0;
  c->away_since_s = NAN;
  c->last_mapped_s = -INFINITY;
}

/* Nothing was received for longer than the window (window_s and a block of receipt time): the window has nothing left
 * to judge a sample against. */
static int silent(const hm_clock *c, double receipt_s) {
  return receipt_s - c->block_start_s >= c->cfg.window_s + c->cfg.window_s / HM_CLOCK_BLOCKS;
}

/* A stamp that continues the stamps used (not earlier than the last, at most max_step_s after it): a backlog's. */
static int continues(const hm_clock *c, double stamp_s) {
  return isfinite(c->last_stamp_s) && stamp_s >= c->last_stamp_s && stamp_s - c->last_stamp_s <= c->cfg.max_step_s;
}

hm_status hm_clock_init(hm_clock *c, const hm_clock_config *cfg) {
  if (!c || !cfg) return HM_EINVAL;
  if (hm_clock_config_validate(cfg, NULL, 0) != HM_OK) return HM_EDOMAIN;
  c->cfg = *cfg;
  c->n_steps = c->n_dropped = c->n_late = 0;
  hm_clock_reset(c);
  return HM_OK;
}

void hm_clock_reset(hm_clock *c) {
  if (!c) return;
  c->have_offset = 0;
  c->offset_s = c->latency_s = 0.0;
  for (unsigned i = 0; i < HM_CLOCK_BLOCKS; ++i) c->block_min_s[i] = INFINITY;
  c->block_start_s = 0.0;
  c->n_blocks = 0;
  c->newest = 0;
  c->away_since_s = NAN;
  c->last_mapped_s = -INFINITY;
  c->last_stamp_s = NAN;
}

void hm_clock_shift(hm_clock *c, double delta_s) {
  if (!c || !isfinite(delta_s) || !c->have_offset) return;
  c->offset_s += delta_s;
  for (unsigned i = 0; i < HM_CLOCK_BLOCKS; ++i) c->block_min_s[i] += delta_s;
  c->block_start_s += delta_s;
  if (!isnan(c->away_since_s)) c->away_since_s += delta_s;
}

/* d enters the window: blocks of window_s / HM_CLOCK_BLOCKS of receipt time; the offset is their least value. After a
 * silence longer than the window the window starts again, from the offset it had where d is a stall's backlog (late,
 * its stamps continuous: backlog), and the receiver's times taken onto the sensor's line stay monotonic (a stall of
 * 20 s had anchored the offset on the backlog's first sample, 20 s late, and moved that line back by 20 s). */
static void enter(hm_clock *c, double d, double receipt_s, int backlog) {
  const double block_s = c->cfg.window_s / HM_CLOCK_BLOCKS;
  if (silent(c, receipt_s)) {
    const double offset = c->offset_s, mapped = c->last_mapped_s;
    anchor(c, backlog ? fmin(d, offset) : d, receipt_s);
    c->last_mapped_s = mapped;
    return;
  }
  while (receipt_s - c->block_start_s >= block_s) {
    c->newest = (c->newest + 1) % HM_CLOCK_BLOCKS;
    c->block_min_s[c->newest] = INFINITY;
    c->block_start_s += block_s;
    if (c->n_blocks < HM_CLOCK_BLOCKS) c->n_blocks++;
  }
  if (d < c->block_min_s[c->newest]) c->block_min_s[c->newest] = d;
  double least = INFINITY;
  for (unsigned i = 0; i < c->n_blocks; ++i) {
    const double b = c->block_min_s[(c->newest + HM_CLOCK_BLOCKS - i) % HM_CLOCK_BLOCKS];
    if (b < least) least = b;
  }
  c->offset_s = least;
}

hm_status hm_clock_observe(hm_clock *c, double stamp_s, double receipt_s, hm_clock_verdict *verdict) {
  if (!c || !verdict || !isfinite(stamp_s) || !isfinite(receipt_s)) return HM_EINVAL;
  const double d = receipt_s - stamp_s;
  if (!isfinite(d)) return HM_EINVAL;
  if (!c->have_offset) {
    anchor(c, d, receipt_s);
    c->last_stamp_s = stamp_s;
    *verdict = HM_CLOCK_USE;
    return HM_OK;
  }
  const double dev = d - c->offset_s;
  int chained = 1; /* the stamp continues the stamps used (a late one that does not is used, not chained on) */
  const int backlog = dev > c->cfg.max_step_s && continues(c, stamp_s);
  if (!backlog && fabs(dev) > c->cfg.max_step_s && silent(c, receipt_s)) {
    /* off the line after a silence longer than the window: a new line at once (a sensor rebooted while silent; the
     * window would have taken it in as the offset, the stamps gone back unseen: issue #27's review) */
    anchor(c, d, receipt_s);
    c->last_stamp_s = stamp_s;
    c->n_steps++;
    *verdict = HM_CLOCK_STEPPED;
    return HM_OK;
  }
  if (backlog) { /* a stall's backlog: late, its stamps continuous */
    c->n_late++;
    c->away_since_s = NAN;
  } else if (fabs(dev) > c->cfg.max_step_s) {
    if (isnan(c->away_since_s)) c->away_since_s = receipt_s;
    if (receipt_s - c->away_since_s >= c->cfg.confirm_s) {
      anchor(c, d, receipt_s);
      c->last_stamp_s = stamp_s;
      c->n_steps++;
      *verdict = HM_CLOCK_STEPPED;
      return HM_OK;
    }
    if (dev < 0.0) {  /* stamped later than the receiver's now on the sensor's line allows */
      c->n_dropped++;
      *verdict = HM_CLOCK_DROP;
      return HM_OK;
    }
    c->n_late++;  /* late: plausible, used; it cannot lower the least value */
    chained = 0;
  } else {
    c->away_since_s = NAN;
  }
  enter(c, d, receipt_s, backlog);
  c->latency_s = d - c->offset_s;
  if (chained) c->last_stamp_s = stamp_s;
  *verdict = HM_CLOCK_USE;
  return HM_OK;
}

double hm_clock_offset_s(const hm_clock *c) { return c && c->have_offset ? c->offset_s : 0.0; }

double hm_clock_to_sensor(hm_clock *c, double receiver_s) {
  if (!c) return receiver_s;
  double t = c->have_offset ? receiver_s - c->offset_s : receiver_s;
  if (c->have_offset && t < c->last_mapped_s) t = c->last_mapped_s;
  if (c->have_offset) c->last_mapped_s = t;
  return t;
}
