# The Linux port (j288_linux, static), the robot config reader and multi-bus runner
# (j288_robot, static; libyaml when found, else the reader says it is missing), the shared
# library libj288.so (lib + port + runner: what the Python package loads) and the tools j288
# (tools/j288), j288-sim (tools/j288-sim) and j288-dds (tools/j288-dds), with the Makefile's sources and flags. POSIX
# programs: Linux only.
if(NOT CMAKE_SYSTEM_NAME STREQUAL "Linux")
    message(STATUS "j288: the Linux port, j288 and j288-sim are built on Linux only")
    return()
endif()
find_library(J288_LIBM m)

set(_j288_port_sources "${PROJECT_SOURCE_DIR}/port/desktop/j288_serial.c"
                       "${PROJECT_SOURCE_DIR}/port/linux/j288_linux.c")
add_library(j288_linux STATIC ${_j288_port_sources})
target_include_directories(j288_linux PUBLIC "${PROJECT_SOURCE_DIR}/port/desktop"
                                             "${PROJECT_SOURCE_DIR}/port/linux")
target_link_libraries(j288_linux PUBLIC j288::j288)

find_library(J288_YAML_LIB yaml)
find_path(J288_YAML_INCLUDE yaml.h)
set(_j288_robot_sources "${PROJECT_SOURCE_DIR}/host/j288_robot.c"
                        "${PROJECT_SOURCE_DIR}/host/j288_robot_config.c"
                        "${PROJECT_SOURCE_DIR}/host/j288_number.c")
add_library(j288_robot STATIC ${_j288_robot_sources})
target_include_directories(j288_robot PUBLIC "${PROJECT_SOURCE_DIR}/host")
target_link_libraries(j288_robot PUBLIC j288_linux)
# The installed package's j288::robot is libj288.so; in the tree, the static runner.
add_library(j288::robot ALIAS j288_robot)

file(GLOB _j288_shared_sources CONFIGURE_DEPENDS "${PROJECT_SOURCE_DIR}/lib/src/*.c")
add_library(j288_shared SHARED ${_j288_shared_sources} ${_j288_port_sources} ${_j288_robot_sources})
target_include_directories(j288_shared PUBLIC
    "$<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/lib/include;${PROJECT_SOURCE_DIR}/port/desktop;${PROJECT_SOURCE_DIR}/port/linux;${PROJECT_SOURCE_DIR}/host>"
    "$<INSTALL_INTERFACE:include;include/j288>")
get_target_property(_j288_defs j288 INTERFACE_COMPILE_DEFINITIONS)
target_compile_definitions(j288_shared PUBLIC ${_j288_defs})
set_target_properties(j288_shared PROPERTIES OUTPUT_NAME j288 VERSION ${PROJECT_VERSION}
                      SOVERSION ${PROJECT_VERSION_MAJOR} EXPORT_NAME robot)

foreach(t j288_robot j288_shared)
    if(J288_YAML_LIB AND J288_YAML_INCLUDE)
        target_compile_definitions(${t} PRIVATE J288_HAVE_LIBYAML)
        target_include_directories(${t} PRIVATE "${J288_YAML_INCLUDE}")
        target_link_libraries(${t} PRIVATE ${J288_YAML_LIB})
    endif()
endforeach()
if(NOT (J288_YAML_LIB AND J288_YAML_INCLUDE))
    message(STATUS "j288: libyaml not found (Debian: libyaml-dev): robot config files are refused")
endif()

file(GLOB _j288_cli_sources CONFIGURE_DEPENDS "${PROJECT_SOURCE_DIR}/tools/j288/*.c")
add_executable(j288_cli ${_j288_cli_sources})
# The tools are POSIX programs (signals, realpath, popen); lib/ stays pure C99.
target_compile_definitions(j288_cli PRIVATE _XOPEN_SOURCE=700)
# (libyaml comes with the static j288_robot: its private link dependency, LINK_ONLY)
target_link_libraries(j288_cli PRIVATE j288_robot j288_linux)

add_executable(j288_sim "${PROJECT_SOURCE_DIR}/tools/j288-sim/servo_model.c"
                        "${PROJECT_SOURCE_DIR}/tools/j288-sim/sim_main.c")
target_link_libraries(j288_sim PRIVATE j288::j288)

# The DDS bridge (tools/j288-dds, docs/dds.md), when Cyclone DDS is there (Debian: cyclonedds-dev
# cyclonedds-tools). idlc's code (NO_TYPE_INFO: -t, as in mk/dds.mk) is built apart, without the
# project's warning set: it is idlc's.
find_package(CycloneDDS QUIET)
set(_j288_tools j288_cli j288_sim)
if(CycloneDDS_FOUND)
    file(GLOB _j288_idl CONFIGURE_DEPENDS "${PROJECT_SOURCE_DIR}/tools/j288-dds/idl/*.idl")
    idlc_generate(TARGET j288_dds_idl FILES ${_j288_idl} NO_TYPE_INFO
                  INCLUDES "${PROJECT_SOURCE_DIR}/tools/j288-dds/idl")
    add_library(j288_dds_types STATIC)
    target_link_libraries(j288_dds_types PRIVATE j288_dds_idl PUBLIC CycloneDDS::ddsc)
    target_include_directories(j288_dds_types PUBLIC "${CMAKE_CURRENT_BINARY_DIR}")
    file(GLOB _j288_dds_sources CONFIGURE_DEPENDS "${PROJECT_SOURCE_DIR}/tools/j288-dds/*.c")
    add_executable(j288_dds ${_j288_dds_sources})
    target_compile_definitions(j288_dds PRIVATE _XOPEN_SOURCE=700)
    target_link_libraries(j288_dds PRIVATE j288_dds_types j288_robot j288_linux)
    set_target_properties(j288_dds PROPERTIES OUTPUT_NAME j288-dds)
    # sd_notify (READY, WATCHDOG) when libsystemd is there (Debian: libsystemd-dev; service.h)
    find_package(PkgConfig QUIET)
    if(PKG_CONFIG_FOUND)
        pkg_check_modules(J288_LIBSYSTEMD QUIET IMPORTED_TARGET libsystemd)
    endif()
    if(J288_LIBSYSTEMD_FOUND)
        target_compile_definitions(j288_dds PRIVATE J288_DDS_SYSTEMD=1)
        target_link_libraries(j288_dds PRIVATE PkgConfig::J288_LIBSYSTEMD)
    else()
        message(STATUS "j288: libsystemd not found (Debian: libsystemd-dev): j288-dds without sd_notify")
    endif()
    list(APPEND _j288_tools j288_dds)
else()
    message(STATUS "j288: Cyclone DDS not found (Debian: cyclonedds-dev cyclonedds-tools): no j288-dds")
endif()

set_target_properties(j288_cli PROPERTIES OUTPUT_NAME j288)
set_target_properties(j288_sim PROPERTIES OUTPUT_NAME j288-sim)
foreach(t j288_linux j288_robot j288_shared ${_j288_tools})
    set_target_properties(${t} PROPERTIES C_STANDARD 99 C_STANDARD_REQUIRED ON C_EXTENSIONS OFF)
    if(CMAKE_C_COMPILER_ID MATCHES "GNU|Clang")
        target_compile_options(${t} PRIVATE ${J288_WARNINGS})
    endif()
    if(J288_LIBM AND NOT t STREQUAL j288_linux AND NOT t STREQUAL j288_robot)
        target_link_libraries(${t} PRIVATE ${J288_LIBM})
    endif()
endforeach()

# Man pages from the tools' --help and --version (Debian's help2man), when it is there.
# j288's page also has every command's own --help (scripts/man-include.sh, help2man --include).
find_program(J288_HELP2MAN help2man)
function(j288_man target name what)
    set(_include "")
    set(_deps ${target})
    if(ARGC GREATER 3)
        set(_h2m "${PROJECT_BINARY_DIR}/${name}.h2m")
        add_custom_command(OUTPUT "${name}.h2m" COMMAND bash "${ARGV3}" "$<TARGET_FILE:${target}>"
            "${_h2m}" DEPENDS ${target} "${ARGV3}" VERBATIM)
        set(_include --include "${_h2m}")
        list(APPEND _deps "${name}.h2m")
    endif()
    add_custom_command(OUTPUT "${name}.1" COMMAND "${J288_HELP2MAN}" --no-info --name "${what}"
        ${_include} --output "${PROJECT_BINARY_DIR}/${name}.1" "$<TARGET_FILE:${target}>"
        DEPENDS ${_deps} VERBATIM)
    add_custom_target(${target}_man ALL DEPENDS "${name}.1")
endfunction()
if(J288_HELP2MAN)
    j288_man(j288_cli j288 "Unitree J288/S288 servo bus tool"
             "${PROJECT_SOURCE_DIR}/scripts/man-include.sh")
    j288_man(j288_sim j288-sim "simulated J288 servo bus")
    set(J288_MAN_PAGES "${PROJECT_BINARY_DIR}/j288.1" "${PROJECT_BINARY_DIR}/j288-sim.1")
    if(TARGET j288_dds)
        j288_man(j288_dds j288-dds "J288 robot on DDS for ROS 2 and unitree_sdk2")
        list(APPEND J288_MAN_PAGES "${PROJECT_BINARY_DIR}/j288-dds.1")
    endif()
else()
    message(STATUS "j288: help2man not found (Debian: help2man): no man pages")
endif()
