#include "host/train/budget_trial_record.h"

#include <fstream>

#include "io/atomic_file.h"

namespace litgs::host {
namespace {

const char* const kRecord = "trial.json";

}  // namespace

void write_finished_trial(const std::filesystem::path& dir, const nlohmann::json& key,
                          const FinishedTrial& t) {
  std::filesystem::create_directories(dir);
  io::write_file_atomic(dir / kRecord, [&](std::ostream& os) {
    os << nlohmann::json{{"key", key},
                         {"validation_psnr_db", t.psnr_db},
                         {"validation_ssim", t.ssim},
                         {"validation_psnr_db_per_view", t.view_psnr_db},
                         {"gaussians", t.gaussians},
                         {"wall_s", t.wall_s}}
              .dump(2)
       << "\n";
  });
}

std::optional<FinishedTrial> read_finished_trial(const std::filesystem::path& dir,
                                                 const nlohmann::json& key) {
  std::ifstream in(dir / kRecord);
  if (!in) return std::nullopt;
  try {
    const nlohmann::json j = nlohmann::json::parse(in);
    if (j.at("key") != key) return std::nullopt;
    FinishedTrial t;
    t.psnr_db = j.at("validation_psnr_db").get<double>();
    t.ssim = j.at("validation_ssim").get<double>();
    t.view_psnr_db = j.at("validation_psnr_db_per_view").get<std::vector<double>>();
    t.gaussians = j.at("gaussians").get<uint32_t>();
    t.wall_s = j.at("wall_s").get<double>();
    return t;
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;  // cut short while written by hand, or another format: train it again
  }
}

}  // namespace litgs::host
