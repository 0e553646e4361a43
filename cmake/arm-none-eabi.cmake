# Cross toolchain for the driver board's firmware (firmware_interface/stm32f446/): the
# GNU Arm Embedded toolchain as Debian packages it (gcc-arm-none-eabi,
# libnewlib-arm-none-eabi). Bare metal: no OS, no C runtime start-up files
# (startup.c is ours), newlib-nano only for memcpy/memset.
#
#   cmake -S firmware_interface/stm32f446 -B build/firmware-stm32f446 \
#         -DCMAKE_TOOLCHAIN_FILE=cmake/arm-none-eabi.cmake
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)

find_program(PINBALL_ARM_GCC arm-none-eabi-gcc)
if(NOT PINBALL_ARM_GCC)
  message(FATAL_ERROR "arm-none-eabi-gcc not found: install gcc-arm-none-eabi and libnewlib-arm-none-eabi "
                      "(scripts/install-deps.sh)")
endif()
get_filename_component(_pinball_arm_bin "${PINBALL_ARM_GCC}" DIRECTORY)

set(CMAKE_C_COMPILER "${PINBALL_ARM_GCC}")
set(CMAKE_ASM_COMPILER "${PINBALL_ARM_GCC}")
set(CMAKE_OBJCOPY "${_pinball_arm_bin}/arm-none-eabi-objcopy" CACHE FILEPATH "objcopy for the target")
set(CMAKE_OBJDUMP "${_pinball_arm_bin}/arm-none-eabi-objdump" CACHE FILEPATH "objdump for the target")
set(CMAKE_SIZE "${_pinball_arm_bin}/arm-none-eabi-size" CACHE FILEPATH "size for the target")

# The compiler checks build a static library: linking a test program would
# need our linker script and start-up code.
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

# Look for libraries and headers in the target's sysroot only, programs on the host.
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
