/* hm_scenario: recordings for the hunting monitor's test campaign (scripts/campaign), made by vehicles that are not
 * the monitor's model, on a line with what a real line adds. Independent of the core: libc, libm and LAPACK's dgeev_.
 *
 *   hm_scenario --out DIR --name NAME [--vehicle wheelset|bogie] [--profile steps:250@50,400@50] ...   (--help)
 *
 * Vehicles (docs/MODEL.md sections 1-3, test/unit/test_bogie.c):
 *  - wheelset: MODEL.md's nonlinear wheelset; the conicity lambda(r) and the flange force F_T(r) act on the position
 *    relative to the track r = y - y_track(s), the primary springs on y (held by the ground);
 *  - bogie: two such wheelsets at +-a on a frame with lateral and yaw freedom, held to a fixed car body by secondary
 *    springs and dampers (test_bogie.c's equations); the rear wheelset meets the track 2a / v after the leading one:
 *      m y_i''   = -2 f / v y_i' + 2 f psi_i - (Ky + Kg) q_i - F_T(r_i)           q_i = y_i - yf - x_i psif
 *      I psi_i'' = -2 f d0 lambda(r_i) r_i / r0 - 2 f d0^2 / v psi_i' - Kx d1^2 (psi_i - psif)
 *      mf yf''   = sum (Ky + Kg) q_i - Ksy yf - Csy yf'
 *      If psif'' = sum [x_i (Ky + Kg) q_i + Kx d1^2 (psi_i - psif)] - Kspsi psif - Cpsi psif'   x_1 = a, x_2 = -a
 *    (Kg = Kx (l0/l1 - 1); the lone wheelset is one of these with the frame held at 0 and x_1 = 0.)
 * Integration: classic RK4 at 1/fs split into substeps of at most 0.5 ms (and of at most 2 / the largest |eigenvalue|
 * at the profile's lowest speed, for a stiff bogie), the speed and the track held per substep.
 * The track: a Gaussian lateral alignment (amplitude spectrum ~ 1/spatial frequency, wavelengths 3-60 m) made once on a
 * 0.05 m grid by an inverse FFT, periodic over its grid (at most 2^22 points, 210 km: longer runs meet it again), plus
 * slabs (a pure sine in distance), joints (a comb of 1 m wide kinks) and spans (a comb of wide bumps).
 * The accelerometer adds white noise, an offset, fixed lines (--sine) and noise-driven modes (--broad: an AR(2)
 * recursion with the mode's poles, its output the added acceleration), none of them fed back to the dynamics; the
 * speed signal is the profile sampled at --speed-hz with white noise, quantised if asked. Every random draw has its
 * own splitmix64 stream of --seed (track, noise, speed, lines), so adding a line leaves the rest as it was. A
 * recording ends early (stopped_at_s) if |y1| passes 40 mm.
 *
 * Writes DIR/NAME_accel.csv (t_s,accel_mps2), DIR/NAME_speed.csv (t_s,speed_kmh) and DIR/NAME_truth.json (also printed
 * on stdout): the vehicle's linear critical (Hopf) speed from the eigenvalues of its Jacobian at the origin (forward
 * differences of the same right-hand side, dgeev, a 5 km/h scan over 100..1500 km/h for the first sign change of the
 * largest real part of a complex pair, bisection to 0.01 km/h), the least-damped pair at the profile's steady speeds,
 * the hunting onset (test_bogie.c's rule: |y1| beyond 3 mm in each of eight 0.25 s blocks in a row, the onset the
 * first crossing in the first of them) and every setting. --truth-only: the linear truth alone, at once (no
 * recording; scripts/campaign asks it for the Hopf speed before it sets the profile). Exit 2 on a bad option, 1 on a
 * failure to write.
 *
 * Bogie presets: frame {mf, If, a, Ksy, Csy, Kspsi, Cpsi} (SI) and primary Kx, Ky [MN/m]; the Hopf speed and the
 * critical pair's frequency here at lambda0 0.1358 / 0.16 (dgeev; the wheelset model's closed form: 553.81, 517.62,
 * 473.77, 420.71 km/h at lambda0 0.12, 0.1358, 0.16, 0.20, always at 14.28 Hz):
 *   stiff    {2600, 1500, 1.25, 0.25e6, 30e3, 0.3e6, 5e6}    8.96/8.96  545.39 / 496.98 km/h, 14.33 / 14.32 Hz
 *            (test_bogie.c's strong yaw dampers: it prints 545.4 km/h at 14.33 Hz)
 *   standard {2600, 6000, 1.25, 0.25e6, 100e3, 0.3e6, 20e6}  8.96/8.96  524.87 / 479.84 km/h, 14.30 / 14.30 Hz
 *            (the model's primary springs, the frame's yaw held harder still: +3..+10 km/h over lambda0 0.10-0.30;
 *            the frame modes stay stable to 800 km/h up to lambda0 0.20. If is 6000 so that the yaw damper's pole
 *            -Cpsi / If is -3333 1/s as in stiff, within RK4's reach at 0.5 ms; with If 1500 the Hopf speeds are the
 *            same to 0.1 km/h but the pole is -13333 1/s and needs 0.15 ms steps)
 *   soft     {2600, 1500, 1.25, 0.25e6, 30e3, 0.3e6, 7.8e5}  8.96/8.96  482.18 / 415.10 km/h,  6.40 /  6.63 Hz
 *            (test_bogie.c's weak yaw dampers, 482.2 km/h at 6.40 Hz there: the frame's mode, not hunting)
 *   unstable {2600, 6000, 1.25, 0.25e6, 100e3, 0.3e6, 20e6}  6.80/8.96  462.71 / 425.42 km/h, 13.06 / 13.06 Hz
 *            (standard with softer primary longitudinal springs; 493.08 / 379.59 km/h at 0.12 / 0.20: 41-61 km/h below
 *            the model over 0.12-0.20, 31-71 over 0.10-0.30, the critical mode always the wheelsets' 13.06 Hz one.
 *            The frame alone does not get there: 40000 random frames on the model's primary springs (log-uniform mf
 *            300-10000 kg, If 100-30000 kg m^2, Ksy 1e4-1e7, Csy 1e3-1e6, Kspsi 1e4-1e8, Cpsi 1e4-3e7; a 0.5-2.5 m)
 *            gave no 12-15 Hz critical pair below 505 km/h at 0.1358: the frame stabilises the wheelsets' mode (a
 *            rigidly held frame tends to the lone wheelset from above); only its low-frequency modes went below, as
 *            in soft. Softer primary springs are what make a bogie hunt earlier at 12-15 Hz.)
 */
#define _POSIX_C_SOURCE 200809L /* stat(): --out must be a directory */
#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

extern void dgeev_(const char *jobvl, const char *jobvr, const int *n, double *a, const int *lda, double *wr,
                   double *wi, double *vl, const int *ldvl, double *vr, const int *ldvr, double *work,
                   const int *lwork, int *info);

enum { NS_MAX = 12, MAX_FEATURES = 16, MAX_LINES = 8, MAX_STEPS = 64, MAX_STEADY = 128, HUNT_BLOCKS = 8 };

static const double PI = 3.14159265358979323846;
/* MODEL.md section 2: wheelset mass, yaw inertia, half distances of the contacts and of the primary springs, rolling
 * radius, creep coefficient (kx = ky), the geometric ratio l0/l1; section 3: the flange force and the conicity's
 * Gaussians (at +-0.01 m, width 0.00145 m, height 0.7) */
static const double M_WS = 1869.0, I_WS = 910.0, D0 = 0.7465, D1 = 1.0, R0 = 0.43, CREEP = 7.99e6;
static const double L_RATIO = 1.351186, ALPHA1 = -1.6e11, ALPHA2 = 1.6e15;
static const double LAMBDA_PEAK = 0.7, LAMBDA_AT = 0.01, LAMBDA_WIDTH = 0.00145;
static const double H_MAX_S = 0.5e-3;        /* the integrator's largest substep (smaller where the vehicle is stiff) */
static const double TRACK_DS_M = 0.05;       /* the irregularity's grid */
static const double HUNT_M = 3e-3, HUNT_BLOCK_S = 0.25;
static const double STOP_M = 0.04;           /* |y1| beyond this: off the rails in all but name, past RK4's reach */
static const double TAIL_S = 20.0;           /* the vehicle's acceleration r.m.s. is reported over the last 20 s */

/* ---- vehicles ---- */

typedef struct {
  double mf, If, a, ksy, csy, kspsi, cpsi; /* frame mass, yaw inertia, half wheelbase; secondary springs, dampers */
} bogie_params;

typedef struct {
  const char *name;
  bogie_params p;
  double kx_mn, ky_mn; /* the primary springs of its wheelsets [MN/m] (--kx, --ky override them) */
} bogie_preset;

static const bogie_preset PRESETS[] = {
    {"stiff", {2600.0, 1500.0, 1.25, 0.25e6, 30e3, 0.3e6, 5e6}, 8.96, 8.96},
    {"standard", {2600.0, 6000.0, 1.25, 0.25e6, 100e3, 0.3e6, 20e6}, 8.96, 8.96},
    {"soft", {2600.0, 1500.0, 1.25, 0.25e6, 30e3, 0.3e6, 7.8e5}, 8.96, 8.96},
    {"unstable", {2600.0, 6000.0, 1.25, 0.25e6, 100e3, 0.3e6, 20e6}, 6.8, 8.96},
};

typedef struct {
  int bogie, n;      /* 1 for the bogie; states: 4 (y psi and rates) or 12 (two wheelsets, then yf yf' psif psif') */
  double kx, ky, kg; /* primary longitudinal, lateral stiffness, the geometric term Kx (l0/l1 - 1) [N/m] */
  bogie_params b;
} vehicle;

static double conicity(double r, double lambda0) {
  const double zp = (r - LAMBDA_AT) / LAMBDA_WIDTH, zm = (r + LAMBDA_AT) / LAMBDA_WIDTH;
  return LAMBDA_PEAK * exp(-zp * zp) + LAMBDA_PEAK * exp(-zm * zm) + lambda0;
}

/* One wheelset w = (y, y', psi, psi') on primary springs to a frame at (yf, psif), x_i ahead of the frame's centre,
 * over the track at yt: writes d = w'; returns the primary lateral force on the frame, *moment its yaw moment. */
static double wheelset_rhs(const vehicle *veh, const double *w, double yf, double psif, double xi, double yt,
                           double lambda0, double v, double *d, double *moment) {
  const double q = w[0] - yf - xi * psif, r = w[0] - yt, r2 = r * r;
  const double flange = r * r2 * (ALPHA1 + ALPHA2 * r2), lateral = (veh->ky + veh->kg) * q;
  const double yaw = veh->kx * D1 * D1 * (w[2] - psif);
  d[0] = w[1];
  d[1] = (-2.0 * CREEP / v * w[1] + 2.0 * CREEP * w[2] - lateral - flange) / M_WS;
  d[2] = w[3];
  d[3] = (-2.0 * CREEP * D0 * conicity(r, lambda0) * r / R0 - 2.0 * CREEP * D0 * D0 / v * w[3] - yaw) / I_WS;
  *moment = xi * lateral + yaw;
  return lateral;
}

/* dx/dt at speed v [m/s]; yt[i], lam0[i]: the track's lateral position and the conicity's constant under wheelset i
 * (the leading one first). */
static void vehicle_rhs(const vehicle *veh, const double *x, double v, const double *yt, const double *lam0,
                        double *dx) {
  double mz = 0.0, m_i;
  if (!veh->bogie) {
    (void)wheelset_rhs(veh, x, 0.0, 0.0, 0.0, yt[0], lam0[0], v, dx, &m_i);
    return;
  }
  const double xs[2] = {veh->b.a, -veh->b.a};
  double fy = 0.0;
  for (int i = 0; i < 2; ++i) {
    fy += wheelset_rhs(veh, x + 4 * i, x[8], x[10], xs[i], yt[i], lam0[i], v, dx + 4 * i, &m_i);
    mz += m_i;
  }
  dx[8] = x[9];
  dx[9] = (fy - veh->b.ksy * x[8] - veh->b.csy * x[9]) / veh->b.mf;
  dx[10] = x[11];
  dx[11] = (mz - veh->b.kspsi * x[10] - veh->b.cpsi * x[11]) / veh->b.If;
}

/* The accelerometer's vehicle part: the leading axle box (y1'') or the frame over the leading axle (yf'' + a psif'') */
static double sensor_accel(const vehicle *veh, int frame_sensor, const double *dx) {
  return frame_sensor ? dx[9] + veh->b.a * dx[11] : dx[1];
}

static void rk4_step(const vehicle *veh, double *x, double v, const double *yt, const double *lam0, double h) {
  double k1[NS_MAX], k2[NS_MAX], k3[NS_MAX], k4[NS_MAX], tmp[NS_MAX];
  const int n = veh->n;
  vehicle_rhs(veh, x, v, yt, lam0, k1);
  for (int i = 0; i < n; ++i) tmp[i] = x[i] + 0.5 * h * k1[i];
  vehicle_rhs(veh, tmp, v, yt, lam0, k2);
  for (int i = 0; i < n; ++i) tmp[i] = x[i] + 0.5 * h * k2[i];
  vehicle_rhs(veh, tmp, v, yt, lam0, k3);
  for (int i = 0; i < n; ++i) tmp[i] = x[i] + h * k3[i];
  vehicle_rhs(veh, tmp, v, yt, lam0, k4);
  for (int i = 0; i < n; ++i) x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
}

/* ---- the linear truth ---- */

/* The eigenvalues (wr + i wi, n of them) of the vehicle linearised at the origin at V [km/h] with the conicity's
 * constant lambda0; dgeev's info (0: done). The right-hand side is affine at the origin up to third-order terms (the
 * flange force; lambda(r) r, whose Gaussians are 3e-21 there), so a forward difference of 1e-9 is exact to rounding. */
static int eigenvalues(const vehicle *veh, double v_kmh, double lambda0, double *wr, double *wi) {
  double A[NS_MAX * NS_MAX], x[NS_MAX] = {0}, d0[NS_MAX], d1[NS_MAX];
  const double v = v_kmh / 3.6, h = 1e-9, yt[2] = {0.0, 0.0}, lam0[2] = {lambda0, lambda0};
  const int n = veh->n;
  vehicle_rhs(veh, x, v, yt, lam0, d0);
  for (int j = 0; j < n; ++j) {
    x[j] = h;
    vehicle_rhs(veh, x, v, yt, lam0, d1);
    x[j] = 0.0;
    for (int i = 0; i < n; ++i) A[i + n * j] = (d1[i] - d0[i]) / h; /* column-major */
  }
  int nn = n, info = 0, lwork = 8 * NS_MAX, one = 1;
  double work[8 * NS_MAX], dummy = 0.0;
  dgeev_("N", "N", &nn, A, &nn, wr, wi, &dummy, &one, &dummy, &one, work, &lwork, &info);
  return info;
}

/* The largest real part among the complex eigenvalue pairs at V [km/h], lambda0, and that pair's frequency [Hz]
 * (-INFINITY, NAN if there is no complex pair; NAN, NAN if dgeev failed). */
static double least_damped(const vehicle *veh, double v_kmh, double lambda0, double *f_hz) {
  double wr[NS_MAX], wi[NS_MAX], best = -INFINITY;
  *f_hz = NAN;
  if (eigenvalues(veh, v_kmh, lambda0, wr, wi)) return NAN;
  for (int i = 0; i < veh->n; ++i)
    if (wi[i] > 0.0 && wr[i] > best) best = wr[i], *f_hz = wi[i] / (2.0 * PI);
  return best;
}

/* The largest |eigenvalue| at V [km/h]: RK4 is stable for h |s| below about 2.8 (on the real axis), so the substep
 * is kept at 2 / max|s| or below (the creep damping grows as 1 / v: the profile's lowest speed decides). */
static double spectral_radius(const vehicle *veh, double v_kmh, double lambda0) {
  double wr[NS_MAX], wi[NS_MAX], rho = 0.0;
  if (eigenvalues(veh, v_kmh, lambda0, wr, wi)) return NAN;
  for (int i = 0; i < veh->n; ++i) rho = fmax(rho, hypot(wr[i], wi[i]));
  return rho;
}

/* The Hopf speed [km/h]: the first 5 km/h step of 100..1500 where the least-damped pair's real part turns positive,
 * bisected to 0.01 km/h (the last bracket's midpoint), and the pair's frequency there; NAN if there is no such
 * crossing (stable throughout, or unstable from 100 km/h on). */
static double hopf_speed(const vehicle *veh, double lambda0, double *f_hz) {
  double lo = 100.0, f;
  *f_hz = NAN;
  if (!(least_damped(veh, lo, lambda0, &f) < 0.0)) return NAN;
  for (double v = 105.0; v <= 1500.0 + 1e-9; v += 5.0) {
    if (least_damped(veh, v, lambda0, &f) > 0.0) {
      double hi = v;
      while (hi - lo > 0.01) {
        const double mid = 0.5 * (lo + hi);
        if (least_damped(veh, mid, lambda0, &f) > 0.0) hi = mid;
        else lo = mid;
      }
      least_damped(veh, 0.5 * (lo + hi), lambda0, f_hz);
      return 0.5 * (lo + hi);
    }
    lo = v;
  }
  return NAN;
}

/* ---- random numbers: splitmix64 streams, Box-Muller ---- */

typedef struct {
  uint64_t state;
  double spare;
  int has_spare;
} rng;

enum { STREAM_TRACK = 1, STREAM_NOISE, STREAM_SPEED, STREAM_LINES, STREAM_BROAD };

static uint64_t splitmix64(uint64_t *s) {
  uint64_t z = (*s += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

/* one independent stream per use, so that adding a line to the signal leaves the track and the noise as they were */
static rng rng_stream(uint64_t seed, uint64_t stream) {
  uint64_t s = seed ^ (stream * 0xd1b54a32d192ed03ull);
  rng r = {splitmix64(&s), 0.0, 0};
  return r;
}

static double rng_uniform(rng *r) { /* in (0, 1) */
  return ((double)(splitmix64(&r->state) >> 11) + 0.5) / 9007199254740992.0;
}

static double rng_normal(rng *r) {
  if (r->has_spare) {
    r->has_spare = 0;
    return r->spare;
  }
  const double rad = sqrt(-2.0 * log(rng_uniform(r))), ang = 2.0 * PI * rng_uniform(r);
  r->spare = rad * sin(ang);
  r->has_spare = 1;
  return rad * cos(ang);
}

/* ---- the track ---- */

typedef enum { FEATURE_SLABS, FEATURE_JOINTS, FEATURE_SPANS } feature_kind;

typedef struct {
  feature_kind kind;
  double length_m, amp_m;
} feature;

typedef struct {
  double *y;            /* the random alignment on a periodic grid of TRACK_DS_M [m]; NULL for --irr-mm 0 */
  size_t n;             /* its points, a power of two */
  const feature *feat;  /* the periodic features on top */
  int n_feat;
} track;

/* Slabs: A sin(2 pi p / L), a lone line. Joints: A exp(-(d / 0.5 m)^2), spans: A exp(-(d / 0.15 L)^2), d the distance
 * to the nearest joint (at whole multiples of L); beyond 6 widths the bump is below 3e-16 A and left out. */
static double feature_at(const feature *f, double p) {
  if (f->kind == FEATURE_SLABS) return f->amp_m * sin(2.0 * PI * p / f->length_m);
  const double width = f->kind == FEATURE_JOINTS ? 0.5 : 0.15 * f->length_m;
  const double d = p - f->length_m * floor(p / f->length_m + 0.5), z = d / width;
  return fabs(z) > 6.0 ? 0.0 : f->amp_m * exp(-z * z);
}

static double track_at(const track *tr, double p) {
  double y = 0.0;
  if (tr->y) { /* linear interpolation on the periodic grid (negative p wraps round, as the FFT's track does) */
    const double u = p / TRACK_DS_M, fl = floor(u);
    const size_t mask = tr->n - 1, i = (size_t)(int64_t)fl & mask;
    y = tr->y[i] + (u - fl) * (tr->y[(i + 1) & mask] - tr->y[i]);
  }
  for (int k = 0; k < tr->n_feat; ++k) y += feature_at(&tr->feat[k], p);
  return y;
}

/* In-place radix-2 complex FFT of n points (a power of two): sign -1 forward, +1 inverse (unscaled). The twiddle
 * factors are computed directly (cos, sin of each angle: n - 1 pairs in all), not by recurrence. */
static void fft(double *re, double *im, size_t n, int sign) {
  for (size_t i = 1, j = 0; i < n; ++i) {
    size_t bit = n >> 1;
    for (; j & bit; bit >>= 1) j ^= bit;
    j ^= bit;
    if (i < j) {
      double t = re[i];
      re[i] = re[j], re[j] = t;
      t = im[i];
      im[i] = im[j], im[j] = t;
    }
  }
  for (size_t len = 2; len <= n; len <<= 1) {
    const double ang = sign * 2.0 * PI / (double)len;
    for (size_t j = 0; j < len / 2; ++j) {
      const double wr = cos(ang * (double)j), wi = sin(ang * (double)j);
      for (size_t i = j; i < n; i += len) {
        const size_t k = i + len / 2;
        const double xr = re[k] * wr - im[k] * wi, xi = re[k] * wi + im[k] * wr;
        re[k] = re[i] - xr, im[k] = im[i] - xi;
        re[i] += xr, im[i] += xi;
      }
    }
  }
}

/* The random alignment for length_m of line: random complex amplitudes (normal real and imaginary parts) / spatial
 * frequency between 1/60 and 1/3 1/m, Hermitian, inverse FFT, scaled to rms_m. -1 if out of memory. */
static int track_build(track *tr, double length_m, double rms_m, uint64_t seed) {
  tr->y = NULL;
  tr->n = 0;
  if (!(rms_m > 0.0)) return 0;
  size_t n = 4096;
  while ((double)n * TRACK_DS_M < length_m && n < ((size_t)1 << 22)) n <<= 1;
  double *re = calloc(n, sizeof *re), *im = calloc(n, sizeof *im);
  if (!re || !im) {
    free(re);
    free(im);
    return -1;
  }
  rng r = rng_stream(seed, STREAM_TRACK);
  const double df = 1.0 / ((double)n * TRACK_DS_M);
  for (size_t k = 1; k < n / 2; ++k) {
    const double f = (double)k * df;
    if (f <= 1.0 / 60.0 || f >= 1.0 / 3.0) continue;
    const double a = rng_normal(&r) / f, b = rng_normal(&r) / f;
    re[k] = a, im[k] = b;
    re[n - k] = a, im[n - k] = -b;
  }
  fft(re, im, n, +1);
  free(im);
  double ss = 0.0;
  for (size_t k = 0; k < n; ++k) ss += re[k] * re[k];
  const double scale = rms_m / sqrt(ss / (double)n);
  for (size_t k = 0; k < n; ++k) re[k] *= scale;
  tr->y = re;
  tr->n = n;
  return 0;
}

/* ---- the speed profile ---- */

typedef enum { PROFILE_CONST, PROFILE_STEPS, PROFILE_RAMP, PROFILE_NOTCHED } profile_kind;

typedef struct {
  profile_kind kind;
  int n;                                                                  /* steps */
  double v[MAX_STEPS], dur[MAX_STEPS], t0[MAX_STEPS], v_from[MAX_STEPS];   /* km/h, s, s, km/h (where a move starts) */
  double v0, rate, on, off, step_rate;                                    /* km/h, km/h/s, s, s, km/h/s */
} profile;

static double approach(double from, double to, double by) {
  return to > from ? fmin(to, from + by) : fmax(to, from - by);
}

/* The speed [km/h] at t [s]: a step moves from where the last one ended towards its speed at step_rate, then holds. */
static double profile_kmh(const profile *p, double t) {
  switch (p->kind) {
  case PROFILE_CONST: return p->v0;
  case PROFILE_RAMP: return p->v0 + p->rate * t;
  case PROFILE_NOTCHED: {
    const double cycle = p->on + p->off, k = floor(t / cycle);
    return p->v0 + p->rate * (k * p->on + fmin(t - k * cycle, p->on));
  }
  default: {
    int k = p->n - 1;
    while (k > 0 && p->t0[k] > t) --k;
    return approach(p->v_from[k], p->v[k], p->step_rate * (t - p->t0[k]));
  }
  }
}

static int parse_number(const char *s, double *x) {
  char *end;
  errno = 0;
  *x = strtod(s, &end);
  return end != s && *end == '\0' && isfinite(*x) && errno != ERANGE ? 0 : -1;
}

/* Numbers separated by the pattern's characters in turn ("@," for V@S,V@S; ":" for L:A): their count, or -1. */
static int parse_fields(const char *s, const char *seps, double *out, int max) {
  char buf[1024];
  const size_t np = strlen(seps);
  if (strlen(s) >= sizeof buf) return -1;
  strcpy(buf, s);
  char *p = buf;
  for (int n = 0; n < max; ++n) {
    char *q = p + strcspn(p, seps);
    const char c = *q;
    *q = '\0';
    if (parse_number(p, &out[n])) return -1;
    if (c == '\0') return n + 1;
    if (c != seps[n % np]) return -1;
    p = q + 1;
  }
  return -1;
}

static int parse_steps(profile *p, const char *rest) {
  double f[2 * MAX_STEPS];
  const int n = parse_fields(rest, "@,", f, 2 * MAX_STEPS);
  if (n < 2 || n % 2) return -1;
  p->kind = PROFILE_STEPS;
  p->n = n / 2;
  for (int k = 0; k < p->n; ++k) {
    p->v[k] = f[2 * k], p->dur[k] = f[2 * k + 1];
    if (!(p->dur[k] > 0.0)) return -1;
    p->t0[k] = k ? p->t0[k - 1] + p->dur[k - 1] : 0.0;
    p->v_from[k] = k ? approach(p->v_from[k - 1], p->v[k - 1], p->step_rate * p->dur[k - 1]) : p->v[0];
  }
  return 0;
}

/* const:V, steps:V@S,V@S,..., ramp:V0:RATE, notched:V0:RATE:ON:OFF; 0 or -1. */
static int profile_parse(profile *p, const char *spec, double step_rate) {
  memset(p, 0, sizeof *p);
  p->step_rate = step_rate;
  const char *colon = strchr(spec, ':');
  if (!colon) return -1;
  const size_t k = (size_t)(colon - spec);
  const char *rest = colon + 1;
  double f[4];
  if (k == 5 && !strncmp(spec, "steps", 5)) return parse_steps(p, rest);
  if (k == 5 && !strncmp(spec, "const", 5)) {
    p->kind = PROFILE_CONST;
    if (parse_fields(rest, ":", f, 1) != 1) return -1;
  } else if (k == 4 && !strncmp(spec, "ramp", 4)) {
    p->kind = PROFILE_RAMP;
    if (parse_fields(rest, ":", f, 2) != 2) return -1;
  } else if (k == 7 && !strncmp(spec, "notched", 7)) {
    p->kind = PROFILE_NOTCHED;
    if (parse_fields(rest, ":", f, 4) != 4 || !(f[2] > 0.0) || !(f[3] >= 0.0)) return -1;
    p->on = f[2], p->off = f[3];
  } else {
    return -1;
  }
  p->v0 = f[0];
  p->rate = p->kind == PROFILE_CONST ? 0.0 : f[1];
  return 0;
}

/* The lowest and highest speed over [0, T]: the ends and every step's speed (the moves between are monotone). */
static void profile_extremes(const profile *p, double T, double *lo, double *hi) {
  *lo = fmin(profile_kmh(p, 0.0), profile_kmh(p, T));
  *hi = fmax(profile_kmh(p, 0.0), profile_kmh(p, T));
  for (int k = 0; p->kind == PROFILE_STEPS && k < p->n; ++k) *lo = fmin(*lo, p->v[k]), *hi = fmax(*hi, p->v[k]);
}

static int add_distinct(double *v, int n, int max, double x) {
  for (int i = 0; i < n; ++i)
    if (fabs(v[i] - x) < 1e-9) return n;
  if (n < max) v[n++] = x;
  return n;
}

/* The distinct speeds of the profile's steady parts that begin within [0, T): the constant, each step's speed, each
 * hold of a notched ramp; none for a ramp (unless its rate is 0). */
static int profile_steady(const profile *p, double T, double *v, int max) {
  int n = 0;
  if (p->kind == PROFILE_CONST || (p->kind == PROFILE_RAMP && p->rate == 0.0)) n = add_distinct(v, n, max, p->v0);
  for (int k = 0; p->kind == PROFILE_STEPS && k < p->n; ++k)
    if (p->t0[k] < T) n = add_distinct(v, n, max, p->v[k]);
  if (p->kind == PROFILE_NOTCHED && p->off > 0.0)
    for (int k = 1; n < max && (k - 1) * (p->on + p->off) + p->on < T; ++k)
      n = add_distinct(v, n, max, p->v0 + p->rate * p->on * k);
  return n;
}

/* ---- the scenario: options ---- */

typedef struct {
  double f_hz, amp_mps2, sigma; /* --sine F:A (sigma 0), --broad F:SIGMA:A */
} signal_line;

typedef struct {
  const char *out, *name, *vehicle, *preset, *sensor, *profile_spec;
  double kx_mn, ky_mn, lambda0, noise, bias, fs, step_rate, t_s, speed_hz, speed_noise, speed_quant, irr_mm;
  bogie_params over; /* --mf ... --cpsi (NAN: the preset's) */
  bogie_params b;    /* the bogie run (preset and overrides) */
  feature feat[MAX_FEATURES];
  signal_line sine[MAX_LINES], broad[MAX_LINES];
  int n_feat, n_sine, n_broad, has_switch, truth_only, frame_sensor, bogie;
  double switch_s, switch_l0;
  uint64_t seed;
  profile prof;
} scenario;

typedef struct option_spec {
  const char *name, *arg;
  int (*parse)(scenario *sc, const struct option_spec *o, const char *value); /* NULL: a number at offset */
  size_t offset;
  double lo, hi; /* a number's range; a feature's wavelength range */
  const char *help;
} option_spec;

static int fail(const char *fmt, ...) {
  va_list ap;
  fputs("hm_scenario: ", stderr);
  va_start(ap, fmt);
  vfprintf(stderr, fmt, ap);
  va_end(ap);
  fputc('\n', stderr);
  return 2;
}

static int opt_text(scenario *sc, const option_spec *o, const char *value) {
  *(const char **)((char *)sc + o->offset) = value;
  return 0;
}

static int opt_seed(scenario *sc, const option_spec *o, const char *value) {
  char *end;
  errno = 0;
  const unsigned long long s = strtoull(value, &end, 10);
  if (value[0] < '0' || value[0] > '9' || *end != '\0' || errno == ERANGE)
    return fail("--%s: '%s' is not an unsigned 64-bit integer", o->name, value);
  sc->seed = (uint64_t)s;
  return 0;
}

/* --slabs / --joints / --spans L:A (L in the option's range [m], |A| <= 5 mm) */
static int opt_feature(scenario *sc, const option_spec *o, const char *value) {
  double f[2];
  if (parse_fields(value, ":", f, 2) != 2) return fail("--%s: '%s' is not L:A", o->name, value);
  if (!(f[0] >= o->lo && f[0] <= o->hi)) return fail("--%s: L %g m is out of %g..%g", o->name, f[0], o->lo, o->hi);
  if (!(fabs(f[1]) <= 5.0)) return fail("--%s: A %g mm is out of -5..5", o->name, f[1]);
  if (sc->n_feat == MAX_FEATURES) return fail("at most %d track features", MAX_FEATURES);
  const feature_kind kind = o->name[1] == 'l' ? FEATURE_SLABS : o->name[0] == 'j' ? FEATURE_JOINTS : FEATURE_SPANS;
  sc->feat[sc->n_feat++] = (feature){kind, f[0], f[1] * 1e-3};
  return 0;
}

/* --sine F:A and --broad F:SIGMA:A (F in the option's range; the Nyquist frequency is checked with --fs) */
static int opt_line(scenario *sc, const option_spec *o, const char *value) {
  const int broad = o->name[0] == 'b', want = broad ? 3 : 2;
  double f[3];
  if (parse_fields(value, ":", f, want) != want)
    return fail("--%s: '%s' is not %s", o->name, value, broad ? "F:SIGMA:A" : "F:A");
  const double amp = f[want - 1], sigma = broad ? f[1] : 0.0;
  if (!(f[0] >= o->lo && f[0] <= o->hi)) return fail("--%s: F %g Hz is out of %g..%g", o->name, f[0], o->lo, o->hi);
  if (!(amp >= 0.0 && amp <= 50.0)) return fail("--%s: A %g m/s^2 is out of 0..50", o->name, amp);
  if (broad && !(sigma >= -200.0 && sigma <= -0.1))
    return fail("--%s: SIGMA %g 1/s is out of -200..-0.1 (a decaying mode)", o->name, sigma);
  int *n = broad ? &sc->n_broad : &sc->n_sine;
  if (*n == MAX_LINES) return fail("at most %d --%s", MAX_LINES, o->name);
  (broad ? sc->broad : sc->sine)[(*n)++] = (signal_line){f[0], amp, sigma};
  return 0;
}

static int opt_switch(scenario *sc, const option_spec *o, const char *value) {
  double f[2];
  if (parse_fields(value, ":", f, 2) != 2) return fail("--%s: '%s' is not S:L0", o->name, value);
  if (!(f[0] >= 0.0 && f[0] <= 1e8)) return fail("--%s: S %g m is out of 0..1e8", o->name, f[0]);
  if (!(f[1] >= 0.03 && f[1] <= 0.6)) return fail("--%s: L0 %g is out of 0.03..0.6", o->name, f[1]);
  sc->has_switch = 1, sc->switch_s = f[0], sc->switch_l0 = f[1];
  return 0;
}

#define NUM(field) NULL, offsetof(scenario, field)
#define TEXT(field) opt_text, offsetof(scenario, field), 0.0, 0.0
static const option_spec OPTIONS[] = {
    {"out", "DIR", TEXT(out), "directory of the recordings (an existing one)"},
    {"name", "NAME", TEXT(name), "recording name: DIR/NAME_accel.csv, _speed.csv, _truth.json ([A-Za-z0-9._-])"},
    {"vehicle", "KIND", TEXT(vehicle), "wheelset | bogie (wheelset)"},
    {"bogie-preset", "NAME", TEXT(preset), "stiff | standard | soft | unstable (standard)"},
    {"mf", "KG", NUM(over.mf), 100.0, 50e3, "bogie frame mass (preset)"},
    {"If", "KG_M2", NUM(over.If), 50.0, 50e3, "bogie frame yaw inertia (preset)"},
    {"a", "M", NUM(over.a), 0.5, 2.5, "half wheelbase (preset)"},
    {"ksy", "N/M", NUM(over.ksy), 0.0, 1e8, "secondary lateral stiffness (preset)"},
    {"csy", "N_S/M", NUM(over.csy), 0.0, 1e7, "secondary lateral damping (preset)"},
    {"kspsi", "N_M/RAD", NUM(over.kspsi), 0.0, 1e8, "secondary yaw stiffness (preset)"},
    {"cpsi", "N_M_S/RAD", NUM(over.cpsi), 0.0, 1e8, "yaw damping (preset)"},
    {"kx", "MN/M", NUM(kx_mn), 0.5, 50.0, "primary longitudinal stiffness (8.96; a bogie: its preset's)"},
    {"ky", "MN/M", NUM(ky_mn), 0.5, 50.0, "primary lateral stiffness (8.96; a bogie: its preset's)"},
    {"lambda0", "L", NUM(lambda0), 0.03, 0.6, "the conicity's constant (0.1358)"},
    {"lambda-switch", "S:L0", opt_switch, 0, 0.0, 0.0, "the conicity's constant becomes L0 from S m on"},
    {"sensor", "WHERE", TEXT(sensor), "axlebox | frame (axlebox; frame needs the bogie)"},
    {"noise", "MPS2", NUM(noise), 0.0, 20.0, "accelerometer white noise r.m.s. (0.2)"},
    {"bias", "MPS2", NUM(bias), -50.0, 50.0, "accelerometer offset (0)"},
    {"fs", "HZ", NUM(fs), 200.0, 5000.0, "accelerometer rate (1000)"},
    {"profile", "SPEC", TEXT(profile_spec), "const:V, steps:V@S,.., ramp:V0:RATE, notched:V0:RATE:ON:OFF (const:300)"},
    {"step-rate", "KMH/S", NUM(step_rate), 0.01, 20.0, "speed change between steps (0.5)"},
    {"t", "S", NUM(t_s), 1e-3, 3600.0, "recording length (60)"},
    {"speed-hz", "HZ", NUM(speed_hz), 1.0, 200.0, "speed signal rate (10)"},
    {"speed-noise", "KMH", NUM(speed_noise), 0.0, 20.0, "speed signal white noise r.m.s. (0.3)"},
    {"speed-quant", "KMH", NUM(speed_quant), 0.0, 50.0, "speed signal quantisation step, 0 none (0)"},
    {"irr-mm", "MM", NUM(irr_mm), 0.0, 5.0, "track alignment irregularity r.m.s., wavelengths 3-60 m (0.3)"},
    {"slabs", "L:A", opt_feature, 0, 3.0, 10.0, "slabs: A mm sin(2 pi s / L), L 3..10 m (repeatable)"},
    {"joints", "L:A", opt_feature, 0, 10.0, 60.0, "joints: A mm exp(-(d/0.5)^2) every L m, L 10..60 (repeatable)"},
    {"spans", "L:A", opt_feature, 0, 15.0, 60.0, "spans: A mm exp(-(d/0.15L)^2) every L m, L 15..60 (repeatable)"},
    {"sine", "F:A", opt_line, 0, 0.1, 2500.0, "a fixed line of F Hz, amplitude A m/s^2 (repeatable)"},
    {"broad", "F:SIGMA:A", opt_line, 0, 0.5, 2500.0, "a noise-driven mode: F Hz, SIGMA 1/s < 0, r.m.s. A (rep.)"},
    {"seed", "N", opt_seed, 0, 0.0, 0.0, "seed of the track, the noises and the lines (1)"},
};
#undef NUM
#undef TEXT

static void usage(FILE *f) {
  fputs("usage: hm_scenario --out DIR --name NAME [options]\n"
        "A recording (lateral acceleration, speed) of a wheelset or a bogie on an irregular line, and its truth\n"
        "(the Hopf speed, the least-damped modes, the hunting onset). Options:\n",
        f);
  for (size_t i = 0; i < sizeof OPTIONS / sizeof OPTIONS[0]; ++i)
    fprintf(f, "  --%-13s %-10s %s\n", OPTIONS[i].name, OPTIONS[i].arg, OPTIONS[i].help);
  fputs("  --truth-only             the truth only (no recording; the files only with --out and --name)\n"
        "  --help                   this text\n",
        f);
}

static void scenario_defaults(scenario *sc) {
  memset(sc, 0, sizeof *sc);
  sc->vehicle = "wheelset", sc->sensor = "axlebox", sc->profile_spec = "const:300";
  sc->kx_mn = sc->ky_mn = NAN, sc->lambda0 = 0.1358, sc->noise = 0.2, sc->fs = 1000.0, sc->step_rate = 0.5;
  sc->t_s = 60.0, sc->speed_hz = 10.0, sc->speed_noise = 0.3, sc->irr_mm = 0.3, sc->seed = 1;
  sc->over = (bogie_params){NAN, NAN, NAN, NAN, NAN, NAN, NAN};
}

/* 0, 1 for --help (done), 2 after a message */
static int parse_args(scenario *sc, int argc, char **argv) {
  for (int i = 1; i < argc; ++i) {
    const char *a = argv[i];
    if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
      usage(stdout);
      return 1;
    }
    if (!strcmp(a, "--truth-only")) {
      sc->truth_only = 1;
      continue;
    }
    const option_spec *o = NULL;
    for (size_t k = 0; k < sizeof OPTIONS / sizeof OPTIONS[0] && !o; ++k)
      if (!strncmp(a, "--", 2) && !strcmp(a + 2, OPTIONS[k].name)) o = &OPTIONS[k];
    if (!o) return fail("unknown option '%s' (see --help)", a);
    if (i + 1 >= argc) return fail("--%s needs a value %s", o->name, o->arg);
    const char *value = argv[++i];
    if (o->parse) {
      const int rc = o->parse(sc, o, value);
      if (rc) return rc;
      continue;
    }
    double x;
    if (parse_number(value, &x)) return fail("--%s: '%s' is not a number", o->name, value);
    if (!(x >= o->lo && x <= o->hi)) return fail("--%s: %g is out of range %g..%g", o->name, x, o->lo, o->hi);
    *(double *)((char *)sc + o->offset) = x;
  }
  return 0;
}

/* The vehicle from --vehicle, --bogie-preset and the overrides. */
static int resolve_vehicle(scenario *sc, vehicle *veh) {
  const bogie_params *ov = &sc->over;
  const int overridden = !isnan(ov->mf) || !isnan(ov->If) || !isnan(ov->a) || !isnan(ov->ksy) || !isnan(ov->csy) ||
                         !isnan(ov->kspsi) || !isnan(ov->cpsi);
  if (strcmp(sc->vehicle, "wheelset") && strcmp(sc->vehicle, "bogie"))
    return fail("--vehicle: '%s' is neither wheelset nor bogie", sc->vehicle);
  sc->bogie = !strcmp(sc->vehicle, "bogie");
  if (!sc->bogie && (sc->preset || overridden))
    return fail("--bogie-preset, --mf, --If, --a, --ksy, --csy, --kspsi and --cpsi need --vehicle bogie");
  if (strcmp(sc->sensor, "axlebox") && strcmp(sc->sensor, "frame"))
    return fail("--sensor: '%s' is neither axlebox nor frame", sc->sensor);
  sc->frame_sensor = !strcmp(sc->sensor, "frame");
  if (sc->frame_sensor && !sc->bogie) return fail("--sensor frame needs --vehicle bogie (a wheelset has no frame)");
  const char *preset = sc->preset ? sc->preset : "standard";
  const bogie_preset *p = NULL;
  for (size_t k = 0; k < sizeof PRESETS / sizeof PRESETS[0]; ++k)
    if (!strcmp(PRESETS[k].name, preset)) p = &PRESETS[k];
  if (!p) return fail("--bogie-preset: '%s' is none of stiff, standard, soft, unstable", preset);
  sc->b = p->p;
  if (!isnan(ov->mf)) sc->b.mf = ov->mf;
  if (!isnan(ov->If)) sc->b.If = ov->If;
  if (!isnan(ov->a)) sc->b.a = ov->a;
  if (!isnan(ov->ksy)) sc->b.ksy = ov->ksy;
  if (!isnan(ov->csy)) sc->b.csy = ov->csy;
  if (!isnan(ov->kspsi)) sc->b.kspsi = ov->kspsi;
  if (!isnan(ov->cpsi)) sc->b.cpsi = ov->cpsi;
  if (isnan(sc->kx_mn)) sc->kx_mn = sc->bogie ? p->kx_mn : 8.96;
  if (isnan(sc->ky_mn)) sc->ky_mn = sc->bogie ? p->ky_mn : 8.96;
  veh->bogie = sc->bogie;
  veh->n = sc->bogie ? 12 : 4;
  veh->kx = sc->kx_mn * 1e6, veh->ky = sc->ky_mn * 1e6, veh->kg = veh->kx * (L_RATIO - 1.0);
  veh->b = sc->b;
  return 0;
}

/* Everything that needs more than one option: the profile, the Nyquist frequency, the files' names. */
static int resolve_signal(scenario *sc) {
  if (profile_parse(&sc->prof, sc->profile_spec, sc->step_rate))
    return fail("--profile: '%s' is none of const:V, steps:V@S,V@S..., ramp:V0:RATE, notched:V0:RATE:ON:OFF (ON > 0, "
                "OFF >= 0, S > 0, at most %d steps)",
                sc->profile_spec, MAX_STEPS);
  double lo, hi;
  profile_extremes(&sc->prof, sc->t_s, &lo, &hi);
  if (!(lo >= 20.0 && hi <= 1500.0))
    return fail("--profile: the speed reaches %g..%g km/h within --t %g s (20..1500 km/h is simulated)", lo, hi,
                sc->t_s);
  for (int k = 0; k < sc->n_sine + sc->n_broad; ++k) {
    const double f = k < sc->n_sine ? sc->sine[k].f_hz : sc->broad[k - sc->n_sine].f_hz;
    if (!(f < 0.5 * sc->fs))
      return fail("--sine/--broad: %g Hz is not below the Nyquist frequency %g Hz", f, sc->fs / 2.0);
  }
  if (!sc->truth_only && (!sc->out || !sc->name)) return fail("--out DIR and --name NAME are required");
  if (sc->name && (!sc->name[0] || strlen(sc->name) > 200 || strspn(sc->name,
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789._-") != strlen(sc->name)))
    return fail("--name: '%s' must be 1-200 of A-Z a-z 0-9 . _ -", sc->name);
  struct stat st;
  if (sc->out && (!sc->out[0] || strlen(sc->out) > 3000 || stat(sc->out, &st) || !S_ISDIR(st.st_mode)))
    return fail("--out: '%s' is not an existing directory", sc->out);
  return 0;
}

/* ---- the recording ---- */

typedef struct {
  double hopf_kmh, hopf_hz, hopf_after_kmh, hopf_after_hz;
  int n_steady;
  double steady_kmh[MAX_STEADY], steady_sigma[MAX_STEADY], steady_hz[MAX_STEADY];
  double after_sigma[MAX_STEADY], after_hz[MAX_STEADY];
  double t_hunt, v_hunt, max_disp_m, switch_t, stopped_t, tail_rms, duration_s;
  long samples;
  int substeps;
} truth;

/* test_bogie.c's hunting rule: |y1| beyond 3 mm in each of HUNT_BLOCKS 0.25 s blocks in a row; the onset is the first
 * crossing in the first block of the run. */
typedef struct {
  long block;
  int run;
  double block_max, first_t, first_v, run_t, run_v, onset_t, onset_v;
} hunt_watch;

static void hunt_close_block(hunt_watch *w) {
  if (w->block_max > HUNT_M) {
    if (w->run++ == 0) w->run_t = w->first_t, w->run_v = w->first_v;
    if (w->run == HUNT_BLOCKS && isnan(w->onset_t)) w->onset_t = w->run_t, w->onset_v = w->run_v;
  } else {
    w->run = 0;
  }
}

static void hunt_update(hunt_watch *w, double t, double v_kmh, double y_abs) {
  const long b = (long)floor(t / HUNT_BLOCK_S);
  if (b != w->block) {
    hunt_close_block(w);
    w->block = b, w->block_max = 0.0, w->first_t = NAN;
  }
  w->block_max = fmax(w->block_max, y_abs);
  if (isnan(w->first_t) && y_abs > HUNT_M) w->first_t = t, w->first_v = v_kmh;
}

/* What the accelerometer adds: noise, offset, the fixed lines, the noise-driven modes (AR(2) recursions with the poles
 * exp((sigma +- i w) / fs), their stationary variance (1 - p2) / ((1 + p2) ((1 - p2)^2 - p1^2)) scaled to A^2, run in
 * for 10 time constants). */
typedef struct {
  rng noise, lines;
  double phase[MAX_LINES];
  double p1[MAX_LINES], p2[MAX_LINES], gain[MAX_LINES], x1[MAX_LINES], x2[MAX_LINES];
} sensor_state;

static double broad_next(sensor_state *ss, int k) {
  const double x = ss->p1[k] * ss->x1[k] + ss->p2[k] * ss->x2[k] + rng_normal(&ss->lines);
  ss->x2[k] = ss->x1[k], ss->x1[k] = x;
  return ss->gain[k] * x;
}

static void sensor_init(sensor_state *ss, const scenario *sc) {
  memset(ss, 0, sizeof *ss);
  ss->noise = rng_stream(sc->seed, STREAM_NOISE);
  rng ph = rng_stream(sc->seed, STREAM_LINES);
  for (int k = 0; k < sc->n_sine; ++k) ss->phase[k] = 2.0 * PI * rng_uniform(&ph);
  ss->lines = rng_stream(sc->seed, STREAM_BROAD);
  for (int k = 0; k < sc->n_broad; ++k) {
    const signal_line *b = &sc->broad[k];
    const double rho = exp(b->sigma / sc->fs), th = 2.0 * PI * b->f_hz / sc->fs;
    const double p1 = 2.0 * rho * cos(th), p2 = -rho * rho;
    ss->p1[k] = p1, ss->p2[k] = p2;
    ss->gain[k] = b->amp_mps2 / sqrt((1.0 - p2) / ((1.0 + p2) * ((1.0 - p2) * (1.0 - p2) - p1 * p1)));
    for (long i = 0, n = (long)ceil(10.0 * sc->fs / -b->sigma); i < n; ++i) (void)broad_next(ss, k);
  }
}

static double measured(const scenario *sc, sensor_state *ss, double t, double vehicle_accel) {
  double a = vehicle_accel + sc->bias + sc->noise * rng_normal(&ss->noise);
  for (int k = 0; k < sc->n_sine; ++k) a += sc->sine[k].amp_mps2 * sin(2.0 * PI * sc->sine[k].f_hz * t + ss->phase[k]);
  for (int k = 0; k < sc->n_broad; ++k) a += broad_next(ss, k);
  return a;
}

/* The track's position and the conicity's constant under each wheelset: the leading one at distance s, the rear one
 * 2a behind it (it meets the same track 2a / v later). */
static void wheel_inputs(const scenario *sc, const vehicle *veh, const track *tr, double s, double *yt, double *lam0) {
  for (int i = 0; i < (veh->bogie ? 2 : 1); ++i) {
    const double p = s - 2.0 * veh->b.a * i;
    yt[i] = track_at(tr, p);
    lam0[i] = sc->has_switch && p >= sc->switch_s ? sc->switch_l0 : sc->lambda0;
  }
}

typedef struct {
  double x[NS_MAX], s; /* the state; the leading wheelset's distance [m] */
} sim_state;

/* One sample period from t0: nsub RK4 substeps of h, the speed and the track held over each. */
static void advance(const scenario *sc, const vehicle *veh, const track *tr, sim_state *st, double t0, int nsub,
                    double h) {
  double yt[2], lam0[2];
  for (int j = 0; j < nsub; ++j) {
    const double v = profile_kmh(&sc->prof, t0 + j * h) / 3.6;
    wheel_inputs(sc, veh, tr, st->s, yt, lam0);
    rk4_step(veh, st->x, v, yt, lam0, h);
    st->s += v * h;
  }
}

/* The acceleration recording (one row a sample) and the nonlinear truth: the hunting onset, the largest |y1|, the
 * switch's time, the vehicle's acceleration r.m.s. over the last TAIL_S. */
static void simulate(const scenario *sc, const vehicle *veh, const track *tr, FILE *out, truth *tru) {
  const double dt = 1.0 / sc->fs;
  const long n = lround(sc->t_s * sc->fs) > 0 ? lround(sc->t_s * sc->fs) : 1;
  double v_lo, v_hi;
  profile_extremes(&sc->prof, sc->t_s, &v_lo, &v_hi);
  const double rho = spectral_radius(veh, v_lo, fmax(sc->lambda0, sc->has_switch ? sc->switch_l0 : 0.0));
  const int nsub = (int)fmax(ceil(dt / H_MAX_S - 1e-9), isfinite(rho) ? ceil(dt * rho / 2.0 - 1e-9) : 1.0);
  sim_state st;
  memset(&st, 0, sizeof st);
  sensor_state ss;
  sensor_init(&ss, sc);
  hunt_watch hw = {0, 0, 0.0, NAN, NAN, NAN, NAN, NAN, NAN};
  double dx[NS_MAX], yt[2], lam0[2], tail_ss = 0.0;
  long tail_n = 0, i;
  tru->substeps = nsub;
  for (i = 0; i < n; ++i) {
    advance(sc, veh, tr, &st, (double)i * dt, nsub, dt / nsub);
    const double t = (double)(i + 1) * dt, v_kmh = profile_kmh(&sc->prof, t), y_abs = fabs(st.x[0]);
    wheel_inputs(sc, veh, tr, st.s, yt, lam0);
    vehicle_rhs(veh, st.x, v_kmh / 3.6, yt, lam0, dx);
    const double a_vehicle = sensor_accel(veh, sc->frame_sensor, dx);
    fprintf(out, "%.7f,%.5f\n", t, measured(sc, &ss, t, a_vehicle));
    hunt_update(&hw, t, v_kmh, y_abs);
    tru->max_disp_m = fmax(tru->max_disp_m, y_abs);
    if (sc->has_switch && isnan(tru->switch_t) && st.s >= sc->switch_s) tru->switch_t = t;
    if (t > (double)n * dt - TAIL_S) tail_ss += a_vehicle * a_vehicle, ++tail_n;
    if (!(y_abs <= STOP_M)) {
      tru->stopped_t = t;
      ++i;
      break;
    }
  }
  hunt_close_block(&hw);
  tru->t_hunt = hw.onset_t, tru->v_hunt = hw.onset_v;
  tru->tail_rms = tail_n ? sqrt(tail_ss / (double)tail_n) : NAN;
  tru->samples = i, tru->duration_s = (double)i * dt;
}

/* The speed signal: speed_hz samples from t = 0 of the profile with white noise, quantised if asked. */
static void write_speeds(const scenario *sc, FILE *out) {
  rng r = rng_stream(sc->seed, STREAM_SPEED);
  for (long j = 0; (double)j / sc->speed_hz <= sc->t_s + 1e-9; ++j) {
    const double t = (double)j / sc->speed_hz;
    double v = profile_kmh(&sc->prof, t) + sc->speed_noise * rng_normal(&r);
    if (sc->speed_quant > 0.0) v = sc->speed_quant * floor(v / sc->speed_quant + 0.5);
    fprintf(out, "%.6f,%.3f\n", t, v);
  }
}

static FILE *open_output(const scenario *sc, const char *suffix, char *path, size_t size) {
  snprintf(path, size, "%s/%s_%s", sc->out, sc->name, suffix);
  FILE *f = fopen(path, "w");
  if (!f) fprintf(stderr, "hm_scenario: cannot write %s: %s\n", path, strerror(errno));
  return f;
}

static int close_output(FILE *f, const char *path) {
  const int bad = ferror(f) | fclose(f);
  if (bad) fprintf(stderr, "hm_scenario: writing %s failed\n", path);
  return bad ? 1 : 0;
}

/* The two recordings; 1 on a failure (said on stderr). */
static int record(const scenario *sc, const vehicle *veh, truth *tru) {
  double lo, hi;
  char path[4096];
  profile_extremes(&sc->prof, sc->t_s, &lo, &hi);
  track tr = {NULL, 0, sc->feat, sc->n_feat};
  if (track_build(&tr, hi / 3.6 * sc->t_s + 2.0 * veh->b.a + 100.0, sc->irr_mm * 1e-3, sc->seed)) {
    fprintf(stderr, "hm_scenario: out of memory for the track\n");
    return 1;
  }
  FILE *f = open_output(sc, "accel.csv", path, sizeof path);
  int rc = !f;
  if (f) {
    setvbuf(f, NULL, _IOFBF, 1 << 20);
    fputs("t_s,accel_mps2\n", f);
    simulate(sc, veh, &tr, f, tru);
    rc = close_output(f, path);
  }
  free(tr.y);
  if (rc || !(f = open_output(sc, "speed.csv", path, sizeof path))) return 1;
  fputs("t_s,speed_kmh\n", f);
  write_speeds(sc, f);
  return close_output(f, path);
}

/* The linear truth: Hopf speeds (before and after a conicity switch), the least-damped pair at each steady speed. */
static void truth_linear(const scenario *sc, const vehicle *veh, truth *tru) {
  memset(tru, 0, sizeof *tru);
  tru->t_hunt = tru->v_hunt = tru->max_disp_m = tru->switch_t = tru->stopped_t = tru->tail_rms = NAN;
  tru->duration_s = NAN;
  tru->hopf_kmh = hopf_speed(veh, sc->lambda0, &tru->hopf_hz);
  tru->hopf_after_kmh = tru->hopf_after_hz = NAN;
  if (sc->has_switch) tru->hopf_after_kmh = hopf_speed(veh, sc->switch_l0, &tru->hopf_after_hz);
  tru->n_steady = profile_steady(&sc->prof, sc->t_s, tru->steady_kmh, MAX_STEADY);
  for (int k = 0; k < tru->n_steady; ++k) {
    tru->steady_sigma[k] = least_damped(veh, tru->steady_kmh[k], sc->lambda0, &tru->steady_hz[k]);
    if (sc->has_switch)
      tru->after_sigma[k] = least_damped(veh, tru->steady_kmh[k], sc->switch_l0, &tru->after_hz[k]);
  }
}

/* ---- the truth as JSON ---- */

typedef struct {
  FILE *f;
  int n; /* items so far in the innermost object or array */
} json_out;

static void j_key(json_out *j, const char *key) {
  fputs(j->n++ ? ", " : "", j->f);
  if (key) fprintf(j->f, "\"%s\": ", key);
}

static void j_num(json_out *j, const char *key, double x) {
  j_key(j, key);
  if (isfinite(x)) fprintf(j->f, "%.10g", x);
  else fputs("null", j->f);
}

static void j_str(json_out *j, const char *key, const char *s) {
  j_key(j, key);
  if (!s) {
    fputs("null", j->f);
    return;
  }
  fputc('"', j->f);
  for (; *s; ++s) {
    if (*s == '"' || *s == '\\') fprintf(j->f, "\\%c", *s);
    else if ((unsigned char)*s < 0x20) fprintf(j->f, "\\u%04x", (unsigned)(unsigned char)*s);
    else fputc(*s, j->f);
  }
  fputc('"', j->f);
}

static void j_open(json_out *j, const char *key, char c) {
  j_key(j, key);
  fputc(c, j->f);
  j->n = 0;
}

static void j_close(json_out *j, char c) {
  fputc(c, j->f);
  j->n = 1; /* the enclosing object or array has at least this item */
}

static void j_least_damped(json_out *j, const char *key, const truth *tr, const double *sigma, const double *hz) {
  j_open(j, key, '[');
  for (int k = 0; k < tr->n_steady; ++k) {
    j_open(j, NULL, '{');
    j_num(j, "speed_kmh", tr->steady_kmh[k]);
    j_num(j, "decay_rate_1_s", sigma[k]);
    j_num(j, "frequency_hz", hz[k]);
    j_close(j, '}');
  }
  j_close(j, ']');
}

static void j_lines(json_out *j, const char *key, const signal_line *l, int n, int broad) {
  j_open(j, key, '[');
  for (int k = 0; k < n; ++k) {
    j_open(j, NULL, '{');
    j_num(j, "f_hz", l[k].f_hz);
    if (broad) j_num(j, "sigma_1_s", l[k].sigma);
    j_num(j, broad ? "rms_mps2" : "amplitude_mps2", l[k].amp_mps2);
    j_close(j, '}');
  }
  j_close(j, ']');
}

static void j_features(json_out *j, const char *key, const scenario *sc, feature_kind kind) {
  j_open(j, key, '[');
  for (int k = 0; k < sc->n_feat; ++k) {
    if (sc->feat[k].kind != kind) continue;
    j_open(j, NULL, '{');
    j_num(j, "length_m", sc->feat[k].length_m);
    j_num(j, "amplitude_mm", sc->feat[k].amp_m * 1e3);
    j_close(j, '}');
  }
  j_close(j, ']');
}

static void j_settings(json_out *j, const scenario *sc) {
  j_open(j, "settings", '{');
  j_str(j, "vehicle", sc->vehicle);
  j_str(j, "bogie_preset", sc->bogie ? (sc->preset ? sc->preset : "standard") : NULL);
  const bogie_params *b = &sc->b;
  const double bv[] = {b->mf, b->If, b->a, b->ksy, b->csy, b->kspsi, b->cpsi};
  const char *bn[] = {"mf", "If", "a", "ksy", "csy", "kspsi", "cpsi"};
  for (int k = 0; k < 7; ++k) j_num(j, bn[k], sc->bogie ? bv[k] : NAN);
  j_num(j, "kx", sc->kx_mn), j_num(j, "ky", sc->ky_mn), j_num(j, "lambda0", sc->lambda0);
  j_key(j, "lambda_switch");
  if (sc->has_switch) fprintf(j->f, "{\"s_m\": %.10g, \"lambda0\": %.10g}", sc->switch_s, sc->switch_l0);
  else fputs("null", j->f);
  j_str(j, "sensor", sc->sensor);
  j_num(j, "noise", sc->noise), j_num(j, "bias", sc->bias), j_num(j, "fs", sc->fs);
  j_str(j, "profile", sc->profile_spec);
  j_num(j, "step_rate", sc->step_rate), j_num(j, "t", sc->t_s), j_num(j, "speed_hz", sc->speed_hz);
  j_num(j, "speed_noise", sc->speed_noise), j_num(j, "speed_quant", sc->speed_quant);
  j_num(j, "irr_mm", sc->irr_mm);
  j_features(j, "slabs", sc, FEATURE_SLABS);
  j_features(j, "joints", sc, FEATURE_JOINTS);
  j_features(j, "spans", sc, FEATURE_SPANS);
  j_lines(j, "sine", sc->sine, sc->n_sine, 0);
  j_lines(j, "broad", sc->broad, sc->n_broad, 1);
  j_key(j, "seed");
  fprintf(j->f, "%" PRIu64, sc->seed);
  j_key(j, "truth_only");
  fputs(sc->truth_only ? "true" : "false", j->f);
  j_str(j, "out", sc->out), j_str(j, "name", sc->name);
  j_close(j, '}');
}

static void write_truth(FILE *f, const scenario *sc, const truth *tr) {
  json_out j = {f, 0};
  j_open(&j, NULL, '{');
  j_str(&j, "name", sc->name);
  j_num(&j, "hopf_kmh", tr->hopf_kmh), j_num(&j, "hopf_frequency_hz", tr->hopf_hz);
  j_num(&j, "hopf_after_switch_kmh", tr->hopf_after_kmh);
  j_num(&j, "hopf_after_switch_frequency_hz", tr->hopf_after_hz);
  j_least_damped(&j, "least_damped_at_kmh", tr, tr->steady_sigma, tr->steady_hz);
  if (sc->has_switch) j_least_damped(&j, "least_damped_after_switch_at_kmh", tr, tr->after_sigma, tr->after_hz);
  j_num(&j, "t_hunt_3mm", tr->t_hunt), j_num(&j, "v_hunt_3mm", tr->v_hunt);
  j_num(&j, "max_disp_mm", tr->max_disp_m * 1e3);
  j_num(&j, "switch_t_s", tr->switch_t);
  j_num(&j, "stopped_at_s", tr->stopped_t); /* |y1| beyond 40 mm: the recording ends there */
  j_num(&j, "vehicle_accel_rms_last_20s_mps2", tr->tail_rms); /* the sensor's vehicle part: no noise, bias, lines */
  j_num(&j, "duration_s", tr->duration_s);
  j_num(&j, "samples", sc->truth_only ? NAN : (double)tr->samples);
  j_num(&j, "substeps", sc->truth_only ? NAN : (double)tr->substeps);
  j_settings(&j, sc);
  j_close(&j, '}');
  fputc('\n', f);
}

int main(int argc, char **argv) {
  scenario sc;
  scenario_defaults(&sc);
  int rc = parse_args(&sc, argc, argv);
  if (rc) return rc == 1 ? 0 : 2;
  vehicle veh;
  if ((rc = resolve_vehicle(&sc, &veh)) || (rc = resolve_signal(&sc))) return rc;
  truth tr;
  truth_linear(&sc, &veh, &tr);
  if (!sc.truth_only && record(&sc, &veh, &tr)) return 1;
  if (sc.out && sc.name) {
    char path[4096];
    FILE *f = open_output(&sc, "truth.json", path, sizeof path);
    if (!f) return 1;
    write_truth(f, &sc, &tr);
    if (close_output(f, path)) return 1;
  }
  write_truth(stdout, &sc, &tr);
  return fflush(stdout) ? 1 : 0;
}
