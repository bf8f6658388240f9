/* The whole vehicle: a carbody on two bogies (see car.h). */
#include "hunting_monitor/car.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "validate.h"

enum { NB = HM_BOGIE_DIM, YC = 2 * HM_BOGIE_DIM }; /* states per bogie; the carbody's first state */

void hm_car_default(hm_car *car) {
  memset(car, 0, sizeof *car);
  hm_bogie_default(&car->bogie);
  car->carbody_mass_kg = 35000.0;
  car->carbody_yaw_inertia_kg_m2 = 1.8e6;
  car->half_bogie_distance_m = 8.75;
}

/* The weight's term of the roll (car.h), mc g h [N m/rad], and the roll stiffness on both bogies less it. */
static double weight_term(const hm_car *car) {
  return car->carbody_mass_kg * HM_CAR_GRAVITY_MPS2 * car->carbody_cg_height_m;
}
static double roll_stiffness(const hm_car *car) { return 2.0 * car->secondary_roll_stiffness_n_m_rad - weight_term(car); }

hm_status hm_car_validate(const hm_car *car, char *why, size_t why_len) {
  if (!car) {
    (void)hm_reject(why, why_len, "car", "NULL pointer", 0.0);
    return HM_EINVAL;
  }
  hm_status st = hm_bogie_validate(&car->bogie, why, why_len);
  if (st != HM_OK) return st;
  /* a carbody's roll inertia is 5e4-2e5 kg m^2 (0: no roll); far outside it the roll's pulsation sqrt(2 kr / Ix)
   * leaves the simulations' explicit integrator steps of nanoseconds */
  const hm_field_check checks[] = {
      {"car.carbody_mass_kg", car->carbody_mass_kg, HM_RULE_POSITIVE, 0.0, 0.0},
      {"car.carbody_yaw_inertia_kg_m2", car->carbody_yaw_inertia_kg_m2, HM_RULE_POSITIVE, 0.0, 0.0},
      {"car.half_bogie_distance_m", car->half_bogie_distance_m, HM_RULE_POSITIVE, 0.0, 0.0},
      {"car.roll.inertia_kg_m2", car->carbody_roll_inertia_kg_m2, HM_RULE_OFF_OR_RANGE, 1e3, 1e7},
      {"car.roll.cg_height_m", car->carbody_cg_height_m, HM_RULE_RANGE, 0.0, 5.0},
      {"car.roll.stiffness_n_m_rad", car->secondary_roll_stiffness_n_m_rad, HM_RULE_RANGE, 0.0, 1e8},
      {"car.roll.damping_n_m_s_rad", car->secondary_roll_damping_n_m_s_rad, HM_RULE_RANGE, 0.0, 1e7},
  };
  if ((st = hm_check_fields(checks, sizeof checks / sizeof checks[0], why, why_len)) != HM_OK) return st;
  if (!(car->carbody_roll_inertia_kg_m2 > 0.0)) return HM_OK;
  if (!(roll_stiffness(car) > 0.0)) {
    char reason[96];
    snprintf(reason, sizeof reason, "must exceed mc g h / 2 = %.6g (the carbody's weight tips it over)",
             0.5 * weight_term(car));
    return hm_reject(why, why_len, "car.roll.stiffness_n_m_rad", reason, car->secondary_roll_stiffness_n_m_rad);
  }
  return HM_OK;
}

static const char *const CAR_BODIES[] = {"wheelsets", "bogie frame", "carbody"};

static size_t car_dim(const hm_car_model *m) {
  return m->carbody_held ? HM_CAR_HELD_DIM : m->rolls ? HM_CAR_DIM : HM_CAR_RIGID_DIM;
}

static hm_status sys_rhs(const void *model, double v, const double *x, double *dx) {
  return hm_car_rhs((const hm_car_model *)model, v, x, NULL, dx);
}
static hm_status sys_jac(const void *model, double v, const double *x, double *jac) {
  return hm_car_jacobian((const hm_car_model *)model, v, x, jac);
}
static hm_status sys_dfdv(const void *model, double v, const double *x, double *dfdv) {
  return hm_car_dfdv((const hm_car_model *)model, v, x, dfdv);
}
static hm_status sys_rhs_track(const void *model, double v, const double *x, const double *yt, double *dx) {
  return hm_car_rhs((const hm_car_model *)model, v, x, yt, dx);
}

hm_status hm_car_sensor(const hm_car_model *m, const char *where, hm_sensor_point *out) {
  if (!m || !where || !out) return HM_EINVAL;
  if (strcmp(where, "carbody") == 0) {
    if (m->carbody_held) return HM_EINVAL;
    *out = (hm_sensor_point){2, {YC + 1, YC + 3, 0, 0}, {1.0, m->car.half_bogie_distance_m, 0.0, 0.0}};
    return HM_OK;
  }
  return hm_bogie_sensor(&m->bogie, where, out); /* the leading bogie's states come first */
}

hm_status hm_car_model_init(hm_car_model *m, const hm_car *car, int carbody_held, hm_system *sys) {
  if (!m || !car || !sys) return HM_EINVAL;
  hm_status st = hm_car_validate(car, NULL, 0);
  if (st != HM_OK) return st;
  hm_car_model w;
  memset(&w, 0, sizeof w);
  w.car = *car;
  w.carbody_held = carbody_held != 0;
  hm_system bogie_sys;
  if ((st = hm_bogie_model_init(&w.bogie, &car->bogie, 0, &bogie_sys)) != HM_OK) return st;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < NB; ++i) {
      w.inertia[NB * j + i] = w.bogie.inertia[i];
      w.scale[NB * j + i] = w.bogie.scale[i];
      w.body[NB * j + i] = w.bogie.body[i];
    }
  w.rolls = car->carbody_roll_inertia_kg_m2 > 0.0;
  const double car_inertia[6] = {0.0, car->carbody_mass_kg, 0.0, car->carbody_yaw_inertia_kg_m2, 0.0,
                                 car->carbody_roll_inertia_kg_m2};
  for (int i = 0; i < (w.rolls ? 6 : 4); ++i) {
    w.inertia[YC + i] = car_inertia[i];
    w.scale[YC + i] = i % 2 ? 0.1 : 1e-3;
    w.body[YC + i] = 2;
  }
  const double a = car->half_bogie_distance_m, b = car->bogie.half_wheelbase_m;
  w.x_m[0] = a + b, w.x_m[1] = a - b, w.x_m[2] = -a + b, w.x_m[3] = -a - b;
  w.y_state[0] = 0, w.y_state[1] = 4, w.y_state[2] = NB, w.y_state[3] = NB + 4;
  *m = w;
  *sys = (hm_system){car_dim(m), sys_rhs, sys_jac, sys_dfdv, m, 3, CAR_BODIES,
                     m->body, m->inertia, m->scale, 0, 1, bogie_sys.odd, sys_rhs_track, 4, m->x_m, m->y_state};
  return HM_OK;
}

hm_status hm_car_rhs(const hm_car_model *m, double v, const double *x, const double *y_track_m, double *dxdt) {
  const hm_car *car = &m->car;
  const double xs[2] = {car->half_bogie_distance_m, -car->half_bogie_distance_m};
  const double *c = x + YC;
  /* the carbody's lateral motion at the secondary's level: its roll's part */
  const double h = car->carbody_cg_height_m, roll = m->rolls ? h * c[4] : 0.0, roll_rate = m->rolls ? h * c[5] : 0.0;
  double dx[HM_CAR_DIM], fy = 0.0, mz = 0.0;
  for (int j = 0; j < 2; ++j) {
    double att[4] = {0.0, 0.0, 0.0, 0.0}, f, mo;
    if (!m->carbody_held)
      att[0] = c[0] + xs[j] * c[2] + roll, att[1] = c[1] + xs[j] * c[3] + roll_rate, att[2] = c[2], att[3] = c[3];
    hm_status st = hm_bogie_rhs_under(&m->bogie, v, x + NB * j, y_track_m ? y_track_m + 2 * j : NULL, att,
                                      dx + NB * j, &f, &mo);
    if (st != HM_OK) return st;
    fy += f;
    mz += xs[j] * f + mo;
  }
  size_t n = HM_CAR_HELD_DIM;
  if (!m->carbody_held) {
    dx[YC] = c[1];
    dx[YC + 1] = fy / car->carbody_mass_kg;
    dx[YC + 2] = c[3];
    dx[YC + 3] = mz / car->carbody_yaw_inertia_kg_m2;
    if (m->rolls) {
      dx[YC + 4] = c[5];
      dx[YC + 5] = (h * fy - roll_stiffness(car) * c[4] - 2.0 * car->secondary_roll_damping_n_m_s_rad * c[5]) /
                   car->carbody_roll_inertia_kg_m2;
    }
    n = car_dim(m);
    if (!isfinite(dx[YC + 1]) || !isfinite(dx[YC + 3]) || (m->rolls && !isfinite(dx[YC + 5]))) return HM_ENONFINITE;
  }
  memcpy(dxdt, dx, n * sizeof(double));
  return HM_OK;
}

/* The Jacobian's entries of the roll (car.h): h phic in each secondary's lateral motion, the roll's own row. */
static void roll_rows(const hm_car_model *m, double *J, size_t n) {
  const hm_car *car = &m->car;
  const hm_bogie *b = &car->bogie;
  const double mf = b->frame_mass_kg, mc = car->carbody_mass_kg, ic = car->carbody_yaw_inertia_kg_m2;
  const double ix = car->carbody_roll_inertia_kg_m2, h = car->carbody_cg_height_m;
  const double ksy = b->secondary_lat_stiffness_n_m, csy = b->secondary_lat_damping_n_s_m;
  const double xs[2] = {car->half_bogie_distance_m, -car->half_bogie_distance_m};
  const size_t P = YC + 4, PD = YC + 5;
#define AT(i, j) J[n * (size_t)(i) + (size_t)(j)]
  AT(P, PD) = 1.0;
  AT(PD, P) = -roll_stiffness(car) / ix;
  AT(PD, PD) = -2.0 * car->secondary_roll_damping_n_m_s_rad / ix;
  for (int j = 0; j < 2; ++j) {
    const int o = NB * j;
    /* F_j = Ksy (yf - yc - x_j psic - h phic) + Csy (...)': its dependence on the roll, and the roll's on it */
    AT(o + 9, P) = ksy * h / mf;
    AT(o + 9, PD) = csy * h / mf;
    AT(YC + 1, P) -= ksy * h / mc;
    AT(YC + 1, PD) -= csy * h / mc;
    AT(YC + 3, P) -= xs[j] * ksy * h / ic;
    AT(YC + 3, PD) -= xs[j] * csy * h / ic;
    AT(PD, o + 8) = h * ksy / ix;
    AT(PD, o + 9) = h * csy / ix;
    AT(PD, YC) -= h * ksy / ix;
    AT(PD, YC + 1) -= h * csy / ix;
    AT(PD, YC + 2) -= h * xs[j] * ksy / ix;
    AT(PD, YC + 3) -= h * xs[j] * csy / ix;
    AT(PD, P) -= h * h * ksy / ix;
    AT(PD, PD) -= h * h * csy / ix;
  }
#undef AT
}

hm_status hm_car_jacobian(const hm_car_model *m, double v, const double *x, double *jac) {
  const hm_car *car = &m->car;
  const hm_bogie *b = &car->bogie;
  const size_t n = car_dim(m);
  const double xs[2] = {car->half_bogie_distance_m, -car->half_bogie_distance_m};
  double J[HM_CAR_DIM * HM_CAR_DIM], block[NB * NB];
  memset(J, 0, sizeof J);
#define AT(i, j) J[n * (size_t)(i) + (size_t)(j)]
  for (int j = 0; j < 2; ++j) {
    hm_status st = hm_bogie_jacobian(&m->bogie, v, x + NB * j, block);
    if (st != HM_OK) return st;
    for (int r = 0; r < NB; ++r)
      for (int q = 0; q < NB; ++q) AT(NB * j + r, NB * j + q) = block[NB * r + q];
  }
  if (!m->carbody_held) {
    const double mf = b->frame_mass_kg, jf = b->frame_yaw_inertia_kg_m2, mc = car->carbody_mass_kg;
    const double ic = car->carbody_yaw_inertia_kg_m2, ksy = b->secondary_lat_stiffness_n_m;
    const double csy = b->secondary_lat_damping_n_s_m, dd = b->yaw_damper_half_distance_m;
    const double kd = b->yaw_damper_stiffness_n_m, cd = b->yaw_damper_damping_n_s_m;
    const double kyaw = 2.0 * b->airspring_long_stiffness_n_m * b->airspring_half_distance_m *
                            b->airspring_half_distance_m + 2.0 * dd * dd * kd;
    AT(YC, YC + 1) = 1.0;
    AT(YC + 2, YC + 3) = 1.0;
    for (int j = 0; j < 2; ++j) {
      const int o = NB * j;
      /* the frame's rows: its secondary forces follow the carbody's motion at the bogie centre */
      AT(o + 9, YC) = ksy / mf;
      AT(o + 9, YC + 1) = csy / mf;
      AT(o + 9, YC + 2) = ksy * xs[j] / mf;
      AT(o + 9, YC + 3) = csy * xs[j] / mf;
      AT(o + 11, YC + 2) = kyaw / jf;
      AT(o + 12, YC + 2) = -kd * dd / cd;
      /* the carbody's rows: F_j = Ksy (yf - yc - x_j psic) + Csy (yf' - ...), M_j = kyaw (psif - psic) - 2 dd kd u */
      AT(YC + 1, o + 8) = ksy / mc;
      AT(YC + 1, o + 9) = csy / mc;
      AT(YC + 1, YC) -= ksy / mc;
      AT(YC + 1, YC + 1) -= csy / mc;
      AT(YC + 1, YC + 2) -= ksy * xs[j] / mc;
      AT(YC + 1, YC + 3) -= csy * xs[j] / mc;
      AT(YC + 3, o + 8) = xs[j] * ksy / ic;
      AT(YC + 3, o + 9) = xs[j] * csy / ic;
      AT(YC + 3, o + 10) = kyaw / ic;
      AT(YC + 3, o + 12) = -2.0 * dd * kd / ic;
      AT(YC + 3, YC) -= xs[j] * ksy / ic;
      AT(YC + 3, YC + 1) -= xs[j] * csy / ic;
      AT(YC + 3, YC + 2) -= (xs[j] * xs[j] * ksy + kyaw) / ic;
      AT(YC + 3, YC + 3) -= xs[j] * xs[j] * csy / ic;
    }
    if (m->rolls) roll_rows(m, J, n);
  }
#undef AT
  memcpy(jac, J, n * n * sizeof(double));
  return HM_OK;
}

hm_status hm_car_dfdv(const hm_car_model *m, double v, const double *x, double *dfdv) {
  const size_t n = car_dim(m);
  for (size_t i = 0; i < n; ++i) dfdv[i] = 0.0;
  for (int j = 0; j < 2; ++j) {
    hm_status st = hm_bogie_dfdv(&m->bogie, v, x + NB * j, dfdv + NB * j);
    if (st != HM_OK) return st;
  }
  return HM_OK;
}
