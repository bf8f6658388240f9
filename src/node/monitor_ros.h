// hunting_monitor_node: ROS plumbing around the C core's estimator and alarm (no physics or signal processing
// here): parameters, subscriptions, message conversion, publication, diagnostics and rviz markers.
#ifndef HUNTING_MONITOR_MONITOR_ROS_H
#define HUNTING_MONITOR_MONITOR_ROS_H

#include <diagnostic_updater/diagnostic_updater.h>
#include <hunting_monitor/HuntingStatus.h>
#include <diagnostic_updater/update_functions.h>
#include <ros/ros.h>
#include <sensor_msgs/Imu.h>
#include <std_msgs/Float64.h>

#include <memory>
#include <string>

#include "settings_reconfigure.h"
#include "stability_chart.h"
#include "table_refiner.h"

extern "C" {
#include "hunting_monitor/clock.h"
#include "hunting_monitor/model.h"
#include "hunting_monitor/monitor.h"
#include "hunting_monitor/report.h"
#include "hunting_monitor/state.h"
}

namespace hunting_monitor {

class MonitorRos {
 public:
  // Reads and validates every parameter; on a bad one logs ROS_FATAL and leaves ok() false.
  MonitorRos(ros::NodeHandle nh, ros::NodeHandle pnh);
  ~MonitorRos();
  bool ok() const { return ok_; }

 private:
  bool loadParameters();
  bool loadTopicParameters();
  bool loadStateAndClockParameters();
  bool createMonitor();
  void onAccelFloat(const std_msgs::Float64::ConstPtr& msg);
  void onAccelImu(const sensor_msgs::Imu::ConstPtr& msg);
  void onSpeed(const std_msgs::Float64::ConstPtr& msg);
  void pushAccel(double t, double a);
  // One time line (the core's clock.h): the monitor runs on the sensor's stamps; ROS times (the speed's receipt,
  // now) are taken onto that line by the clock's offset, so staleness and the speed's pairing do not depend on the
  // sensor clock's offset. Time that jumps restarts the monitor on the new line: ROS time moving backwards (a bag
  // restarted or looped), or the sensor's clock stepping (the clock says so). With ~time_source receipt the stamps
  // are ROS time and the offset 0.
  void checkRosTime(const ros::Time& now);
  double lineTime(const ros::Time& now) { return hm_clock_to_sensor(&clock_, now.toSec()); }
  void timeJumped(const std::string& what, double delta_s);
  void onTimer(const ros::TimerEvent& ev);
  // The HuntingStatus of one update, in parts: the mode and lines, the margin's estimates, the boundaries in use.
  void fillStatus(const hm_monitor_status& st, const ros::Time& now, hunting_monitor::HuntingStatus& m);
  void fillMode(const hm_report& r, hunting_monitor::HuntingStatus& m);
  void fillMargin(const hm_report& r, hunting_monitor::HuntingStatus& m);
  void fillBoundaries(const hm_report& r, const hm_monitor_status& st, hunting_monitor::HuntingStatus& m);
  void refineTable();
  void publishMarkers(const hm_monitor_status& st, const ros::Time& now);
  // The level on hunting_alarm (bare, on change) and hunting_alarm_stamped (on change of level or reason, and at
  // least once a second).
  void publishLevel(const hm_assessment& s, const std::string& text, const ros::Time& now);
  // ROS time of a time on the sensor's line.
  double rosTime(double line_s) const { return line_s + hm_clock_offset_s(&clock_); }
  // An update that failed still gives a status (NO_DATA, the reason in words) and the alarm level NO_DATA.
  void publishFailure(hm_status st, const ros::Time& now);
  void diagnoseInputs(diagnostic_updater::DiagnosticStatusWrapper& stat);
  void diagnoseLevel(diagnostic_updater::DiagnosticStatusWrapper& stat);
  void diagnoseTable(diagnostic_updater::DiagnosticStatusWrapper& stat);
  void diagnoseSettings(diagnostic_updater::DiagnosticStatusWrapper& stat);
  // The state file (state.h: what the monitor learned, kept through a restart): restored once the time line is
  // known (the first stamped sample, or with receipt time the first ROS time), its age on the wall clock; written
  // every ~state_period_s of wall time and at shutdown.
  void restoreState(const ros::Time& now);
  void saveState(double line_s, double wall_s);
  void diagnoseState(diagnostic_updater::DiagnosticStatusWrapper& stat);

  ros::NodeHandle nh_, pnh_;
  bool ok_ = false;
  // parameters
  std::string accel_type_, imu_axis_, speed_unit_, frame_id_, table_file_, time_source_;
  int axis_ = 1;                  // ~imu_axis resolved once: 0 x, 1 y, 2 z
  bool header_time_ = true;       // ~time_source: Imu header stamps (true) or receipt time
  double status_rate_hz_ = 20.0;
  bool allow_reconfigure_ = false;  // ~allow_reconfigure: offer the alarm and criteria settings to dynamic_reconfigure
  std::string state_file_;          // ~state_file ("" disables; unset: under ROS_HOME, named after the node)
  double state_period_s_ = 2.0;     // ~state_period_s (wall time)
  hm_vehicle vehicle_{};            // the (leading) wheelset's parameters
  hm_model_kind kind_ = HM_MODEL_WHEELSET;  // ~model: wheelset, bogie or car (issue #28)
  hm_car model_params_{};           // the bogie's or car's parameters (the wheelset's in .bogie.wheelset)
  hm_monitor_config cfg_{};
  // the core's monitor (estimator, identification, margin, alarm, table)
  hm_monitor monitor_ = nullptr;
  // last results, for diagnostics
  hm_monitor_status last_{};
  bool have_last_ = false;
  int last_published_level_ = -1, last_published_reason_ = -1, last_logged_level_ = -1;
  double last_stamped_at_ = -1e300;  // ROS time hunting_alarm_stamped was last published
  unsigned long last_changes_ = 0;  // conicity changes the margin had detected at the last status (logged once each)
  // the table's refinement (the core says where, the worker computes, the callbacks never wait)
  std::unique_ptr<TableRefiner> refiner_;
  unsigned long refinements_ = 0, refinement_failures_ = 0;
  double last_refined_conicity_ = 0.0, last_refine_s_ = 0.0;
  std::string last_refine_error_;
  bool bench_table_churn_ = false;  // ~bench_table_churn: benchmarking only, a refinement every 0.5 s
  double churn_ = 0.0, next_churn_ = 0.0;
  // the sensor's clock against ROS time, and time jumps
  hm_clock clock_{};
  double last_ros_time_ = 0.0;
  double ros_step_ = 0.0;           // a step back of ROS time, judged on the stamped samples after it (checkRosTime)
  double ros_step_ref_ = 0.0;       // the highest stamp of the line when it was seen: stamps that go on from it decide
                                    // "ROS time alone" only once they have gone on for kRosStepJudgeS
  double stamp_high_ = -1e301;      // the highest stamp used on the current line
  unsigned long time_jumps_ = 0;
  std::string last_jump_;
  double last_jump_at_ = -1e300;
  // the state file
  bool state_restore_pending_ = false;  // enabled and not restored yet (nothing is written before)
  std::string state_outcome_;           // what the restore did (hm_state_outcome's text)
  int state_verdict_ = -1;              // its hm_state_verdict (-1 before)
  bool state_from_prev_ = false;        // restored from FILE.prev: FILE was missing or refused
  double next_state_write_ = 0.0;       // wall time of the next write
  double last_line_s_ = 0.0, last_wall_s_ = 0.0;  // the last update's time (sensor line) and wall time
  bool have_update_ = false;
  unsigned long state_writes_ = 0, state_write_failures_ = 0;
  std::string state_write_error_;       // the last write's failure ("" after a success)
  double state_write_ms_ = 0.0;         // how long the last write took (fsync included)
  // ROS
  ros::Subscriber accel_sub_, speed_sub_;
  ros::Publisher status_pub_, alarm_pub_, alarm_stamped_pub_, marker_pub_, chart_pub_;
  std::unique_ptr<StabilityChart> chart_;
  std::unique_ptr<SettingsReconfigure> reconfigure_;  // only with ~allow_reconfigure
  ros::Timer timer_;
  diagnostic_updater::Updater updater_;
  double accel_min_hz_ = 0.0, accel_max_hz_ = 0.0;
  std::unique_ptr<diagnostic_updater::FrequencyStatus> accel_freq_;
};

}  // namespace hunting_monitor

#endif
