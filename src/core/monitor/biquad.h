/* Private: second-order IIR sections (RBJ cookbook = bilinear transform pre-warped at the corner), shared by the
 * estimator's and the modal identification's filters. */
#ifndef HUNTING_MONITOR_BIQUAD_H
#define HUNTING_MONITOR_BIQUAD_H

#include <math.h>

#include "hunting_monitor/model.h"

typedef struct {
  double b0, b1, b2, a1, a2, z1, z2;
} hm_biquad;

/* Butterworth Q factors: order 4 = two sections, order 2 = one. */
static const double HM_BUTTERWORTH_Q4[2] = {0.54119610014619698, 1.3065629648763766};
static const double HM_BUTTERWORTH_Q2 = 0.70710678118654752;

/* High-pass (highpass != 0) or low-pass section with corner f0 [Hz] and quality q at sample rate fs [Hz]. */
static inline hm_biquad hm_biquad_design(int highpass, double f0, double q, double fs) {
  const double w0 = 2.0 * HM_PI * f0 / fs, cw = cos(w0), alpha = sin(w0) / (2.0 * q), a0 = 1.0 + alpha;
  hm_biquad b;
  b.b0 = (highpass ? (1.0 + cw) : (1.0 - cw)) / 2.0 / a0;
  b.b1 = (highpass ? -(1.0 + cw) : (1.0 - cw)) / a0;
  b.b2 = b.b0;
  b.a1 = -2.0 * cw / a0;
  b.a2 = (1.0 - alpha) / a0;
  b.z1 = b.z2 = 0.0;
  return b;
}

static inline void hm_biquad_clear(hm_biquad *f) { f->z1 = f->z2 = 0.0; }

/* Transposed direct form II. */
static inline double hm_biquad_step(hm_biquad *f, double x) {
  const double y = f->b0 * x + f->z1;
  f->z1 = f->b1 * x - f->a1 * y + f->z2;
  f->z2 = f->b2 * x - f->a2 * y;
  return y;
}

/* |H(e^{i theta})| at theta = 2 pi f / fs. */
static inline double hm_biquad_gain(const hm_biquad *f, double theta) {
  const double c1 = cos(theta), s1 = sin(theta), c2 = cos(2.0 * theta), s2 = sin(2.0 * theta);
  const double nr = f->b0 + f->b1 * c1 + f->b2 * c2, ni = -(f->b1 * s1 + f->b2 * s2);
  const double dr = 1.0 + f->a1 * c1 + f->a2 * c2, di = -(f->a1 * s1 + f->a2 * s2);
  return sqrt((nr * nr + ni * ni) / (dr * dr + di * di));
}

#endif
