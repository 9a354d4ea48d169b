#include "host/nn/embedded_models.h"

// The models' bytes, assembled into read-only data (GNU as .incbin): 2.6 and 2.3 MB, read once per use.
#define LITGS_EMBED(symbol, file)         \
  __asm__(                                \
      ".pushsection .rodata\n"            \
      ".global " #symbol                  \
      "\n"                                \
      ".balign 16\n" #symbol              \
      ":\n"                               \
      ".incbin \"" file                   \
      "\"\n"                              \
      ".global " #symbol "_end\n" #symbol \
      "_end:\n"                           \
      ".popsection\n");                   \
  extern "C" const char symbol[];         \
  extern "C" const char symbol##_end[];

LITGS_EMBED(litgs_xfeat_onnx, LITGS_XFEAT_MODEL_FILE)
LITGS_EMBED(litgs_lighterglue_onnx, LITGS_LIGHTERGLUE_MODEL_FILE)

namespace litgs::host::nn {

io::OnnxModel xfeat_model(const std::filesystem::path& path) {
  if (!path.empty()) return io::read_onnx_model(path);
  return io::parse_onnx_model(litgs_xfeat_onnx, size_t(litgs_xfeat_onnx_end - litgs_xfeat_onnx),
                              "the embedded xfeat_640x640.onnx");
}

io::OnnxModel lighterglue_model(const std::filesystem::path& path) {
  if (!path.empty()) return io::read_onnx_model(path);
  return io::parse_onnx_model(litgs_lighterglue_onnx,
                              size_t(litgs_lighterglue_onnx_end - litgs_lighterglue_onnx),
                              "the embedded lighterglue_L3.onnx");
}

}  // namespace litgs::host::nn
