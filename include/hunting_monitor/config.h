/*
 * hunting_monitor - the vehicle configuration file (YAML, parsed with libyaml).
 *
 *   vehicle:                        # docs/MODEL.md section 2 (SI units except stiffnesses in MN/m)
 *     name: crh380_default          # optional
 *     mass_kg: 1869
 *     yaw_inertia_kg_m2: 910
 *     contact_half_distance_m: 0.7465
 *     spring_half_distance_m: 1.0
 *     rolling_radius_m: 0.43
 *     creep_long_n: 7.99e6
 *     creep_lat_n: 7.99e6
 *     spring_ratio: 1.351186        # l0/l1
 *     kx_mn_m: 8.96
 *     ky_mn_m: 8.96
 *   conicity:                       # lambda(y) = constant + sum a exp(-((y - b)/c)^2)
 *     constant: 0.1358
 *     gaussians:
 *       - {amplitude: 0.7, center_m: 0.01, width_m: 0.00145}
 *   flange:                         # F_T(y) = alpha1 y^3 + alpha2 y^5
 *     alpha1_n_m3: -1.6e11
 *     alpha2_n_m5: 1.6e15
 *
 * Every key of the three sections is required (gaussians may be an empty list or absent); an unknown key
 * inside them is an error; other top-level sections are left to other modules (monitor settings).
 *
 * A two-axle bogie (bogie.h; config/bogie_default.yaml) says so at the top level and adds a section, every key
 * required, SI units as named; its wheelsets are the three sections above:
 *   model: bogie                    # absent or `wheelset`: the wheelset above
 *   bogie:
 *     frame_mass_kg: 2600
 *     frame_yaw_inertia_kg_m2: 1800
 *     half_wheelbase_m: 1.25
 *     secondary_lat_stiffness_n_m: 2.5e5
 *     secondary_lat_damping_n_s_m: 3e4
 *     airspring_long_stiffness_n_m: 1.5e5   # each of two, at lateral arm airspring_half_distance_m
 *     airspring_half_distance_m: 1.0
 *     yaw_damper_damping_n_s_m: 1e6          # each of two, in series with yaw_damper_stiffness_n_m,
 *     yaw_damper_stiffness_n_m: 5e7          # at lateral arm yaw_damper_half_distance_m
 *     yaw_damper_half_distance_m: 1.3
 * A whole vehicle (car.h; config/car_default.yaml): `model: car`, the sections above and
 *   car:
 *     carbody_mass_kg: 35000
 *     carbody_yaw_inertia_kg_m2: 1.8e6
 *     half_bogie_distance_m: 8.75
 *     roll:                          # optional (config/car_roll.yaml): without it the carbody does not roll
 *       inertia_kg_m2: 6.4e4
 *       cg_height_m: 0.9
 *       stiffness_n_m_rad: 2.6e6       # each bogie's
 *       damping_n_m_s_rad: 6.76e4      # each bogie's
 * Each reader refuses the other models' configs: a model is never taken for another silently.
 */
#ifndef HUNTING_MONITOR_CONFIG_H
#define HUNTING_MONITOR_CONFIG_H

#include <stddef.h>

#include "hunting_monitor/bogie.h"
#include "hunting_monitor/car.h"
#include "hunting_monitor/monitor.h"
#include "hunting_monitor/model.h"
#include "hunting_monitor/status.h"

#ifdef __cplusplus
extern "C" {
#endif

#define HM_VEHICLE_NAME_MAX 64

/*
 * Parse a vehicle config from YAML text of len bytes. source names the text in messages (e.g. its path).
 * On failure returns HM_EPARSE (malformed YAML, missing or unknown key, non-numeric value) or HM_EDOMAIN
 * (a value outside its physical domain, see hm_vehicle_validate) and writes "source:line: key: reason"
 * into err. name (may be NULL) receives vehicle.name or "". Outputs untouched on failure.
 */
hm_status hm_config_parse_vehicle(const char *text, size_t len, const char *source, hm_vehicle *veh, char *name,
                                  char *err, size_t err_len);

/* Read the file at path and parse it as above; HM_EIO if it cannot be read. */
hm_status hm_config_load_vehicle(const char *path, hm_vehicle *veh, char *name, char *err, size_t err_len);

/* Which model a vehicle config describes (its `model:` key; absent: the wheelset). HM_EPARSE for another value or
 * malformed YAML. */
hm_status hm_config_model_kind(const char *text, size_t len, const char *source, hm_model_kind *kind, char *err,
                               size_t err_len);
hm_status hm_config_load_model_kind(const char *path, hm_model_kind *kind, char *err, size_t err_len);

/* A bogie config (above): as hm_config_parse_vehicle, then the bogie section, then hm_bogie_validate. Outputs
 * untouched on failure. */
hm_status hm_config_parse_bogie(const char *text, size_t len, const char *source, hm_bogie *bogie, char *name,
                                char *err, size_t err_len);
hm_status hm_config_load_bogie(const char *path, hm_bogie *bogie, char *name, char *err, size_t err_len);

/* A car config (above): as hm_config_parse_bogie, then the car section, then hm_car_validate. */
hm_status hm_config_parse_car(const char *text, size_t len, const char *source, hm_car *car, char *name, char *err,
                              size_t err_len);
hm_status hm_config_load_car(const char *path, hm_car *car, char *name, char *err, size_t err_len);

/*
 * Monitor settings (config/monitor.yaml): optional sections `estimator:`, `modal:`, `margin:`, `alarm:` and `table:`
 * whose keys are the field names of hm_estimator_config, hm_modal_config, hm_margin_config, hm_alarm_config and
 * hm_monitor_config.table (refine and use_conicity_estimate: true/false; measurement_point: wheelset/bogie_frame,
 * which first sets the criteria's defaults for that point, hm_estimator_config_criteria, then the section's other keys apply). Fields not given keep
 * the values *cfg holds on entry (pass the defaults); unknown keys and non-numbers are errors (HM_EPARSE), then the
 * whole configuration is validated (HM_EDOMAIN). Output untouched on failure. Other top-level sections (vehicle,
 * conicity, flange) are ignored, so one file may hold both.
 */
hm_status hm_config_parse_monitor(const char *text, size_t len, const char *source, hm_monitor_config *cfg, char *err,
                                  size_t err_len);
hm_status hm_config_load_monitor(const char *path, hm_monitor_config *cfg, char *err, size_t err_len);

/*
 * Write veh as a complete vehicle config (the format above, values with 17 significant digits so that parsing
 * gives back the same doubles) into buf of len bytes; name may be NULL; comment (may be NULL) is written as
 * '#' lines at the top. *needed receives the size including the terminating NUL; HM_EINVAL if len is too
 * small (call again with *needed bytes).
 */
hm_status hm_config_format_vehicle(const hm_vehicle *veh, const char *name, const char *comment, char *buf,
                                   size_t len, size_t *needed);

#ifdef __cplusplus
}
#endif

#endif
