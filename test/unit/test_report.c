/* The status as published (report.h): each gating rule the header states, checked field by field on a status whose
 * every number is set to a known finite value and whose validity flags are switched one at a time; the field list
 * against the record (every member listed once, in bounds, of its kind's size). */
#include <math.h>
#include <string.h>

#include "hm_test.h"
#include "hunting_monitor/report.h"

/* A status with every validity on and known numbers. */
static hm_monitor_status full(void) {
  hm_monitor_status st;
  memset(&st, 0, sizeof st);
  st.estimate.speed_valid = 1;
  st.estimate.speed_kmh = 432.0;
  st.mode.valid = 1;
  st.mode.poles = 2;
  st.mode.frequency_hz = 13.9;
  st.mode.decay_rate_1_s = -2.5;
  st.mode.second_frequency_hz = 14.6;
  st.mode.second_decay_rate_1_s = -7.0;
  st.mode.lines_found = 1;
  st.mode.line_fundamental_hz = 4.8;
  st.mode_speed_kmh = 432.0;
  st.mode_speed_spread_kmh = 1.5;
  st.mode_steady = 1;
  st.line_wavelength_m = 25.0;
  st.margin.conicity_valid = 1;
  st.margin.conicity = 0.15;
  st.margin.hopf_model_valid = 1;
  st.margin.hopf_model_kmh = 480.0;
  st.assessment.boundaries_valid = 1;
  st.assessment.boundaries.hopf_speed_kmh = 481.0;
  st.assessment.hopf_low_kmh = 470.0;
  st.assessment.warn_from_kmh = 471.0;
  st.assessment.edge_used_m = 0.004;
  st.assessment.hunted_at_kmh = 455.0;
  return st;
}

static void gating_rules(void) {
  hm_report r;
  hm_monitor_status st = full();
  hm_report_make(&st, 0.0, &r);
  HM_CHECK(r.mode_frequency_hz == 13.9 && r.mode_second_decay_rate_1_s == -7.0 && r.line_wavelength_m == 25.0 &&
               r.conicity_estimate == 0.15 && r.hopf_model_kmh == 480.0 && r.hopf_kmh == 481.0 &&
               r.warn_from_kmh == 471.0 && r.cycles_valid && r.unstable_cycle_amplitude_m == 0.004,
           "all valid: every number shown");
  /* a fit over a changing speed: shown, not used */
  st.mode_steady = 0;
  hm_report_make(&st, 0.0, &r);
  HM_CHECK(!r.mode_valid && r.mode_fit_valid && r.decay_rate_1_s == -2.5, "not steady: the fit shown, flagged");
  /* no valid fit: no mode numbers, and a single pair has no second */
  st.mode.valid = 0;
  hm_report_make(&st, 0.0, &r);
  HM_CHECK(isnan(r.mode_frequency_hz) && isnan(r.decay_rate_1_s) && isnan(r.mode_speed_kmh) && r.mode_pole_pairs == 0,
           "no fit: NAN");
  st = full();
  st.mode.poles = 1;
  hm_report_make(&st, 0.0, &r);
  HM_CHECK(r.mode_frequency_hz == 13.9 && isnan(r.mode_second_frequency_hz), "one pair: no second");
  /* a line's numbers only where found */
  st = full();
  st.mode.lines_found = 0;
  hm_report_make(&st, 0.0, &r);
  HM_CHECK(isnan(r.line_fundamental_hz) && isnan(r.line_wavelength_m), "no line: NAN");
  /* the model's whole spectrum (its conicity and the description's check, shape and share) only where fitted for this
   * window (spectrum_valid > 0; -1: asked and not fitted) */
  st = full();
  st.mode.spectrum_valid = 1;
  st.mode.spectrum_conicity = 0.152;
  st.mode.spectrum_shape_chi2 = 7.5;
  st.mode.spectrum_model_share = 0.97;
  hm_report_make(&st, 0.0, &r);
  HM_CHECK(r.spectrum_conicity == 0.152 && r.spectrum_shape_chi2 == 7.5 && r.spectrum_model_share == 0.97,
           "a spectrum fitted: its conicity, shape and share shown");
  st.mode.spectrum_valid = -1;
  hm_report_make(&st, 0.0, &r);
  HM_CHECK(isnan(r.spectrum_conicity) && isnan(r.spectrum_shape_chi2) && isnan(r.spectrum_model_share),
           "asked and not fitted: NAN");
  /* the margin's estimates each by its own validity */
  st = full();
  st.margin.conicity_valid = 0;
  hm_report_make(&st, 0.0, &r);
  HM_CHECK(isnan(r.conicity_estimate) && r.hopf_model_kmh == 480.0, "conicity invalid alone");
  /* stale boundaries are never shown as current; the hunted-at memory is */
  st = full();
  st.assessment.boundaries_valid = 0;
  hm_report_make(&st, 0.0, &r);
  HM_CHECK(isnan(r.hopf_kmh) && isnan(r.hopf_kmh_low) && isnan(r.warn_from_kmh) && !r.cycles_valid &&
               isnan(r.unstable_cycle_amplitude_m) && r.hunted_at_kmh == 455.0,
           "no boundaries: NAN, the memory kept");
}

static size_t kind_size(hm_report_kind k) {
  switch (k) {
    case HM_REPORT_NUMBER: return sizeof(double);
    case HM_REPORT_INT: return sizeof(long);
    case HM_REPORT_FLAG: return sizeof(int);
    case HM_REPORT_STATIC_TEXT: return sizeof(const char *);
    case HM_REPORT_TEXT: return HM_REPORT_TEXT_LEN;
  }
  return 0;
}

/* The list covers the record: each field in bounds, none overlapping another, their sizes (with alignment) adding up
 * to no more than the record's, and names unique. */
static void field_list_covers_the_record(void) {
  size_t n = 0;
  const hm_report_field *f = hm_report_fields(&n);
  HM_CHECK(n > 100, "%zu fields", n);
  size_t total = 0;
  for (size_t i = 0; i < n; ++i) {
    const size_t sz = kind_size(f[i].kind);
    total += sz;
    HM_CHECK(f[i].offset + sz <= sizeof(hm_report), "%s in bounds", f[i].name);
    for (size_t j = 0; j < i; ++j) {
      HM_CHECK(strcmp(f[i].name, f[j].name) != 0, "%s listed twice", f[i].name);
      const size_t szj = kind_size(f[j].kind);
      HM_CHECK(f[i].offset + sz <= f[j].offset || f[j].offset + szj <= f[i].offset, "%s overlaps %s", f[i].name,
               f[j].name);
    }
  }
  HM_CHECK(total <= sizeof(hm_report) && sizeof(hm_report) - total < 8 * n, "sizes %zu of %zu", total,
           sizeof(hm_report));
}

int main(void) {
  HM_RUN(gating_rules);
  HM_RUN(field_list_covers_the_record);
  HM_TEST_EXIT();
}
