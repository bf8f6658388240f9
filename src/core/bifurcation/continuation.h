/* Private to the core: the pseudo-arclength continuation engine shared by the cycle families (cycles.c) and the
 * fold-of-cycles curves (lpc.c): Newton's corrector on n - 1 equations plus the arclength row, the tangent, the
 * predictor, the branch-jump guard, step control and event location, written once. The problems supply their
 * equations through callbacks; the step-control settings are the public hm_cont_options (cycles.h). */
#ifndef HM_CORE_CONTINUATION_H
#define HM_CORE_CONTINUATION_H

#include <stddef.h>

#include "hunting_monitor/cycles.h"
#include "hunting_monitor/system.h"

#define HM_CONT_MAX_N (HM_SYSTEM_MAX_DIM + 2) /* largest number of unknowns: a cycle of any model (system_cycles.c) */

/* The head of every problem's node: the unknowns and the unit tangent there. */
typedef struct {
  double u[HM_CONT_MAX_N]; /* unknowns (user units) */
  double t[HM_CONT_MAX_N]; /* unit tangent in scaled units (u / scale) */
} hm_cont_point;

typedef struct {
  size_t n;                /* unknowns; the problem has n - 1 equations */
  const double *scale;     /* scale of each unknown: the engine works in u / scale */
  size_t node_size;        /* sizeof the problem's node, whose first member is an hm_cont_point */
  void *ctx;
  /* Scaled residual res[n - 1] and Jacobian jac[(n - 1) x n] (row-major, d res / d(u / scale)) at u. iter counts
   * from 0 within one correction; rows the problem does not refresh after iter 0 (a chord) keep their values. */
  hm_status (*eval)(void *ctx, const double *u, int iter, double *res, double *jac);
  /* Fill the node at the converged u with the unit tangent t (from the last evaluation). */
  hm_status (*finish)(void *ctx, const double *u, const double *t, void *node);
  /* The reason to stop at this node, or HM_CONT_RUNNING. */
  int (*stop)(void *ctx, const void *node);
  /* Called for each accepted step from a to b of arclength ds (event detection, storage); may be NULL. */
  void (*accepted)(void *ctx, const void *a, const void *b, double ds);
  /* counters, added to by the engine */
  size_t newton_iterations;
} hm_cont_problem;

enum { HM_CONT_RUNNING = -1 };

/* Newton's method from u (in/out) on the equations and row . (u / scale) = target, then the unit tangent oriented
 * along tref; fills node. HM_ENOCONV if it does not converge in o->newton_max_iter iterations or an update exceeds
 * 50 scaled units (divergence). *iters (may be NULL) gets the iteration count. */
hm_status hm_cont_correct(hm_cont_problem *p, const hm_cont_options *o, double *u, const double *row, double target,
                          const double *tref, void *node, int *iters);

/* One pseudo-arclength step of length sigma from node a: predictor along a's tangent, corrector orthogonal to it,
 * rejected (HM_ENOCONV) when the corrector lands farther than max(|sigma|, o->jump_floor) from the predictor. */
hm_status hm_cont_step(hm_cont_problem *p, const hm_cont_options *o, const void *a, double sigma, void *out,
                       int *iters);

/* Continue from *cur until a stop reason, the step limit or a failure at ds_min; *cur ends as the last node.
 * scratch is one more node. stats (may be NULL) gets the stop reason and step counts (newton_iterations is
 * the problem's counter's growth during the run). */
hm_cont_stop hm_cont_run(hm_cont_problem *p, const hm_cont_options *o, void *cur, void *scratch,
                         hm_cont_stats *stats);

/* Locate the zero of test(node) between node a (value fa) and node b, the step ds further (value fb), by Brent's
 * method along the arclength to o->locate_tol; out gets the node there. Each correction starts from the point
 * found last (at first b), moved along a's tangent. */
hm_status hm_cont_locate(hm_cont_problem *p, const hm_cont_options *o, const void *a, const void *b, double ds,
                         double fa, double fb, double (*test)(const void *node, void *arg), void *arg, void *out);

#endif
