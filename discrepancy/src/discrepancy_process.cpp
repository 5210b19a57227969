#include "tofguard/discrepancy/discrepancy_process.hpp"

#include <algorithm>
#include <cstdio>

#include "tofguard/common/clock.hpp"
#include "tofguard/common/lcm_node.hpp"
#include "tofguard/common/resident_heap.hpp"
#include "tofguard/common/wire_checks.hpp"
#include "tofguard/discrepancy/discrepancy_image.hpp"
#include "tofguard/discrepancy/frame_pairer.hpp"
#include "tofguard/discrepancy/witness_frames.hpp"

namespace tofguard::discrepancy {

ProcessInfo process_info() {
  ProcessInfo info{
      "tofguard-discrepancy",
      "Pairs camera and rendered frames by seq and computes I_dis = I_gen - I_ToF: TOF_DEPTH, "
      "TOF_RENDERED, TOF_LABELS -> SAFETY_DISCREPANCY (discrepancy_t), and optionally the colour "
      "image (discrepancy_image_t)."};
  info.per_camera = true;
  return info;
}

namespace {

// The other cameras' TOF_DEPTH and TOF_LABELS into `witnesses`.
void subscribe_witnesses(LcmNode& node, const DiscrepancyProcessSettings& settings,
                         WitnessFrames* witnesses) {
  for (size_t c = 0; c < settings.witnesses.size(); ++c) {
    const settings::WitnessCameraSettings& camera = settings.witnesses[c];
    const std::string id = camera.id;
    node.subscribe<depth_image_t>(
        node.images(), camera.depth_channel,
        [witnesses, c](const depth_image_t& image) { witnesses->add_depth(c, image); },
        [id](const depth_image_t& image) { return check_depth_image_from(image, id); });
    node.subscribe<link_labels_t>(
        node.images(), camera.labels_channel,
        [&node, witnesses, c, channel = camera.labels_channel](const link_labels_t& labels) {
          if (const std::string why = witnesses->add_labels(c, labels); !why.empty())
            node.errors().report(channel, channel + ": seq " + std::to_string(labels.seq) + ": " + why);
        },
        check_link_labels);
  }
}

}  // namespace

DiscrepancyOptions process_discrepancy_options(const DiscrepancyProcessSettings& settings) {
  DiscrepancyOptions options = discrepancy_options(settings.discrepancy);
  options.hidden_volume = hidden_volume_options(settings.detection_capability_m, settings.approach_speed_m_s);
  options.other_cameras = !settings.witnesses.empty();
  return options;
}

int run_discrepancy(const DiscrepancyProcessSettings& settings) {
  if (!keep_heap_resident())
    std::fprintf(stderr, "tofguard-discrepancy: warning: mallopt refused keep_heap_resident's settings\n");
  LcmNode node(settings.lcm, settings.channels, process_info().name);
  const DiscrepancySettings& dc = settings.discrepancy;
  const DiscrepancyOptions options = process_discrepancy_options(settings);
  WitnessFrames witnesses(settings.witnesses);
  FramePairer pairer(dc.pair_timeout_us, dc.max_pending_frames);
  RepeatCounter repeats;
  WorkerPool workers(dc.worker_threads);
  // (`worker_threads: auto` depends on the machine: say what it became.)
  std::fprintf(stderr,
               "tofguard-discrepancy: compute_discrepancy on %d thread(s) (discrepancy.worker_threads; %d "
               "CPUs allowed)\n",
               dc.worker_threads, allowed_cpu_count());
  int64_t judged = 0;
  int64_t unusable = 0;

  auto publish = [&](const discrepancy_t& summary) {
    node.safety().publish(settings.channels.discrepancy, &summary);
    node.counters().frames_out++;
    node.heartbeat().set_last_frame_utime(summary.utime);
    (summary.usable ? judged : unusable)++;
    node.heartbeat().set_status(
        "ok: " + std::to_string(judged) + " frames compared, " + std::to_string(unusable) + " unusable" +
        (node.errors().last().empty() ? "" : "; last error: " + node.errors().last()));
  };

  auto handle = [&](PairingOutput& out) {
    for (PairedFrame& pair : out.paired) {
      const int64_t start_us = monotonic_us();
      const depth_image_t empty{};
      DiscrepancyFrame frame =
          compute_discrepancy(pair.camera.image, pair.rendered ? *pair.rendered : empty, pair.labels, options,
                              &workers, witnesses.views_at(pair.camera.image.utime));
      frame.summary.depth_hash = pair.camera.depth_hash;
      frame.summary.repeat_count = pair.camera.repeat_count;
      frame.summary.compute_us = static_cast<int32_t>(monotonic_us() - start_us);
      if (!frame.summary.usable && frame.summary.unusable_kind == discrepancy_t::UNUSABLE_MISMATCHED) {
        node.errors().report(
            "pair", "seq " + std::to_string(frame.summary.seq) + ": " + frame.summary.unusable_reason);
      }
      publish(frame.summary);
      if (dc.colour_image_enabled) {
        const discrepancy_image_t colour = colour_image(frame, dc.colour_image_full_scale_mm);
        node.images().publish(dc.colour_image_channel, &colour);
      }
    }
    for (UnpairedFrame& lost : out.unpaired) {
      node.counters().frames_dropped++;
      node.errors().report("unpaired", "camera frame " + lost.reason);
      discrepancy_t summary =
          unusable_summary(lost.camera.image, discrepancy_t::UNUSABLE_NO_RENDERING, lost.reason);
      summary.depth_hash = lost.camera.depth_hash;
      summary.repeat_count = lost.camera.repeat_count;
      publish(summary);
    }
    node.counters().frames_dropped += out.dropped_partners;
  };

  const std::string camera_id = settings.camera_id;
  auto check_camera = [camera_id](const depth_image_t& image) {
    return check_depth_image_from(image, camera_id);
  };

  node.subscribe<depth_image_t>(
      node.images(), settings.channels.depth,
      [&](const depth_image_t& image) {
        PairingOutput out;
        CameraFrame frame{image, depth_hash(image.depth_mm), 0};
        frame.repeat_count = repeats.update(frame.depth_hash);
        pairer.add_camera(std::move(frame), monotonic_us(), &out);
        handle(out);
      },
      check_camera);
  node.subscribe<depth_image_t>(
      node.images(), settings.channels.rendered,
      [&](const depth_image_t& rendered) {
        PairingOutput out;
        pairer.add_rendered(rendered, monotonic_us(), &out);
        handle(out);
      },
      check_depth_image);
  node.subscribe<link_labels_t>(
      node.images(), settings.channels.labels,
      [&](const link_labels_t& labels) {
        PairingOutput out;
        pairer.add_labels(labels, monotonic_us(), &out);
        handle(out);
      },
      check_link_labels);
  subscribe_witnesses(node, settings, &witnesses);
  // Expire waiting frames at a tenth of the pairing timeout (at least 1 ms).
  node.add_timer(std::max<int64_t>(1000, dc.pair_timeout_us / 10), [&] {
    PairingOutput out;
    pairer.expire(monotonic_us(), &out);
    handle(out);
  });
  node.heartbeat().set_status("ok: waiting for frames");
  node.run();
  return 0;
}

}  // namespace tofguard::discrepancy
