// ros_latency: publishes sensor_msgs/Imu at 2 kHz for 20 s to hunting_monitor_node and measures, for each
// hunting_status, how old the newest acceleration sample behind it is on arrival (the latency from an
// acceleration message to the status that reflects it). Prints JSON. Used by bench/ros_bench (not a test).
// `ros_latency --listen`: publishes nothing (the stream comes from the BenchImuSource nodelet) and only measures.
#include <hunting_monitor/HuntingStatus.h>
#include <ros/ros.h>
#include <sensor_msgs/Imu.h>
#include <std_msgs/Float64.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

int main(int argc, char** argv) {
  ros::init(argc, argv, "ros_latency");
  const bool listen_only = argc > 1 && std::string(argv[1]) == "--listen";
  ros::NodeHandle nh;
  std::vector<double> ages, ages_refining;
  std::atomic<bool> streaming{true};  // statuses after the stream ends reflect old samples by design: not counted
  std::atomic<double> last_advance{0.0};  // wall time of the last status behind a newer sample than the one before
  ros::Time newest;
  ros::Subscriber sub = nh.subscribe<hunting_monitor::HuntingStatus>(
      "hunting_status", 100,
      [&](const hunting_monitor::HuntingStatus::ConstPtr& m) {
        // only statuses behind a newer sample than the last: those after a stream stops are not latencies
        if (streaming && !m->accel_stamp.isZero() && m->accel_stamp > newest) {
          newest = m->accel_stamp;
          last_advance = ros::WallTime::now().toSec();
          ages.push_back((ros::Time::now() - m->accel_stamp).toSec());
          if (m->table_refining) ages_refining.push_back(ages.back());
        }
      },
      ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
  ros::Publisher acc, spd;
  if (!listen_only) {
    acc = nh.advertise<sensor_msgs::Imu>("accel", 4000);
    spd = nh.advertise<std_msgs::Float64>("speed", 10);
  }
  ros::AsyncSpinner spinner(1);
  spinner.start();
  ros::WallDuration(1.5).sleep();
  const ros::WallTime start = ros::WallTime::now();
  long n = 0;
  if (listen_only) {  // until the statuses stop advancing for a second (the source's 20 s), at most 60 s
    while (ros::ok() && (ros::WallTime::now() - start).toSec() < 60.0 &&
           !(last_advance > 0.0 && ros::WallTime::now().toSec() - last_advance > 1.0))
      ros::WallDuration(0.1).sleep();
  }
  while (!listen_only && (ros::WallTime::now() - start).toSec() < 20.0 && ros::ok()) {
    const ros::WallTime due = start + ros::WallDuration(n / 2000.0);
    // sleep (not spin) to the sample's time: a sensor driver waits for its data, it does not occupy a core
    const ros::WallDuration ahead = due - ros::WallTime::now();
    if (ahead > ros::WallDuration(0)) ahead.sleep();
    sensor_msgs::Imu m;
    m.header.stamp = ros::Time::now();
    m.linear_acceleration.y = 2.0 * std::sin(2.0 * M_PI * 14.0 * n / 2000.0);
    acc.publish(m);
    if (n % 40 == 0) {
      std_msgs::Float64 v;
      v.data = 450.0;
      spd.publish(v);
    }
    ++n;
  }
  streaming = false;
  ros::WallDuration(0.3).sleep();
  spinner.stop();
  if (ages.size() < 40) {
    std::printf("{\"error\": \"only %zu statuses received\"}\n", ages.size());
    return 1;
  }
  std::vector<double> a(ages.begin() + 20, ages.end());
  std::sort(a.begin(), a.end());
  if (std::getenv("HM_LATENCY_DEBUG"))
    for (size_t i = a.size() - 8; i < a.size(); ++i) std::fprintf(stderr, "%.3f ms\n", 1e3 * a[i]);
  std::sort(ages_refining.begin(), ages_refining.end());
  const double r_p99 = ages_refining.empty() ? 0.0 : ages_refining[static_cast<size_t>(0.99 * ages_refining.size())];
  std::printf("{\"samples_published\": %ld, \"statuses\": %zu, \"latency_ms_median\": %.3f, \"latency_ms_p99\": %.3f, "
              "\"statuses_while_refining_the_table\": %zu, \"latency_ms_p99_while_refining\": %.3f}\n",
              n, a.size(), 1e3 * a[a.size() / 2], 1e3 * a[static_cast<size_t>(0.99 * a.size())], ages_refining.size(),
              1e3 * r_p99);
  return 0;
}
