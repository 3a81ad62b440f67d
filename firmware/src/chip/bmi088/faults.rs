//! The chip faults of the BMI088 (the [`Chip`](super::super::Chip) fault hooks,
//! `margemu_model::fault`), on both dies at once.
//!
//! - **Reset** ([`Bmi088::fault_reset`]): both dies power-cycled ([`Bmi088Accel::power_cycle`],
//!   [`Bmi088Gyro::power_cycle`]): every register at its power-on value (DS 5.3, 5.5; the soft
//!   resets restore the same values): the accelerometer suspended and off (ACC_PWR_CONF 0x03,
//!   ACC_PWR_CTRL 0x00: no data until a driver turns it on again) and back in I2C mode (the
//!   next SPI transaction only switches it), ±6 g at 100 Hz; the gyroscope in normal mode at
//!   ±2000 °/s, 2000 Hz (BANDWIDTH 0x80), its FIFO and interrupt mapping off. Both FIFOs are
//!   emptied and the data-ready state cleared; the sensor time keeps counting. A driver's
//!   read-back of ACC_PWR_CTRL, ACC_CONF, ACC_RANGE, GYRO_RANGE, GYRO_BANDWIDTH or the INT
//!   mapping sees the difference.
//! - **Wrong identity** ([`Bmi088::fault_identity`]): ACC_CHIP_ID and GYRO_CHIP_ID both read
//!   the given value.
//! - **FIFO overflow** ([`Bmi088::fault_fifo_overflow`]): while on, each die's FIFO is filled
//!   with copies of each new frame and one more is written: on the accelerometer (AN 2.1,
//!   3.2.2) the frame is lost in FIFO mode or the oldest makes room in stream mode, and the
//!   next burst begins with a skip frame; on the gyroscope (AN 4) FIFO_STATUS.fifo_overrun is
//!   set, and fifo_int as the full FIFO raises it. A FIFO that is off receives nothing and
//!   does not overflow.
//!
//! Driver sequences that check these (read, no code taken): PX4
//! `src/drivers/imu/bosch/bmi088/BMI088_Accelerometer.cpp` and `BMI088_Gyroscope.cpp`
//! (`RegisterCheck`, the FIFO overrun and skip-frame handling and `FIFOReset`), ArduPilot
//! `libraries/AP_InertialSensor/AP_InertialSensor_BMI088.cpp` (CHIP_ID probes, FIFO reset).

use super::{Bmi088, Bmi088Accel, Bmi088Gyro};

/// One die's fault overrides, kept across resets (they belong to the fault window).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct DieFaults {
    /// What CHIP_ID reads instead of the die's identity.
    pub chip_id: Option<u8>,
    /// The FIFO is forced to overflow at each frame.
    pub fifo_overflow: bool,
}

impl Bmi088Accel {
    /// The wrong-identity fault: ACC_CHIP_ID reads `value`; `None` restores.
    pub fn fault_identity(&mut self, value: Option<u8>) {
        self.fault.chip_id = value;
    }

    /// The FIFO-overflow fault, on or off (see `faults.rs`).
    pub fn fault_fifo_overflow(&mut self, on: bool) {
        self.fault.fifo_overflow = on;
    }
}

impl Bmi088Gyro {
    /// The wrong-identity fault: GYRO_CHIP_ID reads `value`; `None` restores.
    pub fn fault_identity(&mut self, value: Option<u8>) {
        self.fault.chip_id = value;
    }

    /// The FIFO-overflow fault, on or off (see `faults.rs`).
    pub fn fault_fifo_overflow(&mut self, on: bool) {
        self.fault.fifo_overflow = on;
    }
}

impl Bmi088 {
    /// The reset fault: both dies power-cycled (see `faults.rs`).
    pub fn fault_reset(&mut self) {
        self.accel.power_cycle();
        self.gyro.power_cycle();
        self.restart_accel_clock();
    }

    /// The wrong-identity fault on both dies.
    pub fn fault_identity(&mut self, value: Option<u8>) {
        self.accel.fault_identity(value);
        self.gyro.fault_identity(value);
    }

    /// The FIFO-overflow fault on both dies.
    pub fn fault_fifo_overflow(&mut self, on: bool) {
        self.accel.fault_fifo_overflow(on);
        self.gyro.fault_fifo_overflow(on);
    }
}
