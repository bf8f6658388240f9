/* Shared fixtures of the unit tests. */
#ifndef HM_FIXTURES_H
#define HM_FIXTURES_H

#include "hunting_monitor/tables.h"

/* The boundary table of the default vehicle over lambda(0) 0.12..0.16 (3 conicities; about 0.1 s). */
static inline hm_status hm_test_small_table(hm_table *table) {
  hm_vehicle v;
  hm_vehicle_default(&v);
  hm_table_spec spec;
  hm_table_spec_default(&spec);
  spec.conicity_min = 0.12;
  spec.conicity_max = 0.16;
  spec.n_conicity = 3;
  return hm_table_build(&v, &spec, table);
}

#endif
