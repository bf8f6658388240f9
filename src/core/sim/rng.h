/* Private to the core: the one random generator of the simulations (track amplitudes, sensor noise), splitmix64
 * (Steele, Lea, Flood 2014) with Box-Muller for Gaussian numbers. Deterministic for a seed on every platform. */
#ifndef HM_CORE_RNG_H
#define HM_CORE_RNG_H

#include <math.h>
#include <stdint.h>

#include "hunting_monitor/model.h"

/* Uniform in (0, 1): never 0, so log() below is finite. */
static inline double hm_rng_uniform(uint64_t *state) {
  uint64_t z = (*state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return ((double)(z >> 11) + 0.5) / 9007199254740992.0;
}

/* Standard normal (Box-Muller, the cosine half). */
static inline double hm_rng_gaussian(uint64_t *state) {
  const double u1 = hm_rng_uniform(state), u2 = hm_rng_uniform(state);
  return sqrt(-2.0 * log(u1)) * cos(2.0 * HM_PI * u2);
}

#endif
