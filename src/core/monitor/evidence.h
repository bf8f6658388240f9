/* Private to the core: the Hopf interval the evidence gives (alarm.h states the rules). Which of the margin's
 * estimates count this update, each flag held against its chatter (a flag raised at once and cleared only after its
 * condition has been false for HM_ALARM_FLAG_CLEAR_S; the estimate used alone again only after its condition held that
 * long), and the interval they and the prior give. The interval module (interval.h) holds one hm_evidence for the
 * flags' memory (saved in its snapshot) and adds the table's boundaries; nothing here looks up a table or decides a
 * level. */
#ifndef HM_CORE_EVIDENCE_H
#define HM_CORE_EVIDENCE_H

#include "hunting_monitor/alarm.h"
#include "hunting_monitor/margin.h"

typedef struct {
  int on;
  double false_since_s; /* NAN: the condition held at the last update */
} hm_sticky_flag;

/* What the weighing remembers from one update to the next. */
typedef struct {
  int precise;          /* the estimate was used alone at the last update with data (set by the caller) */
  int se_ok;            /* its standard error was small enough at the last update with data (its hysteresis) */
  int precise_lost;     /* it stopped being used alone: used again once it could have been since precise_since */
  double precise_since; /* (NAN: it could not be at the last update) */
  hm_sticky_flag mismatch, free_beside; /* model_mismatch, the model-free interval beside the model's (alarm.h) */
  double free_low_kmh, free_high_kmh;   /* the last valid model-free interval */
} hm_evidence;

/* The settings it weighs by: the alarm's, resolved for the vehicle. */
typedef struct {
  int use_conicity_estimate;
  double conicity_max_se;
  double conicity_fallback, conicity_prior_low;     /* the prior's point and its optimistic end */
  double prior_hopf_low_kmh, prior_hopf_high_kmh;   /* the prior's Hopf interval */
  double fallback_hopf_kmh;                         /* the Hopf speed at conicity_fallback */
  int axle; /* the model-based interval can count: an axle-box sensor, or a model that holds the sensor's point */
} hm_evidence_config;

/* The interval of one update. */
typedef struct {
  int mismatch;         /* model_mismatch as the level uses it (held) */
  int precise;          /* the estimate enters alone */
  int usable;           /* the estimate counts, combined with the prior where not precise */
  int free_alone;       /* the model-free interval is the only evidence of where the Hopf speed lies */
  int free_counts;      /* the model-free interval's lower end counts (its last valid one, held) */
  int from_prior;       /* the prior set the interval (the estimate moved neither end) */
  double conicity;      /* the conicity in use */
  double conicity_opt;  /* the interval's optimistic end's */
  double conicity_se;   /* 0 where the prior's is in use */
  double low_kmh, high_kmh; /* before the table's value at the point is added */
} hm_evidence_interval;

/* The flags forgotten (a restart of the time line); the last model-free interval kept. */
void hm_evidence_restart(hm_evidence *ev);
/* Every time of ev moved by delta_s (a shift of the time line). */
void hm_evidence_shift_time(hm_evidence *ev, double delta_s);
/* Weigh g (may be NULL: the prior alone) at now_s into *out, ev's memory updated. */
void hm_evidence_weigh(hm_evidence *ev, const hm_evidence_config *cfg, const hm_margin_estimate *g, double now_s,
                       hm_evidence_interval *out);

#endif
