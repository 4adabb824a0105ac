cmake_minimum_required(VERSION 3.25)
# Runs `${SWARM} plan ${ARGS}` (ARGS separated by '|'; standard output to STDOUT if given) and
# checks that it exits with EXIT and that its standard error matches the regex STDERR: ctest's
# PASS_REGULAR_EXPRESSION alone would pass whatever the exit code.
string(REPLACE "|" ";" args "${ARGS}")
if(DEFINED STDOUT)
  execute_process(COMMAND ${SWARM} plan ${args} RESULT_VARIABLE rc OUTPUT_FILE ${STDOUT}
                  ERROR_VARIABLE err)
else()
  execute_process(COMMAND ${SWARM} plan ${args} RESULT_VARIABLE rc OUTPUT_QUIET
                  ERROR_VARIABLE err)
endif()
if(NOT rc STREQUAL EXIT)
  message(FATAL_ERROR "oscar-swarm plan ${args} exited with ${rc}, expected ${EXIT}; stderr: ${err}")
endif()
if(NOT err MATCHES "${STDERR}")
  message(FATAL_ERROR "oscar-swarm plan ${args}: stderr '${err}' does not match '${STDERR}'")
endif()
