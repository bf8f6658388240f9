/* Private to the core: a cycle's Floquet multipliers from its shooting matrix and the test functions of its events,
 * shared by the wheelset's cycles (cycles.c) and those of any model (system_cycles.c). */
#ifndef HM_CORE_FLOQUET_H
#define HM_CORE_FLOQUET_H

#include <stddef.h>

#include "hunting_monitor/cycles.h"
#include "hunting_monitor/status.h"
#include "continuation.h"

/* The test functions whose sign changes (or, for ns_count, changes) between two cycles of a branch mark its events. */
typedef struct {
  double dparam_ds; /* LPC: the parameter's component of the unit tangent */
  double bpc;       /* BPC: det(R + I) over the real mu (symmetric cycles), else prod(m - 1) over the real non-trivial */
  double pd;        /* PD: det(M + I) over the non-trivial multipliers */
  double ns;        /* NS: the largest modulus of a complex non-trivial multiplier, minus 1 (-inf: none) */
  int ns_count;     /* complex non-trivial multipliers outside the unit circle */
  double amp_m;     /* the cycle's amplitude and stability: on which side of a fold the stable cycles lie */
  int stable;
} hm_cycle_tests;

/*
 * The multipliers of a cycle from phi, Phi(tau) column-major n x n: with symmetric (half-period shooting of an odd
 * model, Phi(T/2)) R = -Phi(T/2) has eigenvalues mu and the multipliers are mu^2; otherwise the eigenvalues of
 * Phi(T). Written by decreasing modulus into mult_re/mult_im[n]; the trivial one (its mu closest to +1) at
 * *trivial_index; *n_unstable the non-trivial ones outside the unit circle; tests filled but for dparam_ds and
 * amp_m (0) and stable (n_unstable == 0).
 */
hm_status hm_floquet(size_t n, const double *phi, int symmetric, double *mult_re, double *mult_im, int *trivial_index,
                     int *n_unstable, hm_cycle_tests *tests);

double hm_cycle_test_value(const hm_cycle_tests *t, hm_cycle_event_kind kind);

/* Which events lie between two consecutive cycles a and b: flags[kind] = 1 (a BPC of full-period shooting only
 * where no fold is, its test function changing sign at folds too). */
void hm_cycle_event_flags(const hm_cycle_tests *a, const hm_cycle_tests *b, int symmetric, int flags[4]);

/* The events between consecutive nodes a and b of a cycle family's continuation (b reached from a by the arclength
 * ds), each node holding its hm_cycle_tests at tests_offset: each flagged one (hm_cycle_event_flags) located by
 * hm_cont_locate into scratch (one node), a Neimark-Sacker kept only where it is a crossing (|test| <= 1e-4), then
 * handed to emit with, for a fold, the side its stable cycles lie on (+1 the larger amplitude, -1 the smaller, 0
 * neither). Written once for the wheelset's engine and any model's. */
void hm_cycle_events_between(hm_cont_problem *p, const hm_cont_options *o, const void *a, const void *b, double ds,
                             size_t tests_offset, int symmetric, void *scratch,
                             void (*emit)(void *ctx, hm_cycle_event_kind kind, const void *located, int stable_side),
                             void *ctx);

#endif
