# Node.js-driven tests of the viewer (web/test): a real headless Chromium
# (Debian's chromium via playwright-core) and Foxglove's own client library
# against real processes. Integration tests: they start the cell. They skip
# (exit 77, shown as "Skipped") only when Node.js, web/node_modules or
# Chromium is missing; scripts/setup.sh installs all three.
set(_web ${PROJECT_SOURCE_DIR}/web)
set(_run_dir ${PROJECT_BINARY_DIR}/viewer-run)
set(_env IPLAN_BIN_DIR=${IPLAN_BIN_DIR} IPLAN_SOURCE_DIR=${PROJECT_SOURCE_DIR} IPLAN_VIEWER_RUN_DIR=${_run_dir})
function(iplan_add_web_test name script timeout)
  if(IPLAN_NODE_EXE AND EXISTS ${_web}/node_modules)
    add_test(NAME ${name} COMMAND ${IPLAN_NODE_EXE} ${_web}/test/${script} WORKING_DIRECTORY ${_web})
  else()
    add_test(NAME ${name} COMMAND sh -c "echo 'SKIP: Node.js or web/node_modules missing (run scripts/setup.sh)'; exit 77")
  endif()
  set_tests_properties(${name} PROPERTIES LABELS integration RUN_SERIAL TRUE TIMEOUT ${timeout}
                       SKIP_RETURN_CODE 77 ENVIRONMENT "${_env}")
endfunction()
iplan_add_web_test(viewer_foxglove_client_test foxglove_client_test.mjs 120)
iplan_add_web_test(viewer_browser_test viewer_browser_test.mjs 600)
iplan_add_web_test(viewer_demo_run demo_run.mjs 400)
iplan_add_web_test(viewer_replay_test replay_test.mjs 300)
iplan_add_web_test(viewer_report_test report_test.mjs 120)
set_tests_properties(viewer_demo_run PROPERTIES FIXTURES_SETUP viewer_run)
set_tests_properties(viewer_replay_test viewer_report_test PROPERTIES FIXTURES_REQUIRED viewer_run)
