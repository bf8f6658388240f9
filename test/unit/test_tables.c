/* Boundary tables: lookups against closed forms and direct continuation, round trip, malformed files. */
#include <stdlib.h>
#include <string.h>

#include "hm_fixtures.h"
#include "hm_test.h"
#include "hunting_monitor/cycles.h"
#include "hunting_monitor/linear.h"
#include "hunting_monitor/tables.h"
#include "hunting_monitor/threads.h"

static hm_table table;
static hm_vehicle vehicle;

/* The Hopf speed from the table equals the closed form at any conicity (1/V^2 is affine in lambda). */
static void hopf_lookup_is_exact(void) {
  for (int i = 0; i < 50; ++i) {
    const double c = hm_test_uniform(0.12, 0.16);
    hm_table_lookup_result r;
    HM_CHECK(hm_table_lookup(table, c, 400.0, &r) == HM_OK, "lookup");
    double v;
    HM_CHECK(hm_linear_critical_speed(&vehicle, c, &v) == HM_OK, "closed form");
    HM_CHECK_REL(r.hopf_speed_kmh, hm_kmh_from_mps(v), 1e-9, "table Hopf speed vs closed form");
    HM_CHECK(r.origin_stable == (400.0 < r.hopf_speed_kmh) && !r.clamped, "flags");
  }
}

enum { CAP = 5000 };

/* The cycle family of the test vehicle (lambda(0) = 0.1358) computed directly with the tables' settings (150-700
 * km/h, up to 16 mm); *o gets the options used. */
static hm_cycle_point *direct_family_of(const hm_vehicle *veh, size_t *np, hm_cycle_event *ev, size_t *ne,
                                        hm_cycle_options *o) {
  hm_hopf_point h;
  size_t n;
  HM_CHECK(hm_hopf_find(veh, 500.0, HM_PARAM_SPEED, 100.0, 900.0, 1e-10, &h, 1, &n) == HM_OK && n == 1, "Hopf");
  hm_cycle_options_default(o, HM_PARAM_SPEED);
  o->p_min = 150.0;
  o->p_max = 700.0;
  o->amp_max_m = 0.016;
  hm_cycle_point *pts = malloc(CAP * sizeof *pts);
  *np = *ne = 0;
  HM_CHECK(hm_cycles_continue(veh, 500.0, &h, o, pts, CAP, np, ev, 16, ne, NULL) == HM_OK, "family");
  return pts;
}

static hm_cycle_point *direct_family(size_t *np, hm_cycle_event *ev, size_t *ne, hm_cycle_options *o) {
  return direct_family_of(&vehicle, np, ev, ne, o);
}

/* The smallest unstable cycle's amplitude at a speed on a directly continued family (INFINITY: none). */
static double direct_edge(const hm_cycle_point *pts, size_t np, double v_kmh) {
  double edge = INFINITY;
  for (size_t i = 1; i < np; ++i) {
    const hm_cycle_point *a = &pts[i - 1], *b = &pts[i];
    if ((a->param - v_kmh) * (b->param - v_kmh) > 0.0 || a->stable || b->stable) continue;
    const double f = (v_kmh - a->param) / (b->param - a->param);
    edge = fmin(edge, a->amp_y_m + f * (b->amp_y_m - a->amp_y_m));
  }
  return edge;
}

/* At lambda(0) = 0.1358 (between grid points): MODEL.md section 7 and a direct continuation agree with the
 * lookup within the table's stated errors. */
static void lookup_matches_direct_continuation(void) {
  hm_table_lookup_result r;
  HM_CHECK(hm_table_lookup(table, 0.1358, 420.0, &r) == HM_OK, "lookup");
  printf("  stated errors: speeds %.3f km/h, amplitudes %.3f mm\n", r.error_speed_kmh, r.error_amp_m * 1e3);
  /* against MODEL.md section 7 with its own precision (239.5 km/h to 0.05; "about 8.2 mm" to 0.05 mm), and the
   * fold the continuation locates directly (239.549 km/h, test_cycles), not against the table's own stated error */
  HM_CHECK_DELTA(r.lowest_cycle_speed_kmh, 239.549, 0.5, "lowest cycle speed (MODEL: 239.5, direct 239.549)");
  HM_CHECK(r.has_edge && r.consistent, "an edge at 420 km/h");
  HM_CHECK_DELTA(r.edge_amp_m, 8.2e-3, 0.1e-3, "edge at 420 km/h (MODEL: about 8.2 mm)");
  /* direct: the family at lambda(0) = 0.1358 */
  hm_cycle_options o;
  hm_cycle_event ev[16];
  size_t np = 0, ne = 0;
  hm_cycle_point *pts = direct_family(&np, ev, &ne, &o);
  const double speeds[] = {300.0, 400.0, 480.0};
  for (int k = 0; k < 3; ++k) {
    const double edge = direct_edge(pts, np, speeds[k]);
    HM_CHECK(hm_table_lookup(table, 0.1358, speeds[k], &r) == HM_OK, "lookup");
    printf("  V %.0f: edge direct %.4f mm, table %.4f mm\n", speeds[k], edge * 1e3, r.edge_amp_m * 1e3);
    HM_CHECK(isfinite(edge), "no unstable cycle at %g km/h on the direct family", speeds[k]);
    /* the interpolation error measured where neighbours agree is about 1 um (README): hold it to 10 um */
    HM_CHECK_DELTA(r.edge_amp_m, edge, 10e-6, "edge amplitude against direct continuation");
  }
  free(pts);
}

/* Outside the table's conicities (0.12-0.16) the widened lookup is on the cautious side of the truth (issue #27 item 8):
 * against the family continued directly at 0.18, 0.20 and 0.25 (worn beyond the table) and 0.11 and 0.10 (new), the
 * Hopf speed the closed form's (1e-9), the lowest cycle speed and the edge at 0.6, 0.8 and 0.95 of the Hopf speed at
 * or below the direct family's; where the clamped lookup (the end conicity's, as the monitor took it) was not: at 0.20
 * its lowest cycle speed 234.5 km/h for the family's 226.8, its edge at 400 km/h 8.13 mm for 7.40. */
static void widened_lookup_is_cautious_outside(void) {
  const double conicities[5] = {0.18, 0.20, 0.25, 0.11, 0.10};
  int clamped_below = 1; /* the clamped lookup was at or below the truth everywhere */
  for (int k = 0; k < 5; ++k) {
    hm_vehicle veh = vehicle;
    HM_CHECK(hm_vehicle_set_conicity_at_zero(&veh, conicities[k]) == HM_OK, "conicity %g", conicities[k]);
    hm_cycle_options o;
    hm_cycle_event ev[16];
    size_t np = 0, ne = 0;
    hm_cycle_point *pts = direct_family_of(&veh, &np, ev, &ne, &o);
    const double lowest = hm_cycles_lowest(pts, np, ev, ne), hopf = hm_linear_hopf_kmh(&veh, conicities[k]);
    hm_table_lookup_result w, c;
    HM_CHECK(hm_table_lookup_widened(table, conicities[k], 300.0, &w) == HM_OK && w.widened && w.clamped && isnan(w.l1),
             "widened, l1 not known (%g)", w.l1);
    HM_CHECK_REL(w.hopf_speed_kmh, hopf, 1e-9, "the widened Hopf speed against the closed form");
    HM_CHECK(hm_table_lookup(table, conicities[k], 300.0, &c) == HM_OK && c.clamped && !c.widened, "clamped");
    printf("  %.2f: Hopf %.1f km/h, lowest cycle speed direct %.1f, widened %.1f, clamped %.1f\n", conicities[k], hopf,
           lowest, w.lowest_cycle_speed_kmh, c.lowest_cycle_speed_kmh);
    HM_CHECK(w.lowest_cycle_speed_kmh <= lowest, "%.2f: lowest cycle speed %.1f above the family's %.1f",
             conicities[k], w.lowest_cycle_speed_kmh, lowest);
    clamped_below &= c.lowest_cycle_speed_kmh <= lowest;
    const double fractions[3] = {0.6, 0.8, 0.95};
    for (int j = 0; j < 3; ++j) {
      const double v = fractions[j] * hopf, edge = direct_edge(pts, np, v);
      HM_CHECK(hm_table_lookup_widened(table, conicities[k], v, &w) == HM_OK && hm_table_lookup(table, conicities[k],
               v, &c) == HM_OK, "lookups");
      printf("     at %.1f km/h: edge direct %.3f mm, widened %.3f, clamped %s%.3f\n", v, 1e3 * edge,
             w.has_edge ? 1e3 * w.edge_amp_m : NAN, c.has_edge && c.origin_stable ? "" : "(origin unstable) ",
             1e3 * c.edge_amp_m);
      HM_CHECK(isfinite(edge) && w.has_edge && w.origin_stable && w.edge_amp_m <= edge && w.edge_amp_m > 0.8 * edge,
               "%.2f at %.1f km/h: widened edge %.4f mm, direct %.4f", conicities[k], v, 1e3 * w.edge_amp_m, 1e3 * edge);
      clamped_below &= c.has_edge && c.edge_amp_m <= edge;
    }
    free(pts);
  }
  HM_CHECK(!clamped_below, "the clamped lookup was already cautious everywhere: the reference shows nothing");
  hm_table_lookup_result r;
  HM_CHECK(hm_table_lookup_widened(table, 0.13, 400.0, &r) == HM_OK && !r.widened && !r.clamped, "inside: a lookup");
  HM_CHECK(hm_table_lookup_widened(table, NAN, 400.0, &r) == HM_EDOMAIN, "NaN");
}

/* format -> parse -> format reproduces the text; lookups agree. */
static void round_trip(void) {
  size_t need = 0;
  HM_CHECK(hm_table_format(table, NULL, 0, &need) == HM_EINVAL && need > 100, "size query");
  char *a = malloc(need), *b = malloc(need);
  HM_CHECK(hm_table_format(table, a, need, &need) == HM_OK, "format");
  hm_table t2 = NULL;
  char err[128] = "";
  HM_CHECK(hm_table_parse(a, need - 1, &t2, err, sizeof err) == HM_OK, "parse: %s", err);
  size_t need2 = 0;
  HM_CHECK(t2 && hm_table_format(t2, b, need, &need2) == HM_OK && need2 == need && strcmp(a, b) == 0, "same text");
  hm_table_lookup_result r1, r2;
  HM_CHECK(hm_table_lookup(table, 0.137, 333.0, &r1) == HM_OK && hm_table_lookup(t2, 0.137, 333.0, &r2) == HM_OK,
           "lookups");
  HM_CHECK_DELTA(r2.edge_amp_m, r1.edge_amp_m, 1e-9, "lookup after round trip");
  hm_table_destroy(t2);
  free(a);
  free(b);
}

static void malformed_tables(void) {
  const char *good_head = "hunting_monitor_boundary_table 1\n"
                          "kx_mn_m 8.96 ky_mn_m 8.96 speed_min_kmh 150 speed_max_kmh 700 amp_max_m 0.016\n"
                          "error_hopf_kmh 0 error_lowest_kmh 0.1 error_edge_amp_m 1e-4\n";
  const struct {
    const char *body, *message;
  } cases[] = {
      {"conicity 0.1 hopf_kmh 600 l1 1 lowest_kmh 250 n 1\n600 0 1\n", "at least two conicities"},
      {"conicity 0.1 hopf_kmh 600 l1 1 lowest_kmh 250 n 1\n600 0 1\nconicity 0.2 hopf_kmh 500 l1 1 "
       "lowest_kmh 250 n 2\n500 0 1\n",
       "missing cycle points (1 of 2)"},
      {"conicity 0.1 hopf_kmh 600 l1 1 lowest_kmh 250 n 1\n600 x 1\nconicity 0.2 hopf_kmh 500 l1 1 "
       "lowest_kmh 250 n 1\n500 0 1\n",
       "line 5: expected 'v_kmh amplitude_m stable(0|1)'"},
      {"conicity 0.2 hopf_kmh 600 l1 1 lowest_kmh 250 n 1\n600 0 1\nconicity 0.1 hopf_kmh 500 l1 1 "
       "lowest_kmh 250 n 1\n500 0 1\n",
       "line 6: conicities must increase"},
      {"conicity 0.1 hopf_kmh nan l1 1 lowest_kmh 250 n 1\n600 0 1\nconicity 0.2 hopf_kmh 500 l1 1 "
       "lowest_kmh 250 n 1\n500 0 1\n",
       "line 4: 'hopf_kmh': bad number 'nan'"},
      {"conicity 0.1 hopf_kmh 600 l1 1 lowest_kmh 250 n 1\n600 0 2\nconicity 0.2 hopf_kmh 500 l1 1 "
       "lowest_kmh 250 n 1\n500 0 1\n",
       "line 5: expected"},
      /* implausible boundaries (found by fuzzing: read as OK "below the lowest speed with a cycle") */
      {"conicity 0.1 hopf_kmh 0 l1 1 lowest_kmh -5 n 1\n600 0 1\nconicity 0.2 hopf_kmh 500 l1 1 "
       "lowest_kmh 250 n 1\n500 0 1\n",
       "line 4: hopf_kmh must be in (0, 3000]"},
      {"conicity 0.1 hopf_kmh 600 l1 1 lowest_kmh -5 n 1\n600 0 1\nconicity 0.2 hopf_kmh 500 l1 1 "
       "lowest_kmh 250 n 1\n500 0 1\n",
       "line 4: lowest_kmh must be > 0 and not above hopf_kmh"},
      {"conicity 0.1 hopf_kmh 600 l1 1 lowest_kmh 650 n 1\n600 0 1\nconicity 0.2 hopf_kmh 500 l1 1 "
       "lowest_kmh 250 n 1\n500 0 1\n",
       "line 4: lowest_kmh must be > 0 and not above hopf_kmh"},
      {"conicity 0.1 hopf_kmh 600 l1 1 lowest_kmh 250 n 1\n100 0 1\nconicity 0.2 hopf_kmh 500 l1 1 "
       "lowest_kmh 250 n 1\n500 0 1\n",
       "line 5: cycle speed 100 km/h below lowest_kmh"},
      {"conicity 0.1 hopf_kmh 600 l1 1 lowest_kmh 250 n 1\n600 5 1\nconicity 0.2 hopf_kmh 500 l1 1 "
       "lowest_kmh 250 n 1\n500 0 1\n",
       "line 5: cycle amplitude 5 m is not plausible"},
      {"conicity 0.1 hopf_kmh 500 l1 1 lowest_kmh 250 n 1\n500 0 1\nconicity 0.2 hopf_kmh 600 l1 1 "
       "lowest_kmh 250 n 1\n600 0 1\n",
       "hopf_kmh must decrease as the conicity increases"},
      {"conicity -0.1 hopf_kmh 600 l1 1 lowest_kmh 250 n 1\n600 0 1\nconicity 0.2 hopf_kmh 500 l1 1 "
       "lowest_kmh 250 n 1\n500 0 1\n",
       "line 4: conicity must be > 0"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
    char text[1024], err[160] = "";
    snprintf(text, sizeof text, "%s%s", good_head, cases[i].body);
    hm_table t = (hm_table)0x1;
    const hm_status st = hm_table_parse(text, strlen(text), &t, err, sizeof err);
    HM_CHECK(st == HM_EPARSE, "case %zu: %s", i, hm_status_str(st));
    HM_CHECK(strstr(err, cases[i].message) != NULL, "case %zu: '%s' lacks '%s'", i, err, cases[i].message);
    HM_CHECK(t == (hm_table)0x1, "case %zu: output changed on failure", i);
  }
  char err[160] = "";
  hm_table t = NULL;
  HM_CHECK(hm_table_parse("not a table\n", 12, &t, err, sizeof err) == HM_EPARSE && strstr(err, "line 1"), "%s", err);
  HM_CHECK(hm_table_load_file("/nonexistent.tbl", &t, err, sizeof err) == HM_EIO, "missing file");
  /* header plausibility */
  const char *bad_head = "hunting_monitor_boundary_table 1\n"
                         "kx_mn_m -8.96 ky_mn_m 8.96 speed_min_kmh 150 speed_max_kmh 700 amp_max_m 0.016\n"
                         "error_hopf_kmh 0 error_lowest_kmh 0.1 error_edge_amp_m 1e-4\n";
  HM_CHECK(hm_table_parse(bad_head, strlen(bad_head), &t, err, sizeof err) == HM_EPARSE &&
               strstr(err, "kx_mn_m and ky_mn_m must be > 0"),
           "%s", err);
  hm_table_lookup_result r;
  memset(&r, 0x33, sizeof r);
  const hm_table_lookup_result before = r;
  HM_CHECK(hm_table_lookup(table, NAN, 300.0, &r) == HM_EDOMAIN, "NaN conicity");
  HM_CHECK(hm_table_lookup(table, 0.13, INFINITY, &r) == HM_EDOMAIN, "infinite speed");
  HM_CHECK(memcmp(&r, &before, sizeof r) == 0, "lookup output changed on failure");
}

/* A table is used only for the vehicle it was made for: the shipped table fits the default vehicle (its Hopf
 * speeds within 1e-3 km/h of the closed form), and is refused for other stiffnesses, other creep coefficients (same
 * Kx/Ky, different Hopf speeds) and when one record was altered. */
static void table_checked_against_vehicle(void) {
  hm_table shipped = NULL;
  char err[256] = "";
  HM_CHECK(hm_table_load_file(HM_SOURCE_DIR "/config/crh380_default.tbl", &shipped, err, sizeof err) == HM_OK, "%s", err);
  if (!shipped) return;
  HM_CHECK(hm_table_check_vehicle(shipped, &vehicle, 1e-3, err, sizeof err) == HM_OK, "shipped table: %s", err);
  hm_vehicle other = vehicle;
  other.stiffness_long_n_m = 9.7e6;
  HM_CHECK(hm_table_check_vehicle(shipped, &other, 1e-3, err, sizeof err) == HM_EDOMAIN &&
               strstr(err, "table made for Kx 8.96, Ky 8.96 MN/m, vehicle has Kx 9.7"),
           "other Kx: %s", err);
  other = vehicle;
  other.creep_long_n *= 1.1;
  HM_CHECK(hm_table_check_vehicle(shipped, &other, 1e-3, err, sizeof err) == HM_EDOMAIN &&
               strstr(err, "does not match the vehicle's"),
           "other creep: %s", err);
  hm_table_destroy(shipped);
  /* one Hopf speed altered by 2 km/h in the text */
  size_t need = 0;
  hm_table_format(table, NULL, 0, &need);
  char *text = malloc(need);
  HM_CHECK(text && hm_table_format(table, text, need, &need) == HM_OK, "format");
  if (!text) return;
  char *h = strstr(text, " hopf_kmh "); /* the first record's (not error_hopf_kmh) */
  if (h) ++h;
  hm_table altered = NULL;
  if (h) {
    const double v = strtod(h + 9, NULL);
    char *rest = strstr(h, " l1 ");
    char *copy = malloc(need + 64);
    snprintf(copy, need + 64, "%.*shopf_kmh %.10g%s", (int)(h - text), text, v - 2.0, rest);
    HM_CHECK(hm_table_parse(copy, strlen(copy), &altered, err, sizeof err) == HM_OK, "%s", err);
    HM_CHECK(altered && hm_table_check_vehicle(altered, &vehicle, 1.0, err, sizeof err) == HM_EDOMAIN, "altered");
    hm_table_destroy(altered);
    free(copy);
  }
  free(text);
}

static char *format(const hm_table t) {
  size_t len = 0;
  hm_table_format(t, NULL, 0, &len);
  char *text = malloc(len);
  if (text && hm_table_format(t, text, len, &len) != HM_OK) text[0] = 0;
  return text;
}

/* A runner that forgets the last job: the build must fail, not return a table with a hole. */
static void skip_last(void *runner, size_t n, hm_job_fn job, void *ctx) {
  (void)runner;
  for (size_t i = 0; i + 1 < n; ++i) job(ctx, i);
}

/* The families built on 1, 2 and 3 threads make the same table as the sequential build, byte for byte. */
static void parallel_build_equals_sequential(void) {
  hm_table_spec spec;
  hm_table_spec_default(&spec);
  spec.conicity_min = 0.12;
  spec.conicity_max = 0.16;
  spec.n_conicity = 3;
  char *ref = format(table);
  for (unsigned k = 1; k <= 3; ++k) {
    hm_threads threads = {k};
    hm_table t = NULL;
    HM_CHECK(hm_table_build_parallel(&vehicle, &spec, hm_threads_parallel_for, &threads, &t) == HM_OK, "build");
    char *text = t ? format(t) : NULL;
    HM_CHECK(ref && text && strcmp(ref, text) == 0, "%u threads: table differs from the sequential build", k);
    free(text);
    hm_table_destroy(t);
  }
  hm_table t = NULL;
  HM_CHECK(hm_table_build_parallel(&vehicle, &spec, skip_last, NULL, &t) == HM_EINVAL && t == NULL, "skipped job");
  free(ref);
}

/* A table refined at lambda(0) = 0.1358 (between its grid points) gives there the lowest cycle speed of the family
 * computed directly (its located fold, hm_cycles_lowest) and the unstable cycle that Newton finds at the speed;
 * the expected local error is zero there and largest mid-interval; the original table is untouched; a conicity
 * outside the table, on a curve, or another vehicle is refused. */
static void refined_table_is_exact_at_its_new_curve(void) {
  char *before = format(table);
  double e_mid_v, e_mid_a, e_node_v, e_node_a;
  HM_CHECK(hm_table_local_error(table, 0.13, &e_mid_v, &e_mid_a) == HM_OK, "local error mid-interval");
  HM_CHECK(hm_table_local_error(table, 0.14, &e_node_v, &e_node_a) == HM_OK, "local error on a curve");
  hm_table_lookup_result g;
  hm_table_lookup(table, 0.13, 400.0, &g);
  printf("  expected error mid-interval %.3f km/h %.4f mm (stated %.3f km/h), on a curve %.2g km/h\n", e_mid_v,
         e_mid_a * 1e3, g.error_speed_kmh, e_node_v);
  HM_CHECK_DELTA(e_mid_v, g.error_speed_kmh, 1e-12, "mid-interval: the measured error");
  HM_CHECK(e_node_v == 0.0 && e_node_a == 0.0, "on a curve: no interpolation error");
  hm_table r = NULL;
  HM_CHECK(hm_table_refine(table, &vehicle, 0.1358, &r) == HM_OK && r, "refine");
  if (!r) {
    free(before);
    return;
  }
  /* direct: the family at lambda(0) = 0.1358 with the table's settings */
  hm_cycle_options o;
  hm_cycle_event ev[16];
  size_t np = 0, ne = 0;
  hm_cycle_point *pts = direct_family(&np, ev, &ne, &o);
  hm_hopf_point h;
  size_t nh = 0;
  HM_CHECK(hm_hopf_find(&vehicle, 500.0, HM_PARAM_SPEED, 100.0, 900.0, 1e-10, &h, 1, &nh) == HM_OK, "Hopf");
  hm_table_lookup_result a, b;
  HM_CHECK(hm_table_lookup(table, 0.1358, 400.0, &a) == HM_OK && hm_table_lookup(r, 0.1358, 400.0, &b) == HM_OK,
           "lookups");
  const double lowest = hm_cycles_lowest(pts, np, ev, ne);
  printf("  lowest cycle speed: direct %.6f, refined table %.6f, original table %.6f km/h\n", lowest,
         b.lowest_cycle_speed_kmh, a.lowest_cycle_speed_kmh);
  HM_CHECK_DELTA(b.lowest_cycle_speed_kmh, lowest, 1e-6, "refined: lowest cycle speed");
  /* the unstable cycle at 400 km/h by Newton from the branch point nearest in speed among the unstable ones */
  const hm_cycle_point *near = NULL;
  for (size_t i = 0; i < np; ++i)
    if (!pts[i].stable && pts[i].amp_y_m < 0.0095 && pts[i].param < 505.0 &&
        (!near || fabs(pts[i].param - 400.0) < fabs(near->param - 400.0)))
      near = &pts[i];
  hm_cycle_point exact;
  HM_CHECK(near && hm_cycle_solve(&vehicle, 500.0, &o, 400.0, near->x0, near->period_s, &exact) == HM_OK,
           "cycle at 400 km/h");
  if (near) {
    printf("  unstable cycle at 400 km/h: Newton %.5f mm, refined table %.5f mm, original %.5f mm\n",
           exact.amp_y_m * 1e3, b.edge_amp_m * 1e3, a.edge_amp_m * 1e3);
    /* the table keeps the branch within 1 um (its decimation); the polyline's chord error adds about that */
    HM_CHECK_DELTA(b.edge_amp_m, exact.amp_y_m, 3e-6, "refined: unstable cycle at 400 km/h");
  }
  /* the family for display: exact on the refined table, its folds those the continuation located */
  hm_family_point fam[4096];
  size_t nf = 0;
  int on_curve = 0;
  HM_CHECK(hm_table_family(r, 0.1358, fam, 4096, &nf, &on_curve) == HM_OK && on_curve && nf > 2 && nf <= 4096, "family");
  HM_CHECK_DELTA(fam[0].speed_kmh, h.speed_kmh, 1e-9, "the family starts at the Hopf point");
  HM_CHECK(fam[0].amp_m == 0.0, "at amplitude 0");
  size_t n_folds = 0, matched = 0;
  for (size_t k = 0; k < nf; ++k) {
    if (!fam[k].fold) continue;
    ++n_folds;
    for (size_t j = 0; j < ne; ++j)
      matched += ev[j].kind == HM_CYCLE_LPC && fabs(ev[j].point.param - fam[k].speed_kmh) < 1e-6;
  }
  size_t n_lpc = 0;
  for (size_t j = 0; j < ne; ++j) n_lpc += ev[j].kind == HM_CYCLE_LPC;
  HM_CHECK(n_folds == n_lpc && matched == n_lpc && n_lpc == 3, "folds in the family %zu, located %zu, matched %zu",
           n_folds, n_lpc, matched);
  HM_CHECK(hm_table_family(table, 0.1358, fam, 4096, &nf, &on_curve) == HM_OK && !on_curve, "interpolated family");
  HM_CHECK_DELTA(fam[0].speed_kmh, h.speed_kmh, 1e-9, "scaled to the Hopf speed at 0.1358");
  HM_CHECK(hm_table_family(table, 0.5, fam, 4096, &nf, &on_curve) == HM_EDOMAIN, "outside");
  double e_v, e_a;
  HM_CHECK(hm_table_local_error(r, 0.1358, &e_v, &e_a) == HM_OK && e_v == 0.0 && e_a == 0.0, "refined: exact");
  HM_CHECK(hm_table_size(r, NULL, NULL) == hm_table_size(table, NULL, NULL) + 1, "one curve more");
  char *after = format(table);
  HM_CHECK(before && after && strcmp(before, after) == 0, "the original table changed");
  hm_table x = NULL;
  HM_CHECK(hm_table_refine(table, &vehicle, 0.5, &x) == HM_EDOMAIN && !x, "outside");
  HM_CHECK(hm_table_refine(table, &vehicle, 0.14, &x) == HM_EDOMAIN && !x, "on a curve");
  hm_vehicle other = vehicle;
  other.stiffness_long_n_m *= 1.1;
  HM_CHECK(hm_table_refine(table, &other, 0.1358, &x) == HM_EDOMAIN && !x, "another vehicle");
  free(pts);
  free(before);
  free(after);
  hm_table_destroy(r);
}

int main(void) {
  hm_vehicle_default(&vehicle);
  if (hm_test_small_table(&table) != HM_OK) {
    printf("FAIL table_build\n");
    return 1;
  }
  HM_RUN(hopf_lookup_is_exact);
  HM_RUN(lookup_matches_direct_continuation);
  HM_RUN(widened_lookup_is_cautious_outside);
  HM_RUN(round_trip);
  HM_RUN(malformed_tables);
  HM_RUN(table_checked_against_vehicle);
  HM_RUN(parallel_build_equals_sequential);
  HM_RUN(refined_table_is_exact_at_its_new_curve);
  hm_table_destroy(table);
  HM_TEST_EXIT();
}
