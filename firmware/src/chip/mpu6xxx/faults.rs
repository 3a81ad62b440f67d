//! The chip faults of the 6xxx family (the [`Chip`](super::super::Chip) fault hooks,
//! `margemu_model::fault`).
//!
//! - **Reset** ([`Mpu6xxx::fault_reset`]): a power cycle of both dies
//!   ([`Mpu6xxx::power_cycle`]): every register at the part's power-on value (RM-MPU-9250A-00
//!   section 3 and the MPU-6500 RM: PWR_MGMT_1 = 0x01, the clock running on the PLL; the
//!   MPU-6000 PS/RM: 0x40, asleep; the ICM-20602 DS: 0x41, asleep; every other register 0
//!   but WHO_AM_I and the factory trim), the data registers, FIFO, INT_STATUS and the
//!   auxiliary master cleared, the AK8963 in power-down (its own power-on values). A part
//!   that wakes asleep takes no samples until a driver clears SLEEP, and one that wakes
//!   running samples at the power-on rate and ranges (±2 g, ±250 °/s): a driver's read-back
//!   of GYRO_CONFIG, ACCEL_CONFIG, CONFIG, SMPLRT_DIV, INT_ENABLE, USER_CTRL or PWR_MGMT_1 sees
//!   the difference.
//! - **Wrong identity** ([`Mpu6xxx::fault_identity`]): WHO_AM_I, and the AK8963's WIA on the
//!   parts that carry one, read the given value.
//! - **FIFO overflow** ([`Mpu6xxx::fault_fifo_overflow`]): while on, each sample, after its
//!   own record, fills the FIFO with copies of that record up to its size and writes one more,
//!   so the FIFO wraps as the RM says (CONFIG.FIFO_MODE = 0: the oldest byte is dropped, so the
//!   FIFO no longer begins on a record boundary; FIFO_MODE = 1: the new byte is lost) and
//!   INT_STATUS.FIFO_OFLOW_INT is set (and INT driven, when FIFO_OFLOW_EN). With the FIFO off
//!   (USER_CTRL.FIFO_EN clear, or nothing in FIFO_EN) nothing is written, so nothing overflows,
//!   as on the silicon.
//!
//! Driver sequences that check these (read for their register sequences, no code taken):
//! ArduPilot `libraries/AP_InertialSensor/AP_InertialSensor_Invensense.cpp`
//! (`_check_register` list and `check_next_register` each sample; FIFO_OFLOW → FIFO reset) and
//! PX4 `src/drivers/imu/invensense/mpu6000/MPU6000.cpp` (`RegisterCheck`, FIFO overflow
//! handling in `FIFORead`).

use margemu_protocol::regmap::mpu6xxx::{bits, reg};

use super::Mpu6xxx;

/// The fault hooks' overrides, kept across resets (they belong to the fault window).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct FaultState {
    /// What WHO_AM_I (and the AK8963's WIA) reads instead of the part's identity.
    pub who_am_i: Option<u8>,
    /// The FIFO is forced to overflow at each sample.
    pub fifo_overflow: bool,
}

impl Mpu6xxx {
    /// The reset fault: a power cycle of both dies (see `faults.rs`).
    pub fn fault_reset(&mut self) {
        self.power_cycle();
    }

    /// The wrong-identity fault: WHO_AM_I (and the AK8963's WIA) read `value`; `None` restores.
    pub fn fault_identity(&mut self, value: Option<u8>) {
        self.fault.who_am_i = value;
        if let Some(ak) = &mut self.ak {
            ak.fault_identity(value);
        }
    }

    /// The FIFO-overflow fault, on or off (see `faults.rs`).
    pub fn fault_fifo_overflow(&mut self, on: bool) {
        self.fault.fifo_overflow = on;
    }

    /// Fills the FIFO with copies of the record of `data` until it is full, then writes one
    /// more record: the overflow of a FIFO nobody reads.
    pub(super) fn fifo_fill(&mut self, data: &[u8]) {
        if self.regs[usize::from(reg::USER_CTRL)] & bits::USER_FIFO_EN == 0 {
            return;
        }
        let capacity = self.fifo.capacity();
        while self.fifo.len() < capacity {
            let before = self.fifo.len();
            self.fifo_push_record(data);
            if self.fifo.len() == before {
                return; // no source enabled: records are empty
            }
        }
        self.fifo_push_record(data);
    }
}
