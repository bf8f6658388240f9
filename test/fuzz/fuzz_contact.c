/* libFuzzer harness: delta-r from arbitrary wheel and rail profiles (contact.h): the input split into a wheel and a
 * rail of (y, z) doubles after a byte choosing the inclination and the roll. Either a refusal or finite radii, contacts on the
 * track; the out array untouched on refusal. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "fuzz_pairs.h"
#include "hunting_monitor/contact.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (size < 1) return 0;
  enum { MAX = 128 };
  double w[2][MAX], r[2][MAX];
  const size_t pairs = (size - 1) / 16, nw = pairs / 2 > MAX ? MAX : pairs / 2, nr = pairs - nw > MAX ? MAX : pairs - nw;
  fuzz_pairs(data, size, 1, w[0], w[1], nw);
  fuzz_pairs(data, size, 1 + 16 * nw, r[0], r[1], nr);
  hm_contact_config c;
  hm_contact_config_default(&c);
  c.inclination = (data[0] % 3) / 40.0;
  c.include_roll = (data[0] >> 2) & 1;
  const hm_profile wp = {w[0], w[1], nw}, rp = {r[0], r[1], nr};
  const double s[3] = {-0.008, 0.0, 0.008};
  hm_contact_point p[3];
  memset(p, 0, sizeof p);
  char why[160];
  if (hm_contact_delta_r(&c, &wp, NULL, &rp, NULL, s, 3, p, why, sizeof why) != HM_OK) {
    if (p[0].r_left_m != 0.0) __builtin_trap();
    return 0;
  }
  for (int k = 0; k < 3; ++k)
    if (!isfinite(p[k].delta_r_m) || !isfinite(p[k].contact_left_m) || !isfinite(p[k].contact_right_m))
      __builtin_trap();
  return 0;
}
