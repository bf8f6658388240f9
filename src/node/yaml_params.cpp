#include "yaml_params.h"

#include <cstdio>
#include <sstream>

extern "C" {
#include "hunting_monitor/config.h"
}

namespace hunting_monitor {
namespace {

void emit(std::ostringstream& out, XmlRpc::XmlRpcValue& v) {
  switch (v.getType()) {
    case XmlRpc::XmlRpcValue::TypeBoolean: out << (static_cast<bool>(v) ? "true" : "false"); break;
    case XmlRpc::XmlRpcValue::TypeInt: out << static_cast<int>(v); break;
    case XmlRpc::XmlRpcValue::TypeDouble: {
      char buf[40];
      std::snprintf(buf, sizeof buf, "%.17g", static_cast<double>(v));
      out << buf;
      break;
    }
    case XmlRpc::XmlRpcValue::TypeString: {
      out << '"';
      for (char c : static_cast<std::string>(v))
        if (c != '"' && c != '\\' && static_cast<unsigned char>(c) >= 0x20) out << c;
      out << '"';
      break;
    }
    case XmlRpc::XmlRpcValue::TypeArray:
      out << '[';
      for (int i = 0; i < v.size(); ++i) {
        if (i) out << ", ";
        emit(out, v[i]);
      }
      out << ']';
      break;
    case XmlRpc::XmlRpcValue::TypeStruct: {
      out << '{';
      bool first = true;
      for (auto& kv : v) {
        if (!first) out << ", ";
        first = false;
        out << '"' << kv.first << "\": ";
        emit(out, kv.second);
      }
      out << '}';
      break;
    }
    default: out << "null"; break;
  }
}

}  // namespace

std::string sectionsAsYaml(const ros::NodeHandle& nh, const std::vector<std::string>& sections) {
  std::ostringstream out;
  out << '{';
  bool first = true;
  for (const auto& s : sections) {
    XmlRpc::XmlRpcValue v;
    if (!nh.getParam(s, v)) continue;
    if (!first) out << ", ";
    first = false;
    out << '"' << s << "\": ";
    emit(out, v);
  }
  out << "}\n";
  return out.str();
}

bool loadVehicleModelParams(const ros::NodeHandle& nh, hm_model_kind* kind, hm_car* params, std::string* error) {
  const std::string yaml = sectionsAsYaml(nh, {"model", "vehicle", "conicity", "flange", "bogie", "car"});
  char err[512] = "";
  const char* src = "~ (vehicle parameters)";
  hm_model_kind k = HM_MODEL_WHEELSET;
  hm_car c;
  hm_car_default(&c);
  hm_status st = hm_config_model_kind(yaml.c_str(), yaml.size(), src, &k, err, sizeof err);
  if (st == HM_OK) {
    if (k == HM_MODEL_WHEELSET)
      st = hm_config_parse_vehicle(yaml.c_str(), yaml.size(), src, &c.bogie.wheelset, nullptr, err, sizeof err);
    else if (k == HM_MODEL_BOGIE)
      st = hm_config_parse_bogie(yaml.c_str(), yaml.size(), src, &c.bogie, nullptr, err, sizeof err);
    else
      st = hm_config_parse_car(yaml.c_str(), yaml.size(), src, &c, nullptr, err, sizeof err);
  }
  if (st != HM_OK) {
    *error = err;
    return false;
  }
  *kind = k;
  *params = c;
  return true;
}

bool loadVehicleParams(const ros::NodeHandle& nh, hm_vehicle* vehicle, std::string* error) {
  const std::string yaml = sectionsAsYaml(nh, {"vehicle", "conicity", "flange"});
  char err[512] = "";
  if (hm_config_parse_vehicle(yaml.c_str(), yaml.size(), "~ (vehicle parameters)", vehicle, nullptr, err,
                              sizeof err) == HM_OK)
    return true;
  *error = err;
  return false;
}

}  // namespace hunting_monitor
