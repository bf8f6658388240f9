/* Private to the core: the one way a setting is checked against its domain. A table of fields (the config's name,
 * the value, the rule and, for a range, its ends) is checked in order; the first failure writes
 * "field: reason (got value)" into why and gives HM_EDOMAIN. A rule between fields (a band's upper end above its
 * lower, a limit above another) is written with hm_reject, in the same form. Every config validator of the core
 * uses these two. */
#ifndef HM_CORE_VALIDATE_H
#define HM_CORE_VALIDATE_H

#include <math.h>
#include <stddef.h>
#include <stdio.h>

#include "hunting_monitor/status.h"

typedef enum {
  HM_RULE_FINITE = 0,     /* any finite number */
  HM_RULE_POSITIVE = 1,   /* finite and > 0 */
  HM_RULE_NONNEG = 2,     /* finite and >= 0 */
  HM_RULE_RANGE = 3,      /* lo <= v <= hi */
  HM_RULE_RANGE_OPEN = 4, /* lo < v <= hi */
  HM_RULE_FLAG = 5,       /* 0 or 1 */
  HM_RULE_OPEN = 6,       /* lo < v < hi */
  HM_RULE_OFF_OR_RANGE = 7 /* 0 (off), or lo <= v <= hi */
} hm_rule;

typedef struct {
  const char *field; /* the name the user wrote it under, e.g. "bogie.frame_mass_kg" */
  double value;      /* in the unit of that name (MN/m for kx_mn_m) */
  hm_rule rule;
  double lo, hi; /* a range's ends (HM_RULE_RANGE, HM_RULE_RANGE_OPEN, HM_RULE_OPEN, HM_RULE_OFF_OR_RANGE) */
} hm_field_check;

static inline hm_status hm_reject(char *why, size_t why_len, const char *field, const char *reason, double got) {
  if (why && why_len > 0) snprintf(why, why_len, "%s: %s (got %g)", field, reason, got);
  return HM_EDOMAIN;
}

static inline int hm_field_ok(const hm_field_check *f) {
  const double v = f->value;
  switch (f->rule) {
    case HM_RULE_FINITE: return isfinite(v);
    case HM_RULE_POSITIVE: return isfinite(v) && v > 0.0;
    case HM_RULE_NONNEG: return isfinite(v) && v >= 0.0;
    case HM_RULE_RANGE: return v >= f->lo && v <= f->hi;
    case HM_RULE_RANGE_OPEN: return v > f->lo && v <= f->hi;
    case HM_RULE_FLAG: return v == 0.0 || v == 1.0;
    case HM_RULE_OPEN: return v > f->lo && v < f->hi;
    case HM_RULE_OFF_OR_RANGE: return v == 0.0 || (v >= f->lo && v <= f->hi);
  }
  return 0;
}

static inline hm_status hm_check_fields(const hm_field_check *f, size_t n, char *why, size_t why_len) {
  for (size_t i = 0; i < n; ++i) {
    if (hm_field_ok(&f[i])) continue;
    /* a range states its ends whatever the value; any other rule, a value that is not finite, says so */
    const int range = f[i].rule == HM_RULE_RANGE || f[i].rule == HM_RULE_RANGE_OPEN || f[i].rule == HM_RULE_OPEN ||
                      f[i].rule == HM_RULE_OFF_OR_RANGE;
    char reason[80] = "must be a finite number";
    if (range || isfinite(f[i].value)) switch (f[i].rule) {
        case HM_RULE_POSITIVE: snprintf(reason, sizeof reason, "must be > 0"); break;
        case HM_RULE_NONNEG: snprintf(reason, sizeof reason, "must be >= 0"); break;
        case HM_RULE_RANGE: snprintf(reason, sizeof reason, "must be in [%g, %g]", f[i].lo, f[i].hi); break;
        case HM_RULE_RANGE_OPEN: snprintf(reason, sizeof reason, "must be in (%g, %g]", f[i].lo, f[i].hi); break;
        case HM_RULE_OPEN: snprintf(reason, sizeof reason, "must be in (%g, %g)", f[i].lo, f[i].hi); break;
        case HM_RULE_OFF_OR_RANGE:
          snprintf(reason, sizeof reason, "must be 0 (off) or in [%g, %g]", f[i].lo, f[i].hi);
          break;
        case HM_RULE_FLAG: snprintf(reason, sizeof reason, "must be 0 or 1"); break;
        case HM_RULE_FINITE: break;
      }
    return hm_reject(why, why_len, f[i].field, reason, f[i].value);
  }
  return HM_OK;
}

/* A wheel's rolling radius [m], wherever one is configured (the vehicle, the contact geometry, delta-r). */
#define HM_R0_MIN_M 0.1
#define HM_R0_MAX_M 1.0

#define HM_COUNT_OF(a) (sizeof(a) / sizeof((a)[0]))

#endif
