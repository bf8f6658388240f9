/* The monitor's status as published, gated once (report.h). */
#include "hunting_monitor/report.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "hunting_monitor/linear.h"

/* x where valid, else NAN */
static double when(int valid, double x) { return valid ? x : NAN; }

static void level_part(const hm_assessment *s, double origin_s, hm_report *r) {
  r->level = hm_level_name(s->level);
  r->reason_code = (long)s->reason;
  hm_assessment_reason_text(s, origin_s, r->reason, sizeof r->reason); /* with a hold's cause, times and release */
  r->level_changed = s->changed;
  r->latched = s->latched;
  r->release_in_s = s->latched ? s->release_in_s : 0.0;
  r->held = s->held;
  r->hold_cause_code = (long)s->hold_cause;
  r->hold_cause = s->latched ? hm_reason_text(s->hold_cause) : "";
  r->hold_since_s = s->hold_since_s;
  r->hold_last_met_s = s->hold_last_met_s;
  r->hold_release_below_kmh = s->hold_release_below_kmh;
  r->hold_release_amplitude_m = s->hold_release_amplitude_m;
  r->calm_s = s->calm_s;
  r->calm_needed_s = s->calm_needed_s;
  r->hold_waits = (long)s->hold_waits;
}

static void estimate_part(const hm_estimate *e, hm_report *r) {
  r->speed_valid = e->speed_valid;
  r->speed_kmh = e->speed_kmh;
  r->accel_valid = e->accel_valid;
  r->sample_rate_hz = e->sample_rate_measured_hz;
  r->sample_rate_mismatch = e->sample_rate_mismatch;
  r->oscillation_valid = e->oscillation_valid;
  r->amplitude_accel_mps2 = e->amplitude_accel_mps2;
  r->frequency_hz = e->frequency_hz;
  r->amplitude_m = e->amplitude_displacement_m;
  r->rms_mps2 = e->rms_mps2;
  r->rms_exceeded = e->rms_exceeded;
  r->consecutive_peaks = (long)e->consecutive_peaks;
  r->peaks_exceeded = e->peaks_exceeded;
  r->displacement_exceeded = e->displacement_exceeded;
  r->wheelset_displacement_m = e->wheelset_displacement_m;
  r->accel_samples = (long)e->n_samples;
  r->rejected_samples = (long)(e->n_rejected_nonfinite + e->n_rejected_range + e->n_rejected_order);
  r->rejected_nonfinite = (long)e->n_rejected_nonfinite;
  r->rejected_out_of_range = (long)e->n_rejected_range;
  r->rejected_out_of_order = (long)e->n_rejected_order;
  r->gaps = (long)e->n_gaps;
  r->samples_lost = (long)e->n_samples_lost;
  r->samples_lost_fraction = e->loss_fraction;
  r->rate_changes = (long)e->n_rate_changes;
  r->speed_updates = (long)e->n_speed_updates;
  r->rejected_speeds = (long)e->n_speed_rejected;
}

/* The latest window's mode and what was found beside it. */
static void mode_part(const hm_monitor_status *st, hm_report *r) {
  const hm_mode_estimate *md = &st->mode;
  const int v = md->valid, two = v && md->poles == 2;
  r->mode_valid = st->mode_steady;
  r->mode_fit_valid = v;
  r->mode_frequency_hz = when(v, md->frequency_hz);
  r->mode_frequency_se_hz = when(v, md->frequency_se_hz);
  r->decay_rate_1_s = when(v, md->decay_rate_1_s);
  r->decay_rate_se_1_s = when(v, md->decay_rate_se_1_s);
  r->damping_ratio = when(v, md->damping_ratio);
  r->damping_ratio_se = when(v, md->damping_ratio_se);
  r->mode_speed_kmh = when(v, st->mode_speed_kmh);
  r->mode_speed_spread_kmh = when(v && st->mode_speed_spread_kmh >= 0.0, st->mode_speed_spread_kmh);
  r->mode_pole_pairs = v ? (long)md->poles : 0L;
  r->mode_second_frequency_hz = when(two, md->second_frequency_hz);
  r->mode_second_decay_rate_1_s = when(two, md->second_decay_rate_1_s);
  r->mode_window_verdict = (long)st->mode_verdict;
  r->mode_window_verdict_text = hm_window_verdict_text(st->mode_verdict);
  /* a periodic excitation of the track in the latest window (its bins left out of the fit) */
  const int lf = md->lines_found;
  r->lines_found = lf;
  r->line_fundamental_hz = when(lf, md->line_fundamental_hz);
  r->line_wavelength_m = when(lf, st->line_wavelength_m);
  r->line_harmonics = (long)md->line_harmonics;
  r->line_strongest_hz = when(lf, md->line_strongest_hz);
  r->line_strongest_mps2 = when(lf, md->line_strongest_mps2);
  /* lone lines set aside, lines taken out in distance, and a narrow peak (modal.h, margin.h) */
  const int lone = md->lone_lines > 0;
  r->lone_lines = (long)md->lone_lines;
  r->lone_line_hz = when(lone, md->lone_line_hz[0]);
  r->lone_line_mps2 = when(lone, md->lone_line_mps2[0]);
  r->lone_line_wavelength_m = when(lone && md->lone_line_hz[0] > 0.0, hm_mps_from_kmh(st->mode_speed_kmh) /
                                                                           md->lone_line_hz[0]);
  const int ol = md->order_lines > 0;
  r->order_lines = (long)md->order_lines;
  r->order_line_wavelength_m = when(ol, md->order_line_wavelength_m);
  r->order_line_hz = when(ol, md->order_line_hz);
  r->order_line_mps2 = when(ol, md->order_line_mps2);
  r->mode_speed_tracking = md->speed_tracking;
  r->mode_speed_tracking_se = md->speed_tracking_se;
  /* a vehicle model's fit of the whole spectrum (spectrum_fit.h; NAN where none was made for this window) */
  const int sf = md->spectrum_valid > 0; /* (-1: asked and not fitted) */
  r->spectrum_conicity = when(sf, md->spectrum_conicity);
  r->spectrum_conicity_se = when(sf, md->spectrum_conicity_se);
  r->spectrum_motion_rms_m = when(sf, md->spectrum_motion_rms_m);
  r->spectrum_shape_chi2 = when(sf, md->spectrum_shape_chi2);
  r->spectrum_model_share = when(sf, md->spectrum_model_share);
  r->narrow_peak = md->narrow_peak;
  r->narrow_peak_hz = when(md->narrow_peak, md->narrow_peak_hz);
  r->narrow_peak_wavelength_m = when(md->narrow_peak && md->narrow_peak_wavelength_m > 0.0,
                                     md->narrow_peak_wavelength_m);
  r->narrow_peak_tracked = md->narrow_peak && md->narrow_peak_tracked;
  r->narrow_peak_envelope_ratio = when(md->narrow_peak, md->narrow_peak_envelope_ratio);
  r->narrow_peak_line_ratio = when(md->narrow_peak, md->narrow_peak_line_ratio);
  r->narrow_peak_taken_for = hm_narrow_verdict_text(st->margin.narrow);
  r->narrow_peak_verdict = (long)st->margin.narrow;
}

/* The margin's estimates: model-based and model-free Hopf speeds, the mismatch. */
static void margin_part(const hm_margin_estimate *g, const hm_assessment *s, hm_report *r) {
  r->windows_used = (long)g->n_windows;
  r->conicity_valid = g->conicity_valid;
  r->conicity_estimate = when(g->conicity_valid, g->conicity);
  r->conicity_se = when(g->conicity_valid, g->conicity_se);
  r->hopf_model_valid = g->hopf_model_valid;
  r->hopf_model_kmh = when(g->hopf_model_valid, g->hopf_model_kmh);
  r->hopf_model_kmh_low = when(g->hopf_model_valid, g->hopf_model_low_kmh);
  r->hopf_model_kmh_high = when(g->hopf_model_valid, g->hopf_model_high_kmh);
  r->hopf_free_valid = g->hopf_free_valid;
  r->hopf_free_kmh = when(g->hopf_free_valid, g->hopf_free_kmh);
  r->hopf_free_kmh_low = when(g->hopf_free_valid, g->hopf_free_low_kmh);
  r->hopf_free_kmh_high = when(g->hopf_free_valid, g->hopf_free_high_kmh);
  /* as the level uses it (held against the provisional window's chatter, alarm.h), and as the windows say now */
  r->model_mismatch = s->boundaries_valid ? s->model_mismatch : g->model_mismatch;
  r->model_mismatch_windows = g->model_mismatch;
  r->birge_ratio = g->birge_ratio;
  r->misfit_windows = (long)g->n_misfits;
  r->conicity_changes = (long)g->n_changes;
  r->last_conicity_change_s = when(g->n_changes > 0, g->last_change_s);
  r->windows_since_change = (long)g->windows_since_change;
  r->conicity_outside_prior = (long)g->outside_prior;
}

/* The boundaries at the current speed: none shown as current without current data. */
static void boundaries_part(const hm_assessment *s, hm_report *r) {
  const int b = s->boundaries_valid;
  r->boundaries_valid = b;
  r->conicity_used = when(b, s->conicity);
  r->conicity_from_estimate = b && s->conicity_from_estimate;
  r->conicity_from_prior = b && s->conicity_from_prior;
  r->model_interval_used = b && s->model_interval_used;
  r->hopf_free_used = b && s->hopf_free_used;
  r->hopf_kmh = when(b, s->boundaries.hopf_speed_kmh);
  r->hopf_kmh_low = when(b, s->hopf_low_kmh);
  r->hopf_kmh_high = when(b, s->hopf_high_kmh);
  r->warn_from_kmh = when(b, s->warn_from_kmh);
  r->watch_from_kmh = when(b, s->watch_from_kmh);
  r->warn_risk = when(b, s->warn_risk);
  /* (a memory, not a margin: shown while it counts, also held without current data) */
  r->hunted_at_kmh = s->hunted_at_kmh;
  r->hunted_at_s = s->hunted_at_s;
  r->hopf_low_from_hunting = b && s->hopf_low_from_hunting;
  r->anticipation_kmh = when(b, s->anticipation_kmh);
  r->lowest_cycle_kmh = when(b, s->boundaries.lowest_cycle_speed_kmh);
  r->conicity_outside_table = b ? (long)s->conicity_outside_table : 0L; /* boundaries widened (tables.h) */
  r->margin_hopf_kmh = when(b, s->margin_hopf_kmh);
  r->margin_lowest_cycle_kmh = when(b, s->margin_lowest_cycle_kmh);
  r->cycles_valid = b && s->edge_used_m > 0.0;
  r->unstable_cycle_amplitude_m = when(r->cycles_valid, s->edge_used_m);
  r->stable_cycle_amplitude_m = when(b && s->boundaries.has_stable_outer, s->boundaries.stable_outer_amp_m);
}

void hm_report_make(const hm_monitor_status *st, double origin_s, hm_report *out) {
  if (!st || !out) return;
  hm_report r;
  memset(&r, 0, sizeof r);
  level_part(&st->assessment, origin_s, &r);
  estimate_part(&st->estimate, &r);
  mode_part(st, &r);
  margin_part(&st->margin, &st->assessment, &r);
  boundaries_part(&st->assessment, &r);
  *out = r;
}

#define HM_REPORT_ENTRY(name, kind) {#name, HM_REPORT_##kind, offsetof(hm_report, name)},

static const hm_report_field fields[] = {HM_REPORT_FIELDS(HM_REPORT_ENTRY)};

const hm_report_field *hm_report_fields(size_t *n) {
  if (n) *n = sizeof fields / sizeof fields[0];
  return fields;
}
