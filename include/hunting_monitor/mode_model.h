/*
 * hunting_monitor - the hunting mode of any vehicle model (wheelset, bogie, car) as a function of the wheels'
 * equivalent conicity lambda(0) and the speed: the identified mode read as a conicity and a Hopf speed by that model
 * (issue #28; inversion.h does the same in closed form for the wheelset alone).
 *
 * The model's conicity is set by shifting the constant of every wheelset's lambda(y) (hm_vehicle_set_conicity_at_zero).
 * Its hunting root at (lambda, v) is the eigenvalue of the Jacobian at the origin (dgeev) with a positive imaginary
 * part nearest a reference mode s_ref = sigma_ref + i 2 pi f_ref in the measured errors' metric
 * ((Re s - sigma_ref) / e_sigma)^2 + ((Im s - w_ref) / e_w)^2: a bogie has several oscillatory modes, and the one the
 * accelerometer shows is the one to follow.
 * The inversion minimises the same weighted misfit of the root from the measured mode over lambda: the start from a
 * scan of HM_MODE_MODEL_SCAN conicities over [0.01, 1] (the root nearest the measured mode at each), then Gauss-Newton
 * with the sensitivity ds/dlambda by central differences (step 1e-6 lambda), the root followed from the last one;
 * converged when the step is below tol; HM_ENOCONV after max_iter or outside 0 < lambda < 10. Its standard error and
 * chi2 as inversion.h's. For the wheelset it gives inversion.h's numbers (test_mode_model: to 1e-7).
 * The Hopf speed at a conicity: hm_system_critical_speed (HM_MODE_MODEL_V_MIN_KMH-1500 km/h, 5 km/h scan, bisection
 * to 1e-6 km/h), the first crossing of any mode, and whose mode that is.
 * The Hopf curve for the monitor (hm_mode_model_hopf_kmh): the exact speed at HM_MODE_MODEL_GRID conicities spaced
 * geometrically over [HM_MODE_MODEL_LAMBDA_MIN, HM_MODE_MODEL_LAMBDA_MAX], each computed when first needed, and
 * 1/V^2 interpolated linearly in the conicity between them (exact for the wheelset, whose Hurwitz condition is affine
 * in lambda; for the bogie within 0.05 km/h where one mode stays critical, test_mode_model); between grid points
 * whose critical modes differ in frequency by more than HM_MODE_MODEL_KINK_HZ (a kink: the bogie's wheelsets' mode
 * giving way to its frame's) the exact speed; 0 where the vehicle is unstable already at HM_MODE_MODEL_V_MIN_KMH.
 * One model is used by one thread at a time (it holds its parameters, system and curve); create allocates, nothing
 * after.
 */
#ifndef HUNTING_MONITOR_MODE_MODEL_H
#define HUNTING_MONITOR_MODE_MODEL_H

#include "hunting_monitor/bogie.h"
#include "hunting_monitor/car.h"
#include "hunting_monitor/inversion.h"
#include "hunting_monitor/model.h"
#include "hunting_monitor/status.h"
#include "hunting_monitor/system.h"

#ifdef __cplusplus
extern "C" {
#endif

#define HM_MODE_MODEL_SCAN 40
#define HM_MODE_MODEL_GRID 160
#define HM_MODE_MODEL_LAMBDA_MIN 0.01
#define HM_MODE_MODEL_LAMBDA_MAX 2.0
#define HM_MODE_MODEL_CURVE_ERR_KMH 0.05
#define HM_MODE_MODEL_V_MIN_KMH 1.0     /* the Hopf search starts here */
#define HM_MODE_MODEL_KINK_HZ 0.5       /* neighbouring grid points whose critical modes differ more: exact between */
#define HM_MODE_MODEL_BAND_LOW_HZ 2.0   /* the least-damped root's default band: hunting, not a carbody's sway */
#define HM_MODE_MODEL_BAND_HIGH_HZ 30.0 /* the curve's stated error against the exact Hopf speed (test_mode_model) */

typedef struct hm_mode_model_s *hm_mode_model;

/* A model of the wheelset, the bogie or the car; validated (HM_EDOMAIN), HM_ENOMEM; *out untouched on failure. */
hm_status hm_mode_model_create_wheelset(const hm_vehicle *veh, hm_mode_model *out);
hm_status hm_mode_model_create_bogie(const hm_bogie *bogie, hm_mode_model *out);
hm_status hm_mode_model_create_car(const hm_car *car, hm_mode_model *out);
void hm_mode_model_destroy(hm_mode_model m);

/* Any of the three from a kind and the car's parameters (the bogie's are car->bogie, the wheelset's
 * car->bogie.wheelset). */
hm_status hm_mode_model_create(hm_model_kind kind, const hm_car *params, hm_mode_model *out);

hm_model_kind hm_mode_model_kind(const hm_mode_model m);
/* The band [Hz] the least-damped root is sought in (0 <= low < high). */
hm_status hm_mode_model_set_band(hm_mode_model m, double low_hz, double high_hz);
/* The parameters the model was made with (the conicity as given at creation). */
void hm_mode_model_params(const hm_mode_model m, hm_car *params);

/* The least-damped oscillatory root at conicity and speed whose frequency lies in the model's band (by default
 * HM_MODE_MODEL_BAND_LOW_HZ..HIGH_HZ; the monitor sets its identification's band): the hunting mode that goes
 * unstable first, not a car's 0.6 Hz carbody sway. HM_ENOCRIT if none in the band. */
hm_status hm_mode_model_least_damped(hm_mode_model m, double conicity, double speed_kmh, double *sigma_1_s,
                                     double *omega_rad_s);

/* The Hopf speed at a conicity from the curve above [km/h]; HM_LINEAR_NO_HOPF_KMH (linear.h) where the origin is
 * stable up to 1500 km/h or the conicity is outside the grid's range, 0 where it is unstable at every speed; computes
 * grid points on first need. */
double hm_mode_model_hopf_kmh(hm_mode_model m, double conicity);

/* The hunting root at conicity and speed nearest the reference mode (errors e_sigma [1/s], e_f [Hz] > 0 weigh the
 * distance): its decay rate [1/s] and frequency [Hz]. HM_ENOCRIT if no oscillatory mode. */
hm_status hm_mode_model_root(hm_mode_model m, double conicity, double speed_kmh, double sigma_ref, double e_sigma,
                             double f_ref_hz, double e_f, double *sigma_1_s, double *f_hz);

/* The linear critical speed at a conicity [km/h], its frequency [Hz] and the body its mode moves (system.h's
 * body index; NULLs allowed). HM_ENOCRIT if none in HM_MODE_MODEL_V_MIN_KMH-1500 km/h. */
hm_status hm_mode_model_hopf(hm_mode_model m, double conicity, double *speed_kmh, double *f_hz, int *body);

/* The conicity whose hunting root is nearest the measured mode (above); inputs as inversion.h's. */
hm_status hm_mode_model_invert(hm_mode_model m, double speed_kmh, double sigma_m, double e_sigma, double f_m,
                               double e_f, double tol, unsigned max_iter, hm_conicity_inversion *out);

/* ---- the spectrum the model predicts at a sensor (a prototype of the reading for a model, issue #28) ----
 * The linearised model driven by the track's alignment under each wheelset (the trailing ones (x_0 - x_i) / v later)
 * through its right-hand side over a track (the derivative by one-sided differences of 1e-7 m), the track's spectrum
 * the German low-disturbance one (excitation.h); the acceleration at the point: its transfer function H(w) by a complex
 * solve (zgesv) per frequency; the shape |H(w)|^2 S(w / v) / v [(m/s^2)^2 / Hz, up to a constant factor]. */

/* Where an accelerometer sits on the model: "axlebox" (any model), "frame", "carbody" (bogie.h, car.h). */
hm_status hm_mode_model_sensor(hm_mode_model m, const char *where, hm_sensor_point *out);

/* The most frequencies a spectrum at a sensor is asked at once. */
#define HM_MODE_MODEL_SPECTRUM_MAX_BINS 4096

/* The shape at n (1..HM_MODE_MODEL_SPECTRUM_MAX_BINS) frequencies f_hz[] (> 0) for the conicity and speed into
 * shape[] (untouched on a failure). */
hm_status hm_mode_model_sensor_spectrum(hm_mode_model m, double conicity, double speed_kmh,
                                        const hm_sensor_point *point, const double *f_hz, size_t n, double *shape);

/* The running state the spectrum is linearised about: the periodogram's window (each pole widened by its leakage,
 * 2 / window_s, as the identification's fit takes a window's leakage, whittle.h; 0: none) and each wheelset's rms displacement
 * from the track [m] (0: at rest; otherwise Gaussian equivalent linearisation: the wheel-rail terms' mean slope over
 * that motion, which for MODEL.md's flange force alpha1 r^3 + alpha2 r^5 is 3 alpha1 s^2 + 15 alpha2 s^4; lambda(y)
 * enters likewise, though the 5-point rule is exact for F_T alone: for MODEL.md's lambda(y), whose Gaussians of width
 * 1.45 mm sit at +-10 mm, its mean is good to 0.3% up to 2 mm of motion and wrong by tens of percent from 3 mm, where
 * a wheelset nears its flange and no Gaussian linearisation holds). Leading wheelset first, as the system's. */
typedef struct {
  double window_s;
  double motion_rms_m[HM_SYSTEM_MAX_WHEELSETS];
} hm_running;

/* The shape at n frequencies (as hm_mode_model_sensor_spectrum) about a running state. HM_EDOMAIN for a window below 0
 * or a motion below 0 or not finite. */
hm_status hm_mode_model_running_spectrum(hm_mode_model m, double conicity, double speed_kmh,
                                         const hm_sensor_point *point, const hm_running *run, const double *f_hz,
                                         size_t n, double *shape);

/* Each wheelset's rms displacement from the track [m] (motion_rms_m[0..n_wheelsets-1]) when the track's spectrum is
 * `amplitude` times the shape's (the factor a fit of the shape to a measured two-sided density finds, spectrum_fit.h):
 * 2 a times the integral over f > 0 of |R_i(f)|^2 S(2 pi f / v) / v, R_i the transfer from the track to wheelset i's
 * displacement from it, over the track's wavelengths 1-200 m (400 points geometric in f), linearised about run. */
hm_status hm_mode_model_motion_rms(hm_mode_model m, double conicity, double speed_kmh, const hm_running *run,
                                   double amplitude, double *motion_rms_m);

/* The relative band [-] around a frequency in which hm_mode_model_displacement_per_accel takes its mode. */
#define HM_MODE_MODEL_SHAPE_BAND 0.05
/* The wheelsets' displacement per acceleration at the sensor point [m per m/s^2] in an oscillation at f_hz (> 0): in
 * the mode shape of the least-damped oscillatory root within HM_MODE_MODEL_SHAPE_BAND of f (the right eigenvector of
 * the Jacobian at rest), the largest wheelset lateral displacement over the point's acceleration (lambda times its
 * velocity states). A self-excited oscillation is that mode's (hunting is its limit cycle: the shape near the Hopf
 * point's), not the track's forced response, whose wheelsets meet the track 2b / v apart: from a bogie frame's
 * hunting it reads the wheelsets' amplitude (estimator.h's displacement map). *out untouched on a failure
 * (HM_EDOMAIN for a speed or frequency not > 0 and finite, a conicity < 0 or not finite; HM_ENOCRIT without such a
 * root; HM_ENONFINITE where the point does not move in it). */
hm_status hm_mode_model_displacement_per_accel(hm_mode_model m, double conicity, double speed_kmh,
                                               const hm_sensor_point *point, double f_hz, double *out);

/* ---- the monitor's reading on the model ----
 * The monitor reads the hunting mode off the sensor's spectrum as one or two pole pairs over a smooth background
 * (modal.h), and on a bogie that reading is no eigenvalue: its two wheelsets meet the same track 2b / v apart and an
 * axle box sums their responses, so its peak is sharper than the least-damped root (the default bogie, conicity
 * 0.1358, 460 km/h: the least-damped root -4.58 1/s at 13.76 Hz; one pair reads -5.93 at 14.58 Hz, two pairs -2.18 at
 * 14.05 beside -6.48 at 16.41). The model's reading is that same fit (whittle.h) on the model's spectrum at the sensor
 * (above, times the measured signal's filters where given, without sensor noise: a floor of HM_MODE_MODEL_READING_FLOOR
 * of its mean) over the model's band in bins of
 * HM_MODE_MODEL_READING_DF_HZ (wider where the band needs more than HM_MODE_MODEL_READING_MAX_BINS), its poles moved left by the leakage of a HM_MODE_MODEL_READING_WINDOW_S window and the fit
 * told that window (whittle.h's leakage, so that the reading is the pole pair's own; a peak sharper than the bins
 * would leave the fit rough), started from three widths at the peak and from every root in the band (the best likelihood kept), or within an
 * inversion from the measured mode and from the peak (the one nearest the measured mode kept; two pairs: of the two
 * splits of that pair's peak the one of least objective, as modal.c keeps); a fit counts as a mode
 * when its damping ratio is below HM_MODE_MODEL_READING_MAX_ZETA and its peak above HM_MODE_MODEL_READING_MIN_PEAK
 * times the band's mean; the pair the monitor takes for the mode (the less damped of
 * two). Inverting the measured reading against it (hm_mode_model_invert_reading) compares like with like: on the
 * wheelset it is the least-damped root to about 0.07 1/s (test_mode_model). Costs one spectrum (a complex solve of
 * the model's dimension per bin) and one fit per conicity tried. */
#define HM_MODE_MODEL_READING_DF_HZ 0.025
#define HM_MODE_MODEL_READING_WINDOW_S 10.0 /* the leakage both sides are given (a peak a few bins wide) */
#define HM_MODE_MODEL_READING_MAX_BINS 1024
#define HM_MODE_MODEL_READING_FLOOR 1e-6
#define HM_MODE_MODEL_READING_MAX_ZETA 0.5  /* a reading more damped than this is no mode (modal.h's validity) */
#define HM_MODE_MODEL_READING_MIN_PEAK 1.0  /* nor one whose peak lies below the band's mean level */
#define HM_MODE_MODEL_READING_TOL 1e-11 /* the fit's relative change of the objective that ends it */
#define HM_MODE_MODEL_READING_ITER 200
#define HM_MODE_MODEL_READING_SCAN 16   /* conicities 0.02-0.8 (geometric) the reading's inversion starts from */
#define HM_MODE_MODEL_EDGE_RTOL 1e-9    /* the stability edge's bisection in the conicity (relative) */
/* readings the stable pass's start is refined with (golden section over the best scanned conicity's neighbours), the
 * relative precision its bracket is cut at the stability edges with, and the misfit above which the pass is retried
 * from that start (the readings' misfit is rough in the conicity: Gauss-Newton from a scanned point ended in local
 * minima of chi2 4-1600 where another start found the model's own reading to 1e-6) */
#define HM_MODE_MODEL_START_EVALS 10
#define HM_MODE_MODEL_START_EDGE_RTOL 1e-4
#define HM_MODE_MODEL_RETRY_CHI2 1.0
/* the unconstrained pass from an unstable start: where the reading's decay rate sits at 0 (beyond the edge, its slope
 * 0) the steps oscillate to max_iter (60 in margin.c: 1.2-1.6 s), where a result comes within 3-5 */
#define HM_MODE_MODEL_UNSTABLE_START_ITER 15

/* The sensor whose reading the model gives ("axlebox", "frame", "carbody" as hm_mode_model_sensor); NULL: none (the
 * inversion by roots). HM_EINVAL for a place the model has not, the sensor unchanged. */
hm_status hm_mode_model_set_sensor(hm_mode_model m, const char *where);
/* The power gain |H(f)|^2 of what filters the measured signal before its reading (the monitor's: modal.h's
 * hm_modal_filter_power_gain with its hm_modal), applied to the model's spectrum; NULL: none. ctx is borrowed. */
typedef double (*hm_mode_model_gain_fn)(const void *ctx, double f_hz);
void hm_mode_model_set_reading_gain(hm_mode_model m, hm_mode_model_gain_fn gain, const void *ctx);
int hm_mode_model_has_sensor(const hm_mode_model m);

/* The model's reading with `poles` pairs (1 or 2) at conicity and speed: the mode's decay rate (-|sigma|, or +|sigma|
 * where the root it follows, the oscillatory one nearest it in frequency, is unstable: no stationary spectrum to read,
 * and the measured one is not its mirror image) and frequency. Without a measured mode to follow the best-fitting
 * peak is read, which may change from one peak to another with the conicity. HM_EDOMAIN without a sensor; HM_ENOCRIT if the fit finds no mode inside the band. */
hm_status hm_mode_model_reading(hm_mode_model m, double conicity, double speed_kmh, unsigned poles, double *sigma_1_s,
                                double *f_hz);

/* hm_mode_model_invert against the model's reading of `poles` pairs (the measured window's choice) instead of its
 * roots; with no sensor set, hm_mode_model_invert. The step tolerance is at least 1e-6 max(lambda, 1) (a reading's
 * precision). A measured (decaying) reading is never explained by a conicity at which the model is unstable at that
 * speed (any root with a real part >= 0, as hm_mode_model_hopf counts the first crossing of any mode: the vehicle ran
 * there without hunting). Gauss-Newton starts from the scanned conicity whose reading is nearest the measured mode;
 * where that conicity is unstable it runs unconstrained for at most HM_MODE_MODEL_UNSTABLE_START_ITER steps and its
 * result is kept if stable; otherwise (and where the nearest scanned conicity is stable) it runs from the nearest
 * stable one projected onto the stable side (where that fails, ends at the edge or misfits by chi2 above
 * HM_MODE_MODEL_RETRY_CHI2, again from that conicity refined by a golden section over its scanned neighbours, cut at
 * the edges, in HM_MODE_MODEL_START_EVALS readings; the better kept): a step that would leave it ends at its edge (bisected to a relative
 * HM_MODE_MODEL_EDGE_RTOL), and a step so clipped below the tolerance ends the search there. Such an edge result (the
 * Hopf speed at the window's speed: the nearest a stable model comes to the reading) is returned with its misfit chi2
 * for the caller to judge; its slope is a backward difference, the reading's decay rate changing sign across the
 * edge. Both passes are damped: a step to where the misfit grows, the reading fails or the conicity leaves
 * [HM_MODE_MODEL_LAMBDA_MIN, HM_MODE_MODEL_LAMBDA_MAX] is halved from the point before it (warm from that point's
 * fits), and where the halved step reaches the tolerance that point is the result (the misfit's minimum along the
 * step to within it). HM_ENOCONV where no stable conicity in that range is reached, at max_iter, or where the reading
 * does not change with the conicity. */
hm_status hm_mode_model_invert_reading(hm_mode_model m, unsigned poles, double speed_kmh, double sigma_m,
                                       double e_sigma, double f_m, double e_f, double tol, unsigned max_iter,
                                       hm_conicity_inversion *out);

#ifdef __cplusplus
}
#endif

#endif
