/*
 * hunting_monitor - status codes shared by every function of the C core.
 *
 * Every function that can fail returns an hm_status; on failure its outputs are left untouched.
 */
#ifndef HUNTING_MONITOR_STATUS_H
#define HUNTING_MONITOR_STATUS_H

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
  HM_OK = 0,        /* success */
  HM_EINVAL = 1,    /* invalid argument: NULL pointer, zero size, bad option value */
  HM_EDOMAIN = 2,   /* a parameter is outside its physical domain (NaN, inf, non-positive mass, ...) */
  HM_ENOMEM = 3,    /* memory allocation failed */
  HM_ENOCONV = 4,   /* an iteration did not converge within its tolerance and iteration limit */
  HM_ENOCRIT = 5,   /* no critical value exists (the system is stable, or unstable, for every value) */
  HM_ESTEP = 6,     /* step size underflow or step limit reached in a time integration */
  HM_ENONFINITE = 7,/* a non-finite value (NaN, inf) appeared during a computation */
  HM_ELAPACK = 8,   /* a LAPACK routine reported failure (singular matrix, QR did not converge) */
  HM_EPARSE = 9,    /* malformed input text (config, CSV) */
  HM_EIO = 10       /* a file could not be opened or read */
} hm_status;

/* A short English description of a status code; never NULL. */
const char *hm_status_str(hm_status status);

#ifdef __cplusplus
}
#endif

#endif
