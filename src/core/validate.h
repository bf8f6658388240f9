/* Private to the core: the one way a setting is checked against its domain. A table of fields (the config's name,
 * the value, the rule) is checked in order; the first failure writes "field: reason (got value)" into why and gives
 * HM_EDOMAIN. model.c's wheelset and bogie.c's frame use it; the other validators are to follow (issue #28). */
#ifndef HM_CORE_VALIDATE_H
#define HM_CORE_VALIDATE_H

#include <math.h>
#include <stddef.h>
#include <stdio.h>

#include "hunting_monitor/status.h"

typedef enum {
  HM_RULE_FINITE = 0,   /* any finite number */
  HM_RULE_POSITIVE = 1, /* finite and > 0 */
  HM_RULE_NONNEG = 2    /* finite and >= 0 */
} hm_rule;

typedef struct {
  const char *field; /* the name the user wrote it under, e.g. "bogie.frame_mass_kg" */
  double value;      /* in the unit of that name (MN/m for kx_mn_m) */
  hm_rule rule;
} hm_field_check;

static inline hm_status hm_reject(char *why, size_t why_len, const char *field, const char *reason, double got) {
  if (why && why_len > 0) snprintf(why, why_len, "%s: %s (got %g)", field, reason, got);
  return HM_EDOMAIN;
}

static inline hm_status hm_check_fields(const hm_field_check *f, size_t n, char *why, size_t why_len) {
  static const char *const reason[] = {"must be a finite number", "must be > 0", "must be >= 0"};
  for (size_t i = 0; i < n; ++i) {
    const double v = f[i].value;
    const int ok = isfinite(v) && (f[i].rule == HM_RULE_FINITE || (f[i].rule == HM_RULE_POSITIVE ? v > 0.0 : v >= 0.0));
    if (!ok) return hm_reject(why, why_len, f[i].field, isfinite(v) ? reason[f[i].rule] : reason[0], v);
  }
  return HM_OK;
}

#endif
