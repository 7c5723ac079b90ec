# The source tree stays what the repository holds: its root has only the
# entries the design names (the build, the sources, the scenes, the tests,
# the outputs folder, the docs), and nothing a run or a test wrote is left
# untracked in it (outputs go to outputs/ or the build folder, which git
# ignores). Run by ctest (Hygiene.Tree) and by `make test` after the suite,
# so that files the tests themselves leave are caught too.
#
#   cmake -DROOT=<source tree> [-DBEFORE=<file>] -P check_tree.cmake
#   cmake -DSELFTEST=<empty folder> -P check_tree.cmake
#
# BEFORE names a file listing the untracked files that were already there
# before the suite ran (`make test` writes it): a user's own scene or notes
# are theirs, not a fault of the tests; only what appeared since is reported.
# Outside a git clone (a source archive) only the root's entries are checked.
# SELFTEST makes a small git tree there with a stray file at the root, an
# untracked one below, and an untracked one listed as there before (excused),
# and passes only if exactly the first two are reported
# (ctest Hygiene.TreeCheckCatches).
cmake_minimum_required(VERSION 3.20)
set(allowed .ci .git .gitignore CMakeLists.txt Makefile README.md analysis cd configs docs outputs tests)
find_program(GIT git)

function(tree_problems root out)
  set(problems "")
  if(GIT AND EXISTS ${root}/.git)
    # What git tracks, and what is untracked and not ignored.
    execute_process(COMMAND ${GIT} -C ${root} ls-files OUTPUT_VARIABLE tracked RESULT_VARIABLE rc)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "check_tree.cmake: git ls-files failed in ${root}")
    endif()
    execute_process(COMMAND ${GIT} -C ${root} ls-files --others --exclude-standard OUTPUT_VARIABLE untracked)
    string(REPLACE "\n" ";" tracked "${tracked}")
    string(REPLACE "\n" ";" untracked "${untracked}")
    foreach(f IN LISTS tracked)
      string(REGEX REPLACE "/.*" "" top "${f}")
      if(f AND NOT top IN_LIST allowed)
        list(APPEND problems "tracked at the root: ${f}")
      endif()
    endforeach()
    set(before "")
    if(BEFORE AND EXISTS ${BEFORE})
      file(STRINGS ${BEFORE} before)
    endif()
    foreach(f IN LISTS untracked)
      if(f AND NOT f IN_LIST before)
        list(APPEND problems "untracked (written by a run or a test, or not yet added): ${f}")
      endif()
    endforeach()
  else()
    file(GLOB entries RELATIVE ${root} ${root}/* ${root}/.*)
    foreach(e IN LISTS entries)
      if(NOT e IN_LIST allowed AND NOT e MATCHES "^build")
        list(APPEND problems "at the root: ${e}")
      endif()
    endforeach()
  endif()
  list(REMOVE_DUPLICATES problems)
  set(${out} "${problems}" PARENT_SCOPE)
endfunction()

if(SELFTEST)
  if(NOT GIT)
    message(FATAL_ERROR "check_tree.cmake: the self-test needs git")
  endif()
  file(REMOVE_RECURSE ${SELFTEST})
  file(MAKE_DIRECTORY ${SELFTEST}/cd ${SELFTEST}/outputs)
  execute_process(COMMAND ${GIT} init -q ${SELFTEST} RESULT_VARIABLE rc)
  file(WRITE ${SELFTEST}/Makefile "")
  file(WRITE ${SELFTEST}/.gitignore "/outputs/*\n")
  file(WRITE ${SELFTEST}/cd/a.cpp "")
  file(WRITE ${SELFTEST}/stray.txt "a record of a failed command\n")
  execute_process(COMMAND ${GIT} -C ${SELFTEST} add Makefile .gitignore cd/a.cpp stray.txt RESULT_VARIABLE rc2)
  file(WRITE ${SELFTEST}/cd/left.txt "")
  # A user's own untracked file, there before the suite: excused.
  file(WRITE ${SELFTEST}/cd/mine.toml "")
  file(WRITE ${SELFTEST}.before "cd/mine.toml\n")
  set(BEFORE ${SELFTEST}.before)
  file(WRITE ${SELFTEST}/outputs/run.csv "")
  if(NOT rc EQUAL 0 OR NOT rc2 EQUAL 0)
    message(FATAL_ERROR "check_tree.cmake: could not make the self-test tree in ${SELFTEST}")
  endif()
  tree_problems(${SELFTEST} problems)
  set(expect "tracked at the root: stray.txt"
             "untracked (written by a run or a test, or not yet added): cd/left.txt")
  if(NOT problems STREQUAL expect)
    message(FATAL_ERROR "check_tree.cmake: found [${problems}], expected [${expect}]")
  endif()
  message(STATUS "check_tree.cmake: the self-test tree's two faults are found, and only they")
  return()
endif()

tree_problems(${ROOT} problems)
if(problems)
  string(REPLACE ";" "\n  " text "${problems}")
  string(REPLACE ";" ", " names "${allowed}")
  message(FATAL_ERROR "the source tree holds what it should not (the root holds only ${names}; "
                      "outputs go to outputs/ or the build folder):\n  ${text}")
endif()
message(STATUS "check_tree.cmake: the root holds only what it should, nothing untracked")
