// tofguard-judge-campaign: the detection and false-stop figures
// (docs/safety-chain.md, "Measured"; docs/detection.md): the judgement run in-process on simulated
// frames of the default arm, the iiwa14 and the Kinova Gen3 (../shared) with
// injected joint offsets, camera pose errors, objects, frozen and stalled
// streams, and nominal frames for false stops.
//
//   tofguard-judge-campaign [--arms default,iiwa14,kinova] [--offsets-deg 3,5,10]
//                           [--camera-cm 2,3] [--camera-deg 1] [--streams RUNS]
//                           [--nominal-s SECONDS] [--passers-s SECONDS] [--no-faults]
//                           [--objects-cm 5,10,20,40,80] [--beyond-cm 10]
//                           [--rates-hz 25,30] [--turns-deg 0,40] [--shared DIR]
//                           [--tsv FILE] [--plots DIR] [--plots-from FILE]
//
// --camera-cm / --camera-deg: the camera moved along / turned about each
// axis of its optical frame by each magnitude (fault_runs).
// --streams: that many runs each of a frozen camera image, a stalled camera
// stream and a stalled joint stream.
// --objects-cm: the unknown objects (object_runs): a 10 cm cube still at each
// distance from the arm, a hand approaching at K, a person and a cart
// walking past --beyond-cm beyond the warning field of the arm at rest.
// --passers-s: people and carts crossing 10 cm beyond the warning field,
// one after another, for that long (passer_runs), besides --nominal-s of
// the scene alone: the false-stop figure.
// --rates-hz: each arm at each camera rate (default: the config's).
// --turns-deg: each arm from each camera placement: its camera turned by
// that much about the vertical through the robot's root (default 0).
// --tsv: every run, a line each (campaign_tsv); --plots: detection rate and
// latency against magnitude per fault kind (plot_campaign), of this
// campaign's runs or, with --plots-from FILE, of the runs in FILE (a TSV
// written by --tsv) without running any.
//
// Prints a markdown table per arm, rate and placement (and every run that
// missed a target).
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>
#include <vector>

#include "judge_campaign.hpp"
#include "report_format.hpp"
#include "tool_support.hpp"

namespace {

int usage(const std::string& why) {
  std::cerr
      << "tofguard-judge-campaign: " << why
      << "\nusage: tofguard-judge-campaign [--arms default,iiwa14,kinova] [--offsets-deg 3,5,10] "
         "[--camera-cm 2,3] [--camera-deg 1] [--streams RUNS] [--nominal-s SECONDS] [--passers-s SECONDS] "
         "[--no-faults] [--objects-cm 5,10,20,40,80] [--beyond-cm 10] [--rates-hz 25,30] "
         "[--turns-deg 0,40] [--shared DIR] [--tsv FILE] [--plots DIR] [--plots-from FILE]\n";
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace tofguard::test;
  std::vector<std::string> arms = {"default", "iiwa14", "kinova"};
  FaultMagnitudes magnitudes{{3, 5, 10}, {2, 3}, {1}};
  double nominal_s = 0;
  double passers_s = 0;
  int streams = 0;
  bool faults = true;
  std::vector<double> objects_m;
  double beyond_m = 0.1;
  std::vector<double> rates_hz;
  std::vector<double> turns_deg = {0};
  std::string tsv_path;
  std::string plots_dir;
  std::string plots_from;
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
        arms = split_list(value);
      } else if (option == "--offsets-deg") {
        magnitudes.joint_offsets_deg = number_list(value);
      } else if (option == "--camera-cm") {
        magnitudes.camera_translations_cm = number_list(value);
      } else if (option == "--camera-deg") {
        magnitudes.camera_rotations_deg = number_list(value);
      } else if (option == "--streams") {
        streams = std::stoi(value);
      } else if (option == "--nominal-s") {
        nominal_s = std::stod(value);
      } else if (option == "--passers-s") {
        passers_s = std::stod(value);
      } else if (option == "--objects-cm") {
        for (double cm : number_list(value)) objects_m.push_back(cm / 100);
      } else if (option == "--beyond-cm") {
        beyond_m = std::stod(value) / 100;
      } else if (option == "--rates-hz") {
        rates_hz = number_list(value);
      } else if (option == "--turns-deg") {
        turns_deg = number_list(value);
      } else if (option == "--shared") {
        shared = value;
      } else if (option == "--tsv") {
        tsv_path = value;
      } else if (option == "--plots") {
        plots_dir = value;
      } else if (option == "--plots-from") {
        plots_from = value;
      } else {
        return usage("unknown option " + option);
      }
    } catch (const std::exception&) {
      return usage(option + ": expected a number list or a number, got '" + value + "'");
    }
  }
  if (!plots_from.empty()) {
    if (plots_dir.empty()) return usage("--plots-from: needs --plots DIR");
    std::ifstream in(plots_from);
    if (!in) return usage("--plots-from: cannot read '" + plots_from + "'");
    const std::string tsv((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    try {
      for (const std::string& path : plot_campaign(tsv, plots_dir)) std::cout << "plot: " << path << "\n";
    } catch (const std::exception& e) {
      std::cerr << "tofguard-judge-campaign: " << e.what() << "\n";
      return 1;
    }
    return 0;
  }
  const std::string scene_dir = output_dir() + "/judge_campaign";
  std::string tsv;
  try {
    for (const std::string& name : arms) {
      std::optional<CampaignArm> base;
      if (name == "default") {
        base = default_campaign_arm();
      } else if (name == "iiwa14") {
        base = iiwa14_campaign_arm(shared, scene_dir);
      } else if (name == "kinova") {
        base = kinova_gen3_campaign_arm(shared, scene_dir);
      } else {
        return usage("--arms: expected default, iiwa14 or kinova, got '" + name + "'");
      }
      if (!base) {
        std::cout << name << ": skipped, its URDF is not under " << shared << "/robots\n";
        continue;
      }
      std::vector<CampaignArm> variants;
      for (double turn : turns_deg) {
        const CampaignArm placed = turn == 0 ? *base : with_camera_turned(*base, turn);
        if (rates_hz.empty()) variants.push_back(placed);
        for (double rate : rates_hz) variants.push_back(with_camera_rate(placed, rate));
      }
      for (const CampaignArm& arm : variants) {
        std::vector<CampaignRun> runs;
        auto append = [&runs](const std::vector<CampaignRun>& more) {
          runs.insert(runs.end(), more.begin(), more.end());
        };
        if (faults) append(fault_runs(arm, magnitudes));
        if (streams > 0) append(stream_fault_runs(streams));
        if (nominal_s > 0) append(nominal_runs(nominal_s, 60, arm.config.camera.rate_hz, 7));
        if (passers_s > 0) append(passer_runs(arm, passers_s, 9000));
        if (!objects_m.empty()) append(object_runs(arm, objects_m, beyond_m));
        const std::vector<CampaignResult> results = run_campaign(arm, runs);
        std::cout << campaign_report(arm.name, results, 1.0 / arm.config.camera.rate_hz) << "\n";
        if (!objects_m.empty() || passers_s > 0)
          std::cout << object_report(arm.name, results, arm.config) << "\n";
        std::cout << std::flush;
        tsv += campaign_tsv(arm.name, results, tsv.empty());
      }
    }
    if (!tsv_path.empty()) {
      std::ofstream out(tsv_path);
      out << tsv;
      if (!out) throw std::runtime_error(tsv_path + ": cannot write the runs");
    }
    if (!plots_dir.empty())
      for (const std::string& path : plot_campaign(tsv, plots_dir)) std::cout << "plot: " << path << "\n";
  } catch (const std::exception& e) {
    std::cerr << "tofguard-judge-campaign: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
