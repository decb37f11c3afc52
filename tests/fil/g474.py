"""An STM32G474 just large enough for this firmware, around Unicorn's Cortex-M4F.

Modelled from RM0440, only what embassy-stm32's init and the firmware touch: RCC/PWR/FLASH
ready bits, GPIO, TIM1 (update event = TRGO2, compare registers, MOE, break), TIM15 (the
time driver: counter, CC and update flags), ADC1's injected sequence and its interrupt,
FDCAN1's init handshake and message RAM (Rx FIFO 0, Tx buffers), LPUART1 as storage, IWDG (reset on expiry),
flash program/erase with their timing and ECC on half-programmed double-words, and the
core's NVIC/SCB/DWT. Any access to an address no model claims raises `Unmodelled`: a new
peripheral use cannot slip through.

Exceptions are taken by the harness (Unicorn has no NVIC): the full register file is
saved, a standard frame pushed, LR set to a return trampoline; the handler's return to
the trampoline restores the context.

Unicorn is GPL-2 (the `unicorn` wheel from PyPI); test-only, never linked into firmware.
"""
import struct

from elftools.elf.elffile import ELFFile
from unicorn import Uc, UcError, UC_ARCH_ARM, UC_MODE_THUMB, UC_MODE_MCLASS, UC_HOOK_CODE, UC_HOOK_MEM_UNMAPPED
from unicorn import arm_const as A

CORE_HZ = 170_000_000
PWM_HZ = 20_000
PERIOD_NS = 1_000_000_000 // PWM_HZ
TRAMPOLINE = 0x3000_0000
FLASH = 0x0800_0000
FLASH_SIZE = 512 * 1024
SLOT_A, SLOT_B = 0x0807_F000, 0x0807_F800

IRQ_ADC1_2, IRQ_FDCAN1_IT0, IRQ_FDCAN1_IT1 = 18, 21, 22
IRQ_TIM1_BRK_TIM15, IRQ_TIM1_UP_TIM16 = 24, 25
EXC_NMI, EXC_HARDFAULT = -14, -13

GPR = [A.UC_ARM_REG_R0 + i for i in range(13)] + [A.UC_ARM_REG_SP, A.UC_ARM_REG_LR, A.UC_ARM_REG_PC]
FPR = [getattr(A, f"UC_ARM_REG_S{i}") for i in range(32)]


class Unmodelled(Exception):
    pass


class Reset(Exception):
    """The chip resets (watchdog)."""


class Peripheral:
    """Plain storage registers in [base, base+size), with hooks for the ones that act."""

    def __init__(self, name, base, size, resets=None):
        self.name, self.base, self.size = name, base, size
        self.regs = dict(resets or {})

    def read(self, m, off):
        return self.regs.get(off, 0)

    def write(self, m, off, val):
        self.regs[off] = val


class Rcc(Peripheral):
    def __init__(self, csr_flags):
        super().__init__("RCC", 0x4002_1000, 0x400, {0x00: 0x63, 0x08: 0x5, 0x94: 0x0C00_0000 | csr_flags})

    def read(self, m, off):
        v = self.regs.get(off, 0)
        if off == 0x00:  # CR: ready follows on (HSI 8→10, HSE 16→17, PLL 24→25)
            v &= ~((1 << 10) | (1 << 17) | (1 << 25))
            v |= ((v >> 8) & 1) << 10 | ((v >> 16) & 1) << 17 | ((v >> 24) & 1) << 25
        elif off == 0x08:  # CFGR: SWS follows SW
            v = (v & ~0xC) | ((v & 3) << 2)
        elif off == 0x98:  # CRRCR: HSI48RDY follows HSI48ON
            v = (v & ~2) | ((v & 1) << 1)
        elif off in (0x90, 0x94):  # BDCR/CSR: LSERDY/LSIRDY follow ON
            v = (v & ~2) | ((v & 1) << 1)
        return v

    def write(self, m, off, val):
        if off == 0x94 and val & (1 << 23):  # RMVF clears the reset flags
            val &= 0x00FF_FFFF & ~(1 << 23)
        self.regs[off] = val


class Flash(Peripheral):
    """FLASH registers and the array: page erase ~22 ms, double-word program ~85 µs
    (RM0440 / DS12288 tPROG, tERASE), BSY while busy; a double-word cut mid-program reads
    back with an uncorrectable ECC error (NMI, FLASH_ECCR.ECCD)."""

    ERASE_NS, PROG_NS = 22_000_000, 85_000

    def __init__(self):
        super().__init__("FLASH", 0x4002_2000, 0x400, {0x00: 0x600, 0x14: 0xC000_0000})
        self.busy_until = 0
        self.pending = None  # what completes at busy_until
        self.latch = {}
        self.ecc_bad = set()
        self.ops = 0  # erase and program operations started
        self.cut_at = None  # reset when this operation is under way

    def get(self, addr, n=8):
        return bytes(self.array[addr - SLOT_A:addr - SLOT_A + n])

    def put(self, addr, data):
        self.array[addr - SLOT_A:addr - SLOT_A + len(data)] = data

    def read(self, m, off):
        if off == 0x10:  # SR
            v = self.regs.get(0x10, 0)
            if m.now < self.busy_until:
                v |= 1 << 16
            return v
        return self.regs.get(off, 0)

    def start(self, m, kind, arg, dur):
        if m.now < self.busy_until:
            raise Unmodelled("flash operation started while BSY")
        self.ops += 1
        self.busy_until = m.now + dur
        self.pending = (kind, arg)
        if self.cut_at is not None and self.ops == self.cut_at:
            # Power cut in the middle of this operation: half done.
            if kind == "erase":
                # Cut half-way: every other double-word erased, the rest unreadable.
                for a in range(arg, arg + 2048, 8):
                    if a % 16 == 0:
                        self.put(a, b"\xff" * 8)
                        self.ecc_bad.discard(a)
                    else:
                        self.ecc_bad.add(a)
            else:
                a, data = arg
                old = self.get(a)
                self.put(a, bytes(x & y for x, y in zip(old, data[:4] + b"\xff" * 4)))
                self.ecc_bad.add(a)
            raise Reset("power cut during flash operation %d (%s)" % (self.ops, kind))

    def complete(self, m):
        if self.pending and m.now >= self.busy_until:
            kind, arg = self.pending
            self.pending = None
            if kind == "erase":
                self.put(arg, b"\xff" * 2048)
                for a in range(arg, arg + 2048, 8):
                    self.ecc_bad.discard(a)
            else:
                a, data = arg
                self.put(a, bytes(x & y for x, y in zip(self.get(a), data)))
            self.regs[0x10] = self.regs.get(0x10, 0) | 1  # EOP

    def write(self, m, off, val):
        if off == 0x08:  # KEYR
            seq = self.regs.get("keys", [])
            seq = (seq + [val])[-2:]
            self.regs["keys"] = seq
            if seq == [0x4567_0123, 0xCDEF_89AB]:
                self.regs[0x14] = self.regs.get(0x14, 0) & ~(1 << 31)
            return
        if off == 0x10:  # SR: write 1 to clear
            self.regs[0x10] = self.regs.get(0x10, 0) & ~val
            return
        if off == 0x18:  # ECCR: ECCD/ECCC write 1 to clear
            self.regs[0x18] = (self.regs.get(0x18, 0) & ~(val & 0xC000_0000)) | (val & 0x3FFF_FFFF)
            return
        if off == 0x14:
            cr = self.regs.get(0x14, 0)
            if cr & (1 << 31) and val & 0x7FFF_FFFF:
                raise Unmodelled("FLASH_CR written while locked")
            self.regs[0x14] = val
            if val & (1 << 16) and val & 2:  # STRT with PER
                if not val & (1 << 11):
                    raise Unmodelled("page erase in bank 1 (the code)")
                page = (val >> 3) & 0x7F
                self.start(m, "erase", 0x0804_0000 + page * 2048, self.ERASE_NS)
                self.regs[0x14] = val & ~(1 << 16)
            return
        self.regs[off] = val

    def program_word(self, m, addr, val):
        cr = self.regs.get(0x14, 0)
        if not cr & 1 or cr & (1 << 31):
            raise Unmodelled("flash write without PG at 0x%08x" % addr)
        if addr < SLOT_A:
            raise Unmodelled("flash write outside the configuration slots at 0x%08x" % addr)
        self.latch[addr] = val
        if addr % 8 == 4:
            lo = self.latch.pop(addr - 4, None)
            if lo is None:
                raise Unmodelled("second word without the first at 0x%08x" % addr)
            self.start(m, "prog", (addr - 4, struct.pack("<II", lo, val)), self.PROG_NS)
        m.tick(200)


class Tim1(Peripheral):
    def __init__(self):
        super().__init__("TIM1", 0x4001_2C00, 0x400)

    @property
    def moe(self):
        return bool(self.regs.get(0x44, 0) & (1 << 15))

    def write(self, m, off, val):
        if off == 0x10:  # SR: rc_w0
            self.regs[0x10] = self.regs.get(0x10, 0) & val
            return
        if off == 0x44:  # BDTR: LOCK level 1 freezes DTG/BKE/BKP/AOE/BKF
            old = self.regs.get(0x44, 0)
            if old & 0x300:
                keep = 0xFF | (1 << 12) | (1 << 13) | (1 << 14) | 0xF0000 | 0x300
                val = (old & keep) | (val & ~keep)
            self.regs[0x44] = val
            return
        self.regs[off] = val


class Tim15(Peripheral):
    """The embassy time driver's timer: 1 MHz ticks (PSC), 16-bit counter, CC1..CC2."""

    def __init__(self):
        super().__init__("TIM15", 0x4001_4000, 0x400)
        self.t0 = 0

    def count(self, m):
        psc = self.regs.get(0x28, 0) + 1
        return ((m.now - self.t0) * CORE_HZ // 1_000_000_000 // psc) & 0xFFFF

    def read(self, m, off):
        if off == 0x24:
            return self.count(m)
        return self.regs.get(off, 0)

    def write(self, m, off, val):
        if off == 0x24:
            self.t0 = m.now
            return
        if off == 0x10:
            self.regs[0x10] = self.regs.get(0x10, 0) & val
            return
        if off == 0x14 and val & 1:  # UG
            self.t0 = m.now
            return
        self.regs[off] = val

    def advance(self, m, prev_ns):
        """Set the flags for counter events between prev_ns and now; pend the interrupt."""
        if not self.regs.get(0x00, 0) & 1:
            return
        psc = self.regs.get(0x28, 0) + 1
        a = (prev_ns - self.t0) * CORE_HZ // 1_000_000_000 // psc
        b = (m.now - self.t0) * CORE_HZ // 1_000_000_000 // psc
        if b <= a:
            return
        sr = self.regs.get(0x10, 0)
        if (b >> 16) != (a >> 16):
            sr |= 1
        for n in (1, 2):
            c = self.regs.get(0x34 + 4 * (n - 1), 0)
            # any k in (a, b] with k & 0xFFFF == c
            k = (a & ~0xFFFF) | c
            if k <= a:
                k += 0x10000
            if k <= b:
                sr |= 1 << n
        self.regs[0x10] = sr
        if sr & self.regs.get(0x0C, 0) & 0x7:
            m.pend(IRQ_TIM1_BRK_TIM15)


class Adc(Peripheral):
    """ADC1 (0x000) and the ADC12 common block (0x300): calibration, ready, injected
    sequence started by TIM1 TRGO2; JDR1..3 from the harness's samples."""

    def __init__(self):
        super().__init__("ADC12", 0x5000_0000, 0x400)
        self.samples = (2048, 2048, 2048)

    def read(self, m, off):
        v = self.regs.get(off, 0)
        if off == 0x08:  # CR: ADCAL self-clears; ADDIS clears ADEN
            v &= ~(1 << 31)
        return v

    def write(self, m, off, val):
        if off == 0x00:  # ISR: write 1 to clear
            self.regs[0] = self.regs.get(0, 0) & ~val
            return
        if off == 0x08:
            isr = self.regs.get(0, 0)
            if val & 1:  # ADEN → ADRDY
                isr |= 1
            if val & 2:  # ADDIS
                val &= ~3
            self.regs[0] = isr
            val &= ~(1 << 31)  # ADCAL done at once
            if val & (1 << 4) and val & (1 << 5):
                val &= ~(1 << 5)  # JADSTP
        self.regs[off] = val

    def trigger(self, m):
        """TIM1 TRGO2: convert the injected sequence if armed (JADSTART, JEXTEN≠0,
        JEXTSEL = TIM1_TRGO2 = 8)."""
        cr, jsqr = self.regs.get(0x08, 0), self.regs.get(0x4C, 0)
        if not (cr & 1 and cr & (1 << 3) and (jsqr >> 7) & 3):
            return False
        if (jsqr >> 2) & 0x1F != 8:
            raise Unmodelled("injected trigger is not TIM1_TRGO2 (JEXTSEL %d)" % ((jsqr >> 2) & 0x1F))
        for i, s in enumerate(self.samples):
            self.regs[0x80 + 4 * i] = s & 0xFFF
        self.regs[0] = self.regs.get(0, 0) | (1 << 5) | (1 << 6)  # JEOC, JEOS
        if self.regs.get(0x04, 0) & (1 << 6):  # JEOSIE
            m.pend(IRQ_ADC1_2)
        return True


class Fdcan(Peripheral):
    """FDCAN1 registers (0x000) with the message RAM (SRAMCAN, RM0440 §44.3.3 layout):
    INIT/CCE handshake, Rx FIFO 0 fed by the harness, Tx buffers captured."""

    RAM = 0x4000_A400
    RXF0 = 0x0B0
    TXB = 0x278

    def __init__(self):
        super().__init__("FDCAN1", 0x4000_6400, 0x400, {0x00: 0x3214_1218, 0x04: 0x8765_4321, 0x18: 1})
        self.sent = []

    def read(self, m, off):
        return self.regs.get(off, 0)

    def write(self, m, off, val):
        if off == 0x50:  # IR: write 1 to clear
            self.regs[0x50] = self.regs.get(0x50, 0) & ~val
            return
        if off == 0x94:  # RXF0A: acknowledge up to the index
            s = self.regs.get(0x90, 0)
            fill = s & 0xF
            get = (s >> 8) & 3
            n = (val - get) % 3 + 1 if fill else 0
            fill = max(0, fill - n)
            get = (val + 1) % 3
            self.regs[0x90] = (s & ~0x30F) | fill | (get << 8)
            return
        if off == 0xCC:  # TXBAR: transmit at once
            for i in range(3):
                if val & (1 << i):
                    base = self.RAM + self.TXB + 72 * i
                    w0, w1 = struct.unpack("<II", bytes(m.uc.mem_read(base, 8)))
                    dlc = (w1 >> 16) & 0xF
                    data = bytes(m.uc.mem_read(base + 8, 8))[:dlc]
                    self.sent.append(((w0 >> 18) & 0x7FF, data))
                    self.regs[0xD8] = self.regs.get(0xD8, 0) | (1 << i)  # TXBTO
            self.regs[0x50] = self.regs.get(0x50, 0) | (1 << 7)  # TC
            self.irq(m)
            return
        self.regs[off] = val

    def irq(self, m):
        ir, ie, ils, ile = (self.regs.get(o, 0) for o in (0x50, 0x54, 0x58, 0x5C))
        act = ir & ie
        if not act:
            return
        # ILS groups on the G4: bit per group; RxFIFO0 group bit0, TX group bit 4 (SMSG)
        line1 = 0
        if act & 0x7 and ils & 1:
            line1 = 1
        if line1 and ile & 2:
            m.pend(IRQ_FDCAN1_IT1)
        elif ile & 1:
            m.pend(IRQ_FDCAN1_IT0)

    def receive(self, m, ident, data):
        if self.regs.get(0x18, 0) & 1:
            return False  # still in INIT
        s = self.regs.get(0x90, 0)
        fill, get, put = s & 0xF, (s >> 8) & 3, (s >> 16) & 3
        if fill >= 3:
            return False
        base = self.RAM + self.RXF0 + 72 * put
        m.uc.mem_write(base, struct.pack("<II", (ident & 0x7FF) << 18, len(data) << 16))
        m.uc.mem_write(base + 8, bytes(data).ljust(64, b"\0"))
        self.regs[0x90] = (fill + 1) | (get << 8) | (((put + 1) % 3) << 16)
        self.regs[0x50] = self.regs.get(0x50, 0) | 1  # RF0N
        self.irq(m)
        return True

    def write_cccr(self, val):
        pass


class Iwdg(Peripheral):
    def __init__(self):
        super().__init__("IWDG", 0x4000_3000, 0x400, {0x04: 0, 0x08: 0xFFF})
        self.deadline = None
        self.frozen = False

    def read(self, m, off):
        if off == 0x0C:
            return 0  # SR: updates done at once
        return self.regs.get(off, 0)

    def timeout_ns(self):
        pr = self.regs.get(0x04, 0) & 7
        rl = self.regs.get(0x08, 0xFFF) & 0xFFF
        return (4 << pr) * (rl + 1) * 1_000_000_000 // 32_000

    def write(self, m, off, val):
        if off == 0x00:
            if val == 0xCCCC or (val == 0xAAAA and self.deadline is not None):
                self.deadline = m.now + self.timeout_ns()
            return
        self.regs[off] = val


class Scs(Peripheral):
    """NVIC, SCB, SysTick, DWT, DCB, FPU control (0xE000_0000–0xE00F_FFFF, the parts used)."""

    def __init__(self):
        super().__init__("SCS", 0xE000_0000, 0x10_0000)

    def read(self, m, off):
        if off == 0x1004:  # DWT CYCCNT
            return (m.now * CORE_HZ // 1_000_000_000 + m.insn_guess) & 0xFFFF_FFFF
        if 0xE100 <= off < 0xE120:
            return m.nvic_bits(m.enabled, (off - 0xE100) * 8)
        if 0xE180 <= off < 0xE1A0:
            return m.nvic_bits(m.enabled, (off - 0xE180) * 8)
        if 0xE200 <= off < 0xE220:
            return m.nvic_bits(m.pending, (off - 0xE200) * 8)
        if 0xE280 <= off < 0xE2A0:
            return m.nvic_bits(m.pending, (off - 0xE280) * 8)
        if 0xE400 <= off < 0xE4F0:
            return sum(m.prio.get((off - 0xE400) + i, 0) << (8 * i) for i in range(4))
        if off == 0xED00:
            return 0x410FC241  # CPUID Cortex-M4 r0p1
        return self.regs.get(off, 0)

    def write(self, m, off, val):
        if 0xE100 <= off < 0xE120:
            m.nvic_set(m.enabled, (off - 0xE100) * 8, val, True)
        elif 0xE180 <= off < 0xE1A0:
            m.nvic_set(m.enabled, (off - 0xE180) * 8, val, False)
        elif 0xE200 <= off < 0xE220:
            m.nvic_set(m.pending, (off - 0xE200) * 8, val, True)
        elif 0xE280 <= off < 0xE2A0:
            m.nvic_set(m.pending, (off - 0xE280) * 8, val, False)
        elif 0xE400 <= off < 0xE4F0:
            for i in range(4):
                m.prio[(off - 0xE400) + i] = (val >> (8 * i)) & 0xFF
        elif off == 0xED04:  # ICSR: PENDSVSET
            if val & (1 << 28):
                m.pend(-2)
        else:
            self.regs[off] = val


def window(name, base, size, resets=None):
    return Peripheral(name, base, size, resets)


class Machine:
    def __init__(self, elf_path, flash_image=None, csr_flags=0x0400_0000):
        self.elf_path = elf_path
        self.now = 0
        self.insn_guess = 0
        self.flash = Flash()
        self.flash_image = flash_image
        self.boot(csr_flags)

    # -- construction -------------------------------------------------------------
    def boot(self, csr_flags, keep_flash=None):
        self.uc = uc = Uc(UC_ARCH_ARM, UC_MODE_THUMB | UC_MODE_MCLASS)
        uc.ctl_set_cpu_model(A.UC_CPU_ARM_CORTEX_M4)
        uc.mem_map(FLASH, SLOT_A - FLASH)
        uc.mmio_map(SLOT_A, 0x1000, self._slot_rd, None, self._slot_wr, None)
        uc.mem_map(0x2000_0000, 128 * 1024)
        uc.mem_map(0x1000_0000, 32 * 1024)  # CCM SRAM (memory.x: `.ccmram`, the Preisach slots)
        uc.mem_map(0x1FFF_0000, 0x10000)  # system memory: UID, flash size, package
        uc.mem_map(TRAMPOLINE, 0x1000)
        uc.mem_write(TRAMPOLINE, b"\xfe\xe7" * 8)  # b .
        with open(self.elf_path, "rb") as f:
            elf = ELFFile(f)
            for seg in elf.iter_segments():
                if seg["p_type"] == "PT_LOAD" and seg["p_filesz"]:
                    uc.mem_write(seg["p_paddr"], seg.data())
            self.symbols = {}
            for sec in elf.iter_sections():
                if sec.name == ".symtab":
                    for s in sec.iter_symbols():
                        if s["st_value"]:
                            self.symbols[s.name] = s["st_value"]
        if keep_flash is not None:
            self.flash.array = bytearray(keep_flash)
        elif self.flash_image is not None:
            self.flash.array = bytearray(self.flash_image)
        else:
            self.flash.array = bytearray(b"\xff" * 4096)
        uc.mem_write(0x1FFF_75E0, struct.pack("<H", 512))  # flash size, KiB
        self.flash.busy_until, self.flash.pending, self.flash.latch = 0, None, {}
        self.flash.regs = {0x00: 0x600, 0x14: 0xC000_0000}
        self.tim1, self.tim15, self.adc, self.can, self.iwdg = Tim1(), Tim15(), Adc(), Fdcan(), Iwdg()
        self.scs = Scs()
        self.rcc = Rcc(csr_flags)
        self.periph = [
            self.rcc, self.flash, self.tim1, self.tim15, self.adc, self.can, self.iwdg,
            window("PWR", 0x4000_7000, 0x400, {0x14: 0}),
            # LPUART1 (the serial link): configured, never spoken to here; ISR reads
            # transmitter/receiver enabled and an empty transmit register.
            window("LPUART1", 0x4000_8000, 0x400, {0x1C: 0x0060_00C0}),
            window("GPIOA", 0x4800_0000, 0x400, {0x00: 0xABFF_FFFF}),
            window("GPIOB", 0x4800_0400, 0x400, {0x00: 0xFFFF_FEBF}),
            window("GPIOC", 0x4800_0800, 0x400, {0x00: 0xFFFF_FFFF}),
            window("GPIOD", 0x4800_0C00, 0x400),
            window("GPIOE", 0x4800_1000, 0x400),
            window("GPIOF", 0x4800_1400, 0x400),
            window("GPIOG", 0x4800_1800, 0x400),
            window("SYSCFG", 0x4001_0000, 0x200),
            window("COMP", 0x4001_0200, 0x200),
            window("EXTI", 0x4001_0400, 0x400),
            window("DAC3", 0x5000_1000, 0x400),
            window("DBGMCU", 0xE004_2000, 0x100),
            self.scs,  # last: the DBGMCU window lies inside its range
        ]
        self.fdcan_ram = (Fdcan.RAM, 0x350 * 3)
        uc.mmio_map(0x4000_0000, 0xA000, self._rd, 0x4000_0000, self._wr, 0x4000_0000)
        uc.mmio_map(0x4000_B000, 0x2_5000, self._rd, 0x4000_B000, self._wr, 0x4000_B000)
        uc.mmio_map(0x4800_0000, 0x2000, self._rd, 0x4800_0000, self._wr, 0x4800_0000)
        uc.mmio_map(0x5000_0000, 0x2000, self._rd, 0x5000_0000, self._wr, 0x5000_0000)
        uc.mmio_map(0xE000_0000, 0x10_0000, self._rd, 0xE000_0000, self._wr, 0xE000_0000)
        uc.mem_map(0x4000_A000, 0x1000)  # SRAMCAN (message RAM) as plain RAM
        uc.hook_add(UC_HOOK_MEM_UNMAPPED, self._unmapped)
        uc.hook_add(UC_HOOK_CODE, self._trampoline, begin=TRAMPOLINE, end=TRAMPOLINE + 16)
        self.wfe = self._find_wfe()
        for a in self.wfe:
            uc.hook_add(UC_HOOK_CODE, self._at_wfe, begin=a, end=a)
        self.enabled, self.pending, self.prio = set(), set(), {}
        self.stack = []
        self.idle = False
        self.fault = None
        vt = bytes(uc.mem_read(FLASH, 8))
        sp, pc = struct.unpack("<II", vt)
        uc.reg_write(A.UC_ARM_REG_SP, sp)
        uc.reg_write(A.UC_ARM_REG_PC, pc | 1)
        self.pc = pc | 1

    def _find_wfe(self):
        import subprocess
        out = subprocess.run([self.objdump, "-d", "--no-show-raw-insn", self.elf_path],
                             capture_output=True, text=True, check=True).stdout
        self.disassembly = out
        return [int(l.split(":")[0], 16) for l in out.splitlines() if l.strip().endswith("\twfe") or l.rstrip().endswith(" wfe")]

    objdump = "llvm-objdump"

    # -- memory -------------------------------------------------------------------
    def _find(self, addr):
        for p in self.periph:
            if p.base <= addr < p.base + p.size:
                return p
        raise Unmodelled("unmodelled register 0x%08x" % addr)

    def _rd(self, uc, off, size, base):
        addr = base + off
        p = self._find(addr & ~3)
        v = p.read(self, (addr & ~3) - p.base)
        sh = (addr & 3) * 8
        return (v >> sh) & ((1 << (8 * size)) - 1)

    def _wr(self, uc, off, size, val, base):
        addr = base + off
        p = self._find(addr & ~3)
        o = (addr & ~3) - p.base
        if size < 4:
            sh = (addr & 3) * 8
            mask = ((1 << (8 * size)) - 1) << sh
            val = (p.read(self, o) & ~mask) | ((val << sh) & mask)
        p.write(self, o, val)

    def _unmapped(self, uc, access, addr, size, value, ud):
        self.fault = "unmapped access 0x%08x at pc 0x%08x" % (addr, uc.reg_read(A.UC_ARM_REG_PC))
        return False

    ecc_latched = None

    def _slot_rd(self, uc, off, size, ud):
        # An uncorrectable double-word raises the NMI once: the stop below makes Unicorn
        # re-execute the load after the handler returns, which must then just read.
        a = off & ~7
        if SLOT_A + a != self.ecc_latched:
            self.ecc_latched = None
        if SLOT_A + a in self.flash.ecc_bad and self.ecc_latched is None:
            self.ecc_latched = SLOT_A + a
            self.flash.regs[0x18] = (self.flash.regs.get(0x18, 0) | (1 << 31)) & ~0x7FFFF | ((SLOT_A + a) & 0x7FFFF)
            self.pend_nmi = True
            uc.emu_stop()
        return int.from_bytes(self.flash.array[off:off + size], "little")

    def _slot_wr(self, uc, off, size, val, ud):
        if size != 4:
            raise Unmodelled("flash write of %d bytes" % size)
        self.flash.program_word(self, SLOT_A + off, val)

    pend_nmi = False

    # -- NVIC ---------------------------------------------------------------------
    def nvic_bits(self, s, first):
        return sum(1 << i for i in range(32) if first + i in s)

    def nvic_set(self, s, first, val, on):
        for i in range(32):
            if val & (1 << i):
                (s.add if on else s.discard)(first + i)

    def pend(self, irq):
        self.pending.add(irq)

    def priority(self, irq):
        if irq == EXC_NMI:
            return -2
        if irq == EXC_HARDFAULT:
            return -1
        if irq < 0:
            return 256
        return self.prio.get(irq, 0)

    def deliverable(self):
        primask = self.uc.reg_read(A.UC_ARM_REG_PRIMASK)
        basepri = self.uc.reg_read(A.UC_ARM_REG_BASEPRI)
        cur = self.stack[-1][0] if self.stack else 1000
        best = None
        for irq in self.pending:
            if irq >= 0 and irq not in self.enabled:
                continue
            p = self.priority(irq)
            if irq >= 0 and (primask or (basepri and p >= basepri)):
                continue
            if p < self.priority(cur) if self.stack else True:
                if best is None or p < self.priority(best) or (p == self.priority(best) and irq < best):
                    best = irq
        return best

    def enter(self, irq):
        uc = self.uc
        self.pending.discard(irq)
        regs = [uc.reg_read(r) for r in GPR]
        fregs = [uc.reg_read(r) for r in FPR]
        xpsr = uc.reg_read(A.UC_ARM_REG_XPSR)
        fpscr = uc.reg_read(A.UC_ARM_REG_FPSCR)
        pc = regs[15]
        if self.idle:
            pc = self.idle_pc + 2
            self.idle = False
        sp = regs[13]
        frame_sp = (sp - 32) & ~7
        uc.mem_write(frame_sp, struct.pack("<8I", regs[0], regs[1], regs[2], regs[3], regs[12], regs[14], pc & ~1, xpsr | (1 << 24)))
        self.stack.append((irq, regs[:15] + [pc | 1], fregs, xpsr, fpscr))
        vec = 16 + irq
        handler = struct.unpack("<I", bytes(uc.mem_read(FLASH + 4 * vec, 4)))[0]
        uc.reg_write(A.UC_ARM_REG_SP, frame_sp)
        uc.reg_write(A.UC_ARM_REG_LR, TRAMPOLINE | 1)
        uc.reg_write(A.UC_ARM_REG_PC, handler | 1)

    def _trampoline(self, uc, addr, size, ud):
        if not self.stack:
            self.fault = "exception return with no exception active"
            uc.emu_stop()
            return
        irq, regs, fregs, xpsr, fpscr = self.stack.pop()
        for r, v in zip(GPR, regs):
            uc.reg_write(r, v)
        for r, v in zip(FPR, fregs):
            uc.reg_write(r, v)
        uc.reg_write(A.UC_ARM_REG_XPSR, xpsr)
        uc.reg_write(A.UC_ARM_REG_FPSCR, fpscr)
        self.returned = True
        uc.emu_stop()

    def _at_wfe(self, uc, addr, size, ud):
        if not self.stack:
            self.idle = True
            self.idle_pc = addr
            uc.emu_stop()

    # -- running ------------------------------------------------------------------
    def tick(self, ns):
        self.now += ns

    def run_cpu(self, budget_insns):
        """Run until idle (WFE in thread mode) or `budget_insns` instructions; deliver
        interrupts as they become deliverable. Advances time by the instructions run."""
        uc = self.uc
        left = budget_insns
        while left > 0:
            if self.pend_nmi:
                self.pend_nmi = False
                self.pending.add(EXC_NMI)
            irq = self.deliverable()
            if irq is not None:
                self.enter(irq)
            elif self.idle:
                return
            self.returned = False
            pc = uc.reg_read(A.UC_ARM_REG_PC)
            chunk = min(left, 2000)
            try:
                uc.emu_start(pc | 1, 0xFFFF_FFFF, count=chunk)
            except UcError as e:
                self.fault = self.fault or "%s at pc 0x%08x" % (e, uc.reg_read(A.UC_ARM_REG_PC))
                raise Unmodelled(self.fault)
            if self.fault:
                raise Unmodelled(self.fault)
            # Rough instruction accounting: a stop (idle/return) used part of the chunk.
            used = chunk if not (self.idle or self.returned) else chunk // 4
            left -= used
            self.now += used * 1_000_000_000 // CORE_HZ
            self.flash.complete(self)
            self.watchdog()

    def watchdog(self):
        if self.iwdg.deadline is not None and self.now > self.iwdg.deadline:
            raise Reset("independent watchdog")

    def period(self, samples, budget=8500):
        """One PWM period: update event (TRGO2 → ADC), then the CPU for a period."""
        start = self.now
        if self.tim1.regs.get(0x00, 0) & 1:
            sr = self.tim1.regs.get(0x10, 0) | 1
            self.tim1.regs[0x10] = sr
            if self.tim1.regs.get(0x0C, 0) & 1:
                self.pend(IRQ_TIM1_UP_TIM16)
            self.adc.samples = samples
            self.adc.trigger(self)
        self.run_cpu(budget)
        self.now = max(self.now, start + PERIOD_NS)
        self.tim15.advance(self, start)
        self.flash.complete(self)
        self.watchdog()

    # -- observation ---------------------------------------------------------------
    def compares(self):
        return self.tim1.regs.get(0x34, 0), self.tim1.regs.get(0x38, 0)

    def returns_in(self, function):
        """(address, size) of every return (`pop {.., pc}`, `bx lr`) in the function whose
        llvm-objdump name contains `function`."""
        inside, lines = False, []
        for line in self.disassembly.splitlines():
            if line.endswith(">:") and function in line:
                inside = True
            elif inside and line.strip() == "":
                break
            elif inside and ":" in line:
                lines.append(line)
        out = []
        for this, nxt in zip(lines, lines[1:] + [None]):
            ins = this.split("\t", 1)[-1]
            if ("pop" in ins and "pc" in ins) or ins.startswith("bx\tlr"):
                a = int(this.split(":")[0], 16)
                size = int(nxt.split(":")[0], 16) - a if nxt else 2
                out.append((a, size))
        if not out:
            raise Unmodelled("no return in %s" % function)
        return out

    def in_handler(self):
        return [s[0] for s in self.stack]

    def read_u32(self, addr):
        return struct.unpack("<I", bytes(self.uc.mem_read(addr, 4)))[0]
