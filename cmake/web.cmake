# The page of `pneumid app` (web/): built with npm (vite) into
# ${CMAKE_BINARY_DIR}/web (index.html + assets/), which the server reads in the
# build tree; installed to share/pneumid/web. Needs npm and web/node_modules
# (scripts/setup runs `npm ci` in web/); without them the page is not built.
set(PNEUMID_WEB_SOURCE_DIR ${CMAKE_CURRENT_SOURCE_DIR}/web)
set(PNEUMID_WEB_OUTPUT_DIR ${CMAKE_BINARY_DIR}/web)
find_program(PNEUMID_NPM npm)
find_program(PNEUMID_NODE node)
set(_node_version "")
if(PNEUMID_NODE)
  execute_process(COMMAND ${PNEUMID_NODE} --version OUTPUT_VARIABLE _node_version
                  OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  string(REGEX REPLACE "^v" "" _node_version "${_node_version}")
endif()
if(PNEUMID_NPM AND _node_version VERSION_LESS 20.19)
  # vite 8 needs Node.js 20.19 or newer
  message(STATUS "pneumid app: node ${_node_version} is older than 20.19; the page (web/) is not built")
elseif(PNEUMID_NPM AND EXISTS ${PNEUMID_WEB_SOURCE_DIR}/node_modules)
  file(GLOB _web_sources CONFIGURE_DEPENDS
       ${PNEUMID_WEB_SOURCE_DIR}/src/*
       ${PNEUMID_WEB_SOURCE_DIR}/index.html
       ${PNEUMID_WEB_SOURCE_DIR}/package.json
       ${PNEUMID_WEB_SOURCE_DIR}/package-lock.json
       ${PNEUMID_WEB_SOURCE_DIR}/vite.config.ts)
  set(_web_stamp ${CMAKE_BINARY_DIR}/web.stamp)
  add_custom_command(
    OUTPUT ${_web_stamp} ${PNEUMID_WEB_OUTPUT_DIR}/index.html
    COMMAND ${PNEUMID_NPM} run --silent build -- --outDir ${PNEUMID_WEB_OUTPUT_DIR}
    COMMAND ${CMAKE_COMMAND} -E touch ${_web_stamp}
    DEPENDS ${_web_sources}
    WORKING_DIRECTORY ${PNEUMID_WEB_SOURCE_DIR}
    COMMENT "Building the page of pneumid app into ${PNEUMID_WEB_OUTPUT_DIR}"
    VERBATIM)
  add_custom_target(pneumid_web ALL DEPENDS ${_web_stamp})
  # OPTIONAL: a tree built without the target pneumid_web still installs
  install(DIRECTORY ${PNEUMID_WEB_OUTPUT_DIR}/
          DESTINATION ${CMAKE_INSTALL_DATADIR}/pneumid/web OPTIONAL)
else()
  message(STATUS "pneumid app: npm or web/node_modules not found (run scripts/setup); "
                 "the page (web/) is not built")
endif()

# End-to-end test of the page in Chromium (tests/app/browser_test.sh). It
# fails, naming what is missing, without node, web/node_modules or chromium.
if(PNEUMID_BUILD_TESTS)
  add_test(NAME app.browser
           COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/tests/app/browser_test.sh
                   $<TARGET_FILE:pneumid_cli>
           WORKING_DIRECTORY ${CMAKE_BINARY_DIR})
  set_tests_properties(app.browser PROPERTIES LABELS "app" TIMEOUT 300)
endif()
