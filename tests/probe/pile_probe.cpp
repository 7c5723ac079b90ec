#include <cstdio>
#include <omp.h>
#include "../world_util.hpp"
int main(int argc, char** argv) {
  int n = argc > 1 ? atoi(argv[1]) : 300;
  double dt = argc > 2 ? atof(argv[2]) : 1e-3;
  double tol = argc > 3 ? atof(argv[3]) : 1e-4;
  int steps = argc > 4 ? atoi(argv[4]) : 3000;
  double W = argc > 5 ? atof(argv[5]) : 20;
  auto p = cdtest::params(dt, 9.81, 0.4);
  p.solver.tol = tol; p.solver.max_iter = 1000;
  cd::World w(p);
  cdtest::fill_box(w, n, W, 1e9, 0.8, 1.2, 7);
  double m = 0; for (auto x : w.bodies.mass) m += x;
  for (int k = 1; k <= steps; ++k) {
    w.step();
    auto& s = w.last();
    if (k % (steps/20) == 0) printf("t=%.3f KE/(mgd)=%.3e contacts=%d act=%d it=%d cap=%d res=%.2e/%.2e ovmax=%.2e ovmean=%.2e\n", w.time, w.kinetic_energy()/(m*9.81), s.contacts, s.active, s.solve.iterations, s.solve.cap_hit, s.solve.residual_max, s.solve.residual_mean, s.max_overlap, s.mean_overlap);
  }
  printf("times detect %.3f solve %.3f integ %.3f\n", w.times.detect, w.times.solve, w.times.integrate);
}
