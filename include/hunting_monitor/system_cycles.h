/*
 * hunting_monitor - limit cycles of any model (system.h) in the running speed: single shooting with the variational
 * equations, Floquet multipliers, pseudo-arclength continuation of the family born at the linear critical (Hopf)
 * speed, and its folds (LPC), symmetry-breaking branch points (BPC), period doublings (PD) and Neimark-Sacker
 * points (NS) (issue #28).
 *
 * The method is cycles.h's, written for dimension n: unknowns u = (x0 without its phase state, T, V), the start
 * point on the section x[phase_state] = 0 (the amplitude coordinate at an extreme), the period and the speed in km/h;
 * residuals x(tau) - sigma x0 with tau = T/2, sigma = -1 for an odd model's symmetric cycles (half the cost; R =
 * -Phi(T/2) separates folds from branch points) and tau = T, sigma = 1 otherwise; the monodromy matrix and the
 * speed sensitivity from the variational equations (Dormand-Prince 8(5,3) at rtol, the error controlled on the state;
 * J Phi multiplies only J's non-zero entries: a bogie's Jacobian is three-quarters zeros). The same continuation engine
 * (continuation.h), step control and event location as the wheelset's families. The family starts at the Hopf point
 * found by hm_system_critical_speed (from v_min_kmh): the first cycle of amplitude amp_start_m along the critical
 * eigenvector, solved with its amplitude fixed, the second at twice that.
 * MODEL.md's wheelset keeps its own 4-state engine (cycles.h: its sparsity written out, the published numbers); run
 * through this one it gives the same folds (test_system_cycles).
 */
#ifndef HUNTING_MONITOR_SYSTEM_CYCLES_H
#define HUNTING_MONITOR_SYSTEM_CYCLES_H

#include <stddef.h>

#include "hunting_monitor/cycles.h"
#include "hunting_monitor/status.h"
#include "hunting_monitor/system.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
  double v_min_kmh, v_max_kmh; /* the Hopf search starts at v_min; continuation stops outside [v_min, v_max] */
  double amp_max_m;            /* stop when the amplitude (any wheelset's max |y|) exceeds this [m] */
  double amp_start_m;          /* the first cycle's amplitude near the Hopf point [m] */
  hm_shooting_options shoot;
  hm_cont_options cont;
} hm_system_cycle_options;

/* 100..1500 km/h, 20 mm, 0.2 mm, rtol 1e-9, atol 1e-12, symmetry on, hm_cont_options_default. */
void hm_system_cycle_options_default(hm_system_cycle_options *opt);

typedef struct {
  size_t dim;
  double speed_kmh;
  double period_s;
  double amp_m;                  /* max |y| over the cycle and every wheelset (wheelset_y_state) */
  double x0[HM_SYSTEM_MAX_DIM];  /* the start point: x[phase_state] = 0 */
  double mult_re[HM_SYSTEM_MAX_DIM], mult_im[HM_SYSTEM_MAX_DIM]; /* Floquet multipliers, decreasing modulus */
  int trivial_index;             /* the trivial multiplier's index (closest to +1) */
  int n_unstable;                /* non-trivial multipliers outside the unit circle */
  int stable;
  double dspeed_ds;              /* the speed's component of the unit tangent (scaled): folds where it changes sign */
} hm_system_cycle_point;

typedef struct {
  hm_cycle_event_kind kind;
  size_t index;                  /* between branch points index - 1 and index */
  hm_system_cycle_point point;
  int stable_side;               /* LPC: +1 stable cycles at higher speeds, -1 lower, 0 none */
} hm_system_cycle_event;

/*
 * The family of cycles born at the system's linear critical speed (the first from v_min_kmh), continued in speed
 * until it leaves [v_min, v_max], exceeds amp_max_m, the step limit or a step that fails at ds_min. Up to max_points
 * points and max_events events written (*n_points, *n_events); stats (may be NULL) as cycles.h's. HM_ENOCRIT if
 * there is no critical speed in the range; HM_OK once two cycles were computed.
 */
hm_status hm_system_cycles_continue(const hm_system *sys, const hm_system_cycle_options *opt,
                                    hm_system_cycle_point *points, size_t max_points, size_t *n_points,
                                    hm_system_cycle_event *events, size_t max_events, size_t *n_events,
                                    hm_cont_stats *stats);

/* One cycle at speed v_kmh near the guess (x0_guess of dim states, its phase state ignored; the period) by Newton's
 * method. HM_ENOCONV if it does not converge. */
hm_status hm_system_cycle_solve(const hm_system *sys, const hm_system_cycle_options *opt, double v_kmh,
                                const double *x0_guess, double period_guess_s, hm_system_cycle_point *cycle);

/* The lowest speed of a computed branch (its points and located folds); +inf if empty. */
double hm_system_cycles_lowest(const hm_system_cycle_point *points, size_t n_points,
                               const hm_system_cycle_event *events, size_t n_events);

#ifdef __cplusplus
}
#endif

#endif
