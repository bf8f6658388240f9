/* Track irregularity and speed profile driving the wheelset model (see excitation.h). */
#include "hunting_monitor/excitation.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "hunting_monitor/linear.h"
#include "fft.h"
#include "rng.h"

/* German high-speed alignment spectrum, low disturbance: S(W) = A Wc^2 / ((W^2 + Wr^2)(W^2 + Wc^2)). */
double hm_track_alignment_psd(double w) {
  const double A = 2.119e-7, wc = 0.8246, wr = 0.0206;
  return A * wc * wc / ((w * w + wr * wr) * (w * w + wc * wc));
}

enum { TRACK_LOG2_N = 18 };                 /* 262144 points */
static const double TRACK_DS_M = 0.1;      /* grid spacing: 30 points over the shortest 3 m wavelength */

struct hm_track_s {
  size_t n;
  double ds_m, length_m, rms_m;
  double *y;
};

double hm_track_spectrum_rms_m(double wl_min, double wl_max, double scale) {
  /* the integral of S(W) = A Wc^2 / ((W^2 + Wr^2)(W^2 + Wc^2)) in closed form (partial fractions) */
  const double A = 2.119e-7, wc = 0.8246, wr = 0.0206;
  const double w_lo = 2.0 * HM_PI / wl_max, w_hi = 2.0 * HM_PI / wl_min;
  const double k = A * wc * wc / (wc * wc - wr * wr);
  const double var = k * ((atan(w_hi / wr) - atan(w_lo / wr)) / wr - (atan(w_hi / wc) - atan(w_lo / wc)) / wc);
  return sqrt(fmax(scale * var, 0.0));
}

hm_status hm_track_create(double wl_min, double wl_max, double scale, uint64_t seed, hm_track *out) {
  if (!out || !(wl_min >= 0.2) || !(wl_max > wl_min) || !(wl_max <= 1000.0) || !(scale >= 0.0) || !isfinite(scale))
    return HM_EINVAL;
  const size_t n = (size_t)1 << TRACK_LOG2_N;
  hm_track t = calloc(1, sizeof *t);
  double *re = malloc(n * sizeof(double)), *im = malloc(n * sizeof(double));
  double *cw = malloc(n / 2 * sizeof(double)), *sw = malloc(n / 2 * sizeof(double));
  if (!t || !re || !im || !cw || !sw) {
    free(t);
    free(re);
    free(im);
    free(cw);
    free(sw);
    return HM_ENOMEM;
  }
  t->n = n;
  t->ds_m = TRACK_DS_M;
  t->length_m = (double)n * TRACK_DS_M;
  /* line k at W_k = 2 pi k / L with a complex Gaussian amplitude of variance S(W_k) dW scale: y = sum 2 Re(Y_k
   * e^{i W_k s}) has the spectrum's variance over the band; the inverse transform is the forward one conjugated */
  const double dw = 2.0 * HM_PI / t->length_m;
  uint64_t rng = seed * 0x2545F4914F6CDD1Dull + 7u;
  for (size_t k = 0; k < n; ++k) re[k] = im[k] = 0.0;
  for (size_t k = 1; k < n / 2; ++k) {
    const double w = dw * (double)k;
    if (w < 2.0 * HM_PI / wl_max || w > 2.0 * HM_PI / wl_min) continue;
    const double c = sqrt(scale * hm_track_alignment_psd(w) * dw) / 2.0;
    re[k] = 2.0 * c * hm_rng_gaussian(&rng);
    im[k] = -2.0 * c * hm_rng_gaussian(&rng); /* conjugated for the inverse */
  }
  hm_fft_twiddles(cw, sw, n);
  hm_fft(re, im, n, cw, sw, n);
  double ss = 0.0;
  for (size_t j = 0; j < n; ++j) ss += re[j] * re[j]; /* the real part of the conjugated result */
  t->rms_m = sqrt(ss / (double)n);
  t->y = re;
  free(im);
  free(cw);
  free(sw);
  *out = t;
  return HM_OK;
}

void hm_track_destroy(hm_track t) {
  if (!t) return;
  free(t->y);
  free(t);
}

double hm_track_at(const hm_track t, double s) {
  double u = fmod(s, t->length_m);
  if (u < 0.0) u += t->length_m;
  const double x = u / t->ds_m;
  const size_t i = (size_t)x % t->n;
  const double f = x - floor(x);
  return t->y[i] + f * (t->y[(i + 1) % t->n] - t->y[i]);
}

double hm_track_rms_m(const hm_track t) { return t ? t->rms_m : 0.0; }

int hm_speed_profile_valid(const double *t_s, const double *v_kmh, size_t n) {
  if (!t_s || !v_kmh || n < 1 || n > HM_SPEED_PROFILE_MAX) return 0;
  for (size_t k = 0; k < n; ++k)
    if (!(v_kmh[k] > 0.0) || !isfinite(v_kmh[k]) || !isfinite(t_s[k]) || (k == 0 ? t_s[0] != 0.0 : !(t_s[k] > t_s[k - 1])))
      return 0;
  return 1;
}

hm_status hm_excited_model_init_profile(hm_excited_model *em, const hm_vehicle *veh, const hm_track track,
                                        const double *t_s, const double *v_kmh, size_t n) {
  if (!em || !veh || !t_s || !v_kmh) return HM_EINVAL;
  if (!hm_speed_profile_valid(t_s, v_kmh, n)) return HM_EDOMAIN;
  hm_excited_model out;
  hm_status st = hm_model_init(&out.model, veh, hm_mps_from_kmh(v_kmh[0]));
  if (st != HM_OK) return st;
  out.track = track;
  out.n_profile = n;
  for (size_t k = 0; k < n; ++k) {
    out.profile_t_s[k] = t_s[k];
    out.profile_v_kmh[k] = v_kmh[k];
    out.profile_s_m[k] = k == 0 ? 0.0
                                : out.profile_s_m[k - 1] + 0.5 * hm_mps_from_kmh(v_kmh[k - 1] + v_kmh[k]) *
                                                               (t_s[k] - t_s[k - 1]);
  }
  *em = out;
  return HM_OK;
}

hm_status hm_excited_model_init(hm_excited_model *em, const hm_vehicle *veh, const hm_track track,
                                double v_start_kmh, double v_end_kmh, double ramp_s) {
  if (!em || !veh) return HM_EINVAL;
  if (!(v_start_kmh > 0.0) || !(v_end_kmh > 0.0) || !isfinite(v_start_kmh) || !isfinite(v_end_kmh) ||
      !(ramp_s >= 0.0) || !isfinite(ramp_s))
    return HM_EDOMAIN;
  const double t[2] = {0.0, ramp_s}, v[2] = {v_start_kmh, v_end_kmh};
  if (ramp_s == 0.0) return hm_excited_model_init_profile(em, veh, track, t, v + 1, 1);
  return hm_excited_model_init_profile(em, veh, track, t, v, 2);
}

/* The profile's segment holding t (k with t_k <= t < t_k+1), or n - 1 past its end. */
static size_t profile_segment(const hm_excited_model *em, double t) {
  size_t k = 0;
  while (k + 1 < em->n_profile && em->profile_t_s[k + 1] <= t) ++k;
  return k;
}

double hm_excited_speed_kmh(const hm_excited_model *em, double t) {
  if (t <= 0.0) return em->profile_v_kmh[0];
  const size_t k = profile_segment(em, t);
  if (k + 1 >= em->n_profile) return em->profile_v_kmh[em->n_profile - 1];
  const double f = (t - em->profile_t_s[k]) / (em->profile_t_s[k + 1] - em->profile_t_s[k]);
  return em->profile_v_kmh[k] + (em->profile_v_kmh[k + 1] - em->profile_v_kmh[k]) * f;
}

double hm_excited_distance_m(const hm_excited_model *em, double t) {
  if (t <= 0.0) return hm_mps_from_kmh(em->profile_v_kmh[0]) * t;
  const size_t k = profile_segment(em, t);
  const double dt = t - em->profile_t_s[k];
  return em->profile_s_m[k] + 0.5 * hm_mps_from_kmh(em->profile_v_kmh[k] + hm_excited_speed_kmh(em, t)) * dt;
}

hm_status hm_excited_rhs(double t, const double *x, double *dxdt, void *params) {
  hm_excited_model *em = (hm_excited_model *)params;
  em->model.speed_mps = hm_mps_from_kmh(hm_excited_speed_kmh(em, t));
  if (!em->track) return hm_model_rhs(t, x, dxdt, &em->model);
  /* the wheel-rail terms see y - y_t; evaluate them at the relative displacement and add the suspension part */
  const double yt = hm_track_at(em->track, hm_excited_distance_m(em, t));
  const double xr[4] = {x[0] - yt, x[1], x[2], x[3]};
  double fr[4];
  hm_status st = hm_model_rhs(t, xr, fr, &em->model);
  if (st != HM_OK) return st;
  /* hm_model_rhs used y_r in the suspension term -k_lat y as well: put y back there */
  const double d2 = fr[1] - em->model.coef.k_lat_s2 * yt;
  if (!isfinite(d2)) return HM_ENONFINITE;
  dxdt[0] = fr[0];
  dxdt[1] = d2;
  dxdt[2] = fr[2];
  dxdt[3] = fr[3];
  return HM_OK;
}
