/* mode_model.h: the identified mode read as a conicity and a Hopf speed by any vehicle model. For the wheelset
 * against inversion.h's closed-form inversion and linear.h's closed-form Hopf speed; for the bogie and the car
 * against their own modes (the conicity that made a root is found again from it) and their critical speeds. */
#include <string.h>

#include "hm_test.h"
#include "hunting_monitor/linear.h"
#include "hunting_monitor/modal.h"
#include "hunting_monitor/mode_model.h"
#include "hunting_monitor/monitor.h"
#include "hunting_monitor/sensor_sim.h"
#include "hunting_monitor/tables.h"

static void wheelset_as_inversion_h(void) {
  hm_vehicle veh;
  hm_vehicle_default(&veh);
  hm_mode_model m = NULL;
  HM_CHECK(hm_mode_model_create_wheelset(&veh, &m) == HM_OK && m, "create");
  if (!m) return;
  hm_linear_coef coef;
  hm_linear_coef_from_vehicle(&veh, &coef);
  const double cases[][4] = {/* conicity, speed, and an offset of the measured mode from the root (1/s, Hz) */
                             {0.12, 400.0, 0.0, 0.0}, {0.16, 450.0, 0.3, -0.05}, {0.20, 300.0, -0.5, 0.1},
                             {0.30, 250.0, 0.2, 0.2}};
  for (int k = 0; k < 4; ++k) {
    double s, w;
    HM_CHECK(hm_hunting_root(&coef, cases[k][1], cases[k][0], &s, &w) == HM_OK, "root");
    const double sm = s + cases[k][2], fm = w / (2.0 * HM_PI) + cases[k][3];
    hm_conicity_inversion a, b;
    HM_CHECK(hm_conicity_from_mode(&coef, cases[k][1], sm, 0.2, fm, 0.05, 1e-10, 50, &a) == HM_OK, "inversion.h");
    HM_CHECK(hm_mode_model_invert(m, cases[k][1], sm, 0.2, fm, 0.05, 1e-10, 50, &b) == HM_OK, "mode model");
    HM_CHECK_DELTA(b.conicity, a.conicity, 1e-7, "conicity");
    HM_CHECK_REL(b.conicity_se, a.conicity_se, 1e-5, "its standard error");
    HM_CHECK_DELTA(b.chi2, a.chi2, 1e-6 * (1.0 + a.chi2), "chi2");
    HM_CHECK_DELTA(b.model_frequency_hz, a.model_frequency_hz, 1e-8, "model frequency");
    if (cases[k][2] == 0.0) HM_CHECK_DELTA(b.conicity, cases[k][0], 1e-8, "the root's own conicity");
  }
  const double lambdas[] = {0.08, 0.1358, 0.25};
  for (int k = 0; k < 3; ++k) {
    double v = 0.0, f = 0.0, v_closed = 0.0, omega = 0.0;
    int body = -1;
    HM_CHECK(hm_mode_model_hopf(m, lambdas[k], &v, &f, &body) == HM_OK, "hopf");
    HM_CHECK(hm_linear_critical_speed(&veh, lambdas[k], &v_closed) == HM_OK && hm_linear_hopf_omega(&veh, &omega) == 0,
             "closed form");
    HM_CHECK_DELTA(v, hm_kmh_from_mps(v_closed), 1e-5, "Hopf speed against the closed form");
    HM_CHECK_DELTA(f, omega / (2.0 * HM_PI), 1e-6, "its frequency");
    HM_CHECK(body == 0, "the wheelset's mode");
  }
  hm_mode_model_destroy(m);
}

/* The bogie and the car: the conicity that made a mode is found from it again (the root followed among their 6 and
 * 15 oscillatory pairs), and the Hopf speed is the system's critical speed. */
static void bogie_and_car_find_their_own_conicity(void) {
  hm_bogie b;
  hm_bogie_default(&b);
  hm_car c;
  hm_car_default(&c);
  for (int kind = 0; kind < 2; ++kind) {
    hm_mode_model m = NULL;
    HM_CHECK((kind ? hm_mode_model_create_car(&c, &m) : hm_mode_model_create_bogie(&b, &m)) == HM_OK && m, "create");
    if (!m) continue;
    const double lambdas[] = {0.10, 0.17, 0.25}, speeds[] = {480.0, 400.0, 320.0};
    for (int k = 0; k < 3; ++k) {
      /* the wheelsets' mode at that conicity: the root nearest 14 Hz, well damped or not */
      double s = 0.0, f = 0.0;
      HM_CHECK(hm_mode_model_root(m, lambdas[k], speeds[k], -2.0, 5.0, 14.0, 2.0, &s, &f) == HM_OK, "root");
      hm_conicity_inversion r;
      HM_CHECK(hm_mode_model_invert(m, speeds[k], s, 0.2, f, 0.05, 1e-10, 50, &r) == HM_OK, "invert");
      printf("  %s at %.2f, %.0f km/h: mode %.4f 1/s at %.4f Hz -> conicity %.8f +- %.5f\n", kind ? "car" : "bogie",
             lambdas[k], speeds[k], s, f, r.conicity, r.conicity_se);
      HM_CHECK_DELTA(r.conicity, lambdas[k], 1e-7, "the conicity found again");
      HM_CHECK(r.chi2 < 1e-10, "and the mode explained exactly (chi2 %.3g)", r.chi2);
    }
    double v = 0.0, f = 0.0;
    int body = -1;
    HM_CHECK(hm_mode_model_hopf(m, 0.1358, &v, &f, &body) == HM_OK, "hopf");
    hm_system sys;
    hm_bogie_model bm;
    hm_car_model cm;
    HM_CHECK((kind ? hm_car_model_init(&cm, &c, 0, &sys) : hm_bogie_model_init(&bm, &b, 0, &sys)) == HM_OK, "sys");
    hm_system_critical_options opt;
    hm_system_critical_options_default(&opt);
    double vc = 0.0;
    HM_CHECK(hm_system_critical_speed(&sys, &opt, &vc, NULL) == HM_OK, "critical");
    HM_CHECK_DELTA(v, hm_kmh_from_mps(vc), 1e-5, "Hopf speed as the system's critical speed");
    HM_CHECK(body == 0, "the wheelsets' mode at 0.1358");
    hm_mode_model_destroy(m);
  }
}

/* The Hopf curve for the monitor: exact (the closed form) for the wheelset at any conicity, and within 0.05 km/h
 * of the exact critical speed for the bogie where its wheelsets' mode stays the critical one (0.05-0.25). */
static void hopf_curve(void) {
  hm_vehicle veh;
  hm_vehicle_default(&veh);
  hm_bogie b;
  hm_bogie_default(&b);
  hm_mode_model w = NULL, m = NULL;
  HM_CHECK(hm_mode_model_create_wheelset(&veh, &w) == HM_OK && hm_mode_model_create_bogie(&b, &m) == HM_OK, "create");
  if (!w || !m) return;
  double worst_w = 0.0, worst_b = 0.0;
  for (double l = 0.05; l <= 0.25; l *= 1.037) {
    worst_w = fmax(worst_w, fabs(hm_mode_model_hopf_kmh(w, l) - hm_linear_hopf_kmh(&veh, l)));
    double v = 0.0;
    HM_CHECK(hm_mode_model_hopf(m, l, &v, NULL, NULL) == HM_OK, "exact");
    worst_b = fmax(worst_b, fabs(hm_mode_model_hopf_kmh(m, l) - v));
  }
  printf("  the curve off the exact Hopf speed by at most %.2g km/h (wheelset), %.3f km/h (bogie) over 0.05-0.25\n",
         worst_w, worst_b);
  HM_CHECK(worst_w < 1e-6, "the wheelset's curve is exact");
  HM_CHECK(worst_b < 0.05, "the bogie's curve within 0.05 km/h");
  HM_CHECK(hm_mode_model_hopf_kmh(m, 0.005) == HM_LINEAR_NO_HOPF_KMH, "below the grid: none");
  double s = 0.0, om = 0.0, s_l = 0.0, om_l = 0.0;
  hm_linear_coef coef;
  hm_linear_coef_from_vehicle(&veh, &coef);
  HM_CHECK(hm_mode_model_least_damped(w, 0.16, 430.0, &s, &om) == HM_OK &&
               hm_hunting_root(&coef, 430.0, 0.16, &s_l, &om_l) == HM_OK, "least damped");
  HM_CHECK_DELTA(s, s_l, 1e-9, "least-damped root as inversion.h's hunting root");
  HM_CHECK_DELTA(om, om_l, 1e-9, "its frequency");
  hm_mode_model_destroy(w);
  hm_mode_model_destroy(m);
}

/* Review of issue #28: a car's least-damped root is its hunting mode in the band, not the carbody's 0.6 Hz sway; the
 * bogie's curve across the kink where its frame's mode takes over (near 0.283) is exact there; a conicity whose
 * Hopf speed is below 100 km/h (1.7 for the bogie) has one, not "none". */
static void band_kink_and_low_speeds(void) {
  hm_car c;
  hm_car_default(&c);
  hm_bogie b;
  hm_bogie_default(&b);
  hm_mode_model car = NULL, m = NULL;
  HM_CHECK(hm_mode_model_create_car(&c, &car) == HM_OK && hm_mode_model_create_bogie(&b, &m) == HM_OK, "create");
  if (!car || !m) return;
  double s = 0.0, w = 0.0, s_ref = 0.0, f_ref = 0.0;
  HM_CHECK(hm_mode_model_least_damped(car, 0.1358, 400.0, &s, &w) == HM_OK, "least damped");
  HM_CHECK(hm_mode_model_root(car, 0.1358, 400.0, -5.0, 5.0, 14.0, 2.0, &s_ref, &f_ref) == HM_OK, "14 Hz root");
  printf("  car at 400 km/h: least damped in 2-30 Hz %.3f 1/s at %.2f Hz\n", s, w / (2.0 * HM_PI));
  HM_CHECK(w / (2.0 * HM_PI) > 2.0, "in the band, not the carbody's sway");
  HM_CHECK(s >= s_ref - 1e-12, "no less damped than the wheelsets' 14 Hz mode");
  double worst = 0.0;
  for (double l = 0.275; l <= 0.292; l += 0.0007) {
    double v = 0.0;
    HM_CHECK(hm_mode_model_hopf(m, l, &v, NULL, NULL) == HM_OK, "exact");
    worst = fmax(worst, fabs(hm_mode_model_hopf_kmh(m, l) - v));
  }
  printf("  bogie curve across the kink (0.275-0.292): at most %.3g km/h off the exact speed\n", worst);
  HM_CHECK(worst < 0.05, "the curve's stated error holds across the kink");
  double v = 0.0;
  HM_CHECK(hm_mode_model_hopf(m, 1.7, &v, NULL, NULL) == HM_OK && v < 100.0, "a Hopf speed below 100 km/h: %g", v);
  HM_CHECK_DELTA(hm_mode_model_hopf_kmh(m, 1.7), v, 0.05, "and the curve gives it");
  hm_mode_model_destroy(car);
  hm_mode_model_destroy(m);
}

/* The model's reading (mode_model.h) is a fit of the monitor's spectral model to the model's spectrum: on the lone
 * wheelset, whose axle box shows one hunting pair over a smooth background, it is that pair's eigenvalue (dgeev, a
 * second method) to within the background's pull. */
static void reading_of_the_wheelset_is_its_root(void) {
  hm_vehicle veh;
  hm_vehicle_default(&veh);
  hm_mode_model m = NULL;
  HM_CHECK(hm_mode_model_create_wheelset(&veh, &m) == HM_OK && m, "model");
  if (!m) return;
  double s, f;
  HM_CHECK(hm_mode_model_reading(m, 0.1358, 450.0, 1, &s, &f) == HM_EDOMAIN, "no sensor set: no reading");
  HM_CHECK(hm_mode_model_set_sensor(m, "frame") == HM_EINVAL && !hm_mode_model_has_sensor(m), "a wheelset has no frame");
  HM_CHECK(hm_mode_model_set_band(m, 6.0, 22.0) == HM_OK && hm_mode_model_set_sensor(m, "axlebox") == HM_OK, "sensor");
  double worst_s = 0.0, worst_f = 0.0;
  for (double v = 380.0; v <= 500.0; v += 40.0) {
    double sg, om;
    HM_CHECK(hm_mode_model_least_damped(m, 0.1358, v, &sg, &om) == HM_OK, "root");
    HM_CHECK(hm_mode_model_reading(m, 0.1358, v, 1, &s, &f) == HM_OK, "reading at %.0f km/h", v);
    worst_s = fmax(worst_s, fabs(s - sg));
    worst_f = fmax(worst_f, fabs(f - om / (2.0 * HM_PI)));
  }
  printf("  wheelset 380-500 km/h: reading - root at most %.3f 1/s, %.4f Hz\n", worst_s, worst_f);
  HM_CHECK(worst_s <= 0.1 && worst_f <= 0.02, "the reading is the root");
  hm_mode_model_destroy(m);
}

/* The inversion of a reading finds the conicity it was read at, where the read peak is not the model's strongest (the
 * car's axle box at 480 km/h: its 7.6 Hz peak; a start at the measured mode scaled to the 14 Hz one ran off and had
 * returned 0.0557 for 0.10) and beside the Hopf conicity of another root (the bogie frame's 8.6 Hz mode over 5-13 Hz
 * at 495 km/h, the wheelsets' 14 Hz root unstable from 0.158: the reading had turned growing there and 0.1575 read
 * 0.200). The reference is the conicity given. */
static void reading_inverts_back(void) {
  static const struct {
    hm_model_kind kind;
    const char *where;
    double lo, hi, v, lambda;
  } cases[] = {{HM_MODEL_CAR, "axlebox", 6.0, 22.0, 480.0, 0.10}, {HM_MODEL_BOGIE, "frame", 5.0, 13.0, 495.0, 0.1575}};
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
    hm_car p;
    hm_car_default(&p);
    hm_mode_model m = NULL;
    HM_CHECK(hm_mode_model_create(cases[i].kind, &p, &m) == HM_OK && m, "model");
    if (!m) continue;
    HM_CHECK(hm_mode_model_set_band(m, cases[i].lo, cases[i].hi) == HM_OK &&
                 hm_mode_model_set_sensor(m, cases[i].where) == HM_OK, "sensor");
    double s = NAN, f = NAN;
    HM_CHECK(hm_mode_model_reading(m, cases[i].lambda, cases[i].v, 1, &s, &f) == HM_OK && s < 0.0, "reading");
    hm_conicity_inversion inv;
    memset(&inv, 0, sizeof inv);
    HM_CHECK(hm_mode_model_invert_reading(m, 1, cases[i].v, s, 0.3, f, 0.05, 1e-9, 60, &inv) == HM_OK, "inverted");
    printf("  %s at %.0f km/h, conicity %.4f: reads %.3f 1/s at %.3f Hz, inverted to %.5f (chi2 %.2g)\n",
           cases[i].where, cases[i].v, cases[i].lambda, s, f, inv.conicity, inv.chi2);
    HM_CHECK(fabs(inv.conicity - cases[i].lambda) < 1e-3, "back to the conicity read");
    HM_CHECK(hm_mode_model_invert_reading(m, 3, cases[i].v, s, 0.3, f, 0.05, 1e-9, 60, &inv) == HM_EDOMAIN,
             "three pairs");
    hm_mode_model_destroy(m);
  }
}

/* A recording's measured acceleration. */
typedef struct {
  double *a;
  size_t n, cap;
} acc_rec;

static int keep_accel(void *ctx, double t, double measured, double true_accel, const double *x) {
  (void)t, (void)true_accel, (void)x;
  acc_rec *r = (acc_rec *)ctx;
  if (r->n < r->cap) r->a[r->n++] = measured;
  return 0;
}

/* The whole monitor on a bogie's axle box and frame (issue #28): a recording of the default bogie at 480 km/h
 * (sensor_sim.h: the nonlinear model integrated over a random track) read by its model. The identified reading is no
 * eigenvalue (the two wheelsets' responses summed at the axle box: two pole pairs read -1.6 1/s where the least-damped
 * root is -3.3), so the conicity is the one whose model reading matches; the truth is the simulated conicity and the
 * bogie's Hopf speed by eigenvalue bisection. From the frame (config/monitor_bogie_frame.yaml's settings: its 8 Hz
 * mode read over 5-13 Hz, a window's conicity from the model's whole spectrum over 4-22 Hz, spectrum_fit.h) the
 * conicity comes to within a third of the error the frame's pair readings gave (0.007-0.014 a window). At the axle box
 * with the spectrum a test only (config/monitor_bogie_axlebox.yaml) the conicity is the pair readings' to the bit. */
static void monitor_reads_a_bogie(void) {
  hm_car p;
  hm_car_default(&p);
  double conicity_pairs = NAN;
  for (int run = 0; run < 3; ++run) {
    const int frame = run == 1;
    hm_sensor_sim_config c;
    hm_sensor_sim_config_default(&c);
    c.v_start_kmh = c.v_end_kmh = 480.0;
    c.irregularity_scale = 0.3;
    c.track_seed = c.noise_seed = 11;
    c.accel_rate_hz = 500.0;
    c.accel_noise_mps2 = 0.05;
    hm_bogie_model bm;
    hm_system sys;
    hm_sensor_point point;
    hm_sensor_sim sim = NULL;
    HM_CHECK(hm_bogie_model_init(&bm, &p.bogie, 0, &sys) == HM_OK &&
                 hm_bogie_sensor(&bm, frame ? "frame" : "axlebox", &point) == HM_OK,
             "bogie");
    HM_CHECK(hm_sensor_sim_create_system(&sys, &point, &c, NULL, &sim, NULL, 0) == HM_OK, "run");
    enum { N = 75000 }; /* 150 s */
    static double a[N + 1];
    acc_rec r = {a, 0, N + 1};
    const hm_sensor_sink sink = {keep_accel, NULL, &r};
    if (sim) HM_CHECK(hm_sensor_sim_run(sim, 150.0, &sink) == HM_OK, "simulate");
    hm_sensor_sim_destroy(sim);
    hm_table_spec spec;
    hm_table_spec_default(&spec);
    spec.n_conicity = 2, spec.conicity_min = 0.13, spec.conicity_max = 0.14, spec.speed_min_kmh = 400.0;
    spec.amp_max_m = 0.004;
    hm_table t = NULL;
    hm_monitor mon = NULL;
    hm_monitor_config cfg;
    hm_monitor_config_default(&cfg);
    cfg.estimator.sample_rate_hz = 500.0;
    if (frame) {
      cfg.estimator.measurement_point = HM_POINT_BOGIE_FRAME;
      cfg.modal.band_low_hz = 5.0, cfg.modal.band_high_hz = 13.0, cfg.modal.min_peak_prominence = 4.0;
      cfg.margin.spectrum_low_hz = 4.0, cfg.margin.spectrum_high_hz = 22.0;
    } else if (run == 2) {
      cfg.margin.spectrum_low_hz = 6.0, cfg.margin.spectrum_high_hz = 22.0, cfg.margin.spectrum_conicity = 0;
    }
    char why[256] = "";
    HM_CHECK(hm_table_build_model(HM_MODEL_BOGIE, &p, &spec, NULL, NULL, &t) == HM_OK, "table");
    HM_CHECK(hm_monitor_create_model(&cfg, HM_MODEL_BOGIE, &p, t, NULL, NULL, &mon, why, sizeof why) == HM_OK, "%s",
             why);
    hm_monitor_status st;
    memset(&st, 0, sizeof st);
    int spectra = 0;
    for (size_t k = 0; mon && k < r.n; ++k) {
      const double tk = (double)k / 500.0;
      if (k % 50 == 0) hm_monitor_push_speed(mon, tk, 480.0);
      hm_monitor_push_accel(mon, tk, a[k]);
      if (k % 500 == 499) hm_monitor_update(mon, tk, &st), spectra += st.mode.spectrum_valid;
    }
    hm_mode_model m = NULL;
    double v_true = NAN, sg, om;
    HM_CHECK(hm_mode_model_create_bogie(&p.bogie, &m) == HM_OK &&
                 hm_mode_model_hopf(m, 0.1358, &v_true, NULL, NULL) == HM_OK,
             "the bogie's Hopf speed");
    HM_CHECK(m && hm_mode_model_least_damped(m, 0.1358, 480.0, &sg, &om) == HM_OK, "its least-damped root");
    const hm_margin_estimate *g = &st.margin;
    printf("  bogie %s, 480 km/h: last reading %u pair(s) %.3f 1/s at %.3f Hz (least-damped root %.3f at %.3f);"
           " conicity %.4f +- %.4f (truth 0.1358), Hopf %.1f [%.1f, %.1f] (truth %.2f); %d statuses with the spectrum's"
           " fit\n",
           frame ? "frame" : run ? "axle box (the spectrum a test)" : "axle box", st.mode.poles, st.mode.decay_rate_1_s, st.mode.frequency_hz, sg,
           om / (2.0 * HM_PI), g->conicity, g->conicity_se, g->hopf_model_kmh, g->hopf_model_low_kmh,
           g->hopf_model_high_kmh, v_true, spectra);
    HM_CHECK(g->conicity_valid && fabs(g->conicity - 0.1358) <= 3.0 * g->conicity_se &&
                 g->conicity_se < (frame ? 0.0045 : 0.01),
             "the conicity found again");
    HM_CHECK(g->hopf_model_low_kmh <= v_true && v_true <= g->hopf_model_high_kmh && !g->model_mismatch,
             "the interval holds the bogie's Hopf speed");
    HM_CHECK(run ? spectra > 0 : spectra == 0, "the spectrum fitted where it is set");
    if (run == 0) conicity_pairs = g->conicity;
    if (run == 2) HM_CHECK(g->conicity == conicity_pairs, "a test only: the pairs' conicity %.6f", conicity_pairs);
    hm_mode_model_destroy(m);
    hm_monitor_destroy(mon);
  }
}

static void bad_input(void) {
  hm_vehicle veh;
  hm_vehicle_default(&veh);
  hm_mode_model m = NULL;
  veh.mass_kg = -1.0;
  HM_CHECK(hm_mode_model_create_wheelset(&veh, &m) == HM_EDOMAIN && m == NULL, "negative mass");
  hm_vehicle_default(&veh);
  HM_CHECK(hm_mode_model_create_wheelset(&veh, &m) == HM_OK, "create");
  hm_conicity_inversion r;
  memset(&r, 0x5a, sizeof r);
  const unsigned char before = ((unsigned char *)&r)[0];
  HM_CHECK(hm_mode_model_invert(m, 400.0, 0.5, 0.2, 14.0, 0.05, 1e-10, 50, &r) == HM_EDOMAIN, "a growing mode");
  HM_CHECK(hm_mode_model_invert(m, NAN, -1.0, 0.2, 14.0, 0.05, 1e-10, 50, &r) == HM_EDOMAIN, "NaN speed");
  HM_CHECK(hm_mode_model_invert(m, 400.0, -1.0, 0.0, 14.0, 0.05, 1e-10, 50, &r) == HM_EDOMAIN, "zero error");
  HM_CHECK(((unsigned char *)&r)[0] == before, "output untouched");
  double v = -1.0;
  HM_CHECK(hm_mode_model_hopf(m, -0.1, &v, NULL, NULL) == HM_EDOMAIN && v == -1.0, "negative conicity");
  HM_CHECK(hm_mode_model_hopf(m, 0.001, &v, NULL, NULL) == HM_ENOCRIT && v == -1.0, "no Hopf point in range");
  HM_CHECK(hm_mode_model_kind(NULL) == HM_MODEL_WHEELSET, "a NULL model");
  hm_mode_model_destroy(m);
}

/* A stationary, decaying reading is never explained by a conicity at which the model is unstable at the window's
 * speed (mode_model.h): the vehicle ran there without hunting. The bogie's axle-box readings below were measured at
 * 523 km/h on a recording of conicity 0.12 (scripts/evaluate_vehicle, default_axlebox_1): the one-pair -3.43 1/s at
 * 14.13 Hz had been matched to 0.157, where the wheelsets' root grows at +1.4 1/s (a stable root's peak beside it).
 * The reference is the model's own eigenvalues at the conicity found, and its Hopf speed by eigenvalue bisection. */
static void unstable_conicities_explain_no_reading(void) {
  hm_car p;
  hm_car_default(&p);
  hm_mode_model m = NULL;
  HM_CHECK(hm_mode_model_create(HM_MODEL_BOGIE, &p, &m) == HM_OK && m, "model");
  if (!m) return;
  hm_monitor_config cfg;
  hm_monitor_config_default(&cfg);
  hm_modal modal = NULL;
  HM_CHECK(hm_modal_create(&cfg.modal, 500.0, &modal, NULL, 0) == HM_OK, "the monitor's filters at 500 Hz");
  HM_CHECK(hm_mode_model_set_band(m, cfg.modal.band_low_hz, cfg.modal.band_high_hz) == HM_OK &&
               hm_mode_model_set_sensor(m, "axlebox") == HM_OK, "sensor");
  hm_mode_model_set_reading_gain(m, hm_modal_filter_power_gain, modal);
  static const struct { /* the reading and its errors as margin.c hands them (the model's errors included) */
    unsigned poles;
    double sigma, e_sigma, f_hz, e_f;
  } r[] = {{1, -3.4326, 0.468, 14.1294, 0.155}, {1, -3.4326, 0.4, 14.1294, 0.1}, {2, -0.58, 0.12, 13.93, 0.14},
           {2, -1.16, 0.2, 13.93, 0.14}, {1, -0.9, 0.3, 14.2, 0.14}};
  const double v = 522.9;
  for (size_t i = 0; i < sizeof r / sizeof r[0]; ++i) {
    hm_conicity_inversion inv;
    memset(&inv, 0, sizeof inv);
    const hm_status st =
        hm_mode_model_invert_reading(m, r[i].poles, v, r[i].sigma, r[i].e_sigma, r[i].f_hz, r[i].e_f, 1e-9, 60, &inv);
    double hopf = NAN, sl = NAN, wl = NAN;
    if (st == HM_OK) hm_mode_model_hopf(m, inv.conicity, &hopf, NULL, NULL);
    printf("  %u pair(s) %.2f 1/s at %.2f Hz, %.0f km/h: status %d, conicity %.4f, chi2 %.3g, Hopf %.2f km/h\n",
           r[i].poles, r[i].sigma, r[i].f_hz, v, (int)st, st == HM_OK ? inv.conicity : NAN, inv.chi2, hopf);
    HM_CHECK(st == HM_OK, "a stable conicity explains the reading");
    if (st != HM_OK) continue;
    HM_CHECK(hopf > v, "the conicity found leaves the model stable at the window's speed (Hopf speed above it)");
    HM_CHECK(hm_mode_model_least_damped(m, inv.conicity, v, &sl, &wl) == HM_OK && sl < 0.0, "its roots decay");
  }
  hm_mode_model_destroy(m);
  hm_modal_destroy(modal);
}

/* Near the Hopf speed the reading's decay rate runs into 0 within a few thousandths of conicity and changes sign
 * beyond (the stability edge): round trips 1-10 km/h below the Hopf speed (hm_mode_model_hopf, eigenvalue bisection)
 * must come back to the conicity read, on the stable side (a Gauss-Newton step had alternated across the edge, or
 * halved itself 40 times and crossed anyway: HM_ENOCONV for these five, 2026-12-05). A reading that only the edge
 * explains ends there, the Hopf speed at the window's speed; a hair more conicity is unstable (the bisection's own
 * verdict). Within 1-3 km/h of it the reading hardly changes up to the edge: back to within 3e-3. The errors as the
 * review drove them: hypot(0.15, 0.05 |sigma| + 0.1) 1/s, hypot(0.08, 0.01 f) Hz. */
static void readings_near_the_stability_edge(void) {
  static const struct {
    double yaw_damper_n_s_m, lambda, below_kmh;
    unsigned poles;
  } c[] = {{0.4e6, 0.3, 1.0, 1}, {0.4e6, 0.1358, 3.0, 1}, {0.4e6, 0.16, 3.0, 1}, {3e6, 0.1358, 10.0, 2},
           {3e6, 0.3, 1.0, 2}};
  hm_monitor_config cfg;
  hm_monitor_config_default(&cfg);
  hm_modal modal = NULL;
  HM_CHECK(hm_modal_create(&cfg.modal, 500.0, &modal, NULL, 0) == HM_OK, "the monitor's filters at 500 Hz");
  for (size_t i = 0; i < sizeof c / sizeof c[0] + 1; ++i) {
    const int edge = i == sizeof c / sizeof c[0]; /* last: the default bogie read only at its edge */
    hm_car p;
    hm_car_default(&p);
    if (!edge) p.bogie.yaw_damper_damping_n_s_m = c[i].yaw_damper_n_s_m;
    hm_mode_model m = NULL;
    HM_CHECK(hm_mode_model_create(HM_MODEL_BOGIE, &p, &m) == HM_OK && m, "model");
    if (!m) continue;
    HM_CHECK(hm_mode_model_set_band(m, cfg.modal.band_low_hz, cfg.modal.band_high_hz) == HM_OK &&
                 hm_mode_model_set_sensor(m, "axlebox") == HM_OK, "sensor");
    hm_mode_model_set_reading_gain(m, hm_modal_filter_power_gain, modal);
    double hopf = NAN, v = 300.0, s = -1.5, f = 14.0, back = NAN, beyond = NAN;
    unsigned poles = 2;
    if (!edge) {
      HM_CHECK(hm_mode_model_hopf(m, c[i].lambda, &hopf, NULL, NULL) == HM_OK, "Hopf speed");
      v = hopf - c[i].below_kmh;
      poles = c[i].poles;
      HM_CHECK(hm_mode_model_reading(m, c[i].lambda, v, poles, &s, &f) == HM_OK && s <= 0.0, "a decaying reading");
      s = fmin(s, -1e-6); /* a pole on the axis reads 0 (the fit's bound): a measured mode decays */
    }
    const double es = hypot(0.15, 0.05 * fabs(s) + 0.1), ef = hypot(0.08, 0.01 * f);
    hm_conicity_inversion inv;
    memset(&inv, 0, sizeof inv);
    const hm_status st = hm_mode_model_invert_reading(m, poles, v, s, es, f, ef, 1e-9, 60, &inv);
    if (st == HM_OK) hm_mode_model_hopf(m, inv.conicity, &back, NULL, NULL);
    if (st == HM_OK && edge) hm_mode_model_hopf(m, inv.conicity * (1.0 + 1e-5), &beyond, NULL, NULL);
    printf("  yaw damper %.1e N s/m, %u pair(s) %.3f 1/s at %.3f Hz, %.2f km/h: status %d, conicity %.5f (read at "
           "%.4f), chi2 %.3g, Hopf %.2f km/h\n",
           p.bogie.yaw_damper_damping_n_s_m, poles, s, f, v, (int)st, inv.conicity, edge ? NAN : c[i].lambda,
           inv.chi2, back);
    HM_CHECK(st == HM_OK, "inverted");
    HM_CHECK(back >= v - 1e-3, /* the edge's bisection (1e-9 in conicity) and the Hopf speed's (1e-6 km/h) */
             "on the stable side: the Hopf speed at the conicity found at or above the window's speed");
    if (!edge) {
      HM_CHECK(fabs(inv.conicity - c[i].lambda) < 3e-3 && inv.chi2 < 1.0, "back to the conicity read");
    } else {
      HM_CHECK(inv.chi2 <= 9.0 && back - v < 0.1 && beyond < v, "at the edge: 1e-5 more conicity is unstable there");
    }
    hm_mode_model_destroy(m);
  }
  hm_modal_destroy(modal);
}

/* A model of kind with the default car's parameters, its yaw dampers' damping [N s/m] (<= 0: the default), read at
 * a sensor as the monitor reads it (its filters `modal`) over lo_hz..hi_hz (<= 0: the monitor's band); NULL on failure. */
static hm_mode_model reading_model(hm_model_kind kind, double damper_n_s_m, const char *where, double lo_hz,
                                   double hi_hz, const hm_monitor_config *cfg, hm_modal modal) {
  hm_car p;
  hm_car_default(&p);
  if (damper_n_s_m > 0.0) p.bogie.yaw_damper_damping_n_s_m = damper_n_s_m;
  hm_mode_model m = NULL;
  HM_CHECK(hm_mode_model_create(kind, &p, &m) == HM_OK && m, "model");
  if (!m) return NULL;
  const double lo = lo_hz > 0.0 ? lo_hz : cfg->modal.band_low_hz, hi = hi_hz > 0.0 ? hi_hz : cfg->modal.band_high_hz;
  HM_CHECK(hm_mode_model_set_band(m, lo, hi) == HM_OK && hm_mode_model_set_sensor(m, where) == HM_OK, "sensor");
  hm_mode_model_set_reading_gain(m, hm_modal_filter_power_gain, modal);
  return m;
}

/* A measured reading off the model's frequency near the stability edge (a strong-damper bogie's two-pair window on
 * its axle box at 512 km/h, evaluate_vehicle's strong_axlebox_4: -0.73 +- 0.22 1/s at 13.876 Hz where the model's mode
 * runs at 14.02 Hz). The scanned start 0.143 lies where the model's reading sits at 0 (its root narrower than the
 * leakage), with no slope: the search had ended at the edge (0.1433, chi2 11.7) and the monitor raised a model
 * mismatch. The reference is a second method: the misfit on a grid of stable conicities (step 5e-4, stability from
 * hm_mode_model_hopf); the inversion must reach the grid's minimum within a step. */
static void readings_off_the_model_frequency(void) {
  static const struct {
    double v_kmh, sigma, e_sigma, f, e_f;
  } c[] = {{512.0, -0.73, 0.22, 13.876, 0.16}, {512.0, -0.40, 0.20, 13.85, 0.16}, {500.0, -1.0, 0.2, 13.8, 0.16}};
  hm_monitor_config cfg;
  hm_monitor_config_default(&cfg);
  hm_modal modal = NULL;
  HM_CHECK(hm_modal_create(&cfg.modal, 500.0, &modal, NULL, 0) == HM_OK, "the monitor's filters at 500 Hz");
  hm_mode_model m = reading_model(HM_MODEL_BOGIE, 3e6, "axlebox", 0.0, 0.0, &cfg, modal);
  for (size_t i = 0; m && i < sizeof c / sizeof c[0]; ++i) {
    double grid_l = NAN, grid_chi2 = INFINITY;
    for (double l = 0.12; l <= 0.15; l += 5e-4) {
      double hopf = NAN, s = NAN, f = NAN;
      if (hm_mode_model_hopf(m, l, &hopf, NULL, NULL) != HM_OK || hopf < c[i].v_kmh) continue;
      if (hm_mode_model_reading(m, l, c[i].v_kmh, 2, &s, &f) != HM_OK) continue;
      const double chi2 = pow((s - c[i].sigma) / c[i].e_sigma, 2) + pow((f - c[i].f) / c[i].e_f, 2);
      if (chi2 < grid_chi2) grid_chi2 = chi2, grid_l = l;
    }
    hm_conicity_inversion inv;
    memset(&inv, 0, sizeof inv);
    const hm_status st =
        hm_mode_model_invert_reading(m, 2, c[i].v_kmh, c[i].sigma, c[i].e_sigma, c[i].f, c[i].e_f, 1e-9, 60, &inv);
    printf("  %.3f 1/s at %.3f Hz, %.0f km/h: status %d, conicity %.5f chi2 %.3g; grid %.4f chi2 %.3g\n", c[i].sigma,
           c[i].f, c[i].v_kmh, (int)st, inv.conicity, inv.chi2, grid_l, grid_chi2);
    HM_CHECK(st == HM_OK && isfinite(grid_l), "inverted, and the grid has stable conicities");
    HM_CHECK(fabs(inv.conicity - grid_l) <= 5e-4 && inv.chi2 <= grid_chi2 + 0.05,
             "at the grid's minimum: not stuck at the edge");
  }
  hm_mode_model_destroy(m);
  hm_modal_destroy(modal);
}

/* Windows measured on the default bogie's axle box (evaluate_vehicle's default_axlebox_5: `hunting simulate` of
 * config/bogie_default.yaml at conicity 0.15, 410.1 km/h, 100 km/h below its Hopf speed; two pole pairs, the mode at
 * 14.2 Hz beside a broader one at 16.5), each with margin.c's errors (its standard errors with the model's 5% + 1 / T of
 * the decay rate and 1% of the frequency). The reference is the simulation's conicity: each window's interval (2
 * standard errors) must hold it. The model's two-pair reading had been chosen nearest the measured mode among the
 * fits of two splits of its peak: it jumped from one decomposition to the other with the conicity, and at 0.1875-0.19
 * one sat on the measured mode, an island of 0.003 whose slope gave 0.1953 +- 0.0073 (the monitor's estimate then
 * showed a Hopf speed 70 km/h low and a WARN 80 km/h below the truth). */
static void measured_windows_of_the_bogie(void) {
  static const struct {
    double sigma, sigma_se, f, f_se;
  } c[] = {{-3.49, 0.94, 14.175, 0.097}, {-3.64, 0.91, 14.249, 0.093}, {-3.84, 0.88, 14.274, 0.091}};
  const double v_kmh = 410.1, truth = 0.15, window_s = 40.0;
  hm_monitor_config cfg;
  hm_monitor_config_default(&cfg);
  hm_modal modal = NULL;
  HM_CHECK(hm_modal_create(&cfg.modal, 500.0, &modal, NULL, 0) == HM_OK, "the monitor's filters at 500 Hz");
  hm_mode_model m = reading_model(HM_MODEL_BOGIE, 0.0, "axlebox", 0.0, 0.0, &cfg, modal);
  for (size_t i = 0; m && i < sizeof c / sizeof c[0]; ++i) {
    const double e_sigma = hypot(c[i].sigma_se, 0.05 * fabs(c[i].sigma) + 1.0 / window_s);
    const double e_f = hypot(c[i].f_se, 0.01 * c[i].f);
    hm_conicity_inversion inv;
    memset(&inv, 0, sizeof inv);
    const hm_status st = hm_mode_model_invert_reading(m, 2, v_kmh, c[i].sigma, e_sigma, c[i].f, e_f, 1e-9, 60, &inv);
    printf("  %.2f 1/s at %.3f Hz: status %d, conicity %.4f +- %.4f, chi2 %.3g (simulated %.2f)\n", c[i].sigma, c[i].f,
           (int)st, inv.conicity, inv.conicity_se, inv.chi2, truth);
    HM_CHECK(st == HM_OK && fabs(inv.conicity - truth) <= 2.0 * inv.conicity_se, "the interval holds the simulation's");
  }
  hm_mode_model_destroy(m);
  hm_modal_destroy(modal);
}

/* The car's own readings invert back (the forward reading, hm_mode_model_reading, is the reference): the misfit of a
 * reading is rough in the conicity, and Gauss-Newton from the best scanned conicity had ended in a local minimum
 * (a review's round trips of 2026-12-06: chi2 23.2 at 0.3274, 13.3 at 0.1734, 4.45 at 0.2019); the pass is retried
 * from the refined start where the misfit exceeds HM_MODE_MODEL_RETRY_CHI2. */
static void own_readings_of_the_car_invert_back(void) {
  static const struct {
    const char *where;
    double lo_hz, hi_hz, damper_n_s_m;
    unsigned poles;
    double lambda, v_kmh, e_sigma, e_f;
  } c[] = {{"axlebox", 0.0, 0.0, 3e6, 1, 0.285564, 291.4976, 0.2390, 0.1163},
           {"frame", 5.0, 13.0, 0.4e6, 2, 0.153006, 361.2865, 0.3573, 0.1099},
           {"frame", 5.0, 13.0, 1e6, 2, 0.218597, 305.4306, 0.22, 0.16}};
  hm_monitor_config cfg;
  hm_monitor_config_default(&cfg);
  hm_modal modal = NULL;
  HM_CHECK(hm_modal_create(&cfg.modal, 500.0, &modal, NULL, 0) == HM_OK, "the monitor's filters at 500 Hz");
  for (size_t i = 0; i < sizeof c / sizeof c[0]; ++i) {
    hm_mode_model m = reading_model(HM_MODEL_CAR, c[i].damper_n_s_m, c[i].where, c[i].lo_hz, c[i].hi_hz, &cfg, modal);
    if (!m) continue;
    double s = NAN, f = NAN;
    HM_CHECK(hm_mode_model_reading(m, c[i].lambda, c[i].v_kmh, c[i].poles, &s, &f) == HM_OK && s < 0.0, "a reading");
    hm_conicity_inversion inv;
    memset(&inv, 0, sizeof inv);
    const hm_status st =
        hm_mode_model_invert_reading(m, c[i].poles, c[i].v_kmh, s, c[i].e_sigma, f, c[i].e_f, 1e-9, 60, &inv);
    printf("  car %s, %u pair(s), %.1f km/h, conicity %.6f: reads %.4f 1/s at %.4f Hz; status %d, conicity %.6f, "
           "chi2 %.3g\n", c[i].where, c[i].poles, c[i].v_kmh, c[i].lambda, s, f, (int)st, inv.conicity, inv.chi2);
    HM_CHECK(st == HM_OK && fabs(inv.conicity - c[i].lambda) < 1e-3 && inv.chi2 < 1e-3, "back to the conicity read");
    hm_mode_model_destroy(m);
  }
  hm_modal_destroy(modal);
}

/* The damped steps (a step to where the misfit grows is halved from the point before, warm from that point's fits):
 * a halved trial warm-started from the rejected point's fits had followed another peak, and the search ended on the
 * scanned start (the car, 0.3: 0.2991 with its Gauss-Newton step 0.03 away) or walked below the model's conicities
 * (a reading at 1e-300 Hz: 2.2e-5). Round trips 20 km/h below the Hopf speed (hm_mode_model_hopf), the review's cases
 * of 2026-12-05: the car's back to the conicity read; the frame's at 1078 km/h (its two-pair reading jumps from peak to
 * peak with the conicity, 0.05 an isolated match at the band's edge, and 0.0105 is read within chi2 0.8 too) and the
 * 1e-300 Hz reading never outside [HM_MODE_MODEL_LAMBDA_MIN, HM_MODE_MODEL_LAMBDA_MAX]. */
static void damped_steps_come_back(void) {
  static const struct {
    hm_model_kind kind;
    const char *where;
    double lo, hi, lambda;
    int must_invert;
  } c[] = {{HM_MODEL_CAR, "axlebox", 0.0, 0.0, 0.3, 1}, {HM_MODEL_BOGIE, "frame", 5.0, 13.0, 0.05, 0}};
  hm_monitor_config cfg;
  hm_monitor_config_default(&cfg);
  hm_modal modal = NULL;
  HM_CHECK(hm_modal_create(&cfg.modal, 500.0, &modal, NULL, 0) == HM_OK, "the monitor's filters at 500 Hz");
  for (size_t i = 0; i < sizeof c / sizeof c[0]; ++i) {
    hm_mode_model m = reading_model(c[i].kind, 0.6e6, c[i].where, c[i].lo, c[i].hi, &cfg, modal);
    if (!m) continue;
    double hopf = NAN, s = NAN, f = NAN;
    HM_CHECK(hm_mode_model_hopf(m, c[i].lambda, &hopf, NULL, NULL) == HM_OK, "Hopf speed");
    const double v = hopf - 20.0;
    HM_CHECK(hm_mode_model_reading(m, c[i].lambda, v, 2, &s, &f) == HM_OK && s < 0.0, "a decaying reading");
    hm_conicity_inversion inv;
    memset(&inv, 0, sizeof inv);
    const hm_status st =
        hm_mode_model_invert_reading(m, 2, v, s, hypot(0.15, 0.05 * fabs(s) + 0.1), f, hypot(0.08, 0.01 * f), 1e-9,
                                     60, &inv);
    printf("  %s %s at %.3f km/h, conicity %.4f: reads %.4f 1/s at %.4f Hz; status %d, conicity %.5f +- %.5f, "
           "chi2 %.3g\n", c[i].kind == HM_MODEL_CAR ? "car" : "bogie", c[i].where, v, c[i].lambda, s, f, (int)st,
           inv.conicity, inv.conicity_se, inv.chi2);
    if (c[i].must_invert) HM_CHECK(st == HM_OK, "inverted");
    /* the car's two-pair reading changes decomposition every 0.002-0.005 in the conicity (a sawtooth of misfits
     * 0-18 over 0.28-0.30): 0.3's own is an island of 0.001, and a minimum of chi2 0.83 lies at 0.310; either is an
     * answer, the search's start (0.2991) is not */
    if (c[i].must_invert)
      HM_CHECK(inv.chi2 < 1.0 && fabs(inv.conicity - c[i].lambda) < fmax(3e-3, 2.0 * inv.conicity_se),
               "back to the conicity read: explained, its interval holding it");
    HM_CHECK(st != HM_OK || (inv.conicity >= HM_MODE_MODEL_LAMBDA_MIN && inv.conicity <= HM_MODE_MODEL_LAMBDA_MAX),
             "within the model's conicities");
    hm_conicity_inversion bad;
    memset(&bad, 0x5a, sizeof bad);
    HM_CHECK(hm_mode_model_invert_reading(m, 2, v, s, 0.3, f, 0.1, INFINITY, 60, &bad) == HM_EDOMAIN &&
                 ((unsigned char *)&bad)[0] == 0x5a, "an infinite tolerance: refused, output untouched");
    const hm_status sf = hm_mode_model_invert_reading(m, 1, v, s, 0.3, 1e-300, 0.1, 1e-9, 60, &bad);
    HM_CHECK(sf != HM_OK || bad.conicity >= HM_MODE_MODEL_LAMBDA_MIN, "a reading at 1e-300 Hz: no conicity below 0.01");
    hm_mode_model_destroy(m);
  }
  hm_modal_destroy(modal);
}

/* hm_mode_model_displacement_per_accel: at the wheelset's axle box (the point is its own lateral velocity) the
 * closed form 1 / |lambda|^2 of its hunting root (inversion.h); at the default bogie's frame, 0.05 km/h below its
 * Hopf speed, the forced response's ratio at the root's frequency (the track driving the mode, whose 1 / sigma
 * resonance dwarfs the others there: a second method, hm_mode_model_sensor_spectrum and hm_mode_model_motion_rms's
 * transfer); a frequency 10% off the least-damped root's: no ratio (HM_ENOCRIT), the output untouched. */
static void displacement_per_accel(void) {
  hm_vehicle veh;
  hm_vehicle_default(&veh);
  hm_mode_model w = NULL, m = NULL;
  hm_bogie b;
  hm_bogie_default(&b);
  HM_CHECK(hm_mode_model_create_wheelset(&veh, &w) == HM_OK && hm_mode_model_create_bogie(&b, &m) == HM_OK, "create");
  if (!w || !m) return;
  hm_linear_coef coef;
  hm_linear_coef_from_vehicle(&veh, &coef);
  hm_sensor_point axle, frame;
  HM_CHECK(hm_mode_model_sensor(w, "axlebox", &axle) == HM_OK && hm_mode_model_sensor(m, "frame", &frame) == HM_OK,
           "sensors");
  double s = 0.0, om = 0.0, r = 0.0;
  HM_CHECK(hm_hunting_root(&coef, 430.0, 0.16, &s, &om) == HM_OK, "root");
  HM_CHECK(hm_mode_model_displacement_per_accel(w, 0.16, 430.0, &axle, om / (2.0 * HM_PI) * 1.02, &r) == HM_OK,
           "wheelset");
  HM_CHECK_REL(r, 1.0 / (s * s + om * om), 1e-9, "wheelset: 1 / |lambda|^2");
  double v = 0.0, f = 0.0;
  HM_CHECK(hm_mode_model_hopf(m, 0.1358, &v, &f, NULL) == HM_OK, "bogie Hopf");
  const double vb = v - 0.05;
  double sb = 0.0, omb = 0.0;
  HM_CHECK(hm_mode_model_least_damped(m, 0.1358, vb, &sb, &omb) == HM_OK && sb < 0.0 && sb > -0.05, "near Hopf");
  const double fb = omb / (2.0 * HM_PI);
  HM_CHECK(hm_mode_model_displacement_per_accel(m, 0.1358, vb, &frame, fb, &r) == HM_OK, "frame");
  /* the forced response at fb: |A|^2 S from the sensor's spectrum, |R_i|^2 S from the motion's integrand (one bin) */
  double acc2 = 0.0;
  HM_CHECK(hm_mode_model_sensor_spectrum(m, 0.1358, vb, &frame, &fb, 1, &acc2) == HM_OK, "frame spectrum");
  /* each axle box (bogie.h: the wheelsets' lateral velocities are states 1 and 5): its acceleration over (2 pi f)^2
   * is the wheelset's displacement */
  const hm_sensor_point wheel[2] = {{1, {1, 0, 0, 0}, {1.0, 0.0, 0.0, 0.0}}, {1, {5, 0, 0, 0}, {1.0, 0.0, 0.0, 0.0}}};
  double ax2[2] = {0.0, 0.0};
  for (int i = 0; i < 2; ++i)
    HM_CHECK(hm_mode_model_sensor_spectrum(m, 0.1358, vb, &wheel[i], &fb, 1, &ax2[i]) == HM_OK, "axle-box spectrum");
  const double forced = sqrt(fmax(ax2[0], ax2[1]) / acc2) / pow(2.0 * HM_PI * fb, 2.0);
  printf("  frame at %.2f km/h, %.3f Hz: %.4g m per m/s^2 from the mode shape, %.4g from the forced response\n", vb, fb,
         r, forced);
  HM_CHECK_REL(r, forced, 0.02, "frame: the mode shape against the forced response at resonance");
  HM_CHECK(r * pow(2.0 * HM_PI * fb, 2.0) > 2.0, "the frame moves less than half as much as the wheelsets in it");
  double untouched = -1.0;
  HM_CHECK(hm_mode_model_displacement_per_accel(m, 0.1358, vb, &frame, fb * 1.1, &untouched) == HM_ENOCRIT &&
               untouched == -1.0, "10%% off the root's frequency: none");
  HM_CHECK(hm_mode_model_displacement_per_accel(m, 0.1358, -1.0, &frame, fb, &untouched) == HM_EDOMAIN &&
               hm_mode_model_displacement_per_accel(m, 0.1358, vb, &frame, NAN, &untouched) == HM_EDOMAIN &&
               untouched == -1.0, "bad speed or frequency");
  hm_mode_model_destroy(w);
  hm_mode_model_destroy(m);
}

int main(void) {
  HM_RUN(wheelset_as_inversion_h);
  HM_RUN(bogie_and_car_find_their_own_conicity);
  HM_RUN(hopf_curve);
  HM_RUN(displacement_per_accel);
  HM_RUN(band_kink_and_low_speeds);
  HM_RUN(reading_of_the_wheelset_is_its_root);
  HM_RUN(reading_inverts_back);
  HM_RUN(unstable_conicities_explain_no_reading);
  HM_RUN(readings_near_the_stability_edge);
  HM_RUN(readings_off_the_model_frequency);
  HM_RUN(own_readings_of_the_car_invert_back);
  HM_RUN(measured_windows_of_the_bogie);
  HM_RUN(damped_steps_come_back);
  HM_RUN(monitor_reads_a_bogie);
  HM_RUN(bad_input);
  HM_TEST_EXIT();
}
