# Matrix-form contact problems (read/write .dat, assemble from rows, matrix
# NLGS) and the Lemke reference solver, plus the cdproblem replay command.
target_sources(cdcore PRIVATE src/2d/problem.cpp src/2d/lemke.cpp)

add_executable(cdproblem app/cdproblem.cpp)
target_link_libraries(cdproblem PRIVATE cdcore CLI11::CLI11)
