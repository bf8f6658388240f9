/* libFuzzer harness: the conicity fit on arbitrary point sets (the input read as (y, lambda) pairs of doubles and
 * an options byte). An accepted fit must be finite. */
#include <math.h>
#include <stdint.h>

#include "fuzz_pairs.h"
#include "hunting_monitor/conicity_fit.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (size < 1) return 0;
  enum { MAX = 64 };
  double y[MAX], l[MAX];
  const size_t n = fuzz_pairs(data, size, 1, y, l, MAX);
  hm_fit_options o;
  hm_fit_options_default(&o);
  o.n_terms = 1 + data[0] % 3;
  o.symmetric = (data[0] >> 2) & 1;
  o.fit_constant = !((data[0] >> 3) & 1);
  o.max_iter = 60;
  hm_fit_result r;
  char why[128];
  if (hm_conicity_fit(y, l, n, &o, &r, why, sizeof why) != HM_OK) return 0;
  if (!isfinite(r.sse) || !isfinite(r.conicity.constant)) __builtin_trap();
  return 0;
}
