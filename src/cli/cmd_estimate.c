/* hunting estimate: run the online estimator and alarm logic over recorded data, one JSON object per line. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "hunting_monitor/alarm.h"
#include "hunting_monitor/config.h"
#include "hunting_monitor/estimator.h"
#include "hunting_monitor/tables.h"

const cli_option estimate_opts[] = {
    {"accel", "FILE", "lateral acceleration CSV with header t_s,accel_mps2 (required)"},
    {"speed", "FILE", "speed CSV with header t_s,speed_kmh"},
    {"v", "KM/H", "constant speed instead of --speed"},
    {"monitor", "FILE", "estimator and alarm settings (default: built-in = config/monitor.yaml)"},
    {"table", "FILE", "boundary table from 'hunting tables' (default: computed at start, about 10 s)"},
    {"every", "SECONDS", "output interval in data time (default 0.1)"},
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

static void write_line(const hm_estimate *e, const hm_assessment *s, double t) {
  json_writer w;
  jw_init(&w, stdout);
  jw_object(&w, NULL);
  jw_number(&w, "t_s", t);
  jw_string(&w, "level", hm_level_name(s->level));
  jw_int(&w, "reason_code", (long)s->reason);
  jw_string(&w, "reason", hm_reason_text(s->reason));
  jw_bool(&w, "level_changed", s->changed);
  jw_bool(&w, "speed_valid", e->speed_valid);
  jw_number(&w, "speed_kmh", e->speed_kmh);
  jw_bool(&w, "accel_valid", e->accel_valid);
  jw_bool(&w, "oscillation_valid", e->oscillation_valid);
  jw_number(&w, "amplitude_accel_mps2", e->amplitude_accel_mps2);
  jw_number(&w, "frequency_hz", e->frequency_hz);
  jw_number(&w, "amplitude_m", e->amplitude_displacement_m);
  jw_bool(&w, "conicity_valid", e->conicity_valid);
  jw_number(&w, "conicity_estimate", e->conicity);
  jw_number(&w, "conicity_confidence", e->conicity_confidence);
  const int b = s->boundaries_valid; /* no margins are shown as current without data */
  jw_number(&w, "conicity_used", b ? s->conicity : NAN);
  jw_number(&w, "hopf_kmh", b ? s->boundaries.hopf_speed_kmh : NAN);
  jw_number(&w, "lowest_cycle_kmh", b ? s->boundaries.lowest_cycle_speed_kmh : NAN);
  jw_number(&w, "margin_hopf_kmh", b ? s->margin_hopf_kmh : NAN);
  jw_number(&w, "margin_lowest_cycle_kmh", b ? s->margin_lowest_cycle_kmh : NAN);
  jw_number(&w, "unstable_cycle_amplitude_m", b && s->boundaries.has_edge ? s->boundaries.edge_amp_m : NAN);
  jw_number(&w, "stable_cycle_amplitude_m",
            b && s->boundaries.has_stable_outer ? s->boundaries.stable_outer_amp_m : NAN);
  jw_number(&w, "rms_mps2", e->rms_mps2);
  jw_bool(&w, "rms_exceeded", e->rms_exceeded);
  jw_int(&w, "consecutive_peaks", (long)e->consecutive_peaks);
  jw_bool(&w, "peaks_exceeded", e->peaks_exceeded);
  jw_int(&w, "rejected_samples", (long)(e->n_rejected_nonfinite + e->n_rejected_range + e->n_rejected_order));
  jw_int(&w, "gaps", (long)e->n_gaps);
  jw_int(&w, "rejected_speeds", (long)e->n_speed_rejected);
  jw_end_object(&w);
  jw_finish(&w);
}

static hm_table load_or_build_table(const cli_args *a, const hm_vehicle *veh) {
  hm_table t = NULL;
  const char *path = cli_value(a, "table");
  if (path) {
    char err[256] = "";
    if (hm_table_load_file(path, &t, err, sizeof err) != HM_OK) {
      fprintf(stderr, "hunting: %s: %s\n", path, err);
      return NULL;
    }
    /* a table of another vehicle (or an altered one) gives wrong margins: refuse it */
    if (hm_table_check_vehicle(t, veh, HM_TABLE_CHECK_TOL_KMH, err, sizeof err) != HM_OK) {
      fprintf(stderr, "hunting estimate: %s: not for this vehicle: %s\n", path, err);
      hm_table_destroy(t);
      return NULL;
    }
    return t;
  }
  fprintf(stderr, "hunting estimate: no --table: computing boundary tables (conicity 0.05-0.40)...\n");
  hm_table_spec spec;
  hm_table_spec_default(&spec);
  spec.n_conicity = 8;
  hm_status st = hm_table_build(veh, &spec, &t);
  if (st != HM_OK) {
    cli_fail_status("boundary tables", st);
    return NULL;
  }
  return t;
}

/* Settings: the built-in defaults, the data's rate, then the settings file if given. */
static int load_settings(const cli_args *a, const double *acc, size_t n_acc, const hm_vehicle *veh,
                         hm_estimator_config *ec, hm_alarm_config *ac) {
  hm_estimator_config_default(ec);
  hm_alarm_config_default(ac);
  hm_conicity_eval(&veh->conicity, 0.0, &ac->conicity_fallback, NULL);
  const double rate = inferred_rate(acc, n_acc);
  if (!(rate >= 100.0 && rate <= 5000.0)) { /* the filters cannot be designed for it: say so, do not guess */
    fprintf(stderr, "hunting estimate: the acceleration data's sample rate is %.4g Hz; 100..5000 Hz is supported\n",
            rate);
    return 1;
  }
  ec->sample_rate_hz = rate;
  const char *path = cli_value(a, "monitor");
  char err[256] = "";
  if (path && hm_config_load_monitor(path, ec, ac, err, sizeof err) != HM_OK) {
    fprintf(stderr, "hunting: monitor settings: %s\n", err);
    return 1;
  }
  if (hm_estimator_config_validate(ec, err, sizeof err) != HM_OK) {
    fprintf(stderr, "hunting estimate: estimator settings: %s (the data's sample rate is %.1f Hz)\n", err, rate);
    return 1;
  }
  return 0;
}

int cmd_estimate(const cli_args *a) {
  hm_vehicle veh;
  double every = 0.1, v_const = NAN;
  const char *accel_path = cli_value(a, "accel"), *speed_path = cli_value(a, "speed");
  if (cli_vehicle(a, &veh, NULL) || cli_number(a, "every", &every) || cli_number(a, "v", &v_const)) return 1;
  if (!accel_path || (!speed_path) == !cli_has(a, "v") || !(every > 0.0)) {
    fprintf(stderr, "hunting estimate: need --accel FILE and exactly one of --speed FILE or --v KM/H; --every > 0\n");
    return 1;
  }
  char h_acc[2][64], h_spd[2][64];
  double *acc = NULL, *spd = NULL;
  size_t n_acc = 0, n_spd = 0;
  if (cli_read_csv(accel_path, 2, h_acc, &acc, &n_acc, 1)) return 1;
  int rc = 0;
  if (strcmp(h_acc[0], "t_s") != 0 || strcmp(h_acc[1], "accel_mps2") != 0) {
    fprintf(stderr, "hunting estimate: %s: the header must be 't_s,accel_mps2'\n", accel_path);
    rc = 1;
  }
  size_t n_finite = 0;
  for (size_t i = 0; rc == 0 && i < n_acc; ++i) n_finite += isfinite(acc[2 * i]) != 0;
  if (rc == 0 && n_finite < 2) {
    fprintf(stderr, "hunting estimate: %s: %s\n", accel_path,
            n_acc == 0 ? "no samples (only a header)" : "fewer than two samples with a finite time stamp");
    rc = 1;
  }
  if (rc == 0 && cli_has(a, "v") && !(v_const > 0.0 && v_const <= 1000.0)) {
    fprintf(stderr, "hunting estimate: --v must be in (0, 1000] km/h, got %g\n", v_const);
    rc = 1;
  }
  if (rc == 0 && speed_path) {
    rc = cli_read_csv(speed_path, 2, h_spd, &spd, &n_spd, 1);
    if (rc == 0 && (strcmp(h_spd[0], "t_s") != 0 || strcmp(h_spd[1], "speed_kmh") != 0)) {
      fprintf(stderr, "hunting estimate: %s: the header must be 't_s,speed_kmh'\n", speed_path);
      rc = 1;
    }
  }
  hm_estimator_config ec;
  hm_alarm_config ac;
  hm_table table = NULL;
  hm_estimator est = NULL;
  hm_alarm alarm = NULL;
  if (rc == 0) rc = load_settings(a, acc, n_acc, &veh, &ec, &ac);
  if (rc == 0 && !(table = load_or_build_table(a, &veh))) rc = 1;
  if (rc == 0 && (!(est = hm_estimator_create(&ec, &veh)) || !(alarm = hm_alarm_create(&ac, table)))) {
    cli_fail_status("estimator", HM_ENOMEM);
    rc = 1;
  }
  size_t k = 0;
  double next_out = n_acc ? acc[0] + every : 0.0, t_written = -INFINITY, t_last = -INFINITY;
  for (size_t i = 0; rc == 0 && i < n_acc; ++i) {
    const double t = acc[2 * i];
    if (spd)
      for (; k < n_spd && spd[2 * k] <= t; ++k) hm_estimator_push_speed(est, spd[2 * k], spd[2 * k + 1]);
    else if (i % 10 == 0)
      hm_estimator_push_speed(est, t, v_const);
    hm_estimator_push_accel(est, t, acc[2 * i + 1]);
    if (isfinite(t)) t_last = fmax(t_last, t);
    /* one line per interval of data time, and one at the end of the data */
    if (isfinite(t) && (t >= next_out || i + 1 == n_acc)) {
      hm_estimate e;
      hm_assessment s;
      hm_estimator_read(est, t, &e);
      hm_alarm_update(alarm, &e, t, &s);
      write_line(&e, &s, t);
      t_written = t;
      if (t >= next_out) next_out = t + every - fmod(t - next_out, every);
    }
  }
  if (rc == 0 && isfinite(t_last) && t_written < t_last) { /* the last rows were not finite times */
    hm_estimate e;
    hm_assessment s;
    hm_estimator_read(est, t_last, &e);
    hm_alarm_update(alarm, &e, t_last, &s);
    write_line(&e, &s, t_last);
  }
  hm_alarm_destroy(alarm);
  hm_estimator_destroy(est);
  hm_table_destroy(table);
  free(acc);
  free(spd);
  return rc;
}
