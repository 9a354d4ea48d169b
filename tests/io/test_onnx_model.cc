// io/onnx_model.h on the networks the repository ships (kernels/nn/models/) and on files broken on purpose.
// The counts it must find come from the models' README (nodes by type, parameters), not from this reader.
#include <gtest/gtest.h>
#include <onnx/onnx_pb.h>

#include <filesystem>
#include <fstream>
#include <map>

#include "io/error.h"
#include "io/onnx_model.h"

namespace litgs::io {
namespace {

namespace fs = std::filesystem;

const fs::path kModels = LITGS_NN_MODELS;
const fs::path kXfeat = kModels / "xfeat" / "xfeat_640x640.onnx";
const fs::path kLighterGlue = kModels / "lighterglue" / "lighterglue_L3.onnx";

// Elements of the initializers, as the README counts parameters (LighterGlue's include 32 int64 ones).
size_t parameters(const OnnxModel& m) {
  size_t n = 0;
  for (const auto& [name, t] : m.initializers) n += t.floats.size() + t.ints.size();
  return n;
}

std::map<std::string, int> op_counts(const OnnxModel& m) {
  std::map<std::string, int> counts;
  for (const OnnxNode& n : m.nodes) ++counts[n.op_type];
  return counts;
}

const OnnxValueInfo* find(const std::vector<OnnxValueInfo>& values, const std::string& name) {
  for (const auto& v : values)
    if (v.name == name) return &v;
  return nullptr;
}

TEST(OnnxModel, ReadsXfeatAsItsReadmeDescribesIt) {
  const OnnxModel m = read_onnx_model(kXfeat);
  EXPECT_EQ(m.opset, 11);
  EXPECT_EQ(parameters(m), 659282u);
  const auto ops = op_counts(m);
  EXPECT_EQ(ops.at("Conv"), 27);
  EXPECT_EQ(ops.at("Relu"), 23);
  EXPECT_EQ(ops.at("AveragePool"), 1);
  EXPECT_EQ(ops.at("Resize"), 2);
  EXPECT_EQ(ops.at("Sigmoid"), 1);
  ASSERT_EQ(m.inputs.size(), 1u);
  EXPECT_EQ(m.inputs[0].name, "input");
  EXPECT_EQ(m.inputs[0].dims, (std::vector<int64_t>{1, 1, 640, 640}));
  ASSERT_NE(find(m.outputs, "output_feats"), nullptr);
  EXPECT_EQ(find(m.outputs, "output_feats")->dims, (std::vector<int64_t>{1, 80, 80, 64}));
  ASSERT_NE(find(m.outputs, "output_keypoints"), nullptr);
  EXPECT_EQ(find(m.outputs, "output_keypoints")->dims, (std::vector<int64_t>{1, 80, 80, 65}));
  ASSERT_NE(find(m.outputs, "output_heatmap"), nullptr);
  // Every convolution's weight is an initializer with [out, in / group, k, k] and the kernel size it names.
  for (const OnnxNode& n : m.nodes) {
    if (n.op_type != "Conv") continue;
    const OnnxTensor& w = m.initializer(n.inputs.at(1));
    ASSERT_EQ(w.dims.size(), 4u) << n.name;
    const OnnxAttribute* k = n.attribute("kernel_shape");
    ASSERT_NE(k, nullptr) << n.name;
    EXPECT_EQ(k->ints, (std::vector<int64_t>{w.dims[2], w.dims[3]})) << n.name;
    EXPECT_TRUE(w.dims[2] == 1 || w.dims[2] == 3) << n.name;
  }
  EXPECT_THROW(m.initializer("no-such-weight"), IoError);
}

TEST(OnnxModel, ReadsLighterGlue) {
  const OnnxModel m = read_onnx_model(kLighterGlue);
  EXPECT_EQ(m.opset, 17);
  EXPECT_EQ(parameters(m), 547143u);
  for (const char* name : {"kpts0", "kpts1", "desc0", "desc1"})
    EXPECT_NE(find(m.inputs, name), nullptr) << name;
  EXPECT_NE(find(m.outputs, "matches"), nullptr);
  EXPECT_NE(find(m.outputs, "scores"), nullptr);
}

std::string error_of(const fs::path& path) {
  try {
    read_onnx_model(path);
  } catch (const IoError& e) {
    return e.what();
  }
  return "";
}

fs::path temp_file(const std::string& name) {
  return fs::temp_directory_path() / ("litgs-onnx-" + name);
}

void write_bytes(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

std::string model_bytes() {
  std::ifstream in(kXfeat, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

TEST(OnnxModelBadInput, MissingTruncatedAndForeignFilesNameTheProblem) {
  EXPECT_NE(error_of(kModels / "nowhere.onnx").find("cannot open the model file"), std::string::npos);
  const std::string bytes = model_bytes();
  const fs::path cut = temp_file("cut.onnx");
  write_bytes(cut, bytes.substr(0, bytes.size() / 2));
  const std::string cut_error = error_of(cut);
  EXPECT_NE(cut_error.find(cut.string()), std::string::npos) << cut_error;
  EXPECT_NE(cut_error.find("truncated"), std::string::npos) << cut_error;
  const fs::path text = temp_file("text.onnx");
  write_bytes(text, "scene:\n  camera: 1\n");
  EXPECT_NE(error_of(text).find("not an ONNX model"), std::string::npos) << error_of(text);
  fs::remove(cut);
  fs::remove(text);
}

TEST(OnnxModelBadInput, AMissingNodeOrShortWeightsAreNamed) {
  onnx::ModelProto proto;
  ASSERT_TRUE(proto.ParseFromString(model_bytes()));
  // The first node removed: a file that still parses but whose later nodes read a name nothing defines.
  onnx::ModelProto without_node = proto;
  const std::string first_output = without_node.graph().node(0).output(0);
  without_node.mutable_graph()->mutable_node()->DeleteSubrange(0, 1);
  const fs::path path = temp_file("without-node.onnx");
  write_bytes(path, without_node.SerializeAsString());
  const std::string missing = error_of(path);
  EXPECT_NE(missing.find("'" + first_output + "'"), std::string::npos) << missing;
  EXPECT_NE(missing.find("no graph input, initializer or earlier node defines"), std::string::npos)
      << missing;
  // A weight whose data is shorter than its shape: named with its shape and byte count.
  onnx::ModelProto short_weight = proto;
  onnx::TensorProto* w = short_weight.mutable_graph()->mutable_initializer(0);
  if (w->has_raw_data())
    w->mutable_raw_data()->resize(w->raw_data().size() - 4);
  else
    w->mutable_float_data()->RemoveLast();
  write_bytes(path, short_weight.SerializeAsString());
  const std::string short_error = error_of(path);
  EXPECT_NE(short_error.find("initializer '" + w->name() + "'"), std::string::npos) << short_error;
  EXPECT_NE(short_error.find("truncated or mismatched"), std::string::npos) << short_error;
  fs::remove(path);
}

}  // namespace
}  // namespace litgs::io
