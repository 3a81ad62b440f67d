//! The iSentek IST8310 standalone magnetometer: register file, single-measurement mode, soft
//! reset and the I2C target side (register map and sources in
//! [`margemu_protocol::regmap::ist8310`]).
//!
//! The chip is driven by time: [`Ist8310::advance`] moves its clock to `now_ns` with the field it
//! senses from then on (µT, chip axes). Writing CNTL1 = 1 starts a single measurement that
//! completes [`measurement_ns`](margemu_protocol::regmap::ist8310::measurement_ns) later (6.1 ms
//! with ArduPilot's and PX4's 16 times averaging): the field held at completion is converted at
//! 0.3 µT/LSB with per-axis clipping, STAT1.DRDY is set and CNTL1 returns to stand-by (0).
//! Reading any data register clears DRDY and DOR; DOR is set when a measurement completes while
//! DRDY is still set.
//!
//! CNTL2.SRST performs the power-on reset at once: every register to its reset value, a
//! measurement in progress dropped, SRST reading 0 again (the drivers poll for that).
//!
//! Not emulated yet: the self-test field (STR bit 6 is stored only), the temperature output
//! (TEMPL/TEMPH read 0: the public datasheet gives no conversion), the 16-bit output of CNTL3
//! (stored only), STAT2 and the DRDY pin.
//!
//! ```
//! use margemu_firmware::chip::{I2cTarget, Ist8310};
//! let mut mag = Ist8310::new();
//! assert!(mag.start(0x0E, false));
//! mag.write(0x0A); // CNTL1
//! mag.write(0x01); // single measurement
//! mag.stop();
//! mag.advance(7_000_000, [30.0, -0.3, 0.0]);
//! mag.start(0x0E, false);
//! mag.write(0x02);
//! mag.start(0x0E, true);
//! let stat1_and_data: [u8; 7] = core::array::from_fn(|_| mag.read());
//! mag.stop();
//! assert_eq!(stat1_and_data, [0x01, 100, 0, 0xFF, 0xFF, 0, 0]);
//! ```

use margemu_protocol::regmap::ist8310::{self as map, bits, reg, reset, Mode};

use super::magnetometer::{flag, Held, MAG_WRITE_LOG_LEN};
use super::pointer_i2c::PointerI2c;
use super::WriteLog;

/// The IST8310.
#[derive(Clone, Debug)]
pub struct Ist8310 {
    cntl1: u8,
    cntl2: u8,
    str_: u8,
    cntl3: u8,
    tccntl: u8,
    avgcntl: u8,
    pdcntl: u8,
    drdy: bool,
    dor: bool,
    data: [u8; 6],
    /// Completion time of the measurement in progress, if any.
    next_due: Option<u64>,
    now_ns: u64,
    held: Held,
    pointer: u8,
    address: u8,
    pub(super) bus: PointerI2c,
    pub(super) log: WriteLog<MAG_WRITE_LOG_LEN>,
    /// What WAI reads under the wrong-identity fault (kept across resets).
    identity: Option<u8>,
}

impl Default for Ist8310 {
    fn default() -> Self {
        Self::new()
    }
}

impl Ist8310 {
    /// A powered-on IST8310 in stand-by, at time 0, sensing no field.
    pub const fn new() -> Self {
        Self {
            cntl1: reset::CNTL1,
            cntl2: reset::CNTL2,
            str_: 0,
            cntl3: 0,
            tccntl: 0,
            avgcntl: reset::AVGCNTL,
            pdcntl: reset::PDCNTL,
            drdy: false,
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

    /// Soft reset (CNTL2.SRST, the power-on routine): every register to its reset value. The
    /// clock, the held field and the bus state are kept.
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
    /// the datasheet's soft reset (CNTL2.SRST, "the power-on routine") also gives: stand-by,
    /// every register at its reset value (AVGCNTL 0x24, PDCNTL 0xC0), DRDY/DOR clear, the data
    /// registers 0, the register pointer at 0. The clock, the held field, the write log and a
    /// wrong-identity override are kept. A driver in single-measurement mode (ArduPilot's and
    /// PX4's IST8310 drivers re-trigger CNTL1 each period) simply starts the next measurement;
    /// its read-back of AVGCNTL and PDCNTL sees the difference.
    pub fn fault_reset(&mut self) {
        self.reset();
        self.pointer = 0;
    }

    /// The wrong-identity fault: WAI reads `value` until `None`.
    pub fn fault_identity(&mut self, value: Option<u8>) {
        self.identity = value;
    }

    /// The current operating mode.
    pub fn mode(&self) -> Mode {
        Mode::from_cntl1(self.cntl1)
    }

    /// What the chip senses until the next [`Ist8310::advance`] or image latch.
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
            reg::WAI => self.identity.unwrap_or(map::WAI_VALUE),
            reg::STAT1 => flag(self.drdy, bits::STAT1_DRDY) | flag(self.dor, bits::STAT1_DOR),
            reg::DATAXL..=reg::DATAZH => self
                .data
                .get(usize::from(addr - reg::DATAXL))
                .copied()
                .unwrap_or(0),
            reg::CNTL1 => self.cntl1,
            reg::CNTL2 => self.cntl2,
            reg::STR => self.str_,
            reg::CNTL3 => self.cntl3,
            reg::TCCNTL => self.tccntl,
            reg::AVGCNTL => self.avgcntl,
            reg::PDCNTL => self.pdcntl,
            _ => 0x00, // STAT2, TEMPL/TEMPH and unmapped addresses
        }
    }

    /// Reads the register at `addr` as a bus access does (a data register clears DRDY and DOR).
    pub fn read_register(&mut self, addr: u8) -> u8 {
        let value = self.peek(addr);
        if (reg::DATAXL..=reg::DATAZH).contains(&addr) {
            self.drdy = false;
            self.dor = false;
        }
        value
    }

    /// Writes the register at `addr` as a bus access does. Read-only registers ignore it.
    pub fn write_register(&mut self, addr: u8, value: u8) {
        match addr {
            reg::CNTL1 => self.set_cntl1(value & bits::CNTL1_MODE),
            reg::CNTL2 if value & bits::CNTL2_SRST != 0 => self.reset(),
            reg::CNTL2 => self.cntl2 = value & (bits::CNTL2_DRP | bits::CNTL2_DREN),
            reg::STR => self.str_ = value & bits::STR_SELF_TEST,
            reg::CNTL3 => self.cntl3 = value & bits::CNTL3_XYZ_16BIT,
            reg::TCCNTL => self.tccntl = value,
            reg::AVGCNTL => self.avgcntl = value & bits::AVGCNTL_MASK,
            reg::PDCNTL => self.pdcntl = value & bits::PDCNTL_PD,
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

    /// Reads the register at the pointer and moves the pointer on.
    pub fn read_next(&mut self) -> u8 {
        let value = self.read_register(self.pointer);
        self.pointer = map::next_address(self.pointer);
        value
    }

    /// Writes the register at the pointer and moves the pointer on; returns the register written.
    pub fn write_next(&mut self, value: u8) -> u8 {
        let addr = self.pointer;
        self.write_register(addr, value);
        self.pointer = map::next_address(addr);
        addr
    }

    /// Moves the chip's clock to `now_ns` (never backwards) with `field_ut` (µT, chip axes) as
    /// the field it senses from now on, and completes the measurement due by then, if any.
    pub fn advance(&mut self, now_ns: u64, field_ut: [f32; 3]) {
        self.sense_at(now_ns, Held::Field(field_ut));
    }

    /// Moves the chip's clock to `now_ns` (never backwards) sensing `held` from now on, and
    /// completes what is due by then ([`Ist8310::advance`] with a field or raw values).
    pub fn sense_at(&mut self, now_ns: u64, held: Held) {
        self.held = held;
        self.now_ns = self.now_ns.max(now_ns);
        match self.next_due {
            Some(due) if due <= self.now_ns => {
                self.next_due = None;
                self.measure();
                self.cntl1 = 0; // back to stand-by
            }
            _ => {}
        }
    }

    fn set_cntl1(&mut self, value: u8) {
        self.cntl1 = value;
        self.next_due = match self.mode() {
            Mode::Single => Some(
                self.now_ns
                    .saturating_add(map::measurement_ns(self.avgcntl)),
            ),
            Mode::StandBy | Mode::Reserved => None,
        };
    }

    fn measure(&mut self) {
        let raw = match self.held {
            Held::Field(field_ut) => map::measurement(field_ut).0,
            Held::Raw(raw) => raw,
        };
        self.dor = self.drdy;
        self.drdy = true;
        self.data = map::data_bytes(raw);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::chip::I2cTarget;

    const MS: u64 = 1_000_000;

    fn read(mag: &mut Ist8310, addr: u8, n: usize) -> [u8; 8] {
        mag.set_pointer(addr);
        let mut out = [0; 8];
        for byte in out.iter_mut().take(n) {
            *byte = mag.read_next();
        }
        out
    }

    #[test]
    fn identity_and_reset_values() {
        let mag = Ist8310::new();
        assert_eq!(mag.peek(0x00), 0x10);
        for addr in [0x02, 0x03, 0x08, 0x0A, 0x0B, 0x41, 0x42] {
            assert_eq!(mag.peek(addr), 0, "{addr:#04x}");
        }
    }

    #[test]
    fn written_registers_read_back_within_their_masks() {
        let mut mag = Ist8310::new();
        mag.write_register(0x41, 0xFF);
        mag.write_register(0x42, 0xFF);
        mag.write_register(0x0D, 0xFF);
        mag.write_register(0x0C, 0xFF);
        mag.write_register(0x0B, 0x0C);
        mag.write_register(0x00, 0x55);
        assert_eq!(
            [0x41, 0x42, 0x0D, 0x0C, 0x0B, 0x00].map(|a| mag.peek(a)),
            [0x3F, 0xC0, 0x70, 0x40, 0x0C, 0x10]
        );
    }

    #[test]
    fn single_measurement_completes_after_the_averaging_time() {
        let mut mag = Ist8310::new();
        mag.write_register(0x41, 0x24);
        mag.write_register(0x0A, 0x01);
        mag.advance(6 * MS, [3.0, 0.0, 0.0]);
        assert_eq!([mag.peek(0x02), mag.peek(0x0A)], [0x00, 0x01], "6.1 ms");
        mag.advance(7 * MS, [3.0, 0.0, -3.0]);
        assert_eq!([mag.peek(0x02), mag.peek(0x0A)], [0x01, 0x00]);
        assert_eq!(read(&mut mag, 0x03, 6)[..6], [10, 0, 0, 0, 0xF6, 0xFF]);
        assert_eq!(mag.peek(0x02), 0x00, "reading the data cleared DRDY");
        mag.advance(100 * MS, [0.0; 3]);
        assert_eq!(mag.peek(0x02), 0x00, "no further measurement");
    }

    #[test]
    fn unread_data_overwritten_sets_dor() {
        let mut mag = Ist8310::new();
        mag.write_register(0x0A, 0x01);
        mag.advance(2 * MS, [0.0; 3]);
        mag.write_register(0x0A, 0x01);
        mag.advance(4 * MS, [0.0; 3]);
        assert_eq!(mag.peek(0x02), 0x03, "DRDY | DOR");
        assert_eq!(read(&mut mag, 0x02, 2)[..2], [0x03, 0x00]);
        assert_eq!(mag.peek(0x02), 0x00);
    }

    #[test]
    fn soft_reset_restores_registers_and_self_clears() {
        let mut mag = Ist8310::new();
        mag.write_register(0x41, 0x24);
        mag.write_register(0x42, 0xC0);
        mag.write_register(0x0A, 0x01);
        mag.write_register(0x0B, 0x01);
        for addr in 0..=0x42 {
            assert_eq!(mag.peek(addr), Ist8310::new().peek(addr), "{addr:#04x}");
        }
        mag.advance(50 * MS, [10.0; 3]);
        assert_eq!(
            mag.peek(0x02),
            0x00,
            "the measurement in progress was dropped"
        );
    }

    #[test]
    fn i2c_target_address_pointer_and_burst() {
        let mut mag = Ist8310::new();
        assert!(!mag.start(0x0C, false));
        assert!(mag.start(0x0E, false));
        assert!(mag.write(0x41));
        assert!(mag.write(0x24)); // AVGCNTL
        assert!(mag.write(0xC0)); // PDCNTL, auto-increment
        mag.stop();
        assert_eq!([mag.peek(0x41), mag.peek(0x42)], [0x24, 0xC0]);
        mag.start(0x0E, false);
        mag.write(0x41);
        mag.start(0x0E, true);
        assert_eq!([mag.read(), mag.read()], [0x24, 0xC0]);
        mag.stop();
    }
}
