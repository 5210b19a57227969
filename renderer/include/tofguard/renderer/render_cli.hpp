#pragma once
// `tofguard-renderer render ...`: renders one image from the command line,
// for checks and docs. Writes a 16-bit PNG of depth in millimetres (0 =
// nothing; OpenCV imwrite, CV_16UC1) and optionally a 16-bit PNG of labels
// (the label values of common/depth_frame.hpp).
#include <ostream>
#include <string>
#include <vector>

namespace tofguard::renderer {

// Usage text of the render subcommand.
std::string render_cli_usage();

// `args` are the arguments after "render". Returns the exit code: 0 written,
// 1 model error or unusable frame, 2 usage error; messages go to `err`, a
// one-line summary to `out`.
int run_render_cli(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

}  // namespace tofguard::renderer
