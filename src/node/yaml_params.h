// Thin helpers of the ROS nodes: private parameter sections turned into the YAML text the C core parses, so a
// node validates its parameters with exactly the code and messages of the command-line tool.
#ifndef HUNTING_MONITOR_YAML_PARAMS_H
#define HUNTING_MONITOR_YAML_PARAMS_H

#include <ros/ros.h>

#include <string>
#include <vector>

extern "C" {
#include "hunting_monitor/car.h"
#include "hunting_monitor/model.h"
}

namespace hunting_monitor {

// {"section": <its parameters>, ...} for every listed section present under nh, as flow-style YAML (JSON).
std::string sectionsAsYaml(const ros::NodeHandle& nh, const std::vector<std::string>& sections);

// The vehicle from the private sections vehicle, conicity and flange, validated by the core's config parser.
// On failure returns false with the parser's message in *error.
bool loadVehicleParams(const ros::NodeHandle& nh, hm_vehicle* vehicle, std::string* error);

// The vehicle model from ~model (wheelset, bogie or car; absent: wheelset) and the sections its config holds (those
// above, bogie, car), validated by the core's config parser (config.h): *kind and *params (the wheelset's in
// params->bogie.wheelset, the bogie's in params->bogie). On failure false with the parser's message.
bool loadVehicleModelParams(const ros::NodeHandle& nh, hm_model_kind* kind, hm_car* params, std::string* error);

}  // namespace hunting_monitor

#endif
