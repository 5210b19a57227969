// tofguard-risk: wires config + LCM + the library in src/.
#include <exception>
#include <iostream>

#include "tofguard/risk/risk_process.hpp"

int main(int argc, char** argv) {
  const tofguard::ProcessInfo info = tofguard::risk::process_info();
  return tofguard::run_process(argc, argv, info,
                               [&](const tofguard::Config& config, const std::vector<std::string>&) {
                                 try {
                                   return tofguard::risk::run_risk(config);
                                 } catch (const std::exception& e) {
                                   std::cerr << info.name << ": " << e.what() << "\n";
                                   return 1;
                                 }
                               });
}
