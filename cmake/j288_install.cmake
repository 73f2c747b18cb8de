# Install the static library, its headers, the package config (cmake/*.cmake.in, the same
# files `make install` writes with scripts/cmake-config.sh) and, when built, j288 and j288-sim:
#   find_package(j288 REQUIRED)  +  target_link_libraries(app PRIVATE j288::j288)
# works from any prefix (CMAKE_PREFIX_PATH). (A shared library and a pkg-config file, once the
# build makes them, install here too.)
include(GNUInstallDirs)

install(TARGETS j288 ARCHIVE DESTINATION "${CMAKE_INSTALL_LIBDIR}")
install(DIRECTORY "${PROJECT_SOURCE_DIR}/lib/include/j288" DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}"
        FILES_MATCHING PATTERN "*.h")
if(TARGET j288_cli AND TARGET j288_sim)
    install(TARGETS j288_cli j288_sim RUNTIME DESTINATION "${CMAKE_INSTALL_BINDIR}")
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
