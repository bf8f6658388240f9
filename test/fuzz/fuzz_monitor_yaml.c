/* libFuzzer harness: the monitor settings parser, and every object created from settings it accepted (the buffers
 * are sized from them: a huge tracking_time_s once overflowed that sizing). */
#include <stdint.h>

#include "hunting_monitor/config.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  hm_monitor_config c;
  hm_monitor_config_default(&c);
  char err[256];
  if (hm_config_parse_monitor((const char *)data, size, "fuzz", &c, err, sizeof err) != HM_OK) return 0;
  hm_estimator e = NULL;
  if (hm_estimator_create(&c.estimator, &e, NULL, 0) != HM_OK) __builtin_trap(); /* accepted means usable */
  for (int i = 0; i < 64; ++i) hm_estimator_push_accel(e, i * 1e-3, 1.0);
  hm_estimator_destroy(e);
  hm_modal m = NULL;
  if (hm_modal_create(&c.modal, c.estimator.sample_rate_hz, &m, NULL, 0) == HM_OK) {
    for (int i = 0; i < 64; ++i) hm_modal_push(m, (double)(i % 7));
    hm_modal_destroy(m);
  }
  hm_vehicle v;
  hm_vehicle_default(&v);
  hm_margin g = NULL;
  if (hm_margin_create(&c.margin, &v, &g, NULL, 0) != HM_OK) __builtin_trap();
  hm_margin_destroy(g);
  return 0;
}
