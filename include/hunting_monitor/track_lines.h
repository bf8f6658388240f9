/*
 * hunting_monitor - track lines by their wavelength across speeds: order tracking over windows (issue #26).
 *
 * A periodic feature of the track (slabs of 5.6-6.5 m, joints, spans) forces the vehicle at f = m V / L: its
 * wavelength L = V / f is the same at every speed. The hunting mode's frequency changes far less with the speed (d ln f
 * / d ln V is 0.2-0.3 for the default vehicle, about 0.5 at most: modal.h's speed_tracking), so its "wavelength" V / f
 * moves with the speed. In one window a line and the hunting mode near its Hopf speed look alike (modal.h's narrow
 * peak); across windows at two steady speeds they do not: a peak whose wavelength was seen at a speed differing by at
 * least min_speed_change_rel (5%: a mode's V / f then moves by 2.5% or more) within wavelength_tol_rel (1%) is a track
 * line. A 6.08 m slab's line read as the mode beside the true one at 280 km/h (12.8 Hz) had been seen at 250 km/h
 * (11.42 Hz): 6.081 and 6.080 m.
 *
 * The caller observes the lines of windows fitted at a steady speed (each lone line, each narrow peak, and a comb's
 * fundamental, whose harmonics are its lines too) and asks whether a peak is one seen at another speed. Observations
 * are kept for memory_s (the margin's memory: the track changes); one at nearly the same speed (within a tenth of
 * min_speed_change_rel) and wavelength updates the earlier one, so that a long stretch holds one entry per line. A
 * mode is never merged into a line across speeds: each observation keeps its own speed, and a match compares the
 * wavelength at one speed with that at another (a slowly moving peak cannot creep).
 * No allocation; a plain struct the caller owns.
 */
#ifndef HUNTING_MONITOR_TRACK_LINES_H
#define HUNTING_MONITOR_TRACK_LINES_H

#include <stddef.h>

#include "hunting_monitor/status.h"

#ifdef __cplusplus
extern "C" {
#endif

#define HM_TRACK_LINES_MAX 32

typedef struct {
  double wavelength_tol_rel;   /* a peak is a line seen before when their wavelengths agree within this (relative) */
  double min_speed_change_rel; /* ... seen at a speed differing by at least this (relative to the peak's speed) */
  double memory_s;             /* observations older than this are forgotten [s] */
} hm_track_lines_config;

/* Defaults: 1%, 5%, 900 s. */
void hm_track_lines_config_default(hm_track_lines_config *cfg);
/* The first invalid field as "track_lines.field: reason" (HM_EDOMAIN): wavelength_tol_rel in (0, 0.05],
 * min_speed_change_rel in [2 wavelength_tol_rel, 0.5], memory_s in [1, 1e6]. */
hm_status hm_track_lines_config_validate(const hm_track_lines_config *cfg, char *why, size_t why_len);

/* One line as seen at one steady speed. */
typedef struct {
  double wavelength_m; /* V / f [m] (of the fundamental for a comb) */
  double speed_kmh;    /* the steady speed it was seen at [km/h] */
  double frequency_hz; /* its frequency there [Hz] */
  double level_mps2;   /* its acceleration amplitude there [m/s^2] (0: not known) */
  double seen_s;       /* the end of the latest window it was seen in [s] */
  int comb;            /* 1: a comb's fundamental (its harmonics m V / L are its lines too) */
} hm_track_line;

typedef struct {
  hm_track_lines_config cfg;
  hm_track_line obs[HM_TRACK_LINES_MAX];
  size_t n;          /* observations held (the oldest replaced when full) */
} hm_track_lines;

/* Empty, with a configuration. HM_EINVAL for NULL, HM_EDOMAIN (reason in why) for a bad one (t untouched). */
hm_status hm_track_lines_init(hm_track_lines *t, const hm_track_lines_config *cfg, char *why, size_t why_len);
/* Forget every observation (the time line restarted). */
void hm_track_lines_clear(hm_track_lines *t);
/* Times moved by delta_s (the time line stepped by a known amount). */
void hm_track_lines_shift_time(hm_track_lines *t, double delta_s);

/* A line seen at frequency_hz in a window ending at now_s at the steady speed speed_kmh, level its amplitude [m/s^2]
 * (0 if not known), comb 1 for a comb's fundamental. HM_EINVAL for NULL or values that are not finite and positive
 * (level finite and >= 0): nothing kept. */
hm_status hm_track_lines_observe(hm_track_lines *t, double now_s, double speed_kmh, double frequency_hz,
                                 double level_mps2, int comb);

/* 1 when a peak at frequency_hz at speed_kmh is a line seen within memory_s of now_s at a speed differing by at least
 * min_speed_change_rel: its wavelength V / f within wavelength_tol_rel of that observation's (or, for a comb, of a
 * whole fraction L / m of its fundamental's); the observation (the one furthest in speed) into *out when out is given.
 * 0 otherwise, or for NULL or values that are not finite and positive (*out untouched). */
int hm_track_lines_match(const hm_track_lines *t, double now_s, double speed_kmh, double frequency_hz,
                         hm_track_line *out);

#ifdef __cplusplus
}
#endif

#endif
