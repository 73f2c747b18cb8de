# Install the static library, its headers, the package config (cmake/*.cmake.in, the same
# files `make install` writes with scripts/cmake-config.sh) and, when built, j288 and j288-sim:
#   find_package(j288 REQUIRED)  +  target_link_libraries(app PRIVATE j288::j288)
# works from any prefix (CMAKE_PREFIX_PATH). On Linux also the shared library libj288.so (lib,
# Linux port, config reader, runner), the port's headers and the pkg-config file j288.pc (the
# same file `make install` writes from cmake/j288.pc.in).
include(GNUInstallDirs)

install(TARGETS j288 ARCHIVE DESTINATION "${CMAKE_INSTALL_LIBDIR}")
install(DIRECTORY "${PROJECT_SOURCE_DIR}/lib/include/j288" DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}"
        FILES_MATCHING PATTERN "*.h")
if(TARGET j288_cli AND TARGET j288_sim)
    install(TARGETS j288_cli j288_sim RUNTIME DESTINATION "${CMAKE_INSTALL_BINDIR}")
endif()
if(TARGET j288_shared)
    install(TARGETS j288_shared LIBRARY DESTINATION "${CMAKE_INSTALL_LIBDIR}")
    install(FILES "${PROJECT_SOURCE_DIR}/port/linux/j288_linux.h"
                  "${PROJECT_SOURCE_DIR}/host/j288_host_port.h"
                  "${PROJECT_SOURCE_DIR}/host/j288_robot.h"
                  "${PROJECT_SOURCE_DIR}/host/j288_robot_config.h"
            DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}/j288")
    # Relative to ${pcfiledir}: the file holds wherever the prefix is installed (--prefix,
    # DESTDIR) or moved.
    file(RELATIVE_PATH _j288_pc_up "/p/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/p")
    set(PREFIX "\${pcfiledir}/${_j288_pc_up}")
    set(LIBDIR "\${prefix}/${CMAKE_INSTALL_LIBDIR}")
    set(INCLUDEDIR "\${prefix}/${CMAKE_INSTALL_INCLUDEDIR}")
    set(J288_VERSION "${PROJECT_VERSION}")
    configure_file("${PROJECT_SOURCE_DIR}/cmake/j288.pc.in" "${PROJECT_BINARY_DIR}/j288.pc" @ONLY)
    install(FILES "${PROJECT_BINARY_DIR}/j288.pc" DESTINATION "${CMAKE_INSTALL_LIBDIR}/pkgconfig")
endif()

set(_j288_cmake_dir "${CMAKE_INSTALL_LIBDIR}/cmake/j288")
file(RELATIVE_PATH J288_CONFIG_TO_PREFIX "/p/${_j288_cmake_dir}" "/p")
set(J288_LIBDIR "${CMAKE_INSTALL_LIBDIR}")
set(J288_INCLUDEDIR "${CMAKE_INSTALL_INCLUDEDIR}")
get_target_property(J288_DEFINES j288 INTERFACE_COMPILE_DEFINITIONS)
set(J288_VERSION "${PROJECT_VERSION}")
set(J288_VERSION_MAJOR "${PROJECT_VERSION_MAJOR}")
set(J288_VERSION_MINOR "${PROJECT_VERSION_MINOR}")
foreach(f j288Config j288ConfigVersion)
    configure_file("${PROJECT_SOURCE_DIR}/cmake/${f}.cmake.in" "${PROJECT_BINARY_DIR}/${f}.cmake" @ONLY)
    install(FILES "${PROJECT_BINARY_DIR}/${f}.cmake" DESTINATION "${_j288_cmake_dir}")
endforeach()
