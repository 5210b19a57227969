// tofguard-renderer: wires config + LCM + the library in src/; also the
// one-shot `tofguard-renderer render ...` command.
#include <iostream>

#include "render_cli.hpp"
#include "renderer_process.hpp"

int main(int argc, char** argv) {
  if (argc >= 2 && std::string(argv[1]) == "render") {
    return tofguard::renderer::run_render_cli(std::vector<std::string>(argv + 2, argv + argc), std::cout, std::cerr);
  }
  const tofguard::ProcessInfo info = tofguard::renderer::process_info();
  return tofguard::run_process(argc, argv, info,
                               [&](const tofguard::Config&, const std::vector<std::string>&) {
                                 std::cerr << info.name << ": not implemented yet (issue 3)\n";
                                 return 1;
                               });
}
