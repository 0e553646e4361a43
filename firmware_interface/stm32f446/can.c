/* bxCAN1 (RM0390, bxCAN chapter) on PA11 (CAN1_RX) and PA12 (CAN1_TX),
 * alternate function 9 (datasheet DS10693, alternate function table), to a
 * 3.3 V transceiver (the lab's board: e.g. a TJA1051T/3 or SN65HVD230 on
 * Nucleo CN10-14 / CN10-12).
 *
 * Bit timing (RM0390, bxCAN "Bit timing"): bit = 1 + BS1 + BS2 time
 * quanta, tq = BRP / PCLK1, sample point after 1 + BS1.
 *   PCLK1 45 MHz (HSE/PLL): BRP 5  -> tq 111 ns, 18 tq = 1 + 15 + 2,
 *                           sample point 16/18 = 88.9 %, SJW 2 tq.
 *   PCLK1 16 MHz (HSI):     BRP 2  -> tq 125 ns, 16 tq = 1 + 13 + 2,
 *                           sample point 14/16 = 87.5 %, SJW 2 tq.
 * Both are 500 kbit/s exactly (PROTOCOL.md) with the sample point in the
 * 85..90 % band CiA 301 recommends for 500 kbit/s. On the HSI the clock's
 * own tolerance (about 1 % at 25 C, more over temperature) exceeds what
 * this timing tolerates (about 0.5 %), so the HSI fallback may not reach
 * the bus: the board then stays out of session with every coil off.
 *
 * Receive: one filter bank (0, 32-bit mask mode) passes standard data
 * frames whose id matches 0x100 under mask 0x700 (PROTOCOL.md, "Receive
 * filter") into FIFO 0. FIFO 0 holds 3 frames (about 0.4 ms of traffic at
 * 500 kbit/s), so its interrupt moves each frame into a 16-frame software
 * ring at once; the main loop drains the ring. A frame the hardware FIFO or
 * the ring could not keep is counted.
 *
 * Transmit: straight into one of the three TX mailboxes, sent in the order
 * requested (TXFP). When all three are busy can_send says so and the core
 * keeps the frame in its outbox for the next pass (pbfw_board_service), so
 * no reply is lost to a busy transmitter. Automatic retransmission stays on
 * (NART = 0), and bus-off is left automatically after 128 x 11 recessive
 * bits (ABOM), the host's restart-ms covering its side.
 *
 * Errors: the error interrupt counts error frames (each new last-error
 * code), error-passive and bus-off entries. bxCAN does not hand error frames
 * to software as frames, so they are counted here, not passed to the core
 * (whose Fault 4 is for frames it decoded). */

#include "drivers.h"
#include "registers.h"

#define CAN_BITRATE_BPS PBFW_BITRATE_BPS
#define RX_RING_SIZE 16u /* powers of two: the indices wrap by masking */
/* Entering init waits for the frame on the bus (< 0.3 ms), leaving it for 11
 * recessive bits: 2 ms is ample, and under the IWDG's shortest 6.8 ms. */
#define MODE_CHANGE_TIMEOUT_NS 2000000
#define RX0_PRIORITY 1u /* NVIC: 0 highest; nothing else is enabled */
#define SCE_PRIORITY 2u

_Static_assert((RX_RING_SIZE & (RX_RING_SIZE - 1u)) == 0u, "RX_RING_SIZE is a power of two");

/* Receive ring: the RX0 interrupt writes frames and publishes rx_head; the
 * main loop reads them and publishes rx_tail. One writer per index. */
static pbfw_frame rx_ring[RX_RING_SIZE];
static volatile uint32_t rx_head;
static volatile uint32_t rx_tail;

/* Counters: each written by one context only (noted), read with
 * interrupts masked for a consistent copy. */
static volatile can_counters counters;
/* Error sources masked after they fired, unmasked by the main loop once the
 * condition has cleared: an interrupt per entry, never a storm. */
static volatile uint32_t masked_error_sources;

/* Waits until (*reg & mask) == value, for at most timeout_ns of TIM2 time
 * (well under the IWDG's shortest timeout, 6.8 ms). */
static bool wait_for(const reg32* reg, uint32_t mask, uint32_t value, pbfw_time_ns timeout_ns) {
  const pbfw_time_ns start = time_ns();
  while ((*reg & mask) != value) {
    if (time_ns() - start > timeout_ns) return false;
  }
  return true;
}

/* BTR for 500 kbit/s from PCLK1: the largest bit of at most 18 quanta (the
 * finest resolution BS1 <= 16 allows with the sample point near 87.5 %)
 * that PCLK1 divides exactly. */
static uint32_t bit_timing(uint32_t pclk1_hz) {
  for (uint32_t quanta = 18u; quanta >= 8u; --quanta) {
    const uint32_t per_bit = CAN_BITRATE_BPS * quanta;
    if (pclk1_hz % per_bit != 0u || pclk1_hz / per_bit > 1024u) continue;
    const uint32_t brp = pclk1_hz / per_bit;
    const uint32_t bs2 = (quanta + 4u) / 8u; /* 2 for 12..19 quanta: 87.5..89 % */
    const uint32_t bs1 = quanta - 1u - bs2;
    const uint32_t sjw = bs2 < 2u ? bs2 : 2u;
    return ((brp - 1u) << CAN_BTR_BRP_SHIFT) | ((bs1 - 1u) << CAN_BTR_TS1_SHIFT) |
           ((bs2 - 1u) << CAN_BTR_TS2_SHIFT) | ((sjw - 1u) << CAN_BTR_SJW_SHIFT);
  }
  /* No exact divider: cannot happen with the two clock trees clock.c makes. */
  return 0u;
}

static void configure_pins(void) {
  RCC->AHB1ENR |= RCC_AHB1ENR_GPIOAEN;
  (void)RCC->AHB1ENR;
  /* PA11 and PA12: AF9; a pull-up on RX so an unfitted transceiver reads
   * recessive; TX push-pull at high speed (500 kbit/s needs little). */
  GPIOA->AFR[1] = (GPIOA->AFR[1] & ~(0xFFu << 12)) | ((GPIO_AF9_CAN1 * 0x11u) << 12);
  GPIOA->OTYPER &= ~(1u << 12);
  GPIOA->OSPEEDR = (GPIOA->OSPEEDR & ~(0xFu << 22)) | ((GPIO_SPEED_HIGH * 0x5u) << 22);
  GPIOA->PUPDR = (GPIOA->PUPDR & ~(0xFu << 22)) | (GPIO_PULL_UP << 22);
  GPIOA->MODER = (GPIOA->MODER & ~(0xFu << 22)) | ((GPIO_MODE_AF * 0x5u) << 22);
}

bool can_init(const clock_tree* clock) {
  configure_pins();
  RCC->APB1ENR |= RCC_APB1_CAN1;
  (void)RCC->APB1ENR;
  RCC->APB1RSTR |= RCC_APB1_CAN1;
  RCC->APB1RSTR &= ~RCC_APB1_CAN1;

  bool acknowledged = true;
  /* Out of sleep (the reset state), into initialisation (RM0390, bxCAN
   * "Initialization mode"). */
  CAN1->MCR = (CAN1->MCR & ~CAN_MCR_SLEEP) | CAN_MCR_INRQ;
  if (!wait_for(&CAN1->MSR, CAN_MSR_INAK | CAN_MSR_SLAK, CAN_MSR_INAK, MODE_CHANGE_TIMEOUT_NS)) {
    ++counters.init_timeouts;
    acknowledged = false;
  }
  /* Automatic bus-off management, TX in request order, automatic
   * retransmission, FIFO overwritten (newest kept) on overrun; frozen while
   * a debugger halts the core (DBF, the reset value). */
  CAN1->MCR = CAN_MCR_INRQ | CAN_MCR_ABOM | CAN_MCR_TXFP | CAN_MCR_DBF;
  const uint32_t btr = bit_timing(clock->apb1_hz);
  if (btr == 0u) return false; /* no exact 500 kbit/s: stay off the bus rather than disturb it */
  CAN1->BTR = btr;

  /* Filter bank 0 (RM0390, bxCAN "Identifier filtering"): 32-bit scale,
   * mask mode, FIFO 0. STID in [31:21]; IDE and RTR in the mask too, so only standard data
   * frames pass. */
  CAN1->FMR |= CAN_FMR_FINIT;
  CAN1->FA1R &= ~1u;
  CAN1->FS1R |= 1u;
  CAN1->FM1R &= ~1u;
  CAN1->FFA1R &= ~1u;
  CAN1->FR[0][0] = PBFW_ID_BASE << CAN_ID_STID_SHIFT;
  CAN1->FR[0][1] = (PBFW_ID_MASK << CAN_ID_STID_SHIFT) | CAN_ID_IDE | CAN_ID_RTR;
  CAN1->FA1R |= 1u;
  CAN1->FMR &= ~CAN_FMR_FINIT;

  CAN1->IER = CAN_IER_FMPIE0 | CAN_IER_FOVIE0 | CAN_IER_ERRIE | CAN_IER_LECIE | CAN_IER_BOFIE | CAN_IER_EPVIE;
  CAN1->ESR = CAN_ESR_LEC_SOFTWARE;
  nvic_set_priority(IRQ_CAN1_RX0, RX0_PRIORITY);
  nvic_set_priority(IRQ_CAN1_SCE, SCE_PRIORITY);
  nvic_enable(IRQ_CAN1_RX0);
  nvic_enable(IRQ_CAN1_SCE);

  /* Normal mode: the controller joins after 11 recessive bits. If the bus
   * never shows them, it keeps waiting on its own; the loop goes on. */
  CAN1->MCR &= ~CAN_MCR_INRQ;
  if (!wait_for(&CAN1->MSR, CAN_MSR_INAK, 0u, MODE_CHANGE_TIMEOUT_NS)) {
    ++counters.init_timeouts;
    acknowledged = false;
  }
  return acknowledged;
}

static uint32_t read_le32(const uint8_t* b) {
  return (uint32_t)b[0] | ((uint32_t)b[1] << 8) | ((uint32_t)b[2] << 16) | ((uint32_t)b[3] << 24);
}

static void write_le32(uint8_t* b, uint32_t v) {
  b[0] = (uint8_t)v;
  b[1] = (uint8_t)(v >> 8);
  b[2] = (uint8_t)(v >> 16);
  b[3] = (uint8_t)(v >> 24);
}

/* FIFO 0 message pending or overrun. At most the FIFO's 3 frames a call: a
 * frame that arrives meanwhile raises the interrupt again. */
void CAN1_RX0_IRQHandler(void) {
  if (CAN1->RF0R & CAN_RF0R_FOVR0) {
    ++counters.rx_overruns;      /* ISR-only writer */
    CAN1->RF0R = CAN_RF0R_FOVR0; /* rc_w1; RFOM0 written 0: no release */
  }
  for (unsigned n = 0; n < 3u && (CAN1->RF0R & CAN_RF0R_FMP0_MASK) != 0u; ++n) {
    const can_rx_fifo* box = &CAN1->RX[0];
    const uint32_t rir = box->RIR;
    const uint32_t rdtr = box->RDTR;
    const uint32_t low = box->RDLR;
    const uint32_t high = box->RDHR;
    CAN1->RF0R = CAN_RF0R_RFOM0; /* release the output mailbox */
    ++counters.rx_frames;
    if (rir & (CAN_ID_IDE | CAN_ID_RTR)) continue; /* the filter passes neither */
    const uint32_t head = rx_head;
    if (head - rx_tail >= RX_RING_SIZE) {
      ++counters.rx_ring_full;
      continue;
    }
    pbfw_frame* f = &rx_ring[head & (RX_RING_SIZE - 1u)];
    f->id = rir >> CAN_ID_STID_SHIFT;
    const uint32_t dlc = rdtr & 0xFu;
    f->len = (uint8_t)(dlc > PBFW_MAX_FRAME_BYTES ? PBFW_MAX_FRAME_BYTES : dlc); /* DLC 9..15 mean 8 */
    write_le32(&f->data[0], low);
    write_le32(&f->data[4], high);
    f->error = false;
    dmb(); /* the frame is written before the index that publishes it */
    rx_head = head + 1u;
  }
}

/* Error and status change: count, then let the main loop unmask a source
 * that stays set (bus-off lasts 128 x 11 bits; error passive lasts). */
void CAN1_SCE_IRQHandler(void) {
  const uint32_t esr = CAN1->ESR;
  const uint32_t lec = esr & CAN_ESR_LEC_MASK;
  if (lec != 0u && lec != CAN_ESR_LEC_SOFTWARE) ++counters.bus_errors;
  CAN1->ESR = CAN_ESR_LEC_SOFTWARE; /* only LEC is writable: a new error overwrites it */
  uint32_t mask = 0u;
  /* Counted once per entry: the source stays masked until it has cleared. */
  const uint32_t masked = masked_error_sources;
  if ((esr & CAN_ESR_BOFF) && !(masked & CAN_IER_BOFIE)) {
    ++counters.bus_off;
    mask |= CAN_IER_BOFIE;
  }
  if ((esr & CAN_ESR_EPVF) && !(masked & CAN_IER_EPVIE)) {
    ++counters.error_passive;
    mask |= CAN_IER_EPVIE;
  }
  if (mask != 0u) {
    CAN1->IER &= ~mask; /* also written by can_poll, with interrupts masked */
    masked_error_sources |= mask;
  }
  CAN1->MSR = CAN_MSR_ERRI; /* rc_w1 */
}

bool can_receive(pbfw_frame* out) {
  const uint32_t tail = rx_tail;
  if (rx_head == tail) return false;
  dmb(); /* read the frame after seeing the index that published it */
  *out = rx_ring[tail & (RX_RING_SIZE - 1u)];
  dmb(); /* done with the slot before handing it back */
  rx_tail = tail + 1u;
  return true;
}

bool can_send(const pbfw_frame* f) {
  const uint32_t tsr = CAN1->TSR;
  if ((tsr & (CAN_TSR_TME(0u) | CAN_TSR_TME(1u) | CAN_TSR_TME(2u))) == 0u) return false;
  /* CODE: the number of an empty mailbox when any is (RM0390, CAN_TSR). */
  can_tx_mailbox* box = &CAN1->TX[(tsr >> CAN_TSR_CODE_SHIFT) & 0x3u];
  box->TDTR = f->len > PBFW_MAX_FRAME_BYTES ? PBFW_MAX_FRAME_BYTES : f->len;
  box->TDLR = read_le32(&f->data[0]);
  box->TDHR = read_le32(&f->data[4]);
  /* Id last, with the request: a standard data frame (IDE = RTR = 0). */
  box->TIR = ((f->id & 0x7FFu) << CAN_ID_STID_SHIFT) | CAN_TIR_TXRQ;
  ++counters.tx_frames; /* main-loop-only writer */
  return true;
}

void can_poll(void) {
  /* An error source masked by the interrupt comes back once its condition
   * has cleared (bus-off left, error active again). */
  const uint32_t masked = masked_error_sources;
  if (masked == 0u) return;
  const uint32_t esr = CAN1->ESR;
  uint32_t unmask = 0u;
  if ((masked & CAN_IER_BOFIE) && !(esr & CAN_ESR_BOFF)) unmask |= CAN_IER_BOFIE;
  if ((masked & CAN_IER_EPVIE) && !(esr & CAN_ESR_EPVF)) unmask |= CAN_IER_EPVIE;
  if (unmask != 0u) {
    irq_disable(); /* read-modify-write shared with the error interrupt */
    masked_error_sources &= ~unmask;
    CAN1->IER |= unmask;
    irq_enable();
  }
}

can_counters can_get_counters(void) {
  irq_disable();
  can_counters copy;
  copy.rx_frames = counters.rx_frames;
  copy.rx_overruns = counters.rx_overruns;
  copy.rx_ring_full = counters.rx_ring_full;
  copy.tx_frames = counters.tx_frames;
  copy.bus_errors = counters.bus_errors;
  copy.bus_off = counters.bus_off;
  copy.error_passive = counters.error_passive;
  copy.init_timeouts = counters.init_timeouts;
  irq_enable();
  return copy;
}
