/* The continuation engine (src/core/bifurcation/continuation.c) on curves with closed forms: a circle (points, tangents, the
 * located fold), a line (step growth, the step limit, a failure wall, the branch-jump guard), and its options. */
#include <string.h>

#include "continuation.h"
#include "hm_test.h"

typedef struct {
  hm_cont_point head;
} pnode;

typedef struct {
  hm_cont_problem prob;
  int curve;          /* 0: circle x^2 + y^2 = 1; 1: line y = 0 */
  double wall_x;      /* line: evaluation fails beyond this x */
  double stop_x;      /* circle: stop once x < stop_x on the upper half */
  pnode nodes[4000];
  size_t n;
  double max_turn_cos_violation; /* smallest cos between consecutive accepted tangents */
} plane;

static const double unit_scale[2] = {1.0, 1.0};

static hm_status eval(void *ctx, const double *u, int iter, double *res, double *jac) {
  (void)iter;
  const plane *p = (const plane *)ctx;
  if (p->curve == 0) {
    res[0] = u[0] * u[0] + u[1] * u[1] - 1.0;
    jac[0] = 2.0 * u[0];
    jac[1] = 2.0 * u[1];
  } else {
    if (u[0] > p->wall_x) return HM_EDOMAIN;
    res[0] = u[1];
    jac[0] = 0.0;
    jac[1] = 1.0;
  }
  return HM_OK;
}

static hm_status finish(void *ctx, const double *u, const double *t, void *node) {
  (void)ctx;
  pnode *nd = (pnode *)node;
  memset(nd, 0, sizeof *nd);
  memcpy(nd->head.u, u, 2 * sizeof(double));
  memcpy(nd->head.t, t, 2 * sizeof(double));
  return HM_OK;
}

static int stop(void *ctx, const void *node) {
  const plane *p = (const plane *)ctx;
  const pnode *nd = (const pnode *)node;
  if (p->curve == 0 && nd->head.u[1] > 0.0 && nd->head.u[0] < p->stop_x) return HM_CONT_PARAM_RANGE;
  return HM_CONT_RUNNING;
}

static void accepted(void *ctx, const void *a, const void *b, double ds) {
  (void)ds;
  plane *p = (plane *)ctx;
  const pnode *na = (const pnode *)a, *nb = (const pnode *)b;
  const double c = na->head.t[0] * nb->head.t[0] + na->head.t[1] * nb->head.t[1];
  if (c < p->max_turn_cos_violation) p->max_turn_cos_violation = c;
  if (p->n < sizeof p->nodes / sizeof p->nodes[0]) p->nodes[p->n++] = *nb;
}

static void setup(plane *p, int curve) {
  memset(p, 0, sizeof *p);
  p->curve = curve;
  p->wall_x = 1e300;
  p->max_turn_cos_violation = 1.0;
  p->prob.n = 2;
  p->prob.scale = unit_scale;
  p->prob.node_size = sizeof(pnode);
  p->prob.ctx = p;
  p->prob.eval = eval;
  p->prob.finish = finish;
  p->prob.stop = stop;
  p->prob.accepted = accepted;
}

static double dx_ds(const void *node, void *arg) {
  (void)arg;
  return ((const pnode *)node)->head.t[0];
}

/* Around the circle from (0, -1) anticlockwise: every point on it, every tangent (-y, x), no accepted step turning
 * the tangent more than acos(min_tangent_cos), and the fold in x at (1, 0) located by the engine. */
static void circle(void) {
  static plane p;
  setup(&p, 0);
  p.stop_x = -0.5;
  hm_cont_options o;
  hm_cont_options_default(&o);
  o.ds_max = 0.5;
  double u[2] = {0.1, -1.2};
  const double row[2] = {1.0, 0.0}, tref[2] = {1.0, 0.0};
  pnode cur, scratch;
  int iters = 0;
  HM_CHECK(hm_cont_correct(&p.prob, &o, u, row, 0.0, tref, &cur, &iters) == HM_OK, "start");
  HM_CHECK_DELTA(cur.head.u[0], 0.0, 1e-12, "start x");
  HM_CHECK_DELTA(cur.head.u[1], -1.0, 1e-12, "start y");
  HM_CHECK(iters >= 2 && iters <= 6, "Newton iterations from 0.2 away: %d", iters);
  hm_cont_stats s;
  HM_CHECK(hm_cont_run(&p.prob, &o, &cur, &scratch, &s) == HM_CONT_PARAM_RANGE, "stop reason %d", s.stop);
  HM_CHECK(s.stop == HM_CONT_PARAM_RANGE && s.steps == p.n && s.steps > 5, "steps %zu, stored %zu", s.steps, p.n);
  HM_CHECK(s.newton_iterations >= s.steps, "Newton iterations %zu", s.newton_iterations);
  double worst_res = 0.0, worst_t = 0.0;
  for (size_t i = 0; i < p.n; ++i) {
    const double x = p.nodes[i].head.u[0], y = p.nodes[i].head.u[1];
    worst_res = fmax(worst_res, fabs(hypot(x, y) - 1.0));
    worst_t = fmax(worst_t, hypot(p.nodes[i].head.t[0] + y, p.nodes[i].head.t[1] - x));
  }
  HM_CHECK(worst_res < 1e-9, "distance from the circle %g", worst_res);
  /* the tangent comes from the last evaluation, within the last Newton update (~sqrt(newton_tol)) of the point */
  HM_CHECK(worst_t < 1e-6, "tangent off (-y, x) by %g", worst_t);
  HM_CHECK(p.max_turn_cos_violation >= o.min_tangent_cos, "a step turned the tangent by acos(%g)",
           p.max_turn_cos_violation);
  HM_CHECK(cur.head.u[0] < p.stop_x && cur.head.u[1] > 0.0, "ended at (%g, %g)", cur.head.u[0], cur.head.u[1]);
  /* the fold in x: dx/ds changes sign at (1, 0) */
  size_t k = 0;
  while (k + 1 < p.n && !(p.nodes[k].head.t[0] > 0.0 && p.nodes[k + 1].head.t[0] <= 0.0)) ++k;
  HM_CHECK(k + 1 < p.n, "fold bracketed");
  if (k + 1 < p.n) {
    /* the step between the bracketing nodes: its length along the tangent is the arclength parameter */
    const pnode *a = &p.nodes[k], *b = &p.nodes[k + 1];
    const double ds = (b->head.u[0] - a->head.u[0]) * a->head.t[0] + (b->head.u[1] - a->head.u[1]) * a->head.t[1];
    pnode fold;
    HM_CHECK(hm_cont_locate(&p.prob, &o, a, b, ds, a->head.t[0], b->head.t[0], dx_ds, NULL, &fold) == HM_OK, "locate");
    HM_CHECK_DELTA(fold.head.u[0], 1.0, 1e-12, "fold x");
    HM_CHECK_DELTA(fold.head.u[1], 0.0, 1e-8, "fold y");
  }
}

/* Along y = 0 from the origin: a linear problem converges in one Newton iteration, so every step grows by
 * grow_factor up to ds_max; the step limit stops it where the geometric sum says. */
static void line_steps(void) {
  static plane p;
  setup(&p, 1);
  hm_cont_options o;
  hm_cont_options_default(&o);
  o.max_steps = 12;
  o.ds_max = 2.0;
  pnode cur = {{{0.0, 0.0}, {1.0, 0.0}}}, scratch;
  hm_cont_stats s;
  HM_CHECK(hm_cont_run(&p.prob, &o, &cur, &scratch, &s) == HM_CONT_STEP_LIMIT, "stop %d", s.stop);
  double x = 0.0, ds = o.ds_init;
  for (size_t i = 0; i < o.max_steps; ++i) {
    x += ds;
    ds = fmin(ds * o.grow_factor, o.ds_max);
  }
  HM_CHECK_DELTA(cur.head.u[0], x, 1e-12, "end of the line");
  HM_CHECK(s.steps == 12 && s.rejected == 0 && s.newton_iterations == 12, "steps %zu rejected %zu Newton %zu",
           s.steps, s.rejected, s.newton_iterations);
}

/* A wall at x = 0.5 where evaluation fails: the engine halves the step down to ds_min and stops there, within
 * ds_min of the wall. */
static void failure_wall(void) {
  static plane p;
  setup(&p, 1);
  p.wall_x = 0.5;
  hm_cont_options o;
  hm_cont_options_default(&o);
  pnode cur = {{{0.0, 0.0}, {1.0, 0.0}}}, scratch;
  hm_cont_stats s;
  HM_CHECK(hm_cont_run(&p.prob, &o, &cur, &scratch, &s) == HM_CONT_MIN_STEP, "stop %d", s.stop);
  HM_CHECK(cur.head.u[0] <= 0.5 && cur.head.u[0] > 0.5 - o.ds_min, "stopped at x = %.9f", cur.head.u[0]);
  HM_CHECK(s.rejected > 0, "rejected %zu", s.rejected);
}

/* The branch-jump guard: from (0, 0) on y = 0 with a wrong tangent (0.6, 0.8), a step of 0.5 predicts (0.3, 0.4)
 * and the corrector, orthogonal to the tangent, lands on (0.3 + 0.4 / 0.6 * 0.8, 0) = (5/6, 0), 2/3 away: rejected
 * with the default floor, accepted (at exactly that point) with a floor of 1. */
static void jump_guard(void) {
  static plane p;
  setup(&p, 1);
  hm_cont_options o;
  hm_cont_options_default(&o);
  const pnode a = {{{0.0, 0.0}, {0.6, 0.8}}};
  pnode out;
  HM_CHECK(hm_cont_step(&p.prob, &o, &a, 0.5, &out, NULL) == HM_ENOCONV, "jump rejected");
  o.jump_floor = 1.0;
  HM_CHECK(hm_cont_step(&p.prob, &o, &a, 0.5, &out, NULL) == HM_OK, "accepted with floor 1");
  HM_CHECK_DELTA(out.head.u[0], 5.0 / 6.0, 1e-14, "landing x");
  HM_CHECK_DELTA(out.head.u[1], 0.0, 1e-15, "landing y");
}

static void options(void) {
  hm_cont_options o, bad;
  hm_cont_options_default(&o);
  HM_CHECK(hm_cont_options_valid(&o), "defaults valid");
  bad = o;
  bad.fast_newton_iters = bad.slow_newton_iters;
  HM_CHECK(!hm_cont_options_valid(&bad), "fast >= slow");
  bad = o;
  bad.min_tangent_cos = 1.0;
  HM_CHECK(!hm_cont_options_valid(&bad), "min_tangent_cos 1");
  bad = o;
  bad.ds_init = bad.ds_min / 2.0;
  HM_CHECK(!hm_cont_options_valid(&bad), "ds_init < ds_min");
  bad = o;
  bad.ds_max = NAN;
  HM_CHECK(!hm_cont_options_valid(&bad), "ds_max NaN");
  bad = o;
  bad.shrink_factor = 0.0;
  HM_CHECK(!hm_cont_options_valid(&bad), "shrink 0");
  HM_CHECK(!hm_cont_options_valid(NULL), "NULL");
  HM_CHECK(strcmp(hm_cont_stop_name(HM_CONT_MIN_STEP), "no convergence at the smallest step") == 0, "name");
}

int main(void) {
  HM_RUN(circle);
  HM_RUN(line_steps);
  HM_RUN(failure_wall);
  HM_RUN(jump_guard);
  HM_RUN(options);
  HM_TEST_EXIT();
}
