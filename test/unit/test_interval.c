/* The Hopf interval and the boundaries a level is decided on (interval.h), each number against a reference of its
 * own: the prior's Hopf speeds against the critical speeds by eigenvalue bisection (linear.h's second method, not the
 * closed form the interval uses); the table's value at the conicity in use within its stated error of the same; a
 * precise estimate's interval its own ends; a conicity beyond the table's the exact critical speed and said; the edge
 * inside the interval the table's at the optimistic end; a frame sensor on the wheelset's model kept on the prior;
 * bad settings, input and snapshots refused with the output untouched; the lookups follow the speed and the table, a
 * failed one forgets nothing, a held flag keeps its age across a shift of the time line. */
#include <math.h>
#include <string.h>

#include "hm_fixtures.h"
#include "hm_test.h"
#include "hunting_monitor/alarm.h"
#include "hunting_monitor/interval.h"
#include "hunting_monitor/linear.h"

static hm_table table;
static hm_vehicle vehicle;

/* The critical speed [km/h] by eigenvalues (bisection to 1e-9 m/s). */
static double hopf_eig(double conicity) {
  double v = NAN;
  const hm_status st = hm_linear_critical_speed_eig(&vehicle, conicity, 50.0, 400.0, 1e-9, &v);
  return st == HM_OK ? hm_kmh_from_mps(v) : NAN;
}

/* With the prior's point (0: the vehicle's lambda(0)) and range (0, 0: the point -+ 0.03). */
static hm_interval make_at(double fallback, double prior_low, double prior_high) {
  hm_alarm_config a;
  hm_alarm_config_default(&a);
  a.conicity_fallback = fallback, a.conicity_prior_low = prior_low, a.conicity_prior_high = prior_high;
  hm_interval_config c;
  hm_alarm_interval_config(&a, &c);
  hm_interval iv = NULL;
  char why[160] = "";
  HM_CHECK(hm_interval_create(&c, &vehicle, table, &iv, why, sizeof why) == HM_OK, "create: %s", why);
  return iv;
}

static hm_interval make(double prior_low, double prior_high) { return make_at(0.0, prior_low, prior_high); }

/* 0.16 +- 0.003, its interval at -+2 standard errors, as margin.h makes it (the Hopf speeds the eigenvalues'). */
static hm_margin_estimate identified(double conicity) {
  hm_margin_estimate g;
  memset(&g, 0, sizeof g);
  g.conicity_valid = g.hopf_model_valid = 1;
  g.conicity = conicity, g.conicity_se = 0.003;
  g.conicity_low = conicity - 0.006, g.conicity_high = conicity + 0.006;
  g.interval_z = 2.0;
  g.hopf_model_kmh = hopf_eig(conicity);
  g.hopf_model_low_kmh = hopf_eig(conicity + 0.006);
  g.hopf_model_high_kmh = hopf_eig(conicity - 0.006);
  return g;
}

/* The default prior (lambda(0) 0.1358 -+ 0.03) at 400 km/h: its ends' critical speeds, the table's value at the
 * fallback within its error of the eigenvalues' 517.618 km/h (MODEL.md), the edge at the fallback (the origin stable
 * there) the table's own. */
static void the_prior(void) {
  hm_interval iv = make(0.0, 0.0);
  double lo = 0.0, hi = 0.0;
  hm_interval_prior(iv, &lo, &hi);
  HM_CHECK(fabs(lo - 0.1058) < 1e-12 && fabs(hi - 0.1658) < 1e-12, "prior %.4f..%.4f", lo, hi);
  hm_hopf_interval h;
  HM_CHECK(hm_interval_update(iv, 400.0, NULL, 0.0, &h) == HM_OK, "update");
  printf("  prior: %.3f [%.3f, %.3f] km/h at %.4f\n", h.boundaries.hopf_speed_kmh, h.hopf_low_kmh, h.hopf_high_kmh,
         h.conicity);
  HM_CHECK(h.conicity_from_prior && !h.conicity_from_estimate && !h.model_interval_used && h.conicity == 0.1358 &&
               h.conicity_se == 0.0,
           "on the prior at 0.1358");
  HM_CHECK_DELTA(h.hopf_low_kmh, hopf_eig(0.1658), 1e-6, "lower end: the critical speed at the prior's high end");
  HM_CHECK_DELTA(h.hopf_high_kmh, hopf_eig(0.1058), 1e-6, "upper end: the critical speed at the prior's low end");
  HM_CHECK(fabs(h.boundaries.hopf_speed_kmh - 517.618) <= h.boundaries.error_speed_kmh + 1e-3,
           "the table's %.3f km/h within its error %.3f of 517.618", h.boundaries.hopf_speed_kmh,
           h.boundaries.error_speed_kmh);
  hm_table_lookup_result r;
  HM_CHECK(hm_table_lookup(table, 0.1358, 400.0, &r) == HM_OK && r.origin_stable && r.has_edge &&
               h.edge_used_m == r.edge_amp_m && h.conicity_outside_table == 0,
           "edge %.5f m against the table's %.5f", h.edge_used_m, r.edge_amp_m);
  hm_interval_destroy(iv);
}

/* A precise estimate inside the prior is used alone: its interval as given, the WARN rule's inputs with it; the
 * same from a frame sensor on the wheelset's model stays on the prior (the model does not hold the frame). */
static void a_precise_estimate_and_the_sensor(void) {
  const hm_margin_estimate g = identified(0.16);
  for (int frame = 0; frame < 2; ++frame) {
    hm_interval iv = make(0.0, 0.0);
    if (frame) hm_interval_set_measurement_point(iv, HM_POINT_BOGIE_FRAME);
    hm_hopf_interval h;
    HM_CHECK(hm_interval_update(iv, 450.0, &g, 0.0, &h) == HM_OK, "update");
    if (!frame) {
      HM_CHECK(h.conicity_from_estimate && h.model_interval_used && h.conicity == 0.16 && h.conicity_se == 0.003 &&
                   h.interval_z == 2.0 && !h.estimate_with_prior,
               "alone");
      HM_CHECK_DELTA(h.hopf_low_kmh, hopf_eig(0.166), 1e-6, "the estimate's lower end");
      HM_CHECK_DELTA(h.hopf_high_kmh, hopf_eig(0.154), 1e-6, "the estimate's upper end");
      HM_CHECK_DELTA(h.boundaries.hopf_speed_kmh, hopf_eig(0.16), 1e-6, "the point: the critical speed at 0.16");
    } else {
      HM_CHECK(!h.conicity_from_estimate && !h.model_interval_used && h.conicity == 0.1358, "frame: on the prior");
      HM_CHECK_DELTA(h.hopf_low_kmh, hopf_eig(0.1658), 1e-6, "frame: the prior's lower end");
    }
    hm_interval_destroy(iv);
  }
}

/* A conicity beyond the table's range (0.12-0.16): the exact critical speed, said by conicity_outside_table; inside
 * the interval above the point the edge is the table's at the optimistic end. */
static void beyond_the_table_and_the_edge(void) {
  hm_interval iv = make_at(0.2, 0.17, 0.23);
  hm_hopf_interval h;
  HM_CHECK(hm_interval_update(iv, 300.0, NULL, 0.0, &h) == HM_OK, "update");
  HM_CHECK(h.conicity == 0.2 && h.conicity_outside_table == 1, "0.2 above the table: %d", h.conicity_outside_table);
  HM_CHECK_DELTA(h.boundaries.hopf_speed_kmh, hopf_eig(0.2), 1e-6, "beyond the table: the critical speed at 0.2");
  hm_interval_destroy(iv);
  /* 0.16 +- 0.003 at 1 km/h above its point: the origin unstable at 0.16, the edge that of 0.154, the optimistic end */
  const hm_margin_estimate g = identified(0.16);
  iv = make(0.0, 0.0);
  const double v = g.hopf_model_kmh + 1.0;
  HM_CHECK(hm_interval_update(iv, v, &g, 0.0, &h) == HM_OK && !h.boundaries.origin_stable, "above the point");
  hm_table_lookup_result r;
  HM_CHECK(hm_table_lookup(table, 0.154, v, &r) == HM_OK && r.origin_stable && r.has_edge, "the optimistic end's");
  printf("  at %.1f km/h (point %.1f): edge %.5f m, the table's at 0.154 %.5f m\n", v, g.hopf_model_kmh,
         h.edge_used_m, r.edge_amp_m);
  HM_CHECK(h.edge_used_m == r.edge_amp_m && h.edge_used_m > 0.0, "the edge at the optimistic end");
  hm_interval_destroy(iv);
}

/* Refused with the reason and nothing written: a prior without the fallback, settings out of range, a NaN time, a
 * snapshot out of range; a restore brings the estimate's use back. */
static void refusals_and_the_snapshot(void) {
  hm_interval_config c = {1, 0.01, 0.0, 0.15, 0.30};
  hm_interval bad = (hm_interval)0x1;
  char why[200] = "";
  HM_CHECK(hm_interval_create(&c, &vehicle, table, &bad, why, sizeof why) == HM_EDOMAIN && bad == (hm_interval)0x1 &&
               strstr(why, "must hold the fallback conicity 0.1358"),
           "a prior without the fallback: %s", why);
  c.conicity_prior_low = 0.0, c.conicity_prior_high = 0.0, c.conicity_max_se = 0.0;
  HM_CHECK(hm_interval_config_validate(&c, why, sizeof why) == HM_EDOMAIN && strstr(why, "conicity_max_se"), "%s",
           why);
  c.conicity_max_se = 0.01, c.conicity_prior_high = 0.2;
  HM_CHECK(hm_interval_config_validate(&c, why, sizeof why) == HM_EDOMAIN && strstr(why, "conicity_prior_high"),
           "one end only: %s", why);
  hm_interval iv = make(0.0, 0.0);
  hm_hopf_interval h, h0;
  memset(&h, 0x5a, sizeof h);
  h0 = h;
  HM_CHECK(hm_interval_update(iv, 400.0, NULL, NAN, &h) == HM_EINVAL && memcmp(&h, &h0, sizeof h) == 0,
           "a NaN time: refused, nothing written");
  const hm_margin_estimate g = identified(0.16);
  HM_CHECK(hm_interval_update(iv, 400.0, &g, 0.0, &h) == HM_OK && h.conicity_from_estimate, "alone");
  hm_interval_snapshot s;
  hm_interval_take_snapshot(iv, &s);
  HM_CHECK(s.precise == 1 && s.se_ok == 1 && s.precise_lost == 0, "snapshot %d %d %d", s.precise, s.se_ok,
           s.precise_lost);
  hm_interval_snapshot wrong = s;
  wrong.se_ok = 2;
  HM_CHECK(hm_interval_restore(iv, &wrong, why, sizeof why) == HM_EDOMAIN && strstr(why, "interval: se_ok"), "%s",
           why);
  hm_interval other = make(0.0, 0.0);
  HM_CHECK(hm_interval_restore(other, &s, why, sizeof why) == HM_OK, "restore: %s", why);
  hm_interval_snapshot back;
  hm_interval_take_snapshot(other, &back);
  HM_CHECK(back.precise == 1 && back.se_ok == 1 && back.precise_lost == 0, "restored");
  hm_interval_restart(other);
  hm_interval_take_snapshot(other, &back);
  HM_CHECK(back.precise == 0 && back.se_ok == 0, "a restart forgets the estimate's use");
  hm_interval_destroy(iv);
  hm_interval_destroy(other);
}

/* The lookups follow the speed and a new table (no stale cache); a prior narrower than the table's error is widened
 * to the table's value -+ its error; a failed lookup leaves the output and the flags' memory as they were; a shift of
 * the time line keeps a held flag's age. */
static void cache_widening_failure_and_time(void) {
  hm_interval iv = make(0.1358 - 1e-5, 0.1358 + 1e-5);
  hm_hopf_interval h;
  hm_table_lookup_result r;
  HM_CHECK(hm_interval_update(iv, 300.0, NULL, 0.0, &h) == HM_OK && hm_interval_update(iv, 400.0, NULL, 1.0, &h) ==
               HM_OK && hm_table_lookup(table, 0.1358, 400.0, &r) == HM_OK && h.edge_used_m == r.edge_amp_m,
           "the edge at 400 km/h after 300: %.6f against %.6f", h.edge_used_m, r.edge_amp_m);
  HM_CHECK_DELTA(h.hopf_low_kmh, r.hopf_speed_kmh - r.error_speed_kmh, 1e-9, "narrow prior: the table's value less its error");
  HM_CHECK_DELTA(h.hopf_high_kmh, r.hopf_speed_kmh + r.error_speed_kmh, 1e-9, "narrow prior: plus its error");
  HM_CHECK(r.error_speed_kmh > 0.05, "the table's error %.3f km/h exceeds the prior's width", r.error_speed_kmh);
  hm_table other = NULL;
  hm_table_spec spec;
  hm_table_spec_default(&spec);
  spec.conicity_min = 0.10, spec.conicity_max = 0.20, spec.n_conicity = 3;
  HM_CHECK(hm_table_build(&vehicle, &spec, &other) == HM_OK, "a second table");
  hm_interval_set_table(iv, other);
  hm_table_lookup_result r2;
  HM_CHECK(hm_interval_update(iv, 400.0, NULL, 2.0, &h) == HM_OK && hm_table_lookup(other, 0.1358, 400.0, &r2) == HM_OK &&
               h.boundaries.error_speed_kmh == r2.error_speed_kmh && r2.error_speed_kmh != r.error_speed_kmh,
           "the new table's: error %.4f against %.4f (old %.4f)", h.boundaries.error_speed_kmh, r2.error_speed_kmh,
           r.error_speed_kmh);
  hm_interval_set_table(iv, table);
  hm_table_destroy(other);
  hm_interval_destroy(iv);
  /* a failed lookup (a speed the table cannot look up) after a precise estimate: nothing written, nothing forgotten */
  iv = make(0.0, 0.0);
  const hm_margin_estimate g = identified(0.16);
  HM_CHECK(hm_interval_update(iv, 450.0, &g, 0.0, &h) == HM_OK && h.conicity_from_estimate, "alone");
  hm_interval_snapshot before, after;
  hm_interval_take_snapshot(iv, &before);
  hm_hopf_interval h0 = h;
  hm_margin_estimate worse = g;
  worse.conicity_se = 0.02; /* (would drop the estimate's use, were it weighed) */
  HM_CHECK(hm_interval_update(iv, NAN, &worse, 1.0, &h) != HM_OK && memcmp(&h, &h0, sizeof h) == 0,
           "a failed lookup: refused, nothing written");
  hm_interval_take_snapshot(iv, &after);
  HM_CHECK(memcmp(&before, &after, sizeof before) == 0, "a failed lookup: the flags' memory kept");
  hm_interval_destroy(iv);
  /* model_mismatch held for HM_ALARM_FLAG_CLEAR_S (20 s) after it clears, across a shift of the time line */
  for (int shift = 0; shift < 2; ++shift) {
    iv = make(0.0, 0.0);
    hm_margin_estimate mm = g;
    mm.model_mismatch = 1;
    hm_interval_update(iv, 450.0, &mm, 0.0, &h);
    mm.model_mismatch = 0;
    hm_interval_update(iv, 450.0, &mm, 5.0, &h); /* false from 5 s: held until 25 s */
    if (shift) hm_interval_shift_time(iv, 100.0);
    hm_interval_update(iv, 450.0, &mm, 20.0 + 100.0 * shift, &h);
    HM_CHECK(h.model_mismatch, "shift %d: held 15 s after it cleared", shift);
    hm_interval_update(iv, 450.0, &mm, 26.0 + 100.0 * shift, &h);
    HM_CHECK(!h.model_mismatch, "shift %d: cleared 21 s after", shift);
    hm_interval_destroy(iv);
  }
  hm_interval_snapshot bad = {1, 1, 3};
  char why[120] = "";
  HM_CHECK(hm_interval_snapshot_validate(&bad, why, sizeof why) == HM_EDOMAIN && strstr(why, "precise_lost"), "%s",
           why);
}

int main(void) {
  hm_vehicle_default(&vehicle);
  if (hm_test_small_table(&table) != HM_OK) {
    printf("FAIL table_build\n");
    return 1;
  }
  HM_RUN(the_prior);
  HM_RUN(a_precise_estimate_and_the_sensor);
  HM_RUN(beyond_the_table_and_the_edge);
  HM_RUN(refusals_and_the_snapshot);
  HM_RUN(cache_widening_failure_and_time);
  hm_table_destroy(table);
  HM_TEST_EXIT();
}
