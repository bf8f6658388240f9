/* The online monitor (hm_monitor: estimator, identification, margin, alarm) on the core's sensor simulation
 * (sensor_sim.h): the nonlinear wheelset driven by a random lateral track irregularity, sampled like an axle-box
 * accelerometer at 2 kHz with sensor noise. */
#include <stdlib.h>
#include <string.h>

#include "hm_fixtures.h"
#include "hm_test.h"
#include "hunting_monitor/monitor.h"
#include "hunting_monitor/cycles.h"
#include "hunting_monitor/linear.h"
#include "hunting_monitor/sensor_sim.h"

static char *table_text; /* the small table, formatted once: each run's monitor takes over a parsed copy */
static size_t table_len;
static hm_vehicle vehicle;

typedef struct {
  hm_monitor mon;
  hm_sensor_sim sim;
  double next_read;
  double true_amp;         /* running max |y| over the last 0.1 s (the true displacement amplitude) */
  double true_amp_window;
  /* what the run saw */
  double first_alarm_s, t_true_beyond;
  hm_reason first_alarm_reason;
  double first_alarm_amp, first_alarm_rms, true_amp_max;
  double edge_m;           /* unstable cycle amplitude at the run's speed (direct continuation) */
  double t_true_3mm;       /* the first time the true |y| reached 3 mm (-1: never) */
  double t_true_2mm_last;  /* the last time the true |y| reached 2.1 mm, the displacement criterion's (-1: never) */
  double first_warn_s, first_warn_kmh; /* the first WARN or ALARM after 2 s (-1: none) */
  int levels_seen[5];
  int verdicts_seen[16];   /* the identification's window verdicts (margin.h) seen by the updates */
  hm_level last_level;
  hm_monitor_status last;
} run_state;

/* Each acceleration sample (2 kHz, with 0.05 m/s^2 noise) goes to the monitor; the true state gives the true
 * amplitude; the monitor is read at 20 Hz. */
static int on_accel(void *ctx, double t, double measured, double true_accel, const double *x) {
  run_state *r = (run_state *)ctx;
  (void)true_accel;
  hm_monitor_push_accel(r->mon, t, measured);
  r->true_amp_window = fmax(r->true_amp_window, fabs(x[0]));
  r->true_amp_max = fmax(r->true_amp_max, fabs(x[0]));
  if (fabs(x[0]) >= 3e-3 && r->t_true_3mm < 0.0) r->t_true_3mm = t;
  if (fabs(x[0]) >= 2.1e-3) r->t_true_2mm_last = t;
  if (t >= r->next_read) {
    r->true_amp = r->true_amp_window;
    r->true_amp_window = 0.0;
    hm_monitor_status st;
    HM_CHECK(hm_monitor_update(r->mon, t, &st) == HM_OK, "update at %g s", t);
    const hm_assessment s = st.assessment;
    r->last = st;
    if (t > 2.0) r->levels_seen[s.level]++;
    if (t > 2.0 && s.level >= HM_LEVEL_WARN && r->first_warn_s < 0.0)
      r->first_warn_s = t, r->first_warn_kmh = st.estimate.speed_kmh;
    if ((unsigned)st.mode_verdict < 16) r->verdicts_seen[st.mode_verdict]++;
    if (s.level == HM_LEVEL_ALARM && r->first_alarm_s < 0.0) {
      r->first_alarm_s = t;
      r->first_alarm_reason = s.reason;
      r->first_alarm_amp = st.estimate.amplitude_displacement_m;
      r->first_alarm_rms = st.estimate.rms_mps2;
    }
    if (r->edge_m > 0.0 && r->true_amp > r->edge_m && r->t_true_beyond < 0.0) r->t_true_beyond = t;
    r->last_level = s.level;
    r->next_read += 0.05;
  }
  return 0;
}

static int on_speed(void *ctx, double t, double v_kmh) {
  hm_monitor_push_speed(((run_state *)ctx)->mon, t, v_kmh);
  return 0;
}

/* A run at a steady v_kmh on a track with `scale` of the low-disturbance spectrum's power (track_seed), the sensor
 * noise from noise_seed; speed samples at 50 Hz. */
static void run_init(run_state *r, double v_kmh, double scale, uint64_t track_seed, uint64_t noise_seed) {
  memset(r, 0, sizeof *r);
  hm_monitor_config cfg;
  hm_monitor_config_default(&cfg);
  hm_table t = NULL;
  char why[256] = "";
  HM_CHECK(hm_table_parse(table_text, table_len, &t, why, sizeof why) == HM_OK, "table: %s", why);
  HM_CHECK(hm_monitor_create(&cfg, &vehicle, t, &r->mon, why, sizeof why) == HM_OK, "monitor: %s", why);
  hm_sensor_sim_config sc;
  hm_sensor_sim_config_default(&sc);
  sc.v_start_kmh = sc.v_end_kmh = v_kmh;
  sc.irregularity_scale = scale;
  sc.track_seed = track_seed;
  sc.noise_seed = noise_seed;
  sc.speed_rate_hz = 50.0;
  HM_CHECK(hm_sensor_sim_create(&vehicle, &sc, NULL, &r->sim, why, sizeof why) == HM_OK, "simulation: %s", why);
  r->first_alarm_s = r->t_true_beyond = r->t_true_3mm = r->t_true_2mm_last = r->first_warn_s = -1.0;
}

/* A run of the simulated vehicle sim_veh (the monitor's is `vehicle`) on a speed profile of n points (sensor_sim.h;
 * 10% of the low-disturbance spectrum, speed at 50 Hz). */
static void run_init_vehicle(run_state *r, const hm_vehicle *sim_veh, const double *t_s, const double *v_kmh, size_t n,
                             uint64_t seed) {
  run_init(r, v_kmh[0], 0.1, seed, seed);
  hm_sensor_sim_destroy(r->sim);
  hm_sensor_sim_config sc;
  hm_sensor_sim_config_default(&sc);
  sc.n_profile = n;
  for (size_t k = 0; k < n; ++k) sc.profile_t_s[k] = t_s[k], sc.profile_v_kmh[k] = v_kmh[k];
  sc.irregularity_scale = 0.1;
  sc.track_seed = sc.noise_seed = seed;
  sc.speed_rate_hz = 50.0;
  char why[256] = "";
  HM_CHECK(hm_sensor_sim_create(sim_veh, &sc, NULL, &r->sim, why, sizeof why) == HM_OK, "simulation: %s", why);
}

static void run_init_profile(run_state *r, const double *t_s, const double *v_kmh, size_t n, uint64_t seed) {
  run_init_vehicle(r, &vehicle, t_s, v_kmh, n, seed);
}

/* A run on a speed ramp v0 -> v1 over ramp_s. */
static void run_init_ramp(run_state *r, double v0_kmh, double v1_kmh, double ramp_s, uint64_t seed) {
  const double t[2] = {0.0, ramp_s}, v[2] = {v0_kmh, v1_kmh};
  run_init_profile(r, t, v, 2, seed);
}

static void run_segment(run_state *r, double t1) {
  const hm_sensor_sink sink = {on_accel, on_speed, r};
  HM_CHECK(hm_sensor_sim_run(r->sim, t1, &sink) == HM_OK, "simulate to %g s", t1);
}

static void run_free(run_state *r) {
  hm_monitor_destroy(r->mon);
  hm_sensor_sim_destroy(r->sim);
}

/* 200 km/h, below the lowest speed with any cycle (about 239.5 km/h): 30 s on the full low-disturbance track,
 * level OK throughout. */
static void below_lowest_cycle_speed_stays_ok(void) {
  run_state r;
  run_init(&r, 200.0, 1.0, 42, 1);
  run_segment(&r, 30.0);
  printf("  200 km/h: levels after 2 s: OK %d, WATCH %d, WARN %d, ALARM %d\n", r.levels_seen[1], r.levels_seen[2],
         r.levels_seen[3], r.levels_seen[4]);
  HM_CHECK(r.levels_seen[HM_LEVEL_OK] > 0 && r.levels_seen[HM_LEVEL_WATCH] + r.levels_seen[HM_LEVEL_WARN] +
                                                   r.levels_seen[HM_LEVEL_ALARM] + r.levels_seen[HM_LEVEL_NO_DATA] == 0,
           "not OK throughout");
  run_free(&r);
}

/* 505 km/h, 12.6 km/h below the Hopf speed, on a smooth track (1% of the low-disturbance spectrum's power: with
 * all of it the track itself kicks this wheelset into hunting within seconds, as MODEL.md section 7 warns): 12 s of
 * excitation (WATCH, within 30 km/h of the Hopf speed, or WARN, never ALARM), then a disturbance just beyond the unstable cycle: sustained hunting on the large stable cycle, and ALARM
 * within 1 s of the true amplitude passing the unstable cycle (the edge of the basin, from direct continuation). */
static void hunting_onset_alarms_within_a_second(void) {
  const double v = 505.0;
  /* the unstable cycle at 505 km/h: continuation of the family from the Hopf point */
  hm_hopf_point h;
  size_t n = 0, np = 0, ne = 0;
  HM_CHECK(hm_hopf_find(&vehicle, 500.0, HM_PARAM_SPEED, 100.0, 900.0, 1e-10, &h, 1, &n) == HM_OK && n == 1, "Hopf");
  hm_cycle_options o;
  hm_cycle_options_default(&o, HM_PARAM_SPEED);
  o.amp_max_m = 0.009;
  enum { CAP = 4000 };
  hm_cycle_point *pts = malloc(CAP * sizeof *pts);
  hm_cycle_event ev[8];
  HM_CHECK(hm_cycles_continue(&vehicle, 500.0, &h, &o, pts, CAP, &np, ev, 8, &ne, NULL) == HM_OK, "family");
  const hm_cycle_point *edge = NULL;
  for (size_t i = 1; i < np; ++i) /* the unstable cycle beyond LPC2 crossing 505 km/h */
    if ((pts[i - 1].param - v) * (pts[i].param - v) <= 0.0 && pts[i].amp_y_m > 0.006) edge = &pts[i];
  HM_CHECK(edge != NULL, "no unstable cycle at 505 km/h");
  if (!edge) {
    free(pts);
    return;
  }
  run_state r;
  run_init(&r, v, 0.01, 42, 2);
  run_segment(&r, 12.0);
  printf("  505 km/h, 12 s excitation: OK %d, WATCH %d, WARN %d, ALARM %d\n", r.levels_seen[1], r.levels_seen[2],
         r.levels_seen[3], r.levels_seen[4]);
  HM_CHECK(r.first_alarm_s < 0.0 && r.levels_seen[HM_LEVEL_WATCH] + r.levels_seen[HM_LEVEL_WARN] > 0 &&
               r.levels_seen[HM_LEVEL_OK] == 0,
           "false alarm, or not WATCH/WARN before the kick");
  /* the kick: the state of the unstable cycle scaled by 1.05 (outside the basin of the origin) */
  r.edge_m = edge->amp_y_m;
  double x[4];
  for (int i = 0; i < 4; ++i) x[i] = 1.05 * edge->x0[i];
  HM_CHECK(hm_sensor_sim_set_state(r.sim, x) == HM_OK, "kick");
  run_segment(&r, 18.0);
  printf("  kick at 12 s: true amplitude beyond the %.2f mm edge at %.2f s, ALARM at %.2f s, final level %s, "
         "true amplitude %.2f mm\n",
         r.edge_m * 1e3, r.t_true_beyond, r.first_alarm_s, hm_level_name(r.last_level), r.true_amp * 1e3);
  HM_CHECK(r.t_true_beyond >= 12.0 && r.first_alarm_s >= 12.0, "no exceedance or no alarm");
  HM_CHECK(r.first_alarm_s <= r.t_true_beyond + 1.0, "ALARM %.2f s after the exceedance",
           r.first_alarm_s - r.t_true_beyond);
  HM_CHECK(r.last_level == HM_LEVEL_ALARM && r.true_amp > 0.012, "sustained hunting not alarmed");
  /* hunting is not the linear mode: no window of it reaches the margin (monitor.h), the interval stays the prior's */
  run_segment(&r, 45.0);
  printf("  hunting to 45 s: %d statuses with a window refused as nonlinear, %u windows held, level %s%s\n",
         r.verdicts_seen[HM_WINDOW_NONLINEAR], r.last.margin.n_windows, hm_level_name(r.last_level),
         r.last.assessment.latched ? " (latched)" : "");
  HM_CHECK(r.verdicts_seen[HM_WINDOW_NONLINEAR] > 0 && r.last.margin.n_windows == 0 &&
               r.last.assessment.conicity_from_prior,
           "a window of the limit cycle was used: %d nonlinear verdicts, %u windows",
           r.verdicts_seen[HM_WINDOW_NONLINEAR], r.last.margin.n_windows);
  HM_CHECK(r.last_level == HM_LEVEL_ALARM && r.last.assessment.latched, "the hunting ALARM is not held");
  run_free(&r);
  free(pts);
}

/* The table's refinement policy: running at 400 km/h with the fallback conicity (the vehicle's 0.1358, between the
 * small table's curves 0.12 / 0.14 / 0.16) the monitor wants the exact family there; with it swapped in, the lowest
 * cycle speed in the assessment is the fold itself (MODEL.md section 7: 239.5; the continuation: 239.549) and no
 * more is wanted; a table of another vehicle is refused and the one in use kept. */
static void table_refined_at_the_conicity_in_use(void) {
  run_state r;
  run_init(&r, 400.0, 0.01, 42, 3);
  run_segment(&r, 5.0);
  double c = 0.0;
  HM_CHECK(r.last.assessment.level != HM_LEVEL_NO_DATA, "no data after 5 s");
  HM_CHECK(hm_monitor_table_wanted(r.mon, &c) == 1 && c == r.last.assessment.conicity, "refinement wanted at %g", c);
  HM_CHECK_DELTA(c, 0.1358, 1e-12, "the fallback conicity (the vehicle's lambda(0))");
  double c2 = 0.0;
  hm_monitor_table_failed(r.mon, c);
  HM_CHECK(hm_monitor_table_wanted(r.mon, &c2) == 0, "wanted again where the family failed");
  hm_monitor_table_failed(r.mon, c + 0.01);
  HM_CHECK(hm_monitor_table_wanted(r.mon, &c2) == 1 && c2 == c, "not wanted after a failure elsewhere");
  const double before = r.last.assessment.boundaries.lowest_cycle_speed_kmh;
  hm_table refined = NULL;
  HM_CHECK(hm_table_refine(hm_monitor_table(r.mon), &vehicle, c, &refined) == HM_OK, "refine");
  char why[256] = "";
  HM_CHECK(hm_monitor_replace_table(r.mon, refined, NULL, why, sizeof why) == HM_OK, "replace: %s", why);
  run_segment(&r, 6.0);
  const double after = r.last.assessment.boundaries.lowest_cycle_speed_kmh;
  printf("  lowest cycle speed at 0.1358: interpolated %.4f, refined %.6f km/h\n", before, after);
  HM_CHECK_DELTA(after, 239.548876, 1e-5, "lowest cycle speed with the exact family (the located fold)");
  HM_CHECK(hm_monitor_table_wanted(r.mon, &c) == 0, "still wanted after the swap");
  hm_vehicle other = vehicle;
  other.stiffness_lat_n_m *= 1.2;
  /* a table for other stiffnesses (two conicities: quick), offered */
  hm_table_spec spec;
  hm_table_spec_default(&spec);
  spec.conicity_min = 0.12;
  spec.conicity_max = 0.16;
  spec.n_conicity = 2;
  hm_table foreign = NULL;
  HM_CHECK(hm_table_build(&other, &spec, &foreign) == HM_OK, "foreign table");
  HM_CHECK(hm_monitor_replace_table(r.mon, foreign, NULL, why, sizeof why) == HM_EDOMAIN && strstr(why, "table made for"),
           "another vehicle's table accepted: %s", why);
  HM_CHECK(hm_monitor_table(r.mon) && hm_table_size(hm_monitor_table(r.mon), NULL, NULL) == 4, "the table in use");
  run_segment(&r, 7.0);
  HM_CHECK_DELTA(r.last.assessment.boundaries.lowest_cycle_speed_kmh, 239.548876, 1e-5, "still the refined table");
  run_free(&r);
}

/* Settings changed while monitoring (commissioning): at 425 km/h before identification (OK: 39.8 km/h below the
 * prior's Hopf interval, 464.8..593.8 km/h, WATCH starts 30 km/h below it) a 45 km/h WATCH margin makes the next
 * status WATCH; an invalid value is refused with
 * its reason and the running settings kept; a criterion limit below the running r.m.s. gives the criterion's ALARM;
 * a field that needs a new monitor (the sample rate) is not taken over. */
static void settings_changed_while_running(void) {
  run_state r;
  run_init(&r, 425.0, 0.01, 42, 4);
  run_segment(&r, 5.0);
  HM_CHECK(r.last.assessment.level == HM_LEVEL_OK, "level %s before", hm_level_name(r.last.assessment.level));
  hm_monitor_config c;
  hm_monitor_settings(r.mon, &c);
  c.alarm.watch_speed_margin_kmh = 45.0;
  c.estimator.sample_rate_hz = 500.0; /* ignored: needs a new monitor */
  char why[256] = "";
  HM_CHECK(hm_monitor_set_runtime_settings(r.mon, &c, why, sizeof why) == HM_OK, "valid change: %s", why);
  run_segment(&r, 5.2);
  HM_CHECK(r.last.assessment.level == HM_LEVEL_WATCH && r.last.assessment.reason == HM_REASON_APPROACHING_HOPF,
           "level %s after the WATCH margin went to 45 km/h", hm_level_name(r.last.assessment.level));
  hm_monitor_config now;
  hm_monitor_settings(r.mon, &now);
  HM_CHECK(now.alarm.watch_speed_margin_kmh == 45.0 && now.estimator.sample_rate_hz == 2000.0, "running settings");
  hm_monitor_config bad = now;
  bad.alarm.hysteresis_kmh = -1.0;
  HM_CHECK(hm_monitor_set_runtime_settings(r.mon, &bad, why, sizeof why) == HM_EDOMAIN &&
               strstr(why, "alarm.hysteresis_kmh") != NULL,
           "invalid change accepted or unexplained: %s", why);
  hm_monitor_settings(r.mon, &now);
  HM_CHECK(now.alarm.hysteresis_kmh == c.alarm.hysteresis_kmh, "the refused value was applied");
  bad = now;
  bad.estimator.peaks_count = 0;
  HM_CHECK(hm_monitor_set_runtime_settings(r.mon, &bad, why, sizeof why) == HM_EDOMAIN && strstr(why, "peaks_count"),
           "peaks_count 0 accepted: %s", why);
  const double rms = r.last.estimate.rms_mps2;
  c = now;
  c.estimator.rms_limit_mps2 = 0.5 * rms;
  HM_CHECK(rms > 0.0 && hm_monitor_set_runtime_settings(r.mon, &c, why, sizeof why) == HM_OK, "rms limit: %s", why);
  run_segment(&r, 5.4);
  HM_CHECK(r.last.assessment.level == HM_LEVEL_ALARM && r.last.assessment.reason == HM_REASON_RMS_CRITERION,
           "rms %.3f over a limit of %.3f m/s^2 gave %s", r.last.estimate.rms_mps2, 0.5 * rms,
           hm_level_name(r.last.assessment.level));
  run_free(&r);
}

static int n_seeds = 5;

/* The hunting mode's decay rate identified by the monitor after 45 s at a steady speed (our own simulator: the
 * DOPRI-integrated nonlinear model on a random track with the German low-disturbance spectrum, an axle-box
 * accelerometer at 2 kHz with 0.05 m/s^2 noise) within max(25%, 0.3 1/s) of the real part of the model's eigenvalue
 * (dgeev), for every seed, and no ALARM. 420 and 470 km/h on 10% of the spectrum's power (0.59 mm r.m.s. over 3-120 m
 * wavelengths, like the independent simulator's 0.3 mm over 3-60 m); 510 km/h, 7.6 km/h below the Hopf speed and
 * inside the bistable band, on 5%. (On the full spectrum, 1.86 mm r.m.s., one seed in five at 470 km/h meets the
 * wheelset peaks criterion with a 1.9 mm response: see README.) */
static void decay_rate_on_our_simulator(void) {
  const double speeds[] = {420.0, 470.0, 510.0}, scales[] = {0.1, 0.1, 0.05};
  for (int i = 0; i < 3; ++i) {
    double re[4], im[4];
    hm_linear_eigenvalues(&vehicle, 0.1358, hm_mps_from_kmh(speeds[i]), re, im);
    double lo = INFINITY, hi = -INFINITY;
    for (int seed = 1; seed <= n_seeds; ++seed) {
      run_state r;
      run_init(&r, speeds[i], scales[i], (uint64_t)(100 + seed), (uint64_t)seed);
      run_segment(&r, 45.0);
      const hm_mode_estimate *m = &r.last.mode;
      HM_CHECK(m->valid && r.last.mode_steady, "V %g seed %d: no mode (steady %d)", speeds[i], seed,
               r.last.mode_steady);
      HM_CHECK_DELTA(m->decay_rate_1_s, re[0], fmax(0.25 * fabs(re[0]), 0.3), "decay rate");
      lo = fmin(lo, m->decay_rate_1_s);
      hi = fmax(hi, m->decay_rate_1_s);
      HM_CHECK(r.levels_seen[HM_LEVEL_ALARM] == 0, "V %g seed %d: ALARM at %.2f s (%s; amplitude %.2f mm, r.m.s. %.2f, "
               "true max |y| %.2f mm)", speeds[i], seed, r.first_alarm_s, hm_reason_text(r.first_alarm_reason),
               1e3 * r.first_alarm_amp, r.first_alarm_rms, 1e3 * r.true_amp_max);
      run_free(&r);
    }
    printf("  %.0f km/h: decay rate %.3f..%.3f 1/s over %d seeds, model %.3f 1/s\n", speeds[i], lo, hi, n_seeds, re[0]);
  }
}

/* A fit over a speed changing faster than the identification follows is shown, not valid (issue #21): on a ramp
 * 470 -> 500 km/h over 40 s (0.75 km/h/s: max_speed_spread_kmh in 16 s, less than min_window_s) the windows'
 * speed varies beyond max_speed_spread_kmh, so the verdict is HM_WINDOW_SPEED_VARIED and mode_steady is 0 even where
 * the fit itself converged; the margin holds no window and the interval is the prior's. */
static void ramp_fits_are_not_valid_modes(void) {
  run_state r;
  run_init_ramp(&r, 470.0, 500.0, 40.0, 7);
  run_segment(&r, 38.0);
  printf("  ramp 470 -> 500 km/h: fit converged %d, verdict %d (%s), steady %d, %u windows held\n", r.last.mode.valid,
         (int)r.last.mode_verdict, hm_window_verdict_text(r.last.mode_verdict), r.last.mode_steady,
         r.last.margin.n_windows);
  HM_CHECK(r.last.mode_verdict == HM_WINDOW_SPEED_VARIED && !r.last.mode_steady && r.last.margin.n_windows == 0 &&
               r.last.assessment.conicity_from_prior,
           "a ramp's fit taken as the mode: verdict %d, steady %d", (int)r.last.mode_verdict, r.last.mode_steady);
  run_free(&r);
}

/* Identification while the speed changes (issue #18): accelerating 440 -> 500 km/h at 0.5 km/h/s on our simulator
 * (conicity 0.1358, closed-form Hopf speed 517.6 km/h), two seeds (one with --short): the ramp's windows are used
 * back to back (at least three in the 120 s), the level's interval then comes from them (not the prior) and holds
 * the closed-form Hopf speed, and no level above WATCH is shown more than 40 km/h below the truth (the bound
 * for a ramp). */
static void ramp_windows_identify_the_mode(void) {
  const double truth = hm_linear_hopf_kmh(&vehicle, 0.1358);
  for (uint64_t seed = 7; seed <= (n_seeds > 1 ? 8u : 7u); ++seed) {
    run_state r;
    run_init_ramp(&r, 440.0, 500.0, 120.0, seed);
    double warn_speed = INFINITY;
    for (double t = 5.0; t <= 119.0 + 1e-9; t += 1.0) {
      run_segment(&r, t);
      if (r.last.assessment.level >= HM_LEVEL_WARN && r.last.estimate.speed_kmh < warn_speed)
        warn_speed = r.last.estimate.speed_kmh;
    }
    const hm_assessment *s = &r.last.assessment;
    printf("  ramp 440 -> 500 km/h, seed %d: %u windows, Hopf %.1f [%.1f, %.1f] (closed form %.1f), from estimate %d, "
           "first WARN at %.1f km/h\n", (int)seed, r.last.margin.n_windows, s->boundaries.hopf_speed_kmh,
           s->hopf_low_kmh, s->hopf_high_kmh, truth, s->conicity_from_estimate, warn_speed);
    HM_CHECK(r.last.margin.n_windows >= 3 && r.verdicts_seen[HM_WINDOW_USED] > 0, "seed %d: %u ramp windows held",
             (int)seed, r.last.margin.n_windows);
    HM_CHECK(s->conicity_from_estimate && s->hopf_low_kmh <= truth && truth <= s->hopf_high_kmh,
             "seed %d: interval [%.1f, %.1f] from estimate %d", (int)seed, s->hopf_low_kmh, s->hopf_high_kmh,
             s->conicity_from_estimate);
    HM_CHECK(warn_speed >= truth - 40.0, "seed %d: WARN at %.1f km/h", (int)seed, warn_speed);
    run_free(&r);
  }
}

/* The WARN's lead on a ramp through the Hopf speed (issue #18's claim, issue #27 item 6): accelerating at a mean
 * 0.5 km/h/s from 420 km/h to 540 km/h on our simulator (conicity 0.1358, closed-form Hopf speed 517.6 km/h), smoothly
 * or in a driver's notches (5 s at 1 km/h/s, then 5 s held), WARN comes at least 10 s before the simulated wheelset's
 * true displacement |y| first reaches 3 mm (the simulator's state, not the monitor's estimate), and no WARN more than
 * 40 km/h below the closed-form Hopf speed (the ramp's bound, evaluate_line); each seed's notched and smooth WARN
 * speeds within 5 km/h of each other (10 s of the mean acceleration; with the least slope between blocks, until issue
 * #27, 8.0-11.9 km/h apart and the notched WARN 5.9 s before 3 mm on seed 203), four seeds (one with --short). */
static void warn_leads_3mm_on_smooth_and_notched_ramps(void) {
  const double truth = hm_linear_hopf_kmh(&vehicle, 0.1358), v0 = 420.0, v1 = 540.0, on_s = 5.0, off_s = 5.0;
  double t[HM_SPEED_PROFILE_MAX], v[HM_SPEED_PROFILE_MAX];
  size_t n_notched = 0;
  for (double tk = 0.0, vk = v0; vk < v1 - 1e-9 && n_notched + 2 <= HM_SPEED_PROFILE_MAX; tk += on_s + off_s) {
    t[n_notched] = tk, v[n_notched++] = vk; /* a notch: 1 km/h/s for on_s */
    vk += 1.0 * on_s;
    t[n_notched] = tk + on_s, v[n_notched++] = vk; /* then held for off_s */
  }
  const double t_end = t[n_notched - 1] + 60.0;
  HM_CHECK(v[n_notched - 1] >= v1 - 1e-9, "the notched profile reaches %.1f km/h only", v[n_notched - 1]);
  double lead_min[2] = {INFINITY, INFINITY}, lead_max[2] = {-INFINITY, -INFINITY};
  for (int seed = 1; seed <= (n_seeds > 1 ? 4 : 1); ++seed) {
    double warn_kmh[2] = {NAN, NAN};
    for (int notched = 0; notched < 2; ++notched) {
      run_state r;
      const double ts[2] = {0.0, (v1 - v0) / 0.5}, vs[2] = {v0, v1};
      if (notched) run_init_profile(&r, t, v, n_notched, (uint64_t)(200 + seed));
      else run_init_profile(&r, ts, vs, 2, (uint64_t)(200 + seed));
      for (double tk = 10.0; tk <= t_end + 1e-9 && r.t_true_3mm < 0.0; tk += 10.0) run_segment(&r, tk);
      const double lead = r.t_true_3mm - r.first_warn_s;
      printf("  %s ramp, seed %d: WARN at %.1f s (%.1f km/h, %.1f below the Hopf speed), 3 mm at %.1f s: %.1f s "
             "before\n", notched ? "notched" : "smooth", seed, r.first_warn_s, r.first_warn_kmh,
             truth - r.first_warn_kmh, r.t_true_3mm, lead);
      HM_CHECK(r.t_true_3mm > 0.0 && r.first_warn_s > 0.0, "seed %d: no 3 mm (%.1f) or no WARN (%.1f)", seed,
               r.t_true_3mm, r.first_warn_s);
      HM_CHECK(r.first_warn_s <= r.t_true_3mm - 10.0, "%s seed %d: WARN only %.1f s before 3 mm",
               notched ? "notched" : "smooth", seed, lead);
      HM_CHECK(r.first_warn_kmh >= truth - 40.0, "%s seed %d: WARN at %.1f km/h, %.1f below the Hopf speed",
               notched ? "notched" : "smooth", seed, r.first_warn_kmh, truth - r.first_warn_kmh);
      warn_kmh[notched] = r.first_warn_kmh;
      lead_min[notched] = fmin(lead_min[notched], lead);
      lead_max[notched] = fmax(lead_max[notched], lead);
      run_free(&r);
    }
    HM_CHECK(fabs(warn_kmh[1] - warn_kmh[0]) <= 5.0, "seed %d: WARN at %.1f km/h notched, %.1f smooth", seed,
             warn_kmh[1], warn_kmh[0]);
  }
  printf("  WARN before 3 mm: smooth %.1f..%.1f s, notched %.1f..%.1f s\n", lead_min[0], lead_max[0], lead_min[1],
         lead_max[1]);
}

/* Braking through the fold (issue #27 item 7): worn wheels (the simulated conicity 0.16; the monitor keeps the
 * vehicle's configuration) hunting on their large cycle from 490 km/h (a kick of 8 mm), braking at 1 km/h/s to 220 km/h.
 * References: the simulator's own state (the speed at the last time the true |y| reached 2.1 mm: here 260.5 km/h, the
 * large cycle lost where it is unstable between its symmetry-breaking points) and the fold of the cycle family at 0.16
 * (the table's exact family there: 234.5 km/h), below which no cycle exists. The hunted-at speed lies at most 5 km/h
 * below that speed (the criteria's windows lag the truth by up to 5 s: 1 s of tracking, 100 m of r.m.s., six peaks)
 * and not 5 km/h below the fold; once the oscillation has died the level is held: reason the
 * cause that latched the ALARM and the text saying "held", the release speed the hunted-at speed less 3 km/h, calm 0
 * until the speed is below it; released 10 s (release_s) after the first status below it. */
static void braking_through_the_fold_holds_and_says_why(void) {
  hm_vehicle worn = vehicle;
  HM_CHECK(hm_vehicle_set_conicity_at_zero(&worn, 0.16) == HM_OK, "worn wheels");
  hm_table t = NULL;
  char why[256] = "";
  HM_CHECK(hm_table_parse(table_text, table_len, &t, why, sizeof why) == HM_OK, "table: %s", why);
  hm_table_lookup_result fold;
  HM_CHECK(hm_table_lookup(t, 0.16, 300.0, &fold) == HM_OK && !fold.clamped, "lookup at 0.16");
  hm_table_destroy(t);
  const double ts[4] = {0.0, 20.0, 290.0, 330.0}, vs[4] = {490.0, 490.0, 220.0, 220.0};
  run_state r;
  run_init_vehicle(&r, &worn, ts, vs, 4, 31);
  const double x0[4] = {0.008, 0.0, 0.0, 0.0};
  HM_CHECK(hm_sensor_sim_set_state(r.sim, x0) == HM_OK, "kick");
  double t_below = -1.0, released = -1.0, release_below = NAN, hunted = NAN;
  int held_seen = 0, held_ok = 1;
  hm_reason first_cause = HM_REASON_STARTUP;
  char text[512] = "";
  for (double tk = 0.5; tk <= 330.0 + 1e-9 && released < 0.0; tk += 0.05) {
    run_segment(&r, tk);
    const hm_assessment *s = &r.last.assessment;
    if (s->latched && first_cause == HM_REASON_STARTUP) first_cause = s->hold_cause;
    if (s->latched && s->held) {
      if (!held_seen) hm_assessment_reason_text(s, 0.0, text, sizeof text);
      held_seen = 1;
      hunted = s->hunted_at_kmh;
      release_below = s->hold_release_below_kmh;
      held_ok &= s->reason == first_cause && s->hold_cause == first_cause && s->level == HM_LEVEL_ALARM &&
                 fabs(s->hold_release_below_kmh - (s->hunted_at_kmh - 3.0)) < 1e-9 && s->calm_needed_s == 10.0 &&
                 (t_below < 0.0 ? s->calm_s == 0.0 : s->calm_s > 0.0);
      if (t_below < 0.0 && r.last.estimate.speed_kmh < s->hold_release_below_kmh) t_below = r.last.assessment.time_s;
    }
    if (held_seen && !s->latched) released = s->time_s;
  }
  const double v_true = hm_sensor_sim_speed_kmh(r.sim, r.t_true_2mm_last);
  printf("  the first held status: %s\n", text);
  printf("  fold %.1f km/h, true |y| last at 2.1 mm at %.1f s (%.1f km/h), hunted at %.1f km/h, release below %.1f "
         "from %.2f s, released at %.2f s\n", fold.lowest_cycle_speed_kmh, r.t_true_2mm_last, v_true, hunted,
         release_below, t_below, released);
  HM_CHECK(held_seen && held_ok && strncmp(text, "held (", 6) == 0 && strstr(text, "releases below"),
           "the hold: seen %d, fields %d, text %s", held_seen, held_ok, text);
  HM_CHECK(hunted >= v_true - 5.0 && hunted <= v_true + 1.0 && hunted >= fold.lowest_cycle_speed_kmh - 5.0,
           "hunted at %.1f km/h, the true oscillation died at %.1f, the fold at %.1f", hunted, v_true,
           fold.lowest_cycle_speed_kmh);
  HM_CHECK(t_below > 0.0 && fabs(released - (t_below + 10.0)) <= 0.051, "released at %.2f s, below from %.2f s",
           released, t_below);
  run_free(&r);
}

int main(int argc, char **argv) {
  if (argc > 1 && strcmp(argv[1], "--short") == 0) n_seeds = 1;
  hm_vehicle_default(&vehicle);
  if (hm_test_small_table_text(&table_text, &table_len) != HM_OK) {
    printf("FAIL table_build\n");
    return 1;
  }
  HM_RUN(below_lowest_cycle_speed_stays_ok);
  HM_RUN(hunting_onset_alarms_within_a_second);
  HM_RUN(table_refined_at_the_conicity_in_use);
  HM_RUN(settings_changed_while_running);
  HM_RUN(decay_rate_on_our_simulator);
  HM_RUN(ramp_fits_are_not_valid_modes);
  HM_RUN(ramp_windows_identify_the_mode);
  HM_RUN(warn_leads_3mm_on_smooth_and_notched_ramps);
  HM_RUN(braking_through_the_fold_holds_and_says_why);
  free(table_text);
  HM_TEST_EXIT();
}
