/* The sensor simulation (sensor_sim.h): sample times and counts, the speed profile's closed form, the noise's
 * statistics against its setting, the acceleration against the derivative of the sampled velocity, reproducibility,
 * disturbances, stopping, and refused settings. */
#include <stdlib.h>
#include <string.h>

#include "hm_test.h"
#include "hunting_monitor/bogie.h"
#include "hunting_monitor/linear.h"
#include "hunting_monitor/sensor_sim.h"

typedef struct {
  size_t n_accel, n_speed, cap;
  double *t, *meas, *truth, *dy, *y;
  double last_speed_t;
  int order_ok;             /* every speed sample arrived before the acceleration sample of the same time */
  double last_accel_t;
  size_t stop_after;        /* stop once this many acceleration samples arrived (0: never) */
  double v_err;             /* largest |speed - closed form| */
  double v0, v1, ramp;
} rec;

static int on_accel(void *ctx, double t, double measured, double true_accel, const double *x) {
  rec *r = (rec *)ctx;
  if (r->n_accel < r->cap) {
    r->t[r->n_accel] = t;
    r->meas[r->n_accel] = measured;
    r->truth[r->n_accel] = true_accel;
    r->dy[r->n_accel] = x[1];
    r->y[r->n_accel] = x[0];
  }
  r->last_accel_t = t;
  ++r->n_accel;
  return r->stop_after && r->n_accel >= r->stop_after;
}

static int on_speed(void *ctx, double t, double v) {
  rec *r = (rec *)ctx;
  if (r->n_accel > 0 && t <= r->last_accel_t) r->order_ok = 0;
  const double ref = t >= r->ramp ? r->v1 : r->v0 + (r->v1 - r->v0) * t / r->ramp;
  r->v_err = fmax(r->v_err, fabs(v - ref));
  ++r->n_speed;
  return 0;
}

static void rec_init(rec *r, size_t cap, const hm_sensor_sim_config *c) {
  memset(r, 0, sizeof *r);
  r->cap = cap;
  r->t = malloc(cap * sizeof(double));
  r->meas = malloc(cap * sizeof(double));
  r->truth = malloc(cap * sizeof(double));
  r->dy = malloc(cap * sizeof(double));
  r->y = malloc(cap * sizeof(double));
  r->order_ok = 1;
  r->last_accel_t = -1.0;
  r->v0 = c->v_start_kmh;
  r->v1 = c->v_end_kmh;
  r->ramp = c->ramp_s;
}

static void rec_free(rec *r) {
  free(r->t);
  free(r->meas);
  free(r->truth);
  free(r->dy);
  free(r->y);
}

/* 3 s at 2 kHz in two runs (0..1.3, 1.3..3): samples at k / 2000, 6001 of them (both ends), none twice; speed at
 * 10 Hz, 31 samples, before the acceleration sample of the same time, on the linear ramp 400 -> 460 km/h over 2 s. */
static void sample_times_and_speed_profile(void) {
  hm_vehicle veh;
  hm_vehicle_default(&veh);
  hm_sensor_sim_config c;
  hm_sensor_sim_config_default(&c);
  c.v_start_kmh = 400.0;
  c.v_end_kmh = 460.0;
  c.ramp_s = 2.0;
  rec r;
  rec_init(&r, 7000, &c);
  const double x0[4] = {1e-3, 0.0, 0.0, 0.0};
  hm_sensor_sim s = NULL;
  HM_CHECK(hm_sensor_sim_create(&veh, &c, x0, &s, NULL, 0) == HM_OK, "create");
  const hm_sensor_sink sink = {on_accel, on_speed, &r};
  HM_CHECK(hm_sensor_sim_run(s, 1.3, &sink) == HM_OK && hm_sensor_sim_run(s, 3.0, &sink) == HM_OK, "run");
  HM_CHECK(r.n_accel == 6001 && r.n_speed == 31, "%zu acceleration and %zu speed samples", r.n_accel, r.n_speed);
  double worst = 0.0;
  for (size_t k = 0; k < r.n_accel && k < r.cap; ++k) worst = fmax(worst, fabs(r.t[k] - (double)k / 2000.0));
  HM_CHECK(worst < 1e-12, "sample time off k / rate by %g s", worst);
  HM_CHECK(r.order_ok, "a speed sample came after the acceleration sample of its time");
  HM_CHECK(r.v_err < 1e-9, "speed off the ramp by %g km/h", r.v_err);
  HM_CHECK_DELTA(hm_sensor_sim_time(s), 3.0, 0.0, "time");
  hm_sensor_sim_destroy(s);
  rec_free(&r);
}

/* On a perfect track the true acceleration is the derivative of the sampled lateral velocity: a central difference
 * over 1/2000 s agrees to its O(h^2) truncation (the hunting mode at ~14 Hz: relative error (w h)^2 / 6 = 3e-4). The
 * noise (sigma 0.05 m/s^2) has mean 0 within 4 sigma / sqrt(N) and its standard deviation within 3%. */
static void acceleration_and_noise(void) {
  hm_vehicle veh;
  hm_vehicle_default(&veh);
  hm_sensor_sim_config c;
  hm_sensor_sim_config_default(&c);
  c.v_start_kmh = c.v_end_kmh = 450.0;
  c.rtol = 1e-11;
  c.atol = 1e-14;
  rec r;
  rec_init(&r, 8001, &c);
  const double x0[4] = {2e-3, 0.0, 0.0, 0.0};
  hm_sensor_sim s = NULL;
  HM_CHECK(hm_sensor_sim_create(&veh, &c, x0, &s, NULL, 0) == HM_OK, "create");
  const hm_sensor_sink sink = {on_accel, on_speed, &r};
  HM_CHECK(hm_sensor_sim_run(s, 4.0, &sink) == HM_OK && r.n_accel == 8001, "run");
  double worst = 0.0, peak = 0.0, sum = 0.0, sum2 = 0.0;
  const double h = 1.0 / 2000.0;
  for (size_t k = 1; k + 1 < r.n_accel; ++k) {
    const double fd = (r.dy[k + 1] - r.dy[k - 1]) / (2.0 * h);
    worst = fmax(worst, fabs(fd - r.truth[k]));
    peak = fmax(peak, fabs(r.truth[k]));
  }
  for (size_t k = 0; k < r.n_accel; ++k) {
    const double e = r.meas[k] - r.truth[k];
    sum += e;
    sum2 += e * e;
  }
  const double n = (double)r.n_accel, mean = sum / n, sd = sqrt(sum2 / n - mean * mean);
  printf("  peak acceleration %.3f m/s^2, derivative check %.2e, noise mean %.2e sd %.5f\n", peak, worst, mean, sd);
  HM_CHECK(peak > 1.0 && worst < 5e-4 * peak, "acceleration off the velocity's derivative by %g", worst);
  HM_CHECK(fabs(mean) < 4.0 * 0.05 / sqrt(n), "noise mean %g", mean);
  HM_CHECK_REL(sd, 0.05, 0.03, "noise sd");
  hm_sensor_sim_destroy(s);
  rec_free(&r);
}

/* The same seeds give the same stream bit for bit; another noise seed changes the noise but not the truth; a state
 * set between runs is where the next run starts; a callback's nonzero return stops the run. */
static void reproducible_disturbed_and_stoppable(void) {
  hm_vehicle veh;
  hm_vehicle_default(&veh);
  hm_sensor_sim_config c;
  hm_sensor_sim_config_default(&c);
  c.irregularity_scale = 0.1;
  rec a, b, d;
  rec_init(&a, 2001, &c);
  rec_init(&b, 2001, &c);
  rec_init(&d, 2001, &c);
  hm_sensor_sim sa = NULL, sb = NULL, sd = NULL;
  HM_CHECK(hm_sensor_sim_create(&veh, &c, NULL, &sa, NULL, 0) == HM_OK, "a");
  HM_CHECK(hm_sensor_sim_create(&veh, &c, NULL, &sb, NULL, 0) == HM_OK, "b");
  c.noise_seed = 2;
  HM_CHECK(hm_sensor_sim_create(&veh, &c, NULL, &sd, NULL, 0) == HM_OK, "d");
  HM_CHECK(hm_sensor_sim_track_rms_m(sa) > 0.0, "a track");
  const hm_sensor_sink ka = {on_accel, NULL, &a}, kb = {on_accel, NULL, &b}, kd = {on_accel, NULL, &d};
  HM_CHECK(hm_sensor_sim_run(sa, 1.0, &ka) == HM_OK && hm_sensor_sim_run(sb, 1.0, &kb) == HM_OK &&
               hm_sensor_sim_run(sd, 1.0, &kd) == HM_OK,
           "runs");
  HM_CHECK(memcmp(a.meas, b.meas, a.n_accel * sizeof(double)) == 0 && a.n_accel == b.n_accel, "not reproducible");
  size_t same_noise = 0;
  double truth_diff = 0.0;
  for (size_t k = 0; k < a.n_accel; ++k) {
    same_noise += a.meas[k] == d.meas[k];
    truth_diff = fmax(truth_diff, fabs(a.truth[k] - d.truth[k]));
  }
  HM_CHECK(same_noise == 0 && truth_diff == 0.0, "%zu equal noisy samples, truth differs by %g", same_noise,
           truth_diff);
  /* a kick: the state set at t = 1 s is the next sample's (the sample at t = 1 s came before it) */
  const double kick[4] = {5e-3, 0.01, -1e-3, 0.02};
  HM_CHECK(hm_sensor_sim_set_state(sa, kick) == HM_OK, "set state");
  rec k;
  rec_init(&k, 10, &c);
  k.stop_after = 3;
  const hm_sensor_sink kk = {on_accel, NULL, &k};
  HM_CHECK(hm_sensor_sim_run(sa, 2.0, &kk) == HM_OK, "run after the kick");
  HM_CHECK(k.n_accel == 3, "stopped after %zu samples", k.n_accel);
  /* one sample period h later, by the trapezoidal rule: y = y0 + h (dy0 + dy) / 2 + O(h^3 jerk) */
  const double y_trap = kick[0] + 0.0005 * (kick[1] + k.dy[0]) / 2.0;
  HM_CHECK(fabs(k.t[0] - 1.0005) < 1e-12 && fabs(k.y[0] - y_trap) < 1e-7,
           "first sample after the kick at %g s: y %.9g, trapezoidal rule from the kick %.9g", k.t[0], k.y[0], y_trap);
  const double nan4[4] = {NAN, 0, 0, 0};
  HM_CHECK(hm_sensor_sim_set_state(sa, nan4) == HM_EINVAL, "NaN state refused");
  hm_sensor_sim_destroy(sa);
  hm_sensor_sim_destroy(sb);
  hm_sensor_sim_destroy(sd);
  rec_free(&a);
  rec_free(&b);
  rec_free(&d);
  rec_free(&k);
}

static void refused_settings(void) {
  hm_vehicle veh;
  hm_vehicle_default(&veh);
  hm_sensor_sim_config good, c;
  hm_sensor_sim_config_default(&good);
  hm_sensor_sim s = NULL;
  char why[160];
  c = good;
  c.v_start_kmh = NAN;
  HM_CHECK(hm_sensor_sim_create(&veh, &c, NULL, &s, why, sizeof why) == HM_EDOMAIN && strstr(why, "v_start_kmh"), "NaN");
  c = good;
  c.accel_noise_mps2 = -0.1;
  HM_CHECK(hm_sensor_sim_create(&veh, &c, NULL, &s, why, sizeof why) == HM_EDOMAIN && strstr(why, "noise"), "noise");
  c = good;
  c.speed_rate_hz = 0.0;
  HM_CHECK(hm_sensor_sim_create(&veh, &c, NULL, &s, why, sizeof why) == HM_EDOMAIN && strstr(why, "rate"), "rate");
  c = good;
  c.wavelength_min_m = 200.0;
  HM_CHECK(hm_sensor_sim_create(&veh, &c, NULL, &s, why, sizeof why) == HM_EDOMAIN && strstr(why, "wavelength"),
           "band");
  c = good;
  c.rtol = 0.0;
  HM_CHECK(hm_sensor_sim_create(&veh, &c, NULL, &s, why, sizeof why) == HM_EDOMAIN && strstr(why, "rtol"), "rtol");
  hm_vehicle bad = veh;
  bad.mass_kg = -1.0;
  HM_CHECK(hm_sensor_sim_create(&bad, &good, NULL, &s, why, sizeof why) == HM_EDOMAIN && strstr(why, "mass_kg"),
           "negative mass: %s", why);
  const double inf4[4] = {INFINITY, 0, 0, 0};
  HM_CHECK(hm_sensor_sim_create(&veh, &good, inf4, &s, why, sizeof why) == HM_EDOMAIN, "infinite x0");
  HM_CHECK(s == NULL, "output written on failure");
}

/* A model's run (hm_sensor_sim_create_system). The wheelset as a system gives the wheelset's run bit for bit; a bogie
 * with its frame held (two independent wheelsets) shows the track under the trailing wheelset 2b / v after the
 * leading one: once the start has died away, y2(t) = y1(t - 2b / v); a frame accelerometer reads yf'' + b psif'' of
 * the bogie's own equations. */
typedef struct {
  size_t n, cap, dim;
  double *x;     /* n x dim states */
  double *accel; /* the true acceleration */
} state_rec;

static int on_state(void *ctx, double t, double measured, double true_accel, const double *x) {
  (void)t, (void)measured;
  state_rec *r = (state_rec *)ctx;
  if (r->n < r->cap) {
    memcpy(r->x + r->dim * r->n, x, r->dim * sizeof(double));
    r->accel[r->n] = true_accel;
  }
  ++r->n;
  return 0;
}

static void run_states(hm_sensor_sim sim, double t_end, state_rec *r) {
  const hm_sensor_sink sink = {on_state, NULL, r};
  HM_CHECK(hm_sensor_sim_run(sim, t_end, &sink) == HM_OK, "run");
}

static void models_on_a_track(void) {
  hm_sensor_sim_config c;
  hm_sensor_sim_config_default(&c);
  c.v_start_kmh = c.v_end_kmh = 300.0;
  c.irregularity_scale = 1.0;
  c.accel_rate_hz = 1000.0;
  c.accel_noise_mps2 = 0.0;
  enum { N = 20001 };
  /* the wheelset both ways */
  hm_vehicle veh;
  hm_vehicle_default(&veh);
  hm_wheelset_system ws;
  hm_system sys;
  HM_CHECK(hm_wheelset_system_init(&ws, &veh, &sys) == HM_OK, "wheelset system");
  const hm_sensor_point axle = {1, {1, 0, 0, 0}, {1.0, 0.0, 0.0, 0.0}};
  state_rec a = {0, N, 4, calloc(N * 4, sizeof(double)), calloc(N, sizeof(double))};
  state_rec b = {0, N, 4, calloc(N * 4, sizeof(double)), calloc(N, sizeof(double))};
  hm_sensor_sim sa = NULL, sb = NULL;
  HM_CHECK(hm_sensor_sim_create(&veh, &c, NULL, &sa, NULL, 0) == HM_OK, "wheelset run");
  HM_CHECK(hm_sensor_sim_create_system(&sys, &axle, &c, NULL, &sb, NULL, 0) == HM_OK, "system run");
  if (sa && sb) {
    run_states(sa, 5.0, &a);
    run_states(sb, 5.0, &b);
    HM_CHECK(a.n == b.n && a.n == 5001, "samples %zu, %zu", a.n, b.n);
    HM_CHECK(memcmp(a.x, b.x, 4 * a.n * sizeof(double)) == 0 && memcmp(a.accel, b.accel, a.n * sizeof(double)) == 0,
             "the wheelset as a system is the wheelset, bit for bit");
  }
  hm_sensor_sim_destroy(sa);
  hm_sensor_sim_destroy(sb);
  /* the held bogie: the trailing wheelset repeats the leading one 2b / v later */
  hm_bogie bogie;
  hm_bogie_default(&bogie);
  hm_bogie_model held;
  HM_CHECK(hm_bogie_model_init(&held, &bogie, 1, &sys) == HM_OK, "held bogie");
  state_rec h = {0, N, HM_BOGIE_HELD_DIM, calloc(N * HM_BOGIE_HELD_DIM, sizeof(double)), calloc(N, sizeof(double))};
  hm_sensor_sim sh = NULL;
  HM_CHECK(hm_sensor_sim_create_system(&sys, &axle, &c, NULL, &sh, NULL, 0) == HM_OK && sh, "held run");
  if (sh) {
    run_states(sh, 20.0, &h);
    const double delay_s = 2.0 * bogie.half_wheelbase_m / hm_mps_from_kmh(300.0); /* 0.03 s: 30 samples */
    const size_t lag = (size_t)lround(delay_s * c.accel_rate_hz);
    double worst = 0.0, size = 0.0;
    for (size_t k = 10000; k < h.n && k < N; ++k) {
      const double y1 = h.x[HM_BOGIE_HELD_DIM * (k - lag)], y2 = h.x[HM_BOGIE_HELD_DIM * k + 4];
      worst = fmax(worst, fabs(y2 - y1));
      size = fmax(size, fabs(y1));
    }
    printf("  held bogie: |y2(t) - y1(t - %.3f s)| <= %.3g m over 10-20 s, |y1| up to %.3g m\n", delay_s, worst, size);
    HM_CHECK(size > 1e-4 && worst < 1e-6 * size, "the trailing wheelset meets the track 2b / v later");
  }
  hm_sensor_sim_destroy(sh);
  /* a frame accelerometer: yf'' + b psif'' of the bogie's right-hand side at the sampled state */
  hm_bogie_model free_frame;
  HM_CHECK(hm_bogie_model_init(&free_frame, &bogie, 0, &sys) == HM_OK, "bogie");
  hm_sensor_point frame;
  HM_CHECK(hm_bogie_sensor(&free_frame, "frame", &frame) == HM_OK, "frame point");
  HM_CHECK(hm_bogie_sensor(&held, "frame", &frame) == HM_EINVAL, "no frame point on a held frame");
  HM_CHECK(hm_bogie_sensor(&free_frame, "frame", &frame) == HM_OK, "frame point");
  c.irregularity_scale = 0.0; /* on a perfect track the right-hand side is the bogie's without track input */
  const double x0[HM_BOGIE_DIM] = {0.003, 0.0, 0.0005, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  state_rec f = {0, N, HM_BOGIE_DIM, calloc(N * HM_BOGIE_DIM, sizeof(double)), calloc(N, sizeof(double))};
  hm_sensor_sim sf = NULL;
  HM_CHECK(hm_sensor_sim_create_system(&sys, &frame, &c, x0, &sf, NULL, 0) == HM_OK && sf, "frame run");
  if (sf) {
    run_states(sf, 2.0, &f);
    double worst = 0.0, size = 0.0;
    for (size_t k = 0; k < f.n && k < N; ++k) {
      double dx[HM_BOGIE_DIM];
      hm_bogie_rhs(&free_frame, hm_mps_from_kmh(300.0), f.x + HM_BOGIE_DIM * k, NULL, dx);
      const double ref = dx[9] + bogie.half_wheelbase_m * dx[11];
      worst = fmax(worst, fabs(f.accel[k] - ref));
      size = fmax(size, fabs(ref));
    }
    HM_CHECK(size > 0.01 && worst <= 1e-12 * size, "frame acceleration yf'' + b psif'' (off by %.3g of %.3g)", worst,
             size);
  }
  hm_sensor_sim_destroy(sf);
  const hm_sensor_point off = {1, {40, 0, 0, 0}, {1.0, 0.0, 0.0, 0.0}};
  hm_sensor_sim bad = NULL;
  char why[120] = "";
  HM_CHECK(hm_sensor_sim_create_system(&sys, &off, &c, NULL, &bad, why, sizeof why) == HM_EINVAL && !bad &&
               strstr(why, "not on the model"), "a sensor off the model: %s", why);
  free(a.x), free(a.accel), free(b.x), free(b.accel), free(h.x), free(h.accel), free(f.x), free(f.accel);
}

int main(void) {
  HM_RUN(sample_times_and_speed_profile);
  HM_RUN(acceleration_and_noise);
  HM_RUN(reproducible_disturbed_and_stoppable);
  HM_RUN(refused_settings);
  HM_RUN(models_on_a_track);
  HM_TEST_EXIT();
}
