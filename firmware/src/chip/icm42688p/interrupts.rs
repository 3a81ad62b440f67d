//! INT_STATUS and the INT1/INT2 pins (DS 4.12 Interrupts; INT_CONFIG,
//! INT_CONFIG0, INT_CONFIG1, INT_SOURCE0, INT_SOURCE3).
//!
//! Every event sets its INT_STATUS bit (data ready, FIFO threshold, FIFO full, reset done),
//! routed or not, so polling drivers see it. A pin whose INT_SOURCE routes the event then
//! either holds while a routed status bit is set (INTx_MODE latched) or starts a pulse of
//! 100 µs, or 8 µs with INT_CONFIG1.INT_TPULSE_DURATION. Unless INT_TDEASSERT_DISABLE, a pulse
//! does not start within 100 µs of the previous pulse's end (the minimum de-assertion time),
//! which is why drivers set it at ODRs of 4 kHz and up.

use margemu_protocol::regmap::icm42688p::{bank0, bits};

use super::Icm42688p;

/// Minimum INT de-assertion time, ns.
pub const INT_DEASSERT_NS: u64 = 100_000;

/// One pin's latest pulse.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct Pulse {
    start_ns: Option<u64>,
    len_ns: u64,
}

impl Pulse {
    pub(super) fn end_ns(self) -> Option<u64> {
        Some(self.start_ns?.saturating_add(self.len_ns))
    }

    fn active_at(self, now_ns: u64) -> bool {
        match (self.start_ns, self.end_ns()) {
            (Some(start), Some(end)) => now_ns >= start && now_ns < end,
            _ => false,
        }
    }
}

impl Icm42688p {
    /// Sets `status` bits in INT_STATUS and pulses the pins they are routed to.
    pub(super) fn raise_interrupt(&mut self, status: u8) {
        self.int_status |= status;
        let config1 = self.reg0(bank0::INT_CONFIG1);
        let len_ns = if config1 & bits::INT_TPULSE_DURATION != 0 {
            8_000
        } else {
            100_000
        };
        let deassert_ns = if config1 & bits::INT_TDEASSERT_DISABLE != 0 {
            0
        } else {
            INT_DEASSERT_NS
        };
        let now = self.now_ns;
        let (source0, source3) = (self.reg0(bank0::INT_SOURCE0), self.reg0(bank0::INT_SOURCE3));
        for (source, pulse) in [(source0, &mut self.int1), (source3, &mut self.int2)] {
            if status & source == 0 {
                continue;
            }
            let free = pulse
                .end_ns()
                .is_none_or(|end| now >= end.saturating_add(deassert_ns));
            if free {
                *pulse = Pulse {
                    start_ns: Some(now),
                    len_ns,
                };
            }
        }
    }

    /// Whether pin `line` (1 or 2) is asserted at `now_ns`, before polarity.
    pub(super) fn int_line_asserted(&self, line: u8, now_ns: u64) -> bool {
        let config = self.reg0(bank0::INT_CONFIG);
        let (latched, source, pulse) = if line == 1 {
            (
                config & bits::INT1_MODE != 0,
                self.reg0(bank0::INT_SOURCE0),
                self.int1,
            )
        } else {
            (
                config & bits::INT2_MODE != 0,
                self.reg0(bank0::INT_SOURCE3),
                self.int2,
            )
        };
        if latched {
            self.int_status & source & 0x7F != 0
        } else {
            pulse.active_at(now_ns)
        }
    }
}
