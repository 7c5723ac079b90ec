# Every relative link of the documentation resolves: in README.md,
# docs/*.md, tests/README.md and outputs/README.md, each `](path)`,
# `](path#anchor)` and `](#anchor)` names a file or folder that exists
# (relative to the page), and an anchor into a Markdown file is the slug of
# one of its headings, as GitHub makes them: the heading's text (code spans,
# links and emphasis reduced to their text) lowercased, every character that
# is not a letter, a digit, a space, a hyphen or an underscore removed
# (letters of any script stay: μ, φ; digits are decimal digits, so a
# superscript such as the ³ of 10⁻³ goes, as on GitHub), spaces turned into
# hyphens; a slug met again gets -1, -2, ... Links to web addresses, and
# links inside code (fenced blocks, `code spans`), are not checked.
#
#   cmake -DROOT=<source tree> -P check_doc_links.cmake
#   cmake -DSELFTEST=<empty folder> -P check_doc_links.cmake
#
# Fails naming each broken link as <page>:<line>: <link> (<why>). SELFTEST
# writes two small pages there, with good links (Greek and superscript
# headings, a repeated heading, a folder, a link in a table) and broken
# ones (a missing file, a missing anchor, a repeat that is not there, an
# anchor that keeps a superscript; links in code must be ignored), and passes only if
# exactly the broken ones are reported (ctest Docs.LinksCheckCatches).
#
# GitHub keeps letters, marks, decimal digits and connector punctuation
# (its Ruby filter: [^\p{Word}\- ] removed; github-slugger the same). CMake
# has no Unicode classes, so they are told apart by ranges of code points:
# Latin-1's punctuation, symbols and superscript digits, general
# punctuation, super- and subscript digits and signs, currency, fractions,
# arrows, mathematical operators, enclosed numbers, box drawing, shapes and
# dingbats, emoji: removed; the rest kept. Lowercasing covers Latin-1, Latin
# Extended-A, Greek and Cyrillic: what these docs use.
cmake_minimum_required(VERSION 3.20)

# Placeholders for the characters that CMake lists treat specially (";",
# "[", "]", "\"), so that a page can be split into a list of its lines.
string(ASCII 1 SC)
string(ASCII 2 LB)
string(ASCII 3 RB)
string(ASCII 4 BS)

# The slug's bytes for each ASCII character, in hex ("" where removed).
foreach(c RANGE 0 127)
  math(EXPR h "${c}" OUTPUT_FORMAT HEXADECIMAL)
  string(SUBSTRING "${h}" 2 -1 h)
  string(LENGTH "${h}" len)
  if(len EQUAL 1)
    set(h "0${h}")
  endif()
  if(c GREATER_EQUAL 65 AND c LESS_EQUAL 90)  # A-Z to a-z
    math(EXPR lc "${c} + 32" OUTPUT_FORMAT HEXADECIMAL)
    string(SUBSTRING "${lc}" 2 -1 ascii_${h})
  elseif((c GREATER_EQUAL 97 AND c LESS_EQUAL 122) OR (c GREATER_EQUAL 48 AND c LESS_EQUAL 57)
         OR c EQUAL 45 OR c EQUAL 95)
    set(ascii_${h} ${h})
  elseif(c EQUAL 32)
    set(ascii_${h} 2d)
  else()
    set(ascii_${h} "")
  endif()
endforeach()

# A non-ASCII code point: is it a letter, a digit or a mark (kept)?
function(kept cp out)
  set(k TRUE)
  foreach(range 0x80:0xA9 0xAB:0xB4 0xB6:0xB9 0xBB:0xBF 0xD7:0xD7 0xF7:0xF7
                0x37E:0x37E 0x384:0x385 0x387:0x387 0x2000:0x2070 0x2072:0x207E 0x2080:0x208F
                0x20A0:0x20CF 0x2150:0x215F 0x2189:0x218B 0x2190:0x249B 0x24EA:0x24FF
                0x2500:0x2BFF 0x2E00:0x2E7F
                0x3000:0x3003 0x3008:0x3020 0xFF01:0xFF0F 0xFF1A:0xFF20 0xFF3B:0xFF40
                0xFF5B:0xFF65 0x1F000:0x1FAFF)
    string(REPLACE ":" ";" ab "${range}")
    list(GET ab 0 a)
    list(GET ab 1 b)
    math(EXPR a "${a}")
    math(EXPR b "${b}")
    if(cp GREATER_EQUAL a AND cp LESS_EQUAL b)
      set(k FALSE)
      break()
    endif()
  endforeach()
  set(${out} ${k} PARENT_SCOPE)
endfunction()

# A non-ASCII code point lowercased (the scripts these docs use).
function(lower cp out)
  set(l ${cp})
  if((cp GREATER_EQUAL 0xC0 AND cp LESS_EQUAL 0xDE AND NOT cp EQUAL 0xD7)
     OR (cp GREATER_EQUAL 0x391 AND cp LESS_EQUAL 0x3A9 AND NOT cp EQUAL 0x3A2)
     OR (cp GREATER_EQUAL 0x410 AND cp LESS_EQUAL 0x42F))
    math(EXPR l "${cp} + 32")
  elseif(cp GREATER_EQUAL 0x400 AND cp LESS_EQUAL 0x40F)
    math(EXPR l "${cp} + 80")
  elseif(cp GREATER_EQUAL 0x100 AND cp LESS_EQUAL 0x17F)
    math(EXPR odd "${cp} % 2")
    if(((cp LESS_EQUAL 0x137 OR (cp GREATER_EQUAL 0x14A AND cp LESS_EQUAL 0x177)) AND odd EQUAL 0)
       OR (((cp GREATER_EQUAL 0x139 AND cp LESS_EQUAL 0x148) OR cp GREATER_EQUAL 0x179) AND odd EQUAL 1))
      math(EXPR l "${cp} + 1")
    endif()
  endif()
  set(${out} ${l} PARENT_SCOPE)
endfunction()

# UTF-8 bytes (hex, two digits each, no separator) of a code point >= 0x80.
function(utf8_hex cp out)
  if(cp LESS 0x800)
    math(EXPR b1 "0xC0 | (${cp} >> 6)" OUTPUT_FORMAT HEXADECIMAL)
    math(EXPR b2 "0x80 | (${cp} & 0x3F)" OUTPUT_FORMAT HEXADECIMAL)
    set(bytes ${b1} ${b2})
  elseif(cp LESS 0x10000)
    math(EXPR b1 "0xE0 | (${cp} >> 12)" OUTPUT_FORMAT HEXADECIMAL)
    math(EXPR b2 "0x80 | ((${cp} >> 6) & 0x3F)" OUTPUT_FORMAT HEXADECIMAL)
    math(EXPR b3 "0x80 | (${cp} & 0x3F)" OUTPUT_FORMAT HEXADECIMAL)
    set(bytes ${b1} ${b2} ${b3})
  else()
    math(EXPR b1 "0xF0 | (${cp} >> 18)" OUTPUT_FORMAT HEXADECIMAL)
    math(EXPR b2 "0x80 | ((${cp} >> 12) & 0x3F)" OUTPUT_FORMAT HEXADECIMAL)
    math(EXPR b3 "0x80 | ((${cp} >> 6) & 0x3F)" OUTPUT_FORMAT HEXADECIMAL)
    math(EXPR b4 "0x80 | (${cp} & 0x3F)" OUTPUT_FORMAT HEXADECIMAL)
    set(bytes ${b1} ${b2} ${b3} ${b4})
  endif()
  string(REPLACE "0x" "" bytes "${bytes}")
  string(REPLACE ";" "" bytes "${bytes}")
  set(${out} ${bytes} PARENT_SCOPE)
endfunction()

# Hex bytes ("e2", "80", ...) as a list.
function(hex_bytes text out)
  string(HEX "${text}" hex)
  string(REGEX REPLACE "(..)" "\\1;" bytes "${hex}")
  set(${out} ${bytes} PARENT_SCOPE)
endfunction()

# GitHub's slug of a heading's text, as hex bytes (compared in hex, since
# CMake's strings and regular expressions see bytes, not characters).
function(slug_hex text out)
  hex_bytes("${text}" bytes)
  list(LENGTH bytes n)
  set(slug "")
  set(i 0)
  while(i LESS n)
    list(GET bytes ${i} b)
    math(EXPR i "${i} + 1")
    math(EXPR v "0x${b}")
    if(v LESS 0x80)
      string(APPEND slug "${ascii_${b}}")
      continue()
    endif()
    # A multi-byte character: its code point.
    set(seq ${b})
    if(v GREATER_EQUAL 0xF0)
      math(EXPR cp "${v} & 0x07")
      set(more 3)
    elseif(v GREATER_EQUAL 0xE0)
      math(EXPR cp "${v} & 0x0F")
      set(more 2)
    elseif(v GREATER_EQUAL 0xC0)
      math(EXPR cp "${v} & 0x1F")
      set(more 1)
    else()
      continue()  # a stray continuation byte: not a character
    endif()
    foreach(k RANGE 1 ${more})
      if(i LESS n)
        list(GET bytes ${i} c)
        math(EXPR i "${i} + 1")
        math(EXPR cp "(${cp} << 6) | (0x${c} & 0x3F)")
        string(APPEND seq ${c})
      endif()
    endforeach()
    kept(${cp} k)
    if(k)
      lower(${cp} l)
      if(l EQUAL cp)
        string(APPEND slug "${seq}")
      else()
        utf8_hex(${l} lseq)
        string(APPEND slug "${lseq}")
      endif()
    endif()
  endwhile()
  string(TOLOWER "${slug}" slug)
  set(${out} "${slug}" PARENT_SCOPE)
endfunction()

# An anchor as written in a link, as hex bytes, %XX decoded.
function(anchor_hex anchor out)
  string(REGEX MATCHALL "%[0-9A-Fa-f][0-9A-Fa-f]|[^%]+|%" parts "${anchor}")
  set(hex "")
  foreach(p IN LISTS parts)
    if(p MATCHES "^%([0-9A-Fa-f][0-9A-Fa-f])$")
      string(APPEND hex "${CMAKE_MATCH_1}")
    else()
      string(HEX "${p}" h)
      string(APPEND hex "${h}")
    endif()
  endforeach()
  string(TOLOWER "${hex}" hex)
  set(${out} "${hex}" PARENT_SCOPE)
endfunction()

# The lines of a page as a list, with ; [ ] \ replaced by placeholders.
# Code fences: `fence` (the caller's variable) holds the open fence's mark
# ("```" or "~~~", "" outside one) and is updated by a fence line; `out` is
# true for a fence line and for every line inside a fence (no heading or
# link counts there).
function(in_code line fence_var out)
  if(line MATCHES "^ ? ? ?(```+|~~~+)")
    string(SUBSTRING "${CMAKE_MATCH_1}" 0 3 mark)
    if("${${fence_var}}" STREQUAL "")
      set(${fence_var} "${mark}" PARENT_SCOPE)
    elseif("${${fence_var}}" STREQUAL mark)
      set(${fence_var} "" PARENT_SCOPE)
    endif()
    set(${out} TRUE PARENT_SCOPE)
  elseif(NOT "${${fence_var}}" STREQUAL "")
    set(${out} TRUE PARENT_SCOPE)
  else()
    set(${out} FALSE PARENT_SCOPE)
  endif()
endfunction()

function(page_lines file out)
  file(READ "${file}" text)
  string(REPLACE "\\" "${BS}" text "${text}")
  string(REPLACE ";" "${SC}" text "${text}")
  string(REPLACE "[" "${LB}" text "${text}")
  string(REPLACE "]" "${RB}" text "${text}")
  string(REPLACE "\r" "" text "${text}")
  string(REPLACE "\n" ";" text "${text}")
  set(${out} "${text}" PARENT_SCOPE)
endfunction()

function(restore text out)
  string(REPLACE "${BS}" "\\" text "${text}")
  string(REPLACE "${SC}" ";" text "${text}")
  string(REPLACE "${LB}" "[" text "${text}")
  string(REPLACE "${RB}" "]" text "${text}")
  set(${out} "${text}" PARENT_SCOPE)
endfunction()

# The anchors (hex slugs) of a Markdown file's headings, outside fenced
# code; computed once per file.
function(anchors_of file out)
  get_property(done GLOBAL PROPERTY doc_links_anchors_done_${file} SET)
  if(done)
    get_property(anchors GLOBAL PROPERTY doc_links_anchors_${file})
    set(${out} "${anchors}" PARENT_SCOPE)
    return()
  endif()
  page_lines("${file}" lines)
  set(anchors "")
  set(fence "")
  foreach(line IN LISTS lines)
    in_code("${line}" fence code)
    if(code OR NOT line MATCHES "^ ? ? ?(#|##|###|####|#####|######)[ \t]")
      continue()
    endif()
    string(REGEX REPLACE "^ ? ? ?#+[ \t]+" "" text "${line}")
    string(REGEX REPLACE "[ \t]+#+[ \t]*$" "" text "${text}")  # closing #s
    string(STRIP "${text}" text)
    # Rendered text: images and links to their text, code spans and HTML
    # tags to their content, escapes to the character.
    string(REGEX REPLACE "!?${LB}([^${RB}]*)${RB}\\([^)]*\\)" "\\1" text "${text}")
    string(REGEX REPLACE "<[^>]*>" "" text "${text}")
    string(REGEX REPLACE "${BS}(.)" "\\1" text "${text}")
    restore("${text}" text)
    slug_hex("${text}" slug)
    set(candidate "${slug}")
    set(k 0)
    while(candidate IN_LIST anchors)
      math(EXPR k "${k} + 1")
      string(HEX "-${k}" suffix)
      set(candidate "${slug}${suffix}")
    endwhile()
    list(APPEND anchors "${candidate}")
  endforeach()
  set_property(GLOBAL PROPERTY doc_links_anchors_done_${file} TRUE)
  set_property(GLOBAL PROPERTY doc_links_anchors_${file} "${anchors}")
  set(${out} "${anchors}" PARENT_SCOPE)
endfunction()

# The broken links of the pages (paths relative to root), as
# "<page>:<line>: <link> (<why>)".
function(link_problems root pages out)
  set(problems "")
  foreach(page IN LISTS pages)
    get_filename_component(dir "${root}/${page}" DIRECTORY)
    page_lines("${root}/${page}" lines)
    set(number 0)
    set(fence "")
    foreach(line IN LISTS lines)
      math(EXPR number "${number} + 1")
      in_code("${line}" fence code)
      if(code)
        continue()
      endif()
      string(REGEX REPLACE "``[^`]*``|`[^`]*`" "" line "${line}")
      string(REGEX MATCHALL "${RB}\\([^)]*\\)" links "${line}")
      foreach(link IN LISTS links)
        string(REGEX REPLACE "^${RB}\\((.*)\\)$" "\\1" target "${link}")
        restore("${target}" target)
        string(STRIP "${target}" target)
        string(REGEX REPLACE "^<(.*)>$" "\\1" target "${target}")
        string(REGEX REPLACE "[ \t]+(\"[^\"]*\"|'[^']*')$" "" target "${target}")  # a title
        set(shown "${target}")
        if(target STREQUAL "" OR target MATCHES "^[A-Za-z][A-Za-z0-9+.-]*:")
          continue()  # empty, or a web address (https:, mailto:, ...)
        endif()
        set(path "${target}")
        set(anchor "")
        if(target MATCHES "^([^#]*)#(.*)$")
          set(path "${CMAKE_MATCH_1}")
          set(anchor "${CMAKE_MATCH_2}")
        endif()
        string(REPLACE "%20" " " path "${path}")
        if(path STREQUAL "")
          set(file "${root}/${page}")
        elseif(path MATCHES "^/")
          set(file "${root}${path}")
        else()
          set(file "${dir}/${path}")
        endif()
        if(NOT EXISTS "${file}")
          list(APPEND problems "${page}:${number}: ${shown} (no such file)")
          continue()
        endif()
        if(anchor STREQUAL "" OR IS_DIRECTORY "${file}" OR NOT file MATCHES "\\.md$")
          continue()
        endif()
        get_filename_component(file "${file}" REALPATH)
        anchors_of("${file}" anchors)
        anchor_hex("${anchor}" want)
        if(NOT want IN_LIST anchors)
          file(RELATIVE_PATH rel "${root}" "${file}")
          list(APPEND problems "${page}:${number}: ${shown} (no heading of ${rel} has the anchor #${anchor})")
        endif()
      endforeach()
    endforeach()
  endforeach()
  set(${out} "${problems}" PARENT_SCOPE)
endfunction()

if(SELFTEST)
  file(REMOVE_RECURSE "${SELFTEST}")
  file(MAKE_DIRECTORY "${SELFTEST}/docs/sub")
  file(WRITE "${SELFTEST}/README.md"
"# Top

See [the guide](docs/guide.md), [a folder](docs/sub/), [μ(I)](docs/guide.md#μi-and-φi-fits),
[I = 10⁻³](docs/guide.md#a-stop-at-i--10-and-the-alert),
[escaped](docs/guide.md#%CE%BCi-and-%CF%86i-fits) and [here](#top).
| a table | [the repeat](docs/guide.md#notes-1) |
[gone](docs/missing.md) and [no anchor](docs/guide.md#not-a-heading),
[kept ³](docs/guide.md#a-stop-at-i--10³-and-the-alert).
The web: [GitHub](https://github.com/) and [mail](mailto:a@b.c).
In code: `[x](docs/nothing.md)`.

```sh
echo [x](docs/nothing-either.md)
```
")
  file(WRITE "${SELFTEST}/docs/guide.md"
"# The guide

## μ(I) and φ(I) fits

### A stop at I = 10⁻³, and the alert

## Notes

## Notes

```
# not a heading
```

Back to [the top](../README.md#top), [the second notes](#notes-1),
[a third](#notes-2), [`make x` (code)](#the-guide).
")
  link_problems("${SELFTEST}" "README.md;docs/guide.md" problems)
  set(expect
    "README.md:7: docs/missing.md (no such file)"
    "README.md:7: docs/guide.md#not-a-heading (no heading of docs/guide.md has the anchor #not-a-heading)"
    "README.md:8: docs/guide.md#a-stop-at-i--10³-and-the-alert (no heading of docs/guide.md has the anchor #a-stop-at-i--10³-and-the-alert)"
    "docs/guide.md:16: #notes-2 (no heading of docs/guide.md has the anchor #notes-2)")
  if(NOT problems STREQUAL expect)
    string(REPLACE ";" "\n  " found "${problems}")
    string(REPLACE ";" "\n  " wanted "${expect}")
    message(FATAL_ERROR "check_doc_links.cmake: found\n  ${found}\nexpected\n  ${wanted}")
  endif()
  message(STATUS "check_doc_links.cmake: the self-test pages' four broken links are found, and only they")
  return()
endif()

if(NOT ROOT)
  message(FATAL_ERROR "check_doc_links.cmake: give -DROOT=<source tree>")
endif()
file(GLOB docs RELATIVE "${ROOT}" "${ROOT}/docs/*.md")
set(pages README.md ${docs} tests/README.md outputs/README.md)
list(SORT pages)
link_problems("${ROOT}" "${pages}" problems)
if(problems)
  string(REPLACE ";" "\n  " text "${problems}")
  message(FATAL_ERROR "broken links in the documentation (a file that is not there, or an anchor "
                      "that is no heading's):\n  ${text}")
endif()
list(LENGTH pages n)
message(STATUS "check_doc_links.cmake: every relative link of the ${n} pages resolves")
