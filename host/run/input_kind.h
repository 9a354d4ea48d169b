// What INPUT of `litgs-engine run` is, from the file system alone.
#pragma once

#include <filesystem>
#include <string>

namespace litgs::host::run {

enum class InputKind {
  kUnknown,
  kScene,      // a scene directory (scene.yaml): used in place
  kSynthetic,  // "synth:PRESET": the built-in synthetic generator
  kRosBag,     // a .bag file (needs import.calib)
  kLivo2,      // a FAST-LIVO2 Log/ folder (result/ and pcd/; needs import.livo2_config)
  kMetashape,  // a Metashape camera .xml
  kColmap,     // a COLMAP sparse model folder (cameras.bin or cameras.txt), or a folder with sparse/0
};

std::string kind_name(InputKind kind);
// kUnknown for anything else (the caller says what was expected: input_kind_help()).
InputKind detect_input_kind(const std::string& input);
std::string input_kind_help();
// The synthetic preset a "synth:PRESET" input names ("" for "synth:").
std::string synthetic_preset(const std::string& input);

}  // namespace litgs::host::run
