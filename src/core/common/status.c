#include "hunting_monitor/status.h"

const char *hm_status_str(hm_status status) {
  switch (status) {
    case HM_OK: return "success";
    case HM_EINVAL: return "invalid argument";
    case HM_EDOMAIN: return "parameter outside its physical domain";
    case HM_ENOMEM: return "out of memory";
    case HM_ENOCONV: return "iteration did not converge";
    case HM_ENOCRIT: return "no critical value exists";
    case HM_ESTEP: return "integration step failed (step size underflow or step limit)";
    case HM_ENONFINITE: return "non-finite value encountered";
    case HM_ELAPACK: return "LAPACK routine failed";
    case HM_EPARSE: return "malformed input";
    case HM_EIO: return "input/output error";
  }
  return "unknown status";
}
