# Matrix-form contact problems (read/write .dat, assemble from rows, matrix
# NLGS) and the Lemke reference solver, plus the cdproblem replay command.
# 3D frozen problems (src/3d/: laws, FCLib reader, 3D NLGS, polyhedral LCP)
# need FCLib (Debian: libfclib-dev, which brings serial HDF5; found in the
# top-level CMakeLists.txt).
target_sources(cdcore PRIVATE src/2d/problem.cpp src/2d/lemke.cpp src/core/lcp.cpp
  src/3d/problem3.cpp src/3d/lemke3.cpp)
target_include_directories(cdcore PUBLIC src/3d)
target_link_libraries(cdcore PRIVATE FCLIB::fclib)

add_executable(cdproblem app/cdproblem.cpp)
target_link_libraries(cdproblem PRIVATE cdcore CLI11::CLI11)
