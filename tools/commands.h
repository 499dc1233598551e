#pragma once
// One function per `reconar` subcommand; argv[first] is the first argument after the name.

namespace reconar::tools {

int RunFeatures(int argc, char** argv, int first);
int RunMatch(int argc, char** argv, int first);
int RunBundleAdjust(int argc, char** argv, int first);
int RunSfm(int argc, char** argv, int first);
int RunTags(int argc, char** argv, int first);
int RunTrack(int argc, char** argv, int first);
int RunCalibrate(int argc, char** argv, int first);
int RunView(int argc, char** argv, int first);    // defined only with RECONAR_HAVE_VIEW
int RunRender(int argc, char** argv, int first);  // defined only with RECONAR_HAVE_VIEW
int RunExport(int argc, char** argv, int first);
int RunMesh(int argc, char** argv, int first);
int RunDense(int argc, char** argv, int first);
int RunTexture(int argc, char** argv, int first);
int RunReconstruct(int argc, char** argv, int first);
int RunMap(int argc, char** argv, int first);
int RunLocalize(int argc, char** argv, int first);
int RunCapture(int argc, char** argv, int first);
int RunMeasure(int argc, char** argv, int first);
int RunCompare(int argc, char** argv, int first);
// reconstruct and sfm (sparse_only: the sparse stages, no preview): tools/reconstruct_command.cc.
int RunReconstructCommand(int argc, char** argv, int first, const char* help, bool sparse_only);

}  // namespace reconar::tools

#include "core/base/status.h"
#include "core/features/sift/sift.h"
#include "core/pipeline/dense_stage.h"
#include "core/pipeline/feature_stage.h"
#include "core/pipeline/match_stage.h"
#include "tools/args.h"

namespace reconar::tools {

// --first-octave, --max-features, --contrast-threshold and --sift-memory-mib (MiB) shared by
// features, match, sfm and reconstruct.
Result<SiftOptions> SiftOptionsFromArgs(const Args& args);
inline const std::set<std::string> kSiftValuedOptions = {"first-octave", "max-features", "sift-memory-mib",
                                                         "contrast-threshold"};
// The feature stage's options: the SIFT ones above.
Result<FeatureStageOptions> FeatureStageOptionsFromArgs(const Args& args);

// --ratio, --checks, --min-inliers, --f-threshold, --exhaustive-up-to, --window, --retrieved and
// --threads over the values `options` holds.
Status ReadMatchArgs(const Args& args, MatchStageOptions* options);
inline const std::set<std::string> kMatchValuedOptions = {
    "ratio", "checks", "min-inliers", "f-threshold", "exhaustive-up-to", "window", "retrieved", "threads"};

// --level 0|1|2|auto, --max-image-size N, --method pmvs|patchmatch and the flag --no-fill, shared by dense and
// reconstruct (reconstruct_command.cc).
Status ReadDenseArgs(const Args& args, DenseStageOptions* dense);
inline const std::set<std::string> kDenseValuedOptions = {"level", "method", "max-image-size"};

}  // namespace reconar::tools
