//! The PNI RM3100 3-axis magneto-inductive magnetometer (MagI2C ASIC): register addresses, bits,
//! reset values, I2C addresses, the continuous-mode rates (TMRC), the measurement time and gain
//! as functions of the cycle counts, and the µT → register conversion (24-bit big-endian).
//!
//! Sources. The datasheet ("DS" below: PNI "RM3100 & RM2100 Magneto-Inductive Magnetometer User
//! Manual", doc 1017252 V14.0): Table 3-1 (gain 20/38/75 LSB/µT and maximum single-axis sample
//! rate 1600/850/440 Hz at 50/100/200 cycle counts, "divide by 3 for max. 3-axis sample rate";
//! circuit oscillation frequency 180 kHz; field range ±800 µT), §4.5 (7-bit I2C address
//! 0b01000 + SA1:SA0, 0x20–0x23), §4.4 (SPI: R/W̄ bit 7 + 7-bit address, auto-increment, STATUS
//! returned during the address byte), Table 5-1 (register map and defaults: CCX/CCY/CCZ =
//! 0x00C8, TMRC = 0x96, HSHAKE = 0x1B), §5.2 (CMM bits; TMRC Table 5-4: 0x92 ≈ 600 Hz to 0x9F
//! ≈ 0.075 Hz; the cycle counts override a faster TMRC), §5.3 (POLL bits), §5.4.1 (STATUS bit 7
//! DRDY), §5.5 (results: 24-bit two's complement, MSB first), §5.6 (BIST, HSHAKE, REVID). PNI's
//! RM3100 FAQ: "cycle count and gain are linearly related" (200 → 75, 300 → 113, 400 → 150).
//!
//! What the drivers rely on (nothing copied from them): ArduPilot
//! `libraries/AP_Compass/AP_Compass_RM3100.cpp` has no identity check: it requires the six
//! cycle-count bytes to read their defaults (0x00, 0xC8), writes TMRC = 0x94 and CMM = 0x71 and
//! re-reads them in rotation, polls STATUS bit 7 and reads 9 bytes from 0x24 at 75 LSB/µT.
//! PX4 `src/drivers/magnetometer/rm3100/` (`rm3100.cpp`, `rm3100.h`, `rm3100_i2c.cpp`,
//! `rm3100_spi.cpp`) probes REVID = 0x22 at 0x20 or over SPI mode 3, runs the self test
//! (BIST = 0x8F, POLL = 0x70, XOK/YOK/ZOK), then CMM = 0x71 and TMRC = 0x95.
//!
//! Not from the datasheet (stated where used): the measurement time as an exact function of the
//! cycle count ([`axis_measurement_ns`], fitted to Table 3-1), the exact TMRC periods
//! ([`tmrc_period_ns`], the table's rates taken as exact halvings of 600 Hz) and the gain
//! between the tabulated points ([`lsb_per_ut`], PNI's linear rule: 0.375 LSB/µT per cycle count,
//! which the table rounds to 20 and 38 at 50 and 100 counts).
//!
//! ```
//! use margemu_protocol::regmap::rm3100::{data_bytes, lsb_per_ut, measurement, tmrc_period_ns, reg};
//! assert_eq!((reg::STATUS, reg::REVID), (0x34, 0x36));
//! assert_eq!(lsb_per_ut(200), 75.0);
//! assert_eq!(tmrc_period_ns(0x94), 6_666_666); // ~150 Hz
//! let raw = measurement([50.0, -0.02, 1000.0], [200; 3]);
//! assert_eq!(raw, [3750, -2, 75_000]);
//! assert_eq!(data_bytes(raw[1]), [0xFF, 0xFF, 0xFE]);
//! ```

use super::mpu6xxx::convert::round_saturate_i32;

/// The 7-bit I2C address with SA0 and SA1 low (DS §4.5: 0b01000 then SA1:SA0).
pub const I2C_ADDRESS_BASE: u8 = 0x20;

/// The 7-bit I2C address for the levels of SA0 (bit 0) and SA1 (bit 1): 0x20–0x23.
pub const fn i2c_address(sa0: bool, sa1: bool) -> u8 {
    I2C_ADDRESS_BASE | sa0 as u8 | (sa1 as u8) << 1
}

/// The value of REVID (read-only; PX4 probes it, ArduPilot does not).
pub const REVID_VALUE: u8 = 0x22;

/// Register addresses (DS Table 5-1). Addresses are 7 bits; bit 7 of the SPI address byte reads.
pub mod reg {
    /// Single measurement: PMX, PMY, PMZ.
    pub const POLL: u8 = 0x00;
    /// Continuous measurement mode: START, DRDM, CMX, CMY, CMZ.
    pub const CMM: u8 = 0x01;
    /// Cycle count, x axis, MSB (LSB at 0x05).
    pub const CCX: u8 = 0x04;
    /// Cycle count, y axis, MSB (LSB at 0x07).
    pub const CCY: u8 = 0x06;
    /// Cycle count, z axis, MSB (LSB at 0x09).
    pub const CCZ: u8 = 0x08;
    /// Last cycle-count byte (z LSB).
    pub const CCZ_LSB: u8 = 0x09;
    /// Continuous-mode update rate.
    pub const TMRC: u8 = 0x0B;
    /// X measurement, most significant byte (MX2); MX1, MX0 follow.
    pub const MX: u8 = 0x24;
    /// Y measurement, most significant byte.
    pub const MY: u8 = 0x27;
    /// Z measurement, most significant byte.
    pub const MZ: u8 = 0x2A;
    /// Last result byte (MZ0).
    pub const MZ_LSB: u8 = 0x2C;
    /// Built-in self test: STE, ZOK, YOK, XOK, BW, BP.
    pub const BIST: u8 = 0x33;
    /// Status: DRDY in bit 7.
    pub const STATUS: u8 = 0x34;
    /// Handshake: DRC0, DRC1, NACK0–2.
    pub const HSHAKE: u8 = 0x35;
    /// Revision identification, 0x22.
    pub const REVID: u8 = 0x36;
}

/// Bits.
pub mod bits {
    /// Axis bits of POLL (PMX, PMY, PMZ) and CMM (CMX, CMY, CMZ): x, y, z in bits 4, 5, 6.
    pub const AXES: u8 = 0x70;
    /// CMM: start continuous measurement.
    pub const CMM_START: u8 = 1 << 0;
    /// CMM: DRDY after any axis (1) or after the whole sequence (0) (DS Table 5-3).
    pub const CMM_DRDM: u8 = 1 << 2;
    /// CMM: the bits that read back. Bits 7 and 1 are reserved (write 0); bit 3 ("0" in the
    /// DS, DRDM1 in revisions before R05) is stored without effect, so PNI's own example value
    /// 0x79 reads back.
    pub const CMM_MASK: u8 = 0x7D;
    /// STATUS: data ready.
    pub const STATUS_DRDY: u8 = 1 << 7;
    /// BIST: self-test enable (a POLL write runs the self test).
    pub const BIST_STE: u8 = 1 << 7;
    /// BIST: XOK, YOK, ZOK (read-only results).
    pub const BIST_OK: u8 = 0x70;
    /// BIST: timeout field BW.
    pub const BIST_BW: u8 = 0x0C;
    /// BIST: LR periods field BP.
    pub const BIST_BP: u8 = 0x03;
    /// BIST: the writable bits.
    pub const BIST_MASK: u8 = BIST_STE | BIST_BW | BIST_BP;
    /// HSHAKE: DRDY cleared by any register write.
    pub const HSHAKE_DRC0: u8 = 1 << 0;
    /// HSHAKE: DRDY cleared by reading the results.
    pub const HSHAKE_DRC1: u8 = 1 << 1;
    /// HSHAKE: the writable bits.
    pub const HSHAKE_MASK: u8 = HSHAKE_DRC0 | HSHAKE_DRC1;
    /// HSHAKE: bit 3, which always reads 1.
    pub const HSHAKE_ONE: u8 = 1 << 3;
    /// HSHAKE: write to an undefined register.
    pub const HSHAKE_NACK0: u8 = 1 << 4;
    /// HSHAKE: POLL written during continuous mode, or CMM during a single measurement.
    pub const HSHAKE_NACK1: u8 = 1 << 5;
    /// HSHAKE: results read while DRDY was clear.
    pub const HSHAKE_NACK2: u8 = 1 << 6;
}

/// Reset values (DS Table 5-1).
pub mod reset {
    /// Cycle count of each axis: 200.
    pub const CYCLE_COUNT: u16 = 0x00C8;
    /// TMRC: ~37 Hz.
    pub const TMRC: u8 = 0x96;
    /// HSHAKE: DRC0, DRC1, bit 3 and NACK0 set.
    pub const HSHAKE: u8 = 0x1B;
}

/// The registers a write reaches (DS Table 5-1, "RW"); a write elsewhere sets NACK0.
pub const fn is_writable(addr: u8) -> bool {
    matches!(
        addr,
        reg::POLL | reg::CMM | reg::CCX..=reg::CCZ_LSB | reg::TMRC | reg::BIST | reg::HSHAKE
    )
}

/// The axes selected by a POLL or CMM value, as a mask: bit 0 x, bit 1 y, bit 2 z.
pub const fn axes(value: u8) -> u8 {
    (value & bits::AXES) >> 4
}

/// Time between continuous measurements set by TMRC (DS Table 5-4: 0x92 ~1.7 ms ~600 Hz, each
/// step halving the rate, to 0x9F ~13 s ~0.075 Hz). Taken as exactly 1/600 s × 2^(nibble − 2);
/// low nibbles 0 and 1, outside the table, act as 0x92 (assumption). The upper nibble "should be
/// 0x9" and is ignored.
pub const fn tmrc_period_ns(tmrc: u8) -> u64 {
    let n = (tmrc & 0x0F).saturating_sub(2);
    (5_000_000u64 << n) / 3
}

/// Fixed part of one axis measurement. Assumption: fitted so that [`axis_measurement_ns`]
/// meets DS Table 3-1's maximum single-axis rates (1600, 850, 440 Hz at 50, 100, 200 counts)
/// within 2%.
pub const AXIS_OVERHEAD_NS: u64 = 60_000;

/// Time of one axis measurement at `cycle_count`: the LR oscillator runs `cycle_count` cycles
/// in each bias direction at 180 kHz (DS §4.1 and Table 3-1), plus [`AXIS_OVERHEAD_NS`].
/// 200 counts: 2.28 ms (438 Hz).
pub const fn axis_measurement_ns(cycle_count: u16) -> u64 {
    AXIS_OVERHEAD_NS + cycle_count as u64 * 100_000 / 9
}

/// Time of a measurement of the `axes` (mask, as [`axes`]) at the given cycle counts: the axes
/// are measured one after the other (DS Table 3-1: "divide by 3 for max. 3-axis sample rate").
pub const fn measurement_ns(axes: u8, cycle_counts: [u16; 3]) -> u64 {
    let mut total = 0;
    let mut i = 0;
    while i < 3 {
        if axes & (1 << i) != 0 {
            total += axis_measurement_ns(cycle_counts[i]);
        }
        i += 1;
    }
    total
}

/// Time between continuous measurements: the TMRC period, or the measurement itself when that
/// is longer ("the rate established by the cycle count will override the TMRC request", DS
/// §5.2.1). ArduPilot's TMRC = 0x94 with 3 axes at 200 counts gives 6.85 ms (146 Hz).
pub const fn continuous_period_ns(tmrc: u8, axes: u8, cycle_counts: [u16; 3]) -> u64 {
    let tmrc = tmrc_period_ns(tmrc);
    let meas = measurement_ns(axes, cycle_counts);
    if meas > tmrc {
        meas
    } else {
        tmrc
    }
}

/// Duration of the built-in self test of the `axes` (mask) for a BIST value: per axis, the BP
/// number of LR periods (1, 2, 4) times the BW timeout (30, 60, 120 µs) (DS Tables 5-6, 5-7; 480
/// µs per axis with PX4's 0x8F). Assumptions: the axes are tested one after the other, and the
/// "unused" codes 00 act as the smallest setting.
pub const fn self_test_ns(bist: u8, axes: u8) -> u64 {
    let periods = match bist & bits::BIST_BP {
        0 | 1 => 1,
        2 => 2,
        _ => 4,
    };
    let timeout_ns = match (bist & bits::BIST_BW) >> 2 {
        0 | 1 => 30_000,
        2 => 60_000,
        _ => 120_000,
    };
    axes.count_ones() as u64 * periods * timeout_ns
}

/// Gain in LSB/µT at `cycle_count`: 0.375 per count (DS Table 3-1: 75 at 200; PNI FAQ: linear).
pub fn lsb_per_ut(cycle_count: u16) -> f32 {
    0.375 * f32::from(cycle_count)
}

/// The largest result (24-bit two's complement, DS §5.5).
pub const MAX_RAW: i32 = (1 << 23) - 1;

/// The smallest result.
pub const MIN_RAW: i32 = -(1 << 23);

/// The result of one axis: `field_ut` (µT along the axis) at the cycle count's gain, rounded
/// (halves away from zero) and saturated at 24 bits. NaN reads 0. Beyond ±800 µT (DS: the
/// monotonic range) the real output bends; here it stays linear up to saturation.
pub fn axis_to_raw(field_ut: f32, cycle_count: u16) -> i32 {
    round_saturate_i32(field_ut * lsb_per_ut(cycle_count), MIN_RAW, MAX_RAW)
}

/// The results of x, y, z for a field in µT in the chip's axes.
pub fn measurement(field_ut: [f32; 3], cycle_counts: [u16; 3]) -> [i32; 3] {
    core::array::from_fn(|i| axis_to_raw(field_ut[i], cycle_counts[i]))
}

/// The three result bytes of one axis, most significant first (DS §5.5).
pub fn data_bytes(raw: i32) -> [u8; 3] {
    let [_, a, b, c] = raw.to_be_bytes();
    [a, b, c]
}

/// Bytes of one register image: the result registers MX..=MZ (x, y, z, 24-bit big-endian) at
/// the cycle counts the image was computed for.
pub const IMAGE_LEN: usize = 9;

/// The image (MX..=MZ) of results x, y, z.
pub fn image(raw: [i32; 3]) -> [u8; IMAGE_LEN] {
    let [x, y, z] = raw.map(data_bytes);
    [x[0], x[1], x[2], y[0], y[1], y[2], z[0], z[1], z[2]]
}

/// The results x, y, z of an image.
pub fn parse_image(image: &[u8; IMAGE_LEN]) -> [i32; 3] {
    let [a, b, c, d, e, f, g, h, i] = *image;
    [
        from_data_bytes([a, b, c]),
        from_data_bytes([d, e, f]),
        from_data_bytes([g, h, i]),
    ]
}

/// The field in µT (chip axes) results stand for at `cycle_counts`.
pub fn field_ut(raw: [i32; 3], cycle_counts: [u16; 3]) -> [f64; 3] {
    core::array::from_fn(|i| f64::from(raw[i]) / f64::from(lsb_per_ut(cycle_counts[i])))
}

/// A result from its three bytes, sign-extended (what a driver computes).
pub fn from_data_bytes(bytes: [u8; 3]) -> i32 {
    i32::from_be_bytes([bytes[0], bytes[1], bytes[2], 0]) >> 8
}

/// The next register after `addr` in a burst: the address increments within 7 bits.
pub const fn next_address(addr: u8) -> u8 {
    addr.wrapping_add(1) & 0x7F
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn addresses_follow_the_pins() {
        assert_eq!(i2c_address(false, false), 0x20);
        assert_eq!(i2c_address(true, false), 0x21);
        assert_eq!(i2c_address(false, true), 0x22);
        assert_eq!(i2c_address(true, true), 0x23);
    }

    #[test]
    fn tmrc_table() {
        let rates_hz = [600.0, 300.0, 150.0, 75.0, 37.5, 18.75, 9.375, 4.69];
        for (i, hz) in rates_hz.into_iter().enumerate() {
            let period = tmrc_period_ns(0x92 + i as u8) as f64 * 1e-9;
            assert!((1.0 / period - hz).abs() / hz < 0.01, "{i}");
        }
        assert_eq!(tmrc_period_ns(0x9F), 13_653_333_333, "~13 s");
        assert_eq!(tmrc_period_ns(0x90), tmrc_period_ns(0x92));
    }

    #[test]
    fn measurement_time_meets_table_3_1() {
        for (cc, max_hz) in [(50u16, 1600.0), (100, 850.0), (200, 440.0)] {
            let hz = 1e9 / axis_measurement_ns(cc) as f64;
            assert!((hz - max_hz).abs() / max_hz < 0.02, "{cc}: {hz}");
            let three = 1e9 / measurement_ns(0b111, [cc; 3]) as f64;
            assert!(
                (three - max_hz / 3.0).abs() / max_hz < 0.01,
                "{cc}: {three}"
            );
        }
        assert_eq!(measurement_ns(0b010, [0, 200, 0]), axis_measurement_ns(200));
        assert_eq!(measurement_ns(0, [200; 3]), 0);
    }

    #[test]
    fn cycle_counts_override_a_faster_tmrc() {
        assert_eq!(continuous_period_ns(0x94, 0b111, [200; 3]), 6_846_666);
        assert_eq!(continuous_period_ns(0x95, 0b111, [200; 3]), 13_333_333);
        assert_eq!(continuous_period_ns(0x92, 0b001, [50; 3]), 1_666_666);
    }

    #[test]
    fn self_test_time() {
        assert_eq!(self_test_ns(0x8F, 0b111), 1_440_000);
        assert_eq!(self_test_ns(0x85, 0b001), 30_000);
        assert_eq!(self_test_ns(0x80, 0b011), 60_000);
        assert_eq!(self_test_ns(0x8A, 0), 0);
    }

    #[test]
    fn gain_conversion_and_bytes() {
        assert_eq!([lsb_per_ut(50), lsb_per_ut(100)], [18.75, 37.5]);
        assert_eq!(measurement([1.0; 3], [50, 100, 400]), [19, 38, 150]);
        assert_eq!(axis_to_raw(-0.0066, 200), 0);
        assert_eq!(axis_to_raw(-0.0067, 200), -1);
        assert_eq!(axis_to_raw(1e6, 200), MAX_RAW);
        assert_eq!(axis_to_raw(f32::NEG_INFINITY, 200), MIN_RAW);
        assert_eq!(axis_to_raw(f32::NAN, 200), 0);
        assert_eq!(data_bytes(MAX_RAW), [0x7F, 0xFF, 0xFF]);
        assert_eq!(data_bytes(MIN_RAW), [0x80, 0x00, 0x00]);
        for raw in [0, 1, -1, 3750, -75_000, MAX_RAW, MIN_RAW] {
            assert_eq!(from_data_bytes(data_bytes(raw)), raw);
        }
    }

    #[test]
    fn writable_registers_and_axes() {
        let writable = [
            0x00, 0x01, 0x04, 0x05, 0x06, 0x07, 0x08, 0x09, 0x0B, 0x33, 0x35,
        ];
        for addr in 0..0x80 {
            assert_eq!(is_writable(addr), writable.contains(&addr), "{addr:#04x}");
        }
        assert_eq!([axes(0x71), axes(0x10), axes(0x8F)], [0b111, 0b001, 0]);
        assert_eq!(next_address(0x2C), 0x2D);
        assert_eq!(next_address(0x7F), 0x00);
    }
}
