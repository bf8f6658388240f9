/* Vehicle config: the shipped file holds MODEL.md's values; every malformed config gets a located error. */
#include <stdlib.h>
#include <string.h>

#include "hm_test.h"
#include "hunting_monitor/config.h"

static const char *VALID =
    "vehicle:\n"
    "  name: test\n"
    "  mass_kg: 1869\n"
    "  yaw_inertia_kg_m2: 910\n"
    "  contact_half_distance_m: 0.7465\n"
    "  spring_half_distance_m: 1.0\n"
    "  rolling_radius_m: 0.43\n"
    "  creep_long_n: 7.99e6\n"
    "  creep_lat_n: 7.99e6\n"
    "  spring_ratio: 1.351186\n"
    "  kx_mn_m: 9.7\n"
    "  ky_mn_m: 10.96\n"
    "conicity:\n"
    "  constant: 0.1358\n"
    "  gaussians:\n"
    "    - {amplitude: 0.7, center_m: 0.01, width_m: 0.00145}\n"
    "    - {amplitude: 0.7, center_m: -0.01, width_m: 0.00145}\n"
    "flange:\n"
    "  alpha1_n_m3: -1.6e11\n"
    "  alpha2_n_m5: 1.6e15\n"
    "monitor:\n"
    "  anything: 1\n";

static void shipped_config_holds_model_values(void) {
  hm_vehicle v;
  char name[HM_VEHICLE_NAME_MAX], err[256] = "";
  const hm_status st = hm_config_load_vehicle(HM_SOURCE_DIR "/config/crh380_default.yaml", &v, name, err, sizeof err);
  HM_CHECK(st == HM_OK, "load: %s", err);
  HM_CHECK(strcmp(name, "crh380_default") == 0, "name '%s'", name);
  /* MODEL.md section 2 and 3, in SI. */
  HM_CHECK(v.mass_kg == 1869 && v.yaw_inertia_kg_m2 == 910 && v.contact_half_distance_m == 0.7465, "m, I, d0");
  HM_CHECK(v.spring_half_distance_m == 1.0 && v.rolling_radius_m == 0.43, "d1, r0");
  HM_CHECK(v.creep_long_n == 7.99e6 && v.creep_lat_n == 7.99e6 && v.spring_ratio == 1.351186, "kx, ky, l0/l1");
  HM_CHECK_DELTA(v.stiffness_long_n_m, 8.96e6, 1e-6, "Kx [N/m]");
  HM_CHECK_DELTA(v.stiffness_lat_n_m, 8.96e6, 1e-6, "Ky [N/m]");
  HM_CHECK(v.conicity.constant == 0.1358 && v.conicity.n_terms == 2, "conicity constant, terms");
  HM_CHECK(v.conicity.terms[0].amplitude == 0.7 && v.conicity.terms[0].center_m == 0.01 &&
               v.conicity.terms[0].width_m == 0.00145 && v.conicity.terms[1].center_m == -0.01,
           "Gaussian terms");
  HM_CHECK(v.flange_alpha1_n_m3 == -1.6e11 && v.flange_alpha2_n_m5 == 1.6e15, "flange");
  /* and it is what the library calls its default */
  hm_vehicle d;
  hm_vehicle_default(&d);
  HM_CHECK(v.mass_kg == d.mass_kg && fabs(v.stiffness_long_n_m - d.stiffness_long_n_m) < 1e-6 &&
               v.conicity.constant == d.conicity.constant && v.flange_alpha2_n_m5 == d.flange_alpha2_n_m5,
           "shipped file and hm_vehicle_default differ");
}

static void valid_text_parses_with_units(void) {
  hm_vehicle v;
  char err[256] = "";
  HM_CHECK(hm_config_parse_vehicle(VALID, strlen(VALID), "t", &v, NULL, err, sizeof err) == HM_OK, "%s", err);
  HM_CHECK_DELTA(v.stiffness_long_n_m, 9.7e6, 1e-6, "kx_mn_m 9.7 -> N/m");
  HM_CHECK_DELTA(v.stiffness_lat_n_m, 10.96e6, 1e-6, "ky_mn_m 10.96 -> N/m");
}

/* Replace the first occurrence of `from` in VALID by `to`. */
static void variant(char *out, size_t len, const char *from, const char *to) {
  const char *p = strstr(VALID, from);
  if (!p) {
    snprintf(out, len, "%s", VALID);
    printf("  test bug: '%s' not in the valid text\n", from);
    hm_test_case_failed = 1;
    return;
  }
  snprintf(out, len, "%.*s%s%s", (int)(p - VALID), VALID, to, p + strlen(from));
}

typedef struct {
  const char *from, *to;
  hm_status status;
  const char *message; /* expected substring */
} bad_case;

static void malformed_configs_get_clear_errors(void) {
  const bad_case cases[] = {
      {"  mass_kg: 1869\n", "", HM_EPARSE, "vehicle.mass_kg: missing key"},
      {"  mass_kg: 1869\n", "  mass_kg: -1869\n", HM_EDOMAIN, "vehicle.mass_kg: must be > 0"},
      {"  mass_kg: 1869\n", "  mass_kg: heavy\n", HM_EPARSE, "t:3: vehicle.mass_kg: expected a finite number"},
      {"  mass_kg: 1869\n", "  mass_kg: .nan\n", HM_EPARSE, "vehicle.mass_kg: expected a finite number"},
      {"  mass_kg: 1869\n", "  mass_kg: nan\n", HM_EPARSE, "vehicle.mass_kg: expected a finite number"},
      {"  mass_kg: 1869\n", "  mass_kg: 1e999\n", HM_EPARSE, "vehicle.mass_kg: expected a finite number"},
      {"  mass_kg: 1869\n", "  mass_kg: [1869]\n", HM_EPARSE, "vehicle.mass_kg: expected a number"},
      {"  mass_kg: 1869\n", "  mass_kg: 1869\n  mass_kg: 1870\n", HM_EPARSE, "vehicle.mass_kg: duplicate key"},
      {"  mass_kg: 1869\n", "  mas_kg: 1869\n", HM_EPARSE, "vehicle.mas_kg: unknown key"},
      {"  kx_mn_m: 9.7\n", "  kx_mn_m: 0\n", HM_EDOMAIN, "vehicle.kx_mn_m: must be > 0"},
      {"  yaw_inertia_kg_m2: 910\n", "  yaw_inertia_kg_m2: 0\n", HM_EDOMAIN, "vehicle.yaw_inertia_kg_m2"},
      {"  rolling_radius_m: 0.43\n", "  rolling_radius_m: -0.43\n", HM_EDOMAIN, "vehicle.rolling_radius_m"},
      {"width_m: 0.00145}\n    - {", "width_m: 0}\n    - {", HM_EDOMAIN, "conicity.gaussians[0].width_m"},
      {"width_m: 0.00145}\n    - {", "width: 0.00145}\n    - {", HM_EPARSE, "conicity.gaussians[0].width: unknown"},
      {"center_m: -0.01, ", "", HM_EPARSE, "conicity.gaussians[1].center_m: missing key"},
      {"  constant: 0.1358\n", "", HM_EPARSE, "conicity.constant: missing key"},
      {"  gaussians:\n", "  gaussians: 3\n  other:\n", HM_EPARSE, "conicity.other: unknown key"},
      {"flange:\n  alpha1_n_m3: -1.6e11\n  alpha2_n_m5: 1.6e15\n", "", HM_EPARSE, "flange: missing section"},
      {"conicity:\n  constant", "conicity: 3\nx:\n  constant", HM_EPARSE, "conicity: expected a mapping"},
      {"  name: test\n", "  name: test\n   bad_indent: 1\n", HM_EPARSE, "YAML syntax error"},
      {"  alpha2_n_m5: 1.6e15\n", "  alpha2_n_m5: 1.6e15\n  - x\n", HM_EPARSE, "YAML syntax error"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
    char text[4096], err[256] = "";
    variant(text, sizeof text, cases[i].from, cases[i].to);
    hm_vehicle v;
    memset(&v, 0x11, sizeof v);
    const hm_vehicle before = v;
    const hm_status st = hm_config_parse_vehicle(text, strlen(text), "t", &v, NULL, err, sizeof err);
    HM_CHECK(st == cases[i].status, "case %zu: status '%s', expected '%s' (%s)", i, hm_status_str(st),
             hm_status_str(cases[i].status), err);
    HM_CHECK(strstr(err, cases[i].message) != NULL, "case %zu: message '%s' lacks '%s'", i, err, cases[i].message);
    HM_CHECK(memcmp(&v, &before, sizeof v) == 0, "case %zu: output changed on failure", i);
  }
}

static void degenerate_documents(void) {
  hm_vehicle v;
  char err[256] = "";
  HM_CHECK(hm_config_parse_vehicle("", 0, "t", &v, NULL, err, sizeof err) == HM_EPARSE, "empty");
  HM_CHECK(strstr(err, "empty document") != NULL, "message '%s'", err);
  HM_CHECK(hm_config_parse_vehicle("- 1\n- 2\n", 8, "t", &v, NULL, err, sizeof err) == HM_EPARSE, "list");
  HM_CHECK(strstr(err, "expected a mapping at the top level") != NULL, "message '%s'", err);
  char many[8192];
  int n = snprintf(many, sizeof many, "%s", VALID);
  char *g = strstr(many, "  gaussians:\n");
  n = (int)(g - many);
  n += snprintf(many + n, sizeof many - (size_t)n, "  gaussians:\n");
  for (int i = 0; i < 9; ++i)
    n += snprintf(many + n, sizeof many - (size_t)n, "    - {amplitude: 0.1, center_m: 0.0, width_m: 0.001}\n");
  snprintf(many + n, sizeof many - (size_t)n, "flange:\n  alpha1_n_m3: 0\n  alpha2_n_m5: 0\n");
  HM_CHECK(hm_config_parse_vehicle(many, strlen(many), "t", &v, NULL, err, sizeof err) == HM_EPARSE, "9 terms");
  HM_CHECK(strstr(err, "at most 8") != NULL, "message '%s'", err);
  HM_CHECK(hm_config_load_vehicle("/nonexistent/vehicle.yaml", &v, NULL, err, sizeof err) == HM_EIO, "missing file");
  HM_CHECK(strstr(err, "/nonexistent/vehicle.yaml: cannot open") != NULL, "message '%s'", err);
}

/* Writing a vehicle and parsing it back gives the same doubles (17 significant digits). */
static void format_round_trip(void) {
  hm_vehicle v, back;
  hm_vehicle_default(&v);
  v.stiffness_long_n_m = 9.7e6 / 3.0; /* not representable in few digits */
  v.conicity.terms[1].width_m = 0.00145 * (1.0 + 1e-15);
  size_t need = 0;
  HM_CHECK(hm_config_format_vehicle(&v, "round \"trip\"", "line one\nline two", NULL, 0, &need) == HM_EINVAL, "size");
  char *buf = malloc(need);
  HM_CHECK(hm_config_format_vehicle(&v, "round \"trip\"", "line one\nline two", buf, need, &need) == HM_OK, "format");
  char name[HM_VEHICLE_NAME_MAX], err[256] = "";
  HM_CHECK(hm_config_parse_vehicle(buf, need - 1, "rt", &back, name, err, sizeof err) == HM_OK, "parse: %s", err);
  HM_CHECK(strcmp(name, "round trip") == 0, "name '%s'", name);
  HM_CHECK(back.stiffness_long_n_m == v.stiffness_long_n_m, "Kx %.17g vs %.17g", back.stiffness_long_n_m,
           v.stiffness_long_n_m);
  HM_CHECK(back.conicity.terms[1].width_m == v.conicity.terms[1].width_m && back.mass_kg == v.mass_kg &&
               back.flange_alpha2_n_m5 == v.flange_alpha2_n_m5 && back.conicity.n_terms == 2,
           "fields differ after the round trip");
  free(buf);
  /* unit-converted fields give back the same doubles (8.81 MN/m once read back as 8809999.9999999981 N/m) */
  int exact = 1;
  for (int i = 0; i < 2000 && exact; ++i) {
    hm_vehicle w;
    hm_vehicle_default(&w);
    w.stiffness_long_n_m = i == 0 ? 8810000.0 : hm_test_uniform(1e5, 5e7);
    w.stiffness_lat_n_m = i == 0 ? 8809999.9999999981 : floor(hm_test_uniform(1e5, 5e7) / 1e4) * 1e4;
    char text[4096];
    hm_status st = hm_config_format_vehicle(&w, "", NULL, text, sizeof text, &need);
    if (st == HM_OK) st = hm_config_parse_vehicle(text, need - 1, "rt", &back, name, err, sizeof err);
    exact = st == HM_OK && back.stiffness_long_n_m == w.stiffness_long_n_m &&
            back.stiffness_lat_n_m == w.stiffness_lat_n_m;
    HM_CHECK(exact, "case %d: Kx %.17g -> %.17g, Ky %.17g -> %.17g (%s)", i, w.stiffness_long_n_m,
             back.stiffness_long_n_m, w.stiffness_lat_n_m, back.stiffness_lat_n_m, err);
  }
  /* and a hand-written 8.81 reads as the double nearest to 8.81e6 */
  const char *doc = "vehicle:\n  mass_kg: 1869\n  yaw_inertia_kg_m2: 910\n  contact_half_distance_m: 0.7465\n"
                    "  spring_half_distance_m: 1\n  rolling_radius_m: 0.43\n  creep_long_n: 7.99e6\n"
                    "  creep_lat_n: 7.99e6\n  spring_ratio: 1.351186\n  kx_mn_m: 8.81\n  ky_mn_m: 1.5e-1\n"
                    "conicity:\n  constant: 0.1358\n  gaussians: []\n"
                    "flange:\n  alpha1_n_m3: -1.6e11\n  alpha2_n_m5: 1.6e15\n";
  HM_CHECK(hm_config_parse_vehicle(doc, strlen(doc), "doc", &back, name, err, sizeof err) == HM_OK, "%s", err);
  HM_CHECK(back.stiffness_long_n_m == 8810000.0 && back.stiffness_lat_n_m == 150000.0, "Kx %.17g Ky %.17g",
           back.stiffness_long_n_m, back.stiffness_lat_n_m);
}

/* The shipped monitor settings are the documented defaults; measurement_point sets the criteria's defaults
 * (the standards' bogie-frame limits: EN 14363 5.2 m/s^2, 8 m/s^2 peaks in 0.5-10 Hz) before the section's
 * explicit keys, whatever their order; errors are located and leave the output unchanged. */
static void monitor_settings(void) {
  hm_monitor_config m, d;
  memset(&m, 0, sizeof m); /* padding too, for the memcmp below */
  memset(&d, 0, sizeof d);
  hm_monitor_config_default(&m);
  hm_monitor_config_default(&d);
  m.estimator.band_low_hz = 99.0; /* must be overwritten by the file */
  char err[256] = "";
  HM_CHECK(hm_config_load_monitor(HM_SOURCE_DIR "/config/monitor.yaml", &m, err, sizeof err) == HM_OK, "%s", err);
  HM_CHECK(memcmp(&m, &d, sizeof m) == 0, "config/monitor.yaml differs from the defaults");
  for (int k = 0; k < 2; ++k) { /* the bogie's sensors: the model's spectrum a test at the axle box, the conicity at the frame */
    hm_monitor_config s = d;
    const char *path = k ? HM_SOURCE_DIR "/config/monitor_bogie_frame.yaml" : HM_SOURCE_DIR "/config/monitor_bogie_axlebox.yaml";
    HM_CHECK(hm_config_load_monitor(path, &s, err, sizeof err) == HM_OK, "%s", err);
    HM_CHECK(s.margin.spectrum_low_hz == (k ? 4.0 : 6.0) && s.margin.spectrum_high_hz == 22.0 &&
                 s.margin.spectrum_conicity == k && s.margin.spectrum_model_error == 0.02,
             "%s: the spectrum's band", path);
  }
  const char *bogie = "estimator:\n  rms_limit_mps2: 6\n  measurement_point: bogie_frame\n";
  hm_monitor_config b = d;
  HM_CHECK(hm_config_parse_monitor(bogie, strlen(bogie), "b", &b, err, sizeof err) == HM_OK, "%s", err);
  HM_CHECK(b.estimator.measurement_point == HM_POINT_BOGIE_FRAME && b.estimator.rms_limit_mps2 == 6.0 &&
               b.estimator.peaks_limit_mps2 == 8.0 && b.estimator.peaks_band_low_hz == 0.5 &&
               b.estimator.peaks_band_high_hz == 10.0,
           "bogie frame: rms %g peaks %g band %g-%g", b.estimator.rms_limit_mps2, b.estimator.peaks_limit_mps2,
           b.estimator.peaks_band_low_hz, b.estimator.peaks_band_high_hz);
  const struct {
    const char *text, *message;
    hm_status st;
  } bad[] = {
      {"estimator:\n  band_low: 2\n", "t:2: estimator.band_low: unknown key", HM_EPARSE},
      {"alarm:\n  use_conicity_estimate: maybe\n", "alarm.use_conicity_estimate: expected false or true", HM_EPARSE},
      {"estimator:\n  measurement_point: roof\n", "measurement_point: expected wheelset or bogie_frame", HM_EPARSE},
      {"estimator:\n  peaks_count: 6.5\n", "estimator.peaks_count: expected a whole number", HM_EPARSE},
      {"estimator:\n  sample_rate_hz: 20\n", "estimator.sample_rate_hz: must be in [100, 5000]", HM_EDOMAIN},
      {"alarm:\n  min_hold_s: -1\n", "alarm.min_hold_s: must be in [0, 3600] (got -1)", HM_EDOMAIN},
      {"alarm:\n  warn_standard_errors: 6\n", "alarm.warn_standard_errors: must be in [0, 5] (got 6)", HM_EDOMAIN},
      {"modal:\n  window_s: 1000\n", "modal.window_s: must be in [5, 300]", HM_EDOMAIN},
      {"modal:\n  min_peak_prominence: -1\n", "modal.min_peak_prominence: must be 0 (off) or in [2, 100]", HM_EDOMAIN},
      {"modal:\n  min_peak_prominence: 1\n", "modal.min_peak_prominence: must be 0 (off) or in [2, 100]", HM_EDOMAIN},
      {"margin:\n  interval_z: 0\n", "margin.interval_z: must be in [0.5, 10]", HM_EDOMAIN},
      {"margin:\n  spectrum_low_hz: 6\n", "margin.spectrum_high_hz: must be 0 with spectrum_low_hz 0", HM_EDOMAIN},
      {"margin:\n  spectrum_low_hz: 6\n  spectrum_high_hz: 10\n", "else at least twice it (got 10)", HM_EDOMAIN},
      {"margin:\n  spectrum_low_hz: 0.1\n  spectrum_high_hz: 10\n", "margin.spectrum_low_hz: must be 0 (off) or in",
       HM_EDOMAIN},
      {"margin:\n  spectrum_low_hz: 6\n  spectrum_high_hz: 60\n",
       "margin.spectrum_high_hz: must be below half modal.decimated_rate_hz (got 60)", HM_EDOMAIN},
      {"track_lines:\n  min_speed_change_rel: 0.01\n", "track_lines.min_speed_change_rel: must be in [0.02, 0.5]",
       HM_EDOMAIN},
      {"track_lines:\n  wavelength: 0.01\n", "track_lines.wavelength: unknown key", HM_EPARSE},
      /* found by fuzzing: huge values sized the buffers by an overflowing float-to-size_t conversion */
      {"estimator:\n  tracking_time_s: 57646075230342348\n", "tracking_time_s: must be in (0, 20]", HM_EDOMAIN},
      {"estimator:\n  rms_window_m: 1e300\n", "rms_window_m: must be in (0, 1000]", HM_EDOMAIN},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
    hm_monitor_config m2 = d;
    const hm_status st = hm_config_parse_monitor(bad[i].text, strlen(bad[i].text), "t", &m2, err, sizeof err);
    HM_CHECK(st == bad[i].st && strstr(err, bad[i].message), "case %zu: %s: '%s'", i, hm_status_str(st), err);
    HM_CHECK(memcmp(&m2, &d, sizeof m2) == 0, "case %zu: output changed", i);
  }
}

/* The bogie and the car (issue #28): the shipped config/bogie_default.yaml and car_default.yaml hold hm_bogie_default's
 * and hm_car_default's values; the readers refuse each other's configs; the bogie section's errors are located like
 * the wheelset's. */
/* An edit of a valid config's text (from replaced by to) and what its reader must say. */
typedef struct {
  const char *from, *to, *message;
  hm_status status;
} edit_case;

typedef hm_status (*text_reader)(const char *text, size_t len, void *out, char *err, size_t err_len);
static hm_status read_bogie(const char *text, size_t len, void *out, char *err, size_t err_len) {
  return hm_config_parse_bogie(text, len, "t", out, NULL, err, err_len);
}
static hm_status read_car(const char *text, size_t len, void *out, char *err, size_t err_len) {
  return hm_config_parse_car(text, len, "t", out, NULL, err, err_len);
}

/* Each case's edit of base read into out (size bytes, at most an hm_car's): its status and message, out untouched. */
static void check_edits(const char *base, const edit_case *cases, size_t n, text_reader read, void *out, size_t size) {
  unsigned char before[sizeof(hm_car)];
  HM_CHECK(size <= sizeof before, "test bug");
  for (size_t i = 0; i < n && size <= sizeof before; ++i) {
    char text[8192], err[256] = "";
    const char *p = strstr(base, cases[i].from);
    HM_CHECK(p != NULL, "case %zu: test bug", i);
    if (!p) continue;
    snprintf(text, sizeof text, "%.*s%s%s", (int)(p - base), base, cases[i].to, p + strlen(cases[i].from));
    memset(out, 0x11, size);
    memcpy(before, out, size);
    const hm_status st = read(text, strlen(text), out, err, sizeof err);
    HM_CHECK(st == cases[i].status && strstr(err, cases[i].message), "case %zu: %s: '%s'", i, hm_status_str(st), err);
    HM_CHECK(memcmp(out, before, size) == 0, "case %zu: output changed on failure", i);
  }
}

static void bogie_configs(void) {
  hm_bogie b, d;
  char name[HM_VEHICLE_NAME_MAX], err[256] = "";
  HM_CHECK(hm_config_load_bogie(HM_SOURCE_DIR "/config/bogie_default.yaml", &b, name, err, sizeof err) == HM_OK,
           "load: %s", err);
  hm_bogie_default(&d);
  HM_CHECK(strcmp(name, "bogie_default") == 0, "name '%s'", name);
  HM_CHECK(b.frame_mass_kg == 2600 && b.frame_yaw_inertia_kg_m2 == 1800 && b.half_wheelbase_m == 1.25, "frame");
  HM_CHECK(b.secondary_lat_stiffness_n_m == 2.5e5 && b.secondary_lat_damping_n_s_m == 3e4, "secondary lateral");
  HM_CHECK(b.airspring_long_stiffness_n_m == 1.5e5 && b.airspring_half_distance_m == 1.0, "air springs");
  HM_CHECK(b.yaw_damper_damping_n_s_m == 1e6 && b.yaw_damper_stiffness_n_m == 5e7 &&
               b.yaw_damper_half_distance_m == 1.3, "yaw dampers");
  HM_CHECK(memcmp(&b, &d, sizeof b) == 0, "the shipped bogie and hm_bogie_default differ");
  hm_model_kind kind = HM_MODEL_WHEELSET;
  HM_CHECK(hm_config_load_model_kind(HM_SOURCE_DIR "/config/bogie_default.yaml", &kind, err, sizeof err) == HM_OK &&
               kind == HM_MODEL_BOGIE, "kind of the bogie: %s", err);
  HM_CHECK(hm_config_load_model_kind(HM_SOURCE_DIR "/config/crh380_default.yaml", &kind, err, sizeof err) == HM_OK &&
               kind == HM_MODEL_WHEELSET, "kind of the wheelset: %s", err);
  hm_vehicle v;
  HM_CHECK(hm_config_load_vehicle(HM_SOURCE_DIR "/config/bogie_default.yaml", &v, name, err, sizeof err) ==
                   HM_EPARSE && strstr(err, "model: 'bogie' where a wheelset config is expected"),
           "the wheelset reader on a bogie: %s", err);
  HM_CHECK(hm_config_load_bogie(HM_SOURCE_DIR "/config/crh380_default.yaml", &b, name, err, sizeof err) ==
                   HM_EPARSE && strstr(err, "model: 'wheelset' where a bogie config is expected"),
           "the bogie reader on a wheelset: %s", err);
  /* the whole vehicle: its bogies are the shipped bogie's, its carbody hm_car_default's */
  hm_car car, car_d;
  HM_CHECK(hm_config_load_car(HM_SOURCE_DIR "/config/car_default.yaml", &car, name, err, sizeof err) == HM_OK,
           "load car: %s", err);
  hm_car_default(&car_d);
  HM_CHECK(memcmp(&car, &car_d, sizeof car) == 0 && memcmp(&car.bogie, &d, sizeof d) == 0, "car = hm_car_default");
  HM_CHECK(car.carbody_mass_kg == 35000 && car.carbody_yaw_inertia_kg_m2 == 1.8e6 && car.half_bogie_distance_m == 8.75,
           "carbody");
  HM_CHECK(hm_config_load_model_kind(HM_SOURCE_DIR "/config/car_default.yaml", &kind, err, sizeof err) == HM_OK &&
               kind == HM_MODEL_CAR, "kind of the car");
  HM_CHECK(hm_config_load_bogie(HM_SOURCE_DIR "/config/car_default.yaml", &b, name, err, sizeof err) == HM_EPARSE &&
               strstr(err, "model: 'car' where a bogie config is expected"), "the bogie reader on a car: %s", err);
  HM_CHECK(hm_config_load_car(HM_SOURCE_DIR "/config/bogie_default.yaml", &car, name, err, sizeof err) == HM_EPARSE &&
               strstr(err, "model: 'bogie' where a car config is expected"), "the car reader on a bogie: %s", err);
  const char *bogie_text = "model: bogie\n"
                           "bogie:\n"
                           "  frame_mass_kg: 2600\n  frame_yaw_inertia_kg_m2: 1800\n  half_wheelbase_m: 1.25\n"
                           "  secondary_lat_stiffness_n_m: 2.5e5\n  secondary_lat_damping_n_s_m: 3e4\n"
                           "  airspring_long_stiffness_n_m: 1.5e5\n  airspring_half_distance_m: 1.0\n"
                           "  yaw_damper_damping_n_s_m: 1e6\n  yaw_damper_stiffness_n_m: 5e7\n"
                           "  yaw_damper_half_distance_m: 1.3\n";
  const edit_case cases[] = {
      {"  frame_mass_kg: 2600\n", "  frame_mass_kg: -2600\n", "bogie.frame_mass_kg: must be > 0 (got -2600)",
       HM_EDOMAIN},
      {"  frame_mass_kg: 2600\n", "", "bogie.frame_mass_kg: missing key", HM_EPARSE},
      {"  half_wheelbase_m: 1.25\n", "  half_wheelbase: 1.25\n", "bogie.half_wheelbase: unknown key", HM_EPARSE},
      {"  yaw_damper_stiffness_n_m: 5e7\n", "  yaw_damper_stiffness_n_m: stiff\n",
       "bogie.yaw_damper_stiffness_n_m: expected a finite number", HM_EPARSE},
      {"model: bogie\n", "model: tram\n", "model: expected wheelset, bogie or car, got 'tram'", HM_EPARSE},
      {"model: bogie\nbogie:\n", "model: bogie\nbogies:\n", "bogie: missing section", HM_EPARSE},
  };
  /* the wheelset's sections of VALID (without its monitor section), then the bogie's */
  char base[4096];
  snprintf(base, sizeof base, "%.*s%s", (int)(strstr(VALID, "monitor:") - VALID), VALID, bogie_text);
  HM_CHECK(hm_config_parse_bogie(base, strlen(base), "t", &b, NULL, err, sizeof err) == HM_OK, "base: %s", err);
  check_edits(base, cases, sizeof cases / sizeof cases[0], read_bogie, &b, sizeof b);
}

/* A car's optional roll (car.h): config/car_roll.yaml is car_default with its four values; a car without it does not
 * roll; a roll section missing a key, not a mapping, or too soft to carry the carbody: clear errors, output untouched. */
static void car_roll_configs(void) {
  hm_car car, plain;
  char name[HM_VEHICLE_NAME_MAX], err[256] = "";
  HM_CHECK(hm_config_load_car(HM_SOURCE_DIR "/config/car_roll.yaml", &car, name, err, sizeof err) == HM_OK,
           "load: %s", err);
  HM_CHECK(hm_config_load_car(HM_SOURCE_DIR "/config/car_default.yaml", &plain, NULL, err, sizeof err) == HM_OK,
           "load car_default: %s", err);
  HM_CHECK(strcmp(name, "car_roll") == 0, "name '%s'", name);
  HM_CHECK(plain.carbody_roll_inertia_kg_m2 == 0.0, "car_default does not roll");
  HM_CHECK(car.carbody_roll_inertia_kg_m2 == 6.4e4 && car.carbody_cg_height_m == 0.9 &&
               car.secondary_roll_stiffness_n_m_rad == 2.6e6 && car.secondary_roll_damping_n_m_s_rad == 6.76e4,
           "the roll's values");
  plain.carbody_roll_inertia_kg_m2 = car.carbody_roll_inertia_kg_m2;
  plain.carbody_cg_height_m = car.carbody_cg_height_m;
  plain.secondary_roll_stiffness_n_m_rad = car.secondary_roll_stiffness_n_m_rad;
  plain.secondary_roll_damping_n_m_s_rad = car.secondary_roll_damping_n_m_s_rad;
  HM_CHECK(memcmp(&plain, &car, sizeof car) == 0, "everything else as car_default");
  FILE *f = fopen(HM_SOURCE_DIR "/config/car_roll.yaml", "rb");
  char base[8192];
  const size_t n = f ? fread(base, 1, sizeof base - 1, f) : 0;
  if (f) fclose(f);
  base[n] = '\0';
  const edit_case cases[] = {
      {"    damping_n_m_s_rad: 6.76e4", "    damping: 6.76e4", "car.roll.damping: unknown key", HM_EPARSE},
      {"    cg_height_m: 0.9", "    cg_height_m: -0.9", "car.roll.cg_height_m: must be in [0, 5] (got -0.9)",
       HM_EDOMAIN},
      {"    stiffness_n_m_rad: 2.6e6", "    stiffness_n_m_rad: 1.5e5",
       "car.roll.stiffness_n_m_rad: must exceed mc g h / 2 = 154455", HM_EDOMAIN},
      {"    inertia_kg_m2: 6.4e4", "    inertia_kg_m2: -1",
       "car.roll.inertia_kg_m2: must be 0 (off) or in [1000, 1e+07] (got -1)", HM_EDOMAIN},
      {"    inertia_kg_m2: 6.4e4", "    inertia_kg_m2: 1e-6", "car.roll.inertia_kg_m2: must be 0 (off) or in",
       HM_EDOMAIN},
      {"    stiffness_n_m_rad: 2.6e6", "    stiffness_n_m_rad: 1e300", "car.roll.stiffness_n_m_rad: must be in [0, 1e+08]",
       HM_EDOMAIN},
  };
  check_edits(base, cases, sizeof cases / sizeof cases[0], read_car, &car, sizeof car);
  char text[8192];
  /* without roll (its inertia 0) the other keys are still checked */
  char *ix = strstr(base, "inertia_kg_m2: 6.4e4"), *h = strstr(base, "cg_height_m: 0.9");
  HM_CHECK(ix && h, "test bug");
  if (ix && h) {
    memcpy(ix, "inertia_kg_m2: 0    ", 20);
    memcpy(h, "cg_height_m: -7 ", 16);
    HM_CHECK(hm_config_parse_car(base, strlen(base), "t", &car, NULL, err, sizeof err) == HM_EDOMAIN &&
                 strstr(err, "car.roll.cg_height_m: must be in [0, 5] (got -7)"),
             "no roll, a bad height: '%s'", err);
    memcpy(ix, "inertia_kg_m2: 6.4e4", 20);
    memcpy(h, "cg_height_m: 0.9", 16);
  }
  const char *roll = strstr(base, "  roll:");
  HM_CHECK(roll != NULL, "test bug");
  snprintf(text, sizeof text, "%.*s  roll: 3\n", roll ? (int)(roll - base) : 0, base);
  HM_CHECK(hm_config_parse_car(text, strlen(text), "t", &car, NULL, err, sizeof err) == HM_EPARSE &&
               strstr(err, "car.roll: expected a mapping"), "roll not a mapping: '%s'", err);
}

int main(void) {
  HM_RUN(monitor_settings);
  HM_RUN(format_round_trip);
  HM_RUN(shipped_config_holds_model_values);
  HM_RUN(valid_text_parses_with_units);
  HM_RUN(malformed_configs_get_clear_errors);
  HM_RUN(degenerate_documents);
  HM_RUN(bogie_configs);
  HM_RUN(car_roll_configs);
  HM_TEST_EXIT();
}
