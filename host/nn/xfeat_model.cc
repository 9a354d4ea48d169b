#include "host/nn/xfeat_model.h"

// The model's bytes, assembled into read-only data (GNU as .incbin): 2.6 MB, read once per use.
__asm__(
    ".pushsection .rodata\n"
    ".global litgs_xfeat_onnx\n"
    ".balign 16\n"
    "litgs_xfeat_onnx:\n"
    ".incbin \"" LITGS_XFEAT_MODEL_FILE
    "\"\n"
    ".global litgs_xfeat_onnx_end\n"
    "litgs_xfeat_onnx_end:\n"
    ".popsection\n");
extern "C" const char litgs_xfeat_onnx[];
extern "C" const char litgs_xfeat_onnx_end[];

namespace litgs::host::nn {

io::OnnxModel xfeat_model(const std::filesystem::path& path) {
  if (!path.empty()) return io::read_onnx_model(path);
  return io::parse_onnx_model(litgs_xfeat_onnx, size_t(litgs_xfeat_onnx_end - litgs_xfeat_onnx),
                              "the embedded xfeat_640x640.onnx");
}

}  // namespace litgs::host::nn
