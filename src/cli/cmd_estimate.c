/* hunting estimate: run the online estimator and alarm logic over recorded data, one JSON object per line. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cli.h"
#include "hunting_monitor/config.h"
#include "hunting_monitor/linear.h"
#include "hunting_monitor/monitor.h"
#include "hunting_monitor/report.h"
#include "hunting_monitor/state.h"
#include "hunting_monitor/tables.h"
#include "hunting_monitor/threads.h"

const cli_option estimate_opts[] = {
    {"accel", "FILE", "lateral acceleration CSV with header t_s,accel_mps2 (required)"},
    {"speed", "FILE", "speed CSV with header t_s,speed_kmh"},
    {"v", "KM/H", "constant speed instead of --speed"},
    {"monitor", "FILE", "estimator and alarm settings (default: built-in = config/monitor.yaml)"},
    {"table", "FILE", "boundary table from 'hunting tables' (default: computed at start, 36 conicities in about 0.6 s)"},
    {"every", "SECONDS", "output interval in data time (default 0.1)"},
    {"state-in", "FILE", "restore what a run learned from FILE (or FILE.prev) at the first sample (above)"},
    {"state-out", "FILE", "write what the run learned to FILE (atomically, keeping FILE.prev) every --state-every"},
    {"state-every", "SECONDS", "recording time between --state-out writes, and one at the end (default 2)"},
    {"state-clock", "CLOCK", "recording (default) or wall: the clock a --state-in file's age is read on (above)"},
    CLI_VEHICLE_OPTIONS,
    {NULL, NULL, NULL}};

/* Median sample interval of the acceleration data -> nominal rate (when no settings file gives one). */
static double inferred_rate(const double *d, size_t n) {
  enum { M = 2001 };
  double dt[M];
  size_t m = 0;
  for (size_t i = 1; i < n && m < M; ++i) {
    const double x = d[2 * i] - d[2 * (i - 1)];
    if (x > 0.0) dt[m++] = x;
  }
  if (m == 0) return 0.0;
  for (size_t i = 1; i < m; ++i) /* insertion sort is fine for 2000 values */
    for (size_t j = i; j > 0 && dt[j - 1] > dt[j]; --j) {
      const double t = dt[j];
      dt[j] = dt[j - 1];
      dt[j - 1] = t;
    }
  return 1.0 / dt[m / 2];
}

/* What the tool read, beside what the monitor counted (hm_estimate's counters). */
typedef struct {
  unsigned long accel_rows, speed_rows; /* data rows read from the files */
  unsigned long speed_rows_unused;      /* speed rows after the acceleration's last sample: not given to the monitor */
} read_counts;

/* One JSON line: the time, restored (the --state-in outcome) when not NULL, every field of the published status in
 * report.h's order and gating, and what the tool read. */
static void write_line(const hm_monitor_status *st, double t, const read_counts *rc, const char *restored) {
  hm_report r;
  hm_report_make(st, 0.0, &r);
  json_writer w;
  jw_init(&w, stdout);
  jw_object(&w, NULL);
  jw_number(&w, "t_s", t);
  if (restored) jw_string(&w, "restored", restored);
  size_t n = 0;
  const hm_report_field *f = hm_report_fields(&n);
  for (size_t i = 0; i < n; ++i) {
    const char *at = (const char *)&r + f[i].offset;
    /* what the tool read, beside what the monitor counted (as the lines have always had them) */
    if (strcmp(f[i].name, "accel_samples") == 0) jw_int(&w, "accel_rows", (long)rc->accel_rows);
    if (strcmp(f[i].name, "speed_updates") == 0) jw_int(&w, "speed_rows", (long)rc->speed_rows);
    switch (f[i].kind) {
      case HM_REPORT_NUMBER: jw_number(&w, f[i].name, *(const double *)(const void *)at); break;
      case HM_REPORT_INT: jw_int(&w, f[i].name, *(const long *)(const void *)at); break;
      case HM_REPORT_FLAG: jw_bool(&w, f[i].name, *(const int *)(const void *)at); break;
      case HM_REPORT_STATIC_TEXT: jw_string(&w, f[i].name, *(const char *const *)(const void *)at); break;
      case HM_REPORT_TEXT: jw_string(&w, f[i].name, at); break;
    }
  }
  jw_int(&w, "speed_rows_unused", (long)rc->speed_rows_unused);
  jw_end_object(&w);
  jw_finish(&w);
}

/* A table from --table, or NULL: the monitor then computes one for the vehicle. */
static int load_table(const cli_args *a, hm_table *t) {
  *t = NULL;
  const char *path = cli_value(a, "table");
  if (!path) {
    fprintf(stderr, "hunting estimate: no --table: computing boundary tables (conicity 0.05-0.40)...\n");
    return 0;
  }
  char err[256] = "";
  if (hm_table_load_file(path, t, err, sizeof err) != HM_OK) {
    fprintf(stderr, "hunting: %s: %s\n", path, err);
    return 1;
  }
  return 0;
}

/* Settings: the built-in defaults, the data's rate, then the settings file if given. */
static int load_settings(const cli_args *a, const double *acc, size_t n_acc, hm_monitor_config *cfg) {
  hm_monitor_config_default(cfg);
  const double rate = inferred_rate(acc, n_acc);
  if (!(rate >= 100.0 && rate <= 5000.0)) { /* the filters cannot be designed for it: say so, do not guess */
    fprintf(stderr, "hunting estimate: the acceleration data's sample rate is %.4g Hz; 100..5000 Hz is supported\n",
            rate);
    return 1;
  }
  cfg->estimator.sample_rate_hz = rate;
  const char *path = cli_value(a, "monitor");
  char err[256] = "";
  if (path && hm_config_load_monitor(path, cfg, err, sizeof err) != HM_OK) {
    fprintf(stderr, "hunting: monitor settings: %s\n", err);
    return 1;
  }
  return 0;
}

enum { HEAD_ROWS = 2001 }; /* rows read ahead to infer the sample rate */

typedef struct {
  hm_monitor mon;
  const hm_vehicle *veh;
  double every, v_const, next_out, t_written, t_last;
  unsigned long i, since_line; /* acceleration rows, and rows since the last line written */
  cli_csv *spd;
  double spd_next[2];
  int spd_have;
  read_counts counts;
  const char *restored;  /* the --state-in outcome, for the first line (then NULL) */
  const char *state_out; /* --state-out FILE or NULL */
  double state_every, next_state;
  int state_failed;      /* a write failed (said once): the run's exit status is 1 */
} run_state;

/* The wall clock [s since the epoch]. */
static double wall_clock_s(void) {
  struct timespec ts;
  return timespec_get(&ts, TIME_UTC) == TIME_UTC ? (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec : NAN;
}

/* What the monitor has learned into --state-out at recording time t. */
static void write_state(run_state *r, double t) {
  char why[512] = "";
  if (hm_state_save_file(r->mon, r->state_out, t, wall_clock_s(), why, sizeof why) == HM_OK || r->state_failed) return;
  fprintf(stderr, "hunting estimate: --state-out: %s\n", *why ? why : "the state could not be written");
  r->state_failed = 1;
}

/* The speed file's rows up to time t into the monitor (one row of look-ahead in r->spd_next; the first was read and
 * counted before; a row without a finite time at once, for the monitor to refuse and count); with t infinite the
 * rest of the file, counted as unused. */
static int push_speeds_until(run_state *r, double t) {
  while (r->spd_have && !(r->spd_next[0] > t)) {
    if (isfinite(t)) hm_monitor_push_speed(r->mon, r->spd_next[0], r->spd_next[1]);
    else ++r->counts.speed_rows_unused;
    const int k = cli_csv_next(r->spd, r->spd_next);
    if (k < 0) return 1;
    r->spd_have = k == 1;
    r->counts.speed_rows += (unsigned long)r->spd_have;
  }
  return 0;
}

/* The table's refinement as the node does it, but at once (offline nothing waits): the exact family where the
 * monitor wants one (monitor.h). */
static void refine_table(run_state *r) {
  double c;
  if (!hm_monitor_table_wanted(r->mon, &c)) return;
  hm_table t = NULL;
  if (hm_table_refine(hm_monitor_table(r->mon), r->veh, c, &t) != HM_OK ||
      hm_monitor_replace_table(r->mon, t, NULL, NULL, 0) != HM_OK)
    hm_monitor_table_failed(r->mon, c);
}

/* One acceleration row through the monitor, a JSON line per output interval. */
static int process_row(run_state *r, const double *row, int last_row) {
  const double t = row[0];
  if (r->spd) {
    if (push_speeds_until(r, t)) return 1;
  } else if (r->i % 10 == 0) {
    hm_monitor_push_speed(r->mon, t, r->v_const);
  }
  ++r->i;
  ++r->since_line;
  r->counts.accel_rows = r->i;
  hm_monitor_push_accel(r->mon, t, row[1]);
  if (isfinite(t)) r->t_last = fmax(r->t_last, t);
  if (!isfinite(r->next_out) && isfinite(t)) r->next_out = t + r->every;
  hm_monitor_status st;
  if (isfinite(t) && (t >= r->next_out || last_row) && hm_monitor_update(r->mon, t, &st) == HM_OK) {
    refine_table(r);
    write_line(&st, t, &r->counts, r->restored);
    r->restored = NULL;
    r->t_written = t;
    r->since_line = 0;
    if (t >= r->next_out) r->next_out = t + r->every - fmod(t - r->next_out, r->every);
  }
  if (r->state_out && isfinite(t)) { /* every state_every of recording time */
    if (!isfinite(r->next_state)) r->next_state = t + r->state_every;
    if (t >= r->next_state) {
      write_state(r, t);
      r->next_state = t + r->state_every;
    }
  }
  return 0;
}

/* --state-out, --state-every and --state-clock into r and *clock; nonzero (said) for a bad value. */
static int state_options(const cli_args *a, run_state *r, hm_state_clock *clock) {
  hm_state_config sc;
  hm_state_config_default(&sc);
  char why[160] = "";
  if (cli_number(a, "state-every", &sc.period_s)) return 1;
  if (hm_state_config_validate(&sc, why, sizeof why) != HM_OK) {
    fprintf(stderr, "hunting estimate: --state-every: %s\n", why);
    return 1;
  }
  r->state_every = sc.period_s;
  r->state_out = cli_value(a, "state-out");
  const char *c = cli_value(a, "state-clock");
  *clock = c && strcmp(c, "wall") == 0 ? HM_STATE_CLOCK_WALL : HM_STATE_CLOCK_LINE;
  if (c && strcmp(c, "wall") != 0 && strcmp(c, "recording") != 0) {
    fprintf(stderr, "hunting estimate: --state-clock must be recording or wall, got '%s'\n", c);
    return 1;
  }
  return 0;
}

/* --state-in restored at the first sample's time t0 (or refused: the prior), said on stderr; the outcome's text in
 * text for the first line. */
static void restore_state(const char *path, hm_monitor mon, double t0, hm_state_clock clock, char *text, size_t len) {
  hm_state_outcome o;
  hm_state_restore_file(mon, path, t0, wall_clock_s(), clock, &o);
  fprintf(stderr, "hunting estimate: --state-in %s: %s\n", path, o.text);
  snprintf(text, len, "%s", o.text);
}

/* The vehicle model and its parameters from the options (a bogie's or car's kept in *cm); 0, or 1 with the reason on
 * stderr. (A state file holds the model it was written for: another's is refused at --state-in, state.h.) */
static int estimate_model(const cli_args *a, cli_model *cm, hm_vehicle *veh, hm_model_kind *kind, hm_car *params) {
  if (cli_model_kind(a, kind)) return 1;
  if (*kind == HM_MODEL_WHEELSET ? cli_vehicle(a, veh, NULL) : cli_vehicle_model(a, *kind, cm)) return 1;
  if (*kind == HM_MODEL_WHEELSET) {
    hm_car_default(params);
    params->bogie.wheelset = *veh;
  } else {
    *params = cm->params;
  }
  *veh = params->bogie.wheelset;
  return 0;
}

/* The acceleration file's header and its first HEAD_ROWS rows into head (to infer the sample rate); *ended when that
 * was all. 0, or 1 with the reason on stderr. */
static int read_head(cli_csv *acc, const char *path, double *head, size_t *n_head, int *ended) {
  if (strcmp(acc->header[0], "t_s") != 0 || strcmp(acc->header[1], "accel_mps2") != 0) {
    fprintf(stderr, "hunting estimate: %s: the header must be 't_s,accel_mps2'\n", path);
    return 1;
  }
  size_t n = 0, n_finite = 0;
  int r = 1;
  while (n < HEAD_ROWS && (r = cli_csv_next(acc, &head[2 * n])) == 1) n_finite += isfinite(head[2 * n++]) != 0;
  *n_head = n;
  *ended = r == 0;
  if (r < 0) return 1;
  if (*ended && n_finite < 2) {
    fprintf(stderr, "hunting estimate: %s: %s\n", path,
            n == 0 ? "no samples (only a header)" : "fewer than two samples with a finite time stamp");
    return 1;
  }
  return 0;
}

/* The speed file opened into *spd (*open set) and its first row read into run; 0, or 1 with the reason on stderr. */
static int open_speed(cli_csv *spd, const char *path, run_state *run, int *open) {
  if (cli_csv_open(spd, path, 2, 1)) return 1;
  *open = 1;
  if (strcmp(spd->header[0], "t_s") != 0 || strcmp(spd->header[1], "speed_kmh") != 0) {
    fprintf(stderr, "hunting estimate: %s: the header must be 't_s,speed_kmh'\n", path);
    return 1;
  }
  const int s = cli_csv_next(spd, run->spd_next);
  run->spd_have = s == 1;
  run->counts.speed_rows = (unsigned long)run->spd_have;
  run->spd = spd;
  if (s < 0) return 1;
  if (s == 0) {
    fprintf(stderr, "hunting estimate: %s: no samples (only a header)\n", path);
    return 1;
  }
  return 0;
}

/* The monitor of the model into run->mon (a table to compute computed on every processor); 0, or 1 with the reason
 * on stderr. */
static int create_monitor(const cli_args *a, const hm_monitor_config *cfg, hm_model_kind kind, const hm_car *params,
                          hm_table table, run_state *run) {
  char why[256] = "";
  hm_threads threads = {0};
  const hm_status st =
      hm_monitor_create_model(cfg, kind, params, table, hm_threads_parallel_for, &threads, &run->mon, why, sizeof why);
  if (st == HM_OK) return 0;
  const int of_table = cli_value(a, "table") && strstr(why, "table") != NULL;
  fprintf(stderr, "hunting estimate: %s%s%s\n", of_table ? cli_value(a, "table") : "",
          of_table ? ": not for this vehicle: " : "", *why ? why : hm_status_str(st));
  return 1;
}

/* After the data: one line at its end (its counters the whole run's, rows refused after the last line included), the
 * state file, and a run that could use no speed or no acceleration refused whatever it printed (every line NO_DATA).
 * 0, or 1 with the reason on stderr. */
static int finish_run(run_state *run, const char *accel_path, const char *speed_path) {
  if (isfinite(run->t_last) && (run->t_written < run->t_last || run->since_line > 0 ||
                                run->counts.speed_rows_unused > 0)) {
    hm_monitor_status st;
    if (hm_monitor_update(run->mon, run->t_last, &st) == HM_OK)
      write_line(&st, run->t_last, &run->counts, run->restored);
  }
  if (run->state_out && isfinite(run->t_last)) write_state(run, run->t_last); /* and at the end */
  if (run->state_failed) return 1;
  hm_monitor_status end;
  if (!run->mon || !isfinite(run->t_last) || hm_monitor_update(run->mon, run->t_last, &end) != HM_OK) return 0;
  const hm_estimate *e = &end.estimate;
  if (e->n_speed_updates <= e->n_speed_rejected) { /* every speed refused, or none */
    fprintf(stderr, "hunting estimate: %s: no usable speed (%lu rejected)\n", speed_path ? speed_path : "--v",
            e->n_speed_rejected);
    return 1;
  }
  if (e->n_samples == 0) {
    fprintf(stderr, "hunting estimate: %s: no usable acceleration sample (%lu rejected)\n", accel_path,
            e->n_rejected_nonfinite + e->n_rejected_range + e->n_rejected_order);
    return 1;
  }
  return 0;
}

int cmd_estimate(const cli_args *a) {
  static cli_model cm; /* a bogie's or car's */
  hm_vehicle veh;
  hm_model_kind kind;
  hm_car params;
  double every = 0.1, v_const = NAN;
  const char *accel_path = cli_value(a, "accel"), *speed_path = cli_value(a, "speed");
  if (estimate_model(a, &cm, &veh, &kind, &params)) return 1;
  if (cli_number(a, "every", &every) || cli_number(a, "v", &v_const)) return 1;
  if (!accel_path || (!speed_path) == !cli_has(a, "v") || !(every > 0.0)) {
    fprintf(stderr, "hunting estimate: need --accel FILE and exactly one of --speed FILE or --v KM/H; --every > 0\n");
    return 1;
  }
  if (cli_has(a, "v") && !(v_const > 0.0 && v_const <= 1000.0)) {
    fprintf(stderr, "hunting estimate: --v must be in (0, 1000] km/h, got %g\n", v_const);
    return 1;
  }
  /* recordings of any length are streamed: only the first HEAD_ROWS rows are held, to infer the sample rate */
  cli_csv acc, spd;
  if (cli_csv_open(&acc, accel_path, 2, 1)) return 1;
  static double head[2 * HEAD_ROWS];
  size_t n_head = 0;
  int ended = 0, spd_open = 0;
  int rc = read_head(&acc, accel_path, head, &n_head, &ended);
  run_state run = {NULL, &veh, every, v_const, NAN, -INFINITY, -INFINITY, 0, 0, NULL, {0.0, 0.0}, 0, {0, 0, 0},
                   NULL, NULL, 0.0, NAN, 0};
  hm_state_clock clock = HM_STATE_CLOCK_LINE;
  if (rc == 0) rc = state_options(a, &run, &clock);
  if (rc == 0 && speed_path) rc = open_speed(&spd, speed_path, &run, &spd_open);
  hm_monitor_config cfg;
  hm_table table = NULL;
  if (rc == 0) rc = load_settings(a, head, n_head, &cfg);
  if (rc == 0) rc = load_table(a, &table);
  if (rc == 0) rc = create_monitor(a, &cfg, kind, &params, table, &run);
  static char restored[HM_STATE_TEXT_MAX];
  for (size_t i = 0; rc == 0 && cli_value(a, "state-in") && i < n_head; ++i)
    if (isfinite(head[2 * i])) { /* at the first sample: its time is the restored ages' now */
      restore_state(cli_value(a, "state-in"), run.mon, head[2 * i], clock, restored, sizeof restored);
      run.restored = restored;
      break;
    }
  for (size_t i = 0; rc == 0 && i < n_head; ++i) rc = process_row(&run, &head[2 * i], ended && i + 1 == n_head);
  double row[2];
  int r;
  while (rc == 0 && !ended && (r = cli_csv_next(&acc, row)) != 0) rc = r < 0 ? 1 : process_row(&run, row, 0);
  if (rc == 0 && run.spd) rc = push_speeds_until(&run, INFINITY); /* the rest, after the acceleration's end */
  if (rc == 0) rc = finish_run(&run, accel_path, speed_path);
  hm_monitor_destroy(run.mon);
  cli_csv_close(&acc);
  if (spd_open) cli_csv_close(&spd);
  return rc;
}
