/* car.h: the whole vehicle of issue #28. Checked against the bogie (the carbody held: its eigenvalues each twice and
 * its critical speed), its analytic Jacobian against central differences of its right-hand side, and its critical
 * speed by eigenvalues against the growth rate of a time simulation (the tests' own RK4 of the right-hand side) on
 * both sides of it (the wheelsets' mode of the default car). A carbody mode: without secondary lateral damping at
 * conicity 0.03 the default car's carbody sway on its air springs (the closed form sqrt(2 Ksy / mc) / 2 pi) is the
 * mode that crosses, if only just (its real part moves by about 1e-5 1/s per km/h there: MODEL.md's geometric term
 * ties each wheelset to the track with 3.15 MN/m). And carbody hunting: config/car_carbody_hunting.yaml (no such
 * term, a lighter carbody on stiffer air springs, a weaker lateral damper) at conicity 0.02, where
 * the carbody's mode crosses at about 195 km/h and 0.76 Hz: the speed against the simulation's growth rate either
 * side, the frequency against the simulation's own oscillation. The carbody's roll (config/car_roll.yaml's): its
 * Jacobian against differences; without the secondary's lateral spring and damper the roll alone, whose eigenvalues
 * are the closed form's of Ix s^2 + 2 cr s + 2 kr - mc g h (the weight's term with it), the other 30 the rigid car's;
 * the lower and upper sway against the carbody on its secondary over fixed frames (a 2 x 2 closed form); the rolling
 * carbody-hunting car's critical speed against the simulation's growth rate. */
#include <complex.h>
#include <string.h>

#include "hm_test.h"
#include "system_checks.h"
#include "hunting_monitor/car.h"
#include "hunting_monitor/config.h"
#include "hunting_monitor/linear.h"

static void car_at(double lambda0, double csy, int held, hm_car_model *m, hm_system *sys) {
  hm_car c;
  hm_car_default(&c);
  c.bogie.secondary_lat_damping_n_s_m = csy;
  HM_CHECK(hm_vehicle_set_conicity_at_zero(&c.bogie.wheelset, lambda0) == HM_OK, "conicity");
  HM_CHECK(hm_car_model_init(m, &c, held, sys) == HM_OK, "init");
}

static void held_carbody_is_two_bogies(void) {
  hm_car_model m;
  hm_system sys, bsys;
  car_at(0.1358, 30e3, 1, &m, &sys);
  hm_bogie_model bm;
  HM_CHECK(hm_bogie_model_init(&bm, &m.car.bogie, 0, &bsys) == HM_OK, "bogie");
  HM_CHECK(sys.dim == HM_CAR_HELD_DIM, "dimension");
  const double speeds[] = {300.0, 540.0};
  for (int k = 0; k < 2; ++k) {
    hm_system_spectrum s, b;
    const double v = hm_mps_from_kmh(speeds[k]);
    HM_CHECK(hm_system_spectrum_at(&sys, v, &s) == HM_OK && hm_system_spectrum_at(&bsys, v, &b) == HM_OK, "spectra");
    int used[HM_BOGIE_DIM] = {0};
    for (size_t i = 0; i < s.dim; ++i) {
      size_t best = 0;
      double d_best = INFINITY;
      for (size_t q = 0; q < b.dim; ++q) {
        const double d = hypot(s.re[i] - b.re[q], s.im[i] - b.im[q]);
        if (d < d_best) d_best = d, best = q;
      }
      used[best]++;
      HM_CHECK(d_best <= 1e-8 * hypot(b.re[best], b.im[best]), "eigenvalue %zu off by %.3g", i, d_best);
    }
    for (size_t q = 0; q < b.dim; ++q) HM_CHECK(used[q] == 2, "bogie eigenvalue %zu found %d times", q, used[q]);
  }
  hm_system_critical_options opt;
  hm_system_critical_options_default(&opt);
  double vc = 0.0, vb = 0.0;
  HM_CHECK(hm_system_critical_speed(&sys, &opt, &vc, NULL) == HM_OK, "car held");
  HM_CHECK(hm_system_critical_speed(&bsys, &opt, &vb, NULL) == HM_OK, "bogie");
  HM_CHECK_REL(vc, vb, 1e-9, "the held carbody's critical speed is the bogie's");
}

static void jacobian_against_differences(void) {
  for (int held = 0; held <= 1; ++held) {
    hm_car_model m;
    hm_system sys;
    car_at(0.1358, 30e3, held, &m, &sys);
    double x[HM_CAR_DIM];
    for (size_t i = 0; i < HM_CAR_DIM; ++i) { /* in the nonlinear range: 2-6 mm, 0.02-0.06 m/s, the dampers 0.2 mm */
      const size_t k = i < 26 ? i % 13 : i - 26;
      x[i] = (k == 12 ? 2e-4 : k % 2 ? 0.02 : 0.002) * (i % 3 ? 1.0 : -0.7) * (1.0 + 0.07 * (double)i);
    }
    check_jacobian(&sys, hm_mps_from_kmh(380.0), x, held ? "carbody held" : "carbody free");
  }
}

static void critical_speed_against_simulation(void) {
  hm_car_model m;
  hm_system sys;
  car_at(0.1358, 30e3, 0, &m, &sys);
  double vc = 0.0;
  hm_system_spectrum s;
  check_critical_against_simulation(&sys, &vc, &s);
  HM_CHECK(s.dominant_body == 0, "the wheelsets' mode");
}

static void carbody_mode(void) {
  hm_car_model m;
  hm_system sys;
  car_at(0.03, 0.0, 0, &m, &sys);
  hm_system_critical_options opt;
  hm_system_critical_options_default(&opt);
  double vc = 0.0;
  hm_system_spectrum s;
  HM_CHECK(hm_system_critical_speed(&sys, &opt, &vc, &s) == HM_OK, "critical");
  printf("  conicity 0.03, no lateral damper: critical %.2f km/h at %.3f Hz, the mode's energy %.3f in the carbody\n",
         hm_kmh_from_mps(vc), s.frequency_hz, s.body_share[2]);
  HM_CHECK(s.dominant_body == 2 && s.body_share[2] > 0.99, "the carbody's mode");
  const double f_sway = sqrt(2.0 * m.car.bogie.secondary_lat_stiffness_n_m / m.car.carbody_mass_kg) / (2.0 * HM_PI);
  HM_CHECK_DELTA(s.frequency_hz, f_sway, 0.03 * f_sway, "at the carbody's sway frequency on the air springs");
}

/* The frequency [Hz] of the carbody's lateral motion in a simulation at v (the tests' RK4 at 1 ms from a disturbance
 * of every displacement): up-crossings of y_carbody over span_s after settle_s, renormalised as it grows. */
static double carbody_frequency(const hm_system *sys, double v, double settle_s, double span_s) {
  double x[HM_CAR_DIM] = {0.0};
  for (size_t i = 0; i < sys->dim; i += 2) x[i] = 1e-6 * (i % 4 ? 1.0 : -0.6);
  const size_t yc = 2 * HM_BOGIE_DIM; /* the carbody's lateral displacement (car.h's state order) */
  const double h = 1e-3;
  double prev = x[yc], first = -1.0, last = -1.0;
  long ups = 0;
  for (long s = 1; s <= (long)((settle_s + span_s) / h); ++s) {
    system_rk4_step(sys, v, x, h);
    if (fabs(x[yc]) > 1e-3)
      for (size_t i = 0; i < sys->dim; ++i) x[i] *= 1e-3;
    const double t = (double)s * h;
    if (t > settle_s && prev < 0.0 && x[yc] >= 0.0) {
      const double tc = t - h * x[yc] / (x[yc] - prev);
      if (first < 0.0) first = tc;
      last = tc;
      ++ups;
    }
    prev = x[yc];
  }
  return ups > 1 ? (double)(ups - 1) / (last - first) : 0.0;
}

static void add_roll(hm_car *c);

/* config/car_carbody_hunting.yaml (with roll: add_roll's) at a conicity into *m, *sys; its critical speed against the
 * simulation's growth rate either side (system_checks.h). */
static void carbody_hunting_car(double lambda0, int roll, hm_car_model *m, hm_system *sys, double *vc,
                                hm_system_spectrum *s) {
  hm_car c;
  char name[HM_VEHICLE_NAME_MAX], err[256] = "";
  HM_CHECK(hm_config_load_car(HM_SOURCE_DIR "/config/car_carbody_hunting.yaml", &c, name, err, sizeof err) == HM_OK,
           "load: %s", err);
  if (roll) add_roll(&c);
  HM_CHECK(hm_vehicle_set_conicity_at_zero(&c.bogie.wheelset, lambda0) == HM_OK, "conicity");
  HM_CHECK(hm_car_model_init(m, &c, 0, sys) == HM_OK, "init");
  check_critical_against_simulation(sys, vc, s);
}

static void carbody_hunting_at_low_conicity(void) {
  hm_car_model m;
  hm_system sys;
  double vc = 0.0;
  hm_system_spectrum s;
  carbody_hunting_car(0.02, 0, &m, &sys, &vc, &s);
  HM_CHECK(s.dominant_body == 2 && s.body_share[2] > 0.9, "the carbody's mode");
  HM_CHECK(hm_kmh_from_mps(vc) > 150.0 && hm_kmh_from_mps(vc) < 250.0, "at a speed the vehicle runs");
  const double f_sim = carbody_frequency(&sys, vc, 60.0, 120.0);
  printf("  the simulation's carbody oscillates at %.4f Hz\n", f_sim);
  HM_CHECK_REL(f_sim, s.frequency_hz, 2e-3, "the simulation's frequency is the eigenvalue's");
}

/* config/car_roll.yaml's roll on a car c. */
static void add_roll(hm_car *c) {
  c->carbody_roll_inertia_kg_m2 = 6.4e4;
  c->carbody_cg_height_m = 0.9;
  c->secondary_roll_stiffness_n_m_rad = 2.6e6;
  c->secondary_roll_damping_n_m_s_rad = 6.76e4;
}

static void roll_jacobian_against_differences(void) {
  hm_car c;
  hm_car_default(&c);
  add_roll(&c);
  HM_CHECK(hm_vehicle_set_conicity_at_zero(&c.bogie.wheelset, 0.1358) == HM_OK, "conicity");
  hm_car_model m;
  hm_system sys;
  HM_CHECK(hm_car_model_init(&m, &c, 0, &sys) == HM_OK && sys.dim == HM_CAR_DIM, "init");
  double x[HM_CAR_DIM];
  for (size_t i = 0; i < HM_CAR_DIM; ++i) {
    const size_t k = i < 26 ? i % 13 : i - 26;
    x[i] = (k == 12 ? 2e-4 : k % 2 ? 0.02 : 0.002) * (i % 3 ? 1.0 : -0.7) * (1.0 + 0.07 * (double)i);
  }
  check_jacobian(&sys, hm_mps_from_kmh(380.0), x, "rolling carbody");
}

/* Every eigenvalue of a within tol (relative) of one of b's or of the pair p, each of b's and p's used once. */
static void spectrum_is_union(const hm_system_spectrum *a, const hm_system_spectrum *b, double complex p, double tol,
                              const char *what) {
  int used_b[HM_SYSTEM_MAX_DIM] = {0}, used_p[2] = {0};
  HM_CHECK(a->dim == b->dim + 2, "%s: dimensions %zu, %zu", what, a->dim, b->dim);
  for (size_t i = 0; i < a->dim; ++i) {
    const double complex z = a->re[i] + I * a->im[i];
    size_t best = 0;
    double d_best = INFINITY;
    for (size_t q = 0; q < b->dim + 2; ++q) {
      const double complex w = q < b->dim ? b->re[q] + I * b->im[q] : q == b->dim ? p : conj(p);
      const int free = q < b->dim ? !used_b[q] : !used_p[q - b->dim];
      if (free && cabs(z - w) < d_best) d_best = cabs(z - w), best = q;
    }
    if (best < b->dim) used_b[best] = 1;
    else used_p[best - b->dim] = 1;
    HM_CHECK(d_best <= tol * fmax(1.0, cabs(z)), "%s: eigenvalue %zu (%.6g%+.6gi) off by %.3g", what, i, a->re[i],
             a->im[i], d_best);
  }
  HM_CHECK(used_p[0] && used_p[1], "%s: the closed form's pair", what);
}

static void roll_alone_closed_form(void) {
  const double v = hm_mps_from_kmh(300.0), g = HM_CAR_GRAVITY_MPS2;
  for (int weight = 0; weight <= 1; ++weight) {
    /* no coupling: the centre of mass at the secondary's level (h = 0), or no lateral spring and damper */
    hm_car rigid;
    hm_car_default(&rigid);
    if (weight) rigid.bogie.secondary_lat_stiffness_n_m = rigid.bogie.secondary_lat_damping_n_s_m = 0.0;
    hm_car rolling = rigid;
    add_roll(&rolling);
    if (!weight) rolling.carbody_cg_height_m = 0.0;
    hm_car_model mr, mb;
    hm_system sr, sb;
    HM_CHECK(hm_car_model_init(&mr, &rolling, 0, &sr) == HM_OK && hm_car_model_init(&mb, &rigid, 0, &sb) == HM_OK,
             "init");
    hm_system_spectrum a, b;
    HM_CHECK(hm_system_spectrum_at(&sr, v, &a) == HM_OK && hm_system_spectrum_at(&sb, v, &b) == HM_OK, "spectra");
    const double ix = rolling.carbody_roll_inertia_kg_m2, cr = 2.0 * rolling.secondary_roll_damping_n_m_s_rad;
    const double kr = 2.0 * rolling.secondary_roll_stiffness_n_m_rad -
                      rolling.carbody_mass_kg * g * rolling.carbody_cg_height_m;
    const double complex p = (-cr + csqrt(cr * cr - 4.0 * ix * kr)) / (2.0 * ix);
    printf("  %s: roll %.4f Hz, %.4f 1/s\n", weight ? "no lateral secondary, h 0.9 m" : "h 0", cimag(p) / (2 * HM_PI),
           creal(p));
    spectrum_is_union(&a, &b, p, 1e-8, weight ? "no lateral secondary" : "h = 0");
  }
}

/* The lower and upper sway: the carbody on its secondary (lateral 2 Ksy at h, roll 2 kr - mc g h) over frames held,
 * against the car's, whose frames sit on primary springs 70 times stiffer than the secondary's: within 3%. */
static void sway_modes(void) {
  hm_car c;
  hm_car_default(&c);
  add_roll(&c);
  hm_car_model m;
  hm_system sys;
  HM_CHECK(hm_car_model_init(&m, &c, 0, &sys) == HM_OK, "init");
  const double ksy = 2.0 * c.bogie.secondary_lat_stiffness_n_m, h = c.carbody_cg_height_m, mc = c.carbody_mass_kg;
  const double ix = c.carbody_roll_inertia_kg_m2;
  const double k11 = ksy / mc, k12 = ksy * h / sqrt(mc * ix),
               k22 = (ksy * h * h + 2.0 * c.secondary_roll_stiffness_n_m_rad - mc * HM_CAR_GRAVITY_MPS2 * h) / ix;
  const double mean = 0.5 * (k11 + k22), dev = sqrt(0.25 * (k11 - k22) * (k11 - k22) + k12 * k12);
  const double f_lower = sqrt(mean - dev) / (2.0 * HM_PI), f_upper = sqrt(mean + dev) / (2.0 * HM_PI);
  hm_system_spectrum s;
  HM_CHECK(hm_system_spectrum_at(&sys, hm_mps_from_kmh(300.0), &s) == HM_OK, "spectrum");
  const double want[2] = {f_lower, f_upper};
  for (int k = 0; k < 2; ++k) {
    double best = INFINITY;
    for (size_t i = 0; i < s.dim; ++i)
      if (fabs(s.im[i] / (2.0 * HM_PI) - want[k]) < fabs(best - want[k])) best = s.im[i] / (2.0 * HM_PI);
    printf("  %s sway: %.4f Hz (the closed form over held frames %.4f Hz)\n", k ? "upper" : "lower", best, want[k]);
    HM_CHECK_REL(best, want[k], 0.03, k ? "upper sway" : "lower sway");
  }
}

static void rolling_carbody_hunting(void) {
  hm_car_model m;
  hm_system sys;
  double vc = 0.0;
  hm_system_spectrum s;
  carbody_hunting_car(0.01, 1, &m, &sys, &vc, &s);
  HM_CHECK(s.dominant_body == 2, "the carbody's mode");
}

static void bad_parameters(void) {
  hm_car c;
  hm_car_default(&c);
  char why[160] = "";
  HM_CHECK(hm_car_validate(&c, why, sizeof why) == HM_OK, "defaults: %s", why);
  c.carbody_mass_kg = -1.0;
  HM_CHECK(hm_car_validate(&c, why, sizeof why) == HM_EDOMAIN &&
               strcmp(why, "car.carbody_mass_kg: must be > 0 (got -1)") == 0, "message: %s", why);
  hm_car_default(&c);
  c.bogie.frame_mass_kg = NAN;
  HM_CHECK(hm_car_validate(&c, why, sizeof why) == HM_EDOMAIN && strstr(why, "bogie.frame_mass_kg"), "%s", why);
  hm_car_default(&c);
  add_roll(&c);
  HM_CHECK(hm_car_validate(&c, why, sizeof why) == HM_OK, "with roll: %s", why);
  c.secondary_roll_stiffness_n_m_rad = 0.5 * c.carbody_mass_kg * HM_CAR_GRAVITY_MPS2 * c.carbody_cg_height_m * 0.99;
  HM_CHECK(hm_car_validate(&c, why, sizeof why) == HM_EDOMAIN && strstr(why, "car.roll.stiffness_n_m_rad: must exceed"),
           "a carbody its springs cannot hold up: %s", why);
  hm_car_model m;
  hm_system sys;
  HM_CHECK(hm_car_model_init(&m, &c, 0, &sys) == HM_EDOMAIN, "no model of it");
}

int main(void) {
  HM_RUN(held_carbody_is_two_bogies);
  HM_RUN(jacobian_against_differences);
  HM_RUN(critical_speed_against_simulation);
  HM_RUN(carbody_mode);
  HM_RUN(carbody_hunting_at_low_conicity);
  HM_RUN(roll_jacobian_against_differences);
  HM_RUN(roll_alone_closed_form);
  HM_RUN(sway_modes);
  HM_RUN(rolling_carbody_hunting);
  HM_RUN(bad_parameters);
  HM_TEST_EXIT();
}
