# Tests registered outside the per-domain GoogleTest binaries (included by tests/CMakeLists.txt).

# The studio's unit tests link the studio server library (apps/studio).
if(TARGET cleave_test_studio AND TARGET cleave_studio_server)
  target_link_libraries(cleave_test_studio PRIVATE cleave_studio_server)
endif()

# The io tests write NIfTI fixtures with nifticlib (the library links it privately).
if(TARGET cleave_test_io AND TARGET cleave_nifti)
  target_link_libraries(cleave_test_io PRIVATE cleave_nifti)
endif()

# End-to-end tests of `cleave studio` in Debian's chromium (playwright-core, node's test runner).
# Needs scripts/install-deps.sh (chromium, node) and scripts/install-web.sh (web/node_modules);
# the tests fail with that instruction when either is missing. Port 0: the server picks a free
# port and prints it; the tests read it from its output.
find_program(CLEAVE_NODE node)
if(CLEAVE_NODE AND TARGET cleave_cli)
  add_test(NAME browser_e2e
           COMMAND ${CLEAVE_NODE} --experimental-websocket --test --test-concurrency=1
                   ${CMAKE_CURRENT_SOURCE_DIR}/browser/server.test.mjs ${CMAKE_CURRENT_SOURCE_DIR}/browser/studio.test.mjs
                   ${CMAKE_CURRENT_SOURCE_DIR}/browser/interactions.test.mjs
           WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  set_tests_properties(browser_e2e PROPERTIES
    LABELS "browser"
    TIMEOUT 600
    ENVIRONMENT "CLEAVE_BIN=$<TARGET_FILE:cleave_cli>;CLEAVE_STUDIO_PORT=0;CLEAVE_SCREENSHOTS=${PROJECT_BINARY_DIR}/browser-screenshots")
endif()

# The page's message reader (web/js/packed.js) alone: node only, no server or browser.
if(CLEAVE_NODE)
  add_test(NAME web_message_reader
           COMMAND ${CLEAVE_NODE} --test ${CMAKE_CURRENT_SOURCE_DIR}/browser/packed.test.mjs
           WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  set_tests_properties(web_message_reader PROPERTIES LABELS "web")
endif()
