// The authentication of messages that can allow motion (docs/security.md):
// the signer's envelope is accepted once, for its channel, by the holder of
// the same key, within the replay window; every alteration, another key,
// another channel, a replay and a stale message are refused with a reason.
// Also the key file's rules and tofguard-keygen.
#include <sys/stat.h>

#include <filesystem>

#include <gtest/gtest.h>

#include "tofguard/auth/auth_key.hpp"
#include "tofguard/auth/message_signer.hpp"
#include "tofguard/auth/message_verifier.hpp"
#include "tofguard/risk_t.hpp"
#include "tofguard/safety_status_t.hpp"
#include "tool_support.hpp"

namespace tofguard::auth {
namespace {

using test::bin_dir;
using test::output_dir;
using test::run_command;

constexpr int64_t kNow = 1'800'000'000'000'000;  // a wall clock, microseconds since the epoch
constexpr int64_t kMaxAgeUs = 250'000;

// A fresh key file made by tofguard-keygen.
std::string new_key_file(const std::string& name) {
  const std::string path = output_dir() + "/" + name + ".key";
  std::filesystem::remove(path);
  std::string out;
  EXPECT_EQ(run_command("keygen-" + name, {bin_dir() + "/tofguard-keygen", path}, &out), 0) << out;
  return path;
}

safety_status_t allowed_status() {
  safety_status_t s{};
  s.utime = kNow;
  s.seq = 7;
  s.motion_allowed = true;
  s.reason = "reset accepted";
  return s;
}

TEST(MessageVerifierTest, AcceptsTheSignedMessageOnceForItsChannelWithinTheWindow) {
  const AuthKey key = read_auth_key_file(new_key_file("accept"));
  MessageSigner signer(key, kNow);
  MessageVerifier verifier(key, kMaxAgeUs);
  const authenticated_message_t m = signer.sign("SAFETY_STATUS", allowed_status(), kNow);
  EXPECT_EQ(m.seq, kNow);  // the counter starts at the wall clock
  std::string why;
  const auto status = verifier.open<safety_status_t>(m, "SAFETY_STATUS", kNow + 1000, &why);
  ASSERT_TRUE(status) << why;
  EXPECT_TRUE(status->motion_allowed);
  EXPECT_EQ(status->reason, "reset accepted");
  // The same message again: a replay.
  EXPECT_FALSE(verifier.open<safety_status_t>(m, "SAFETY_STATUS", kNow + 2000, &why));
  EXPECT_NE(why.find("replayed: seq"), std::string::npos) << why;
  // The next one is accepted; the counter rises by one per message even
  // when the clock has not moved.
  const authenticated_message_t next = signer.sign("SAFETY_STATUS", allowed_status(), kNow);
  EXPECT_EQ(next.seq, kNow + 1);
  EXPECT_EQ(verifier.check(next, "SAFETY_STATUS", kNow + 3000), "");
}

TEST(MessageVerifierTest, RefusesEveryAlterationAnotherKeyAnotherChannelAndStaleMessages) {
  const AuthKey key = read_auth_key_file(new_key_file("refuse"));
  const AuthKey other_key = read_auth_key_file(new_key_file("refuse-other"));
  ASSERT_NE(key.id, other_key.id);
  MessageSigner signer(key, kNow);
  const authenticated_message_t good = signer.sign("SAFETY_RISK", risk_t{}, kNow);
  auto refusal = [&](const authenticated_message_t& m, const std::string& channel, int64_t now) {
    MessageVerifier fresh(key, kMaxAgeUs);  // nothing accepted before
    return fresh.check(m, channel, now);
  };
  ASSERT_EQ(refusal(good, "SAFETY_RISK", kNow), "");

  authenticated_message_t m = good;
  m.payload[m.payload.size() - 1] ^= 1;  // one bit of the verdict
  EXPECT_EQ(refusal(m, "SAFETY_RISK", kNow), "tag does not match (forged or altered)");
  m = good;
  m.utime += 1;
  EXPECT_EQ(refusal(m, "SAFETY_RISK", kNow), "tag does not match (forged or altered)");
  m = good;
  m.seq += 1000;  // a replay dressed up with a higher counter
  EXPECT_EQ(refusal(m, "SAFETY_RISK", kNow), "tag does not match (forged or altered)");
  m = good;
  m.tag[0] ^= 0x80;
  EXPECT_EQ(refusal(m, "SAFETY_RISK", kNow), "tag does not match (forged or altered)");
  m = good;
  m.channel = "SAFETY_STATUS";  // moved to another channel, tag kept
  EXPECT_EQ(refusal(m, "SAFETY_STATUS", kNow), "tag does not match (forged or altered)");
  // Signed for one channel, offered on another.
  EXPECT_NE(refusal(good, "SAFETY_STATUS", kNow).find("signed for channel 'SAFETY_RISK'"), std::string::npos);
  // Another key's holder.
  MessageVerifier other(other_key, kMaxAgeUs);
  EXPECT_NE(other.check(good, "SAFETY_RISK", kNow).find("not this deployment's key"), std::string::npos);
  // A forger who copies the key id but not the key.
  m = MessageSigner(other_key, kNow).sign("SAFETY_RISK", risk_t{}, kNow);
  m.key_id = key.id;
  EXPECT_EQ(refusal(m, "SAFETY_RISK", kNow), "tag does not match (forged or altered)");
  // The replay window, both ways, on the receiver's wall clock.
  EXPECT_EQ(refusal(good, "SAFETY_RISK", kNow + kMaxAgeUs), "");
  EXPECT_NE(refusal(good, "SAFETY_RISK", kNow + kMaxAgeUs + 1).find("stale: sent 250 ms ago"),
            std::string::npos);
  EXPECT_NE(refusal(good, "SAFETY_RISK", kNow - kMaxAgeUs - 1).find("stale"), std::string::npos);
}

TEST(MessageVerifierTest, ARefusedMessageDoesNotMoveTheReplayCounter) {
  const AuthKey key = read_auth_key_file(new_key_file("counter"));
  MessageSigner signer(key, kNow);
  MessageVerifier verifier(key, kMaxAgeUs);
  const authenticated_message_t first = signer.sign("SAFETY_RESET", risk_t{}, kNow);
  authenticated_message_t forged = signer.sign("SAFETY_RESET", risk_t{}, kNow);
  forged.tag[5] ^= 1;
  forged.seq += 1'000'000;
  EXPECT_NE(verifier.check(forged, "SAFETY_RESET", kNow), "");
  EXPECT_EQ(verifier.check(first, "SAFETY_RESET", kNow), "");
  // Counters are per channel: a status seq does not block a risk seq.
  const authenticated_message_t risk = signer.sign("SAFETY_RISK", risk_t{}, kNow);
  EXPECT_EQ(verifier.check(risk, "SAFETY_RISK", kNow), "");
}

TEST(MessageVerifierTest, APayloadOfAnotherTypeIsRefusedEvenWithAValidTag) {
  const AuthKey key = read_auth_key_file(new_key_file("payload"));
  MessageSigner signer(key, kNow);
  MessageVerifier verifier(key, kMaxAgeUs);
  const authenticated_message_t risk_as_status = signer.sign("SAFETY_STATUS", risk_t{}, kNow);
  std::string why;
  EXPECT_FALSE(verifier.open<safety_status_t>(risk_as_status, "SAFETY_STATUS", kNow, &why));
  EXPECT_EQ(why, "payload is not a safety_status_t (wrong fingerprint, or truncated)");
  // Trailing bytes after a valid message.
  std::vector<uint8_t> payload(static_cast<size_t>(allowed_status().getEncodedSize()));
  allowed_status().encode(payload.data(), 0, static_cast<int>(payload.size()));
  payload.push_back(0);
  const authenticated_message_t padded = signer.sign_payload("SAFETY_STATUS", payload, kNow);
  EXPECT_FALSE(verifier.open<safety_status_t>(padded, "SAFETY_STATUS", kNow, &why));
  EXPECT_NE(why.find("payload is not one safety_status_t (" + std::to_string(payload.size() - 1) + " of " +
                     std::to_string(payload.size()) + " bytes decoded)"),
            std::string::npos)
      << why;
}

TEST(AuthKeyFileTest, KeygenWritesAnOwnerOnlyKeyAndNeverOverwritesIt) {
  const std::string path = new_key_file("keygen");
  struct stat st {};
  ASSERT_EQ(::stat(path.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  EXPECT_EQ(test::read_file(path).size(), 65u);  // 64 hex digits and a newline
  const std::string id = read_auth_key_file(path).id;
  EXPECT_EQ(id.size(), 16u);
  std::string out, err;
  EXPECT_EQ(run_command("keygen-again", {bin_dir() + "/tofguard-keygen", path}, &out, &err), 2);
  EXPECT_EQ(err, "tofguard-keygen: " + path +
                     ": cannot create: File exists (remove the old key first to change it)\n");
  EXPECT_EQ(run_command("keygen-keep", {bin_dir() + "/tofguard-keygen", "--keep-existing", path}, &out), 0);
  EXPECT_EQ(read_auth_key_file(path).id, id);  // the key is still the same
  // Two keys are never the same.
  EXPECT_NE(read_auth_key_file(new_key_file("keygen-second")).id, id);
}

TEST(AuthKeyFileTest, RefusesAKeyOpenToOthersMissingOrMalformed) {
  const std::string path = new_key_file("rules");
  ::chmod(path.c_str(), 0640);
  try {
    read_auth_key_file(path);
    FAIL() << "a group-readable key was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), path +
                                         ": key file is open to group or others (mode 0640); it must be "
                                         "readable by the safety user only: chmod 600 " +
                                         path);
  }
  EXPECT_THROW(read_auth_key_file(output_dir() + "/no-such.key"), std::runtime_error);
  const std::string short_key = output_dir() + "/short.key";
  test::write_file(short_key, "abcdef\n");
  ::chmod(short_key.c_str(), 0600);
  try {
    read_auth_key_file(short_key);
    FAIL() << "a short key was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("expected 64 hex digits"), std::string::npos) << e.what();
  }
  test::write_file(short_key, std::string(64, 'g') + "\n");  // 64 characters, not hex
  EXPECT_THROW(read_auth_key_file(short_key), std::runtime_error);
}

}  // namespace
}  // namespace tofguard::auth
