// The service's request parser: every accepted form gives the camera it says, every mistake a RequestError
// (400) whose message names the field.
#include <gtest/gtest.h>

#include <cmath>

#include "tools/serve/render_request.h"

namespace litgs::serve {
namespace {

const char* kValid = R"({"pose": {"T_cam_world": {"q": [1, 0, 0, 0], "t": [0.5, -1, 2]}},
  "intrinsics": {"fx": 50, "fy": 51, "cx": 24, "cy": 20}, "width": 48, "height": 40})";

std::string error_of(const std::string& body, uint64_t max_pixels = 1 << 20) {
  try {
    parse_render_json(body, {max_pixels});
  } catch (const RequestError& e) {
    EXPECT_EQ(e.status, 400) << e.what();
    return e.what();
  }
  return "no error";
}

TEST(RenderRequest, ValidBodyGivesItsCameraAndDefaults) {
  const RenderRequest r = parse_render_json(kValid, {});
  EXPECT_EQ(r.camera.width, 48u);
  EXPECT_EQ(r.camera.fy, 51.0);
  EXPECT_EQ(r.camera.t_cam_world.z, 2.0);
  EXPECT_EQ(r.model, "default");
  EXPECT_TRUE(r.image.wanted);
  EXPECT_EQ(r.image.encoding, Encoding::kPng8);
  EXPECT_FALSE(r.depth.wanted);
  EXPECT_EQ(r.sh_degree, -1);
}

TEST(RenderRequest, CameraToWorldIsInverted) {
  // A camera at (1, 2, 3) in the world, turned 90 degrees about z: R_world_cam = Rz(90).
  const double h = std::sqrt(0.5);
  const RenderRequest r = parse_render_json(
      R"({"pose": {"T_world_cam": {"q": [)" + std::to_string(h) + ", 0, 0, " + std::to_string(h) +
          R"(], "t": [1, 2, 3]}}, "intrinsics": {"fov_y_deg": 90}, "width": 10, "height": 8})",
      {});
  // p_cam = R^T (p_world - c): the camera centre maps to the origin.
  const glm::dvec3 c = r.camera.R_cam_world * glm::dvec3(1, 2, 3) + r.camera.t_cam_world;
  EXPECT_NEAR(glm::length(c), 0.0, 1e-6);
  // the world x axis is the camera's -y axis after a +90 degree turn about z
  const glm::dvec3 x = r.camera.R_cam_world * glm::dvec3(1, 0, 0);
  EXPECT_NEAR(x.y, -1.0, 1e-6);
  EXPECT_NEAR(r.camera.fy, 4.0, 1e-9);  // (8 / 2) / tan(45 degrees)
  EXPECT_EQ(r.camera.cx, 5.0);
}

TEST(RenderRequest, MalformedJsonIsNamed) {
  EXPECT_NE(error_of("{\"width\": ").find("malformed JSON"), std::string::npos);
}

TEST(RenderRequest, MissingAndExtraFieldsAreNamed) {
  EXPECT_NE(error_of(R"({"width": 4, "height": 4})").find("missing field 'pose'"), std::string::npos);
  std::string extra = kValid;
  extra.insert(1, R"("colour": "red", )");
  EXPECT_NE(error_of(extra).find("unknown field 'colour'"), std::string::npos);
  std::string nested = kValid;
  nested.replace(nested.find("\"t\": [0.5"), 1, "\"s\": 1, \"t");
  EXPECT_NE(error_of(nested).find("unknown field 'pose.T_cam_world.s'"), std::string::npos);
}

TEST(RenderRequest, InfiniteAndNonNumericValuesAreRefused) {
  std::string inf = kValid;
  inf.replace(inf.find("\"fx\": 50"), 8, "\"fx\": 1e999");
  EXPECT_NE(error_of(inf).find("number overflow parsing '1e999'"), std::string::npos) << error_of(inf);
  std::string text = kValid;
  text.replace(text.find("\"fx\": 50"), 8, "\"fx\": \"50\"");
  EXPECT_NE(error_of(text).find("'intrinsics.fx' must be a number"), std::string::npos);
  EXPECT_NE(error_of(R"({"pose": 1})").find("missing field 'width'"), std::string::npos);
}

TEST(RenderRequest, NonUnitQuaternionIsRefused) {
  std::string q = kValid;
  q.replace(q.find("[1, 0, 0, 0]"), 12, "[2, 0, 0, 0]");
  EXPECT_NE(error_of(q).find("norm 2"), std::string::npos) << error_of(q);
  std::string zero = kValid;
  zero.replace(zero.find("[1, 0, 0, 0]"), 12, "[0, 0, 0, 0]");
  EXPECT_NE(error_of(zero).find("unit quaternion"), std::string::npos);
}

TEST(RenderRequest, PoseNeedsExactlyOneDirection) {
  EXPECT_NE(error_of(R"({"width": 4, "height": 4, "pose": {}})").find("exactly one of T_cam_world"),
            std::string::npos);
}

TEST(RenderRequest, ZeroAndHugeSizesAreRefused) {
  std::string zero = kValid;
  zero.replace(zero.find("\"width\": 48"), 11, "\"width\": 0");
  EXPECT_NE(error_of(zero).find("'width' is 0"), std::string::npos) << error_of(zero);
  EXPECT_NE(error_of(kValid, 1000).find("above this server's --max-pixels 1000"), std::string::npos);
  std::string negative = kValid;
  negative.replace(negative.find("\"height\": 40"), 12, "\"height\": -3");
  EXPECT_NE(error_of(negative).find("'height' is -3"), std::string::npos);
}

TEST(RenderRequest, OutputsAndPalettes) {
  std::string body = kValid;
  body.insert(body.size() - 1,
              R"(, "outputs": {"image": {"palette": "ironbow", "range": [0.2, 0.8]},
                  "depth": {"format": "png16", "scale": 100}, "alpha": {"format": "float32"}})");
  const RenderRequest r = parse_render_json(body, {});
  EXPECT_EQ(r.output_count(), 3u);
  EXPECT_EQ(*r.image.palette, io::Palette::kIronbow);
  EXPECT_EQ(r.image.lo, 0.2);
  EXPECT_EQ(r.depth.scale, 100.0);
  EXPECT_EQ(r.alpha.encoding, Encoding::kFloat32);
  auto with_outputs = [](const std::string& outputs) {
    std::string b = kValid;
    b.insert(b.size() - 1, ", \"outputs\": " + outputs);
    return error_of(b);
  };
  EXPECT_NE(with_outputs(R"({"image": {"palette": "jet"}})").find("unknown palette 'jet'"),
            std::string::npos);
  EXPECT_NE(with_outputs(R"({"image": {"format": "png16", "palette": "gray"}})").find("png8"),
            std::string::npos);
  EXPECT_NE(with_outputs(R"({"depth": {"palette": "gray"}})").find("outputs.depth.range"), std::string::npos);
  EXPECT_NE(with_outputs(R"({"image": {"palette": "gray", "range": [1, 1]}})").find("LO < HI"),
            std::string::npos);
  EXPECT_NE(with_outputs("{}").find("asks for nothing"), std::string::npos);
  EXPECT_NE(with_outputs(R"({"normals": {}})").find("unknown field 'outputs.normals'"), std::string::npos);
}

TEST(RenderRequest, QueryParametersMatchTheJsonForm) {
  const RenderRequest q = parse_render_query({{"pose", "T_cam_world"},
                                              {"q", "1,0,0,0"},
                                              {"t", "0.5,-1,2"},
                                              {"fx", "50"},
                                              {"fy", "51"},
                                              {"cx", "24"},
                                              {"cy", "20"},
                                              {"width", "48"},
                                              {"height", "40"},
                                              {"outputs", "image,depth"},
                                              {"depth_format", "float32"}},
                                             {});
  const RenderRequest j = parse_render_json(kValid, {});
  EXPECT_EQ(q.camera.R_cam_world, j.camera.R_cam_world);
  EXPECT_EQ(q.camera.t_cam_world, j.camera.t_cam_world);
  EXPECT_EQ(q.camera.fx, j.camera.fx);
  EXPECT_EQ(q.output_count(), 2u);
  EXPECT_EQ(q.depth.encoding, Encoding::kFloat32);
  auto query_error = [](std::vector<std::pair<std::string, std::string>> p) {
    try {
      parse_render_query(p, {});
    } catch (const RequestError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(query_error({{"fx", "nan"}}).find("'fx' is not a number"), std::string::npos);
  EXPECT_NE(query_error({{"fx", "inf"}}).find("'fx'"), std::string::npos);
  EXPECT_NE(query_error({{"zoom", "2"}}).find("unknown query parameter 'zoom'"), std::string::npos);
  EXPECT_NE(query_error({{"q", "1,0,0,0"}}).find("need pose=T_cam_world"), std::string::npos);
  EXPECT_NE(query_error({{"pose", "T_cam"}}).find("T_cam_world or T_world_cam"), std::string::npos);
}

}  // namespace
}  // namespace litgs::serve
