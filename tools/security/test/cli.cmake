# `oscar security` as people use it, run by ctest with -DSECURITY=<oscar-security> -DWORK=<dir>:
# init twice (the second keeps everything), check (exit 0), list --json, check against a system
# that grew a module (exit 2, naming it), and a system file without a keystore (exit 2). No
# output ever holds a private key.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
set(modules "modules:\n  - { name: camera, kernels: [ { type: bench_source, name: cam } ] }\n  - { name: viewer, kernels: [ { type: bench_sink, name: view, inputs: { in: cam/out } } ] }\n")
file(WRITE ${WORK}/system.yaml "system: cli\nsecurity: { keystore: keys, cue_protection: sign }\n${modules}")
file(WRITE ${WORK}/grown.yaml "system: cli\nsecurity: { keystore: keys, cue_protection: sign }\n${modules}  - { name: lidar, kernels: [ { type: bench_source, name: lid } ] }\n")
file(WRITE ${WORK}/plain.yaml "system: cli\n${modules}")

# run(<exit code> <output regex> args...)
function(run code regex)
  execute_process(COMMAND ${SECURITY} ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out
                  ERROR_VARIABLE err)
  set(all "${out}${err}")
  if(NOT rc EQUAL code)
    message(FATAL_ERROR "oscar-security ${ARGN}: exit ${rc}, expected ${code}\n${all}")
  endif()
  if(NOT all MATCHES "${regex}")
    message(FATAL_ERROR "oscar-security ${ARGN}: output does not match '${regex}':\n${all}")
  endif()
  if(all MATCHES "PRIVATE KEY")
    message(FATAL_ERROR "oscar-security ${ARGN} printed a private key")
  endif()
  message(STATUS "oscar-security ${ARGN}: exit ${rc}\n${all}")
endfunction()

run(0 "created identity module.camera \\(CN=module.camera,O=OSCAR" init ${WORK}/system.yaml)
run(0 "wrote governance \\(cue protection: sign\\)" init ${WORK}/grown.yaml --keystore ${WORK}/other)
run(0 "kept governance \\(cue protection: sign\\)\n  kept 7 identities unchanged" init ${WORK}/system.yaml)
run(0 "keystore ${WORK}/keys: 0 errors, 0 warnings" check ${WORK}/system.yaml)
run(2 "error: module.lidar: missing \\(the system file has it; run `oscar security init`\\)" check ${WORK}/grown.yaml)
run(1 "warning: module.lidar: not in the system file" check ${WORK}/system.yaml --keystore ${WORK}/other)
run(0 "\"identity\": \"module.viewer\"" list ${WORK}/system.yaml --json)
run(0 "module.viewer +CN=module.viewer,O=OSCAR +[0-9-]+ +oscar/log, oscar/cue/view/\\*" list --keystore ${WORK}/keys)
run(2 "plain.yaml has no security: keystore:; give --keystore DIR" check ${WORK}/plain.yaml)
