/* The identification's spectral model and its Whittle fit (src/core/monitor/whittle.h, private) against spectra known in
 * closed form: a periodogram equal to the model's own spectrum at known parameters has Whittle's optimum exactly
 * there (d/dtheta sum(ln S + I/S) = sum(1 - I/S) d ln S / dtheta = 0 at S = I), so the scoring must return them from
 * a start away from them; and the pair's term holds its power whatever its damping (the area of a Lorentzian). */
#include <stdint.h>
#include <string.h>

#include "hm_test.h"
#include "hunting_monitor/model.h"

#include "whittle.h" /* private to the core */

enum { NB_MAX = 1024 };

/* The bins of a 40 s window decimated to 100 Hz and zero-padded to 4096 points, over 6-22 Hz, and the periodogram of
 * theta's own spectrum there. */
typedef struct {
  double w[NB_MAX], u[NB_MAX], p[NB_MAX];
  hm_whittle_data d;
} bins;

static void make_bins(bins *b, const double *theta, unsigned poles) {
  const double df = 100.0 / 4096.0, w_ref = 2.0 * HM_PI * 14.0;
  size_t n = 0;
  for (size_t k = (size_t)ceil(6.0 / df); (double)k * df <= 22.0 && n < NB_MAX; ++k, ++n) {
    b->w[n] = 2.0 * HM_PI * (double)k * df;
    b->u[n] = log(b->w[n] / w_ref);
  }
  b->d.w = b->w, b->d.u = b->u, b->d.pgram = b->p, b->d.n = n, b->d.window_s = 40.0;
  for (size_t k = 0; k < n; ++k) b->p[k] = hm_whittle_spectrum(theta, poles, 40.0, b->w[k], b->u[k]);
}

/* One pair (-1.5 1/s at 14 Hz over a sloped numerator and noise) and two (-0.56 beside -8 1/s at 14.24 and 13.6 Hz,
 * the broad resonance) from starts 0.3-2 1/s, 0.05-0.3 Hz and a factor e off: the poles back to 1e-4 (the
 * two pairs named either way), the spectrum to 1e-6, the Fisher information positive definite (finite variances). */
static void fit_returns_the_spectrum_it_was_given(void) {
  double t1[HM_WHITTLE_MAX_NP] = {-1.5, 2.0 * HM_PI * 14.0, 2.0, -0.5, 0.3, -0.2, log(0.05)};
  double t2[HM_WHITTLE_MAX_NP] = {-0.56, 2.0 * HM_PI * 14.24, 1.0, -0.5, 0.3, -0.2, log(0.05), -8.0,
                                  2.0 * HM_PI * 13.6, log(4.0)};
  const double *truth[2] = {t1, t2};
  for (unsigned poles = 1; poles <= 2; ++poles) {
    bins b;
    const double *tt = truth[poles - 1];
    make_bins(&b, tt, poles);
    const unsigned np = hm_whittle_np(poles);
    double th[HM_WHITTLE_MAX_NP], f[HM_WHITTLE_MAX_NP][HM_WHITTLE_MAX_NP], obj;
    memcpy(th, tt, sizeof th);
    th[HM_W_SIGMA] -= 0.3 * poles, th[HM_W_W0] += 2.0 * HM_PI * 0.05, th[HM_W_C0] += 1.0, th[HM_W_LN] -= 1.0;
    if (poles == 2) th[HM_W_SIGMA2] += 2.0, th[HM_W_W02] -= 2.0 * HM_PI * 0.3, th[HM_W_LNRHO] -= 1.0;
    unsigned it = 0;
    HM_CHECK(hm_whittle_score(&b.d, poles, th, 1e-14, 400, &obj, f, &it), "%u pairs: converged (%u steps)", poles, it);
    if (poles == 2 && fabs(th[HM_W_SIGMA]) > fabs(th[HM_W_SIGMA2])) { /* the same spectrum with the pairs named the
                                                                         other way: B rho / B and 1 / rho */
      const double s = th[HM_W_SIGMA], w = th[HM_W_W0];
      th[HM_W_SIGMA] = th[HM_W_SIGMA2], th[HM_W_W0] = th[HM_W_W02], th[HM_W_SIGMA2] = s, th[HM_W_W02] = w;
      th[HM_W_C0] += th[HM_W_LNRHO];
      th[HM_W_LNRHO] = -th[HM_W_LNRHO];
    }
    /* the poles to 1e-4 (the frequencies to 1e-5 relative, the broad pair to 4e-4; the numerator's cubic and the noise trade along a flat ridge where the noise dominates: the
     * spectrum, not each of them, is what the data fix), the spectrum at every bin to 1e-6, the objective the
     * truth's (the global minimum: ln S + I / S >= ln I + 1 bin by bin) */
    const unsigned poles_idx[4] = {HM_W_SIGMA, HM_W_W0, HM_W_SIGMA2, HM_W_W02};
    for (unsigned i = 0; i < 2 * poles; ++i)
      HM_CHECK_DELTA(th[poles_idx[i]], tt[poles_idx[i]], 1e-4 * fmax(1.0, 0.1 * fabs(tt[poles_idx[i]]) + (i >= 2) * 3.0),
                     poles == 1 ? "one pair's pole" : "two pairs' pole");
    double worst = 0.0;
    for (size_t k = 0; k < b.d.n; ++k)
      worst = fmax(worst, fabs(hm_whittle_spectrum(th, poles, 40.0, b.w[k], b.u[k]) / b.p[k] - 1.0));
    HM_CHECK(worst <= 1e-6, "%u pairs: the spectrum off by %g", poles, worst);
    HM_CHECK(obj <= hm_whittle_objective(&b.d, poles, tt) + 1e-9 * fabs(obj), "%u pairs: the objective", poles);
    double var[HM_WHITTLE_MAX_NP];
    hm_whittle_variances((const double(*)[HM_WHITTLE_MAX_NP])f, np, 1.0, var);
    int finite = 1;
    for (unsigned i = 0; i < np; ++i) finite &= isfinite(var[i]) && var[i] > 0.0;
    HM_CHECK(finite, "%u pairs: the covariance", poles);
    printf("  %u pair%s: back to the given spectrum in %u steps, sigma %.7f (%.2f)\n", poles, poles == 1 ? "" : "s",
           it, th[HM_W_SIGMA], tt[HM_W_SIGMA]);
  }
}

/* A line (sigma = 0: the window's kernel) is a point of the model: a spectrum given at sigma 0 is fitted back at the
 * bound with a finite error (a Lorentzian alone would narrow onto one bin with a diverging one). */
static void a_line_is_sigma_zero(void) {
  double tt[HM_WHITTLE_MAX_NP] = {0.0, 2.0 * HM_PI * 14.0, 0.0, 0.0, 0.0, 0.0, log(0.01)};
  bins b;
  make_bins(&b, tt, 1);
  double th[HM_WHITTLE_MAX_NP], f[HM_WHITTLE_MAX_NP][HM_WHITTLE_MAX_NP], obj;
  memcpy(th, tt, sizeof th);
  th[HM_W_SIGMA] = -1.0, th[HM_W_W0] += 0.2, th[HM_W_C0] -= 1.0;
  unsigned it = 0;
  HM_CHECK(hm_whittle_score(&b.d, 1, th, 1e-14, 400, &obj, f, &it), "converged (%u steps)", it);
  HM_CHECK_DELTA(th[HM_W_SIGMA], 0.0, 1e-6, "the line's decay rate");
  HM_CHECK_DELTA(th[HM_W_W0], tt[HM_W_W0], 1e-5, "the line's frequency");
  double var[HM_WHITTLE_MAX_NP];
  hm_whittle_variances((const double(*)[HM_WHITTLE_MAX_NP])f, 7, 1.0, var);
  HM_CHECK(isfinite(var[HM_W_SIGMA]) && var[HM_W_SIGMA] > 0.0, "finite error at sigma 0: %g", var[HM_W_SIGMA]);
}

/* A negligible noise is no trap (review of 2026-12-04): where the noise is negligible d ln S / d ln N vanishes and
 * steps crawl or go on down to the floor. The review's window (a -6.5 1/s mode at 14.27 Hz, the white noise a fifth
 * of the median periodogram: the optimum it found, here the truth) as periodograms drawn from it (each bin the
 * spectrum times an exponential variate, 40 seeds), fitted from the review's trapped start (a broader pair, ln N at
 * the floor -60, then at -20 where the crawl stopped), scored and then, as the identification does every fifth fit,
 * retried (hm_whittle_reseed_noise): every start must end at the best objective over starts with the noise at its
 * true level and a factor e either side (a second way to the optimum; before the retry the trapped fits ended up to
 * 1.0 above it, the decay rate up to 0.4 1/s off; a retry from the noise at the periodogram's mean alone, with the
 * trapped cubic background kept, still failed 5 of 200 seeds, review of ac12d3a). And a spectrum without noise is
 * fitted back as it was (the retry is kept only if it is better). */
static void a_negligible_noise_is_no_trap(void) {
  const double tt[HM_WHITTLE_MAX_NP] = {-6.541286, 89.658298, 13.979036, 0.231159, -6.113023, -7.397272, -3.260777};
  const double trapped[HM_WHITTLE_MAX_NP] = {-5.89046, 89.0901, 13.9182, 0.558154, -1.2898, -2.47813, 0.0};
  for (uint64_t seed = 1; seed <= 40; ++seed) {
    bins b;
    make_bins(&b, tt, 1);
    uint64_t x = 0x9E3779B97F4A7C15ull * seed;
    for (size_t k = 0; k < b.d.n; ++k) {
      x ^= x << 13, x ^= x >> 7, x ^= x << 17;
      b.p[k] *= -log(((double)(x >> 11) + 0.5) / 9007199254740992.0);
    }
    double th[HM_WHITTLE_MAX_NP], f[HM_WHITTLE_MAX_NP][HM_WHITTLE_MAX_NP], obj, best = INFINITY, best_sigma = 0.0;
    unsigned it = 0;
    for (int k = -1; k <= 1; ++k) {
      memcpy(th, tt, sizeof th);
      th[HM_W_LN] += k;
      if (hm_whittle_score(&b.d, 1, th, 1e-10, 200, &obj, f, &it) && obj < best) best = obj, best_sigma = th[HM_W_SIGMA];
    }
    HM_CHECK(isfinite(best), "seed %u: the fits from the noise's level converged", (unsigned)seed);
    const double starts[2] = {HM_WHITTLE_LN_FLOOR, -20.0};
    for (int k = 0; k < 2; ++k) {
      memcpy(th, trapped, sizeof th);
      th[HM_W_LN] = starts[k];
      it = 0;
      HM_CHECK(hm_whittle_score(&b.d, 1, th, 1e-7, 200, &obj, f, &it), "seed %u from ln N %g: converged", (unsigned)seed,
               starts[k]);
      hm_whittle_reseed_noise(&b.d, 1, th, 1e-7, 200, &obj, f, &it);
      HM_CHECK(obj <= best + 1e-6 * fabs(best), "seed %u from ln N %g: the objective %.9g against %.9g", (unsigned)seed,
               starts[k], obj, best);
      HM_CHECK_DELTA(th[HM_W_SIGMA], best_sigma, 1e-2, "the decay rate");
      if (k == 0 && seed <= 4)
        printf("  seed %u, from ln N at the floor: decay rate %.4f (%.4f from the noise's level), ln N %.3f, %u steps\n",
               (unsigned)seed, th[HM_W_SIGMA], best_sigma, th[HM_W_LN], it);
    }
  }
  double quiet[HM_WHITTLE_MAX_NP];
  memcpy(quiet, tt, sizeof quiet);
  quiet[HM_W_LN] = HM_WHITTLE_LN_FLOOR;
  bins b;
  make_bins(&b, quiet, 1);
  double th[HM_WHITTLE_MAX_NP], f[HM_WHITTLE_MAX_NP][HM_WHITTLE_MAX_NP], obj;
  memcpy(th, quiet, sizeof th);
  th[HM_W_SIGMA] -= 0.5, th[HM_W_C0] += 0.5;
  unsigned it = 0;
  HM_CHECK(hm_whittle_score(&b.d, 1, th, 1e-12, 200, &obj, f, &it), "without noise: converged (%u steps)", it);
  const double obj_before = obj;
  hm_whittle_reseed_noise(&b.d, 1, th, 1e-12, 200, &obj, f, &it);
  HM_CHECK(obj <= obj_before, "without noise: the retry kept only if better");
  HM_CHECK_DELTA(th[HM_W_SIGMA], quiet[HM_W_SIGMA], 1e-5, "without noise: the decay rate");
  HM_CHECK(th[HM_W_LN] < log(1e-3 * b.p[0]), "without noise: the noise stays negligible (ln N %.3g)", th[HM_W_LN]);
}

/* The pair's term holds the pair's power whatever its damping: its integral over w > 0 is that of a / d over the two
 * poles, pi / (4 (w0^2 + a_e^2)) (the residues of a / ((a^2 + (w - w0)^2)(a^2 + (w + w0)^2)) over the real line,
 * pi / (2 (w0^2 + a^2)), half of it by symmetry), for a_e from a line's 2 / T to a broad 8 1/s: trapezoids on a fine
 * grid to 1e-4. */
static void a_pair_holds_its_power(void) {
  const double w0 = 2.0 * HM_PI * 14.0, T = 40.0, sigmas[] = {0.0, -0.5, -8.0};
  for (int i = 0; i < 3; ++i) {
    const double th[HM_WHITTLE_MAX_NP] = {sigmas[i], w0, 0.0, 0.0, 0.0, 0.0, -700.0};
    const double ae = -sigmas[i] + HM_WHITTLE_LEAKAGE / T, h = fmin(ae, 1.0) / 200.0;
    double sum = 0.0;
    for (double w = h; w < 40.0 * w0; w += h) sum += hm_whittle_spectrum(th, 1, T, w, 0.0) * h;
    const double exact = HM_PI / (4.0 * (w0 * w0 + ae * ae));
    HM_CHECK_REL(sum, exact, 1e-4, "the pair's power");
  }
}

/* The pass's own e^x (whittle.h) against the C library's long-double expl over [-708, 708]: evenly spaced points,
 * the ends, and points where r, the reduced argument, is at its ends (x = (k + 1/2) ln 2); at most 2 ulp of the
 * double nearest e^x, and exactly 1 at 0. */
static void its_exp_is_exp(void) {
  double worst = 0.0, at = 0.0;
  for (long i = 0; i <= 2000000; ++i) {
    const double x = i < 1000000 ? -708.0 + 1416.0 * (double)i / 1e6 : (double)(i - 1000000 - 1021) * 0.5 * log(2.0);
    if (!(x >= -708.0 && x <= 708.0)) continue;
    const long double ref = expl((long double)x);
    const double ulp = nextafter((double)ref, INFINITY) - (double)ref;
    const double err = fabs((double)((long double)hm_whittle_exp(x) - ref)) / ulp;
    if (err > worst) worst = err, at = x;
  }
  printf("  e^x over [-708, 708]: at most %.2f ulp (at x = %.6g)\n", worst, at);
  HM_CHECK(worst <= 2.0, "%.2f ulp at %g", worst, at);
  HM_CHECK(hm_whittle_exp(0.0) == 1.0, "e^0 = %.17g", hm_whittle_exp(0.0));
}

int main(void) {
  HM_RUN(its_exp_is_exp);
  HM_RUN(fit_returns_the_spectrum_it_was_given);
  HM_RUN(a_line_is_sigma_zero);
  HM_RUN(a_negligible_noise_is_no_trap);
  HM_RUN(a_pair_holds_its_power);
  HM_TEST_EXIT();
}
