// The options `litgs-engine refine` shares with run.yaml's refine section (host/option_name.h).
#pragma once

#include "host/option_name.h"

namespace litgs::host::refine_option {

inline constexpr OptionName kTracks{
    "tracks", "--tracks",
    "Track source: auto or sfm (the front end's SCENE/sfm/, from litgs-engine match), oracle (projected "
    "from a synth scene's true poses: an experiment that separates the refinement from the front end)"};
inline constexpr OptionName kAnchors{
    "anchors", "--anchors",
    "The estimator's anchors (weights and priors): auto (with oracle tracks only; on the front end's tracks "
    "they made the poses worse, docs/refinement.md) | on | off"};
inline constexpr OptionName kPlanes{
    "planes", "!--no-planes",
    "LiDAR point-to-plane term (--no-planes: none; off where the scene has no "
    "LiDAR map)"};
inline constexpr OptionName kScans{
    "scans", "!--no-scans",
    "LiDAR scans in the solve from --scans-from-round on, each scan's points held to the planes of the map "
    "the current poses build from all scans (--no-scans: none; off where the scene has no scans)"};
inline constexpr OptionName kRounds{"rounds", "--rounds", "Rounds (association, solve, rejection)"};
inline constexpr OptionName kThreads{"threads", "--threads", "Ceres threads"};
// run.yaml's refine.absolute_priors decides it (run passes "absolute" or "odometry").
inline constexpr OptionName kPriors{
    "priors", "--priors",
    "auto (from scene.yaml's poses_origin: Metashape and COLMAP imports are absolute) | absolute (a pose "
    "prior "
    "on every frame) | odometry (relative priors between neighbouring frames)"};

}  // namespace litgs::host::refine_option
