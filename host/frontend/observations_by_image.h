// A spatial index of one component's observations for the conflict split (track_conflicts.cc).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <compare>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "host/frontend/triangulation.h"
#include "io/sfm_files.h"

namespace litgs::host::frontend {

// The component's posed observations per image, bucketed in square pixel cells as wide as the bound: a
// point's agreeing observations lie within the bound of its projection, in the 3x3 cells around it, so they
// are found without testing every observation of the component (repeated texture makes components of tens
// of thousands). Assumes the views of one image share its pose, as the prior poses do.
class ObservationsByImage {
 public:
  ObservationsByImage(const io::SfmTrack& component,
                      const std::vector<std::optional<TriangulationView>>& views, double fx, double fy,
                      double bound_px)
      // The margin covers the rounding between fx * (x - x') and fx * x - fx * x'.
      : fx_(fx),
        fy_(fy),
        cell_px_(bound_px * (1 + 1e-9) + 1e-6),
        slot_of_(component.observations.size(), SIZE_MAX) {
    for (size_t i = 0; i < component.observations.size(); ++i) {
      if (!views[i]) continue;
      const uint32_t image = component.observations[i].image;
      if (slots_.empty() || slots_.back().image != image) slots_.push_back({image, &*views[i], {}});
      const auto cell = cell_of(fx * views[i]->xy.x(), fy * views[i]->xy.y());
      if (cell) slots_.back().cells.push_back({(*cell)[0], (*cell)[1], i});
      slot_of_[i] = slots_.size() - 1;
    }
    for (auto& slot : slots_) std::sort(slot.cells.begin(), slot.cells.end());
  }
  size_t slots() const { return slots_.size(); }
  size_t slot_of(size_t observation) const { return slot_of_[observation]; }
  // Calls visit(observation) for the observations of one slot in the 3x3 cells around X's projection (every
  // one within the bound of it, and some farther); none where X is behind the camera.
  template <class Visit>
  void near(size_t slot, const Eigen::Vector3d& X, Visit&& visit) const {
    const Slot& s = slots_[slot];
    const Eigen::Vector3d c = s.pose->R_cam_world * X + s.pose->t_cam_world;
    if (!(c.z() > 1e-6)) return;
    const auto cell = cell_of(fx_ * (c.x() / c.z()), fy_ * (c.y() / c.z()));
    if (!cell) return;
    const auto [row, column] = *cell;
    for (int64_t r = row - 1; r <= row + 1; ++r) {
      auto k = std::lower_bound(s.cells.begin(), s.cells.end(), Entry{r, column - 1, 0});
      for (; k != s.cells.end() && k->row == r && k->column <= column + 1; ++k) visit(k->observation);
    }
  }

 private:
  struct Entry {
    int64_t row, column;
    size_t observation;
    auto operator<=>(const Entry&) const = default;
  };
  struct Slot {
    uint32_t image;
    const TriangulationView* pose;  // the image's first posed observation
    std::vector<Entry> cells;       // sorted by cell, then observation
  };
  // (row, column) of a pixel; none for one too far out to bucket (no keypoint lies there).
  std::optional<std::array<int64_t, 2>> cell_of(double u, double v) const {
    if (!(std::abs(u) < 1e12 && std::abs(v) < 1e12)) return std::nullopt;
    return std::array<int64_t, 2>{static_cast<int64_t>(std::floor(v / cell_px_)),
                                  static_cast<int64_t>(std::floor(u / cell_px_))};
  }
  double fx_, fy_, cell_px_;
  std::vector<Slot> slots_;  // in image order
  std::vector<size_t> slot_of_;
};

}  // namespace litgs::host::frontend
