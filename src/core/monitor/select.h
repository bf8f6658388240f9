/* Internal: order statistics of a double array (the estimator's median stamp difference). */
#ifndef HUNTING_MONITOR_SELECT_H
#define HUNTING_MONITOR_SELECT_H

#include <stddef.h>

/* The k-th smallest of x[0..n) (0 <= k < n, n >= 1; x is reordered): Hoare's selection, O(n) on average. */
static inline double hm_select_kth(double *x, size_t n, size_t k) {
  size_t lo = 0, hi = n - 1;
  while (lo < hi) {
    const double pivot = x[lo + (hi - lo) / 2];
    size_t i = lo, j = hi;
    while (i <= j) {
      while (x[i] < pivot) ++i;
      while (x[j] > pivot) --j;
      if (i <= j) {
        const double t = x[i];
        x[i] = x[j];
        x[j] = t;
        ++i;
        if (j == 0) break;
        --j;
      }
    }
    if (k <= j) hi = j;
    else if (k >= i) lo = i;
    else break;
  }
  return x[k];
}

#endif
