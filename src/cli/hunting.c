/* hunting: command-line front end of the hunting_monitor C core (argument parsing and output only). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "hunting_monitor/config.h"
#include "hunting_monitor/integrate.h"
#include "hunting_monitor/linear.h"
#include "hunting_monitor/lyapunov.h"
#include "hunting_monitor/model.h"
#include "hunting_monitor/sensor_sim.h"

#define VEHICLE_OPTIONS CLI_VEHICLE_OPTIONS

int cli_fail_status(const char *what, hm_status st) {
  fprintf(stderr, "hunting: %s: %s\n", what, hm_status_str(st));
  return 1;
}
#define fail_status cli_fail_status

/* Speed option --v in km/h, required, > 0. */
int cli_speed_option(const cli_args *a, double *v_kmh) {
  if (!cli_has(a, "v")) {
    fprintf(stderr, "hunting: --v KM/H (running speed) is required\n");
    return 1;
  }
  if (cli_number(a, "v", v_kmh)) return 1;
  if (!(*v_kmh > 0.0)) {
    fprintf(stderr, "hunting: --v must be > 0 km/h, got %g\n", *v_kmh);
    return 1;
  }
  return 0;
}

/* ---- critical ---- */

static const cli_option critical_opts[] = {VEHICLE_OPTIONS, {NULL, NULL, NULL}};

/* The least-damped mode of a spectrum: frequency, decay rate, whose it is and its kinetic energy by body. */
static void jw_system_mode(json_writer *w, const hm_system *sys, const hm_system_spectrum *s) {
  jw_number(w, "frequency_hz", s->frequency_hz);
  jw_number(w, "decay_rate_1_s", s->abscissa_1_s);
  jw_string(w, "mode", sys->body_names[s->dominant_body]);
  jw_object(w, "mode_energy_share");
  for (size_t b = 0; b < sys->n_bodies; ++b) jw_number(w, sys->body_names[b], s->body_share[b]);
  jw_end_object(w);
}

/* critical on a bogie or car: its linear critical speed by eigenvalues, the mode that goes first, and the speed with
 * its frame (bogie) or carbody (car) held beside it. */
static int critical_system(const cli_args *a, hm_model_kind kind) {
  static cli_model cm; /* its systems point into it */
  if (cli_vehicle_model(a, kind, &cm)) return 1;
  hm_system_critical_options opt;
  hm_system_critical_options_default(&opt);
  double v = 0.0, v_held = 0.0;
  hm_system_spectrum s;
  hm_status st = hm_system_critical_speed(&cm.sys, &opt, &v, &s);
  const double lambda = cli_conicity0(&cm.wheelset);
  if (st == HM_ENOCRIT) {
    fprintf(stderr, "hunting: no critical speed: the %s at conicity %g is stable from 100 to 1500 km/h, or "
            "unstable already at 100 km/h\n", hm_model_kind_name(kind), lambda);
    return 1;
  }
  if (st != HM_OK) return fail_status("critical speed", st);
  const hm_status st_held = hm_system_critical_speed(&cm.held, &opt, &v_held, NULL);
  json_writer w;
  jw_init(&w, stdout);
  jw_object(&w, NULL);
  jw_string(&w, "model", hm_model_kind_name(kind));
  jw_number(&w, "v_crit_kmh", hm_kmh_from_mps(v));
  jw_number(&w, "v_crit_mps", v);
  jw_system_mode(&w, &cm.sys, &s);
  jw_number(&w, "conicity", lambda);
  jw_number(&w, "kx_mn_m", cm.wheelset.stiffness_long_n_m / 1e6);
  jw_number(&w, "ky_mn_m", cm.wheelset.stiffness_lat_n_m / 1e6);
  jw_number(&w, cm.held_name, st_held == HM_OK ? hm_kmh_from_mps(v_held) : NAN);
  jw_spectrum(&w, "eigenvalues", &s);
  jw_end_object(&w);
  jw_finish(&w);
  return 0;
}

static int cmd_critical(const cli_args *a) {
  hm_vehicle veh;
  hm_model_kind kind;
  if (cli_model_kind(a, &kind)) return 1;
  if (kind != HM_MODEL_WHEELSET) return critical_system(a, kind);
  if (cli_vehicle(a, &veh, NULL)) return 1;
  const double lambda = cli_conicity0(&veh);
  double v_mps, omega, re[4], im[4];
  hm_status st = hm_linear_critical_speed(&veh, lambda, &v_mps);
  if (st == HM_ENOCRIT) {
    double abscissa = 0.0; /* with no crossing, the stability at any one speed holds at every speed */
    hm_linear_spectral_abscissa(&veh, lambda, 1.0, &abscissa);
    fprintf(stderr, "hunting: no critical speed: the linear model at conicity %g is %s at every speed\n", lambda,
            abscissa < 0.0 ? "stable" : "unstable");
    return 1;
  }
  if (st != HM_OK) return fail_status("critical speed", st);
  if ((st = hm_linear_hopf_omega(&veh, &omega)) != HM_OK) return fail_status("Hopf frequency", st);
  if ((st = hm_linear_eigenvalues(&veh, lambda, v_mps, re, im)) != HM_OK) return fail_status("eigenvalues", st);
  json_writer w;
  jw_init(&w, stdout);
  jw_object(&w, NULL);
  jw_string(&w, "model", "wheelset");
  jw_number(&w, "v_crit_kmh", hm_kmh_from_mps(v_mps));
  jw_number(&w, "v_crit_mps", v_mps);
  jw_number(&w, "frequency_hz", omega / (2.0 * HM_PI));
  jw_number(&w, "omega_rad_s", omega);
  jw_number(&w, "conicity", lambda);
  jw_number(&w, "kx_mn_m", veh.stiffness_long_n_m / 1e6);
  jw_number(&w, "ky_mn_m", veh.stiffness_lat_n_m / 1e6);
  jw_eigenvalues(&w, "eigenvalues", re, im);
  jw_end_object(&w);
  jw_finish(&w);
  return 0;
}

/* ---- critical-conicity ---- */

static const cli_option critical_conicity_opts[] = {
    {"v", "KM/H", "running speed (required)"}, VEHICLE_OPTIONS, {NULL, NULL, NULL}};

static int cmd_critical_conicity(const cli_args *a) {
  hm_vehicle veh;
  double v_kmh, lambda_c;
  if (cli_vehicle(a, &veh, NULL) || cli_speed_option(a, &v_kmh)) return 1;
  hm_status st = hm_linear_critical_conicity(&veh, hm_mps_from_kmh(v_kmh), &lambda_c);
  if (st == HM_ENOCRIT) {
    fprintf(stderr, "hunting: no critical conicity: the linear model is unstable at %g km/h for every conicity\n",
            v_kmh);
    return 1;
  }
  if (st != HM_OK) return fail_status("critical conicity", st);
  json_writer w;
  jw_init(&w, stdout);
  jw_object(&w, NULL);
  jw_number(&w, "v_kmh", v_kmh);
  jw_number(&w, "conicity_crit", lambda_c);
  jw_end_object(&w);
  jw_finish(&w);
  return 0;
}

/* ---- eig ---- */

static const cli_option eig_opts[] = {{"v", "KM/H", "running speed (required)"}, VEHICLE_OPTIONS, {NULL, NULL, NULL}};

static int eig_system(const cli_args *a, hm_model_kind kind) {
  static cli_model cm;
  double v_kmh;
  if (cli_vehicle_model(a, kind, &cm) || cli_speed_option(a, &v_kmh)) return 1;
  hm_system_spectrum s;
  hm_status st = hm_system_spectrum_at(&cm.sys, hm_mps_from_kmh(v_kmh), &s);
  if (st != HM_OK) return fail_status("eigenvalues", st);
  json_writer w;
  jw_init(&w, stdout);
  jw_object(&w, NULL);
  jw_string(&w, "model", hm_model_kind_name(kind));
  jw_number(&w, "v_kmh", v_kmh);
  jw_number(&w, "conicity", cli_conicity0(&cm.wheelset));
  jw_spectrum(&w, "eigenvalues", &s);
  jw_bool(&w, "stable", s.re[0] < 0.0);
  jw_object(&w, "least_damped");
  jw_system_mode(&w, &cm.sys, &s);
  jw_end_object(&w);
  jw_end_object(&w);
  jw_finish(&w);
  return 0;
}

static int cmd_eig(const cli_args *a) {
  hm_vehicle veh;
  double v_kmh, re[4], im[4];
  hm_model_kind kind;
  if (cli_model_kind(a, &kind)) return 1;
  if (kind != HM_MODEL_WHEELSET) return eig_system(a, kind);
  if (cli_vehicle(a, &veh, NULL) || cli_speed_option(a, &v_kmh)) return 1;
  const double lambda = cli_conicity0(&veh);
  hm_status st = hm_linear_eigenvalues(&veh, lambda, hm_mps_from_kmh(v_kmh), re, im);
  if (st != HM_OK) return fail_status("eigenvalues", st);
  json_writer w;
  jw_init(&w, stdout);
  jw_object(&w, NULL);
  jw_number(&w, "v_kmh", v_kmh);
  jw_number(&w, "conicity", lambda);
  jw_eigenvalues(&w, "eigenvalues", re, im);
  jw_bool(&w, "stable", re[0] < 0.0);
  jw_end_object(&w);
  jw_finish(&w);
  return 0;
}

/* ---- simulate ---- */

static const cli_option simulate_opts[] = {
    {"v", "KM/H", "running speed (required; the start speed with --v-end)"},
    {"v-end", "KM/H", "ramp the speed linearly from --v to this over --t"},
    {"profile", "T:V,T:V,...", "a speed profile instead (s:km/h, linear between, from 0 s; up to 64 points; --v not needed)"},
    {"x0", "Y,DY,PSI,DPSI", "initial state [m, m/s, rad, rad/s] (default 0.001,0,0,0)"},
    {"t", "SECONDS", "simulated time (default 10)"},
    {"dt-out", "SECONDS", "output interval, dense output of the integrator (default 0.001)"},
    {"out", "FILE", "write the CSV there instead of stdout"},
    {"irregularity", "SCALE", "lateral track irregularity: power of the German low-disturbance spectrum x SCALE"},
    {"seed", "N", "random phases of the irregularity (default 1)"},
    {"accel-out", "FILE", "also write a sensor stream t_s,accel_mps2 (at --dt-out, with --accel-noise)"},
    {"speed-out", "FILE", "also write a sensor stream t_s,speed_kmh (at 10 Hz)"},
    {"accel-noise", "SIGMA", "white noise [m/s^2] added to --accel-out (default 0)"},
    {"linear", NULL, "linear model: constant conicity lambda(0), no flange force"},
    {"sensor", "WHERE", "a bogie's or car's accelerometer: axlebox (the leading wheelset, default), frame, carbody"},
    {"rtol", "R", "relative tolerance of Dormand-Prince 5(4) (default 1e-9)"},
    {"atol", "A", "absolute tolerance (default 1e-12)"},
    VEHICLE_OPTIONS,
    {NULL, NULL, NULL}};

typedef struct {
  FILE *out, *accel_out, *speed_out;
  int write_error;
} sim_writer;

static int sim_failed(sim_writer *w) {
  if (ferror(w->out) || (w->accel_out && ferror(w->accel_out)) || (w->speed_out && ferror(w->speed_out)))
    w->write_error = 1; /* a full disk: stop integrating for nobody */
  return w->write_error;
}

static int write_accel(void *ctx, double t, double measured, double true_accel, const double *x) {
  sim_writer *w = (sim_writer *)ctx;
  fprintf(w->out, "%.9g,%.12g,%.12g,%.12g,%.12g,%.12g\n", t, x[0], x[1], x[2], x[3], true_accel);
  if (w->accel_out) fprintf(w->accel_out, "%.9g,%.9g\n", t, measured);
  return sim_failed(w);
}

static int write_speed(void *ctx, double t, double v_kmh) {
  sim_writer *w = (sim_writer *)ctx;
  if (w->speed_out) fprintf(w->speed_out, "%.9g,%.9g\n", t, v_kmh);
  return sim_failed(w);
}

/* Open each requested output file (NULL where not requested); nonzero on failure. */
static int open_outputs(const cli_args *a, FILE **out, FILE **acc, FILE **spd) {
  const char *names[3] = {"out", "accel-out", "speed-out"};
  FILE **files[3] = {out, acc, spd};
  for (int k = 0; k < 3; ++k) {
    const char *p = cli_value(a, names[k]);
    *files[k] = p ? fopen(p, "w") : NULL;
    if (p && !*files[k]) {
      perror(p);
      return 1;
    }
  }
  if (!*out) *out = stdout;
  return 0;
}

/* Close the files; nonzero (with a message) if anything written to them was lost. */
static int close_outputs(const cli_args *a, FILE *out, FILE *acc, FILE *spd) {
  const char *names[3] = {"out", "accel-out", "speed-out"};
  FILE *files[3] = {out != stdout ? out : NULL, acc, spd};
  int rc = 0;
  for (int k = 0; k < 3; ++k)
    if (files[k] && (ferror(files[k]) | fclose(files[k])) != 0) {
      fprintf(stderr, "hunting simulate: %s: write error\n", cli_value(a, names[k]));
      rc = 1;
    }
  return rc;
}

/* "T:V,T:V,..." into the profile; 0, or 1 with the message printed. */
static int parse_profile(const char *s, double *t, double *v, size_t *n) {
  size_t k = 0;
  const char *p = s;
  while (*p) {
    char *end = NULL;
    if (k == HM_SPEED_PROFILE_MAX) break;
    t[k] = strtod(p, &end);
    if (end == p || *end != ':') break;
    p = end + 1;
    v[k] = strtod(p, &end);
    if (end == p || !isfinite(t[k]) || !isfinite(v[k])) break;
    ++k;
    p = end;
    if (*p == ',') ++p;
    else if (*p) break;
  }
  if (*p || k == 0) {
    fprintf(stderr, "hunting simulate: --profile must be T:V,T:V,... (s:km/h, up to %d points), got '%s'\n",
            HM_SPEED_PROFILE_MAX, s);
    return 1;
  }
  *n = k;
  return 0;
}

/* A bogie's or car's run: the accelerometer where --sensor says (axlebox by default), --x0 the leading wheelset's. */
static hm_status simulate_system(const cli_args *a, const cli_model *cm, const hm_sensor_sim_config *cfg,
                                 const double *x_lead, hm_sensor_sim *sim, char *why, size_t len) {
  const char *where = cli_value(a, "sensor") ? cli_value(a, "sensor") : "axlebox";
  hm_sensor_point point;
  hm_status st = cm->kind == HM_MODEL_CAR ? hm_car_sensor(&cm->car, where, &point)
                                          : hm_bogie_sensor(&cm->bogie, where, &point);
  if (st != HM_OK) {
    snprintf(why, len, "--sensor: '%s' is not a place on a %s (axlebox, frame%s)", where,
             hm_model_kind_name(cm->kind), cm->kind == HM_MODEL_CAR ? ", carbody" : "");
    return st;
  }
  double x0[HM_SYSTEM_MAX_DIM] = {0.0};
  for (int i = 0; i < 4; ++i) x0[i] = x_lead[i];
  return hm_sensor_sim_create_system(&cm->sys, &point, cfg, x0, sim, why, len);
}

static int cmd_simulate(const cli_args *a) {
  static cli_model cm; /* a bogie's or car's; its system points into it */
  hm_model_kind kind;
  if (cli_model_kind(a, &kind) || (kind != HM_MODEL_WHEELSET && cli_vehicle_model(a, kind, &cm))) return 1;
  if (kind != HM_MODEL_WHEELSET && cli_has(a, "linear")) {
    fprintf(stderr, "hunting simulate: --linear is for the wheelset model\n");
    return 1;
  }
  if (kind == HM_MODEL_WHEELSET && cli_has(a, "sensor") && strcmp(cli_value(a, "sensor"), "axlebox") != 0) {
    fprintf(stderr, "hunting simulate: a wheelset has only its axle box (--sensor axlebox)\n");
    return 1;
  }
  hm_vehicle veh, lin;
  double v_kmh = 0.0, x[4] = {0.001, 0.0, 0.0, 0.0}, t_end = 10.0, dt_out = 0.001, rtol = 1e-9, atol = 1e-12;
  double v_end = NAN, scale = 0.0, seed = 1.0, noise = 0.0;
  double prof_t[HM_SPEED_PROFILE_MAX], prof_v[HM_SPEED_PROFILE_MAX];
  size_t n_prof = 0;
  const char *profile = cli_value(a, "profile");
  if (profile && parse_profile(profile, prof_t, prof_v, &n_prof)) return 1;
  if (profile) v_kmh = prof_v[0];
  if ((kind == HM_MODEL_WHEELSET && cli_vehicle(a, &veh, NULL)) || (!profile && cli_speed_option(a, &v_kmh)) ||
      cli_number_list(a, "x0", x, 4) ||
      cli_number(a, "t", &t_end) || cli_number(a, "dt-out", &dt_out) || cli_number(a, "rtol", &rtol) ||
      cli_number(a, "atol", &atol) || cli_number(a, "v-end", &v_end) || cli_number(a, "irregularity", &scale) ||
      cli_number(a, "seed", &seed) || cli_number(a, "accel-noise", &noise))
    return 1;
  if (isnan(v_end)) v_end = v_kmh;
  if (!(t_end > 0.0) || !(dt_out > 0.0) || t_end / dt_out > 1e8 || !(rtol > 0.0) || !(atol >= 0.0) ||
      !(v_end > 0.0) || !(scale >= 0.0) || !(noise >= 0.0) || !(seed >= 0.0 && seed <= 9007199254740992.0) ||
      seed != floor(seed)) {
    fprintf(stderr, "hunting simulate: need --t > 0, --dt-out > 0 (at most 1e8 rows), --rtol > 0, --atol >= 0, "
                    "--v-end > 0, --irregularity >= 0, --accel-noise >= 0 and a whole --seed in 0..2^53\n");
    return 1;
  }
  if (cli_has(a, "linear")) {
    hm_vehicle_linearized(&veh, &lin);
    veh = lin;
  }
  hm_sensor_sim_config cfg;
  hm_sensor_sim_config_default(&cfg);
  cfg.v_start_kmh = v_kmh;
  cfg.v_end_kmh = v_end;
  cfg.ramp_s = t_end;
  cfg.n_profile = n_prof;
  for (size_t k = 0; k < n_prof; ++k) cfg.profile_t_s[k] = prof_t[k], cfg.profile_v_kmh[k] = prof_v[k];
  cfg.irregularity_scale = scale;
  cfg.track_seed = cfg.noise_seed = (uint64_t)seed;
  cfg.accel_rate_hz = 1.0 / dt_out;
  cfg.accel_noise_mps2 = noise;
  cfg.rtol = rtol;
  cfg.atol = atol;
  cfg.max_step_s = scale > 0.0 ? 2e-3 : 0.0;
  hm_sensor_sim sim = NULL;
  char why[160] = "";
  hm_status st = kind == HM_MODEL_WHEELSET ? hm_sensor_sim_create(&veh, &cfg, x, &sim, why, sizeof why)
                                           : simulate_system(a, &cm, &cfg, x, &sim, why, sizeof why);
  if (st != HM_OK) {
    fprintf(stderr, "hunting simulate: %s\n", why);
    return 1;
  }
  FILE *out = NULL, *acc = NULL, *spd = NULL;
  if (open_outputs(a, &out, &acc, &spd)) {
    close_outputs(a, out, acc, spd);
    hm_sensor_sim_destroy(sim);
    return 1;
  }
  fprintf(out, "t_s,y_m,dy_mps,psi_rad,dpsi_radps,accel_lat_mps2\n");
  if (acc) fprintf(acc, "t_s,accel_mps2\n");
  if (spd) fprintf(spd, "t_s,speed_kmh\n");
  sim_writer w = {out, acc, spd, 0};
  const hm_sensor_sink sink = {write_accel, write_speed, &w};
  st = hm_sensor_sim_run(sim, t_end, &sink);
  hm_sensor_sim_destroy(sim);
  if (close_outputs(a, out, acc, spd) || w.write_error) return 1;
  if (st != HM_OK) return fail_status("simulation (the trajectory diverged or the step size collapsed)", st);
  return 0;
}

/* ---- lyapunov ---- */

static const cli_option lyapunov_opts[] = {
    {"v", "KM/H", "running speed (required)"},
    {"x0", "Y,DY,PSI,DPSI", "initial state (default: the origin, whose exponents are its eigenvalues' real parts)"},
    {"t", "SECONDS", "averaging time (default 100)"},
    {"transient", "SECONDS", "time integrated before averaging (default 0)"},
    {"method", "NAME", "midpoint (implicit midpoint rule, default) or dopri (Dormand-Prince 5(4))"},
    {"h", "SECONDS", "midpoint step (default 1e-4)"},
    {"renorm", "SECONDS", "QR re-orthonormalisation interval (default 0.01)"},
    {"rtol", "R", "dopri relative tolerance (default 1e-9)"},
    {"atol", "A", "dopri absolute tolerance (default 1e-12)"},
    {"linear", NULL, "linear model: constant conicity lambda(0), no flange force"},
    VEHICLE_OPTIONS,
    {NULL, NULL, NULL}};

static int cmd_lyapunov(const cli_args *a) {
  hm_vehicle veh, lin;
  hm_lyap_options opt;
  hm_lyap_options_default(&opt);
  double v_kmh, x[4] = {0.0, 0.0, 0.0, 0.0};
  if (cli_vehicle(a, &veh, NULL) || cli_speed_option(a, &v_kmh) || cli_number_list(a, "x0", x, 4) ||
      cli_number(a, "t", &opt.duration_s) || cli_number(a, "transient", &opt.transient_s) ||
      cli_number(a, "h", &opt.step_s) || cli_number(a, "renorm", &opt.renorm_interval_s) ||
      cli_number(a, "rtol", &opt.rtol) || cli_number(a, "atol", &opt.atol))
    return 1;
  const char *method = cli_value(a, "method");
  if (method && strcmp(method, "dopri") == 0)
    opt.method = HM_LYAP_DOPRI;
  else if (method && strcmp(method, "midpoint") != 0) {
    fprintf(stderr, "hunting lyapunov: --method must be midpoint or dopri, got '%s'\n", method);
    return 1;
  }
  const int linear = cli_has(a, "linear");
  if (linear) {
    hm_vehicle_linearized(&veh, &lin);
    veh = lin;
  }
  hm_model model;
  hm_status st = hm_model_init(&model, &veh, hm_mps_from_kmh(v_kmh));
  if (st != HM_OK) return fail_status("model", st);
  const hm_ode_system sys = {4, hm_model_rhs, hm_model_jacobian, &model};
  double exps[4], x_end[4], re[4], im[4];
  st = hm_lyapunov_spectrum(&sys, 0.0, x, 4, &opt, exps, x_end);
  if (st == HM_EINVAL) {
    fprintf(stderr, "hunting lyapunov: invalid options (need --t > 0, --transient >= 0, 0 < --h <= --renorm <= --t, "
                    "and at most %.0e steps of --h over --transient + --t)\n", HM_LYAP_MAX_STEPS);
    return 1;
  }
  if (st != HM_OK) return fail_status("Lyapunov spectrum", st);
  json_writer w;
  jw_init(&w, stdout);
  jw_object(&w, NULL);
  jw_number(&w, "v_kmh", v_kmh);
  jw_string(&w, "model", linear ? "linear" : "nonlinear");
  jw_string(&w, "method", opt.method == HM_LYAP_DOPRI ? "dopri" : "midpoint");
  jw_numbers(&w, "exponents", exps, 4);
  jw_numbers(&w, "x_end", x_end, 4);
  if (linear && hm_linear_eigenvalues(&veh, cli_conicity0(&veh), model.speed_mps, re, im) == HM_OK)
    jw_numbers(&w, "eigenvalue_real_parts", re, 4);
  jw_end_object(&w);
  jw_finish(&w);
  return 0;
}

/* ---- sweep ---- */

static const cli_option sweep_opts[] = {
    {"from", "L", "first conicity (default 0.05)"},
    {"to", "L", "last conicity (default 0.40)"},
    {"n", "COUNT", "number of conicities (default 15)"},
    {"table", NULL, "print a readable table instead of JSON"},
    VEHICLE_OPTIONS,
    {NULL, NULL, NULL}};

/* The sweep's range: 0, or 1 with the reason on stderr. */
static int sweep_range(const cli_args *a, double *from, double *to, int *n) {
  double n_d = 15;
  *from = 0.05, *to = 0.40;
  if (cli_number(a, "from", from) || cli_number(a, "to", to) || cli_number(a, "n", &n_d)) return 1;
  if (!(*from > 0.0) || !(*to >= *from) || !(n_d >= 1.0 && n_d <= 10000.0) || n_d != floor(n_d)) {
    fprintf(stderr, "hunting sweep: need 0 < --from <= --to and an integer --n in 1..10000\n");
    return 1;
  }
  *n = (int)n_d;
  return 0;
}

/* sweep on a bogie or car: at each conicity its linear critical speed by eigenvalues, the mode that goes first, and
 * the speed with its frame (bogie) or carbody (car) held (JSON). */
static int sweep_system(const cli_args *a, hm_model_kind kind) {
  static cli_model cm;
  double from, to;
  int n;
  if (cli_vehicle_model(a, kind, &cm) || sweep_range(a, &from, &to, &n)) return 1;
  if (cli_has(a, "table")) {
    fprintf(stderr, "hunting sweep: --table takes the wheelset (a %s's rows are JSON)\n", hm_model_kind_name(kind));
    return 1;
  }
  hm_vehicle first = cm.params.bogie.wheelset; /* (the conicities rise: the first is the one that can be refused) */
  if (hm_vehicle_set_conicity_at_zero(&first, from) != HM_OK) {
    fprintf(stderr, "hunting sweep: --from %g: below the Gaussian terms' value at y = 0\n", from);
    return 1;
  }
  hm_system_critical_options opt;
  hm_system_critical_options_default(&opt);
  json_writer w;
  jw_init(&w, stdout);
  jw_object(&w, NULL);
  jw_string(&w, "model", hm_model_kind_name(kind));
  jw_number(&w, "kx_mn_m", cm.wheelset.stiffness_long_n_m / 1e6);
  jw_number(&w, "ky_mn_m", cm.wheelset.stiffness_lat_n_m / 1e6);
  jw_array(&w, "rows");
  for (int i = 0; i < n; ++i) {
    const double lambda = n == 1 ? from : from + (to - from) * i / (n - 1);
    hm_car car = cm.params;
    if (hm_vehicle_set_conicity_at_zero(&car.bogie.wheelset, lambda) != HM_OK) {
      fprintf(stderr, "hunting sweep: conicity %g: below the Gaussian terms' value at y = 0\n", lambda);
      return 1;
    }
    static cli_model row; /* (its systems point into it) */
    hm_status st = cli_model_init(kind, &car, &row);
    if (st != HM_OK) return fail_status(hm_model_kind_name(kind), st);
    double v = 0.0, v_held = 0.0;
    hm_system_spectrum s;
    st = hm_system_critical_speed(&row.sys, &opt, &v, &s);
    if (st != HM_OK && st != HM_ENOCRIT) return fail_status("critical speed", st);
    const hm_status st_held = hm_system_critical_speed(&row.held, &opt, &v_held, NULL);
    jw_object(&w, NULL);
    jw_number(&w, "conicity", lambda);
    jw_number(&w, "v_crit_kmh", st == HM_OK ? hm_kmh_from_mps(v) : NAN); /* null: no critical speed */
    if (st == HM_OK) jw_system_mode(&w, &row.sys, &s);
    jw_number(&w, cm.held_name, st_held == HM_OK ? hm_kmh_from_mps(v_held) : NAN);
    jw_end_object(&w);
  }
  jw_end_array(&w);
  jw_end_object(&w);
  jw_finish(&w);
  return 0;
}

static int cmd_sweep(const cli_args *a) {
  hm_vehicle veh;
  hm_model_kind kind;
  char name[HM_VEHICLE_NAME_MAX + 32];
  double from, to, omega;
  int n;
  if (cli_model_kind(a, &kind)) return 1;
  if (kind != HM_MODEL_WHEELSET) return sweep_system(a, kind);
  if (cli_vehicle(a, &veh, name) || sweep_range(a, &from, &to, &n)) return 1;
  hm_status st = hm_linear_hopf_omega(&veh, &omega);
  if (st != HM_OK) return fail_status("Hopf frequency", st);
  const int table = cli_has(a, "table");
  json_writer w;
  jw_init(&w, stdout);
  if (table) {
    printf("Linear critical (Hopf) speed of the wheelset vs equivalent conicity\n");
    printf("vehicle %s: Kx = %.2f MN/m, Ky = %.2f MN/m; hunting frequency at criticality %.3f Hz\n\n", name,
           veh.stiffness_long_n_m / 1e6, veh.stiffness_lat_n_m / 1e6, omega / (2.0 * HM_PI));
    printf("  conicity   critical speed [km/h]\n");
  } else {
    jw_object(&w, NULL);
    jw_number(&w, "kx_mn_m", veh.stiffness_long_n_m / 1e6);
    jw_number(&w, "ky_mn_m", veh.stiffness_lat_n_m / 1e6);
    jw_number(&w, "frequency_hz", omega / (2.0 * HM_PI));
    jw_array(&w, "rows");
  }
  for (int i = 0; i < n; ++i) {
    const double lambda = n == 1 ? from : from + (to - from) * i / (n - 1);
    double v_mps;
    st = hm_linear_critical_speed(&veh, lambda, &v_mps);
    if (st != HM_OK && st != HM_ENOCRIT) return fail_status("critical speed", st);
    if (table) {
      if (st == HM_OK)
        printf("  %8.4f   %10.2f\n", lambda, hm_kmh_from_mps(v_mps));
      else
        printf("  %8.4f   %10s\n", lambda, "none");
    } else {
      jw_object(&w, NULL);
      jw_number(&w, "conicity", lambda);
      jw_number(&w, "v_crit_kmh", st == HM_OK ? hm_kmh_from_mps(v_mps) : NAN); /* null: no critical speed */
      jw_end_object(&w);
    }
  }
  if (!table) {
    jw_end_array(&w);
    jw_end_object(&w);
    jw_finish(&w);
  }
  return 0;
}

/* ---- dispatch ---- */

typedef struct {
  const char *name;
  const char *brief; /* one line for the command list */
  const char *usage;
  const char *summary;
  const cli_option *opts;
  int (*run)(const cli_args *a);
} command;

static const command commands[] = {
    {"critical", "linear critical (Hopf) speed, hunting frequency, eigenvalues there", "[options]",
     "Linear critical (Hopf) speed from the closed-form Hurwitz condition, the hunting frequency there, and the\n"
     "eigenvalues at that speed (LAPACK dgeev). JSON: model, v_crit_kmh, frequency_hz, eigenvalues [[re, im], ...].\n"
     "A bogie's or car's config (model: bogie | car, config/bogie_default.yaml, car_default.yaml): the speed where\n"
     "the largest real part of its 13 (30) eigenvalues reaches 0 (a 5 km/h scan from 100 km/h, bisection to 1e-9\n"
     "km/h), that mode's frequency and whose it is (mode: wheelsets, bogie frame or carbody; mode_energy_share: its\n"
     "kinetic energy by body), and frame_held_v_crit_kmh (the lone wheelset's) or carbody_held_v_crit_kmh (the\n"
     "bogie's).",
     critical_opts, cmd_critical},
    {"critical-conicity", "critical equivalent conicity at a speed", "--v KM/H [options]",
     "Largest equivalent conicity for which the linear model is stable at the given speed (closed form).",
     critical_conicity_opts, cmd_critical_conicity},
    {"eig", "eigenvalues of the linearised model and stability", "--v KM/H [options]",
     "Eigenvalues [1/s] of the linearised model at the origin and whether it is stable. With a bogie's or car's\n"
     "config also its least-damped mode: frequency, decay rate and whose it is (wheelsets, bogie frame, carbody).",
     eig_opts, cmd_eig},
    {"simulate", "time integration of the nonlinear model to CSV", "--v KM/H [--x0 Y,DY,PSI,DPSI] [--t SECONDS] [options]",
     "Integrate the nonlinear model (Dormand-Prince 5(4), error control, dense output) and write CSV:\n"
     "t_s,y_m,dy_mps,psi_rad,dpsi_radps,accel_lat_mps2 (the lateral acceleration is dy'/dt of the model);\n"
     "optionally on an irregular track along a speed ramp, with sensor streams for 'hunting estimate'.\n"
     "A bogie's or car's config: its leading wheelset's states in those columns, the acceleration at --sensor\n"
     "(axlebox, frame: the frame over the leading axle, carbody: over the leading bogie), the wheelsets meeting\n"
     "the track one after another at their spacing.",
     simulate_opts, cmd_simulate},
    {"lyapunov", "Lyapunov exponent spectrum of a trajectory", "--v KM/H [--linear] [options]",
     "Lyapunov exponent spectrum [1/s] of a trajectory (Benettin with QR re-orthonormalisation), by the\n"
     "implicit midpoint rule (the study's method) or Dormand-Prince on the variational equations.",
     lyapunov_opts, cmd_lyapunov},
    {"hopf", "Hopf point of the nonlinear model and its Lyapunov coefficients", "[--param v|kx|ky|conicity] [options]",
     "Hopf point of the origin along a parameter with the first Lyapunov coefficient l1 (MATCONT convention; > 0\n"
     "subcritical) and the second l2 (meaningful where l1 = 0). For --param kx, ky or conicity give --v and a range.",
     hopf_opts, cmd_hopf},
    {"cycles", "family of limit cycles from the Hopf point, folds, stability", "[--param v] [options]",
     "Continue the limit cycles born at the Hopf point (shooting with Floquet multipliers, pseudo-arclength):\n"
     "folds (LPC) with the side of the stable cycles, symmetry-breaking branch points (BPC), period doublings, NS\n"
     "points, the lowest speed with a cycle, and the branch (parameter, amplitude, period, stability).",
     cycles_opts, cmd_cycles},
    {"hopf-curve", "two-parameter Hopf curve with GH points", "--plane kx-v|ky-v|kx-ky --from A --to B [options]",
     "Hopf curve in a parameter plane with l1 along it and the generalised Hopf points (l1 = 0) with l2.",
     hopf_curve_opts, cmd_hopf_curve},
    {"lpc-curve", "two-parameter curve of folds of cycles with cusps", "--plane kx-v|ky-v --from A --to B [options]",
     "Fold-of-cycles (LPC) curves in the (stiffness, speed) plane, continued from the folds found at --start,\n"
     "with their cusp points (CPC).",
     lpc_curve_opts, cmd_lpc_curve},
    {"tables", "boundary tables for the online monitor", "--out FILE [options]",
     "Compute the monitor's boundary tables over a conicity grid (Hopf speed, lowest speed with a cycle, the\n"
     "cycle families) with their measured interpolation error, and write them to FILE.",
     tables_opts, cmd_tables},
    {"table-lookup", "query a boundary table", "--table FILE --conicity L --v KM/H",
     "Boundaries at one conicity and speed from a table: Hopf and lowest cycle speeds, the unstable cycle (edge\n"
     "of the basin of the stable origin) and the stable cycle beyond it; null where none exists.",
     table_lookup_opts, cmd_table_lookup},
    {"fit-conicity", "fit lambda(y) to measured equivalent conicity", "DATA.csv [--terms N] [--symmetric] [options]",
     "Least-squares fit (Levenberg-Marquardt) of lambda(y) = constant + N Gaussians to a CSV with header\n"
     "y_m,conicity (or y_mm,conicity with --y-unit mm): parameters with standard errors, SSE, R^2, adjusted\n"
     "R^2, RMSE, lambda(0) and the vehicle's Hopf speed with it; --write-config writes a vehicle config.",
     fit_conicity_opts, cmd_fit_conicity},
    {"delta-r", "rolling-radius difference from wheel and rail profiles",
     "--wheel FILE.csv --rail FILE.csv [--out DR.csv] [options]",
     "Rolling-radius difference delta-r = r_left - r_right over lateral shifts of the wheelset (rigid single-point\n"
     "contact, roll neglected): wheel profile y_mm,z_mm (y from the flange back to the field side, z = radius - r0),\n"
     "rail profile y_mm,z_mm in the rail's axes (y to the field side, z up), mirrored for the right side unless\n"
     "given; rails inclined 1:40, gauge 1435 mm at 14 mm below the top, flange backs 1360 mm apart.",
     delta_r_opts, cmd_delta_r},
    {"equivalent-conicity", "equivalent conicity per amplitude from delta-r (EN 15302)",
     "--delta-r FILE.csv [--method integration|regression] [--amplitudes 1:7.5:0.1] [options]",
     "Equivalent conicity tan gamma_e per amplitude from the rolling-radius difference (CSV y_mm,delta_r_mm:\n"
     "r_left - r_right as the wheelset moves y to the left): EN 15302's integration method (the kinematic\n"
     "oscillation's wavelength against Klingel's for a cone) or the regression weighted by a sinusoid's\n"
     "distribution; null beyond the data. --csv-out writes y_mm,conicity for 'hunting fit-conicity --y-unit mm'.",
     equivalent_conicity_opts, cmd_equivalent_conicity},
    {"estimate", "run the online monitor over recorded acceleration and speed",
     "--accel FILE.csv (--speed FILE.csv | --v KM/H) [--table FILE] [--monitor FILE] [--every S]\n"
     "                [--state-in FILE] [--state-out FILE] [--state-every S] [--state-clock recording|wall]",
     "Run exactly the online estimator and alarm code over recorded data (CSV t_s,accel_mps2 and t_s,speed_kmh)\n"
     "and print one JSON object per output interval: amplitude, frequency, conicity estimate, margins,\n"
     "criteria, level and reason.\n"
     "State kept between runs: --state-out writes what the monitor learned (the identification's windows with\n"
     "their speeds and ages, conicity changes, a held ALARM, hunted-at speeds); --state-in restores it at the first\n"
     "sample, unless it is for another vehicle or other settings, damaged, of a newer format, or memory_s (900 s)\n"
     "old or more; the outcome goes to stderr and into the first line (\"restored\": \"restored, age 42 s, 3\n"
     "windows\" or the reason). Its age is read on the recording's time line (--state-clock recording: right when\n"
     "both runs read one recording's time line, e.g. its first minute and then the rest, however long apart the\n"
     "runs were made) or on the wall clock (--state-clock wall).",
     estimate_opts, cmd_estimate},
    {"sweep", "linear critical speed over a conicity range", "[--from L --to L --n COUNT] [--table]",
     "Linear critical speed over a range of equivalent conicities (JSON, or a table with --table). With a bogie's or\n"
     "car's --config, by its eigenvalues at each conicity: the mode that goes first and the speed with the frame\n"
     "(bogie) or carbody (car) held beside it.", sweep_opts,
     cmd_sweep},
};

static void print_main_help(FILE *f) {
  fprintf(f,
          "usage: hunting COMMAND [options]\n\n"
          "Stability analysis of a railway wheelset against hunting (MODEL.md). Speeds are in km/h, stiffnesses\n"
          "in MN/m, everything else SI. Results are JSON on stdout (CSV for simulate); errors go to stderr\n"
          "with a non-zero exit status.\n\ncommands:\n");
  for (size_t i = 0; i < sizeof commands / sizeof commands[0]; ++i)
    fprintf(f, "  %-18s %s\n", commands[i].name, commands[i].brief);
  fprintf(f, "\n'hunting COMMAND --help' describes a command's options.\n"
             "example: hunting critical --kx 8.96 --ky 8.96 --conicity 0.1271\n");
}

int main(int argc, char **argv) {
  if (argc < 2 || strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0 || strcmp(argv[1], "help") == 0) {
    print_main_help(argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  for (size_t i = 0; i < sizeof commands / sizeof commands[0]; ++i) {
    const command *c = &commands[i];
    if (strcmp(argv[1], c->name) != 0) continue;
    /* --help (or -h) anywhere before "--" describes the command, whatever its options list */
    for (int k = 2; k < argc && strcmp(argv[k], "--") != 0; ++k)
      if (strcmp(argv[k], "--help") == 0 || strcmp(argv[k], "-h") == 0) {
        cli_print_help(stdout, c->name, c->usage, c->summary, c->opts);
        return 0;
      }
    cli_args args;
    const int positional = c->run == cmd_fit_conicity; /* the data file */
    if (cli_parse(c->name, argc - 1, argv + 1, c->opts, positional, &args)) return 2;
    if (cli_has(&args, "help")) {
      cli_print_help(stdout, c->name, c->usage, c->summary, c->opts);
      return 0;
    }
    const int rc = c->run(&args);
    /* output lost (a full disk, a closed pipe) is a failure, not a success with nothing written */
    if (fflush(stdout) != 0 || ferror(stdout)) {
      fprintf(stderr, "hunting %s: cannot write the output: %s\n", c->name, strerror(errno));
      return 1;
    }
    return rc;
  }
  fprintf(stderr, "hunting: unknown command '%s'\n\n", argv[1]);
  print_main_help(stderr);
  return 2;
}
