//! The PNI RM3100 magnetometer: register file, single and continuous measurements timed by the
//! cycle counts and TMRC, STATUS.DRDY with the HSHAKE clearing rules, the built-in self test,
//! and the I2C and SPI target sides (register map and sources in
//! [`margemu_protocol::regmap::rm3100`]).
//!
//! **Time and samples.** [`Rm3100::latch_at`] hands the chip the field it senses from `now_ns`
//! on ([`PhysicalSample::mag`], µT, chip axes); [`Rm3100::advance`] moves its clock without a
//! new sample. An axis measurement completing at `t` converts the field of the last sample
//! latched at or before `t` (sample and hold).
//!
//! **Measurements** (DS §5.2, §5.3). The axes of a measurement are measured one after the other,
//! each taking [`axis_measurement_ns`](margemu_protocol::regmap::rm3100::axis_measurement_ns) of
//! its own cycle count (2.28 ms at the default 200) and converting the field held when it
//! completes, at a gain of 0.375 LSB/µT per cycle count. The result registers take the new values
//! when DRDY rises, all measured axes at once, so a read never mixes two measurements
//! (assumption: the DS does not say when each axis's registers change). A write to POLL with
//! axis bits starts a single measurement: DRDY rises when all requested axes are done.
//! CMM with START and axis bits runs measurements every
//! [`continuous_period_ns`](margemu_protocol::regmap::rm3100::continuous_period_ns) (the TMRC
//! period, or the measurement itself when that is longer), the first starting at the write;
//! DRDY rises after each whole sequence, or after every axis with CMM.DRDM. A write to the cycle
//! counts or TMRC during continuous mode restarts the sequence with the new timing (assumption).
//!
//! **DRDY** (DS §4.3.1, §5.6.2). With HSHAKE.DRC1 (default) reading the results clears DRDY
//! when the first result byte goes out; with HSHAKE.DRC0 (default) a register write clears it:
//! on SPI at the address byte of a write, on I2C at the first data byte of a write. The DS says
//! "the register address byte for the write transaction", but an I2C register read also starts
//! with a write of the register address, and ArduPilot's STATUS poll over I2C (write 0x34,
//! repeated START, read) works with the real part, so a bare pointer write does not clear it.
//!
//! **Refused writes** (DS §4.5.1, §5.6.2). A write to a register that is not read/write sets
//! HSHAKE.NACK0; POLL during continuous mode, or CMM during a single measurement or self test,
//! is ignored and sets NACK1; on I2C these data bytes are not acknowledged. Reading the results
//! while DRDY is clear sets NACK2. The NACK bits clear when HSHAKE is written (assumption); NACK0
//! reads set after reset, as the DS default 0x1B has it.
//!
//! **Self test** (DS §5.6.1). With BIST.STE set, a POLL write runs the self test of the polled
//! axes instead of a measurement: after
//! [`self_test_ns`](margemu_protocol::regmap::rm3100::self_test_ns) DRDY rises and XOK/YOK/ZOK
//! read set for the tested axes (the emulated oscillators never fail) while STE stays set;
//! a BIST write clears them. The results are not changed.
//!
//! **Not the DS literally.** The DS notes that reading CMM or writing TMRC ends continuous mode.
//! ArduPilot re-reads CMM once a second (its register check) and PX4 writes TMRC after CMM; under
//! the note ArduPilot would lose most of its data and PX4 all of it, yet both are in use with the
//! real part on many boards, so by default neither stops it.
//! [`Rm3100::set_strict_cmm`] applies the note.
//!
//! **Buses.** I2C at the address set by SA0/SA1 (0x20–0x23), a register pointer written first,
//! auto-increment within 7 bits. SPI (mode 0 or 3): first byte R/W̄ | address, auto-increment,
//! no dummy byte; the MISO byte during the address byte is STATUS (DS §4.4), during writes 0x00.
//!
//! Not emulated: the alarm registers of DS revisions before R05, the DRDY pin, the noise, the
//! non-linearity beyond ±200 µT and the bent characteristic beyond ±800 µT.
//!
//! ```
//! use margemu_firmware::chip::{I2cTarget, PhysicalSample, Rm3100};
//! let mut mag = Rm3100::new();
//! let sample = PhysicalSample { mag: [50.0, -0.02, 1000.0], ..Default::default() };
//! mag.latch_at(&sample, 0);
//! assert!(mag.start(0x20, false));
//! mag.write(0x00); // POLL
//! mag.write(0x70); // x, y, z
//! mag.stop();
//! mag.advance(7_000_000); // 3 axes at 200 counts take 6.85 ms
//! mag.start(0x20, false);
//! mag.write(0x34); // STATUS, then the results from 0x24 in a second read
//! mag.start(0x20, true);
//! assert_eq!(mag.read(), 0x80);
//! mag.start(0x20, false);
//! mag.write(0x24);
//! mag.start(0x20, true);
//! let results: [u8; 9] = core::array::from_fn(|_| mag.read());
//! mag.stop();
//! // 50 µT × 75 LSB/µT = 3750, -1.5 → -2, 75000; 24-bit big-endian.
//! assert_eq!(results, [0x00, 0x0E, 0xA6, 0xFF, 0xFF, 0xFE, 0x01, 0x24, 0xF8]);
//! assert_eq!(mag.peek(0x34), 0x00, "reading the results cleared DRDY");
//! ```

mod boundary;
mod bus;
mod measure;

use margemu_protocol::regmap::rm3100::{self as map, bits, reg, reset};

use super::spi_phase::SpiPhase;
use super::{PhysicalSample, WriteLog};
use measure::Run;

/// The RM3100.
#[derive(Clone, Debug)]
pub struct Rm3100 {
    address: u8,
    poll: u8,
    cmm: u8,
    cycle_counts: [u16; 3],
    tmrc: u8,
    bist: u8,
    bist_ok: u8,
    drc: u8,
    nack: u8,
    drdy: bool,
    data: [u8; 9],
    /// Axes measured in the current sequence, not yet in `data`.
    pending: [u8; 9],
    run: Run,
    now_ns: u64,
    held: Held,
    strict_cmm: bool,
    pointer: u8,
    expect_register: bool,
    addressed: bool,
    /// A result byte already went out in this transaction (DRC1 and NACK2 act on the first).
    results_read: bool,
    spi: SpiPhase,
    log: WriteLog<RM3100_WRITE_LOG_LEN>,
    /// What REVID reads under the wrong-identity fault (kept across resets).
    identity: Option<u8>,
}

/// Register writes the RM3100 keeps for the link.
const RM3100_WRITE_LOG_LEN: usize = 32;

/// What the RM3100 senses until the next latch: a field (converted at each axis's cycle count
/// when that axis is measured) or an image's results (at the cycle counts the host predicted,
/// copied as they are).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Held {
    /// µT, chip axes.
    Field([f32; 3]),
    /// Results x, y, z.
    Raw([i32; 3]),
}

impl Default for Rm3100 {
    fn default() -> Self {
        Self::new()
    }
}

impl Rm3100 {
    /// A powered-on RM3100 at I2C address 0x20 (SA0 and SA1 low), idle, at time 0, sensing no
    /// field.
    pub const fn new() -> Self {
        Self::with_pins(false, false)
    }

    /// A powered-on RM3100 with the SA0 and SA1 pins at these levels (I2C 0x20–0x23).
    pub const fn with_pins(sa0: bool, sa1: bool) -> Self {
        Self {
            address: map::i2c_address(sa0, sa1),
            poll: 0,
            cmm: 0,
            cycle_counts: [reset::CYCLE_COUNT; 3],
            tmrc: reset::TMRC,
            bist: 0,
            bist_ok: 0,
            drc: reset::HSHAKE & bits::HSHAKE_MASK,
            nack: reset::HSHAKE & (bits::HSHAKE_NACK0 | bits::HSHAKE_NACK1 | bits::HSHAKE_NACK2),
            drdy: false,
            data: [0; 9],
            pending: [0; 9],
            run: Run::Idle,
            now_ns: 0,
            held: Held::Field([0.0; 3]),
            strict_cmm: false,
            pointer: 0,
            expect_register: false,
            addressed: false,
            results_read: false,
            spi: SpiPhase::Idle,
            log: WriteLog::new(),
            identity: None,
        }
    }

    /// The reset fault (`margemu_model::fault::FaultKind::Reset`): the power-on state (the
    /// RM3100 has no soft reset; DS §5.6: POLL and CMM 0, cycle counts 200, TMRC 0x96, HSHAKE
    /// 0x1B): idle, DRDY clear, the results 0, the register pointer at 0. The clock, the held
    /// field, the bus transaction in progress, the write log, the strict-CMM setting and a
    /// wrong-identity override are kept. A driver in continuous mode stops getting data; its
    /// read-back of CMM, the cycle counts or TMRC (ArduPilot's RM3100 driver checks CMM)
    /// sees the difference.
    pub fn fault_reset(&mut self) {
        *self = Self {
            address: self.address,
            now_ns: self.now_ns,
            held: self.held,
            strict_cmm: self.strict_cmm,
            expect_register: self.expect_register,
            addressed: self.addressed,
            spi: self.spi,
            log: core::mem::take(&mut self.log),
            identity: self.identity,
            ..Self::new()
        };
    }

    /// The wrong-identity fault: REVID reads `value` until `None`.
    pub fn fault_identity(&mut self, value: Option<u8>) {
        self.identity = value;
    }

    /// The 7-bit I2C address the chip answers.
    pub fn i2c_address(&self) -> u8 {
        self.address
    }

    /// Applies the DS note that reading CMM or writing TMRC ends continuous mode (START reads
    /// 0 afterwards). Off by default (see the [module docs](self)).
    pub fn set_strict_cmm(&mut self, on: bool) {
        self.strict_cmm = on;
    }

    /// Whether continuous measurements are running.
    pub fn is_continuous(&self) -> bool {
        matches!(self.run, Run::Continuous { .. })
    }

    /// What the chip senses until the next latch.
    pub fn held(&self) -> Held {
        self.held
    }

    /// The cycle counts of x, y, z.
    pub fn cycle_counts(&self) -> [u16; 3] {
        self.cycle_counts
    }

    /// The register value at `addr`, without side effects.
    pub fn peek(&self, addr: u8) -> u8 {
        match addr {
            reg::POLL => self.poll,
            reg::CMM => self.cmm,
            reg::CCX..=reg::CCZ_LSB => {
                let i = usize::from(addr - reg::CCX);
                let cc = self.cycle_counts.get(i / 2).copied().unwrap_or(0);
                cc.to_be_bytes().get(i % 2).copied().unwrap_or(0)
            }
            reg::TMRC => self.tmrc,
            reg::MX..=reg::MZ_LSB => self
                .data
                .get(usize::from(addr - reg::MX))
                .copied()
                .unwrap_or(0),
            reg::BIST if self.bist & bits::BIST_STE != 0 => self.bist | self.bist_ok,
            reg::BIST => self.bist,
            reg::STATUS if self.drdy => bits::STATUS_DRDY,
            reg::HSHAKE => bits::HSHAKE_ONE | self.nack | self.drc,
            reg::REVID => self.identity.unwrap_or(map::REVID_VALUE),
            _ => 0x00, // STATUS without DRDY, unmapped addresses
        }
    }

    /// Reads the register at `addr` as a one-byte bus read does (results clear DRDY with
    /// HSHAKE.DRC1).
    pub fn read_register(&mut self, addr: u8) -> u8 {
        self.results_read = false;
        let value = self.peek(addr);
        self.commit_read(addr);
        value
    }

    /// Writes the register at `addr` as a one-register bus write does (clearing DRDY with
    /// HSHAKE.DRC0); returns whether the write was carried out (the I2C ACK).
    pub fn write_register(&mut self, addr: u8, value: u8) -> bool {
        self.clear_on_write();
        self.write_byte(addr, value)
    }

    /// Latches `sample`'s field as what the chip senses from `now_ns` on, after completing with
    /// the previous field what was due before `now_ns` (see the [module docs](self)).
    pub fn latch_at(&mut self, sample: &PhysicalSample, now_ns: u64) {
        let now = self.now_ns.max(now_ns);
        if now > 0 {
            self.run_until(now - 1);
        }
        self.held = Held::Field(sample.mag);
        self.advance(now);
    }

    /// [`Rm3100::latch_at`] with an image's results (see [`Held::Raw`]).
    pub fn latch_raw_at(&mut self, raw: [i32; 3], now_ns: u64) {
        let now = self.now_ns.max(now_ns);
        if now > 0 {
            self.run_until(now - 1);
        }
        self.held = Held::Raw(raw);
        self.advance(now);
    }

    /// The chip's clock.
    pub fn now_ns(&self) -> u64 {
        self.now_ns
    }

    /// Moves the chip's clock to `now_ns` (never backwards), completing what is due by then.
    pub fn advance(&mut self, now_ns: u64) {
        self.now_ns = self.now_ns.max(now_ns);
        self.run_until(self.now_ns);
    }

    /// The side effects of a read of `addr` whose value went out.
    fn commit_read(&mut self, addr: u8) {
        match addr {
            reg::MX..=reg::MZ_LSB if !self.results_read => {
                self.results_read = true;
                if !self.drdy {
                    self.nack |= bits::HSHAKE_NACK2;
                }
                if self.drc & bits::HSHAKE_DRC1 != 0 {
                    self.drdy = false;
                }
            }
            reg::CMM if self.strict_cmm => self.stop_continuous(),
            _ => {}
        }
    }

    /// DRDY cleared by a write transaction (HSHAKE.DRC0).
    fn clear_on_write(&mut self) {
        if self.drc & bits::HSHAKE_DRC0 != 0 {
            self.drdy = false;
        }
    }

    /// One data byte written to `addr`; returns whether it was carried out.
    fn write_byte(&mut self, addr: u8, value: u8) -> bool {
        match addr {
            reg::POLL if self.cmm & bits::CMM_START != 0 => return self.refuse(bits::HSHAKE_NACK1),
            reg::POLL => {
                self.poll = value & bits::AXES;
                self.start_single();
            }
            reg::CMM if self.run.is_single() => return self.refuse(bits::HSHAKE_NACK1),
            reg::CMM => {
                self.cmm = value & bits::CMM_MASK;
                self.start_continuous();
            }
            reg::CCX..=reg::CCZ_LSB => {
                let i = usize::from(addr - reg::CCX);
                if let Some(cc) = self.cycle_counts.get_mut(i / 2) {
                    let mut bytes = cc.to_be_bytes();
                    if let Some(b) = bytes.get_mut(i % 2) {
                        *b = value;
                    }
                    *cc = u16::from_be_bytes(bytes);
                }
                self.reschedule();
            }
            reg::TMRC => {
                self.tmrc = value;
                if self.strict_cmm {
                    self.stop_continuous();
                } else {
                    self.reschedule();
                }
            }
            reg::BIST => {
                self.bist = value & bits::BIST_MASK;
                self.bist_ok = 0;
            }
            reg::HSHAKE => {
                self.drc = value & bits::HSHAKE_MASK;
                self.nack = 0;
            }
            _ => return self.refuse(bits::HSHAKE_NACK0),
        }
        true
    }

    fn refuse(&mut self, nack: u8) -> bool {
        self.nack |= nack;
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reset_values() {
        let mag = Rm3100::new();
        let expected = |addr: u8| match addr {
            0x05 | 0x07 | 0x09 => 0xC8,
            0x0B => 0x96,
            0x35 => 0x1B,
            0x36 => 0x22,
            _ => 0x00,
        };
        for addr in 0..0x80 {
            assert_eq!(mag.peek(addr), expected(addr), "{addr:#04x}");
        }
        assert_eq!(Rm3100::with_pins(true, true).i2c_address(), 0x23);
    }

    #[test]
    fn writes_read_back_through_their_masks() {
        let mut mag = Rm3100::new();
        for (addr, value, back) in [
            (0x04, 0x01, 0x01),
            (0x05, 0x2C, 0x2C),
            (0x0B, 0x94, 0x94),
            (0x33, 0xFF, 0x8F),
            (0x35, 0xFF, 0x0B),
            (0x01, 0xFE, 0x7C),
            (0x00, 0xFF, 0x70),
        ] {
            assert!(mag.write_register(addr, value), "{addr:#04x}");
            assert_eq!(mag.peek(addr), back, "{addr:#04x}");
        }
        assert_eq!(mag.cycle_counts(), [300, 200, 200]);
        for addr in [0x02, 0x0A, 0x24, 0x34, 0x36, 0x40] {
            assert!(!mag.write_register(addr, 0x55), "{addr:#04x} refused");
        }
        assert_eq!([mag.peek(0x24), mag.peek(0x36)], [0x00, 0x22]);
        assert_eq!(mag.peek(0x35), 0x1B, "NACK0");
    }
}
