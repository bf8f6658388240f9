// hunting_monitor_node: see monitor_ros.h.
#include <ros/ros.h>

#include "monitor_ros.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "hunting_monitor");
  hunting_monitor::MonitorRos monitor(ros::NodeHandle(), ros::NodeHandle("~"));
  if (!monitor.ok()) return 1;
  ros::spin();
  return 0;
}
