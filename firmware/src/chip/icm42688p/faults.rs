//! The chip faults of the ICM-42688-P (the [`Chip`](super::super::Chip) fault hooks,
//! `margemu_model::fault`).
//!
//! - **Reset** ([`Icm42688p::fault_reset`]): a power cycle ([`Icm42688p::power_cycle`]). The
//!   datasheet's soft reset (DEVICE_CONFIG.SOFT_RESET_CONFIG) restores every register of every
//!   bank to its power-on value as well, so both share one path: sensors off (PWR_MGMT0 = 0),
//!   ±2000 °/s and ±16 g at 1 kHz, FIFO in bypass and empty, interrupts cleared but
//!   RESET_DONE_INT, INTF_CONFIG1 = 0x91 (AFSR back on), bank 0 selected, the AFSR range state
//!   low. The data registers read −32768 from the next sample on (sensors off) and the chip
//!   takes no sample until a driver turns a sensor on again: a driver's read-back of
//!   PWR_MGMT0, GYRO_CONFIG0, ACCEL_CONFIG0, FIFO_CONFIG, INT_CONFIG, INT_SOURCE0 or
//!   INTF_CONFIG1 sees the difference.
//! - **Wrong identity** ([`Icm42688p::fault_identity`]): WHO_AM_I reads the given value.
//! - **FIFO overflow** ([`Icm42688p::fault_fifo_overflow`]): while on, each sample's packet is
//!   followed by copies of it until one does not fit: in stream mode the oldest packets make
//!   room, in stop-on-full mode the copy is dropped; either way FIFO_LOST_PKT counts it,
//!   FIFO_FULL_INT is set (INT1/INT2 as INT_SOURCE routes it) and FIFO_COUNT reads the full
//!   FIFO (2048 bytes of 16-byte packets, 2040 of 20-byte ones). In bypass mode nothing is
//!   written and nothing overflows, as on the silicon.
//!
//! Driver sequences that check these (read for their register sequences, no code taken):
//! ArduPilot `libraries/AP_InertialSensor/AP_InertialSensor_Invensensev3.cpp` (checked
//! registers, `check_next_register` each sample, FIFO reset on a bad header), PX4
//! `src/drivers/imu/invensense/icm42688p/ICM42688P.cpp` (`RegisterCheck`, FIFO_FULL_INT and
//! the count check in `FIFORead`, `FIFOReset`).

use super::Icm42688p;

/// The fault hooks' overrides, kept across resets (they belong to the fault window).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct FaultState {
    /// What WHO_AM_I reads instead of the configured identity.
    pub who_am_i: Option<u8>,
    /// The FIFO is forced to overflow at each sample.
    pub fifo_overflow: bool,
}

impl Icm42688p {
    /// The reset fault: a power cycle (see `faults.rs`).
    pub fn fault_reset(&mut self) {
        self.power_cycle();
    }

    /// The wrong-identity fault: WHO_AM_I reads `value`; `None` restores.
    pub fn fault_identity(&mut self, value: Option<u8>) {
        self.fault.who_am_i = value;
    }

    /// The FIFO-overflow fault, on or off (see `faults.rs`).
    pub fn fault_fifo_overflow(&mut self, on: bool) {
        self.fault.fifo_overflow = on;
    }
}
