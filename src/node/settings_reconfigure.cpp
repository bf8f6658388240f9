#include "settings_reconfigure.h"

#include <cstdio>

namespace hunting_monitor {

namespace {

// The fields offered (cfg/Monitor.cfg) and where each lives in the core's configuration: one table for the
// conversion both ways and for the list of changes.
struct Field {
  const char* name;  // section.field as in monitor.yaml
  double MonitorConfig::*dr;
  double* (*core)(hm_monitor_config*);
};
const Field kFields[] = {
    {"alarm.warn_amplitude_fraction", &MonitorConfig::warn_amplitude_fraction,
     [](hm_monitor_config* c) { return &c->alarm.warn_amplitude_fraction; }},
    {"alarm.warn_speed_margin_kmh", &MonitorConfig::warn_speed_margin_kmh,
     [](hm_monitor_config* c) { return &c->alarm.warn_speed_margin_kmh; }},
    {"alarm.warn_standard_errors", &MonitorConfig::warn_standard_errors,
     [](hm_monitor_config* c) { return &c->alarm.warn_standard_errors; }},
    {"alarm.watch_speed_margin_kmh", &MonitorConfig::watch_speed_margin_kmh,
     [](hm_monitor_config* c) { return &c->alarm.watch_speed_margin_kmh; }},
    {"alarm.hysteresis_kmh", &MonitorConfig::hysteresis_kmh,
     [](hm_monitor_config* c) { return &c->alarm.hysteresis_kmh; }},
    {"alarm.hysteresis_amplitude_fraction", &MonitorConfig::hysteresis_amplitude_fraction,
     [](hm_monitor_config* c) { return &c->alarm.hysteresis_amplitude_fraction; }},
    {"alarm.min_hold_s", &MonitorConfig::min_hold_s, [](hm_monitor_config* c) { return &c->alarm.min_hold_s; }},
    {"alarm.conicity_max_se", &MonitorConfig::conicity_max_se,
     [](hm_monitor_config* c) { return &c->alarm.conicity_max_se; }},
    {"alarm.conicity_fallback", &MonitorConfig::conicity_fallback,
     [](hm_monitor_config* c) { return &c->alarm.conicity_fallback; }},
    {"estimator.rms_limit_mps2", &MonitorConfig::rms_limit_mps2,
     [](hm_monitor_config* c) { return &c->estimator.rms_limit_mps2; }},
    {"estimator.peaks_limit_mps2", &MonitorConfig::peaks_limit_mps2,
     [](hm_monitor_config* c) { return &c->estimator.peaks_limit_mps2; }},
};

MonitorConfig toReconfigure(hm_monitor_config c, const std::string& result) {
  MonitorConfig r = MonitorConfig::__getDefault__();
  for (const Field& f : kFields) r.*f.dr = *f.core(&c);
  r.use_conicity_estimate = c.alarm.use_conicity_estimate != 0;
  r.peaks_count = static_cast<int>(c.estimator.peaks_count);
  r.result = result;
  return r;
}

std::string fmt(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", x);
  return b;
}

}  // namespace

SettingsReconfigure::SettingsReconfigure(ros::NodeHandle pnh, hm_monitor monitor) : monitor_(monitor) {
  hm_monitor_settings(monitor_, &loaded_);
  server_.reset(new dynamic_reconfigure::Server<MonitorConfig>(pnh));
  // The server starts from the parameter server or the .cfg defaults; the running (loaded) settings replace them
  // before the callback is set, so that its first call changes nothing.
  server_->updateConfig(toReconfigure(loaded_, "as loaded at start"));
  server_->setCallback([this](MonitorConfig& c, uint32_t level) { onReconfigure(c, level); });
}

void SettingsReconfigure::onReconfigure(MonitorConfig& config, uint32_t) {
  const auto before = changes();
  hm_monitor_config running;
  hm_monitor_settings(monitor_, &running);
  hm_monitor_config want = running;
  for (const Field& f : kFields) *f.core(&want) = config.*f.dr;
  want.alarm.use_conicity_estimate = config.use_conicity_estimate ? 1 : 0;
  char why[256] = "";
  hm_status st = HM_OK;
  if (config.peaks_count < 0) {  // not representable in the core's unsigned field: refused here, in its words
    std::snprintf(why, sizeof why, "estimator.peaks_count: must be in [1, 1000] (got %d)", config.peaks_count);
    st = HM_EDOMAIN;
  } else {
    want.estimator.peaks_count = static_cast<unsigned>(config.peaks_count);
    st = hm_monitor_set_runtime_settings(monitor_, &want, why, sizeof why);
  }
  if (st != HM_OK) {  // the running settings stay; the client gets them back with the reason
    ++refused_;
    last_refused_ = *why ? why : hm_status_str(st);
    ROS_ERROR("hunting_monitor: settings change refused, running settings kept: %s", last_refused_.c_str());
    config = toReconfigure(running, "refused: " + last_refused_);
    return;
  }
  hm_monitor_config now;
  hm_monitor_settings(monitor_, &now);
  const auto after = changes();
  std::string list;
  for (const auto& c : after) list += (list.empty() ? "" : ", ") + c.first + ": " + c.second;
  if (after != before) {
    ++applied_;
    ROS_WARN("hunting_monitor: settings changed at runtime (%s)",
             list.empty() ? "back to the loaded ones" : list.c_str());
  }
  config = toReconfigure(now, list.empty() ? "applied: settings as loaded" : "applied: " + list);
}

std::vector<std::pair<std::string, std::string>> SettingsReconfigure::changes() const {
  hm_monitor_config now, loaded = loaded_;
  hm_monitor_settings(monitor_, &now);
  std::vector<std::pair<std::string, std::string>> out;
  for (const Field& f : kFields)
    if (*f.core(&now) != *f.core(&loaded))
      out.emplace_back(f.name, fmt(*f.core(&loaded)) + " -> " + fmt(*f.core(&now)));
  if (now.alarm.use_conicity_estimate != loaded.alarm.use_conicity_estimate)
    out.emplace_back("alarm.use_conicity_estimate", std::string(loaded.alarm.use_conicity_estimate ? "true" : "false") +
                                                        " -> " + (now.alarm.use_conicity_estimate ? "true" : "false"));
  if (now.estimator.peaks_count != loaded.estimator.peaks_count)
    out.emplace_back("estimator.peaks_count", std::to_string(loaded.estimator.peaks_count) + " -> " +
                                                  std::to_string(now.estimator.peaks_count));
  return out;
}

void SettingsReconfigure::diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat) const {
  const auto c = changes();
  if (c.empty())
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "settings as loaded (dynamic_reconfigure allowed)");
  else
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "settings changed at runtime");
  for (const auto& change : c) stat.add(change.first, change.second);
  stat.add("changes applied", applied_);
  stat.add("changes refused", refused_);
  if (refused_ > 0) stat.add("last refused", last_refused_);
}

}  // namespace hunting_monitor
