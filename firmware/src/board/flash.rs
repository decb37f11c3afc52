//! The two configuration slots in flash (`firmware::slots`): bank 2's last two 2 KiB pages
//! (the G474RE in its factory dual-bank mode; `memory.x` keeps the linker out of them).
//!
//! Program and erase by register (RM0440 §5.3.6–5.3.8), not through the HAL's blocking
//! driver, which holds a critical section for the whole erase (~22 ms) and every
//! double-word: the code runs from bank 1 while bank 2 is busy (read-while-write), so the
//! control interrupt keeps running, and the waits yield to the executor so the watchdog
//! task keeps petting. Reads go through [`read_slot`], which arms the NMI handler's ECC
//! guard: a double-word with an uncorrectable ECC error (a program cut by a reset) marks
//! the slot unusable instead of ending in a fault.

use core::sync::atomic::{AtomicBool, Ordering};

use embassy_stm32::pac;
use embassy_time::Timer;
use firmware::slots::{Slot, SLOT_BYTES};

/// Flash base and the slots' addresses: bank 2 pages 126 (A) and 127 (B).
const FLASH_BASE: u32 = 0x0800_0000;
const BANK2: u32 = 0x0804_0000;
const PAGE: u32 = 2048;
pub const SLOT_A: u32 = 0x0807_F000;
pub const SLOT_B: u32 = 0x0807_F800;

/// Set while [`read_slot`] reads; the NMI handler then records an ECC error in
/// [`ECC_HIT`] and returns instead of stopping.
pub static ECC_GUARD: AtomicBool = AtomicBool::new(false);
pub static ECC_HIT: AtomicBool = AtomicBool::new(false);

pub const fn address(slot: Slot) -> u32 {
    match slot {
        Slot::A => SLOT_A,
        Slot::B => SLOT_B,
    }
}

/// Why a flash operation failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub enum FlashError {
    /// An error flag in FLASH_SR (the raw register for the log).
    Status(u32),
    /// An address outside the slots.
    Range,
}

/// Read a slot; `Err(())` when a double-word of it had an uncorrectable ECC error.
pub fn read_slot(slot: Slot) -> Result<[u8; SLOT_BYTES], ()> {
    let base = address(slot);
    let mut out = [0u8; SLOT_BYTES];
    ECC_HIT.store(false, Ordering::SeqCst);
    ECC_GUARD.store(true, Ordering::SeqCst);
    for (i, chunk) in out.chunks_exact_mut(4).enumerate() {
        // SAFETY: inside the slot page, word-aligned, flash is always readable.
        let w = unsafe { ((base as usize + 4 * i) as *const u32).read_volatile() };
        chunk.copy_from_slice(&w.to_le_bytes());
    }
    cortex_m::asm::dsb();
    ECC_GUARD.store(false, Ordering::SeqCst);
    if ECC_HIT.swap(false, Ordering::SeqCst) {
        Err(())
    } else {
        Ok(out)
    }
}

/// The NMI handler's ECC check: clears a double ECC error flag; `true` when it happened
/// inside a guarded read (the NMI may then return).
pub fn take_ecc_error() -> bool {
    let eccr = pac::FLASH.eccr().read();
    if !eccr.eccd() {
        return false;
    }
    pac::FLASH.eccr().modify(|w| w.set_eccd(true));
    if ECC_GUARD.load(Ordering::SeqCst) {
        ECC_HIT.store(true, Ordering::SeqCst);
        true
    } else {
        false
    }
}

const KEY1: u32 = 0x4567_0123;
const KEY2: u32 = 0xCDEF_89AB;
/// Error flags of FLASH_SR: OPERR, PROGERR, WRPERR, PGAERR, SIZERR, PGSERR, MISSERR,
/// FASTERR, RDERR, OPTVERR.
const SR_ERRORS: u32 = 0b1100_0011_1111_1010;
const SR_BSY: u32 = 1 << 16;

fn unlock() {
    if pac::FLASH.cr().read().lock() {
        pac::FLASH.keyr().write_value(KEY1);
        pac::FLASH.keyr().write_value(KEY2);
    }
}

fn lock() {
    pac::FLASH.cr().modify(|w| {
        w.set_pg(false);
        w.set_per(false);
        w.set_lock(true);
    });
}

/// Wait for BSY to clear, yielding to the executor; then check and clear the flags.
async fn finish() -> Result<(), FlashError> {
    while pac::FLASH.sr().read().0 & SR_BSY != 0 {
        Timer::after_micros(200).await;
    }
    let sr = pac::FLASH.sr().read().0;
    // Write 1 to clear EOP and the error flags.
    pac::FLASH.sr().write_value(pac::flash::regs::Sr(sr & (SR_ERRORS | 1)));
    if sr & SR_ERRORS != 0 {
        Err(FlashError::Status(sr))
    } else {
        Ok(())
    }
}

/// Erase the slot's page and program `image` into it, the commit record (its last
/// double-word) last. A reset anywhere in here leaves the other slot as it was.
pub async fn program_slot(slot: Slot, image: &[u8; SLOT_BYTES]) -> Result<(), FlashError> {
    let base = address(slot);
    if !(BANK2..FLASH_BASE + 0x8_0000).contains(&base) {
        return Err(FlashError::Range);
    }
    unlock();
    let result = async {
        finish().await?;
        let page = ((base - BANK2) / PAGE) as u8;
        pac::FLASH.cr().modify(|w| {
            w.set_per(true);
            w.set_bker(true);
            w.set_pnb(page);
        });
        pac::FLASH.cr().modify(|w| w.set_strt(true));
        finish().await?;
        pac::FLASH.cr().modify(|w| {
            w.set_per(false);
            w.set_pg(true);
        });
        for (i, dw) in image.chunks_exact(8).enumerate() {
            if dw.iter().all(|b| *b == 0xFF) {
                continue; // erased already; programming 0xFF would only cost time
            }
            let lo = u32::from_le_bytes([dw[0], dw[1], dw[2], dw[3]]);
            let hi = u32::from_le_bytes([dw[4], dw[5], dw[6], dw[7]]);
            let at = (base as usize + 8 * i) as *mut u32;
            // The two words back to back (the programming starts on the second).
            critical_section::with(|_| {
                // SAFETY: inside the erased slot page, PG set, double-word aligned.
                unsafe {
                    at.write_volatile(lo);
                    at.add(1).write_volatile(hi);
                }
            });
            finish().await?;
        }
        Ok(())
    }
    .await;
    lock();
    result
}
