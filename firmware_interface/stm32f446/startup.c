/* Reset and exception entry for the STM32F446 (Cortex-M4): the vector table,
 * Reset_Handler (C runtime set-up, then main) and the one handler every
 * unexpected exception or interrupt lands in.
 *
 * The vector table layout is the Cortex-M4's 16 system entries (ARM DUI
 * 0553, "Vector table") followed by the STM32F446's 97 interrupt lines
 * (RM0390, Interrupts and events: the vector table). Only the lines this
 * firmware enables have their own handler; a strong definition elsewhere
 * (can.c) replaces the weak alias below.
 *
 * No floating point is used (-mfloat-abi=soft), so the FPU stays off and
 * exception entry never stacks its registers. */

#include <stdint.h>

#include "drivers.h"
#include "registers.h"
#include "startup.h"

/* Linker script symbols (stm32f446.ld): names reserved for such use. */
/* NOLINTBEGIN(bugprone-reserved-identifier) */
extern uint32_t _estack[];
extern uint32_t _sidata[], _sdata[], _edata[];
extern uint32_t _sbss[], _ebss[];
/* NOLINTEND(bugprone-reserved-identifier) */

int main(void);

/* Every exception and interrupt without its own handler: the coils off
 * first, then wait for the independent watchdog to reset the MCU, whose
 * reset state is every coil off too (coils.c). Started here if main had not
 * started it yet: a fault before iwdg_start still ends in a reset, at the
 * IWDG's reset timeout (4096 / (32 kHz / 4) = 512 ms nominal). Writing the
 * start key to a running IWDG changes nothing (RM0390, IWDG functional
 * description). */
void Default_Handler(void) {
  coils_emergency_off();
  IWDG->KR = IWDG_KR_START;
  for (;;) {
    /* No refresh: the IWDG ends this. */
  }
}

void NMI_Handler(void) __attribute__((weak, alias("Default_Handler")));
void HardFault_Handler(void) __attribute__((weak, alias("Default_Handler")));
void MemManage_Handler(void) __attribute__((weak, alias("Default_Handler")));
void BusFault_Handler(void) __attribute__((weak, alias("Default_Handler")));
void UsageFault_Handler(void) __attribute__((weak, alias("Default_Handler")));
void SVC_Handler(void) __attribute__((weak, alias("Default_Handler")));
void DebugMon_Handler(void) __attribute__((weak, alias("Default_Handler")));
void PendSV_Handler(void) __attribute__((weak, alias("Default_Handler")));
void SysTick_Handler(void) __attribute__((weak, alias("Default_Handler")));
void CAN1_RX0_IRQHandler(void) __attribute__((weak, alias("Default_Handler")));
void CAN1_SCE_IRQHandler(void) __attribute__((weak, alias("Default_Handler")));

void Reset_Handler(void);

typedef void (*vector)(void);

/* Default_Handler for n consecutive interrupt lines. */
#define D1 Default_Handler
#define D2 D1, D1
#define D4 D2, D2
#define D10 D4, D4, D2

/* Placed at 0x08000000 by the linker script (.isr_vector), the address the
 * MCU boots from with BOOT0 low (RM0390, boot configuration), aliased at 0.
 * Every line has a handler, so a stray interrupt lands in Default_Handler,
 * not at address 0. */
__attribute__((section(".isr_vector"), used)) const vector vector_table[] = {
    (vector)(uintptr_t)_estack,
    Reset_Handler,
    NMI_Handler, /* also the clock security system: HSE lost (clock.c) */
    HardFault_Handler,
    MemManage_Handler,
    BusFault_Handler,
    UsageFault_Handler,
    0, 0, 0, 0, /* reserved */
    SVC_Handler,
    DebugMon_Handler,
    0, /* reserved */
    PendSV_Handler,
    SysTick_Handler,
    D10, D10,            /* lines 0..19 */
    CAN1_RX0_IRQHandler, /* line 20 (IRQ_CAN1_RX0) */
    D1,                  /* line 21: CAN1_RX1, FIFO 1 is not used */
    CAN1_SCE_IRQHandler, /* line 22 (IRQ_CAN1_SCE) */
    D10, D10, D10, D10, D10, D10, D10, D4 /* lines 23..96 */
};
_Static_assert(sizeof(vector_table) / sizeof(vector_table[0]) == 16u + IRQ_COUNT, "one entry per line");
_Static_assert(IRQ_CAN1_RX0 == 20u && IRQ_CAN1_SCE == 22u, "the table above places them by position");

__attribute__((section(".noinit"))) reset_record g_reset_record;

void Reset_Handler(void) {
  /* .data from its load address in flash, .bss to zero (C11 6.7.9p10). The
   * sizes come from the linker as addresses; word loops, the sections are
   * 4-aligned by the linker script. */
  const uintptr_t data_words = ((uintptr_t)_edata - (uintptr_t)_sdata) / sizeof(uint32_t);
  for (uintptr_t i = 0; i < data_words; ++i) _sdata[i] = _sidata[i];
  const uintptr_t bss_words = ((uintptr_t)_ebss - (uintptr_t)_sbss) / sizeof(uint32_t);
  for (uintptr_t i = 0; i < bss_words; ++i) _sbss[i] = 0u;

  SCB->VTOR = (uint32_t)(uintptr_t)vector_table;
  /* Divide by zero traps instead of returning 0; the configurable faults get
   * their own entries (all land in Default_Handler). */
  SCB->CCR |= SCB_CCR_DIV_0_TRP;
  SCB->SHCSR |= SCB_SHCSR_MEMFAULTENA | SCB_SHCSR_BUSFAULTENA | SCB_SHCSR_USGFAULTENA;
  dsb();

  (void)main();
  Default_Handler(); /* main never returns; if it did, make the board safe */
}
