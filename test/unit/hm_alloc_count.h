/* An allocation counter for the unit tests that check "no allocation" (the binary is linked with --wrap for malloc,
 * calloc and realloc: CMakeLists.txt): n_allocations counts every call. Include it in one file of a test binary. */
#ifndef HM_ALLOC_COUNT_H
#define HM_ALLOC_COUNT_H

#include <stddef.h>

static long n_allocations;
void *__real_malloc(size_t n);
void *__real_calloc(size_t n, size_t m);
void *__real_realloc(void *p, size_t n);
void *__wrap_malloc(size_t n);
void *__wrap_calloc(size_t n, size_t m);
void *__wrap_realloc(void *p, size_t n);
void *__wrap_malloc(size_t n) {
  ++n_allocations;
  return __real_malloc(n);
}
void *__wrap_calloc(size_t n, size_t m) {
  ++n_allocations;
  return __real_calloc(n, m);
}
void *__wrap_realloc(void *p, size_t n) {
  ++n_allocations;
  return __real_realloc(p, n);
}

#endif
