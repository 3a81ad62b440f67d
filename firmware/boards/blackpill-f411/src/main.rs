//! margemu firmware for the WeAct STM32F411CEU6 "Black Pill": the emulated chip (an MPU-9250
//! with its AK8963 until the host configures another model) on SPI1 and I2C1, its INT pin on
//! PB0, and the host link on USB CDC.
//!
//! Contexts, most urgent first:
//! - EXTI4 (NSS falling, priority 0): serves each SPI transaction from a shadow of the register
//!   file with a speculative DMA preload ([`spi`], [`margemu_firmware::spi_shadow`]);
//! - I2C1_EV/ER (priority 0x10): drive the chip's I2C target, the bus held by clock stretching
//!   while the main loop has the device ([`i2c`], [`device`]);
//! - the main loop: USB, the link handler ([`margemu_firmware::link::Device`]) fed and polled on
//!   the TIM5 time base ([`clock`]), the SPI transactions replayed into the chip and judged, the
//!   shadow refreshed with the speculator's prediction, the INT pin and the I2C addresses
//!   updated. The chip's bus faults (`margemu_firmware::bus_fault`) apply on both buses: on
//!   SPI to the shadow ([`Shadow::apply_bus_faults`]) and to the replay, on I2C in [`i2c`].
//!
//! [`Shadow::apply_bus_faults`]: margemu_firmware::spi_shadow::Shadow::apply_bus_faults
//!
//! Clocks: 25 MHz HSE → SYSCLK 96 MHz (the closest to the F411's 100 MHz that gives USB its
//! 48 MHz from the same PLL), APB1 48 MHz, APB2 96 MHz. Untested on hardware; see
//! docs/boards/blackpill-f411.md.
#![no_std]
#![no_main]

mod clock;
mod device;
mod i2c;
mod int_pin;
mod spi;
mod usb;

use core::cell::UnsafeCell;
use core::panic::PanicInfo;

use cortex_m::peripheral::SCB;
use cortex_m_rt::{entry, exception, ExceptionFrame};
use margemu_firmware::bus_fault::BusFaults;
use margemu_firmware::chip::Chip;
use margemu_firmware::link::Identity;
use margemu_firmware::protocol::link::{FirmwareVersion, ResetCause, DEVICE_ID_LEN};
use margemu_firmware::spi_shadow::{replay, Speculator, Stats};
use stm32f4xx_hal::gpio::Speed;
use stm32f4xx_hal::pac::{self, TIM5};
use stm32f4xx_hal::prelude::*;
use stm32f4xx_hal::rcc::{BusTimerClock, Config};

use crate::clock::Clock;
use crate::int_pin::IntPin;
use crate::spi::SpiTarget;
use crate::usb::UsbLink;

/// The Black Pill's crystal.
const HSE_HZ: u32 = 25_000_000;
const SYSCLK_HZ: u32 = 96_000_000;
const PCLK1_HZ: u32 = 48_000_000;
/// Most received bytes fed to the device in one go.
const RX_CHUNK: usize = 256;
/// RM0383, "Unique device ID register (96 bits)".
const UID_ADDRESS: usize = 0x1FFF_7A10;
const UID_LEN: usize = 12;

/// SPI serving figures ([`Stats`]), for a debugger (`probe-rs`/gdb: symbol `SPI_STATS`): the
/// link protocol has no field for them.
#[used]
#[no_mangle]
static SPI_STATS: StatsCell = StatsCell(UnsafeCell::new(Stats {
    transactions: 0,
    empty: 0,
    writes: 0,
    hits: 0,
    fixed: 0,
    misses: 0,
    stale: 0,
    truncated: 0,
    dropped: 0,
}));

struct StatsCell(UnsafeCell<Stats>);
// SAFETY: written by the main loop only; a debugger reads it with the core halted.
unsafe impl Sync for StatsCell {}

#[entry]
fn main() -> ! {
    let Some(dp) = pac::Peripherals::take() else {
        panic!("peripherals taken once");
    };
    let cause = reset_cause(&dp.RCC);
    let mut rcc = dp.RCC.freeze(
        Config::hse(HSE_HZ.Hz())
            .sysclk(SYSCLK_HZ.Hz())
            .pclk1(PCLK1_HZ.Hz())
            .require_pll48clk(),
    );
    let gpioa = dp.GPIOA.split(&mut rcc);
    let gpiob = dp.GPIOB.split(&mut rcc);
    let _spi_pins = (
        gpioa.pa4.into_alternate::<5>(),
        gpioa.pa5.into_alternate::<5>(),
        gpioa.pa6.into_alternate::<5>().speed(Speed::VeryHigh),
        gpioa.pa7.into_alternate::<5>(),
    );
    let _i2c_pins = (
        gpiob.pb6.into_alternate_open_drain::<4>(),
        gpiob.pb7.into_alternate_open_drain::<4>(),
    );
    let mut int = IntPin::new(gpiob.pb0.into_push_pull_output());

    let timer_hz = TIM5::timer_clock(&rcc.clocks).raw();
    let pclk1_hz = rcc.clocks.pclk1().raw();
    let mut clock = Clock::start(dp.TIM5, &mut rcc, timer_hz);
    let uid = unique_id();
    device::install(identity(&uid), cause);
    let usb = stm32f4xx_hal::otg_fs::USB::new(
        (dp.OTG_FS_GLOBAL, dp.OTG_FS_DEVICE, dp.OTG_FS_PWRCLK),
        (gpioa.pa11, gpioa.pa12),
        &rcc.clocks,
    );
    let mut link = UsbLink::new(usb, serial_number(&uid));
    let mut spi = SpiTarget::init(dp.SPI1, dp.DMA2, &mut rcc);
    i2c::init(dp.I2C1, &mut rcc, pclk1_hz);

    // Device 0's bus faults on SPI1 (the I2C target keeps its own, `i2c::configure`).
    let spi_faults: &'static mut BusFaults =
        cortex_m::singleton!(: BusFaults = BusFaults::new(0)).expect("made once");
    let mut speculator = Speculator::new();
    let mut stats = Stats::default();
    let mut generation = 0u32;
    let mut shadow_stale = true;
    let mut rx = [0u8; RX_CHUNK];
    loop {
        link.poll();
        let n = link.read(&mut rx);
        let now = clock.now_ns();
        device::lock(|device| {
            spi_faults.sync(device.faults());
            // Transactions first: they happened before anything fed or served now.
            while let Some(capture) = spi.take() {
                let chip = device.chip_mut();
                let at = chip.now_ns();
                let outcome = replay(&mut spi_faults.on(chip, at), &capture, generation);
                stats.record(outcome);
                speculator.observe(&capture);
                shadow_stale = true;
            }
            if i2c::take_activity() {
                generation = generation.wrapping_add(1);
                shadow_stale = true;
            }
            if n > 0 {
                device.feed(&rx[..n], now);
                generation = generation.wrapping_add(1);
                shadow_stale = true;
            }
            let served = device.counters().served;
            device.poll(now, &mut |frame: &[u8]| link.send(frame));
            if device.counters().served != served {
                generation = generation.wrapping_add(1);
                shadow_stale = true;
            }
            if shadow_stale {
                if let Some(back) = spi.back() {
                    let chip = device.chip();
                    back.capture(chip, speculator.predict(chip.burst_start()), generation);
                    back.apply_bus_faults(spi_faults, chip.now_ns());
                    spi.publish();
                    shadow_stale = false;
                }
            }
            int.set(device.int_pin_at(0, now), device.chip().int_open_drain());
            i2c::configure(device.rig(), device.faults());
        });
        stats.dropped = spi.dropped();
        // SAFETY: the main loop is the only writer (see `StatsCell`).
        unsafe { *SPI_STATS.0.get() = stats };
    }
}

/// Why the MCU booted (RCC_CSR reset flags), then clears the flags. The pin flag is
/// set by every reset, so it counts only when no other is.
fn reset_cause(rcc: &pac::RCC) -> ResetCause {
    let csr = rcc.csr().read();
    let cause = if csr.borrstf().bit_is_set() && csr.porrstf().bit_is_clear() {
        ResetCause::Brownout
    } else if csr.porrstf().bit_is_set() {
        ResetCause::PowerOn
    } else if csr.wdgrstf().bit_is_set() || csr.wwdgrstf().bit_is_set() {
        ResetCause::Watchdog
    } else if csr.sftrstf().bit_is_set() {
        ResetCause::Software
    } else if csr.padrstf().bit_is_set() {
        ResetCause::Pin
    } else {
        ResetCause::Unknown
    };
    rcc.csr().modify(|_, w| w.rmvf().set_bit());
    cause
}

fn unique_id() -> [u8; UID_LEN] {
    let mut uid = [0u8; UID_LEN];
    for (i, byte) in uid.iter_mut().enumerate() {
        // SAFETY: the factory-programmed, read-only UID bytes of every STM32F411.
        *byte = unsafe { core::ptr::read_volatile((UID_ADDRESS + i) as *const u8) };
    }
    uid
}

/// HelloAck's identity: this crate's version, and the MCU's unique ID as the device ID.
fn identity(uid: &[u8; UID_LEN]) -> Identity {
    let part = |s: &str| s.parse().unwrap_or(0);
    let mut device_id = [0u8; DEVICE_ID_LEN];
    device_id[..UID_LEN].copy_from_slice(uid);
    Identity {
        firmware: FirmwareVersion {
            major: part(env!("CARGO_PKG_VERSION_MAJOR")),
            minor: part(env!("CARGO_PKG_VERSION_MINOR")),
            patch: part(env!("CARGO_PKG_VERSION_PATCH")),
        },
        device_id,
    }
}

/// The unique ID in hex, for the USB serial number string.
fn serial_number(uid: &[u8; UID_LEN]) -> &'static str {
    const HEX: &[u8; 16] = b"0123456789ABCDEF";
    let text: &'static mut [u8; 2 * UID_LEN] =
        cortex_m::singleton!(: [u8; 2 * UID_LEN] = [0; 2 * UID_LEN]).expect("made once");
    for (pair, byte) in text.chunks_exact_mut(2).zip(uid) {
        pair[0] = HEX[usize::from(byte >> 4)];
        pair[1] = HEX[usize::from(byte & 0xF)];
    }
    core::str::from_utf8(text).unwrap_or("0")
}

#[exception]
unsafe fn HardFault(_frame: &ExceptionFrame) -> ! {
    SCB::sys_reset()
}

/// A panic (none is expected: the firmware library never panics) resets the MCU; the next
/// boot reports a software reset.
#[panic_handler]
fn panic(_info: &PanicInfo) -> ! {
    SCB::sys_reset()
}
