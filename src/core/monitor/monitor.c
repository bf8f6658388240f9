/* The online monitor: estimator + identification + margin + alarm + table, and the start-up policy (monitor.h). */
#include "hunting_monitor/monitor.h"

#include "hunting_monitor/linear.h"
#include "hunting_monitor/spectrum_fit.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "validate.h"

/* Speed statistics per fit interval, so that the steady part of the window and its speed are known. */
typedef struct {
  double min, max, sum, n, duration_s;
} speed_chunk;

struct hm_monitor_s {
  hm_monitor_config cfg;
  hm_vehicle veh;                /* the (leading) wheelset's parameters */
  hm_mode_model model;           /* a bogie's or car's model (owned), NULL for the wheelset */
  hm_table table;
  hm_estimator est;
  hm_modal modal;
  hm_margin margin;
  hm_interval interval;          /* the Hopf interval and boundaries the alarm decides on (interval.h) */
  hm_alarm alarm;
  hm_track_lines lines;          /* the track's lines seen at steady speeds (track_lines.h) */
  int modal_ok;                  /* the identification can run at the current rate */
  unsigned long restarts;        /* the estimator's, as last seen */
  double rate_hz;
  int have_speed;
  double speed_kmh;
  speed_chunk *chunks;           /* ring, one per fit interval */
  size_t n_chunks_cap, chunk_head, n_chunks;
  speed_chunk cur;
  double t_chunk;                /* start of the current chunk */
  hm_mode_estimate mode;
  double mode_speed, mode_spread;
  hm_window_verdict verdict;
  double committed_until;        /* end of the last window committed to the margin (or the stream's restart) */
  double conicity_in_use;        /* of the latest update that had data; NAN before */
  double refine_failed_at;       /* the conicity whose exact family could not be computed; NAN if none */
  double a_prev;                 /* the previous accepted acceleration sample (bridging lost samples) */
  double large_at;               /* the latest update that saw a large oscillation (-inf: none) */
  hm_sensor_point sensor;        /* a model's sensor, whose spectrum a window's is fitted by (margin.spectrum_*_hz) */
  double *spec_f, *spec_p;       /* that fit's bins (HM_SPECTRUM_FIT_MAX_BINS each; NULL: no such fit) */
  hm_spectrum_fit spec_last;     /* the last such fit (spec_at NAN: none), its time and where its data began */
  double spec_at, spec_stretch;
};

void hm_monitor_config_default(hm_monitor_config *c) {
  hm_estimator_config_default(&c->estimator);
  hm_modal_config_default(&c->modal);
  hm_margin_config_default(&c->margin);
  hm_alarm_config_default(&c->alarm);
  hm_track_lines_config_default(&c->track_lines);
  c->table_n_conicity = 36;
  c->table.refine = 1;
  c->table.tolerance_kmh = 0.05;
  c->table.tolerance_m = 5e-6;
  c->table.max_curves = 200;
}

static hm_status prefixed(hm_status st, const char *section, char *why, size_t len) {
  if (st != HM_OK && why && len) {
    char tmp[256];
    snprintf(tmp, sizeof tmp, "%s", why);
    snprintf(why, len, "%s.%s", section, tmp);
  }
  return st;
}

hm_status hm_monitor_config_validate(const hm_monitor_config *c, char *why, size_t len) {
  if (!c) return HM_EINVAL;
  hm_status st = prefixed(hm_estimator_config_validate(&c->estimator, why, len), "estimator", why, len);
  if (st == HM_OK) st = prefixed(hm_modal_config_validate(&c->modal, why, len), "modal", why, len);
  if (st == HM_OK) st = prefixed(hm_margin_config_validate(&c->margin, why, len), "margin", why, len);
  if (st == HM_OK) st = prefixed(hm_alarm_config_validate(&c->alarm, why, len), "alarm", why, len);
  if (st == HM_OK) st = hm_track_lines_config_validate(&c->track_lines, why, len); /* "track_lines." prefixed */
  /* the spectrum's band within the identification's decimated signal (modal.h: its Nyquist at least the rate asked) */
  if (st == HM_OK && c->margin.spectrum_high_hz > 0.0 && !(c->margin.spectrum_high_hz < 0.5 * c->modal.decimated_rate_hz))
    st = hm_reject(why, len, "margin.spectrum_high_hz", "must be below half modal.decimated_rate_hz",
                   c->margin.spectrum_high_hz);
  if (st != HM_OK) return st;
  const hm_field_check f[] = {{"table_n_conicity", (double)c->table_n_conicity, HM_RULE_RANGE, 2.0, 1000.0},
                              {"table.tolerance_kmh", c->table.tolerance_kmh, HM_RULE_POSITIVE, 0.0, 0.0},
                              {"table.tolerance_m", c->table.tolerance_m, HM_RULE_POSITIVE, 0.0, 0.0},
                              {"table.refine", (double)c->table.refine, HM_RULE_FLAG, 0.0, 0.0},
                              {"table.max_curves", (double)c->table.max_curves, HM_RULE_RANGE, 0.0, 10000.0}};
  return hm_check_fields(f, HM_COUNT_OF(f), why, len);
}

static void chunk_clear(speed_chunk *k) {
  k->min = INFINITY;
  k->max = -INFINITY;
  k->sum = k->n = k->duration_s = 0.0;
}

/* The interval's prior (resolved for the vehicle) is the margin's too: it judges narrow peaks and reports estimates
 * outside it. */
static void share_prior(hm_monitor m) {
  double lo = 0.0, hi = 0.0;
  hm_interval_prior(m->interval, &lo, &hi);
  hm_margin_set_prior(m->margin, lo, hi);
}

static void restart_stream(hm_monitor m) {
  m->n_chunks = m->chunk_head = 0;
  chunk_clear(&m->cur);
  m->t_chunk = NAN;
  if (m->margin) hm_margin_commit_pending(m->margin); /* a gap ends the steady stretch */
  m->committed_until = -INFINITY;
}

hm_status hm_monitor_create(const hm_monitor_config *cfg, const hm_vehicle *veh, hm_table table, hm_monitor *out,
                            char *why, size_t len) {
  return hm_monitor_create_parallel(cfg, veh, table, NULL, NULL, out, why, len);
}

/* The table checked against the vehicle, or built for it. */
static hm_status ready_table(const hm_monitor_config *cfg, const hm_vehicle *veh, hm_model_kind kind,
                             const hm_car *params, hm_mode_model model, hm_table *table, hm_parallel_for_fn pfor,
                             void *runner, char *why, size_t len) {
  if (*table)
    return model ? hm_table_check_model(*table, model, HM_TABLE_CHECK_TOL_KMH, why, len)
                 : hm_table_check_vehicle(*table, veh, HM_TABLE_CHECK_TOL_KMH, why, len);
  hm_table_spec spec;
  hm_table_spec_default(&spec);
  spec.n_conicity = cfg->table_n_conicity;
  const hm_status st = model ? hm_table_build_model(kind, params, &spec, pfor, runner, table)
                             : hm_table_build_parallel(veh, &spec, pfor, runner, table);
  if (st != HM_OK && why && len) snprintf(why, len, "computing the boundary tables: %s", hm_status_str(st));
  return st;
}

hm_status hm_monitor_create_parallel(const hm_monitor_config *cfg, const hm_vehicle *veh, hm_table table,
                                     hm_parallel_for_fn pfor, void *runner, hm_monitor *out, char *why, size_t len) {
  if (!veh) {
    hm_table_destroy(table);
    return HM_EINVAL;
  }
  hm_car params;
  hm_car_default(&params);
  params.bogie.wheelset = *veh;
  return hm_monitor_create_model(cfg, HM_MODEL_WHEELSET, &params, table, pfor, runner, out, why, len);
}

static double wheelset_displacement(void *ctx, double f_hz, double speed_kmh);

hm_status hm_monitor_create_model(const hm_monitor_config *cfg, hm_model_kind kind, const hm_car *params,
                                  hm_table table, hm_parallel_for_fn pfor, void *runner, hm_monitor *out, char *why,
                                  size_t len) {
  hm_status st = !cfg || !params || !out ? HM_EINVAL : hm_monitor_config_validate(cfg, why, len);
  const hm_vehicle *veh = params ? &params->bogie.wheelset : NULL;
  hm_mode_model model = NULL;
  if (st == HM_OK) {
    st = kind == HM_MODEL_WHEELSET ? hm_vehicle_validate(veh, why, len)
       : kind == HM_MODEL_BOGIE   ? hm_bogie_validate(&params->bogie, why, len)
       : kind == HM_MODEL_CAR     ? hm_car_validate(params, why, len)
                                  : HM_EINVAL;
    if (st == HM_EINVAL && why && len) snprintf(why, len, "model: not a vehicle model the core holds (%d)", (int)kind);
  }
  if (st == HM_OK && kind != HM_MODEL_WHEELSET) st = hm_mode_model_create(kind, params, &model);
  if (st == HM_OK) st = ready_table(cfg, veh, kind, params, model, &table, pfor, runner, why, len);
  hm_monitor m = st == HM_OK ? calloc(1, sizeof *m) : NULL;
  if (st == HM_OK && !m) st = HM_ENOMEM;
  if (st != HM_OK) {
    hm_table_destroy(table);
    hm_mode_model_destroy(model);
    return st;
  }
  m->model = model;
  m->cfg = *cfg;
  m->veh = *veh;
  m->table = table;
  m->n_chunks_cap = (size_t)ceil(cfg->modal.window_s / cfg->modal.fit_interval_s) + 2;
  m->chunks = malloc(m->n_chunks_cap * sizeof *m->chunks);
  st = m->chunks ? HM_OK : HM_ENOMEM;
  if (st == HM_OK) st = hm_estimator_create(&cfg->estimator, &m->est, why, len);
  if (st == HM_OK) st = hm_modal_create(&cfg->modal, cfg->estimator.sample_rate_hz, &m->modal, why, len);
  if (st == HM_OK) st = hm_margin_create(&cfg->margin, veh, &m->margin, why, len);
  hm_interval_config icfg;
  hm_alarm_interval_config(&cfg->alarm, &icfg);
  if (st == HM_OK) st = hm_interval_create(&icfg, veh, table, &m->interval, why, len);
  if (st == HM_OK) st = hm_alarm_create(&cfg->alarm, &m->alarm, why, len);
  if (st == HM_OK && model) {
    st = hm_mode_model_set_band(model, cfg->modal.band_low_hz, cfg->modal.band_high_hz);
    /* the identified mode is compared with what the same reading gives on the model at the sensor (mode_model.h) */
    const char *where = cfg->estimator.measurement_point == HM_POINT_BOGIE_FRAME ? "frame" : "axlebox";
    if (st == HM_OK) st = hm_mode_model_set_sensor(model, where);
    hm_mode_model_set_reading_gain(model, hm_modal_filter_power_gain, m->modal);
    m->spec_at = NAN; /* (no spectrum fitted yet) */
    if (st == HM_OK) st = hm_mode_model_sensor(model, where, &m->sensor);
    if (st == HM_OK && cfg->margin.spectrum_high_hz > 0.0) { /* the spectrum's fit (margin.h) */
      m->spec_f = malloc(HM_SPECTRUM_FIT_MAX_BINS * sizeof(double));
      m->spec_p = malloc(HM_SPECTRUM_FIT_MAX_BINS * sizeof(double));
      st = m->spec_f && m->spec_p ? HM_OK : HM_ENOMEM;
    }
    /* a frame sensor's oscillation judged as the wheelsets' displacement it implies (estimator.h) */
    if (st == HM_OK && cfg->estimator.measurement_point == HM_POINT_BOGIE_FRAME)
      hm_estimator_set_displacement_map(m->est, wheelset_displacement, m);
    hm_margin_set_model(m->margin, model);
    if (st == HM_OK) st = hm_interval_set_model(m->interval, model);
  }
  if (st == HM_OK) st = hm_track_lines_init(&m->lines, &cfg->track_lines, why, len);
  if (st != HM_OK) {
    hm_monitor_destroy(m);
    return st;
  }
  hm_alarm_set_displacement_limit(m->alarm, cfg->estimator.displacement_limit_m);
  hm_interval_set_measurement_point(m->interval, cfg->estimator.measurement_point);
  hm_alarm_set_memory(m->alarm, cfg->margin.memory_s);
  share_prior(m);
  m->modal_ok = 1;
  m->verdict = HM_WINDOW_MODE_INVALID; /* no fit yet */
  m->mode.speed_tracking = m->mode.speed_tracking_se = NAN;
  m->large_at = -INFINITY;
  m->conicity_in_use = NAN;
  m->refine_failed_at = NAN;
  m->restarts = hm_estimator_restarts(m->est, &m->rate_hz);
  restart_stream(m);
  *out = m;
  return HM_OK;
}

void hm_monitor_destroy(hm_monitor m) {
  if (!m) return;
  hm_alarm_destroy(m->alarm);
  hm_interval_destroy(m->interval);
  hm_margin_destroy(m->margin);
  hm_modal_destroy(m->modal);
  hm_estimator_destroy(m->est);
  hm_table_destroy(m->table);
  hm_mode_model_destroy(m->model);
  free(m->chunks);
  free(m->spec_f);
  free(m->spec_p);
  free(m);
}

/* The stream restarts: estimator, identification and the steady stretch's speed chunks. */
static void restart_input(hm_monitor m) {
  hm_estimator_reset(m->est);
  m->modal_ok = hm_modal_set_rate(m->modal, m->cfg.estimator.sample_rate_hz) == HM_OK;
  m->restarts = hm_estimator_restarts(m->est, &m->rate_hz);
  m->have_speed = 0;
  hm_modal_set_speed(m->modal, NAN); /* (the identification keeps a speed across its own resets: not the old stream's) */
  memset(&m->mode, 0, sizeof m->mode);
  m->mode.speed_tracking = m->mode.speed_tracking_se = NAN; /* not measured */
  m->verdict = HM_WINDOW_MODE_INVALID;
  restart_stream(m);
}

void hm_monitor_reset(hm_monitor m) {
  if (!m) return;
  restart_input(m);
  hm_margin_reset(m->margin); /* its windows' times are on the old time line */
  hm_track_lines_clear(&m->lines);
  m->large_at = -INFINITY;
  hm_alarm_restart(m->alarm); /* a held ALARM stays held: a latch carries no times that matter */
  hm_interval_restart(m->interval);
}

void hm_monitor_time_jump(hm_monitor m, double delta_s) {
  if (!m) return;
  if (!isfinite(delta_s)) {
    hm_monitor_reset(m);
    return;
  }
  restart_input(m);
  hm_margin_shift_time(m->margin, delta_s);
  hm_track_lines_shift_time(&m->lines, delta_s);
  m->large_at += delta_s;
  hm_alarm_shift_time(m->alarm, delta_s);
  hm_interval_shift_time(m->interval, delta_s);
}

/* The mean speed of the newer half of the last window_s seconds over the older half's (the chunks'); 0 if unknown. */
static double halves_ratio(const hm_monitor m, double window_s) {
  double sum[2] = {0.0, 0.0}, n[2] = {0.0, 0.0}, t = 0.0;
  for (size_t k = 0; k < m->n_chunks && t < window_s - 1e-9; ++k) {
    const speed_chunk *c = &m->chunks[(m->chunk_head + m->n_chunks_cap - 1 - k) % m->n_chunks_cap];
    const int half = t + 0.5 * c->duration_s < 0.5 * window_s ? 0 : 1; /* 0: the newer half */
    sum[half] += c->sum;
    n[half] += c->n;
    t += c->duration_s;
  }
  if (!(n[0] > 0.0 && n[1] > 0.0 && sum[1] > 0.0)) return 0.0;
  return (sum[0] / n[0]) / (sum[1] / n[1]);
}

/* The speed held for most of the last window_s [km/h]: the chunks' mean within rel / 2 of the newest chunk's, when
 * they make at least half of it (a line's peak is at that speed's V / L, whatever the rest of the window did); 0 if
 * none held so long. */
static double held_speed(const hm_monitor m, double window_s, double rel) {
  double t = 0.0, held_s = 0.0, sum = 0.0, n = 0.0, ref = NAN;
  for (size_t k = 0; k < m->n_chunks && t < window_s - 1e-9; ++k) {
    const speed_chunk *c = &m->chunks[(m->chunk_head + m->n_chunks_cap - 1 - k) % m->n_chunks_cap];
    t += c->duration_s;
    if (!(c->n > 0.0)) continue;
    const double v = c->sum / c->n;
    if (!isfinite(ref)) ref = v;
    if (fabs(v - ref) <= 0.5 * rel * ref) held_s += c->duration_s, sum += c->sum, n += c->n;
  }
  return n > 0.0 && held_s >= 0.5 * window_s ? sum / n : 0.0;
}

/* The lines of a window fitted at one steady speed v [km/h]: whether its narrow peak is a line seen at another speed
 * (into mode's narrow_peak_tracked, with narrow_peak_wavelength_m), then each of its lines kept (track_lines.h). */
static void track_lines_of(hm_monitor m, double t, double v, hm_mode_estimate *mode) {
  if (mode->narrow_peak) { /* matched before it is kept: only another speed's sight of it counts */
    mode->narrow_peak_wavelength_m = hm_mps_from_kmh(v) / mode->narrow_peak_hz;
    mode->narrow_peak_tracked = hm_track_lines_match(&m->lines, t, v, mode->narrow_peak_hz, NULL);
    hm_track_lines_observe(&m->lines, t, v, mode->narrow_peak_hz, mode->narrow_peak_mps2, 0);
  }
  for (unsigned k = 0; k < mode->lone_lines && k < HM_MODAL_MAX_LONE; ++k)
    hm_track_lines_observe(&m->lines, t, v, mode->lone_line_hz[k], mode->lone_line_mps2[k], 0);
  if (mode->lines_found)
    hm_track_lines_observe(&m->lines, t, v, mode->line_fundamental_hz, 0.0, 1);
}

/* The estimator's displacement map (estimator.h) on the model: the wheelsets' displacement per acceleration at the
 * sensor at the conicity in use (none before the first assessment). */
static double wheelset_displacement(void *ctx, double f_hz, double speed_kmh) {
  const hm_monitor m = ctx;
  double s = 0.0;
  if (isfinite(m->conicity_in_use) &&
      hm_mode_model_displacement_per_accel(m->model, m->conicity_in_use, speed_kmh, &m->sensor, f_hz, &s) != HM_OK)
    s = 0.0;
  return s;
}

/* The window's conicity from the model's whole spectrum at the sensor (spectrum_fit.h, linearised about the motion it
 * implies), for the margin (margin.h): where it has a model and the band set, the window's mode was read and no narrow
 * peak (a line or the mode, the margin's question) is in it. A full window is fitted; a stretch's provisional one
 * takes the stretch's last fit while that is less than HM_MONITOR_SPECTRUM_EVERY_S old (a fit takes 0.1-0.4 s of a
 * bogie's spectrum: every second it would hold the monitor behind real time). The fit's residual under the reading's
 * peaks (f -+ max(|sigma| / 2 pi, HM_MODAL_PEAK_MIN_HALFWIDTH / T)) is measured on the window's own spectrum, with
 * the fit it takes. */
static void spectrum_of(hm_monitor m, double t, double stretch_start, int full, hm_mode_estimate *e) {
  e->spectrum_valid = 0;
  e->spectrum_peak_z = e->spectrum_second_peak_z = NAN;
  if (!m->spec_f || !e->valid || e->narrow_peak) return;
  e->spectrum_valid = -1; /* (until a fit succeeds: a window asked for and not fitted is a misfit, margin.h) */
  const int reuse = !full && fabs(m->spec_stretch - stretch_start) < 0.5 && t - m->spec_at >= 0.0 &&
                    t - m->spec_at < HM_MONITOR_SPECTRUM_EVERY_S; /* (false while spec_at is NAN) */
  size_t n;
  double dof, window_s;
  if (!reuse) m->spec_at = NAN; /* (a fit not made now is no longer the stretch's) */
  if (hm_modal_window_spectrum(m->modal, m->cfg.margin.spectrum_low_hz, m->cfg.margin.spectrum_high_hz, m->spec_f,
                               m->spec_p, HM_SPECTRUM_FIT_MAX_BINS, &n, &dof, &window_s) != HM_OK)
    return;
  if (!reuse) {
    hm_spectrum_fit_options o;
    hm_spectrum_fit_options_default(&o);
    o.window_s = window_s;
    if (hm_spectrum_fit_conicity(m->model, m->mode_speed, &m->sensor, m->spec_f, m->spec_p, n, dof, &o,
                                 &m->spec_last) != HM_OK)
      return;
    m->spec_at = t;
    m->spec_stretch = stretch_start;
  }
  const hm_spectrum_fit *fit = &m->spec_last;
  e->spectrum_valid = 1;
  e->spectrum_conicity = fit->conicity;
  e->spectrum_conicity_se = fit->conicity_se;
  e->spectrum_conicity_at_rest = fit->conicity_at_rest;
  e->spectrum_motion_rms_m = fit->motion_rms_m;
  e->spectrum_shape_chi2 = fit->shape_chi2;
  e->spectrum_model_share = fit->model_share;
  const double min_hw = HM_MODAL_PEAK_MIN_HALFWIDTH / fmax(window_s, 1.0);
  for (unsigned k = 0; k < e->poles && k < 2; ++k) {
    const double f = k ? e->second_frequency_hz : e->frequency_hz;
    const double hw = fmax(fabs(k ? e->second_decay_rate_1_s : e->decay_rate_1_s) / (2.0 * HM_PI), min_hw);
    double z = NAN;
    if (hm_spectrum_fit_peak_z(m->model, m->mode_speed, &m->sensor, fit, m->spec_f, m->spec_p, n, dof, f - hw, f + hw,
                               &z) == HM_OK)
      *(k ? &e->spectrum_second_peak_z : &e->spectrum_peak_z) = z;
  }
}

/* A fit of the identification. At a steady speed (the newest stretch whose speed varied by at most the margin's
 * max_speed_spread_kmh) the part of the stretch not yet given to the margin is fitted, up to window_s: a full
 * window is committed to the margin, a shorter one (from min_window_s) is its provisional window, committed when the
 * stretch ends. So a stretch contributes while it lasts and once in long, non-overlapping windows. While the speed
 * changes gradually (acceleration or braking: the stretch ends where its speed range reached the spread, at 0.5
 * km/h/s after 24 s) the stretch is committed whole when it has nothing committed in it: ramp windows back to back,
 * at their mean speed (the margin counts the change of the model's decay rate over the window's speed range as a
 * systematic error, margin.h). Otherwise the whole window is fitted for display only. */
static void fit(hm_monitor m, double t) {
  m->cur.duration_s = isfinite(m->t_chunk) ? t - m->t_chunk : 0.0;
  m->chunks[m->chunk_head] = m->cur;
  m->chunk_head = (m->chunk_head + 1) % m->n_chunks_cap;
  if (m->n_chunks < m->n_chunks_cap) ++m->n_chunks;
  chunk_clear(&m->cur);
  m->t_chunk = t;
  const hm_modal_config *mc = &m->cfg.modal;
  speed_chunk steady;
  chunk_clear(&steady);
  const double max_spread = m->cfg.margin.max_speed_spread_kmh;
  int ramp = 0; /* the stretch ends where a gradual change of speed took it beyond max_spread: a ramp */
  for (size_t k = 0; k < m->n_chunks && steady.duration_s < mc->window_s; ++k) {
    const speed_chunk *c = &m->chunks[(m->chunk_head + m->n_chunks_cap - 1 - k) % m->n_chunks_cap];
    if (c->n == 0.0) break;
    if (fmax(steady.max, c->max) - fmin(steady.min, c->min) > max_spread) {
      ramp = c->max - c->min <= max_spread && steady.max - steady.min >= 0.5 * max_spread;
      break;
    }
    steady.min = fmin(steady.min, c->min);
    steady.max = fmax(steady.max, c->max);
    steady.sum += c->sum;
    steady.n += c->n;
    steady.duration_s += c->duration_s;
  }
  const int is_steady = steady.duration_s >= mc->min_window_s;
  if (!is_steady) hm_margin_commit_pending(m->margin); /* the stretch ended */
  /* the part of the stretch after the last committed window */
  const double fresh = is_steady ? fmin(steady.duration_s, t - m->committed_until) : 0.0;
  const int for_margin = fresh >= mc->min_window_s;
  hm_mode_estimate e;
  const double spread_rel =
      is_steady && steady.n > 0.0 && steady.sum > 0.0 ? (steady.max - steady.min) / (steady.sum / steady.n) : 0.0;
  const double fitted_s = for_margin ? fresh : mc->window_s;
  if (hm_modal_fit(m->modal, fitted_s, spread_rel, halves_ratio(m, mc->window_s), &e) != HM_OK) {
    m->mode.valid = 0;
    return;
  }
  m->mode_speed = steady.n > 0.0 ? steady.sum / steady.n : m->speed_kmh;
  m->mode_spread = is_steady ? steady.max - steady.min : INFINITY;
  /* the track's lines: a window at least half at one speed (held_speed) tells their wavelengths; a narrow peak whose
   * wavelength was seen at another speed is a line (track_lines.h) */
  const double v_held = held_speed(m, e.window_s, m->cfg.track_lines.wavelength_tol_rel);
  if (v_held > 0.0) track_lines_of(m, t, v_held, &e);
  m->mode = e;
  m->verdict = is_steady ? HM_WINDOW_OVERLAPS : HM_WINDOW_SPEED_VARIED;
  if (!for_margin) return;
  if (t - e.window_s <= m->large_at) { /* a large oscillation in the window: not the linear mode */
    m->verdict = HM_WINDOW_NONLINEAR;
    hm_margin_commit_pending(m->margin); /* what the stretch gave before it stays; nothing of it after */
    m->committed_until = t;
    return;
  }
  const int full = e.window_s >= mc->window_s * (1.0 - 1e-9) || (ramp && fresh >= steady.duration_s - 1e-9);
  spectrum_of(m, t, t - fresh, full, &e);
  m->mode = e;
  /* a full window, or on a ramp the whole stretch the spread allows (back to back, each once) */
  if (full) {
    hm_margin_add_window(m->margin, t, m->mode_speed, m->mode_spread, &e, &m->verdict);
    if (m->verdict == HM_WINDOW_USED) m->committed_until = t;
  } else {
    hm_margin_set_pending(m->margin, t, m->mode_speed, m->mode_spread, &e, &m->verdict);
  }
  if (m->verdict == HM_WINDOW_CHANGE) m->committed_until = t; /* the change's window is committed (margin.h) */
  /* a narrow peak the margin took for a line: the mode shown is the one beside it */
  if (m->mode.narrow_peak && hm_margin_last_narrow(m->margin) == HM_NARROW_LINE) {
    hm_mode_estimate_use_reading(&m->mode, hm_mode_estimate_beside_line(&m->mode));
    m->mode.speed_tracking = m->mode.speed_tracking_se = NAN; /* measured on the narrow peak's reading, not this one */
  }
}

hm_status hm_monitor_push_accel(hm_monitor m, double t, double a) {
  if (!m) return HM_EINVAL;
  const hm_status st = hm_estimator_push_accel(m->est, t, a);
  if (st != HM_OK) return st;
  double rate;
  const unsigned long restarts = hm_estimator_restarts(m->est, &rate);
  if (restarts != m->restarts) { /* a gap or a redesign: the identification restarts with the filters */
    m->restarts = restarts;
    if (rate != m->rate_hz) {
      m->rate_hz = rate;
      m->modal_ok = hm_modal_set_rate(m->modal, rate) == HM_OK;
    } else {
      hm_modal_reset(m->modal);
    }
    restart_stream(m);
  }
  if (!isfinite(m->t_chunk)) m->t_chunk = t; /* the first chunk starts with the stream */
  if (m->have_speed) {
    m->cur.min = fmin(m->cur.min, m->speed_kmh);
    m->cur.max = fmax(m->cur.max, m->speed_kmh);
    m->cur.sum += m->speed_kmh;
    m->cur.n += 1.0;
  }
  const double a_prev = m->a_prev;
  m->a_prev = a;
  if (!m->modal_ok) return HM_OK;
  /* the samples the estimator bridged (lost on a regular grid), interpolated as it did */
  const unsigned fill = hm_estimator_last_fill(m->est);
  for (unsigned j = 1; j <= fill; ++j) hm_modal_push(m->modal, a_prev + (a - a_prev) * (double)j / (double)(fill + 1));
  hm_modal_push(m->modal, a);
  if (hm_modal_fit_due(m->modal)) fit(m, t);
  return HM_OK;
}

hm_status hm_monitor_push_speed(hm_monitor m, double t, double v) {
  if (!m) return HM_EINVAL;
  const hm_status st = hm_estimator_push_speed(m->est, t, v);
  if (st == HM_OK) {
    m->have_speed = 1;
    m->speed_kmh = v;
    hm_modal_set_speed(m->modal, hm_mps_from_kmh(v)); /* (kept with each sample: the lines' order tracking) */
  }
  return st;
}

hm_status hm_monitor_update(hm_monitor m, double now, hm_monitor_status *out) {
  if (!m || !out || !isfinite(now)) return HM_EINVAL;
  hm_monitor_status s;
  memset(&s, 0, sizeof s);
  hm_estimator_read(m->est, now, &s.estimate);
  if (s.estimate.rms_exceeded || s.estimate.peaks_exceeded || s.estimate.displacement_exceeded)
    m->large_at = s.estimate.time_s;
  hm_margin_read(m->margin, now, &s.margin);
  /* the interval with current data only (as the alarm judges: without, no margins are current) */
  hm_hopf_interval iv;
  const int data = s.estimate.accel_valid && s.estimate.speed_valid;
  hm_status st = data ? hm_interval_update(m->interval, s.estimate.speed_kmh, &s.margin, now, &iv) : HM_OK;
  if (st == HM_OK) st = hm_alarm_update(m->alarm, &s.estimate, data ? &iv : NULL, now, &s.assessment);
  if (st != HM_OK) return st;
  if (s.assessment.level != HM_LEVEL_NO_DATA && isfinite(s.assessment.conicity))
    m->conicity_in_use = s.assessment.conicity;
  s.mode = m->mode;
  s.mode_speed_kmh = m->mode_speed;
  s.mode_speed_spread_kmh = isfinite(m->mode_spread) ? m->mode_spread : -1.0;
  s.mode_verdict = m->verdict;
  s.mode_steady = m->mode.valid && m->verdict != HM_WINDOW_SPEED_VARIED && m->verdict != HM_WINDOW_NONLINEAR;
  s.line_wavelength_m = m->mode.lines_found && m->mode.line_fundamental_hz > 0.0
                            ? hm_mps_from_kmh(m->mode_speed) / m->mode.line_fundamental_hz
                            : 0.0;
  *out = s;
  return HM_OK;
}

hm_table hm_monitor_table(const hm_monitor m) { return m ? m->table : NULL; }

hm_status hm_monitor_set_runtime_settings(hm_monitor m, const hm_monitor_config *cfg, char *why, size_t len) {
  if (!m || !cfg) return HM_EINVAL;
  hm_monitor_config c = m->cfg;
  c.alarm = cfg->alarm;
  c.estimator.rms_limit_mps2 = cfg->estimator.rms_limit_mps2;
  c.estimator.peaks_limit_mps2 = cfg->estimator.peaks_limit_mps2;
  c.estimator.peaks_count = cfg->estimator.peaks_count;
  c.estimator.displacement_limit_m = cfg->estimator.displacement_limit_m;
  hm_status st = hm_monitor_config_validate(&c, why, len);
  if (st != HM_OK) return st;
  /* the interval first: it alone can still refuse (a prior that does not hold the vehicle's fallback), and then
   * nothing has changed; the other parts were validated above, so they cannot fail half-way */
  hm_interval_config icfg;
  hm_alarm_interval_config(&c.alarm, &icfg);
  if ((st = hm_interval_set_config(m->interval, &icfg, &m->veh, why, len)) != HM_OK) return st;
  if ((st = hm_estimator_set_limits(m->est, &c.estimator, why, len)) != HM_OK) return st;
  if ((st = hm_alarm_set_config(m->alarm, &c.alarm, why, len)) != HM_OK) return st;
  hm_alarm_set_displacement_limit(m->alarm, c.estimator.displacement_limit_m);
  m->cfg = c;
  share_prior(m);
  return HM_OK;
}

void hm_monitor_settings(const hm_monitor m, hm_monitor_config *cfg) {
  if (m && cfg) *cfg = m->cfg;
}

int hm_monitor_table_wanted(const hm_monitor m, double *conicity) {
  if (!m || !conicity || !m->cfg.table.refine || !isfinite(m->conicity_in_use)) return 0;
  double lo, hi, e_kmh, e_m;
  if (hm_table_size(m->table, &lo, &hi) >= m->cfg.table.max_curves) return 0;
  if (!(m->conicity_in_use > lo && m->conicity_in_use < hi)) return 0; /* outside: clamped, nothing to add */
  if (hm_table_local_error(m->table, m->conicity_in_use, &e_kmh, &e_m) != HM_OK) return 0;
  if (e_kmh <= m->cfg.table.tolerance_kmh && e_m <= m->cfg.table.tolerance_m) return 0;
  if (fabs(m->conicity_in_use - m->refine_failed_at) <= 1e-4) return 0; /* failed there: not retried */
  *conicity = m->conicity_in_use;
  return 1;
}

void hm_monitor_table_failed(hm_monitor m, double conicity) {
  if (m) m->refine_failed_at = conicity;
}

hm_status hm_monitor_replace_table(hm_monitor m, hm_table table, hm_table *replaced, char *why, size_t len) {
  if (replaced) *replaced = NULL;
  if (!m || !table) {
    hm_table_destroy(table);
    return HM_EINVAL;
  }
  const hm_status st = m->model ? hm_table_check_model(table, m->model, HM_TABLE_CHECK_TOL_KMH, why, len)
                                : hm_table_check_vehicle(table, &m->veh, HM_TABLE_CHECK_TOL_KMH, why, len);
  if (st != HM_OK) {
    hm_table_destroy(table);
    return st;
  }
  hm_interval_set_table(m->interval, table);
  if (replaced) *replaced = m->table;
  else hm_table_destroy(m->table);
  m->table = table;
  return HM_OK;
}

hm_model_kind hm_monitor_model_kind(const hm_monitor m) {
  return m && m->model ? hm_mode_model_kind(m->model) : HM_MODEL_WHEELSET;
}

void hm_monitor_model_params(const hm_monitor m, hm_car *params) {
  if (!m || !params) return;
  if (m->model) {
    hm_mode_model_params(m->model, params);
  } else {
    hm_car_default(params);
    params->bogie.wheelset = m->veh;
  }
}

void hm_monitor_vehicle(const hm_monitor m, hm_vehicle *veh) {
  if (m && veh) *veh = m->veh;
}

void hm_monitor_take_snapshot(const hm_monitor m, double now_s, hm_monitor_snapshot *out) {
  if (!m || !out || !isfinite(now_s)) return;
  hm_monitor_snapshot s;
  hm_margin_take_snapshot(m->margin, now_s, &s.margin);
  hm_alarm_take_snapshot(m->alarm, now_s, &s.alarm);
  hm_interval_take_snapshot(m->interval, &s.interval);
  *out = s;
}

hm_status hm_monitor_restore(hm_monitor m, double now_s, const hm_monitor_snapshot *snap, char *why, size_t len) {
  if (!m || !snap || !isfinite(now_s)) return HM_EINVAL;
  hm_status st = hm_margin_snapshot_validate(&snap->margin, why, len);
  if (st == HM_OK) st = hm_alarm_snapshot_validate(&snap->alarm, why, len);
  if (st == HM_OK) st = hm_interval_snapshot_validate(&snap->interval, why, len);
  if (st != HM_OK) return st;
  restart_input(m);
  m->large_at = -INFINITY;
  /* all three were validated above, so none can fail half-way */
  if ((st = hm_margin_restore(m->margin, now_s, &snap->margin, why, len)) != HM_OK) return st;
  if ((st = hm_interval_restore(m->interval, &snap->interval, why, len)) != HM_OK) return st;
  return hm_alarm_restore(m->alarm, now_s, &snap->alarm, why, len);
}
