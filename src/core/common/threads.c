/* A parallel loop over POSIX threads (see threads.h). */
#include "hunting_monitor/threads.h"

#include <pthread.h>
#include <unistd.h>

enum { MAX_THREADS = 64 };

typedef struct {
  pthread_mutex_t lock;
  size_t next, n;
  hm_job_fn job;
  void *ctx;
} loop;

static void *worker(void *arg) {
  loop *l = (loop *)arg;
  for (;;) {
    pthread_mutex_lock(&l->lock);
    const size_t i = l->next < l->n ? l->next++ : l->n;
    pthread_mutex_unlock(&l->lock);
    if (i == l->n) return NULL;
    l->job(l->ctx, i);
  }
}

void hm_threads_parallel_for(void *runner, size_t n, hm_job_fn job, void *ctx) {
  const hm_threads *t = (const hm_threads *)runner;
  long want = t && t->n_threads ? (long)t->n_threads : sysconf(_SC_NPROCESSORS_ONLN);
  if (want < 1) want = 1;
  if (want > MAX_THREADS) want = MAX_THREADS;
  if ((size_t)want > n) want = (long)n;
  loop l = {PTHREAD_MUTEX_INITIALIZER, 0, n, job, ctx};
  pthread_t tid[MAX_THREADS];
  int started[MAX_THREADS] = {0};
  for (long k = 1; k < want; ++k) started[k] = pthread_create(&tid[k], NULL, worker, &l) == 0;
  worker(&l); /* the calling thread takes its share */
  for (long k = 1; k < want; ++k)
    if (started[k]) pthread_join(tid[k], NULL);
  pthread_mutex_destroy(&l.lock);
}
