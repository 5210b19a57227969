// tofguard-discrepancy: wires config + LCM + the library in src/.
#include <exception>
#include <iostream>

#include "tofguard/discrepancy/discrepancy_process.hpp"

int main(int argc, char** argv) {
  const tofguard::ProcessInfo info = tofguard::discrepancy::process_info();
  return tofguard::run_process(argc, argv, info,
                               [&](const tofguard::Config& config, const std::vector<std::string>&) {
                                 try {
                                   return tofguard::discrepancy::run_discrepancy(config);
                                 } catch (const std::exception& e) {
                                   std::cerr << info.name << ": " << e.what() << "\n";
                                   return 1;
                                 }
                               });
}
