# Install the library, its headers and a relocatable package config, so that
#   find_package(j288 REQUIRED)  +  target_link_libraries(app PRIVATE j288::j288)
# works from any prefix (CMAKE_PREFIX_PATH).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(J288_CMAKE_DIR "${CMAKE_INSTALL_LIBDIR}/cmake/j288")

install(TARGETS j288 EXPORT j288Targets
    ARCHIVE DESTINATION "${CMAKE_INSTALL_LIBDIR}"
    LIBRARY DESTINATION "${CMAKE_INSTALL_LIBDIR}"
    RUNTIME DESTINATION "${CMAKE_INSTALL_BINDIR}"
    INCLUDES DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}")
install(DIRECTORY "${PROJECT_SOURCE_DIR}/lib/include/j288"
    DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}"
    FILES_MATCHING PATTERN "*.h")
install(EXPORT j288Targets NAMESPACE j288:: DESTINATION "${J288_CMAKE_DIR}")

configure_package_config_file("${PROJECT_SOURCE_DIR}/cmake/j288Config.cmake.in"
    "${PROJECT_BINARY_DIR}/j288Config.cmake"
    INSTALL_DESTINATION "${J288_CMAKE_DIR}")
write_basic_package_version_file("${PROJECT_BINARY_DIR}/j288ConfigVersion.cmake"
    VERSION ${PROJECT_VERSION}
    COMPATIBILITY SameMinorVersion)
install(FILES "${PROJECT_BINARY_DIR}/j288Config.cmake" "${PROJECT_BINARY_DIR}/j288ConfigVersion.cmake"
    DESTINATION "${J288_CMAKE_DIR}")
