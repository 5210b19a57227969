#pragma once
// How long a live chain whose fault has gone may take to judge frames SAFE
// again. A stop test the fault drove to h, which the frames hardly inform
// (its allowance for the camera's static error takes most of its drift
// under no fault), falls only by its bounded memory: below its warning
// level after half of risk::kEvidenceMemoryS. The whole memory covers
// that, the diagnosis's clearing test and its clean frames.
#include <chrono>

#include "tofguard/risk/sequential_evidence.hpp"

namespace tofguard::test {

constexpr std::chrono::seconds kRecoveryDeadline{static_cast<int>(risk::kEvidenceMemoryS)};

}  // namespace tofguard::test
