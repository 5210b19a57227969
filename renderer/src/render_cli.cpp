#include "tofguard/renderer/render_cli.hpp"

#include <cmath>
#include <optional>
#include <sstream>
#include <utility>

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

// What the command line asks to render.
struct RenderRequest {
  std::string robot_urdf, out_path, labels_path, frame;
  std::vector<std::string> environment_urdfs;
  robot_model::SceneOptions options;
  robot_model::JointPositions joints;
  CameraPose pose;
  Intrinsics intrinsics;
  bool have_pose = false, have_intrinsics = false;
  double near_m = 0.1, far_m = 8.0;
};

// Option `option`'s value into *r. Throws UsageError (or ModelError for
// --geometry).
void set_option(const std::string& option, const std::string& value, RenderRequest* r) {
  if (option == "--urdf") {
    r->robot_urdf = value;
  } else if (option == "--env") {
    r->environment_urdfs.push_back(value);
  } else if (option == "--geometry") {
    r->options.geometry = robot_model::parse_geometry_source(value);
  } else if (option == "--padding") {
    r->options.padding_m = parse_numbers(option, value, 1)[0];
  } else if (option == "--simplify-error-mm") {
    r->options.simplify_error_m = parse_numbers(option, value, 1)[0] / 1000.0;
  } else if (option == "--package-path") {
    r->options.package_paths.push_back(value);
  } else if (option == "--joint") {
    const size_t equals = value.find('=');
    if (equals == std::string::npos || equals == 0)
      throw UsageError("--joint: expected NAME=VALUE, got '" + value + "'");
    r->joints[value.substr(0, equals)] = parse_numbers(option, value.substr(equals + 1), 1)[0];
  } else if (option == "--camera-pose") {
    const std::vector<double> v = parse_numbers(option, value, 7);
    r->pose.translation_m = Eigen::Vector3d(v[0], v[1], v[2]);
    r->pose.rotation = Eigen::Quaterniond(v[3], v[4], v[5], v[6]);
    r->have_pose = true;
  } else if (option == "--frame") {
    r->frame = value;
  } else if (option == "--intrinsics") {
    const std::vector<double> v = parse_numbers(option, value, 6);
    r->intrinsics = {whole(option, v[0]), whole(option, v[1]), v[2], v[3], v[4], v[5]};
    r->have_intrinsics = true;
  } else if (option == "--near") {
    r->near_m = parse_numbers(option, value, 1)[0];
  } else if (option == "--far") {
    r->far_m = parse_numbers(option, value, 1)[0];
  } else if (option == "--out") {
    r->out_path = value;
  } else if (option == "--labels") {
    r->labels_path = value;
  } else {
    throw UsageError("unknown option '" + option + "'");
  }
}

// Throws UsageError for a request missing something or out of range.
void check_request(const RenderRequest& r) {
  if (r.robot_urdf.empty()) throw UsageError("--urdf is required");
  if (!r.have_pose) throw UsageError("--camera-pose is required");
  if (!r.have_intrinsics) throw UsageError("--intrinsics is required");
  if (r.out_path.empty()) throw UsageError("--out is required");
  if (const auto v = r.intrinsics.check()) throw UsageError("--intrinsics: " + v->line());
  if (!(r.near_m > 0 && r.far_m > r.near_m)) throw UsageError("need 0 < --near < --far");
}

// The command line into *r; the exit code when it is done (--help: 0) or
// wrong (2).
std::optional<int> parse_request(const std::vector<std::string>& args, std::ostream& out, std::ostream& err,
                                 RenderRequest* r) {
  try {
    for (size_t i = 0; i < args.size(); ++i) {
      const std::string& option = args[i];
      if (option == "--help" || option == "-h") {
        out << render_cli_usage();
        return 0;
      }
      if (i + 1 >= args.size()) throw UsageError(option + ": needs a value");
      set_option(option, args[++i], r);
    }
    check_request(*r);
  } catch (const UsageError& e) {
    err << "tofguard-renderer render: " << e.what() << "\n" << render_cli_usage();
    return 2;
  } catch (const robot_model::ModelError& e) {  // --geometry
    err << "tofguard-renderer render: " << e.what() << "\n";
    return 2;
  }
  return std::nullopt;
}

// A render as 16-bit PNG images, and its pixels counted.
struct RenderImages {
  cv::Mat depth_mm;  // Z in millimetres, 0 = nothing
  cv::Mat labels;
  int robot_pixels = 0, environment_pixels = 0;
};

RenderImages images_of(const RenderResult& result) {
  RenderImages images;
  images.depth_mm = cv::Mat(result.height, result.width, CV_16UC1);
  images.labels = cv::Mat(result.height, result.width, CV_16UC1);
  for (int v = 0; v < result.height; ++v) {
    for (int u = 0; u < result.width; ++u) {
      const size_t i = static_cast<size_t>(v) * result.width + u;
      const double mm = std::round(result.depth_m[i] * 1000.0);
      images.depth_mm.at<uint16_t>(v, u) = static_cast<uint16_t>(mm > 0 && mm <= 65535 ? mm : 0);
      images.labels.at<uint16_t>(v, u) = static_cast<uint16_t>(result.labels[i]);
      images.robot_pixels += is_robot_label(result.labels[i]);
      images.environment_pixels += is_environment_label(result.labels[i]);
    }
  }
  return images;
}

// Renders the request and writes its images; the exit code.
int render_and_write(RenderRequest r, std::ostream& out, std::ostream& err) {
  const robot_model::SceneModel scene = robot_model::load_scene(r.robot_urdf, r.environment_urdfs, r.options);
  r.pose.frame_id = r.frame.empty() ? scene.links.front().name : r.frame;
  DepthRenderer renderer(scene, r.near_m, r.far_m);
  const RenderResult result = renderer.render(r.joints, r.pose, r.intrinsics);
  if (!result.usable) {
    err << "tofguard-renderer render: frame unusable: " << result.unusable_reason << "\n";
    return 1;
  }
  const RenderImages images = images_of(result);
  if (!cv::imwrite(r.out_path, images.depth_mm)) {
    err << "tofguard-renderer render: cannot write " << r.out_path << "\n";
    return 1;
  }
  if (!r.labels_path.empty() && !cv::imwrite(r.labels_path, images.labels)) {
    err << "tofguard-renderer render: cannot write " << r.labels_path << "\n";
    return 1;
  }
  out << "wrote " << r.out_path << (r.labels_path.empty() ? "" : " and " + r.labels_path) << ": "
      << result.width << "x" << result.height << ", " << images.robot_pixels << " robot pixels, "
      << images.environment_pixels << " environment pixels, " << scene.num_triangles() << " triangles ("
      << renderer.description() << ")\n";
  return 0;
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
  RenderRequest request;
  if (const std::optional<int> rc = parse_request(args, out, err, &request)) return *rc;
  try {
    return render_and_write(std::move(request), out, err);
  } catch (const std::exception& e) {
    err << "tofguard-renderer render: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace tofguard::renderer
