# The runtime's headers, one by one (cmake -DSOURCE_DIR=... -DCXX=... -DEIGEN=... -DWORK_DIR=... -P):
#  - no include cycle among statsim/*.hpp and statsim/detail/*.hpp (with #pragma once a cycle
#    still compiles, in an order that depends on which header a user includes first);
#  - statsim/statsim.hpp includes every public header (those directly in statsim/);
#  - each header compiles alone, included by a file of its own, so that none leans on what
#    another header happened to include before it. (A compiler checks a template's dependent
#    calls only when it is instantiated: a header missing the one that declares such a call
#    still compiles alone. Names that do not depend on a template argument are checked.)
# Fails naming every problem it finds.
cmake_minimum_required(VERSION 3.20)

file(GLOB _public RELATIVE ${SOURCE_DIR} ${SOURCE_DIR}/statsim/*.hpp)
file(GLOB _detail RELATIVE ${SOURCE_DIR} ${SOURCE_DIR}/statsim/detail/*.hpp)
set(_headers ${_public} ${_detail})
list(SORT _headers)
set(_problems "")

# The include graph: an edge from each header to each runtime header it includes.
foreach(_h IN LISTS _headers)
  file(STRINGS ${SOURCE_DIR}/${_h} _lines REGEX "^[ \t]*#[ \t]*include[ \t]*[\"<]statsim/")
  set(_deps_${_h} "")
  foreach(_line IN LISTS _lines)
    string(REGEX REPLACE "^[ \t]*#[ \t]*include[ \t]*[\"<](statsim/[^\">]*)[\">].*$" "\\1" _dep "${_line}")
    if(NOT EXISTS ${SOURCE_DIR}/${_dep})
      list(APPEND _problems "${_h} includes ${_dep}, which does not exist")
    elseif(_dep STREQUAL _h)
      list(APPEND _problems "${_h} includes itself")
    else()
      list(APPEND _deps_${_h} ${_dep})
    endif()
  endforeach()
endforeach()

# Cycles: take out, again and again, the headers that include no header left, then those that no
# header left includes: what remains lies on a cycle.
function(_peel mode)
  while(TRUE)
    set(_next "")
    foreach(_h IN LISTS _left)
      set(_linked FALSE)
      foreach(_g IN LISTS _left)
        if(mode STREQUAL "includes")
          list(FIND _deps_${_h} ${_g} _at)
        else()
          list(FIND _deps_${_g} ${_h} _at)
        endif()
        if(NOT _at EQUAL -1)
          set(_linked TRUE)
          break()
        endif()
      endforeach()
      if(NOT _linked)
        list(APPEND _next ${_h})
      endif()
    endforeach()
    if(NOT _next)
      break()
    endif()
    list(REMOVE_ITEM _left ${_next})
  endwhile()
  set(_left ${_left} PARENT_SCOPE)
endfunction()
set(_left ${_headers})
_peel(includes)
_peel(included)
foreach(_h IN LISTS _left)
  set(_on "")
  foreach(_dep IN LISTS _deps_${_h})
    list(FIND _left ${_dep} _at)
    if(NOT _at EQUAL -1)
      list(APPEND _on ${_dep})
    endif()
  endforeach()
  string(REPLACE ";" ", " _on "${_on}")
  list(APPEND _problems "include cycle: ${_h} includes ${_on}")
endforeach()

# The umbrella includes every public header.
foreach(_h IN LISTS _public)
  if(NOT _h STREQUAL "statsim/statsim.hpp")
    list(FIND _deps_statsim/statsim.hpp ${_h} _at)
    if(_at EQUAL -1)
      list(APPEND _problems "statsim/statsim.hpp does not include ${_h}")
    endif()
  endif()
endforeach()

# Each header alone.
file(MAKE_DIRECTORY ${WORK_DIR})
foreach(_h IN LISTS _headers)
  string(MAKE_C_IDENTIFIER ${_h} _name)
  file(WRITE ${WORK_DIR}/${_name}.cpp "#include \"${_h}\"\n")
  execute_process(COMMAND ${CXX} -std=c++17 -fsyntax-only -Wall -Wextra -Werror -I${SOURCE_DIR} -isystem ${EIGEN}
                          ${WORK_DIR}/${_name}.cpp
                  RESULT_VARIABLE _rc OUTPUT_VARIABLE _out ERROR_VARIABLE _out)
  if(NOT _rc EQUAL 0)
    list(APPEND _problems "${_h} does not compile alone:\n${_out}")
  endif()
endforeach()

list(LENGTH _headers _count)
if(_problems)
  string(REPLACE ";" "\n" _problems "${_problems}")
  message(FATAL_ERROR "${_problems}")
endif()
message(STATUS "${_count} runtime headers: no include cycle, statsim.hpp includes every public one, each compiles alone")
