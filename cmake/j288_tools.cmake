# The Linux port (j288_linux, static) and the tools j288 (tools/j288) and j288-sim
# (tools/j288-sim), with the Makefile's sources and flags. POSIX programs: Linux only.
if(NOT CMAKE_SYSTEM_NAME STREQUAL "Linux")
    message(STATUS "j288: the Linux port, j288 and j288-sim are built on Linux only")
    return()
endif()
find_library(J288_LIBM m)

add_library(j288_linux STATIC "${PROJECT_SOURCE_DIR}/port/linux/j288_linux.c")
target_include_directories(j288_linux PUBLIC "${PROJECT_SOURCE_DIR}/port/linux")
target_link_libraries(j288_linux PUBLIC j288::j288)

file(GLOB _j288_cli_sources CONFIGURE_DEPENDS "${PROJECT_SOURCE_DIR}/tools/j288/*.c")
add_executable(j288_cli ${_j288_cli_sources})
# The tools are POSIX programs (signals, realpath, popen); lib/ stays pure C99.
target_compile_definitions(j288_cli PRIVATE _XOPEN_SOURCE=700)
target_link_libraries(j288_cli PRIVATE j288_linux)
# The robot config reader (--config): with libyaml when found (Debian's libyaml-dev), else
# built as stubs that say robot config files need it.
target_sources(j288_cli PRIVATE "${PROJECT_SOURCE_DIR}/port/linux/j288_robot_config.c")
find_path(J288_YAML_INCLUDE yaml.h)
find_library(J288_YAML_LIB yaml)
if(J288_YAML_INCLUDE AND J288_YAML_LIB)
    target_compile_definitions(j288_cli PRIVATE J288_HAVE_LIBYAML)
    target_include_directories(j288_cli PRIVATE "${J288_YAML_INCLUDE}")
    target_link_libraries(j288_cli PRIVATE "${J288_YAML_LIB}")
else()
    message(STATUS "j288: libyaml not found: j288 --config is unavailable (install libyaml-dev)")
endif()

add_executable(j288_sim "${PROJECT_SOURCE_DIR}/tools/j288-sim/servo_model.c"
                        "${PROJECT_SOURCE_DIR}/tools/j288-sim/sim_main.c")
target_link_libraries(j288_sim PRIVATE j288::j288)

set_target_properties(j288_cli PROPERTIES OUTPUT_NAME j288)
set_target_properties(j288_sim PROPERTIES OUTPUT_NAME j288-sim)
foreach(t j288_linux j288_cli j288_sim)
    set_target_properties(${t} PROPERTIES C_STANDARD 99 C_STANDARD_REQUIRED ON C_EXTENSIONS OFF)
    if(CMAKE_C_COMPILER_ID MATCHES "GNU|Clang")
        target_compile_options(${t} PRIVATE ${J288_WARNINGS})
    endif()
    if(J288_LIBM AND NOT t STREQUAL j288_linux)
        target_link_libraries(${t} PRIVATE ${J288_LIBM})
    endif()
endforeach()
