// hunting_monitor/BenchImuSource (benchmark only, bench/ros_bench): the 2 kHz stream of bench/ros_latency (a 14 Hz,
// 2 m/s^2 lateral sine in sensor_msgs/Imu, the speed 450 km/h at 50 Hz) published from a nodelet for 20 s, as an IMU
// driver nodelet would: messages published as shared pointers, so that a subscriber nodelet in the same manager gets
// them by pointer, without serialisation.
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>
#include <sensor_msgs/Imu.h>
#include <std_msgs/Float64.h>

#include <atomic>
#include <cmath>
#include <thread>

namespace hunting_monitor {

class BenchImuSource : public nodelet::Nodelet {
 public:
  ~BenchImuSource() override {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }

 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    acc_ = nh.advertise<sensor_msgs::Imu>("accel", 4000);
    spd_ = nh.advertise<std_msgs::Float64>("speed", 10);
    getPrivateNodeHandle().param("delay_s", delay_s_, 1.5);
    thread_ = std::thread([this] { run(); });
  }

  void run() {
    ros::WallDuration(delay_s_).sleep();
    const ros::WallTime start = ros::WallTime::now();
    for (long n = 0; !stop_ && ros::ok() && (ros::WallTime::now() - start).toSec() < 20.0; ++n) {
      const ros::WallDuration ahead = start + ros::WallDuration(n / 2000.0) - ros::WallTime::now();
      if (ahead > ros::WallDuration(0)) ahead.sleep();
      sensor_msgs::ImuPtr m(new sensor_msgs::Imu);
      m->header.stamp = ros::Time::now();
      m->linear_acceleration.y = 2.0 * std::sin(2.0 * M_PI * 14.0 * n / 2000.0);
      acc_.publish(m);
      if (n % 40 == 0) {
        std_msgs::Float64Ptr v(new std_msgs::Float64);
        v->data = 450.0;
        spd_.publish(v);
      }
    }
  }

  ros::Publisher acc_, spd_;
  double delay_s_ = 1.5;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace hunting_monitor

PLUGINLIB_EXPORT_CLASS(hunting_monitor::BenchImuSource, nodelet::Nodelet)
