#include "monitor_ros.h"

#include <hunting_monitor/HuntingAlarm.h>
#include <std_msgs/UInt8.h>
#include <visualization_msgs/MarkerArray.h>

#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "yaml_params.h"

extern "C" {
#include "hunting_monitor/config.h"
#include "hunting_monitor/linear.h"
#include "hunting_monitor/report.h"
#include "hunting_monitor/threads.h"
}

namespace hunting_monitor {

namespace {
// The inputs diagnostic warns when more than this fraction of the samples was lost over the last 10 s.
constexpr double kLossWarnFraction = 0.01;
// A NaN never goes out: unknown quantities are 0 with their *_valid flag false.
double finite(double x) { return std::isfinite(x) ? x : 0.0; }
// The status's reason in words (the core's: while held, its cause, ages and the release condition).
std::string reasonText(const hm_assessment& s) {
  char text[512];
  hm_assessment_reason_text(&s, NAN, text, sizeof text);  // times as ages: the sensor's line is no clock to read
  return text;
}

// The state file's default: $ROS_HOME (or ~/.ros)/hunting_monitor_state/<the node's namespace, '/' as '.'>, the
// directories made if missing (each monitor its own file: a node and a nodelet on one machine do not share one).
std::string defaultStateFile(const std::string& ns) {
  const char* ros_home = std::getenv("ROS_HOME");
  const char* home = std::getenv("HOME");
  const std::string dir = ros_home && *ros_home ? ros_home : std::string(home && *home ? home : ".") + "/.ros";
  std::string name = ns.substr(ns.find_first_not_of('/') == std::string::npos ? ns.size() : ns.find_first_not_of('/'));
  for (char& ch : name)
    if (ch == '/') ch = '.';
  ::mkdir(dir.c_str(), 0755);
  ::mkdir((dir + "/hunting_monitor_state").c_str(), 0755);
  return dir + "/hunting_monitor_state/" + (name.empty() ? "hunting_monitor" : name);
}
}  // namespace

// The diagnostics are named after the private namespace: the node's name, or the nodelet's (not its manager's).
MonitorRos::MonitorRos(ros::NodeHandle nh, ros::NodeHandle pnh)
    : nh_(nh), pnh_(pnh), updater_(nh, pnh, pnh.getNamespace()) {
  if (!loadParameters()) return;
  if (accel_type_ == "imu")
    accel_sub_ = nh_.subscribe("accel", 4000, &MonitorRos::onAccelImu, this, ros::TransportHints().tcpNoDelay());
  else
    accel_sub_ = nh_.subscribe("accel", 4000, &MonitorRos::onAccelFloat, this, ros::TransportHints().tcpNoDelay());
  speed_sub_ = nh_.subscribe("speed", 100, &MonitorRos::onSpeed, this);
  status_pub_ = nh_.advertise<hunting_monitor::HuntingStatus>("hunting_status", 50);
  alarm_pub_ = nh_.advertise<std_msgs::UInt8>("hunting_alarm", 1, true);
  alarm_stamped_pub_ = nh_.advertise<hunting_monitor::HuntingAlarm>("hunting_alarm_stamped", 1, true);
  marker_pub_ = nh_.advertise<visualization_msgs::MarkerArray>("hunting_markers", 5);
  chart_pub_ = nh_.advertise<visualization_msgs::MarkerArray>("hunting_chart", 5);
  chart_.reset(new StabilityChart(frame_id_));
  updater_.setHardwareID("hunting_monitor");
  accel_min_hz_ = 0.9 * cfg_.estimator.sample_rate_hz;
  accel_max_hz_ = 1.1 * cfg_.estimator.sample_rate_hz;
  accel_freq_.reset(new diagnostic_updater::FrequencyStatus(
      diagnostic_updater::FrequencyStatusParam(&accel_min_hz_, &accel_max_hz_, 0.0, 5)));
  updater_.add(*accel_freq_);
  updater_.add("inputs", this, &MonitorRos::diagnoseInputs);
  updater_.add("hunting level", this, &MonitorRos::diagnoseLevel);
  updater_.add("boundary table", this, &MonitorRos::diagnoseTable);
  updater_.add("settings", this, &MonitorRos::diagnoseSettings);
  updater_.add("state file", this, &MonitorRos::diagnoseState);
  if (allow_reconfigure_) {
    reconfigure_.reset(new SettingsReconfigure(pnh_, monitor_));
    ROS_WARN("hunting_monitor: ~allow_reconfigure: the alarm and criteria settings can be changed through "
             "dynamic_reconfigure (%s/set_parameters)", pnh_.getNamespace().c_str());
  }
  timer_ = nh_.createTimer(ros::Duration(1.0 / status_rate_hz_), &MonitorRos::onTimer, this);
  ok_ = true;
  ROS_INFO("hunting_monitor: ready (accel %s at %.0f Hz stamped by %s time, speed in %s, status at %.1f Hz, table %s)",
           accel_type_.c_str(), cfg_.estimator.sample_rate_hz, time_source_.c_str(), speed_unit_.c_str(), status_rate_hz_,
           table_file_.c_str());
  if (state_file_.empty())
    ROS_INFO("hunting_monitor: ~state_file empty: what the monitor learns is not kept through a restart");
  else
    ROS_INFO("hunting_monitor: state file %s (restored with the first sample, written every %.1f s and at shutdown)",
             state_file_.c_str(), state_period_s_);
}

MonitorRos::~MonitorRos() {
  // No callback may touch the monitor once it is freed: as a nodelet this object is destroyed while the manager
  // runs on; shutting down waits for a callback in progress.
  timer_.stop();
  accel_sub_.shutdown();
  speed_sub_.shutdown();
  reconfigure_.reset();
  refiner_.reset();  // joins the worker, which may be reading the monitor's table
  if (monitor_ && !state_file_.empty() && !state_restore_pending_ && have_update_) {
    saveState(last_line_s_, last_wall_s_);  // at shutdown: what the last update knew
    ROS_INFO_COND(state_write_error_.empty(), "hunting_monitor: state written to %s", state_file_.c_str());
  }
  hm_monitor_destroy(monitor_);
}

bool MonitorRos::loadParameters() {
  char err[512] = "";
  // vehicle, estimator and alarm sections go through the core's own YAML parsers
  std::string error;
  if (!loadVehicleModelParams(pnh_, &kind_, &model_params_, &error)) {
    ROS_FATAL("hunting_monitor: %s", error.c_str());
    return false;
  }
  vehicle_ = model_params_.bogie.wheelset;
  hm_monitor_config_default(&cfg_);
  const std::string monitor_yaml = sectionsAsYaml(pnh_, {"estimator", "modal", "margin", "track_lines", "alarm", "table"});
  if (hm_config_parse_monitor(monitor_yaml.c_str(), monitor_yaml.size(), "~ (monitor parameters)", &cfg_, err,
                              sizeof err) != HM_OK) {
    ROS_FATAL("hunting_monitor: %s", err);
    return false;
  }
  return loadTopicParameters() && loadStateAndClockParameters() && createMonitor();
}

// The inputs' and outputs' parameters (message types, axis, time source, units, rate), checked.
bool MonitorRos::loadTopicParameters() {
  pnh_.param<std::string>("accel_type", accel_type_, "imu");
  pnh_.param<std::string>("imu_axis", imu_axis_, "y");
  pnh_.param<std::string>("time_source", time_source_, "header");
  pnh_.param<std::string>("speed_unit", speed_unit_, "kmh");
  pnh_.param<std::string>("frame_id", frame_id_, "base_link");
  pnh_.param<std::string>("table_file", table_file_, "");
  pnh_.param("status_rate_hz", status_rate_hz_, 20.0);
  pnh_.param("bench_table_churn", bench_table_churn_, false);
  pnh_.param("allow_reconfigure", allow_reconfigure_, false);
  if (accel_type_ != "imu" && accel_type_ != "float64") {
    ROS_FATAL("hunting_monitor: ~accel_type must be imu or float64, got '%s'", accel_type_.c_str());
    return false;
  }
  if (time_source_ != "header" && time_source_ != "receipt") {
    ROS_FATAL("hunting_monitor: ~time_source must be header or receipt, got '%s'", time_source_.c_str());
    return false;
  }
  if (accel_type_ == "float64" && time_source_ == "header") time_source_ = "receipt";  // a Float64 has no header
  header_time_ = time_source_ == "header";
  axis_ = imu_axis_ == "x" ? 0 : imu_axis_ == "y" ? 1 : imu_axis_ == "z" ? 2 : -1;
  if (axis_ < 0) {
    ROS_FATAL("hunting_monitor: ~imu_axis must be x, y or z, got '%s'", imu_axis_.c_str());
    return false;
  }
  if (speed_unit_ != "kmh" && speed_unit_ != "mps") {
    ROS_FATAL("hunting_monitor: ~speed_unit must be kmh or mps, got '%s'", speed_unit_.c_str());
    return false;
  }
  if (!(status_rate_hz_ > 0.0 && status_rate_hz_ <= 1000.0)) {
    ROS_FATAL("hunting_monitor: ~status_rate_hz must be in (0, 1000], got %g", status_rate_hz_);
    return false;
  }
  return true;
}

// The state file's and the sensor clock's parameters, validated by the core.
bool MonitorRos::loadStateAndClockParameters() {
  char err[512] = "";
  hm_state_config state_cfg;
  hm_state_config_default(&state_cfg);
  pnh_.param("state_period_s", state_cfg.period_s, state_cfg.period_s);
  if (hm_state_config_validate(&state_cfg, err, sizeof err) != HM_OK) {
    ROS_FATAL("hunting_monitor: ~state_period_s: %s", err);
    return false;
  }
  state_period_s_ = state_cfg.period_s;
  if (!pnh_.getParam("state_file", state_file_)) state_file_ = defaultStateFile(pnh_.getNamespace());
  state_restore_pending_ = !state_file_.empty();
  state_outcome_ = state_file_.empty() ? "off (~state_file empty)" : "waiting for the first sample to restore";
  hm_clock_config clock_cfg;
  hm_clock_config_default(&clock_cfg);
  pnh_.param("clock/window_s", clock_cfg.window_s, clock_cfg.window_s);
  pnh_.param("clock/max_step_s", clock_cfg.max_step_s, clock_cfg.max_step_s);
  pnh_.param("clock/confirm_s", clock_cfg.confirm_s, clock_cfg.confirm_s);
  if (hm_clock_config_validate(&clock_cfg, err, sizeof err) != HM_OK) {
    ROS_FATAL("hunting_monitor: ~%s", err);
    return false;
  }
  hm_clock_init(&clock_, &clock_cfg);
  return true;
}

// The monitor over its table: ~table_file checked against the vehicle, or computed on start (~table_n); the
// start-up policy (the table's check, the fallback conicity) is the core's.
bool MonitorRos::createMonitor() {
  char err[512] = "";
  hm_table table = nullptr;
  if (table_file_.empty()) {  // computed on start (on every processor: 36 conicities in about 0.55 s)
    int n = static_cast<int>(cfg_.table_n_conicity);
    pnh_.param("table_n", n, n);
    if (n < 2 || n > 1000) {
      ROS_FATAL("hunting_monitor: ~table_n must be 2..1000, got %d", n);
      return false;
    }
    cfg_.table_n_conicity = static_cast<size_t>(n);
    ROS_INFO("hunting_monitor: no ~table_file: computing the boundary tables (%d conicities)...", n);
    table_file_ = "(computed on start)";
  } else if (hm_table_load_file(table_file_.c_str(), &table, err, sizeof err) != HM_OK) {
    ROS_FATAL("hunting_monitor: ~table_file: %s", err);
    return false;
  }
  if (kind_ != HM_MODEL_WHEELSET) {
    // a bogie's or car's families come from its own engine; the background refinement computes the wheelset's
    cfg_.table.refine = 0;
    ROS_INFO("hunting_monitor: vehicle model %s (its modes, Hopf speeds and table; no background table refinement)",
             hm_model_kind_name(kind_));
  }
  hm_threads threads = {0};
  const hm_status st = hm_monitor_create_model(&cfg_, kind_, &model_params_, table, hm_threads_parallel_for, &threads,
                                               &monitor_, err, sizeof err);
  if (st != HM_OK) {
    ROS_FATAL("hunting_monitor: %s%s: %s", table ? "~table_file " : "", table ? table_file_.c_str() : "",
              *err ? err : hm_status_str(st));
    return false;
  }
  refiner_.reset(new TableRefiner(vehicle_));
  return true;
}

void MonitorRos::refineTable() {
  bool failed = false;
  hm_status st = HM_OK;
  double c = 0.0, secs = 0.0;
  hm_table done = refiner_->take(&failed, &st, &c, &secs);
  if (done) {
    char err[256] = "";
    hm_table old = nullptr;
    st = hm_monitor_replace_table(monitor_, done, &old, err, sizeof err);  // the monitor takes it over
    refiner_->retire(old);
    if (st == HM_OK) {
      ++refinements_;
      last_refined_conicity_ = c;
      last_refine_s_ = secs;
      ROS_INFO_COND(!bench_table_churn_,
                    "hunting_monitor: exact cycle family at conicity %.4f added to the table (%.0f ms, %zu conicities)",
                    c, 1e3 * secs, hm_table_size(hm_monitor_table(monitor_), nullptr, nullptr));
    } else {
      failed = true;
      last_refine_error_ = err;
    }
  } else if (failed) {
    last_refine_error_ = hm_status_str(st);
  }
  if (failed) {  // not retried at that conicity (the core's policy): the table's interpolation stays in use there
    ++refinement_failures_;
    hm_monitor_table_failed(monitor_, c);
    ROS_WARN_COND(!bench_table_churn_, "hunting_monitor: no exact cycle family at conicity %.4f: %s", c,
                  last_refine_error_.c_str());
  }
  double want = 0.0, lo = 0.0, hi = 0.0;
  if (refiner_->busy()) return;
  if (hm_monitor_table_wanted(monitor_, &want)) {
    refiner_->request(hm_monitor_table(monitor_), want);
  } else if (bench_table_churn_ && ros::WallTime::now().toSec() >= next_churn_ &&
             hm_table_size(hm_monitor_table(monitor_), &lo, &hi) < cfg_.table.max_curves) {
    // benchmarking only: an exact family twice a second (far more often than the conicity in use moves), at
    // conicities spread over the table (golden-ratio steps)
    next_churn_ = ros::WallTime::now().toSec() + 0.5;
    churn_ = std::fmod(churn_ + 0.6180339887498949, 1.0);
    refiner_->request(hm_monitor_table(monitor_), lo + (0.02 + 0.96 * churn_) * (hi - lo));
  }
}

void MonitorRos::timeJumped(const std::string& what, double delta_s) {
  // a known step keeps the windows and a held ALARM, their ages moved with it; the stream restarts (monitor.h)
  hm_monitor_time_jump(monitor_, delta_s);
  ++time_jumps_;
  last_jump_ = what;
  last_jump_at_ = ros::WallTime::now().toSec();
  ROS_WARN("hunting_monitor: %s: the stream restarted (windows and a held ALARM kept), monitoring again after its "
           "settling time", what.c_str());
  updater_.force_update();  // now, and its period restarts on the new time line (it would wait for the old one)
}

void MonitorRos::checkRosTime(const ros::Time& now) {
  const double t = now.toSec();
  if (last_ros_time_ > 0.0 && t < last_ros_time_ - 0.5) {
    const double delta = t - last_ros_time_;
    if (header_time_ && accel_type_ == "imu") {
      // the monitor's time line is the sensor's stamps: the next sample tells whether they stepped too (a bag
      // restarted) or ROS time alone did (an NTP correction: onAccelImu)
      ros_step_ = delta;
      ros_step_ref_ = stamp_high_;
    } else {
      char what[160];
      std::snprintf(what, sizeof what, "ROS time moved backwards by %.3f s (an NTP correction, a bag restarted or "
                    "looped)", -delta);
      hm_clock_reset(&clock_);
      timeJumped(what, delta);
    }
  }
  last_ros_time_ = t;
}

void MonitorRos::pushAccel(double t, double a) {
  if (hm_monitor_push_accel(monitor_, t, a) == HM_OK) accel_freq_->tick();
}

void MonitorRos::onAccelFloat(const std_msgs::Float64::ConstPtr& msg) {
  const ros::Time now = ros::Time::now();
  if (now.isZero()) return;  // simulated time before its first /clock: no receipt time yet
  checkRosTime(now);
  pushAccel(now.toSec(), msg->data);  // receipt time: no stamp in a Float64
}

void MonitorRos::onAccelImu(const sensor_msgs::Imu::ConstPtr& msg) {
  const ros::Time now = ros::Time::now();
  // simulated time before its first /clock has no receipt time: a stamped sample taken at 0 anchored the clock
  // offset at -stamp, every later sample then late and the stream stale for the offset's 10 s window (timejump.test:
  // "not monitoring at first", 1 run in 10)
  if (now.isZero()) return;
  checkRosTime(now);
  const auto& a = msg->linear_acceleration;
  const double value = axis_ == 0 ? a.x : axis_ == 1 ? a.y : a.z;
  if (!header_time_) {
    pushAccel(now.toSec(), value);
    return;
  }
  const double stamp = msg->header.stamp.toSec();
  // a message in flight across the step still carries the old line's stamps: "ROS time alone" is decided only once
  // the stamps have gone on for kRosStepJudgeS after it (judged on the first one, a restarted bag whose first
  // message was in flight read as an NTP correction, its stream then stale: timejump.test failed 3 runs in 10)
  constexpr double kRosStepJudgeS = 0.5;  // (under the clock's confirm_s, 1 s, which would call it a step)
  // (against the highest stamp before the step: a new line's sample received just before ROS time stepped may
  // already have been taken, late)
  const bool back = ros_step_ != 0.0 && ros_step_ref_ > -1e300 && stamp < ros_step_ref_ + ros_step_ * 0.5;
  if (ros_step_ != 0.0 && (back || stamp >= ros_step_ref_ + kRosStepJudgeS)) {
    const double step = ros_step_;
    ros_step_ = 0.0;
    if (back) {  // the stamps stepped back with ROS time
      char what[200];
      std::snprintf(what, sizeof what, "ROS time moved backwards by %.3f s, the sensor's stamps by %.3f s (a bag "
                    "restarted or looped)", -step, ros_step_ref_ - stamp);
      hm_clock_reset(&clock_);
      stamp_high_ = stamp;
      timeJumped(what, stamp - ros_step_ref_);
    } else {  // ROS time alone: the clock's offset moves with it, the stamps' time line goes on
      hm_clock_shift(&clock_, step);
      ROS_WARN("hunting_monitor: ROS time moved backwards by %.3f s, the sensor's stamps did not (an NTP correction): "
               "the clock offset follows it", -step);
    }
  }
  const double before = clock_.offset_s;
  hm_clock_verdict v = HM_CLOCK_DROP;
  if (hm_clock_observe(&clock_, stamp, now.toSec(), &v) != HM_OK || v == HM_CLOCK_DROP) return;
  if (v == HM_CLOCK_STEPPED) {
    char what[200];
    std::snprintf(what, sizeof what,
                  "sensor stamps %.3f s off their time line for %.1f s (its clock stepped): ROS time - stamp now %.3f s",
                  clock_.offset_s - before, clock_.cfg.confirm_s, clock_.offset_s);
    stamp_high_ = stamp;
    timeJumped(what, before - clock_.offset_s);  // the stamps moved by minus the offset's change
  }
  stamp_high_ = std::max(stamp_high_, stamp);
  pushAccel(stamp, value);
}

void MonitorRos::onSpeed(const std_msgs::Float64::ConstPtr& msg) {
  const double v = speed_unit_ == "mps" ? msg->data * 3.6 : msg->data;
  const ros::Time now = ros::Time::now();
  checkRosTime(now);
  hm_monitor_push_speed(monitor_, lineTime(now), v);  // no stamp in a Float64: its receipt, on the sensor's line
}

void MonitorRos::onTimer(const ros::TimerEvent&) {
  const ros::Time now = ros::Time::now();
  checkRosTime(now);
  // the state is restored on a known time line: the sensor's, from its first stamped sample (receipt time: ROS time)
  if (state_restore_pending_ && !now.isZero() && (!header_time_ || clock_.have_offset)) restoreState(now);
  hm_monitor_status st;
  const double line_s = lineTime(now), wall_s = ros::WallTime::now().toSec();
  const hm_status ust = hm_monitor_update(monitor_, line_s, &st);
  if (ust != HM_OK) {
    publishFailure(ust, now);
    return;
  }
  last_line_s_ = line_s;
  last_wall_s_ = wall_s;
  have_update_ = true;
  if (!state_file_.empty() && !state_restore_pending_ && wall_s >= next_state_write_) {
    saveState(line_s, wall_s);
    next_state_write_ = wall_s + state_period_s_;
  }
  refineTable();
  last_ = st;
  have_last_ = true;
  const hm_assessment& s = st.assessment;
  const hm_margin_estimate& g = st.margin;
  if (g.n_changes != last_changes_) {
    if (g.n_changes > last_changes_)
      ROS_WARN("hunting_monitor: the conicity changed (a window %.0f s ago disagreed with those held): the "
               "identification continues from that window, with the prior (the more cautious) until a second agrees",
               lineTime(now) - g.last_change_s);
    last_changes_ = g.n_changes;
  }
  hunting_monitor::HuntingStatus m;
  fillStatus(st, now, m);
  status_pub_.publish(m);

  publishLevel(s, m.reason, now);
  if (static_cast<int>(s.level) != last_logged_level_) {
    last_logged_level_ = static_cast<int>(s.level);
    ROS_INFO("hunting_monitor: level %s (%s) at %.1f km/h", hm_level_name(s.level), m.reason.c_str(),
             st.estimate.speed_kmh);
  }
  publishMarkers(st, now);
  const visualization_msgs::MarkerArray chart = chart_->update(st, hm_monitor_table(monitor_), now);
  if (!chart.markers.empty()) chart_pub_.publish(chart);
  updater_.update();
}

// The status message: the report's fields (every one gated once, report.h; NAN -> 0 beside its flag here) and what
// only the node knows (stamps on ROS time, the sensor clock, the table's error and refinement).
void MonitorRos::fillStatus(const hm_monitor_status& st, const ros::Time& now, hunting_monitor::HuntingStatus& m) {
  hm_report r;
  hm_report_make(&st, NAN, &r);  // times as ages: the sensor's line is no clock to read
  const hm_estimate& e = st.estimate;
  m.header.stamp = now;
  m.header.frame_id = frame_id_;
  if (e.n_samples > 0) m.accel_stamp = ros::Time(rosTime(e.time_s));
  m.sensor_clock_offset_s = hm_clock_offset_s(&clock_);
  m.sensor_clock_steps = static_cast<uint32_t>(clock_.n_steps);
  m.level = static_cast<uint8_t>(st.assessment.level);
  m.reason_code = static_cast<uint8_t>(r.reason_code);
  m.reason = r.reason;
  m.level_latched = r.latched;
  m.latch_release_in_s = finite(r.release_in_s);
  m.level_held = r.held;
  m.hold_cause_code = static_cast<uint8_t>(r.hold_cause_code);
  m.hold_cause = r.hold_cause;
  if (std::isfinite(r.hold_since_s)) m.hold_since = ros::Time(rosTime(r.hold_since_s));
  if (std::isfinite(r.hold_last_met_s)) m.hold_last_met = ros::Time(rosTime(r.hold_last_met_s));
  m.hold_release_below_kmh = finite(r.hold_release_below_kmh);
  m.hold_release_amplitude_m = finite(r.hold_release_amplitude_m);
  m.hold_calm_s = finite(r.calm_s);
  m.hold_calm_needed_s = finite(r.calm_needed_s);
  m.hold_waits = static_cast<uint8_t>(r.hold_waits);
  m.hopf_low_from_hunting = r.hopf_low_from_hunting;
  // (a memory, not a margin: shown while it counts, also held without current data)
  m.hunted_at_kmh = finite(r.hunted_at_kmh);
  if (std::isfinite(r.hunted_at_s)) m.hunted_at = ros::Time(rosTime(r.hunted_at_s));
  m.speed_kmh = finite(r.speed_kmh);
  m.speed_valid = r.speed_valid;
  m.sample_rate_hz = finite(r.sample_rate_hz);
  m.sample_rate_mismatch = r.sample_rate_mismatch;
  m.samples_lost = static_cast<uint64_t>(r.samples_lost);
  m.samples_lost_fraction = finite(r.samples_lost_fraction);
  fillMode(r, m);
  fillMargin(r, m);
  fillBoundaries(r, st, m);
}

void MonitorRos::fillMode(const hm_report& r, hunting_monitor::HuntingStatus& m) {
  m.mode_valid = r.mode_valid;  // a fit over a changing speed is shown, not used (mode_verdict says why)
  m.mode_verdict = static_cast<uint8_t>(r.mode_window_verdict);
  m.mode_verdict_text = r.mode_window_verdict_text;
  m.mode_frequency_hz = finite(r.mode_frequency_hz);
  m.mode_frequency_se_hz = finite(r.mode_frequency_se_hz);
  m.decay_rate_1_s = finite(r.decay_rate_1_s);
  m.decay_rate_se_1_s = finite(r.decay_rate_se_1_s);
  m.damping_ratio = finite(r.damping_ratio);
  m.damping_ratio_se = finite(r.damping_ratio_se);
  m.windows_used = static_cast<uint32_t>(r.windows_used);
  m.track_lines_found = r.lines_found;
  m.track_line_wavelength_m = finite(r.line_wavelength_m);
  m.track_line_spacing_hz = finite(r.line_fundamental_hz);
  m.track_line_strongest_hz = finite(r.line_strongest_hz);
  m.track_line_strongest_mps2 = finite(r.line_strongest_mps2);
  m.mode_pole_pairs = static_cast<uint8_t>(r.mode_pole_pairs);
  m.mode_second_frequency_hz = finite(r.mode_second_frequency_hz);
  m.mode_second_decay_rate_1_s = finite(r.mode_second_decay_rate_1_s);
  m.lone_lines = static_cast<uint8_t>(r.lone_lines);
  m.lone_line_hz = finite(r.lone_line_hz);
  m.lone_line_mps2 = finite(r.lone_line_mps2);
  m.lone_line_wavelength_m = finite(r.lone_line_wavelength_m);
  m.order_lines = static_cast<uint8_t>(r.order_lines);
  m.order_line_wavelength_m = finite(r.order_line_wavelength_m);
  m.order_line_hz = finite(r.order_line_hz);
  m.order_line_mps2 = finite(r.order_line_mps2);
  m.narrow_peak = r.narrow_peak;
  m.narrow_peak_hz = finite(r.narrow_peak_hz);
  m.narrow_peak_verdict = static_cast<uint8_t>(r.narrow_peak_verdict);
  m.narrow_peak_verdict_text = r.narrow_peak_taken_for;
  m.narrow_peak_wavelength_m = finite(r.narrow_peak_wavelength_m);
  m.narrow_peak_tracked = r.narrow_peak_tracked;
  m.narrow_peak_envelope_ratio = finite(r.narrow_peak_envelope_ratio);
  m.narrow_peak_line_ratio = finite(r.narrow_peak_line_ratio);
  m.speed_tracking_measured = std::isfinite(r.mode_speed_tracking);
  m.mode_speed_tracking = finite(r.mode_speed_tracking);
  m.mode_speed_tracking_se = finite(r.mode_speed_tracking_se);
  m.spectrum_conicity = finite(r.spectrum_conicity);
  m.spectrum_conicity_se = finite(r.spectrum_conicity_se);
  m.spectrum_motion_rms_m = finite(r.spectrum_motion_rms_m);
  m.spectrum_shape_chi2 = finite(r.spectrum_shape_chi2);
  m.spectrum_model_share = finite(r.spectrum_model_share);
}

void MonitorRos::fillMargin(const hm_report& r, hunting_monitor::HuntingStatus& m) {
  m.conicity_valid = r.conicity_valid;
  m.conicity_estimate = finite(r.conicity_estimate);
  m.conicity_se = finite(r.conicity_se);
  m.hopf_model_valid = r.hopf_model_valid;
  m.hopf_model_kmh = finite(r.hopf_model_kmh);
  m.hopf_model_kmh_low = finite(r.hopf_model_kmh_low);
  m.hopf_model_kmh_high = finite(r.hopf_model_kmh_high);
  m.hopf_free_valid = r.hopf_free_valid;
  m.hopf_free_kmh = finite(r.hopf_free_kmh);
  m.hopf_free_kmh_low = finite(r.hopf_free_kmh_low);
  m.hopf_free_kmh_high = finite(r.hopf_free_kmh_high);
  m.model_mismatch = r.model_mismatch;  // as the level uses it (held)
  m.model_mismatch_windows = r.model_mismatch_windows;
  m.windows_birge_ratio = finite(r.birge_ratio);
  m.misfit_windows = static_cast<uint32_t>(r.misfit_windows);
  m.conicity_changes = static_cast<uint32_t>(r.conicity_changes);
  m.windows_since_change = static_cast<uint32_t>(r.windows_since_change);
  m.conicity_outside_prior = static_cast<int8_t>(r.conicity_outside_prior);
  if (std::isfinite(r.last_conicity_change_s)) m.last_conicity_change = ros::Time(rosTime(r.last_conicity_change_s));
}

void MonitorRos::fillBoundaries(const hm_report& r, const hm_monitor_status& st, hunting_monitor::HuntingStatus& m) {
  const hm_assessment& s = st.assessment;
  m.boundaries_valid = r.boundaries_valid;  // never a stale margin presented as current
  m.conicity_used = finite(r.conicity_used);
  m.conicity_from_estimate = r.conicity_from_estimate;
  m.conicity_from_prior = r.conicity_from_prior;
  m.model_interval_used = r.model_interval_used;
  m.hopf_free_used = r.hopf_free_used;
  m.conicity_outside_table = static_cast<int8_t>(r.conicity_outside_table);
  m.hopf_speed_kmh = finite(r.hopf_kmh);
  m.hopf_speed_kmh_low = finite(r.hopf_kmh_low);
  m.hopf_speed_kmh_high = finite(r.hopf_kmh_high);
  m.warn_from_kmh = finite(r.warn_from_kmh);
  m.watch_from_kmh = finite(r.watch_from_kmh);
  m.warn_risk = finite(r.warn_risk);
  m.anticipation_kmh = finite(r.anticipation_kmh);
  m.lowest_cycle_speed_kmh = finite(r.lowest_cycle_kmh);
  m.margin_to_hopf_kmh = finite(r.margin_hopf_kmh);
  m.margin_to_lowest_cycle_kmh = finite(r.margin_lowest_cycle_kmh);
  m.table_conicities = static_cast<uint32_t>(hm_table_size(hm_monitor_table(monitor_), nullptr, nullptr));
  double err_kmh = 0.0, err_m = 0.0;
  if (s.boundaries_valid && hm_table_local_error(hm_monitor_table(monitor_), s.conicity, &err_kmh, &err_m) == HM_OK) {
    m.table_error_speed_kmh = finite(err_kmh);
    m.table_error_amp_m = finite(err_m);
  }
  m.table_refining = refiner_->busy();
  m.amplitude_accel_mps2 = finite(r.amplitude_accel_mps2);
  m.amplitude_displacement_m = finite(r.amplitude_m);
  m.frequency_hz = finite(r.frequency_hz);
  m.oscillation_valid = r.oscillation_valid;
  m.cycles_valid = r.cycles_valid;
  m.unstable_cycle_amplitude_m = finite(r.unstable_cycle_amplitude_m);
  m.stable_cycle_amplitude_m = finite(r.stable_cycle_amplitude_m);
  m.rms_accel_mps2 = finite(r.rms_mps2);
  m.consecutive_peaks = static_cast<uint32_t>(r.consecutive_peaks);
  m.criterion_rms_exceeded = r.rms_exceeded;
  m.criterion_peaks_exceeded = r.peaks_exceeded;
  m.criterion_displacement_exceeded = r.displacement_exceeded;
  m.wheelset_displacement_m = finite(r.wheelset_displacement_m);
}

void MonitorRos::publishLevel(const hm_assessment& s, const std::string& text, const ros::Time& now) {
  const hm_level level = s.level;
  const hm_reason reason = s.reason;
  const bool changed = static_cast<int>(level) != last_published_level_;
  if (changed) {
    std_msgs::UInt8 bare;
    bare.data = static_cast<uint8_t>(level);
    alarm_pub_.publish(bare);
    last_published_level_ = static_cast<int>(level);
  }
  if (changed || static_cast<int>(reason) != last_published_reason_ || now.toSec() - last_stamped_at_ >= 1.0 ||
      now.toSec() < last_stamped_at_) {
    hunting_monitor::HuntingAlarm a;
    a.header.stamp = now;
    a.header.frame_id = frame_id_;
    a.level = static_cast<uint8_t>(level);
    a.reason_code = static_cast<uint8_t>(reason);
    a.reason = text;
    a.level_latched = s.latched;
    a.level_held = s.held;
    a.hold_release_below_kmh = finite(s.hold_release_below_kmh);
    a.hold_calm_s = finite(s.calm_s);
    a.hold_calm_needed_s = finite(s.calm_needed_s);
    alarm_stamped_pub_.publish(a);
    last_published_reason_ = static_cast<int>(reason);
    last_stamped_at_ = now.toSec();
  }
}

void MonitorRos::publishFailure(hm_status st, const ros::Time& now) {
  hunting_monitor::HuntingStatus m;  // every field 0 / false: nothing is current
  m.header.stamp = now;
  m.header.frame_id = frame_id_;
  m.level = HM_LEVEL_NO_DATA;
  m.reason_code = HM_REASON_STARTUP;
  m.reason = std::string("the monitor could not update: ") + hm_status_str(st);
  status_pub_.publish(m);
  hm_assessment none{};  // nothing current, nothing held
  none.level = HM_LEVEL_NO_DATA;
  none.reason = HM_REASON_STARTUP;
  publishLevel(none, m.reason, now);
  have_last_ = false;  // the diagnostics say "no data" rather than show the last good status as current
  ROS_ERROR_THROTTLE(5.0, "hunting_monitor: %s", m.reason.c_str());
  updater_.update();
}

void MonitorRos::publishMarkers(const hm_monitor_status& st, const ros::Time& now) {
  const hm_estimate& e = st.estimate;
  const hm_assessment& s = st.assessment;
  const float* c = levelColour(s.level);
  visualization_msgs::MarkerArray arr;
  visualization_msgs::Marker lamp;
  lamp.header.stamp = now;
  lamp.header.frame_id = frame_id_;
  lamp.ns = "hunting";
  lamp.id = 0;
  lamp.type = visualization_msgs::Marker::SPHERE;
  lamp.action = visualization_msgs::Marker::ADD;
  lamp.pose.orientation.w = 1.0;
  lamp.scale.x = lamp.scale.y = lamp.scale.z = 1.0;
  lamp.color.r = c[0];
  lamp.color.g = c[1];
  lamp.color.b = c[2];
  lamp.color.a = 1.0;
  arr.markers.push_back(lamp);
  visualization_msgs::Marker text = lamp;
  text.id = 1;
  text.type = visualization_msgs::Marker::TEXT_VIEW_FACING;
  text.pose.position.z = -1.3;  // below the lamp: the stability chart is to its right (x from 1.5 m)
  text.scale.x = text.scale.y = 0.0;
  text.scale.z = 0.16;
  text.color.r = text.color.g = text.color.b = 1.0;
  char buf[512], decay[32] = "-";
  if (st.mode_steady) std::snprintf(decay, sizeof decay, "%.2f 1/s", st.mode.decay_rate_1_s);
  if (s.boundaries_valid)
    std::snprintf(buf, sizeof buf,
                  "%s: %s\nV %.1f km/h  Hopf %.1f [%.1f, %.1f] (%s)  lowest cycle %.1f\n"
                  "amplitude %.2f mm at %.1f Hz  unstable cycle %.2f mm\nconicity %.3f (%s)  decay %s",
                  hm_level_name(s.level), reasonText(s).c_str(), e.speed_kmh, s.boundaries.hopf_speed_kmh,
                  s.hopf_low_kmh, s.hopf_high_kmh, hopfMarginWords(s.margin_hopf_kmh).c_str(),
                  s.boundaries.lowest_cycle_speed_kmh,
                  1e3 * e.amplitude_displacement_m, e.frequency_hz, 1e3 * s.edge_used_m, s.conicity,
                  s.conicity_from_estimate ? "identified" : "prior", decay);
  else
    std::snprintf(buf, sizeof buf, "%s: %s", hm_level_name(s.level), reasonText(s).c_str());
  text.text = buf;
  arr.markers.push_back(text);
  marker_pub_.publish(arr);
}

void MonitorRos::diagnoseInputs(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  const hm_estimate& e = last_.estimate;
  if (!have_last_ || !e.accel_valid || !e.speed_valid)
    stat.summary(diagnostic_msgs::DiagnosticStatus::ERROR,
                 !have_last_                ? "no data yet"
                 : !e.sample_rate_supported ? "acceleration at a sample rate the filters cannot use"
                 : !e.accel_valid           ? "acceleration stale or missing"
                 : e.speed_refused          ? std::string("speeds arrive, refused: ") + hm_speed_refusal_text(e.speed_refused)
                                            : "speed stale or missing");
  else if (ros::WallTime::now().toSec() - last_jump_at_ < 10.0)
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "time jumped: " + last_jump_);
  else if (e.sample_rate_mismatch)
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                 "acceleration at " + std::to_string(static_cast<int>(std::lround(e.sample_rate_measured_hz))) +
                     " Hz, configured " + std::to_string(static_cast<int>(std::lround(cfg_.estimator.sample_rate_hz))) +
                     " Hz: filters follow the measured rate");
  else if (e.loss_fraction > kLossWarnFraction) {
    char text[128];
    std::snprintf(text, sizeof text, "%.1f%% of the acceleration samples lost over the last 10 s (bridged)",
                  100.0 * e.loss_fraction);
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, text);
  } else if (e.n_rejected_nonfinite + e.n_rejected_range + e.n_rejected_order + e.n_speed_rejected + e.n_gaps > 0)
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "inputs current; some samples were rejected");
  else
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "inputs current");
  stat.add("speed_kmh", e.speed_kmh);
  stat.add("sample rate measured [Hz]", e.sample_rate_measured_hz);
  stat.add("sample rate configured [Hz]", cfg_.estimator.sample_rate_hz);
  stat.add("samples", e.n_samples);
  stat.add("rejected non-finite", e.n_rejected_nonfinite);
  stat.add("rejected out of range", e.n_rejected_range);
  stat.add("rejected out of order", e.n_rejected_order);
  stat.add("gaps", e.n_gaps);
  stat.add("samples lost", e.n_samples_lost);
  stat.add("samples lost over the last 10 s [%]", 100.0 * e.loss_fraction);
  stat.add("stamps on a regular grid", static_cast<bool>(e.stamps_regular));
  stat.add("rejected speeds", e.n_speed_rejected);
  stat.add("time jumps", time_jumps_);
  stat.add("last time jump", last_jump_.empty() ? std::string("none") : last_jump_);
  stat.add("sensor clock offset (ROS time - stamp, least) [s]", hm_clock_offset_s(&clock_));
  stat.add("latest sample's latency beyond the least [s]", clock_.latency_s);
  stat.add("sensor clock steps", clock_.n_steps);
  stat.add("samples dropped: stamped ahead of ROS time", clock_.n_dropped);
  stat.add("samples received late (beyond max_step_s)", clock_.n_late);
  stat.add("oscillation valid", static_cast<bool>(e.oscillation_valid));
}

void MonitorRos::diagnoseLevel(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  const hm_assessment& s = last_.assessment;
  const hm_level l = have_last_ ? s.level : HM_LEVEL_NO_DATA;
  const unsigned char d = l == HM_LEVEL_OK || l == HM_LEVEL_WATCH ? diagnostic_msgs::DiagnosticStatus::OK
                          : l == HM_LEVEL_WARN                       ? diagnostic_msgs::DiagnosticStatus::WARN
                                                                     : diagnostic_msgs::DiagnosticStatus::ERROR;
  stat.summary(d, std::string(hm_level_name(l)) + ": " +
                     (have_last_ ? reasonText(s) : std::string(hm_reason_text(HM_REASON_STARTUP))));
  if (have_last_ && s.latched) {
    stat.add("latched by", std::string(hm_reason_text(s.hold_cause)));
    stat.add("held (no criterion met now)", static_cast<bool>(s.held));
    stat.add("release below [km/h]", s.hold_release_below_kmh);
    stat.add("release: amplitude below [mm]", 1e3 * s.hold_release_amplitude_m);
    stat.add("calm so far [s]", s.calm_s);
    stat.add("calm needed [s]", s.calm_needed_s);
    stat.add("latched: calm still needed [s]", s.release_in_s);
  }
  if (have_last_ && s.boundaries_valid) {
    stat.add("margin to Hopf [km/h]", s.margin_hopf_kmh);
    stat.add("Hopf interval low [km/h]", s.hopf_low_kmh);
    stat.add("Hopf interval high [km/h]", s.hopf_high_kmh);
    stat.add("margin to lowest cycle speed [km/h]", s.margin_lowest_cycle_kmh);
    stat.add("conicity used", s.conicity);
    stat.add("conicity from identification", static_cast<bool>(s.conicity_from_estimate));
    if (s.conicity_outside_table)
      stat.add("conicity outside the table", std::string(s.conicity_outside_table > 0 ? "above: boundaries widened"
                                                                                      : "below: boundaries widened"));
  }
  const hm_margin_estimate& g = last_.margin;
  if (have_last_) {
    stat.add("identified windows", g.n_windows);
    stat.add("identification window", std::string(hm_window_verdict_text(last_.mode_verdict)));
    if (last_.mode_steady) {
      stat.add("decay rate [1/s]", last_.mode.decay_rate_1_s);
      stat.add("damping ratio", last_.mode.damping_ratio);
    }
    if (g.hopf_free_valid) stat.add("model-free Hopf [km/h]", g.hopf_free_kmh);
    if (last_.mode.lines_found) {
      char text[160];
      std::snprintf(text, sizeof text, "every %.1f m (lines every %.2f Hz, strongest %.2f Hz at %.3f m/s^2): left out",
                    last_.line_wavelength_m, last_.mode.line_fundamental_hz, last_.mode.line_strongest_hz,
                    last_.mode.line_strongest_mps2);
      stat.add("periodic track excitation", std::string(text));
    } else {
      stat.add("periodic track excitation", std::string("none found"));
    }
    stat.add("model mismatch", static_cast<bool>(s.boundaries_valid ? s.model_mismatch : g.model_mismatch));
    stat.add("misfit windows", g.n_misfits);
    stat.add("windows' Birge ratio", g.birge_ratio);
    stat.add("conicity changes detected", g.n_changes);
  }
}

void MonitorRos::diagnoseTable(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  const hm_table t = hm_monitor_table(monitor_);
  double lo = 0.0, hi = 0.0, err_kmh = 0.0, err_m = 0.0;
  const size_t n = hm_table_size(t, &lo, &hi);
  const bool at_use = have_last_ && last_.assessment.boundaries_valid &&
                      hm_table_local_error(t, last_.assessment.conicity, &err_kmh, &err_m) == HM_OK;
  const bool within = !at_use || (err_kmh <= cfg_.table.tolerance_kmh && err_m <= cfg_.table.tolerance_m);
  char text[160];
  std::snprintf(text, sizeof text, "%zu conicities %.3f-%.3f, %lu exact families added%s", n, lo, hi, refinements_,
                refiner_->busy() ? ", computing one" : "");
  stat.summary(refinement_failures_ == 0 && (within || refiner_->busy()) ? diagnostic_msgs::DiagnosticStatus::OK
                                                                          : diagnostic_msgs::DiagnosticStatus::WARN,
               std::string(text) + (within ? "" : "; interpolated beyond the tolerance at the conicity in use"));
  stat.add("file", table_file_);
  if (at_use) {
    stat.add("expected error at the conicity in use [km/h]", err_kmh);
    stat.add("expected error at the conicity in use [mm]", 1e3 * err_m);
  }
  if (refinements_ > 0) {
    stat.add("last exact family at conicity", last_refined_conicity_);
    stat.add("last exact family took [ms]", 1e3 * last_refine_s_);
  }
  if (refinement_failures_ > 0) stat.add("last failure", last_refine_error_);
}

void MonitorRos::restoreState(const ros::Time& now) {
  state_restore_pending_ = false;
  hm_state_outcome o;
  const double wall_s = ros::WallTime::now().toSec();
  const hm_status st =
      hm_state_restore_file(monitor_, state_file_.c_str(), lineTime(now), wall_s, HM_STATE_CLOCK_WALL, &o);
  state_outcome_ = o.text;
  state_verdict_ = static_cast<int>(o.verdict);
  state_from_prev_ = o.from_prev != 0;
  if (st == HM_OK || o.verdict == HM_STATE_NO_FILE)
    ROS_INFO("hunting_monitor: state file %s: %s", state_file_.c_str(), o.text);
  else
    ROS_WARN("hunting_monitor: state file %s: %s (starting from the prior)", state_file_.c_str(), o.text);
  next_state_write_ = wall_s + state_period_s_;
  updater_.force_update();
}

void MonitorRos::saveState(double line_s, double wall_s) {
  char why[512] = "";
  const ros::WallTime t0 = ros::WallTime::now();
  if (hm_state_save_file(monitor_, state_file_.c_str(), line_s, wall_s, why, sizeof why) == HM_OK) {
    ++state_writes_;
    state_write_error_.clear();
  } else {
    ++state_write_failures_;
    state_write_error_ = why;
    ROS_ERROR_THROTTLE(10.0, "hunting_monitor: the state could not be written: %s", why);
  }
  state_write_ms_ = 1e3 * (ros::WallTime::now() - t0).toSec();
}

void MonitorRos::diagnoseState(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  using diagnostic_msgs::DiagnosticStatus;
  // refused, or restored from FILE.prev (FILE was refused): WARN
  const bool refused = (state_verdict_ > static_cast<int>(HM_STATE_RESTORED) &&
                        state_verdict_ != static_cast<int>(HM_STATE_NO_FILE)) ||
                       state_from_prev_;
  if (!state_write_error_.empty())
    stat.summary(DiagnosticStatus::ERROR, "the state could not be written: " + state_write_error_);
  else if (state_verdict_ == static_cast<int>(HM_STATE_NO_FILE))
    stat.summary(DiagnosticStatus::OK, "no state file yet (a first start): " + state_outcome_);
  else
    stat.summary(refused ? DiagnosticStatus::WARN : DiagnosticStatus::OK, state_outcome_);
  stat.add("file", state_file_.empty() ? std::string("(off)") : state_file_);
  stat.add("restore", state_outcome_);
  stat.add("written every [s]", state_period_s_);
  stat.add("writes", state_writes_);
  stat.add("write failures", state_write_failures_);
  stat.add("last write took [ms]", state_write_ms_);
}

void MonitorRos::diagnoseSettings(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  if (reconfigure_)
    reconfigure_->diagnose(stat);
  else
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "settings as loaded (dynamic_reconfigure not allowed)");
}

}  // namespace hunting_monitor
