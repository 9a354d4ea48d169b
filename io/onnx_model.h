// An ONNX model file read into plain structs: the graph's nodes in order, their attributes, the
// initializers (weights) as float or int64 tensors, and the graph's inputs and outputs with their shapes.
// Parsed with Debian's libonnx (the ONNX protobuf format); no protobuf type appears here. What it checks:
// the file opens and parses, every tensor's data matches its shape and type, and every name a node reads is
// a graph input, an initializer or an earlier node's output (a file cut at a field boundary still parses,
// but loses nodes or weights that later names need). Each failure is an io::IoError naming the file and
// what is wrong.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace litgs::io {

struct OnnxTensor {
  std::string name;
  std::vector<int64_t> dims;
  std::vector<float> floats;  // FLOAT tensors
  std::vector<int64_t> ints;  // INT64 and INT32 tensors
  size_t elements() const;    // the product of dims (1 for a scalar)
};

struct OnnxAttribute {
  std::string name;
  std::vector<int64_t> ints;  // INT (one value) or INTS
  std::vector<float> floats;  // FLOAT (one value) or FLOATS
  std::string text;           // STRING
  bool has_tensor = false;
  OnnxTensor tensor;  // TENSOR (a Constant node's value)
};

struct OnnxNode {
  std::string name, op_type;
  std::vector<std::string> inputs, outputs;  // an empty input name: an optional input left out
  std::vector<OnnxAttribute> attributes;
  // The attribute of that name, or nullptr.
  const OnnxAttribute* attribute(const std::string& name) const;
};

struct OnnxValueInfo {
  std::string name;
  std::vector<int64_t> dims;  // -1 for a named (symbolic) dimension
};

struct OnnxModel {
  int64_t opset = 0;  // of the default domain
  std::vector<OnnxNode> nodes;
  std::map<std::string, OnnxTensor> initializers;
  std::vector<OnnxValueInfo> inputs, outputs;  // inputs exclude initializers
  // The initializer of that name; IoError naming the file and the name when there is none.
  const OnnxTensor& initializer(const std::string& name) const;
  std::filesystem::path file;
};

OnnxModel read_onnx_model(const std::filesystem::path& path);
// The same from bytes in memory (a model embedded in the binary); `name` stands for the file in errors.
OnnxModel parse_onnx_model(const void* bytes, size_t size, const std::string& name);

}  // namespace litgs::io
