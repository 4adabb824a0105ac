# Fails if a generated constructor registers its file's type objects on every construction
# (cmake/OscarIdl.cmake makes it once per process; fastddsgen 2.3 does it every time, which cost
# the coordinator 2/3 of its time at 1000 applets). Run by the test Idl.ConstructorsRegisterTypeObjectsOnce.
file(GLOB sources "${DIR}/*.cxx")
set(checked 0)
foreach(f IN LISTS sources)
  if(f MATCHES "(PubSubTypes|TypeObject)\\.cxx$")
    continue()
  endif()
  math(EXPR checked "${checked} + 1")
  file(STRINGS "${f}" bare REGEX "^[ ]*register[A-Za-z0-9_]*Types\\(\\);$")
  if(bare)
    message(FATAL_ERROR "${f}: a constructor registers the type objects each time: ${bare}")
  endif()
endforeach()
if(checked EQUAL 0)
  message(FATAL_ERROR "no generated sources in ${DIR}")
endif()
message(STATUS "${checked} generated files register their type objects once")
