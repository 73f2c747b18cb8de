# Toolchain file for bare-metal Arm Cortex-M with the GNU Arm toolchain (arm-none-eabi-gcc):
#   cmake -S . -B build/arm -DCMAKE_TOOLCHAIN_FILE=cmake/arm-none-eabi.cmake [-DJ288_CPU=cortex-m0]
# J288_CPU names a CPU fragment of the Make build, mk/cpu/<cpu>.mk (default cortex-m4f): its
# core flags, and J288_CONFIG_SI_FLOAT when the fragment sets it; or give the flags yourself
# with -DJ288_ARM_FLAGS="...". Builds the library only (no host tools when cross compiling).
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)

set(J288_ARM_PREFIX "arm-none-eabi-" CACHE STRING "Cross tool prefix")
set(CMAKE_C_COMPILER "${J288_ARM_PREFIX}gcc")
set(CMAKE_ASM_COMPILER "${J288_ARM_PREFIX}gcc")
set(CMAKE_AR "${J288_ARM_PREFIX}ar" CACHE FILEPATH "")
set(CMAKE_RANLIB "${J288_ARM_PREFIX}ranlib" CACHE FILEPATH "")
set(CMAKE_SIZE "${J288_ARM_PREFIX}size" CACHE FILEPATH "")

set(J288_CPU "cortex-m4f" CACHE STRING "A CPU of mk/cpu/*.mk")
if(NOT J288_ARM_FLAGS)
    set(_cpu_file "${CMAKE_CURRENT_LIST_DIR}/../mk/cpu/${J288_CPU}.mk")
    if(NOT EXISTS "${_cpu_file}")
        message(FATAL_ERROR "J288_CPU=${J288_CPU}: no mk/cpu/${J288_CPU}.mk")
    endif()
    file(STRINGS "${_cpu_file}" _flags REGEX "^CPU_[A-Za-z0-9]+_FLAGS :=")
    file(STRINGS "${_cpu_file}" _defs REGEX "^CPU_[A-Za-z0-9]+_DEFS :=")
    string(REGEX REPLACE "^CPU_[A-Za-z0-9]+_FLAGS := *" "" _flags "${_flags}")
    set(J288_ARM_FLAGS "${_flags}" CACHE STRING "Core and FPU flags for every compile and link")
    if(_defs MATCHES "J288_CONFIG_SI_FLOAT=1")
        set(J288_CONFIG_SI_FLOAT ON CACHE BOOL "SI API in float instead of double")
    endif()
endif()
# try_compile's projects see the same CPU.
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES J288_CPU J288_ARM_FLAGS)
set(CMAKE_C_FLAGS_INIT "${J288_ARM_FLAGS} -ffunction-sections -fdata-sections")
set(CMAKE_EXE_LINKER_FLAGS_INIT "${J288_ARM_FLAGS} --specs=nano.specs -Wl,--gc-sections")

# No OS to run test programs on: let try_compile build a static library instead of linking.
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
