// Training a partition's blocks through an executor (host/partition/block_training.h), with a stand-in for
// litgs-engine: a script that "trains" a block by copying a model, and fails for the block it is told to.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>

#include "host/partition/block_training.h"
#include "host/partition/partition_scene.h"
#include "host/synth/synth.h"
#include "io/gaussian_ply.h"

namespace litgs::host::partition {
namespace {
namespace fs = std::filesystem;

class BlockTrainingTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           (std::string("litgs-blocks-") + info->name() + "-" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    synth::SynthOptions s;
    s.preset = "street";
    s.seed = 1;
    s.frames = 24;
    s.width = 96;
    s.height = 64;
    s.out = dir_ / "scene";
    synth::generate_synthetic_scene(s);
    PartitionOptions o;
    o.columns = 3;
    o.rows = 1;
    partition_scene(s.out, dir_ / "part", o);
    kernels::GaussianModel m;
    m.channels = 1;
    m.sh_degree = 0;
    m.resize(1);
    m.quats[0] = 1;
    io::write_gaussian_ply(dir_ / "model.ply", m);
    // `engine train SCENE --out OUT ARGS...`: fails when SCENE ends in $FAIL_BLOCK, else copies the model.
    engine_ = dir_ / "fake-engine";
    std::ofstream(engine_)
        << "#!/bin/sh\n"
        << "[ \"$1\" = train ] || exit 2\n"
        << "case \"$2\" in *\"${FAIL_BLOCK:-none}\") echo \"cannot train $2\"; exit 1;; esac\n"
        << "mkdir -p \"$4\" && cp " << (dir_ / "model.ply").string()
        << " \"$4/point_cloud.ply\" && echo \"trained $2 with $5 $6 (all: $*)\"\n";
    ::chmod(engine_.c_str(), 0755);
  }
  void TearDown() override {
    ::unsetenv("FAIL_BLOCK");
    fs::remove_all(dir_);
  }
  fs::path dir_, engine_;
};

TEST_F(BlockTrainingTest, LocalTrainsEveryBlockAndARerunSkipsThem) {
  BlockTrainingOptions o;
  o.parallel = 2;
  o.train_args = {"--iterations", "7"};
  const BlockTrainingReport r = train_blocks(dir_ / "part", engine_, o);
  ASSERT_EQ(r.blocks.size(), 3u);
  for (const auto& b : r.blocks) {
    EXPECT_EQ(b.state, "trained") << b.name;
    EXPECT_TRUE(fs::exists(dir_ / "part/blocks" / b.name / "train/point_cloud.ply"));
    std::ifstream log(b.log);
    const std::string text(std::istreambuf_iterator<char>(log), {});
    EXPECT_NE(text.find("with --iterations 7"), std::string::npos) << text;
    // Each block's progress reports go to its own trace, which the run report draws.
    EXPECT_NE(text.find("--trace " + (dir_ / "part/blocks" / b.name / "train/trace.jsonl").string()),
              std::string::npos)
        << text;
  }
  for (const auto& b : train_blocks(dir_ / "part", engine_, o).blocks) EXPECT_EQ(b.state, "done before");
}

TEST_F(BlockTrainingTest, AFailedBlockIsNamedWithItsLogAndTheOthersAreKept) {
  ::setenv("FAIL_BLOCK", "block-1-0", 1);
  try {
    train_blocks(dir_ / "part", engine_, {});
    FAIL() << "a failed block went unreported";
  } catch (const std::runtime_error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("block-1-0: see " + (dir_ / "part/blocks/block-1-0/train.log").string()),
              std::string::npos)
        << m;
    EXPECT_EQ(m.find("block-0-0"), std::string::npos) << m;
  }
  EXPECT_TRUE(fs::exists(dir_ / "part/blocks/block-0-0/train/point_cloud.ply"));
  EXPECT_TRUE(fs::exists(dir_ / "part/blocks/block-2-0/train/point_cloud.ply"));
  // The rerun trains only the failed block.
  ::unsetenv("FAIL_BLOCK");
  const BlockTrainingReport r = train_blocks(dir_ / "part", engine_, {});
  EXPECT_EQ(r.blocks[0].state, "done before");
  EXPECT_EQ(r.blocks[1].state, "trained");
  EXPECT_EQ(r.blocks[2].state, "done before");
}

TEST_F(BlockTrainingTest, SlurmWithoutSbatchNamesTheExecutor) {
  BlockTrainingOptions o;
  o.executor = Executor::kSlurm;
  o.sbatch = "litgs-no-such-sbatch";
  try {
    train_blocks(dir_ / "part", engine_, o);
    FAIL() << "ran without sbatch";
  } catch (const std::runtime_error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("the slurm executor needs sbatch"), std::string::npos) << m;
    EXPECT_NE(m.find("litgs-no-such-sbatch"), std::string::npos) << m;
  }
  EXPECT_THROW(executor_from("pbs"), std::invalid_argument);
}

// The job array script, run as Slurm would run one of its tasks: task 1 trains the second pending block.
TEST_F(BlockTrainingTest, TheArrayScriptTrainsTheBlockOfItsTaskId) {
  BlockTrainingOptions o;
  o.executor = Executor::kSlurm;
  o.train_args = {"--iterations", "it's 9"};
  o.slurm = default_slurm_resources(dir_ / "part", o.slurm);
  EXPECT_FALSE(o.slurm.mem.empty());
  const std::string script = slurm_array_script(dir_ / "part", engine_, {"block-0-0", "block-2-0"}, o);
  EXPECT_NE(script.find("#SBATCH --array=0-1\n"), std::string::npos) << script;
  EXPECT_NE(script.find("#SBATCH --gres=gpu:1\n"), std::string::npos) << script;
  EXPECT_NE(script.find("#SBATCH --mem=" + o.slurm.mem + "\n"), std::string::npos) << script;
  EXPECT_NE(script.find("--trace \"$scene/train/trace.jsonl\""), std::string::npos) << script;
  std::ofstream(dir_ / "task.sh") << script;
  const std::string command = "SLURM_ARRAY_TASK_ID=1 bash " + (dir_ / "task.sh").string();
  ASSERT_EQ(std::system(command.c_str()), 0) << script;
  EXPECT_FALSE(fs::exists(dir_ / "part/blocks/block-0-0/train/point_cloud.ply"));
  EXPECT_TRUE(fs::exists(dir_ / "part/blocks/block-2-0/train/point_cloud.ply"));
  std::ifstream log(dir_ / "part/blocks/block-2-0/train.log");
  const std::string text(std::istreambuf_iterator<char>(log), {});
  EXPECT_NE(text.find("with --iterations it's 9"), std::string::npos) << text;
}

}  // namespace
}  // namespace litgs::host::partition
