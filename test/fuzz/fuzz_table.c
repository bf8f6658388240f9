/* libFuzzer harness: the boundary-table parser, lookups on what it accepts, the vehicle check, and the format ->
 * parse round trip. A lookup on an accepted table must give finite boundaries. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "hunting_monitor/tables.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  hm_table t = NULL;
  char err[256];
  if (hm_table_parse((const char *)data, size, &t, err, sizeof err) != HM_OK) return 0;
  double lo, hi;
  hm_table_size(t, &lo, &hi);
  const double conicities[] = {lo - 0.01, lo, 0.5 * (lo + hi), hi, hi + 1.0, 1e-300};
  const double speeds[] = {0.0, 1.0, 239.5, 517.6, 2999.0, 1e300};
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) {
      hm_table_lookup_result r;
      if (hm_table_lookup(t, conicities[i], speeds[j], &r) != HM_OK) continue;
      if (!isfinite(r.hopf_speed_kmh) || !(r.hopf_speed_kmh > 0.0) || !isfinite(r.lowest_cycle_speed_kmh) ||
          !(r.lowest_cycle_speed_kmh > 0.0) || !isfinite(r.edge_amp_m) || !isfinite(r.stable_outer_amp_m))
        __builtin_trap();
    }
  hm_vehicle v;
  hm_vehicle_default(&v);
  hm_table_check_vehicle(t, &v, 0.01, err, sizeof err);
  size_t need = 0;
  hm_table_format(t, NULL, 0, &need);
  char *text = malloc(need);
  if (text && hm_table_format(t, text, need, &need) == HM_OK) {
    hm_table back = NULL;
    if (hm_table_parse(text, need - 1, &back, err, sizeof err) != HM_OK) __builtin_trap(); /* its own output */
    hm_table_destroy(back);
  }
  free(text);
  hm_table_destroy(t);
  return 0;
}
