/* libFuzzer harness: the whole online monitor (estimator, identification, margin, alarm) fed arbitrary streams.
 * The input is a sequence of records: one op byte, then a time step and a value (doubles; NaN, inf, denormals,
 * huge, negative and repeated steps all occur): acceleration, speed, or a status update. Statuses must be finite. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "fuzz_monitor.h"
#include "hunting_monitor/monitor.h"

static hm_monitor monitor;

static void check(const hm_monitor_status *s) {
  const hm_assessment *a = &s->assessment;
  if ((unsigned)a->level > HM_LEVEL_ALARM || !isfinite(s->estimate.amplitude_accel_mps2) ||
      !isfinite(s->estimate.frequency_hz) || !isfinite(s->estimate.rms_mps2) || !isfinite(a->margin_hopf_kmh))
    __builtin_trap();
  if (a->level == HM_LEVEL_NO_DATA && a->boundaries_valid) __builtin_trap(); /* stale shown as current */
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (!monitor) {
    hm_monitor_config c;
    hm_monitor_config_default(&c);
    c.modal.min_window_s = 2.0; /* fits early: they are what the fuzzer should reach */
    c.modal.window_s = 5.0;
    monitor = fuzz_monitor_create(&c);
  }
  hm_monitor_reset(monitor);
  double t = 0.0;
  for (size_t k = 0; k + 17 <= size; k += 17) {
    double dt, x;
    memcpy(&dt, data + k + 1, 8);
    memcpy(&x, data + k + 9, 8);
    const uint8_t op = data[k];
    t += (op & 0x80) ? dt : 1.0 / 2000.0; /* mostly regular, sometimes any step */
    const int repeat = 1 + (op & 0x0f) * 64; /* long runs reach the fits */
    for (int r = 0; r < repeat; ++r) {
      const double tr = t + r / 2000.0;
      switch ((op >> 4) & 3) {
        case 0: hm_monitor_push_accel(monitor, tr, (r & 1) ? x : x * sin(tr * 88.0)); break;
        case 1: hm_monitor_push_speed(monitor, tr, x); break;
        default: {
          hm_monitor_status s;
          if (hm_monitor_update(monitor, tr, &s) == HM_OK) check(&s);
        }
      }
    }
    t += (repeat - 1) / 2000.0;
  }
  hm_monitor_status s;
  if (hm_monitor_update(monitor, t, &s) == HM_OK) check(&s);
  return 0;
}
