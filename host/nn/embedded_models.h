// The learned front end's ONNX models (kernels/nn/models/, Apache-2.0: XFeat and LighterGlue) embedded in
// the binary at build time, so that an installed `litgs-engine` stays one file; a path given by the user
// replaces one.
#pragma once

#include <filesystem>

#include "io/onnx_model.h"

namespace litgs::host::nn {

// The embedded model when `path` is empty, else the file at `path` (io::IoError naming what is wrong).
io::OnnxModel xfeat_model(const std::filesystem::path& path = {});
io::OnnxModel lighterglue_model(const std::filesystem::path& path = {});

}  // namespace litgs::host::nn
