/* Floquet multipliers and the cycles' event tests (see floquet.h). */
#include "floquet.h"

#include <math.h>
#include <string.h>

#include "hunting_monitor/system.h"
#include "lapack.h"

enum { NMAX = HM_SYSTEM_MAX_DIM };

hm_status hm_floquet(size_t n, const double *phi, int symmetric, double *mult_re, double *mult_im, int *trivial_index,
                     int *n_unstable, hm_cycle_tests *tests) {
  if (n < 1 || n > NMAX) return HM_EINVAL;
  double a[NMAX * NMAX], re[NMAX], im[NMAX], work[8 * NMAX], dummy[1];
  memcpy(a, phi, n * n * sizeof(double));
  const int nn = (int)n, one = 1, lwork = 8 * NMAX;
  int info = 0;
  dgeev_("N", "N", &nn, a, &nn, re, im, dummy, &one, dummy, &one, work, &lwork, &info, 1, 1);
  if (info != 0) return HM_ELAPACK;
  /* Symmetric cycles: R = -Phi(T/2) has eigenvalues mu = -eig(Phi), the multipliers are mu^2, and det(R + I) =
   * prod(mu + 1) changes sign where a real mu crosses -1 (symmetry-breaking branch point). Otherwise the multipliers
   * are eig(Phi(T)) and the branch-point test is prod(m - 1) over the non-trivial real ones. The trivial multiplier
   * (eigenvalue of R at +1 along the flow) is the one closest to +1. */
  double bpc = 1.0, dmin = INFINITY;
  size_t trivial = 0;
  for (size_t i = 0; i < n; ++i) {
    const double mr = symmetric ? -re[i] : re[i], mi = symmetric ? -im[i] : im[i];
    const double d = hypot(mr - 1.0, mi);
    if (d < dmin) dmin = d, trivial = i;
    if (symmetric) {
      if (mi == 0.0) bpc *= mr + 1.0;
      re[i] = mr * mr - mi * mi;
      im[i] = 2.0 * mr * mi;
    }
  }
  if (!symmetric)
    for (size_t i = 0; i < n; ++i)
      if (i != trivial && im[i] == 0.0) bpc *= re[i] - 1.0;
  size_t order[NMAX]; /* by decreasing modulus, following the trivial multiplier */
  for (size_t i = 0; i < n; ++i) order[i] = i;
  for (size_t i = 1; i < n; ++i)
    for (size_t j = i; j > 0 && hypot(re[order[j - 1]], im[order[j - 1]]) < hypot(re[order[j]], im[order[j]]); --j) {
      const size_t tmp = order[j];
      order[j] = order[j - 1];
      order[j - 1] = tmp;
    }
  hm_cycle_tests t = {0.0, bpc, 1.0, -INFINITY, 0, 0.0, 0};
  int unstable = 0, triv = 0;
  for (size_t k = 0; k < n; ++k) {
    const size_t i = order[k];
    mult_re[k] = re[i];
    mult_im[k] = im[i];
    if (i == trivial) {
      triv = (int)k;
      continue;
    }
    const double mod = hypot(re[i], im[i]);
    if (mod > 1.0) ++unstable;
    if (fabs(im[i]) > 1e-12 * (1.0 + mod) && mod > 1.0) ++t.ns_count;
    if (im[i] != 0.0) t.ns = fmax(t.ns, mod - 1.0);
    if (im[i] == 0.0) t.pd *= re[i] + 1.0;
    else if (im[i] > 0.0) t.pd *= (re[i] + 1.0) * (re[i] + 1.0) + im[i] * im[i];
  }
  *trivial_index = triv;
  *n_unstable = unstable;
  t.stable = unstable == 0;
  *tests = t;
  return HM_OK;
}

double hm_cycle_test_value(const hm_cycle_tests *t, hm_cycle_event_kind kind) {
  switch (kind) {
    case HM_CYCLE_LPC: return t->dparam_ds;
    case HM_CYCLE_BPC: return t->bpc;
    case HM_CYCLE_PD: return t->pd;
    case HM_CYCLE_NS: return t->ns;
  }
  return NAN;
}

static int sign_change(double x, double y) { return (x > 0.0) != (y > 0.0); }

void hm_cycle_event_flags(const hm_cycle_tests *a, const hm_cycle_tests *b, int symmetric, int flags[4]) {
  flags[HM_CYCLE_LPC] = sign_change(a->dparam_ds, b->dparam_ds);
  flags[HM_CYCLE_BPC] = sign_change(a->bpc, b->bpc) && (symmetric || !flags[HM_CYCLE_LPC]);
  flags[HM_CYCLE_PD] = sign_change(a->pd, b->pd);
  flags[HM_CYCLE_NS] = a->ns_count != b->ns_count && a->ns > -INFINITY && b->ns > -INFINITY;
}

typedef struct {
  hm_cycle_event_kind kind;
  size_t offset;
} test_of;

static const hm_cycle_tests *tests_at(const void *node, size_t offset) {
  return (const hm_cycle_tests *)((const char *)node + offset);
}

static double located_test(const void *node, void *arg) {
  const test_of *t = (const test_of *)arg;
  return hm_cycle_test_value(tests_at(node, t->offset), t->kind);
}

void hm_cycle_events_between(hm_cont_problem *p, const hm_cont_options *o, const void *a, const void *b, double ds,
                             size_t tests_offset, int symmetric, void *scratch,
                             void (*emit)(void *ctx, hm_cycle_event_kind kind, const void *located, int stable_side),
                             void *ctx) {
  const hm_cycle_tests *ta = tests_at(a, tests_offset), *tb = tests_at(b, tests_offset);
  int flags[4];
  hm_cycle_event_flags(ta, tb, symmetric, flags);
  for (int k = 0; k < 4; ++k) {
    if (!flags[k]) continue;
    test_of t = {(hm_cycle_event_kind)k, tests_offset};
    if (hm_cont_locate(p, o, a, b, ds, hm_cycle_test_value(ta, t.kind), hm_cycle_test_value(tb, t.kind), located_test,
                       &t, scratch) != HM_OK)
      continue;
    if (k == HM_CYCLE_NS && fabs(tests_at(scratch, tests_offset)->ns) > 1e-4) continue; /* not a crossing */
    int side = 0;
    if (k == HM_CYCLE_LPC) {
      const hm_cycle_tests *upper = ta->amp_m > tb->amp_m ? ta : tb, *lower = upper == ta ? tb : ta;
      side = upper->stable ? 1 : lower->stable ? -1 : 0;
    }
    emit(ctx, t.kind, scratch, side);
  }
}
