// Tracks through repetitive texture (host/frontend/track_conflicts.h): a component holding two keypoints of
// one image is split by the prior poses, keeping the observations that agree with one 3D point.
#include <gtest/gtest.h>

#include "host/frontend/track_conflicts.h"
#include "host/frontend/tracks.h"

namespace litgs::host::frontend {
namespace {

constexpr double kF = 300;

// Four cameras 0.3 m apart along x, looking along +z at a wall at z = 5 with a brick every 0.25 m.
TriangulationView camera(int i, const Eigen::Vector3d& X_world) {
  TriangulationView v;
  v.t_cam_world = Eigen::Vector3d(-0.3 * i, 0, 0);  // camera centre at (0.3 i, 0, 0)
  const Eigen::Vector3d c = X_world + v.t_cam_world;
  v.xy = {c.x() / c.z(), c.y() / c.z()};
  return v;
}

// Each observation of `component` sees the point `seen` lists for it (same order).
ObservationView view_of(const io::SfmTrack& component, const std::vector<Eigen::Vector3d>& seen) {
  return [&component, &seen](const io::SfmObservation& o) -> std::optional<TriangulationView> {
    for (size_t k = 0; k < component.observations.size(); ++k)
      if (component.observations[k].image == o.image && component.observations[k].keypoint == o.keypoint)
        return camera(static_cast<int>(o.image), seen[k]);
    return std::nullopt;
  };
}

TEST(FrontendTrackConflicts, RepetitiveTextureKeepsTheConsistentBrickAndDropsItsNeighbour) {
  const Eigen::Vector3d brick(0.5, 0.1, 5), neighbour(0.75, 0.1, 5);
  // Observations sorted by image; image 2 also saw the neighbour brick, matched by mistake to image 1.
  io::SfmTrack component;
  component.observations = {{0, 0}, {1, 0}, {2, 0}, {2, 1}, {3, 0}};
  const std::vector<Eigen::Vector3d> seen = {brick, brick, brick, neighbour, brick};
  const std::vector<std::array<size_t, 2>> edges = {{0, 1}, {1, 2}, {1, 3}, {2, 4}};
  const ObservationView view = view_of(component, seen);
  const ConflictSplit split = split_conflicting_component(component, edges, view, kF, kF, {});
  ASSERT_EQ(split.tracks.size(), 1u);
  EXPECT_EQ(split.tracks[0].observations, (std::vector<io::SfmObservation>{{0, 0}, {1, 0}, {2, 0}, {3, 0}}));
  EXPECT_EQ(split.dropped, 1u);
}

TEST(FrontendTrackConflicts, TwoBricksChainedByOneWrongMatchBecomeTwoTracks) {
  // Brick A seen by images 0..2, brick B by images 1..3; a wrong match joined A in image 2 with B in image
  // 1. The split gives both tracks back whole.
  const Eigen::Vector3d A(0.5, 0.1, 5), B(0.75, -0.2, 5);
  io::SfmTrack component;
  component.observations = {{0, 0}, {1, 0}, {1, 1}, {2, 0}, {2, 1}, {3, 1}};
  const std::vector<Eigen::Vector3d> seen = {A, A, B, A, B, B};
  const std::vector<std::array<size_t, 2>> edges = {{0, 1}, {1, 3}, {2, 4}, {4, 5}, {2, 3}};
  const ObservationView view = view_of(component, seen);
  const ConflictSplit split = split_conflicting_component(component, edges, view, kF, kF, {});
  ASSERT_EQ(split.tracks.size(), 2u);
  EXPECT_EQ(split.dropped, 0u);
  for (const auto& t : split.tracks) EXPECT_EQ(t.observations.size(), 3u);
}

TEST(FrontendTrackConflicts, UnposedImagesAreNeverSplitIntoATrack) {
  io::SfmTrack component;
  component.observations = {{0, 0}, {0, 1}, {1, 0}};
  const ConflictSplit split = split_conflicting_component(
      component, {{0, 2}, {1, 2}}, [](const io::SfmObservation&) { return std::nullopt; }, kF, kF, {});
  EXPECT_TRUE(split.tracks.empty());
  EXPECT_EQ(split.dropped, 3u);
}

TEST(FrontendTrackConflicts, ATrackTheDriftSplitInTimeIsMergedBack) {
  // One brick seen by images 0..5, but the priors of images 3..5 drifted 0.15 m down: through them the brick
  // projects 9 px off the others' point. Each half is exact on its own, the union leaves about 4.5 px, and
  // a wrong match in image 2 makes the component conflicting.
  const Eigen::Vector3d brick(0.8, 0.1, 5), drifted(0.8, 0.25, 5), neighbour(1.05, 0.1, 5);
  io::SfmTrack component;
  component.observations = {{0, 0}, {1, 0}, {2, 0}, {2, 1}, {3, 0}, {4, 0}, {5, 0}};
  const std::vector<Eigen::Vector3d> seen = {brick, brick, brick, neighbour, drifted, drifted, drifted};
  const std::vector<std::array<size_t, 2>> edges = {{0, 1}, {1, 2}, {1, 3}, {2, 4}, {4, 5}, {5, 6}};
  const ObservationView view = view_of(component, seen);

  ConflictOptions no_merge;
  no_merge.merge_factor = 0;
  const ConflictSplit split = split_conflicting_component(component, edges, view, kF, kF, no_merge);
  ASSERT_EQ(split.tracks.size(), 2u);  // the two halves
  EXPECT_EQ(split.tracks[0].observations.size() + split.tracks[1].observations.size(), 6u);

  const ConflictSplit merged = split_conflicting_component(component, edges, view, kF, kF, {});
  ASSERT_EQ(merged.tracks.size(), 1u);
  EXPECT_EQ(merged.tracks[0].observations,
            (std::vector<io::SfmObservation>{{0, 0}, {1, 0}, {2, 0}, {3, 0}, {4, 0}, {5, 0}}));
  EXPECT_EQ(merged.dropped, 1u);  // the neighbour

  // Beyond the merge bound (twice the 3 px split bound): a drift of 0.4 m leaves about 12 px each way.
  std::vector<Eigen::Vector3d> far_seen = seen;
  for (size_t k = 4; k < 7; ++k) far_seen[k] = Eigen::Vector3d(0.8, 0.5, 5);
  const ConflictSplit apart =
      split_conflicting_component(component, edges, view_of(component, far_seen), kF, kF, {});
  EXPECT_EQ(apart.tracks.size(), 2u);
}

TEST(FrontendTrackConflicts, TheObservationMatchedToTheTrackBeatsANearerNeighbour) {
  // Image 2's prior drifted: through it the brick lands 2 px off, while a different feature lands 1 px
  // off. The nearest would be the wrong one; the brick's keypoint has verified matches to images 1 and 3,
  // the other feature only to image 1.
  constexpr double kPx = 5.0 / kF;  // metres per pixel on the wall
  const Eigen::Vector3d brick(0.5, 0.1, 5);
  io::SfmTrack component;
  component.observations = {{0, 0}, {1, 0}, {2, 0}, {2, 1}, {3, 0}};
  const std::vector<Eigen::Vector3d> seen = {brick, brick, brick + Eigen::Vector3d(0, 2 * kPx, 0),
                                             brick + Eigen::Vector3d(kPx, 0, 0), brick};
  const std::vector<std::array<size_t, 2>> edges = {{0, 1}, {1, 2}, {2, 4}, {1, 3}};
  const ConflictSplit split =
      split_conflicting_component(component, edges, view_of(component, seen), kF, kF, {});
  ASSERT_EQ(split.tracks.size(), 1u);
  EXPECT_EQ(split.tracks[0].observations, (std::vector<io::SfmObservation>{{0, 0}, {1, 0}, {2, 0}, {3, 0}}));
  EXPECT_EQ(split.dropped, 1u);
}

TEST(FrontendTrackConflicts, AnObservationJustBeyondTheBoundJoinsTheTrackItIsMatchedTo) {
  // Image 4 sees the brick 4.5 px off along the baseline (its prior drifted): beyond the 3 px bound, within
  // twice it (the two-view point of images 3 and 4 moves in depth and loses the others). Image 3 also holds
  // a wrong keypoint, so the component is split.
  constexpr double kPx = 5.0 / kF;
  const Eigen::Vector3d brick(0.5, 0.1, 5), neighbour(0.75, 0.1, 5);
  io::SfmTrack component;
  component.observations = {{0, 0}, {1, 0}, {2, 0}, {3, 0}, {3, 1}, {4, 0}};
  const std::vector<Eigen::Vector3d> seen = {brick, brick,     brick,
                                             brick, neighbour, brick + Eigen::Vector3d(4.5 * kPx, 0, 0)};
  const std::vector<std::array<size_t, 2>> edges = {{0, 1}, {1, 2}, {2, 3}, {2, 4}, {3, 5}};
  const ConflictSplit attached =
      split_conflicting_component(component, edges, view_of(component, seen), kF, kF, {});
  ASSERT_EQ(attached.tracks.size(), 1u);
  EXPECT_EQ(attached.tracks[0].observations,
            (std::vector<io::SfmObservation>{{0, 0}, {1, 0}, {2, 0}, {3, 0}, {4, 0}}));
  EXPECT_EQ(attached.dropped, 1u);  // the neighbour
  ConflictOptions strict;
  strict.merge_factor = 0;
  const ConflictSplit dropped =
      split_conflicting_component(component, edges, view_of(component, seen), kF, kF, strict);
  ASSERT_EQ(dropped.tracks.size(), 1u);
  EXPECT_EQ(dropped.tracks[0].observations.size(), 4u);
  EXPECT_EQ(dropped.dropped, 2u);
}

TEST(FrontendTrackConflicts, AWallOfBricksMatchedOnePeriodOffSplitsIntoOneTrackPerBrick) {
  // 40 x 10 bricks 0.25 m apart (15 px at 5 m), seen by 8 images: 3,200 observations in one component,
  // 400 per image, rows of equal x, each keypoint jittered. Every brick is matched between neighbouring
  // images, and every third also to the next brick of its row (one period off, on the epipolar line). Each
  // brick must come back as one track through all 8 images: an agreeing observation missed by the search per
  // image would shorten or drop tracks.
  constexpr size_t kImages = 8, kColumns = 40, kRows = 10, kBricks = kColumns * kRows;
  io::SfmTrack component;
  std::vector<Eigen::Vector3d> seen;
  for (uint32_t image = 0; image < kImages; ++image)
    for (uint32_t b = 0; b < kBricks; ++b) {
      component.observations.push_back({image, b});
      // Each keypoint up to 1.2 px off its brick, so the agreeing observation is not at the projection.
      const double jitter_x = 0.6 * static_cast<double>((b * 7 + image * 3) % 5) - 1.2;
      const double jitter_y = 0.6 * static_cast<double>((b * 3 + image * 5) % 5) - 1.2;
      seen.emplace_back(-2.0 + 0.25 * static_cast<double>(b % kColumns) + jitter_x * 5 / kF,
                        -1.0 + 0.25 * static_cast<double>(b / kColumns) + jitter_y * 5 / kF, 5);
    }
  std::vector<std::array<size_t, 2>> edges;
  for (size_t image = 0; image + 1 < kImages; ++image)
    for (size_t b = 0; b < kBricks; ++b) {
      edges.push_back({image * kBricks + b, (image + 1) * kBricks + b});
      if (b % 3 == 0 && b % kColumns + 1 < kColumns)
        edges.push_back({image * kBricks + b, (image + 1) * kBricks + b + 1});
    }
  // Uneven steps along the wall: with even ones a match one period off would be a point in front of the
  // wall that every image sees one more period off, as consistent as the bricks.
  const std::array<double, kImages> centre_x = {0, 0.37, 0.61, 1.05, 1.3, 1.72, 2.01, 2.44};
  const ObservationView view = [&](const io::SfmObservation& o) -> std::optional<TriangulationView> {
    TriangulationView v;
    v.t_cam_world = Eigen::Vector3d(-centre_x[o.image], 0, 0);
    const Eigen::Vector3d c = seen[o.image * kBricks + o.keypoint] + v.t_cam_world;
    v.xy = {c.x() / c.z(), c.y() / c.z()};
    return v;
  };
  const ConflictSplit split = split_conflicting_component(component, edges, view, kF, kF, {});
  EXPECT_EQ(split.dropped, 0u);
  ASSERT_EQ(split.tracks.size(), kBricks);
  std::vector<char> brick_seen(kBricks, 0);
  for (const auto& t : split.tracks) {
    ASSERT_EQ(t.observations.size(), kImages);
    const uint32_t brick = t.observations[0].keypoint;
    for (uint32_t image = 0; image < kImages; ++image)
      EXPECT_EQ(t.observations[image], (io::SfmObservation{image, brick}));
    brick_seen[brick] = 1;
  }
  EXPECT_EQ(std::count(brick_seen.begin(), brick_seen.end(), 1), static_cast<long>(kBricks));
}

TEST(FrontendTracks, WithASplitterConflictsAreSplitAndTheLostMatchesCounted) {
  // A chain 0:0 - 1:0 - 2:0 and a match 0:0 - 2:1: with a splitter the component {0:0, 1:0, 2:0, 2:1}
  // reaches it whole (this splitter keeps image 2's keypoint 0); 1:1 - 2:2 is a track of its own.
  std::vector<io::SfmPairMatches> pairs = {
      {0, 1, {{0, 0, true}}},
      {1, 2, {{0, 0, true}, {1, 2, true}}},
      {0, 2, {{0, 1, true}}},
  };
  size_t calls = 0;
  const ComponentSplitter split = [&](const io::SfmTrack& c,
                                      const std::vector<std::array<size_t, 2>>& edges) {
    ++calls;
    EXPECT_EQ(c.observations, (std::vector<io::SfmObservation>{{0, 0}, {1, 0}, {2, 0}, {2, 1}}));
    EXPECT_EQ(edges.size(), 3u);
    ConflictSplit s;
    s.tracks.push_back({});
    s.tracks[0].observations = {{0, 0}, {1, 0}, {2, 0}};
    s.dropped = 1;
    return s;
  };
  const TrackSet t = build_tracks({1, 2, 3}, pairs, {}, split);
  EXPECT_EQ(calls, 1u);
  EXPECT_EQ(t.matches, 4u);
  EXPECT_EQ(t.conflicts, 1u);  // the 0:0 - 2:1 match
  EXPECT_EQ(t.conflicting_components, 1u);
  EXPECT_EQ(t.conflict_observations_kept, 3u);
  EXPECT_EQ(t.conflict_observations_dropped, 1u);
  ASSERT_EQ(t.tracks.size(), 2u);
  EXPECT_EQ(t.tracks[1].observations, (std::vector<io::SfmObservation>{{1, 1}, {2, 2}}));
}

}  // namespace
}  // namespace litgs::host::frontend
