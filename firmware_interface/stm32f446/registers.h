#ifndef PINBALL_FIRMWARE_STM32F446_REGISTERS_H
#define PINBALL_FIRMWARE_STM32F446_REGISTERS_H
/* The STM32F446 registers this firmware touches, and only those, written
 * from the reference manual RM0390 and the Cortex-M4 generic user
 * guide (ARM DUI 0553). No vendor header is copied: each block is a struct
 * of volatile 32-bit words laid out as the manual's register map, its
 * offsets checked at compile time, and each bit we use is named after the
 * manual's bit name with the block as prefix.
 *
 * Every access goes through a volatile lvalue, so the compiler neither
 * drops, merges nor reorders register accesses (C11 5.1.2.3p6). The
 * addresses come from RM0390's memory map (Memory and bus architecture). */

#include <stddef.h>
#include <stdint.h>

typedef volatile uint32_t reg32;

#define REG_CHECK(type, field, offset) _Static_assert(offsetof(type, field) == (offset), #type "." #field)

/* ---- RCC: reset and clock control (RM0390, RCC registers) ---- */
typedef struct rcc_regs {
  reg32 CR;            /* 0x00 */
  reg32 PLLCFGR;       /* 0x04 */
  reg32 CFGR;          /* 0x08 */
  reg32 CIR;           /* 0x0C */
  reg32 AHB1RSTR;      /* 0x10 */
  reg32 AHB2RSTR;      /* 0x14 */
  reg32 AHB3RSTR;      /* 0x18 */
  reg32 reserved0;     /* 0x1C */
  reg32 APB1RSTR;      /* 0x20 */
  reg32 APB2RSTR;      /* 0x24 */
  reg32 reserved1[2];  /* 0x28 */
  reg32 AHB1ENR;       /* 0x30 */
  reg32 AHB2ENR;       /* 0x34 */
  reg32 AHB3ENR;       /* 0x38 */
  reg32 reserved2;     /* 0x3C */
  reg32 APB1ENR;       /* 0x40 */
  reg32 APB2ENR;       /* 0x44 */
  reg32 reserved3[11]; /* 0x48 */
  reg32 CSR;           /* 0x74 */
} rcc_regs;
REG_CHECK(rcc_regs, AHB1ENR, 0x30);
REG_CHECK(rcc_regs, APB1ENR, 0x40);
REG_CHECK(rcc_regs, CSR, 0x74);
#define RCC ((rcc_regs*)0x40023800u)

#define RCC_CR_HSION (1u << 0)
#define RCC_CR_HSIRDY (1u << 1)
#define RCC_CR_HSEON (1u << 16)
#define RCC_CR_HSERDY (1u << 17)
#define RCC_CR_HSEBYP (1u << 18)
#define RCC_CR_CSSON (1u << 19)
#define RCC_CR_PLLON (1u << 24)
#define RCC_CR_PLLRDY (1u << 25)

#define RCC_PLLCFGR_PLLM_SHIFT 0u  /* [5:0]  2..63 */
#define RCC_PLLCFGR_PLLN_SHIFT 6u  /* [14:6] 50..432 */
#define RCC_PLLCFGR_PLLP_SHIFT 16u /* [17:16] 0 = /2 */
#define RCC_PLLCFGR_PLLSRC_HSE (1u << 22)
#define RCC_PLLCFGR_PLLQ_SHIFT 24u /* [27:24] 2..15 */
#define RCC_PLLCFGR_PLLR_SHIFT 28u /* [30:28] 2..7 */

#define RCC_CFGR_SW_MASK 0x3u
#define RCC_CFGR_SW_HSI 0x0u
#define RCC_CFGR_SW_PLLP 0x2u
#define RCC_CFGR_SWS_MASK (0x3u << 2)
#define RCC_CFGR_SWS_HSI (0x0u << 2)
#define RCC_CFGR_SWS_PLLP (0x2u << 2)
#define RCC_CFGR_HPRE_SHIFT 4u   /* [7:4]  0xxx = /1 */
#define RCC_CFGR_PPRE1_SHIFT 10u /* [12:10] 0xx /1, 100 /2, 101 /4 */
#define RCC_CFGR_PPRE2_SHIFT 13u /* [15:13] */
#define RCC_CFGR_PPRE_DIV1 0x0u
#define RCC_CFGR_PPRE_DIV2 0x4u
#define RCC_CFGR_PPRE_DIV4 0x5u

#define RCC_CIR_CSSC (1u << 23)

#define RCC_AHB1ENR_GPIOAEN (1u << 0)
#define RCC_AHB1ENR_GPIOBEN (1u << 1)
#define RCC_AHB1ENR_GPIOCEN (1u << 2)

#define RCC_APB1_TIM2 (1u << 0) /* same bit in APB1RSTR and APB1ENR */
#define RCC_APB1_TIM3 (1u << 1)
#define RCC_APB1_TIM4 (1u << 2)
#define RCC_APB1_CAN1 (1u << 25)
#define RCC_APB1_PWR (1u << 28)

#define RCC_CSR_LSION (1u << 0)
#define RCC_CSR_RMVF (1u << 24)
#define RCC_CSR_BORRSTF (1u << 25)
#define RCC_CSR_PINRSTF (1u << 26)
#define RCC_CSR_PORRSTF (1u << 27)
#define RCC_CSR_SFTRSTF (1u << 28)
#define RCC_CSR_IWDGRSTF (1u << 29)
#define RCC_CSR_WWDGRSTF (1u << 30)
#define RCC_CSR_LPWRRSTF (1u << 31)

/* ---- PWR: power controller (RM0390, PWR registers) ---- */
typedef struct pwr_regs {
  reg32 CR;  /* 0x00 */
  reg32 CSR; /* 0x04 */
} pwr_regs;
#define PWR ((pwr_regs*)0x40007000u)

#define PWR_CR_VOS_SHIFT 14u /* [15:14] 11 = scale 1 */
#define PWR_CR_VOS_SCALE1 (0x3u << 14)
#define PWR_CR_ODEN (1u << 16)
#define PWR_CR_ODSWEN (1u << 17)
#define PWR_CSR_VOSRDY (1u << 14)
#define PWR_CSR_ODRDY (1u << 16)
#define PWR_CSR_ODSWRDY (1u << 17)

/* ---- FLASH interface (RM0390, flash interface registers) ---- */
typedef struct flash_regs {
  reg32 ACR; /* 0x00 */
} flash_regs;
#define FLASH ((flash_regs*)0x40023C00u)

#define FLASH_ACR_LATENCY_MASK 0xFu
#define FLASH_ACR_PRFTEN (1u << 8)
#define FLASH_ACR_ICEN (1u << 9)
#define FLASH_ACR_DCEN (1u << 10)

/* ---- GPIO (RM0390, GPIO registers) ---- */
typedef struct gpio_regs {
  reg32 MODER;   /* 0x00: 2 bits a pin, 00 input 01 output 10 AF 11 analog */
  reg32 OTYPER;  /* 0x04: 0 push-pull */
  reg32 OSPEEDR; /* 0x08 */
  reg32 PUPDR;   /* 0x0C: 00 none 01 pull-up 10 pull-down */
  reg32 IDR;     /* 0x10 */
  reg32 ODR;     /* 0x14 */
  reg32 BSRR;    /* 0x18: low half sets, high half resets, atomically */
  reg32 LCKR;    /* 0x1C */
  reg32 AFR[2];  /* 0x20, 0x24: 4 bits a pin */
} gpio_regs;
REG_CHECK(gpio_regs, BSRR, 0x18);
REG_CHECK(gpio_regs, AFR, 0x20);
#define GPIOA ((gpio_regs*)0x40020000u)
#define GPIOB ((gpio_regs*)0x40020400u)
#define GPIOC ((gpio_regs*)0x40020800u)

#define GPIO_MODE_INPUT 0x0u
#define GPIO_MODE_OUTPUT 0x1u
#define GPIO_MODE_AF 0x2u
#define GPIO_PULL_NONE 0x0u
#define GPIO_PULL_UP 0x1u
#define GPIO_PULL_DOWN 0x2u
#define GPIO_SPEED_MEDIUM 0x1u
#define GPIO_SPEED_HIGH 0x2u
#define GPIO_AF2_TIM3_4_5 2u /* datasheet DS10693, alternate function table */
#define GPIO_AF9_CAN1 9u

/* ---- TIM2..TIM5: general-purpose timers (RM0390, TIM2 to TIM5 registers).
 * TIM2 and TIM5 count 32 bits, TIM3 and TIM4 16 bits. ---- */
typedef struct tim_regs {
  reg32 CR1;   /* 0x00 */
  reg32 CR2;   /* 0x04 */
  reg32 SMCR;  /* 0x08 */
  reg32 DIER;  /* 0x0C */
  reg32 SR;    /* 0x10 */
  reg32 EGR;   /* 0x14 */
  reg32 CCMR1; /* 0x18 */
  reg32 CCMR2; /* 0x1C */
  reg32 CCER;  /* 0x20 */
  reg32 CNT;   /* 0x24 */
  reg32 PSC;   /* 0x28 */
  reg32 ARR;   /* 0x2C */
  reg32 reserved0;
  reg32 CCR[4]; /* 0x34..0x40 */
} tim_regs;
REG_CHECK(tim_regs, CNT, 0x24);
REG_CHECK(tim_regs, CCR, 0x34);
#define TIM2 ((tim_regs*)0x40000000u)
#define TIM3 ((tim_regs*)0x40000400u)
#define TIM4 ((tim_regs*)0x40000800u)

#define TIM_CR1_CEN (1u << 0)
#define TIM_CR1_URS (1u << 2)
#define TIM_CR1_ARPE (1u << 7)
#define TIM_EGR_UG (1u << 0)
#define TIM_SR_UIF (1u << 0)
/* CCMRx output compare: channel 2k+1 in bits [7:0], channel 2k+2 in [15:8]. */
#define TIM_CCMR_OCM_PWM1 0x6u                        /* OCxM = 110: active while CNT < CCRx */
#define TIM_CCMR_OCM_FORCE_INACTIVE 0x4u              /* OCxM = 100 */
#define TIM_CCMR_OCM_SHIFT(ch) (((ch)&1u) ? 12u : 4u) /* ch 0..3 */
#define TIM_CCMR_OCPE(ch) (((ch)&1u) ? (1u << 11) : (1u << 3))
#define TIM_CCER_CCE(ch) (1u << (4u * (ch)))      /* CCxE */
#define TIM_CCER_CCP(ch) (1u << (4u * (ch) + 1u)) /* CCxP: 0 active high */

/* ---- IWDG: independent watchdog (RM0390, IWDG registers) ---- */
typedef struct iwdg_regs {
  reg32 KR;  /* 0x00 */
  reg32 PR;  /* 0x04: [2:0] 0 = /4 .. 6 = /256 */
  reg32 RLR; /* 0x08: [11:0] */
  reg32 SR;  /* 0x0C */
} iwdg_regs;
#define IWDG ((iwdg_regs*)0x40003000u)

#define IWDG_KR_START 0xCCCCu
#define IWDG_KR_REFRESH 0xAAAAu
#define IWDG_KR_UNLOCK 0x5555u
#define IWDG_SR_PVU (1u << 0)
#define IWDG_SR_RVU (1u << 1)

/* ---- DBGMCU: the debug support's freeze bits (RM0390, DBG registers) ---- */
typedef struct dbgmcu_regs {
  reg32 IDCODE;  /* 0x00 */
  reg32 CR;      /* 0x04 */
  reg32 APB1_FZ; /* 0x08 */
  reg32 APB2_FZ; /* 0x0C */
} dbgmcu_regs;
REG_CHECK(dbgmcu_regs, APB1_FZ, 0x08);
#define DBGMCU ((dbgmcu_regs*)0xE0042000u)

#define DBGMCU_APB1_FZ_DBG_WWDG_STOP (1u << 11)
#define DBGMCU_APB1_FZ_DBG_IWDG_STOP (1u << 12)

/* ---- bxCAN1 (RM0390, bxCAN registers) ---- */
typedef struct can_tx_mailbox {
  reg32 TIR;  /* STID [31:21], IDE 2, RTR 1, TXRQ 0 */
  reg32 TDTR; /* DLC [3:0] */
  reg32 TDLR; /* data bytes 0..3, byte 0 in [7:0] */
  reg32 TDHR; /* data bytes 4..7 */
} can_tx_mailbox;
typedef struct can_rx_fifo {
  reg32 RIR;  /* STID [31:21], IDE 2, RTR 1 */
  reg32 RDTR; /* DLC [3:0], FMI [15:8] */
  reg32 RDLR;
  reg32 RDHR;
} can_rx_fifo;
typedef struct can_regs {
  reg32 MCR;  /* 0x000 */
  reg32 MSR;  /* 0x004 */
  reg32 TSR;  /* 0x008 */
  reg32 RF0R; /* 0x00C */
  reg32 RF1R; /* 0x010 */
  reg32 IER;  /* 0x014 */
  reg32 ESR;  /* 0x018 */
  reg32 BTR;  /* 0x01C */
  reg32 reserved0[88];
  can_tx_mailbox TX[3]; /* 0x180 */
  can_rx_fifo RX[2];    /* 0x1B0 */
  reg32 reserved1[12];
  reg32 FMR;       /* 0x200 */
  reg32 FM1R;      /* 0x204 */
  reg32 reserved2; /* 0x3C */
  reg32 FS1R;      /* 0x20C */
  reg32 reserved3;
  reg32 FFA1R; /* 0x214 */
  reg32 reserved4;
  reg32 FA1R; /* 0x21C */
  reg32 reserved5[8];
  reg32 FR[28][2]; /* 0x240: bank i's FR1, FR2 */
} can_regs;
REG_CHECK(can_regs, BTR, 0x01C);
REG_CHECK(can_regs, TX, 0x180);
REG_CHECK(can_regs, RX, 0x1B0);
REG_CHECK(can_regs, FMR, 0x200);
REG_CHECK(can_regs, FA1R, 0x21C);
REG_CHECK(can_regs, FR, 0x240);
#define CAN1 ((can_regs*)0x40006400u)

#define CAN_MCR_INRQ (1u << 0)
#define CAN_MCR_SLEEP (1u << 1)
#define CAN_MCR_TXFP (1u << 2)
#define CAN_MCR_RFLM (1u << 3)
#define CAN_MCR_NART (1u << 4)
#define CAN_MCR_AWUM (1u << 5)
#define CAN_MCR_ABOM (1u << 6)
#define CAN_MCR_TTCM (1u << 7)
#define CAN_MCR_RESET (1u << 15)
#define CAN_MCR_DBF (1u << 16)
#define CAN_MSR_INAK (1u << 0)
#define CAN_MSR_SLAK (1u << 1)
#define CAN_TSR_TME(m) (1u << (26u + (m)))
#define CAN_TSR_CODE_SHIFT 24u
#define CAN_RF0R_FMP0_MASK 0x3u
#define CAN_RF0R_FULL0 (1u << 3)
#define CAN_RF0R_FOVR0 (1u << 4)
#define CAN_RF0R_RFOM0 (1u << 5)
#define CAN_IER_FMPIE0 (1u << 1)
#define CAN_IER_FOVIE0 (1u << 3)
#define CAN_IER_EPVIE (1u << 9)
#define CAN_IER_BOFIE (1u << 10)
#define CAN_IER_LECIE (1u << 11)
#define CAN_IER_ERRIE (1u << 15)
#define CAN_MSR_ERRI (1u << 2)
#define CAN_ESR_EWGF (1u << 0)
#define CAN_ESR_EPVF (1u << 1)
#define CAN_ESR_BOFF (1u << 2)
#define CAN_ESR_LEC_SHIFT 4u
#define CAN_ESR_LEC_MASK (0x7u << 4)
#define CAN_ESR_LEC_SOFTWARE (0x7u << 4) /* "set by software": no new error since */
#define CAN_BTR_BRP_SHIFT 0u             /* [9:0]  prescaler - 1 */
#define CAN_BTR_TS1_SHIFT 16u            /* [19:16] tBS1 - 1 */
#define CAN_BTR_TS2_SHIFT 20u            /* [22:20] tBS2 - 1 */
#define CAN_BTR_SJW_SHIFT 24u            /* [25:24] tSJW - 1 */
#define CAN_ID_STID_SHIFT 21u
#define CAN_ID_IDE (1u << 2)
#define CAN_ID_RTR (1u << 1)
#define CAN_TIR_TXRQ (1u << 0)
#define CAN_FMR_FINIT (1u << 0)

/* ---- Cortex-M4 system control space (ARM DUI 0553, 4.2-4.4) ---- */
typedef struct scb_regs {
  reg32 CPUID; /* 0xE000ED00 */
  reg32 ICSR;
  reg32 VTOR; /* 0xE000ED08 */
  reg32 AIRCR;
  reg32 SCR;
  reg32 CCR; /* 0xE000ED14 */
  reg32 SHPR[3];
  reg32 SHCSR; /* 0xE000ED24 */
  reg32 CFSR;  /* 0xE000ED28 */
  reg32 HFSR;
} scb_regs;
REG_CHECK(scb_regs, CCR, 0x14);
REG_CHECK(scb_regs, CFSR, 0x28);
#define SCB ((scb_regs*)0xE000ED00u)
#define SCB_CCR_DIV_0_TRP (1u << 4)
#define SCB_CCR_UNALIGN_TRP (1u << 3)
#define SCB_CCR_STKALIGN (1u << 9)
#define SCB_SHCSR_MEMFAULTENA (1u << 16)
#define SCB_SHCSR_BUSFAULTENA (1u << 17)
#define SCB_SHCSR_USGFAULTENA (1u << 18)

typedef struct nvic_regs {
  reg32 ISER[8]; /* 0xE000E100 */
  reg32 reserved0[24];
  reg32 ICER[8]; /* 0xE000E180 */
  reg32 reserved1[24];
  reg32 ISPR[8]; /* 0xE000E200 */
  reg32 reserved2[24];
  reg32 ICPR[8];             /* 0xE000E280 */
  reg32 reserved3[88];       /* IABR at 0x200 is not used */
  volatile uint8_t IPR[240]; /* 0xE000E400: 8 bits a line, the STM32 implements the top 4 */
} nvic_regs;
REG_CHECK(nvic_regs, ICER, 0x80);
REG_CHECK(nvic_regs, IPR, 0x300);
#define NVIC ((nvic_regs*)0xE000E100u)

typedef struct systick_regs {
  reg32 CSR; /* 0xE000E010 */
  reg32 RVR;
  reg32 CVR;
  reg32 CALIB;
} systick_regs;
#define SYSTICK ((systick_regs*)0xE000E010u)

/* STM32F446 interrupt lines (RM0390, Interrupts and events: vector table). */
#define IRQ_CAN1_RX0 20u
#define IRQ_CAN1_SCE 22u
#define IRQ_COUNT 97u

static inline void nvic_enable(unsigned irq) { NVIC->ISER[irq >> 5] = 1u << (irq & 31u); }
static inline void nvic_disable(unsigned irq) { NVIC->ICER[irq >> 5] = 1u << (irq & 31u); }
static inline void nvic_set_priority(unsigned irq, uint8_t priority) {
  NVIC->IPR[irq] = (uint8_t)(priority << 4);
}

/* Interrupts masked / unmasked (PRIMASK), with the compiler barrier that keeps
 * memory accesses on their side of it. */
static inline void irq_disable(void) { __asm__ volatile("cpsid i" ::: "memory"); }
static inline void irq_enable(void) { __asm__ volatile("cpsie i" ::: "memory"); }
/* Data memory barrier: an ISR's writes are visible before the index that publishes them. */
static inline void dmb(void) { __asm__ volatile("dmb" ::: "memory"); }
static inline void dsb(void) { __asm__ volatile("dsb" ::: "memory"); }

#endif /* PINBALL_FIRMWARE_STM32F446_REGISTERS_H */
