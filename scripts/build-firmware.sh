#!/usr/bin/env bash
# Builds the driver board's firmware (firmware_interface/stm32f446/, its own CMake
# project) with the Arm cross compiler and prints its size: the board image
# and the QEMU self-test image, from the same start-up code and core.
#
# Usage: scripts/build-firmware.sh [--json] [--max-flash BYTES] [--max-ram BYTES] [BUILD_DIR]
#   BUILD_DIR     default build/firmware-stm32f446
#   --json        print only one JSON object (flash and RAM bytes) on stdout;
#                 the build's own output goes to stderr
#   --max-flash / --max-ram
#                 fail (exit 1) when the board image needs more
# Environment: FIRMWARE_JOBS (default 1), FIRMWARE_OPT (-O2 or -Os; default
# the project's, -O2), FIRMWARE_BENCH_STEPPING=1 (a halt freezes the IWDG, for
# single-stepping with coil power off; FIRMWARE.md), CMAKE (default cmake).
#
# Flash = every section placed in flash plus .data's initial values; RAM =
# .data + .bss + .noinit + the stack the linker script reserves (4 KiB).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"

json=0
max_flash=""
max_ram=""
dir=""
while [ $# -gt 0 ]; do
  case "$1" in
    --json) json=1 ;;
    --max-flash) max_flash="$2"; shift ;;
    --max-ram) max_ram="$2"; shift ;;
    -h|--help) sed -n '2,16p' "$0"; exit 0 ;;
    -*) echo "build-firmware: unknown option $1" >&2; exit 2 ;;
    *) dir="$1" ;;
  esac
  shift
done
dir="${dir:-$root/build/firmware-stm32f446}"

cmake="${CMAKE:-cmake}"
for tool in arm-none-eabi-gcc arm-none-eabi-size "$cmake"; do
  if ! command -v "$tool" >/dev/null 2>&1; then
    echo "build-firmware: $tool not found: install gcc-arm-none-eabi, libnewlib-arm-none-eabi and cmake" \
         "(scripts/install-deps.sh)" >&2
    exit 1
  fi
done

src="$root/firmware_interface/stm32f446"
# A build folder configured from another source folder (the firmware moved,
# or another checkout) cannot be reused: start it again.
if [ -f "$dir/CMakeCache.txt" ] && ! grep -qx "CMAKE_HOME_DIRECTORY:INTERNAL=$src" "$dir/CMakeCache.txt"; then
  rm -rf "$dir/CMakeCache.txt" "$dir/CMakeFiles"
fi
generator=()
if [ ! -f "$dir/CMakeCache.txt" ] && command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
options=(-DCMAKE_TOOLCHAIN_FILE="$root/cmake/arm-none-eabi.cmake")
if [ -n "${FIRMWARE_OPT:-}" ]; then options+=(-DPINBALL_FW_OPT="$FIRMWARE_OPT"); fi
# Said every time: the cache would keep a bench build's setting for the next, lab build.
if [ "${FIRMWARE_BENCH_STEPPING:-0}" = 1 ]; then
  options+=(-DPINBALL_FW_IWDG_MAY_STOP_UNDER_HALT=ON)
else
  options+=(-DPINBALL_FW_IWDG_MAY_STOP_UNDER_HALT=OFF)
fi

# In --json mode stdout carries the JSON object alone.
if [ "$json" = 1 ]; then exec 3>&1 1>&2; else exec 3>&1; fi

"$cmake" -S "$src" -B "$dir" "${generator[@]}" "${options[@]}" >/dev/null
"$cmake" --build "$dir" --parallel "${FIRMWARE_JOBS:-1}" >/dev/null

# flash_bytes, ram_bytes of an image, from its section table (size -A):
# sections by address, .data counted in both (its initial values live in flash).
measure() {
  arm-none-eabi-size -A "$1" | awk '
    $3 ~ /^[0-9]+$/ {
      addr = $3 + 0; size = $2 + 0
      if (addr >= 134217728 && addr < 134742016) flash += size       # 0x08000000 + 512 KiB
      if (addr >= 536870912 && addr < 537001984) ram += size         # 0x20000000 + 128 KiB
      if ($1 == ".data") flash += size
    }
    END { printf "%d %d\n", flash, ram }'
}

board="$dir/pinball_driver_board.elf"
selftest="$dir/pinball_driver_board_selftest.elf"
read -r flash ram < <(measure "$board")
read -r st_flash st_ram < <(measure "$selftest")
stack=$(arm-none-eabi-size -A "$board" | awk '$1 == ".stack" { print $2 }')
flash_total=524288
ram_total=131072

if [ "$json" = 1 ]; then
  printf '{"image": "pinball_driver_board.elf", "flash_bytes": %d, "ram_bytes": %d, "stack_bytes": %d, ' \
    "$flash" "$ram" "$stack" >&3
  printf '"flash_total_bytes": %d, "ram_total_bytes": %d, "selftest_flash_bytes": %d, "selftest_ram_bytes": %d}\n' \
    "$flash_total" "$ram_total" "$st_flash" "$st_ram" >&3
else
  {
    echo "== $board"
    arm-none-eabi-size -A -x "$board" | grep -v '^\.debug\|^\.comment\|^\.ARM\.attributes\|^Total'
    arm-none-eabi-size -B "$board" "$selftest"
    awk -v f="$flash" -v ft="$flash_total" -v r="$ram" -v rt="$ram_total" -v s="$stack" 'BEGIN {
      printf "board image:     flash %6d of %d bytes (%.1f %%), RAM %6d of %d bytes (%.1f %%, %d of it the stack)\n",
             f, ft, 100 * f / ft, r, rt, 100 * r / rt, s }'
    printf 'self-test image: flash %6d bytes, RAM %6d bytes\n' "$st_flash" "$st_ram"
  } >&3
fi

status=0
if [ -n "$max_flash" ] && [ "$flash" -gt "$max_flash" ]; then
  echo "build-firmware: the board image needs $flash bytes of flash, over the limit of $max_flash" >&2
  status=1
fi
if [ -n "$max_ram" ] && [ "$ram" -gt "$max_ram" ]; then
  echo "build-firmware: the board image needs $ram bytes of RAM, over the limit of $max_ram" >&2
  status=1
fi
exit $status
