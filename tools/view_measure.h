#pragma once
// `reconar view --project DIR --measure "X1,Y1 X2,Y2"`: the view's tap-to-measure, headless.
#include <string>

#include "core/base/status.h"
#include "render/ar/ar_view.h"
#include "tools/args.h"

namespace reconar::tools {

// --measure "X1,Y1 X2,Y2" (two pixels of the video frame): opens the project's measurer into
// `options`. InvalidArgument for a malformed value or without --project; the measurer's errors
// (a project without a sparse model or mesh) as they are. Without --measure, in a window with
// --project, the measurer is opened for clicks when the project allows (else a note on stderr).
Status ReadMeasureArgs(const Args& args, ArViewOptions* options);

// The frame's JSON line with "measure": {"kind", "points", "value", "sigma", "unit", "ms"} (or
// {"error", "ms"}) added when the frame measured (or tried to); else as it is.
std::string WithMeasurement(std::string frame_json, const ViewMeasurement& measurement);

}  // namespace reconar::tools
