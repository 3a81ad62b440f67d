//! The AK8963 magnetometer die: registers, operating modes, measurement timing and the
//! data-protection rules of its datasheet (AKM MS1356-E-02, "DS").
//!
//! The die is driven by time: [`Ak8963::advance`] moves its clock to `now_ns` and completes the
//! measurements that are due by then — every 125 ms (continuous mode 1, 8 Hz) or 10 ms
//! (continuous mode 2, 100 Hz) after a first one 7.2 ms after the mode was set, and once 7.2 ms
//! after a single or self-test measurement was started. A measurement stores the most recent
//! field given to it (sample and hold).
//!
//! Reading rules (DS 6.4.3.2–6.4.3.4): reading any of HXL..=HZH or ST2 starts a data read, which
//! clears ST1.DRDY and ST1.DOR and *protects* the data registers: a measurement that completes
//! before ST2 is read is discarded, and the next stored one reports ST1.DOR. Reading ST2 ends
//! the read. In the continuous modes DOR is also set when a measurement overwrites data that was
//! never read.
//!
//! The die is an [`I2cTarget`] at 0x0C (in the MPU-9250 it is reached in bypass mode or through
//! the auxiliary I2C master, which use the same register pointer).
//!
//! ```
//! use margemu_firmware::chip::{Ak8963, I2cTarget, MagSource};
//! let mut ak = Ak8963::new([128; 3], 0);
//! // CNTL1 = 0x16: 16-bit output, continuous mode 2 (100 Hz).
//! assert!(ak.start(0x0C, false));
//! ak.write(0x0A);
//! ak.write(0x16);
//! ak.stop();
//! ak.advance(10_000_000, MagSource::Physical([0.0, 15.0, 0.0])); // 15 µT along MPU y = AK x
//! ak.start(0x0C, false);
//! ak.write(0x02);
//! ak.start(0x0C, true);
//! let st1_to_st2: [u8; 8] = core::array::from_fn(|_| ak.read());
//! ak.stop();
//! assert_eq!(st1_to_st2, [0x01, 100, 0, 0, 0, 0, 0, 0x10]);
//! ```

use margemu_protocol::regmap::ak8963::{self as map, bits, reg, MagBits, Mode};
use margemu_protocol::regmap::mpu6xxx::convert::{mag_measurement, mag_self_test};

use super::I2cTarget;

/// What the AK8963 would measure now.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MagSource {
    /// A field in µT in the MPU-9250's accel/gyro axes (converted with the die's own ASA values
    /// and output setting when a measurement completes).
    Physical([f32; 3]),
    /// A finished measurement from a register image: HXL..=HZH and ST2 (HOFL and BITM are used).
    Registers {
        /// HXL, HXH, HYL, HYH, HZL, HZH.
        data: [u8; 6],
        /// ST2 as the image carries it.
        st2: u8,
    },
}

/// The AK8963.
#[derive(Clone, Debug)]
pub struct Ak8963 {
    asa: [u8; 3],
    info: u8,
    cntl1: u8,
    astc: u8,
    ts: [u8; 2],
    i2cdis: u8,
    drdy: bool,
    dor: bool,
    data: [u8; 6],
    st2: u8,
    /// A data read is in progress (started by HXL..=ST2, ended by ST2).
    protected: bool,
    /// A measurement was discarded while protected; the next stored one reports DOR.
    skipped: bool,
    /// Completion time of the next measurement, if one is scheduled.
    next_due: Option<u64>,
    now_ns: u64,
    source: MagSource,
    pointer: u8,
    expect_register: bool,
    /// What WIA reads under the wrong-identity fault (kept across resets).
    identity: Option<u8>,
}

impl Ak8963 {
    /// A powered-on AK8963 with fuse ROM values `asa` (ASAX, ASAY, ASAZ) and INFO byte `info`.
    pub fn new(asa: [u8; 3], info: u8) -> Self {
        Self {
            asa,
            info,
            cntl1: 0,
            astc: 0,
            ts: [0; 2],
            i2cdis: 0,
            drdy: false,
            dor: false,
            data: [0; 6],
            st2: 0,
            protected: false,
            skipped: false,
            next_due: None,
            now_ns: 0,
            source: MagSource::Physical([0.0; 3]),
            pointer: 0,
            expect_register: false,
            identity: None,
        }
    }

    /// Soft reset (CNTL2.SRST): every register to its reset value, power-down mode. The fuse
    /// ROM, the clock and the held field are kept.
    pub fn reset(&mut self) {
        *self = Self {
            now_ns: self.now_ns,
            source: self.source,
            identity: self.identity,
            ..Self::new(self.asa, self.info)
        };
    }

    /// The reset fault (`margemu_model::fault::FaultKind::Reset`): the die's power-on state,
    /// which is its soft reset's (DS 8.3.6: SRST initialises every register; the fuse ROM is
    /// read only): power-down mode, DRDY/DOR clear, the data registers 0. The clock, the held
    /// field and a wrong-identity override are kept; the register pointer returns to 0.
    pub fn fault_reset(&mut self) {
        self.reset();
    }

    /// The wrong-identity fault: WIA reads `value` until `None`.
    pub fn fault_identity(&mut self, value: Option<u8>) {
        self.identity = value;
    }

    /// The fuse ROM sensitivity adjustment values.
    pub fn asa(&self) -> [u8; 3] {
        self.asa
    }

    /// The current operating mode.
    pub fn mode(&self) -> Mode {
        Mode::from_cntl1(self.cntl1)
    }

    /// The current output setting (CNTL1.BIT).
    pub fn bits(&self) -> MagBits {
        MagBits::from_cntl1(self.cntl1)
    }

    /// The field the die senses until the next [`Ak8963::advance`].
    pub fn held_source(&self) -> MagSource {
        self.source
    }

    /// The register value at `addr`, without side effects.
    pub fn peek(&self, addr: u8) -> u8 {
        match addr {
            reg::WIA => self.identity.unwrap_or(map::WIA_VALUE),
            reg::INFO => self.info,
            reg::ST1 => flag(self.drdy, bits::ST1_DRDY) | flag(self.dor, bits::ST1_DOR),
            reg::HXL..=reg::HZH => self.data[usize::from(addr - reg::HXL)],
            reg::ST2 => self.st2,
            reg::CNTL1 => self.cntl1,
            reg::ASTC => self.astc,
            reg::TS1 => self.ts[0],
            reg::TS2 => self.ts[1],
            reg::I2CDIS => self.i2cdis,
            reg::ASAX..=reg::ASAZ if self.mode() == Mode::FuseRom => {
                self.asa[usize::from(addr - reg::ASAX)]
            }
            _ => 0x00, // CNTL2 reads 0; the fuse ROM reads 0 outside fuse ROM access mode
        }
    }

    /// Reads the register at `addr` as a bus access does (data-read protection, DRDY/DOR clear).
    pub fn read_register(&mut self, addr: u8) -> u8 {
        let value = self.peek(addr);
        if (reg::HXL..=reg::ST2).contains(&addr) {
            self.drdy = false;
            self.dor = false;
            self.protected = addr != reg::ST2;
        }
        value
    }

    /// Writes the register at `addr` as a bus access does. Read-only registers ignore it.
    pub fn write_register(&mut self, addr: u8, value: u8) {
        match addr {
            reg::CNTL1 => self.set_cntl1(value & (bits::CNTL1_BIT | bits::CNTL1_MODE)),
            reg::CNTL2 if value & bits::CNTL2_SRST != 0 => self.reset(),
            reg::ASTC => self.astc = value & bits::ASTC_SELF,
            reg::TS1 => self.ts[0] = value,
            reg::TS2 => self.ts[1] = value,
            reg::I2CDIS => self.i2cdis = value,
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

    /// Whether the next byte written over I2C is data (not the register pointer).
    pub fn expects_data(&self) -> bool {
        !self.expect_register
    }

    /// Reads the register at the pointer and moves the pointer on (DS 7.2.3 wrapping rules).
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

    /// Moves the die's clock to `now_ns` (never backwards) with `source` as the field it senses
    /// from now on, and completes every measurement due by then.
    pub fn advance(&mut self, now_ns: u64, source: MagSource) {
        self.source = source;
        self.now_ns = self.now_ns.max(now_ns);
        let Some(due) = self.next_due else { return };
        if self.now_ns < due {
            return;
        }
        let mode = self.mode();
        match mode.period_ns() {
            Some(period) => {
                let completed = (self.now_ns - due) / period + 1;
                self.next_due = Some(due.saturating_add(completed.saturating_mul(period)));
                self.measure(completed > 1);
            }
            None => {
                self.next_due = None;
                self.measure(false);
                self.cntl1 &= bits::CNTL1_BIT; // back to power-down (DS 6.4)
            }
        }
    }

    fn set_cntl1(&mut self, value: u8) {
        self.cntl1 = value;
        let start = self.now_ns.saturating_add(map::MEASUREMENT_NS);
        self.next_due = match self.mode() {
            Mode::Single | Mode::SelfTest | Mode::Continuous1 | Mode::Continuous2 => Some(start),
            _ => None,
        };
    }

    /// Stores one measurement (`overrun`: a continuous measurement was overwritten unread).
    fn measure(&mut self, overrun: bool) {
        if self.protected {
            self.skipped = true;
            return;
        }
        let mode = self.mode();
        let out = self.bits();
        let bitm = if out == MagBits::Bits16 {
            bits::ST2_BITM
        } else {
            0
        };
        let (data, st2) = if mode == Mode::SelfTest && self.astc & bits::ASTC_SELF != 0 {
            (le_bytes(mag_self_test(self.asa, out)), bitm)
        } else {
            match self.source {
                MagSource::Physical(field) => {
                    let (raw, overflow) = mag_measurement(field, self.asa, out);
                    (le_bytes(raw), bitm | flag(overflow, bits::ST2_HOFL))
                }
                MagSource::Registers { data, st2 } => {
                    (data, st2 & (bits::ST2_HOFL | bits::ST2_BITM))
                }
            }
        };
        let continuous = mode.period_ns().is_some();
        self.dor = continuous && (self.drdy || self.skipped || overrun);
        self.skipped = false;
        self.drdy = true;
        self.data = data;
        self.st2 = st2;
    }
}

fn flag(set: bool, bit: u8) -> u8 {
    if set {
        bit
    } else {
        0
    }
}

fn le_bytes(raw: [i16; 3]) -> [u8; 6] {
    let [x, y, z] = raw.map(i16::to_le_bytes);
    [x[0], x[1], y[0], y[1], z[0], z[1]]
}

impl I2cTarget for Ak8963 {
    fn start(&mut self, address: u8, read: bool) -> bool {
        self.expect_register = !read;
        address == map::I2C_ADDRESS
    }

    fn write(&mut self, byte: u8) -> bool {
        if self.expect_register {
            self.expect_register = false;
            self.pointer = byte;
        } else {
            self.write_next(byte);
        }
        true
    }

    fn read(&mut self) -> u8 {
        self.read_next()
    }

    fn stop(&mut self) {
        self.expect_register = false;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: u64 = 1_000_000;

    fn ak() -> Ak8963 {
        Ak8963::new([128, 128, 128], 0x9A)
    }

    fn read(ak: &mut Ak8963, addr: u8, n: usize) -> [u8; 8] {
        ak.set_pointer(addr);
        let mut out = [0; 8];
        for byte in out.iter_mut().take(n) {
            *byte = ak.read_next();
        }
        out
    }

    #[test]
    fn identity_and_fuse_rom() {
        let mut ak = Ak8963::new([0xB0, 0xB1, 0xB2], 0x9A);
        assert_eq!(read(&mut ak, 0x00, 2)[..2], [0x48, 0x9A]);
        assert_eq!(
            read(&mut ak, 0x10, 3)[..3],
            [0, 0, 0],
            "fuse ROM hidden in power-down"
        );
        ak.write_register(0x0A, 0x1F);
        assert_eq!(
            read(&mut ak, 0x10, 4)[..4],
            [0xB0, 0xB1, 0xB2, 0xB0],
            "wraps 0x12 → 0x10"
        );
        assert_eq!(ak.peek(0x0A), 0x1F);
    }

    #[test]
    fn continuous_mode_timing_and_data_ready() {
        let mut ak = ak();
        ak.write_register(0x0A, 0x12); // 16-bit, 8 Hz
        ak.advance(7 * MS, MagSource::Physical([0.0, 0.15, 0.0]));
        assert_eq!(ak.peek(0x02), 0x00, "first measurement after 7.2 ms");
        ak.advance(8 * MS, MagSource::Physical([0.0, 0.15, 0.0]));
        assert_eq!(read(&mut ak, 0x02, 8), [0x01, 1, 0, 0, 0, 0, 0, 0x10]);
        assert_eq!(ak.peek(0x02), 0x00, "reading the data cleared DRDY");
        ak.advance(130 * MS, MagSource::Physical([0.0, 0.3, 0.0]));
        assert_eq!(ak.peek(0x02), 0x00, "next one at 132.2 ms");
        ak.advance(133 * MS, MagSource::Physical([0.0, 0.3, 0.0]));
        assert_eq!(read(&mut ak, 0x02, 2)[..2], [0x01, 2]);
    }

    #[test]
    fn unread_data_overwritten_sets_dor() {
        let mut ak = ak();
        ak.write_register(0x0A, 0x06); // 14-bit, 100 Hz
        ak.advance(8 * MS, MagSource::Physical([0.0; 3]));
        assert_eq!(ak.peek(0x02), 0x01);
        ak.advance(18 * MS, MagSource::Physical([0.0; 3]));
        assert_eq!(ak.peek(0x02), 0x03, "DRDY | DOR");
        ak.read_register(0x09);
        assert_eq!(ak.peek(0x02), 0x00);
        // Two periods in one step: one measurement skipped.
        ak.advance(38 * MS, MagSource::Physical([0.0; 3]));
        assert_eq!(ak.peek(0x02), 0x03);
    }

    #[test]
    fn data_is_protected_until_st2_is_read() {
        let mut ak = ak();
        ak.write_register(0x0A, 0x16);
        ak.advance(8 * MS, MagSource::Physical([0.0, 0.15, 0.0]));
        assert_eq!(read(&mut ak, 0x03, 1)[0], 1); // HXL: read started
        ak.advance(18 * MS, MagSource::Physical([0.0, 0.3, 0.0]));
        assert_eq!(
            read(&mut ak, 0x04, 6)[..6],
            [0, 0, 0, 0, 0, 0x10],
            "old data, then ST2"
        );
        assert_eq!(ak.peek(0x03), 1, "the 18 ms measurement was discarded");
        ak.advance(28 * MS, MagSource::Physical([0.0, 0.3, 0.0]));
        assert_eq!(
            read(&mut ak, 0x02, 2)[..2],
            [0x03, 2],
            "next one stored, DOR reports the skip"
        );
    }

    #[test]
    fn single_measurement_returns_to_power_down() {
        let mut ak = ak();
        ak.write_register(0x0A, 0x11);
        ak.advance(5 * MS, MagSource::Physical([0.0, 0.0, -0.15])); // −z MPU = +z AK
        assert_eq!(ak.peek(0x0A), 0x11);
        ak.advance(8 * MS, MagSource::Physical([0.0, 0.0, -0.15]));
        assert_eq!(ak.peek(0x0A), 0x10, "power-down, BIT kept");
        assert_eq!(read(&mut ak, 0x02, 8), [0x01, 0, 0, 0, 0, 1, 0, 0x10]);
        ak.advance(100 * MS, MagSource::Physical([0.0; 3]));
        assert_eq!(ak.peek(0x02), 0x00, "no further measurement");
    }

    #[test]
    fn overflow_sets_hofl() {
        let mut ak = ak();
        ak.write_register(0x0A, 0x01);
        ak.advance(10 * MS, MagSource::Physical([3000.0, 3000.0, 0.0]));
        assert_eq!(ak.peek(0x09), 0x08, "HOFL, 14-bit");
        assert_eq!(
            [ak.peek(0x03), ak.peek(0x04)],
            [0x88, 0x13],
            "data still stored: 5000 LSB"
        );
    }

    #[test]
    fn self_test_uses_the_internal_field_only_with_self_set() {
        let mut ak = ak();
        ak.write_register(0x0C, 0xFF);
        assert_eq!(ak.peek(0x0C), 0x40);
        ak.write_register(0x0A, 0x08);
        ak.advance(10 * MS, MagSource::Physical([30.0, 30.0, 30.0]));
        let d = read(&mut ak, 0x03, 6);
        let z = i16::from_le_bytes([d[4], d[5]]);
        assert_eq!(z, -400);
        assert_eq!(ak.peek(0x0A), 0x00);
    }

    #[test]
    fn image_source_and_soft_reset() {
        let mut ak = ak();
        ak.write_register(0x0A, 0x01);
        ak.advance(
            10 * MS,
            MagSource::Registers {
                data: [1, 2, 3, 4, 5, 6],
                st2: 0xFF,
            },
        );
        assert_eq!(read(&mut ak, 0x03, 7)[..7], [1, 2, 3, 4, 5, 6, 0x18]);
        ak.write_register(0x0C, 0x40);
        ak.write_register(0x0B, 0x01);
        for addr in 0..0x13 {
            assert_eq!(
                ak.peek(addr),
                Ak8963::new([128; 3], 0x9A).peek(addr),
                "{addr:#04x}"
            );
        }
        assert_eq!(ak.peek(0x0B), 0);
    }

    #[test]
    fn i2c_target_pointer_and_wrap() {
        let mut ak = ak();
        assert!(!ak.start(0x0D, false));
        assert!(ak.start(0x0C, false));
        assert!(ak.write(0x0A));
        assert!(ak.write(0x06)); // CNTL1
        assert!(ak.write(0x00)); // CNTL2: no reset
        assert!(ak.write(0x40)); // ASTC
        ak.stop();
        assert_eq!([ak.peek(0x0A), ak.peek(0x0C)], [0x06, 0x40]);
        ak.start(0x0C, false);
        ak.write(0x0C);
        ak.start(0x0C, true);
        assert_eq!([ak.read(), ak.read()], [0x40, 0x48], "0x0C wraps to WIA");
    }

    #[test]
    fn fault_reset_and_wrong_identity() {
        let mut ak = ak();
        ak.write_register(0x0A, 0x16); // continuous mode 2, 16-bit
        ak.advance(20 * MS, MagSource::Physical([0.0, 15.0, 0.0]));
        assert_eq!(read(&mut ak, 0x02, 1)[0] & 0x01, 0x01, "DRDY");
        ak.fault_identity(Some(0x00));
        ak.fault_reset();
        assert_eq!(
            read(&mut ak, 0x00, 3)[..3],
            [0x00, 0x9A, 0x00],
            "WIA wrong, ST1 clear"
        );
        assert_eq!(read(&mut ak, 0x03, 7)[..7], [0; 7], "data as at power-up");
        assert_eq!(ak.mode(), Mode::PowerDown);
        ak.advance(200 * MS, MagSource::Physical([0.0, 15.0, 0.0]));
        assert_eq!(
            read(&mut ak, 0x02, 1)[0],
            0x00,
            "no measurement until CNTL1 again"
        );
        ak.fault_identity(None);
        assert_eq!(read(&mut ak, 0x00, 1)[0], 0x48);
    }
}
