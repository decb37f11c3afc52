"""Firmware in the loop: run the shipping ELF on the emulated G474 (g474.py).

    run.py ELF control PERIODS TRACE.csv       from reset, closed loop on a coil model,
                                               enable and set-points over CAN; per period
                                               the trace holds what the control interrupt
                                               saw and wrote (compared with model-core on
                                               the host by tests/tests/firmware_in_loop.rs)
    run.py ELF board                           boot; the bring-up registers as JSON
    run.py ELF faults                          panic, HardFault, NMI, stuck interrupt,
                                               watchdog stall: MOE off in time
    run.py ELF powercut FLASH.bin PAGE.bin     FLASH.bin (both slots, A holding an old page)
                                               as the flash; PAGE.bin committed over CAN
                                               and cut at every flash operation: boots
                                               on the old or the new page

Prints one line per check and `N passed, M failed`; exit 1 on a failure.
"""
import os
import struct
import sys
import zlib

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import g474  # noqa: E402

QUIET = (2048, 2048, 2200)  # Hall mid-scale, zero current, 24.0 V


def sym(m, part):
    hits = [a for n, a in m.symbols.items() if part in n]
    if len(hits) != 1:
        raise SystemExit("symbol %s: %d matches" % (part, len(hits)))
    return hits[0]


def boot(m, periods=60):
    for _ in range(periods):
        m.period(QUIET)
    if m.read_u32(sym(m, "controller7SAMPLES")) == 0:
        raise AssertionError("control interrupt never ran")


def send(m, data, periods=4):
    for _ in range(50):
        if m.can.receive(m, 0x120, data):
            break
        m.period(QUIET)
    for _ in range(periods):
        m.period(QUIET)


class Host:
    """A host on CAN as `model_core::protocol::session` wants it: it claims the board, then
    every driving command carries its session and sequence number (the tag) and a deadline
    300 ms ahead of the board's clock, followed from the session reply's clock."""

    NONCE = 0x4242

    def __init__(self):
        self.tag = None  # the tag of the last command sent
        self.clock = None  # (board ms, emulated ns) at the session reply

    def claim_frame(self):
        return bytes([0x06]) + struct.pack("<H", self.NONCE)

    def take_session(self, m):
        """The session reply, once it has been sent (False before)."""
        for _, d in m.can.sent:
            if d[:1] == b"\x85" and struct.unpack("<H", d[1:3])[0] == self.NONCE:
                tag, ms = struct.unpack("<HH", d[3:7])
                self.tag = (tag & 0xF000) | ((tag - 1) & 0x0FFF)
                self.clock = (ms, m.now)
                return True
        return False

    def claim(self, m):
        send(m, self.claim_frame())
        for _ in range(200):
            if self.take_session(m):
                return
            m.period(QUIET)
        raise AssertionError("no session granted: %r" % m.can.sent[-3:])

    def guarded(self, m, code, payload=b""):
        self.tag = (self.tag & 0xF000) | ((self.tag + 1) & 0x0FFF)
        ms, at = self.clock
        deadline = (ms + (m.now - at) // 1_000_000 + 300) & 0xFFFF
        return bytes([code]) + struct.pack("<HH", self.tag, deadline) + payload

    def enable(self, m):
        return self.guarded(m, 0x02, b"\x01")

    def torque(self, m, v):
        milli = int(round(v * 1000))
        return self.guarded(m, 0x01, struct.pack("<i", milli)[:3])


def acked(sent, code):
    """Whether the board acknowledged a command with this byte."""
    return any(d[:2] == bytes([0x82, code]) for _, d in sent)


class Plant:
    """The coil and the Hall sensor, enough to keep the loop's plausibility checks quiet:
    i' = (V − R·i)/L with V = duty · supply, B = 0.2 T/A · i, 12-bit readings with the
    default configuration's scales and a small deterministic noise (a frozen Hall reading
    would trip the stuck-sensor check)."""

    R, L, DT = 4.0, 0.05, 1.0 / 20_000

    def __init__(self):
        self.i, self.seed = 0.0, 12345

    def noise(self):
        self.seed = (self.seed * 1103515245 + 12345) & 0x7FFF_FFFF
        return (self.seed >> 16) % 5 - 2

    def sample(self, supply_counts):
        b = 0.2 * self.i
        hall = int(round(2048 + b / (1.25 / 2048))) + self.noise()
        cur = int(round(2048 + self.i / (6.0 / 2048))) + self.noise()
        clamp = lambda x: max(0, min(4095, x))
        return clamp(hall), clamp(cur), supply_counts

    def advance(self, ccr1, ccr2, moe, supply_v):
        v = (ccr1 - ccr2) / 4250.0 * supply_v if moe else 0.0
        self.i += self.DT * (v - self.R * self.i) / self.L


def reference(k):
    """Torque reference (N·m): off, a step, a slow sine."""
    import math
    if k < 2000:
        return 0.0
    if k < 8000:
        return 1.5
    return 1.0 + 0.8 * math.sin(2 * math.pi * 5 * k / 20_000)


def control(elf, periods, trace_csv, flash_path=None):
    """Closed loop from reset (from the configuration slots in `flash_path` when given):
    every period's inputs and what the interrupt wrote."""
    m = g474.Machine(elf, flash_image=open(flash_path, "rb").read() if flash_path else None)
    plant = Plant()
    addr = {k: sym(m, p) for k, p in [("en", "controller6ENABLE"), ("ref", "controller9REFERENCE"),
                                       ("reset", "controller5RESET"), ("stall", "controller7STALLED"),
                                       ("slow", "controller11SLOW_PASSES"), ("n", "controller7SAMPLES")]}
    b = lambda a: m.uc.mem_read(a, 1)[0]
    out = open(trace_csv, "w")
    out.write("ran,hall,current,supply,enable,reference_bits,reset,stalled,slow,ccr1,ccr2,moe\n")
    supply = 2200
    supply_v = supply * (3.3 / 4095 * 11)
    driven = 0
    start = None  # the first period with a control step (a Preisach page boots in ~350)
    host = Host()
    for k in range(periods):
        if start is not None and k == start + 50:
            m.can.receive(m, 0x120, host.claim_frame())
        elif start is not None and k == start + 100:
            assert host.take_session(m), "no session granted by period %d" % k
            m.can.receive(m, 0x120, host.enable(m))
        elif start is not None and k > start + 100 and k % 20 == 0:
            # The set-point streamed at 1 kHz (the command timeout is 100 ms).
            m.can.receive(m, 0x120, host.torque(m, reference(k)))
        h, i, s = plant.sample(supply)
        seen = (b(addr["en"]), m.read_u32(addr["ref"]), b(addr["reset"]), b(addr["stall"]))
        slow0, n0 = m.read_u32(addr["slow"]), m.read_u32(addr["n"])
        m.period((h, i, s))
        ran = m.read_u32(addr["n"]) - n0
        if ran and start is None:
            start = k
        if ran > 1 or (ran == 0 and n0 > 0):
            raise AssertionError("period %d: %d control steps instead of 1" % (k, ran))
        slow = m.read_u32(addr["slow"]) - slow0
        c1, c2 = m.compares()
        moe = m.tim1.moe
        driven += moe
        plant.advance(c1, c2, moe, supply_v)
        out.write("%d,%d,%d,%d,%d,%d,%d,%d,%d,%d,%d,%d\n" % (ran, h, i, s, *seen, slow, c1, c2, int(moe)))
    out.close()
    if not acked(m.can.sent, 0x02):
        raise AssertionError("no ack of the enable command: %r" % m.can.sent[:3])
    print("control: %d periods traced from reset (first control step in period %d), bridge driving in %d" % (periods, start if start is not None else -1, driven))


def running(m, periods=200):
    """Enable with a torque reference and run until the bridge drives."""
    host = Host()
    host.claim(m)
    send(m, host.enable(m))
    for k in range(3000):
        if k % 20 == 0:
            m.can.receive(m, 0x120, host.torque(m, 2.0))
        m.period((2048 + (k % 7), 2048 + (k % 5), 2200))
        if m.tim1.moe:
            return True
    return False


def within_period(m, what, inject):
    """Inject a fault at a period start; MOE must be off by the end of that period."""
    assert m.tim1.moe, "%s: bridge not driving before the fault" % what
    inject(m)
    t0 = m.now
    try:
        m.period((2048, 2048, 2200))
    except g474.Unmodelled:
        pass  # the handler parks the core (UDF/loop): what counts is MOE
    ok = not m.tim1.moe
    print("%s: MOE %s by the end of the PWM period it happened in (%.0f µs)"
          % (what, "off" if ok else "STILL ON", g474.PERIOD_NS / 1000))
    return ok


def faults(elf):
    results = []

    def fresh():
        m = g474.Machine(elf)
        boot(m)
        assert running(m), "bridge never enabled"
        return m

    def panic(m):
        # The control interrupt returns into core::panicking::panic (as if its code had
        # panicked): the firmware's panic handler must turn the bridge off.
        p = sym(m, "panicking18panic_bounds_check")
        m.pend(g474.IRQ_ADC1_2)  # make sure we are inside the ISR
        m.uc.reg_write(g474.A.UC_ARM_REG_R0, 0x0800_0000)
        m.uc.reg_write(g474.A.UC_ARM_REG_R1, 4)
        m.uc.reg_write(g474.A.UC_ARM_REG_R2, 0x2000_0000)
        m.uc.reg_write(g474.A.UC_ARM_REG_PC, p | 1)
        m.idle = False

    results.append(within_period(fresh(), "panic", panic))
    results.append(within_period(fresh(), "HardFault", lambda m: m.pend(g474.EXC_HARDFAULT)))
    results.append(within_period(fresh(), "NMI", lambda m: m.pend(g474.EXC_NMI)))

    # A stuck control interrupt: every return of its body patched to spin (b .), so it
    # hangs after writing the compares with MOE on; the deadline monitor (TIM1 update,
    # above it) must clear MOE within one period.
    m = fresh()
    for at, size in m.returns_in("__cortex_m_rt_ADC1_2"):
        m.uc.mem_write(at, b"\xfe\xe7" + b"\x00\xbf" * ((size - 2) // 2))  # b . ; nop
        m.uc.ctl_remove_cache(at, at + size)  # drop the translated block
    n = sym(m, "controller7SAMPLES")
    missed_at = None  # end of the first period whose step did not run: its deadline
    for _ in range(4):
        before = m.read_u32(n)
        m.period((2048, 2048, 2200))
        if missed_at is None and m.read_u32(n) == before:
            missed_at = m.now
        if missed_at is not None and not m.tim1.moe:
            break
    late = (m.now - missed_at) / 1000 if missed_at is not None else float("inf")
    ok = not m.tim1.moe and late <= g474.PERIOD_NS / 1000
    print("stuck control interrupt: MOE %s %.0f µs after the first missed step's deadline"
          % ("off" if ok else "STILL ON", late))
    results.append(ok)

    # Watchdog stall: thread mode stops (time driver interrupts withheld): the IWDG must
    # reset the chip within its timeout, and after the reset MOE is off.
    m = fresh()
    m.enabled.discard(g474.IRQ_TIM1_BRK_TIM15)
    t0 = m.now
    reset_at = None
    try:
        for _ in range(int(0.2e9 / g474.PERIOD_NS)):
            m.period((2048, 2048, 2200))
    except g474.Reset as e:
        reset_at = m.now - t0
        m.boot(0x2000_0000, keep_flash=bytes(m.flash.array))  # IWDGRSTF
    ok = reset_at is not None and reset_at <= 60e6 and not m.tim1.moe
    print("watchdog stall: reset after %s ms, MOE %s" % ("%.1f" % (reset_at / 1e6) if reset_at else "never",
                                                        "off" if not m.tim1.moe else "ON"))
    results.append(ok)
    return results


def commit_frames(m, host, page):
    frames = [host.guarded(m, 0x10, struct.pack("<H", len(page)))]
    for off in range(0, len(page), 5):
        frames.append(bytes([0x11]) + struct.pack("<H", off) + page[off:off + 5])
    frames.append(bytes([0x12]) + struct.pack("<I", zlib.crc32(page) & 0xFFFF_FFFF))
    return frames


def source(m):
    """The configuration the firmware runs (app::CONFIG_SOURCE): (slot, seq)."""
    v = m.read_u32(sym(m, "app13CONFIG_SOURCE"))
    return ({0: "defaults", 1: "A", 2: "B", 3: "damaged"}[v & 3], v >> 2)


def commit(m, page, cut_at=None):
    """Send a page over CAN and wait for the commit's reply (or the cut's reset)."""
    m.flash.cut_at = cut_at
    host = Host()
    host.claim(m)
    m.can.sent.clear()
    for f in commit_frames(m, host, page):
        send(m, f, periods=1)
    for _ in range(4000):
        m.period(QUIET)
        if any(d[:1] in (b"\x82", b"\x83") and d[1] == 0x12 for _, d in m.can.sent):
            return m.can.sent[-1][1]
    raise AssertionError("no reply to the commit")


def reboot(m, csr):
    m.flash.cut_at = None
    m.boot(csr, keep_flash=bytes(m.flash.array))
    boot(m, 120)


def powercut(elf, flash_path, page_path):
    """Slot A holds the old page (commit 1); the new page goes to B (commit 2). A reset
    at every flash operation of the commit must boot A/1 or B/2, never the defaults."""
    flash = open(flash_path, "rb").read()
    page = open(page_path, "rb").read()
    m = g474.Machine(elf, flash_image=flash)
    boot(m)
    old = source(m)
    assert old == ("A", 1), "the old page did not boot: %r" % (old,)
    before = m.flash.ops
    reply = commit(m, page)
    assert reply[:2] == bytes([0x82, 0x12]), "commit refused: %r" % reply
    ops = m.flash.ops - before
    reboot(m, 0x0C00_0000)
    new = source(m)
    assert new == ("B", 2), "the new page did not boot: %r" % (new,)
    print("commit: %d flash operations (page erase + double-words, record last); old %r, new %r" % (ops, old, new))
    good, seen = 0, {}
    for cut in range(1, ops + 1):
        m = g474.Machine(elf, flash_image=flash)
        boot(m)
        try:
            commit(m, page, cut_at=m.flash.ops + cut)
            print("cut %d: the commit finished without reaching it" % cut)
            continue
        except g474.Reset:
            pass
        try:
            reboot(m, 0x0C00_0000)
            got = source(m)
        except (g474.Unmodelled, g474.Reset, AssertionError) as e:
            print("cut %d: not bootable: %s" % (cut, e))
            continue
        if got in (old, new):
            good += 1
            seen[got] = seen.get(got, 0) + 1
        else:
            print("cut %d: boots %r" % (cut, got))
    print("power cut: %d of %d interrupted commits boot the old or the new page (%s)"
          % (good, ops, ", ".join("%s/%d: %d" % (k[0], k[1], v) for k, v in sorted(seen.items()))))
    # Never silently: the old page's CRC broken (a flipped bit), slot B blank → the
    # defaults, reported as damaged, and the drive refused.
    bad = bytearray(flash)
    bad[100] ^= 0x01
    m = g474.Machine(elf, flash_image=bytes(bad))
    boot(m)
    got = source(m)
    drove = running(m)
    loud = got == ("damaged", 0) and not drove
    print("damaged slot, other blank: boots %r, bridge %s" % (got, "DRIVEN" if drove else "held off"))
    return [good == ops, loud]


def board(elf):
    """Boot and dump the registers the bring-up set (JSON on the last line); the Rust test
    checks them against the firmware's own numbers."""
    import json
    m = g474.Machine(elf)
    boot(m)
    p = {q.name: q for q in m.periph}
    ram = g474.Fdcan.RAM
    regs = {
        "rcc_cr": m.rcc.regs.get(0x00, 0), "rcc_pllcfgr": m.rcc.regs.get(0x0C, 0),
        "rcc_ccipr": m.rcc.regs.get(0x88, 0), "rcc_cfgr": m.rcc.regs.get(0x08, 0),
        "tim1_bdtr": m.tim1.regs.get(0x44, 0), "tim1_af1": m.tim1.regs.get(0x60, 0),
        "tim1_rcr": m.tim1.regs.get(0x30, 0), "tim1_cr2": m.tim1.regs.get(0x04, 0),
        "tim1_dier": m.tim1.regs.get(0x0C, 0), "tim1_arr": m.tim1.regs.get(0x2C, 0),
        "comp1_csr": p["COMP"].regs.get(0x00, 0), "dac3_dhr12r1": p["DAC3"].regs.get(0x08, 0),
        "dac3_cr": p["DAC3"].regs.get(0x00, 0), "dac3_mcr": p["DAC3"].regs.get(0x3C, 0),
        "syscfg_cfgr2": p["SYSCFG"].regs.get(0x1C, 0), "dbgmcu_apb1fzr1": p["DBGMCU"].regs.get(0x08, 0),
        "adc1_smpr1": m.adc.regs.get(0x14, 0), "adc1_smpr2": m.adc.regs.get(0x18, 0),
        "adc1_jsqr": m.adc.regs.get(0x4C, 0), "adc12_ccr": m.adc.regs.get(0x308, 0),
        "fdcan_nbtp": m.can.regs.get(0x1C, 0), "fdcan_rxgfc": m.can.regs.get(0x80, 0),
        "fdcan_flssa0": m.read_u32(ram), "iwdg_pr": m.iwdg.regs.get(0x04, 0), "iwdg_rlr": m.iwdg.regs.get(0x08, 0),
        "rcc_csr": m.rcc.read(m, 0x94),
        "prio": {str(k): v for k, v in sorted(m.prio.items()) if k in (18, 21, 22, 24, 25)},
        "enabled": sorted(i for i in m.enabled if i in (18, 21, 22, 24, 25)),
    }
    print(json.dumps(regs))


def main():
    g474.Machine.objdump = os.environ.get("OBJDUMP", "llvm-objdump")
    elf, what = sys.argv[1], sys.argv[2]
    if what == "board":
        board(elf)
        return
    if what == "control":
        control(elf, int(sys.argv[3]), sys.argv[4], sys.argv[5] if len(sys.argv) > 5 else None)
        return
    res = faults(elf) if what == "faults" else powercut(elf, sys.argv[3], sys.argv[4])
    p = sum(res)
    print("%d passed, %d failed" % (p, len(res) - p))
    sys.exit(0 if p == len(res) else 1)


if __name__ == "__main__":
    main()
