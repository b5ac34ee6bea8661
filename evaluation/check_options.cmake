# SPDX-License-Identifier: BSD-3-Clause
# evaluate_collision's command line: --help exits 0 with the usage; a value that is not what its
# option takes, an unknown --only setting and an --out inside --data exit 2 naming the option and
# value, before any output directory is made; an empty value or list item is refused too; a failure
# while running (a --data without its files) exits 1.
# cmake -DEXE=... -DDATA=... -DWORK=DIR -P check_options.cmake
file(REMOVE_RECURSE "${WORK}")
function(expect code pattern)
  execute_process(COMMAND "${EXE}" ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL code)
    message(FATAL_ERROR "evaluate_collision ${ARGN}: exit ${rc}, expected ${code}: ${out}${err}")
  endif()
  if(NOT "${out}${err}" MATCHES "${pattern}")
    message(FATAL_ERROR "evaluate_collision ${ARGN}: does not say '${pattern}': ${out}${err}")
  endif()
  message(STATUS "${ARGN}: ${out}${err}")
endfunction()
expect(0 "^usage: evaluate_collision --out DIR" --help)
set(base --out "${WORK}/out" --data "${DATA}")
expect(2 "option --seed: 'abc' is not a whole number" ${base} --seed abc)
expect(2 "option --seed: '5x' is not a whole number" ${base} --seed 5x)
expect(2 "option --seed: '-1' is not a whole number" ${base} --seed -1)
expect(2 "option --rescans: '2.5' is not a whole number" ${base} --rescans 2.5)
expect(2 "option --noise: '1O' is not a finite number" ${base} --noise 0.5,1O)
expect(2 "option --noise: -1 must be above 0" ${base} --noise -1)
expect(2 "option --merge: -2 must be at least 0" ${base} --merge -2)
expect(2 "option --drop: 100 % leaves no sample" ${base} --drop 100)
expect(2 "option --only: unknown setting 'bogus' \\(this run's: default, " ${base} --only default,bogus)
# An empty value or item: "--noise ''" ran the default levels, "--only ''" every setting, silently.
# (An empty argument is lost when a list is expanded, so these name it themselves.)
foreach(option --noise --workloads --only)
  execute_process(COMMAND "${EXE}" --out "${WORK}/out" --data "${DATA}" ${option} "" RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(NOT rc EQUAL 2 OR NOT err MATCHES "option ${option}: '' has an empty item")
    message(FATAL_ERROR "evaluate_collision ${option} '': exit ${rc}: ${err}")
  endif()
  message(STATUS "${option} '': ${err}")
endforeach()
expect(2 "option --noise: '0.5,,1' has an empty item" ${base} --noise 0.5,,1)
expect(2 "option --only: 'default,' has an empty item" ${base} --only default,)
expect(2 "option --seed needs a value" ${base} --seed)
expect(2 "--out '.*' lies in --data" --out "${DATA}/scenes" --data "${DATA}/")
# Through a symbolic link (to a --data of its own here: a run taken by mistake writes nothing shared).
file(MAKE_DIRECTORY "${WORK}/own_data/scenes")
file(CREATE_LINK "${WORK}/own_data/scenes" "${WORK}/link" SYMBOLIC)
expect(2 "--out '.*/link/results' lies in --data" --out "${WORK}/link/results" --data "${WORK}/own_data")
# A --data that is no directory, before --out is made (it was made, then the read failed).
expect(2 "--data '.*/missing' is not a directory" --out "${WORK}/out" --data "${WORK}/missing")
if(EXISTS "${WORK}/out")
  message(FATAL_ERROR "a refused run made ${WORK}/out")
endif()
# A failure while running is not a usage error: exit 1 (it was 2).
file(MAKE_DIRECTORY "${WORK}/no_data")
expect(1 "cannot read ${WORK}/no_data/scenes/queries.csv" --out "${WORK}/out" --data "${WORK}/no_data" --workloads W3)
