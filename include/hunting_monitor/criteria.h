/*
 * hunting_monitor - the two standard instability criteria on lateral acceleration, as a streaming object the
 * estimator feeds (estimator.h states their limits and where they come from):
 *  (a) EN 14363 style: the sliding r.m.s. of the hunting-band acceleration over the last rms_window_m of track
 *      against rms_limit_mps2 (the window is counted in metres: the speed times each sample's interval);
 *  (b) consecutive half-cycle peaks of the acceleration filtered to [peaks_band_low_hz, peaks_band_high_hz]
 *      (2nd-order Butterworth high-pass, 4th-order low-pass) at or above peaks_limit_mps2, against peaks_count.
 * Memory: the r.m.s. ring is sized at create for the highest supported rate (5 kHz) down to 30 km/h; no allocation
 * after create.
 */
#ifndef HUNTING_MONITOR_CRITERIA_H
#define HUNTING_MONITOR_CRITERIA_H

#include <stddef.h>

#include "hunting_monitor/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
  double rms_window_m, rms_limit_mps2;
  double peaks_band_low_hz, peaks_band_high_hz, peaks_limit_mps2;
  unsigned peaks_count;
} hm_criteria_config;

typedef struct {
  double rms_mps2;          /* sliding r.m.s. over the window (or what is available of it) */
  int rms_window_complete;
  int rms_exceeded;
  unsigned consecutive_peaks;
  int peaks_exceeded;
} hm_criteria_state;

typedef struct hm_criteria_s *hm_criteria;

/* The configuration is checked by the estimator's validator (estimator.h); HM_EINVAL for a window outside
 * (0, 1000] m, HM_ENOMEM. */
hm_status hm_criteria_create(const hm_criteria_config *cfg, hm_criteria *out);
void hm_criteria_destroy(hm_criteria c);
/* Clear the window and the peak count, and design the peaks filter for sample rate fs [Hz]. */
void hm_criteria_restart(hm_criteria c, double fs_hz);
/* One sample: band_x the hunting-band acceleration [m/s^2] (for the r.m.s.), raw_a the raw one (for the peaks),
 * metres the track covered since the previous sample. */
void hm_criteria_push(hm_criteria c, double band_x, double raw_a, double metres);
void hm_criteria_read(const hm_criteria c, hm_criteria_state *out);
/* New limits from the next read on (the caller validated them: hm_estimator_config_validate); the state is kept. */
void hm_criteria_set_limits(hm_criteria c, double rms_limit_mps2, double peaks_limit_mps2, unsigned peaks_count);

#ifdef __cplusplus
}
#endif

#endif
