#pragma once
// A second computer on the wheelchair, for the tests of a deployment whose
// processes run on two hosts: a network namespace of its own, joined to the
// test's namespace (run-in-netns) by a veth pair, as two computers joined
// by a cable. Both sides route multicast (224.0.0.0/4) over the pair, so
// LCM's udpm with ttl=1 reaches the other side and each side still hears
// its own messages (multicast loopback). Only inside the test's private
// namespace: the machine's real interfaces are never touched.
//
// The namespace is held by a child (`unshare -n sleep`); a process runs on
// the second host through `nsenter --net=` (argv_prefix()).
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "tool_support.hpp"

namespace tofguard::test {

class SecondHost {
 public:
  // Addresses of the pair: this side 10.77.0.1/24, the second host
  // 10.77.0.2/24 (private, inside the test's namespaces only).
  SecondHost() {
    holder_ = std::make_unique<Subprocess>(
        "second-host", std::vector<std::string>{"/usr/bin/unshare", "-n", "--", "/usr/bin/sleep", "3600"});
    const std::string own = std::filesystem::read_symlink("/proc/self/ns/net").string();
    const bool apart = wait_until(
        [&] {
          std::error_code error;
          const auto link = std::filesystem::read_symlink(net_namespace(), error);
          return !error && link.string() != own;
        },
        std::chrono::seconds(5), [] { usleep(1000); });
    if (!apart) throw std::runtime_error("the second host's namespace did not come up");
    ip({"link", "add", "tg-here", "type", "veth", "peer", "name", "tg-there", "netns",
        std::to_string(holder_->pid())});
    ip({"addr", "add", "10.77.0.1/24", "dev", "tg-here"});
    ip({"link", "set", "tg-here", "up", "multicast", "on"});
    ip({"route", "replace", "224.0.0.0/4", "dev", "tg-here"});
    there({"link", "set", "lo", "up"});
    there({"addr", "add", "10.77.0.2/24", "dev", "tg-there"});
    there({"link", "set", "tg-there", "up", "multicast", "on"});
    there({"route", "add", "224.0.0.0/4", "dev", "tg-there"});
  }

  // The prefix that runs a command on the second host.
  std::vector<std::string> argv_prefix() const {
    return {"/usr/bin/nsenter", "--net=" + net_namespace(), "--"};
  }

  // The cable pulled (false) or plugged back (true): the second host's end
  // goes down, so this side loses its carrier and keeps its routes (its own
  // multicast still loops back to its own processes, as on a computer whose
  // cable is pulled).
  // (Down removes the second host's route over it; up puts it back.)
  void link(bool up) {
    there({"link", "set", "tg-there", up ? "up" : "down"});
    if (up) there({"route", "replace", "224.0.0.0/4", "dev", "tg-there"});
  }

 private:
  std::string net_namespace() const { return "/proc/" + std::to_string(holder_->pid()) + "/ns/net"; }

  static void ip(const std::vector<std::string>& arguments) {
    std::vector<std::string> argv{"/usr/sbin/ip"};
    argv.insert(argv.end(), arguments.begin(), arguments.end());
    std::string out, err;
    if (run_command("second-host-ip", argv, &out, &err) != 0) throw std::runtime_error("ip failed: " + err);
  }
  void there(const std::vector<std::string>& arguments) const {
    std::vector<std::string> argv = argv_prefix();
    argv.push_back("/usr/sbin/ip");
    argv.insert(argv.end(), arguments.begin(), arguments.end());
    std::string out, err;
    if (run_command("second-host-ip", argv, &out, &err) != 0) {
      throw std::runtime_error("ip on the second host failed: " + err);
    }
  }

  std::unique_ptr<Subprocess> holder_;
};

}  // namespace tofguard::test
