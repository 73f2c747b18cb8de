# Toolchain file for bare-metal ARM Cortex-M with the GNU Arm toolchain (arm-none-eabi-gcc).
#   cmake -S . -B build/arm -DCMAKE_TOOLCHAIN_FILE=cmake/arm-none-eabi.cmake \
#         [-DJ288_ARM_FLAGS="-mcpu=cortex-m0 -mthumb -mfloat-abi=soft"]
# Builds the library only (host tests are skipped when cross compiling). The default core is a
# Cortex-M4F with hard float; pair it with -DJ288_CONFIG_SI_FLOAT=ON for float SI units.
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)

set(J288_ARM_PREFIX "arm-none-eabi-" CACHE STRING "Cross tool prefix")
set(CMAKE_C_COMPILER "${J288_ARM_PREFIX}gcc")
set(CMAKE_CXX_COMPILER "${J288_ARM_PREFIX}g++")
set(CMAKE_ASM_COMPILER "${J288_ARM_PREFIX}gcc")
set(CMAKE_AR "${J288_ARM_PREFIX}ar" CACHE FILEPATH "")
set(CMAKE_RANLIB "${J288_ARM_PREFIX}ranlib" CACHE FILEPATH "")
set(CMAKE_SIZE "${J288_ARM_PREFIX}size" CACHE FILEPATH "")

set(J288_ARM_FLAGS "-mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16"
    CACHE STRING "Core and FPU flags for every compile and link")
set(CMAKE_C_FLAGS_INIT "${J288_ARM_FLAGS} -ffunction-sections -fdata-sections")
set(CMAKE_EXE_LINKER_FLAGS_INIT "${J288_ARM_FLAGS} --specs=nano.specs -Wl,--gc-sections")

# No OS to run test programs on: let try_compile build a static library instead of linking.
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
