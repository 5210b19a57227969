// tofguard-discrepancy: wires config + LCM + the library in src/.
#include <iostream>

#include "discrepancy_process.hpp"

int main(int argc, char** argv) {
  const tofguard::ProcessInfo info = tofguard::discrepancy::process_info();
  return tofguard::run_process(argc, argv, info,
                               [&](const tofguard::Config&, const std::vector<std::string>&) {
                                 std::cerr << info.name << ": not implemented yet (issue 5)\n";
                                 return 1;
                               });
}
