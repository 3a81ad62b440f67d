//! The QST QMC5883L standalone magnetometer: register file, continuous mode at the configured
//! rate, STATUS flags, soft reset, pointer roll-over and the I2C target side (register map and
//! sources in [`margemu_protocol::regmap::qmc5883l`]).
//!
//! The chip is driven by time: [`Qmc5883l::advance`] moves its clock to `now_ns` with the field
//! it senses from then on (µT, chip axes). In continuous mode a measurement completes every ODR
//! period, the first one period after the mode was set (an assumption: the datasheet gives no
//! start-up time). A measurement stores the held field at the configured range, sets
//! STATUS.DRDY, sets OVL if an axis clipped, and sets DOR if the previous data was never read
//! (or a whole period passed without a measurement being stored, when the clock jumps).
//! Reading any data register (0x00–0x05) clears DRDY and DOR (DS STATUS); OVL follows each
//! measurement.
//!
//! CONF2.SOFT_RST restores every register to its default at once and reads 0 again.
//!
//! Not emulated yet: the temperature output (TOUT reads 0), the over-sampling ratio's effect on
//! noise (OSR is stored only), the SET/RESET period's effect (stored only) and the DRDY pin.
//!
//! ```
//! use margemu_firmware::chip::{I2cTarget, Qmc5883l};
//! let mut mag = Qmc5883l::new();
//! assert!(mag.start(0x0D, false));
//! mag.write(0x09); // CONF1: continuous, 100 Hz, 8 G
//! mag.write(0x19);
//! mag.stop();
//! mag.advance(10_000_000, [50.0, 0.0, -1.0]);
//! mag.start(0x0D, false);
//! mag.write(0x00);
//! mag.start(0x0D, true);
//! let data_and_status: [u8; 7] = core::array::from_fn(|_| mag.read());
//! mag.stop();
//! assert_eq!(data_and_status, [0xDC, 0x05, 0, 0, 0xE2, 0xFF, 0x00]);
//! ```

use margemu_protocol::regmap::mag_image;
use margemu_protocol::regmap::qmc5883l::{self as map, bits, reg, Mode, Odr, Range};

use super::magnetometer::{flag, Held, MAG_WRITE_LOG_LEN};
use super::pointer_i2c::PointerI2c;
use super::WriteLog;

/// The QMC5883L.
#[derive(Clone, Debug)]
pub struct Qmc5883l {
    conf1: u8,
    conf2: u8,
    period: u8,
    undoc: [u8; 2],
    drdy: bool,
    ovl: bool,
    dor: bool,
    data: [u8; 6],
    /// Completion time of the next measurement in continuous mode.
    next_due: Option<u64>,
    now_ns: u64,
    held: Held,
    pointer: u8,
    address: u8,
    pub(super) bus: PointerI2c,
    pub(super) log: WriteLog<MAG_WRITE_LOG_LEN>,
    /// What CHIP_ID reads under the wrong-identity fault (kept across resets).
    identity: Option<u8>,
}

impl Default for Qmc5883l {
    fn default() -> Self {
        Self::new()
    }
}

impl Qmc5883l {
    /// A powered-on QMC5883L in standby, at time 0, sensing no field.
    pub const fn new() -> Self {
        Self {
            conf1: 0,
            conf2: 0,
            period: 0,
            undoc: [0; 2],
            drdy: false,
            ovl: false,
            dor: false,
            data: [0; 6],
            next_due: None,
            now_ns: 0,
            held: Held::Field([0.0; 3]),
            pointer: 0,
            address: map::I2C_ADDRESS,
            bus: PointerI2c::new(),
            log: WriteLog::new(),
            identity: None,
        }
    }

    /// The chip strapped to 7-bit I2C `address` (the drivers' default: [`map::I2C_ADDRESS`]).
    pub const fn with_address(address: u8) -> Self {
        let mut chip = Self::new();
        chip.address = address;
        chip
    }

    /// Soft reset (CONF2.SOFT_RST): every register to its default. The clock, the held field and
    /// the bus state are kept.
    pub fn reset(&mut self) {
        *self = Self {
            now_ns: self.now_ns,
            held: self.held,
            pointer: self.pointer,
            address: self.address,
            bus: self.bus,
            log: self.log.clone(),
            identity: self.identity,
            ..Self::new()
        };
    }

    /// The reset fault (`margemu_model::fault::FaultKind::Reset`): the power-on state, which
    /// the datasheet's soft reset (CONF2.SOFT_RST: "restore default value of all registers")
    /// also gives: standby, CONF1/CONF2/SET_RESET_PERIOD 0, DRDY/OVL/DOR clear, the data
    /// registers 0, the register pointer at 0. The clock, the held field, the write log and a
    /// wrong-identity override are kept. A driver's read-back of CONF1 sees standby instead of
    /// continuous mode (and of 0x20/0x21, which ArduPilot's driver sets, 0), and no new data
    /// comes.
    pub fn fault_reset(&mut self) {
        self.reset();
        self.pointer = 0;
    }

    /// The wrong-identity fault: CHIP_ID (0x0D) reads `value` until `None`. (0x0C, which
    /// ArduPilot's probe also checks for 0x01, is a reserved register, not an identity: kept.)
    pub fn fault_identity(&mut self, value: Option<u8>) {
        self.identity = value;
    }

    /// The current operating mode.
    pub fn mode(&self) -> Mode {
        Mode::from_conf1(self.conf1)
    }

    /// The current output data rate.
    pub fn odr(&self) -> Odr {
        Odr::from_conf1(self.conf1)
    }

    /// The current range.
    pub fn range(&self) -> Range {
        Range::from_conf1(self.conf1)
    }

    /// What the chip senses until the next [`Qmc5883l::advance`] or image latch.
    pub fn held(&self) -> Held {
        self.held
    }

    /// The chip's clock.
    pub fn now_ns(&self) -> u64 {
        self.now_ns
    }

    /// The chip's 7-bit I2C address.
    pub fn address(&self) -> u8 {
        self.address
    }

    /// The register value at `addr`, without side effects.
    pub fn peek(&self, addr: u8) -> u8 {
        match addr {
            reg::XOUT_L..=reg::ZOUT_H => self.data.get(usize::from(addr)).copied().unwrap_or(0),
            reg::STATUS => {
                flag(self.drdy, bits::STATUS_DRDY)
                    | flag(self.ovl, bits::STATUS_OVL)
                    | flag(self.dor, bits::STATUS_DOR)
            }
            reg::CONF1 => self.conf1,
            reg::CONF2 => self.conf2,
            reg::PERIOD => self.period,
            reg::RESERVED_0C => map::REG_0C_VALUE,
            reg::CHIP_ID => self.identity.unwrap_or(map::CHIP_ID_VALUE),
            reg::UNDOC_20 => self.undoc[0],
            reg::UNDOC_21 => self.undoc[1],
            _ => 0x00, // TOUT and unmapped addresses
        }
    }

    /// Reads the register at `addr` as a bus access does (a data register clears DRDY and DOR).
    pub fn read_register(&mut self, addr: u8) -> u8 {
        let value = self.peek(addr);
        if (reg::XOUT_L..=reg::ZOUT_H).contains(&addr) {
            self.drdy = false;
            self.dor = false;
        }
        value
    }

    /// Writes the register at `addr` as a bus access does. Read-only registers ignore it.
    pub fn write_register(&mut self, addr: u8, value: u8) {
        match addr {
            reg::CONF1 => self.set_conf1(value),
            reg::CONF2 if value & bits::CONF2_SOFT_RST != 0 => self.reset(),
            reg::CONF2 => self.conf2 = value & (bits::CONF2_ROL_PNT | bits::CONF2_INT_ENB),
            reg::PERIOD => self.period = value,
            reg::UNDOC_20 => self.undoc[0] = value,
            reg::UNDOC_21 => self.undoc[1] = value,
            _ => {}
        }
    }

    /// Sets the register pointer (the first byte of an I2C write).
    pub fn set_pointer(&mut self, addr: u8) {
        self.pointer = addr;
    }

    /// The register pointer.
    pub fn pointer(&self) -> u8 {
        self.pointer
    }

    /// Reads the register at the pointer and moves the pointer on (roll-over per CONF2.ROL_PNT).
    pub fn read_next(&mut self) -> u8 {
        let value = self.read_register(self.pointer);
        self.pointer = map::next_address(self.pointer, self.roll_over());
        value
    }

    /// Writes the register at the pointer and moves the pointer on; returns the register written.
    pub fn write_next(&mut self, value: u8) -> u8 {
        let addr = self.pointer;
        self.write_register(addr, value);
        self.pointer = map::next_address(addr, self.roll_over());
        addr
    }

    /// Moves the chip's clock to `now_ns` (never backwards) with `field_ut` (µT, chip axes) as
    /// the field it senses from now on, and completes the measurements due by then (only the
    /// last one is visible; the others count as skipped).
    pub fn advance(&mut self, now_ns: u64, field_ut: [f32; 3]) {
        self.sense_at(now_ns, Held::Field(field_ut));
    }

    /// Moves the chip's clock to `now_ns` (never backwards) sensing `held` from now on, and
    /// completes what is due by then ([`Qmc5883l::advance`] with a field or raw values).
    pub fn sense_at(&mut self, now_ns: u64, held: Held) {
        self.held = held;
        self.now_ns = self.now_ns.max(now_ns);
        let Some(due) = self.next_due else { return };
        if self.now_ns < due {
            return;
        }
        let period = self.odr().period_ns();
        let completed = (self.now_ns - due) / period + 1;
        self.next_due = Some(due.saturating_add(completed.saturating_mul(period)));
        self.measure(completed > 1);
    }

    fn roll_over(&self) -> bool {
        self.conf2 & bits::CONF2_ROL_PNT != 0
    }

    fn set_conf1(&mut self, value: u8) {
        let was = (self.mode(), self.odr());
        self.conf1 = value;
        self.next_due = match self.mode() {
            Mode::Continuous if was == (Mode::Continuous, self.odr()) => self.next_due,
            Mode::Continuous => Some(self.now_ns.saturating_add(self.odr().period_ns())),
            Mode::Standby | Mode::Reserved => None,
        };
    }

    /// Stores one measurement (`skipped`: earlier ones were overwritten before anyone could read).
    fn measure(&mut self, skipped: bool) {
        let raw = match self.held {
            Held::Field(field_ut) => map::measurement(field_ut, self.range()).0,
            Held::Raw(raw) => raw,
        };
        self.data = mag_image::emit(raw);
        self.dor = self.drdy || skipped;
        self.drdy = true;
        self.ovl = map::overflows(raw);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::chip::I2cTarget;

    const MS: u64 = 1_000_000;

    fn read(mag: &mut Qmc5883l, addr: u8, n: usize) -> [u8; 8] {
        mag.set_pointer(addr);
        let mut out = [0; 8];
        for byte in out.iter_mut().take(n) {
            *byte = mag.read_next();
        }
        out
    }

    #[test]
    fn identity_and_defaults() {
        let mag = Qmc5883l::new();
        assert_eq!([mag.peek(0x0C), mag.peek(0x0D)], [0x01, 0xFF]);
        for addr in [0x00, 0x05, 0x06, 0x09, 0x0A, 0x0B, 0x20, 0x21] {
            assert_eq!(mag.peek(addr), 0, "{addr:#04x}");
        }
    }

    #[test]
    fn written_registers_read_back() {
        let mut mag = Qmc5883l::new();
        for (addr, value) in [(0x0B, 0x01), (0x20, 0x40), (0x21, 0x01), (0x09, 0xDD)] {
            mag.write_register(addr, value);
            assert_eq!(mag.peek(addr), value, "{addr:#04x}");
        }
        mag.write_register(0x0A, 0x7F);
        assert_eq!(mag.peek(0x0A), 0x41);
        mag.write_register(0x0D, 0x00);
        assert_eq!(mag.peek(0x0D), 0xFF, "read-only");
    }

    #[test]
    fn continuous_mode_at_each_rate() {
        for (odr_bits, period) in [(0x00, 100), (0x04, 20), (0x08, 10), (0x0C, 5)] {
            let mut mag = Qmc5883l::new();
            mag.write_register(0x09, 0x01 | odr_bits);
            mag.advance(period * MS - 1, [1.0, 0.0, 0.0]);
            assert_eq!(mag.peek(0x06), 0x00, "{period} ms");
            mag.advance(period * MS, [1.0, 0.0, 0.0]);
            assert_eq!(read(&mut mag, 0x06, 1)[0], 0x01);
            assert_eq!(read(&mut mag, 0x00, 2)[..2], [120, 0], "2 G: 120 LSB/µT");
            assert_eq!(mag.peek(0x06), 0x00, "reading the data cleared DRDY");
            mag.advance(2 * period * MS, [2.0, 0.0, 0.0]);
            assert_eq!(read(&mut mag, 0x00, 2)[..2], [240, 0]);
        }
    }

    #[test]
    fn skipped_data_sets_dor_and_range_overflow_sets_ovl() {
        let mut mag = Qmc5883l::new();
        mag.write_register(0x09, 0x09); // 100 Hz, 2 G
        mag.advance(10 * MS, [0.0; 3]);
        assert_eq!(mag.peek(0x06), 0x01);
        mag.advance(20 * MS, [300.0, 0.0, 0.0]);
        assert_eq!(mag.peek(0x06), 0x07, "DRDY | OVL | DOR");
        assert_eq!(
            read(&mut mag, 0x00, 2)[..2],
            [0xC0, 0x5D],
            "clipped at 24000"
        );
        assert_eq!(mag.peek(0x06), 0x02, "OVL stays with the data");
        mag.advance(50 * MS, [0.0; 3]);
        assert_eq!(mag.peek(0x06), 0x05, "two periods in one step: DOR");
    }

    #[test]
    fn standby_stops_and_soft_reset_restores_defaults() {
        let mut mag = Qmc5883l::new();
        mag.write_register(0x09, 0x1D);
        mag.write_register(0x0A, 0x40);
        mag.write_register(0x0B, 0x01);
        mag.write_register(0x09, 0x1C);
        mag.advance(100 * MS, [1.0; 3]);
        assert_eq!(mag.peek(0x06), 0x00, "standby: no measurement");
        mag.write_register(0x0A, 0x80);
        for addr in 0..=0x21 {
            assert_eq!(mag.peek(addr), Qmc5883l::new().peek(addr), "{addr:#04x}");
        }
    }

    #[test]
    fn pointer_rolls_over_only_with_rol_pnt() {
        let mut mag = Qmc5883l::new();
        assert_eq!(read(&mut mag, 0x05, 3)[..3], [0, 0, 0], "0x05, 0x06, 0x07");
        assert_eq!(mag.pointer(), 0x08);
        mag.write_register(0x0A, 0x40);
        mag.write_register(0x09, 0x19);
        mag.advance(10 * MS, [0.1, 0.0, 0.0]);
        assert_eq!(read(&mut mag, 0x06, 3)[..3], [0x01, 3, 0], "0x06 → 0x00");
    }

    #[test]
    fn i2c_target_address_and_auto_increment() {
        let mut mag = Qmc5883l::new();
        assert!(!mag.start(0x0E, false));
        assert!(mag.start(0x0D, false));
        assert!(mag.write(0x09));
        assert!(mag.write(0x1D));
        assert!(mag.write(0x40));
        assert!(mag.write(0x01));
        mag.stop();
        assert_eq!(
            [mag.peek(0x09), mag.peek(0x0A), mag.peek(0x0B)],
            [0x1D, 0x40, 0x01]
        );
        mag.start(0x0D, false);
        mag.write(0x0C);
        mag.start(0x0D, true);
        assert_eq!([mag.read(), mag.read()], [0x01, 0xFF]);
        mag.stop();
    }
}
