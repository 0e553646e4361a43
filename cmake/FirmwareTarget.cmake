# The driver board's firmware for its MCU (firmware_interface/stm32f446/, its own
# cross-compiled CMake project) as two ctest tests, label `firmware`:
#
#   firmware_target_build      scripts/build-firmware.sh into
#                              <build>/firmware-stm32f446, and the board
#                              image within its flash and RAM budget
#   firmware_target_qemu_boot  the self-test image's scripted session and
#                              instruction counts, and the board image
#                              reaching its main loop, in QEMU
#
# Added only where the tools are (Debian: gcc-arm-none-eabi,
# libnewlib-arm-none-eabi, qemu-system-arm; scripts/install-deps.sh);
# otherwise configure says which is missing, in one line.
if(NOT PINBALL_BUILD_TESTS)
  return()
endif()

# Budgets: about three times what the image needs today (docs/results.md),
# so that pulling in printf or a heap fails here rather than on the bench.
set(PINBALL_FIRMWARE_MAX_FLASH 32768 CACHE STRING "flash budget of the driver board image, bytes")
set(PINBALL_FIRMWARE_MAX_RAM 16384 CACHE STRING "RAM budget of the driver board image (stack included), bytes")

find_program(PINBALL_ARM_NONE_EABI_GCC arm-none-eabi-gcc)
find_program(PINBALL_QEMU_SYSTEM_ARM qemu-system-arm)
if(NOT PINBALL_ARM_NONE_EABI_GCC)
  message(STATUS "Driver-board firmware: no arm-none-eabi-gcc, so no firmware_target_* tests "
                 "(install gcc-arm-none-eabi libnewlib-arm-none-eabi qemu-system-arm)")
  return()
endif()

set(_pinball_firmware_dir "${CMAKE_BINARY_DIR}/firmware-stm32f446")
add_test(NAME firmware_target_build
         COMMAND "${PROJECT_SOURCE_DIR}/scripts/build-firmware.sh"
                 --max-flash ${PINBALL_FIRMWARE_MAX_FLASH} --max-ram ${PINBALL_FIRMWARE_MAX_RAM}
                 "${_pinball_firmware_dir}")
set_tests_properties(firmware_target_build PROPERTIES
  LABELS firmware TIMEOUT 120 FIXTURES_SETUP pinball_firmware_image
  ENVIRONMENT "CMAKE=${CMAKE_COMMAND}")

if(NOT PINBALL_QEMU_SYSTEM_ARM)
  message(STATUS "Driver-board firmware: no qemu-system-arm, so no firmware_target_qemu_boot test "
                 "(install qemu-system-arm)")
  return()
endif()
add_test(NAME firmware_target_qemu_boot
         COMMAND "${PROJECT_SOURCE_DIR}/firmware_interface/stm32f446/tools/qemu-boot-test.sh" "${_pinball_firmware_dir}")
set_tests_properties(firmware_target_qemu_boot PROPERTIES
  LABELS firmware TIMEOUT 60 FIXTURES_REQUIRED pinball_firmware_image
  ENVIRONMENT "QEMU=${PINBALL_QEMU_SYSTEM_ARM}")
