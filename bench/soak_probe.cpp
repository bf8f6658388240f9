// soak_probe: listens to hunting_monitor_node for a given time (scripts/soak) and prints JSON: statuses received
// against the 20 Hz expected (over the whole run, which includes the node's start, and after the warm-up), the age of the newest acceleration sample behind each status on arrival (median,
// p99, max), the levels seen after a warm-up with the reasons of those not OK (alarm.h's hm_reason, its code and
// hm_reason_text: what a failing soak was told, e.g. a starved simulator's lost samples as WATCH partly blind), and the
// node's own count of accepted samples (from /diagnostics).
//   soak_probe SECONDS [WARMUP_SECONDS]
#include <diagnostic_msgs/DiagnosticArray.h>
#include <hunting_monitor/HuntingStatus.h>
#include <hunting_monitor/alarm.h>
#include <ros/ros.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <mutex>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  ros::init(argc, argv, "soak_probe", ros::init_options::AnonymousName);
  if (argc < 2) {
    std::fprintf(stderr, "usage: soak_probe SECONDS [WARMUP_SECONDS]\n");
    return 2;
  }
  const double seconds = std::atof(argv[1]), warmup = argc > 2 ? std::atof(argv[2]) : 60.0;
  ros::NodeHandle nh;
  std::mutex lock;
  std::vector<double> ages;
  long statuses = 0, after_warmup = 0, levels[5] = {0, 0, 0, 0, 0};
  std::map<int, long> reasons; /* reason_code -> statuses not OK after the warm-up */
  std::string samples = "0", rejected = "0", gaps = "0";
  const ros::WallTime start = ros::WallTime::now();
  ros::Subscriber sub = nh.subscribe<hunting_monitor::HuntingStatus>(
      "hunting_status", 1000,
      [&](const hunting_monitor::HuntingStatus::ConstPtr& m) {
        std::lock_guard<std::mutex> g(lock);
        ++statuses;
        if ((ros::WallTime::now() - start).toSec() < warmup) return;
        ++after_warmup;
        if (m->level < 5) ++levels[m->level];
        if (m->level != hunting_monitor::HuntingStatus::LEVEL_OK) ++reasons[m->reason_code];
        if (!m->accel_stamp.isZero()) ages.push_back((ros::Time::now() - m->accel_stamp).toSec());
      },
      ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
  ros::Subscriber diag = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 100, [&](const diagnostic_msgs::DiagnosticArray::ConstPtr& a) {
        std::lock_guard<std::mutex> g(lock);
        for (const auto& s : a->status)
          if (s.name.find("inputs") != std::string::npos)
            for (const auto& kv : s.values) {
              if (kv.key == "samples") samples = kv.value;
              if (kv.key == "rejected out of order") rejected = kv.value;
              if (kv.key == "gaps") gaps = kv.value;
            }
      });
  ros::AsyncSpinner spinner(1);
  spinner.start();
  while (ros::ok() && (ros::WallTime::now() - start).toSec() < seconds) ros::WallDuration(0.2).sleep();
  spinner.stop();
  std::lock_guard<std::mutex> g(lock);
  std::sort(ages.begin(), ages.end());
  const auto pct = [&](double p) { return ages.empty() ? -1.0 : 1e3 * ages[static_cast<size_t>(p * (ages.size() - 1))]; };
  std::string not_ok = "{";
  for (const auto& r : reasons) {
    std::string text;
    for (const char* c = hm_reason_text(static_cast<hm_reason>(r.first)); c && *c; ++c)
      if (*c != '"' && *c != '\\') text += *c;
    not_ok += (not_ok.size() > 1 ? ", \"" : "\"") + std::to_string(r.first) + "\": {\"statuses\": " +
              std::to_string(r.second) + ", \"reason\": \"" + text + "\"}";
  }
  not_ok += "}";
  std::printf("{\"seconds\": %.0f, \"statuses\": %ld, \"statuses_expected\": %.0f, \"statuses_after_warmup\": %ld, "
              "\"statuses_expected_after_warmup\": %.0f, \"latency_ms_median\": %.3f, "
              "\"latency_ms_p99\": %.3f, \"latency_ms_max\": %.3f, \"levels_after_warmup\": {\"NO_DATA\": %ld, \"OK\": "
              "%ld, \"WATCH\": %ld, \"WARN\": %ld, \"ALARM\": %ld}, \"node_samples_accepted\": %s, "
              "\"node_rejected_out_of_order\": %s, \"node_gaps\": %s, \"reason_codes_not_ok\": %s}\n",
              seconds, statuses, 20.0 * seconds, after_warmup, 20.0 * (seconds - warmup), pct(0.5), pct(0.99), pct(1.0), levels[0], levels[1], levels[2],
              levels[3], levels[4], samples.c_str(), rejected.c_str(), gaps.c_str(), not_ok.c_str());
  return 0;
}
