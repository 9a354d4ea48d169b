// import: INPUT to a scene directory with the existing importers (`litgs-engine import KIND`, or `synth` for
// synth:PRESET); a scene directory is used in place.
#include <stdexcept>

#include "host/run/stage.h"

namespace litgs::host::run {
namespace {

namespace fs = std::filesystem;

fs::path first_existing(std::initializer_list<fs::path> candidates, const std::string& what) {
  for (const fs::path& p : candidates)
    if (fs::is_directory(p)) return p;
  std::string tried;
  for (const fs::path& p : candidates) tried += (tried.empty() ? "" : ", ") + p.string();
  throw std::invalid_argument("no " + what + " folder (tried " + tried + "): set import.images in run.yaml");
}

StagePlan plan(const StageContext& c) {
  const RunConfig::Import& o = c.config.import;
  StagePlan p;
  p.options = section_json(c.config, "import");
  p.options["kind"] = kind_name(c.kind);
  const std::string scene = (c.stage_dir("import") / "scene").string();
  const fs::path input = fs::absolute(c.input);
  switch (c.kind) {
    case InputKind::kScene:
      p.inputs = {input};  // used in place: nothing to run
      return p;
    case InputKind::kSynthetic: {
      const std::string preset =
          synthetic_preset(c.input.string()).empty() ? o.synth_preset : synthetic_preset(c.input.string());
      p.options["preset"] = preset;
      p.command = {"synth",
                   "--preset",
                   preset,
                   "--out",
                   scene,
                   "--frames",
                   std::to_string(o.synth_frames),
                   "--width",
                   std::to_string(o.synth_width),
                   "--height",
                   std::to_string(o.synth_height),
                   "--seed",
                   std::to_string(o.synth_seed),
                   "--force"};
      break;
    }
    case InputKind::kRosBag:
      if (o.calib.empty())
        throw std::invalid_argument(c.input.string() +
                                    " is a ROS 1 bag: give --calib FILE (M2DGR calibration_results.txt) or "
                                    "import.calib in run.yaml");
      p.inputs = {input, o.calib};
      p.command = {"import", "bag", "--bag", input.string(), "--calib", o.calib, "--out", scene};
      break;
    case InputKind::kLivo2:
      if (o.livo2_config.empty())
        throw std::invalid_argument(
            c.input.string() +
            " is a FAST-LIVO2 log folder: list its camera and extrinsic YAML files in "
            "import.livo2_config in run.yaml");
      p.inputs = {input};
      p.command = {"import", "livo2", "--log", input.string(), "--out", scene, "--config"};
      for (const std::string& y : o.livo2_config) {
        p.inputs.push_back(y);
        p.command.push_back(y);
      }
      break;
    case InputKind::kMetashape: {
      const fs::path images =
          o.images.empty() ? first_existing({input.parent_path() / "images"}, "images") : fs::path(o.images);
      p.inputs = {input, images};
      p.command = {"import",   "metashape",     "--xml", input.string(),
                   "--images", images.string(), "--out", scene};
      break;
    }
    case InputKind::kColmap: {
      fs::path model = input;
      for (const fs::path& m : {input / "sparse" / "0", input / "sparse"})
        if (fs::exists(m / "cameras.bin") || fs::exists(m / "cameras.txt")) {
          model = m;
          break;
        }
      const fs::path images =
          o.images.empty() ? first_existing({input / "images", input.parent_path() / "images"}, "images")
                           : fs::path(o.images);
      p.inputs = {model, images};
      p.command = {"import",   "colmap",        "--model", model.string(),
                   "--images", images.string(), "--out",   scene};
      break;
    }
    case InputKind::kUnknown:
      throw std::invalid_argument(c.input.string() + ": unknown kind of input: " + input_kind_help());
  }
  p.command.insert(p.command.end(), o.extra_args.begin(), o.extra_args.end());
  p.outputs = {c.stage_rel("import") / "scene"};
  return p;
}

nlohmann::json result(const StageContext& c) {
  const fs::path scene =
      c.kind == InputKind::kScene ? fs::absolute(c.input) : c.stage_dir("import") / "scene";
  size_t frames = 0;
  for ([[maybe_unused]] const auto& f : fs::directory_iterator(scene / "thermal")) ++frames;
  return {{"scene", scene.string()}, {"metrics", {{"frames", frames}, {"kind", kind_name(c.kind)}}}};
}

}  // namespace

Stage import_stage() {
  return {"import", "INPUT to a scene directory", plan, result};
}

}  // namespace litgs::host::run
