/* libFuzzer harness: the vehicle YAML parsers (the model kind, the bogie's, the wheelset's), and the writer's promise
 * that parsing its output gives back the same doubles. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "hunting_monitor/config.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  hm_vehicle v, back;
  char name[HM_VEHICLE_NAME_MAX], err[256];
  hm_model_kind kind;
  hm_bogie bogie;
  const hm_status kst = hm_config_model_kind((const char *)data, size, "fuzz", &kind, err, sizeof err);
  const hm_status bst = hm_config_parse_bogie((const char *)data, size, "fuzz", &bogie, name, err, sizeof err);
  if (bst == HM_OK && (hm_bogie_validate(&bogie, NULL, 0) != HM_OK || kst != HM_OK || kind != HM_MODEL_BOGIE))
    __builtin_trap(); /* parsed means valid, and a bogie */
  hm_car car;
  if (hm_config_parse_car((const char *)data, size, "fuzz", &car, name, err, sizeof err) == HM_OK &&
      (hm_car_validate(&car, NULL, 0) != HM_OK || kst != HM_OK || kind != HM_MODEL_CAR))
    __builtin_trap();
  if (hm_config_parse_vehicle((const char *)data, size, "fuzz", &v, name, err, sizeof err) != HM_OK) return 0;
  if (hm_vehicle_validate(&v, NULL, 0) != HM_OK) __builtin_trap(); /* parsed means valid */
  size_t need = 0;
  hm_config_format_vehicle(&v, name, "fuzz", NULL, 0, &need);
  char *text = malloc(need);
  if (!text) return 0;
  if (hm_config_format_vehicle(&v, name, "fuzz", text, need, &need) != HM_OK) __builtin_trap();
  if (hm_config_parse_vehicle(text, need - 1, "round trip", &back, name, err, sizeof err) != HM_OK) __builtin_trap();
  if (back.mass_kg != v.mass_kg || back.stiffness_long_n_m != v.stiffness_long_n_m ||
      back.stiffness_lat_n_m != v.stiffness_lat_n_m || back.conicity.n_terms != v.conicity.n_terms ||
      back.conicity.constant != v.conicity.constant || back.flange_alpha2_n_m5 != v.flange_alpha2_n_m5)
    __builtin_trap();
  free(text);
  return 0;
}
