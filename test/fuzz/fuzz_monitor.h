/* The harnesses' monitor: the default vehicle with the shipped table (config/crh380_default.tbl) and cfg; a trap if it
 * cannot be made (the harness would test nothing). */
#ifndef HM_FUZZ_MONITOR_H
#define HM_FUZZ_MONITOR_H

#include "hunting_monitor/monitor.h"

static hm_monitor fuzz_monitor_create(const hm_monitor_config *cfg) {
  hm_vehicle v;
  hm_vehicle_default(&v);
  hm_table t = NULL;
  hm_monitor m = NULL;
  if (hm_table_load_file(HM_SOURCE_DIR "/config/crh380_default.tbl", &t, NULL, 0) != HM_OK ||
      hm_monitor_create(cfg, &v, t, &m, NULL, 0) != HM_OK)
    __builtin_trap();
  return m;
}

#endif
