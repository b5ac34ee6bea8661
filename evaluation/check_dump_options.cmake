# SPDX-License-Identifier: BSD-3-Clause
# dump_primitive's command line: --help exits 0 with the usage on stdout (it exited 2 as an
# "unknown or incomplete argument"); a value that is not what its option takes exits 2 naming the
# option and the value, as evaluate_collision's (evaluation/eval_options.h), before DIR is made.
# cmake -DEXE=... -DWORK=DIR -P check_dump_options.cmake
file(REMOVE_RECURSE "${WORK}")
function(expect code stream pattern)
  execute_process(COMMAND "${EXE}" ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL code)
    message(FATAL_ERROR "dump_primitive ${ARGN}: exit ${rc}, expected ${code}: ${out}${err}")
  endif()
  if(NOT "${${stream}}" MATCHES "${pattern}")
    message(FATAL_ERROR "dump_primitive ${ARGN}: its ${stream} does not say '${pattern}': ${out}${err}")
  endif()
  message(STATUS "${ARGN}: ${out}${err}")
endfunction()
expect(0 out "^usage: dump_primitive --out DIR" --help)
expect(0 out "^usage: dump_primitive --out DIR" -h)
set(base --out "${WORK}/out")
expect(2 err "option --seed: 'abc' is not a whole number" ${base} --seed abc sphere_sphere/0s)
expect(2 err "option --seed: '-1' is not a whole number" ${base} --seed -1 sphere_sphere/0s)
expect(2 err "option --scale: '1O' is not a finite number" ${base} --scale 1O sphere_sphere/0s)
expect(2 err "option --scale: 0 must be above 0" ${base} --scale 0 sphere_sphere/0s)
expect(2 err "option --scale needs a value" ${base} sphere_sphere/0s --scale)
expect(2 err "--out and PREFIX are required" --seed 1 sphere_sphere/0s)
# A prefix no query has: exit 1, and no directory made (it was made before the search).
expect(1 err "no W2 query name starts with 'no_such_scenario'" ${base} no_such_scenario)
if(EXISTS "${WORK}/out")
  message(FATAL_ERROR "a refused run made ${WORK}/out")
endif()
