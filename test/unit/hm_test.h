/*
 * Minimal test harness for the C core's unit tests: each test case prints "PASS name" or "FAIL name" (with
 * the failed checks above it); scripts/test counts those lines. Every check compares against an independent
 * reference with a stated tolerance.
 */
#ifndef HM_TEST_H
#define HM_TEST_H

#include <math.h>
#include <stdio.h>

static int hm_test_case_failed;
static int hm_test_passed, hm_test_failed;

#define HM_CHECK(cond, ...)                                     \
  do {                                                          \
    if (!(cond)) {                                              \
      hm_test_case_failed = 1;                                  \
      printf("  check failed at %s:%d: ", __FILE__, __LINE__); \
      printf(__VA_ARGS__);                                      \
      printf("\n");                                             \
    }                                                           \
  } while (0)

/* |x - ref| <= tol */
#define HM_CHECK_DELTA(x, ref, tol, what)                                                                   \
  do {                                                                                                      \
    const double hm_x_ = (x), hm_r_ = (ref), hm_t_ = (tol);                                                 \
    HM_CHECK(fabs(hm_x_ - hm_r_) <= hm_t_, "%s = %.12g, expected %.12g +- %.3g (off by %.3g)", what, hm_x_, \
             hm_r_, hm_t_, hm_x_ - hm_r_);                                                                  \
  } while (0)

/* |x - ref| <= rel |ref| */
#define HM_CHECK_REL(x, ref, rel, what) HM_CHECK_DELTA(x, ref, (rel) * fabs(ref), what)

#define HM_RUN(fn)                          \
  do {                                      \
    hm_test_case_failed = 0;                \
    fn();                                   \
    if (hm_test_case_failed) {              \
      hm_test_failed++;                     \
      printf("FAIL %s\n", #fn);             \
    } else {                                \
      hm_test_passed++;                     \
      printf("PASS %s\n", #fn);             \
    }                                       \
    fflush(stdout);                         \
  } while (0)

#define HM_TEST_EXIT() return hm_test_failed ? 1 : 0

/* Deterministic uniform random numbers (xorshift64*), so failures reproduce. */
static unsigned long long hm_test_rng_state = 0x9E3779B97F4A7C15ull;
static inline double hm_test_uniform(double lo, double hi) {
  hm_test_rng_state ^= hm_test_rng_state >> 12;
  hm_test_rng_state ^= hm_test_rng_state << 25;
  hm_test_rng_state ^= hm_test_rng_state >> 27;
  const unsigned long long r = hm_test_rng_state * 2685821657736338717ull;
  return lo + (hi - lo) * ((double)(r >> 11) / 9007199254740992.0);
}

/* Standard normal numbers (Box-Muller on the generator above). */
static inline double hm_test_gauss(void) {
  const double u1 = hm_test_uniform(1e-12, 1.0), u2 = hm_test_uniform(0.0, 1.0);
  return sqrt(-2.0 * log(u1)) * cos(6.283185307179586 * u2);
}

#endif
