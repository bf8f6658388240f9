/* hunting hopf | cycles | hopf-curve | lpc-curve: argument parsing and JSON/CSV output over hopf.h, cycles.h. */
#define _POSIX_C_SOURCE 200809L /* open_memstream */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "hunting_monitor/cycles.h"
#include "hunting_monitor/hopf.h"
#include "hunting_monitor/linear.h"
#include "hunting_monitor/system_cycles.h"

/* --param NAME (default v). */
static int param_option(const cli_args *a, hm_param *p) {
  const char *name = cli_value(a, "param");
  *p = HM_PARAM_SPEED;
  if (name && hm_param_from_name(name, p) != HM_OK) {
    fprintf(stderr, "hunting: --param must be v, kx, ky or conicity, got '%s'\n", name);
    return 1;
  }
  return 0;
}

/* Speed of the analysis: --v for every parameter but the speed itself. */
static int fixed_speed(const cli_args *a, hm_param p, double *speed_kmh) {
  *speed_kmh = 500.0; /* unused when the speed is the parameter */
  if (p == HM_PARAM_SPEED) {
    if (cli_has(a, "v")) {
      fprintf(stderr, "hunting: --v is the parameter here; use --v-min/--v-max to bound it\n");
      return 1;
    }
    return 0;
  }
  return cli_speed_option(a, speed_kmh);
}

static void default_range(hm_param p, double *lo, double *hi) {
  switch (p) {
    case HM_PARAM_SPEED: *lo = 100.0, *hi = 900.0; break;
    case HM_PARAM_CONICITY: *lo = 0.01, *hi = 1.0; break;
    default: *lo = 0.1, *hi = 60.0; break;
  }
}

static const char *kind_of(double l1) { return l1 > 0.0 ? "subcritical" : l1 < 0.0 ? "supercritical" : "degenerate"; }

static void write_hopf(json_writer *w, const char *key, const hm_hopf_point *h) {
  jw_object(w, key);
  jw_number(w, "v_kmh", h->speed_kmh);
  jw_number(w, "kx_mn_m", h->kx_mn_m);
  jw_number(w, "ky_mn_m", h->ky_mn_m);
  jw_number(w, "conicity", h->conicity);
  jw_number(w, "omega_rad_s", h->omega_rad_s);
  jw_number(w, "frequency_hz", h->omega_rad_s / (2.0 * HM_PI));
  jw_number(w, "l1", h->l1);
  jw_number(w, "l2", h->l2);
  jw_string(w, "kind", kind_of(h->l1));
  jw_end_object(w);
}

/* Hopf points of parameter p over the range options (--from/--to, or --v-min/--v-max for the speed). */
static int find_hopf(const cli_args *a, const hm_vehicle *veh, hm_param p, double speed_kmh, const char *lo_key,
                     const char *hi_key, hm_hopf_point *pts, size_t max, size_t *n) {
  double lo, hi;
  default_range(p, &lo, &hi);
  if (cli_number(a, lo_key, &lo) || cli_number(a, hi_key, &hi)) return 1;
  if (!(hi > lo)) {
    fprintf(stderr, "hunting: need --%s < --%s\n", lo_key, hi_key);
    return 1;
  }
  hm_status st = hm_hopf_find(veh, speed_kmh, p, lo, hi, 1e-10, pts, max, n);
  if (st != HM_OK) return cli_fail_status("Hopf points", st);
  if (*n == 0) {
    fprintf(stderr, "hunting: no Hopf point of the origin for %s in [%g, %g]\n", hm_param_name(p), lo, hi);
    return 1;
  }
  if (*n > max) *n = max;
  return 0;
}

/* ---- hopf ---- */

const cli_option hopf_opts[] = {
    {"param", "NAME", "parameter along which the Hopf point is sought: v (default), kx, ky or conicity"},
    {"v", "KM/H", "running speed (for --param kx, ky or conicity)"},
    {"from", "VALUE", "lower end of the search range (kx, ky [MN/m], conicity; default 0.1 / 0.01)"},
    {"to", "VALUE", "upper end of the search range (default 60 / 1.0)"},
    CLI_VEHICLE_OPTIONS,
    {NULL, NULL, NULL}};

int cmd_hopf(const cli_args *a) {
  hm_vehicle veh;
  hm_param p;
  double speed;
  if (cli_vehicle(a, &veh, NULL) || param_option(a, &p) || fixed_speed(a, p, &speed)) return 1;
  hm_hopf_point pts[8];
  size_t n = 0;
  if (find_hopf(a, &veh, p, speed, "from", "to", pts, 8, &n)) return 1;
  json_writer w;
  jw_init(&w, stdout);
  if (p == HM_PARAM_SPEED) {
    write_hopf(&w, NULL, &pts[0]);
  } else {
    jw_object(&w, NULL);
    jw_string(&w, "param", hm_param_name(p));
    jw_array(&w, "points");
    for (size_t i = 0; i < n; ++i) write_hopf(&w, NULL, &pts[i]);
    jw_end_array(&w);
    jw_end_object(&w);
  }
  jw_finish(&w);
  return 0;
}

/* ---- cycles ---- */

const cli_option cycles_opts[] = {
    {"param", "NAME", "continuation parameter: v (default), kx, ky or conicity"},
    {"v", "KM/H", "running speed (for --param kx, ky or conicity)"},
    {"v-min", "KM/H", "--param v: stop below this speed (default 100)"},
    {"v-max", "KM/H", "--param v: stop above this speed (default 900)"},
    {"from", "VALUE", "other parameters: lower end of the Hopf search and continuation range"},
    {"to", "VALUE", "other parameters: upper end"},
    {"amp-max", "M", "stop when max|y| exceeds this (default 0.020 m)"},
    {"ds-max", "S", "largest continuation step, scaled units (default 5)"},
    {"rtol", "R", "shooting integration tolerance (default 1e-9)"},
    {"refine", NULL, "repeat with 100x tighter tolerances and 4x smaller steps; report which points persist"},
    {"csv", NULL, "write the branch as CSV instead of JSON"},
    {"out", "FILE", "write the output there instead of stdout"},
    CLI_VEHICLE_OPTIONS,
    {NULL, NULL, NULL}};

enum { MAX_BRANCH = 20000, MAX_EVENTS = 64 };

typedef struct {
  hm_cycle_point *points;
  size_t n_points;
  hm_cycle_event events[MAX_EVENTS];
  size_t n_events;
  hm_cont_stats stats;
} family;

static int run_family(const hm_vehicle *veh, double speed, const hm_hopf_point *hopf, const hm_cycle_options *o,
                      family *fam) {
  fam->points = malloc(MAX_BRANCH * sizeof *fam->points);
  if (!fam->points) return cli_fail_status("cycles", HM_ENOMEM);
  hm_status st = hm_cycles_continue(veh, speed, hopf, o, fam->points, MAX_BRANCH, &fam->n_points, fam->events,
                                    MAX_EVENTS, &fam->n_events, &fam->stats);
  if (st != HM_OK) return cli_fail_status("continuation of cycles from the Hopf point", st);
  return 0;
}

static double max_nontrivial_modulus(const hm_cycle_point *c) {
  double m = 0.0;
  for (int k = 0; k < 4; ++k)
    if (k != c->trivial_index) m = fmax(m, hypot(c->mult_re[k], c->mult_im[k]));
  return m;
}

static void write_cycle_fields(json_writer *w, const char *pname, const hm_cycle_point *c) {
  jw_number(w, pname, c->param);
  jw_number(w, "amplitude_m", c->amp_y_m);
  jw_number(w, "amplitude_psi_rad", c->amp_psi_rad);
  jw_number(w, "period_s", c->period_s);
  jw_number(w, "frequency_hz", 1.0 / c->period_s);
}

static void write_events(json_writer *w, const char *key, const family *fam, hm_cycle_event_kind kind,
                         const char *pname) {
  jw_array(w, key);
  for (size_t i = 0; i < fam->n_events; ++i) {
    const hm_cycle_event *e = &fam->events[i];
    if (e->kind != kind) continue;
    jw_object(w, NULL);
    write_cycle_fields(w, pname, &e->point);
    if (kind == HM_CYCLE_LPC)
      jw_string(w, "stable_side", e->stable_side > 0 ? "upper" : e->stable_side < 0 ? "lower" : "none");
    jw_int(w, "index", (long)e->index);
    jw_end_object(w);
  }
  jw_end_array(w);
}

/* For each event of the base run: the nearest event of the same kind in the refined run. */
static void write_refinement(json_writer *w, const family *base, const family *fine, const char *pname) {
  jw_array(w, "refinement");
  for (size_t i = 0; i < base->n_events; ++i) {
    const hm_cycle_event *e = &base->events[i];
    double best = INFINITY, value = NAN;
    for (size_t j = 0; j < fine->n_events; ++j) {
      const hm_cycle_event *f = &fine->events[j];
      const double d = fabs(f->point.param - e->point.param) + fabs(f->point.amp_y_m - e->point.amp_y_m) * 1e3;
      if (f->kind == e->kind && d < best) {
        best = d;
        value = f->point.param;
      }
    }
    jw_object(w, NULL);
    jw_string(w, "kind", hm_cycle_event_name(e->kind));
    jw_number(w, pname, e->point.param);
    jw_number(w, "refined", value);
    jw_number(w, "change", value - e->point.param);
    jw_bool(w, "persists", best < 0.05);
    jw_end_object(w);
  }
  jw_end_array(w);
  jw_int(w, "refined_event_count", (long)fine->n_events);
}

static void write_branch_csv(FILE *f, const family *fam, const char *pname) {
  fprintf(f, "%s,amplitude_m,amplitude_psi_rad,period_s,stable,n_unstable,max_multiplier_modulus\n", pname);
  for (size_t i = 0; i < fam->n_points; ++i) {
    const hm_cycle_point *c = &fam->points[i];
    fprintf(f, "%.10g,%.10g,%.10g,%.10g,%d,%d,%.6g\n", c->param, c->amp_y_m, c->amp_psi_rad, c->period_s,
            c->stable, c->n_unstable, max_nontrivial_modulus(c));
  }
}

/* What a continuation cost: accepted and rejected steps, Newton iterations, integrations of the shooting system. */
static void write_cont_stats(json_writer *w, const char *key, const hm_cont_stats *s) {
  jw_object(w, key);
  jw_string(w, "stop_reason", hm_cont_stop_name(s->stop));
  jw_number(w, "steps", (double)s->steps);
  jw_number(w, "rejected_steps", (double)s->rejected);
  jw_number(w, "newton_iterations", (double)s->newton_iterations);
  jw_number(w, "shots", (double)s->shots);
  jw_number(w, "integration_steps", (double)s->integration_steps);
  jw_end_object(w);
}

static void write_family_json(FILE *f, const hm_hopf_point *hopf, const family *fam, const family *fine,
                              hm_param p) {
  const char *pname = hm_param_name(p);
  json_writer w;
  jw_init(&w, f);
  jw_object(&w, NULL);
  jw_string(&w, "param", pname);
  write_hopf(&w, "hopf", hopf);
  write_events(&w, "folds", fam, HM_CYCLE_LPC, pname);
  write_events(&w, "branch_points", fam, HM_CYCLE_BPC, pname);
  write_events(&w, "period_doublings", fam, HM_CYCLE_PD, pname);
  write_events(&w, "neimark_sacker", fam, HM_CYCLE_NS, pname);
  const double lowest = hm_cycles_lowest(fam->points, fam->n_points, fam->events, fam->n_events);
  jw_number(&w, p == HM_PARAM_SPEED ? "lowest_cycle_v_kmh" : "lowest_cycle_param", lowest);
  jw_string(&w, "stop_reason", hm_cont_stop_name(fam->stats.stop));
  write_cont_stats(&w, "continuation", &fam->stats);
  if (fine) write_refinement(&w, fam, fine, pname);
  jw_array(&w, "branch");
  for (size_t i = 0; i < fam->n_points; ++i) {
    const hm_cycle_point *c = &fam->points[i];
    jw_object(&w, NULL);
    write_cycle_fields(&w, pname, c);
    jw_bool(&w, "stable", c->stable);
    jw_int(&w, "n_unstable", c->n_unstable);
    jw_array(&w, "multipliers");
    for (int k = 0; k < 4; ++k) {
      jw_array(&w, NULL);
      jw_number(&w, NULL, c->mult_re[k]);
      jw_number(&w, NULL, c->mult_im[k]);
      jw_end_array(&w);
    }
    jw_end_array(&w);
    jw_end_object(&w);
  }
  jw_end_array(&w);
  jw_end_object(&w);
  jw_finish(&w);
}

/* Cycle options from the command line: the parameter range, amplitude limit, step and tolerance. */
static int cycle_options(const cli_args *a, hm_param p, hm_cycle_options *o) {
  hm_cycle_options_default(o, p);
  default_range(p, &o->p_min, &o->p_max);
  const char *lo_key = p == HM_PARAM_SPEED ? "v-min" : "from", *hi_key = p == HM_PARAM_SPEED ? "v-max" : "to";
  if (cli_number(a, lo_key, &o->p_min) || cli_number(a, hi_key, &o->p_max) ||
      cli_number(a, "amp-max", &o->amp_max_m) || cli_number(a, "ds-max", &o->cont.ds_max) ||
      cli_number(a, "rtol", &o->shoot.rtol))
    return 1;
  if (!(o->p_max > o->p_min) || !(o->amp_max_m > 2.0 * o->amp_start_m) || !(o->cont.ds_max >= o->cont.ds_init) ||
      !(o->shoot.rtol > 0.0 && o->shoot.rtol < 1e-3)) {
    fprintf(stderr, "hunting cycles: need --%s < --%s, --amp-max > %g m, --ds-max >= %g, 0 < --rtol < 1e-3\n",
            lo_key, hi_key, 2.0 * o->amp_start_m, o->cont.ds_init);
    return 1;
  }
  return 0;
}

/* --out FILE (or stdout) for a command's output; NULL with *rc = 1 after saying why. */
static FILE *open_out(const cli_args *a, int *rc) {
  const char *path = cli_value(a, "out");
  FILE *f = path ? fopen(path, "w") : stdout;
  if (!f) {
    perror(path);
    *rc = 1;
  }
  return f;
}

/* Close what open_out opened: 1 (said) if the file could not be written. */
static int close_out(const cli_args *a, FILE *f) {
  const char *path = cli_value(a, "out");
  if (path && fclose(f) != 0) {
    perror(path);
    return 1;
  }
  return 0;
}

/* ---- cycles of a bogie (system_cycles.h) ---- */

static double system_max_modulus(const hm_system_cycle_point *c) {
  double m = 0.0;
  for (size_t k = 0; k < c->dim; ++k)
    if ((int)k != c->trivial_index) m = fmax(m, hypot(c->mult_re[k], c->mult_im[k]));
  return m;
}

static void write_system_cycle(json_writer *w, const hm_system_cycle_point *c) {
  jw_number(w, "v_kmh", c->speed_kmh);
  jw_number(w, "amplitude_m", c->amp_m);
  jw_number(w, "period_s", c->period_s);
  jw_number(w, "frequency_hz", 1.0 / c->period_s);
}

static void write_system_events(json_writer *w, const char *key, const hm_system_cycle_event *ev, size_t ne,
                               hm_cycle_event_kind kind) {
  jw_array(w, key);
  for (size_t i = 0; i < ne; ++i) {
    if (ev[i].kind != kind) continue;
    jw_object(w, NULL);
    write_system_cycle(w, &ev[i].point);
    if (kind == HM_CYCLE_LPC)
      jw_string(w, "stable_side", ev[i].stable_side > 0 ? "upper" : ev[i].stable_side < 0 ? "lower" : "none");
    jw_int(w, "index", (long)ev[i].index);
    jw_end_object(w);
  }
  jw_end_array(w);
}

static void write_system_family(FILE *f, const hm_system *sys, const hm_vehicle *wheelset,
                                const hm_system_cycle_point *pts, size_t np, const hm_system_cycle_event *ev, size_t ne,
                                const hm_cont_stats *st, int csv) {
  if (csv) {
    fprintf(f, "v_kmh,amplitude_m,period_s,stable,n_unstable,max_multiplier_modulus\n");
    for (size_t i = 0; i < np; ++i)
      fprintf(f, "%.10g,%.10g,%.10g,%d,%d,%.6g\n", pts[i].speed_kmh, pts[i].amp_m, pts[i].period_s, pts[i].stable,
              pts[i].n_unstable, system_max_modulus(&pts[i]));
    return;
  }
  hm_system_critical_options copt;
  hm_system_critical_options_default(&copt);
  copt.v_min_mps = hm_mps_from_kmh(pts[0].speed_kmh - 50.0 > 1.0 ? pts[0].speed_kmh - 50.0 : 1.0);
  double vh = NAN;
  hm_system_spectrum spec;
  const int have_hopf = hm_system_critical_speed(sys, &copt, &vh, &spec) == HM_OK;
  json_writer w;
  jw_init(&w, f);
  jw_object(&w, NULL);
  jw_string(&w, "model", sys->n_bodies == 3 ? "car" : "bogie");
  jw_string(&w, "param", "v_kmh");
  jw_object(&w, "hopf");
  jw_number(&w, "v_kmh", have_hopf ? hm_kmh_from_mps(vh) : NAN);
  jw_number(&w, "frequency_hz", have_hopf ? spec.frequency_hz : NAN);
  jw_string(&w, "mode", have_hopf ? sys->body_names[spec.dominant_body] : "");
  jw_string(&w, "kind", np > 1 ? (pts[1].speed_kmh < pts[0].speed_kmh ? "subcritical" : "supercritical") : "");
  jw_number(&w, "conicity", cli_conicity0(wheelset));
  jw_number(&w, "kx_mn_m", wheelset->stiffness_long_n_m / 1e6);
  jw_number(&w, "ky_mn_m", wheelset->stiffness_lat_n_m / 1e6);
  jw_end_object(&w);
  write_system_events(&w, "folds", ev, ne, HM_CYCLE_LPC);
  write_system_events(&w, "branch_points", ev, ne, HM_CYCLE_BPC);
  write_system_events(&w, "period_doublings", ev, ne, HM_CYCLE_PD);
  write_system_events(&w, "neimark_sacker", ev, ne, HM_CYCLE_NS);
  jw_number(&w, "lowest_cycle_v_kmh", hm_system_cycles_lowest(pts, np, ev, ne));
  jw_string(&w, "stop_reason", hm_cont_stop_name(st->stop));
  write_cont_stats(&w, "continuation", st);
  jw_array(&w, "branch");
  for (size_t i = 0; i < np; ++i) {
    jw_object(&w, NULL);
    write_system_cycle(&w, &pts[i]);
    jw_bool(&w, "stable", pts[i].stable);
    jw_int(&w, "n_unstable", pts[i].n_unstable);
    jw_number(&w, "max_multiplier_modulus", system_max_modulus(&pts[i]));
    jw_end_object(&w);
  }
  jw_end_array(&w);
  jw_end_object(&w);
  jw_finish(&w);
}

/* cycles on a bogie or car config: the family from its Hopf point in speed (system_cycles.h). */
static int cycles_system(const cli_args *a, hm_model_kind kind) {
  static cli_model cm; /* its systems point into it */
  if (cli_vehicle_model(a, kind, &cm)) return 1;
  const char *pname = cli_value(a, "param");
  if ((pname && strcmp(pname, "v") && strcmp(pname, "v_kmh")) || cli_has(a, "refine") || cli_has(a, "from") ||
      cli_has(a, "to")) {
    fprintf(stderr, "hunting cycles: a %s's cycles are continued in speed only (no --param, --from, --to or "
            "--refine yet)\n", hm_model_kind_name(kind));
    return 1;
  }
  hm_system_cycle_options o;
  hm_system_cycle_options_default(&o);
  o.v_min_kmh = 100.0, o.v_max_kmh = 900.0, o.cont.ds_max = 5.0;
  if (cli_number(a, "v-min", &o.v_min_kmh) || cli_number(a, "v-max", &o.v_max_kmh) ||
      cli_number(a, "amp-max", &o.amp_max_m) || cli_number(a, "ds-max", &o.cont.ds_max) ||
      cli_number(a, "rtol", &o.shoot.rtol))
    return 1;
  if (!(o.v_max_kmh > o.v_min_kmh && o.v_min_kmh > 0.0) || !(o.amp_max_m > 2.0 * o.amp_start_m) ||
      !(o.cont.ds_max >= o.cont.ds_init) || !(o.shoot.rtol > 0.0 && o.shoot.rtol < 1e-3)) {
    fprintf(stderr, "hunting cycles: need 0 < --v-min < --v-max, --amp-max > %g m, --ds-max >= %g, 0 < --rtol < "
            "1e-3\n", 2.0 * o.amp_start_m, o.cont.ds_init);
    return 1;
  }
  const hm_system *sys = &cm.sys;
  hm_status st;
  hm_system_cycle_point *pts = malloc(MAX_BRANCH * sizeof *pts);
  hm_system_cycle_event ev[MAX_EVENTS];
  size_t np = 0, ne = 0;
  hm_cont_stats cs;
  if (!pts) return cli_fail_status("cycles", HM_ENOMEM);
  st = hm_system_cycles_continue(sys, &o, pts, MAX_BRANCH, &np, ev, MAX_EVENTS, &ne, &cs);
  int rc = 0;
  if (st == HM_ENOCRIT) {
    fprintf(stderr, "hunting cycles: the %s has no Hopf point between %g and %g km/h\n", hm_model_kind_name(kind),
            o.v_min_kmh, o.v_max_kmh);
    rc = 1;
  } else if (st != HM_OK) {
    rc = cli_fail_status("cycles", st);
  }
  FILE *f = rc == 0 ? open_out(a, &rc) : NULL;
  if (f) {
    write_system_family(f, sys, &cm.wheelset, pts, np, ev, ne, &cs, cli_has(a, "csv"));
    rc = close_out(a, f);
  }
  free(pts);
  return rc;
}

int cmd_cycles(const cli_args *a) {
  hm_vehicle veh;
  hm_param p;
  double speed;
  hm_cycle_options o;
  hm_model_kind kind;
  if (cli_model_kind(a, &kind)) return 1;
  if (kind != HM_MODEL_WHEELSET) return cycles_system(a, kind);
  if (cli_vehicle(a, &veh, NULL) || param_option(a, &p) || fixed_speed(a, p, &speed) || cycle_options(a, p, &o))
    return 1;
  hm_hopf_point hopf;
  size_t n = 0;
  if (find_hopf(a, &veh, p, speed, p == HM_PARAM_SPEED ? "v-min" : "from", p == HM_PARAM_SPEED ? "v-max" : "to",
                &hopf, 1, &n))
    return 1;
  family fam = {0}, fine = {0};
  int rc = run_family(&veh, speed, &hopf, &o, &fam);
  if (rc == 0 && cli_has(a, "refine")) {
    hm_cycle_options of = o;
    of.shoot.rtol *= 1e-2;
    of.shoot.atol *= 1e-2;
    of.cont.ds_max *= 0.25;
    of.cont.ds_init *= 0.25;
    /* 4x smaller steps where the predictor's error (growing as ds^2, or ds^3 with the curvature) sets them */
    of.cont.predictor_tol /= of.cont.curvature_predictor ? 64.0 : 16.0;
    of.cont.max_steps *= 4;
    rc = run_family(&veh, speed, &hopf, &of, &fine);
  }
  FILE *f = rc == 0 ? open_out(a, &rc) : NULL;
  if (f) {
    if (cli_has(a, "csv"))
      write_branch_csv(f, &fam, hm_param_name(p));
    else
      write_family_json(f, &hopf, &fam, cli_has(a, "refine") ? &fine : NULL, p);
    rc = close_out(a, f);
  }
  free(fam.points);
  free(fine.points);
  return rc;
}

/* ---- hopf-curve ---- */

const cli_option hopf_curve_opts[] = {
    {"plane", "NAME", "kx-v (default), ky-v, or kx-ky (at the speed --v)"},
    {"from", "MN/m", "first value of Kx (Ky for ky-v) (default 2)"},
    {"to", "MN/m", "last value (default 20)"},
    {"n", "COUNT", "number of samples (default 35)"},
    {"v", "KM/H", "kx-ky: the fixed speed"},
    {"ky-min", "MN/m", "kx-ky: lower end of the Ky search (default 0.1)"},
    {"ky-max", "MN/m", "kx-ky: upper end of the Ky search (default 60)"},
    CLI_VEHICLE_OPTIONS,
    {NULL, NULL, NULL}};

static int plane_option(const cli_args *a, hm_plane *plane, int allow_kx_ky) {
  const char *name = cli_value(a, "plane");
  *plane = HM_PLANE_KX_V;
  if (!name || strcmp(name, "kx-v") == 0) return 0;
  if (strcmp(name, "ky-v") == 0) {
    *plane = HM_PLANE_KY_V;
    return 0;
  }
  if (allow_kx_ky && strcmp(name, "kx-ky") == 0) {
    *plane = HM_PLANE_KX_KY;
    return 0;
  }
  fprintf(stderr, "hunting: --plane must be kx-v, ky-v%s, got '%s'\n", allow_kx_ky ? " or kx-ky" : "", name);
  return 1;
}

int cmd_hopf_curve(const cli_args *a) {
  hm_vehicle veh;
  hm_hopf_curve_options o = {HM_PLANE_KX_V, 2.0, 20.0, 35, 0.0, 0.1, 60.0, 1e-9};
  double n_d = 35;
  if (cli_vehicle(a, &veh, NULL) || plane_option(a, &o.plane, 1) || cli_number(a, "from", &o.from) ||
      cli_number(a, "to", &o.to) || cli_number(a, "n", &n_d) || cli_number(a, "ky-min", &o.ky_min) ||
      cli_number(a, "ky-max", &o.ky_max))
    return 1;
  if (o.plane == HM_PLANE_KX_KY) {
    if (cli_speed_option(a, &o.speed_kmh)) return 1;
  } else if (cli_has(a, "v")) {
    fprintf(stderr, "hunting hopf-curve: --v is only for --plane kx-ky\n");
    return 1;
  }
  if (!(n_d >= 2 && n_d <= 100000) || n_d != floor(n_d) || !(o.to > o.from) || !(o.from > 0.0)) {
    fprintf(stderr, "hunting hopf-curve: need 0 < --from < --to and an integer --n in 2..100000\n");
    return 1;
  }
  o.n_points = (size_t)n_d;
  const size_t cap = 2 * o.n_points;
  hm_hopf_curve_point *pts = malloc(cap * sizeof *pts);
  hm_hopf_point gh[32];
  size_t np = 0, ng = 0;
  if (!pts) return cli_fail_status("hopf-curve", HM_ENOMEM);
  hm_status st = hm_hopf_curve(&veh, &o, pts, cap, &np, gh, 32, &ng);
  if (st != HM_OK) {
    free(pts);
    return cli_fail_status("Hopf curve", st);
  }
  json_writer w;
  jw_init(&w, stdout);
  jw_object(&w, NULL);
  jw_string(&w, "plane", o.plane == HM_PLANE_KX_V ? "kx-v" : o.plane == HM_PLANE_KY_V ? "ky-v" : "kx-ky");
  jw_array(&w, "points");
  for (size_t i = 0; i < np && i < cap; ++i) {
    const hm_hopf_point *h = &pts[i].point;
    jw_object(&w, NULL);
    jw_number(&w, "kx_mn_m", h->kx_mn_m);
    jw_number(&w, "ky_mn_m", h->ky_mn_m);
    jw_number(&w, "v_kmh", h->speed_kmh);
    jw_number(&w, "omega_rad_s", h->omega_rad_s);
    jw_number(&w, "l1", h->l1);
    jw_int(&w, "branch", pts[i].branch);
    jw_end_object(&w);
  }
  jw_end_array(&w);
  jw_array(&w, "gh");
  for (size_t i = 0; i < ng && i < 32; ++i) {
    jw_object(&w, NULL);
    jw_number(&w, "kx_mn_m", gh[i].kx_mn_m);
    jw_number(&w, "ky_mn_m", gh[i].ky_mn_m);
    jw_number(&w, "v_kmh", gh[i].speed_kmh);
    jw_number(&w, "omega_rad_s", gh[i].omega_rad_s);
    jw_number(&w, "l2", gh[i].l2);
    jw_end_object(&w);
  }
  jw_end_array(&w);
  jw_end_object(&w);
  jw_finish(&w);
  free(pts);
  return 0;
}

/* ---- lpc-curve ---- */

const cli_option lpc_curve_opts[] = {
    {"plane", "NAME", "kx-v (default) or ky-v: the fold speed as the stiffness varies"},
    {"from", "MN/m", "lower end of the stiffness range (default 0.1)"},
    {"to", "MN/m", "upper end (default 60)"},
    {"start", "MN/m", "stiffness where the folds to follow are found (default: middle of the range)"},
    {"v-min", "KM/H", "lowest speed followed (default 100)"},
    {"v-max", "KM/H", "highest speed followed (default 900)"},
    {"amp-max", "M", "largest cycle amplitude followed (default 0.020 m)"},
    CLI_VEHICLE_OPTIONS,
    {NULL, NULL, NULL}};

enum { MAX_LPC = 4096 };

/* Whether the fold lies on an already traced curve: the curve crosses p2 = start near its speed. */
static int on_curve(const hm_lpc_point *pts, size_t n, double start, const hm_cycle_event *fold) {
  for (size_t i = 1; i < n; ++i) {
    const hm_lpc_point *a = &pts[i - 1], *b = &pts[i];
    if ((a->p2 - start) * (b->p2 - start) > 0.0 || a->p2 == b->p2) continue;
    const double f = (start - a->p2) / (b->p2 - a->p2);
    const double v = a->p1 + f * (b->p1 - a->p1), amp = a->amp_y_m + f * (b->amp_y_m - a->amp_y_m);
    if (fabs(v - fold->point.param) < 0.05 && fabs(amp - fold->point.amp_y_m) < 2e-4) return 1;
  }
  return 0;
}

static void write_lpc_point(json_writer *w, const hm_lpc_point *p, const char *p2name) {
  jw_object(w, NULL);
  jw_number(w, p2name, p->p2);
  jw_number(w, "v_kmh", p->p1);
  jw_number(w, "amplitude_m", p->amp_y_m);
  jw_number(w, "period_s", p->period_s);
  jw_end_object(w);
}

/* lpc-curve's options: the vehicle with --start set on the plane's second parameter, the cycles' and curve's
 * options; 1 after an error message. */
static int lpc_setup(const cli_args *a, hm_vehicle *veh, hm_plane *plane, hm_cycle_options *o, hm_lpc_options *lo,
                     double *start, double *speed) {
  if (cli_vehicle(a, veh, NULL) || plane_option(a, plane, 0) || cycle_options(a, HM_PARAM_SPEED, o)) return 1;
  const hm_param p2 = *plane == HM_PLANE_KY_V ? HM_PARAM_KY : HM_PARAM_KX;
  hm_lpc_options_default(lo, p2);
  if (cli_number(a, "from", &lo->p2_min) || cli_number(a, "to", &lo->p2_max)) return 1;
  *start = 0.5 * (lo->p2_min + lo->p2_max);
  *speed = 500.0;
  if (cli_number(a, "start", start)) return 1;
  if (!(lo->p2_max > lo->p2_min) || !(*start >= lo->p2_min && *start <= lo->p2_max)) {
    fprintf(stderr, "hunting lpc-curve: need --from < --to and --start between them\n");
    return 1;
  }
  if (hm_param_set(veh, speed, p2, *start) != HM_OK) {
    fprintf(stderr, "hunting lpc-curve: invalid --start %g\n", *start);
    return 1;
  }
  return 0;
}

/* One curve's object: the fold it started from, its two directions' stops and statistics, its points. */
static void write_lpc_curve(json_writer *w, const hm_cycle_event *fold, const hm_cont_stats stats[2],
                            const hm_lpc_point *pts, size_t np, const char *p2name) {
  jw_object(w, NULL);
  jw_number(w, "from_fold_v_kmh", fold->point.param);
  jw_number(w, "from_fold_amplitude_m", fold->point.amp_y_m);
  jw_array(w, "stop_reasons");
  jw_string(w, NULL, hm_cont_stop_name(stats[0].stop));
  jw_string(w, NULL, hm_cont_stop_name(stats[1].stop));
  jw_end_array(w);
  jw_array(w, "continuation");
  write_cont_stats(w, NULL, &stats[0]);
  write_cont_stats(w, NULL, &stats[1]);
  jw_end_array(w);
  jw_array(w, "points");
  for (size_t k = 0; k < np; ++k) write_lpc_point(w, &pts[k], p2name);
  jw_end_array(w);
  jw_end_object(w);
}

/* The curves from every fold of the family not already on one (all: MAX_LPC points, cusps: 32), then the cusps; the
 * exit status (0, or 1 after an error message). */
static int write_lpc_curves(json_writer *w, const hm_vehicle *veh, double speed, const hm_cycle_options *o,
                            const hm_lpc_options *lo, const family *fam, double start, const char *p2name,
                            hm_lpc_point *all) {
  hm_lpc_point cusps[32];
  size_t used = 0, n_cusps = 0;
  int rc = 0;
  jw_array(w, "curves");
  for (size_t i = 0; i < fam->n_events && rc == 0; ++i) {
    const hm_cycle_event *fold = &fam->events[i];
    if (fold->kind != HM_CYCLE_LPC || on_curve(all, used, start, fold)) continue;
    size_t np = 0, nc = 0;
    hm_cont_stats stats[2];
    const hm_status st = hm_lpc_curve(veh, speed, o, lo, fold, all + used, MAX_LPC - used, &np, cusps + n_cusps,
                                      32 - n_cusps, &nc, stats);
    if (st != HM_OK) {
      rc = cli_fail_status("LPC curve", st);
      break;
    }
    write_lpc_curve(w, fold, stats, all + used, np, p2name);
    used += np;
    n_cusps += nc;
  }
  jw_end_array(w);
  jw_array(w, "cusps");
  for (size_t k = 0; k < n_cusps; ++k) write_lpc_point(w, &cusps[k], p2name);
  jw_end_array(w);
  return rc;
}

int cmd_lpc_curve(const cli_args *a) {
  hm_vehicle veh;
  hm_plane plane;
  hm_cycle_options o;
  hm_lpc_options lo;
  double start, speed;
  if (lpc_setup(a, &veh, &plane, &o, &lo, &start, &speed)) return 1;
  hm_hopf_point hopf;
  size_t n = 0;
  if (find_hopf(a, &veh, HM_PARAM_SPEED, speed, "v-min", "v-max", &hopf, 1, &n)) return 1;
  family fam = {0};
  if (run_family(&veh, speed, &hopf, &o, &fam)) {
    free(fam.points);
    return 1;
  }
  hm_lpc_point *all = malloc(MAX_LPC * sizeof *all);
  /* the document is built in memory and written only when complete: a failure half-way leaves no broken JSON */
  char *doc = NULL;
  size_t doc_len = 0;
  FILE *mem = all ? open_memstream(&doc, &doc_len) : NULL;
  if (!mem) {
    free(all);
    free(fam.points);
    return cli_fail_status("lpc-curve", HM_ENOMEM);
  }
  json_writer w;
  jw_init(&w, mem);
  jw_object(&w, NULL);
  jw_string(&w, "plane", plane == HM_PLANE_KY_V ? "ky-v" : "kx-v");
  jw_number(&w, "start", start);
  const hm_param p2 = plane == HM_PLANE_KY_V ? HM_PARAM_KY : HM_PARAM_KX;
  const int rc = write_lpc_curves(&w, &veh, speed, &o, &lo, &fam, start, hm_param_name(p2), all);
  jw_end_object(&w);
  jw_finish(&w);
  fclose(mem);
  if (rc == 0 && jw_ok(&w)) fwrite(doc, 1, doc_len, stdout);
  free(doc);
  free(all);
  free(fam.points);
  return rc;
}
