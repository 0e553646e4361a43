#!/usr/bin/env bash
# Boots the firmware in QEMU's netduinoplus2 (an STM32F405: the F446's
# Cortex-M4, flash and SRAM map, and the STM32F2xx timers; no RCC, bxCAN,
# GPIO or IWDG model, whose registers read 0 there).
#
#   1. the self-test image: a scripted session through the real core, its
#      checks and instruction counts over semihosting; must exit 0;
#   2. the board image itself, for 2 s of host time: it must reach its main
#      loop and stay there (read back over QEMU's monitor), not sit in the
#      fault handler.
#
# Usage: firmware_interface/stm32f446/tools/qemu-boot-test.sh BUILD_DIR
# Both runs use -icount shift=0: virtual time is the instruction count, so
# every figure the self-test prints is the same on every machine.
set -euo pipefail
dir="${1:?usage: qemu-boot-test.sh BUILD_DIR}"
qemu="${QEMU:-qemu-system-arm}"
machine=(-M netduinoplus2 -display none -serial null -icount shift=0)

if ! command -v "$qemu" >/dev/null 2>&1; then
  echo "qemu-boot-test: $qemu not found: install qemu-system-arm (scripts/install-deps.sh)" >&2
  exit 1
fi

echo "== self-test image"
set +e
output=$(timeout 60 "$qemu" "${machine[@]}" -monitor none -chardev stdio,id=semihosting \
           -semihosting-config enable=on,target=native,chardev=semihosting \
           -kernel "$dir/pinball_driver_board_selftest.elf" </dev/null)
rc=$?
set -e
echo "$output"
if [ $rc -ne 0 ] || ! grep -q '^PASS ' <<<"$output"; then
  echo "qemu-boot-test: the self-test failed (exit $rc: the number of failed checks, 124 a timeout)" >&2
  exit 1
fi

echo "== board image: boots to its main loop"
board="$dir/pinball_driver_board.elf"
symbol() { arm-none-eabi-nm -S "$board" | awk -v s="$1" '$4 == s { print $1, $2 }'; }
read -r state _ <<<"$(symbol g_board_state)"
read -r fault fault_size <<<"$(symbol Default_Handler)"
# g_board_state's layout: main.c static_asserts these offsets.
monitor=$( (sleep 2; echo "xp /3wx 0x$(printf '%x' $((0x$state + 24)))"; echo "info registers"; echo quit) |
           timeout 30 "$qemu" "${machine[@]}" -monitor stdio -kernel "$board" 2>&1 | tr -d '\r')
words=$(grep -a -o "^0*$(printf '%x' $((0x$state + 24))): .*" <<<"$monitor" | head -1 | cut -d' ' -f2-4)
pc=$(grep -a -o 'R15=[0-9a-f]*' <<<"$monitor" | head -1 | cut -d= -f2)
read -r clamps loops max_loop_ns <<<"$words"
if [ -z "${loops:-}" ] || [ -z "$pc" ]; then
  echo "qemu-boot-test: could not read the board image's state over the monitor" >&2
  echo "$monitor" | tail -5 >&2
  exit 1
fi
echo "main loop iterations $((loops)), longest $((max_loop_ns)) ns of TIM2 time, output clamps $((clamps)), pc 0x$pc"
if [ $((loops)) -eq 0 ]; then
  echo "qemu-boot-test: the board image never completed a main loop iteration" >&2
  exit 1
fi
if [ $((0x$pc)) -ge $((0x$fault)) ] && [ $((0x$pc)) -lt $((0x$fault + 0x$fault_size)) ]; then
  echo "qemu-boot-test: the board image is in Default_Handler (a fault)" >&2
  exit 1
fi
if [ $((clamps)) -ne 0 ]; then
  echo "qemu-boot-test: the output stage clamped a duty" >&2
  exit 1
fi
echo "qemu-boot-test: passed"
