// tofguard-judge-campaign: the detection and false-stop figures (docs/safety-chain.md,
// "Measured"; docs/detection.md): the judgement run in-process on simulated
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
//                           [--imperfect-cameras N] [--camera-seeds 2,4]
//                           [--commission-s SECONDS] [--fault-camera ID]
//                           [--occluder-before ID] [--occluder-cm CM] [--camera-alone ID]
//                           [--second-camera-deg DEG]
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
// --imperfect-cameras: each arm (and variant) watched by N cameras as
// imperfect as real ones (draw_imperfect_camera(1..N)), each commissioned
// first (commissioned_camera.hpp), instead of the config's ideal camera;
// --camera-seeds: those of the draws only (a camera of a campaign again);
// --commission-s: how long its learning recording is, the check recording
// three times that (default 40 s and 120 s: a
// 12 s recording kept the Kinova Gen3 farther from camera 5 than its motion
// later goes, and commissioning refuses such a profile).
// --fault-camera: with several cameras (--arms two-cameras), the camera
// faults (pose, frozen image, stall) in camera ID (default: the first).
// --occluder-before: in every run, from its first frame, a still cube of
// --occluder-cm (default 6) edge 0.2 m before camera ID on its optical axis
// (a harmless object hiding part of that camera's view of the arm).
// --camera-alone: a deployment of several cameras judged as one of camera
// ID alone (the matched comparison: the same runs, poses and noise).
// --second-camera-deg: each arm of one camera watched by a second one as
// well, its camera turned by DEG about the vertical through the robot's
// root (its id the first's with "-2").
// --tsv: every run, a line each (campaign_tsv); --plots: detection rate and
// latency against magnitude per fault kind (plot_campaign), of this
// campaign's runs or, with --plots-from FILE, of the runs in FILE (a TSV
// written by --tsv) without running any.
//
// Prints a markdown table per arm, rate and placement (and every run that
// missed a target).
#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <iterator>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "commissioned_camera.hpp"
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
         "[--turns-deg 0,40] [--shared DIR] [--tsv FILE] [--plots DIR] [--plots-from FILE] "
         "[--imperfect-cameras N] [--camera-seeds 2,4] [--commission-s SECONDS] [--fault-camera ID] "
         "[--occluder-before ID] [--occluder-cm CM] "
         "[--camera-alone ID] [--second-camera-deg DEG]\n";
  return 2;
}

// The command line's choices.
struct Options {
  std::vector<std::string> arms = {"default", "iiwa14", "kinova"};
  tofguard::test::FaultMagnitudes magnitudes{{3, 5, 10}, {2, 3}, {1}};
  double nominal_s = 0;
  double passers_s = 0;
  int streams = 0;
  bool faults = true;
  std::vector<double> objects_m;
  double beyond_m = 0.1;
  std::vector<double> rates_hz;
  std::vector<double> turns_deg = {0};
  std::string fault_camera;     // "": the first
  std::string occluder_camera;  // "": no occluder
  double occluder_m = 0.06;
  std::string camera_alone;  // "": every camera
  std::optional<double> second_camera_deg;
  std::string tsv_path;
  std::string plots_dir;
  std::string plots_from;
  std::string shared = tofguard::test::shared_dir();
  // The imperfect cameras' draws (draw_imperfect_camera's seeds); none:
  // the config's ideal camera.
  std::vector<int> camera_seeds;
  double commission_s = 40;
};

// A value that is a number but not one the option takes: its own message.
struct OptionError : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

// Option `option`'s value into *o; false for an unknown option. Throws
// for a value that is not a number (list), OptionError for one out of range.
bool set_option(const std::string& option, const std::string& value, Options* o) {
  using namespace tofguard::test;
  if (option == "--arms") {
    o->arms = split_list(value);
  } else if (option == "--offsets-deg") {
    o->magnitudes.joint_offsets_deg = number_list(value);
  } else if (option == "--camera-cm") {
    o->magnitudes.camera_translations_cm = number_list(value);
  } else if (option == "--camera-deg") {
    o->magnitudes.camera_rotations_deg = number_list(value);
  } else if (option == "--streams") {
    o->streams = std::stoi(value);
  } else if (option == "--nominal-s") {
    o->nominal_s = std::stod(value);
  } else if (option == "--passers-s") {
    o->passers_s = std::stod(value);
  } else if (option == "--objects-cm") {
    for (double cm : number_list(value)) o->objects_m.push_back(cm / 100);
  } else if (option == "--beyond-cm") {
    o->beyond_m = std::stod(value) / 100;
  } else if (option == "--rates-hz") {
    o->rates_hz = number_list(value);
  } else if (option == "--turns-deg") {
    o->turns_deg = number_list(value);
  } else if (option == "--shared") {
    o->shared = value;
  } else if (option == "--imperfect-cameras") {
    o->camera_seeds.clear();
    for (int seed = 1; seed <= static_cast<int>(number_list(value).at(0)); ++seed)
      o->camera_seeds.push_back(seed);
  } else if (option == "--camera-seeds") {
    o->camera_seeds.clear();
    for (double seed : number_list(value)) {
      if (!(seed >= 1) || seed != static_cast<int>(seed))
        throw OptionError("--camera-seeds: expected whole numbers >= 1, got '" + value + "'");
      o->camera_seeds.push_back(static_cast<int>(seed));
    }
  } else if (option == "--commission-s") {
    o->commission_s = number_list(value).at(0);
  } else if (option == "--fault-camera") {
    o->fault_camera = value;
  } else if (option == "--occluder-before") {
    o->occluder_camera = value;
  } else if (option == "--occluder-cm") {
    o->occluder_m = std::stod(value) / 100;
  } else if (option == "--camera-alone") {
    o->camera_alone = value;
  } else if (option == "--second-camera-deg") {
    o->second_camera_deg = std::stod(value);
  } else if (option == "--tsv") {
    o->tsv_path = value;
  } else if (option == "--plots") {
    o->plots_dir = value;
  } else if (option == "--plots-from") {
    o->plots_from = value;
  } else {
    return false;
  }
  return true;
}

// The command line into *o; the exit code (usage) when it is wrong.
std::optional<int> parse_options(int argc, char** argv, Options* o) {
  for (int i = 1; i < argc; ++i) {
    const std::string option = argv[i];
    if (option == "--no-faults") {
      o->faults = false;
      continue;
    }
    if (i + 1 >= argc) return usage(option + ": expected a value");
    const std::string value = argv[++i];
    try {
      if (!set_option(option, value, o)) return usage("unknown option " + option);
    } catch (const OptionError& e) {
      return usage(e.what());
    } catch (const std::exception&) {
      return usage(option + ": expected a number list or a number, got '" + value + "'");
    }
  }
  return std::nullopt;
}

// --plots-from: the plots of the runs in a TSV file, without running any.
int plot_from_file(const Options& o) {
  if (o.plots_dir.empty()) return usage("--plots-from: needs --plots DIR");
  std::ifstream in(o.plots_from);
  if (!in) return usage("--plots-from: cannot read '" + o.plots_from + "'");
  const std::string tsv((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  try {
    for (const std::string& path : tofguard::test::plot_campaign(tsv, o.plots_dir))
      std::cout << "plot: " << path << "\n";
  } catch (const std::exception& e) {
    std::cerr << "tofguard-judge-campaign: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

// Each camera placement (--turns-deg) of `base` at each camera rate
// (--rates-hz; none: the config's).
std::vector<tofguard::test::CampaignArm> variants_of(const tofguard::test::CampaignArm& base,
                                                     const Options& o) {
  using namespace tofguard::test;
  std::vector<CampaignArm> variants;
  for (double turn : o.turns_deg) {
    const CampaignArm placed = turn == 0 ? base : with_camera_turned(base, turn);
    if (o.rates_hz.empty()) variants.push_back(placed);
    for (double rate : o.rates_hz) variants.push_back(with_camera_rate(placed, rate));
  }
  return variants;
}

// The index of camera `id` in `arm`'s cameras (for `option`'s error).
size_t camera_index(const tofguard::test::CampaignArm& arm, const std::string& id,
                    const std::string& option) {
  const auto& cameras = arm.config.cameras;
  const auto at =
      std::find_if(cameras.begin(), cameras.end(), [&](const auto& camera) { return camera.id == id; });
  if (at == cameras.end()) throw std::runtime_error(option + ": " + arm.name + " has no camera '" + id + "'");
  return static_cast<size_t>(at - cameras.begin());
}

// The runs the options ask for on `arm`.
std::vector<tofguard::test::CampaignRun> runs_for(const tofguard::test::CampaignArm& arm, const Options& o) {
  using namespace tofguard::test;
  std::vector<CampaignRun> runs;
  auto append = [&runs](const std::vector<CampaignRun>& more) {
    runs.insert(runs.end(), more.begin(), more.end());
  };
  if (o.faults) append(fault_runs(arm, o.magnitudes));
  if (o.streams > 0) append(stream_fault_runs(o.streams));
  if (o.nominal_s > 0) append(nominal_runs(o.nominal_s, 60, arm.config.camera.rate_hz, 7));
  if (o.passers_s > 0) append(passer_runs(arm, o.passers_s, 9000));
  if (!o.objects_m.empty()) append(object_runs(arm, o.objects_m, o.beyond_m));
  if (!o.fault_camera.empty()) {
    const size_t camera = camera_index(arm, o.fault_camera, "--fault-camera");
    for (CampaignRun& run : runs) run.fault.camera = camera;
  }
  return runs;
}

// The runs the options ask for on `arm`, with the occluder before camera
// --occluder-before of `scene` (the arm before --camera-alone took its
// other cameras away).
std::vector<tofguard::test::CampaignRun> runs_for(const tofguard::test::CampaignArm& arm,
                                                  const tofguard::test::CampaignArm& scene,
                                                  const Options& o) {
  using namespace tofguard::test;
  std::vector<CampaignRun> runs = runs_for(arm, o);
  if (!o.occluder_camera.empty()) {
    const Eigen::Vector3d centre_m = occluder_before(scene, o.occluder_camera, 0.2);
    for (CampaignRun& run : runs) {
      run.occluder_size_m = o.occluder_m;
      run.occluder_centre_m = centre_m;
    }
  }
  return runs;
}

// Runs `arm`'s campaign, prints its report(s) and adds its runs to *tsv.
// `scene`: the arm before --camera-alone (the occluder's camera is in it).
void run_arm(const tofguard::test::CampaignArm& arm, const tofguard::test::CampaignArm& scene,
             const Options& o, std::string* tsv) {
  using namespace tofguard::test;
  const std::vector<CampaignResult> results = run_campaign(arm, runs_for(arm, scene, o));
  std::cout << campaign_report(arm.name, results, 1.0 / arm.config.camera.rate_hz) << "\n";
  if (!o.objects_m.empty() || o.passers_s > 0)
    std::cout << object_report(arm.name, results, arm.config) << "\n";
  std::cout << std::flush;
  *tsv += campaign_tsv(arm.name, results, tsv->empty());
}

// The campaign on every arm asked for, then the TSV and the plots; the
// exit code.
int run_campaigns(const Options& o) {
  using namespace tofguard::test;
  const std::string scene_dir = output_dir() + "/judge_campaign";
  std::string tsv;
  try {
    for (const std::string& name : o.arms) {
      std::optional<CampaignArm> base;
      if (name == "default") {
        base = default_campaign_arm();
      } else if (name == "two-cameras") {
        base = two_camera_campaign_arm();
      } else if (name == "iiwa14") {
        base = iiwa14_campaign_arm(o.shared, scene_dir);
      } else if (name == "kinova") {
        base = kinova_gen3_campaign_arm(o.shared, scene_dir);
      } else {
        return usage("--arms: expected default, two-cameras, iiwa14 or kinova, got '" + name + "'");
      }
      if (!base) {
        std::cout << name << ": skipped, its URDF is not under " << o.shared << "/robots\n";
        continue;
      }
      if (o.second_camera_deg) base = with_second_camera(*base, *o.second_camera_deg);
      for (const CampaignArm& arm : variants_of(*base, o)) {
        if (o.camera_seeds.empty()) {
          run_arm(o.camera_alone.empty() ? arm : camera_alone(arm, o.camera_alone), arm, o, &tsv);
          continue;
        }
        for (int seed : o.camera_seeds) {
          const CommissionedCamera camera =
              commission_imperfect_camera(arm, static_cast<uint64_t>(seed), o.commission_s);
          if (!camera.ok) {
            std::cout << arm.name << " camera " << seed << ": commissioning refused: " << camera.error
                      << "\n";
            continue;
          }
          std::cout << camera.summary << "\n";
          run_arm(camera.arm, camera.arm, o, &tsv);
        }
      }
    }
    if (!o.tsv_path.empty()) {
      std::ofstream out(o.tsv_path);
      out << tsv;
      if (!out) throw std::runtime_error(o.tsv_path + ": cannot write the runs");
    }
    if (!o.plots_dir.empty())
      for (const std::string& path : plot_campaign(tsv, o.plots_dir)) std::cout << "plot: " << path << "\n";
  } catch (const std::exception& e) {
    std::cerr << "tofguard-judge-campaign: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  if (const std::optional<int> rc = parse_options(argc, argv, &options)) return *rc;
  if (!options.plots_from.empty()) return plot_from_file(options);
  return run_campaigns(options);
}
