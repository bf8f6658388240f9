/* hunting tables | table-lookup: build, write and query the monitor's boundary tables (tables.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "cli.h"
#include "hunting_monitor/tables.h"
#include "hunting_monitor/threads.h"

const cli_option tables_opts[] = {
    {"out", "FILE", "write the table there (required)"},
    {"conicity-min", "L", "smallest lambda(0) (default 0.05)"},
    {"conicity-max", "L", "largest lambda(0) (default 0.40)"},
    {"n", "COUNT", "number of conicities (default 15)"},
    {"v-min", "KM/H", "lowest speed followed (default 150)"},
    {"v-max", "KM/H", "highest speed of interest (default 700)"},
    {"amp-max", "M", "largest cycle amplitude followed (default 0.016 m)"},
    {"threads", "N", "threads computing the families (default 0: one per processor)"},
    CLI_VEHICLE_OPTIONS,
    {NULL, NULL, NULL}};

int cmd_tables(const cli_args *a) {
  static cli_model cm; /* a bogie's or car's */
  hm_vehicle veh;
  hm_model_kind kind;
  hm_table_spec spec;
  hm_table_spec_default(&spec);
  double n_d = (double)spec.n_conicity, threads_d = 0.0;
  const char *path = cli_value(a, "out");
  if (cli_model_kind(a, &kind) ||
      (kind == HM_MODEL_WHEELSET ? cli_vehicle(a, &veh, NULL) : cli_vehicle_model(a, kind, &cm)) ||
      cli_number(a, "conicity-min", &spec.conicity_min) ||
      cli_number(a, "conicity-max", &spec.conicity_max) || cli_number(a, "n", &n_d) ||
      cli_number(a, "v-min", &spec.speed_min_kmh) || cli_number(a, "v-max", &spec.speed_max_kmh) ||
      cli_number(a, "amp-max", &spec.amp_max_m) || cli_number(a, "threads", &threads_d))
    return 1;
  if (!(threads_d >= 0 && threads_d <= 64) || threads_d != (double)(unsigned)threads_d) {
    fprintf(stderr, "hunting tables: --threads must be an integer in 0..64\n");
    return 1;
  }
  if (!path) {
    fprintf(stderr, "hunting tables: --out FILE is required\n");
    return 1;
  }
  if (!(n_d >= 2 && n_d <= 1000) || n_d != (double)(size_t)n_d) {
    fprintf(stderr, "hunting tables: --n must be an integer in 2..1000\n");
    return 1;
  }
  spec.n_conicity = (size_t)n_d;
  struct timespec t0, t1;
  timespec_get(&t0, TIME_UTC);
  hm_table t = NULL;
  hm_threads threads = {(unsigned)threads_d};
  hm_status st = kind == HM_MODEL_WHEELSET
                     ? hm_table_build_parallel(&veh, &spec, hm_threads_parallel_for, &threads, &t)
                     : hm_table_build_model(kind, &cm.params, &spec, hm_threads_parallel_for, &threads, &t);
  if (st == HM_EINVAL) {
    fprintf(stderr, "hunting tables: need 0 < --conicity-min < --conicity-max, 0 < --v-min < --v-max <= %g, "
                    "0.001 < --amp-max <= 0.1\n", HM_TABLE_MAX_SPEED_KMH);
    return 1;
  }
  if (st != HM_OK) return cli_fail_status("boundary table", st);
  timespec_get(&t1, TIME_UTC);
  size_t need = 0;
  hm_table_format(t, NULL, 0, &need);
  char *buf = malloc(need);
  FILE *f = buf ? fopen(path, "w") : NULL;
  int rc = 0;
  if (!buf || !f || hm_table_format(t, buf, need, &need) != HM_OK || fputs(buf, f) == EOF) {
    perror(path);
    rc = 1;
  }
  if (f && fclose(f) != 0) rc = 1;
  if (rc == 0) {
    hm_table_lookup_result r;
    hm_table_lookup(t, 0.5 * (spec.conicity_min + spec.conicity_max), spec.speed_min_kmh, &r);
    json_writer w;
    jw_init(&w, stdout);
    jw_object(&w, NULL);
    jw_string(&w, "table", path);
    jw_int(&w, "conicities", (long)spec.n_conicity);
    jw_int(&w, "bytes", (long)(need - 1));
    jw_number(&w, "build_s", (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec));
    jw_number(&w, "error_speed_kmh", r.error_speed_kmh);
    jw_number(&w, "error_amp_m", r.error_amp_m);
    jw_end_object(&w);
    jw_finish(&w);
  }
  free(buf);
  hm_table_destroy(t);
  return rc;
}

const cli_option table_lookup_opts[] = {
    {"table", "FILE", "boundary table written by 'hunting tables' (required)"},
    {"conicity", "L", "equivalent conicity lambda(0) (required)"},
    {"v", "KM/H", "running speed (required)"},
    {"widen", NULL, "outside the table's conicities: the cautious reading (tables.h), not an error"},
    {"help", NULL, "show this help"},
    {NULL, NULL, NULL}};

int cmd_table_lookup(const cli_args *a) {
  const char *path = cli_value(a, "table");
  double conicity = NAN, v_kmh;
  if (!path || !cli_has(a, "conicity")) {
    fprintf(stderr, "hunting table-lookup: --table FILE and --conicity L are required\n");
    return 1;
  }
  if (cli_number(a, "conicity", &conicity) || cli_speed_option(a, &v_kmh)) return 1;
  hm_table t = NULL;
  char err[256] = "";
  hm_status st = hm_table_load_file(path, &t, err, sizeof err);
  if (st != HM_OK) {
    fprintf(stderr, "hunting: %s: %s\n", path, err[0] ? err : hm_status_str(st));
    return 1;
  }
  /* outside the table a lookup would clamp (the end conicity's boundaries, issue #27): refused, or with --widen the
   * cautious reading */
  hm_table_lookup_result r;
  double c_min = 0.0, c_max = 0.0;
  hm_table_size(t, &c_min, &c_max);
  const int outside = conicity < c_min || conicity > c_max, widen = cli_has(a, "widen");
  st = widen ? hm_table_lookup_widened(t, conicity, v_kmh, &r) : hm_table_lookup(t, conicity, v_kmh, &r);
  hm_table_destroy(t);
  if (st == HM_EDOMAIN && widen && isfinite(conicity)) {
    fprintf(stderr, "hunting table-lookup: conicity %g: the table's extrapolation (%g..%g) has no Hopf speed there\n",
            conicity, c_min, c_max);
    return 1;
  }
  if (st != HM_OK) return cli_fail_status("lookup", st);
  if (outside && !widen) {
    fprintf(stderr, "hunting table-lookup: conicity %g is outside the table's %g..%g (the lookup would give the end "
                    "conicity's boundaries): refused; --widen gives the cautious reading\n", conicity, c_min, c_max);
    return 1;
  }
  if (r.clamped && !outside) {
    fprintf(stderr, "hunting table-lookup: --v %g km/h is outside the table's speeds (the lookup would clamp it): "
                    "refused\n", v_kmh);
    return 1;
  }
  json_writer w;
  jw_init(&w, stdout);
  jw_object(&w, NULL);
  jw_number(&w, "conicity", conicity);
  jw_number(&w, "table_conicity", r.conicity); /* the query's, or with --widen outside the table its end's */
  jw_number(&w, "v_kmh", v_kmh);
  jw_number(&w, "hopf_kmh", r.hopf_speed_kmh);
  jw_number(&w, "l1", r.l1);
  jw_number(&w, "lowest_cycle_kmh", r.lowest_cycle_speed_kmh);
  jw_bool(&w, "origin_stable", r.origin_stable);
  if (r.has_edge)
    jw_number(&w, "unstable_cycle_amplitude_m", r.edge_amp_m);
  else
    jw_number(&w, "unstable_cycle_amplitude_m", NAN);
  if (r.has_stable_outer)
    jw_number(&w, "stable_cycle_amplitude_m", r.stable_outer_amp_m);
  else
    jw_number(&w, "stable_cycle_amplitude_m", NAN);
  jw_bool(&w, "clamped", r.clamped);
  jw_bool(&w, "widened", r.widened);
  jw_bool(&w, "consistent", r.consistent);
  jw_number(&w, "neighbour_spread_m", r.neighbour_spread_m);
  jw_number(&w, "error_speed_kmh", r.error_speed_kmh);
  jw_number(&w, "error_amp_m", r.error_amp_m);
  jw_end_object(&w);
  jw_finish(&w);
  return 0;
}
