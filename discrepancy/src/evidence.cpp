#include "tofguard/discrepancy/evidence.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

#include "double2.hpp"
#include "tofguard/common/camera_profile.hpp"
#include "tofguard/common/demand.hpp"
#include "tofguard/common/depth_frame.hpp"
#include "tofguard/discrepancy/joint_search.hpp"

namespace tofguard::discrepancy {

bool read_label_kinematics(const link_labels_t& labels, size_t pixels, LabelKinematics* out) {
  // The wire checks make these hold; an in-process caller may not have run
  // them, so a misfit only switches the evidence off.
  const auto n = static_cast<size_t>(std::max(labels.num_axes, 0));
  if (labels.num_axes <= 0 || labels.num_joints <= 0 || labels.axis_joint.size() != n ||
      labels.axis_multiplier.size() != n || labels.axis_prismatic.size() != n ||
      labels.axis_origin_m.size() != n || labels.axis_direction.size() != n ||
      labels.axis_parent.size() != n || labels.num_robot_links < 0 ||
      labels.link_axis.size() != static_cast<size_t>(labels.num_robot_links) ||
      labels.num_link_axes != labels.num_robot_links || labels.label.size() != pixels) {
    return false;
  }
  LabelKinematics k;
  k.num_joints = labels.num_joints;
  k.num_robot_links = labels.num_robot_links;
  k.num_links = labels.num_links;
  k.axes.resize(n);
  for (size_t m = 0; m < n; ++m) {
    LabelAxis& a = k.axes[m];
    if (labels.axis_origin_m[m].size() != 3 || labels.axis_direction[m].size() != 3) return false;
    a.joint = labels.axis_joint[m];
    a.multiplier = labels.axis_multiplier[m];
    a.prismatic = labels.axis_prismatic[m];
    a.origin_mm = 1000.0 * Eigen::Vector3d(labels.axis_origin_m[m][0], labels.axis_origin_m[m][1],
                                           labels.axis_origin_m[m][2]);
    a.direction = Eigen::Vector3d(labels.axis_direction[m][0], labels.axis_direction[m][1],
                                  labels.axis_direction[m][2]);
    a.parent = labels.axis_parent[m];
    if (a.joint < 0 || a.joint >= k.num_joints || a.parent < -1 || a.parent >= static_cast<int>(m))
      return false;
  }
  k.link_axis = labels.link_axis;
  for (int a : k.link_axis) {
    if (a < -1 || a >= static_cast<int>(n)) return false;
  }
  *out = std::move(k);
  return true;
}

EvidenceJacobian::EvidenceJacobian(const depth_image_t& rendered, const link_labels_t& labels,
                                   double silhouette_jump_mm)
    : width_(rendered.width),
      height_(rendered.height),
      fx_(rendered.fx),
      fy_(rendered.fy),
      cx_(rendered.cx),
      cy_(rendered.cy),
      jump_limit_mm_(silhouette_step_limit_mm(silhouette_jump_mm > 0 ? silhouette_jump_mm : 1e9)),
      depth_(rendered.depth_mm.data()),
      label_(labels.label.data()) {
  const size_t pixels = static_cast<size_t>(std::max(width_, 0)) * static_cast<size_t>(std::max(height_, 0));
  if (rendered.depth_mm.size() != pixels || !(fx_ > 0) || !(fy_ > 0)) return;
  available_ = read_label_kinematics(labels, pixels, &kinematics_);
}

[[gnu::always_inline]] inline bool EvidenceJacobian::at_pixel(int u, int v, double camera[6], double* joints,
                                                              bool* moved, int* link_out) const {
  const int i = v * width_ + u;
  const int z_mm = depth_[i];
  if (z_mm <= 0) return false;
  const int l = label_[i];
  const int link = link_of_label(l, kinematics_.num_robot_links, kinematics_.num_links);
  if (link < 0) return false;
  // The slope of the rendered surface, mm per pixel: central differences
  // over the neighbours on the same link and surface, one-sided with one.
  const auto qualifies = [&](int n) {
    const int d = depth_[n];
    return d > 0 && label_[n] == l && std::abs(d - z_mm) <= jump_limit_mm_;
  };
  double gu = 0;
  {
    const bool a = u > 0 && qualifies(i - 1);
    const bool b = u + 1 < width_ && qualifies(i + 1);
    if (a && b) {
      gu = 0.5 * (depth_[i + 1] - depth_[i - 1]);
    } else if (b) {
      gu = depth_[i + 1] - z_mm;
    } else if (a) {
      gu = z_mm - depth_[i - 1];
    } else {
      return false;
    }
  }
  double gv = 0;
  {
    const bool a = v > 0 && qualifies(i - width_);
    const bool b = v + 1 < height_ && qualifies(i + width_);
    if (a && b) {
      gv = 0.5 * (depth_[i + width_] - depth_[i - width_]);
    } else if (b) {
      gv = depth_[i + width_] - z_mm;
    } else if (a) {
      gv = z_mm - depth_[i - width_];
    } else {
      return false;
    }
  }
  const double z = z_mm;
  const Eigen::Vector3d p((u - cx_) * z / fx_, (v - cy_) * z / fy_, z);
  const Eigen::Vector3d g(-gu * fx_ / z, -gv * fy_ / z,
                          1.0 + (gu * fx_ * p.x() + gv * fy_ * p.y()) / (z * z));
  *link_out = link;
  const int first_axis = link < kinematics_.num_robot_links ? kinematics_.link_axis[link] : -1;
  *moved = first_axis >= 0;
  if (*moved) {
    std::fill(joints, joints + kinematics_.num_joints, 0.0);
    for (int m = first_axis; m >= 0; m = kinematics_.axes[m].parent) {
      const LabelAxis& a = kinematics_.axes[m];
      // Revolute: v = direction x (p - origin) (mm per rad); prismatic:
      // v = direction (1000 mm per m).
      const double j = a.prismatic ? 1000.0 * g.dot(a.direction) : g.dot(a.direction.cross(p - a.origin_mm));
      joints[a.joint] += a.multiplier * j;
    }
  } else {
    // A static point seen from the optical frame moved by (t, w): its
    // coordinates change by -t - w x p.
    camera[0] = -1000.0 * g.x();
    camera[1] = -1000.0 * g.y();
    camera[2] = -1000.0 * g.z();
    // Rotation w = e_k: v = -e_k x p = p x e_k, and g . (p x e_k) =
    // e_k . (g x p) (mm per radian, p in mm).
    const Eigen::Vector3d gxp = g.cross(p);
    camera[3] = gxp.x();
    camera[4] = gxp.y();
    camera[5] = gxp.z();
  }
  return true;
}

bool EvidenceJacobian::at(int i, double camera[6], double* joints, bool* moved, int* link_out) const {
  if (!available_ || i < 0 || i >= width_ * height_) return false;
  return at_zeroing_the_other(i % width_, i / width_, camera, joints, moved, link_out);
}

bool EvidenceJacobian::at(int u, int v, double camera[6], double* joints, bool* moved, int* link_out) const {
  if (!available_) return false;
  return at_zeroing_the_other(u, v, camera, joints, moved, link_out);
}

bool EvidenceJacobian::at_zeroing_the_other(int u, int v, double camera[6], double* joints, bool* moved,
                                            int* link_out) const {
  if (!at_pixel(u, v, camera, joints, moved, link_out)) return false;
  if (*moved) {
    std::fill(camera, camera + 6, 0.0);
  } else {
    std::fill(joints, joints + kinematics_.num_joints, 0.0);
  }
  return true;
}

int evidence_stride(int width, int height, int max_pixels) {
  if (max_pixels <= 0 || width <= 0 || height <= 0) return 1;
  int k = 1;
  const auto sampled = [&](int stride) {
    return int64_t{(width + stride - 1) / stride} * int64_t{(height + stride - 1) / stride};
  };
  while (sampled(k) > max_pixels && k < std::max(width, height)) ++k;
  return k;
}

void clear_evidence(discrepancy_t* s) {
  s->evidence_available = false;
  s->num_link_bias = 0;
  s->link_bias_mm.clear();
  s->link_bias_sigma_mm.clear();
  s->camera_fit_pixels = 0;
  std::fill(s->camera_score, s->camera_score + 6, 0.0);
  std::fill(s->camera_information, s->camera_information + 36, 0.0);
  std::fill(s->camera_correction, s->camera_correction + 6, 0.0);
  s->static_chi2 = 0;
  std::fill(s->camera_region_fit_pixels, s->camera_region_fit_pixels + 4, 0);
  std::fill(s->camera_region_score, s->camera_region_score + 24, 0.0);
  std::fill(s->camera_region_information, s->camera_region_information + 24, 0.0);
  s->distance_offset_score = 0;
  s->distance_offset_information = 0;
  std::fill(s->distance_offset_cross, s->distance_offset_cross + 6, 0.0);
  std::fill(s->camera_static_bound, s->camera_static_bound + 6, 0.0);
  std::fill(s->camera_region_static_bound, s->camera_region_static_bound + 24, 0.0);
  s->joint_static_bound.clear();
  s->num_joints = 0;
  s->joint_name.clear();
  s->joint_fit_pixels.clear();
  s->joint_score.clear();
  s->joint_information.clear();
  s->joint_naming_score.clear();
  s->joint_naming_information.clear();
  s->robot_fit_pixels = 0;
  s->robot_chi2 = 0;
  s->search_points = 0;
  s->joint_search_offset.clear();
  s->joint_search_gain.clear();
  s->camera_search_static_points = 0;
  s->camera_search_axis = -1;
  s->camera_search_offset = 0;
  s->camera_search_gain = 0;
}

namespace {

// compute_evidence's bands of rows: a fixed number, so that the sums do not
// depend on how many threads run them.
constexpr int kEvidenceBands = 8;

// One band's sums of the evidence fits (the discrepancy_t fields of the
// same names; link_sum_* per link: sum of w r and of w).
struct EvidenceSums {
  EvidenceSums(int num_links, int num_joints)
      : link_sum_wr(num_links, 0.0),
        link_sum_w(num_links, 0.0),
        joint_fit_pixels(num_joints, 0),
        joint_score(num_joints, 0.0),
        joint_information(num_joints, 0.0),
        joint_naming_score(num_joints, 0.0),
        joint_naming_information(num_joints, 0.0),
        joint_bias_abs(num_joints, 0.0),
        joint_bias_square(num_joints, 0.0),
        joint_near_step_abs(num_joints, 0.0) {}
  void add(const EvidenceSums& o) {
    for (size_t l = 0; l < link_sum_wr.size(); ++l) {
      link_sum_wr[l] += o.link_sum_wr[l];
      link_sum_w[l] += o.link_sum_w[l];
    }
    robot_fit_pixels += o.robot_fit_pixels;
    robot_chi2 += o.robot_chi2;
    for (size_t j = 0; j < joint_score.size(); ++j) {
      joint_fit_pixels[j] += o.joint_fit_pixels[j];
      joint_score[j] += o.joint_score[j];
      joint_information[j] += o.joint_information[j];
      joint_naming_score[j] += o.joint_naming_score[j];
      joint_naming_information[j] += o.joint_naming_information[j];
      joint_bias_abs[j] += o.joint_bias_abs[j];
      joint_bias_square[j] += o.joint_bias_square[j];
      joint_near_step_abs[j] += o.joint_near_step_abs[j];
    }
    static_chi2 += o.static_chi2;
    camera_fit_pixels += o.camera_fit_pixels;
    camera_score += o.camera_score;
    camera_information += o.camera_information;
    for (int k = 0; k < 4; ++k) camera_region_fit_pixels[k] += o.camera_region_fit_pixels[k];
    for (int k = 0; k < 24; ++k) {
      camera_region_score[k] += o.camera_region_score[k];
      camera_region_information[k] += o.camera_region_information[k];
      camera_region_bias_abs[k] += o.camera_region_bias_abs[k];
      camera_region_bias_square[k] += o.camera_region_bias_square[k];
      camera_region_near_step_abs[k] += o.camera_region_near_step_abs[k];
    }
    distance_offset_score += o.distance_offset_score;
    distance_offset_information += o.distance_offset_information;
    for (int a = 0; a < 6; ++a) distance_offset_cross[a] += o.distance_offset_cross[a];
  }
  std::vector<double> link_sum_wr;
  std::vector<double> link_sum_w;
  int32_t robot_fit_pixels = 0;
  double robot_chi2 = 0;
  std::vector<int32_t> joint_fit_pixels;
  std::vector<double> joint_score;
  std::vector<double> joint_information;
  std::vector<double> joint_naming_score;
  std::vector<double> joint_naming_information;
  // The static error's reach into each score (EvidenceOptions::
  // static_bias_mm): sum w |J| and sum w^2 J^2 over the fit's pixels.
  std::vector<double> joint_bias_abs;
  std::vector<double> joint_bias_square;
  // sum w |J| over the pixels on the near side of a step
  // (EvidenceOptions::silhouette_bias_mm).
  std::vector<double> joint_near_step_abs;
  double static_chi2 = 0;
  int32_t camera_fit_pixels = 0;
  Eigen::Matrix<double, 6, 1> camera_score = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix<double, 6, 6> camera_information = Eigen::Matrix<double, 6, 6>::Zero();  // upper triangle
  int32_t camera_region_fit_pixels[4] = {0, 0, 0, 0};
  double camera_region_score[24] = {};
  double camera_region_information[24] = {};
  // The camera fit's sum w |J| and sum w^2 J^2 per region and parameter
  // (the whole image's: the four regions' together).
  double camera_region_bias_abs[24] = {};
  double camera_region_bias_square[24] = {};
  double camera_region_near_step_abs[24] = {};
  // The common distance offset over the camera fit's pixels
  // (discrepancy_t.distance_offset_*): J = f, Z per radial mm.
  double distance_offset_score = 0;
  double distance_offset_information = 0;
  double distance_offset_cross[6] = {};
};

// The static error's reach into the camera fit of pixels n_first ..
// n_end - 1 (as add_camera_fit's): bias_abs[a] += w |J_a|, bias_square[a]
// += (w J_a)^2.
void add_camera_bias_reach(const double* jacobian, const double* weight, const float* near_step_mm,
                           int n_first, int n_end, double* bias_abs, double* bias_square,
                           double* near_step_abs) {
  for (int n = n_first; n < n_end; ++n) {
    const double* j = jacobian + 6 * n;
    for (int a = 0; a < 6; ++a) {
      const double wj = weight[n] * j[a];
      bias_abs[a] += std::abs(wj);
      bias_square[a] += wj * wj;
      near_step_abs[a] += near_step_mm[n] * std::abs(wj);
    }
  }
}

// The camera fit's sums over one row's static pixels n_first .. n_end - 1
// (their Jacobians 6 to a pixel in `jacobian`, weights w, clipped residuals
// r), all in one image quadrant: score[a] and region_score[a] -= w J_a r,
// region_information[a] += w J_a J_a, information(a, c) += w J_a J_c for
// c >= a (the upper triangle of Eigen's column-major 6x6). Each sum takes
// the pixels in order, as the loop one pixel at a time did: the same
// numbers to the last bit (bench digest, docs/benchmarks.md).
void add_camera_fit(const double* jacobian, const double* weight, const double* residual, int n_first,
                    int n_end, double* score, double* information, double* region_score,
                    double* region_information) {
  if (n_first >= n_end) return;
  // The scores and the region's diagonal, parameters (0, 1), (2, 3), (4, 5).
  Double2 s[3], rs[3], ri[3];
#pragma GCC unroll 3
  for (int k = 0; k < 3; ++k) {
    s[k] = load2(score + 2 * k);
    rs[k] = load2(region_score + 2 * k);
    ri[k] = load2(region_information + 2 * k);
  }
  for (int n = n_first; n < n_end; ++n) {
    const double* j = jacobian + 6 * n;
    const Double2 w = {weight[n], weight[n]};
    const Double2 r = {residual[n], residual[n]};
#pragma GCC unroll 3
    for (int k = 0; k < 3; ++k) {
      const Double2 jk = load2(j + 2 * k);
      const Double2 wj = w * jk;
      s[k] -= wj * r;
      rs[k] -= wj * r;
      ri[k] += wj * jk;
    }
  }
#pragma GCC unroll 3
  for (int k = 0; k < 3; ++k) {
    store2(score + 2 * k, s[k]);
    store2(region_score + 2 * k, rs[k]);
    store2(region_information + 2 * k, ri[k]);
  }
  // information(a, c), row a in the pairs of columns (c, c + 1) from the
  // pair holding a: 12 pairs; a row's lane left of a (row 1's column 0,
  // ...) is summed too and never stored.
  constexpr int kFirstPair[6] = {0, 0, 1, 1, 2, 2};
  constexpr int kPairIndex[6] = {0, 3, 6, 8, 10, 11};
  Double2 m[12];
#pragma GCC unroll 6
  for (int a = 0; a < 6; ++a) {
#pragma GCC unroll 3
    for (int k = kFirstPair[a]; k < 3; ++k) {
      m[kPairIndex[a] + k - kFirstPair[a]] =
          Double2{information[a + 6 * (2 * k)], information[a + 6 * (2 * k + 1)]};
    }
  }
  for (int n = n_first; n < n_end; ++n) {
    const double* j = jacobian + 6 * n;
    const Double2 jk[3] = {load2(j), load2(j + 2), load2(j + 4)};
#pragma GCC unroll 6
    for (int a = 0; a < 6; ++a) {
      const double wj = weight[n] * j[a];
      const Double2 wj2 = {wj, wj};
#pragma GCC unroll 3
      for (int k = kFirstPair[a]; k < 3; ++k) m[kPairIndex[a] + k - kFirstPair[a]] += wj2 * jk[k];
    }
  }
#pragma GCC unroll 6
  for (int a = 0; a < 6; ++a) {
#pragma GCC unroll 3
    for (int k = kFirstPair[a]; k < 3; ++k) {
      const Double2 v = m[kPairIndex[a] + k - kFirstPair[a]];
      if (2 * k >= a) information[a + 6 * (2 * k)] = v[0];
      information[a + 6 * (2 * k + 1)] = v[1];
    }
  }
}

}  // namespace

// EvidenceJacobian::at_pixel for compute_evidence's per-pixel step (a
// friend of EvidenceJacobian).
struct EvidencePixelAccess {
  [[gnu::always_inline]] static bool at_pixel(const EvidenceJacobian& jacobian, int u, int v,
                                              double camera[6], double* joints, bool* moved, int* link) {
    return jacobian.at_pixel(u, v, camera, joints, moved, link);
  }
};

namespace {

// What every band of a frame reads: the images, the fit's settings and
// the sampling.
struct EvidenceFrame {
  const depth_image_t& camera;
  const depth_image_t& rendered;
  const std::vector<uint8_t>& silhouette;
  // Per pixel, the silhouette allowance on the near side of a step (mm;
  // near_step_allowance_mm; empty: none).
  const std::vector<float>& near_step_mm;
  // The static pixels the naming search explains (when have_explained):
  // the arm's evidence, kept out of the camera fit.
  const std::vector<uint8_t>& explained_static;
  bool have_explained;
  const EvidenceJacobian& jacobian;
  const DepthNoise& noise;
  const EvidenceOptions& options;
  // Every stride-th pixel in u and v (EvidenceOptions::max_pixels), each
  // weighted (inv_pps) for the noise correlation left between the sampled
  // pixels.
  int stride;
  double inv_pps;
};

// One row's static pixels in the camera fit: their Jacobians (6 to a
// pixel, written there by the Jacobian), weights and clipped residuals,
// `left` of them in the image's left half. The 6x6 sums then run
// over the row in registers (add_camera_fit), not through 40 sums in
// memory per pixel.
struct RowFit {
  explicit RowFit(int width)
      : jacobian(static_cast<size_t>(6 * (width + 1))),
        weight(static_cast<size_t>(width)),
        residual(static_cast<size_t>(width)),
        near_step_mm(static_cast<size_t>(width)) {}
  // Pixels n_first..n_end of the row into image region `region`'s sums.
  void add_to(int n_first, int n_end, int region, EvidenceSums* b) const {
    if (n_first >= n_end) return;
    b->camera_region_fit_pixels[region] += n_end - n_first;
    add_camera_fit(jacobian.data(), weight.data(), residual.data(), n_first, n_end, b->camera_score.data(),
                   b->camera_information.data(), b->camera_region_score + 6 * region,
                   b->camera_region_information + 6 * region);
    add_camera_bias_reach(jacobian.data(), weight.data(), near_step_mm.data(), n_first, n_end,
                          b->camera_region_bias_abs + 6 * region, b->camera_region_bias_square + 6 * region,
                          b->camera_region_near_step_abs + 6 * region);
  }
  std::vector<double> jacobian;
  std::vector<double> weight;
  std::vector<double> residual;
  std::vector<float> near_step_mm;
  int fit = 0;
  int left = 0;
};

// A robot pixel's weighted residual into the joints it moves.
void add_robot_pixel(double w, double r, bool in_naming_fit, double near_step_mm,
                     const std::vector<double>& joint_row, EvidenceSums* b) {
  ++b->robot_fit_pixels;
  b->robot_chi2 += w * r * r;
  for (size_t j = 0; j < joint_row.size(); ++j) {
    const double jj = joint_row[j];
    if (jj == 0.0) continue;
    ++b->joint_fit_pixels[j];
    b->joint_score[j] -= w * jj * r;
    b->joint_information[j] += w * jj * jj;
    b->joint_bias_abs[j] += w * std::abs(jj);
    b->joint_bias_square[j] += w * w * jj * jj;
    b->joint_near_step_abs[j] += near_step_mm * w * std::abs(jj);
    if (!in_naming_fit) continue;
    b->joint_naming_score[j] -= w * jj * r;
    b->joint_naming_information[j] += w * jj * jj;
  }
}

// A static pixel's weighted residual into the static chi2 and, inside the
// gate, into the row's camera fit (its Jacobian already in the row's slot).
void add_static_pixel(double w, double r, bool in_naming_fit, float near_step_mm, bool left_half,
                      double z_per_radial, RowFit* row, EvidenceSums* b) {
  b->static_chi2 += w * r * r;
  // A static pixel beyond the gate is outside the camera's linear model
  // as the naming fit's are outside the joints': a pose off by the
  // test's delta (2 cm, 1 degree) moves smooth static surfaces by a few
  // sigma, while an object in front of them (a person walking past
  // the wall) differs by tens of centimetres. Its clipped residual
  // would say only that something is there, and the protective fields
  // judge that; in the camera fit it would pull the pose.
  if (!in_naming_fit) return;
  // The common distance offset: J = f (a distance read d mm farther
  // changes Z by f d), with the pixel's camera Jacobian for the cross terms.
  const double* camera_jacobian = row->jacobian.data() + 6 * row->fit;
  b->distance_offset_score -= w * z_per_radial * r;
  b->distance_offset_information += w * z_per_radial * z_per_radial;
  for (int a = 0; a < 6; ++a) b->distance_offset_cross[a] += w * z_per_radial * camera_jacobian[a];
  // Into the row's camera fit (added at the row's end, sum_row).
  row->weight[static_cast<size_t>(row->fit)] = w;
  row->residual[static_cast<size_t>(row->fit)] = r;
  row->near_step_mm[static_cast<size_t>(row->fit)] = near_step_mm;
  if (left_half) row->left = row->fit + 1;
  ++row->fit;
}

// Pixel (u, v) (index i) into the band's sums.
void add_pixel(const EvidenceFrame& f, int u, int v, int i, std::vector<double>* joint_row, RowFit* row,
               EvidenceSums* b) {
  const int t = f.camera.depth_mm[static_cast<size_t>(i)];
  const int gen = f.rendered.depth_mm[static_cast<size_t>(i)];
  if (t <= 0 || gen <= 0 || f.silhouette[static_cast<size_t>(i)]) return;
  bool moved = false;
  int link = -1;
  // A static pixel's camera Jacobian goes straight into the row's
  // next slot (kept only if the pixel enters the camera fit).
  double* camera_row = row->jacobian.data() + 6 * row->fit;
  if (!EvidencePixelAccess::at_pixel(f.jacobian, u, v, camera_row, joint_row->data(), &moved, &link)) return;
  if (!moved && f.have_explained && f.explained_static[static_cast<size_t>(i)]) return;
  const EvidenceOptions& options = f.options;
  const double sigma_d = f.noise.sigma_mm(t);
  const double var = sigma_d * sigma_d + options.model_sigma_mm * options.model_sigma_mm;
  const double limit = options.clip_sigmas * std::sqrt(var);
  const double raw_r = static_cast<double>(gen - t);
  const double r = std::clamp(raw_r, -limit, limit);
  const bool in_naming_fit = std::abs(raw_r) <= options.naming_gate_sigmas * std::sqrt(var);
  const double w = f.inv_pps / var;
  b->link_sum_wr[link] += w * r;
  b->link_sum_w[link] += w;
  const float near_step_mm = f.near_step_mm.empty() ? 0.0f : f.near_step_mm[static_cast<size_t>(i)];
  if (moved) {
    add_robot_pixel(w, r, in_naming_fit, near_step_mm, *joint_row, b);
  } else {
    add_static_pixel(w, r, in_naming_fit, near_step_mm, u < f.camera.width / 2,
                     z_per_radial(f.camera.fx, f.camera.fy, f.camera.cx, f.camera.cy, u, v), row, b);
  }
}

// Row v's sampled pixels u_first..u_end into the band's sums, its static
// pixels in the camera fit left half then right (the image quadrants,
// discrepancy_t.camera_region_*), each sum taking the pixels in the order
// of the row as the pixels came.
void sum_row(const EvidenceFrame& f, int v, int u_first, int u_end, std::vector<double>* joint_row,
             RowFit* row, EvidenceSums* b) {
  row->fit = 0;
  row->left = 0;
  const int stride = f.stride;
  for (int u = (u_first + stride - 1) / stride * stride; u < u_end; u += stride) {
    add_pixel(f, u, v, v * f.camera.width + u, joint_row, row, b);
  }
  b->camera_fit_pixels += row->fit;
  const bool lower = v >= f.camera.height / 2;
  row->add_to(0, row->left, lower ? 2 : 0, b);
  row->add_to(row->left, row->fit, lower ? 3 : 1, b);
}

// Band `band` of kEvidenceBands (the image's pixels in bands of rows) into
// *b: its rows, each from the band's first pixel (first row) to its last
// (last row); with a sampling stride k every k-th row and column.
void sum_band(const EvidenceFrame& f, int band, EvidenceSums* b) {
  const int width = f.camera.width;
  const int num_pixels = width * f.camera.height;
  std::vector<double> joint_row(f.jacobian.num_joints(), 0.0);
  const int first = static_cast<int>(static_cast<int64_t>(num_pixels) * band / kEvidenceBands);
  const int last = static_cast<int>(static_cast<int64_t>(num_pixels) * (band + 1) / kEvidenceBands);
  if (first >= last) return;
  RowFit row(width);
  for (int v = first / width; v <= (last - 1) / width; ++v) {
    if (v % f.stride != 0) continue;
    const int row_start = v * width;
    sum_row(f, v, std::max(first - row_start, 0), std::min(last - row_start, width), &joint_row, &row, b);
  }
}

// The frame's sums: the image in kEvidenceBands bands of rows, each summed
// on its own (a WorkerPool task when `workers` is given) and the bands
// added in order: the sums are the same whichever threads run them.
EvidenceSums sum_frame(const EvidenceFrame& f, int num_links, WorkerPool* workers) {
  const int num_joints = f.jacobian.num_joints();
  std::vector<EvidenceSums> bands(kEvidenceBands, EvidenceSums(num_links, num_joints));
  const auto one = [&](int band) { sum_band(f, band, &bands[static_cast<size_t>(band)]); };
  run_tasks(workers, kEvidenceBands, one);
  EvidenceSums total(num_links, num_joints);
  for (const EvidenceSums& b : bands) total.add(b);
  return total;
}

// The sums the summary carries as they are.
void store_sums(const EvidenceSums& total, discrepancy_t* s) {
  s->robot_fit_pixels = total.robot_fit_pixels;
  s->robot_chi2 = total.robot_chi2;
  s->static_chi2 = total.static_chi2;
  s->camera_fit_pixels = total.camera_fit_pixels;
  s->joint_fit_pixels = total.joint_fit_pixels;
  s->joint_score = total.joint_score;
  s->joint_information = total.joint_information;
  s->joint_naming_score = total.joint_naming_score;
  s->joint_naming_information = total.joint_naming_information;
  std::copy(total.camera_region_fit_pixels, total.camera_region_fit_pixels + 4, s->camera_region_fit_pixels);
  std::copy(total.camera_region_score, total.camera_region_score + 24, s->camera_region_score);
  std::copy(total.camera_region_information, total.camera_region_information + 24,
            s->camera_region_information);
  s->distance_offset_score = total.distance_offset_score;
  s->distance_offset_information = total.distance_offset_information;
  std::copy(total.distance_offset_cross, total.distance_offset_cross + 6, s->distance_offset_cross);
}

// The camera fit: its score, its information (both halves) and the
// correction it solves for.
void store_camera_fit(const EvidenceSums& total, discrepancy_t* s) {
  const Eigen::Matrix<double, 6, 1> camera_score = total.camera_score;
  Eigen::Matrix<double, 6, 6> camera_information = total.camera_information;
  camera_information = camera_information.selfadjointView<Eigen::Upper>();
  Eigen::Matrix<double, 6, 1> correction = Eigen::Matrix<double, 6, 1>::Zero();
  if (s->camera_fit_pixels > 0) {
    const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt(camera_information);
    const Eigen::Matrix<double, 6, 1> d = ldlt.vectorD();
    // Rank-deficient (e.g. a single plane seen head-on leaves the sideways
    // translation unobservable): no correction.
    if (ldlt.info() == Eigen::Success && ldlt.isPositive() && d.maxCoeff() > 0 &&
        d.minCoeff() > 1e-12 * d.maxCoeff()) {
      correction = ldlt.solve(camera_score);
      if (!correction.allFinite()) correction.setZero();
    }
  }
  for (int k = 0; k < 6; ++k) {
    s->camera_score[k] = camera_score[k];
    s->camera_correction[k] = correction[k];
    for (int c = 0; c < 6; ++c) s->camera_information[6 * k + c] = camera_information(k, c);
  }
}

// The composite null (EvidenceOptions::static_bias_mm): every detection
// score shrunk by the most a static error within the bound gives it. After
// store_camera_fit: the fitted correction stays the plain fit's (what the
// camera pose looks like), the scores the tests read are shrunk. The naming
// fit is left plain: it names a joint among joints, all biased alike.
void shrink_by_static_error(const EvidenceSums& total, const EvidenceOptions& options, discrepancy_t* s) {
  const double b = options.static_bias_mm;
  const double fp = kFixedPatternSigmas * options.fixed_pattern_sigma_mm;
  s->joint_static_bound.assign(s->joint_score.size(), 0.0);
  if (!(b > 0) && !(fp > 0) && options.silhouette_band_px <= 0) return;
  // near_step_abs carries each pixel's silhouette allowance already.
  const auto bound = [&](double bias_abs, double bias_square, double near_step_abs) {
    return b * bias_abs + near_step_abs + fp * std::sqrt(bias_square);
  };
  for (size_t j = 0; j < s->joint_score.size(); ++j) {
    s->joint_static_bound[j] =
        bound(total.joint_bias_abs[j], total.joint_bias_square[j], total.joint_near_step_abs[j]);
    s->joint_score[j] = shrink_score(s->joint_score[j], s->joint_static_bound[j]);
  }
  for (int a = 0; a < 6; ++a) {
    double image_abs = 0, image_square = 0, image_near_step = 0;
    for (int r = 0; r < 4; ++r) {
      const int k = 6 * r + a;
      image_abs += total.camera_region_bias_abs[k];
      image_square += total.camera_region_bias_square[k];
      image_near_step += total.camera_region_near_step_abs[k];
      s->camera_region_static_bound[k] =
          bound(total.camera_region_bias_abs[k], total.camera_region_bias_square[k],
                total.camera_region_near_step_abs[k]);
      s->camera_region_score[k] = shrink_score(s->camera_region_score[k], s->camera_region_static_bound[k]);
    }
    s->camera_static_bound[a] = bound(image_abs, image_square, image_near_step);
    s->camera_score[a] = shrink_score(s->camera_score[a], s->camera_static_bound[a]);
  }
}

// Each link's weighted mean residual (mm) and its sigma.
void store_link_bias(const EvidenceSums& total, int num_links, discrepancy_t* s) {
  s->num_link_bias = num_links;
  s->link_bias_mm.assign(num_links, 0.0f);
  s->link_bias_sigma_mm.assign(num_links, 0.0f);
  for (int l = 0; l < num_links; ++l) {
    if (total.link_sum_w[l] <= 0) continue;
    s->link_bias_mm[l] = static_cast<float>(total.link_sum_wr[l] / total.link_sum_w[l]);
    s->link_bias_sigma_mm[l] = static_cast<float>(1.0 / std::sqrt(total.link_sum_w[l]));
  }
}

}  // namespace

std::vector<uint8_t> step_distance_px(const depth_image_t& rendered, int max_px, double silhouette_jump_mm) {
  const int width = rendered.width;
  const int height = rendered.height;
  const size_t pixels = static_cast<size_t>(std::max(width, 0)) * static_cast<size_t>(std::max(height, 0));
  std::vector<uint8_t> distance(pixels, 0);
  if (max_px <= 0 || pixels == 0 || rendered.depth_mm.size() != pixels) return distance;
  max_px = std::min(max_px, 255);
  const int limit = silhouette_step_limit_mm(silhouette_jump_mm);
  // farthest: the farthest rendered depth within k pixels (Chebyshev), one
  // 3x3 dilation per k (pixels outside the image take no part). In float:
  // depths in mm up to 65535 and reach below 2^24 are exact.
  cv::Mat1f farthest(height, width);
  // reach: the depth a surface within k must exceed to be a step.
  cv::Mat1f reach(height, width);
  float* far = farthest.ptr<float>(0);
  float* beyond = reach.ptr<float>(0);
  size_t open = 0;  // pixels with a surface and no step found yet
  for (size_t i = 0; i < pixels; ++i) {
    const int gen = rendered.depth_mm[i];
    far[i] = static_cast<float>(gen);
    beyond[i] = gen > 0 ? static_cast<float>(gen + limit) : std::numeric_limits<float>::infinity();
    if (gen > 0) ++open;
  }
  const cv::Mat square = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3));
  for (int k = 1; k <= max_px && open > 0; ++k) {
    cv::dilate(farthest, farthest, square);
    for (size_t i = 0; i < pixels; ++i) {
      if (distance[i] == 0 && far[i] > beyond[i]) {
        distance[i] = static_cast<uint8_t>(k);
        --open;
      }
    }
  }
  return distance;
}

std::vector<uint8_t> near_side_of_steps(const depth_image_t& rendered, int band_px, double silhouette_jump_mm,
                                        const std::vector<uint8_t>* farther_from) {
  const int width = rendered.width;
  const int height = rendered.height;
  const size_t pixels = static_cast<size_t>(std::max(width, 0)) * static_cast<size_t>(std::max(height, 0));
  std::vector<uint8_t> near(pixels, 0);
  if (band_px <= 0 || pixels == 0 || rendered.depth_mm.size() != pixels) return near;
  TOFGUARD_DEMAND(farther_from == nullptr || farther_from->size() == pixels,
                  "near_side_of_steps: farther_from has " + std::to_string(farther_from->size()) +
                      " entries for " + std::to_string(pixels) + " pixels");
  band_px = std::min(band_px, 255);
  const int limit = silhouette_step_limit_mm(silhouette_jump_mm);
  // The farthest rendered depth within band_px (Chebyshev): one dilation
  // by the (2 band_px + 1)-square, which equals band_px 3x3 dilations
  // (step_distance_px's) at a fraction of their cost. Pixels outside the
  // image take no part; one that may not be the farther surface takes
  // part as none (0). In float: depths in mm are exact.
  cv::Mat1f farthest(height, width);
  float* far = farthest.ptr<float>(0);
  for (size_t i = 0; i < pixels; ++i) {
    far[i] = farther_from == nullptr || (*farther_from)[i] ? static_cast<float>(rendered.depth_mm[i]) : 0.0f;
  }
  const cv::Mat square =
      cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * band_px + 1, 2 * band_px + 1));
  cv::dilate(farthest, farthest, square);
  for (size_t i = 0; i < pixels; ++i) {
    const int gen = rendered.depth_mm[i];
    near[i] = gen > 0 && far[i] > static_cast<float>(gen + limit) ? 1 : 0;
  }
  return near;
}

std::vector<float> near_step_allowance_mm(const depth_image_t& rendered, const link_labels_t& labels,
                                          const EvidenceOptions& options, double silhouette_jump_mm) {
  if (options.silhouette_band_px <= 0) return {};
  // Per link (labels' order): its own allowance where commissioning
  // measured one, silhouette_bias_mm otherwise.
  std::vector<float> by_link(static_cast<size_t>(std::max(labels.num_links, 0)),
                             static_cast<float>(options.silhouette_bias_mm));
  for (size_t k = 0; k < by_link.size() && k < labels.link_name.size(); ++k) {
    const auto own = options.silhouette_bias_by_link_mm.find(labels.link_name[k]);
    if (own != options.silhouette_bias_by_link_mm.end()) by_link[k] = static_cast<float>(own->second);
  }
  const double band_step_mm =
      silhouette_band_step_or_jump_mm(options.silhouette_band_step_mm, silhouette_jump_mm);
  const std::vector<uint8_t> near = near_side_of_steps(rendered, options.silhouette_band_px, band_step_mm);
  std::vector<float> allowance(near.size(), 0.0f);
  const bool labelled = labels.label.size() == near.size();
  if (!labelled) {
    for (size_t i = 0; i < near.size(); ++i)
      if (near[i]) allowance[i] = static_cast<float>(options.silhouette_bias_mm);
    return allowance;
  }
  // The arm's pixels, and the pixels within the band of a farther one.
  std::vector<uint8_t> arm(near.size(), 0);
  for (size_t i = 0; i < near.size(); ++i) {
    const int link = link_of_label(labels.label[i], labels.num_robot_links, labels.num_links);
    arm[i] = link >= 0 && link < labels.num_robot_links ? 1 : 0;
  }
  const std::vector<uint8_t> before_arm =
      near_side_of_steps(rendered, options.silhouette_band_px, band_step_mm, &arm);
  for (size_t i = 0; i < near.size(); ++i) {
    if (!near[i]) continue;
    if (arm[i]) {
      allowance[i] = by_link[static_cast<size_t>(
          link_of_label(labels.label[i], labels.num_robot_links, labels.num_links))];
    } else if (before_arm[i] > 0) {
      allowance[i] = static_cast<float>(options.silhouette_bias_mm);
    }
  }
  return allowance;
}

void compute_evidence(const depth_image_t& camera, const depth_image_t& rendered, const link_labels_t& labels,
                      const std::vector<uint8_t>& silhouette, double silhouette_jump_mm,
                      const DepthNoise& noise, const EvidenceOptions& options, discrepancy_t* summary,
                      WorkerPool* workers, SideTask* beside) {
  discrepancy_t& s = *summary;
  clear_evidence(&s);
  const EvidenceJacobian jacobian(rendered, labels, silhouette_jump_mm);
  const int num_pixels = camera.width * camera.height;
  if (!jacobian.available() || camera.depth_mm.size() != static_cast<size_t>(num_pixels) ||
      silhouette.size() != static_cast<size_t>(num_pixels)) {
    return;
  }
  // The naming search first: the static pixels that the best joint's
  // offset explains (the real arm where the model's is not) are the arm's
  // evidence, not the camera's, and stay out of the camera fit.
  std::vector<uint8_t> explained_static;
  search_joint_offsets(camera, rendered, labels, jacobian.kinematics(), noise, options, &s, &explained_static,
                       workers, beside);
  const int stride = evidence_stride(camera.width, camera.height, options.max_pixels);
  const std::vector<float> near_step_mm =
      near_step_allowance_mm(rendered, labels, options, silhouette_jump_mm);
  const EvidenceFrame frame{camera,
                            rendered,
                            silhouette,
                            near_step_mm,
                            explained_static,
                            explained_static.size() == static_cast<size_t>(num_pixels),
                            jacobian,
                            noise,
                            options,
                            stride,
                            1.0 / sampled_pixels_per_sample(options.pixels_per_sample, stride)};
  const EvidenceSums total = sum_frame(frame, labels.num_links, workers);
  store_sums(total, &s);
  store_camera_fit(total, &s);
  shrink_by_static_error(total, options, &s);
  store_link_bias(total, labels.num_links, &s);
  s.num_joints = jacobian.num_joints();
  s.joint_name = labels.joint_name;
  s.evidence_available = true;
}

}  // namespace tofguard::discrepancy
