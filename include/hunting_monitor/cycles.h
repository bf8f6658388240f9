/*
 * hunting_monitor - limit cycles of the wheelset model: shooting, Floquet multipliers, pseudo-arclength
 * continuation of the family born at a Hopf point, and its folds (LPC), symmetry-breaking branch points
 * (BPC), period doublings (PD) and Neimark-Sacker points (NS).
 *
 * Method: single shooting with the variational equations, not orthogonal collocation. The model is 4-D,
 * smooth and non-stiff with a cheap right-hand side and periods of about 0.07 s whose Floquet multipliers
 * stay within about 1e-3..1e2, so one shooting interval is well conditioned; the variational equations
 * (integrated with Dormand-Prince 5(4) to rtol) give the monodromy matrix and hence the multipliers exactly
 * to integration accuracy, Newton's matrix is only 5x5 (LAPACK dgesv), and the integrator's error control
 * replaces mesh adaptation. The model is odd (f(-x) = -f(x)) when lambda(y) is even; its symmetric cycles
 * satisfy x(t + T/2) = -x(t), so half a period is shot with the condition x(T/2) = -x(0) (half the cost), and
 * R = -Phi(T/2) gives the multipliers as eig(R)^2 and separates folds (an eigenvalue of R at +1) from
 * symmetry-breaking branch points (an eigenvalue of R at -1).
 *
 * Unknowns: u = (y0, psi0, dpsi0, T, p), the start point on the section dy/dt = 0 (the phase condition), the
 * period and the parameter; continuation in scaled units (mm, mrad, 0.1 rad/s, 10 ms, and 1 km/h, 0.03 MN/m or
 * 0.001 of conicity), so the arclength step is measured in "millimetres and km/h".
 */
#ifndef HUNTING_MONITOR_CYCLES_H
#define HUNTING_MONITOR_CYCLES_H

#include <stddef.h>

#include "hunting_monitor/hopf.h"
#include "hunting_monitor/model.h"
#include "hunting_monitor/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Integration of the shooting system. */
typedef struct {
  double rtol, atol;        /* Dormand-Prince 5(4) tolerances of the state and its variations */
  int use_symmetry;         /* 1: half-period shooting when the vehicle is odd-symmetric; 0: never */
} hm_shooting_options;

/*
 * Pseudo-arclength continuation, shared by cycle families and LPC curves: predictor along the unit tangent (plus,
 * with curvature_predictor, half the step squared times the curvature vector estimated from the last two
 * tangents, (t_k - t_k-1) / ds), Newton's corrector orthogonal to the tangent (an update above 50 scaled units counts as divergence), then step control.
 * Newton has converged when its update, or the error left after it as estimated from the last two updates
 * (d_k^2 / d_(k-1), the linear-convergence bound), is below newton_tol. A step is rejected and retried at half
 * the length (down to ds_min) when the corrector fails, lands farther than max(|ds|, jump_floor) from the
 * predictor (a jump to another branch) or turns the tangent by more than acos(min_tangent_cos). After an accepted
 * step, with predictor_tol > 0, ds is scaled by (predictor_tol / e)^(1/q) within [shrink_factor, grow_factor], e the
 * distance from predictor to corrector, whose error grows as ds^q (q = 2 for the tangent, 3 with the curvature):
 * few points where the branch is straight, many where it bends. With predictor_tol = 0, ds grows by grow_factor when Newton needed at most
 * fast_newton_iters iterations and shrinks by shrink_factor when it needed slow_newton_iters or more.
 */
typedef struct {
  double ds_init, ds_min, ds_max; /* arclength steps (scaled units, see above): 0.2, 1e-4, 20 */
  size_t max_steps;         /* step attempts, accepted or rejected (per direction for LPC curves) */
  double predictor_tol;     /* 0.03 scaled units (30 um or 0.03 km/h); 0: step control by Newton iterations */
  int curvature_predictor;  /* 1 (default): the second-order predictor above; 0: the tangent only */
  double min_tangent_cos;   /* cycles 0.95; LPC curves 0.9 (their fold row makes the tangent noisier) */
  int fast_newton_iters;    /* (predictor_tol = 0) cycles 2; LPC curves 3 (their fold-test row is a chord) */
  int slow_newton_iters;    /* (predictor_tol = 0) cycles 5; LPC curves 6 */
  double grow_factor;       /* 1.5 */
  double shrink_factor;     /* 0.7 */
  double jump_floor;        /* 0.05 scaled units */
  double newton_tol;        /* 1e-9 (max norm of the scaled update or of the estimated error) */
  size_t newton_max_iter;   /* 8 */
  double locate_tol;        /* events are located to this arclength (scaled units): 1e-9 */
} hm_cont_options;

/* The cycle-family defaults above (ds 0.2 in 0.0001..20, 2000 steps, 0.03, 0.95, 2/5, 1.5/0.7, 0.05, 1e-9, 8,
 * 1e-9). */
void hm_cont_options_default(hm_cont_options *opt);
/* 1 if the settings are usable (positive steps in order, 0 < min_tangent_cos < 1, fast < slow, ...). */
int hm_cont_options_valid(const hm_cont_options *opt);

/* Why a continuation ended. */
typedef enum {
  HM_CONT_STEP_LIMIT = 0,   /* max_steps attempts made */
  HM_CONT_PARAM_RANGE,      /* the (first) parameter left [p_min, p_max] */
  HM_CONT_PARAM2_RANGE,     /* LPC curves: the second parameter left its range */
  HM_CONT_AMP_MAX,          /* the cycle's max|y| exceeded amp_max_m */
  HM_CONT_AMP_MIN,          /* LPC curves: the fold cycle shrank below amp_min_m (towards a GH point) */
  HM_CONT_MIN_STEP          /* no step converged even at ds_min */
} hm_cont_stop;

const char *hm_cont_stop_name(hm_cont_stop stop); /* a short English phrase */

typedef struct {
  hm_cont_stop stop;
  size_t steps;             /* accepted steps */
  size_t rejected;          /* rejected step attempts */
  size_t newton_iterations; /* Newton iterations of the run, event location included */
  size_t shots;             /* integrations of the shooting system (LPC: the fold test's gradient included) */
  size_t integration_steps; /* Dormand-Prince steps of those integrations */
} hm_cont_stats;

typedef struct {
  hm_param param;           /* continuation parameter */
  double p_min, p_max;      /* stop when the parameter leaves [p_min, p_max] (user units) */
  double amp_max_m;         /* stop when max|y| exceeds this [m] */
  double amp_start_m;       /* max|y| of the first cycle computed near the Hopf point [m] */
  hm_shooting_options shoot;
  hm_cont_options cont;
} hm_cycle_options;

/* Defaults for parameter p: a wide range, 20 mm amplitude limit, hm_cont_options_default, rtol 1e-9,
 * atol 1e-12 (fold speeds then agree with rtol 1e-12 to 1e-6 km/h), symmetry on. */
void hm_cycle_options_default(hm_cycle_options *opt, hm_param p);

typedef struct {
  double param;             /* parameter value (user units) */
  double period_s;
  double amp_y_m;           /* max |y| over the cycle */
  double amp_psi_rad;       /* max |psi| over the cycle */
  double x0[4];             /* the cycle's point with dy/dt = 0 (and y > 0) */
  double mult_re[4], mult_im[4]; /* Floquet multipliers, by decreasing modulus; the trivial one included */
  int trivial_index;        /* index of the trivial multiplier (closest to +1) */
  int n_unstable;           /* non-trivial multipliers outside the unit circle */
  int stable;               /* 1 if n_unstable == 0 */
  double dparam_ds;         /* parameter component of the unit tangent (scaled): folds where it changes sign */
} hm_cycle_point;

typedef enum {
  HM_CYCLE_LPC = 0,  /* fold (limit point) of cycles */
  HM_CYCLE_BPC = 1,  /* branch point: a real multiplier crosses +1 without a fold (symmetry breaking) */
  HM_CYCLE_PD = 2,   /* period doubling: a real multiplier crosses -1 */
  HM_CYCLE_NS = 3    /* Neimark-Sacker: a complex pair crosses the unit circle */
} hm_cycle_event_kind;

typedef struct {
  hm_cycle_event_kind kind;
  size_t index;             /* the event lies between branch points index - 1 and index */
  hm_cycle_point point;     /* located point */
  int stable_side;          /* LPC: +1 if the stable cycles lie at larger parameter values, -1 smaller, 0 none */
} hm_cycle_event;

const char *hm_cycle_event_name(hm_cycle_event_kind kind); /* "LPC", "BPC", "PD", "NS" */

/*
 * Continue the family of cycles born at the Hopf point `hopf` (found with hm_hopf_find for opt->param; the
 * other parameters are those of veh and speed_kmh). The first cycle is solved at max|y| = amp_start_m, the
 * second at twice that, then pseudo-arclength continuation runs until a stop condition: parameter range,
 * amplitude limit, step limit, or a step that cannot converge even at ds_min. Events are detected between
 * consecutive points (LPC: sign change of dparam_ds; BPC: of det(I - Phi(T/2)) for symmetric cycles, or of the
 * product of (mu - 1) over the non-trivial real multipliers otherwise; PD: of det(M + I); NS: change in the
 * number of complex multipliers outside the unit circle) and located by Brent's method along the arclength.
 * Writes up to max_points points and max_events events; *n_points and *n_events count those written.
 * *stats (may be NULL) receives why the continuation ended and its step, Newton and shot counts.
 * Returns HM_OK if at least two points were computed; otherwise the error that prevented it.
 */
hm_status hm_cycles_continue(const hm_vehicle *veh, double speed_kmh, const hm_hopf_point *hopf,
                             const hm_cycle_options *opt, hm_cycle_point *points, size_t max_points,
                             size_t *n_points, hm_cycle_event *events, size_t max_events, size_t *n_events,
                             hm_cont_stats *stats);

/* The lowest parameter value on a computed branch: the smallest over its points and its located folds (a fold
 * between two points lies below both). +inf for an empty branch. */
double hm_cycles_lowest(const hm_cycle_point *points, size_t n_points, const hm_cycle_event *events, size_t n_events);

/*
 * One cycle at fixed parameter value p near the guess (x0 with dy/dt = 0, period) by Newton's method on the
 * shooting equations (opt->shoot and opt->cont's Newton settings). HM_ENOCONV if Newton does not converge.
 */
hm_status hm_cycle_solve(const hm_vehicle *veh, double speed_kmh, const hm_cycle_options *opt, double p,
                         const double x0_guess[4], double period_guess_s, hm_cycle_point *cycle);

/* ---- two-parameter continuation of folds of cycles (LPC curves) and their cusps (CPC) ---- */

typedef struct {
  hm_param param2;          /* the second parameter (the first is the cycle options' param) */
  double p2_min, p2_max;    /* stop when it leaves this range */
  double amp_min_m;         /* stop when the fold cycle shrinks below this (the curve ends at a GH point) */
  double fd_step;           /* forward-difference step of the fold test's gradient (scaled units) */
  hm_cont_options cont;     /* step control (the shooting settings are the cycle options') */
} hm_lpc_options;

/* Defaults: p2 in [0.1, 100] (or conicity [0.001, 2]), amp_min 0.5 mm, fd 1e-6, and the continuation defaults
 * but ds_init 0.1, 400 steps per direction, min_tangent_cos 0.9 and Newton thresholds 3/6. */
void hm_lpc_options_default(hm_lpc_options *opt, hm_param param2);

typedef struct {
  double p1, p2;            /* the two parameters (user units) */
  double amp_y_m;           /* max |y| of the fold cycle */
  double period_s;
  double x0[4];
  double dp1_ds, dp2_ds;    /* tangent components (scaled) */
} hm_lpc_point;

/*
 * Continue the fold of cycles `fold` (an LPC event from hm_cycles_continue with copt, at the p2 of veh and
 * speed_kmh) in the two parameters (copt->param, lopt->param2), in both directions. Unknowns: the cycle, p1 and
 * p2; equations: the shooting equations, the fold condition det(d res / d(y0, psi0, dpsi0, T)) = 0 (its
 * gradient by forward differences), and the pseudo-arclength condition. Cusp points (CPC) are where dp2/ds
 * changes sign along the curve, located by Brent's method. points (ordered along the curve) and cusps receive
 * up to max_points / max_cusps entries; counts in *n_points, *n_cusps. stats[0..1] (may be NULL) say why each
 * direction (backward, forward) ended and what it cost; the correction onto the first fold counts in stats[0].
 */
hm_status hm_lpc_curve(const hm_vehicle *veh, double speed_kmh, const hm_cycle_options *copt,
                       const hm_lpc_options *lopt, const hm_cycle_event *fold, hm_lpc_point *points,
                       size_t max_points, size_t *n_points, hm_lpc_point *cusps, size_t max_cusps,
                       size_t *n_cusps, hm_cont_stats stats[2]);

#ifdef __cplusplus
}
#endif

#endif
