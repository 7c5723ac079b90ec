# `make help` against the Makefile: every target the Makefile defines (rule
# heads without a pattern or a path, and the names in .PHONY lists) must be
# named on a help line that starts with "make ", every name on such a line
# must be a target, and every variable a user sets (assigned with ?=, or
# read but never assigned, like THREADS or WINDOW) must be shown as VAR=.
#
#   cmake -DROOT=<folder of the Makefile> [-DEXPECT=<problems>] -P check_help.cmake
#
# Fails naming each problem as "target:<t>" (not in help), "variable:<V>"
# (not in help) or "stale:<t>" (in help, not a target). With EXPECT (a
# ;-list of such names) it passes exactly when the problems found are those:
# the test that the check catches what it must (tests/data/help/).
cmake_minimum_required(VERSION 3.20)
if(NOT ROOT)
  message(FATAL_ERROR "check_help.cmake: give -DROOT=<folder of the Makefile>")
endif()

file(STRINGS ${ROOT}/Makefile lines)
set(targets "")
set(assigned "")
set(user_vars "")
set(read_vars "")
foreach(line IN LISTS lines)
  if(line MATCHES "^\\.PHONY *:(.*)$")
    string(REGEX MATCHALL "[^ \t]+" words "${CMAKE_MATCH_1}")
    list(APPEND targets ${words})
  elseif(line MATCHES "^([A-Za-z_][A-Za-z0-9_]*) *(\\?|:|\\+)?=")
    list(APPEND assigned ${CMAKE_MATCH_1})
    if(CMAKE_MATCH_2 STREQUAL "?")
      list(APPEND user_vars ${CMAKE_MATCH_1})
    endif()
  elseif(line MATCHES "^define +([A-Za-z_][A-Za-z0-9_]*)")
    list(APPEND assigned ${CMAKE_MATCH_1})
  elseif(line MATCHES "^([A-Za-z0-9][A-Za-z0-9 _.-]*):([^=]|$)")
    # A rule head (tabs begin recipes, so a recipe line never matches).
    string(REGEX MATCHALL "[^ \t]+" words "${CMAKE_MATCH_1}")
    list(APPEND targets ${words})
  endif()
  # Variables read as $(NAME) (not $$(...), the shell's).
  string(REGEX MATCHALL "(^|[^$])\\$\\([A-Z][A-Z0-9_]*\\)" refs "${line}")
  foreach(r IN LISTS refs)
    string(REGEX REPLACE ".*\\$\\(([A-Z0-9_]+)\\)" "\\1" r "${r}")
    list(APPEND read_vars ${r})
  endforeach()
endforeach()
list(REMOVE_DUPLICATES targets)
list(REMOVE_DUPLICATES read_vars)
# make's own variables
foreach(v IN LISTS read_vars)
  if(NOT v IN_LIST assigned AND NOT v MATCHES "^(MAKE|MAKEFLAGS|MFLAGS|MAKELEVEL|MAKECMDGOALS|CURDIR|SHELL)$")
    list(APPEND user_vars ${v})
  endif()
endforeach()
list(REMOVE_DUPLICATES user_vars)

# The help, as a user gets it (nothing inherited from a make that runs ctest).
execute_process(COMMAND ${CMAKE_COMMAND} -E env --unset=MAKEFLAGS --unset=MFLAGS --unset=MAKELEVEL
                        make -s -C ${ROOT} help
                RESULT_VARIABLE rc OUTPUT_VARIABLE help ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "check_help.cmake: `make -s help` in ${ROOT} failed (${rc}):\n${err}")
endif()
string(REPLACE ";" "," help "${help}")
string(REPLACE "\n" ";" help_lines "${help}")
set(named "")
set(shown "")
foreach(l IN LISTS help_lines)
  if(l MATCHES "^ *make +(.*)$")
    # The names: up to the description (two spaces), without VAR=value and <...>.
    string(REGEX REPLACE "  .*" "" names "${CMAKE_MATCH_1}")
    string(REGEX REPLACE "<[^>]*>" " " names "${names}")
    string(REGEX REPLACE "[A-Z_0-9]+=[^ ]*|\\(= make " " " names "${names}")
    string(REGEX MATCHALL "[a-z0-9][a-z0-9-]*" words "${names}")
    list(APPEND named ${words})
  endif()
  if(l MATCHES "^ *([A-Z][A-Z0-9_]*)=")
    list(APPEND shown ${CMAKE_MATCH_1})
  endif()
endforeach()

set(problems "")
foreach(t IN LISTS targets)
  if(NOT t IN_LIST named)
    list(APPEND problems "target:${t}")
  endif()
endforeach()
foreach(v IN LISTS user_vars)
  if(NOT v IN_LIST shown)
    list(APPEND problems "variable:${v}")
  endif()
endforeach()
list(REMOVE_DUPLICATES named)
foreach(t IN LISTS named)
  if(NOT t IN_LIST targets)
    list(APPEND problems "stale:${t}")
  endif()
endforeach()

list(LENGTH targets nt)
list(LENGTH user_vars nv)
if(DEFINED EXPECT)
  list(SORT problems)
  set(expect ${EXPECT})
  list(SORT expect)
  if(NOT problems STREQUAL expect)
    message(FATAL_ERROR "check_help.cmake: on ${ROOT} found [${problems}], expected [${expect}]")
  endif()
  message(STATUS "check_help.cmake: found exactly the planted problems: ${problems}")
elseif(problems)
  string(REPLACE ";" "\n  " list "${problems}")
  message(FATAL_ERROR "`make help` and the Makefile differ (target: a target help does not name; "
                      "variable: a variable help does not show as VAR=; stale: a name help gives "
                      "that is not a target):\n  ${list}\nAdd it to the help target (Makefile).")
else()
  message(STATUS "make help names all ${nt} targets and shows all ${nv} user variables")
endif()
