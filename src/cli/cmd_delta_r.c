/* hunting delta-r: wheel and rail profiles (CSV y_mm,z_mm) -> delta-r over lateral shifts (contact.h): JSON, and the
 * y_mm,delta_r_mm CSV that 'hunting equivalent-conicity' reads. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "cli.h"
#include "hunting_monitor/contact.h"

const cli_option delta_r_opts[] = {
    {"wheel", "FILE", "wheel profile CSV y_mm,z_mm: y from the flange back to the field side, z = radius - r0 (required)"},
    {"wheel-right", "FILE", "the right wheel's profile (default: the left one, mirrored)"},
    {"rail", "FILE", "rail profile CSV y_mm,z_mm in the rail's axes: y to the field side, z up (required)"},
    {"rail-right", "FILE", "the right rail's profile (default: the left one, mirrored)"},
    {"r0-mm", "MM", "nominal rolling radius at the measuring circle (default 460)"},
    {"r0-right-mm", "MM", "the right wheel's (default: --r0-mm)"},
    {"inclination", "N", "rails inclined 1:N toward the track centre (default 40; 0: upright)"},
    {"gauge-mm", "MM", "track gauge between the gauge points (default 1435)"},
    {"gauge-depth-mm", "MM", "the gauge point below the rail top (default 14)"},
    {"flange-back-mm", "MM", "distance between the flange backs (default 1360)"},
    {"measuring-circle-mm", "MM", "the measuring circle's y on the wheel profile (default 70)"},
    {"max-shift-mm", "MM", "lateral shifts from -MM to +MM (default 8)"},
    {"step-mm", "MM", "their step (default 0.1)"},
    {"roll", NULL, "let the rigid wheelset roll until both wheels rest on their rails (default: roll neglected, as in "
                   "EN 15302's reference cases)"},
    {"out", "FILE", "write y_mm,delta_r_mm for 'hunting equivalent-conicity --delta-r'"},
    {NULL, NULL, NULL}};

/* A y_mm,z_mm profile in metres into *p (one malloc'd block: free p->y_m). */
static int read_profile(const char *path, hm_profile *p) {
  double *m = NULL;
  size_t n = 0;
  if (cli_read_mm_columns("delta-r", path, "y_mm", "z_mm", &m, &n)) return 1;
  *p = (hm_profile){m, m + n, n};
  return 0;
}

/* The contact settings from the options (mm, 1:N), checked by the core; 0, or 1 with the reason on stderr. *max_shift
 * and *step [mm] the shifts' range and step; the gauge and flange-back distance [mm] as given. */
static int contact_settings(const cli_args *a, hm_contact_config *c, double *max_shift, double *step, double *gauge_mm,
                            double *fb_mm) {
  hm_contact_config_default(c);
  double r0 = 1e3 * c->r0_left_m, r0r = NAN, incl = 40.0, gauge = 1e3 * c->gauge_m, depth = 1e3 * c->gauge_depth_m,
         fb = 1e3 * c->flange_back_distance_m, mc = 1e3 * c->measuring_circle_m;
  *max_shift = 8.0, *step = 0.1;
  if (cli_number(a, "r0-mm", &r0) || cli_number(a, "r0-right-mm", &r0r) || cli_number(a, "inclination", &incl) ||
      cli_number(a, "gauge-mm", &gauge) || cli_number(a, "gauge-depth-mm", &depth) ||
      cli_number(a, "flange-back-mm", &fb) || cli_number(a, "measuring-circle-mm", &mc) ||
      cli_number(a, "max-shift-mm", max_shift) || cli_number(a, "step-mm", step))
    return 1;
  *gauge_mm = gauge, *fb_mm = fb; /* (as given, for the JSON) */
  if (!(incl == 0.0 || incl >= 10.0)) {
    fprintf(stderr, "hunting delta-r: --inclination must be 0 (upright) or N >= 10 for 1:N (got %g)\n", incl);
    return 1;
  }
  if (!(*max_shift > 0.0 && *max_shift <= 50.0) || !(*step > 0.0 && *step <= *max_shift) ||
      *max_shift / *step > 100000.0) {
    fprintf(stderr, "hunting delta-r: --max-shift-mm must be in (0, 50] and --step-mm in (0, max-shift], at most "
                    "100000 steps each side (got %g and %g)\n", *max_shift, *step);
    return 1;
  }
  c->r0_left_m = 1e-3 * r0;
  c->r0_right_m = 1e-3 * (isnan(r0r) ? r0 : r0r);
  c->inclination = incl == 0.0 ? 0.0 : 1.0 / incl;
  c->gauge_m = 1e-3 * gauge;
  c->gauge_depth_m = 1e-3 * depth;
  c->flange_back_distance_m = 1e-3 * fb;
  c->measuring_circle_m = 1e-3 * mc;
  c->include_roll = cli_has(a, "roll");
  char why[256] = "";
  if (hm_contact_config_validate(c, why, sizeof why) != HM_OK) {
    fprintf(stderr, "hunting delta-r: %s (in m)\n", why);
    return 1;
  }
  return 0;
}

/* --out: delta-r as fit's CSV (y_mm,delta_r_mm); 0, or 1 with the reason on stderr. */
static int write_delta_r_csv(const char *out, const double *s, const hm_contact_point *p, size_t n) {
  FILE *f = fopen(out, "w");
  int bad = !f || fprintf(f, "y_mm,delta_r_mm\n") < 0;
  for (size_t k = 0; !bad && k < n; ++k) bad = fprintf(f, "%.6f,%.9f\n", 1e3 * s[k], 1e3 * p[k].delta_r_m) < 0;
  if (f && fclose(f) != 0) bad = 1;
  if (bad) perror(out);
  return bad;
}

/* The JSON result: the settings and every column over the shifts; 0, or 1 out of memory. */
static int write_delta_r_json(const hm_contact_config *c, double gauge_mm, double fb_mm, const double *s,
                              const hm_contact_point *p, size_t n) {
  double *col = malloc(n * sizeof *col);
  if (!col) return cli_fail_status("delta-r", HM_ENOMEM);
  json_writer w;
  jw_init(&w, stdout);
  jw_object(&w, NULL);
  jw_number(&w, "inclination", c->inclination);
  jw_bool(&w, "roll_included", c->include_roll);
  jw_number(&w, "gauge_mm", gauge_mm);
  jw_number(&w, "flange_back_mm", fb_mm);
  jw_number(&w, "r0_left_mm", 1e3 * c->r0_left_m);
  jw_number(&w, "r0_right_mm", 1e3 * c->r0_right_m);
  for (size_t k = 0; k < n; ++k) col[k] = 1e3 * s[k];
  jw_numbers(&w, "y_mm", col, n);
  for (size_t k = 0; k < n; ++k) col[k] = 1e3 * p[k].delta_r_m;
  jw_numbers(&w, "delta_r_mm", col, n);
  for (size_t k = 0; k < n; ++k) col[k] = 1e3 * p[k].contact_left_m;
  jw_numbers(&w, "contact_left_mm", col, n);
  for (size_t k = 0; k < n; ++k) col[k] = 1e3 * p[k].contact_right_m;
  jw_numbers(&w, "contact_right_mm", col, n);
  for (size_t k = 0; k < n; ++k) col[k] = p[k].contact_angle_left_rad;
  jw_numbers(&w, "contact_angle_left_rad", col, n);
  for (size_t k = 0; k < n; ++k) col[k] = p[k].contact_angle_right_rad;
  jw_numbers(&w, "contact_angle_right_rad", col, n);
  for (size_t k = 0; k < n; ++k) col[k] = p[k].roll_rad;
  jw_numbers(&w, "roll_rad", col, n);
  jw_end_object(&w);
  jw_finish(&w);
  free(col);
  return 0;
}

int cmd_delta_r(const cli_args *a) {
  const char *wp = cli_value(a, "wheel"), *rp = cli_value(a, "rail");
  if (!wp || !rp) {
    fprintf(stderr, "hunting delta-r: give the profiles: --wheel FILE.csv --rail FILE.csv (y_mm,z_mm)\n");
    return 1;
  }
  hm_contact_config c;
  double max_shift, step, gauge_mm, fb_mm;
  if (contact_settings(a, &c, &max_shift, &step, &gauge_mm, &fb_mm)) return 1;
  hm_profile wl = {0}, wr = {0}, rl = {0}, rr = {0};
  const char *wrp = cli_value(a, "wheel-right"), *rrp = cli_value(a, "rail-right");
  const size_t n = 2 * (size_t)floor(max_shift / step + 1e-9) + 1;
  double *s = NULL;
  hm_contact_point *p = NULL;
  int rc = 1;
  if (read_profile(wp, &wl) || read_profile(rp, &rl) || (wrp && read_profile(wrp, &wr)) ||
      (rrp && read_profile(rrp, &rr)))
    goto done;
  s = malloc(n * sizeof *s);
  p = malloc(n * sizeof *p);
  if (!s || !p) {
    rc = cli_fail_status("delta-r", HM_ENOMEM);
    goto done;
  }
  for (size_t k = 0; k < n; ++k) s[k] = 1e-3 * step * ((double)k - (double)(n / 2));
  char why[256] = "";
  const hm_status st =
      hm_contact_delta_r(&c, &wl, wrp ? &wr : NULL, &rl, rrp ? &rr : NULL, s, n, p, why, sizeof why);
  if (st != HM_OK) {
    fprintf(stderr, "hunting delta-r: %s\n", why[0] ? why : hm_status_str(st));
    goto done;
  }
  const char *out = cli_value(a, "out");
  if (out && write_delta_r_csv(out, s, p, n)) goto done;
  rc = write_delta_r_json(&c, gauge_mm, fb_mm, s, p, n);
done:
  free((void *)wl.y_m), free((void *)wr.y_m), free((void *)rl.y_m), free((void *)rr.y_m);
  free(s), free(p);
  return rc;
}
