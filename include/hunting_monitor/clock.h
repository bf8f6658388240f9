/*
 * hunting_monitor - one time line for a stamped sensor and the receiving computer (issue #21, "one clock").
 *
 * A sensor stamps its samples with its own clock; the computer receives them some time later on its clock (ROS
 * time). For every sample d = receipt - stamp is the clocks' offset plus that sample's latency (>= 0). The offset in
 * use is the least d over the last window_s (in 8 blocks, so a least value leaves the window within window_s / 8 of
 * its age): the sensor clock's offset plus the link's least latency. It follows a slow drift of either clock, and
 * one late sample or a burst after a stall does not move it. The receiver's times (the speed, which has no stamp,
 * and "now" for staleness) are taken onto the sensor's time line by subtracting the offset: staleness, the pairing of
 * speed with acceleration and the r.m.s. window's distance then all use one time line, whatever the sensor clock's
 * offset; the age of the newest sample is its latency beyond the least one.
 *
 * A latency and a clock offset cannot be told apart without a synchronised clock: a latency that grows by dt
 * reads as samples dt late (stale when dt exceeds the estimator's timeout) until the least value before the change
 * has left the window, then as a clock offset.
 *
 * A clock that steps: a sample whose d departs from the offset by more than max_step_s
 *  - later than the offset says with a stamp that continues the stamps used (not earlier than the last, at most
 *    max_step_s after it): a stall's backlog, draining at any rate: used, never a step (issue #27: a 2 s stall whose
 *    backlog drained at twice real time read as a step and reset the monitor);
 *  - later than the offset says otherwise (a burst of late samples, or the sensor's clock stepped back): used (its
 *    stamp is plausible; the estimator refuses it if it is out of order);
 *  - earlier than possible (a stamp ahead of the receiver's now on the sensor's time line by more than max_step_s):
 *    dropped;
 * and if either lasts confirm_s of receipt time, the sensor's clock stepped: the offset is taken anew from that
 * sample (HM_CLOCK_STEPPED: the caller restarts what holds times of the old line). After a silence longer than the
 * window (nothing received for window_s and a block) a sample that departs and is no backlog is a step at once (a
 * sensor rebooted while silent: there is nothing left to confirm it against). A stall's backlog after such a silence
 * starts the window again from the offset it had.
 * No allocation; a plain struct the caller owns.
 */
#ifndef HUNTING_MONITOR_CLOCK_H
#define HUNTING_MONITOR_CLOCK_H

#include <stddef.h>

#include "hunting_monitor/status.h"

#ifdef __cplusplus
extern "C" {
#endif

#define HM_CLOCK_BLOCKS 8

typedef struct {
  double window_s;   /* the offset is the least receipt - stamp over this long [s] (receipt time) */
  double max_step_s; /* a sample departing from the offset by more than this ... [s] */
  double confirm_s;  /* ... for this long [s] (receipt time) means the sensor's clock stepped */
} hm_clock_config;

/* 10 s, 1 s, 1 s. */
void hm_clock_config_default(hm_clock_config *cfg);
/* The first invalid field as "clock.field: reason" (HM_EDOMAIN): window_s in (0, 3600], max_step_s in (0, 3600],
 * confirm_s in (0, 60]. */
hm_status hm_clock_config_validate(const hm_clock_config *cfg, char *why, size_t why_len);

typedef enum {
  HM_CLOCK_USE = 0,     /* push the sample at its stamp */
  HM_CLOCK_DROP = 1,    /* a stamp ahead of what is possible: drop the sample */
  HM_CLOCK_STEPPED = 2  /* the sensor's clock stepped: restart, then push the sample at its stamp */
} hm_clock_verdict;

typedef struct {
  hm_clock_config cfg;
  int have_offset;                       /* 1 after the first sample */
  double offset_s;                       /* receiver time - sensor time: least receipt - stamp over the window [s] */
  double latency_s;                      /* the last sample's receipt - stamp - offset_s [s] (>= 0 unless it stepped) */
  double block_min_s[HM_CLOCK_BLOCKS];   /* least receipt - stamp of each block [s] */
  double block_start_s;                  /* receipt time the newest block began [s] */
  unsigned n_blocks, newest;             /* blocks in use, index of the newest */
  double away_since_s;                   /* receipt time since which samples depart by > max_step_s; NaN: none */
  double last_mapped_s;                  /* the last receiver time taken onto the sensor's line (kept monotonic) */
  double last_stamp_s;                   /* the stamp of the last sample used; NaN: none */
  unsigned long n_steps, n_dropped, n_late; /* clock steps, samples dropped, samples later than max_step_s */
} hm_clock;

/* Ready for a sensor (no offset known). HM_EINVAL for NULL, HM_EDOMAIN for an invalid configuration (c untouched). */
hm_status hm_clock_init(hm_clock *c, const hm_clock_config *cfg);
/* Forget the offset (the receiver's time jumped), keeping the configuration and the counters. */
void hm_clock_reset(hm_clock *c);
/* The receiver's clock stepped by delta_s (a ROS time correction) while the sensor's did not: the offset moves with
 * it, and the sensor's time line, the stamps, is continuous (nothing to restart). */
void hm_clock_shift(hm_clock *c, double delta_s);
/* One sample stamped stamp_s (sensor clock) received at receipt_s (receiver clock). HM_EINVAL for NULL or a
 * non-finite time (c untouched). */
hm_status hm_clock_observe(hm_clock *c, double stamp_s, double receipt_s, hm_clock_verdict *verdict);
/* The offset in use, receiver time - sensor time [s]; 0 before the first sample (or NULL). */
double hm_clock_offset_s(const hm_clock *c);
/* A receiver time on the sensor's time line: receiver_s - offset_s (receiver_s itself before the first sample),
 * never earlier than the previous result (the offset moves up by the least latency's changes). */
double hm_clock_to_sensor(hm_clock *c, double receiver_s);

#ifdef __cplusplus
}
#endif

#endif
