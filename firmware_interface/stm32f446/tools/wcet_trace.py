#!/usr/bin/env python3
"""Worst-case cycle estimate of the self-test's measured windows.

Runs the self-test image in QEMU with one instruction per translation block
and the execution log on (-singlestep -d exec,nochain), so the log names the
address of every instruction executed, in order. The self-test brackets each
measurement with calls of wcet_begin and wcet_end (selftest_main.c); every
instruction between them belongs to that window, and the first window (the
empty harness) is subtracted from the others.

Each executed instruction is then priced with the Cortex-M4 cycle counts of
its Technical Reference Manual (ARM DDI 0439B, 3.3.1, Table 3-1), taking the
dearest case where the table gives a range:

  data processing, IT, not-taken branch        1
  LDR/STR family (single)                      2   (1 when pipelined: not assumed)
  LDRD/STRD                                    3
  LDM/STM/PUSH/POP of N registers              1 + N
  taken branch, or any write to the PC         + P, P = 3 (pipeline refill, 1..3)
  TBB/TBH                                      2 + P
  MUL, long multiplies                         1;  MLA, MLS 2
  UDIV/SDIV                                    12  (2..12)
  DMB/DSB/ISB                                  4   (not given: assumed)

Two figures per window:

  core cycles   the model above with no memory stalls: code and data
                served without wait states, which is what the ART
                accelerator (RM0390 3.4.2) gives on a hit;
  cold bound    the same plus, at 180 MHz's 5 flash wait states, 5 cycles
                for every new 128-bit flash line the fetch enters and 5 for
                every data load (a literal pool or constant table in flash
                would cost that; an SRAM load costs less), plus 8 for each
                load or store of a peripheral register (APB1 at 45 MHz).
                An upper bound for a cold cache and no prefetch.

Usage: wcet_trace.py --elf build/.../pinball_driver_board_selftest.elf
                     [--qemu qemu-system-arm] [--objdump arm-none-eabi-objdump]
                     [--nm arm-none-eabi-nm] [--mhz 180] [--json] [--profile WINDOW]
"""

import argparse
import json
import re
import subprocess
import sys
import tempfile

FLASH_WAIT_STATES = 5
PIPELINE_REFILL = 3
PERIPHERAL_ACCESS = 8
# Functions whose loads and stores reach peripheral registers on the hot path.
PERIPHERAL_FUNCTIONS = {"coils_set_duty", "coils_apply", "coils_duty", "time_raw_count", "time_ns", "eos_read"}

# The mnemonics that cost more than one cycle, longest first so that a
# prefix match finds "ldrd" before "ldr"; a condition suffix (ldrne, popeq)
# or width suffix (.w, .n) follows the base. Everything else costs 1.
PRICED = ("ldrsb", "ldrsh", "ldrex", "ldrd", "ldrb", "ldrh", "ldm", "ldr",
          "strex", "strd", "strb", "strh", "stm", "str", "push", "pop",
          "tbb", "tbh", "mla", "mls", "udiv", "sdiv", "dmb", "dsb", "isb")


def base_mnemonic(mnemonic):
    """'ldr.w' -> 'ldr', 'ldmia' -> 'ldm', 'strbne' -> 'strb', 'adds' -> 'adds'."""
    m = mnemonic.split(".")[0]
    for base in PRICED:
        if m.startswith(base):
            return base
    return m


def register_count(operands):
    """Registers named in a {...} list, ranges like r4-r7 included."""
    inside = re.search(r"\{([^}]*)\}", operands)
    if not inside:
        return 1
    n = 0
    for part in inside.group(1).split(","):
        part = part.strip()
        r = re.match(r"r(\d+)-r(\d+)", part)
        n += int(r.group(2)) - int(r.group(1)) + 1 if r else 1
    return n


def load_disassembly(objdump, elf):
    out = subprocess.run([objdump, "-d", elf], check=True, capture_output=True, text=True).stdout
    code = {}
    functions = []  # (start, name)
    line = re.compile(r"^\s*([0-9a-f]+):\s+((?:[0-9a-f]{4}\s?){1,2})\s+(\S+)\s*(.*)$")
    for text in out.splitlines():
        f = re.match(r"^([0-9a-f]+) <([^>]+)>:$", text)
        if f:
            functions.append((int(f.group(1), 16), f.group(2)))
            continue
        m = line.match(text)
        if not m or m.group(3).startswith("."):
            continue
        size = 2 * len(m.group(2).split())
        code[int(m.group(1), 16)] = (size, m.group(3), m.group(4).split(";")[0].split("@")[0].strip())
    functions.sort()
    return code, functions


def function_of(functions, address):
    name = None
    for start, fname in functions:
        if start > address:
            break
        name = fname
    return name


def symbol(nm, elf, name):
    out = subprocess.run([nm, elf], check=True, capture_output=True, text=True).stdout
    for text in out.splitlines():
        parts = text.split()
        if len(parts) == 3 and parts[2] == name:
            return int(parts[0], 16) & ~1
    raise SystemExit(f"wcet_trace: symbol {name} not in {elf}")


class Window:
    def __init__(self):
        self.functions = {}  # name -> instructions executed in it
        self.instructions = 0
        self.core = 0
        self.lines = 0
        self.loads = 0
        self.peripheral = 0
        self.taken = 0

    def cold(self):
        return self.core + FLASH_WAIT_STATES * (self.lines + self.loads) + PERIPHERAL_ACCESS * self.peripheral

    def minus(self, other):
        w = Window()
        for k in ("instructions", "core", "lines", "loads", "peripheral", "taken"):
            setattr(w, k, getattr(self, k) - getattr(other, k))
        return w


def price(entry, taken):
    """Cycles of one executed instruction; (cycles, is_load, is_access)."""
    size, mnemonic, operands = entry
    m = base_mnemonic(mnemonic)
    writes_pc = taken
    if m in ("ldr", "ldrb", "ldrh", "ldrsb", "ldrsh", "ldrex"):
        c, load, access = 2, True, True
    elif m in ("str", "strb", "strh", "strex"):
        c, load, access = 2, False, True
    elif m in ("ldrd",):
        c, load, access = 3, True, True
    elif m in ("strd",):
        c, load, access = 3, False, True
    elif m in ("ldm", "pop"):
        c, load, access = 1 + register_count(operands), True, True
    elif m in ("stm", "push"):
        c, load, access = 1 + register_count(operands), False, True
    elif m in ("tbb", "tbh"):
        return 2 + PIPELINE_REFILL, True, True
    elif m in ("mla", "mls"):
        c, load, access = 2, False, False
    elif m in ("udiv", "sdiv"):
        c, load, access = 12, False, False
    elif m in ("dmb", "dsb", "isb"):
        c, load, access = 4, False, False
    else:
        c, load, access = 1, False, False
    if writes_pc:
        c += PIPELINE_REFILL
    return c, load, access


def run(args):
    code, functions = load_disassembly(args.objdump, args.elf)
    begin = symbol(args.nm, args.elf, "wcet_begin")
    end = symbol(args.nm, args.elf, "wcet_end")
    peripheral_ranges = set()
    for i, (start, name) in enumerate(functions):
        if name in PERIPHERAL_FUNCTIONS:
            stop = functions[i + 1][0] if i + 1 < len(functions) else start + 0x1000
            peripheral_ranges.add((start, stop))

    def in_peripheral_function(pc):
        return any(a <= pc < b for a, b in peripheral_ranges)

    # Semihosting output on stdout (the chardev), the execution log on stderr.
    cmd = [args.qemu, "-M", "netduinoplus2", "-display", "none", "-serial", "null", "-monitor", "none",
           "-icount", "shift=0", "-singlestep", "-d", "exec,nochain", "-D", "/dev/stderr",
           "-chardev", "stdio,id=semihosting",
           "-semihosting-config", "enable=on,target=native,chardev=semihosting", "-kernel", args.elf]
    windows = []
    current = None
    previous = None  # (pc, entry)
    trace = re.compile(r"^Trace \d+: \S+ \[[0-9a-f]+/([0-9a-f]+)/")
    with tempfile.TemporaryFile(mode="w+") as stdout:
        proc = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=stdout, stderr=subprocess.PIPE, text=True,
                                bufsize=1 << 20)
        for text in proc.stderr:
            t = trace.match(text)
            if not t:
                continue
            pc = int(t.group(1), 16)
            # Under -icount an instruction that touches a device register is
            # executed again in a block of its own, and logged twice; no
            # instruction but a branch to itself follows itself.
            if previous is not None and pc == previous[0] and not previous[1][1].startswith(("b", "cb")):
                continue
            if previous is not None and current is not None:
                ppc, pentry = previous
                taken = pc != ppc + pentry[0]
                c, load, access = price(pentry, taken)
                current.instructions += 1
                fname = function_of(functions, ppc)
                current.functions[fname] = current.functions.get(fname, 0) + 1
                current.core += c
                current.loads += 1 if load else 0
                current.taken += 1 if taken else 0
                if access and in_peripheral_function(ppc):
                    current.peripheral += 1
                if (pc >> 4) != (ppc >> 4):
                    current.lines += 1
            if pc == begin:
                current = Window()
                current.lines = 1
            elif pc == end and current is not None:
                windows.append(current)
                current = None
            entry = code.get(pc)
            previous = (pc, entry) if entry is not None else None
        rc = proc.wait()
        stdout.seek(0)
        output = stdout.read()
    names = [m.group(1) for m in re.finditer(r"^icount (\S+) (\d+)$", output, re.M)]
    icounts = {m.group(1): int(m.group(2)) for m in re.finditer(r"^icount (\S+) (\d+)$", output, re.M)}
    if rc != 0 or len(names) != len(windows) or not names or names[0] != "harness_overhead":
        sys.stderr.write(output)
        raise SystemExit(f"wcet_trace: self-test exit {rc}, {len(windows)} windows for {len(names)} counts")
    baseline = windows[0]
    rows = []
    for name, w in zip(names[1:], windows[1:]):
        d = w.minus(baseline)
        rows.append({
            "window": name,
            "instructions": d.instructions,
            "instructions_tim2": icounts[name],
            "taken_branches": d.taken,
            "loads": d.loads,
            "flash_lines": d.lines,
            "core_cycles": d.core,
            "cold_bound_cycles": d.cold(),
            "core_us": round(d.core / args.mhz, 2),
            "cold_bound_us": round(d.cold() / args.mhz, 2),
            "by_function": dict(sorted(w.functions.items(), key=lambda kv: -kv[1])),
        })
    return rows


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--elf", required=True)
    p.add_argument("--qemu", default="qemu-system-arm")
    p.add_argument("--objdump", default="arm-none-eabi-objdump")
    p.add_argument("--nm", default="arm-none-eabi-nm")
    p.add_argument("--mhz", type=float, default=180.0)
    p.add_argument("--json", action="store_true")
    p.add_argument("--profile", metavar="WINDOW", help="also list the instructions WINDOW spent in each function")
    args = p.parse_args()
    rows = run(args)
    if args.profile:
        for r in rows:
            if r["window"] == args.profile:
                print(f"instructions by function in {args.profile} (harness included):")
                for name, n in r["by_function"].items():
                    print(f"{n:8d}  {name}")
        print()
    if args.json:
        print(json.dumps(rows, indent=1))
        return
    print(f"| window | instructions (trace / TIM2) | core cycles | cold bound | at {args.mhz:g} MHz |")
    print("|---|---:|---:|---:|---:|")
    for r in rows:
        print(f"| {r['window']} | {r['instructions']} / {r['instructions_tim2']} | {r['core_cycles']} | "
              f"{r['cold_bound_cycles']} | {r['core_us']} .. {r['cold_bound_us']} us |")


if __name__ == "__main__":
    main()
