#include "tofguard/renderer/render_cli.hpp"

#include <cmath>
#include <sstream>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "tofguard/renderer/depth_renderer.hpp"

namespace tofguard::renderer {
namespace {

class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

std::vector<double> parse_numbers(const std::string& option, const std::string& text, size_t count) {
  std::vector<double> values;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    size_t used = 0;
    double value = 0;
    try {
      value = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() || !std::isfinite(value)) {
      throw UsageError(option + ": '" + item + "' is not a number");
    }
    values.push_back(value);
  }
  if (values.size() != count) {
    throw UsageError(option + ": expected " + std::to_string(count) + " comma-separated numbers, got '" +
                     text + "'");
  }
  return values;
}

int whole(const std::string& option, double value) {
  if (value != std::floor(value) || value < 1 || value > 100000) {
    throw UsageError(option + ": width and height must be positive whole numbers");
  }
  return static_cast<int>(value);
}

}  // namespace

std::string render_cli_usage() {
  return "usage: tofguard-renderer render --urdf ROBOT.urdf [--env ENV.urdf ...] [--geometry "
         "visual|collision]\n"
         "         [--padding METRES] [--simplify-error-mm MM] [--package-path DIR ...] [--joint NAME=VALUE "
         "...]\n"
         "         --camera-pose x,y,z,qw,qx,qy,qz [--frame LINK] --intrinsics W,H,fx,fy,cx,cy\n"
         "         [--near METRES] [--far METRES] --out DEPTH.png [--labels LABELS.png]\n"
         "Renders the model once. The camera pose is the optical frame's (x right, y down, z forward)\n"
         "in LINK (default: the robot's root link), metres and a unit quaternion. Joint values in\n"
         "radians or metres. DEPTH.png: 16-bit Z in millimetres, 0 = nothing. LABELS.png: 16-bit\n"
         "labels, 0 = nothing, 1.. robot links, 1000.. environment links. Meshes are exact unless\n"
         "--simplify-error-mm is given (as renderer.simplify_error_mm in the config).\n";
}

int run_render_cli(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  std::string robot_urdf, out_path, labels_path, frame;
  std::vector<std::string> environment_urdfs;
  robot_model::SceneOptions options;
  robot_model::JointPositions joints;
  CameraPose pose;
  Intrinsics intrinsics;
  bool have_pose = false, have_intrinsics = false;
  double near_m = 0.1, far_m = 8.0;
  try {
    for (size_t i = 0; i < args.size(); ++i) {
      const std::string& option = args[i];
      if (option == "--help" || option == "-h") {
        out << render_cli_usage();
        return 0;
      }
      if (i + 1 >= args.size()) throw UsageError(option + ": needs a value");
      const std::string& value = args[++i];
      if (option == "--urdf") {
        robot_urdf = value;
      } else if (option == "--env") {
        environment_urdfs.push_back(value);
      } else if (option == "--geometry") {
        options.geometry = robot_model::parse_geometry_source(value);
      } else if (option == "--padding") {
        options.padding_m = parse_numbers(option, value, 1)[0];
      } else if (option == "--simplify-error-mm") {
        options.simplify_error_m = parse_numbers(option, value, 1)[0] / 1000.0;
      } else if (option == "--package-path") {
        options.package_paths.push_back(value);
      } else if (option == "--joint") {
        const size_t equals = value.find('=');
        if (equals == std::string::npos || equals == 0)
          throw UsageError("--joint: expected NAME=VALUE, got '" + value + "'");
        joints[value.substr(0, equals)] = parse_numbers(option, value.substr(equals + 1), 1)[0];
      } else if (option == "--camera-pose") {
        const std::vector<double> v = parse_numbers(option, value, 7);
        pose.translation_m = Eigen::Vector3d(v[0], v[1], v[2]);
        pose.rotation = Eigen::Quaterniond(v[3], v[4], v[5], v[6]);
        have_pose = true;
      } else if (option == "--frame") {
        frame = value;
      } else if (option == "--intrinsics") {
        const std::vector<double> v = parse_numbers(option, value, 6);
        intrinsics = {whole(option, v[0]), whole(option, v[1]), v[2], v[3], v[4], v[5]};
        have_intrinsics = true;
      } else if (option == "--near") {
        near_m = parse_numbers(option, value, 1)[0];
      } else if (option == "--far") {
        far_m = parse_numbers(option, value, 1)[0];
      } else if (option == "--out") {
        out_path = value;
      } else if (option == "--labels") {
        labels_path = value;
      } else {
        throw UsageError("unknown option '" + option + "'");
      }
    }
    if (robot_urdf.empty()) throw UsageError("--urdf is required");
    if (!have_pose) throw UsageError("--camera-pose is required");
    if (!have_intrinsics) throw UsageError("--intrinsics is required");
    if (out_path.empty()) throw UsageError("--out is required");
    if (const auto v = intrinsics.check()) throw UsageError("--intrinsics: " + v->line());
    if (!(near_m > 0 && far_m > near_m)) throw UsageError("need 0 < --near < --far");
  } catch (const UsageError& e) {
    err << "tofguard-renderer render: " << e.what() << "\n" << render_cli_usage();
    return 2;
  } catch (const robot_model::ModelError& e) {  // --geometry
    err << "tofguard-renderer render: " << e.what() << "\n";
    return 2;
  }

  try {
    const robot_model::SceneModel scene = robot_model::load_scene(robot_urdf, environment_urdfs, options);
    pose.frame_id = frame.empty() ? scene.links.front().name : frame;
    DepthRenderer renderer(scene, near_m, far_m);
    const RenderResult result = renderer.render(joints, pose, intrinsics);
    if (!result.usable) {
      err << "tofguard-renderer render: frame unusable: " << result.unusable_reason << "\n";
      return 1;
    }
    cv::Mat depth_mm(result.height, result.width, CV_16UC1);
    cv::Mat labels(result.height, result.width, CV_16UC1);
    int robot_pixels = 0, environment_pixels = 0;
    for (int v = 0; v < result.height; ++v) {
      for (int u = 0; u < result.width; ++u) {
        const size_t i = static_cast<size_t>(v) * result.width + u;
        const double mm = std::round(result.depth_m[i] * 1000.0);
        depth_mm.at<uint16_t>(v, u) = static_cast<uint16_t>(mm > 0 && mm <= 65535 ? mm : 0);
        labels.at<uint16_t>(v, u) = static_cast<uint16_t>(result.labels[i]);
        robot_pixels += is_robot_label(result.labels[i]);
        environment_pixels += is_environment_label(result.labels[i]);
      }
    }
    if (!cv::imwrite(out_path, depth_mm)) {
      err << "tofguard-renderer render: cannot write " << out_path << "\n";
      return 1;
    }
    if (!labels_path.empty() && !cv::imwrite(labels_path, labels)) {
      err << "tofguard-renderer render: cannot write " << labels_path << "\n";
      return 1;
    }
    out << "wrote " << out_path << (labels_path.empty() ? "" : " and " + labels_path) << ": " << result.width
        << "x" << result.height << ", " << robot_pixels << " robot pixels, " << environment_pixels
        << " environment pixels, " << scene.num_triangles() << " triangles (" << renderer.description()
        << ")\n";
    return 0;
  } catch (const std::exception& e) {
    err << "tofguard-renderer render: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace tofguard::renderer
