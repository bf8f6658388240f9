/* What the monitor has learned as a versioned binary record, and back (see state.h). */
#include "hunting_monitor/state.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "validate.h"

static const unsigned char magic[8] = {'H', 'M', 'S', 'T', 'A', 'T', 'E', '\0'};
enum { HEADER_BYTES = 40, FIXED_BYTES = 136, WINDOW_BYTES = 72, MISFIT_BYTES = 8 };

void hm_state_config_default(hm_state_config *cfg) {
  if (cfg) cfg->period_s = 2.0;
}

hm_status hm_state_config_validate(const hm_state_config *cfg, char *why, size_t len) {
  if (!cfg) return HM_EINVAL;
  const hm_field_check f[] = {{"state.period_s", cfg->period_s, HM_RULE_RANGE, 0.1, 3600.0}};
  return hm_check_fields(f, HM_COUNT_OF(f), why, len);
}

/* ---- little-endian fields ---- */

typedef struct {
  unsigned char *p;
  size_t at;
} writer;

static void put_u64(writer *w, uint64_t x) {
  for (int k = 0; k < 8; ++k) w->p[w->at++] = (unsigned char)(x >> (8 * k));
}
static void put_u32(writer *w, uint32_t x) {
  for (int k = 0; k < 4; ++k) w->p[w->at++] = (unsigned char)(x >> (8 * k));
}
static void put_f64(writer *w, double x) {
  uint64_t u;
  memcpy(&u, &x, sizeof u);
  put_u64(w, u);
}

typedef struct {
  const unsigned char *p;
  size_t at, len;
  int short_read; /* a field ran past the end */
} reader;

static uint64_t get_le(reader *r, int bytes) {
  uint64_t x = 0;
  if (r->at + (size_t)bytes > r->len) {
    r->short_read = 1;
    return 0;
  }
  for (int k = 0; k < bytes; ++k) x |= (uint64_t)r->p[r->at++] << (8 * k);
  return x;
}
static uint32_t get_u32(reader *r) { return (uint32_t)get_le(r, 4); }
static uint64_t get_u64(reader *r) { return get_le(r, 8); }
static double get_f64(reader *r) {
  const uint64_t u = get_le(r, 8);
  double x;
  memcpy(&x, &u, sizeof x);
  return x;
}

/* ---- the hash and the checksum ---- */

static uint64_t fnv_u64(uint64_t h, uint64_t x) {
  for (int k = 0; k < 8; ++k) {
    h ^= (x >> (8 * k)) & 0xffu;
    h *= 0x100000001b3ull;
  }
  return h;
}
static uint64_t fnv_f64(uint64_t h, double x) {
  uint64_t u;
  memcpy(&u, &x, sizeof u);
  return fnv_u64(h, u);
}

uint64_t hm_state_hash(const hm_monitor_config *cfg, const hm_vehicle *veh) {
  if (!cfg || !veh) return 0;
  uint64_t h = 0xcbf29ce484222325ull; /* FNV-1a's offset basis */
  h = fnv_u64(h, HM_STATE_VERSION);
  /* every field of hm_vehicle, hm_modal_config and hm_margin_config: one added there must be added here */
  const double v[] = {veh->mass_kg, veh->yaw_inertia_kg_m2, veh->contact_half_distance_m,
                      veh->spring_half_distance_m, veh->rolling_radius_m, veh->creep_long_n, veh->creep_lat_n,
                      veh->spring_ratio, veh->stiffness_long_n_m, veh->stiffness_lat_n_m, veh->conicity.constant,
                      veh->flange_alpha1_n_m3, veh->flange_alpha2_n_m5};
  for (size_t k = 0; k < sizeof v / sizeof v[0]; ++k) h = fnv_f64(h, v[k]);
  const size_t n_terms = veh->conicity.n_terms < HM_CONICITY_MAX_TERMS ? veh->conicity.n_terms : HM_CONICITY_MAX_TERMS;
  h = fnv_u64(h, n_terms);
  for (size_t k = 0; k < n_terms; ++k) {
    h = fnv_f64(h, veh->conicity.terms[k].amplitude);
    h = fnv_f64(h, veh->conicity.terms[k].center_m);
    h = fnv_f64(h, veh->conicity.terms[k].width_m);
  }
  const hm_modal_config *md = &cfg->modal;
  const double mv[] = {md->window_s, md->min_window_s, md->decimated_rate_hz, md->band_low_hz, md->band_high_hz,
                       md->fit_interval_s, md->tol, md->line_candidate_ratio, md->line_min_fundamental_hz};
  for (size_t k = 0; k < sizeof mv / sizeof mv[0]; ++k) h = fnv_f64(h, mv[k]);
  h = fnv_u64(h, md->max_iter);
  h = fnv_u64(h, (uint64_t)(int64_t)md->reject_lines);
  h = fnv_u64(h, md->line_min_harmonics);
  if (md->min_peak_prominence != 0.0) h = fnv_f64(h, md->min_peak_prominence); /* (off: the hash of before) */
  const hm_margin_config *g = &cfg->margin;
  const double gv[] = {g->frequency_model_error, g->decay_rate_model_error, g->max_speed_spread_kmh,
                       g->min_speed_kmh, g->memory_s, g->min_speed_span_kmh, g->max_extrapolation_kmh,
                       g->interval_z, g->max_misfit_chi2, g->change_z};
  for (size_t k = 0; k < sizeof gv / sizeof gv[0]; ++k) h = fnv_f64(h, gv[k]);
  if (g->spectrum_high_hz != 0.0) { /* (off: the hash of before) */
    h = fnv_f64(h, g->spectrum_low_hz);
    h = fnv_f64(h, g->spectrum_high_hz);
    h = fnv_f64(h, g->spectrum_model_error);
    h = fnv_f64(h, g->spectrum_max_shape_chi2);
    h = fnv_u64(h, (uint64_t)(int64_t)g->spectrum_conicity);
  }
  return h;
}

uint32_t hm_state_checksum(const unsigned char *b, size_t n) {
  uint32_t c = 0xffffffffu;
  for (size_t i = 0; b && i < n; ++i) {
    c ^= b[i];
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
  }
  return ~c;
}

/* ---- writing ---- */

static uint64_t monitor_hash(const hm_monitor m) {
  hm_monitor_config cfg;
  hm_vehicle veh;
  hm_monitor_settings(m, &cfg);
  hm_monitor_vehicle(m, &veh);
  uint64_t h = hm_state_hash(&cfg, &veh);
  const hm_model_kind kind = hm_monitor_model_kind(m);
  if (kind != HM_MODEL_WHEELSET) { /* a bogie's or car's state is theirs alone (the wheelset's hash as before) */
    hm_car p;
    hm_monitor_model_params(m, &p);
    const hm_bogie *b = &p.bogie;
    const double v[] = {b->frame_mass_kg, b->frame_yaw_inertia_kg_m2, b->half_wheelbase_m,
                        b->secondary_lat_stiffness_n_m, b->secondary_lat_damping_n_s_m, b->airspring_long_stiffness_n_m,
                        b->airspring_half_distance_m, b->yaw_damper_damping_n_s_m, b->yaw_damper_stiffness_n_m,
                        b->yaw_damper_half_distance_m, p.carbody_mass_kg, p.carbody_yaw_inertia_kg_m2,
                        p.half_bogie_distance_m, p.carbody_roll_inertia_kg_m2, p.carbody_cg_height_m,
                        p.secondary_roll_stiffness_n_m_rad, p.secondary_roll_damping_n_m_s_rad};
    h = fnv_u64(h, (uint64_t)kind);
    h = fnv_u64(h, (uint64_t)cfg.estimator.measurement_point); /* (the model's sensor: what its windows read) */
    /* the bogie's 10, the car's 13, with roll all 17 (a car without roll hashes as before roll existed) */
    const size_t n = kind != HM_MODEL_CAR ? 10 : p.carbody_roll_inertia_kg_m2 > 0.0 ? sizeof v / sizeof v[0] : 13;
    for (size_t k = 0; k < n; ++k) h = fnv_f64(h, v[k]);
  }
  return h;
}

hm_status hm_state_save(const hm_monitor m, double now_s, double written_unix_s, unsigned char *buf, size_t cap,
                        size_t *len) {
  if (!m || !buf || !len || !isfinite(now_s) || !isfinite(written_unix_s)) return HM_EINVAL;
  hm_monitor_snapshot s;
  hm_monitor_take_snapshot(m, now_s, &s);
  const hm_margin_snapshot *g = &s.margin;
  const hm_alarm_snapshot *a = &s.alarm;
  const size_t total = FIXED_BYTES + WINDOW_BYTES * (size_t)g->n_windows + MISFIT_BYTES * (size_t)g->n_misfits;
  if (cap < total) return HM_EINVAL;
  writer w = {buf, 0};
  memcpy(buf, magic, sizeof magic);
  w.at = sizeof magic;
  put_u32(&w, HM_STATE_VERSION);
  put_u32(&w, (uint32_t)total);
  put_u64(&w, monitor_hash(m));
  put_f64(&w, written_unix_s);
  put_f64(&w, now_s);
  put_u32(&w, g->n_windows);
  for (unsigned k = 0; k < g->n_windows; ++k) {
    const hm_margin_window *o = &g->windows[k];
    const double f[] = {o->age_s,    o->speed_kmh,   o->window_s,      o->sigma_1_s,    o->sigma_stat_1_s,
                        o->conicity, o->conicity_se, o->conicity_stat, o->conicity_sys};
    for (size_t j = 0; j < sizeof f / sizeof f[0]; ++j) put_f64(&w, f[j]);
  }
  put_u32(&w, g->n_misfits);
  for (unsigned k = 0; k < g->n_misfits; ++k) put_f64(&w, g->misfit_age_s[k]);
  put_u64(&w, g->n_changes);
  put_f64(&w, g->last_change_age_s);
  put_u32(&w, g->windows_since_change);
  put_u32(&w, (uint32_t)g->narrow);
  put_f64(&w, g->narrow_peak_hz);
  put_f64(&w, g->narrow_age_s);
  put_f64(&w, g->ambiguous_age_s);
  put_u32(&w, (uint32_t)a->latched);
  put_u32(&w, (uint32_t)a->latch_reason);
  put_f64(&w, a->hunted_at_kmh);
  put_f64(&w, a->hunted_age_s);
  put_u32(&w, (uint32_t)s.interval.precise);
  put_u32(&w, (uint32_t)s.interval.se_ok);
  put_u32(&w, (uint32_t)s.interval.precise_lost);
  put_u32(&w, hm_state_checksum(buf, w.at));
  *len = w.at;
  return HM_OK;
}

/* ---- reading ---- */

/* Version 1's payload (after the header) into *s; 0 if its layout does not fill exactly len bytes. */
static int read_payload(reader *r, hm_monitor_snapshot *s) {
  memset(s, 0, sizeof *s);
  hm_margin_snapshot *g = &s->margin;
  hm_alarm_snapshot *a = &s->alarm;
  const uint32_t n_windows = get_u32(r);
  if (n_windows > HM_MARGIN_MAX_WINDOWS) return 0;
  g->n_windows = n_windows;
  for (unsigned k = 0; k < n_windows; ++k) {
    hm_margin_window *o = &g->windows[k];
    double *f[] = {&o->age_s,    &o->speed_kmh,   &o->window_s,      &o->sigma_1_s,   &o->sigma_stat_1_s,
                   &o->conicity, &o->conicity_se, &o->conicity_stat, &o->conicity_sys};
    for (size_t j = 0; j < sizeof f / sizeof f[0]; ++j) *f[j] = get_f64(r);
  }
  const uint32_t n_misfits = get_u32(r);
  if (n_misfits > HM_MARGIN_MAX_WINDOWS) return 0;
  g->n_misfits = n_misfits;
  for (unsigned k = 0; k < n_misfits; ++k) g->misfit_age_s[k] = get_f64(r);
  const uint64_t n_changes = get_u64(r);
  g->n_changes = (unsigned long)n_changes;
  g->last_change_age_s = get_f64(r);
  g->windows_since_change = get_u32(r);
  /* an enumeration or flag out of range is kept out of range (validated by the margin, the alarm and the interval) */
  const uint32_t narrow = get_u32(r);
  g->narrow = (hm_narrow_verdict)(narrow <= HM_NARROW_AMBIGUOUS ? narrow : HM_NARROW_AMBIGUOUS + 1);
  g->narrow_peak_hz = get_f64(r);
  g->narrow_age_s = get_f64(r);
  g->ambiguous_age_s = get_f64(r);
  const uint32_t latched = get_u32(r), reason = get_u32(r);
  a->latched = latched <= 1 ? (int)latched : 2;
  a->latch_reason = (hm_reason)(reason <= 255 ? reason : 255);
  a->hunted_at_kmh = get_f64(r);
  a->hunted_age_s = get_f64(r);
  const uint32_t precise = get_u32(r);
  hm_interval_snapshot *iv = &s->interval;
  iv->precise = precise <= 1 ? (int)precise : 2;
  const uint32_t se_ok = get_u32(r), lost = get_u32(r);
  iv->se_ok = se_ok <= 1 ? (int)se_ok : 2;
  iv->precise_lost = lost <= 1 ? (int)lost : 2;
  if (n_changes != (uint64_t)g->n_changes) return 0;
  return !r->short_read && r->at + 4 == r->len; /* the checksum follows */
}

/* The outcome of a refusal: the verdict and "not restored: " with the reason; st returned. */
static hm_status refuse(hm_state_outcome *o, hm_state_verdict v, hm_status st, const char *fmt, ...) {
  if (o) {
    char reason[HM_STATE_TEXT_MAX - 16];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(reason, sizeof reason, fmt, ap);
    va_end(ap);
    o->verdict = v;
    snprintf(o->text, sizeof o->text, "not restored: %s", reason);
  }
  return st;
}

/* "restored, age 42 s, 3 windows", the held ALARM and the hunted-at speed. */
static void describe(hm_state_outcome *o, const hm_monitor_snapshot *s) {
  int n = snprintf(o->text, sizeof o->text, "restored, age %.0f s, %u window%s", o->age_s, o->n_windows,
                   o->n_windows == 1 ? "" : "s");
  if (n > 0 && (size_t)n < sizeof o->text && s->alarm.latched)
    n += snprintf(o->text + n, sizeof o->text - (size_t)n, "; ALARM held: %s", hm_reason_text(s->alarm.latch_reason));
  if (n > 0 && (size_t)n < sizeof o->text && s->alarm.hunted_at_kmh < INFINITY)
    snprintf(o->text + n, sizeof o->text - (size_t)n, "; hunted at %.1f km/h", s->alarm.hunted_at_kmh);
}

hm_status hm_state_restore(hm_monitor m, const unsigned char *b, size_t len, double now_s, double now_unix_s,
                           hm_state_clock clock, hm_state_outcome *o) {
  if (o) {
    memset(o, 0, sizeof *o);
    o->age_s = NAN;
  }
  const double now_clock = clock == HM_STATE_CLOCK_LINE ? now_s : now_unix_s;
  if (!m || (!b && len) || !isfinite(now_s) || !isfinite(now_clock) ||
      (clock != HM_STATE_CLOCK_WALL && clock != HM_STATE_CLOCK_LINE))
    return refuse(o, HM_STATE_BAD_CONTENT, HM_EINVAL, "invalid arguments");
  if (len && memcmp(b, magic, len < sizeof magic ? len : sizeof magic) != 0)
    return refuse(o, HM_STATE_NOT_A_STATE, HM_EPARSE, "not a hunting_monitor state (no HMSTATE magic)");
  reader r = {b, sizeof magic, len, 0};
  const uint32_t version = get_u32(&r), declared = get_u32(&r);
  if (len < 16) return refuse(o, HM_STATE_TRUNCATED, HM_EPARSE, "truncated: %zu bytes, not even a header", len);
  if (declared > len) return refuse(o, HM_STATE_TRUNCATED, HM_EPARSE, "truncated: %zu of %u bytes", len, declared);
  if (declared < len)
    return refuse(o, HM_STATE_CORRUPT, HM_EPARSE, "corrupt: %zu bytes where the record declares %u", len, declared);
  if (declared < 20) /* not even a header and a checksum: its length field is damaged */
    return refuse(o, HM_STATE_CORRUPT, HM_EPARSE, "corrupt: a declared length of %u bytes", declared);
  reader tail = {b, len - 4, len, 0};
  if (get_u32(&tail) != hm_state_checksum(b, len - 4))
    return refuse(o, HM_STATE_CORRUPT, HM_EPARSE, "corrupt: the checksum does not match");
  if (version != HM_STATE_VERSION)
    return refuse(o, HM_STATE_VERSION_UNKNOWN, HM_EPARSE, "format version %u %s (this reader knows %u)", version,
                  version > HM_STATE_VERSION ? "is newer" : "is unknown", HM_STATE_VERSION);
  if (len < FIXED_BYTES)
    return refuse(o, HM_STATE_BAD_CONTENT, HM_EPARSE, "bad content: %zu bytes, version 1 has at least %d", len,
                  (int)FIXED_BYTES);
  const uint64_t hash = get_u64(&r), ours = monitor_hash(m);
  if (hash != ours)
    return refuse(o, HM_STATE_FOREIGN, HM_EDOMAIN,
                  "written for another vehicle or other settings (hash %016llx, this monitor's %016llx)",
                  (unsigned long long)hash, (unsigned long long)ours);
  const double written_unix_s = get_f64(&r), written_line_s = get_f64(&r);
  if (!isfinite(written_unix_s) || !isfinite(written_line_s))
    return refuse(o, HM_STATE_BAD_CONTENT, HM_EPARSE, "bad content: a time of writing not finite");
  const double age = now_clock - (clock == HM_STATE_CLOCK_LINE ? written_line_s : written_unix_s);
  const char *clock_name = clock == HM_STATE_CLOCK_LINE ? "time line" : "wall clock";
  hm_monitor_config cfg;
  hm_monitor_settings(m, &cfg);
  if (age < 0.0)
    return refuse(o, HM_STATE_FROM_FUTURE, HM_EDOMAIN, "written %.3g s after now on the %s (another time line?)",
                  -age, clock_name);
  if (!(age < cfg.margin.memory_s))
    return refuse(o, HM_STATE_TOO_OLD, HM_EDOMAIN, "too old: age %.0f s on the %s, the margin's memory_s %.0f s",
                  age, clock_name, cfg.margin.memory_s);
  hm_monitor_snapshot s;
  if (!read_payload(&r, &s))
    return refuse(o, HM_STATE_BAD_CONTENT, HM_EPARSE, "bad content: the layout is not version 1's (%zu bytes)", len);
  /* the record's age is every kept time's too */
  for (unsigned k = 0; k < s.margin.n_windows; ++k) s.margin.windows[k].age_s += age;
  for (unsigned k = 0; k < s.margin.n_misfits; ++k) s.margin.misfit_age_s[k] += age;
  if (s.margin.n_changes) s.margin.last_change_age_s += age;
  s.margin.narrow_age_s += age;
  s.margin.ambiguous_age_s += age;
  s.alarm.hunted_age_s += age;
  char why[256] = "";
  if (hm_monitor_restore(m, now_s, &s, why, sizeof why) != HM_OK)
    return refuse(o, HM_STATE_BAD_CONTENT, HM_EPARSE, "bad content: %s", why);
  if (o) {
    o->verdict = HM_STATE_RESTORED;
    o->age_s = age;
    o->latched = s.alarm.latched;
    for (unsigned k = 0; k < s.margin.n_windows; ++k) o->n_windows += s.margin.windows[k].age_s <= cfg.margin.memory_s;
    describe(o, &s);
  }
  return HM_OK;
}
