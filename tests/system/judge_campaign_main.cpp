// tofguard-judge-campaign: issue 14's figures (docs/safety-chain.md,
// "Measured"): the judgement run in-process on simulated frames of the
// default arm, the iiwa14 and the Kinova Gen3 (../shared) with injected
// joint offsets and camera pose errors, and nominal frames for false stops.
//
//   tofguard-judge-campaign [--arms default,iiwa14,kinova] [--offsets-deg 3,5,10]
//                           [--nominal-s SECONDS] [--no-faults] [--shared DIR]
//                           [--objects-cm 5,10,20,40,80] [--beyond-cm 10]
//
// --objects-cm: issue 15's objects (object_runs): a 10 cm cube still at each
// distance from the arm, a hand approaching at K, a person and a cart
// walking past --beyond-cm beyond the warning field of the arm at rest.
//
// Prints a markdown table per arm (and every run that missed a target).
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "judge_campaign.hpp"
#include "test_support.hpp"

namespace {

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> parts;
  std::stringstream s(text);
  for (std::string part; std::getline(s, part, ',');)
    if (!part.empty()) parts.push_back(part);
  return parts;
}

int usage(const std::string& why) {
  std::cerr
      << "tofguard-judge-campaign: " << why
      << "\nusage: tofguard-judge-campaign [--arms default,iiwa14,kinova] [--offsets-deg 3,5,10] "
         "[--nominal-s SECONDS] [--no-faults] [--shared DIR] [--objects-cm 5,10,20,40,80] [--beyond-cm 10]\n";
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace tofguard::test;
  std::vector<std::string> arms = {"default", "iiwa14", "kinova"};
  std::vector<double> offsets_deg = {3, 5, 10};
  double nominal_s = 0;
  bool faults = true;
  std::vector<double> objects_m;
  double beyond_m = 0.1;
  std::string shared = shared_dir();
  for (int i = 1; i < argc; ++i) {
    const std::string option = argv[i];
    if (option == "--no-faults") {
      faults = false;
      continue;
    }
    if (i + 1 >= argc) return usage(option + ": expected a value");
    const std::string value = argv[++i];
    try {
      if (option == "--arms") {
        arms = split(value);
      } else if (option == "--offsets-deg") {
        offsets_deg.clear();
        for (const std::string& v : split(value)) offsets_deg.push_back(std::stod(v));
      } else if (option == "--nominal-s") {
        nominal_s = std::stod(value);
      } else if (option == "--objects-cm") {
        for (const std::string& v : split(value)) objects_m.push_back(std::stod(v) / 100);
      } else if (option == "--beyond-cm") {
        beyond_m = std::stod(value) / 100;
      } else if (option == "--shared") {
        shared = value;
      } else {
        return usage("unknown option " + option);
      }
    } catch (const std::exception&) {
      return usage(option + ": expected a number list or a number, got '" + value + "'");
    }
  }
  const std::string scene_dir = output_dir() + "/judge_campaign";
  try {
    for (const std::string& name : arms) {
      std::optional<CampaignArm> arm;
      if (name == "default") {
        arm = default_campaign_arm();
      } else if (name == "iiwa14") {
        arm = iiwa14_campaign_arm(shared, scene_dir);
      } else if (name == "kinova") {
        arm = kinova_gen3_campaign_arm(shared, scene_dir);
      } else {
        return usage("--arms: expected default, iiwa14 or kinova, got '" + name + "'");
      }
      if (!arm) {
        std::cout << name << ": skipped, its URDF is not under " << shared << "/robots\n";
        continue;
      }
      std::vector<CampaignRun> runs;
      if (faults) runs = standard_fault_runs(*arm, offsets_deg);
      if (nominal_s > 0) {
        const std::vector<CampaignRun> nominal = nominal_runs(nominal_s, 60, 7);
        runs.insert(runs.end(), nominal.begin(), nominal.end());
      }
      if (!objects_m.empty()) {
        const std::vector<CampaignRun> objects = object_runs(*arm, objects_m, beyond_m);
        runs.insert(runs.end(), objects.begin(), objects.end());
      }
      const std::vector<CampaignResult> results = run_campaign(*arm, runs);
      std::cout << campaign_report(arm->name, results, 1.0 / arm->config.camera.rate_hz) << "\n";
      if (!objects_m.empty()) std::cout << object_report(arm->name, results, arm->config) << "\n";
      std::cout << std::flush;
    }
  } catch (const std::exception& e) {
    std::cerr << "tofguard-judge-campaign: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
