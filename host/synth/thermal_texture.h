// Procedural thermal textures: raw radiometric counts (16-bit, around 3000..4500 like the Workswell frames of
// the Thermitage data) as a function of surface coordinates (u, v) in metres.
#pragma once

#include <cstdint>
#include <vector>

namespace litgs::host::synth {

enum class ThermalPattern {
  kUniform,  // smooth value noise only: large areas of almost no thermal gradient
  kBrick,    // running-bond bricks: cooler mortar joints, per-brick offsets
  kPanel,    // rectangular cladding panels (or floor tiles): cooler seams, per-panel offsets
  // A calibration board: OpenCV's asymmetric circle grid (CircleGridPattern) of another temperature.
  kCircleGrid,
};

// The circles of a kCircleGrid board: circle (row i, column j) centred at (u, v) = (origin_u_m + (2j + i mod
// 2) spacing_m, origin_v_m + i spacing_m), radius radius_m, `raw` counts above the board (below: colder).
struct CircleGridPattern {
  int cols = 4, rows = 11;
  double spacing_m = 0.05;
  double radius_m = 0.02;
  double origin_u_m = 0, origin_v_m = 0;
  double raw = 300;
};

// Warm air leaking around an opening (a window, a door): heat bleeding into the wall around the rectangle
// [u0, u1] x [v0, v1], fading with the distance d to it as exp(-d^2 / 2 r^2), slower above it (heat rises).
struct WarmHalo {
  double u0_m = 0, v0_m = 0, u1_m = 0, v1_m = 0;
  double raw = 0;         // counts above the wall at the rectangle's edge
  double radius_m = 0.3;  // fading radius below and beside it; twice that above
};

struct ThermalTexture {
  ThermalPattern pattern = ThermalPattern::kUniform;
  double base_raw = 3500;             // mean raw counts of the surface
  double noise_raw = 2;               // amplitude of the smooth value noise (counts)
  double noise_scale_m = 2;           // feature size of that noise (metres)
  double cell_u_m = 0.25;             // brick / panel width along u (metres)
  double cell_v_m = 0.065;            // brick / panel height along v (metres)
  double joint_m = 0.01;              // mortar / seam width (metres)
  double joint_raw = -15;             // mortar / seam offset from the cell value (counts)
  double cell_jitter_raw = 6;         // spread (uniform +-) of per-cell offsets (counts)
  double gradient_v_raw_per_m = 0;    // linear change with v (heat rising, sky reflected in glass)
  double spot_raw = 0;                // peak of a warm spot (engine, radiator), counts above base; 0: none
  double spot_u_m = 0, spot_v_m = 0;  // centre of the warm spot in (u, v)
  double spot_radius_m = 1;           // its Gaussian radius (metres)
  // Weathering: moisture, stains and emissivity patches as multi-scale value noise (fBm), the largest
  // features `detail_scale_m`, each finer octave half the size at `detail_gain` of the amplitude. Octaves
  // finer than the pixel footprint fade out, so a distant wall does not alias.
  double detail_raw = 0;      // amplitude of the coarsest octave (counts)
  double detail_scale_m = 1;  // its feature size (metres)
  double detail_gain = 0.7;   // amplitude ratio between octaves
  int detail_octaves = 0;     // 0: no weathering
  double streak_raw = 0;      // rain runoff: vertical streaks (narrow along u, long along v), counts
  std::vector<WarmHalo> halos;
  CircleGridPattern circles;  // kCircleGrid only
  uint64_t seed = 0;          // varies the noise and per-cell offsets between surfaces
};

// The room's wall behind a calibration board: plaster at 3,300 counts with 20 counts of metre-sized
// blotches, cooler than the board and than the scene presets' ground.
ThermalTexture calibration_room_wall();

// Radiance in raw counts at (u, v). `footprint_m` is the pixel's footprint on the surface: joints are box-
// filtered over it, so distant brick walls fade to their mean instead of aliasing.
double thermal_radiance(const ThermalTexture& texture, double u_m, double v_m, double footprint_m);

}  // namespace litgs::host::synth
