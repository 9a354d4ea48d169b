// LighterGlue as the front end's matcher (issue 47, `match --features xfeat --matcher lighterglue`): both
// frames' XFeat keypoints, normalized as LighterGlue expects, and descriptors through the network on the
// Vulkan device (kernels/nn/lighterglue.h); the mutual best pairs whose assignment probability is above
// MatchOptions::min_score, as XFeat's match_lighterglue keeps them.
#pragma once

#include <memory>
#include <vector>

#include "engine/context.h"
#include "host/frontend/matching.h"
#include "kernels/nn/nn_weights.h"

namespace litgs::host::nn {

// One image's inputs to LighterGlue: its keypoints normalized as LighterGlue expects ([n][2]) and its
// descriptors as floats ([n][descriptor_width]). Descriptors of another width, or not floats, are
// std::invalid_argument.
struct LighterGlueInputs {
  std::vector<float> keypoints, descriptors;
};
LighterGlueInputs lighterglue_inputs(const frontend::ImageFeatures& f, int width, int height,
                                     size_t descriptor_width);

// A matcher on `context`, which it keeps alive; safe to call from several threads (the device work is
// serialized). Descriptors other than LighterGlue's width of floats are std::invalid_argument.
frontend::LearnedMatcher make_lighterglue_matcher(std::shared_ptr<engine::Context> context,
                                                  const kernels::nn::LighterGlueWeights& weights,
                                                  double min_score);

}  // namespace litgs::host::nn
