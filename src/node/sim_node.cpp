// hunting_sim_node: integrates the C core's nonlinear vehicle model (the wheelset, or with ~model a bogie or a car,
// its accelerometer where ~sensor says: axlebox, frame, carbody) on an irregular track along a speed profile and
// publishes what a vehicle's sensors would: lateral acceleration (sensor_msgs/Imu, stamped, with noise) and speed
// (std_msgs/Float64, km/h). Exits after ~duration_s (so a launch marked required ends with it).
#include <ros/ros.h>
#include <sensor_msgs/Imu.h>
#include <std_msgs/Float64.h>

#include <cmath>
#include <vector>

#include "yaml_params.h"

extern "C" {
#include "hunting_monitor/bogie.h"
#include "hunting_monitor/car.h"
#include "hunting_monitor/sensor_sim.h"
}

namespace {

// Plumbing only: the core's sensor simulation (sensor_sim.h) delivers the samples, this publishes them.
struct Publish {
  ros::Time t0;
  ros::Publisher accel_pub, speed_pub;
  std::string frame_id;
};

int publishAccel(void* ctx, double t_s, double measured_mps2, double, const double*) {
  const Publish* p = static_cast<Publish*>(ctx);
  sensor_msgs::Imu m;
  m.header.stamp = p->t0 + ros::Duration(t_s);
  m.header.frame_id = p->frame_id;
  m.orientation_covariance[0] = -1.0;  // no orientation
  m.angular_velocity_covariance[0] = -1.0;
  m.linear_acceleration.y = measured_mps2;
  p->accel_pub.publish(m);
  return 0;
}

int publishSpeed(void* ctx, double, double speed_kmh) {
  std_msgs::Float64 v;
  v.data = speed_kmh;
  static_cast<Publish*>(ctx)->speed_pub.publish(v);
  return 0;
}

// The scenario's settings beside the core's: how long to hold the last speed, and a lateral kick of the leading
// wheelset at kick_s (< 0: none).
struct Scenario {
  double hold_s, kick_s, kick_m;
};

// The speed profile, track, sensor rate and noise, the kick and the wheels' conicity from ~; false after ROS_FATAL.
bool loadScenario(ros::NodeHandle& pnh, hm_vehicle* veh, hm_sensor_sim_config* cfg, Scenario* sc, Publish* pub) {
  hm_sensor_sim_config_default(cfg);
  int seed;
  pnh.param("v_start_kmh", cfg->v_start_kmh, 450.0);
  pnh.param("v_end_kmh", cfg->v_end_kmh, 560.0);
  pnh.param("ramp_s", cfg->ramp_s, 60.0);
  pnh.param("hold_s", sc->hold_s, 5.0);
  pnh.param("irregularity_scale", cfg->irregularity_scale, 0.01);
  pnh.param("seed", seed, 1);
  pnh.param("accel_rate_hz", cfg->accel_rate_hz, 2000.0);
  pnh.param("accel_noise_mps2", cfg->accel_noise_mps2, 0.05);
  pnh.param("kick_s", sc->kick_s, -1.0);
  pnh.param("kick_m", sc->kick_m, 0.009);
  pnh.param<std::string>("frame_id", pub->frame_id, "base_link");
  if (!(sc->hold_s >= 0 && cfg->accel_rate_hz >= 100 && cfg->accel_rate_hz <= 5000 && seed >= 0 &&
        std::isfinite(sc->kick_m))) {
    ROS_FATAL("hunting_sim: need hold_s >= 0, accel_rate_hz in 100..5000, seed >= 0 and a finite kick_m");
    return false;
  }
  // a speed profile (steps and ramps) instead of the single ramp: ~profile_t_s and ~profile_v_kmh, equal lengths
  std::vector<double> pt, pv;
  pnh.getParam("profile_t_s", pt);
  pnh.getParam("profile_v_kmh", pv);
  if (pt.size() != pv.size() || pt.size() > HM_SPEED_PROFILE_MAX) {
    ROS_FATAL("hunting_sim: ~profile_t_s and ~profile_v_kmh need the same length, at most %d (got %zu and %zu)",
              HM_SPEED_PROFILE_MAX, pt.size(), pv.size());
    return false;
  }
  cfg->n_profile = pt.size();
  for (size_t k = 0; k < pt.size(); ++k) cfg->profile_t_s[k] = pt[k], cfg->profile_v_kmh[k] = pv[k];
  // the simulated wheels' conicity lambda(0) (the monitor keeps its own configuration): 0 keeps the vehicle's
  double conicity = 0.0;
  pnh.param("conicity_at_zero", conicity, 0.0);
  if (conicity != 0.0 && hm_vehicle_set_conicity_at_zero(veh, conicity) != HM_OK) {
    ROS_FATAL("hunting_sim: ~conicity_at_zero %g: must be >= 0 and >= the Gaussian terms' value at y = 0", conicity);
    return false;
  }
  cfg->track_seed = cfg->noise_seed = static_cast<uint64_t>(seed);
  return true;
}

// The core's simulation of the model at ~sensor (axlebox, frame, carbody as the model has them); nullptr after
// ROS_FATAL.
hm_sensor_sim createSimulator(ros::NodeHandle& pnh, hm_model_kind kind, hm_car* params,
                              const hm_sensor_sim_config* cfg) {
  static hm_bogie_model bogie;  // the system points into them for the whole run
  static hm_car_model car;
  static hm_system sys;
  hm_sensor_point point;
  std::string where;
  pnh.param<std::string>("sensor", where, "axlebox");
  hm_status st = HM_OK;
  if (kind == HM_MODEL_BOGIE) {
    st = hm_bogie_model_init(&bogie, &params->bogie, 0, &sys);
    if (st == HM_OK) st = hm_bogie_sensor(&bogie, where.c_str(), &point);
  } else if (kind == HM_MODEL_CAR) {
    st = hm_car_model_init(&car, params, 0, &sys);
    if (st == HM_OK) st = hm_car_sensor(&car, where.c_str(), &point);
  } else if (where != "axlebox") {
    st = HM_EINVAL;
  }
  if (st != HM_OK) {
    ROS_FATAL("hunting_sim: ~sensor '%s': not a place on a %s (axlebox%s)", where.c_str(), hm_model_kind_name(kind),
              kind == HM_MODEL_WHEELSET ? "" : kind == HM_MODEL_BOGIE ? ", frame" : ", frame, carbody");
    return nullptr;
  }
  hm_sensor_sim sim = nullptr;
  char why[160] = "";
  st = kind == HM_MODEL_WHEELSET
           ? hm_sensor_sim_create(&params->bogie.wheelset, cfg, nullptr, &sim, why, sizeof why)
           : hm_sensor_sim_create_system(&sys, &point, cfg, nullptr, &sim, why, sizeof why);
  if (st != HM_OK) {
    ROS_FATAL("hunting_sim: %s", why);
    return nullptr;
  }
  return sim;
}

// Runs the simulation in step with the wall clock until the profile and the hold are done (or ROS stops), the kick
// applied once on the way.
void runScenario(hm_sensor_sim sim, const hm_sensor_sim_config& cfg, const Scenario& sc, Publish* pub) {
  const hm_sensor_sink sink = {publishAccel, publishSpeed, pub};
  const double duration = (cfg.n_profile ? cfg.profile_t_s[cfg.n_profile - 1] : cfg.ramp_s) + sc.hold_s;
  ros::Rate loop(100.0);
  while (ros::ok() && hm_sensor_sim_time(sim) < duration) {
    const double t = hm_sensor_sim_time(sim);
    const double target = std::fmin((ros::Time::now() - pub->t0).toSec(), duration);
    hm_status st = HM_OK;
    if (sc.kick_s >= 0.0 && t < sc.kick_s && target >= sc.kick_s) {  // a lateral disturbance, once
      double x[HM_SYSTEM_MAX_DIM];  // the leading wheelset's y first
      st = hm_sensor_sim_run(sim, sc.kick_s, &sink);
      hm_sensor_sim_state(sim, x);
      x[0] += sc.kick_m;
      if (st == HM_OK) st = hm_sensor_sim_set_state(sim, x);
    }
    if (st == HM_OK && target > hm_sensor_sim_time(sim)) st = hm_sensor_sim_run(sim, target, &sink);
    if (st != HM_OK) {
      ROS_ERROR("hunting_sim: the integration failed at t = %.3f s", hm_sensor_sim_time(sim));
      break;
    }
    loop.sleep();
  }
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "hunting_sim");
  ros::NodeHandle nh, pnh("~");
  hm_model_kind kind;
  static hm_car params;  // the car's, its bogie's or its wheelset's
  std::string error;
  if (!hunting_monitor::loadVehicleModelParams(pnh, &kind, &params, &error)) {
    ROS_FATAL("hunting_sim: %s", error.c_str());
    return 1;
  }
  hm_sensor_sim_config cfg;
  Scenario sc;
  Publish pub;
  if (!loadScenario(pnh, &params.bogie.wheelset, &cfg, &sc, &pub)) return 1;
  hm_sensor_sim sim = createSimulator(pnh, kind, &params, &cfg);
  if (!sim) return 1;
  pub.accel_pub = nh.advertise<sensor_msgs::Imu>("accel", 8000);
  pub.speed_pub = nh.advertise<std_msgs::Float64>("speed", 100);
  ros::Duration(1.0).sleep();  // let subscribers connect
  pub.t0 = ros::Time::now();
  runScenario(sim, cfg, sc, &pub);
  const double t_end = hm_sensor_sim_time(sim);
  hm_sensor_sim_destroy(sim);
  ROS_INFO("hunting_sim: scenario finished after %.1f s", t_end);
  return 0;
}
