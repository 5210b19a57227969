#include "tofguard/estimator/motion_estimator.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include <Eigen/Cholesky>
#include <opencv2/imgproc.hpp>

#include "tofguard/common/camera_geometry.hpp"
#include "tofguard/common/depth_frame.hpp"

namespace tofguard::estimator {

using robot_model::JointType;

// The current estimate: joint offsets (added to each frame's reported
// positions, actuated order) and the camera correction.
struct MotionEstimator::State {
  std::vector<double> joint_offsets;
  // Added to the measured depth of the robot's surfaces, metres along Z.
  double robot_depth_offset_m = 0;
  Eigen::Isometry3d correction = Eigen::Isometry3d::Identity();
};

// Parameters after the joints: camera translation (3), camera rotation (3)
// (a twist in the seen optical frame), and the robot's depth offset (1).
constexpr int kExtraParams = 7;

// Normal equations of one iteration, parameters ordered [joints...,
// kExtraParams].
struct MotionEstimator::Linearization {
  Eigen::MatrixXd hessian;
  Eigen::VectorXd gradient;
  double weighted_sq = 0;
  int num_points = 0;
  int num_inliers = 0;
  // Inliers on links each joint moves.
  std::vector<int> joint_points;
  double clipped_sq = 0;
  // Contour residuals, and those inside the robust scale.
  int num_contour_points = 0;
  int num_contour_inliers = 0;

  // Residual rows not yet in the normal equations (row-major, one row of
  // num_joints + kExtraParams per residual), their weights and values:
  // folded in by one matrix product (flush), much faster than a rank-1
  // update per residual.
  std::vector<double> pending_rows;
  std::vector<double> pending_weights;
  std::vector<double> pending_residuals;

  // Residuals that move no joint touch only the kExtraParams (camera and
  // depth offset): most of the image (the environment), so they go into a
  // small fixed-size block.
  using StaticRow = Eigen::Matrix<double, kExtraParams, 1>;
  Eigen::Matrix<double, kExtraParams, kExtraParams> static_hessian = Eigen::Matrix<double, 7, 7>::Zero();
  StaticRow static_gradient = StaticRow::Zero();
  void add_static(const StaticRow& row, double weight, double residual) {
    static_hessian.noalias() += (weight * row) * row.transpose();
    static_gradient += (weight * residual) * row;
    weighted_sq += weight * residual * residual;
  }

  // A zeroed row for one more residual.
  double* add_row(double weight, double residual) {
    const size_t width = static_cast<size_t>(gradient.size());
    pending_rows.resize(pending_rows.size() + width, 0.0);
    pending_weights.push_back(weight);
    pending_residuals.push_back(residual);
    return pending_rows.data() + pending_rows.size() - width;
  }
  void flush() {
    const int first_static = static_cast<int>(gradient.size()) - kExtraParams;
    hessian.block<kExtraParams, kExtraParams>(first_static, first_static) += static_hessian;
    gradient.segment<kExtraParams>(first_static) += static_gradient;
    static_hessian.setZero();
    static_gradient.setZero();
    const Eigen::Index count = static_cast<Eigen::Index>(pending_weights.size());
    if (count == 0) return;
    using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
    const Eigen::Map<const RowMajor> rows(pending_rows.data(), count, gradient.size());
    const Eigen::Map<const Eigen::VectorXd> w(pending_weights.data(), count);
    const Eigen::Map<const Eigen::VectorXd> r(pending_residuals.data(), count);
    const Eigen::MatrixXd weighted_transpose = rows.transpose() * w.asDiagonal();
    hessian.noalias() += weighted_transpose * rows;
    gradient.noalias() += weighted_transpose * r;
    weighted_sq += (w.array() * r.array().square()).sum();
    pending_rows.clear();
    pending_weights.clear();
    pending_residuals.clear();
  }

  void reset(int num_joints) {
    pending_rows.clear();
    pending_weights.clear();
    pending_residuals.clear();
    static_hessian.setZero();
    static_gradient.setZero();
    hessian = Eigen::MatrixXd::Zero(num_joints + kExtraParams, num_joints + kExtraParams);
    gradient = Eigen::VectorXd::Zero(num_joints + kExtraParams);
    weighted_sq = 0;
    num_points = 0;
    num_inliers = 0;
    joint_points.assign(num_joints, 0);
    clipped_sq = 0;
    num_contour_points = 0;
    num_contour_inliers = 0;
  }
  double clipped_rms_m() const { return num_points > 0 ? std::sqrt(clipped_sq / num_points) : 0.0; }
};

// A rendered robot point, for the joint search.
struct MotionEstimator::Sample {
  int link;
  Eigen::Vector3d world;
};

namespace {

// The joint search scores at most about this many distal points per joint.
constexpr size_t kSearchPoints = 500;

// The joint search's offsets (rad): every step within +-range, 0 left out.
std::vector<double> search_grid(double range_rad, double step_rad) {
  std::vector<double> grid;
  const int steps = static_cast<int>(std::floor(range_rad / step_rad));
  for (int s = -steps; s <= steps; ++s) {
    if (s != 0) grid.push_back(s * step_rad);
  }
  return grid;
}

// A robust scale level past the end of any schedule (the final scale).
constexpr int kFinalLevel = 1000;

int64_t now_us() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

EstimateResult unusable_result(const std::string& why, int64_t start_us) {
  EstimateResult result;
  result.usable = false;
  result.unusable_reason = why;
  result.compute_us = now_us() - start_us;
  return result;
}

bool finite(const Eigen::Isometry3d& pose) { return pose.matrix().allFinite(); }

// exp of a small twist (translation v, rotation w about the axes of the
// frame it is applied in, on the right).
Eigen::Isometry3d twist_exp(const Eigen::Vector3d& v, const Eigen::Vector3d& w) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  const double angle = w.norm();
  if (angle > 0) t.linear() = Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
  t.translation() = v;
  return t;
}

}  // namespace

double correction_angle_rad(const EstimateResult& result) {
  return Eigen::AngleAxisd(result.correction.linear()).angle();
}

MotionEstimator::MotionEstimator(const robot_model::SceneModel& scene, renderer::DepthRenderer* renderer,
                                 const EstimatorOptions& options, std::vector<renderer::ExtraObject> occupant)
    : scene_(scene), renderer_(renderer), occupant_(std::move(occupant)), options_(options) {
  if (renderer_ == nullptr) throw std::invalid_argument("MotionEstimator: renderer is null");
  const EstimatorOptions& o = options_;
  if (o.pixel_stride < 1 || !(o.final_robust_scale_m > 0) ||
      !(o.initial_robust_scale_m >= o.final_robust_scale_m) ||
      !(o.robust_scale_factor > 0 && o.robust_scale_factor < 1) || !(o.gate_scales >= 1) ||
      o.max_iterations < 1 || !(o.final_damping >= 0) || o.max_working_pixels < 64 ||
      o.coarse_pixel_stride < 1 || !(o.coarse_skip_step >= 0) || o.max_camera_iterations < 1 ||
      !(o.step_tolerance > 0) || !(o.joint_search_step_rad > 0) || !(o.joint_search_range_rad >= 0) ||
      o.joint_search_rounds < 0 || o.min_joint_points < 1 || !(o.max_joint_sigma > 0) ||
      !(o.sigma_scale > 0) || !(o.residual_clip_m > 0) || !(o.noise.sigma_at_0m_mm > 0) ||
      !(o.model_sigma_m >= 0) || !(o.noise.sigma_per_m2_mm >= 0) || !(o.normal_jump_m > 0) ||
      !(o.contour_jump_fraction > 0) || !(o.final_contour_scale_px > 0) || !(o.contour_sigma_px > 0)) {
    throw std::invalid_argument("MotionEstimator: options out of range");
  }
  num_params_ = static_cast<int>(scene_.actuated_joint_names.size());
  std::map<std::string, int> param_of;
  for (int k = 0; k < num_params_; ++k) param_of[scene_.actuated_joint_names[k]] = k;
  chains_.resize(scene_.links.size());
  for (size_t l = 0; l < scene_.links.size(); ++l) {
    int joint_index = scene_.links[l].parent_joint;
    while (joint_index >= 0) {
      const robot_model::Joint& joint = scene_.joints[joint_index];
      if (joint.type != JointType::kFixed) {
        // A mimic joint moves with its leader: d(value)/d(leader) is the
        // product of the multipliers down the mimic chain.
        double multiplier = 1;
        int leader = joint_index;
        while (scene_.joints[leader].mimic_joint >= 0) {
          multiplier *= scene_.joints[leader].mimic_multiplier;
          leader = scene_.joints[leader].mimic_joint;
        }
        const auto found = param_of.find(scene_.joints[leader].name);
        if (found != param_of.end()) chains_[l].push_back({joint_index, found->second, multiplier});
      }
      joint_index = scene_.links[joint.parent_link].parent_joint;
    }
  }
}

std::string MotionEstimator::check_frame(const EstimatorFrame& frame) const {
  if (const auto v = frame.intrinsics.check()) return "intrinsics: " + v->line();
  const size_t pixels = static_cast<size_t>(frame.intrinsics.width) * frame.intrinsics.height;
  if (frame.depth_m.size() != pixels) {
    return "depth image: expected " + std::to_string(pixels) + " pixels, got " +
           std::to_string(frame.depth_m.size());
  }
  for (const std::string& name : scene_.actuated_joint_names) {
    const auto found = frame.reported_joints.find(name);
    if (found == frame.reported_joints.end()) return "joint '" + name + "' missing from the joint state";
    if (!std::isfinite(found->second)) return "joint '" + name + "' is not a finite number";
  }
  if (!finite(frame.world_from_optical)) return "camera pose is not finite";
  return "";
}

namespace {

robot_model::JointPositions joints_at(const robot_model::SceneModel& scene, const EstimatorFrame& frame,
                                      const std::vector<double>& offsets) {
  robot_model::JointPositions joints = frame.reported_joints;
  for (size_t k = 0; k < offsets.size(); ++k) joints[scene.actuated_joint_names[k]] += offsets[k];
  return joints;
}

struct JointAxis {
  Eigen::Vector3d axis_world;
  Eigen::Vector3d origin_world;
};

std::vector<JointAxis> joint_axes(const robot_model::SceneModel& scene, const robot_model::LinkPoses& poses) {
  std::vector<JointAxis> axes(scene.joints.size());
  for (size_t j = 0; j < scene.joints.size(); ++j) {
    const robot_model::Joint& joint = scene.joints[j];
    const Eigen::Isometry3d world_from_joint =
        poses.world_from_link[joint.parent_link] * joint.parent_from_joint;
    axes[j].axis_world = world_from_joint.linear() * joint.axis;
    axes[j].origin_world = world_from_joint.translation();
  }
  return axes;
}

}  // namespace

const MotionEstimator::MeasuredEdges& MotionEstimator::edges_of(const EstimatorFrame& frame) {
  const auto found = edges_.find(frame.depth_m.data());
  if (found != edges_.end()) return found->second;
  const int width = frame.intrinsics.width;
  const int height = frame.intrinsics.height;
  // Occluding contours: the near side of a depth step between two valid
  // pixels.
  cv::Mat not_edge(height, width, CV_8U, cv::Scalar(255));
  std::vector<int> edge_pixels;
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const size_t i = static_cast<size_t>(v) * width + u;
      const float z = frame.depth_m[i];
      if (!(z > 0) || !std::isfinite(z)) continue;
      const float jump = static_cast<float>(options_.contour_jump_fraction) * z;
      bool edge = false;
      auto farther = [&](size_t j) {
        const float zj = frame.depth_m[j];
        return zj > 0 && std::isfinite(zj) && zj - z > jump;
      };
      if (u > 0) edge = edge || farther(i - 1);
      if (u + 1 < width) edge = edge || farther(i + 1);
      if (v > 0) edge = edge || farther(i - width);
      if (v + 1 < height) edge = edge || farther(i + width);
      if (edge) not_edge.at<uint8_t>(v, u) = 0;
    }
  }
  MeasuredEdges& edges = edges_[frame.depth_m.data()];
  edges.nearest.assign(frame.depth_m.size(), -1);
  if (cv::countNonZero(not_edge) == static_cast<int>(frame.depth_m.size())) return edges;
  cv::Mat distance, labels;
  cv::distanceTransform(not_edge, distance, labels, cv::DIST_L2, cv::DIST_MASK_5, cv::DIST_LABEL_PIXEL);
  // Each edge pixel carries its own label.
  std::map<int, int> pixel_of_label;
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      if (not_edge.at<uint8_t>(v, u) == 0) pixel_of_label[labels.at<int>(v, u)] = v * width + u;
    }
  }
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const auto p = pixel_of_label.find(labels.at<int>(v, u));
      if (p != pixel_of_label.end()) edges.nearest[static_cast<size_t>(v) * width + u] = p->second;
    }
  }
  return edges;
}

// What the contour and depth terms of one frame rendered at one state
// share: the rendered images, the joint axes and the camera pose at that
// state, the measured contours, and the robust scales of this stage.
struct MotionEstimator::RenderedView {
  const EstimatorFrame& frame;
  const State& state;
  const renderer::RenderResult& rendered;
  const MeasuredEdges& edges;
  std::vector<JointAxis> axes;  // per scene joint, world frame
  Eigen::Isometry3d world_from_optical;
  Eigen::Matrix3d optical_from_world_rotation;
  double scale;  // robust (Tukey) scale of the depth term, m
  int stride;    // depth term on every stride-th pixel
  bool joints_free;
  double gate;              // |z_model - z_measured| beyond this is an outlier, m
  double clip;              // residuals clipped here in clipped_sq, m
  double sigma_1m;          // noise sigma at 1 m, m
  double contour_scale_px;  // robust scale of the contour term, px
  double contour_weight;    // contour px^2 in units of depth m^2

  // The optical-frame point (m) of pixel (u, v) at depth z (m).
  Eigen::Vector3d back_project(int u, int v, double z) const {
    return optical_point_m(frame.intrinsics, u, v, z);
  }
};

void MotionEstimator::add_residual(const RenderedView& view, const std::vector<ChainJoint>& chain,
                                   const Eigen::Vector3d& m, const Eigen::Vector3d& world,
                                   const Eigen::Vector3d& g, double residual, double weight,
                                   bool count_joint_points, double d_depth_offset, Linearization* lin) const {
  const int n = num_params_;
  const Eigen::Vector3d g_cross_m = g.cross(m);
  if (chain.empty() || !view.joints_free) {
    Linearization::StaticRow row;
    row << -g, g_cross_m, d_depth_offset;
    lin->add_static(row, weight, residual);
    return;
  }
  double* row = lin->add_row(weight, residual);
  row[n + 6] = d_depth_offset;
  for (const ChainJoint& c : chain) {
    const JointAxis& axis = view.axes[c.scene_joint];
    const Eigen::Vector3d d_world = scene_.joints[c.scene_joint].type == JointType::kPrismatic
                                        ? axis.axis_world
                                        : Eigen::Vector3d(axis.axis_world.cross(world - axis.origin_world));
    row[c.param] += c.multiplier * g.dot(view.optical_from_world_rotation * d_world);
    if (count_joint_points) ++lin->joint_points[c.param];
  }
  // The seen frame moved by the twist (v, w): m' = m - v - w x m.
  for (int k = 0; k < 3; ++k) {
    row[n + k] = -g[k];
    row[n + 3 + k] = g_cross_m[k];
  }
}

void MotionEstimator::add_contour_term(const RenderedView& view, const std::vector<ChainJoint>& chain, int u,
                                       int v, Linearization* lin) const {
  const Intrinsics& in = view.frame.intrinsics;
  const int width = in.width;
  const std::vector<float>& model = view.rendered.depth_m;
  const size_t i = static_cast<size_t>(v) * width + u;
  const double z_model = model[i];
  // The direction (image, px) in which the rendered surface steps away:
  // this pixel is on the model's occluding contour when there is one.
  Eigen::Vector2d outward = Eigen::Vector2d::Zero();
  const double contour_jump = options_.contour_jump_fraction * z_model;
  auto farther = [&](size_t j) { return model[j] > 0 && model[j] - z_model > contour_jump; };
  if (farther(i - 1)) outward.x() -= 1;
  if (farther(i + 1)) outward.x() += 1;
  if (farther(i - width)) outward.y() -= 1;
  if (farther(i + width)) outward.y() += 1;
  if (!(outward.squaredNorm() > 0) || view.edges.nearest[i] < 0) return;
  outward.normalize();
  const int edge_u = view.edges.nearest[i] % width;
  const int edge_v = view.edges.nearest[i] / width;
  const double e = outward.dot(Eigen::Vector2d(u - edge_u, v - edge_v));
  ++lin->num_contour_points;
  if (!(std::abs(e) < view.contour_scale_px)) return;
  const double t = e / view.contour_scale_px;
  const double tukey = (1 - t * t) * (1 - t * t);
  const Eigen::Vector3d m = view.back_project(u, v, z_model);
  const double inv_z = 1.0 / m.z();
  // d(e)/d(m) = outward^T * d(pixel)/d(m).
  const Eigen::Vector3d g(outward.x() * in.fx * inv_z, outward.y() * in.fy * inv_z,
                          -(outward.x() * in.fx * m.x() + outward.y() * in.fy * m.y()) * inv_z * inv_z);
  add_residual(view, chain, m, view.world_from_optical * m, g, e, tukey * view.contour_weight, false, 0.0,
               lin);
  ++lin->num_contour_inliers;
}

void MotionEstimator::add_depth_term(const RenderedView& view, const std::vector<ChainJoint>& chain, int link,
                                     int u, int v, Linearization* lin, std::vector<Sample>* samples) const {
  const Intrinsics& in = view.frame.intrinsics;
  const int width = in.width;
  const std::vector<float>& model = view.rendered.depth_m;
  const std::vector<int16_t>& labels = view.rendered.labels;
  const size_t i = static_cast<size_t>(v) * width + u;
  const size_t left = i - 1, right = i + 1, up = i - width, down = i + width;
  const double z_model = model[i];
  const int point_stride = chain.empty() ? view.stride : std::min(view.stride, options_.pixel_stride);
  if (u % point_stride != 0 || v % point_stride != 0) return;
  const double z_measured = view.frame.depth_m[i];
  if (!(z_measured > 0) || !std::isfinite(z_measured)) return;
  bool smooth = true;
  for (size_t nb : {left, right, up, down}) {
    smooth = smooth && labels[nb] == labels[i] && std::abs(model[nb] - z_model) < options_.normal_jump_m;
  }
  if (!smooth) return;
  const Eigen::Vector3d m = view.back_project(u, v, z_model);
  Eigen::Vector3d normal =
      (view.back_project(u + 1, v, model[right]) - view.back_project(u - 1, v, model[left]))
          .cross(view.back_project(u, v + 1, model[down]) - view.back_project(u, v - 1, model[up]));
  const double normal_norm = normal.norm();
  if (!(normal_norm > 0)) return;
  normal /= normal_norm;
  if (normal.dot(m) > 0) normal = -normal;
  const Eigen::Vector3d world = view.world_from_optical * m;
  if (samples != nullptr && !chain.empty()) samples->push_back({link, world});

  // The robot's measured surfaces corrected by the depth offset: the
  // ToF camera's systematic error (calibration residual, multipath)
  // shifts a small object's surface along the rays by about the same
  // amount, which would otherwise turn the distal joints.
  const bool robot = is_robot_label(labels[i]);
  const Eigen::Vector3d ray = optical_point_m(in, u, v, 1.0);
  const Eigen::Vector3d d =
      view.back_project(u, v, z_measured) + (robot ? view.state.robot_depth_offset_m : 0.0) * ray;
  const double residual = normal.dot(m - d);
  const double depth_difference = z_model - z_measured;
  ++lin->num_points;
  const bool gated = std::abs(depth_difference) > view.gate;
  const double clipped = gated ? view.clip : std::min(std::abs(residual), view.clip);
  lin->clipped_sq += clipped * clipped;
  if (gated || std::abs(residual) >= view.scale) return;
  const double t = residual / view.scale;
  const double tukey = (1 - t * t) * (1 - t * t);
  const double sigma = options_.noise.sigma_m(z_measured);
  ++lin->num_inliers;
  add_residual(view, chain, m, world, normal, residual,
               // (A strided pixel stands for point_stride^2 pixels, so that
               // the depth and contour terms keep their balance.)
               point_stride * point_stride * tukey * view.sigma_1m * view.sigma_1m /
                   (sigma * sigma + options_.model_sigma_m * options_.model_sigma_m),
               true, robot ? -normal.dot(ray) : 0.0, lin);
}

std::string MotionEstimator::linearize(const EstimatorFrame& frame, const State& state, double scale,
                                       int stride, PointSet points, bool joints_free, Linearization* lin,
                                       std::vector<Sample>* samples) {
  const robot_model::LinkPoses poses =
      robot_model::forward_kinematics(scene_, joints_at(scene_, frame, state.joint_offsets));
  if (!poses.usable) return poses.unusable_reason;
  const Eigen::Isometry3d world_from_optical = frame.world_from_optical * state.correction;
  const renderer::RenderResult rendered =
      renderer_->render_at(poses, world_from_optical, frame.intrinsics, occupant_);
  if (!rendered.usable) return "render: " + rendered.unusable_reason;
  const double sigma_1m = options_.noise.sigma_m(1.0);
  const RenderedView view{
      frame,
      state,
      rendered,
      edges_of(frame),
      joint_axes(scene_, poses),
      world_from_optical,
      world_from_optical.linear().transpose(),
      scale,
      stride,
      joints_free,
      options_.gate_scales * scale,
      options_.residual_clip_m,
      sigma_1m,
      // The contour scale shrinks with the depth scale.
      options_.final_contour_scale_px * scale / options_.final_robust_scale_m,
      sigma_1m * sigma_1m / (options_.contour_sigma_px * options_.contour_sigma_px),
  };

  const int width = frame.intrinsics.width;
  const int height = frame.intrinsics.height;
  for (int v = 1; v + 1 < height; ++v) {
    for (int u = 1; u + 1 < width; ++u) {
      const size_t i = static_cast<size_t>(v) * width + u;
      const int link =
          link_of_label(rendered.labels[i], scene_.num_robot_links, static_cast<int>(scene_.links.size()));
      if (link < 0) continue;
      const std::vector<ChainJoint>& chain = chains_[link];
      if (points == PointSet::kStatic && !chain.empty()) continue;
      if (!(rendered.depth_m[i] > 0)) continue;
      if (options_.hidden_nearer_than_m > 0 && frame.depth_m[i] > 0 &&
          rendered.depth_m[i] - frame.depth_m[i] > options_.hidden_nearer_than_m)
        continue;
      // Contour term: a rendered occluding contour pixel against the
      // nearest measured one, distance along the contour's normal, pixels.
      add_contour_term(view, chain, u, v, lin);
      // Depth term (every stride-th pixel): point-to-plane against the
      // measured point on the same pixel, with the rendered surface's
      // normal from the neighbouring pixels of the same link; none on a
      // silhouette.
      add_depth_term(view, chain, link, u, v, lin, samples);
    }
  }
  lin->flush();
  return "";
}

namespace {

// Which parameters a solve moves: joints seen by enough inliers (and with
// information), the camera's six when free.
std::vector<int> active_parameters(const Eigen::MatrixXd& hessian, const std::vector<int>& joint_points,
                                   int num_joints, bool joints_free, bool camera_free, bool depth_offset_free,
                                   int min_joint_points) {
  std::vector<int> active;
  if (joints_free) {
    for (int k = 0; k < num_joints; ++k) {
      if (joint_points[k] >= min_joint_points && hessian(k, k) > 1e-12) active.push_back(k);
    }
  }
  if (camera_free) {
    for (int k = 0; k < 6; ++k) active.push_back(num_joints + k);
  }
  if (depth_offset_free && hessian(num_joints + 6, num_joints + 6) > 1e-12) active.push_back(num_joints + 6);
  return active;
}

}  // namespace

std::string MotionEstimator::solve(const std::vector<const EstimatorFrame*>& frames, bool joints_free,
                                   bool camera_free, PointSet points, int max_iterations, State* state,
                                   Linearization* final_lin, bool* converged, int* iterations) {
  const int n = num_params_;
  *converged = false;
  Linearization lin;
  // The coarse iterations (robust scale above the final one) only bring
  // the estimate into the final scale's basin: every coarse_pixel_stride-th
  // pixel's depth residual of what no joint moves (most of the image: the
  // environment) is enough for them; the links a joint moves keep every
  // pixel (the small ones would fall below min_joint_points).
  const int coarse_stride = std::max(options_.pixel_stride, options_.coarse_pixel_stride);
  int level = 0;  // the robust scale's step in its schedule
  for (int it = 0; it < max_iterations; ++it, ++level) {
    const double scale =
        std::max(options_.final_robust_scale_m,
                 options_.initial_robust_scale_m * std::pow(options_.robust_scale_factor, level));
    const bool final_scale = scale <= options_.final_robust_scale_m * (1 + 1e-9);
    lin.reset(n);
    for (const EstimatorFrame* frame : frames) {
      const std::string error =
          linearize(*frame, *state, scale, final_scale ? options_.pixel_stride : coarse_stride, points,
                    joints_free, &lin, nullptr);
      if (!error.empty()) return error;
    }
    ++*iterations;
    *final_lin = lin;
    const std::vector<int> active =
        active_parameters(lin.hessian, lin.joint_points, n, joints_free, camera_free,
                          joints_free && options_.estimate_robot_depth_offset, options_.min_joint_points);
    if (active.empty()) {
      *converged = true;
      return "";
    }
    if (lin.num_inliers < static_cast<int>(active.size()) + 20) {
      return "too few model points match the image (" + std::to_string(lin.num_inliers) + " inliers)";
    }
    const int p = static_cast<int>(active.size());
    Eigen::MatrixXd a(p, p);
    Eigen::VectorXd b(p);
    for (int r = 0; r < p; ++r) {
      b[r] = lin.gradient[active[r]];
      for (int c = 0; c < p; ++c) a(r, c) = lin.hessian(active[r], active[c]);
    }
    // A little Levenberg-Marquardt damping keeps weakly seen directions
    // from jumping.
    for (int r = 0; r < p; ++r) a(r, r) *= 1.0 + (final_scale ? options_.final_damping : 1e-3);
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(a);
    if (ldlt.info() != Eigen::Success) return "normal equations are singular";
    const Eigen::VectorXd step = -ldlt.solve(b);
    if (!step.allFinite()) return "solver diverged (non-finite step)";

    Eigen::VectorXd full = Eigen::VectorXd::Zero(n + kExtraParams);
    for (int r = 0; r < p; ++r) full[active[r]] = step[r];
    double largest = 0;
    for (int k = 0; k < n; ++k) {
      const double s = std::clamp(full[k], -options_.max_joint_step, options_.max_joint_step);
      state->joint_offsets[k] += s;
      largest = std::max(largest, std::abs(s));
    }
    Eigen::Vector3d v = full.segment<3>(n);
    Eigen::Vector3d w = full.segment<3>(n + 3);
    if (v.norm() > options_.max_camera_translation_step_m)
      v *= options_.max_camera_translation_step_m / v.norm();
    if (w.norm() > options_.max_camera_rotation_step_rad)
      w *= options_.max_camera_rotation_step_rad / w.norm();
    largest = std::max({largest, v.cwiseAbs().maxCoeff(), w.cwiseAbs().maxCoeff()});
    state->robot_depth_offset_m += std::clamp(full[n + 6], -0.02, 0.02);
    state->correction = state->correction * twist_exp(v, w);
    if (final_scale && largest < options_.step_tolerance) {
      *converged = true;
      return "";
    }
    // The camera alone already in the basin (a small first step: the
    // static links agree with the reported pose): on to the final scale at
    // once. (Not with the joints: their coarse iterations,
    // undamped, also carry them most of the way after the search.)
    if (!joints_free && it == 0 && largest < options_.coarse_skip_step) level = kFinalLevel;
  }
  return "";
}

std::vector<const MotionEstimator::Sample*> MotionEstimator::distal_samples(
    const std::vector<Sample>& samples, int k, size_t* every) const {
  std::vector<const Sample*> distal;
  for (const Sample& s : samples) {
    for (const ChainJoint& c : chains_[s.link]) {
      if (c.param == k) {
        distal.push_back(&s);
        break;
      }
    }
  }
  // Too few to judge: none.
  if (static_cast<int>(distal.size()) < options_.min_joint_points) return {};
  // Scoring every distal point of a large link for 30 offsets costs
  // more than a render; a few hundred points, spread over the links,
  // score as well.
  *every = (distal.size() + kSearchPoints - 1) / kSearchPoints;
  if (*every > 1) {
    size_t kept = 0;
    for (size_t i = 0; i < distal.size(); i += *every) distal[kept++] = distal[i];
    distal.resize(kept);
  }
  return distal;
}

int MotionEstimator::search_joints(const EstimatorFrame& frame, State* state, std::string* error) {
  const Intrinsics& in = frame.intrinsics;
  const int width = in.width;
  const int height = in.height;
  const double tolerance_floor = options_.final_robust_scale_m;
  int moves = 0;
  const std::vector<double> grid =
      search_grid(options_.joint_search_range_rad, options_.joint_search_step_rad);
  for (int round = 0; round < options_.joint_search_rounds; ++round) {
    std::vector<Sample> samples;
    Linearization scratch;
    scratch.reset(num_params_);
    *error = linearize(frame, *state, options_.final_robust_scale_m, options_.pixel_stride, PointSet::kAll,
                       false, &scratch, &samples);
    if (!error->empty()) return moves;
    const robot_model::LinkPoses base =
        robot_model::forward_kinematics(scene_, joints_at(scene_, frame, state->joint_offsets));
    const Eigen::Isometry3d optical_from_world = (frame.world_from_optical * state->correction).inverse();

    // +1 for a point the camera sees where the model puts it, -1 for one
    // the camera sees through (it measures farther), 0 when something
    // nearer hides it, it has no return, or it leaves the image.
    auto score = [&](const std::vector<const Sample*>& distal, const std::vector<Eigen::Isometry3d>& moved) {
      int total = 0;
      for (const Sample* s : distal) {
        const Eigen::Vector3d m = optical_from_world * (moved[s->link] * s->world);
        if (!(m.z() > 0)) continue;
        const int u = static_cast<int>(std::lround(in.fx * m.x() / m.z() + in.cx));
        const int v = static_cast<int>(std::lround(in.fy * m.y() / m.z() + in.cy));
        if (u < 0 || v < 0 || u >= width || v >= height) continue;
        const double z = frame.depth_m[static_cast<size_t>(v) * width + u];
        if (!(z > 0) || !std::isfinite(z)) continue;
        const double sigma = options_.noise.sigma_m(z);
        const double tolerance = std::max(tolerance_floor, 3 * sigma);
        const double dz = m.z() - z;
        if (std::abs(dz) <= tolerance) {
          ++total;
        } else if (dz < 0) {
          --total;
        }
      }
      return total;
    };

    int best_param = -1;
    double best_offset = 0;
    // The joint whose move explains the most points (in all, not as a
    // fraction of its own distal points: a wrist joint swung far can
    // realign a large share of the few points it moves when the error is
    // at the shoulder, which moves them all).
    int best_gain = 0;
    std::vector<Eigen::Isometry3d> moved(scene_.links.size(), Eigen::Isometry3d::Identity());
    for (int k = 0; k < num_params_; ++k) {
      size_t every = 1;
      const std::vector<const Sample*> distal = distal_samples(samples, k, &every);
      if (distal.empty()) continue;
      std::fill(moved.begin(), moved.end(), Eigen::Isometry3d::Identity());
      const int base_score = score(distal, moved);
      for (double offset : grid) {
        std::vector<double> offsets = state->joint_offsets;
        offsets[k] += offset;
        const robot_model::LinkPoses poses =
            robot_model::forward_kinematics(scene_, joints_at(scene_, frame, offsets));
        if (!poses.usable) continue;
        for (size_t l = 0; l < moved.size(); ++l) {
          moved[l] = poses.world_from_link[l] * base.world_from_link[l].inverse();
        }
        const int scored_gain = score(distal, moved) - base_score;
        const int gain = scored_gain * static_cast<int>(every);  // in all distal points
        const double fraction = static_cast<double>(scored_gain) / distal.size();
        if (gain >= options_.min_joint_points && fraction >= options_.min_search_gain_fraction &&
            gain > best_gain) {
          best_gain = gain;
          best_param = k;
          best_offset = offset;
        }
      }
    }
    if (best_param < 0) break;
    state->joint_offsets[best_param] += best_offset;
    ++moves;
  }
  return moves;
}

EstimateResult MotionEstimator::finish(const EstimatorFrame& frame, const State& state,
                                       const Linearization& lin, bool camera_free, bool joints_free) const {
  EstimateResult result;
  result.usable = true;
  const int n = num_params_;
  const std::vector<int> active =
      active_parameters(lin.hessian, lin.joint_points, n, joints_free, camera_free,
                        joints_free && options_.estimate_robot_depth_offset, options_.min_joint_points);
  const int p = static_cast<int>(active.size());
  std::vector<double> variance(n + kExtraParams, -1.0);
  if (p > 0) {
    Eigen::MatrixXd a(p, p);
    for (int r = 0; r < p; ++r)
      for (int c = 0; c < p; ++c) a(r, c) = lin.hessian(active[r], active[c]);
    const double dof = std::max(1, lin.num_inliers - p);
    const double residual_variance = lin.weighted_sq / dof;
    const Eigen::MatrixXd covariance = residual_variance * a.ldlt().solve(Eigen::MatrixXd::Identity(p, p));
    for (int r = 0; r < p; ++r) variance[active[r]] = covariance(r, r);
  }
  auto sigma_of = [&](int k) {
    return variance[k] >= 0 ? options_.sigma_scale * std::sqrt(variance[k]) : kUnobservableSigma;
  };
  for (int k = 0; k < n; ++k) {
    JointEstimate joint;
    joint.name = scene_.actuated_joint_names[k];
    joint.reported = frame.reported_joints.at(joint.name);
    joint.sigma = sigma_of(k);
    joint.observable = joints_free && variance[k] >= 0 && joint.sigma <= options_.max_joint_sigma;
    if (!joint.observable) joint.sigma = kUnobservableSigma;
    joint.estimated = joint.observable ? joint.reported + state.joint_offsets[k] : joint.reported;
    result.joints.push_back(joint);
  }
  result.camera_estimated = camera_free;
  if (camera_free) {
    result.correction = state.correction;
    double translation = 0, rotation = 0;
    for (int k = 0; k < 3; ++k) {
      translation = std::max(translation, sigma_of(n + k));
      rotation = std::max(rotation, sigma_of(n + 3 + k));
    }
    result.correction_translation_sigma_m = translation;
    result.correction_rotation_sigma_rad = rotation;
  }
  result.robot_depth_offset_m = state.robot_depth_offset_m;
  result.num_points = lin.num_points;
  result.num_inliers = lin.num_inliers;
  result.residual_after_m = lin.clipped_rms_m();
  return result;
}

EstimateResult MotionEstimator::estimate(const EstimatorFrame& frame) { return estimate_frames({&frame}); }

EstimateResult MotionEstimator::estimate(const std::vector<EstimatorFrame>& frames) {
  std::vector<const EstimatorFrame*> pointers;
  for (const EstimatorFrame& f : frames) pointers.push_back(&f);
  return estimate_frames(pointers);
}

namespace {

// `full` at a working resolution of every k-th pixel in u and v (no
// averaging, which would make mixed pixels of every silhouette), with the
// intrinsics scaled to match.
EstimatorFrame working_frame(const EstimatorFrame& full, int k) {
  EstimatorFrame reduced;
  reduced.reported_joints = full.reported_joints;
  reduced.world_from_optical = full.world_from_optical;
  const Intrinsics& in = full.intrinsics;
  reduced.intrinsics = in;
  reduced.intrinsics.width = in.width / k;
  reduced.intrinsics.height = in.height / k;
  reduced.intrinsics.fx = in.fx / k;
  reduced.intrinsics.fy = in.fy / k;
  reduced.intrinsics.cx = in.cx / k;
  reduced.intrinsics.cy = in.cy / k;
  reduced.depth_m.resize(static_cast<size_t>(reduced.intrinsics.width) * reduced.intrinsics.height);
  for (int v = 0; v < reduced.intrinsics.height; ++v) {
    for (int u = 0; u < reduced.intrinsics.width; ++u) {
      reduced.depth_m[static_cast<size_t>(v) * reduced.intrinsics.width + u] =
          full.depth_m[static_cast<size_t>(v * k) * in.width + u * k];
    }
  }
  return reduced;
}

}  // namespace

EstimateResult MotionEstimator::estimate_frames(const std::vector<const EstimatorFrame*>& full_frames) {
  const int64_t start = now_us();
  auto fail = [&](const std::string& why) { return unusable_result(why, start); };
  if (full_frames.empty()) return fail("no frames");
  for (size_t f = 0; f < full_frames.size(); ++f) {
    const std::string problem = check_frame(*full_frames[f]);
    if (!problem.empty())
      return fail(full_frames.size() > 1 ? "frame " + std::to_string(f) + ": " + problem : problem);
    if (full_frames[f]->intrinsics.width != full_frames[0]->intrinsics.width ||
        full_frames[f]->intrinsics.height != full_frames[0]->intrinsics.height) {
      return fail("frame " + std::to_string(f) + ": image size differs from frame 0's");
    }
  }
  edges_.clear();
  // A large image is estimated at a working resolution (options:
  // max_working_pixels).
  const Intrinsics& full = full_frames[0]->intrinsics;
  int k = 1;
  while (static_cast<int64_t>(full.width / k) * (full.height / k) > options_.max_working_pixels) ++k;
  std::vector<EstimatorFrame> reduced;
  std::vector<const EstimatorFrame*> frames = full_frames;
  if (k > 1) {
    reduced.reserve(full_frames.size());  // (frames points into it)
    for (size_t f = 0; f < full_frames.size(); ++f) {
      reduced.push_back(working_frame(*full_frames[f], k));
      frames[f] = &reduced.back();
    }
  }
  const EstimatorFrame& frame = *frames[0];

  State state;
  state.joint_offsets.assign(num_params_, 0.0);
  // The residual before: the estimate's own frame at the reported values.
  Linearization before;
  before.reset(num_params_);
  std::string error = linearize(frame, state, options_.final_robust_scale_m, options_.pixel_stride,
                                PointSet::kAll, false, &before, nullptr);
  if (!error.empty()) return fail(error);

  const bool joints_free = options_.estimate_joints;
  const bool camera_free = options_.estimate_camera;
  int iterations = 0;
  bool converged = true;
  Linearization lin = before;
  if (joints_free && camera_free) {
    // The camera first from what no joint moves.
    error = solve(frames, false, true, PointSet::kStatic, options_.max_camera_iterations, &state, &lin,
                  &converged, &iterations);
    if (!error.empty()) return fail("camera: " + error);
  }
  int moves = 0;
  if (joints_free) {
    // The search on the estimate's own frame: the offsets it finds are
    // every frame's (an encoder offset does not change in 100 ms).
    moves = search_joints(frame, &state, &error);
    if (!error.empty()) return fail("joint search: " + error);
  }
  if (joints_free || camera_free) {
    error = solve(frames, joints_free, camera_free, PointSet::kAll, options_.max_iterations, &state, &lin,
                  &converged, &iterations);
    if (!error.empty()) return fail(error);
  }
  EstimateResult result = finish(frame, state, lin, camera_free, joints_free);
  result.converged = converged;
  result.iterations = iterations;
  result.search_moves = moves;
  result.num_frames = static_cast<int>(frames.size());
  result.residual_before_m = before.clipped_rms_m();
  result.compute_us = now_us() - start;
  return result;
}

EstimateResult MotionEstimator::estimate_camera(const std::vector<EstimatorFrame>& frames) {
  const int64_t start = now_us();
  auto fail = [&](const std::string& why) { return unusable_result(why, start); };
  if (frames.empty()) return fail("no frames");
  edges_.clear();
  std::vector<const EstimatorFrame*> pointers;
  for (size_t f = 0; f < frames.size(); ++f) {
    const std::string problem = check_frame(frames[f]);
    if (!problem.empty()) return fail("frame " + std::to_string(f) + ": " + problem);
    if (!frames[f].world_from_optical.isApprox(frames[0].world_from_optical, 1e-9)) {
      return fail("frame " + std::to_string(f) + ": initial camera pose differs from frame 0's");
    }
    pointers.push_back(&frames[f]);
  }
  State state;
  state.joint_offsets.assign(num_params_, 0.0);
  Linearization before;
  before.reset(num_params_);
  for (const EstimatorFrame* frame : pointers) {
    const std::string error = linearize(*frame, state, options_.final_robust_scale_m, options_.pixel_stride,
                                        PointSet::kAll, false, &before, nullptr);
    if (!error.empty()) return fail(error);
  }
  Linearization lin = before;
  int iterations = 0;
  bool converged = false;
  const std::string error = solve(pointers, false, true, PointSet::kAll, options_.max_iterations, &state,
                                  &lin, &converged, &iterations);
  if (!error.empty()) return fail(error);
  EstimateResult result = finish(frames[0], state, lin, true, false);
  result.converged = converged;
  result.iterations = iterations;
  result.residual_before_m = before.clipped_rms_m();
  result.compute_us = now_us() - start;
  return result;
}

}  // namespace tofguard::estimator
