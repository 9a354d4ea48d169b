#include "io/metashape.h"

#include <tinyxml2.h>

#include <Eigen/Geometry>
#include <cmath>
#include <stdexcept>

#include "io/error.h"
#include "io/text.h"

namespace litgs::io {
namespace {

using tinyxml2::XMLElement;

struct Xml {
  std::filesystem::path path;
  tinyxml2::XMLDocument doc;

  explicit Xml(const std::filesystem::path& p) : path(p) {
    if (!std::filesystem::exists(p)) fail(p, 0, "file does not exist");
    if (doc.LoadFile(p.c_str()) != tinyxml2::XML_SUCCESS)
      fail(p, doc.ErrorLineNum(), std::string("malformed XML: ") + doc.ErrorStr());
  }

  [[noreturn]] void bad(const XMLElement* e, const std::string& problem) const {
    fail(path, e ? e->GetLineNum() : 0, problem);
  }

  std::vector<double> numbers(const XMLElement* e, size_t expected) const {
    const char* text = e->GetText();
    const auto tokens = split_ws(text ? text : "");
    if (tokens.size() != expected)
      bad(e, "<" + std::string(e->Name()) + "> holds " + std::to_string(tokens.size()) +
                 " numbers, expected " + std::to_string(expected));
    std::vector<double> v;
    for (const auto& t : tokens) v.push_back(parse_double(t, path, e->GetLineNum(), e->Name()));
    return v;
  }

  double number(const XMLElement* e) const { return numbers(e, 1)[0]; }

  int int_attribute(const XMLElement* e, const char* name) const {
    int v = 0;
    if (e->QueryIntAttribute(name, &v) != tinyxml2::XML_SUCCESS)
      bad(e, "<" + std::string(e->Name()) + "> lacks the integer attribute '" + name + "'");
    return v;
  }

  double double_attribute(const XMLElement* e, const char* name) const {
    const char* s = e->Attribute(name);
    if (!s) bad(e, "<" + std::string(e->Name()) + "> lacks the attribute '" + name + "'");
    return parse_double(s, path, e->GetLineNum(), name);
  }
};

MetashapeCalibration parse_calibration(const Xml& xml, const XMLElement* c) {
  MetashapeCalibration cal;
  if (const XMLElement* r = c->FirstChildElement("resolution")) {
    cal.width = xml.int_attribute(r, "width");
    cal.height = xml.int_attribute(r, "height");
  } else {
    const XMLElement* w = c->FirstChildElement("width");
    const XMLElement* h = c->FirstChildElement("height");
    if (!w || !h) xml.bad(c, "<calibration> has neither <resolution> nor <width>/<height>");
    // Range-checked before the cast: an out-of-range double -> int conversion is undefined behaviour
    // (found by the fuzzer with a 100-digit height).
    auto pixels = [&](const XMLElement* e, const char* what) {
      const double v = xml.number(e);
      if (!(v >= 1 && v <= 1e6) || v != std::floor(v))
        xml.bad(e, std::string("<") + what + "> must be a whole number of pixels in 1..1000000");
      return static_cast<int>(v);
    };
    cal.width = pixels(w, "width");
    cal.height = pixels(h, "height");
  }
  const XMLElement* f = c->FirstChildElement("f");
  if (!f) xml.bad(c, "<calibration> lacks <f>");
  cal.f = xml.number(f);
  if (!(cal.f > 0)) xml.bad(f, "focal length must be positive");
  const auto optional = [&](const char* name, double& value) {
    if (const XMLElement* e = c->FirstChildElement(name)) value = xml.number(e);
  };
  optional("cx", cal.cx);
  optional("cy", cal.cy);
  optional("k1", cal.k1);
  optional("k2", cal.k2);
  optional("k3", cal.k3);
  optional("k4", cal.k4);
  optional("p1", cal.p1);
  optional("p2", cal.p2);
  optional("b1", cal.b1);
  optional("b2", cal.b2);
  if (cal.width <= 0 || cal.height <= 0) xml.bad(c, "calibration resolution must be positive");
  return cal;
}

}  // namespace

Eigen::Vector2d MetashapeCalibration::project(const Eigen::Vector3d& p) const {
  const double x = p.x() / p.z(), y = p.y() / p.z();
  const double r2 = x * x + y * y;
  const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * (k3 + r2 * k4)));
  const double xd = x * radial + p1 * (r2 + 2 * x * x) + 2 * p2 * x * y;
  const double yd = y * radial + p2 * (r2 + 2 * y * y) + 2 * p1 * x * y;
  return {0.5 * width + cx + xd * f + xd * b1 + yd * b2, 0.5 * height + cy + yd * f};
}

const MetashapeSensor* MetashapeDocument::sensor(int id) const {
  for (const auto& s : sensors)
    if (s.id == id) return &s;
  return nullptr;
}

const MetashapeCamera* MetashapeDocument::camera(int id) const {
  for (const auto& c : cameras)
    if (c.id == id) return &c;
  return nullptr;
}

Eigen::Matrix4d MetashapeDocument::T_world_cam(const MetashapeCamera& camera) const {
  if (!camera.T_chunk_cam) throw std::invalid_argument("camera '" + camera.label + "' has no transform");
  const Eigen::Matrix4d& T = *camera.T_chunk_cam;
  Eigen::Matrix4d out = Eigen::Matrix4d::Identity();
  out.topLeftCorner<3, 3>() = chunk.R * T.topLeftCorner<3, 3>();
  out.topRightCorner<3, 1>() = chunk.scale * chunk.R * T.topRightCorner<3, 1>() + chunk.t;
  return out;
}

MetashapeDocument read_metashape_xml(const std::filesystem::path& path) {
  Xml xml(path);
  const XMLElement* root = xml.doc.RootElement();
  if (!root || std::string(root->Name()) != "document") xml.bad(root, "the root element is not <document>");
  const XMLElement* chunk = root->FirstChildElement("chunk");
  if (!chunk) xml.bad(root, "no <chunk>");
  MetashapeDocument d;

  if (const XMLElement* sensors = chunk->FirstChildElement("sensors")) {
    for (const XMLElement* s = sensors->FirstChildElement("sensor"); s; s = s->NextSiblingElement("sensor")) {
      MetashapeSensor sensor;
      sensor.id = xml.int_attribute(s, "id");
      sensor.label = s->Attribute("label") ? s->Attribute("label") : "";
      if (const XMLElement* r = s->FirstChildElement("resolution")) {
        sensor.width = xml.int_attribute(r, "width");
        sensor.height = xml.int_attribute(r, "height");
      }
      if (const XMLElement* c = s->FirstChildElement("calibration"))
        sensor.calibration = parse_calibration(xml, c);
      d.sensors.push_back(sensor);
    }
  }

  if (const XMLElement* cameras = chunk->FirstChildElement("cameras")) {
    for (const XMLElement* c = cameras->FirstChildElement("camera"); c; c = c->NextSiblingElement("camera")) {
      MetashapeCamera camera;
      camera.id = xml.int_attribute(c, "id");
      camera.sensor_id = xml.int_attribute(c, "sensor_id");
      camera.label = c->Attribute("label") ? c->Attribute("label") : "";
      if (!d.sensor(camera.sensor_id))
        xml.bad(c,
                "camera '" + camera.label + "' names the unknown sensor " + std::to_string(camera.sensor_id));
      if (const XMLElement* t = c->FirstChildElement("transform")) {
        const auto v = xml.numbers(t, 16);
        Eigen::Matrix4d T;
        for (int i = 0; i < 16; ++i) T(i / 4, i % 4) = v[i];
        const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
        if ((R.transpose() * R - Eigen::Matrix3d::Identity()).norm() > 1e-6 || R.determinant() < 0 ||
            T.row(3) != Eigen::RowVector4d(0, 0, 0, 1))
          xml.bad(t, "camera '" + camera.label +
                         "': the transform is not rigid (orthonormal rotation, last row 0 0 0 1)");
        camera.T_chunk_cam = T;
      }
      d.cameras.push_back(camera);
    }
  }

  if (const XMLElement* t = chunk->FirstChildElement("transform")) {
    const XMLElement* r = t->FirstChildElement("rotation");
    const XMLElement* tr = t->FirstChildElement("translation");
    const XMLElement* s = t->FirstChildElement("scale");
    if (r) {
      const auto v = xml.numbers(r, 9);
      for (int i = 0; i < 9; ++i) d.chunk.R(i / 3, i % 3) = v[i];
      if ((d.chunk.R.transpose() * d.chunk.R - Eigen::Matrix3d::Identity()).norm() > 1e-6 ||
          d.chunk.R.determinant() < 0)
        xml.bad(r, "the chunk rotation is not a rotation");
    }
    if (tr) {
      const auto v = xml.numbers(tr, 3);
      d.chunk.t = {v[0], v[1], v[2]};
    }
    if (s) {
      d.chunk.scale = xml.number(s);
      if (!(d.chunk.scale > 0)) xml.bad(s, "the chunk scale must be positive");
    }
  }

  if (const XMLElement* markers = chunk->FirstChildElement("markers")) {
    for (const XMLElement* m = markers->FirstChildElement("marker"); m; m = m->NextSiblingElement("marker")) {
      MetashapeMarker marker;
      marker.id = xml.int_attribute(m, "id");
      marker.label = m->Attribute("label") ? m->Attribute("label") : "";
      if (const XMLElement* r = m->FirstChildElement("reference")) {
        marker.reference = Eigen::Vector3d(xml.double_attribute(r, "x"), xml.double_attribute(r, "y"),
                                           xml.double_attribute(r, "z"));
        marker.reference_enabled = r->BoolAttribute("enabled", true);
      }
      d.markers.push_back(marker);
    }
  }
  // Observations: <frames><frame><markers><marker marker_id><location camera_id x y/>.
  if (const XMLElement* frames = chunk->FirstChildElement("frames")) {
    for (const XMLElement* f = frames->FirstChildElement("frame"); f; f = f->NextSiblingElement("frame")) {
      const XMLElement* markers = f->FirstChildElement("markers");
      if (!markers) continue;
      for (const XMLElement* m = markers->FirstChildElement("marker"); m;
           m = m->NextSiblingElement("marker")) {
        const int id = xml.int_attribute(m, "marker_id");
        MetashapeMarker* marker = nullptr;
        for (auto& candidate : d.markers)
          if (candidate.id == id) marker = &candidate;
        if (!marker) xml.bad(m, "observations of the unknown marker " + std::to_string(id));
        for (const XMLElement* l = m->FirstChildElement("location"); l;
             l = l->NextSiblingElement("location")) {
          MetashapeObservation o;
          o.camera_id = xml.int_attribute(l, "camera_id");
          if (!d.camera(o.camera_id))
            xml.bad(l, "observation in the unknown camera " + std::to_string(o.camera_id));
          o.uv = {xml.double_attribute(l, "x"), xml.double_attribute(l, "y")};
          marker->observations.push_back(o);
        }
      }
    }
  }
  return d;
}

MetashapeCalibration read_metashape_calibration(const std::filesystem::path& path) {
  Xml xml(path);
  const XMLElement* root = xml.doc.RootElement();
  if (!root || std::string(root->Name()) != "calibration")
    xml.bad(root, "the root element is not <calibration>");
  return parse_calibration(xml, root);
}

}  // namespace litgs::io
