/* spectrum_fit.h: a conicity from the whole spectrum a vehicle model predicts at its sensor. Against simulated
 * recordings of the same model (sensor_sim.h: the nonlinear model integrated over a random track of the assumed
 * spectrum): the conicity found again; the running's linearisation against a second recording on the same track
 * without the flange force (the effect it removes) and a closed form (without that force it changes nothing); the
 * wheelset's motion it implies against the simulated one. */
#include <math.h>
#include <string.h>

#include "hm_test.h"
#include "hunting_monitor/bogie.h"
#include "hunting_monitor/excitation.h"
#include "hunting_monitor/linear.h"
#include "hunting_monitor/mode_model.h"
#include "hunting_monitor/sensor_sim.h"
#include "hunting_monitor/spectrum_fit.h"

/* The spectrum the model predicts at a sensor, fitted to a simulated recording's (the core's sensor simulation of the
 * same model on a random track of the same spectrum): the conicity found again. A bogie's axle box at 440 km/h is
 * where the identification's pole pairs read -1.9..-3.0 1/s for the true -5.95 (docs/VEHICLES.md); the wheelset's at
 * 450 km/h. Welch's periodogram of 4096-sample Hann segments (not overlapping: 2 degrees of freedom each), a DFT at
 * each bin of 6-22 Hz. */
/* A recording's acceleration and its leading wheelset's displacement from the track (the sink's state less the track
 * under it: the same track made again from the simulation's seed, at the distance run; NULL: the displacement). */
typedef struct {
  double *a, *r;
  size_t n, cap;
  hm_track track;
  double v_mps;
} run_rec;

static int keep_run(void *ctx, double t, double measured, double true_accel, const double *x) {
  (void)true_accel;
  run_rec *r = (run_rec *)ctx;
  if (r->n < r->cap) r->a[r->n] = measured, r->r[r->n++] = x[0] - (r->track ? hm_track_at(r->track, r->v_mps * t) : 0.0);
  return 0;
}

static size_t welch_band(const double *a, size_t n, double fs, double f_lo, double f_hi, double *f, double *p,
                         double *dof) {
  enum { SEG = 4096 };
  const size_t segs = n / SEG;
  size_t nb = 0;
  double wsum = 0.0;
  for (size_t j = 0; j < SEG; ++j) {
    const double w = 0.5 - 0.5 * cos(2.0 * HM_PI * (double)j / SEG);
    wsum += w * w;
  }
  for (size_t k = (size_t)ceil(f_lo * SEG / fs); (double)k * fs / SEG <= f_hi; ++k) {
    double acc = 0.0;
    for (size_t sg = 0; sg < segs; ++sg) {
      const double *x = a + sg * SEG;
      double mean = 0.0, re = 0.0, im = 0.0;
      for (size_t j = 0; j < SEG; ++j) mean += x[j];
      mean /= SEG;
      for (size_t j = 0; j < SEG; ++j) {
        const double w = 0.5 - 0.5 * cos(2.0 * HM_PI * (double)j / SEG), ph = 2.0 * HM_PI * (double)(k * j % SEG) / SEG;
        re += w * (x[j] - mean) * cos(ph);
        im -= w * (x[j] - mean) * sin(ph);
      }
      acc += (re * re + im * im) / (fs * wsum);
    }
    f[nb] = (double)k * fs / SEG;
    p[nb++] = acc / (double)segs;
  }
  *dof = 2.0 * (double)segs;
  return nb;
}

static void finds_the_conicity(void) {
  for (int kind = 0; kind < 2; ++kind) {
    hm_sensor_sim_config c;
    hm_sensor_sim_config_default(&c);
    c.v_start_kmh = c.v_end_kmh = kind ? 440.0 : 450.0;
    c.irregularity_scale = 0.3;
    c.track_seed = c.noise_seed = 6;
    c.accel_rate_hz = 500.0;
    c.accel_noise_mps2 = 0.1;
    hm_bogie b;
    hm_bogie_default(&b);
    hm_bogie_model bm;
    hm_system sys;
    hm_mode_model m = NULL;
    hm_sensor_point point;
    hm_sensor_sim sim = NULL;
    HM_CHECK(kind ? hm_mode_model_create_bogie(&b, &m) == HM_OK : hm_mode_model_create_wheelset(&b.wheelset, &m) == HM_OK,
             "model");
    HM_CHECK(m && hm_mode_model_sensor(m, "axlebox", &point) == HM_OK, "sensor");
    if (kind) {
      HM_CHECK(hm_bogie_model_init(&bm, &b, 0, &sys) == HM_OK, "bogie");
      HM_CHECK(hm_sensor_sim_create_system(&sys, &point, &c, NULL, &sim, NULL, 0) == HM_OK, "bogie run");
    } else {
      HM_CHECK(hm_sensor_sim_create(&b.wheelset, &c, NULL, &sim, NULL, 0) == HM_OK, "wheelset run");
    }
    enum { N = 100000 };
    static double a[N + 1], y[N + 1], f[512], p[512];
    run_rec r = {a, y, 0, N + 1, NULL, 0.0};
    const hm_sensor_sink sink = {keep_run, NULL, &r};
    if (sim) HM_CHECK(hm_sensor_sim_run(sim, 200.0, &sink) == HM_OK, "run");
    hm_sensor_sim_destroy(sim);
    double dof = 0.0;
    const size_t nb = welch_band(a + 5000, r.n - 5000, 500.0, 6.0, 22.0, f, p, &dof);
    hm_spectrum_fit fit;
    hm_spectrum_fit_options o;
    hm_spectrum_fit_options_default(&o);
    /* (no leakage: Hann segments of 8 s, their kernel no Lorentzian of 2 / T) */
    HM_CHECK(m && hm_spectrum_fit_conicity(m, c.v_start_kmh, &point, f, p, nb, dof, &o, &fit) == HM_OK, "fit");
    printf("  %s's axle box at %.0f km/h: the spectrum's fit %.4f +- %.4f (truth 0.1358), %zu bins, %.0f dof\n",
           kind ? "bogie" : "wheelset", c.v_start_kmh, fit.conicity, fit.conicity_se, nb, dof);
    HM_CHECK(fabs(fit.conicity - 0.1358) <= fmax(3.0 * fit.conicity_se, 0.002) && fit.conicity_se < 0.01,
             "the conicity found again");
    /* the residual under a peak (hm_spectrum_fit_peak_z): at one bin k, (x_k - 1) / sqrt(2 / dof) with x_k that bin's
     * ratio to the fit (about N(0, 1)); a line the model does not produce, bin k 30 times higher, against the same
     * fit: exactly (30 x_k - 1) / sqrt(2 / dof), and over bins k-1..k+1 the mean's (x_{k-1} + 30 x_k + x_{k+1}) / 3
     * less 1 over sqrt(2 / (3 dof)); refitted with the line in it, still far beyond the margin's 5. Outside the bins,
     * or a range upside down: refused. */
    size_t k8 = 0;
    while (k8 + 1 < nb && f[k8] < 8.0) ++k8;
    double z_own = NAN, z_left = NAN, z_right = NAN, z_line = NAN, z_three = NAN, z_refit = NAN, z_out = -1.0;
    HM_CHECK(m && hm_spectrum_fit_peak_z(m, c.v_start_kmh, &point, &fit, f, p, nb, dof, f[k8], f[k8], &z_own) == HM_OK &&
                 hm_spectrum_fit_peak_z(m, c.v_start_kmh, &point, &fit, f, p, nb, dof, f[k8 - 1], f[k8 - 1], &z_left) ==
                     HM_OK &&
                 hm_spectrum_fit_peak_z(m, c.v_start_kmh, &point, &fit, f, p, nb, dof, f[k8 + 1], f[k8 + 1],
                                        &z_right) == HM_OK,
             "the residual at a bin");
    const double se1 = sqrt(2.0 / dof), x_k = 1.0 + z_own * se1;
    const double x_l = 1.0 + z_left * se1, x_r = 1.0 + z_right * se1;
    p[k8] *= 30.0;
    hm_spectrum_fit lined;
    HM_CHECK(hm_spectrum_fit_peak_z(m, c.v_start_kmh, &point, &fit, f, p, nb, dof, f[k8] - 1e-9, f[k8] + 1e-9,
                                    &z_line) == HM_OK &&
                 hm_spectrum_fit_peak_z(m, c.v_start_kmh, &point, &fit, f, p, nb, dof, f[k8 - 1], f[k8 + 1],
                                        &z_three) == HM_OK,
             "the residual under the line");
    HM_CHECK(m && hm_spectrum_fit_conicity(m, c.v_start_kmh, &point, f, p, nb, dof, &o, &lined) == HM_OK &&
                 hm_spectrum_fit_peak_z(m, c.v_start_kmh, &point, &lined, f, p, nb, dof, f[k8], f[k8], &z_refit) ==
                     HM_OK,
             "refit");
    const double expect = (30.0 * x_k - 1.0) / se1;
    const double expect3 = ((x_l + 30.0 * x_k + x_r) / 3.0 - 1.0) / sqrt(2.0 / (3.0 * dof));
    printf("  its residual at %.2f Hz: %.2f (x %.3f); with a line 30 times that bin: %.1f (%.1f expected), over "
           "three bins %.1f (%.1f), refitted %.1f\n", f[k8], z_own, x_k, z_line, expect, z_three, expect3, z_refit);
    HM_CHECK(fabs(z_own) < 4.0 && fabs(z_left) < 4.0 && fabs(z_right) < 4.0, "the model's own spectrum explained");
    HM_CHECK(fabs(z_line - expect) <= 1e-9 * expect && fabs(z_three - expect3) <= 1e-9 * expect3,
             "the line's residual at its bin and over three");
    HM_CHECK(z_refit > 20.0, "refitted with the line in it: still far out");
    HM_CHECK(hm_spectrum_fit_peak_z(m, c.v_start_kmh, &point, &lined, f, p, nb, dof, 30.0, 31.0, &z_out) ==
                     HM_EDOMAIN &&
                 hm_spectrum_fit_peak_z(m, c.v_start_kmh, &point, &lined, f, p, nb, dof, 9.0, 8.0, &z_out) ==
                     HM_EDOMAIN &&
                 z_out == -1.0,
             "outside the band, or upside down: refused, the output untouched");
    /* a density negative or not finite in the range, a fit with an infinite amplitude, a NULL pointer: refused */
    hm_spectrum_fit inf_amp = lined;
    inf_amp.amplitude = INFINITY;
    const double keep = p[k8];
    p[k8] = -1e-6;
    const hm_status negative = hm_spectrum_fit_peak_z(m, c.v_start_kmh, &point, &lined, f, p, nb, dof, f[k8], f[k8],
                                                      &z_out);
    p[k8] = INFINITY;
    const hm_status infinite = hm_spectrum_fit_peak_z(m, c.v_start_kmh, &point, &lined, f, p, nb, dof, f[k8 - 1],
                                                      f[k8 + 1], &z_out);
    p[k8] = keep;
    HM_CHECK(negative == HM_EDOMAIN && infinite == HM_EDOMAIN &&
                 hm_spectrum_fit_peak_z(m, c.v_start_kmh, &point, &inf_amp, f, p, nb, dof, f[k8], f[k8], &z_out) ==
                     HM_EDOMAIN &&
                 hm_spectrum_fit_peak_z(m, c.v_start_kmh, &point, NULL, f, p, nb, dof, f[k8], f[k8], &z_out) ==
                     HM_EDOMAIN &&
                 hm_spectrum_fit_peak_z(m, c.v_start_kmh, &point, &lined, f, p, nb, dof, f[k8], f[k8], NULL) ==
                     HM_EDOMAIN &&
                 z_out == -1.0,
             "a negative or infinite density, an infinite amplitude, NULL: refused, the output untouched");
    p[k8] /= 30.0;
    hm_mode_model_destroy(m);
  }
}



/* One periodogram (no taper) of n samples as a two-sided density over [f_lo, f_hi], as the monitor's window gives it
 * (modal.h's hm_modal_window_spectrum): 2 degrees of freedom a bin. */
static size_t periodogram_band(const double *a, size_t n, double fs, double f_lo, double f_hi, double *f, double *p) {
  double mean = 0.0;
  for (size_t j = 0; j < n; ++j) mean += a[j];
  mean /= (double)n;
  size_t nb = 0;
  for (size_t k = (size_t)ceil(f_lo * (double)n / fs); (double)k * fs / (double)n <= f_hi; ++k) {
    double re = 0.0, im = 0.0, c = 1.0, s = 0.0;
    const double dc = cos(2.0 * HM_PI * (double)k / (double)n), ds = -sin(2.0 * HM_PI * (double)k / (double)n);
    for (size_t j = 0; j < n; ++j) { /* e^{-i 2 pi k j / n} by rotation, renormalised every 1024 steps */
      re += (a[j] - mean) * c, im += (a[j] - mean) * s;
      const double c2 = c * dc - s * ds;
      s = c * ds + s * dc, c = c2;
      if ((j & 1023) == 1023) {
        const double norm = hypot(c, s);
        c /= norm, s /= norm;
      }
    }
    f[nb] = (double)k * fs / (double)n;
    p[nb++] = (re * re + im * im) / (fs * (double)n);
  }
  return nb;
}

/* A recording of the bogie b at 511 km/h from the point (the sensor of the model it is read by) over a track of
 * irregularity 0.3 (seed), N samples at FS Hz into rec, the leading wheelset's displacement from the track with it
 * (rec->track made here). 1 if whole. */
enum { FS = 500, N = 30000, W = 24000 };

static int record_at_511(const hm_bogie *b, const hm_sensor_point *point, uint64_t seed, run_rec *rec) {
  hm_sensor_sim_config c;
  hm_sensor_sim_config_default(&c);
  c.v_start_kmh = c.v_end_kmh = 511.0;
  c.irregularity_scale = 0.3;
  c.track_seed = c.noise_seed = seed;
  c.accel_rate_hz = FS;
  hm_bogie_model bm;
  hm_system sys;
  hm_sensor_sim sim = NULL;
  rec->v_mps = hm_mps_from_kmh(511.0);
  HM_CHECK(hm_bogie_model_init(&bm, b, 0, &sys) == HM_OK &&
               hm_sensor_sim_create_system(&sys, point, &c, NULL, &sim, NULL, 0) == HM_OK &&
               hm_track_create(c.wavelength_min_m, c.wavelength_max_m, c.irregularity_scale, c.track_seed,
                               &rec->track) == HM_OK,
           "simulation");
  const hm_sensor_sink sink = {keep_run, NULL, rec};
  if (sim && rec->track) HM_CHECK(hm_sensor_sim_run(sim, (double)N / FS, &sink) == HM_OK, "run");
  hm_sensor_sim_destroy(sim);
  hm_track_destroy(rec->track);
  rec->track = NULL;
  return rec->n == N;
}

/* The default bogie at 511 km/h, 30 km/h below its Hopf speed at 0.1358 (540.98 km/h), where its wheelsets move about
 * 1 mm from the track: 60 s from the frame's accelerometer, the last 48 s fitted over 4-22 Hz, as recorded (MODEL.md's
 * flange force) and again on the same track with the force taken out. */
static void the_running_is_linearised(void) {
  static double a[2][N], r[2][N], f[1024], p[1024];
  hm_spectrum_fit fit[2][2]; /* [flange][passes 0, 2] */
  double motion_sim[2] = {0.0, 0.0};
  for (int flange = 1; flange >= 0; --flange) {
    hm_bogie b;
    hm_bogie_default(&b);
    if (!flange) b.wheelset.flange_alpha1_n_m3 = b.wheelset.flange_alpha2_n_m5 = 0.0;
    hm_sensor_point point;
    hm_mode_model m = NULL;
    HM_CHECK(hm_mode_model_create_bogie(&b, &m) == HM_OK && hm_mode_model_sensor(m, "frame", &point) == HM_OK, "model");
    run_rec rec = {a[flange], r[flange], 0, N, NULL, 0.0};
    if (!m || !record_at_511(&b, &point, 3, &rec)) {
      hm_mode_model_destroy(m);
      return;
    }
    double ss = 0.0, mean = 0.0;
    for (size_t j = N - W; j < N; ++j) mean += r[flange][j];
    mean /= W;
    for (size_t j = N - W; j < N; ++j) ss += (r[flange][j] - mean) * (r[flange][j] - mean);
    motion_sim[flange] = sqrt(ss / W);
    const size_t nb = periodogram_band(a[flange] + (N - W), W, FS, 4.0, 22.0, f, p);
    for (int k = 0; k < 2; ++k) {
      hm_spectrum_fit_options o;
      hm_spectrum_fit_options_default(&o);
      o.window_s = (double)W / FS;
      o.passes = k ? HM_SPECTRUM_FIT_MAX_PASSES : 0;
      HM_CHECK(hm_spectrum_fit_conicity(m, 511.0, &point, f, p, nb, 2.0, &o, &fit[flange][k]) == HM_OK, "fit");
    }
    printf("  %s: at rest %.4f +- %.4f, linearised %.4f +- %.4f (motion %.3f mm, simulated %.3f mm; shape chi2 %.1f)\n",
           flange ? "flange force" : "no flange force", fit[flange][0].conicity, fit[flange][0].conicity_se,
           fit[flange][1].conicity, fit[flange][1].conicity_se, fit[flange][1].motion_rms_m * 1e3,
           motion_sim[flange] * 1e3, fit[flange][1].shape_chi2);
    hm_mode_model_destroy(m);
  }
  /* (the two recordings share their track and noise: the difference is the force's, the window's noise cancels) */
  const double effect = fit[1][0].conicity - fit[0][0].conicity, left = fit[1][1].conicity - fit[0][0].conicity;
  HM_CHECK(effect < -0.001, "at rest the flange's softening reads the conicity low: %.4f against %.4f without it",
           fit[1][0].conicity, fit[0][0].conicity);
  HM_CHECK(fabs(left) <= 0.25 * fabs(effect),
           "linearised it reads what the same track gives without the force: %.4f against %.4f", fit[1][1].conicity,
           fit[0][0].conicity);
  HM_CHECK(fabs(fit[1][1].conicity - 0.1358) <= 3.0 * fit[1][1].conicity_se + 0.02 * 0.1358, "and the truth: %.4f",
           fit[1][1].conicity);
  HM_CHECK(fabs(fit[0][1].conicity - fit[0][0].conicity) <= 1e-4 * fit[0][0].conicity,
           "without the force the linearisation is the model at rest: %.6f, %.6f", fit[0][1].conicity,
           fit[0][0].conicity);
  HM_CHECK(fit[1][1].shape_chi2 <= 30.0 && fit[0][1].shape_chi2 <= 30.0, "the model's shape is the spectrum's");
  for (int flange = 0; flange < 2; ++flange)
    HM_CHECK(fabs(fit[flange][1].motion_rms_m / motion_sim[flange] - 1.0) <= 0.15,
             "the wheelset's motion the fit implies is the simulated one: %.3f mm, %.3f mm",
             fit[flange][1].motion_rms_m * 1e3, motion_sim[flange] * 1e3);
}

/* A vehicle that is not the model: the default bogie's frame with 3.3 times its yaw inertia, 6 times its yaw dampers'
 * damping and 10 times their joints' stiffness (the campaign's hm_scenario bogie: If 6000 kg m^2 and a viscous yaw
 * damping of 20 MN m s against config/bogie_default.yaml's 1800 and 3.4), read by the default model at 511 km/h. The
 * fit still finds a conicity, a wrong one, but its shape misses the spectrum's: shape_chi2 beyond the margin's default
 * 30 (spectrum_max_shape_chi2) from the frame and the axle box, where the model's own recordings give 9
 * (the_running_is_linearised). */
static void a_vehicle_not_the_model_is_told(void) {
  static double a[N], r[N], f[1024], p[1024];
  hm_bogie model_b, vehicle;
  hm_bogie_default(&model_b);
  vehicle = model_b;
  vehicle.frame_yaw_inertia_kg_m2 *= 3.3;
  vehicle.yaw_damper_damping_n_s_m *= 6.0;
  vehicle.yaw_damper_stiffness_n_m *= 10.0;
  hm_mode_model m = NULL;
  HM_CHECK(hm_mode_model_create_bogie(&model_b, &m) == HM_OK, "model");
  double shape[2] = {NAN, NAN};
  for (int k = 0; k < 2 && m; ++k) {
    const char *where = k ? "axlebox" : "frame";
    hm_sensor_point point;
    run_rec rec = {a, r, 0, N, NULL, 0.0};
    HM_CHECK(hm_mode_model_sensor(m, where, &point) == HM_OK, "sensor");
    if (!record_at_511(&vehicle, &point, 4, &rec)) break;
    const size_t nb = periodogram_band(a + (N - W), W, FS, k ? 6.0 : 4.0, 22.0, f, p);
    hm_spectrum_fit_options o;
    hm_spectrum_fit_options_default(&o);
    o.window_s = (double)W / FS;
    hm_spectrum_fit fit;
    HM_CHECK(hm_spectrum_fit_conicity(m, 511.0, &point, f, p, nb, 2.0, &o, &fit) == HM_OK, "fit");
    shape[k] = fit.shape_chi2;
    printf("  another frame, from the %s: %.4f +- %.4f (truth 0.1358), shape chi2 %.1f, deviance %.3f a bin\n", where,
           fit.conicity, fit.conicity_se, fit.shape_chi2, fit.deviance_per_bin);
  }
  HM_CHECK(shape[0] > 30.0 && shape[1] > 30.0, "the spectrum is not the model's: shape chi2 %.1f, %.1f", shape[0],
           shape[1]);
  hm_mode_model_destroy(m);
}

static void bad_input(void) {
  hm_bogie b;
  hm_bogie_default(&b);
  hm_mode_model m = NULL;
  hm_sensor_point point;
  HM_CHECK(hm_mode_model_create_bogie(&b, &m) == HM_OK && hm_mode_model_sensor(m, "axlebox", &point) == HM_OK, "model");
  if (!m) return;
  double f[16], p[16];
  for (int k = 0; k < 16; ++k) f[k] = 6.0 + k, p[k] = 1e-3;
  hm_spectrum_fit_options o;
  hm_spectrum_fit_options_default(&o);
  hm_spectrum_fit out;
  memset(&out, 0x5a, sizeof out);
  HM_CHECK(hm_spectrum_fit_conicity(m, 450.0, &point, f, p, 7, 2.0, &o, &out) == HM_EDOMAIN, "7 bins");
  o.passes = HM_SPECTRUM_FIT_MAX_PASSES + 1;
  HM_CHECK(hm_spectrum_fit_conicity(m, 450.0, &point, f, p, 16, 2.0, &o, &out) == HM_EDOMAIN, "too many passes");
  hm_spectrum_fit_options_default(&o);
  o.conicity_max = o.conicity_min;
  HM_CHECK(hm_spectrum_fit_conicity(m, 450.0, &point, f, p, 16, 2.0, &o, &out) == HM_EDOMAIN, "an empty range");
  hm_spectrum_fit_options_default(&o);
  p[3] = NAN;
  HM_CHECK(hm_spectrum_fit_conicity(m, 450.0, &point, f, p, 16, 2.0, &o, &out) == HM_EDOMAIN, "a NaN bin");
  p[3] = 1e-3;
  HM_CHECK(hm_spectrum_fit_conicity(m, -450.0, &point, f, p, 16, 2.0, &o, &out) == HM_EDOMAIN, "a negative speed");
  f[5] = f[4];
  HM_CHECK(hm_spectrum_fit_conicity(m, 450.0, &point, f, p, 16, 2.0, &o, &out) == HM_EDOMAIN, "frequencies not rising");
  f[5] = 11.0;
  HM_CHECK(((unsigned char *)&out)[0] == 0x5a, "output untouched");
  /* white noise's periodogram (exponential ordinates about a flat level): whatever conicity the fit returns, the floor
   * carries the band (model_share below margin.h's HM_MARGIN_SPECTRUM_MIN_SHARE, which makes such a window a misfit) */
  static double fn[721], pn[721];
  unsigned long long rng = 12345;
  int refused = 0;
  for (int seed = 0; seed < 4; ++seed) {
    for (int k = 0; k < 721; ++k) {
      rng = rng * 6364136223846793005ull + 1442695040888963407ull;
      fn[k] = 4.0 + 0.025 * k, pn[k] = -1e-4 * log(((double)(rng >> 11) + 0.5) / 9007199254740992.0);
    }
    hm_spectrum_fit nf;
    const hm_status st = hm_spectrum_fit_conicity(m, 500.0, &point, fn, pn, 721, 2.0, &o, &nf);
    if (st == HM_OK) printf("  white noise %d: %.4f +- %.4f, shape chi2 %.1f, the model's share %.3g\n", seed, nf.conicity,
                            nf.conicity_se, nf.shape_chi2, nf.model_share);
    refused += st != HM_OK || nf.model_share < 0.5;
  }
  HM_CHECK(refused == 4, "white noise: the floor carries it (%d of 4)", refused);
  hm_running run = {0.0, {1e-3, -1e-3}};
  double shape[16];
  HM_CHECK(hm_mode_model_running_spectrum(m, 0.15, 450.0, &point, &run, f, 16, shape) == HM_EDOMAIN,
           "a negative motion");
  double motion[HM_SYSTEM_MAX_WHEELSETS];
  run.motion_rms_m[1] = 1e-3;
  HM_CHECK(hm_mode_model_motion_rms(m, 0.15, 450.0, &run, NAN, motion) == HM_EDOMAIN, "a NaN amplitude");
  hm_mode_model_destroy(m);
}

int main(void) {
  HM_RUN(finds_the_conicity);
  HM_RUN(the_running_is_linearised);
  HM_RUN(a_vehicle_not_the_model_is_told);
  HM_RUN(bad_input);
  HM_TEST_EXIT();
}
