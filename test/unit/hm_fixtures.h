/* Shared fixtures of the unit tests. */
#ifndef HM_FIXTURES_H
#define HM_FIXTURES_H

#include <stdlib.h>

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

/* That table as text (malloc'd into *text, *len bytes with the NUL), so that each monitor of a test can take over a
 * parsed copy; HM_ENOMEM or the build's status on failure. */
static inline hm_status hm_test_small_table_text(char **text, size_t *len) {
  hm_table table = NULL;
  hm_status st = hm_test_small_table(&table);
  *text = NULL;
  if (st == HM_OK) {
    hm_table_format(table, NULL, 0, len); /* the size, with the NUL */
    st = (*text = malloc(*len)) != NULL ? hm_table_format(table, *text, *len, len) : HM_ENOMEM;
  }
  hm_table_destroy(table);
  return st;
}

#endif
