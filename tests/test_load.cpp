// The oversubscription warning (core/load.hpp): cdsim warns when its threads
// do not fit in the cores the machine's load leaves free.
#include <gtest/gtest.h>

#include "load.hpp"

TEST(Load, WarnsOnlyWhenThreadsDoNotFitBesideTheLoad) {
  // One thread never spins at a barrier.
  EXPECT_EQ(cd::oversubscription_warning(1, 7.5, 2), "");
  // An idle machine, or one busy core of four, leaves room for two threads.
  EXPECT_EQ(cd::oversubscription_warning(2, 0.1, 2), "");
  EXPECT_EQ(cd::oversubscription_warning(2, 1.9, 4), "");
  // Another 2-thread run on a 2-core machine (the campaign case measured at
  // 28x): warned, with the load and the way out named.
  const std::string w = cd::oversubscription_warning(2, 2.0, 2);
  EXPECT_NE(w.find("2.00"), std::string::npos) << w;
  EXPECT_NE(w.find("OMP_NUM_THREADS=1"), std::string::npos) << w;
  // The half-core margin: a load of 0.5 beside 2 threads on 2 cores is noise.
  EXPECT_EQ(cd::oversubscription_warning(2, 0.5, 2), "");
  EXPECT_NE(cd::oversubscription_warning(2, 0.6, 2), "");
}
