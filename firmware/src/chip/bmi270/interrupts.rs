//! Data-ready in INT_STATUS_1 and on the INT1/INT2 pins (DS: interrupts; INT1_IO_CTRL,
//! INT2_IO_CTRL, INT_LATCH, INT_MAP_DATA, INT_STATUS_1).
//!
//! A latch that brings new accel or gyro data sets INT_STATUS_1 acc_drdy_int / gyr_drdy_int;
//! reading INT_STATUS_1 clears them. INT_MAP_DATA drdy_int1 (bit 2) and drdy_int2 (bit 6)
//! route the event to the pins:
//! - **non-latched** (INT_LATCH = 0, the reset value): the pin asserts for
//!   [`DRDY_PULSE_NS`] from the event, and the status flags clear by themselves at the end of
//!   it. The BMI270 datasheet excerpts we could read give no figure; the BMA456 (the same
//!   register generation, an accelerometer of at most 1.6 kHz) clears its data-ready pin and
//!   flag "automatically after 1/(3200Hz)". The BMI270's gyro runs at up to 3.2 kHz, so a
//!   pulse that long would never end between samples and Betaflight, which waits for a rising
//!   edge per sample, would see none: the pulse is taken as 1/(6.4 kHz), the BMI270's internal
//!   gyro rate;
//! - **latched** (INT_LATCH = 1): the pin stays asserted while a mapped status flag is set, until
//!   INT_STATUS_1 is read.
//!
//! Electrically (INTx_IO_CTRL): lvl (bit 1) active high, od (bit 2) open drain, output_en
//! (bit 3). A pin whose output is disabled (the reset state) is not driven: it is reported as an
//! open-drain pin released, so it reads high through the board's pull-up and never asserts.

use margemu_protocol::regmap::bmi270::{bits, reg};

use super::Bmi270;

/// How long a non-latched data-ready pulse lasts, ns (1/6.4 kHz; see the module docs).
pub const DRDY_PULSE_NS: u64 = 156_250;

/// The data-ready state behind INT_STATUS_1 and the pins.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct Interrupts {
    /// INT_STATUS_1 acc_drdy_int / gyr_drdy_int raised and not read.
    status: u8,
    /// When the latest data-ready event happened.
    event_ns: Option<u64>,
}

impl Interrupts {
    /// Whether the latest event's pulse covers `now_ns`.
    fn pulse_at(&self, now_ns: u64) -> bool {
        self.event_ns
            .is_some_and(|start| now_ns >= start && now_ns < start.saturating_add(DRDY_PULSE_NS))
    }
}

impl Bmi270 {
    /// A latch brought new data of the sensors in `drdy` (STATUS drdy_acc / drdy_gyr bits).
    pub(super) fn raise_data_ready(&mut self, drdy: u8) {
        let mut status = 0;
        if drdy & bits::DRDY_ACC != 0 {
            status |= bits::ACC_DRDY_INT;
        }
        if drdy & bits::DRDY_GYR != 0 {
            status |= bits::GYR_DRDY_INT;
        }
        if status == 0 {
            return;
        }
        self.int.status = self.int_status_1() | status;
        self.int.event_ns = Some(self.now_ns);
    }

    /// INT_STATUS_1 as a read returns it now.
    pub(super) fn int_status_1(&self) -> u8 {
        if self.int_latched() || self.int.pulse_at(self.now_ns) {
            self.int.status
        } else {
            0
        }
    }

    /// INT_STATUS_1 was read: its flags clear.
    pub(super) fn int_status_1_read(&mut self) {
        self.int.status = 0;
    }

    /// Whether INT `line` (1 or 2) is asserted at `now_ns`, before its electrical settings.
    fn int_line_asserted(&self, line: u8, now_ns: u64) -> bool {
        let map = if line == 1 {
            bits::DRDY_INT1
        } else {
            bits::DRDY_INT2
        };
        if self.stored(reg::INT_MAP_DATA) & map == 0 {
            return false;
        }
        if self.int_latched() {
            self.int.status != 0
        } else {
            self.int.pulse_at(now_ns)
        }
    }

    /// The electrical level of INT1 at `now_ns` (`true` = high).
    pub fn int_pin_at(&self, now_ns: u64) -> bool {
        self.int_level_at(1, now_ns)
    }

    /// The electrical level of INT2 at `now_ns` (`true` = high).
    pub fn int2_pin_at(&self, now_ns: u64) -> bool {
        self.int_level_at(2, now_ns)
    }

    /// Whether INT1 is open drain (INT1_IO_CTRL.od), or not driven at all (output_en clear).
    pub fn int_open_drain(&self) -> bool {
        let io = self.int_io_ctrl(1);
        io & bits::INT_OD != 0 || io & bits::INT_OUTPUT_EN == 0
    }

    fn int_level_at(&self, line: u8, now_ns: u64) -> bool {
        let io = self.int_io_ctrl(line);
        if io & bits::INT_OUTPUT_EN == 0 {
            return true; // not driven: the pull-up
        }
        let active_high = io & bits::INT_LVL != 0;
        self.int_line_asserted(line, now_ns) == active_high
    }

    /// When the current INT1 pulse ends (non-latched mode only), for a board to schedule the
    /// edge.
    pub fn int_pulse_end_ns(&self) -> Option<u64> {
        let end = self.int.event_ns?.saturating_add(DRDY_PULSE_NS);
        let mapped = self.stored(reg::INT_MAP_DATA) & bits::DRDY_INT1 != 0;
        (mapped && !self.int_latched() && end > self.now_ns).then_some(end)
    }

    pub(super) fn int_reset(&mut self) {
        self.int = Interrupts::default();
    }

    fn int_latched(&self) -> bool {
        self.stored(reg::INT_LATCH) & bits::INT_LATCHED != 0
    }

    fn int_io_ctrl(&self, line: u8) -> u8 {
        self.stored(if line == 1 {
            reg::INT1_IO_CTRL
        } else {
            reg::INT2_IO_CTRL
        })
    }
}
