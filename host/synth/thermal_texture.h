// Procedural thermal textures: raw radiometric counts (16-bit, around 3000..4500 like the Workswell frames of
// the Thermitage data) as a function of surface coordinates (u, v) in metres.
#pragma once

#include <cstdint>

namespace litgs::host::synth {

enum class ThermalPattern {
  kUniform,  // smooth value noise only: large areas of almost no thermal gradient
  kBrick,    // running-bond bricks: cooler mortar joints, per-brick offsets
  kPanel,    // rectangular cladding panels (or floor tiles): cooler seams, per-panel offsets
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
  uint64_t seed = 0;                  // varies the noise and per-cell offsets between surfaces
};

// Radiance in raw counts at (u, v). `footprint_m` is the pixel's footprint on the surface: joints are box-
// filtered over it, so distant brick walls fade to their mean instead of aliasing.
double thermal_radiance(const ThermalTexture& texture, double u_m, double v_m, double footprint_m);

}  // namespace litgs::host::synth
