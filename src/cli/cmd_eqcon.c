/* hunting equivalent-conicity: delta-r CSV -> tan gamma_e per amplitude (EN 15302), JSON; optionally the CSV that
 * 'hunting fit-conicity --y-unit mm' reads. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "hunting_monitor/eqcon.h"

const cli_option equivalent_conicity_opts[] = {
    {"delta-r", "FILE", "CSV with header y_mm,delta_r_mm: r_left - r_right as the wheelset moves y to the left"},
    {"r0-mm", "MM", "nominal rolling radius r0 (default 460)"},
    {"contact-distance-mm", "MM", "distance between the contact points 2 e0 (default 1500)"},
    {"amplitudes", "FROM:TO:STEP", "amplitudes in mm, half the peak-to-peak motion (default 1:7.5:0.1)"},
    {"method", "integration|regression", "EN 15302's integration method (default) or the weighted linear regression"},
    {"csv-out", "FILE", "also write y_mm,conicity (each amplitude at -a and +a) for 'hunting fit-conicity --y-unit mm'"},
    {NULL, NULL, NULL}};

enum { MAX_AMPLITUDES = 10000 };

/* "FROM:TO:STEP" in mm: 0 and the count, or 1 (message printed). */
static int parse_amplitudes(const char *s, double *from, double *step, size_t *count) {
  double a, b, h;
  char tail;
  if (sscanf(s, "%lf:%lf:%lf%c", &a, &b, &h, &tail) != 3 || !(a > 0.0) || !(b >= a) || !(h > 0.0) ||
      !isfinite(b) || (b - a) / h + 1.0 > MAX_AMPLITUDES) {
    fprintf(stderr,
            "hunting equivalent-conicity: --amplitudes must be FROM:TO:STEP in mm with 0 < FROM <= TO, STEP > 0 and "
            "at most %d amplitudes (got '%s')\n",
            MAX_AMPLITUDES, s);
    return 1;
  }
  *from = a;
  *step = h;
  *count = (size_t)floor((b - a) / h + 1e-9) + 1;
  return 0;
}

/* The settings from the options: r0 and the contact distance (mm, checked by the core), the method; 0, or 1 with the
 * reason on stderr. */
static int eqcon_settings(const cli_args *a, hm_eqcon_config *cfg, double *r0_mm, double *c_mm,
                          hm_eqcon_method *method) {
  hm_eqcon_config_default(cfg);
  *r0_mm = 1e3 * cfg->r0_m, *c_mm = 1e3 * cfg->contact_distance_m;
  if (cli_number(a, "r0-mm", r0_mm) || cli_number(a, "contact-distance-mm", c_mm)) return 1;
  cfg->r0_m = 1e-3 * *r0_mm;
  cfg->contact_distance_m = 1e-3 * *c_mm;
  char why[256] = "";
  if (hm_eqcon_config_validate(cfg, why, sizeof why) != HM_OK) {
    fprintf(stderr, "hunting equivalent-conicity: --r0-mm / --contact-distance-mm: %s (in m)\n", why);
    return 1;
  }
  const char *m = cli_value(a, "method");
  *method = HM_EQCON_INTEGRATION;
  if (m && strcmp(m, "regression") == 0)
    *method = HM_EQCON_REGRESSION;
  else if (m && strcmp(m, "integration") != 0) {
    fprintf(stderr, "hunting equivalent-conicity: --method must be integration or regression, got '%s'\n", m);
    return 1;
  }
  return 0;
}

/* --csv-out: lambda(y) as fit-conicity's input, mirrored about y = 0 (y_mm,conicity; undefined amplitudes left
 * out); 0, or 1 with the reason on stderr. */
static int write_conicity_csv(const char *out, const double *amp, const double *con, size_t count) {
  FILE *f = fopen(out, "w");
  int bad = !f || fprintf(f, "y_mm,conicity\n") < 0;
  for (size_t k = count; !bad && k-- > 0;)
    if (isfinite(con[k])) bad = fprintf(f, "%.6g,%.10g\n", -amp[k], con[k]) < 0;
  for (size_t k = 0; !bad && k < count; ++k)
    if (isfinite(con[k])) bad = fprintf(f, "%.6g,%.10g\n", amp[k], con[k]) < 0;
  if (f && fclose(f) != 0) bad = 1;
  if (bad) perror(out);
  return bad;
}

/* tan gamma_e and the wavelength at count amplitudes from [mm] by step (NAN beyond the data); at 3 mm in *at3; 0, or
 * 1 with the reason on stderr. */
static int eqcon_columns(const hm_eqcon e, hm_eqcon_method method, double from, double step, size_t count,
                         double *amp, double *con, double *wl, double *at3) {
  for (size_t k = 0; k < count; ++k) {
    amp[k] = from + step * (double)k;
    hm_eqcon_result r;
    const hm_status s = hm_eqcon_at(e, method, 1e-3 * amp[k], &r);
    if (s != HM_OK && s != HM_EDOMAIN) { /* EDOMAIN: beyond the data, undefined (null) */
      fprintf(stderr, "hunting equivalent-conicity: at %g mm: %s\n", amp[k], hm_status_str(s));
      return 1;
    }
    con[k] = s == HM_OK ? r.tan_gamma_e : NAN;
    wl[k] = s == HM_OK ? r.wavelength_m : NAN;
  }
  hm_eqcon_result r3;
  *at3 = hm_eqcon_at(e, method, 3e-3, &r3) == HM_OK ? r3.tan_gamma_e : NAN;
  return 0;
}

int cmd_equivalent_conicity(const cli_args *a) {
  const char *path = cli_value(a, "delta-r");
  if (!path) {
    fprintf(stderr, "hunting equivalent-conicity: give the delta-r file: --delta-r FILE.csv (y_mm,delta_r_mm)\n");
    return 1;
  }
  hm_eqcon_config cfg;
  double r0_mm, c_mm, from, step;
  hm_eqcon_method method;
  if (eqcon_settings(a, &cfg, &r0_mm, &c_mm, &method)) return 1;
  size_t count;
  const char *amps = cli_value(a, "amplitudes");
  if (parse_amplitudes(amps ? amps : "1:7.5:0.1", &from, &step, &count)) return 1;
  double *y = NULL; /* and delta-r from y + n, in metres */
  size_t n = 0;
  if (cli_read_mm_columns("equivalent-conicity", path, "y_mm", "delta_r_mm", &y, &n)) return 1;
  const double *dr = y + n;
  double *amp = malloc(count * sizeof(double)), *con = malloc(count * sizeof(double)),
         *wl = malloc(count * sizeof(double));
  hm_eqcon e = NULL;
  int rc = 1;
  if (!amp || !con || !wl) {
    rc = cli_fail_status("equivalent-conicity", HM_ENOMEM);
    goto done;
  }
  char why[256] = "";
  const hm_status st = hm_eqcon_create(&cfg, y, dr, n, &e, why, sizeof why);
  if (st != HM_OK) {
    fprintf(stderr, "hunting equivalent-conicity: %s: %s\n", path, why[0] ? why : hm_status_str(st));
    goto done;
  }
  double at3 = NAN;
  if (eqcon_columns(e, method, from, step, count, amp, con, wl, &at3)) goto done;
  const char *out = cli_value(a, "csv-out");
  if (out && write_conicity_csv(out, amp, con, count)) goto done;
  json_writer w;
  jw_init(&w, stdout);
  jw_object(&w, NULL);
  jw_string(&w, "method", method == HM_EQCON_INTEGRATION ? "integration" : "regression");
  jw_number(&w, "r0_mm", r0_mm);
  jw_number(&w, "contact_distance_mm", c_mm);
  jw_int(&w, "points", (long)n);
  jw_number(&w, "equilibrium_mm", 1e3 * hm_eqcon_equilibrium_m(e));
  jw_numbers(&w, "amplitude_mm", amp, count);
  jw_numbers(&w, "conicity", con, count);
  jw_numbers(&w, "wavelength_m", wl, count);
  jw_number(&w, "conicity_3mm", at3);
  jw_end_object(&w);
  jw_finish(&w);
  rc = 0;
done:
  hm_eqcon_destroy(e);
  free(y), free(amp), free(con), free(wl);
  return rc;
}
