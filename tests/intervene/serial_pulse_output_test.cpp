// The pulsed power output (serial_pulse_output.hpp) on a pseudo-terminal:
// the tx line's pulse train while the power is on, none once it is off or
// the output is gone, and a one-line error for a missing device. A
// pseudo-terminal has no modem control lines: dtr / rts are checked to fail
// with a clear error there (on a USB serial adapter they toggle).
#include <gtest/gtest.h>

#include <string>

#include "pseudo_terminal.hpp"
#include "tofguard/intervene/serial_pulse_output.hpp"

namespace tofguard::intervene {
namespace {

using test::PseudoTerminal;

TEST(SerialPulseOutput, TxSendsOneBytePerPeriodOnlyWhileThePowerIsOn) {
  PseudoTerminal pty;
  ASSERT_FALSE(pty.device().empty()) << "no pseudo-terminal";
  SerialPulseOutput output({pty.device(), PulseLine::kTx, 25.0});
  EXPECT_EQ(output.half_period_us(), 20000);  // 25 Hz: a tick every 20 ms
  // Off at first: ticks send nothing.
  ASSERT_EQ(output.set_power(false, "start"), "");
  for (int k = 0; k < 10; ++k) ASSERT_EQ(output.half_period_tick(), "");
  EXPECT_EQ(pty.read_within(50), "");
  // On: one 0x55 per period, i.e. every second tick.
  ASSERT_EQ(output.set_power(true, "motion allowed"), "");
  for (int k = 0; k < 20; ++k) ASSERT_EQ(output.half_period_tick(), "");
  EXPECT_EQ(pty.read_bytes(10, 2000), std::string(10, '\x55'));
  EXPECT_EQ(pty.read_within(50), "");
  EXPECT_EQ(output.pulses(), 10);
  // Re-asserting "on" (the status rate) does not add or drop pulses.
  ASSERT_EQ(output.set_power(true, "motion allowed"), "");
  // Off: the pulses stop at once.
  ASSERT_EQ(output.set_power(false, "DANGEROUS"), "");
  for (int k = 0; k < 20; ++k) ASSERT_EQ(output.half_period_tick(), "");
  EXPECT_EQ(pty.read_within(50), "");
  EXPECT_EQ(output.pulses(), 10);
}

TEST(SerialPulseOutput, NothingIsSentOnceTheOutputIsGone) {
  PseudoTerminal pty;
  ASSERT_FALSE(pty.device().empty()) << "no pseudo-terminal";
  {
    SerialPulseOutput output({pty.device(), PulseLine::kTx, 50.0});
    ASSERT_EQ(output.set_power(true, "motion allowed"), "");
    for (int k = 0; k < 4; ++k) ASSERT_EQ(output.half_period_tick(), "");
  }
  EXPECT_EQ(pty.read_bytes(2, 2000), std::string(2, '\x55'));
  // Nobody ticks any more (the process died or hangs): no pulse comes.
  EXPECT_EQ(pty.read_within(100), "");
}

TEST(SerialPulseOutput, AMissingDeviceOrLineIsAOneLineError) {
  SerialPulseOutput missing({"/dev/tofguard-no-such-tty", PulseLine::kTx, 25.0});
  const std::string error = missing.set_power(true, "motion allowed");
  EXPECT_NE(error.find("/dev/tofguard-no-such-tty"), std::string::npos) << error;
  EXPECT_NE(error.find("cannot open"), std::string::npos) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos);
  EXPECT_NE(missing.half_period_tick(), "");
  PseudoTerminal pty;
  ASSERT_FALSE(pty.device().empty()) << "no pseudo-terminal";
  SerialPulseOutput dtr({pty.device(), PulseLine::kDtr, 25.0});
  ASSERT_EQ(dtr.set_power(true, "motion allowed"), "");
  const std::string line_error = dtr.half_period_tick();
  EXPECT_NE(line_error.find("(dtr): cannot set the line"), std::string::npos) << line_error;
}

}  // namespace
}  // namespace tofguard::intervene
