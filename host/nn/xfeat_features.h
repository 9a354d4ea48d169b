// XFeat as the front end's detector (issue 47): each frame resized to sides that are multiples of 32 as
// XFeat does (bilinear), normalized as its instance norm does, the network and its post-processing on the
// Vulkan device (kernels/nn/xfeat.h), keypoints mapped back to the frame's pixels and the budget spread by
// the front end's grid bucketing, as for the other detectors.
#pragma once

#include <filesystem>
#include <memory>
#include <vector>

#include "engine/context.h"
#include "host/frontend/frontend.h"
#include "kernels/nn/nn_weights.h"

namespace litgs::host::nn {

// XFeat's input: pixels / 255 to zero mean and unit variance (InstanceNorm2d, eps 1e-5); a uniform frame is
// all zeros.
std::vector<float> xfeat_input(const frontend::Gray8& image);

// A detector on `context`, which it keeps alive; safe to call from several threads (the device work is
// serialized). Frames smaller than 32x32 are std::invalid_argument naming the size.
frontend::LearnedDetector make_xfeat_detector(std::shared_ptr<engine::Context> context,
                                              const kernels::nn::XfeatWeights& weights,
                                              const frontend::FeatureOptions& options);

// `options` with a learned detector when its features ask for one, and a learned matcher when its matcher
// is lighterglue (one Vulkan context of their own; the embedded models, or the files at `model` (XFeat) and
// `lighterglue` if given: io::IoError naming a missing or wrong file), else unchanged.
frontend::FrontendOptions with_learned_detector(frontend::FrontendOptions options,
                                                const std::filesystem::path& model = {},
                                                const std::filesystem::path& lighterglue = {});

}  // namespace litgs::host::nn
