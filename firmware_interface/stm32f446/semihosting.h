#ifndef PINBALL_FIRMWARE_STM32F446_SEMIHOSTING_H
#define PINBALL_FIRMWARE_STM32F446_SEMIHOSTING_H
/* ARM semihosting (the "Semihosting for AArch32 and AArch64" spec, v2):
 * a debugger or QEMU (-semihosting-config enable=on) services `bkpt 0xAB`.
 * Only the self-test image uses it: on a board without a debugger the
 * breakpoint would fault. */

#include <stdint.h>

/* Writes a NUL-terminated string to the host's console (SYS_WRITE0). */
void semihosting_write(const char* text);

/* Ends the program with exit code `code` (SYS_EXIT_EXTENDED with
 * ADP_Stopped_ApplicationExit): QEMU exits with that status. */
void semihosting_exit(uint32_t code) __attribute__((noreturn));

/* One line of output built without printf: text and numbers appended, then
 * written with its newline. Truncates at 159 characters. */
typedef struct text_line {
  char text[160];
  unsigned length;
} text_line;

void line_start(text_line* line);
void line_text(text_line* line, const char* text);
void line_u32(text_line* line, uint32_t value);
void line_i64(text_line* line, int64_t value);
void line_hex(text_line* line, uint32_t value, unsigned digits);
void line_write(text_line* line);

#endif /* PINBALL_FIRMWARE_STM32F446_SEMIHOSTING_H */
