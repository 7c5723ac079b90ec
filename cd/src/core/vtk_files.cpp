#include "vtk_files.hpp"

#include <filesystem>
#include <system_error>

#include <fmt/format.h>
#include <vtkErrorCode.h>
#include <vtkNew.h>
#include <vtkPolyData.h>
#include <vtkXMLPolyDataWriter.h>

#include "files.hpp"

namespace cd {

void write_vtp(vtkPolyData* pd, const std::string& path) {
  const std::string tmp = tmp_name(path);
  vtkNew<vtkXMLPolyDataWriter> w;
  w->SetInputData(pd);
  w->SetFileName(tmp.c_str());
  w->SetDataModeToAppended();
  w->EncodeAppendedDataOff();  // raw binary, not base64
  w->SetCompressorTypeToZLib();
  w->SetHeaderTypeToUInt64();  // no 4 GB limit on a data block
  // A failure (disk full) is one message, not VTK's log on stderr.
  const int shown = vtkObject::GetGlobalWarningDisplay();
  vtkObject::GlobalWarningDisplayOff();
  const bool ok = w->Write() == 1 && w->GetErrorCode() == 0;
  vtkObject::SetGlobalWarningDisplay(shown);
  if (!ok) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    const unsigned long code = w->GetErrorCode();
    throw WriteError(fmt::format("could not write '{}': {}", path,
                                 code == vtkErrorCode::OutOfDiskSpaceError
                                     ? "no space left on the device (or over the file size limit)"
                                 : code == vtkErrorCode::CannotOpenFileError
                                     ? "the file cannot be created"
                                     : fmt::format("VTK's writer failed (error code {})", code)));
  }
  rename_into_place(tmp, path);
}

std::string pvd_collection(const std::vector<std::pair<double, std::string>>& frames,
                           const char* stem) {
  std::string s =
      "<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      "  <Collection>\n";
  for (const auto& [t, num] : frames)
    s += fmt::format("    <DataSet timestep=\"{}\" group=\"\" part=\"0\" file=\"{}_{}.vtp\"/>\n",
                     t, stem, num);
  s += "  </Collection>\n</VTKFile>\n";
  return s;
}

}  // namespace cd
