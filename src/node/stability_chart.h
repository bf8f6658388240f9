// The stability chart for rviz: the cycle family at the conicity in use (amplitude max|y| against speed, stable and
// unstable branches, the Hopf point and the folds labelled, axes with ticks and units), the operating point with
// a 30 s trail and the margins, the Hopf interval the level uses as a band on the speed axis and, while an ALARM is
// latched, the speed below which it may be released. Presentation only: the family and its folds come from the core's table
// (hm_table_family); this draws them as markers in ~frame_id, beside the lamp (x: 1 m per 100 km/h from x = 1.5 m;
// z: 1 m per 4 mm).
#ifndef HUNTING_MONITOR_STABILITY_CHART_H
#define HUNTING_MONITOR_STABILITY_CHART_H

#include <ros/ros.h>
#include <visualization_msgs/MarkerArray.h>

#include <deque>
#include <string>

extern "C" {
#include "hunting_monitor/monitor.h"
}

namespace hunting_monitor {

// The level's colour (r, g, b): NO_DATA grey, OK green, WATCH yellow, WARN orange, ALARM red; the lamp's and the
// operating point's.
const float* levelColour(hm_level level);
// The margin to the Hopf speed in words, "6.6 km/h below" or "4.4 km/h ABOVE": rviz may drop the minus sign of small
// text seen from a distance (it did in the screenshots), so neither the lamp nor the chart relies on a sign.
std::string hopfMarginWords(double margin_kmh);

class StabilityChart {
 public:
  static constexpr double kX0 = 1.5;       // m: where 0 km/h is drawn
  static constexpr double kPerKmh = 0.01;  // m per km/h
  static constexpr double kPerM = 250.0;   // m per metre of amplitude (1 m per 4 mm)
  static constexpr double kSpeedMax = 700.0, kAmpMax = 0.016;  // the axes' ends

  explicit StabilityChart(const std::string& frame_id) : frame_id_(frame_id) {}
  // The markers for this status: the family (axes, branches, labels) only when the conicity in use or the table
  // changed (and every 5 s, for a display that subscribes late), the operating point, trail and margins every time.
  // Empty while there are no current boundaries.
  visualization_msgs::MarkerArray update(const hm_monitor_status& st, hm_table table, const ros::Time& now);

 private:
  void drawFamily(visualization_msgs::MarkerArray* arr, double conicity, hm_table table, const ros::Time& now);
  // The Hopf interval in use as a band on the speed axis and, while an ALARM is latched, its release speed.
  void drawInterval(visualization_msgs::MarkerArray* arr, const hm_assessment& s, const ros::Time& now);
  std::string frame_id_;
  double drawn_conicity_ = -1.0, drawn_at_ = -1e300;
  size_t drawn_table_size_ = 0;
  struct Past {
    double t, v, amp;
  };
  std::deque<Past> trail_;
};

}  // namespace hunting_monitor

#endif
