cmake_minimum_required(VERSION 3.25)
# Runs `oscar-swarm plan PROBLEM --seed SEED` twice and fails unless both runs write byte-identical
# schedules; and once with another seed, which must change the schedule (the option reaches the
# planner). PROBLEM needs random choices: nodes with a turning radius whose legs need RRT.
function(plan seed out)
  execute_process(
    COMMAND ${SWARM} plan ${PROBLEM} --seed ${seed}
    OUTPUT_VARIABLE schedule
    RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "oscar-swarm plan ${PROBLEM} --seed ${seed} exited with ${rc}")
  endif()
  set(${out} "${schedule}" PARENT_SCOPE)
endfunction()

plan(${SEED} first)
plan(${SEED} second)
if(NOT first STREQUAL second)
  message(FATAL_ERROR "oscar-swarm plan --seed ${SEED} wrote different schedules on two runs")
endif()
math(EXPR other "${SEED} + 1")
plan(${other} third)
if(first STREQUAL third)
  message(FATAL_ERROR "oscar-swarm plan --seed ${other} wrote the schedule of --seed ${SEED}")
endif()
