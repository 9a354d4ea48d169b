// The image's data units: a model with train's levels.json beside it reports its stretch window in GET
// /model (the viewer's legend uses it); a model without one says it is in model units; a bad --levels file
// stops the server with a message naming it.
#include <fstream>

#include "io/gaussian_ply.h"
#include "serve_fixture.h"
#include "splat_scenes.h"

namespace litgs::testing {
namespace {

using nlohmann::json;

TEST_F(ServeTest, ModelWithoutLevelsJsonIsInModelUnits) {
  const json j = body_json(client()->Get("/model"));
  EXPECT_EQ(j["image_units"]["name"], "model units");
  EXPECT_EQ(j["image_units"]["low"], 0.0);
  EXPECT_EQ(j["image_units"]["high"], 1.0);
  EXPECT_TRUE(j["image_units"]["source"].is_null());
}

TEST_F(ServeTest, ModelLoadedBesideLevelsJsonIsInItsRawCounts) {
  const auto load =
      client()->Post("/models/load", R"({"name": "counts", "path": "counts/model.ply"})", "application/json");
  ASSERT_TRUE(load);
  ASSERT_EQ(load->status, 200) << load->body;
  const json j = body_json(client()->Get("/model?name=counts"));
  EXPECT_EQ(j["image_units"]["name"], "raw counts");
  EXPECT_EQ(j["image_units"]["low"], 1000.0);
  EXPECT_EQ(j["image_units"]["high"], 2000.0);
  EXPECT_NE(j["image_units"]["source"].get<std::string>().find("counts/levels.json"), std::string::npos);
}

TEST(ServeLevelsOption, MalformedLevelsFileStopsTheServerNamingIt) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "litgs-serve-bad-levels";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "levels.json") << "{\"level_model\": \"none\", \"stretch_low\": 5";
  const std::string model = (dir / "model.ply").string();
  io::write_gaussian_ply(model, random_scene(10, 1, 0, 1));
  const CommandResult bad =
      run_engine("serve --model " + model + " --port 0 --levels " + (dir / "levels.json").string());
  EXPECT_NE(bad.status, 0) << bad.output;
  EXPECT_NE(bad.output.find("levels.json"), std::string::npos) << bad.output;
  EXPECT_NE(bad.output.find("bad level table"), std::string::npos) << bad.output;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace litgs::testing
