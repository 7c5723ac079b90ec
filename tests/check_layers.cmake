# The layer rule of the simulator (cd/CMakeLists.txt), checked on the
# sources: each folder of cd/src may include only its own headers and those
# of the layers below it,
#     scene  <  core  <  2d, 3d (siblings: neither includes the other),
# and analysis/ only its own headers, cd/src/core/observables.hpp and
# cd/src/scene/printable.hpp (the one rule for text in messages). The
# include paths of the libraries already refuse most wrong includes at
# compile time; this also covers headers that no library source includes
# (included only by tests or benchmarks) and includes that happen to find a
# file by a relative path.
#
#   cmake -DROOT=<source tree> [-DEXPECT=<violations>] -P check_layers.cmake
#
# Fails naming each wrong include as <folder>/<file>:<header>. With EXPECT
# (a ;-list of such names), it passes exactly when the violations found are
# those: the test that the check itself catches what it must
# (tests/data/layers/bad/).
cmake_minimum_required(VERSION 3.20)
if(NOT ROOT)
  message(FATAL_ERROR "check_layers.cmake: give -DROOT=<source tree>")
endif()

set(layers scene core 2d 3d)
set(below_scene scene)
set(below_core scene core)
set(below_2d scene core 2d)
set(below_3d scene core 3d)

# The layer of every header, by name (an include is by name: a name in two
# layers would be ambiguous, so it is refused).
set(problems "")
foreach(l IN LISTS layers)
  file(GLOB headers RELATIVE ${ROOT}/cd/src/${l} ${ROOT}/cd/src/${l}/*.hpp)
  foreach(h IN LISTS headers)
    if(DEFINED home_${h})
      list(APPEND problems "${l}/${h}:also in ${home_${h}}/")
    endif()
    set(home_${h} ${l})
  endforeach()
endforeach()

function(includes_of file out)
  file(STRINGS ${file} lines REGEX "^[ \t]*#[ \t]*include[ \t]*\"")
  set(names "")
  foreach(line IN LISTS lines)
    string(REGEX REPLACE "^[ \t]*#[ \t]*include[ \t]*\"([^\"]+)\".*" "\\1" name "${line}")
    list(APPEND names ${name})
  endforeach()
  set(${out} ${names} PARENT_SCOPE)
endfunction()

foreach(l IN LISTS layers)
  file(GLOB sources RELATIVE ${ROOT}/cd/src/${l} ${ROOT}/cd/src/${l}/*.hpp ${ROOT}/cd/src/${l}/*.cpp)
  foreach(f IN LISTS sources)
    includes_of(${ROOT}/cd/src/${l}/${f} names)
    foreach(name IN LISTS names)
      if(name MATCHES "^cd/src/([^/]+)/")
        set(to ${CMAKE_MATCH_1})
      elseif(name MATCHES "/")
        set(to "outside")
      elseif(DEFINED home_${name})
        set(to ${home_${name}})
      else()
        set(to "nowhere")
      endif()
      if(NOT to IN_LIST below_${l})
        list(APPEND problems "${l}/${f}:${name}")
      endif()
    endforeach()
  endforeach()
endforeach()

# analysis/: its own headers, the observables' definitions and the rule for
# printable text.
file(GLOB_RECURSE sources RELATIVE ${ROOT} ${ROOT}/analysis/*.hpp ${ROOT}/analysis/*.cpp)
foreach(f IN LISTS sources)
  includes_of(${ROOT}/${f} names)
  foreach(name IN LISTS names)
    if(name MATCHES "^cd/" AND NOT name STREQUAL "cd/src/core/observables.hpp"
       AND NOT name STREQUAL "cd/src/scene/printable.hpp")
      list(APPEND problems "${f}:${name}")
    endif()
  endforeach()
endforeach()

list(SORT problems)
if(DEFINED EXPECT)
  set(expect ${EXPECT})
  list(SORT expect)
  if(NOT problems STREQUAL expect)
    message(FATAL_ERROR "check_layers.cmake: found [${problems}], expected [${expect}]")
  endif()
  message(STATUS "check_layers.cmake: found the expected violations [${problems}]")
elseif(problems)
  string(REPLACE ";" "\n  " text "${problems}")
  message(FATAL_ERROR "includes across the layers (scene < core < 2d, 3d; 2d and 3d never include "
                      "each other; cd/CMakeLists.txt):\n  ${text}")
else()
  message(STATUS "check_layers.cmake: every include goes down the layers")
endif()
