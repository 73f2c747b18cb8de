# Every test `make test` runs, registered with ctest under the name `make test-list` prints
# for it (mk/lists.mk): a binary by its path under the build folder (test/test_crc32,
# crc-nibble/test/test_crc32, ...), a script by its repository path (test/e2e/cli_bus.sh).
# scripts/ci-cmake.sh fails when the two lists differ. Same sources, flags and globs as the
# Makefile fragments named beside each group; every test runs from the repository root with
# BUILD (this build folder) and BIN (<build>/bin) in its environment, as run-tests.sh does.
# Needs cmake/j288_host.cmake first (j288_add_program, the tool targets).

set(J288_SRC "${PROJECT_SOURCE_DIR}")
set(J288_TEST_TIMEOUT 300) # scripts/run-tests.sh's per-test bound
find_program(J288_PYTHON3 python3)
if(NOT J288_PYTHON3)
    set(J288_PYTHON3 python3) # the drift check then fails with "python3: not found"
endif()

# j288_register_test(<name> <command>...): run from the repository root, Make's environment.
function(j288_register_test name)
    add_test(NAME "${name}" COMMAND ${ARGN} WORKING_DIRECTORY "${J288_SRC}")
    set_tests_properties("${name}" PROPERTIES
        TIMEOUT ${J288_TEST_TIMEOUT}
        ENVIRONMENT "BUILD=${PROJECT_BINARY_DIR};BIN=${PROJECT_BINARY_DIR}/bin;PYTHON=${J288_PYTHON3}")
endfunction()

# j288_add_test(<target> <name> SOURCES ... [LIBS ...] [INCLUDES ...] [DEFINES ...]):
# a Unity test binary at <build>/<name>, registered as <name>.
function(j288_add_test target name)
    j288_add_program(${target} OUTPUT "${name}" ${ARGN})
    j288_register_test("${name}" ${target})
endfunction()

# ---- Unity (fetched, never committed) ------------------------------------------------------
# scripts/fetch-unity.sh honours UNITY_DIR (environment or -DUNITY_DIR=...) and otherwise takes
# Debian's copy.
set(J288_UNITY_DIR "${CMAKE_BINARY_DIR}/unity")
if(NOT EXISTS "${J288_UNITY_DIR}/unity.c")
    set(_unity_env "")
    if(DEFINED UNITY_DIR)
        set(_unity_env "UNITY_DIR=${UNITY_DIR}")
    endif()
    execute_process(
        COMMAND env ${_unity_env} bash "${J288_SRC}/scripts/fetch-unity.sh" "${J288_UNITY_DIR}"
        WORKING_DIRECTORY "${J288_SRC}"
        RESULT_VARIABLE _unity_rc)
    if(NOT _unity_rc EQUAL 0)
        message(FATAL_ERROR "could not fetch Unity (scripts/fetch-unity.sh); set UNITY_DIR to a Unity checkout")
    endif()
endif()

add_library(j288_unity STATIC "${J288_UNITY_DIR}/unity.c")
target_include_directories(j288_unity PUBLIC "${J288_UNITY_DIR}")
target_compile_definitions(j288_unity PUBLIC UNITY_INCLUDE_DOUBLE UNITY_SUPPORT_64)
set_target_properties(j288_unity PROPERTIES C_STANDARD 99 C_EXTENSIONS OFF)

# Include folders every Make test compile sees (TEST_CPPFLAGS).
set(J288_TEST_INCLUDES "${J288_SRC}/test/support" "${J288_SRC}/test/vectors")

# test/support/*.c as objects (as in the Makefile), so that a library built with a hook into
# them (the CRC hardware stand-in) still links. <lib>: the library variant whose flags they
# share.
function(j288_add_test_support target lib)
    file(GLOB srcs CONFIGURE_DEPENDS "${J288_SRC}/test/support/*.c")
    list(SORT srcs)
    add_library(${target} OBJECT ${srcs})
    target_include_directories(${target} PUBLIC ${J288_TEST_INCLUDES})
    target_link_libraries(${target} PUBLIC ${lib} j288_unity)
    set_target_properties(${target} PROPERTIES C_STANDARD 99 C_EXTENSIONS OFF)
    if(CMAKE_C_COMPILER_ID MATCHES "GNU|Clang")
        target_compile_options(${target} PRIVATE ${J288_WARNINGS})
    endif()
endfunction()
j288_add_test_support(j288_test_support j288::j288)

# ---- unit tests (Makefile): every test/unit/test_*.c with lib, Unity and test/support ------
file(GLOB J288_UNIT_TESTS CONFIGURE_DEPENDS "${J288_SRC}/test/unit/test_*.c")
list(SORT J288_UNIT_TESTS)
foreach(src ${J288_UNIT_TESTS})
    get_filename_component(name "${src}" NAME_WE)
    j288_add_test(${name} test/${name} SOURCES "${src}"
        LIBS j288_test_support j288::j288 j288_unity)
endforeach()

# ---- the CLI's helpers (mk/cli.mk): linked with the helper sources, not main() --------------
if(TARGET j288_cli)
    set(_cli "${J288_SRC}/examples/cli")
    j288_add_test(test_cli_helpers test/test_cli_helpers
        SOURCES "${J288_SRC}/test/cli/test_cli_helpers.c" "${_cli}/args.c" "${_cli}/hexparse.c"
                "${_cli}/json.c" "${_cli}/frameview.c" "${_cli}/report.c"
        INCLUDES ${J288_TEST_INCLUDES} "${_cli}" "${J288_SRC}/port/linux"
        DEFINES _XOPEN_SOURCE=700
        LIBS j288_unity j288::j288)
endif()

# ---- the codec tests with each compile-time CRC backend (mk/codec.mk) ----------------------
# A library variant per backend; its flags reach the tests and test/support too, as Make's
# EXTRA_CFLAGS do in the crc-<variant> sub-build.
set(J288_CRC_VARIANTS slice4 nibble bitwise hw)
set(J288_CRC_DEFS_slice4 J288_CONFIG_CRC_BACKEND=J288_CRC_BACKEND_SLICE4)
set(J288_CRC_DEFS_nibble J288_CONFIG_CRC_BACKEND=J288_CRC_BACKEND_NIBBLE)
set(J288_CRC_DEFS_bitwise J288_CONFIG_CRC_BACKEND=J288_CRC_BACKEND_BITWISE)
set(J288_CRC_DEFS_hw J288_CONFIG_CRC_BACKEND=J288_CRC_BACKEND_HW
                     J288_CONFIG_CRC_HW_FUNCTION=codec_hw_crc_stub)
set(J288_CRC_TEST_NAMES test_crc32 test_frame test_parser)
get_target_property(J288_LIB_SOURCES j288 SOURCES)
get_target_property(J288_LIB_DEFS j288 INTERFACE_COMPILE_DEFINITIONS)
foreach(v ${J288_CRC_VARIANTS})
    set(lib j288_crc-${v})
    add_library(${lib} STATIC ${J288_LIB_SOURCES})
    target_include_directories(${lib} PUBLIC "${J288_SRC}/lib/include")
    target_compile_definitions(${lib} PUBLIC ${J288_LIB_DEFS} ${J288_CRC_DEFS_${v}})
    set_target_properties(${lib} PROPERTIES C_STANDARD 99 C_STANDARD_REQUIRED ON C_EXTENSIONS OFF)
    if(CMAKE_C_COMPILER_ID MATCHES "GNU|Clang")
        target_compile_options(${lib} PRIVATE ${J288_WARNINGS})
    endif()
    j288_add_test_support(j288_test_support_crc-${v} ${lib})
    foreach(name ${J288_CRC_TEST_NAMES})
        j288_add_test(crc-${v}_${name} crc-${v}/test/${name}
            SOURCES "${J288_SRC}/test/unit/${name}.c"
            LIBS j288_test_support_crc-${v} ${lib} j288_unity)
    endforeach()
endforeach()

# ---- fuzz-corpus replays (mk/hardening.mk): every test/fuzz/fuzz_<name>.c built as a plain
# program that runs its committed corpus test/fuzz/corpus/<name> ----------------------------
file(GLOB J288_FUZZ_TARGETS CONFIGURE_DEPENDS "${J288_SRC}/test/fuzz/fuzz_*.c")
list(SORT J288_FUZZ_TARGETS)
foreach(src ${J288_FUZZ_TARGETS})
    get_filename_component(fname "${src}" NAME_WE)
    string(REGEX REPLACE "^fuzz_" "" name "${fname}")
    set(extra_src "")
    set(extra_inc "")
    set(extra_def "")
    if(name STREQUAL "cli") # the tool's parsers as functions (FUZZ_EXTRA_cli)
        set(extra_src "${J288_SRC}/examples/cli/hexparse.c" "${J288_SRC}/examples/cli/args.c")
        set(extra_inc "${J288_SRC}/examples/cli" "${J288_SRC}/port/linux")
        set(extra_def _XOPEN_SOURCE=700)
    endif()
    j288_add_test(fuzz_replay_${name} test/fuzz_replay_${name}
        SOURCES "${src}" "${J288_SRC}/test/fuzz/replay_main.c" ${extra_src}
        INCLUDES "${J288_SRC}/test/fuzz" "${J288_SRC}/test/support" ${extra_inc}
        DEFINES "FUZZ_CORPUS_DIR=\"test/fuzz/corpus/${name}\"" ${extra_def}
        LIBS j288::j288)
endforeach()

# ---- the Linux port over a real pty served by j288-sim (mk/linux.mk) -----------------------
if(TARGET j288_sim AND EXISTS "${J288_SRC}/test/linux/test_linux_port.c")
    j288_add_test(test_linux_port test/test_linux_port
        SOURCES "${J288_SRC}/test/linux/test_linux_port.c"
        INCLUDES ${J288_TEST_INCLUDES}
        DEFINES "J288_SIM_DEFAULT=\"${PROJECT_BINARY_DIR}/bin/j288-sim\""
        LIBS j288_unity j288_linux j288::j288)
endif()

# ---- the robot config reader (mk/linux.mk): libyaml as scripts/libyaml.sh finds it ----------
if(TARGET j288_linux AND EXISTS "${J288_SRC}/test/linux/test_robot_config.c")
    set(_yaml_dir "${PROJECT_BINARY_DIR}/libyaml")
    if(NOT EXISTS "${_yaml_dir}/libyaml.env")
        execute_process(COMMAND bash "${J288_SRC}/scripts/libyaml.sh" "${_yaml_dir}"
                                "${CMAKE_C_COMPILER}"
                        WORKING_DIRECTORY "${J288_SRC}")
    endif()
    set(YAML_CFLAGS "")
    set(YAML_LIBS "")
    file(STRINGS "${_yaml_dir}/libyaml.env" _yaml_lines)
    foreach(_line ${_yaml_lines})
        if(_line MATCHES "^(YAML_[A-Z]+)=(.*)$")
            separate_arguments(${CMAKE_MATCH_1} UNIX_COMMAND "${CMAKE_MATCH_2}")
        endif()
    endforeach()
    j288_add_test(test_robot_config test/test_robot_config
        SOURCES "${J288_SRC}/test/linux/test_robot_config.c" "${J288_SRC}/port/linux/j288_robot_config.c"
        INCLUDES ${J288_TEST_INCLUDES} "${J288_SRC}/port/linux"
        LIBS j288_unity ${YAML_LIBS})
    target_compile_options(test_robot_config PRIVATE ${YAML_CFLAGS})
endif()

# ---- the simulator's servo model (mk/sim.mk) ------------------------------------------------
if(TARGET j288_sim AND EXISTS "${J288_SRC}/test/sim/test_sim_model.c")
    j288_add_test(test_sim_model test/test_sim_model
        SOURCES "${J288_SRC}/test/sim/test_sim_model.c" "${J288_SRC}/tools/sim/servo_model.c"
        INCLUDES ${J288_TEST_INCLUDES} "${J288_SRC}/tools/sim"
        LIBS j288_unity j288::j288)
endif()

# ---- the STM32 HAL port against the fake HAL, with the real engine (mk/stm32.mk) -----------
# D-cache maintenance on and a 32-byte receive buffer, so that both paths are exercised.
j288_add_test(test_stm32_port test/test_stm32_port
    SOURCES "${J288_SRC}/port/stm32_hal/j288_stm32.c" "${J288_SRC}/test/stm32/fake_hal.c"
            "${J288_SRC}/test/stm32/test_stm32_port.c"
    INCLUDES ${J288_TEST_INCLUDES} "${J288_SRC}/port/stm32_hal" "${J288_SRC}/port/stm32_hal/stub"
             "${J288_SRC}/test/stm32"
    DEFINES J288_STM32_DCACHE=1 J288_STM32_RX_BUF_SIZE=32u
    LIBS j288_unity j288::j288)

# ---- shell tests (TEST_SCRIPTS): the tool and simulator end to end, the vectors' drift -----
if(TARGET j288_cli AND TARGET j288_sim)
    foreach(script test/e2e/cli_offline.sh test/e2e/cli_bus.sh test/e2e/sim_cli.sh)
        j288_register_test(${script} bash ${script})
    endforeach()
endif()
# The committed golden vectors must equal a fresh regeneration.
j288_register_test(tools/vectors/check-drift.sh bash tools/vectors/check-drift.sh)
