# Host programs of the top-level build, with the same sources and flags as the Makefile
# fragments (mk/linux.mk, mk/cli.mk, mk/sim.mk), placed where the Make build puts them so that
# the end-to-end scripts find them with BIN=<build>/bin:
#   j288_linux  libj288_linux.a, the Linux termios2 port (port/linux)
#   j288_cli    <build>/bin/j288, the command-line tool (examples/cli)
#   j288_sim    <build>/bin/j288-sim, the servo simulator (tools/sim)
# POSIX programs (ptys, termios2): built on Linux only.

# j288_add_program(<target> OUTPUT <path under the build dir> SOURCES <src>...
#                  [LIBS <lib>...] [INCLUDES <dir>...] [DEFINES <def>...])
# A C99 executable with the project's warning set, linked with libm like every Make rule.
function(j288_add_program target)
    cmake_parse_arguments(A "" "OUTPUT" "SOURCES;LIBS;INCLUDES;DEFINES" ${ARGN})
    get_filename_component(dir "${A_OUTPUT}" DIRECTORY)
    get_filename_component(file "${A_OUTPUT}" NAME)
    add_executable(${target} ${A_SOURCES})
    # $<0:> keeps multi-config generators from adding a per-configuration subfolder.
    set_target_properties(${target} PROPERTIES
        C_STANDARD 99 C_STANDARD_REQUIRED ON C_EXTENSIONS OFF
        OUTPUT_NAME "${file}"
        RUNTIME_OUTPUT_DIRECTORY "${PROJECT_BINARY_DIR}/${dir}$<0:>")
    target_include_directories(${target} PRIVATE ${A_INCLUDES})
    target_compile_definitions(${target} PRIVATE ${A_DEFINES})
    if(CMAKE_C_COMPILER_ID MATCHES "GNU|Clang")
        target_compile_options(${target} PRIVATE ${J288_WARNINGS})
    endif()
    target_link_libraries(${target} PRIVATE ${A_LIBS})
    if(J288_LIBM)
        target_link_libraries(${target} PRIVATE ${J288_LIBM})
    endif()
endfunction()

find_library(J288_LIBM m)

if(NOT CMAKE_SYSTEM_NAME STREQUAL "Linux")
    message(STATUS "j288: the Linux port, j288 tool and j288-sim are built on Linux only")
    return()
endif()

set(J288_SRC "${PROJECT_SOURCE_DIR}")

add_library(j288_linux STATIC "${J288_SRC}/port/linux/j288_linux.c")
target_include_directories(j288_linux PUBLIC "${J288_SRC}/port/linux")
target_link_libraries(j288_linux PUBLIC j288::j288)
set_target_properties(j288_linux PROPERTIES C_STANDARD 99 C_STANDARD_REQUIRED ON C_EXTENSIONS OFF)
if(CMAKE_C_COMPILER_ID MATCHES "GNU|Clang")
    target_compile_options(j288_linux PRIVATE ${J288_WARNINGS})
endif()

# The tool is a POSIX program (signals, realpath, popen); lib/ stays pure C99.
file(GLOB J288_CLI_SOURCES CONFIGURE_DEPENDS "${J288_SRC}/examples/cli/*.c")
list(SORT J288_CLI_SOURCES)
j288_add_program(j288_cli OUTPUT bin/j288
    SOURCES ${J288_CLI_SOURCES}
    LIBS j288_linux j288::j288
    DEFINES _XOPEN_SOURCE=700)

j288_add_program(j288_sim OUTPUT bin/j288-sim
    SOURCES "${J288_SRC}/tools/sim/servo_model.c" "${J288_SRC}/tools/sim/sim_main.c"
    INCLUDES "${J288_SRC}/tools/sim"
    LIBS j288::j288)
