// hunting_sim_node: integrates the C core's nonlinear wheelset model on an irregular track along a speed profile
// and publishes what a vehicle's sensors would: lateral acceleration (sensor_msgs/Imu, stamped, with noise) and
// speed (std_msgs/Float64, km/h). Exits after ~duration_s (so a launch marked required ends with it).
#include <ros/ros.h>
#include <sensor_msgs/Imu.h>
#include <std_msgs/Float64.h>

#include <cmath>
#include <random>

#include "yaml_params.h"

extern "C" {
#include "hunting_monitor/excitation.h"
#include "hunting_monitor/integrate.h"
}

namespace {

struct Sim {
  hm_excited_model em{};
  hm_track track = nullptr;
  hm_dopri integ = nullptr;
  double x[4] = {0, 0, 0, 0};
  double t = 0.0;               // model time [s] since the start
  double dt_sample = 0.0005;
  double next_sample = 0.0, next_speed = 0.0, kick_s = -1.0, kick_m = 0.0;
  ros::Time t0;
  ros::Publisher accel_pub, speed_pub;
  std::string frame_id;
  std::mt19937_64 rng{1};
  std::normal_distribution<double> noise{0.0, 1.0};
  double noise_sigma = 0.05;
};

struct Ctx {
  Sim* sim;
};

int publishSamples(hm_dopri integ, double t_old, double t_new, const double*, void* ctx) {
  Sim* s = static_cast<Ctx*>(ctx)->sim;
  for (; s->next_sample <= t_new; s->next_sample += s->dt_sample) {
    double x[4], dx[4];
    if (hm_dopri_dense(integ, std::fmax(s->next_sample, t_old), x) != HM_OK) return 1;
    hm_excited_rhs(s->next_sample, x, dx, &s->em);
    sensor_msgs::Imu m;
    m.header.stamp = s->t0 + ros::Duration(s->next_sample);
    m.header.frame_id = s->frame_id;
    m.orientation_covariance[0] = -1.0;  // no orientation
    m.angular_velocity_covariance[0] = -1.0;
    m.linear_acceleration.y = dx[1] + s->noise_sigma * s->noise(s->rng);
    s->accel_pub.publish(m);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "hunting_sim");
  ros::NodeHandle nh, pnh("~");
  hm_vehicle veh;
  std::string error;
  if (!hunting_monitor::loadVehicleParams(pnh, &veh, &error)) {
    ROS_FATAL("hunting_sim: %s", error.c_str());
    return 1;
  }
  double v_start, v_end, ramp_s, hold_s, scale, rate, noise;
  int seed;
  Sim sim;
  pnh.param("v_start_kmh", v_start, 450.0);
  pnh.param("v_end_kmh", v_end, 560.0);
  pnh.param("ramp_s", ramp_s, 60.0);
  pnh.param("hold_s", hold_s, 5.0);
  pnh.param("irregularity_scale", scale, 0.01);
  pnh.param("seed", seed, 1);
  pnh.param("accel_rate_hz", rate, 2000.0);
  pnh.param("accel_noise_mps2", noise, 0.05);
  pnh.param("kick_s", sim.kick_s, -1.0);
  pnh.param("kick_m", sim.kick_m, 0.009);
  pnh.param<std::string>("frame_id", sim.frame_id, "base_link");
  if (!(v_start > 0 && v_end > 0 && ramp_s >= 0 && hold_s >= 0 && scale >= 0 && rate >= 100 && rate <= 5000 &&
        noise >= 0)) {
    ROS_FATAL("hunting_sim: need speeds > 0, ramp_s >= 0, hold_s >= 0, irregularity_scale >= 0, accel_rate_hz in "
              "100..5000 and accel_noise_mps2 >= 0");
    return 1;
  }
  if ((scale > 0 && hm_track_create(3.0, 120.0, scale, static_cast<uint64_t>(seed), &sim.track) != HM_OK) ||
      hm_excited_model_init(&sim.em, &veh, sim.track, v_start, v_end, ramp_s) != HM_OK ||
      !(sim.integ = hm_dopri_create(4))) {
    ROS_FATAL("hunting_sim: cannot set up the model");
    return 1;
  }
  sim.dt_sample = 1.0 / rate;
  sim.noise_sigma = noise;
  sim.rng.seed(static_cast<uint64_t>(seed));
  sim.accel_pub = nh.advertise<sensor_msgs::Imu>("accel", 8000);
  sim.speed_pub = nh.advertise<std_msgs::Float64>("speed", 100);
  ros::Duration(1.0).sleep();  // let subscribers connect
  sim.t0 = ros::Time::now();
  const double duration = ramp_s + hold_s;
  Ctx ctx{&sim};
  const hm_ode_system sys = {4, hm_excited_rhs, nullptr, &sim.em};
  const hm_dopri_options opt = {1e-8, 1e-11, 0.0, 2e-3, 0};
  ros::Rate loop(100.0);
  while (ros::ok() && sim.t < duration) {
    const double target = std::fmin((ros::Time::now() - sim.t0).toSec(), duration);
    if (sim.kick_s >= 0.0 && sim.t < sim.kick_s && target >= sim.kick_s) {  // a lateral disturbance, once
      hm_dopri_integrate(sim.integ, &sys, &opt, sim.t, sim.kick_s, sim.x, nullptr, publishSamples, &ctx, nullptr);
      sim.t = sim.kick_s;
      sim.x[0] += sim.kick_m;
    }
    if (target > sim.t) {
      if (hm_dopri_integrate(sim.integ, &sys, &opt, sim.t, target, sim.x, nullptr, publishSamples, &ctx, nullptr) !=
          HM_OK) {
        ROS_ERROR("hunting_sim: the integration failed at t = %.3f s", sim.t);
        break;
      }
      sim.t = target;
    }
    for (; sim.next_speed <= sim.t; sim.next_speed += 0.1) {
      std_msgs::Float64 v;
      v.data = hm_excited_speed_kmh(&sim.em, sim.next_speed);
      sim.speed_pub.publish(v);
    }
    loop.sleep();
  }
  hm_dopri_destroy(sim.integ);
  hm_track_destroy(sim.track);
  ROS_INFO("hunting_sim: scenario finished after %.1f s", sim.t);
  return 0;
}
