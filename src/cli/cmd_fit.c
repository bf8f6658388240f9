/* hunting fit-conicity: read (y, conicity) CSV, fit lambda(y), print JSON, optionally write a vehicle config. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "hunting_monitor/config.h"
#include "hunting_monitor/conicity_fit.h"
#include "hunting_monitor/linear.h"

const cli_option fit_conicity_opts[] = {
    {"terms", "N", "number of Gaussian terms, 1..8 (default 2)"},
    {"symmetric", NULL, "pairs at +-b with shared amplitude and width (an odd N adds one term at y = 0)"},
    {"no-constant", NULL, "fix the constant term at 0 (like MATLAB's gauss3)"},
    {"y-unit", "m|mm", "unit of the first column (default m)"},
    {"write-config", "FILE", "write the vehicle (--config or the default) with the fitted conicity as YAML"},
    CLI_VEHICLE_OPTIONS,
    {NULL, NULL, NULL}};

static int write_config(const char *path, const hm_vehicle *veh, const char *source) {
  char comment[512];
  snprintf(comment, sizeof comment,
           "Vehicle config written by 'hunting fit-conicity' from %s.\n"
           "conicity: least-squares fit of lambda(y) = constant + Gaussians to those data.",
           source);
  size_t need = 0;
  hm_config_format_vehicle(veh, "fitted", comment, NULL, 0, &need);
  char *buf = malloc(need);
  FILE *f = buf ? fopen(path, "w") : NULL;
  int rc = !buf || !f || hm_config_format_vehicle(veh, "fitted", comment, buf, need, &need) != HM_OK ||
           fputs(buf, f) == EOF;
  if (f && fclose(f) != 0) rc = 1;
  if (rc) perror(path);
  free(buf);
  return rc;
}

static void write_result(const hm_fit_result *r, const hm_fit_options *o, const hm_vehicle *veh) {
  json_writer w;
  jw_init(&w, stdout);
  jw_object(&w, NULL);
  jw_int(&w, "terms", (long)o->n_terms);
  jw_bool(&w, "symmetric", o->symmetric);
  jw_object(&w, "constant");
  jw_number(&w, "value", r->conicity.constant);
  jw_number(&w, "stderr", o->fit_constant ? r->constant_se : 0.0);
  jw_bool(&w, "fitted", o->fit_constant);
  jw_end_object(&w);
  jw_array(&w, "gaussians");
  for (size_t k = 0; k < r->conicity.n_terms; ++k) {
    const hm_gaussian *g = &r->conicity.terms[k];
    jw_object(&w, NULL);
    jw_number(&w, "amplitude", g->amplitude);
    jw_number(&w, "amplitude_stderr", r->amplitude_se[k]);
    jw_number(&w, "center_m", g->center_m);
    jw_number(&w, "center_m_stderr", r->center_se[k]);
    jw_number(&w, "width_m", g->width_m);
    jw_number(&w, "width_m_stderr", r->width_se[k]);
    jw_end_object(&w);
  }
  jw_end_array(&w);
  jw_bool(&w, "stderr_available", r->se_available);
  jw_number(&w, "sse", r->sse);
  jw_number(&w, "r2", r->r2);
  jw_number(&w, "adj_r2", r->adj_r2);
  jw_number(&w, "rmse", r->rmse);
  jw_int(&w, "n_points", (long)r->n_points);
  jw_int(&w, "n_params", (long)r->n_params);
  jw_int(&w, "dof", (long)r->dof);
  jw_int(&w, "iterations", (long)r->iterations);
  jw_int(&w, "starts_tried", (long)r->starts_tried);
  double l0, v_mps;
  hm_conicity_eval(&r->conicity, 0.0, &l0, NULL);
  jw_number(&w, "conicity_at_zero", l0);
  /* what the fitted conicity means for the vehicle: its linear critical (Hopf) speed */
  if (hm_linear_critical_speed(veh, l0, &v_mps) == HM_OK)
    jw_number(&w, "hopf_kmh", hm_kmh_from_mps(v_mps));
  else
    jw_number(&w, "hopf_kmh", NAN);
  jw_end_object(&w);
  jw_finish(&w);
}

int cmd_fit_conicity(const cli_args *a) {
  hm_vehicle veh;
  hm_fit_options o;
  hm_fit_options_default(&o);
  double terms = 2;
  if (cli_vehicle(a, &veh, NULL) || cli_number(a, "terms", &terms)) return 1;
  if (!a->positional) {
    fprintf(stderr, "hunting fit-conicity: give the data file: hunting fit-conicity DATA.csv [options]\n");
    return 1;
  }
  if (!(terms >= 1 && terms <= HM_CONICITY_MAX_TERMS) || terms != floor(terms)) {
    fprintf(stderr, "hunting fit-conicity: --terms must be an integer in 1..%d\n", HM_CONICITY_MAX_TERMS);
    return 1;
  }
  o.n_terms = (size_t)terms;
  o.symmetric = cli_has(a, "symmetric");
  o.fit_constant = !cli_has(a, "no-constant");
  const char *unit = cli_value(a, "y-unit");
  double scale = 1.0;
  if (unit && strcmp(unit, "mm") == 0)
    scale = 1e-3;
  else if (unit && strcmp(unit, "m") != 0) {
    fprintf(stderr, "hunting fit-conicity: --y-unit must be m or mm, got '%s'\n", unit);
    return 1;
  }
  char header[2][64];
  double *d = NULL;
  size_t n = 0;
  if (cli_read_csv(a->positional, 2, header, &d, &n, 0)) return 1;
  const char *y_name = scale == 1.0 ? "y_m" : "y_mm";
  if (strcmp(header[0], y_name) != 0 || strcmp(header[1], "conicity") != 0) {
    fprintf(stderr, "hunting fit-conicity: %s: the header must be '%s,conicity' (got '%s,%s')%s\n", a->positional,
            y_name, header[0], header[1], scale == 1.0 ? "; for millimetres use --y-unit mm" : "");
    free(d);
    return 1;
  }
  double *y = malloc((n ? n : 1) * sizeof(double)), *l = malloc((n ? n : 1) * sizeof(double));
  if (!y || !l) {
    free(d), free(y), free(l);
    return cli_fail_status("fit-conicity", HM_ENOMEM);
  }
  for (size_t i = 0; i < n; ++i) {
    y[i] = d[2 * i] * scale;
    l[i] = d[2 * i + 1];
  }
  hm_fit_result r;
  char why[256] = "";
  const hm_status st = hm_conicity_fit(y, l, n, &o, &r, why, sizeof why);
  free(d), free(y), free(l);
  if (st != HM_OK) {
    fprintf(stderr, "hunting fit-conicity: %s: %s\n", a->positional, why[0] ? why : hm_status_str(st));
    return 1;
  }
  veh.conicity = r.conicity;
  char vwhy[160];
  if (hm_vehicle_validate(&veh, vwhy, sizeof vwhy) != HM_OK) {
    fprintf(stderr, "hunting fit-conicity: the fitted conicity is not a valid vehicle conicity: %s\n", vwhy);
    return 1;
  }
  const char *cfg = cli_value(a, "write-config");
  if (cfg && write_config(cfg, &veh, a->positional)) return 1;
  write_result(&r, &o, &veh);
  return 0;
}
