# Toolchain file for Windows x86-64 with mingw-w64 (Debian: gcc-mingw-w64-x86-64-win32):
#   cmake -S . -B build/win -DCMAKE_TOOLCHAIN_FILE=cmake/mingw-w64.cmake
# Builds the library (j288::j288) and the Windows port (j288::windows, port/windows: Win32
# serial); the Linux tools are not built when cross compiling. The programs run on Windows, or
# here under Wine (make test-windows). J288_MINGW_PREFIX picks another triplet
# (i686-w64-mingw32- for 32-bit Windows).
set(CMAKE_SYSTEM_NAME Windows)
set(CMAKE_SYSTEM_PROCESSOR x86_64)

set(J288_MINGW_PREFIX "x86_64-w64-mingw32-" CACHE STRING "Cross tool prefix")
set(CMAKE_C_COMPILER "${J288_MINGW_PREFIX}gcc")
set(CMAKE_RC_COMPILER "${J288_MINGW_PREFIX}windres")
set(CMAKE_AR "${J288_MINGW_PREFIX}ar" CACHE FILEPATH "")
set(CMAKE_RANLIB "${J288_MINGW_PREFIX}ranlib" CACHE FILEPATH "")

# Headers and libraries of the target only from the cross root; programs from the host.
string(REGEX REPLACE "-$" "" _j288_triplet "${J288_MINGW_PREFIX}")
set(CMAKE_FIND_ROOT_PATH "/usr/${_j288_triplet}")
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
