#pragma once
// What `reconar reconstruct`, `reconar sfm` and `reconar capture --reconstruct` share
// (reconstruct_command.cc): the reconstruct options read from the command line, and the run of
// RunReconstruct (core/pipeline/reconstruct.h) with its printed report.
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/pipeline/project.h"
#include "core/pipeline/reconstruct.h"
#include "tools/args.h"

namespace reconar::tools {

// The options of `reconar reconstruct` that `args` holds (every other one at its default).
Result<ReconstructOptions> ReconstructOptionsFromArgs(const Args& args);

// Runs the reconstruction and prints its report (report.json with `json`); the exit code.
int ReconstructAndPrint(const std::vector<std::string>& paths, const Project& project,
                        const ReconstructOptions& options, bool json);

}  // namespace reconar::tools
