// A PNG read back as RGB pixels (through VTK's PNG reader), so that a
// picture cdanalysis drew can be checked pixel by pixel.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace cda {

struct Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;  // row 0 at the top, 3 bytes a pixel
  std::array<int, 3> at(int x, int y) const {
    const std::size_t i = 3 * (static_cast<std::size_t>(y) * width + x);
    return {rgb[i], rgb[i + 1], rgb[i + 2]};
  }
};

// Throws InputError naming the file when it is not a readable PNG.
Image read_png(const std::string& path);

}  // namespace cda
