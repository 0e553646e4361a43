/* ARM semihosting calls and a printf-free line builder (semihosting.h). */

#include "semihosting.h"

#define SYS_WRITE0 0x04u
#define SYS_EXIT_EXTENDED 0x20u
#define ADP_STOPPED_APPLICATION_EXIT 0x20026u

/* r0 = operation, r1 = argument; the result comes back in r0. The memory
 * clobber: the host reads what r1 points at. */
static uint32_t semihosting_call(uint32_t operation, const void* argument) {
  register uint32_t r0 __asm__("r0") = operation;
  register const void* r1 __asm__("r1") = argument;
  __asm__ volatile("bkpt 0xAB" : "+r"(r0) : "r"(r1) : "memory");
  return r0;
}

void semihosting_write(const char* text) { (void)semihosting_call(SYS_WRITE0, text); }

void semihosting_exit(uint32_t code) {
  const uint32_t block[2] = {ADP_STOPPED_APPLICATION_EXIT, code};
  (void)semihosting_call(SYS_EXIT_EXTENDED, block);
  for (;;) {
    /* Not under a semihosting host: nowhere to go. */
  }
}

void line_start(text_line* line) {
  line->length = 0u;
  line->text[0] = '\0';
}

static void put(text_line* line, char c) {
  if (line->length + 2u < sizeof line->text) { /* room for '\n' and NUL */
    line->text[line->length++] = c;
    line->text[line->length] = '\0';
  }
}

void line_text(text_line* line, const char* text) {
  while (*text != '\0') put(line, *text++);
}

/* The digits of `value`, most significant first. */
static void put_decimal(text_line* line, uint64_t value) {
  char digits[20];
  unsigned n = 0u;
  do {
    digits[n++] = (char)('0' + value % 10u);
    value /= 10u;
  } while (value != 0u);
  while (n > 0u) put(line, digits[--n]);
}

void line_u32(text_line* line, uint32_t value) { put_decimal(line, value); }

void line_i64(text_line* line, int64_t value) {
  uint64_t magnitude = (uint64_t)value;
  if (value < 0) {
    put(line, '-');
    magnitude = 0u - magnitude;
  }
  put_decimal(line, magnitude);
}

void line_hex(text_line* line, uint32_t value, unsigned digits) {
  for (unsigned i = digits; i > 0u; --i) put(line, "0123456789abcdef"[(value >> (4u * (i - 1u))) & 0xFu]);
}

void line_write(text_line* line) {
  line->text[line->length] = '\n';
  line->text[line->length + 1u] = '\0';
  semihosting_write(line->text);
  line->text[line->length] = '\0';
}
