// Commissioning through dynamic_reconfigure: the alarm's settings and the standard criteria's limits (cfg/Monitor.cfg)
// changed while monitoring. Only created with ~allow_reconfigure true (safety settings: any node on the graph can call
// a service). Each change goes as a whole through the core's validator (hm_monitor_set_runtime_settings): applied
// without a restart and logged, or refused with the running settings kept, the reason in the `result` field and the
// log. The diagnostic "settings" says WARN "settings changed at runtime" with each changed value (loaded -> now).
#ifndef HUNTING_MONITOR_SETTINGS_RECONFIGURE_H
#define HUNTING_MONITOR_SETTINGS_RECONFIGURE_H

#include <diagnostic_updater/diagnostic_updater.h>
#include <dynamic_reconfigure/server.h>
#include <hunting_monitor/MonitorConfig.h>
#include <ros/ros.h>

#include <memory>
#include <string>
#include <utility>
#include <vector>

extern "C" {
#include "hunting_monitor/monitor.h"
}

namespace hunting_monitor {

class SettingsReconfigure {
 public:
  // pnh: the monitor's private namespace (its service and parameter topics go there). monitor is borrowed and only
  // touched from the callbacks of pnh's queue, the queue of every other callback of the monitor.
  SettingsReconfigure(ros::NodeHandle pnh, hm_monitor monitor);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat) const;
  // The running settings that differ from those loaded at start: ("section.field", "loaded -> now").
  std::vector<std::pair<std::string, std::string>> changes() const;

 private:
  void onReconfigure(MonitorConfig& config, uint32_t level);

  hm_monitor monitor_;
  hm_monitor_config loaded_{};
  unsigned long applied_ = 0, refused_ = 0;
  std::string last_refused_;
  std::unique_ptr<dynamic_reconfigure::Server<MonitorConfig>> server_;
};

}  // namespace hunting_monitor

#endif
