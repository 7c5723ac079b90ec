#include "image.hpp"

#include <fmt/core.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>

#include "error.hpp"

namespace cda {

Image read_png(const std::string& path) {
  refuse_folder(path);
  vtkNew<vtkPNGReader> r;
  if (!r->CanReadFile(path.c_str())) throw InputError(fmt::format("'{}' is not a readable PNG file", path));
  r->SetFileName(path.c_str());
  r->Update();
  vtkImageData* d = r->GetOutput();
  int dims[3];
  d->GetDimensions(dims);
  const int comps = d->GetNumberOfScalarComponents();
  if (comps < 3) throw InputError(fmt::format("'{}': {} colour components, RGB expected", path, comps));
  Image im;
  im.width = dims[0];
  im.height = dims[1];
  im.rgb.resize(3 * static_cast<std::size_t>(im.width) * im.height);
  // VTK's image rows start at the bottom.
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x)
      for (int c = 0; c < 3; ++c)
        im.rgb[3 * (static_cast<std::size_t>(y) * im.width + x) + c] = static_cast<std::uint8_t>(
            d->GetScalarComponentAsDouble(x, im.height - 1 - y, 0, c));
  return im;
}

}  // namespace cda
