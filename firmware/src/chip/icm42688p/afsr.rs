//! AFSR, the adaptive full-scale range of the gyro, and the stall it causes: on at power-on,
//! and the default behaviour of the emulated gyro whenever a driver leaves it on.
//!
//! **What is known.** INTF_CONFIG1 bits 7:6 (reset value 0x91: bits 7:6 = 10) hold an AFSR
//! control the datasheet (DS-000347 rev. 1.7) lists as reserved. With AFSR on the gyro switches
//! between a low-noise range at low angular rates and a higher-noise range above them; at each
//! switch its output stops updating for 1–2 ms, bitwise identical samples, on one axis at a
//! time (ArduPilot issue #25025 "ICM42688 stuck gyro values", with 8 kHz logs; ArduPilot PR
//! #25332, whose description gives the switch "at angular rates below 100 deg/sec and a
//! higher noise mode above that level" and the stall "between 1ms and 2ms"; Betaflight issue
//! #12970 and PR #13132). Every flight firmware turns it off by writing 01 to bits 7:6, the
//! other bits kept (read for their register sequences, no code taken): Betaflight
//! `src/main/drivers/accgyro/accgyro_spi_icm426xx.c` (`ICM426XX_INTF_CONFIG1_AFSR_MASK` 0xC0,
//! `..._AFSR_DISABLE` 0x40, read-modify-write in `icm426xxGyroInit`), ArduPilot
//! `libraries/AP_InertialSensor/AP_InertialSensor_Invensensev3.cpp` (`(v & 0x3F) | 0x40` in
//! `hardware_init`) and PX4 `src/drivers/imu/invensense/icm42688p/ICM42688P.hpp` (its register
//! configuration sets bit 6 and clears bit 7 of INTF_CONFIG1).
//!
//! **The model.** AFSR is on unless INTF_CONFIG1 bits 7:6 read 01 (an assumption for the
//! undocumented codes 00 and 11: only 01 is known to turn it off). While on, each gyro axis is
//! in the high range when the magnitude of its new sample is at least [`AFSR_THRESHOLD_DPS`]
//! (converted to counts at the full scale in force: 1640 LSB at ±2000 °/s; a full scale
//! below 100 °/s never switches) and in the low range below it, one threshold without
//! hysteresis (the reports give none: an assumption). When an axis changes range at a sample,
//! that axis's output holds the value it had before the sample — in the data registers and in
//! the FIFO (16- and 20-bit) — for [`AFSR_STALL_NS`] from that sample's instant; a switch
//! during a stall does not extend it. The other axes and the accelerometer are unaffected. The
//! range state starts low at power-on and after a reset; with AFSR off the gyro never stalls
//! (the state follows the rate, so turning AFSR on later starts from the current range).

use margemu_protocol::regmap::icm42688p::image::field;
use margemu_protocol::regmap::icm42688p::{bank0, bits, GyroFs, DATA_LEN};

use super::Icm42688p;

/// The angular rate at which the gyro's range switches, °/s (ArduPilot PR #25332; see the
/// module docs of `afsr.rs`, and the chip docs of [`Icm42688p`]).
pub const AFSR_THRESHOLD_DPS: f32 = 100.0;

/// How long an axis's output holds at a switch, ns: 2 ms, the upper end of the 1–2 ms the
/// reports give (ArduPilot PR #25332), so a driver that leaves AFSR on is caught at every ODR
/// of 1 kHz and above.
pub const AFSR_STALL_NS: u64 = 2_000_000;

/// The code of INTF_CONFIG1's AFSR field (`bits::AFSR`, bits 7:6) that turns AFSR off.
const AFSR_OFF: u8 = 0x40;

/// The gyro's range state per axis and its stalls.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct Afsr {
    /// Each axis is in its high range.
    high: [bool; 3],
    /// Each axis holds its output until this instant.
    stall_until: [Option<u64>; 3],
    /// The 20-bit output each axis held last (what a stall repeats in 20-bit FIFO packets).
    last20: [i32; 3],
}

impl Icm42688p {
    /// Whether AFSR is on (INTF_CONFIG1 bits 7:6 other than 01).
    pub fn afsr_enabled(&self) -> bool {
        self.reg0(bank0::INTF_CONFIG1) & bits::AFSR != AFSR_OFF
    }

    /// Applies AFSR to a new gyro sample at the chip's clock: `data` (the big-endian data
    /// registers) and `gyro20` (the 20-bit values) become what the gyro outputs.
    pub(super) fn afsr_apply(&mut self, data: &mut [u8; DATA_LEN], gyro20: &mut [i32; 3]) {
        let now = self.now_ns;
        let enabled = self.afsr_enabled();
        let lsb = GyroFs::from_gyro_config0(self.reg0(bank0::GYRO_CONFIG0)).lsb_per_dps();
        let threshold = (AFSR_THRESHOLD_DPS * lsb) as i32;
        let previous = self.latest_data();
        for (axis, out20) in gyro20.iter_mut().enumerate() {
            let at = field::GYRO.start + 2 * axis;
            let (Some(new), Some(old)) = (data.get_mut(at..at + 2), previous.get(at..at + 2))
            else {
                continue;
            };
            let raw = i32::from(i16::from_be_bytes([new[0], new[1]]));
            let high = raw.abs() >= threshold;
            let state = &mut self.afsr;
            let (Some(was_high), Some(stall), Some(last20)) = (
                state.high.get_mut(axis),
                state.stall_until.get_mut(axis),
                state.last20.get_mut(axis),
            ) else {
                continue;
            };
            let stalled = stall.is_some_and(|end| now < end);
            if !enabled {
                *stall = None;
            } else if high != *was_high && !stalled {
                *stall = Some(now.saturating_add(AFSR_STALL_NS));
            }
            *was_high = high;
            if enabled && stall.is_some_and(|end| now < end) {
                new.copy_from_slice(old);
                *out20 = *last20;
            }
            *last20 = *out20;
        }
    }
}
