// calib extrinsic (calib/extrinsic.h, board_in_scan.h, board_in_image.h): the solve recovers a known
// T_cam_lidar from hole centres projected through it (no detection involved); the detectors find the holes
// of views rendered by synth's holed-board set where the truth (which they never read) puts them; the whole
// chain recovers the rig; the named bad inputs of issue 48.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include "calib/extrinsic.h"
#include "calib/extrinsic_views.h"
#include "calib/holed_board.h"
#include "calib/layout_fit.h"
#include "host/synth/holed_board_views.h"
#include "io/image.h"
#include "io/pcd.h"

namespace litgs::calib {
namespace {

namespace fs = std::filesystem;

double rotation_error_deg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle() * 180 / M_PI;
}

double translation_error_m(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.translation() - b.translation()).norm();
}

// The rendered set (12 views at 320x256 through synth's default rig), made once for the tests that share it.
struct RenderedSet {
  host::synth::HoledBoardViewOptions options;
  std::vector<host::synth::HoledBoardView> views;
  HoledBoard board;
  io::CameraIntrinsics K;
  Eigen::Isometry3d T_cam_lidar;
};

const RenderedSet& rendered_set() {
  static const RenderedSet set = [] {
    RenderedSet s;
    s.options.views = 12;
    s.options.seed = 5;
    s.options.camera.blur_px = 0.5;
    s.views = host::synth::render_holed_board_views(s.options, 2);
    s.K = s.options.camera.intrinsics();
    s.T_cam_lidar = s.options.T_lidar_cam.inverse();
    return s;
  }();
  return set;
}

std::vector<ExtrinsicView> detect(const RenderedSet& s) {
  std::vector<ExtrinsicView> views;
  for (size_t i = 0; i < s.views.size(); ++i)
    views.push_back({"view_" + std::to_string(i), find_board_in_image(s.views[i].raw, s.K, s.board),
                     find_board_in_scan(s.views[i].scan, s.board, {})});
  return views;
}

TEST(CalibExtrinsic, HoleCentresProjectedThroughAKnownRigRecoverIt) {
  // No detection: each view's centres in the LiDAR frame, and their projections with 0.3 px of noise.
  const HoledBoard board;
  io::CameraIntrinsics K;
  K.width = 640;
  K.height = 512;
  K.fx = K.fy = 430;
  K.cx = 321;
  K.cy = 254;
  K.distortion = {-0.3, 0.1, 0.001, 0};
  const Eigen::Isometry3d T_cam_lidar = host::synth::HoledBoardViewOptions::default_rig().inverse();
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0, 0.3);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<ExtrinsicView> views;
  for (int v = 0; v < 40; ++v) {
    Eigen::Isometry3d T_cam_board = Eigen::Isometry3d::Identity();
    T_cam_board.linear() = (Eigen::AngleAxisd(0.4 * u(rng), Eigen::Vector3d::UnitX()) *
                            Eigen::AngleAxisd(0.5 * u(rng), Eigen::Vector3d::UnitY()) *
                            Eigen::AngleAxisd(0.2 * u(rng), Eigen::Vector3d::UnitZ()))
                               .toRotationMatrix();
    T_cam_board.translation() = Eigen::Vector3d(0.4 * u(rng), 0.2 * u(rng), 2.5 + u(rng));
    ExtrinsicView view;
    view.name = std::to_string(v);
    view.image.found = view.scan.found = true;
    view.image.T_cam_board = T_cam_board;
    for (const Eigen::Vector3d& c : board.hole_centres()) {
      const Eigen::Vector3d cam = T_cam_board * c;
      view.image.centres_px.push_back(project_to_pixel(K, cam) + Eigen::Vector2d(noise(rng), noise(rng)));
      view.scan.centres.push_back(T_cam_lidar.inverse() * cam);
    }
    views.push_back(view);
  }
  const ExtrinsicResult r = solve_extrinsic(views, K, board, {});
  std::printf("  rotation error %.4f deg, translation error %.2f mm, RMS %.3f px (+- %.3f deg, %.2f mm)\n",
              rotation_error_deg(r.T_cam_lidar, T_cam_lidar),
              1000 * translation_error_m(r.T_cam_lidar, T_cam_lidar), r.rms_px, r.rotation_sd_deg,
              1000 * r.translation_sd_m);
  EXPECT_EQ(r.views_used, 40u);
  // The targets at 40 views and 0.3 px, and the errors within what the solve's covariance says.
  EXPECT_LT(rotation_error_deg(r.T_cam_lidar, T_cam_lidar), 0.1);
  EXPECT_LT(translation_error_m(r.T_cam_lidar, T_cam_lidar), 0.005);
  EXPECT_LT(rotation_error_deg(r.T_cam_lidar, T_cam_lidar), 4 * r.rotation_sd_deg);
  EXPECT_LT(translation_error_m(r.T_cam_lidar, T_cam_lidar), 4 * r.translation_sd_m);
  EXPECT_NEAR(r.rms_px, 0.3 * std::sqrt(2.0), 0.15) << "the residual is the noise put in";
  EXPECT_GT(r.rotation_sd_deg, 0);
  EXPECT_LT(r.rotation_sd_deg, 0.1);
}

TEST(CalibExtrinsic, TheScanDetectorPutsTheHoleCentresOnTheTruth) {
  const RenderedSet& s = rendered_set();
  int found = 0;
  double worst = 0;
  for (const auto& view : s.views) {
    const BoardInScan b = find_board_in_scan(view.scan, s.board, {});
    if (!b.found) {
      ADD_FAILURE() << b.why_not;
      continue;
    }
    ++found;
    const Eigen::Isometry3d T_lidar_board = s.options.T_lidar_cam * view.T_cam_board;
    const auto truth = s.board.hole_centres();
    for (size_t k = 0; k < truth.size(); ++k)
      worst = std::max(worst, (b.centres[k] - T_lidar_board * truth[k]).norm());
    EXPECT_LT(b.plane_rms_m, 0.02) << "1 cm range noise";
  }
  std::printf("  %d of %zu scans, worst hole centre %.1f mm from the truth\n", found, s.views.size(),
              1000 * worst);
  EXPECT_EQ(found, static_cast<int>(s.views.size()));
  EXPECT_LT(worst, 0.015);
}

TEST(CalibExtrinsic, TheImageDetectorPutsTheHoleCentresOnTheirProjections) {
  const RenderedSet& s = rendered_set();
  double worst = 0, outward = 0;
  int count = 0;
  for (const auto& view : s.views) {
    const BoardInImage b = find_board_in_image(view.raw, s.K, s.board);
    ASSERT_TRUE(b.found) << b.why_not;
    EXPECT_EQ(b.polarity, "warm board");
    const auto truth = s.board.hole_centres();
    for (size_t k = 0; k < truth.size(); ++k) {
      const Eigen::Vector2d e = b.centres_px[k] - project_to_pixel(s.K, view.T_cam_board * truth[k]);
      worst = std::max(worst, e.norm());
      // Outward from the image's centre: a scale error of the centres, which moves the extrinsic along the
      // line of sight (a board-level gradient once pulled them out by 0.04 px on average).
      const Eigen::Vector2d radial = (b.centres_px[k] - Eigen::Vector2d(s.K.cx, s.K.cy)).normalized();
      outward += e.dot(radial);
      ++count;
    }
  }
  std::printf("  worst hole centre %.3f px from its true projection, %+.4f px outward on average\n", worst,
              outward / count);
  EXPECT_LT(worst, 0.25);
  EXPECT_LT(std::abs(outward / count), 0.02);
}

TEST(CalibExtrinsic, RenderedViewsRecoverTheRig) {
  const RenderedSet& s = rendered_set();
  const ExtrinsicResult r = solve_extrinsic(detect(s), s.K, s.board, {});
  const double rot = rotation_error_deg(r.T_cam_lidar, s.T_cam_lidar);
  const double trans = translation_error_m(r.T_cam_lidar, s.T_cam_lidar);
  std::printf("  %zu views used, RMS %.3f px %.4f m; rotation error %.4f deg, translation error %.2f mm\n",
              r.views_used, r.rms_px, r.rms_m, rot, 1000 * trans);
  EXPECT_GE(r.views_used, 11u);
  EXPECT_LT(rot, 0.1);
  EXPECT_LT(trans, 0.005);
}

TEST(CalibExtrinsic, LayoutFitMatchesAnAsymmetricBoardAtAnyTurnAndASymmetricOneUpright) {
  const std::vector<Eigen::Vector2d> asymmetric = {{-0.3, -0.2}, {0.25, -0.25}, {0.3, 0.2}, {-0.1, 0.25}};
  for (const double turn : {0.3, 2.5, -2.0}) {
    std::vector<Eigen::Vector2d> seen;
    const Eigen::Rotation2Dd R(turn);
    for (const auto& h : asymmetric) seen.push_back(R * h + Eigen::Vector2d(0.05, -0.02));
    std::swap(seen[0], seen[2]);  // detections come in any order
    const LayoutFit f = fit_layout_2d(asymmetric, seen);
    ASSERT_TRUE(f.ok);
    EXPECT_EQ(f.detection_of_hole, (std::vector<size_t>{2, 1, 0, 3})) << "turn " << turn;
    EXPECT_NEAR(f.angle_rad, turn, 1e-9);
  }
  // A symmetric board turned by 170 degrees looks like one turned by -10: the upright reading is taken.
  const HoledBoard symmetric;
  std::vector<Eigen::Vector2d> seen;
  for (const auto& h : symmetric.holes) seen.push_back(Eigen::Rotation2Dd(0.2) * h);
  const LayoutFit f = fit_layout_2d(symmetric.holes, seen);
  EXPECT_NEAR(f.angle_rad, 0.2, 1e-9);
  EXPECT_EQ(f.detection_of_hole, (std::vector<size_t>{0, 1, 2, 3}));
}

TEST(CalibExtrinsicBadInput, AScanWithNoBoardIsNamedAndTheOtherViewsCalibrate) {
  const RenderedSet& s = rendered_set();
  std::vector<ExtrinsicView> views = detect(s);
  std::vector<Eigen::Vector3d> background;
  for (const auto& p : s.views[3].scan)
    if (p.norm() > 6) background.push_back(p);  // the wall and the far ground: no board
  views[3].scan = find_board_in_scan(background, s.board, {});
  EXPECT_FALSE(views[3].scan.found);
  EXPECT_NE(views[3].scan.why_not.find("no planar segment of the board's size"), std::string::npos)
      << views[3].scan.why_not;
  const ExtrinsicResult r = solve_extrinsic(views, s.K, s.board, {});
  EXPECT_FALSE(r.views[3].used);
  EXPECT_NE(r.views[3].note.find("scan: no planar segment"), std::string::npos) << r.views[3].note;
  EXPECT_EQ(r.views_used, s.views.size() - 1);
  EXPECT_LT(rotation_error_deg(r.T_cam_lidar, s.T_cam_lidar), 0.1);
}

TEST(CalibExtrinsicBadInput, AnImageWithNoBoardIsNamed) {
  const RenderedSet& s = rendered_set();
  io::Image blank = s.views[0].raw;
  std::fill(blank.data.begin(), blank.data.end(), uint16_t{3300});
  const BoardInImage b = find_board_in_image(blank, s.K, s.board);
  EXPECT_FALSE(b.found);
  EXPECT_NE(b.why_not.find("no board with 4 holes"), std::string::npos) << b.why_not;
}

TEST(CalibExtrinsicBadInput, AnImageOfAnotherSizeThanTheIntrinsicsIsNamed) {
  const RenderedSet& s = rendered_set();
  io::CameraIntrinsics other = s.K;
  other.width = 640;
  const BoardInImage b = find_board_in_image(s.views[0].raw, other, s.board);
  EXPECT_FALSE(b.found);
  EXPECT_EQ(b.why_not, "image 320x256, intrinsics 640x256");
}

TEST(CalibExtrinsicBadInput, TooFewViewsAreRefusedNamingHowManyWereUsable) {
  const RenderedSet& s = rendered_set();
  std::vector<ExtrinsicView> views = detect(s);
  views.resize(3);
  views[2].image = BoardInImage{};
  views[2].image.why_not = "no board with 4 holes (...)";
  try {
    solve_extrinsic(views, s.K, s.board, {});
    FAIL() << "two usable views were accepted";
  } catch (const std::invalid_argument& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("2 of 3 views show the board to both sensors; at least 3 are needed"), std::string::npos)
        << m;
    EXPECT_NE(m.find("view_2 (image: no board with 4 holes"), std::string::npos) << m;
  }
}

TEST(CalibExtrinsicBadInput, AScanWithoutRingsIsNamed) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Eigen::Vector3d> rosette;
  for (int i = 0; i < 5000; ++i) rosette.emplace_back(3, u(rng), 0.5 * u(rng));
  const BoardInScan b = find_board_in_scan(rosette, HoledBoard{}, {});
  EXPECT_FALSE(b.found);
  EXPECT_NE(b.why_not.find("a spinning LiDAR's scan is needed"), std::string::npos) << b.why_not;
}

TEST(CalibExtrinsicBadInput, FilesWithoutPartnersOrUnreadableAreNamedPerView) {
  const RenderedSet& s = rendered_set();
  const fs::path dir = fs::temp_directory_path() / "litgs-calib-extrinsic-files";
  fs::remove_all(dir);
  fs::create_directories(dir / "images");
  fs::create_directories(dir / "scans");
  for (int i = 0; i < 3; ++i) {
    const std::string name = "view_" + std::to_string(i);
    io::write_image(dir / "images" / (name + ".png"), s.views[i].raw);
    io::PointCloud cloud;
    cloud.positions = s.views[i].scan;
    if (i != 1) io::write_pcd(dir / "scans" / (name + ".pcd"), cloud);
  }
  std::ofstream(dir / "scans" / "view_3.pcd") << "not a PCD\n";
  const std::vector<ExtrinsicView> views = find_boards(dir / "images", dir / "scans", s.K, s.board, {});
  ASSERT_EQ(views.size(), 4u);
  EXPECT_TRUE(views[0].image.found && views[0].scan.found);
  EXPECT_NE(views[1].scan.why_not.find("no scan named view_1"), std::string::npos) << views[1].scan.why_not;
  EXPECT_NE(views[3].image.why_not.find("no image named view_3"), std::string::npos)
      << views[3].image.why_not;
  EXPECT_NE(views[3].scan.why_not.find("view_3.pcd"), std::string::npos) << views[3].scan.why_not;
  fs::remove_all(dir);
}

TEST(CalibExtrinsicBadInput, ABoardFileWithAnUnknownKeyOrOverlappingHolesIsRefused) {
  const fs::path dir = fs::temp_directory_path() / "litgs-calib-board-yaml";
  fs::create_directories(dir);
  const auto refused = [&](const std::string& text, const std::string& words) {
    std::ofstream(dir / "board.yaml") << text;
    try {
      read_holed_board(dir / "board.yaml");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  refused(
      "width: 1\nheight: 0.8\nhole_radius: 0.1\nholes: [[-0.2, 0], [0.2, 0], [0, 0.2], [0, "
      "-0.2]]\nthickness: 2\n",
      "unknown key 'thickness'");
  refused("width: 1\nheight: 0.8\nhole_radius: 0.1\nholes: [[-0.2, 0], [-0.15, 0], [0.2, 0], [0, 0.2]]\n",
          "holes 1 and 2 are less than 2.5 radii apart");
  refused("width: 1\nheight: 0.8\nhole_radius: 0.1\nholes: [[-0.2, 0], [0.2, 0], [0, 0.2]]\n",
          "at least 4 holes");
  refused("height: 0.8\nhole_radius: 0.1\nholes: []\n", "missing key 'width'");
  std::ofstream(dir / "board.yaml") << "width: 1\nheight: 0.8\nhole_radius: 0.1\nholes: [[-0.3, -0.2], [0.3, "
                                       "-0.2], [0.3, 0.2], [-0.3, 0.2]]\n";
  EXPECT_EQ(read_holed_board(dir / "board.yaml").holes.size(), 4u);
  fs::remove_all(dir);
}

TEST(HoledBoardFile, TheSyntheticSetRefusesABoardTheSolverWouldRefuse) {
  host::synth::HoledBoardViewOptions o;
  EXPECT_EQ(o.check(), "");
  o.board.holes[1] = o.board.holes[0] + Eigen::Vector2d(0.1, 0);  // within 2.5 radii of hole 1
  EXPECT_NE(o.check().find("holes 1 and 2 are less than 2.5 radii apart"), std::string::npos) << o.check();
  host::synth::HoledBoardViewOptions edge;
  edge.board.holes[2].x() = 0.45;  // 0.45 + 0.12 reaches past the half width, 0.5
  EXPECT_NE(edge.check().find("hole 3 reaches the board's edge"), std::string::npos) << edge.check();
}

}  // namespace
}  // namespace litgs::calib
