/* The libFuzzer harnesses' reader of (a, b) pairs of doubles: the input from byte `at` on, 16 bytes a pair. */
#ifndef HUNTING_MONITOR_FUZZ_PAIRS_H
#define HUNTING_MONITOR_FUZZ_PAIRS_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

/* Up to max pairs into a[] and b[] (as many as the input holds); their number. */
static inline size_t fuzz_pairs(const uint8_t *data, size_t size, size_t at, double *a, double *b, size_t max) {
  size_t n = size > at ? (size - at) / 16 : 0;
  if (n > max) n = max;
  for (size_t i = 0; i < n; ++i) {
    memcpy(&a[i], data + at + 16 * i, 8);
    memcpy(&b[i], data + at + 8 + 16 * i, 8);
  }
  return n;
}

#endif
