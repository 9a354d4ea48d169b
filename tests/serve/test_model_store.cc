// POST /models/load's path confinement: only files inside --models-dir, symlinks followed before the check.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "tools/serve/model_store.h"
#include "tools/serve/request_error.h"

namespace litgs::serve {
namespace {

namespace fs = std::filesystem;

class ModelsDir : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("litgs-models-dir-" + std::to_string(::getpid()));
    fs::create_directories(root_ / "models" / "sub");
    std::ofstream(root_ / "models" / "a.ply") << "x";
    std::ofstream(root_ / "models" / "sub" / "b.ply") << "x";
    std::ofstream(root_ / "outside.ply") << "x";
    fs::create_symlink(root_ / "outside.ply", root_ / "models" / "link.ply");
    fs::create_directory_symlink(root_, root_ / "models" / "up");
  }
  void TearDown() override { fs::remove_all(root_); }
  int status_of(const std::string& path) {
    try {
      confine_to_models_dir(root_ / "models", path);
    } catch (const RequestError& e) {
      EXPECT_NE(std::string(e.what()).find(path.empty() ? "path" : path), std::string::npos) << e.what();
      return e.status;
    }
    return 200;
  }
  fs::path root_;
};

TEST_F(ModelsDir, FilesInsideAreAccepted) {
  EXPECT_EQ(confine_to_models_dir(root_ / "models", "a.ply"), fs::canonical(root_ / "models" / "a.ply"));
  EXPECT_EQ(status_of("sub/b.ply"), 200);
  EXPECT_EQ(status_of("sub/../a.ply"), 200);
  EXPECT_EQ(status_of((root_ / "models" / "a.ply").string()), 200);
}

TEST_F(ModelsDir, TraversalAbsolutePathsAndSymlinksOutsideAreRefused) {
  EXPECT_EQ(status_of("../outside.ply"), 403);
  EXPECT_EQ(status_of("sub/../../outside.ply"), 403);
  EXPECT_EQ(status_of((root_ / "outside.ply").string()), 403);
  EXPECT_EQ(status_of("/etc/passwd"), 403);
  EXPECT_EQ(status_of("link.ply"), 403);
  EXPECT_EQ(status_of("up/outside.ply"), 403);
  EXPECT_EQ(status_of("up/models/a.ply"), 200);  // a way back in through the link is still inside
}

TEST_F(ModelsDir, MissingFilesAndDirectoriesAreNotFound) {
  EXPECT_EQ(status_of("nope.ply"), 404);
  EXPECT_EQ(status_of("sub"), 404);
  EXPECT_EQ(status_of("."), 403);  // the folder itself
  EXPECT_EQ(status_of(""), 400);
}

TEST(ModelsDirUnset, LoadingIsRefused) {
  try {
    confine_to_models_dir("", "a.ply");
    FAIL() << "no error";
  } catch (const RequestError& e) {
    EXPECT_EQ(e.status, 403);
    EXPECT_NE(std::string(e.what()).find("--models-dir"), std::string::npos);
  }
}

}  // namespace
}  // namespace litgs::serve
