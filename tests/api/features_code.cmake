# The code of a feature a world's set leaves out is not compiled (statsim/features.hpp): reads
# the symbols of tests/api/features_code.cpp built with `Features::all` (ALL) and with
# `Features::paper`, sweep-and-prune only and no impact events (PAPER), both without inlining.
# Each function named below belongs to one left-out part; it must be in ALL (so that the check
# can fail) and absent from PAPER.
#   cmake -DNM=nm -DALL=api_features_all -DPAPER=api_features_paper -P features_code.cmake
set(parts
  "hull search=find_hull_witness"
  "tipping=tip_unsupported"
  "slopes=roll_on_slopes"
  "slopes=settle_on_slope"
  "impact events=record_impacts"
  "grid=find_pairs_grid"
  "queries=measure_drift")
foreach(bin ALL PAPER)
  execute_process(COMMAND ${NM} -C ${${bin}} OUTPUT_VARIABLE symbols_${bin} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${NM} -C ${${bin}} failed")
  endif()
endforeach()
set(failed "")
foreach(part IN LISTS parts)
  string(REPLACE "=" ";" pair "${part}")
  list(GET pair 0 feature)
  list(GET pair 1 function)
  string(REGEX MATCH "statsim::detail::${function}<" in_all "${symbols_ALL}")
  string(REGEX MATCH "statsim::detail::${function}<" in_paper "${symbols_PAPER}")
  if(NOT in_all)
    string(APPEND failed "  ${function} (${feature}) is not in the program with every feature: the check cannot tell\n")
  endif()
  if(in_paper)
    string(APPEND failed "  ${function} (${feature}) is compiled into the program without ${feature}\n")
  endif()
  message(STATUS "${feature}: ${function} with all features: ${in_all}; with paper: ${in_paper}")
endforeach()
if(failed)
  message(FATAL_ERROR "feature sets:\n${failed}")
endif()
