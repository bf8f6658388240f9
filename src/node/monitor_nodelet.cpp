// hunting_monitor/MonitorNodelet: the monitor of monitor_ros.h as a nodelet, so that an IMU driver nodelet in the
// same manager hands it its 2 kHz messages by pointer, without serialisation. Same parameters, topics and
// diagnostics as hunting_monitor_node; the node executable stays.
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include <memory>
#include <stdexcept>

#include "monitor_ros.h"

namespace hunting_monitor {

class MonitorNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    // getNodeHandle()/getPrivateNodeHandle() share one single-threaded queue: the callbacks never run concurrently,
    // as in the node, so MonitorRos needs no lock of its own.
    monitor_.reset(new MonitorRos(getNodeHandle(), getPrivateNodeHandle()));
    if (!monitor_->ok()) {
      // A bad parameter was logged (ROS_FATAL) by MonitorRos. As the node exits with status 1, the load fails: the
      // manager drops the nodelet and runs on, `nodelet load` exits with an error (a required one ends the launch).
      monitor_.reset();
      throw std::runtime_error("hunting_monitor: bad parameters (see the error above): not loaded");
    }
  }
  std::unique_ptr<MonitorRos> monitor_;
};

}  // namespace hunting_monitor

PLUGINLIB_EXPORT_CLASS(hunting_monitor::MonitorNodelet, nodelet::Nodelet)
