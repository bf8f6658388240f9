/* Dormand-Prince 8(5,3): the explicit Runge-Kutta pair of E. Hairer, S. P. Norsett, G. Wanner, Solving Ordinary
 * Differential Equations I (2nd ed., Springer 1993), section II.10, as in their code DOP853: 12 stages, order 8,
 * error estimated from the 5th- and 3rd-order embedded formulas, step size h (err^-1/8). See integrate.h. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "hunting_monitor/integrate.h"
#include "rk.h"

/* The tableau (nodes c, coupling a[i][j] for stage i from stage j, weights b, error weights). Stages are numbered
 * 0..11; a stage's zero couplings are omitted by the loops below through the `from` lists. */
static const double C[12] = {0.0,
                             0.526001519587677318785587544488e-01,
                             0.789002279381515978178381316732e-01,
                             0.118350341907227396726757197510e+00,
                             0.281649658092772603273242802490e+00,
                             0.333333333333333333333333333333e+00,
                             0.25e+00,
                             0.307692307692307692307692307692e+00,
                             0.651282051282051282051282051282e+00,
                             0.6e+00,
                             0.857142857142857142857142857142e+00,
                             1.0};

/* a[i][j], j < i */
static const double A[12][11] = {
    {0},
    {5.26001519587677318785587544488e-2},
    {1.97250569845378994544595329183e-2, 5.91751709536136983633785987549e-2},
    {2.95875854768068491816892993775e-2, 0.0, 8.87627564304205475450678981324e-2},
    {2.41365134159266685502369798665e-1, 0.0, -8.84549479328286085344864962717e-1,
     9.24834003261792003115737966543e-1},
    {3.7037037037037037037037037037e-2, 0.0, 0.0, 1.70828608729473871279604482173e-1,
     1.25467687566822425016691814123e-1},
    {3.7109375e-2, 0.0, 0.0, 1.70252211019544039314978060272e-1, 6.02165389804559606850219397283e-2,
     -1.7578125e-2},
    {3.70920001185047927108779319836e-2, 0.0, 0.0, 1.70383925712239993810214054705e-1,
     1.07262030446373284651809199168e-1, -1.53194377486244017527936158236e-2, 8.27378916381402288758473766002e-3},
    {6.24110958716075717114429577812e-1, 0.0, 0.0, -3.36089262944694129406857109825e0,
     -8.68219346841726006818189891453e-1, 2.75920996994467083049415600797e1, 2.01540675504778934086186788979e1,
     -4.34898841810699588477366255144e1},
    {4.77662536438264365890433908527e-1, 0.0, 0.0, -2.48811461997166764192642586468e0,
     -5.90290826836842996371446475743e-1, 2.12300514481811942347288949897e1, 1.52792336328824235832596922938e1,
     -3.32882109689848629194453265587e1, -2.03312017085086261358222928593e-2},
    {-9.3714243008598732571704021658e-1, 0.0, 0.0, 5.18637242884406370830023853209e0,
     1.09143734899672957818500254654e0, -8.14978701074692612513997267357e0, -1.85200656599969598641566180701e1,
     2.27394870993505042818970056734e1, 2.49360555267965238987089396762e0, -3.0467644718982195003823669022e0},
    {2.27331014751653820792359768449e0, 0.0, 0.0, -1.05344954667372501984066689879e1,
     -2.00087205822486249909675718444e0, -1.79589318631187989172765950534e1, 2.79488845294199600508499808837e1,
     -2.85899827713502369474065508674e0, -8.87285693353062954433549289258e0, 1.23605671757943030647266201528e1,
     6.43392746015763530355970484046e-1},
};

/* 8th-order weights (stages 1-4 have none) */
static const double B[12] = {5.42937341165687622380535766363e-2, 0.0, 0.0, 0.0, 0.0,
                             4.45031289275240888144113950566e0,  1.89151789931450038304281599044e0,
                             -5.8012039600105847814672114227e0,  3.1116436695781989440891606237e-1,
                             -1.52160949662516078556178806805e-1, 2.01365400804030348374776537501e-1,
                             4.47106157277725905176885569043e-2};
/* the 5th-order estimate: b - bhh (on stages 0, 8, 11) */
static const double BHH0 = 0.244094488188976377952755905512e+00, BHH8 = 0.733846688281611857341361741547e+00,
                    BHH11 = 0.220588235294117647058823529412e-01;
/* the 3rd-order estimate */
static const double ER[12] = {0.1312004499419488073250102996e-01, 0.0, 0.0, 0.0, 0.0,
                              -0.1225156446376204440720569753e+01, -0.4957589496572501915214079952e+00,
                              0.1664377182454986536961530415e+01, -0.3503288487499736816886487290e+00,
                              0.3341791187130174790297318841e+00, 0.8192320648511571246570742613e-01,
                              -0.2235530786388629525884427845e-01};

struct hm_dop853_s {
  size_t dim;
  double *x, *xs, *xnew, *fnew, *k; /* k: 12 stage derivatives, each dim long */
};

hm_dop853 hm_dop853_create(size_t dim) {
  if (dim == 0 || dim > (size_t)1 << 20) return NULL;
  hm_dop853 d = calloc(1, sizeof *d);
  double *mem = calloc(16 * dim, sizeof(double));
  if (!d || !mem) {
    free(d);
    free(mem);
    return NULL;
  }
  /* x, xs, xnew, fnew, then the 12 stages */
  double **slots[] = {&d->x, &d->xs, &d->xnew, &d->fnew, &d->k};
  for (size_t i = 0; i < 5; ++i) *slots[i] = mem + i * dim;
  d->dim = dim;
  return d;
}

void hm_dop853_destroy(hm_dop853 d) {
  if (!d) return;
  free(d->x);
  free(d);
}

/* One step of size h from (t, x) with k[0] = f(t, x): the stages, xnew, and the error norm (+inf if anything is
 * not finite) over the controlled components. */
static hm_status try_step(hm_dop853 d, const hm_ode_system *sys, const hm_dopri_options *opt, double t, double h,
                          double *err_out) {
  const size_t n = d->dim;
  double *k = d->k;
  for (int i = 1; i < 12; ++i) {
    for (size_t c = 0; c < n; ++c) d->xs[c] = 0.0;
    for (int j = 0; j < i; ++j) {
      const double a = A[i][j];
      if (a == 0.0) continue;
      const double *kj = k + (size_t)j * n;
      for (size_t c = 0; c < n; ++c) d->xs[c] += a * kj[c];
    }
    for (size_t c = 0; c < n; ++c) d->xs[c] = d->x[c] + h * d->xs[c];
    hm_status st = sys->rhs(t + C[i] * h, d->xs, k + (size_t)i * n, sys->params);
    if (st != HM_OK) return st;
  }
  /* the 8th-order solution and the two error estimates (xs holds the weighted sum, fnew the 3rd-order one) */
  double *bsum = d->xs, *esum = d->fnew;
  for (size_t c = 0; c < n; ++c) bsum[c] = esum[c] = 0.0;
  for (int j = 0; j < 12; ++j) {
    const double *kj = k + (size_t)j * n;
    if (B[j] != 0.0)
      for (size_t c = 0; c < n; ++c) bsum[c] += B[j] * kj[c];
    if (ER[j] != 0.0)
      for (size_t c = 0; c < n; ++c) esum[c] += ER[j] * kj[c];
  }
  const size_t m = hm_rk_err_dim(opt, n);
  double e5 = 0.0, e3 = 0.0;
  int finite = 1;
  for (size_t c = 0; c < n; ++c) {
    d->xnew[c] = d->x[c] + h * bsum[c];
    finite = finite && isfinite(d->xnew[c]);
  }
  for (size_t c = 0; c < m; ++c) {
    const double sk = opt->atol + opt->rtol * fmax(fabs(d->x[c]), fabs(d->xnew[c]));
    const double r5 = (bsum[c] - BHH0 * k[c] - BHH8 * k[8 * n + c] - BHH11 * k[11 * n + c]) / sk, r3 = esum[c] / sk;
    e5 += r5 * r5;
    e3 += r3 * r3;
  }
  double deno = e3 + 0.01 * e5;
  if (deno <= 0.0) deno = 1.0;
  const double err = fabs(h) * e3 * sqrt(1.0 / ((double)m * deno));
  *err_out = finite && isfinite(err) ? err : INFINITY;
  return HM_OK;
}

typedef struct {
  hm_dop853 d;
  const hm_ode_system *sys;
  const hm_dopri_options *opt;
  hm_step_observer observer;
  void *ctx;
} run;

static hm_status attempt(void *ctx, double t, double h, double *err) {
  run *r = (run *)ctx;
  return try_step(r->d, r->sys, r->opt, t, h, err);
}

static hm_status accept(void *ctx, double t_old, double t_new, double h, int *stop) {
  (void)h;
  run *r = (run *)ctx;
  hm_dop853 d = r->d;
  hm_status st = r->sys->rhs(t_new, d->xnew, d->fnew, r->sys->params);
  if (st != HM_OK) return st;
  *stop = r->observer && r->observer(t_old, d->x, d->k, t_new, d->xnew, d->fnew, r->ctx);
  memcpy(d->x, d->xnew, d->dim * sizeof(double));
  memcpy(d->k, d->fnew, d->dim * sizeof(double));
  return HM_OK;
}

hm_status hm_dop853_integrate(hm_dop853 d, const hm_ode_system *sys, const hm_dopri_options *opt, double t0,
                              double t1, double *x, hm_step_observer observer, void *ctx, hm_dopri_stats *stats) {
  if (!d) return HM_EINVAL;
  hm_status st = hm_rk_check(sys, d->dim, opt, t0, t1, x);
  if (st != HM_OK) return st;
  const size_t n = d->dim;
  hm_dopri_stats s = {0, 0, 0};
  memcpy(d->x, x, n * sizeof(double));
  if (t1 > t0) {
    if ((st = sys->rhs(t0, d->x, d->k, sys->params)) != HM_OK) return st;
    s.n_rhs = 1;
    /* the first step: a hundredth of the time over which the state changes by its own size (in the controlled
     * components' weighted norm; Hairer's heuristic without its probe step) */
    double h = opt->h_init;
    if (!(h > 0.0)) {
      const size_t m = hm_rk_err_dim(opt, n);
      double dx = 0.0, df = 0.0;
      for (size_t c = 0; c < m; ++c) {
        const double sk = opt->atol + opt->rtol * fabs(d->x[c]);
        dx += (d->x[c] / sk) * (d->x[c] / sk);
        df += (d->k[c] / sk) * (d->k[c] / sk);
      }
      h = dx > 1e-10 && df > 1e-10 ? 0.01 * sqrt(dx / df) : 1e-6;
    }
    run r = {d, sys, opt, observer, ctx};
    const hm_rk_method m = {attempt, accept, &r, 0.125, 0.333, 6.0, 11, 1};
    double t;
    if ((st = hm_rk_drive(&m, opt, t0, t1, h, &t, &s)) != HM_OK) return st;
  }
  memcpy(x, d->x, n * sizeof(double));
  if (stats) *stats = s;
  return HM_OK;
}
