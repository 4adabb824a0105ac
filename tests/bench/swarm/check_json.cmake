cmake_minimum_required(VERSION 3.25)
# Runs `oscar-bench-swarm --json` small and checks the shape issue 6 names:
# {"series":{"<dimension>":[{"n":..,"ms":..,"case":"success|failure"}],
#            "static_obstacles":[{"n":..,"seconds":..,"scheduled":..}]},
#  "e2e":{"nodes":..,"jobs":..,"scheduled":..,"ms_p50":..,"ms_p99":..}}
# Figures are not judged (the benchmark is not a timed test).
execute_process(
  COMMAND ${BENCH} --json --repeat 1 --nodes 10 --obstacles 5 --jobs 20 --static-max 25
  OUTPUT_VARIABLE out
  RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "oscar-bench-swarm --json exited with ${rc}")
endif()
string(JSON static_seconds GET "${out}" series static_obstacles 0 seconds)
foreach(dim moving_obstacles obstacle_detail obstacle_trajectory_segments path_segments nodes
        slots periodic_jobs dependent_jobs)
  string(JSON len LENGTH "${out}" series ${dim})
  set(cases "")
  math(EXPR last "${len} - 1")
  foreach(i RANGE ${last})
    string(JSON n GET "${out}" series ${dim} ${i} n)
    string(JSON ms GET "${out}" series ${dim} ${i} ms)
    string(JSON which GET "${out}" series ${dim} ${i} case)
    if(NOT which MATCHES "^(success|failure)$")
      message(FATAL_ERROR "series.${dim}[${i}].case is '${which}'")
    endif()
    list(APPEND cases ${which})
  endforeach()
  if(NOT "success" IN_LIST cases OR NOT "failure" IN_LIST cases)
    message(FATAL_ERROR "series.${dim} lacks the success or the failure case")
  endif()
endforeach()
string(JSON keys LENGTH "${out}" series)
if(NOT keys EQUAL 9)
  message(FATAL_ERROR "series has ${keys} keys, expected the 8 dimensions and static_obstacles")
endif()
foreach(key nodes jobs scheduled ms_p50 ms_p99)
  string(JSON value GET "${out}" e2e ${key})
endforeach()
string(JSON nodes GET "${out}" e2e nodes)
string(JSON jobs GET "${out}" e2e jobs)
if(NOT nodes EQUAL 10 OR NOT jobs EQUAL 20)
  message(FATAL_ERROR "e2e nodes/jobs are ${nodes}/${jobs}, expected 10/20")
endif()
message(STATUS "oscar-bench-swarm --json has the documented shape")
