/* Boundary tables: build from cycle families, check against a vehicle, and look up (see tables.h); the text format
 * is in tables_io.c. */
#include "hunting_monitor/tables.h"

#include "hunting_monitor/car.h"
#include "hunting_monitor/mode_model.h"
#include "hunting_monitor/system_cycles.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hunting_monitor/cycles.h"
#include "hunting_monitor/hopf.h"
#include "hunting_monitor/linear.h"
#include "tables_internal.h"

void hm_table_spec_default(hm_table_spec *spec) {
  spec->conicity_min = 0.05;
  spec->conicity_max = 0.40;
  spec->n_conicity = 15;
  spec->speed_min_kmh = 150.0;
  spec->speed_max_kmh = 700.0;
  spec->amp_max_m = 0.016;
  spec->rtol = 1e-10;
}

void hm_table_destroy(hm_table t) {
  if (!t) return;
  for (size_t i = 0; i < t->n; ++i) free(t->curves[i].pts);
  free(t->curves);
  free(t);
}

hm_table hm_table_alloc(size_t n) {
  hm_table t = calloc(1, sizeof *t);
  if (!t) return NULL;
  t->curves = calloc(n, sizeof *t->curves);
  if (!t->curves) {
    free(t);
    return NULL;
  }
  t->n = n;
  return t;
}

/* ---- lookup ---- */

typedef struct {
  int has_edge, has_outer;
  double edge, outer;
  size_t count; /* cycles at this speed */
} curve_cycles;

/* Basin edge and stable outer cycle of one curve at speed v (origin stable iff v < its Hopf speed). */
static curve_cycles cycles_of(const tcurve *c, double v) {
  double amp[64];
  int stable[64];
  size_t m = 0;
  for (size_t i = 1; i < c->n && m < 64; ++i) {
    const tpoint *a = &c->pts[i - 1], *b = &c->pts[i];
    if ((a->v_kmh - v) * (b->v_kmh - v) > 0.0 || a->v_kmh == b->v_kmh) continue;
    const double f = (v - a->v_kmh) / (b->v_kmh - a->v_kmh);
    amp[m] = a->amp_m + f * (b->amp_m - a->amp_m);
    stable[m] = a->stable && b->stable;
    ++m;
  }
  curve_cycles r = {0, 0, 0.0, 0.0, m};
  const int origin_stable = v < c->hopf_kmh;
  if (!origin_stable) {
    r.has_edge = 1; /* the origin itself is unstable: no margin at all */
    r.edge = 0.0;
  }
  for (size_t i = 0; i < m; ++i) {
    if (origin_stable && !stable[i] && (!r.has_edge || amp[i] < r.edge)) {
      r.has_edge = 1;
      r.edge = amp[i];
    }
  }
  for (size_t i = 0; i < m; ++i)
    if (stable[i] && (!r.has_edge || amp[i] > r.edge) && (!r.has_outer || amp[i] < r.outer)) {
      r.has_outer = 1;
      r.outer = amp[i];
    }
  return r;
}

/* The interval [curves[i], curves[i+1]] holding c (clamped). */
static size_t interval_of(const hm_table t, double c) {
  size_t lo = 0, hi = t->n - 1;
  while (hi - lo > 1) {
    const size_t mid = (lo + hi) / 2;
    if (t->curves[mid].conicity <= c) lo = mid;
    else hi = mid;
  }
  return lo;
}

/* The Hopf speed at weight w along the interval [curves[i], curves[i+1]] (w outside [0, 1] extrapolates: exact, as
 * 1/V_hopf^2 is affine in lambda(0), linear.h); 0 where the extrapolation leaves no Hopf speed. */
static double hopf_at(const hm_table t, size_t i, double w) {
  const tcurve *a = &t->curves[i], *b = &t->curves[i + 1];
  const double inv2 = 1.0 / (a->hopf_kmh * a->hopf_kmh) + w * (1.0 / (b->hopf_kmh * b->hopf_kmh) -
                                                               1.0 / (a->hopf_kmh * a->hopf_kmh));
  return inv2 > 0.0 ? 1.0 / sqrt(inv2) : 0.0;
}

/* The boundaries at speed v of a conicity whose Hopf speed is hopf_kmh, from the interval [curves[i], curves[i+1]] at
 * weight w: the other speeds scale with the Hopf speed (Klingel: V ~ 1/sqrt(lambda)), so their ratios to it are
 * interpolated and the neighbours' cycle families compared at the same fraction of their own Hopf speed. */
static void lookup_at(const hm_table t, size_t i, double w, double hopf_kmh, double v, double speed_kmh,
                      hm_table_lookup_result *out) {
  const tcurve *a = &t->curves[i], *b = &t->curves[i + 1];
  hm_table_lookup_result r;
  memset(&r, 0, sizeof r);
  r.hopf_speed_kmh = hopf_kmh;
  r.l1 = a->l1 + w * (b->l1 - a->l1);
  const double ra = a->lowest_kmh / a->hopf_kmh, rb = b->lowest_kmh / b->hopf_kmh;
  r.lowest_cycle_speed_kmh = (ra + w * (rb - ra)) * r.hopf_speed_kmh;
  r.origin_stable = speed_kmh < r.hopf_speed_kmh;
  const double ratio = v / r.hopf_speed_kmh;
  const curve_cycles ca = cycles_of(a, ratio * a->hopf_kmh), cb = cycles_of(b, ratio * b->hopf_kmh);
  /* where only one neighbour has a cycle, take it (the smaller margin); otherwise interpolate */
  if (ca.has_edge || cb.has_edge) {
    r.has_edge = 1;
    r.edge_amp_m = ca.has_edge && cb.has_edge ? ca.edge + w * (cb.edge - ca.edge) : ca.has_edge ? ca.edge : cb.edge;
  }
  if (!r.origin_stable) {
    r.has_edge = 1;
    r.edge_amp_m = 0.0;
  }
  if (ca.has_outer || cb.has_outer) {
    r.has_stable_outer = 1;
    r.stable_outer_amp_m =
        ca.has_outer && cb.has_outer ? ca.outer + w * (cb.outer - ca.outer) : ca.has_outer ? ca.outer : cb.outer;
  }
  r.neighbour_spread_m = fmax(ca.has_edge && cb.has_edge ? fabs(ca.edge - cb.edge) : 0.0,
                              ca.has_outer && cb.has_outer ? fabs(ca.outer - cb.outer) : 0.0);
  r.consistent = ca.count == cb.count && ca.has_edge == cb.has_edge && ca.has_outer == cb.has_outer;
  r.error_speed_kmh = fmax(t->err_hopf_kmh, t->err_lowest_kmh);
  r.error_amp_m = t->err_amp_m;
  *out = r;
}

hm_status hm_table_lookup(const hm_table t, double conicity, double speed_kmh, hm_table_lookup_result *out) {
  if (!t || !out || t->n < 2) return HM_EINVAL;
  if (!isfinite(conicity) || !isfinite(speed_kmh)) return HM_EDOMAIN;
  double c = conicity, v = speed_kmh;
  int clamped = 0;
  const double cmin = t->curves[0].conicity, cmax = t->curves[t->n - 1].conicity;
  if (c < cmin || c > cmax) {
    c = fmin(fmax(c, cmin), cmax);
    clamped = 1;
  }
  if (v < t->speed_min_kmh || v > t->speed_max_kmh) {
    v = fmin(fmax(v, t->speed_min_kmh), t->speed_max_kmh);
    clamped = 1;
  }
  const size_t i = interval_of(t, c); /* bracketing curves i, i+1 */
  const double w = (c - t->curves[i].conicity) / (t->curves[i + 1].conicity - t->curves[i].conicity);
  lookup_at(t, i, w, hopf_at(t, i, w), v, speed_kmh, out);
  out->conicity = c;
  out->clamped = clamped;
  return HM_OK;
}

/* The more cautious of two readings of the amplitude of a cycle that bounds the stable origin's basin (the smaller) or
 * of one that hunting may reach (the larger; toward: -1 or +1), less their difference as its error. */
static double cautious(double x, double y, double toward) {
  return toward < 0.0 ? fmin(x, y) - fabs(x - y) : fmax(x, y) + fabs(x - y);
}

hm_status hm_table_lookup_widened(const hm_table t, double conicity, double speed_kmh, hm_table_lookup_result *out) {
  if (!t || !out || t->n < 2) return HM_EINVAL;
  if (!isfinite(conicity) || !isfinite(speed_kmh)) return HM_EDOMAIN;
  const double cmin = t->curves[0].conicity, cmax = t->curves[t->n - 1].conicity;
  if (conicity >= cmin && conicity <= cmax) return hm_table_lookup(t, conicity, speed_kmh, out);
  const double v = fmin(fmax(speed_kmh, t->speed_min_kmh), t->speed_max_kmh);
  const size_t i = conicity < cmin ? 0 : t->n - 2; /* the end interval */
  const double w_end = conicity < cmin ? 0.0 : 1.0;
  const double w = (conicity - t->curves[i].conicity) / (t->curves[i + 1].conicity - t->curves[i].conicity);
  const double hopf = hopf_at(t, i, w);
  if (!(hopf > 0.0)) return HM_EDOMAIN;
  /* (a) the end conicity's boundaries at this speed; (b) its family at this conicity's fraction of the Hopf speed;
   * (c) the end interval extrapolated */
  hm_table_lookup_result ra, rb, rc;
  lookup_at(t, i, w_end, hopf_at(t, i, w_end), v, speed_kmh, &ra);
  lookup_at(t, i, w_end, hopf, v, speed_kmh, &rb);
  lookup_at(t, i, w, hopf, v, speed_kmh, &rc);
  hm_table_lookup_result r = rc;
  r.conicity = t->curves[i + (size_t)w_end].conicity;
  r.clamped = r.widened = 1;
  r.l1 = NAN; /* not known outside the table: the end conicity's had been given, unflagged (issue #27's review) */
  r.lowest_cycle_speed_kmh = fmax(0.0, fmin(ra.lowest_cycle_speed_kmh, cautious(rb.lowest_cycle_speed_kmh,
                                                                                rc.lowest_cycle_speed_kmh, -1.0)));
  /* (the end conicity's edge only where its own origin is stable: beyond its Hopf speed it has none to give) */
  const int a_edge = ra.has_edge && ra.origin_stable;
  r.has_edge = a_edge || rb.has_edge || rc.has_edge;
  if (r.has_edge && r.origin_stable) {
    double e = INFINITY;
    if (a_edge) e = fmin(e, ra.edge_amp_m);
    if (rb.has_edge && rc.has_edge) e = fmin(e, cautious(rb.edge_amp_m, rc.edge_amp_m, -1.0));
    else if (rb.has_edge || rc.has_edge) e = fmin(e, rb.has_edge ? rb.edge_amp_m : rc.edge_amp_m);
    r.edge_amp_m = fmax(e, 0.0);
  }
  r.has_stable_outer = ra.has_stable_outer && rb.has_stable_outer && rc.has_stable_outer;
  if (r.has_stable_outer)
    r.stable_outer_amp_m = fmax(ra.stable_outer_amp_m, cautious(rb.stable_outer_amp_m, rc.stable_outer_amp_m, 1.0));
  r.consistent = ra.consistent && rb.consistent && rc.consistent && ra.has_edge == rc.has_edge &&
                 ra.has_stable_outer == rc.has_stable_outer;
  r.neighbour_spread_m = fmax(fmax(ra.neighbour_spread_m, rc.neighbour_spread_m), fabs(rb.edge_amp_m - rc.edge_amp_m));
  *out = r; /* (the stated errors the table's: the Hopf speed is exact, the rest already widened) */
  return HM_OK;
}

void hm_table_vehicle(const hm_table t, double *kx_mn_m, double *ky_mn_m) {
  if (kx_mn_m) *kx_mn_m = t ? t->kx_mn_m : NAN;
  if (ky_mn_m) *ky_mn_m = t ? t->ky_mn_m : NAN;
}

size_t hm_table_size(const hm_table t, double *conicity_min, double *conicity_max) {
  if (!t || t->n == 0) return 0;
  if (conicity_min) *conicity_min = t->curves[0].conicity;
  if (conicity_max) *conicity_max = t->curves[t->n - 1].conicity;
  return t->n;
}

/* ---- build ---- */

/* Keep the points needed for linear interpolation along the branch within 1 um and 0.01 km/h, every change
 * of stability and both ends. Returns the number kept (in place). */
static size_t decimate(tpoint *p, size_t n) {
  if (n <= 2) return n;
  size_t kept = 1, k = 0; /* p[0] kept */
  size_t j = 1;
  while (j < n) {
    size_t best = j;
    for (size_t e = j + 1; e < n; ++e) {
      int ok = p[e].stable == p[k].stable && p[e - 1].stable == p[k].stable;
      double s_total = 0.0;
      for (size_t q = k + 1; q <= e; ++q)
        s_total += hypot((p[q].v_kmh - p[q - 1].v_kmh) / 0.01, (p[q].amp_m - p[q - 1].amp_m) / 1e-6);
      double s = 0.0;
      for (size_t q = k + 1; q < e && ok; ++q) {
        s += hypot((p[q].v_kmh - p[q - 1].v_kmh) / 0.01, (p[q].amp_m - p[q - 1].amp_m) / 1e-6);
        const double f = s_total > 0.0 ? s / s_total : 0.0;
        ok = fabs(p[k].v_kmh + f * (p[e].v_kmh - p[k].v_kmh) - p[q].v_kmh) <= 0.01 &&
             fabs(p[k].amp_m + f * (p[e].amp_m - p[k].amp_m) - p[q].amp_m) <= 1e-6;
      }
      if (!ok) break;
      best = e;
    }
    p[kept++] = p[best];
    k = best;
    j = best + 1;
  }
  return kept;
}

/* The polyline of a family: the Hopf point (amplitude 0), then the branch br[0..np) with its located folds
 * folds[0..nf) (each between branch points fold_index - 1 and fold_index, in order) as vertices (a fold between two
 * points is the branch's extreme there; flagged stable, each segment beside it takes the stability of its other end),
 * decimated into tp (room for np + nf + 1 points; shrunk, and owned by the curve); the lowest speed over the Hopf
 * point, the branch and its folds. */
static void family_curve(double conicity, double hopf_kmh, double l1, const tpoint *br, size_t np,
                         const tpoint *folds, const size_t *fold_index, size_t nf, tpoint *tp, tcurve *out) {
  double lowest = hopf_kmh;
  size_t m = 0, k = 0;
  tp[m++] = (tpoint){hopf_kmh, 0.0, br[0].stable};
  for (size_t i = 0; i < np; ++i) {
    for (; k < nf && fold_index[k] <= i; ++k)
      if (fold_index[k] == i && i > 0) {
        tp[m++] = folds[k];
        lowest = fmin(lowest, folds[k].v_kmh);
      }
    tp[m++] = br[i];
    lowest = fmin(lowest, br[i].v_kmh);
  }
  const size_t kept = decimate(tp, m);
  tpoint *shrunk = realloc(tp, kept * sizeof *tp);
  *out = (tcurve){conicity, hopf_kmh, l1, lowest, kept, shrunk ? shrunk : tp};
}

static hm_status curve_at(const hm_vehicle *veh, const hm_table_spec *spec, double conicity, tcurve *out) {
  hm_vehicle v = *veh;
  hm_status st = hm_vehicle_set_conicity_at_zero(&v, conicity);
  if (st != HM_OK) return st;
  hm_hopf_point h;
  size_t n = 0;
  if ((st = hm_hopf_find(&v, 500.0, HM_PARAM_SPEED, 1.0, 1e5, 1e-10, &h, 1, &n)) != HM_OK) return st;
  if (n == 0) return HM_ENOCRIT;
  hm_cycle_options o;
  hm_cycle_options_default(&o, HM_PARAM_SPEED);
  o.p_min = spec->speed_min_kmh;
  o.p_max = fmax(spec->speed_max_kmh, 1.2 * h.speed_kmh);
  o.amp_max_m = spec->amp_max_m;
  o.shoot.rtol = spec->rtol;
  o.shoot.atol = spec->rtol * 1e-3;
  /* every point the continuation can make: the two at the start and one per step attempt (300 kB, not the 3 MB of a
   * fixed 20000: a worker refining the table in the background then stays in the heap, off mmap/munmap) */
  const size_t CAP = o.cont.max_steps + 2;
  hm_cycle_point *pts = malloc(CAP * sizeof *pts);
  enum { MAX_EV = 64 };
  tpoint *tp = malloc((CAP + MAX_EV + 1) * sizeof *tp), *br = malloc(CAP * sizeof *br), folds[MAX_EV];
  hm_cycle_event ev[MAX_EV];
  size_t np = 0, ne = 0, nf = 0, fold_index[MAX_EV];
  if (!pts || !tp || !br) st = HM_ENOMEM;
  if (st == HM_OK) st = hm_cycles_continue(&v, 500.0, &h, &o, pts, CAP, &np, ev, MAX_EV, &ne, NULL);
  if (st == HM_OK && np > 0) {
    for (size_t i = 0; i < np; ++i) br[i] = (tpoint){pts[i].param, pts[i].amp_y_m, pts[i].stable};
    for (size_t k = 0; k < ne; ++k)
      if (ev[k].kind == HM_CYCLE_LPC)
        fold_index[nf] = ev[k].index, folds[nf++] = (tpoint){ev[k].point.param, ev[k].point.amp_y_m, 1};
    family_curve(conicity, h.speed_kmh, h.l1, br, np, folds, fold_index, nf, tp, out);
    tp = NULL;
  }
  free(pts);
  free(br);
  free(tp);
  return st;
}

/* A bogie's or car's curve at a conicity: its critical speed (the first crossing from 100 km/h) and its family of
 * cycles (system_cycles.h); l1 is not known without a normal form: its sign only (+1 when the family starts towards
 * lower speeds, subcritical). */
static hm_status curve_at_model(hm_model_kind kind, const hm_car *params, const hm_table_spec *spec, double conicity,
                                tcurve *out) {
  hm_car c = *params;
  hm_status st = hm_vehicle_set_conicity_at_zero(&c.bogie.wheelset, conicity);
  if (st != HM_OK) return st;
  hm_bogie_model bm;
  hm_car_model cm;
  hm_system sys;
  st = kind == HM_MODEL_CAR ? hm_car_model_init(&cm, &c, 0, &sys) : hm_bogie_model_init(&bm, &c.bogie, 0, &sys);
  if (st != HM_OK) return st;
  hm_system_critical_options copt;
  hm_system_critical_options_default(&copt);
  double vh_mps;
  if ((st = hm_system_critical_speed(&sys, &copt, &vh_mps, NULL)) != HM_OK) return st;
  const double vh = hm_kmh_from_mps(vh_mps);
  hm_system_cycle_options o;
  hm_system_cycle_options_default(&o);
  o.v_min_kmh = fmin(spec->speed_min_kmh, 0.9 * vh);
  o.v_max_kmh = fmax(spec->speed_max_kmh, 1.2 * vh);
  o.amp_max_m = spec->amp_max_m;
  o.shoot.rtol = spec->rtol;
  o.shoot.atol = spec->rtol * 1e-3;
  const size_t CAP = o.cont.max_steps + 2;
  enum { MAX_EV = 64 };
  hm_system_cycle_point *pts = malloc(CAP * sizeof *pts);
  tpoint *tp = malloc((CAP + MAX_EV + 1) * sizeof *tp), *br = malloc(CAP * sizeof *br), folds[MAX_EV];
  hm_system_cycle_event ev[MAX_EV];
  size_t np = 0, ne = 0, nf = 0, fold_index[MAX_EV];
  if (!pts || !tp || !br) st = HM_ENOMEM;
  if (st == HM_OK) st = hm_system_cycles_continue(&sys, &o, pts, CAP, &np, ev, MAX_EV, &ne, NULL);
  if (st == HM_OK && np > 1) {
    for (size_t i = 0; i < np; ++i) br[i] = (tpoint){pts[i].speed_kmh, pts[i].amp_m, pts[i].stable};
    for (size_t k = 0; k < ne; ++k)
      if (ev[k].kind == HM_CYCLE_LPC)
        fold_index[nf] = ev[k].index, folds[nf++] = (tpoint){ev[k].point.speed_kmh, ev[k].point.amp_m, 1};
    const double l1 = pts[1].speed_kmh < pts[0].speed_kmh ? 1.0 : -1.0;
    family_curve(conicity, vh, l1, br, np, folds, fold_index, nf, tp, out);
    tp = NULL;
  } else if (st == HM_OK) {
    st = HM_ENOCONV;
  }
  free(pts);
  free(br);
  free(tp);
  return st;
}

/* Largest difference between the table (without the midpoint curve) and the computed midpoint curve. */
static void midpoint_errors(hm_table t, const tcurve *mid, double *e_hopf, double *e_low, double *e_amp) {
  hm_table_lookup_result r;
  if (hm_table_lookup(t, mid->conicity, t->speed_min_kmh, &r) != HM_OK) return;
  *e_hopf = fmax(*e_hopf, fabs(r.hopf_speed_kmh - mid->hopf_kmh));
  *e_low = fmax(*e_low, fabs(r.lowest_cycle_speed_kmh - mid->lowest_kmh));
  for (double v = t->speed_min_kmh; v <= t->speed_max_kmh; v += 5.0) {
    const curve_cycles exact = cycles_of(mid, v);
    if (hm_table_lookup(t, mid->conicity, v, &r) != HM_OK) continue;
    /* near the lowest cycle speed, or where the neighbours disagree on which cycles exist (flagged per lookup),
     * the error is the speed error above */
    if (fabs(v - mid->lowest_kmh) <= 2.0 * *e_low + 1.0 || !r.consistent) continue;
    if (exact.has_edge && r.has_edge) *e_amp = fmax(*e_amp, fabs(r.edge_amp_m - exact.edge));
    if (exact.has_outer && r.has_stable_outer) *e_amp = fmax(*e_amp, fabs(r.stable_outer_amp_m - exact.outer));
  }
}

static int spec_valid(const hm_table_spec *s) {
  return s->n_conicity >= 2 && s->n_conicity <= 1000 && s->conicity_min > 0.0 && isfinite(s->conicity_max) &&
         s->conicity_max > s->conicity_min && s->speed_min_kmh > 0.0 && s->speed_max_kmh > s->speed_min_kmh &&
         s->speed_max_kmh <= HM_TABLE_MAX_SPEED_KMH && s->amp_max_m > 1e-3 && s->amp_max_m <= 0.1 && s->rtol > 0.0 &&
         s->rtol < 1e-3;
}

hm_status hm_table_check_vehicle(const hm_table t, const hm_vehicle *veh, double tol_kmh, char *why, size_t len) {
  if (!t || !veh || !(tol_kmh > 0.0)) return HM_EINVAL;
  hm_status st = hm_vehicle_validate(veh, why, len);
  if (st != HM_OK) return st;
  const double kx = veh->stiffness_long_n_m / 1e6, ky = veh->stiffness_lat_n_m / 1e6;
  if (fabs(t->kx_mn_m - kx) > 1e-6 * kx || fabs(t->ky_mn_m - ky) > 1e-6 * ky) {
    if (why && len)
      snprintf(why, len, "table made for Kx %g, Ky %g MN/m, vehicle has Kx %g, Ky %g MN/m", t->kx_mn_m, t->ky_mn_m,
               kx, ky);
    return HM_EDOMAIN;
  }
  for (size_t i = 0; i < t->n; ++i) {
    double v_mps;
    const hm_status s = hm_linear_critical_speed(veh, t->curves[i].conicity, &v_mps);
    const double v = s == HM_OK ? hm_kmh_from_mps(v_mps) : NAN;
    if (!(fabs(v - t->curves[i].hopf_kmh) <= tol_kmh)) {
      if (why && len)
        snprintf(why, len, "table Hopf speed %g km/h at conicity %g does not match the vehicle's %g km/h",
                 t->curves[i].hopf_kmh, t->curves[i].conicity, v);
      return HM_EDOMAIN;
    }
  }
  return HM_OK;
}

hm_status hm_table_check_model(const hm_table t, hm_mode_model model, double tol_kmh, char *why, size_t len) {
  if (!t || !model || !(tol_kmh > 0.0)) return HM_EINVAL;
  for (size_t i = 0; i < t->n; ++i) {
    double v = NAN;
    if (hm_mode_model_hopf(model, t->curves[i].conicity, &v, NULL, NULL) != HM_OK) v = NAN;
    if (!(fabs(v - t->curves[i].hopf_kmh) <= tol_kmh)) {
      if (why && len)
        snprintf(why, len, "table Hopf speed %g km/h at conicity %g does not match the %s's %g km/h",
                 t->curves[i].hopf_kmh, t->curves[i].conicity, hm_model_kind_name(hm_mode_model_kind(model)), v);
      return HM_EDOMAIN;
    }
  }
  return HM_OK;
}

/* The families of a build: grid curves 0..n-1, then midpoints n..2n-2; each job fills its own slot. */
typedef struct {
  const hm_vehicle *veh;
  hm_model_kind kind;    /* the wheelset (veh), or a bogie's or car's (params) */
  const hm_car *params;
  const hm_table_spec *spec;
  tcurve *curves;
  hm_status *status;
  size_t n;
} build_ctx;

static void build_job(void *ctx, size_t i) {
  build_ctx *b = (build_ctx *)ctx;
  const double dc = (b->spec->conicity_max - b->spec->conicity_min) / (double)(b->n - 1);
  const double at = i < b->n ? (double)i : (double)(i - b->n) + 0.5, lambda = b->spec->conicity_min + dc * at;
  b->status[i] = b->kind == HM_MODEL_WHEELSET ? curve_at(b->veh, b->spec, lambda, &b->curves[i])
                                              : curve_at_model(b->kind, b->params, b->spec, lambda, &b->curves[i]);
}

static void run_in_order(void *runner, size_t n, hm_job_fn job, void *ctx) {
  (void)runner;
  for (size_t i = 0; i < n; ++i) job(ctx, i);
}

static hm_status build(hm_model_kind kind, const hm_car *params, const hm_table_spec *spec, hm_parallel_for_fn pfor,
                       void *runner, hm_table *out) {
  const hm_vehicle *veh = &params->bogie.wheelset;
  hm_status st = HM_OK;
  const size_t n = spec->n_conicity, jobs = 2 * n - 1;
  hm_table t = hm_table_alloc(n);
  tcurve *curves = calloc(jobs, sizeof *curves);
  hm_status *status = malloc(jobs * sizeof *status);
  if (!t || !curves || !status) {
    hm_table_destroy(t);
    free(curves);
    free(status);
    return HM_ENOMEM;
  }
  for (size_t i = 0; i < jobs; ++i) status[i] = HM_EINVAL; /* a job the runner skipped fails the build */
  build_ctx b = {veh, kind, params, spec, curves, status, n};
  (pfor ? pfor : run_in_order)(runner, jobs, build_job, &b);
  for (size_t i = 0; i < jobs && st == HM_OK; ++i) st = status[i];
  t->kx_mn_m = veh->stiffness_long_n_m / 1e6;
  t->ky_mn_m = veh->stiffness_lat_n_m / 1e6;
  t->speed_min_kmh = spec->speed_min_kmh;
  t->speed_max_kmh = spec->speed_max_kmh;
  t->amp_max_m = spec->amp_max_m;
  for (size_t i = 0; i < n; ++i) { /* the table owns the grid curves (freed with it, built or not) */
    t->curves[i] = curves[i];
    curves[i].pts = NULL;
  }
  double e_hopf = 0.0, e_low = 0.0, e_amp = 0.0;
  for (size_t i = n; i < jobs && st == HM_OK; ++i) midpoint_errors(t, &curves[i], &e_hopf, &e_low, &e_amp);
  for (size_t i = n; i < jobs; ++i) free(curves[i].pts);
  free(curves);
  free(status);
  if (st != HM_OK) {
    hm_table_destroy(t);
    return st;
  }
  t->err_hopf_kmh = e_hopf;
  t->err_lowest_kmh = e_low;
  t->err_amp_m = e_amp;
  t->err_step = (spec->conicity_max - spec->conicity_min) / (double)(n - 1);
  t->rtol = spec->rtol;
  *out = t;
  return HM_OK;
}

hm_status hm_table_build_parallel(const hm_vehicle *veh, const hm_table_spec *spec, hm_parallel_for_fn pfor,
                                  void *runner, hm_table *out) {
  if (!veh || !spec || !out || !spec_valid(spec)) return HM_EINVAL;
  hm_status st = hm_vehicle_validate(veh, NULL, 0);
  if (st != HM_OK) return st;
  hm_car c;
  hm_car_default(&c);
  c.bogie.wheelset = *veh;
  return build(HM_MODEL_WHEELSET, &c, spec, pfor, runner, out);
}

hm_status hm_table_build_model(hm_model_kind kind, const hm_car *params, const hm_table_spec *spec,
                               hm_parallel_for_fn pfor, void *runner, hm_table *out) {
  if (!params || !spec || !out || !spec_valid(spec) || (kind != HM_MODEL_BOGIE && kind != HM_MODEL_CAR))
    return HM_EINVAL;
  hm_status st = kind == HM_MODEL_CAR ? hm_car_validate(params, NULL, 0) : hm_bogie_validate(&params->bogie, NULL, 0);
  return st == HM_OK ? build(kind, params, spec, pfor, runner, out) : st;
}

hm_status hm_table_family(const hm_table t, double conicity, hm_family_point *points, size_t max, size_t *n,
                          int *exact) {
  if (!t || t->n < 2 || !n || !exact || (max && !points)) return HM_EINVAL;
  if (!isfinite(conicity) || conicity < t->curves[0].conicity || conicity > t->curves[t->n - 1].conicity)
    return HM_EDOMAIN;
  const size_t i = interval_of(t, conicity);
  const tcurve *a = &t->curves[i], *b = &t->curves[i + 1];
  const tcurve *c = conicity - a->conicity <= b->conicity - conicity ? a : b;
  hm_table_lookup_result r;
  const hm_status st = hm_table_lookup(t, conicity, t->speed_min_kmh, &r);
  if (st != HM_OK) return st;
  const double scale = r.hopf_speed_kmh / c->hopf_kmh;
  for (size_t k = 0; k < c->n && k < max; ++k) {
    const double dv0 = k > 0 ? c->pts[k].v_kmh - c->pts[k - 1].v_kmh : 0.0;
    const double dv1 = k + 1 < c->n ? c->pts[k + 1].v_kmh - c->pts[k].v_kmh : 0.0;
    const int stable = c->pts[k].stable && (k + 1 == c->n || c->pts[k + 1].stable); /* as cycles_of reads it */
    points[k] = (hm_family_point){c->pts[k].v_kmh * scale, c->pts[k].amp_m, stable,
                                  dv0 != 0.0 && dv1 != 0.0 && (dv0 > 0.0) != (dv1 > 0.0)};
  }
  *n = c->n;
  *exact = c->conicity == conicity;
  return HM_OK;
}

hm_status hm_table_local_error(const hm_table t, double conicity, double *err_speed_kmh, double *err_amp_m) {
  if (!t || t->n < 2 || !err_speed_kmh || !err_amp_m) return HM_EINVAL;
  if (!isfinite(conicity)) return HM_EDOMAIN;
  const double c = fmin(fmax(conicity, t->curves[0].conicity), t->curves[t->n - 1].conicity);
  const size_t i = interval_of(t, c);
  const double d = c - t->curves[i].conicity, step = t->curves[i + 1].conicity - t->curves[i].conicity;
  const double f = t->err_step > 0.0 ? fmax(0.0, 4.0 * d * (step - d)) / (t->err_step * t->err_step) : 1.0;
  *err_speed_kmh = f * fmax(t->err_hopf_kmh, t->err_lowest_kmh);
  *err_amp_m = f * t->err_amp_m;
  return HM_OK;
}

hm_status hm_table_refine(const hm_table t, const hm_vehicle *veh, double conicity, hm_table *out) {
  if (!t || !veh || !out || t->n < 2) return HM_EINVAL;
  if (!isfinite(conicity)) return HM_EDOMAIN;
  if (!(conicity > t->curves[0].conicity && conicity < t->curves[t->n - 1].conicity)) return HM_EDOMAIN;
  const size_t i = interval_of(t, conicity);
  if (conicity == t->curves[i].conicity) return HM_EDOMAIN; /* already exact there */
  hm_status st = hm_table_check_vehicle(t, veh, HM_TABLE_CHECK_TOL_KMH, NULL, 0);
  if (st != HM_OK) return st;
  hm_table_spec spec;
  hm_table_spec_default(&spec);
  spec.speed_min_kmh = t->speed_min_kmh;
  spec.speed_max_kmh = t->speed_max_kmh;
  spec.amp_max_m = t->amp_max_m;
  spec.rtol = t->rtol;
  tcurve fresh;
  if ((st = curve_at(veh, &spec, conicity, &fresh)) != HM_OK) return st;
  hm_table r = hm_table_alloc(t->n + 1);
  if (!r) {
    free(fresh.pts);
    return HM_ENOMEM;
  }
  tcurve *curves = r->curves;
  *r = *t;
  r->n = t->n + 1;
  r->curves = curves;
  for (size_t k = 0, j = 0; k < r->n; ++k) {
    if (k == i + 1) {
      r->curves[k] = fresh;
      continue;
    }
    const tcurve *src = &t->curves[j++];
    r->curves[k] = *src;
    r->curves[k].pts = malloc(src->n * sizeof *src->pts);
    if (!r->curves[k].pts) {
      st = HM_ENOMEM;
      r->curves[k].n = 0;
      continue;
    }
    memcpy(r->curves[k].pts, src->pts, src->n * sizeof *src->pts);
  }
  if (st != HM_OK) {
    hm_table_destroy(r);
    return st;
  }
  *out = r;
  return HM_OK;
}

hm_status hm_table_build(const hm_vehicle *veh, const hm_table_spec *spec, hm_table *out) {
  return hm_table_build_parallel(veh, spec, NULL, NULL, out);
}

/* ---- text format ---- */


