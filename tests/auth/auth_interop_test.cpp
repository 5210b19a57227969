// The Python verifier and signer (auth/python/tofguard_auth.py) against the
// C++ ones (auth/include/tofguard/auth/): the same inputs give the same
// envelope byte for byte, and the same envelopes get the same verdicts,
// word for word, on both sides.
#include <filesystem>
#include <sstream>

#include <gtest/gtest.h>

#include "tofguard/auth/auth_key.hpp"
#include "tofguard/auth/message_signer.hpp"
#include "tofguard/auth/message_verifier.hpp"
#include "tofguard/safety_status_t.hpp"
#include "tofguard/speed_limit_t.hpp"
#include "tool_support.hpp"

namespace tofguard::auth {
namespace {

using test::bin_dir;
using test::output_dir;
using test::run_command;
using test::source_dir;

constexpr int64_t kNow = 1'800'000'000'000'000;
const std::string kPython = "/usr/bin/python3";

std::string tool() { return source_dir() + "/auth/python/tofguard_auth.py"; }

template <class T>
std::vector<uint8_t> encoded(const T& message) {
  std::vector<uint8_t> bytes(static_cast<size_t>(message.getEncodedSize()));
  message.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

void write_bytes(const std::string& path, const std::vector<uint8_t>& bytes) {
  test::write_file(path, std::string(bytes.begin(), bytes.end()));
}

std::string hex(const std::vector<uint8_t>& bytes) {
  std::ostringstream s;
  for (uint8_t b : bytes) s << std::hex << (b >> 4) << (b & 15);
  return s.str();
}

class AuthInteropTest : public ::testing::Test {
 protected:
  void SetUp() override {
    key_file_ = output_dir() + "/interop.key";
    std::filesystem::remove(key_file_);
    ASSERT_EQ(run_command("interop-keygen", {bin_dir() + "/tofguard-keygen", key_file_}), 0);
    key_ = read_auth_key_file(key_file_);
    status_.utime = kNow;
    status_.seq = 41;
    status_.motion_allowed = true;
    status_.stop = 0;
    status_.latched = false;
    status_.cause = 0;
    status_.reason = "reset accepted from operator: checked, ünïcode kept";
    status_.since_utime = kNow - 5;
  }

  std::string key_file_;
  AuthKey key_;
  safety_status_t status_{};
};

TEST_F(AuthInteropTest, PythonSignsTheSameBytesAsCpp) {
  MessageSigner signer(key_, kNow);
  const authenticated_message_t cpp = signer.sign("SAFETY_STATUS", status_, kNow);
  const std::string payload_file = output_dir() + "/interop-payload.bin";
  const std::string python_file = output_dir() + "/interop-python.bin";
  write_bytes(payload_file, encoded(status_));
  std::string out;
  ASSERT_EQ(run_command("interop-sign",
                        {kPython, tool(), "sign", "--key", key_file_, "--channel", "SAFETY_STATUS", "--utime",
                         std::to_string(kNow), "--seq", std::to_string(cpp.seq), payload_file, python_file},
                        &out),
            0)
      << out;
  const std::string python = test::read_file(python_file);
  const std::vector<uint8_t> cpp_bytes = encoded(cpp);
  ASSERT_EQ(python.size(), cpp_bytes.size());
  EXPECT_EQ(python, std::string(cpp_bytes.begin(), cpp_bytes.end()));  // fingerprint, fields and tag
  // And C++ opens what Python signed.
  authenticated_message_t from_python;
  ASSERT_EQ(from_python.decode(python.data(), 0, static_cast<int>(python.size())),
            static_cast<int>(python.size()));
  MessageVerifier verifier(key_, 250'000);
  std::string why;
  const auto status = verifier.open<safety_status_t>(from_python, "SAFETY_STATUS", kNow, &why);
  ASSERT_TRUE(status) << why;
  EXPECT_EQ(status->reason, status_.reason);
}

// The speed limit (speed_limit_t) as the Python module decodes it: its
// fingerprint from the .lcm's fields, every field in order.
TEST_F(AuthInteropTest, PythonDecodesTheSpeedLimitAsCppEncodesIt) {
  speed_limit_t limit{};
  limit.utime = kNow;
  limit.seq = 42;
  limit.camera_id = "tof-mast";
  limit.max_arm_speed_m_s = 0.625;
  limit.set_by = speed_limit_t::SET_BY_UNKNOWN_OBJECT;
  limit.separation_m = 0.9;
  limit.arm_speed_m_s = 0.25;
  limit.valid_for_ms = 150;
  limit.reason = "unknown object 0.90 m from the arm";
  const std::string payload_file = output_dir() + "/interop-speed-limit.bin";
  write_bytes(payload_file, encoded(limit));
  std::string out;
  ASSERT_EQ(
      run_command("interop-speed-limit",
                  {kPython, "-c",
                   "import sys; sys.path.insert(0, '" + source_dir() +
                       "/auth/python'); import tofguard_auth as t; "
                       "l = t.decode_speed_limit(open(sys.argv[1], 'rb').read()); "
                       "print(l['seq'], l['camera_id'], l['max_arm_speed_m_s'], l['set_by'], "
                       "repr(l['body_region']), l['separation_m'], l['arm_speed_m_s'], l['valid_for_ms'], "
                       "l['reason'])",
                   payload_file},
                  &out),
      0)
      << out;
  EXPECT_NE(out.find("42 tof-mast 0.625 1 '' 0.9 0.25 150 unknown object 0.90 m from the arm"),
            std::string::npos)
      << out;
}

TEST_F(AuthInteropTest, BothSidesGiveTheSameVerdictsInTheSameWords) {
  MessageSigner signer(key_, kNow);
  MessageSigner other_signer(read_auth_key_file([] {
                               const std::string path = output_dir() + "/interop-other.key";
                               std::filesystem::remove(path);
                               run_command("interop-keygen-other", {bin_dir() + "/tofguard-keygen", path});
                               return path;
                             }()),
                             kNow);
  const authenticated_message_t first = signer.sign("SAFETY_STATUS", status_, kNow);
  const authenticated_message_t second = signer.sign("SAFETY_STATUS", status_, kNow + 10);
  std::vector<authenticated_message_t> cases;
  cases.push_back(first);   // accepted
  cases.push_back(first);   // replayed
  cases.push_back(second);  // accepted
  cases.push_back(second);  // replayed
  authenticated_message_t altered = signer.sign("SAFETY_STATUS", status_, kNow + 20);
  altered.payload[20] ^= 1;  // forged
  cases.push_back(altered);
  cases.push_back(signer.sign("SAFETY_RISK", status_, kNow + 30));          // another channel
  cases.push_back(other_signer.sign("SAFETY_STATUS", status_, kNow + 40));  // another key
  cases.push_back(signer.sign("SAFETY_STATUS", status_, kNow - 400'000));   // stale
  cases.push_back(signer.sign("SAFETY_STATUS", status_, kNow + 300'000));   // from the future

  MessageVerifier verifier(key_, 250'000);
  std::vector<std::string> files;
  std::string expected;
  for (size_t i = 0; i < cases.size(); ++i) {
    files.push_back(output_dir() + "/interop-case-" + std::to_string(i) + ".bin");
    write_bytes(files.back(), encoded(cases[i]));
    const std::string why = verifier.check(cases[i], "SAFETY_STATUS", kNow);
    expected += (why.empty() ? "accepted " + hex(cases[i].payload) : "refused: " + why) + "\n";
  }
  std::vector<std::string> argv = {kPython,         tool(),        "verify",
                                   "--key",         key_file_,     "--channel",
                                   "SAFETY_STATUS", "--now-utime", std::to_string(kNow),
                                   "--max-age-ms",  "250"};
  argv.insert(argv.end(), files.begin(), files.end());
  std::string out, err;
  ASSERT_EQ(run_command("interop-verify", argv, &out, &err), 0) << err;
  EXPECT_EQ(out, expected);
  // The cases did what they say: two accepted, the rest refused.
  EXPECT_EQ(std::count(expected.begin(), expected.end(), '\n'), static_cast<long>(cases.size()));
  size_t accepted = 0;
  std::istringstream lines(expected);
  for (std::string line; std::getline(lines, line);) accepted += line.rfind("accepted ", 0) == 0 ? 1 : 0;
  EXPECT_EQ(accepted, 2u);
}

}  // namespace
}  // namespace tofguard::auth
