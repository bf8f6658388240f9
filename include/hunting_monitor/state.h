/*
 * hunting_monitor - what the monitor has learned, kept through a restart (issue #27): a small versioned binary record
 * that the node and `hunting estimate` write every few seconds and at the end, and read back at start.
 *
 * The core gives and takes bytes in a caller's buffer (hm_state_save, hm_state_restore); the file (written atomically,
 * the previous one kept as FILE.prev) is the io library's, state_io.c (hm_state_save_file, hm_state_restore_file).
 *
 * Kept (hm_monitor_snapshot, monitor.h), every time as an age before the writer's "now", so a restart on a new time
 * line works: the margin's windows within memory_s with their speeds, lengths, decay rates and conicities (the
 * conicity estimate and both Hopf intervals follow from them, computed the same way after the restart), the misfit
 * windows, the conicity changes (count, age of the last, windows since), the latest window's narrow-peak verdict and
 * the latest ambiguous one (a line or the mode: it holds WATCH for HM_ALARM_NARROW_HOLD_S); the alarm's held ALARM with
 * its cause, the hunted-at speed while it counts, and the estimate's use alone with its hysteresis (conicity_max_se's,
 * and a dropped estimate's wait, started again). Not kept: the stream (the estimator's filters, the identification's
 * samples, the current steady stretch: a restart ends it as a gap does, its provisional window kept as committed), the
 * level's hold and the speed's trend (hm_alarm_restart's rules).
 *
 * Restored only when the record is whole and meant for this monitor, else refused with the reason (the monitor is
 * untouched and starts from the prior): the magic; the length it declares (shorter: truncated); the checksum; the
 * format version (only HM_STATE_VERSION is known: a newer one is refused); the hash of the vehicle and the settings
 * that give the windows their meaning (hm_state_hash; for a bogie's or car's monitor also its model's parameters and
 * the sensor's point, whose reading the windows are); its age on the clock the caller names (below 0: written after
 * now, another time line; memory_s or more: too old, the margin would have forgotten every window); every field in
 * its range (hm_margin_snapshot_validate, hm_alarm_snapshot_validate, hm_interval_snapshot_validate). The restored windows are aged by the record's
 * age, and those beyond memory_s are forgotten as usual.
 *
 * The age: the writer supplies both its time line's now (the sensor's stamps, a recording's t_s) and the wall clock
 * (seconds since the epoch); the reader says which to compare with. A node restarting on a live vehicle uses the wall
 * clock (its time line restarts with it); an offline run uses the recording's time line when both runs read the same
 * recording (a state written at t = 60 s and read by a run starting at t = 75 s is 15 s old, however long ago the first
 * run was made), the wall clock otherwise (hunting estimate --state-clock).
 *
 * Format, version 1: little-endian; f64 an IEEE-754 binary64, u32/u64 unsigned integers.
 *     offset  size  field
 *          0     8  magic "HMSTATE\0"
 *          8     4  u32 format version (1)
 *         12     4  u32 length of the whole record in bytes (136 + 72 n_windows + 8 n_misfits)
 *         16     8  u64 hash of the vehicle and settings (hm_state_hash)
 *         24     8  f64 written_unix_s: the wall clock at writing [s since 1970-01-01 UTC]
 *         32     8  f64 written_line_s: the writer's time line at writing [s] (the now the ages count from)
 *         40     4  u32 n_windows (<= 64), then per window, oldest first, 9 f64: age_s, speed_kmh, window_s,
 *                   sigma_1_s, sigma_stat_1_s, conicity, conicity_se, conicity_stat, conicity_sys
 *                4  u32 n_misfits (<= 64), then n_misfits f64 ages [s]
 *                8  u64 n_changes; 8 f64 last_change_age_s; 4 u32 windows_since_change
 *                4  u32 narrow verdict (hm_narrow_verdict); 8 f64 narrow_peak_hz; 8 f64 narrow_age_s (inf: none);
 *                8  f64 ambiguous_age_s (inf: none)
 *                4  u32 latched; 4 u32 latch_reason (hm_reason); 8 f64 hunted_at_kmh (inf: none);
 *                8  f64 hunted_age_s: its memory's age, from when it was met or the latch's release if later
 *                   (NaN: counted from the next update); 4 u32 precise;
 *                4  u32 se_ok; 4 u32 precise_lost
 *     length - 4  4  u32 CRC-32 (IEEE 802.3, as zlib's crc32) of every byte before it
 * The magic, the version and the length at the front and the CRC-32 at the end are the same in every version.
 * hm_state_save and hm_state_restore allocate nothing and do no I/O; hm_state_save_file allocates nothing,
 * hm_state_restore_file reads a file into an allocation of its size (at start).
 */
#ifndef HUNTING_MONITOR_STATE_H
#define HUNTING_MONITOR_STATE_H

#include <stddef.h>
#include <stdint.h>

#include "hunting_monitor/monitor.h"
#include "hunting_monitor/status.h"

#ifdef __cplusplus
extern "C" {
#endif

#define HM_STATE_VERSION 1u
/* The largest record of version 1 [bytes]: 64 windows and 64 misfits. */
#define HM_STATE_MAX_BYTES (136u + 80u * HM_MARGIN_MAX_WINDOWS)
/* An outcome's text [bytes, with the NUL]. */
#define HM_STATE_TEXT_MAX 512

/* How often the state is written [s] (the node: of wall time; hunting estimate: of the recording's time). */
typedef struct {
  double period_s;
} hm_state_config;

/* 2 s. */
void hm_state_config_default(hm_state_config *cfg);
/* HM_EDOMAIN with "state.period_s: must be in [0.1, 3600] (got ...)" in why for an invalid configuration. */
hm_status hm_state_config_validate(const hm_state_config *cfg, char *why, size_t why_len);

/* Which clock the record's age is read on (above). */
typedef enum {
  HM_STATE_CLOCK_WALL = 0, /* now_unix_s - written_unix_s */
  HM_STATE_CLOCK_LINE = 1  /* now_s - written_line_s: the same time line (a recording read again) */
} hm_state_clock;

typedef enum {
  HM_STATE_RESTORED = 0,
  HM_STATE_NOT_A_STATE = 1,   /* no magic (or, state_io.c, too large a file) */
  HM_STATE_TRUNCATED = 2,     /* shorter than its declared length, or than a header */
  HM_STATE_CORRUPT = 3,       /* the checksum does not match, or bytes beyond the declared length */
  HM_STATE_VERSION_UNKNOWN = 4, /* a format version this reader does not know (a newer one) */
  HM_STATE_FOREIGN = 5,       /* written for another vehicle or other settings (the hash differs) */
  HM_STATE_FROM_FUTURE = 6,   /* written after now on the clock used (another time line) */
  HM_STATE_TOO_OLD = 7,       /* its age is memory_s or more */
  HM_STATE_BAD_CONTENT = 8,   /* intact, but a field out of its range or the layout not version 1's */
  HM_STATE_NO_FILE = 9,       /* state_io.c: no such file */
  HM_STATE_UNREADABLE = 10    /* state_io.c: the file could not be read */
} hm_state_verdict;

/* What a restore did. */
typedef struct {
  hm_state_verdict verdict;
  double age_s;        /* the record's age on the clock used [s]; NAN when it was refused before */
  unsigned n_windows;  /* windows restored that are within memory_s now */
  int latched;         /* a held ALARM was restored */
  int from_prev;       /* hm_state_restore_file: restored from FILE.prev (FILE was missing or refused) */
  char text[HM_STATE_TEXT_MAX]; /* "restored, age 42 s, 3 windows" (and "; ALARM held: <cause>", "; hunted at <v>
                                   km/h"), or "not restored: <reason>" */
} hm_state_outcome;

/* FNV-1a (64 bits) over the vehicle's every parameter (the conicity function's terms included) and the settings that
 * give the windows their meaning: the identification's (cfg->modal) and the margin's (cfg->margin, memory_s
 * included). Not the alarm's (they judge the windows, and may change at runtime: hm_monitor_set_runtime_settings),
 * nor the estimator's (the data's sample rate is measured). */
uint64_t hm_state_hash(const hm_monitor_config *cfg, const hm_vehicle *veh);
/* CRC-32 (IEEE 802.3, reflected, polynomial 0xEDB88320, as zlib's crc32) of n bytes; "123456789" gives 0xCBF43926. */
uint32_t hm_state_checksum(const unsigned char *bytes, size_t n);

/* The record of what m holds at now_s (its time line), written at written_unix_s (the wall clock [s since the
 * epoch], the caller's), into buf of cap bytes: *len bytes (at most HM_STATE_MAX_BYTES). HM_EINVAL for NULL
 * arguments, non-finite times or cap too small (then nothing is written). */
hm_status hm_state_save(const hm_monitor m, double now_s, double written_unix_s, unsigned char *buf, size_t cap,
                        size_t *len);

/* Restore m from the record bytes[0..len) at now_s (m's time line) and now_unix_s (the wall clock), the age read on
 * clock. HM_OK when restored; else m is untouched and the status says why: HM_EPARSE (not a state, truncated,
 * corrupt, an unknown version, bad content), HM_EDOMAIN (foreign, from the future, too old), HM_EINVAL (NULL
 * arguments, the time of the clock used not finite). *outcome (if not NULL) says what happened, in every case. */
hm_status hm_state_restore(hm_monitor m, const unsigned char *bytes, size_t len, double now_s, double now_unix_s,
                           hm_state_clock clock, hm_state_outcome *outcome);

/* ---- the file (hunting_monitor_io, state_io.c) ---- */

/* Write hm_state_save's record to path atomically: path.tmp written and fsync'd in the same directory, the existing
 * path (if any) renamed to path.prev, path.tmp renamed to path, the directory fsync'd. A crash leaves path, or
 * path.prev, whole. One writer per path. HM_EIO with "path: reason" in why (or hm_state_save's status). No
 * allocation. */
hm_status hm_state_save_file(const hm_monitor m, const char *path, double now_s, double written_unix_s, char *why,
                             size_t why_len);
/* Restore m from path (hm_state_restore) or, where it is missing or refused, from path.prev: *outcome says which was
 * restored and why the others were not ("restored from FILE.prev, age 44 s, 3 windows (FILE: truncated: ...)", "not
 * restored: FILE: ...; FILE.prev: no file", "not restored: FILE (and .prev): ..." for one reason). HM_OK when one
 * was restored; else hm_state_restore's status for path's refusal, or HM_EIO when neither file exists or can be read.
 */
hm_status hm_state_restore_file(hm_monitor m, const char *path, double now_s, double now_unix_s, hm_state_clock clock,
                                hm_state_outcome *outcome);

#ifdef __cplusplus
}
#endif

#endif
