#include "tofguard/discrepancy/evidence.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

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
      jump_mm_(silhouette_jump_mm > 0 ? silhouette_jump_mm : 1e9),
      depth_(rendered.depth_mm.data()),
      label_(labels.label.data()) {
  const size_t pixels = static_cast<size_t>(std::max(width_, 0)) * static_cast<size_t>(std::max(height_, 0));
  if (rendered.depth_mm.size() != pixels || !(fx_ > 0) || !(fy_ > 0)) return;
  available_ = read_label_kinematics(labels, pixels, &kinematics_);
}

bool EvidenceJacobian::at(int i, double camera[6], double* joints, bool* moved, int* link_out) const {
  if (!available_ || i < 0 || i >= width_ * height_) return false;
  return at(i % width_, i / width_, camera, joints, moved, link_out);
}

bool EvidenceJacobian::at(int u, int v, double camera[6], double* joints, bool* moved, int* link_out) const {
  if (!available_) return false;
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
    return d > 0 && label_[n] == l && !silhouette_step(d, z_mm, jump_mm_);
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
  std::fill(joints, joints + kinematics_.num_joints, 0.0);
  const int first_axis = link < kinematics_.num_robot_links ? kinematics_.link_axis[link] : -1;
  *moved = first_axis >= 0;
  if (*moved) {
    for (int m = first_axis; m >= 0; m = kinematics_.axes[m].parent) {
      const LabelAxis& a = kinematics_.axes[m];
      // Revolute: v = direction x (p - origin) (mm per rad); prismatic:
      // v = direction (1000 mm per m).
      const double j = a.prismatic ? 1000.0 * g.dot(a.direction) : g.dot(a.direction.cross(p - a.origin_mm));
      joints[a.joint] += a.multiplier * j;
    }
    std::fill(camera, camera + 6, 0.0);
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
        joint_naming_information(num_joints, 0.0) {}
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
    }
    static_chi2 += o.static_chi2;
    camera_fit_pixels += o.camera_fit_pixels;
    camera_score += o.camera_score;
    camera_information += o.camera_information;
    for (int k = 0; k < 4; ++k) camera_region_fit_pixels[k] += o.camera_region_fit_pixels[k];
    for (int k = 0; k < 24; ++k) {
      camera_region_score[k] += o.camera_region_score[k];
      camera_region_information[k] += o.camera_region_information[k];
    }
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
  double static_chi2 = 0;
  int32_t camera_fit_pixels = 0;
  Eigen::Matrix<double, 6, 1> camera_score = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix<double, 6, 6> camera_information = Eigen::Matrix<double, 6, 6>::Zero();  // upper triangle
  int32_t camera_region_fit_pixels[4] = {0, 0, 0, 0};
  double camera_region_score[24] = {};
  double camera_region_information[24] = {};
};

}  // namespace

void compute_evidence(const depth_image_t& camera, const depth_image_t& rendered, const link_labels_t& labels,
                      const std::vector<uint8_t>& silhouette, double silhouette_jump_mm,
                      const DepthNoise& noise, const EvidenceParameters& parameters, discrepancy_t* summary,
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
  search_joint_offsets(camera, rendered, labels, jacobian.kinematics(), noise, parameters, &s,
                       &explained_static, workers, beside);
  const bool have_explained = explained_static.size() == static_cast<size_t>(num_pixels);
  const int num_links = labels.num_links;
  const int num_joints = jacobian.num_joints();
  const int16_t* tof = camera.depth_mm.data();
  const int16_t* gen = rendered.depth_mm.data();
  const double model_var = parameters.model_sigma_mm * parameters.model_sigma_mm;
  // Every stride-th pixel in u and v (EvidenceParameters::max_pixels), each
  // weighted for the noise correlation left between the sampled pixels.
  const int stride = evidence_stride(camera.width, camera.height, parameters.max_pixels);
  const double inv_pps = 1.0 / sampled_pixels_per_sample(parameters.pixels_per_sample, stride);
  const int half_width = camera.width / 2;
  const int half_height = camera.height / 2;
  // The image in kEvidenceBands bands of rows, each summed on its own (a
  // WorkerPool task when `workers` is given) and the bands added in order:
  // the sums are the same whichever threads run them.
  std::vector<EvidenceSums> bands(kEvidenceBands, EvidenceSums(num_links, num_joints));
  const auto sum_band = [&](int band) {
    EvidenceSums& b = bands[static_cast<size_t>(band)];
    std::vector<double> joint_row(num_joints, 0.0);
    double camera_row[6];
    const int first = static_cast<int>(static_cast<int64_t>(num_pixels) * band / kEvidenceBands);
    const int last = static_cast<int>(static_cast<int64_t>(num_pixels) * (band + 1) / kEvidenceBands);
    if (first >= last) return;
    const int width = camera.width;
    // The band's rows, each from the band's first pixel (first row) to its
    // last (last row); with a sampling stride k every k-th row and column.
    for (int v = first / width; v <= (last - 1) / width; ++v) {
      if (v % stride != 0) continue;
      const int row = v * width;
      const int u_first = std::max(first - row, 0);
      const int u_end = std::min(last - row, width);
      for (int u = (u_first + stride - 1) / stride * stride; u < u_end; u += stride) {
        const int i = row + u;
        const int t = tof[i];
        if (t <= 0 || gen[i] <= 0 || silhouette[i]) continue;
        bool moved = false;
        int link = -1;
        if (!jacobian.at(u, v, camera_row, joint_row.data(), &moved, &link)) continue;
        if (!moved && have_explained && explained_static[i]) continue;
        const double sigma_d = noise.sigma_mm(t);
        const double var = sigma_d * sigma_d + model_var;
        const double limit = parameters.clip_sigmas * std::sqrt(var);
        const double raw_r = static_cast<double>(gen[i] - t);
        const double r = std::clamp(raw_r, -limit, limit);
        const bool in_naming_fit = std::abs(raw_r) <= parameters.naming_gate_sigmas * std::sqrt(var);
        const double w = inv_pps / var;
        b.link_sum_wr[link] += w * r;
        b.link_sum_w[link] += w;
        if (moved) {
          ++b.robot_fit_pixels;
          b.robot_chi2 += w * r * r;
          for (int j = 0; j < num_joints; ++j) {
            const double jj = joint_row[j];
            if (jj == 0.0) continue;
            ++b.joint_fit_pixels[j];
            b.joint_score[j] -= w * jj * r;
            b.joint_information[j] += w * jj * jj;
            if (!in_naming_fit) continue;
            b.joint_naming_score[j] -= w * jj * r;
            b.joint_naming_information[j] += w * jj * jj;
          }
        } else {
          b.static_chi2 += w * r * r;
          // A static pixel beyond the gate is outside the camera's linear model
          // as the naming fit's are outside the joints': a pose off by the
          // test's delta (2 cm, 1 degree) moves smooth static surfaces by a few
          // sigma, while an object in front of them (a person walking past
          // the wall) differs by tens of centimetres. Its clipped residual
          // would say only that something is there, and the protective fields
          // judge that; in the camera fit it would pull the pose.
          if (!in_naming_fit) continue;
          ++b.camera_fit_pixels;
          // The image quadrant (discrepancy_t.camera_region_*).
          const int region = (u >= half_width ? 1 : 0) + (v >= half_height ? 2 : 0);
          ++b.camera_region_fit_pixels[region];
          double* region_score = b.camera_region_score + 6 * region;
          double* region_information = b.camera_region_information + 6 * region;
          // The upper triangle by hand: Eigen's rankUpdate on a 6x6
          // selfadjoint view costs more than the rest of the pixel.
          for (int a = 0; a < 6; ++a) {
            const double wj = w * camera_row[a];
            b.camera_score[a] -= wj * r;
            region_score[a] -= wj * r;
            region_information[a] += wj * camera_row[a];
            for (int c = a; c < 6; ++c) b.camera_information(a, c) += wj * camera_row[c];
          }
        }
      }
    }
  };
  if (workers != nullptr) {
    workers->run(kEvidenceBands, sum_band);
  } else {
    for (int band = 0; band < kEvidenceBands; ++band) sum_band(band);
  }
  EvidenceSums total(num_links, num_joints);
  for (const EvidenceSums& b : bands) total.add(b);
  s.robot_fit_pixels = total.robot_fit_pixels;
  s.robot_chi2 = total.robot_chi2;
  s.static_chi2 = total.static_chi2;
  s.camera_fit_pixels = total.camera_fit_pixels;
  s.joint_fit_pixels = total.joint_fit_pixels;
  s.joint_score = total.joint_score;
  s.joint_information = total.joint_information;
  s.joint_naming_score = total.joint_naming_score;
  s.joint_naming_information = total.joint_naming_information;
  std::copy(total.camera_region_fit_pixels, total.camera_region_fit_pixels + 4, s.camera_region_fit_pixels);
  std::copy(total.camera_region_score, total.camera_region_score + 24, s.camera_region_score);
  std::copy(total.camera_region_information, total.camera_region_information + 24,
            s.camera_region_information);
  const std::vector<double>& link_sum_wr = total.link_sum_wr;
  const std::vector<double>& link_sum_w = total.link_sum_w;
  Eigen::Matrix<double, 6, 1> camera_score = total.camera_score;
  Eigen::Matrix<double, 6, 6> camera_information = total.camera_information;
  camera_information = camera_information.selfadjointView<Eigen::Upper>();
  Eigen::Matrix<double, 6, 1> correction = Eigen::Matrix<double, 6, 1>::Zero();
  if (s.camera_fit_pixels > 0) {
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
    s.camera_score[k] = camera_score[k];
    s.camera_correction[k] = correction[k];
    for (int c = 0; c < 6; ++c) s.camera_information[6 * k + c] = camera_information(k, c);
  }
  s.num_link_bias = num_links;
  s.link_bias_mm.assign(num_links, 0.0f);
  s.link_bias_sigma_mm.assign(num_links, 0.0f);
  for (int l = 0; l < num_links; ++l) {
    if (link_sum_w[l] <= 0) continue;
    s.link_bias_mm[l] = static_cast<float>(link_sum_wr[l] / link_sum_w[l]);
    s.link_bias_sigma_mm[l] = static_cast<float>(1.0 / std::sqrt(link_sum_w[l]));
  }
  s.num_joints = num_joints;
  s.joint_name = labels.joint_name;
  s.evidence_available = true;
}

}  // namespace tofguard::discrepancy
