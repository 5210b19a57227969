#include "tofguard/common/lcm_settings.hpp"

#include <cstdlib>
#include <regex>

#include "tofguard/common/demand.hpp"

namespace tofguard {

std::string resolve_lcm_url(const std::string& from_config, const char* lcm_default_url_env) {
  if (!from_config.empty()) return from_config;
  if (lcm_default_url_env != nullptr && lcm_default_url_env[0] != '\0') {
    return lcm_default_url_env;
  }
  return kHostLocalLcmUrl;
}

std::string derive_image_url(const std::string& safety_url) {
  static const std::regex udpm(R"(^udpm://([^:/?]+):(\d+)(\?.*)?$)");
  std::smatch m;
  if (!std::regex_match(safety_url, m, udpm)) return safety_url;
  const int port = std::stoi(m[2].str()) + 1;
  std::string options = m[3].str();
  if (options.find("recv_buf_size=") == std::string::npos) {
    options += options.empty() ? "?recv_buf_size=4194304" : "&recv_buf_size=4194304";
  }
  return "udpm://" + m[1].str() + ":" + std::to_string(port) + options;
}

LcmSettings read_lcm_settings(std::optional<YamlMap> section, const char* lcm_default_url_env) {
  std::string url;
  std::string image_url;
  if (section) {
    url = section->optional_string("url").value_or("");
    image_url = section->optional_string("image_url").value_or("");
    section->finish();
  }
  LcmSettings lcm;
  lcm.url = resolve_lcm_url(url, lcm_default_url_env);
  lcm.image_url = image_url.empty() ? derive_image_url(lcm.url) : image_url;
  return lcm;
}

std::string bus_exposure_warning(const std::string& url) {
  const auto scheme_end = url.find("://");
  const std::string provider = scheme_end == std::string::npos ? url : url.substr(0, scheme_end);
  if (provider == "udpm") {
    const auto at = url.find("ttl=");
    if (at == std::string::npos) return "";  // LCM's default ttl is 0
    const long ttl = std::strtol(url.c_str() + at + 4, nullptr, 10);
    if (ttl <= 0) return "";
    return "WARNING: LCM bus " + url + " has ttl=" + std::to_string(ttl) +
           ": its multicast leaves this host, and every machine on that network can read and publish on it "
           "(docs/security.md)";
  }
  if (provider == "tcpq") {
    const std::string rest = url.substr(scheme_end + 3);
    if (rest.rfind("127.", 0) == 0 || rest.rfind("localhost", 0) == 0) return "";
    return "WARNING: LCM bus " + url + " reaches another host over TCP (docs/security.md)";
  }
  return "";
}

ChannelNames camera_channel_names(const ChannelNames& base, const std::string& camera_suffix) {
  ChannelNames c = base;
  for (std::string* name : {&c.depth, &c.camera_pose, &c.rendered, &c.labels, &c.discrepancy,
                            &c.motion_estimate, &c.sim_camera_fault}) {
    *name += camera_suffix;
  }
  c.camera_suffix = camera_suffix;
  return c;
}

ChannelNames base_channel_names(const ChannelNames& camera) {
  ChannelNames c = camera;
  const std::string& suffix = camera.camera_suffix;
  for (std::string* name : {&c.depth, &c.camera_pose, &c.rendered, &c.labels, &c.discrepancy,
                            &c.motion_estimate, &c.sim_camera_fault}) {
    TOFGUARD_DEMAND(name->size() >= suffix.size() &&
                        name->compare(name->size() - suffix.size(), suffix.size(), suffix) == 0,
                    "channel '" + *name + "' does not end in its camera's suffix '" + suffix + "'");
    name->resize(name->size() - suffix.size());
  }
  c.camera_suffix.clear();
  return c;
}

ChannelNames read_channel_names(YamlMap map) {
  ChannelNames c;
  auto name = [&map](const char* key, std::string* out) {
    if (auto v = map.optional_string(key)) *out = *v;
  };
  name("depth", &c.depth);
  name("joint_state", &c.joint_state);
  name("camera_pose", &c.camera_pose);
  name("rendered", &c.rendered);
  name("labels", &c.labels);
  name("discrepancy", &c.discrepancy);
  name("risk", &c.risk);
  name("status", &c.status);
  name("reset", &c.reset);
  name("reset_reply", &c.reset_reply);
  name("heartbeat", &c.heartbeat);
  name("power", &c.power);
  name("risk_auth", &c.risk_auth);
  name("status_auth", &c.status_auth);
  name("power_auth", &c.power_auth);
  name("reset_auth", &c.reset_auth);
  name("speed_limit", &c.speed_limit);
  name("speed_limit_auth", &c.speed_limit_auth);
  name("camera_release", &c.camera_release);
  name("camera_release_auth", &c.camera_release_auth);
  name("camera_release_reply", &c.camera_release_reply);
  name("motion_estimate", &c.motion_estimate);
  name("planned_trajectory", &c.planned_trajectory);
  name("sim_true_joint_state", &c.sim_true_joint_state);
  name("sim_joint_fault", &c.sim_joint_fault);
  name("sim_controller_fault", &c.sim_controller_fault);
  name("sim_camera_fault", &c.sim_camera_fault);
  map.finish();
  return c;
}

}  // namespace tofguard
