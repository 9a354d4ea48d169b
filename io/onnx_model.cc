#include "io/onnx_model.h"

#include <onnx/onnx_pb.h>

#include <cstring>
#include <fstream>
#include <limits>
#include <set>

#include "io/error.h"

namespace litgs::io {
namespace {

std::string dims_text(const std::vector<int64_t>& dims) {
  std::string s = "[";
  for (size_t i = 0; i < dims.size(); ++i) {
    if (i) s += ',';
    s += std::to_string(dims[i]);
  }
  return s + "]";
}

template <class T>
std::vector<T> raw_values(const std::string& raw, size_t count, const std::filesystem::path& path,
                          const std::string& what) {
  if (raw.size() != count * sizeof(T))
    fail(path, 0,
         what + ": " + std::to_string(raw.size()) + " bytes of data for " + std::to_string(count) +
             " elements of " + std::to_string(sizeof(T)) + " bytes (a truncated or mismatched file)");
  std::vector<T> values(count);
  if (count) std::memcpy(values.data(), raw.data(), raw.size());  // ONNX stores raw data little-endian
  return values;
}

OnnxTensor read_tensor(const onnx::TensorProto& t, const std::filesystem::path& path,
                       const std::string& what) {
  OnnxTensor out;
  out.name = t.name();
  for (int64_t d : t.dims()) {
    if (d < 0)
      fail(path, 0, what + ": negative dimension in " + dims_text({t.dims().begin(), t.dims().end()}));
    out.dims.push_back(d);
  }
  const size_t n = out.elements();
  if (t.has_data_location() && t.data_location() == onnx::TensorProto::EXTERNAL)
    fail(path, 0, what + ": data kept in an external file, which this reader does not follow");
  const std::string label = what + " " + dims_text(out.dims);
  switch (t.data_type()) {
    case onnx::TensorProto::FLOAT:
      out.floats = t.has_raw_data() ? raw_values<float>(t.raw_data(), n, path, label)
                                    : std::vector<float>(t.float_data().begin(), t.float_data().end());
      if (out.floats.size() != n)
        fail(path, 0,
             label + ": " + std::to_string(out.floats.size()) + " values for " + std::to_string(n) +
                 " elements (a truncated or mismatched file)");
      break;
    case onnx::TensorProto::INT64:
      out.ints = t.has_raw_data() ? raw_values<int64_t>(t.raw_data(), n, path, label)
                                  : std::vector<int64_t>(t.int64_data().begin(), t.int64_data().end());
      break;
    case onnx::TensorProto::INT32: {
      const std::vector<int32_t> v = t.has_raw_data()
                                         ? raw_values<int32_t>(t.raw_data(), n, path, label)
                                         : std::vector<int32_t>(t.int32_data().begin(), t.int32_data().end());
      out.ints.assign(v.begin(), v.end());
      break;
    }
    default:
      fail(path, 0,
           label + ": element type " + onnx::TensorProto::DataType_Name(t.data_type()) +
               " is not read (FLOAT, INT64 and INT32 are)");
  }
  if (t.data_type() != onnx::TensorProto::FLOAT && out.ints.size() != n)
    fail(path, 0,
         label + ": " + std::to_string(out.ints.size()) + " values for " + std::to_string(n) +
             " elements (a truncated or mismatched file)");
  return out;
}

OnnxValueInfo read_value_info(const onnx::ValueInfoProto& v) {
  OnnxValueInfo out;
  out.name = v.name();
  if (v.type().has_tensor_type() && v.type().tensor_type().has_shape())
    for (const auto& d : v.type().tensor_type().shape().dim())
      out.dims.push_back(d.has_dim_value() ? d.dim_value() : -1);
  return out;
}

}  // namespace

size_t OnnxTensor::elements() const {
  size_t n = 1;
  for (int64_t d : dims) n *= static_cast<size_t>(d);
  return n;
}

const OnnxAttribute* OnnxNode::attribute(const std::string& attribute_name) const {
  for (const OnnxAttribute& a : attributes)
    if (a.name == attribute_name) return &a;
  return nullptr;
}

const OnnxTensor& OnnxModel::initializer(const std::string& name) const {
  const auto it = initializers.find(name);
  if (it == initializers.end()) fail(file, 0, "no initializer (weight) named '" + name + "'");
  return it->second;
}

namespace {

OnnxModel from_proto(const onnx::ModelProto& proto, const std::filesystem::path& path);

}  // namespace

OnnxModel read_onnx_model(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, 0, "cannot open the model file");
  onnx::ModelProto proto;
  if (!proto.ParseFromIstream(&in))
    fail(path, 0, "not an ONNX model: the protobuf does not parse (a truncated or corrupt file?)");
  return from_proto(proto, path);
}

OnnxModel parse_onnx_model(const void* bytes, size_t size, const std::string& name) {
  onnx::ModelProto proto;
  if (size > size_t(std::numeric_limits<int>::max()) || !proto.ParseFromArray(bytes, static_cast<int>(size)))
    fail(name, 0, "not an ONNX model: the protobuf does not parse (a truncated or corrupt model?)");
  return from_proto(proto, name);
}

namespace {

OnnxModel from_proto(const onnx::ModelProto& proto, const std::filesystem::path& path) {
  if (!proto.has_graph() || proto.graph().node_size() == 0)
    fail(path, 0, "the ONNX model has no graph nodes");
  OnnxModel m;
  m.file = path;
  for (const auto& o : proto.opset_import())
    if (o.domain().empty() || o.domain() == "ai.onnx") m.opset = o.version();
  const onnx::GraphProto& g = proto.graph();
  std::set<std::string> defined;
  for (const auto& t : g.initializer()) {
    OnnxTensor tensor = read_tensor(t, path, "initializer '" + t.name() + "'");
    defined.insert(tensor.name);
    m.initializers.emplace(tensor.name, std::move(tensor));
  }
  for (const auto& v : g.input())
    if (!m.initializers.count(v.name())) {
      m.inputs.push_back(read_value_info(v));
      defined.insert(v.name());
    }
  for (const auto& v : g.output()) m.outputs.push_back(read_value_info(v));
  for (const auto& n : g.node()) {
    OnnxNode node;
    node.name = n.name();
    node.op_type = n.op_type();
    const std::string what = "node '" + n.name() + "' (" + n.op_type() + ")";
    for (const std::string& input : n.input()) {
      if (!input.empty() && !defined.count(input))
        fail(path, 0,
             what + " reads '" + input +
                 "', which no graph input, initializer or earlier node defines (a truncated file?)");
      node.inputs.push_back(input);
    }
    for (const std::string& output : n.output()) {
      node.outputs.push_back(output);
      defined.insert(output);
    }
    for (const auto& a : n.attribute()) {
      OnnxAttribute attr;
      attr.name = a.name();
      if (a.has_i()) attr.ints.push_back(a.i());
      attr.ints.insert(attr.ints.end(), a.ints().begin(), a.ints().end());
      if (a.has_f()) attr.floats.push_back(a.f());
      attr.floats.insert(attr.floats.end(), a.floats().begin(), a.floats().end());
      attr.text = a.s();
      if (a.has_t()) {
        attr.has_tensor = true;
        attr.tensor = read_tensor(a.t(), path, what + " attribute '" + a.name() + "'");
      }
      node.attributes.push_back(std::move(attr));
    }
    m.nodes.push_back(std::move(node));
  }
  for (const OnnxValueInfo& o : m.outputs)
    if (!defined.count(o.name)) fail(path, 0, "graph output '" + o.name + "' is produced by no node");
  return m;
}

}  // namespace
}  // namespace litgs::io
