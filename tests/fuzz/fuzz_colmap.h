// COLMAP models are three files in a folder. Input byte 0 picks the file that gets the rest of the input
// (0 cameras, 1 images, 2 points3D, 3 points3D absent); the other files come from a small valid model
// written once per process and restored after each input.
#pragma once

#include <array>
#include <filesystem>
#include <string>

#include "io/colmap.h"
#include "io/file_bytes.h"
#include "tests/fuzz/fuzz_util.h"

namespace litgs::fuzz {

inline io::ColmapModel small_colmap_model() {
  io::ColmapModel m;
  m.cameras[1] = {1, io::ColmapCameraModel::kOpenCv, 8, 6, {500, 501, 4, 3, 0.1, -0.01, 1e-3, 0}};
  io::ColmapImage a;
  a.id = 1;
  a.camera_id = 1;
  a.name = "1.5.png";
  a.t_cam_world = {1, 2, 3};
  a.points2d = {{{1.5, 2.5}, 1}, {{3, 4}, -1}};
  io::ColmapImage b = a;
  b.id = 2;
  b.name = "2.png";
  b.q_cam_world = Eigen::Quaterniond(0.6, 0, 0.8, 0);
  m.images = {a, b};
  m.points = {{1, {0.5, 1, 2}, {1, 2, 3}, 0.25, {{1, 0}, {2, 0}}}};
  return m;
}

template <class Read>
int fuzz_colmap(const uint8_t* data, size_t size, bool binary, Read read) {
  if (size == 0) return 0;
  const auto dir = temp_dir() / (binary ? "colmap-bin" : "colmap-txt");
  const char* ext = binary ? ".bin" : ".txt";
  static const std::array<std::string, 3> good = [&] {
    io::write_colmap_model(dir, small_colmap_model(), binary);
    std::array<std::string, 3> g;
    for (int i = 0; i < 3; ++i)
      g[i] = io::read_file_bytes(dir / (std::string(i == 0   ? "cameras"
                                                    : i == 1 ? "images"
                                                             : "points3D") +
                                        ext));
    return g;
  }();
  const int which = data[0] % 4;
  const auto file = [&](int i) {
    return std::string(binary ? "colmap-bin/" : "colmap-txt/") +
           (i == 0   ? "cameras"
            : i == 1 ? "images"
                     : "points3D") +
           ext;
  };
  if (which == 3)
    std::filesystem::remove(temp_dir() / file(2));
  else
    write_temp(file(which), data + 1, size - 1);
  expect_only_io_error([&] { read(dir); });
  write_temp(file(which == 3 ? 2 : which), good[which == 3 ? 2 : which]);
  return 0;
}

}  // namespace litgs::fuzz
