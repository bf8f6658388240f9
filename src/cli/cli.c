#include "cli.h"

#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "hunting_monitor/config.h"

int cli_parse(const char *command, int argc, char **argv, const cli_option *opts, int allow_positional,
              cli_args *out) {
  memset(out, 0, sizeof *out);
  size_t n_opts = 0;
  while (opts[n_opts].name) ++n_opts;
  struct option *lo = calloc(n_opts + 1, sizeof *lo);
  if (!lo) {
    fprintf(stderr, "hunting %s: out of memory\n", command);
    return 1;
  }
  for (size_t k = 0; k < n_opts; ++k)
    lo[k] = (struct option){opts[k].name, opts[k].arg ? required_argument : no_argument, NULL, (int)k + 1};
  /* getopt_long: --name VALUE or --name=VALUE, unambiguous prefixes, "--" ends the options; a value may start
   * with '-' (--kx -1 reaches the vehicle check). Messages are ours (opterr 0, ':' reports a missing value). */
  optind = 0;
  opterr = 0;
  int rc = 0, c;
  while (rc == 0 && (c = getopt_long(argc, argv, ":", lo, NULL)) != -1) {
    if (c == '?') {
      const char *given = argv[optind - 1], *name = strncmp(given, "--", 2) == 0 ? given + 2 : given;
      const size_t len = strcspn(name, "=");
      int matches = 0;
      for (size_t k = 0; k < n_opts; ++k) matches += strncmp(opts[k].name, name, len) == 0;
      fprintf(stderr, "hunting %s: %s option '%s' (see hunting %s --help)\n", command,
              matches > 1 ? "ambiguous" : "unknown", given, command);
      rc = 1;
    } else if (c == ':') {
      const cli_option *o = optopt > 0 && (size_t)optopt <= n_opts ? &opts[optopt - 1] : NULL;
      if (o) fprintf(stderr, "hunting %s: option --%s needs a value %s\n", command, o->name, o->arg);
      else fprintf(stderr, "hunting %s: option '%s' needs a value\n", command, argv[optind - 1]);
      rc = 1;
    } else {
      const cli_option *o = &opts[c - 1];
      if (cli_has(out, o->name)) {
        fprintf(stderr, "hunting %s: option --%s given twice\n", command, o->name);
        rc = 1;
      } else if (out->count == CLI_MAX_ARGS) {
        fprintf(stderr, "hunting %s: too many options\n", command);
        rc = 1;
      } else {
        out->names[out->count] = o->name;
        out->values[out->count] = o->arg ? optarg : NULL;
        out->count++;
      }
    }
  }
  free(lo);
  for (int i = optind; rc == 0 && i < argc; ++i) {
    if (!allow_positional || out->positional) {
      fprintf(stderr, "hunting %s: unexpected argument '%s' (see hunting %s --help)\n", command, argv[i], command);
      rc = 1;
    } else {
      out->positional = argv[i];
    }
  }
  return rc;
}

int cli_has(const cli_args *a, const char *name) {
  for (int i = 0; i < a->count; ++i)
    if (strcmp(a->names[i], name) == 0) return 1;
  return 0;
}

const char *cli_value(const cli_args *a, const char *name) {
  for (int i = 0; i < a->count; ++i)
    if (strcmp(a->names[i], name) == 0) return a->values[i];
  return NULL;
}

static int parse_double(const char *s, double *out) {
  char *end = NULL;
  errno = 0;
  const double v = strtod(s, &end);
  if (end == s || *end != '\0' || errno == ERANGE || !isfinite(v)) return 1;
  *out = v;
  return 0;
}

int cli_number(const cli_args *a, const char *name, double *out) {
  const char *s = cli_value(a, name);
  if (!s) return 0;
  if (parse_double(s, out)) {
    fprintf(stderr, "hunting: --%s: expected a finite number, got '%s'\n", name, s);
    return 1;
  }
  return 0;
}

int cli_number_list(const cli_args *a, const char *name, double *out, int n) {
  const char *s = cli_value(a, name);
  if (!s) return 0;
  char buf[256];
  if (strlen(s) >= sizeof buf) {
    fprintf(stderr, "hunting: --%s: value too long\n", name);
    return 1;
  }
  strcpy(buf, s);
  double tmp[16];
  int count = 0;
  for (char *tok = strtok(buf, ","); tok; tok = strtok(NULL, ",")) {
    if (count == n || count == 16 || parse_double(tok, &tmp[count])) {
      fprintf(stderr, "hunting: --%s: expected %d comma-separated finite numbers, got '%s'\n", name, n, s);
      return 1;
    }
    ++count;
  }
  if (count != n) {
    fprintf(stderr, "hunting: --%s: expected %d comma-separated finite numbers, got '%s'\n", name, n, s);
    return 1;
  }
  memcpy(out, tmp, (size_t)n * sizeof(double));
  return 0;
}

int cli_vehicle(const cli_args *a, hm_vehicle *veh, char *name) {
  hm_vehicle v;
  char err[512];
  const char *path = cli_value(a, "config");
  if (path) {
    hm_status st = hm_config_load_vehicle(path, &v, name, err, sizeof err);
    if (st != HM_OK) {
      hm_model_kind kind = HM_MODEL_WHEELSET;
      const int other_model = hm_config_load_model_kind(path, &kind, NULL, 0) == HM_OK && kind != HM_MODEL_WHEELSET;
      fprintf(stderr, "hunting: config error: %s%s\n", err,
              other_model ? " (this command takes the wheelset model; critical, eig, cycles, simulate, tables and "
                            "estimate take a bogie or car)"
                          : "");
      return 1;
    }
  } else {
    hm_vehicle_default(&v);
    if (name) strcpy(name, "crh380_default (built-in)");
  }
  double kx = v.stiffness_long_n_m / 1e6, ky = v.stiffness_lat_n_m / 1e6, lambda0 = cli_conicity0(&v);
  if (cli_number(a, "kx", &kx) || cli_number(a, "ky", &ky) || cli_number(a, "conicity", &lambda0)) return 1;
  v.stiffness_long_n_m = kx * 1e6;
  v.stiffness_lat_n_m = ky * 1e6;
  if (hm_vehicle_set_conicity_at_zero(&v, lambda0) != HM_OK) {
    fprintf(stderr, "hunting: --conicity %g: must be >= 0 and >= the Gaussian terms' value at y = 0\n", lambda0);
    return 1;
  }
  if (hm_vehicle_validate(&v, err, sizeof err) != HM_OK) {
    fprintf(stderr, "hunting: invalid vehicle: %s\n", err);
    return 1;
  }
  *veh = v;
  return 0;
}

int cli_model_kind(const cli_args *a, hm_model_kind *kind) {
  const char *path = cli_value(a, "config");
  char err[512];
  *kind = HM_MODEL_WHEELSET;
  if (!path) return 0;
  if (hm_config_load_model_kind(path, kind, err, sizeof err) != HM_OK) {
    fprintf(stderr, "hunting: config error: %s\n", err);
    return 1;
  }
  return 0;
}

hm_status cli_model_init(hm_model_kind kind, const hm_car *car, cli_model *out) {
  out->kind = kind;
  out->wheelset = car->bogie.wheelset;
  out->params = *car;
  hm_status st;
  if (kind == HM_MODEL_CAR) {
    st = hm_car_model_init(&out->car, &out->params, 0, &out->sys);
    if (st == HM_OK) st = hm_car_model_init(&out->car_held, &out->params, 1, &out->held);
    out->held_name = "carbody_held_v_crit_kmh";
  } else {
    st = hm_bogie_model_init(&out->bogie, &out->params.bogie, 0, &out->sys);
    if (st == HM_OK) st = hm_bogie_model_init(&out->bogie_held, &out->params.bogie, 1, &out->held);
    out->held_name = "frame_held_v_crit_kmh";
  }
  return st;
}

int cli_vehicle_model(const cli_args *a, hm_model_kind kind, cli_model *out) {
  hm_car car;
  char err[512];
  const char *path = cli_value(a, "config");
  hm_car_default(&car);
  hm_status st = !path ? HM_EINVAL
                 : kind == HM_MODEL_CAR ? hm_config_load_car(path, &car, NULL, err, sizeof err)
                                        : hm_config_load_bogie(path, &car.bogie, NULL, err, sizeof err);
  if (st != HM_OK) {
    fprintf(stderr, "hunting: config error: %s\n", path ? err : "a bogie or car needs --config FILE");
    return 1;
  }
  hm_vehicle *w = &car.bogie.wheelset;
  double kx = w->stiffness_long_n_m / 1e6, ky = w->stiffness_lat_n_m / 1e6, lambda0 = cli_conicity0(w);
  if (cli_number(a, "kx", &kx) || cli_number(a, "ky", &ky) || cli_number(a, "conicity", &lambda0)) return 1;
  w->stiffness_long_n_m = kx * 1e6;
  w->stiffness_lat_n_m = ky * 1e6;
  if (hm_vehicle_set_conicity_at_zero(w, lambda0) != HM_OK) {
    fprintf(stderr, "hunting: --conicity %g: must be >= 0 and >= the Gaussian terms' value at y = 0\n", lambda0);
    return 1;
  }
  if (hm_car_validate(&car, err, sizeof err) != HM_OK) {
    fprintf(stderr, "hunting: invalid %s: %s\n", hm_model_kind_name(kind), err);
    return 1;
  }
  st = cli_model_init(kind, &car, out);
  if (st != HM_OK) {
    fprintf(stderr, "hunting: %s: %s\n", hm_model_kind_name(kind), hm_status_str(st));
    return 1;
  }
  return 0;
}

void jw_spectrum(json_writer *w, const char *key, const hm_system_spectrum *s) {
  jw_array(w, key);
  for (size_t i = 0; i < s->dim; ++i) {
    const double pair[2] = {s->re[i], s->im[i]};
    jw_numbers(w, NULL, pair, 2);
  }
  jw_end_array(w);
}

double cli_conicity0(const hm_vehicle *veh) {
  double l;
  hm_conicity_eval(&veh->conicity, 0.0, &l, NULL);
  return l;
}

void cli_print_help(FILE *f, const char *command, const char *usage, const char *summary, const cli_option *opts) {
  fprintf(f, "usage: hunting %s %s\n\n%s\n\noptions:\n", command, usage, summary);
  for (const cli_option *o = opts; o->name; ++o) {
    char left[64];
    snprintf(left, sizeof left, "--%s%s%s", o->name, o->arg ? " " : "", o->arg ? o->arg : "");
    fprintf(f, "  %-22s %s\n", left, o->help);
  }
}

/* ---- JSON writer ---- */

void jw_init(json_writer *w, FILE *f) {
  memset(w, 0, sizeof *w);
  w->f = f;
}

static void jw_escaped(FILE *f, const char *text) {
  fputc('"', f);
  for (const char *c = text; *c; ++c) {
    if (*c == '"' || *c == '\\')
      fprintf(f, "\\%c", *c);
    else if ((unsigned char)*c < 0x20)
      fprintf(f, "\\u%04x", (unsigned)(unsigned char)*c);
    else
      fputc(*c, f);
  }
  fputc('"', f);
}

static void jw_prefix(json_writer *w, const char *key) {
  if (w->count[w->depth]++ > 0) fputs(", ", w->f);
  if (key) {
    jw_escaped(w->f, key);
    fputs(": ", w->f);
  }
}

int jw_ok(const json_writer *w) { return !w->error; }

static void jw_open(json_writer *w, const char *key, char bracket) {
  jw_prefix(w, key);
  fputc(bracket, w->f);
  if (w->depth < JW_MAX_DEPTH)
    w->count[++w->depth] = 0;
  else
    w->error = 1;
}

static void jw_close(json_writer *w, char bracket) {
  fputc(bracket, w->f);
  if (w->depth > 0)
    --w->depth;
  else
    w->error = 1;
}

void jw_object(json_writer *w, const char *key) { jw_open(w, key, '{'); }
void jw_array(json_writer *w, const char *key) { jw_open(w, key, '['); }
void jw_end_object(json_writer *w) { jw_close(w, '}'); }
void jw_end_array(json_writer *w) { jw_close(w, ']'); }

void jw_number(json_writer *w, const char *key, double value) {
  jw_prefix(w, key);
  if (!isfinite(value)) {
    fputs("null", w->f);
    return;
  }
  char buf[400]; /* room for any precision as the compiler sees it (at most 17 digits are used) */
  /* the shortest that reads back as the same double, without an exponent for whole numbers below 1e15 */
  const double mag = fabs(value);
  const int digits = mag >= 1.0 && mag < 1e15 ? (int)floor(log10(mag)) + 1 : 1;
  /* reading back is exact from some precision on (17 always): bisect for the first one (4-5 tries, not up to 17) */
  int lo = digits < 17 ? digits : 17, hi = 17;
  while (lo < hi) {
    const int mid = (lo + hi) / 2;
    snprintf(buf, sizeof buf, "%.*g", mid, value);
    if (strtod(buf, NULL) == value) hi = mid;
    else lo = mid + 1;
  }
  snprintf(buf, sizeof buf, "%.*g", lo, value);
  fputs(buf, w->f);
}

void jw_int(json_writer *w, const char *key, long value) {
  jw_prefix(w, key);
  fprintf(w->f, "%ld", value);
}

void jw_string(json_writer *w, const char *key, const char *value) {
  jw_prefix(w, key);
  jw_escaped(w->f, value);
}

void jw_bool(json_writer *w, const char *key, int value) {
  jw_prefix(w, key);
  fputs(value ? "true" : "false", w->f);
}

void jw_finish(json_writer *w) { fputc('\n', w->f); }

/* ---- CSV ---- */

static char *trim(char *s) {
  while (*s == ' ' || *s == '\t') ++s;
  char *e = s + strlen(s);
  while (e > s && (e[-1] == ' ' || e[-1] == '\t' || e[-1] == '\r' || e[-1] == '\n')) *--e = '\0';
  return s;
}

/* Split line at commas into at most max fields; returns the count. */
static int split_commas(char *line, char **fields, int max) {
  int k = 0;
  char *p = line;
  while (k < max) {
    char *comma = strchr(p, ',');
    if (comma) *comma = '\0';
    fields[k++] = trim(p);
    if (!comma) break;
    p = comma + 1;
  }
  return strchr(p, ',') ? max + 1 : k;
}

/* strtod that accepts nan/inf (for recorded data). */
static int parse_any_double(const char *s, double *out) {
  char *end = NULL;
  errno = 0;
  const double v = strtod(s, &end);
  if (end == s || *end != '\0') return 1;
  *out = v;
  return 0;
}

/* The next non-blank, non-comment line split into exactly ncols fields: 1, 0 at the end, -1 on an error. */
static int csv_fields(cli_csv *c, char *line, size_t cap, char **fields) {
  while (fgets(line, (int)cap, c->f)) {
    ++c->lineno;
    if (!strchr(line, '\n') && !feof(c->f)) {
      fprintf(stderr, "hunting: %s:%zu: line too long\n", c->path, c->lineno);
      return -1;
    }
    char *t = trim(line);
    if (!*t || *t == '#') continue;
    const int k = split_commas(t, fields, 16);
    if (k != c->ncols) {
      fprintf(stderr, "hunting: %s:%zu: expected %d comma-separated columns, found %d\n", c->path, c->lineno,
              c->ncols, k);
      return -1;
    }
    return 1;
  }
  if (ferror(c->f)) {
    fprintf(stderr, "hunting: %s: read error\n", c->path);
    return -1;
  }
  return 0;
}

int cli_csv_open(cli_csv *c, const char *path, int ncols, int allow_nonfinite) {
  memset(c, 0, sizeof *c);
  c->path = path;
  c->ncols = ncols;
  c->allow_nonfinite = allow_nonfinite;
  if (ncols < 1 || ncols > 16) return 1;
  c->f = fopen(path, "r");
  if (!c->f) {
    fprintf(stderr, "hunting: %s: cannot open: %s\n", path, strerror(errno));
    return 1;
  }
  char line[1024], *fields[16];
  const int r = csv_fields(c, line, sizeof line, fields);
  if (r == 0) fprintf(stderr, "hunting: %s: no header line\n", path);
  if (r != 1) {
    cli_csv_close(c);
    return 1;
  }
  for (int k = 0; k < ncols; ++k) snprintf(c->header[k], 64, "%s", fields[k]);
  return 0;
}

int cli_csv_next(cli_csv *c, double *row) {
  char line[1024], *fields[16];
  const int r = csv_fields(c, line, sizeof line, fields);
  if (r != 1) return r;
  for (int k = 0; k < c->ncols; ++k)
    if (c->allow_nonfinite ? parse_any_double(fields[k], &row[k]) : parse_double(fields[k], &row[k])) {
      fprintf(stderr, "hunting: %s:%zu: column '%s': expected a %snumber, got '%s'\n", c->path, c->lineno,
              c->header[k], c->allow_nonfinite ? "" : "finite ", fields[k]);
      return -1;
    }
  return 1;
}

void cli_csv_close(cli_csv *c) {
  if (c->f) fclose(c->f);
  c->f = NULL;
}

int cli_read_csv(const char *path, int ncols, char header[][64], double **data, size_t *n, int allow_nonfinite) {
  cli_csv c;
  if (cli_csv_open(&c, path, ncols, allow_nonfinite)) return 1;
  size_t rows = 0, cap = 0;
  double *d = NULL;
  int r;
  for (;;) {
    if (rows == cap) {
      cap = cap ? 2 * cap : 256;
      double *bigger = realloc(d, cap * (size_t)ncols * sizeof(double));
      if (!bigger) {
        fprintf(stderr, "hunting: %s: out of memory\n", path);
        r = -1;
        break;
      }
      d = bigger;
    }
    if ((r = cli_csv_next(&c, &d[rows * (size_t)ncols])) != 1) break;
    ++rows;
  }
  cli_csv_close(&c);
  if (r != 0) {
    free(d);
    return 1;
  }
  for (int k = 0; k < ncols; ++k) memcpy(header[k], c.header[k], 64);
  *data = d;
  *n = rows;
  return 0;
}

int cli_read_mm_columns(const char *command, const char *path, const char *first, const char *second, double **m_data,
                        size_t *n) {
  char header[2][64];
  double *d = NULL;
  size_t rows = 0;
  if (cli_read_csv(path, 2, header, &d, &rows, 0)) return 1;
  if (strcmp(header[0], first) != 0 || strcmp(header[1], second) != 0) {
    fprintf(stderr, "hunting %s: %s: the header must be '%s,%s' (got '%s,%s')\n", command, path, first, second,
            header[0], header[1]);
    free(d);
    return 1;
  }
  double *m = malloc((2 * rows + 1) * sizeof *m);
  if (!m) { /* (as cli_read_csv: cli.c is linked alone into the CSV fuzz harness) */
    fprintf(stderr, "hunting %s: %s: out of memory\n", command, path);
    free(d);
    return 1;
  }
  for (size_t i = 0; i < rows; ++i) {
    m[i] = 1e-3 * d[2 * i];
    m[rows + i] = 1e-3 * d[2 * i + 1];
  }
  free(d);
  *m_data = m;
  *n = rows;
  return 0;
}

void jw_numbers(json_writer *w, const char *key, const double *x, size_t n) {
  jw_array(w, key);
  for (size_t i = 0; i < n; ++i) jw_number(w, NULL, x[i]);
  jw_end_array(w);
}

void jw_eigenvalues(json_writer *w, const char *key, const double re[4], const double im[4]) {
  jw_array(w, key);
  for (int i = 0; i < 4; ++i) {
    const double pair[2] = {re[i], im[i]};
    jw_numbers(w, NULL, pair, 2);
  }
  jw_end_array(w);
}
