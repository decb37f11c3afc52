"""Firmware in the loop: run the shipping ELF on the emulated G474 (g474.py).

    run.py ELF control SAMPLES.csv TRACE.csv   boot, enable over CAN, one sample per PWM
                                               period from SAMPLES (hall,current,supply,
                                               reference); per period the trace holds what
                                               the control interrupt saw and wrote
    run.py ELF faults                          panic, HardFault, NMI, stuck interrupt,
                                               watchdog stall: MOE off in time
    run.py ELF powercut PAGE.bin               a configuration commit cut at every flash
                                               operation: boots on the old or new page

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


def control(elf, samples_csv, trace_csv):
    m = g474.Machine(elf)
    boot(m)
    send(m, bytes([0x02, 1]))
    addr = {k: sym(m, p) for k, p in [("en", "controller6ENABLE"), ("ref", "controller9REFERENCE"),
                                       ("reset", "controller5RESET"), ("stall", "controller7STALLED"),
                                       ("slow", "controller11SLOW_PASSES"), ("n", "controller7SAMPLES")]}
    rows = [tuple(float(x) for x in l.split(",")) for l in open(samples_csv).read().split()[1:]]
    out = open(trace_csv, "w")
    out.write("hall,current,supply,enable,reference_bits,reset,stalled,slow,ccr1,ccr2,moe\n")
    last_ref = None
    for k, (h, i, s, r) in enumerate(rows):
        bits = struct.unpack("<I", struct.pack("<f", r))[0]
        if bits != last_ref and k % 20 == 0:
            # Stream the set-point at 1 kHz (the command timeout is 100 ms).
            m.can.receive(m, 0x120, bytes([0x01]) + struct.pack("<f", r))
            last_ref = bits
        b = lambda a: m.uc.mem_read(a, 1)[0]
        seen = (b(addr["en"]), m.read_u32(addr["ref"]), b(addr["reset"]), b(addr["stall"]))
        slow0, n0 = m.read_u32(addr["slow"]), m.read_u32(addr["n"])
        m.period((int(h), int(i), int(s)))
        n1 = m.read_u32(addr["n"])
        if n1 != n0 + 1:
            raise AssertionError("period %d: %d control steps instead of 1" % (k, n1 - n0))
        slow = m.read_u32(addr["slow"]) - slow0
        c1, c2 = m.compares()
        out.write("%d,%d,%d,%d,%d,%d,%d,%d,%d,%d,%d\n" % (h, i, s, *seen, slow, c1, c2, int(m.tim1.moe)))
    out.close()
    print("control: %d periods traced (%.2f s of control at 20 kHz)" % (len(rows), len(rows) / 20000))


def running(m, periods=200):
    """Enable with a torque reference and run until the bridge drives."""
    send(m, bytes([0x02, 1]))
    for k in range(3000):
        if k % 20 == 0:
            m.can.receive(m, 0x120, bytes([0x01]) + struct.pack("<f", 2.0))
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
    print("%s: MOE %s within %.1f µs" % (what, "off" if ok else "STILL ON", (m.now - t0) / 1000))
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
        p = sym(m, "9panicking5panic17")
        m.pend(g474.IRQ_ADC1_2)  # make sure we are inside the ISR
        m.uc.reg_write(g474.A.UC_ARM_REG_R0, 0x0800_0000)
        m.uc.reg_write(g474.A.UC_ARM_REG_R1, 4)
        m.uc.reg_write(g474.A.UC_ARM_REG_R2, 0x0800_0000)
        m.uc.reg_write(g474.A.UC_ARM_REG_PC, p | 1)
        m.idle = False

    results.append(within_period(fresh(), "panic", panic))
    results.append(within_period(fresh(), "HardFault", lambda m: m.pend(g474.EXC_HARDFAULT)))
    results.append(within_period(fresh(), "NMI", lambda m: m.pend(g474.EXC_NMI)))

    # A stuck control interrupt: the ISR entry patched to spin (b .); the deadline monitor
    # (TIM1 update, above it) must clear MOE within one period.
    m = fresh()
    isr = m.read_u32(0x0800_0000 + 4 * (16 + g474.IRQ_ADC1_2)) & ~1
    m.uc.mem_write(isr, b"\xfe\xe7")
    t0 = m.now
    for _ in range(2):
        m.period((2048, 2048, 2200))
        if not m.tim1.moe:
            break
    ok = not m.tim1.moe and m.now - t0 <= 2 * g474.PERIOD_NS
    print("stuck control interrupt: MOE %s after %.1f µs" % ("off" if not m.tim1.moe else "STILL ON", (m.now - t0) / 1000))
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


def commit_frames(page):
    frames = [bytes([0x10]) + struct.pack("<H", len(page))]
    for off in range(0, len(page), 5):
        chunk = page[off:off + 5]
        frames.append(bytes([0x11]) + struct.pack("<H", off) + chunk)
    frames.append(bytes([0x12]) + struct.pack("<I", zlib.crc32(page) & 0xFFFF_FFFF))
    return frames


def loaded_slot(m):
    """Which page the booted firmware runs: read the commit task's view is not exported,
    so compare the configuration in RAM with the two pages' control words."""
    return None


def powercut(elf, page_path):
    page = open(page_path, "rb").read()
    page = page[:page.rfind(b"\xff" * 64)] if b"\xff" * 64 in page else page
    # The reference commit (no cut): count its flash operations.
    m = g474.Machine(elf)
    boot(m)
    before = m.flash.ops
    replies = m.can.sent
    for f in commit_frames(page):
        send(m, f, periods=1)
    for _ in range(3000):
        m.period(QUIET)
        if any(d[:1] == b"\x82" and d[1] == 0x12 for _, d in replies):
            break
    ops = m.flash.ops - before
    if not ops:
        raise AssertionError("commit did not program the flash: replies %r" % replies[-3:])
    new_image = bytes(m.flash.array)
    print("commit: %d flash operations (erase + double-words)" % ops)
    good = 0
    for cut in range(1, ops + 1):
        m = g474.Machine(elf)
        boot(m)
        old_image = bytes(m.flash.array)
        m.flash.cut_at = m.flash.ops + cut
        try:
            for f in commit_frames(page):
                send(m, f, periods=1)
            for _ in range(3000):
                m.period(QUIET)
            raise AssertionError("cut %d never happened" % cut)
        except g474.Reset:
            pass
        m.flash.cut_at = None
        m.boot(0x0C00_0000, keep_flash=bytes(m.flash.array))
        try:
            boot(m, 120)
            ok = m.read_u32(sym(m, "controller7SAMPLES")) > 0
        except (g474.Unmodelled, AssertionError) as e:
            print("cut %d: not bootable: %s" % (cut, e))
            ok = False
        good += ok
    print("power cut: %d of %d interrupted commits leave a bootable board" % (good, ops))
    return [good == ops]


def main():
    g474.Machine.objdump = os.environ.get("OBJDUMP", "llvm-objdump")
    elf, what = sys.argv[1], sys.argv[2]
    if what == "control":
        control(elf, sys.argv[3], sys.argv[4])
        return
    res = faults(elf) if what == "faults" else powercut(elf, sys.argv[3])
    p = sum(res)
    print("%d passed, %d failed" % (p, len(res) - p))
    sys.exit(0 if p == len(res) else 1)


if __name__ == "__main__":
    main()
