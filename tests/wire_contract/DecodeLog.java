// Decodes the log written by log_roundtrip_test with the generated Java
// classes (build/tofguard_lcmtypes.jar) and checks every field of the five
// fixed types against the values in sample_messages.hpp. Exit code 0 when
// all match, 1 with one line per mismatch otherwise.
import java.io.EOFException;
import java.io.IOException;
import java.util.Arrays;
import java.util.HashSet;
import java.util.Set;

import lcm.logging.Log;
import tofguard.camera_pose_t;
import tofguard.depth_image_t;
import tofguard.joint_state_t;
import tofguard.risk_t;
import tofguard.safety_status_t;

public class DecodeLog {
  static int failures = 0;

  static void check(String what, Object got, Object expected) {
    if (!got.equals(expected)) {
      System.out.println("MISMATCH " + what + ": got " + got + ", expected " + expected);
      failures++;
    }
  }

  public static void main(String[] args) throws IOException {
    Log log = new Log(args[0], "r");
    Set<String> seen = new HashSet<>();
    while (true) {
      Log.Event event;
      try {
        event = log.readNext();
      } catch (EOFException e) {
        break;
      }
      switch (event.channel) {
        case "TOF_DEPTH": {
          depth_image_t m = new depth_image_t(event.data);
          check("depth.utime", m.utime, 1700000000123456L);
          check("depth.seq", m.seq, 42L);
          check("depth.camera_id", m.camera_id, "tof-test");
          check("depth.width", m.width, 4);
          check("depth.height", m.height, 3);
          check("depth.fx", m.fx, 221.5);
          check("depth.fy", m.fy, 220.25);
          check("depth.cx", m.cx, 1.75);
          check("depth.cy", m.cy, 1.25);
          check("depth.calibrated", m.calibrated, true);
          check("depth.num_pixels", m.num_pixels, 12);
          check("depth.num_amplitude", m.num_amplitude, 12);
          short[] depth = new short[12];
          short[] amplitude = new short[12];
          for (int i = 0; i < 12; i++) {
            depth[i] = (short) (i == 5 ? -1 : 500 + 37 * i);
            amplitude[i] = (short) (100 * i);
          }
          check("depth.depth_mm", Arrays.toString(m.depth_mm), Arrays.toString(depth));
          check("depth.amplitude", Arrays.toString(m.amplitude), Arrays.toString(amplitude));
          break;
        }
        case "JOINT_STATE": {
          joint_state_t m = new joint_state_t(event.data);
          check("joints.utime", m.utime, 1700000000200000L);
          check("joints.robot_id", m.robot_id, "friend-test");
          check("joints.num_joints", m.num_joints, 3);
          check("joints.name", Arrays.toString(m.name), "[a1, a2, a3]");
          check("joints.position", Arrays.toString(m.position), "[0.5, -1.25, 3.0]");
          check("joints.velocity", Arrays.toString(m.velocity), "[0.1, 0.0, -0.2]");
          break;
        }
        case "CAMERA_POSE": {
          camera_pose_t m = new camera_pose_t(event.data);
          check("pose.utime", m.utime, 1700000000300000L);
          check("pose.camera_id", m.camera_id, "tof-test");
          check("pose.frame_id", m.frame_id, "world");
          check("pose.translation", Arrays.toString(m.translation), "[-0.35, -0.2, 1.55]");
          check("pose.rotation", Arrays.toString(m.rotation), "[0.5, -0.5, 0.5, -0.5]");
          break;
        }
        case "SAFETY_RISK": {
          risk_t m = new risk_t(event.data);
          check("risk.utime", m.utime, 1700000000123456L);
          check("risk.seq", m.seq, 42L);
          check("risk.level", m.level, risk_t.DANGEROUS);
          check("risk.cause", m.cause, risk_t.CAUSE_JOINT_ERROR);
          check("risk.suspect", m.suspect, "a4");
          check("risk.score", m.score, 123.5);
          check("risk.threshold", m.threshold, 50.0);
          check("risk.detail", m.detail, "joint a4 reads 10.0 deg less than seen");
          break;
        }
        case "SAFETY_STATUS": {
          safety_status_t m = new safety_status_t(event.data);
          check("status.utime", m.utime, 1700000000400000L);
          check("status.seq", m.seq, 7L);
          check("status.motion_allowed", m.motion_allowed, false);
          check("status.stop", m.stop, safety_status_t.STOP_SOFTWARE);
          check("status.latched", m.latched, true);
          check("status.cause", m.cause, risk_t.CAUSE_JOINT_ERROR);
          check("status.reason", m.reason, "DANGEROUS: joint error, suspect a4");
          check("status.since_utime", m.since_utime, 1700000000123999L);
          break;
        }
        default:
          continue;
      }
      seen.add(event.channel);
    }
    check("channels decoded", seen.size(), 5);
    if (failures > 0) {
      System.out.println("DecodeLog: " + failures + " mismatches");
      System.exit(1);
    }
    System.out.println("DecodeLog: all fields of 5 types match");
  }
}
