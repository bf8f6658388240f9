/* Which estimates count and the interval they give (evidence.h, private; the rules in alarm.h), each rule against
 * the number it must give: the prior alone without an estimate; a precise estimate alone; an uncertain one combined
 * with the prior (the lower of the two lower ends, the lower upper end); a mismatch held for HM_ALARM_FLAG_CLEAR_S
 * after it clears, then the model's interval again; an estimate used alone again only after its condition held
 * HM_ALARM_FLAG_CLEAR_S; a frame sensor's interval from the model-free one alone. */
#include <math.h>
#include <string.h>

#include "evidence.h"
#include "hm_test.h"

static hm_evidence_config config(int axle) {
  const hm_evidence_config c = {1, 0.01, 0.15, 0.12, 470.0, 560.0, 500.0, axle};
  return c;
}

/* A precise estimate inside the prior: 0.15 +- 0.002, Hopf 498 [490, 506]. */
static hm_margin_estimate estimate(void) {
  hm_margin_estimate g;
  memset(&g, 0, sizeof g);
  g.conicity_valid = g.hopf_model_valid = 1;
  g.conicity = 0.15, g.conicity_se = 0.002, g.conicity_low = 0.148, g.conicity_high = 0.152;
  g.hopf_model_kmh = 498.0, g.hopf_model_low_kmh = 490.0, g.hopf_model_high_kmh = 506.0;
  return g;
}

static hm_evidence fresh(void) {
  hm_evidence ev;
  memset(&ev, 0, sizeof ev);
  hm_evidence_restart(&ev);
  return ev;
}

static void the_rules(void) {
  const hm_evidence_config c = config(1);
  hm_evidence ev = fresh();
  hm_evidence_interval iv;
  hm_evidence_weigh(&ev, &c, NULL, 0.0, &iv);
  HM_CHECK(!iv.precise && !iv.usable && iv.from_prior && iv.low_kmh == 470.0 && iv.high_kmh == 560.0 &&
               iv.conicity == 0.15 && iv.conicity_opt == 0.12,
           "no estimate: the prior's [470, 560] at 0.15");
  hm_margin_estimate g = estimate();
  hm_evidence_weigh(&ev, &c, &g, 1.0, &iv);
  HM_CHECK(iv.precise && iv.low_kmh == 490.0 && iv.high_kmh == 506.0 && iv.conicity_se == 0.002,
           "precise: the model's [490, 506]");
  ev.precise = iv.precise;
  /* too uncertain to be alone (se 0.02 > 1.25 x 0.01): combined with the prior */
  g.conicity_se = 0.02, g.hopf_model_low_kmh = 450.0, g.hopf_model_high_kmh = 540.0, g.near_evidence = 1;
  hm_evidence_weigh(&ev, &c, &g, 2.0, &iv);
  HM_CHECK(!iv.precise && iv.usable && iv.low_kmh == 450.0 && iv.high_kmh == 540.0 && !iv.from_prior &&
               iv.conicity == 0.15 && iv.conicity_opt == 0.148,
           "combined: [min(470, 450), min(560, 540)] = [450, 540]");
  ev.precise = iv.precise;
  /* precise again at once: not before its condition held HM_ALARM_FLAG_CLEAR_S */
  g = estimate();
  hm_evidence_weigh(&ev, &c, &g, 3.0, &iv);
  const int waited = !iv.precise;
  hm_evidence_weigh(&ev, &c, &g, 3.0 + HM_ALARM_FLAG_CLEAR_S, &iv);
  HM_CHECK(waited && iv.precise, "regained only after %g s", HM_ALARM_FLAG_CLEAR_S);
  ev.precise = iv.precise;
  /* a mismatch: the model's interval does not count, held until false for HM_ALARM_FLAG_CLEAR_S */
  g.model_mismatch = 1;
  hm_evidence_weigh(&ev, &c, &g, 30.0, &iv);
  HM_CHECK(iv.mismatch && !iv.precise && !iv.usable && iv.low_kmh == 470.0, "mismatch: the prior");
  g.model_mismatch = 0;
  hm_evidence_weigh(&ev, &c, &g, 31.0, &iv);
  const int held = iv.mismatch;
  hm_evidence_weigh(&ev, &c, &g, 31.0 + HM_ALARM_FLAG_CLEAR_S, &iv);
  HM_CHECK(held && !iv.mismatch, "the mismatch held %g s after it cleared", HM_ALARM_FLAG_CLEAR_S);
}

/* Off the axle box the model-free interval alone sets both ends where it is the narrower. */
static void frame_sensor_model_free(void) {
  const hm_evidence_config c = config(0);
  hm_evidence ev = fresh();
  hm_margin_estimate g = estimate();
  g.hopf_free_valid = 1, g.hopf_free_low_kmh = 480.0, g.hopf_free_high_kmh = 530.0;
  hm_evidence_interval iv;
  hm_evidence_weigh(&ev, &c, &g, 0.0, &iv);
  HM_CHECK(!iv.usable && iv.free_alone && iv.free_counts && iv.low_kmh == 470.0 && iv.high_kmh == 530.0,
           "frame: [min(470, 480), min(560, 530)] = [470, 530]");
  /* the last valid model-free interval is kept when the next is not valid */
  g.hopf_free_valid = 0;
  hm_evidence_weigh(&ev, &c, &g, 1.0, &iv);
  HM_CHECK(iv.free_counts == 0 && ev.free_low_kmh == 480.0 && ev.free_high_kmh == 530.0, "kept: [480, 530]");
}

int main(void) {
  HM_RUN(the_rules);
  HM_RUN(frame_sensor_model_free);
  HM_TEST_EXIT();
}
