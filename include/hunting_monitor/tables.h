/*
 * hunting_monitor - boundary tables: what the online monitor consults.
 *
 * For a vehicle and a grid of equivalent conicities lambda(0) (the constant term of lambda(y) shifted), the
 * table holds the Hopf speed and l1, the lowest speed at which any limit cycle exists (the nonlinear critical
 * speed: the minimum of the speed over the whole cycle family, i.e. over its folds) and the family of cycles
 * itself as a polyline (speed, amplitude max|y|, stability), decimated so that linear interpolation along it
 * stays within 1 um and 0.01 km/h of the computed branch.
 *
 * A lookup at (conicity, speed) interpolates 1/V_hopf^2 linearly in conicity (exact: the Hurwitz condition is
 * affine in lambda), and compares the two neighbouring conicities' cycle families at the same fraction of their
 * own Hopf speed (hunting speeds scale together, Klingel's V ~ 1/sqrt(lambda)): each family is intersected
 * with that speed, giving the edge of the basin of the stable origin (the smallest unstable cycle; zero where
 * the origin is unstable, none where no cycle exists) and the smallest stable cycle beyond it; amplitudes and
 * speed ratios are then interpolated linearly in conicity. The table
 * states its own interpolation error: at build time every midpoint conicity is computed as well and compared
 * with the lookup (Hopf and lowest-cycle speeds, and edge amplitudes at every 5 km/h).
 *
 * File format (text, one record per line, '#' comments):
 *   hunting_monitor_boundary_table 1
 *   kx_mn_m K  ky_mn_m K  speed_min_kmh V  speed_max_kmh V  amp_max_m A
 *   error_hopf_kmh E  error_lowest_kmh E  error_edge_amp_m E
 *   conicity L hopf_kmh V l1 X lowest_kmh V n N      (then N lines: v_kmh amplitude_m stable)
 */
#ifndef HUNTING_MONITOR_TABLES_H
#define HUNTING_MONITOR_TABLES_H

#include <stddef.h>

#include "hunting_monitor/mode_model.h"
#include "hunting_monitor/model.h"
#include "hunting_monitor/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct hm_table_s *hm_table;

/* Largest speed a table may hold or be built for [km/h]: a parser bound, far above any rail vehicle. */
#define HM_TABLE_MAX_SPEED_KMH 3000.0

typedef struct {
  double conicity_min, conicity_max;  /* lambda(0) range */
  size_t n_conicity;                  /* grid points, >= 2 */
  double speed_min_kmh, speed_max_kmh;/* continuation range of the cycle families */
  double amp_max_m;                   /* largest cycle amplitude followed */
  double rtol;                        /* shooting tolerance */
} hm_table_spec;

/* Defaults: conicity 0.05..0.40 (15 points), speeds 150..700 km/h, cycles up to 16 mm, rtol 1e-10. */
void hm_table_spec_default(hm_table_spec *spec);

/* One unit of work of a parallel loop: index i of [0, n). */
typedef void (*hm_job_fn)(void *ctx, size_t i);
/* Runs job(ctx, i) for every i in [0, n), in any order and possibly at the same time on several threads, and
 * returns when all are done. The core has no threads of its own: the caller supplies this (threads.h has one
 * over POSIX threads). */
typedef void (*hm_parallel_for_fn)(void *runner, size_t n, hm_job_fn job, void *ctx);

/* Compute a table: a cycle family per grid conicity and per midpoint between them (the midpoints measure the
 * interpolation error), 2 n - 1 continuations of about 20-60 ms each. hm_table_build runs them in order on the
 * calling thread; hm_table_build_parallel hands them to pfor(runner, ...) (the families are independent; the
 * result is the same). */
hm_status hm_table_build(const hm_vehicle *veh, const hm_table_spec *spec, hm_table *out);
hm_status hm_table_build_parallel(const hm_vehicle *veh, const hm_table_spec *spec, hm_parallel_for_fn pfor,
                                  void *runner, hm_table *out);
/* The same for a bogie's or car's model (kind HM_MODEL_BOGIE or HM_MODEL_CAR; its wheelsets' conicity shifted):
 * its critical speed by eigenvalues and its families by system_cycles.h (about 0.25 s each for the bogie); the file's
 * l1 is then only its sign (+1 subcritical: the family starts towards lower speeds, -1 supercritical) and kx_mn_m,
 * ky_mn_m its wheelsets' primary stiffnesses. HM_EINVAL for the wheelset (hm_table_build). */
hm_status hm_table_build_model(hm_model_kind kind, const hm_car *params, const hm_table_spec *spec,
                               hm_parallel_for_fn pfor, void *runner, hm_table *out);

/* Serialise into buf (len bytes); *needed gets the full size including the terminating NUL. HM_EINVAL if
 * len is too small (then call again with *needed bytes). */
hm_status hm_table_format(const hm_table t, char *buf, size_t len, size_t *needed);

/* Parse text (HM_EPARSE with "line N: reason" in err); hm_table_load_file reads a file first (HM_EIO). */
hm_status hm_table_parse(const char *text, size_t len, hm_table *out, char *err, size_t err_len);
hm_status hm_table_load_file(const char *path, hm_table *out, char *err, size_t err_len);

void hm_table_destroy(hm_table t);

typedef struct {
  double conicity;              /* the query's conicity, clamped to the table */
  double hopf_speed_kmh;        /* linear critical speed */
  double l1;                    /* first Lyapunov coefficient there (NAN from a widened lookup: not known outside) */
  double lowest_cycle_speed_kmh;/* nonlinear critical speed: below it no cycle exists */
  int origin_stable;            /* speed below the Hopf speed */
  int has_edge;                 /* an unstable cycle bounds the basin of the stable origin at this speed */
  double edge_amp_m;            /* its amplitude max|y| (0 if the origin is unstable) */
  int has_stable_outer;         /* a stable cycle exists beyond the edge (hunting stays bounded there) */
  double stable_outer_amp_m;    /* its amplitude */
  int clamped;                  /* the conicity or speed was outside the table and was clamped */
  int widened;                  /* the conicity was outside the table: hm_table_lookup_widened's cautious reading */
  int consistent;               /* both neighbouring conicities have the same cycles (count, edge, outer) here */
  double neighbour_spread_m;    /* largest difference of the neighbours' amplitudes (a local error indicator) */
  double error_speed_kmh;       /* stated interpolation error of the speeds (max of the table's two) */
  double error_amp_m;           /* stated interpolation error of the amplitudes where consistent */
} hm_table_lookup_result;

/* Boundaries at (conicity, speed). No allocation. HM_EDOMAIN for non-finite input. Outside the table's conicities the
 * end conicity's boundaries (clamped), its Hopf speed included: see hm_table_lookup_widened. */
hm_status hm_table_lookup(const hm_table t, double conicity, double speed_kmh, hm_table_lookup_result *out);
/* The same inside the table; outside its conicities (issue #27 item 8) the cautious reading, widened, not the end
 * conicity's: the Hopf speed extrapolated along the end interval (exact: 1/V^2 is affine in lambda); three readings
 * of the cycles at this speed, (a) the end conicity's own, (b) its family at this conicity's fraction of the Hopf
 * speed (Klingel), (c) the end interval extrapolated; the lowest cycle speed and the edge (the unstable cycle) the
 * least of (a) and of (b) and (c) less their difference, the stable outer cycle the largest so (the stated errors
 * the table's: the Hopf speed is exact, the rest widened already); l1 NAN (not known there); clamped and widened
 * set, conicity the end's. (On the table 0.12-0.16: at 0.20 and 0.25 the
 * lowest cycle speed 186.2 and 141.0 km/h for the continuation's 226.8 and 218.2, where the end's is 234.5; the edge
 * at 0.95 of the Hopf speed 7.35 and 7.23 mm for 7.40 and 7.33, the end's 8.13 and 8.52: test_tables. Cautious, and
 * far from exact that far out.) The end conicity's edge counts only below its own Hopf speed. A speed outside the
 * table's is clamped. HM_EDOMAIN for non-finite input, or a conicity whose extrapolated Hopf speed does not exist. */
hm_status hm_table_lookup_widened(const hm_table t, double conicity, double speed_kmh, hm_table_lookup_result *out);

/* The stiffnesses [MN/m] of the vehicle the table was made for (a user checks them against its vehicle). */
void hm_table_vehicle(const hm_table t, double *kx_mn_m, double *ky_mn_m);

/* Whether the table was made for this vehicle: the stiffnesses agree to 1e-6 relative and every conicity's
 * Hopf speed agrees with the vehicle's closed-form critical speed (linear.h) within tol_kmh. HM_EDOMAIN with
 * the reason in why otherwise (a table of another vehicle, or a corrupt one, must not be used). */
#define HM_TABLE_CHECK_TOL_KMH 0.01 /* tables are written with 10 significant digits: 1e-7 km/h of rounding */
hm_status hm_table_check_vehicle(const hm_table t, const hm_vehicle *veh, double tol_kmh, char *why, size_t why_len);
/* The same against a bogie's or car's model: every curve's Hopf speed within tol_kmh of the model's exact one. */
hm_status hm_table_check_model(const hm_table t, hm_mode_model model, double tol_kmh, char *why, size_t why_len);

/* The interpolation error to expect at a conicity: the table's measured errors (at the midpoints of its original
 * grid step h0, where linear interpolation errs most) scaled by 4 d (h - d) / h0^2, d the distance to the curve
 * below in an interval of width h (the parabolic error profile of linear interpolation; 0 on a curve). */
hm_status hm_table_local_error(const hm_table t, double conicity, double *err_speed_kmh, double *err_amp_m);

/* A copy of t with the exact cycle family at this conicity added (one continuation, 10-60 ms), for veh (checked
 * against the table as hm_table_check_vehicle does). t is only read: another thread may keep using it meanwhile.
 * HM_EDOMAIN for a conicity outside the table or on one of its curves. */
hm_status hm_table_refine(const hm_table t, const hm_vehicle *veh, double conicity, hm_table *out);

/* A point of a cycle family as the table holds it (the polyline from the Hopf point on). */
typedef struct {
  double speed_kmh;
  double amp_m;       /* max |y| of the cycle */
  int stable;         /* the segment from this point to the next is of stable cycles */
  int fold;           /* a turning point in speed (a fold of cycles, LPC) */
} hm_family_point;

/* The cycle family at a conicity, for display: the table's own curve when it has one there (*exact = 1), else the
 * nearest curve's with its speeds scaled by the ratio of the Hopf speeds (Klingel: V ~ 1/sqrt(lambda)), as lookups
 * compare neighbours at the same fraction of their Hopf speeds (*exact = 0). Writes up to max points, *n the
 * number the family has. HM_EDOMAIN outside the table's conicities or for non-finite input. */
hm_status hm_table_family(const hm_table t, double conicity, hm_family_point *points, size_t max, size_t *n,
                          int *exact);

/* Number of conicities and the range, for reporting. */
size_t hm_table_size(const hm_table t, double *conicity_min, double *conicity_max);

#ifdef __cplusplus
}
#endif

#endif
