/*
 * hunting_monitor - the monitor's status as it is published, made once for every output.
 *
 * hm_report_make turns one hm_monitor_status into the flat record that the CLI's JSON line (`hunting estimate`) and
 * the node's HuntingStatus show, with every field gated once by the validity that makes it current: a number that is
 * not current is NAN (the JSON's null; the node writes 0 beside its flag), a flag that is not current is 0. The
 * rules, in one place:
 *   - the level, its reason and its hold always (a hold is a memory, shown while it counts);
 *   - the identified mode's numbers where the latest fit is valid (mode_fit_valid), whether or not its window could
 *     be used (mode_valid: a steady speed and no criterion met; mode_window_verdict says why not);
 *   - a line's numbers where that line was found; the margin's where each of its estimates is valid;
 *   - the Hopf interval, thresholds, margins and cycle amplitudes only where the boundaries are valid (current speed
 *     and data): never a stale margin shown as current; the hunted-at memory while it counts.
 * hm_report_fields lists the fields in the JSON line's order with their kinds, so that a writer needs no list of
 * its own.
 */
#ifndef HUNTING_MONITOR_REPORT_H
#define HUNTING_MONITOR_REPORT_H

#include <stddef.h>

#include "hunting_monitor/monitor.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The kinds of field: a number (double, NAN when not current), an integer (long), a flag (int 0/1), a static text
 * (const char *), a text held in the record (char[HM_REPORT_TEXT]). */
typedef enum { HM_REPORT_NUMBER, HM_REPORT_INT, HM_REPORT_FLAG, HM_REPORT_STATIC_TEXT, HM_REPORT_TEXT } hm_report_kind;

enum { HM_REPORT_TEXT_LEN = 512 };

/* The fields, in the JSON line's order: X(name, kind). Units are in the names (docs/ROS.md and the message's
 * comments say what each means). */
#define HM_REPORT_FIELDS(X)                                                                                            \
  X(level, STATIC_TEXT) X(reason_code, INT) X(reason, TEXT) X(level_changed, FLAG) X(latched, FLAG)                    \
  X(release_in_s, NUMBER) X(held, FLAG) X(hold_cause_code, INT) X(hold_cause, STATIC_TEXT) X(hold_since_s, NUMBER)     \
  X(hold_last_met_s, NUMBER) X(hold_release_below_kmh, NUMBER) X(hold_release_amplitude_m, NUMBER)                     \
  X(calm_s, NUMBER) X(calm_needed_s, NUMBER) X(hold_waits, INT)                                                        \
  X(speed_valid, FLAG) X(speed_kmh, NUMBER) X(accel_valid, FLAG) X(sample_rate_hz, NUMBER)                             \
  X(sample_rate_mismatch, FLAG) X(oscillation_valid, FLAG) X(amplitude_accel_mps2, NUMBER) X(frequency_hz, NUMBER)     \
  X(amplitude_m, NUMBER)                                                                                               \
  X(mode_valid, FLAG) X(mode_fit_valid, FLAG) X(mode_frequency_hz, NUMBER) X(mode_frequency_se_hz, NUMBER)             \
  X(decay_rate_1_s, NUMBER) X(decay_rate_se_1_s, NUMBER) X(damping_ratio, NUMBER) X(damping_ratio_se, NUMBER)          \
  X(mode_speed_kmh, NUMBER) X(mode_speed_spread_kmh, NUMBER) X(mode_pole_pairs, INT)                                   \
  X(mode_second_frequency_hz, NUMBER) X(mode_second_decay_rate_1_s, NUMBER) X(mode_window_verdict, INT)                \
  X(mode_window_verdict_text, STATIC_TEXT)                                                                             \
  X(lines_found, FLAG) X(line_fundamental_hz, NUMBER) X(line_wavelength_m, NUMBER) X(line_harmonics, INT)              \
  X(line_strongest_hz, NUMBER) X(line_strongest_mps2, NUMBER) X(lone_lines, INT) X(lone_line_hz, NUMBER)               \
  X(lone_line_mps2, NUMBER) X(lone_line_wavelength_m, NUMBER) X(order_lines, INT) X(order_line_wavelength_m, NUMBER)   \
  X(order_line_hz, NUMBER) X(order_line_mps2, NUMBER) X(mode_speed_tracking, NUMBER)                                   \
  X(mode_speed_tracking_se, NUMBER) X(spectrum_conicity, NUMBER) X(spectrum_conicity_se, NUMBER)                     \
  X(spectrum_motion_rms_m, NUMBER) X(spectrum_shape_chi2, NUMBER) X(spectrum_model_share, NUMBER)                    \
  X(narrow_peak, FLAG) X(narrow_peak_hz, NUMBER)                                                                       \
  X(narrow_peak_wavelength_m, NUMBER) X(narrow_peak_tracked, FLAG) X(narrow_peak_envelope_ratio, NUMBER)              \
  X(narrow_peak_line_ratio, NUMBER) X(narrow_peak_taken_for, STATIC_TEXT)                                              \
  X(narrow_peak_verdict, INT) X(windows_used, INT)                                                                     \
  X(conicity_valid, FLAG) X(conicity_estimate, NUMBER) X(conicity_se, NUMBER) X(hopf_model_valid, FLAG)                \
  X(hopf_model_kmh, NUMBER) X(hopf_model_kmh_low, NUMBER) X(hopf_model_kmh_high, NUMBER) X(hopf_free_valid, FLAG)      \
  X(hopf_free_kmh, NUMBER) X(hopf_free_kmh_low, NUMBER) X(hopf_free_kmh_high, NUMBER) X(model_mismatch, FLAG)          \
  X(model_mismatch_windows, FLAG) X(birge_ratio, NUMBER) X(misfit_windows, INT) X(conicity_changes, INT)               \
  X(last_conicity_change_s, NUMBER) X(windows_since_change, INT) X(conicity_outside_prior, INT)                        \
  X(boundaries_valid, FLAG) X(conicity_used, NUMBER) X(conicity_from_estimate, FLAG) X(conicity_from_prior, FLAG)      \
  X(model_interval_used, FLAG) X(hopf_free_used, FLAG) X(hopf_kmh, NUMBER) X(hopf_kmh_low, NUMBER)                     \
  X(hopf_kmh_high, NUMBER) X(warn_from_kmh, NUMBER) X(watch_from_kmh, NUMBER) X(warn_risk, NUMBER)                     \
  X(hunted_at_kmh, NUMBER) X(hunted_at_s, NUMBER) X(hopf_low_from_hunting, FLAG) X(anticipation_kmh, NUMBER)           \
  X(lowest_cycle_kmh, NUMBER) X(conicity_outside_table, INT) X(margin_hopf_kmh, NUMBER)                                \
  X(margin_lowest_cycle_kmh, NUMBER) X(cycles_valid, FLAG) X(unstable_cycle_amplitude_m, NUMBER)                       \
  X(stable_cycle_amplitude_m, NUMBER)                                                                                  \
  X(rms_mps2, NUMBER) X(rms_exceeded, FLAG) X(consecutive_peaks, INT) X(peaks_exceeded, FLAG)                          \
  X(displacement_exceeded, FLAG) X(wheelset_displacement_m, NUMBER)                                                    \
  X(accel_samples, INT) X(rejected_samples, INT) X(rejected_nonfinite, INT) X(rejected_out_of_range, INT)              \
  X(rejected_out_of_order, INT) X(gaps, INT) X(samples_lost, INT) X(samples_lost_fraction, NUMBER)                     \
  X(rate_changes, INT) X(speed_updates, INT) X(rejected_speeds, INT)

#define HM_REPORT_MEMBER_TEXT(name) char name[HM_REPORT_TEXT_LEN];
#define HM_REPORT_MEMBER_NUMBER(name) double name;
#define HM_REPORT_MEMBER_INT(name) long name;
#define HM_REPORT_MEMBER_FLAG(name) int name;
#define HM_REPORT_MEMBER_STATIC_TEXT(name) const char *name;
#define HM_REPORT_MEMBER(name, kind) HM_REPORT_MEMBER_##kind(name)

typedef struct {
  HM_REPORT_FIELDS(HM_REPORT_MEMBER)
} hm_report;

typedef struct {
  const char *name;
  hm_report_kind kind;
  size_t offset; /* in hm_report */
} hm_report_field;

/* The record of st (every field set; reason with hm_assessment_reason_text's times from origin_s). */
void hm_report_make(const hm_monitor_status *st, double origin_s, hm_report *out);

/* The fields in order (never NULL); their count in *n. */
const hm_report_field *hm_report_fields(size_t *n);

#ifdef __cplusplus
}
#endif

#endif
