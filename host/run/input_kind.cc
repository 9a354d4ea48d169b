#include "host/run/input_kind.h"

namespace litgs::host::run {

std::string kind_name(InputKind kind) {
  switch (kind) {
    case InputKind::kScene:
      return "scene directory";
    case InputKind::kSynthetic:
      return "synthetic scene";
    case InputKind::kRosBag:
      return "ROS 1 bag";
    case InputKind::kLivo2:
      return "FAST-LIVO2 log folder";
    case InputKind::kMetashape:
      return "Metashape camera XML";
    case InputKind::kColmap:
      return "COLMAP sparse model";
    case InputKind::kUnknown:
      break;
  }
  return "unknown";
}

InputKind detect_input_kind(const std::string& input) {
  namespace fs = std::filesystem;
  if (input.rfind("synth:", 0) == 0) return InputKind::kSynthetic;
  const fs::path p(input);
  std::error_code ec;
  if (fs::is_regular_file(p, ec)) {
    const std::string ext = p.extension().string();
    if (ext == ".bag") return InputKind::kRosBag;
    if (ext == ".xml") return InputKind::kMetashape;
    return InputKind::kUnknown;
  }
  if (!fs::is_directory(p, ec)) return InputKind::kUnknown;
  if (fs::exists(p / "scene.yaml")) return InputKind::kScene;
  if (fs::is_directory(p / "result") && fs::is_directory(p / "pcd")) return InputKind::kLivo2;
  for (const fs::path& model : {p, p / "sparse" / "0", p / "sparse"})
    if (fs::exists(model / "cameras.bin") || fs::exists(model / "cameras.txt")) return InputKind::kColmap;
  return InputKind::kUnknown;
}

std::string input_kind_help() {
  return "expected a scene directory (with scene.yaml), a ROS 1 bag (.bag, with --calib), a FAST-LIVO2 Log "
         "folder (result/ and pcd/), a Metashape camera XML (.xml), a COLMAP model folder (cameras.bin or "
         "cameras.txt, or sparse/0/ inside), or synth:PRESET (facade, street, corridor)";
}

std::string synthetic_preset(const std::string& input) {
  return input.substr(std::string("synth:").size());
}

}  // namespace litgs::host::run
