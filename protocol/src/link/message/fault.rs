//! [`AddFault`]: one scripted fault of the scene's schedule (`docs/spec/link.md` §5.16).
//!
//! After Configure, AddDevice and AddVibration, and before Start, the host sends one AddFault
//! per fault of the scene (`margemu_model::fault::Fault`: device index, window, kind with its
//! parameters), in schedule order, each with its device's seed, so the device draws each
//! fault's random stream (`fault_rng(seed, index)`) exactly as the host does. Floats travel
//! bit for bit (`f32`, as the model holds them).
//!
//! ```
//! use margemu_model::fault::{Fault, FaultKind, Sensor, Window};
//! use margemu_protocol::link::{AddFault, Message};
//! let stuck = Fault::new(0, Window::new(1_000, 2_000), FaultKind::Stuck { sensor: Sensor::Gyr });
//! let msg = Message::AddFault(AddFault { fault: stuck, seed: 7 });
//! let mut payload = [0u8; 64];
//! let n = msg.emit(&mut payload)?;
//! assert_eq!(n, 1 + 8 + 8 + 8 + 1 + 1);
//! assert_eq!(Message::parse(0x07, &payload[..n])?, msg);
//! # Ok::<(), margemu_protocol::link::Error>(())
//! ```

use crate::link::wire::{Reader, Writer};
use crate::link::Error;
use margemu_model::fault::{Fault, FaultKind, Sensor, Window};

/// Host → device: one fault of the schedule and its device's seed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AddFault {
    /// The fault.
    pub fault: Fault,
    /// Its device's seed (`margemu_sim::marg::device_seed`): its random streams' key.
    pub seed: u64,
}

/// Bytes before the kind's parameters: device, seed, start, end, kind code.
const FIXED_LEN: usize = 1 + 8 + 8 + 8 + 1;

/// The wire code of each kind: its position in `FaultKind`'s order ([`FaultKind::code`];
/// `docs/spec/link.md` §5.16).
pub fn kind_code(kind: &FaultKind) -> u8 {
    kind.code()
}

/// Bytes of a kind's parameters.
fn params_len(kind: &FaultKind) -> usize {
    match kind {
        FaultKind::Stuck { .. } | FaultKind::Dropout { .. } => 1,
        FaultKind::StuckAt { .. }
        | FaultKind::BiasStep { .. }
        | FaultKind::Scale { .. }
        | FaultKind::Noise { .. } => 1 + 12,
        FaultKind::Spikes { .. } => 1 + 4 + 4 + 1,
        FaultKind::MagSaturation { .. } => 12,
        FaultKind::Reset | FaultKind::FifoOverflow | FaultKind::Nak => 0,
        FaultKind::WrongIdentity { .. } => 1,
        FaultKind::Corrupt { .. }
        | FaultKind::ClockStretch { .. }
        | FaultKind::DrdyJitter { .. }
        | FaultKind::MissingDrdy { .. }
        | FaultKind::Late { .. } => 4,
        FaultKind::ClockOffset { .. } => 8,
    }
}

fn sensor(r: &mut Reader<'_>) -> Result<Sensor, Error> {
    Sensor::from_code(r.u8()?).ok_or(Error::InvalidValue)
}

fn parse_kind(code: u8, r: &mut Reader<'_>) -> Result<FaultKind, Error> {
    Ok(match code {
        0 => FaultKind::Stuck { sensor: sensor(r)? },
        1 => FaultKind::StuckAt {
            sensor: sensor(r)?,
            value: r.f32s()?,
        },
        2 => FaultKind::Dropout { sensor: sensor(r)? },
        3 => {
            let sensor = sensor(r)?;
            let (rate_hz, amplitude) = (r.f32()?, r.f32()?);
            let axes = r.u8()?;
            if axes > 0b111 {
                return Err(Error::InvalidValue);
            }
            FaultKind::Spikes {
                sensor,
                rate_hz,
                amplitude,
                axes,
            }
        }
        4 => FaultKind::BiasStep {
            sensor: sensor(r)?,
            bias: r.f32s()?,
        },
        5 => FaultKind::Scale {
            sensor: sensor(r)?,
            factor: r.f32s()?,
        },
        6 => FaultKind::Noise {
            sensor: sensor(r)?,
            std: r.f32s()?,
        },
        7 => FaultKind::MagSaturation { field: r.f32s()? },
        8 => FaultKind::Reset,
        9 => FaultKind::WrongIdentity { value: r.u8()? },
        10 => FaultKind::FifoOverflow,
        11 => FaultKind::Nak,
        12 => FaultKind::Corrupt {
            probability: r.f32()?,
        },
        13 => FaultKind::ClockStretch {
            stretch_ns: r.u32()?,
        },
        14 => FaultKind::ClockOffset {
            ppm: r.f32()?,
            drift_ppm_per_s: r.f32()?,
        },
        15 => FaultKind::DrdyJitter { max_ns: r.u32()? },
        16 => FaultKind::MissingDrdy {
            probability: r.f32()?,
        },
        17 => FaultKind::Late { delay_ns: r.u32()? },
        _ => return Err(Error::InvalidValue),
    })
}

fn emit_kind(kind: &FaultKind, w: &mut Writer<'_>) -> Result<(), Error> {
    match *kind {
        FaultKind::Stuck { sensor } | FaultKind::Dropout { sensor } => w.u8(sensor as u8),
        FaultKind::StuckAt { sensor, value: v }
        | FaultKind::BiasStep { sensor, bias: v }
        | FaultKind::Scale { sensor, factor: v }
        | FaultKind::Noise { sensor, std: v } => {
            w.u8(sensor as u8)?;
            w.f32s(&v)
        }
        FaultKind::Spikes {
            sensor,
            rate_hz,
            amplitude,
            axes,
        } => {
            w.u8(sensor as u8)?;
            w.f32(rate_hz)?;
            w.f32(amplitude)?;
            w.u8(axes)
        }
        FaultKind::MagSaturation { field } => w.f32s(&field),
        FaultKind::Reset | FaultKind::FifoOverflow | FaultKind::Nak => Ok(()),
        FaultKind::WrongIdentity { value } => w.u8(value),
        FaultKind::Corrupt { probability: p } | FaultKind::MissingDrdy { probability: p } => {
            w.f32(p)
        }
        FaultKind::ClockStretch { stretch_ns: n }
        | FaultKind::DrdyJitter { max_ns: n }
        | FaultKind::Late { delay_ns: n } => w.u32(n),
        FaultKind::ClockOffset {
            ppm,
            drift_ppm_per_s,
        } => {
            w.f32(ppm)?;
            w.f32(drift_ppm_per_s)
        }
    }
}

impl AddFault {
    pub(crate) fn buffer_len(&self) -> usize {
        FIXED_LEN + params_len(&self.fault.kind)
    }

    pub(crate) fn parse(r: &mut Reader<'_>) -> Result<Self, Error> {
        let device = r.u8()?;
        let seed = r.u64()?;
        let (start_ns, end_ns) = (r.u64()?, r.u64()?);
        if start_ns >= end_ns {
            return Err(Error::InvalidValue);
        }
        let kind = parse_kind(r.u8()?, r)?;
        Ok(Self {
            fault: Fault::new(device, Window::new(start_ns, end_ns), kind),
            seed,
        })
    }

    pub(crate) fn emit(&self, w: &mut Writer<'_>) -> Result<(), Error> {
        let f = &self.fault;
        w.u8(f.device)?;
        w.u64(self.seed)?;
        w.u64(f.window.start_ns)?;
        w.u64(f.window.end_ns)?;
        w.u8(kind_code(&f.kind))?;
        emit_kind(&f.kind, w)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::link::Message;
    use margemu_model::fault::UNTIL_END;

    /// One fault of every kind, with parameters whose bits are not all alike.
    fn every_kind() -> [FaultKind; 18] {
        let v = [0.1f32, -2.5, f32::MIN_POSITIVE];
        let s = Sensor::Mag;
        [
            FaultKind::Stuck {
                sensor: Sensor::Acc,
            },
            FaultKind::StuckAt {
                sensor: Sensor::Gyr,
                value: v,
            },
            FaultKind::Dropout { sensor: s },
            FaultKind::Spikes {
                sensor: s,
                rate_hz: 12.5,
                amplitude: -3.0,
                axes: 0b101,
            },
            FaultKind::BiasStep { sensor: s, bias: v },
            FaultKind::Scale {
                sensor: s,
                factor: v,
            },
            FaultKind::Noise { sensor: s, std: v },
            FaultKind::MagSaturation { field: v },
            FaultKind::Reset,
            FaultKind::WrongIdentity { value: 0xA5 },
            FaultKind::FifoOverflow,
            FaultKind::Nak,
            FaultKind::Corrupt { probability: 0.01 },
            FaultKind::ClockStretch {
                stretch_ns: 150_000,
            },
            FaultKind::ClockOffset {
                ppm: 200.0,
                drift_ppm_per_s: -1.5,
            },
            FaultKind::DrdyJitter { max_ns: 40_000 },
            FaultKind::MissingDrdy { probability: 0.25 },
            FaultKind::Late { delay_ns: 300_000 },
        ]
    }

    fn emit(msg: &Message<'_>) -> heapless::Vec<u8, 64> {
        let mut buf = [0u8; 64];
        let n = msg.emit(&mut buf).unwrap();
        assert_eq!(n, msg.buffer_len(), "{msg:?}");
        heapless::Vec::from_slice(&buf[..n]).unwrap()
    }

    #[test]
    fn every_kind_round_trips_bit_for_bit_with_distinct_codes() {
        let mut codes = [false; 18];
        for (i, kind) in every_kind().into_iter().enumerate() {
            let window = Window::new(5_000 * i as u64, UNTIL_END);
            let msg = Message::AddFault(AddFault {
                fault: Fault::new(2, window, kind),
                seed: 0x0123_4567_89AB_CDEF,
            });
            let bytes = emit(&msg);
            assert_eq!(bytes[25], i as u8, "{kind:?}");
            codes[usize::from(bytes[25])] = true;
            assert_eq!(Message::parse(0x07, &bytes).unwrap(), msg);
            // Every truncation and extension is refused.
            for n in 0..bytes.len() {
                assert!(
                    Message::parse(0x07, &bytes[..n]).is_err(),
                    "{n} of {kind:?}"
                );
            }
            let mut long = bytes.clone();
            long.push(0).unwrap();
            assert_eq!(Message::parse(0x07, &long), Err(Error::PayloadTooLong));
        }
        assert!(codes.iter().all(|&c| c));
        // A NaN's payload bits survive.
        let nan = f32::from_bits(0x7FC0_1234);
        let kind = FaultKind::Corrupt { probability: nan };
        let msg = AddFault {
            fault: Fault::new(0, Window::new(0, 1), kind),
            seed: 1,
        };
        let bytes = emit(&Message::AddFault(msg));
        let Ok(Message::AddFault(back)) = Message::parse(0x07, &bytes) else {
            panic!()
        };
        let FaultKind::Corrupt { probability } = back.fault.kind else {
            panic!()
        };
        assert_eq!(probability.to_bits(), 0x7FC0_1234);
    }

    #[test]
    fn malformed_values_are_refused() {
        let kind = FaultKind::Spikes {
            sensor: Sensor::Gyr,
            rate_hz: 1.0,
            amplitude: 1.0,
            axes: 1,
        };
        let msg = Message::AddFault(AddFault {
            fault: Fault::new(0, Window::new(10, 20), kind),
            seed: 3,
        });
        let bytes = emit(&msg);
        // An unknown kind, an unknown sensor, axes beyond z, an empty and a reversed window.
        let edits: [(usize, u8); 5] = [(25, 18), (26, 3), (35, 8), (9, 20), (9, 30)];
        for (at, value) in edits {
            let mut m = bytes.clone();
            m[at] = value;
            assert_eq!(
                Message::parse(0x07, &m),
                Err(Error::InvalidValue),
                "{at} = {value}"
            );
        }
        // Every byte value at every position parses or is refused, never panics.
        for i in 0..bytes.len() {
            for b in [0u8, 1, 7, 0x80, 0xFF] {
                let mut m = bytes.clone();
                m[i] = b;
                let _ = Message::parse(0x07, &m);
            }
        }
    }
}
