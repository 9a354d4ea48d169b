// The front end's command-line options and summary, shared by `match` and `bench frontend`.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <memory>
#include <string>

#include "host/frontend/frontend.h"

namespace CLI {
class App;
}

namespace litgs::tools {

struct FrontendCli {
  host::frontend::FrontendOptions options;
  std::string features = "sift";
  std::string matcher = "auto";  // ratio for the classical detectors, mnn for xfeat
  std::filesystem::path model;   // xfeat's ONNX model (empty: the embedded one)
  std::string pairs = "covisible";
  bool clahe = true;
  bool no_prior_epipolar = false;
  std::string poses = "estimated";
  // Parses the text options into `options`, with the device detector when xfeat is asked for;
  // std::invalid_argument on a bad value, io::IoError on a bad model file.
  host::frontend::FrontendOptions resolved() const;
};

// --features --no-clahe --pairs --max-keypoints --threads and the finer knobs.
void add_frontend_options(CLI::App& command, const std::shared_ptr<FrontendCli>& cli);

// A progress line on stderr ("\r" updates), finished with a newline when a stage completes.
host::frontend::FrontendProgress progress_printer();

// The summary block: keypoints per image, pairs tried/verified, inlier ratio, tracks, points, mean track
// length, mean reprojection error, seconds per stage.
void print_summary(std::ostream& out, const std::string& title, const host::frontend::FrontendResult& r);

}  // namespace litgs::tools
