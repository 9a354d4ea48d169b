#include "tools/serve/render_request.h"

#include <cmath>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "io/text.h"
#include "tools/render_view.h"

namespace litgs::serve {
namespace {

using nlohmann::json;

[[noreturn]] void bad(const std::string& message) {
  throw RequestError(400, message);
}

// A JSON object whose keys must all be in `allowed`; fields are looked up by name with their full path.
class Fields {
 public:
  Fields(const json& j, std::string path, std::initializer_list<const char*> allowed)
      : j_(j), path_(std::move(path)) {
    if (!j.is_object()) bad(where() + " must be a JSON object");
    std::set<std::string> names(allowed.begin(), allowed.end());
    for (const auto& item : j.items())
      if (!names.count(item.key())) {
        std::string list;
        for (const char* a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
        bad("unknown field '" + field(item.key()) + "' (allowed here: " + list + ")");
      }
  }
  const json* find(const char* key) const {
    const auto it = j_.find(key);
    return it == j_.end() ? nullptr : &*it;
  }
  bool has(const char* key) const { return find(key) != nullptr; }
  const json& need(const char* key) const {
    const json* v = find(key);
    if (!v) bad("missing field '" + field(key) + "'");
    return *v;
  }
  std::string field(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

  double number(const char* key) const { return number_at(need(key), field(key)); }
  static double number_at(const json& v, const std::string& name) {
    if (!v.is_number()) bad("field '" + name + "' must be a number");
    const double x = v.get<double>();
    if (!std::isfinite(x)) bad("field '" + name + "' is not finite");
    return x;
  }
  int64_t integer(const char* key, int64_t lo, int64_t hi) const {
    const json& v = need(key);
    if (!v.is_number_integer()) bad("field '" + field(key) + "' must be an integer");
    const int64_t x =
        v.is_number_unsigned() && v.get<uint64_t>() > uint64_t(INT64_MAX) ? INT64_MAX : v.get<int64_t>();
    if (x < lo || x > hi)
      bad("field '" + field(key) + "' is " + std::to_string(x) + ", outside [" + std::to_string(lo) + ", " +
          std::to_string(hi) + "]");
    return x;
  }
  std::string text(const char* key) const {
    const json& v = need(key);
    if (!v.is_string()) bad("field '" + field(key) + "' must be a string");
    return v.get<std::string>();
  }
  std::vector<double> numbers(const char* key, size_t count) const {
    const json& v = need(key);
    if (!v.is_array() || v.size() != count)
      bad("field '" + field(key) + "' must be an array of " + std::to_string(count) + " numbers");
    std::vector<double> out;
    for (size_t i = 0; i < count; ++i)
      out.push_back(number_at(v[i], field(key) + "[" + std::to_string(i) + "]"));
    return out;
  }

 private:
  std::string where() const { return path_.empty() ? "the request body" : "field '" + path_ + "'"; }
  const json& j_;
  std::string path_;
};

constexpr double kUnitTolerance = 1e-3;

void parse_pose(const Fields& top, kernels::SplatCamera& camera) {
  const Fields pose(top.need("pose"), "pose", {"T_cam_world", "T_world_cam"});
  if (pose.has("T_cam_world") == pose.has("T_world_cam"))
    bad("field 'pose' needs exactly one of T_cam_world (world-to-camera) or T_world_cam (camera-to-world)");
  const char* name = pose.has("T_cam_world") ? "T_cam_world" : "T_world_cam";
  const Fields t(pose.need(name), pose.field(name), {"q", "t"});
  const std::vector<double> q = t.numbers("q", 4), p = t.numbers("t", 3);
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (std::abs(norm - 1.0) > kUnitTolerance) {
    std::ostringstream s;
    s << "field '" << t.field("q") << "' has norm " << norm
      << ": give a unit quaternion [w, x, y, z] (norm within 1e-3 of 1)";
    bad(s.str());
  }
  const glm::dmat3 R = tools::rotation_from_quat(q[0], q[1], q[2], q[3]);
  const glm::dvec3 v{p[0], p[1], p[2]};
  if (name == std::string("T_cam_world")) {
    camera.R_cam_world = R;
    camera.t_cam_world = v;
  } else {  // camera-to-world given: invert it
    camera.R_cam_world = glm::transpose(R);
    camera.t_cam_world = -(camera.R_cam_world * v);
  }
}

void parse_intrinsics(const Fields& top, kernels::SplatCamera& camera) {
  const Fields in(top.need("intrinsics"), "intrinsics", {"fx", "fy", "cx", "cy", "fov_y_deg"});
  if (in.has("fov_y_deg")) {
    if (in.has("fx") || in.has("fy") || in.has("cx") || in.has("cy"))
      bad("field 'intrinsics' takes fx fy cx cy, or fov_y_deg, not both");
    const double fov = in.number("fov_y_deg");
    if (!(fov > 0 && fov < 180)) bad("field 'intrinsics.fov_y_deg' must be in (0, 180) degrees");
    camera.fy = camera.fx = 0.5 * camera.height / std::tan(0.5 * fov * M_PI / 180.0);
    camera.cx = 0.5 * camera.width;
    camera.cy = 0.5 * camera.height;
    return;
  }
  camera.fx = in.number("fx");
  camera.fy = in.number("fy");
  camera.cx = in.number("cx");
  camera.cy = in.number("cy");
  if (!(camera.fx > 0) || !(camera.fy > 0))
    bad("fields 'intrinsics.fx' and 'intrinsics.fy' must be positive");
}

Encoding parse_encoding(const Fields& f, const char* key, std::initializer_list<Encoding> allowed,
                        Encoding fallback) {
  if (!f.has(key)) return fallback;
  const std::string name = f.text(key);
  const Encoding e =
      name == "png8"    ? Encoding::kPng8
      : name == "png16" ? Encoding::kPng16
      : name == "float32"
          ? Encoding::kFloat32
          : throw RequestError(400, "field '" + f.field(key) + "' is '" + name + "': png8, png16 or float32");
  for (Encoding a : allowed)
    if (a == e) return e;
  bad("field '" + f.field(key) + "': '" + name + "' is not offered for this output");
}

void parse_palette(const Fields& f, OutputRequest& out, std::optional<std::vector<double>> default_range) {
  if (!f.has("palette")) {
    if (f.has("range")) bad("field '" + f.field("range") + "' needs a palette");
    return;
  }
  try {
    out.palette = io::parse_palette(f.text("palette"));
  } catch (const std::invalid_argument& e) {
    bad("field '" + f.field("palette") + "': " + e.what());
  }
  if (out.encoding != Encoding::kPng8)
    bad("field '" + f.field("palette") + "' gives an 8-bit RGB PNG: leave out format or give png8");
  if (!f.has("range") && !default_range) bad("field '" + f.field("range") + "' is needed with a palette");
  const std::vector<double> r = f.has("range") ? f.numbers("range", 2) : *default_range;
  if (!(r[1] > r[0])) bad("field '" + f.field("range") + "' needs LO < HI");
  out.lo = r[0];
  out.hi = r[1];
}

void parse_outputs(const Fields& top, RenderRequest& r) {
  if (!top.has("outputs")) {
    r.image.wanted = true;
    r.image.scale = 255.0;
    return;
  }
  const Fields outs(top.need("outputs"), "outputs", {"image", "depth", "alpha"});
  if (outs.has("image")) {
    const Fields f(outs.need("image"), "outputs.image", {"format", "palette", "range"});
    r.image.wanted = true;
    r.image.encoding =
        parse_encoding(f, "format", {Encoding::kPng8, Encoding::kPng16, Encoding::kFloat32}, Encoding::kPng8);
    r.image.scale = r.image.encoding == Encoding::kPng16 ? 65535.0 : 255.0;
    parse_palette(f, r.image, std::vector<double>{0.0, 1.0});
  }
  if (outs.has("depth")) {
    const Fields f(outs.need("depth"), "outputs.depth", {"format", "scale", "palette", "range"});
    r.depth.wanted = true;
    r.depth.encoding = parse_encoding(f, "format", {Encoding::kPng16, Encoding::kFloat32, Encoding::kPng8},
                                      f.has("palette") ? Encoding::kPng8 : Encoding::kPng16);
    if (r.depth.encoding == Encoding::kPng8 && !f.has("palette"))
      bad("field 'outputs.depth.format': png8 is only for a palette (use png16 with a scale, or float32)");
    r.depth.scale = 1000.0;
    if (f.has("scale")) {
      if (r.depth.encoding != Encoding::kPng16) bad("field 'outputs.depth.scale' applies to png16 only");
      r.depth.scale = f.number("scale");
      if (!(r.depth.scale > 0)) bad("field 'outputs.depth.scale' must be positive (PNG value per metre)");
    }
    parse_palette(f, r.depth, std::nullopt);
  }
  if (outs.has("alpha")) {
    const Fields f(outs.need("alpha"), "outputs.alpha", {"format"});
    r.alpha.wanted = true;
    r.alpha.encoding = parse_encoding(f, "format", {Encoding::kPng8, Encoding::kFloat32}, Encoding::kPng8);
    r.alpha.scale = 255.0;
  }
  if (r.output_count() == 0) bad("field 'outputs' asks for nothing: give image, depth or alpha");
}

RenderRequest from_json(const json& body, const RequestLimits& limits) {
  const Fields top(body, "",
                   {"model", "pose", "intrinsics", "width", "height", "sh_degree", "outputs", "bundle"});
  RenderRequest r;
  if (top.has("model")) r.model = top.text("model");
  constexpr int64_t kMaxSide = 16384;
  r.camera.width = static_cast<uint32_t>(top.integer("width", 1, kMaxSide));
  r.camera.height = static_cast<uint32_t>(top.integer("height", 1, kMaxSide));
  const uint64_t pixels = uint64_t{r.camera.width} * r.camera.height;
  if (pixels > limits.max_pixels)
    bad("width x height = " + std::to_string(pixels) + " pixels, above this server's --max-pixels " +
        std::to_string(limits.max_pixels));
  parse_pose(top, r.camera);
  parse_intrinsics(top, r.camera);
  if (top.has("sh_degree")) r.sh_degree = static_cast<int>(top.integer("sh_degree", 0, 3));
  if (top.has("bundle")) {
    if (!top.need("bundle").is_boolean()) bad("field 'bundle' must be true or false");
    r.bundle = top.need("bundle").get<bool>();
  }
  parse_outputs(top, r);
  return r;
}

// A query value as JSON: numbers (strictly parsed; nan and inf refused) and comma lists of numbers.
json query_number(const std::string& name, const std::string& text) {
  double x = 0;
  if (!io::try_parse_double(text, x)) bad("query parameter '" + name + "' is not a number: '" + text + "'");
  if (!std::isfinite(x)) bad("query parameter '" + name + "' is not finite");
  if (x == std::floor(x) && std::abs(x) < 9e15 && text.find_first_of(".eE") == std::string::npos)
    return json(static_cast<int64_t>(x));
  return json(x);
}

json query_numbers(const std::string& name, const std::string& text) {
  json list = json::array();
  std::stringstream s(text);
  std::string item;
  while (std::getline(s, item, ',')) list.push_back(query_number(name, item));
  return list;
}

}  // namespace

RenderRequest parse_render_json(const std::string& body, const RequestLimits& limits) {
  json j;
  try {
    j = json::parse(body);
  } catch (const json::exception& e) {  // parse_error, or out_of_range for a number like 1e999
    bad(std::string("malformed JSON: ") + e.what());
  }
  return from_json(j, limits);
}

RenderRequest parse_render_query(const std::vector<std::pair<std::string, std::string>>& params,
                                 const RequestLimits& limits) {
  json body = json::object();
  std::string pose_name;
  json pose = json::object(), intrinsics = json::object(), outputs = json::object();
  std::set<std::string> seen;
  auto output = [&](const std::string& o) -> json& {
    if (!outputs.contains(o)) outputs[o] = json::object();
    return outputs[o];
  };
  for (const auto& [name, value] : params) {
    if (!seen.insert(name).second) bad("query parameter '" + name + "' is given twice");
    if (name == "model") {
      body["model"] = value;
    } else if (name == "pose") {
      if (value != "T_cam_world" && value != "T_world_cam")
        bad("query parameter 'pose' must be T_cam_world or T_world_cam, not '" + value + "'");
      pose_name = value;
    } else if (name == "q" || name == "t") {
      pose[name] = query_numbers(name, value);
    } else if (name == "fx" || name == "fy" || name == "cx" || name == "cy" || name == "fov_y_deg") {
      intrinsics[name] = query_number(name, value);
    } else if (name == "width" || name == "height" || name == "sh_degree") {
      body[name] = query_number(name, value);
    } else if (name == "outputs") {
      std::stringstream s(value);
      std::string o;
      while (std::getline(s, o, ',')) output(o);
    } else if (name == "image_format" || name == "depth_format" || name == "alpha_format") {
      output(name.substr(0, name.find('_')))["format"] = value;
    } else if (name == "image_palette" || name == "depth_palette") {
      output(name.substr(0, name.find('_')))["palette"] = value;
    } else if (name == "image_range" || name == "depth_range") {
      output(name.substr(0, name.find('_')))["range"] = query_numbers(name, value);
    } else if (name == "depth_scale") {
      output("depth")["scale"] = query_number(name, value);
    } else if (name == "bundle") {
      if (value != "true" && value != "false") bad("query parameter 'bundle' must be true or false");
      body["bundle"] = value == "true";
    } else {
      bad("unknown query parameter '" + name +
          "' (allowed: model pose q t fx fy cx cy fov_y_deg width height sh_degree outputs image_format "
          "image_palette image_range depth_format depth_scale depth_palette depth_range alpha_format "
          "bundle)");
    }
  }
  if (!pose_name.empty())
    body["pose"] = json{{pose_name, pose}};
  else if (!pose.empty())
    bad("query parameters q and t need pose=T_cam_world or pose=T_world_cam");
  if (!intrinsics.empty()) body["intrinsics"] = intrinsics;
  if (!outputs.empty()) body["outputs"] = outputs;
  return from_json(body, limits);
}

}  // namespace litgs::serve
