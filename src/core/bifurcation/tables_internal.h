/* Private: the boundary table's data, shared by its computation and lookup (tables.c) and its text format
 * (tables_io.c). */
#ifndef HUNTING_MONITOR_TABLES_INTERNAL_H
#define HUNTING_MONITOR_TABLES_INTERNAL_H

#include "hunting_monitor/tables.h"

typedef struct {
  double v_kmh, amp_m;
  int stable;
} tpoint;

typedef struct {
  double conicity, hopf_kmh, l1, lowest_kmh;
  size_t n;
  tpoint *pts;
} tcurve;

struct hm_table_s {
  double kx_mn_m, ky_mn_m, speed_min_kmh, speed_max_kmh, amp_max_m;
  double err_hopf_kmh, err_lowest_kmh, err_amp_m;
  double err_step;   /* the conicity step over which those errors were measured (the original uniform grid's) */
  double rtol;       /* the shooting tolerance its families were computed with */
  size_t n;
  tcurve *curves;
};

/* A table of n empty curves (NULL when out of memory). */
hm_table hm_table_alloc(size_t n);

#endif
