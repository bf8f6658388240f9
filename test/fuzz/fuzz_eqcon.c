/* libFuzzer harness: the equivalent conicity (eqcon.h) on arbitrary delta-r tables (the input read as (y, delta-r)
 * pairs of doubles after a byte choosing the method and an amplitude). A table accepted gives, at any amplitude,
 * either a refusal or a finite conicity and wavelength; never a hang (bounded bisections and panels). */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "fuzz_pairs.h"
#include "hunting_monitor/eqcon.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (size < 9) return 0;
  enum { MAX = 256 };
  double y[MAX], dr[MAX], amp;
  memcpy(&amp, data + 1, 8);
  const size_t n = fuzz_pairs(data, size, 9, y, dr, MAX);
  hm_eqcon_config c;
  hm_eqcon_config_default(&c);
  hm_eqcon e = NULL;
  char why[160];
  if (hm_eqcon_create(&c, y, dr, n, &e, why, sizeof why) != HM_OK) return 0;
  hm_eqcon_result r;
  const double amps[3] = {amp, 1e-3, 0.5 * (y[n - 1] - y[0])};
  for (int k = 0; k < 3; ++k)
    if (hm_eqcon_at(e, (hm_eqcon_method)(data[0] & 1), amps[k], &r) == HM_OK &&
        (!isfinite(r.tan_gamma_e) || !(r.wavelength_m > 0.0)))
      __builtin_trap();
  hm_eqcon_destroy(e);
  return 0;
}
