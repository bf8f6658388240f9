/*
 * hunting_monitor - a parallel loop over POSIX threads for the core's hm_parallel_for_fn (tables.h). It lives in
 * the hunting_monitor_io library (with the files and the text), so the numerical core links LAPACK and libm only.
 */
#ifndef HUNTING_MONITOR_THREADS_H
#define HUNTING_MONITOR_THREADS_H

#include <stddef.h>

#include "hunting_monitor/tables.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
  unsigned n_threads; /* threads to use (the caller's included); 0: one per online processor */
} hm_threads;

/* An hm_parallel_for_fn: runner is an hm_threads *. Indices are handed out one at a time to min(n_threads, n)
 * threads, the calling thread among them; if a thread cannot be started its share runs on the others. */
void hm_threads_parallel_for(void *runner, size_t n, hm_job_fn job, void *ctx);

#ifdef __cplusplus
}
#endif

#endif
