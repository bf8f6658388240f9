// hunting_monitor/MonitorNodelet: the monitor of monitor_ros.h as a nodelet, so that an IMU driver nodelet in the
// same manager hands it its 2 kHz messages by pointer, without serialisation. Same parameters, topics and
// diagnostics as hunting_monitor_node; the node executable stays.
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include <memory>

#include "monitor_ros.h"

namespace hunting_monitor {

class MonitorNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    // getNodeHandle()/getPrivateNodeHandle() share one single-threaded queue: the callbacks never run concurrently,
    // as in the node, so MonitorRos needs no lock of its own.
    monitor_.reset(new MonitorRos(getNodeHandle(), getPrivateNodeHandle()));
    if (!monitor_->ok()) {
      // a bad parameter was logged (ROS_FATAL) by MonitorRos; a nodelet cannot exit its manager, so it stays inert
      NODELET_FATAL("hunting_monitor: not monitoring: see the error above");
      monitor_.reset();
    }
  }
  std::unique_ptr<MonitorRos> monitor_;
};

}  // namespace hunting_monitor

PLUGINLIB_EXPORT_CLASS(hunting_monitor::MonitorNodelet, nodelet::Nodelet)
