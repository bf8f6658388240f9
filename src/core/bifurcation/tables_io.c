/* Boundary tables: the text format, written and parsed with plausibility checks (see tables.h). */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tables_internal.h"
#include "textsink.h"

hm_status hm_table_format(const hm_table t, char *buf, size_t len, size_t *needed) {
  if (!t || !needed || (len && !buf)) return HM_EINVAL;
  hm_text_sink s = {buf, len, 0};
  hm_text_sink_printf(&s, "hunting_monitor_boundary_table 1\n");
  hm_text_sink_printf(&s, "# lambda(0) grid, Hopf speed, l1, lowest speed with a cycle; then the cycle family (v_kmh amplitude_m stable)\n");
  hm_text_sink_printf(&s, "kx_mn_m %.10g ky_mn_m %.10g speed_min_kmh %.10g speed_max_kmh %.10g amp_max_m %.10g\n", t->kx_mn_m,
      t->ky_mn_m, t->speed_min_kmh, t->speed_max_kmh, t->amp_max_m);
  hm_text_sink_printf(&s, "error_hopf_kmh %.6g error_lowest_kmh %.6g error_edge_amp_m %.6g\n", t->err_hopf_kmh, t->err_lowest_kmh,
      t->err_amp_m);
  for (size_t i = 0; i < t->n; ++i) {
    const tcurve *c = &t->curves[i];
    hm_text_sink_printf(&s, "conicity %.10g hopf_kmh %.10g l1 %.10g lowest_kmh %.10g n %zu\n", c->conicity, c->hopf_kmh, c->l1,
        c->lowest_kmh, c->n);
    for (size_t k = 0; k < c->n; ++k) hm_text_sink_printf(&s, "%.9g %.7g %d\n", c->pts[k].v_kmh, c->pts[k].amp_m, c->pts[k].stable);
  }
  *needed = s.used + 1;
  return s.used < len ? HM_OK : HM_EINVAL;
}

typedef struct {
  const char *p, *end;
  size_t line;
  char *err;
  size_t err_len;
} reader;

static hm_status perr(reader *r, const char *fmt, ...) {
  if (r->err && r->err_len) {
    int n = snprintf(r->err, r->err_len, "line %zu: ", r->line);
    if (n > 0 && (size_t)n < r->err_len) {
      va_list ap;
      va_start(ap, fmt);
      vsnprintf(r->err + n, r->err_len - (size_t)n, fmt, ap);
      va_end(ap);
    }
  }
  return HM_EPARSE;
}

/* Next non-empty, non-comment line into line[] (NUL-terminated); 0 at the end. */
static int next_line(reader *r, char *line, size_t cap) {
  while (r->p < r->end) {
    const char *nl = memchr(r->p, '\n', (size_t)(r->end - r->p));
    const char *e = nl ? nl : r->end;
    size_t n = (size_t)(e - r->p);
    ++r->line;
    if (n >= cap) n = cap - 1;
    memcpy(line, r->p, n);
    line[n] = '\0';
    r->p = nl ? nl + 1 : r->end;
    const char *q = line;
    while (*q == ' ' || *q == '\t' || *q == '\r') ++q;
    if (*q && *q != '#') return 1;
  }
  return 0;
}

/* The next whitespace-separated token of *s (NUL-terminated in place), or NULL. */
static char *token(char **s) {
  char *p = *s;
  while (*p == ' ' || *p == '\t' || *p == '\r') ++p;
  if (!*p) return NULL;
  char *start = p;
  while (*p && *p != ' ' && *p != '\t' && *p != '\r') ++p;
  if (*p) *p++ = '\0';
  *s = p;
  return start;
}

/* Parse "key value key value ..." with the given keys in order. */
static hm_status keyed(reader *r, char *line, const char *const *keys, double *values, size_t n) {
  char *save = line, *tok = token(&save);
  for (size_t i = 0; i < n; ++i) {
    if (!tok || strcmp(tok, keys[i]) != 0) return perr(r, "expected '%s'", keys[i]);
    char *v = token(&save), *end = NULL;
    if (!v) return perr(r, "'%s' needs a value", keys[i]);
    errno = 0;
    values[i] = strtod(v, &end);
    if (*end || end == v || errno == ERANGE || !isfinite(values[i])) return perr(r, "'%s': bad number '%s'", keys[i], v);
    tok = token(&save);
  }
  if (tok) return perr(r, "unexpected '%s'", tok);
  return HM_OK;
}

static hm_status parse_curve(reader *r, char *line, tcurve *c, double prev_conicity) {
  static const char *const keys[] = {"conicity", "hopf_kmh", "l1", "lowest_kmh", "n"};
  double v[5];
  hm_status st = keyed(r, line, keys, v, 5);
  if (st != HM_OK) return st;
  if (!(v[0] > prev_conicity)) return perr(r, "conicities must increase");
  /* plausibility: a monitor must refuse a table it cannot trust rather than read OK out of it */
  if (!(v[0] > 0.0)) return perr(r, "conicity must be > 0");
  if (!(v[1] > 0.0 && v[1] <= HM_TABLE_MAX_SPEED_KMH)) return perr(r, "hopf_kmh must be in (0, %g]", HM_TABLE_MAX_SPEED_KMH);
  if (!(v[3] > 0.0 && v[3] <= v[1] * (1.0 + 1e-9)))
    return perr(r, "lowest_kmh must be > 0 and not above hopf_kmh (cycles exist from the Hopf speed on)");
  if (!(v[4] >= 1.0 && v[4] <= 1e6) || v[4] != floor(v[4])) return perr(r, "bad point count");
  c->conicity = v[0];
  c->hopf_kmh = v[1];
  c->l1 = v[2];
  c->lowest_kmh = v[3];
  c->n = (size_t)v[4];
  c->pts = malloc(c->n * sizeof *c->pts);
  if (!c->pts) return HM_ENOMEM;
  for (size_t k = 0; k < c->n; ++k) {
    char buf[256], *end = NULL;
    if (!next_line(r, buf, sizeof buf)) return perr(r, "missing cycle points (%zu of %zu)", k, c->n);
    errno = 0;
    const double vk = strtod(buf, &end);
    char *e2 = NULL;
    const double amp = strtod(end, &e2);
    char *e3 = NULL;
    const long stab = strtol(e2, &e3, 10);
    while (*e3 == ' ' || *e3 == '\t' || *e3 == '\r') ++e3;
    if (end == buf || e2 == end || e3 == e2 || *e3 || !isfinite(vk) || !isfinite(amp) || amp < 0.0 ||
        (stab != 0 && stab != 1) || errno == ERANGE)
      return perr(r, "expected 'v_kmh amplitude_m stable(0|1)'");
    if (!(vk >= c->lowest_kmh * (1.0 - 1e-6) && vk <= HM_TABLE_MAX_SPEED_KMH))
      return perr(r, "cycle speed %g km/h below lowest_kmh or above %g", vk, HM_TABLE_MAX_SPEED_KMH);
    if (!(amp <= 0.1)) return perr(r, "cycle amplitude %g m is not plausible (above 0.1 m)", amp);
    c->pts[k] = (tpoint){vk, amp, (int)stab};
  }
  return HM_OK;
}

hm_status hm_table_parse(const char *text, size_t len, hm_table *out, char *err, size_t err_len) {
  if (!text || !out) return HM_EINVAL;
  reader r = {text, text + len, 0, err, err_len};
  char line[512];
  if (!next_line(&r, line, sizeof line) || strcmp(line, "hunting_monitor_boundary_table 1") != 0)
    return perr(&r, "not a hunting_monitor boundary table (version 1)");
  static const char *const k1[] = {"kx_mn_m", "ky_mn_m", "speed_min_kmh", "speed_max_kmh", "amp_max_m"};
  static const char *const k2[] = {"error_hopf_kmh", "error_lowest_kmh", "error_edge_amp_m"};
  double h1[5], h2[3];
  if (!next_line(&r, line, sizeof line)) return perr(&r, "missing header");
  hm_status st = keyed(&r, line, k1, h1, 5);
  if (st != HM_OK) return st;
  if (!next_line(&r, line, sizeof line)) return perr(&r, "missing error line");
  if ((st = keyed(&r, line, k2, h2, 3)) != HM_OK) return st;
  if (!(h1[0] > 0.0 && h1[1] > 0.0)) return perr(&r, "kx_mn_m and ky_mn_m must be > 0");
  if (!(h1[2] > 0.0 && h1[3] > h1[2] && h1[3] <= HM_TABLE_MAX_SPEED_KMH))
    return perr(&r, "speed range must be 0 < speed_min_kmh < speed_max_kmh <= %g", HM_TABLE_MAX_SPEED_KMH);
  if (!(h1[4] > 0.0 && h1[4] <= 0.1)) return perr(&r, "amp_max_m must be in (0, 0.1]");
  if (!(h2[0] >= 0.0 && h2[1] >= 0.0 && h2[2] >= 0.0)) return perr(&r, "stated errors must be >= 0");
  /* count the curves first: every line starting with "conicity" */
  size_t n = 0;
  for (const char *q = r.p; q && q < r.end;) {
    if ((size_t)(r.end - q) >= 9 && strncmp(q, "conicity ", 9) == 0) ++n;
    const char *nl = memchr(q, '\n', (size_t)(r.end - q));
    q = nl ? nl + 1 : NULL;
  }
  if (n < 2) return perr(&r, "at least two conicities are needed");
  hm_table t = hm_table_alloc(n);
  if (!t) return HM_ENOMEM;
  t->kx_mn_m = h1[0], t->ky_mn_m = h1[1], t->speed_min_kmh = h1[2], t->speed_max_kmh = h1[3], t->amp_max_m = h1[4];
  t->err_hopf_kmh = h2[0], t->err_lowest_kmh = h2[1], t->err_amp_m = h2[2];
  double prev = -INFINITY;
  for (size_t i = 0; i < n && st == HM_OK; ++i) {
    if (!next_line(&r, line, sizeof line)) {
      st = perr(&r, "missing conicity record");
      break;
    }
    st = parse_curve(&r, line, &t->curves[i], prev);
    prev = t->curves[i].conicity;
  }
  if (st == HM_OK && next_line(&r, line, sizeof line)) st = perr(&r, "unexpected text after the last record");
  for (size_t i = 1; st == HM_OK && i < n; ++i) { /* 1/V_hopf^2 is affine and increasing in lambda (tables.h) */
    if (!(t->curves[i].hopf_kmh < t->curves[i - 1].hopf_kmh))
      st = perr(&r, "hopf_kmh must decrease as the conicity increases (conicity %g)", t->curves[i].conicity);
    /* the stated errors were measured on the grid's widest step (a refined table's is wider than its others) */
    t->err_step = fmax(t->err_step, t->curves[i].conicity - t->curves[i - 1].conicity);
  }
  hm_table_spec spec;
  hm_table_spec_default(&spec);
  t->rtol = spec.rtol;
  if (st != HM_OK) {
    hm_table_destroy(t);
    return st;
  }
  *out = t;
  return HM_OK;
}

hm_status hm_table_load_file(const char *path, hm_table *out, char *err, size_t err_len) {
  if (!path || !out) return HM_EINVAL;
  FILE *f = fopen(path, "rb");
  if (!f) {
    if (err && err_len) snprintf(err, err_len, "%s: cannot open: %s", path, strerror(errno));
    return HM_EIO;
  }
  size_t cap = 1 << 16, n = 0;
  char *buf = malloc(cap);
  while (buf) {
    n += fread(buf + n, 1, cap - n, f);
    if (n < cap || cap >= ((size_t)64 << 20)) break;
    char *bigger = realloc(buf, cap * 2);
    if (!bigger) {
      free(buf);
      buf = NULL;
      break;
    }
    buf = bigger;
    cap *= 2;
  }
  const int bad = ferror(f);
  fclose(f);
  if (!buf) return HM_ENOMEM;
  hm_status st = bad ? HM_EIO : hm_table_parse(buf, n, out, err, err_len);
  if (bad && err && err_len) snprintf(err, err_len, "%s: read error", path);
  free(buf);
  return st;
}
