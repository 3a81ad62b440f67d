//! The chip faults of the BMI270 (the [`Chip`](super::super::Chip) fault hooks,
//! `margemu_model::fault`).
//!
//! - **Reset** ([`Bmi270::fault_reset`]): a power cycle ([`Bmi270::power_cycle`]): every
//!   register at its power-on value (DS: 5.2 register map; the soft reset CMD 0xB6 restores the
//!   same values), the configuration upload lost (INTERNAL_STATUS not_init, so the sensors give
//!   no data until a driver uploads the file again), PWR_CONF adv_power_save on, PWR_CTRL 0,
//!   the FIFO empty, interrupts cleared, and the interface back in I2C mode: the first SPI
//!   transaction after it only switches to SPI (reads 0x00), as after power-up. SENSORTIME
//!   keeps counting (the chip keeps its clock). A driver's read-back of PWR_CTRL, ACC_CONF,
//!   GYR_CONF, the ranges, FIFO_CONFIG or INTERNAL_STATUS sees the difference.
//! - **Wrong identity** ([`Bmi270::fault_identity`]): CHIP_ID reads the given value.
//! - **FIFO overflow** ([`Bmi270::fault_fifo_overflow`]): while on, each frame is followed by
//!   copies of it until one does not fit: the FIFO is full (FIFO_LENGTH at its fill level) and
//!   the frame that did not fit is lost, which in stream mode sets ERR_REG.fifo_err (DS: 4.7
//!   FIFO, ERR_REG), as `fifo.rs` does for any frame that does not fit.
//!
//! Driver sequences that check these (read, no code taken): ArduPilot
//! `libraries/AP_InertialSensor/AP_InertialSensor_BMI270.cpp` (its checked registers and
//! `check_next_register`, the FIFO reset on a bad frame), Betaflight
//! `src/main/drivers/accgyro/accgyro_spi_bmi270.c` (CHIP_ID probe).

use super::Bmi270;

/// The fault hooks' overrides, kept across resets (they belong to the fault window).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct FaultState {
    /// What CHIP_ID reads instead of 0x24.
    pub chip_id: Option<u8>,
    /// The FIFO is forced to overflow at each frame.
    pub fifo_overflow: bool,
}

impl Bmi270 {
    /// The reset fault: a power cycle (see `faults.rs`).
    pub fn fault_reset(&mut self) {
        self.power_cycle();
    }

    /// The wrong-identity fault: CHIP_ID reads `value`; `None` restores.
    pub fn fault_identity(&mut self, value: Option<u8>) {
        self.fault.chip_id = value;
    }

    /// The FIFO-overflow fault, on or off (see `faults.rs`).
    pub fn fault_fifo_overflow(&mut self, on: bool) {
        self.fault.fifo_overflow = on;
    }
}
