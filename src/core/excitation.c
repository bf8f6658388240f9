/* Track irregularity and speed profile driving the wheelset model (see excitation.h). */
#include "hunting_monitor/excitation.h"

#include <math.h>
#include <string.h>

#include "hunting_monitor/linear.h"

/* German high-speed alignment spectrum, low disturbance: S(W) = A Wc^2 / ((W^2 + Wr^2)(W^2 + Wc^2)). */
static double alignment_psd(double w) {
  const double A = 2.119e-7, wc = 0.8246, wr = 0.0206;
  return A * wc * wc / ((w * w + wr * wr) * (w * w + wc * wc));
}

static double uniform01(uint64_t *s) { /* splitmix64 */
  uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return (double)(z >> 11) / 9007199254740992.0;
}

hm_status hm_irregularity_generate(hm_irregularity *irr, size_t n, double wl_min, double wl_max, double scale,
                                   uint64_t seed) {
  if (!irr || n < 1 || n > HM_IRREGULARITY_MAX_TERMS || !(wl_min > 0.0) || !(wl_max > wl_min) || !isfinite(wl_max) ||
      !(scale >= 0.0) || !isfinite(scale))
    return HM_EINVAL;
  hm_irregularity out;
  memset(&out, 0, sizeof out);
  out.n = n;
  const double w_lo = 2.0 * HM_PI / wl_max, w_hi = 2.0 * HM_PI / wl_min, dw = (w_hi - w_lo) / (double)n;
  uint64_t s = seed;
  for (size_t k = 0; k < n; ++k) {
    const double w = w_lo + ((double)k + 0.5) * dw;
    out.wavenumber_rad_m[k] = w;
    out.amplitude_m[k] = sqrt(2.0 * scale * alignment_psd(w) * dw); /* variance S dW per component */
    out.phase_rad[k] = 2.0 * HM_PI * uniform01(&s);
  }
  *irr = out;
  return HM_OK;
}

double hm_irregularity_at(const hm_irregularity *irr, double s_m) {
  double y = 0.0;
  for (size_t k = 0; k < irr->n; ++k) y += irr->amplitude_m[k] * sin(irr->wavenumber_rad_m[k] * s_m + irr->phase_rad[k]);
  return y;
}

hm_status hm_excited_model_init(hm_excited_model *em, const hm_vehicle *veh, const hm_irregularity *irr,
                                double v_start_kmh, double v_end_kmh, double ramp_s) {
  if (!em || !veh) return HM_EINVAL;
  if (!(v_start_kmh > 0.0) || !(v_end_kmh > 0.0) || !isfinite(v_start_kmh) || !isfinite(v_end_kmh) ||
      !(ramp_s >= 0.0) || !isfinite(ramp_s))
    return HM_EDOMAIN;
  hm_excited_model out;
  hm_status st = hm_model_init(&out.model, veh, hm_mps_from_kmh(v_start_kmh));
  if (st != HM_OK) return st;
  out.irr = irr;
  out.v_start_kmh = v_start_kmh;
  out.v_end_kmh = v_end_kmh;
  out.ramp_s = ramp_s;
  *em = out;
  return HM_OK;
}

double hm_excited_speed_kmh(const hm_excited_model *em, double t) {
  if (t >= em->ramp_s || em->ramp_s == 0.0) return em->v_end_kmh;
  if (t <= 0.0) return em->v_start_kmh;
  return em->v_start_kmh + (em->v_end_kmh - em->v_start_kmh) * t / em->ramp_s;
}

double hm_excited_distance_m(const hm_excited_model *em, double t) {
  const double v0 = hm_mps_from_kmh(em->v_start_kmh), v1 = hm_mps_from_kmh(em->v_end_kmh);
  if (em->ramp_s == 0.0) return v1 * t;
  const double tr = fmin(fmax(t, 0.0), em->ramp_s);
  return v0 * tr + 0.5 * (v1 - v0) * tr * tr / em->ramp_s + v1 * fmax(t - em->ramp_s, 0.0);
}

hm_status hm_excited_rhs(double t, const double *x, double *dxdt, void *params) {
  hm_excited_model *em = (hm_excited_model *)params;
  em->model.speed_mps = hm_mps_from_kmh(hm_excited_speed_kmh(em, t));
  if (!em->irr) return hm_model_rhs(t, x, dxdt, &em->model);
  /* the wheel-rail terms see y - y_t; evaluate them at the relative displacement and add the suspension part */
  const double yt = hm_irregularity_at(em->irr, hm_excited_distance_m(em, t));
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
