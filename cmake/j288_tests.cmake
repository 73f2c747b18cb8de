# Host unit tests, as in the Makefile: every test/unit/test_*.c is a plain main() with RUN_TEST
# lines, linked with the library, Unity and every test/support/*.c; run from the repository
# root (tests open test/vectors/... by relative path).

# Unity is fetched, never committed: scripts/fetch-unity.sh honours UNITY_DIR (environment or
# -DUNITY_DIR=...) and otherwise takes Debian's copy.
set(J288_UNITY_DIR "${CMAKE_BINARY_DIR}/unity")
if(NOT EXISTS "${J288_UNITY_DIR}/unity.c")
    set(_unity_env "")
    if(DEFINED UNITY_DIR)
        set(_unity_env "UNITY_DIR=${UNITY_DIR}")
    endif()
    execute_process(
        COMMAND env ${_unity_env} bash "${PROJECT_SOURCE_DIR}/scripts/fetch-unity.sh" "${J288_UNITY_DIR}"
        WORKING_DIRECTORY "${PROJECT_SOURCE_DIR}"
        RESULT_VARIABLE _unity_rc)
    if(NOT _unity_rc EQUAL 0)
        message(FATAL_ERROR "could not fetch Unity (scripts/fetch-unity.sh); set UNITY_DIR to a Unity checkout")
    endif()
endif()

add_library(j288_unity STATIC "${J288_UNITY_DIR}/unity.c")
target_include_directories(j288_unity PUBLIC "${J288_UNITY_DIR}")
target_compile_definitions(j288_unity PUBLIC UNITY_INCLUDE_DOUBLE UNITY_SUPPORT_64)
set_target_properties(j288_unity PROPERTIES C_STANDARD 99 C_EXTENSIONS OFF)

file(GLOB J288_TEST_SUPPORT_SOURCES CONFIGURE_DEPENDS "${PROJECT_SOURCE_DIR}/test/support/*.c")
list(SORT J288_TEST_SUPPORT_SOURCES)
add_library(j288_test_support STATIC ${J288_TEST_SUPPORT_SOURCES})
target_include_directories(j288_test_support PUBLIC
    "${PROJECT_SOURCE_DIR}/test/support" "${PROJECT_SOURCE_DIR}/test/vectors")
target_link_libraries(j288_test_support PUBLIC j288::j288 j288_unity)
target_compile_options(j288_test_support PRIVATE ${J288_WARNINGS})
set_target_properties(j288_test_support PROPERTIES C_STANDARD 99 C_EXTENSIONS OFF)

find_library(J288_LIBM m)

file(GLOB J288_UNIT_TESTS CONFIGURE_DEPENDS "${PROJECT_SOURCE_DIR}/test/unit/test_*.c")
list(SORT J288_UNIT_TESTS)
foreach(src ${J288_UNIT_TESTS})
    get_filename_component(name "${src}" NAME_WE)
    add_executable(${name} "${src}")
    # test/support is linked as objects in front of the library, as in the Makefile
    target_link_libraries(${name} PRIVATE j288_test_support j288::j288 j288_unity)
    if(J288_LIBM)
        target_link_libraries(${name} PRIVATE ${J288_LIBM})
    endif()
    target_compile_options(${name} PRIVATE ${J288_WARNINGS})
    set_target_properties(${name} PROPERTIES C_STANDARD 99 C_EXTENSIONS OFF)
    add_test(NAME ${name} COMMAND ${name} WORKING_DIRECTORY "${PROJECT_SOURCE_DIR}")
endforeach()

# The committed golden vectors must equal a fresh regeneration (as `make test` checks).
find_program(J288_PYTHON3 python3)
if(J288_PYTHON3)
    add_test(NAME vectors_drift COMMAND env BUILD=${CMAKE_BINARY_DIR} PYTHON=${J288_PYTHON3}
             bash tools/vectors/check-drift.sh
             WORKING_DIRECTORY "${PROJECT_SOURCE_DIR}")
endif()
