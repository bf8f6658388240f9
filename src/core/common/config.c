/* Vehicle configuration: YAML (libyaml document API) to hm_vehicle, with located error messages. */
#include "hunting_monitor/config.h"

#include <errno.h>
#include <stddef.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <yaml.h>

#include "textsink.h"

typedef struct {
  yaml_document_t *doc;
  const char *source;
  char *err;
  size_t err_len;
} parse_ctx;

static hm_status fail(parse_ctx *c, const yaml_node_t *node, hm_status st, const char *fmt, ...) {
  if (c->err && c->err_len > 0) {
    int used = node ? snprintf(c->err, c->err_len, "%s:%lu: ", c->source, (unsigned long)node->start_mark.line + 1)
                    : snprintf(c->err, c->err_len, "%s: ", c->source);
    if (used < 0) used = 0;
    if ((size_t)used < c->err_len) {
      va_list ap;
      va_start(ap, fmt);
      vsnprintf(c->err + used, c->err_len - (size_t)used, fmt, ap);
      va_end(ap);
    }
  }
  return st;
}

static const char *scalar_text(const yaml_node_t *n) { return (const char *)n->data.scalar.value; }

/* Value node of key in a mapping node, or NULL. Duplicate keys are reported by the caller's scan. */
static yaml_node_t *map_get(parse_ctx *c, yaml_node_t *map, const char *key) {
  for (yaml_node_pair_t *p = map->data.mapping.pairs.start; p < map->data.mapping.pairs.top; ++p) {
    yaml_node_t *k = yaml_document_get_node(c->doc, p->key);
    if (k && k->type == YAML_SCALAR_NODE && strcmp(scalar_text(k), key) == 0)
      return yaml_document_get_node(c->doc, p->value);
  }
  return NULL;
}

/* Every key of map must be one of allowed (NULL-terminated) and appear once. */
static hm_status check_keys(parse_ctx *c, yaml_node_t *map, const char *section, const char *const *allowed) {
  for (yaml_node_pair_t *p = map->data.mapping.pairs.start; p < map->data.mapping.pairs.top; ++p) {
    yaml_node_t *k = yaml_document_get_node(c->doc, p->key);
    if (!k || k->type != YAML_SCALAR_NODE) return fail(c, k, HM_EPARSE, "%s: keys must be plain names", section);
    int known = 0;
    for (const char *const *a = allowed; *a; ++a) known |= strcmp(*a, scalar_text(k)) == 0;
    if (!known) return fail(c, k, HM_EPARSE, "%s.%s: unknown key", section, scalar_text(k));
    for (yaml_node_pair_t *q = map->data.mapping.pairs.start; q < p; ++q) {
      yaml_node_t *k2 = yaml_document_get_node(c->doc, q->key);
      if (k2 && k2->type == YAML_SCALAR_NODE && strcmp(scalar_text(k2), scalar_text(k)) == 0)
        return fail(c, k, HM_EPARSE, "%s.%s: duplicate key", section, scalar_text(k));
    }
  }
  return HM_OK;
}

/* The mapping under key in map (path names it in messages), or NULL when absent; not a mapping: an error. */
static hm_status get_optional_section(parse_ctx *c, yaml_node_t *map, const char *key, const char *path,
                                      yaml_node_t **out) {
  yaml_node_t *n = map_get(c, map, key);
  if (n && n->type != YAML_MAPPING_NODE) return fail(c, n, HM_EPARSE, "%s: expected a mapping of keys", path);
  *out = n;
  return HM_OK;
}

static hm_status get_section(parse_ctx *c, yaml_node_t *root, const char *name, yaml_node_t **out) {
  hm_status st = get_optional_section(c, root, name, name, out);
  if (st == HM_OK && !*out) return fail(c, NULL, HM_EPARSE, "%s: missing section", name);
  return st;
}

/* A finite number from a scalar node (strtod accepts 1869, 8.96, 7.99e6). */
static hm_status node_number(parse_ctx *c, yaml_node_t *n, const char *path, double *out) {
  if (n->type != YAML_SCALAR_NODE) return fail(c, n, HM_EPARSE, "%s: expected a number", path);
  const char *s = scalar_text(n);
  char *end = NULL;
  errno = 0;
  const double v = strtod(s, &end);
  if (end == s || *end != '\0' || errno == ERANGE || !isfinite(v))
    return fail(c, n, HM_EPARSE, "%s: expected a finite number, got '%s'", path, s);
  *out = v;
  return HM_OK;
}

/* A number given in 10^decades units (MN/m: decades 6) converted in its decimal text, so that the SI value is the
 * correctly rounded one: 8.81 MN/m reads as exactly strtod("8.81e6"), not 8.81 * 1e6 (which differs in the last
 * bit, and would break the writer's promise that parsing gives back the same doubles). */
static hm_status node_number_scaled(parse_ctx *c, yaml_node_t *n, const char *path, int decades, double *out) {
  if (decades == 0) return node_number(c, n, path, out);
  if (n->type != YAML_SCALAR_NODE) return fail(c, n, HM_EPARSE, "%s: expected a number", path);
  const char *s = scalar_text(n);
  char text[96], *end = NULL;
  const char *e = strpbrk(s, "eE");
  long exponent = 0;
  if (e) {
    errno = 0;
    exponent = strtol(e + 1, &end, 10);
    if (end == e + 1 || *end || errno == ERANGE || labs(exponent) > 10000)
      return fail(c, n, HM_EPARSE, "%s: expected a finite number, got '%s'", path, s);
  }
  const int mant_len = e ? (int)(e - s) : (int)strlen(s);
  if (mant_len <= 0 || mant_len > 64) return fail(c, n, HM_EPARSE, "%s: expected a finite number, got '%s'", path, s);
  snprintf(text, sizeof text, "%.*se%ld", mant_len, s, exponent + decades);
  errno = 0;
  const double v = strtod(text, &end);
  if (end == text || *end != '\0' || errno == ERANGE || !isfinite(v))
    return fail(c, n, HM_EPARSE, "%s: expected a finite number, got '%s'", path, s);
  *out = v;
  return HM_OK;
}

static hm_status get_number(parse_ctx *c, yaml_node_t *map, const char *section, const char *key, double *out) {
  char path[96];
  snprintf(path, sizeof path, "%s.%s", section, key);
  yaml_node_t *n = map_get(c, map, key);
  if (!n) return fail(c, map, HM_EPARSE, "%s: missing key", path);
  return node_number(c, n, path, out);
}

typedef struct {
  const char *key;
  int decades; /* config unit = 10^decades SI units */
  size_t offset;
} number_field;

static hm_status parse_vehicle_section(parse_ctx *c, yaml_node_t *sec, hm_vehicle *veh, char *name) {
  static const char *const allowed[] = {"name", "mass_kg", "yaw_inertia_kg_m2", "contact_half_distance_m",
                                        "spring_half_distance_m", "rolling_radius_m", "creep_long_n",
                                        "creep_lat_n", "spring_ratio", "kx_mn_m", "ky_mn_m", NULL};
  static const number_field fields[] = {
      {"mass_kg", 0, offsetof(hm_vehicle, mass_kg)},
      {"yaw_inertia_kg_m2", 0, offsetof(hm_vehicle, yaw_inertia_kg_m2)},
      {"contact_half_distance_m", 0, offsetof(hm_vehicle, contact_half_distance_m)},
      {"spring_half_distance_m", 0, offsetof(hm_vehicle, spring_half_distance_m)},
      {"rolling_radius_m", 0, offsetof(hm_vehicle, rolling_radius_m)},
      {"creep_long_n", 0, offsetof(hm_vehicle, creep_long_n)},
      {"creep_lat_n", 0, offsetof(hm_vehicle, creep_lat_n)},
      {"spring_ratio", 0, offsetof(hm_vehicle, spring_ratio)},
      {"kx_mn_m", 6, offsetof(hm_vehicle, stiffness_long_n_m)},
      {"ky_mn_m", 6, offsetof(hm_vehicle, stiffness_lat_n_m)},
  };
  hm_status st = check_keys(c, sec, "vehicle", allowed);
  for (size_t i = 0; st == HM_OK && i < sizeof fields / sizeof fields[0]; ++i) {
    double v;
    char path[96];
    snprintf(path, sizeof path, "vehicle.%s", fields[i].key);
    yaml_node_t *n = map_get(c, sec, fields[i].key);
    st = n ? node_number_scaled(c, n, path, fields[i].decades, &v) : fail(c, sec, HM_EPARSE, "%s: missing key", path);
    if (st == HM_OK) *(double *)((char *)veh + fields[i].offset) = v;
  }
  if (st != HM_OK) return st;
  yaml_node_t *n = map_get(c, sec, "name");
  name[0] = '\0';
  if (n) {
    if (n->type != YAML_SCALAR_NODE) return fail(c, n, HM_EPARSE, "vehicle.name: expected a string");
    snprintf(name, HM_VEHICLE_NAME_MAX, "%s", scalar_text(n));
  }
  return HM_OK;
}

static hm_status parse_gaussian(parse_ctx *c, yaml_node_t *item, size_t i, hm_gaussian *g) {
  static const char *const allowed[] = {"amplitude", "center_m", "width_m", NULL};
  char sec[48];
  snprintf(sec, sizeof sec, "conicity.gaussians[%zu]", i);
  if (item->type != YAML_MAPPING_NODE)
    return fail(c, item, HM_EPARSE, "%s: expected {amplitude, center_m, width_m}", sec);
  hm_status st = check_keys(c, item, sec, allowed);
  if (st == HM_OK) st = get_number(c, item, sec, "amplitude", &g->amplitude);
  if (st == HM_OK) st = get_number(c, item, sec, "center_m", &g->center_m);
  if (st == HM_OK) st = get_number(c, item, sec, "width_m", &g->width_m);
  return st;
}

static hm_status parse_conicity_section(parse_ctx *c, yaml_node_t *sec, hm_conicity *con) {
  static const char *const allowed[] = {"constant", "gaussians", NULL};
  hm_status st = check_keys(c, sec, "conicity", allowed);
  if (st == HM_OK) st = get_number(c, sec, "conicity", "constant", &con->constant);
  if (st != HM_OK) return st;
  con->n_terms = 0;
  yaml_node_t *list = map_get(c, sec, "gaussians");
  if (!list || (list->type == YAML_SCALAR_NODE && list->data.scalar.length == 0)) return HM_OK;
  if (list->type != YAML_SEQUENCE_NODE) return fail(c, list, HM_EPARSE, "conicity.gaussians: expected a list");
  const size_t count = (size_t)(list->data.sequence.items.top - list->data.sequence.items.start);
  if (count > HM_CONICITY_MAX_TERMS)
    return fail(c, list, HM_EPARSE, "conicity.gaussians: %zu terms, at most %d supported", count,
                HM_CONICITY_MAX_TERMS);
  for (size_t i = 0; i < count; ++i) {
    yaml_node_t *item = yaml_document_get_node(c->doc, list->data.sequence.items.start[i]);
    if (!item) return fail(c, list, HM_EPARSE, "conicity.gaussians[%zu]: missing", i);
    st = parse_gaussian(c, item, i, &con->terms[i]);
    if (st != HM_OK) return st;
  }
  con->n_terms = count;
  return HM_OK;
}

static hm_status parse_flange_section(parse_ctx *c, yaml_node_t *sec, hm_vehicle *veh) {
  static const char *const allowed[] = {"alpha1_n_m3", "alpha2_n_m5", NULL};
  hm_status st = check_keys(c, sec, "flange", allowed);
  if (st == HM_OK) st = get_number(c, sec, "flange", "alpha1_n_m3", &veh->flange_alpha1_n_m3);
  if (st == HM_OK) st = get_number(c, sec, "flange", "alpha2_n_m5", &veh->flange_alpha2_n_m5);
  return st;
}

/* The top-level `model:` key: wheelset (also when absent) or bogie. */
static hm_status parse_model_kind(parse_ctx *c, yaml_node_t *root, hm_model_kind *kind) {
  yaml_node_t *n = map_get(c, root, "model");
  *kind = HM_MODEL_WHEELSET;
  if (!n) return HM_OK;
  if (n->type == YAML_SCALAR_NODE && strcmp(scalar_text(n), "wheelset") == 0) return HM_OK;
  if (n->type == YAML_SCALAR_NODE && strcmp(scalar_text(n), "bogie") == 0) {
    *kind = HM_MODEL_BOGIE;
    return HM_OK;
  }
  if (n->type == YAML_SCALAR_NODE && strcmp(scalar_text(n), "car") == 0) {
    *kind = HM_MODEL_CAR;
    return HM_OK;
  }
  return fail(c, n, HM_EPARSE, "model: expected wheelset, bogie or car, got '%s'",
              n->type == YAML_SCALAR_NODE ? scalar_text(n) : "(not a name)");
}

/* The wheelset's sections (vehicle, conicity, flange); the document's model kind must be want. */
static hm_status parse_document(parse_ctx *c, hm_model_kind want, hm_vehicle *veh, char *name) {
  yaml_node_t *root = yaml_document_get_root_node(c->doc);
  if (!root) return fail(c, NULL, HM_EPARSE, "empty document");
  if (root->type != YAML_MAPPING_NODE) return fail(c, root, HM_EPARSE, "expected a mapping at the top level");
  hm_model_kind kind;
  hm_status st = parse_model_kind(c, root, &kind);
  if (st != HM_OK) return st;
  if (kind != want)
    return fail(c, map_get(c, root, "model"), HM_EPARSE, "model: '%s' where a %s config is expected",
                hm_model_kind_name(kind), hm_model_kind_name(want));
  yaml_node_t *sv, *sc, *sf;
  st = get_section(c, root, "vehicle", &sv);
  if (st == HM_OK) st = get_section(c, root, "conicity", &sc);
  if (st == HM_OK) st = get_section(c, root, "flange", &sf);
  if (st == HM_OK) st = parse_vehicle_section(c, sv, veh, name);
  if (st == HM_OK) st = parse_conicity_section(c, sc, &veh->conicity);
  if (st == HM_OK) st = parse_flange_section(c, sf, veh);
  return st;
}

/* Parse text into doc (c->doc points at it); a syntax error is reported with its line. */
static hm_status load_document(parse_ctx *c, const char *text, size_t len, yaml_document_t *doc) {
  yaml_parser_t parser;
  if (!yaml_parser_initialize(&parser)) return fail(c, NULL, HM_ENOMEM, "cannot initialise the YAML parser");
  yaml_parser_set_input_string(&parser, (const unsigned char *)text, len);
  const int loaded = yaml_parser_load(&parser, doc);
  hm_status st = HM_OK;
  if (!loaded)
    st = fail(c, NULL, HM_EPARSE, "line %lu: YAML syntax error: %s", (unsigned long)parser.problem_mark.line + 1,
              parser.problem ? parser.problem : "unknown");
  yaml_parser_delete(&parser); /* the document does not refer to the parser */
  if (st == HM_OK) c->doc = doc;
  return st;
}

hm_status hm_config_parse_vehicle(const char *text, size_t len, const char *source, hm_vehicle *veh, char *name,
                                  char *err, size_t err_len) {
  if (!source) source = "<config>";
  parse_ctx c = {NULL, source, err, err_len};
  if (!text || !veh) return fail(&c, NULL, HM_EINVAL, "no text or no output");
  yaml_document_t doc;
  hm_status st0 = load_document(&c, text, len, &doc);
  if (st0 != HM_OK) return st0;
  hm_vehicle out;
  hm_vehicle_default(&out);
  char out_name[HM_VEHICLE_NAME_MAX];
  hm_status st = parse_document(&c, HM_MODEL_WHEELSET, &out, out_name);
  if (st == HM_OK) {
    char why[160];
    st = hm_vehicle_validate(&out, why, sizeof why);
    if (st != HM_OK) fail(&c, NULL, st, "%s", why);
  }
  yaml_document_delete(&doc);
  if (st != HM_OK) return st;
  *veh = out;
  if (name) memcpy(name, out_name, HM_VEHICLE_NAME_MAX);
  return HM_OK;
}

/* Read a whole (small) file into a malloc'd buffer. */
static hm_status read_small_file(parse_ctx *c, const char *path, char **text, size_t *len) {
  FILE *f = fopen(path, "rb");
  if (!f) return fail(c, NULL, HM_EIO, "cannot open: %s", strerror(errno));
  enum { MAX_CONFIG_BYTES = 1 << 20 };
  char *buf = malloc(MAX_CONFIG_BYTES + 1);
  if (!buf) {
    fclose(f);
    return fail(c, NULL, HM_ENOMEM, "out of memory");
  }
  const size_t n = fread(buf, 1, MAX_CONFIG_BYTES + 1, f);
  const int read_error = ferror(f);
  fclose(f);
  hm_status st = HM_OK;
  if (read_error)
    st = fail(c, NULL, HM_EIO, "read error");
  else if (n > MAX_CONFIG_BYTES)
    st = fail(c, NULL, HM_EPARSE, "larger than 1 MiB: not a config file");
  if (st != HM_OK) {
    free(buf);
    return st;
  }
  *text = buf;
  *len = n;
  return HM_OK;
}

/* ---- the bogie (bogie.h) ---- */

/* Every key of the section one of fields (all required; besides them the key sub where not NULL, a subsection the
 * caller reads), SI numbers into base + offset. */
static hm_status parse_number_section(parse_ctx *c, yaml_node_t *sec, const char *name, const number_field *fields,
                                      size_t n, void *base, const char *sub) {
  const char *allowed[16];
  if (n >= 15) return fail(c, sec, HM_EINVAL, "%s: too many fields", name);
  for (size_t i = 0; i < n; ++i) allowed[i] = fields[i].key;
  allowed[n] = sub;
  allowed[n + 1] = NULL;
  hm_status st = check_keys(c, sec, name, allowed);
  for (size_t i = 0; st == HM_OK && i < n; ++i)
    st = get_number(c, sec, name, fields[i].key, (double *)((char *)base + fields[i].offset));
  return st;
}

static hm_status parse_bogie_section(parse_ctx *c, yaml_node_t *sec, hm_bogie *b) {
#define BF(f) {#f, 0, offsetof(hm_bogie, f)}
  static const number_field fields[] = {
      BF(frame_mass_kg),
      BF(frame_yaw_inertia_kg_m2),
      BF(half_wheelbase_m),
      BF(secondary_lat_stiffness_n_m),
      BF(secondary_lat_damping_n_s_m),
      BF(airspring_long_stiffness_n_m),
      BF(airspring_half_distance_m),
      BF(yaw_damper_damping_n_s_m),
      BF(yaw_damper_stiffness_n_m),
      BF(yaw_damper_half_distance_m),
  };
#undef BF
  return parse_number_section(c, sec, "bogie", fields, sizeof fields / sizeof fields[0], b, NULL);
}

/* car: its three numbers, and an optional roll: mapping (every key of it required; without it the carbody does not
 * roll, car.h). */
static hm_status parse_car_section(parse_ctx *c, yaml_node_t *sec, hm_car *car) {
  static const number_field fields[] = {
      {"carbody_mass_kg", 0, offsetof(hm_car, carbody_mass_kg)},
      {"carbody_yaw_inertia_kg_m2", 0, offsetof(hm_car, carbody_yaw_inertia_kg_m2)},
      {"half_bogie_distance_m", 0, offsetof(hm_car, half_bogie_distance_m)},
  };
  static const number_field roll_fields[] = {
      {"inertia_kg_m2", 0, offsetof(hm_car, carbody_roll_inertia_kg_m2)},
      {"cg_height_m", 0, offsetof(hm_car, carbody_cg_height_m)},
      {"stiffness_n_m_rad", 0, offsetof(hm_car, secondary_roll_stiffness_n_m_rad)},
      {"damping_n_m_s_rad", 0, offsetof(hm_car, secondary_roll_damping_n_m_s_rad)},
  };
  yaml_node_t *roll = NULL;
  hm_status st = parse_number_section(c, sec, "car", fields, sizeof fields / sizeof fields[0], car, "roll");
  if (st == HM_OK) st = get_optional_section(c, sec, "roll", "car.roll", &roll);
  if (st == HM_OK && roll)
    st = parse_number_section(c, roll, "car.roll", roll_fields, sizeof roll_fields / sizeof roll_fields[0], car, NULL);
  return st;
}

hm_status hm_config_model_kind(const char *text, size_t len, const char *source, hm_model_kind *kind, char *err,
                               size_t err_len) {
  parse_ctx c = {NULL, source ? source : "<config>", err, err_len};
  if (!text || !kind) return fail(&c, NULL, HM_EINVAL, "no text or no output");
  yaml_document_t doc;
  hm_status st = load_document(&c, text, len, &doc);
  if (st != HM_OK) return st;
  yaml_node_t *root = yaml_document_get_root_node(&doc);
  hm_model_kind k = HM_MODEL_WHEELSET;
  if (!root) st = fail(&c, NULL, HM_EPARSE, "empty document");
  else if (root->type != YAML_MAPPING_NODE) st = fail(&c, root, HM_EPARSE, "expected a mapping at the top level");
  else st = parse_model_kind(&c, root, &k);
  yaml_document_delete(&doc);
  if (st == HM_OK) *kind = k;
  return st;
}

/* The wheelset's and the bogie's sections of a `want` (bogie or car) config into *bogie, the car's into *car. */
static hm_status parse_vehicle_model(const char *text, size_t len, const char *source, hm_model_kind want,
                                     hm_bogie *bogie, hm_car *car, char *name, char *err, size_t err_len) {
  parse_ctx c = {NULL, source ? source : "<config>", err, err_len};
  yaml_document_t doc;
  hm_status st = load_document(&c, text, len, &doc);
  if (st != HM_OK) return st;
  yaml_node_t *sb = NULL, *sc = NULL;
  st = parse_document(&c, want, &bogie->wheelset, name);
  if (st == HM_OK) st = get_section(&c, yaml_document_get_root_node(&doc), "bogie", &sb);
  if (st == HM_OK) st = parse_bogie_section(&c, sb, bogie);
  if (st == HM_OK && car) st = get_section(&c, yaml_document_get_root_node(&doc), "car", &sc);
  if (st == HM_OK && car) st = parse_car_section(&c, sc, car);
  if (st == HM_OK) {
    char why[160];
    if (car) car->bogie = *bogie;
    st = car ? hm_car_validate(car, why, sizeof why) : hm_bogie_validate(bogie, why, sizeof why);
    if (st != HM_OK) fail(&c, NULL, st, "%s", why);
  }
  yaml_document_delete(&doc);
  return st;
}

hm_status hm_config_parse_bogie(const char *text, size_t len, const char *source, hm_bogie *bogie, char *name,
                                char *err, size_t err_len) {
  parse_ctx c = {NULL, source ? source : "<config>", err, err_len};
  if (!text || !bogie) return fail(&c, NULL, HM_EINVAL, "no text or no output");
  hm_bogie out;
  hm_bogie_default(&out);
  char out_name[HM_VEHICLE_NAME_MAX];
  hm_status st = parse_vehicle_model(text, len, source, HM_MODEL_BOGIE, &out, NULL, out_name, err, err_len);
  if (st != HM_OK) return st;
  *bogie = out;
  if (name) memcpy(name, out_name, HM_VEHICLE_NAME_MAX);
  return HM_OK;
}

hm_status hm_config_parse_car(const char *text, size_t len, const char *source, hm_car *car, char *name, char *err,
                              size_t err_len) {
  parse_ctx c = {NULL, source ? source : "<config>", err, err_len};
  if (!text || !car) return fail(&c, NULL, HM_EINVAL, "no text or no output");
  hm_car out;
  hm_car_default(&out);
  char out_name[HM_VEHICLE_NAME_MAX];
  hm_status st = parse_vehicle_model(text, len, source, HM_MODEL_CAR, &out.bogie, &out, out_name, err, err_len);
  if (st != HM_OK) return st;
  *car = out;
  if (name) memcpy(name, out_name, HM_VEHICLE_NAME_MAX);
  return HM_OK;
}

/* Read path and hand its text to parse (one of the three readers above, through a small adapter). */
typedef hm_status (*text_reader)(const char *text, size_t len, const char *source, void *out, char *name, char *err,
                                 size_t err_len);

static hm_status load_with(const char *path, text_reader parse, void *out, char *name, char *err, size_t err_len) {
  parse_ctx c = {NULL, path ? path : "<null>", err, err_len};
  if (!path) return fail(&c, NULL, HM_EINVAL, "no path");
  char *buf = NULL;
  size_t n = 0;
  hm_status st = read_small_file(&c, path, &buf, &n);
  if (st != HM_OK) return st;
  st = parse(buf, n, path, out, name, err, err_len);
  free(buf);
  return st;
}

static hm_status read_kind(const char *t, size_t n, const char *src, void *out, char *name, char *e, size_t el) {
  (void)name;
  return hm_config_model_kind(t, n, src, (hm_model_kind *)out, e, el);
}

static hm_status read_bogie(const char *t, size_t n, const char *src, void *out, char *name, char *e, size_t el) {
  return hm_config_parse_bogie(t, n, src, (hm_bogie *)out, name, e, el);
}

static hm_status read_vehicle(const char *t, size_t n, const char *src, void *out, char *name, char *e, size_t el) {
  return hm_config_parse_vehicle(t, n, src, (hm_vehicle *)out, name, e, el);
}

hm_status hm_config_load_vehicle(const char *path, hm_vehicle *veh, char *name, char *err, size_t err_len) {
  return load_with(path, read_vehicle, veh, name, err, err_len);
}

static hm_status read_car(const char *t, size_t n, const char *src, void *out, char *name, char *e, size_t el) {
  return hm_config_parse_car(t, n, src, (hm_car *)out, name, e, el);
}

hm_status hm_config_load_car(const char *path, hm_car *car, char *name, char *err, size_t err_len) {
  return load_with(path, read_car, car, name, err, err_len);
}

hm_status hm_config_load_model_kind(const char *path, hm_model_kind *kind, char *err, size_t err_len) {
  return load_with(path, read_kind, kind, NULL, err, err_len);
}

hm_status hm_config_load_bogie(const char *path, hm_bogie *bogie, char *name, char *err, size_t err_len) {
  return load_with(path, read_bogie, bogie, name, err, err_len);
}

/* ---- monitor settings ---- */

typedef enum { FIELD_DOUBLE, FIELD_UNSIGNED, FIELD_BOOL, FIELD_POINT } field_type;

typedef struct {
  const char *key;
  field_type type;
  size_t offset;
} settings_field;

#define EST(f, t) {#f, t, offsetof(hm_monitor_config, estimator) + offsetof(hm_estimator_config, f)}
#define MOD(f, t) {#f, t, offsetof(hm_monitor_config, modal) + offsetof(hm_modal_config, f)}
#define MAR(f, t) {#f, t, offsetof(hm_monitor_config, margin) + offsetof(hm_margin_config, f)}
#define ALM(f, t) {#f, t, offsetof(hm_monitor_config, alarm) + offsetof(hm_alarm_config, f)}
#define TRK(f, t) {#f, t, offsetof(hm_monitor_config, track_lines) + offsetof(hm_track_lines_config, f)}
#define TAB(f, t) {#f, t, offsetof(hm_monitor_config, table.f)}

static const settings_field estimator_fields[] = {
    EST(measurement_point, FIELD_POINT),
    EST(sample_rate_hz, FIELD_DOUBLE),       EST(band_low_hz, FIELD_DOUBLE),
    EST(band_high_hz, FIELD_DOUBLE),         EST(tracking_time_s, FIELD_DOUBLE),
    EST(rms_window_m, FIELD_DOUBLE),         EST(rms_limit_mps2, FIELD_DOUBLE),
    EST(peaks_band_low_hz, FIELD_DOUBLE),    EST(peaks_band_high_hz, FIELD_DOUBLE),
    EST(peaks_limit_mps2, FIELD_DOUBLE),     EST(peaks_count, FIELD_UNSIGNED),
    EST(displacement_limit_m, FIELD_DOUBLE),
    EST(max_gap_s, FIELD_DOUBLE),
    EST(accel_timeout_s, FIELD_DOUBLE),      EST(speed_timeout_s, FIELD_DOUBLE),
    EST(max_speed_kmh, FIELD_DOUBLE),        EST(max_speed_rate_kmh_s, FIELD_DOUBLE),
    EST(max_speed_jump_kmh, FIELD_DOUBLE),
    EST(max_accel_mps2, FIELD_DOUBLE),
};

static const settings_field modal_fields[] = {
    MOD(window_s, FIELD_DOUBLE),       MOD(min_window_s, FIELD_DOUBLE), MOD(decimated_rate_hz, FIELD_DOUBLE),
    MOD(band_low_hz, FIELD_DOUBLE),    MOD(band_high_hz, FIELD_DOUBLE), MOD(fit_interval_s, FIELD_DOUBLE),
    MOD(tol, FIELD_DOUBLE),            MOD(max_iter, FIELD_UNSIGNED),
    MOD(reject_lines, FIELD_BOOL),     MOD(line_candidate_ratio, FIELD_DOUBLE),
    MOD(line_min_fundamental_hz, FIELD_DOUBLE), MOD(line_min_harmonics, FIELD_UNSIGNED),
    MOD(min_peak_prominence, FIELD_DOUBLE),
};

static const settings_field margin_fields[] = {
    MAR(frequency_model_error, FIELD_DOUBLE), MAR(decay_rate_model_error, FIELD_DOUBLE),
    MAR(max_speed_spread_kmh, FIELD_DOUBLE),  MAR(min_speed_kmh, FIELD_DOUBLE),
    MAR(memory_s, FIELD_DOUBLE),              MAR(min_speed_span_kmh, FIELD_DOUBLE),
    MAR(max_extrapolation_kmh, FIELD_DOUBLE), MAR(interval_z, FIELD_DOUBLE),
    MAR(max_misfit_chi2, FIELD_DOUBLE),       MAR(change_z, FIELD_DOUBLE),
    MAR(spectrum_low_hz, FIELD_DOUBLE),       MAR(spectrum_high_hz, FIELD_DOUBLE),
    MAR(spectrum_model_error, FIELD_DOUBLE),  MAR(spectrum_max_shape_chi2, FIELD_DOUBLE),
    MAR(spectrum_conicity, FIELD_BOOL),
};

static const settings_field alarm_fields[] = {
    ALM(warn_amplitude_fraction, FIELD_DOUBLE), ALM(warn_speed_margin_kmh, FIELD_DOUBLE),
    ALM(warn_standard_errors, FIELD_DOUBLE),
    ALM(watch_speed_margin_kmh, FIELD_DOUBLE),  ALM(hysteresis_kmh, FIELD_DOUBLE),
    ALM(hysteresis_amplitude_fraction, FIELD_DOUBLE),
    ALM(min_hold_s, FIELD_DOUBLE),              ALM(use_conicity_estimate, FIELD_BOOL),
    ALM(conicity_max_se, FIELD_DOUBLE),         ALM(conicity_fallback, FIELD_DOUBLE),
    ALM(conicity_prior_low, FIELD_DOUBLE),      ALM(conicity_prior_high, FIELD_DOUBLE),
    ALM(release_s, FIELD_DOUBLE),               ALM(release_amplitude_fraction, FIELD_DOUBLE),
    ALM(blind_fraction, FIELD_DOUBLE),
};

static const settings_field track_lines_fields[] = {
    TRK(wavelength_tol_rel, FIELD_DOUBLE), TRK(min_speed_change_rel, FIELD_DOUBLE), TRK(memory_s, FIELD_DOUBLE),
};

static const settings_field table_fields[] = {
    TAB(refine, FIELD_BOOL), TAB(tolerance_kmh, FIELD_DOUBLE), TAB(tolerance_m, FIELD_DOUBLE),
    TAB(max_curves, FIELD_UNSIGNED),
};

static const struct {
  const char *name;
  const settings_field *fields;
  size_t n;
} sections[] = {{"estimator", estimator_fields, sizeof estimator_fields / sizeof estimator_fields[0]},
                {"modal", modal_fields, sizeof modal_fields / sizeof modal_fields[0]},
                {"margin", margin_fields, sizeof margin_fields / sizeof margin_fields[0]},
                {"alarm", alarm_fields, sizeof alarm_fields / sizeof alarm_fields[0]},
                {"track_lines", track_lines_fields, sizeof track_lines_fields / sizeof track_lines_fields[0]},
                {"table", table_fields, sizeof table_fields / sizeof table_fields[0]}};

/* One key's value into the field at base + f->offset. */
static hm_status apply_field(parse_ctx *c, const settings_field *f, yaml_node_t *v, const char *path, void *base) {
  const char *t = v->type == YAML_SCALAR_NODE ? scalar_text(v) : "";
  if (f->type == FIELD_BOOL || f->type == FIELD_POINT) {
    const char *yes_word = f->type == FIELD_BOOL ? "true" : "bogie_frame";
    const char *no_word = f->type == FIELD_BOOL ? "false" : "wheelset";
    const int yes = strcmp(t, yes_word) == 0, no = strcmp(t, no_word) == 0;
    if (!yes && !no) return fail(c, v, HM_EPARSE, "%s: expected %s or %s, got '%s'", path, no_word, yes_word, t);
    if (f->type == FIELD_BOOL)
      *(int *)((char *)base + f->offset) = yes;
    else /* the criteria's defaults for that point first; explicit keys in the section then override them */
      hm_estimator_config_criteria(&((hm_monitor_config *)base)->estimator,
                                   yes ? HM_POINT_BOGIE_FRAME : HM_POINT_WHEELSET);
    return HM_OK;
  }
  double x = 0.0;
  hm_status st = node_number(c, v, path, &x);
  if (st != HM_OK) return st;
  if (f->type == FIELD_UNSIGNED) {
    if (x < 0.0 || x > 1e9 || x != floor(x)) return fail(c, v, HM_EPARSE, "%s: expected a whole number", path);
    *(unsigned *)((char *)base + f->offset) = (unsigned)x;
  } else {
    *(double *)((char *)base + f->offset) = x;
  }
  return HM_OK;
}

/* Apply the keys of one section onto cfg (measurement_point first: it sets the criteria's defaults). */
static hm_status apply_section(parse_ctx *c, yaml_node_t *sec, const char *name, const settings_field *fields,
                               size_t n_fields, hm_monitor_config *cfg) {
  if (sec->type != YAML_MAPPING_NODE) return fail(c, sec, HM_EPARSE, "%s: expected a mapping of keys", name);
  for (int pass = 0; pass < 2; ++pass)
    for (yaml_node_pair_t *p = sec->data.mapping.pairs.start; p < sec->data.mapping.pairs.top; ++p) {
      yaml_node_t *k = yaml_document_get_node(c->doc, p->key), *v = yaml_document_get_node(c->doc, p->value);
      if (!k || k->type != YAML_SCALAR_NODE || !v) return fail(c, k, HM_EPARSE, "%s: keys must be plain names", name);
      const settings_field *f = NULL;
      for (size_t i = 0; i < n_fields && !f; ++i)
        if (strcmp(fields[i].key, scalar_text(k)) == 0) f = &fields[i];
      char path[96];
      snprintf(path, sizeof path, "%s.%s", name, scalar_text(k));
      if (!f) return fail(c, k, HM_EPARSE, "%s: unknown key", path);
      if ((f->type == FIELD_POINT) != (pass == 0)) continue;
      hm_status st = apply_field(c, f, v, path, cfg);
      if (st != HM_OK) return st;
    }
  return HM_OK;
}

hm_status hm_config_parse_monitor(const char *text, size_t len, const char *source, hm_monitor_config *cfg, char *err,
                                  size_t err_len) {
  if (!source) source = "<config>";
  parse_ctx c = {NULL, source, err, err_len};
  if (!text || !cfg) return fail(&c, NULL, HM_EINVAL, "no text or no output");
  yaml_document_t doc;
  hm_status st0 = load_document(&c, text, len, &doc);
  if (st0 != HM_OK) return st0;
  hm_monitor_config m = *cfg;
  hm_status st = HM_OK;
  yaml_node_t *root = yaml_document_get_root_node(&doc);
  if (!root || root->type != YAML_MAPPING_NODE) st = fail(&c, root, HM_EPARSE, "expected a mapping at the top level");
  for (size_t i = 0; st == HM_OK && i < sizeof sections / sizeof sections[0]; ++i) {
    yaml_node_t *sec = map_get(&c, root, sections[i].name);
    if (sec) st = apply_section(&c, sec, sections[i].name, sections[i].fields, sections[i].n, &m);
  }
  char why[200];
  if (st == HM_OK && (st = hm_monitor_config_validate(&m, why, sizeof why)) != HM_OK) fail(&c, NULL, st, "%s", why);
  yaml_document_delete(&doc);
  if (st != HM_OK) return st;
  *cfg = m;
  return HM_OK;
}

hm_status hm_config_load_monitor(const char *path, hm_monitor_config *cfg, char *err, size_t err_len) {
  parse_ctx c = {NULL, path ? path : "<null>", err, err_len};
  if (!path) return fail(&c, NULL, HM_EINVAL, "no path");
  char *buf = NULL;
  size_t n = 0;
  hm_status st = read_small_file(&c, path, &buf, &n);
  if (st != HM_OK) return st;
  st = hm_config_parse_monitor(buf, n, path, cfg, err, err_len);
  free(buf);
  return st;
}

/* ---- writing ---- */


/* The shortest decimal text of x / 10^decades that parses back (node_number_scaled) to exactly x. */
static void scaled_text(double x, int decades, char *out, size_t len) {
  char buf[40];
  for (int prec = 0; prec <= 17; ++prec) {
    snprintf(buf, sizeof buf, "%.*e", prec, x);
    if (strtod(buf, NULL) == x) break;
  }
  char *e = strchr(buf, 'e');
  const int exponent = (int)strtol(e + 1, NULL, 10) - decades;
  *e = '\0';
  if (exponent == 0)
    snprintf(out, len, "%s", buf);
  else
    snprintf(out, len, "%se%d", buf, exponent);
}

hm_status hm_config_format_vehicle(const hm_vehicle *veh, const char *name, const char *comment, char *buf,
                                   size_t len, size_t *needed) {
  if (!veh || !needed || (len && !buf)) return HM_EINVAL;
  hm_text_sink s = {buf, len, 0};
  for (const char *c = comment; c && *c;) { /* each comment line prefixed by '# ' */
    const char *nl = strchr(c, '\n');
    const int n = nl ? (int)(nl - c) : (int)strlen(c);
    hm_text_sink_printf(&s, "# %.*s\n", n, c);
    c = nl ? nl + 1 : c + n;
  }
  hm_text_sink_printf(&s, "vehicle:\n");
  if (name && *name) { /* quoted, with quotes, backslashes and control characters left out */
    hm_text_sink_printf(&s, "  name: \"");
    for (const char *c = name; *c; ++c)
      if (*c != '"' && *c != '\\' && (unsigned char)*c >= 0x20) hm_text_sink_printf(&s, "%c", *c);
    hm_text_sink_printf(&s, "\"\n");
  }
  hm_text_sink_printf(&s, "  mass_kg: %.17g\n", veh->mass_kg);
  hm_text_sink_printf(&s, "  yaw_inertia_kg_m2: %.17g\n", veh->yaw_inertia_kg_m2);
  hm_text_sink_printf(&s, "  contact_half_distance_m: %.17g\n", veh->contact_half_distance_m);
  hm_text_sink_printf(&s, "  spring_half_distance_m: %.17g\n", veh->spring_half_distance_m);
  hm_text_sink_printf(&s, "  rolling_radius_m: %.17g\n", veh->rolling_radius_m);
  hm_text_sink_printf(&s, "  creep_long_n: %.17g\n", veh->creep_long_n);
  hm_text_sink_printf(&s, "  creep_lat_n: %.17g\n", veh->creep_lat_n);
  hm_text_sink_printf(&s, "  spring_ratio: %.17g\n", veh->spring_ratio);
  char kx[64], ky[64];
  scaled_text(veh->stiffness_long_n_m, 6, kx, sizeof kx);
  scaled_text(veh->stiffness_lat_n_m, 6, ky, sizeof ky);
  hm_text_sink_printf(&s, "  kx_mn_m: %s\n", kx);
  hm_text_sink_printf(&s, "  ky_mn_m: %s\n", ky);
  hm_text_sink_printf(&s, "conicity:\n  constant: %.17g\n  gaussians:%s\n", veh->conicity.constant,
       veh->conicity.n_terms ? "" : " []");
  for (size_t i = 0; i < veh->conicity.n_terms; ++i)
    hm_text_sink_printf(&s, "    - {amplitude: %.17g, center_m: %.17g, width_m: %.17g}\n", veh->conicity.terms[i].amplitude,
         veh->conicity.terms[i].center_m, veh->conicity.terms[i].width_m);
  hm_text_sink_printf(&s, "flange:\n  alpha1_n_m3: %.17g\n  alpha2_n_m5: %.17g\n", veh->flange_alpha1_n_m3,
       veh->flange_alpha2_n_m5);
  *needed = s.used + 1;
  return s.used < len ? HM_OK : HM_EINVAL;
}
