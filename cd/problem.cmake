# Contact problems frozen to files. Their forms belong to the engine whose
# step builds and dumps them: the 2D matrix form (read/write .dat, assemble
# from rows, matrix NLGS) is in cd2d, the 3D problems (laws, FCLib reader,
# 3D NLGS) in cd3d, which needs FCLib (Debian: libfclib-dev, which brings
# serial HDF5; found in the top-level CMakeLists.txt). The reference
# solvers (LCP pivoting, 2D Lemke, the 3D polyhedral-cone Lemke) are
# cdfrozen, above both engines, with the cdproblem replay command.
target_sources(cd2d PRIVATE src/2d/problem.cpp)
target_sources(cd3d PRIVATE src/3d/problem3.cpp)
target_link_libraries(cd3d PRIVATE FCLIB::fclib)

add_library(cdfrozen STATIC src/core/lcp.cpp src/2d/lemke.cpp src/3d/lemke3.cpp)
target_link_libraries(cdfrozen PUBLIC cd2d cd3d)

add_executable(cdproblem app/cdproblem.cpp)
target_link_libraries(cdproblem PRIVATE cdfrozen CLI11::CLI11)
