/* The identification's spectral model, one or two pole pairs, and its Whittle fit by Fisher scoring (whittle.h). */
#include "whittle.h"

#include <math.h>
#include <string.h>

enum { NPM = HM_WHITTLE_MAX_NP };

/* One pair's constants over a pass: its effective width a_e = a + HM_WHITTLE_LEAKAGE / T (a = -sigma) and 1 / a_e. */
typedef struct {
  double ae, inv_ae, w0;
} pair_k;

static pair_k pair_constants(double sg, double w0, double T) {
  const double ae = -sg + HM_WHITTLE_LEAKAGE / T;
  return (pair_k){ae, 1.0 / ae, w0};
}

/* One pair's term P (whittle.h) and the derivatives of ln P with respect to sigma (= -a) and w0: the Lorentzian of
 * width a_e over the pair's two poles, times a_e (the power form). */
static inline double pair_term(const pair_k *c, double w, double *dl_sg, double *dl_w0) {
  const double ae = c->ae, dl = w - c->w0, sm = w + c->w0, qd = ae * ae + dl * dl, qs = ae * ae + sm * sm;
  const double iq = 1.0 / (qd * qs), iqd = qs * iq, iqs = qd * iq; /* (one division) */
  *dl_sg = -(c->inv_ae - 2.0 * ae * (iqd + iqs));
  *dl_w0 = 2.0 * (dl * iqd - sm * iqs);
  return ae * iqd * iqs;
}

/* S at one bin given B there (noise = exp(th[ln N]), rho = exp(th[ln rho]): once a pass); evaluate_n writes its
 * gradient's columns itself. */
static inline double spectrum_b(unsigned poles, const pair_k *c1, const pair_k *c2, double noise, double rho,
                                double b, double w) {
  double a1, b1, a2, b2;
  return b * (pair_term(c1, w, &a1, &b1) + (poles == 2 ? rho * pair_term(c2, w, &a2, &b2) : 0.0)) + noise;
}

/* frexp of a normal positive x (the running product's: at most four factors of [1e-70, 1e70] times one of
 * [0.5, 1)): its mantissa in [0.5, 1) back in x, its exponent returned; inline, where libm's frexp is a call every
 * four bins. */
static inline int split_exponent(double *x) {
  uint64_t bits;
  memcpy(&bits, x, sizeof bits);
  const int e = (int)((bits >> 52) & 0x7ffu) - 1022;
  bits = (bits & ~(0x7ffull << 52)) | (1022ull << 52);
  memcpy(x, &bits, sizeof bits);
  return e;
}

/* ln B(u) (whittle.h). */
static inline double background(const double *th, double u) {
  return th[HM_W_C0] + u * (th[HM_W_C1] + u * (th[HM_W_C2] + u * th[HM_W_C3]));
}

enum { BLOCK = 64 }; /* bins a block: its columns of J (NPM x BLOCK doubles, 5 kB) stay in the cache */

/* The objective at th and, when f is not NULL, the Fisher information J'J in f and the score J'(I/S - 1) in g: one
 * pass over blocks of bins, each in loops the compiler vectorises (B's exponent, B, S and J's columns, then J'J and
 * J'(I/S - 1) as dot products of the columns), and one log a pass (the sum of ln S as the logarithm of a product
 * renormalised every four bins by split_exponent: the same to rounding as a log a bin, a fifth of the pass's time).
 * poles is a constant in each caller below, so that the loops unroll. */
static inline double evaluate_n(const hm_whittle_data *d, const unsigned poles, const double *th, double f[NPM][NPM],
                                double *g) {
  const unsigned np = hm_whittle_np(poles);
  const double noise = exp(th[HM_W_LN]), rho = poles == 2 ? exp(th[HM_W_LNRHO]) : 0.0;
  const pair_k c1 = pair_constants(th[HM_W_SIGMA], th[HM_W_W0], d->window_s);
  const pair_k c2 = poles == 2 ? pair_constants(th[HM_W_SIGMA2], th[HM_W_W02], d->window_s) : c1;
  double l_rest = 0.0, prod = 1.0;
  long exp2_sum = 0;
  if (f) {
    memset(f, 0, sizeof(double) * NPM * NPM);
    memset(g, 0, sizeof(double) * NPM);
  }
  for (size_t k0 = 0; k0 < d->n; k0 += BLOCK) {
    const size_t nk = d->n - k0 < BLOCK ? d->n - k0 : BLOCK;
    const double *w = d->w + k0, *u = d->u + k0, *pg = d->pgram + k0;
    double b[BLOCK], s[BLOCK], q[BLOCK], col[NPM][BLOCK]; /* B, S, I / S and J's columns (d ln S / d theta) */
    long wide = 0;
    for (size_t i = 0; i < nk; ++i) b[i] = background(th, u[i]);
    for (size_t i = 0; i < nk; ++i) wide |= (long)((b[i] < -708.0) | (b[i] > 708.0) | (b[i] != b[i]));
    if (!wide)
      for (size_t i = 0; i < nk; ++i) b[i] = hm_whittle_exp(b[i]);
    else /* (a trial step far out, or NaN: libm's exp) */
      for (size_t i = 0; i < nk; ++i) b[i] = exp(b[i]);
    if (f)
      for (size_t i = 0; i < nk; ++i) {
        double a1, b1, a2 = 0.0, b2 = 0.0;
        const double m1 = b[i] * pair_term(&c1, w[i], &a1, &b1);
        const double m2 = poles == 2 ? b[i] * rho * pair_term(&c2, w[i], &a2, &b2) : 0.0;
        const double sk = m1 + m2 + noise, is = 1.0 / sk, r1 = m1 * is, r2 = m2 * is, rb = r1 + r2, uk = u[i];
        s[i] = sk;
        col[HM_W_SIGMA][i] = r1 * a1;
        col[HM_W_W0][i] = r1 * b1;
        col[HM_W_C0][i] = rb;
        col[HM_W_C1][i] = rb * uk;
        col[HM_W_C2][i] = rb * uk * uk;
        col[HM_W_C3][i] = rb * uk * uk * uk;
        col[HM_W_LN][i] = noise * is;
        if (poles == 2) {
          col[HM_W_SIGMA2][i] = r2 * a2;
          col[HM_W_W02][i] = r2 * b2;
          col[HM_W_LNRHO][i] = r2;
        }
      }
    else
      for (size_t i = 0; i < nk; ++i) s[i] = spectrum_b(poles, &c1, &c2, noise, rho, b[i], w[i]);
    for (size_t i = 0; i < nk; ++i) q[i] = pg[i] / s[i];
    for (size_t i = 0; i < nk; ++i) {
      const double sk = s[i];
      l_rest += q[i];
      if (sk >= 1e-70 && sk <= 1e70) /* (four such stay within a double's range; any other, NaN too, taken alone) */
        prod *= sk;
      else
        l_rest += log(sk);
      if (((k0 + i) & 3u) == 3u) exp2_sum += split_exponent(&prod);
    }
    if (!f) continue;
    for (unsigned a = 0; a < np; ++a) {
      double ga = 0.0;
      for (size_t i = 0; i < nk; ++i) ga += col[a][i] * (q[i] - 1.0);
      g[a] += ga;
      for (unsigned c = 0; c <= a; ++c) {
        double fac = 0.0;
        for (size_t i = 0; i < nk; ++i) fac += col[a][i] * col[c][i];
        f[a][c] += fac;
      }
    }
  }
  if (f)
    for (unsigned a = 0; a < np; ++a)
      for (unsigned c = a + 1; c < np; ++c) f[a][c] = f[c][a];
  return log(prod) + (double)exp2_sum * 0.69314718055994530942 + l_rest;
}

static double evaluate(const hm_whittle_data *d, unsigned poles, const double *th, double f[NPM][NPM], double *g) {
  return poles == 2 ? evaluate_n(d, 2, th, f, g) : evaluate_n(d, 1, th, f, g);
}

double hm_whittle_spectrum(const double *th, unsigned poles, double window_s, double w, double u) {
  const pair_k c1 = pair_constants(th[HM_W_SIGMA], th[HM_W_W0], window_s);
  const pair_k c2 = poles == 2 ? pair_constants(th[HM_W_SIGMA2], th[HM_W_W02], window_s) : c1;
  return spectrum_b(poles, &c1, &c2, exp(th[HM_W_LN]), poles == 2 ? exp(th[HM_W_LNRHO]) : 0.0,
                    exp(background(th, u)), w);
}

double hm_whittle_objective(const hm_whittle_data *d, unsigned poles, const double *theta) {
  return evaluate(d, poles, theta, NULL, NULL);
}

/* Cholesky solve of the n x n system a x = b (a overwritten); 0 if not positive definite. */
static int chol_solve(double a[NPM][NPM], unsigned n, double *b) {
  for (unsigned j = 0; j < n; ++j) {
    double s = a[j][j];
    for (unsigned k = 0; k < j; ++k) s -= a[j][k] * a[j][k];
    if (!(s > 0.0)) return 0;
    a[j][j] = sqrt(s);
    for (unsigned i = j + 1; i < n; ++i) {
      double t = a[i][j];
      for (unsigned k = 0; k < j; ++k) t -= a[i][k] * a[j][k];
      a[i][j] = t / a[j][j];
    }
  }
  for (unsigned i = 0; i < n; ++i) {
    double s = b[i];
    for (unsigned k = 0; k < i; ++k) s -= a[i][k] * b[k];
    b[i] = s / a[i][i];
  }
  for (unsigned i = n; i-- > 0;) {
    double s = b[i];
    for (unsigned k = i + 1; k < n; ++k) s -= a[k][i] * b[k];
    b[i] = s / a[i][i];
  }
  return 1;
}

void hm_whittle_variances(const double fisher[NPM][NPM], unsigned np, double scale, double *var) {
  for (unsigned i = 0; i < np; ++i) {
    double a[NPM][NPM], e[NPM] = {0};
    memcpy(a, fisher, sizeof a);
    e[i] = 1.0;
    var[i] = chol_solve(a, np, e) ? e[i] * scale : INFINITY;
  }
}

/* Decay rates at most 0 (a stationary spectrum; 0 is a line's), and floors far below any signal: the noise, or the
 * second pair, may be absent. */
static void clamp(double *th, unsigned poles) {
  th[HM_W_SIGMA] = fmin(th[HM_W_SIGMA], 0.0);
  th[HM_W_LN] = fmax(th[HM_W_LN], HM_WHITTLE_LN_FLOOR);
  if (poles == 2) {
    th[HM_W_SIGMA2] = fmin(th[HM_W_SIGMA2], 0.0);
    th[HM_W_LNRHO] = fmax(th[HM_W_LNRHO], -40.0);
  }
}

/* The damped scoring step (f + mu diag f)^-1 g into st; a decay rate at its bound 0 that the step would raise is held
 * there (the step solved without it: an active set), so that a line's fit converges on the bound. 0 if singular. */
static int damped_step(const double f[NPM][NPM], const double *g, unsigned np, double mu, const double *th,
                       unsigned poles, double *st) {
  int held[NPM] = {0};
  for (int pass = 0; pass < 2; ++pass) {
    double a[NPM][NPM];
    memcpy(a, f, sizeof a);
    memcpy(st, g, sizeof(double) * NPM);
    for (unsigned i = 0; i < np; ++i) {
      a[i][i] += mu * f[i][i] + 1e-12;
      if (!held[i]) continue;
      for (unsigned j = 0; j < np; ++j) a[i][j] = a[j][i] = 0.0;
      a[i][i] = 1.0;
      st[i] = 0.0;
    }
    if (!chol_solve(a, np, st)) return 0;
    int again = 0;
    const unsigned sig[2] = {HM_W_SIGMA, HM_W_SIGMA2};
    for (unsigned p = 0; p < poles; ++p)
      if (!held[sig[p]] && th[sig[p]] >= 0.0 && st[sig[p]] > 0.0) held[sig[p]] = again = 1;
    if (!again) return 1;
  }
  return 1;
}

/* One Levenberg-damped scoring step from th (objective l, information f, score g); 1 when a step was taken (th, l,
 * f, g updated; *change its relative decrease, *raised whether the damping had to be raised for it), 0 at a
 * stationary point (no descent left, or only rounding). */
static int step(const hm_whittle_data *d, unsigned poles, double tol, double *th, double *l, double f[NPM][NPM],
                double *g, double *mu, double *change, int *raised) {
  const unsigned np = hm_whittle_np(poles);
  for (int tries = 0; tries < 30; ++tries) {
    double st[NPM], trial[NPM], ft[NPM][NPM], gt[NPM];
    if (!damped_step(f, g, np, *mu, th, poles, st)) {
      *mu *= 10.0;
      continue;
    }
    memcpy(trial, th, sizeof trial);
    for (unsigned i = 0; i < np; ++i) trial[i] += st[i];
    clamp(trial, poles);
    /* the first try is usually taken: its scoring system comes in the same pass; after a refusal only the
     * objective, and the scoring system once a try is taken */
    const double lt = evaluate(d, poles, trial, tries == 0 ? ft : NULL, gt);
    if (isfinite(lt) && lt <= *l) {
      *change = (*l - lt) / (fabs(*l) + 1.0);
      if (tries > 0) evaluate(d, poles, trial, ft, gt);
      memcpy(th, trial, sizeof trial);
      memcpy(f, ft, sizeof ft);
      memcpy(g, gt, sizeof gt);
      *l = lt;
      *mu = fmax(*mu * 0.3, 1e-9);
      *raised = tries > 0;
      return 1;
    }
    if (isfinite(lt) && (lt - *l) / (fabs(*l) + 1.0) < tol) return 0; /* at the optimum to the tolerance */
    *mu *= 10.0;
    if (*mu > 1e12) return 0; /* no descent direction left */
  }
  return 0;
}

/* Scoring from th (in place) by at most max_iter steps; *l and f set, the steps added to *iters; 1 if converged. */
static int score_from(const hm_whittle_data *d, unsigned poles, double *th, double tol, unsigned max_iter, double *l,
                      double f[NPM][NPM], unsigned *iters) {
  double g[NPM], mu = 1e-3, change = 0.0;
  *l = evaluate(d, poles, th, f, g);
  int converged = 0, raised = 0;
  unsigned it = 0;
  while (it < max_iter && !converged) {
    ++it;
    /* a small decrease is convergence only from a step the damping did not have to shorten (a shortened one is small
     * because it was shortened: review of 2026-12-04, a line reading stopped so at sigma -0.002 where it goes on to
     * -0.03) */
    if (!step(d, poles, tol, th, l, f, g, &mu, &change, &raised)) converged = 1;
    else converged = change < tol && !raised;
  }
  *iters += it;
  return converged && isfinite(*l);
}

int hm_whittle_score(const hm_whittle_data *d, unsigned poles, double *th, double tol, unsigned max_iter,
                     double *obj, double fisher[NPM][NPM], unsigned *iters) {
  double f[NPM][NPM], l;
  unsigned it = 0;
  const int converged = score_from(d, poles, th, tol, max_iter, &l, f, &it);
  *iters = it;
  *obj = l;
  memcpy(fisher, f, sizeof f);
  return converged;
}

int hm_whittle_reseed_noise(const hm_whittle_data *d, unsigned poles, double *th, double tol, unsigned max_iter,
                            double *obj, double fisher[NPM][NPM], unsigned *iters) {
  if (d->n == 0) return 0;
  double mean = 0.0;
  for (size_t k = 0; k < d->n; ++k) mean += d->pgram[k];
  mean /= (double)d->n;
  const double ln_mean = log(mean);
  if (!isfinite(ln_mean) || !(th[HM_W_LN] < ln_mean + HM_WHITTLE_LN_NEGLIGIBLE)) return 0;
  /* from a flat background at the level the cubic had at the pair's frequency: a curved one held the floor the
   * noise would explain, and from it the scoring slid back to a negligible noise (review of ac12d3a) */
  double t[NPM], ft[NPM][NPM], lt;
  memcpy(t, th, sizeof t);
  const double u0 = d->u[0] + log(fabs(th[HM_W_W0]) / d->w[0]);
  t[HM_W_C0] = background(th, u0);
  t[HM_W_C1] = t[HM_W_C2] = t[HM_W_C3] = 0.0;
  t[HM_W_LN] = ln_mean + HM_WHITTLE_RESEED_LN;
  if (!isfinite(t[HM_W_C0])) return 0;
  if (!score_from(d, poles, t, tol, max_iter, &lt, ft, iters) || !(lt < *obj)) return 0;
  memcpy(th, t, sizeof t);
  memcpy(fisher, ft, sizeof ft);
  *obj = lt;
  return 1;
}

/* A pair's term at its own frequency (the peak), Re F(a) / (a^2 + 4 w0^2). */
static double pair_peak(double sg, double w0, double T) {
  double dummy_a, dummy_b;
  const pair_k c = pair_constants(sg, w0, T);
  return pair_term(&c, w0, &dummy_a, &dummy_b);
}

void hm_whittle_cold_start(const hm_whittle_data *d, size_t h, double sigma0, double *th) {
  double best = -1.0, lo = INFINITY;
  size_t kbest = d->n / 2;
  for (size_t k = 0; k < d->n; ++k) {
    double s = 0.0;
    size_t n = 0;
    for (size_t j = k >= h ? k - h : 0; j <= k + h && j < d->n; ++j, ++n) s += d->pgram[j];
    s /= (double)n;
    if (s > best) best = s, kbest = k;
    if (s < lo) lo = s;
  }
  const double w0 = d->w[kbest];
  memset(th, 0, sizeof(double) * NPM);
  th[HM_W_SIGMA] = -fabs(sigma0);
  th[HM_W_W0] = w0;
  th[HM_W_C0] = log(fmax(best - 0.5 * lo, 1e-300) / pair_peak(th[HM_W_SIGMA], w0, d->window_s));
  th[HM_W_LN] = log(fmax(0.5 * lo, 1e-300));
}

void hm_whittle_split_start(const double *th1, double window_s, double narrow, double *th) {
  memcpy(th, th1, sizeof(double) * HM_WHITTLE_NP1);
  const double sg = -fabs(th1[HM_W_SIGMA]), w0 = fabs(th1[HM_W_W0]), sa = narrow * sg, sb = sg / narrow - 2.0;
  /* at the frequency, the narrow pair 70% of the single pair's peak, the broad one 30% */
  const double peak = exp(th1[HM_W_C0]) * pair_peak(sg, w0, window_s);
  th[HM_W_SIGMA] = sa;
  th[HM_W_C0] = log(0.7 * peak / pair_peak(sa, w0, window_s));
  th[HM_W_SIGMA2] = sb;
  th[HM_W_W02] = w0;
  th[HM_W_LNRHO] = log(0.3 * peak / (exp(th[HM_W_C0]) * pair_peak(sb, w0, window_s)));
}

double hm_whittle_peak(const double *th, unsigned pair, double window_s, double w_ref) {
  const double sg = pair ? th[HM_W_SIGMA2] : th[HM_W_SIGMA], w0 = fabs(pair ? th[HM_W_W02] : th[HM_W_W0]);
  const double u = log(w0 / w_ref);
  const double b = exp(background(th, u));
  return (pair ? exp(th[HM_W_LNRHO]) : 1.0) * b * pair_peak(sg, w0, window_s);
}
