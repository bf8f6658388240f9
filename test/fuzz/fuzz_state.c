/* libFuzzer harness: the state reader (state.h). The input is read two ways: as a record as it stands (the header's
 * checks: magic, length, checksum, version, hash), and with its magic, version, length, hash and checksum made right
 * (the times of writing and the payload as given), so that the age's checks, the payload's layout and every field's
 * checks are reached. A refusal must leave the monitor as it was; what is restored must give finite statuses, with
 * and without data. The seed (test/fuzz/seed_state.bin, `test_state --write-seed FILE`) is a record of one window, written at 1.7e9 s
 * (wall clock): restored here, 100 s later. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "fuzz_monitor.h"
#include "hunting_monitor/state.h"

static hm_monitor monitor;
static hm_monitor_snapshot blank; /* nothing learned */
enum { MAX_RECORD = 2 * HM_STATE_MAX_BYTES };

static size_t fingerprint(unsigned char *out) {
  size_t n = 0;
  if (hm_state_save(monitor, 1000.0, 1.7e9, out, HM_STATE_MAX_BYTES, &n) != HM_OK) __builtin_trap();
  return n;
}

static void check(const hm_monitor_status *s) {
  const hm_assessment *a = &s->assessment;
  const hm_margin_estimate *g = &s->margin;
  if ((unsigned)a->level > HM_LEVEL_ALARM) __builtin_trap();
  if (a->boundaries_valid && (!isfinite(a->hopf_low_kmh) || !isfinite(a->hopf_high_kmh) || !isfinite(a->warn_from_kmh) ||
                              !isfinite(a->watch_from_kmh) || !isfinite(a->margin_hopf_kmh) || !isfinite(a->conicity)))
    __builtin_trap();
  if (g->conicity_valid && (!isfinite(g->conicity) || !isfinite(g->conicity_se) || !isfinite(g->hopf_model_low_kmh)))
    __builtin_trap();
  if (g->hopf_free_valid && (!isfinite(g->hopf_free_kmh) || !isfinite(g->hopf_free_low_kmh))) __builtin_trap();
}

/* One restore attempt at now 1000 s (time line) and 1.7e9 + 100 s (wall clock). */
static void attempt(const unsigned char *rec, size_t n) {
  unsigned char before[HM_STATE_MAX_BYTES], after[HM_STATE_MAX_BYTES];
  if (hm_monitor_restore(monitor, 1000.0, &blank, NULL, 0) != HM_OK) __builtin_trap();
  const size_t nb = fingerprint(before);
  hm_state_outcome o;
  const hm_status st = hm_state_restore(monitor, rec, n, 1000.0, 1.7e9 + 100.0, HM_STATE_CLOCK_WALL, &o);
  if ((st == HM_OK) != (o.verdict == HM_STATE_RESTORED) || !memchr(o.text, '\0', sizeof o.text)) __builtin_trap();
  if (st != HM_OK) {
    if (fingerprint(after) != nb || memcmp(before, after, nb) != 0) __builtin_trap(); /* touched by a refusal */
    return;
  }
  hm_monitor_status s;
  if (hm_monitor_update(monitor, 1000.0, &s) != HM_OK) __builtin_trap();
  check(&s);
  for (int k = 0; k < 400; ++k) { /* 0.2 s of data at 450 km/h: the restored margin and alarm are assessed */
    const double t = 1000.0 + k / 2000.0;
    if (k % 40 == 0) hm_monitor_push_speed(monitor, t, 450.0);
    hm_monitor_push_accel(monitor, t, 0.5 * sin(88.0 * t));
  }
  if (hm_monitor_update(monitor, 1000.2, &s) != HM_OK) __builtin_trap();
  check(&s);
}

static void put_le(unsigned char *p, uint64_t x, int bytes) {
  for (int k = 0; k < bytes; ++k) p[k] = (unsigned char)(x >> (8 * k));
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (!monitor) {
    hm_monitor_config c;
    hm_monitor_config_default(&c);
    monitor = fuzz_monitor_create(&c);
    blank.margin.narrow_age_s = blank.margin.ambiguous_age_s = INFINITY;
    blank.alarm.hunted_at_kmh = INFINITY;
  }
  attempt(data, size);
  /* the same bytes with a sound header and checksum */
  if (size < 44 || size > MAX_RECORD) return 0;
  static unsigned char rec[MAX_RECORD];
  hm_monitor_config c;
  hm_vehicle v;
  hm_monitor_settings(monitor, &c);
  hm_monitor_vehicle(monitor, &v);
  memcpy(rec, data, size);
  memcpy(rec, "HMSTATE", 8);
  put_le(rec + 8, HM_STATE_VERSION, 4);
  put_le(rec + 12, size, 4);
  put_le(rec + 16, hm_state_hash(&c, &v), 8);
  put_le(rec + size - 4, hm_state_checksum(rec, size - 4), 4);
  attempt(rec, size);
  return 0;
}
