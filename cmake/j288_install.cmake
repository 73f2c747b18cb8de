# The one install (`make install` runs it too): the static library and its headers, the CMake
# package (exported targets j288::j288 and, on Linux, j288::robot), and when built libj288.so,
# the port's headers, j288.pc, j288, j288-sim and j288-dds with their man pages, bash completion
# and the Python package. `make uninstall` removes what install_manifest.txt lists.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)
set(_j288_cmake_dir "${CMAKE_INSTALL_LIBDIR}/cmake/j288")

install(TARGETS j288 EXPORT j288Targets ARCHIVE DESTINATION "${CMAKE_INSTALL_LIBDIR}")
install(DIRECTORY "${PROJECT_SOURCE_DIR}/lib/include/j288" DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}"
        FILES_MATCHING PATTERN "*.h")
if(TARGET j288_cli AND TARGET j288_sim)
    install(TARGETS ${_j288_tools} RUNTIME DESTINATION "${CMAKE_INSTALL_BINDIR}")
    foreach(f ${J288_MAN_PAGES})
        install(FILES "${f}" DESTINATION "${CMAKE_INSTALL_MANDIR}/man1")
    endforeach()
    foreach(name j288 j288-sim) # bash-completion loads the file named after the command
        install(FILES "${PROJECT_SOURCE_DIR}/tools/completion/j288.bash" RENAME ${name}
                DESTINATION "${CMAKE_INSTALL_DATADIR}/bash-completion/completions")
    endforeach()
endif()
if(TARGET j288_shared)
    install(TARGETS j288_shared EXPORT j288Targets LIBRARY DESTINATION "${CMAKE_INSTALL_LIBDIR}")
    install(FILES "${PROJECT_SOURCE_DIR}/port/desktop/j288_serial.h"
                  "${PROJECT_SOURCE_DIR}/port/linux/j288_linux.h"
                  "${PROJECT_SOURCE_DIR}/host/j288_robot.h"
                  "${PROJECT_SOURCE_DIR}/host/j288_rt.h"
                  "${PROJECT_SOURCE_DIR}/host/j288_robot_config.h"
            DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}/j288")
    # prefix relative to ${pcfiledir}: the file holds wherever the files land (DESTDIR) or move.
    file(RELATIVE_PATH J288_PC_UP "/p/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/p")
    configure_file("${PROJECT_SOURCE_DIR}/cmake/j288.pc.in" "${PROJECT_BINARY_DIR}/j288.pc" @ONLY)
    install(FILES "${PROJECT_BINARY_DIR}/j288.pc" DESTINATION "${CMAKE_INSTALL_LIBDIR}/pkgconfig")
    # The Python package (ctypes over libj288.so): _installed.py holds the library's path
    # relative to the package, so that a prefix that is not on ldconfig's path works too.
    set(J288_PYTHONDIR "lib/python3/dist-packages" CACHE STRING
        "Where the Python package goes, relative to the prefix (empty: not installed)")
    if(J288_PYTHONDIR)
        file(GLOB _j288_py "${PROJECT_SOURCE_DIR}/python/j288/*.py")
        install(FILES ${_j288_py} "${PROJECT_SOURCE_DIR}/python/j288/py.typed"
                DESTINATION "${J288_PYTHONDIR}/j288")
        file(RELATIVE_PATH _j288_rel "/p/${J288_PYTHONDIR}/j288"
             "/p/${CMAKE_INSTALL_LIBDIR}/libj288.so.${PROJECT_VERSION_MAJOR}")
        file(WRITE "${PROJECT_BINARY_DIR}/_installed.py"
             "# Written by the install: the shared library, relative to this package.\nLIBRARY = \"${_j288_rel}\"\n")
        install(FILES "${PROJECT_BINARY_DIR}/_installed.py" DESTINATION "${J288_PYTHONDIR}/j288")
    endif()
endif()

install(EXPORT j288Targets NAMESPACE j288:: DESTINATION "${_j288_cmake_dir}")
# Compatible: the same major.minor, not newer (minor versions may change the API in 0.x).
write_basic_package_version_file("${PROJECT_BINARY_DIR}/j288ConfigVersion.cmake"
                                 COMPATIBILITY SameMinorVersion)
install(FILES "${PROJECT_SOURCE_DIR}/cmake/j288Config.cmake" "${PROJECT_BINARY_DIR}/j288ConfigVersion.cmake"
        DESTINATION "${_j288_cmake_dir}")
