//! [`AddVibration`]: the sampling chain of source mode (b), one piece per message
//! (`docs/spec/link.md` §5.15).
//!
//! After Configure (source model) and before Start the host sends the path the device's chain
//! runs ([`AddVibration::Path`]: the output path, or the chip's internal path with its filter
//! settings as [`ChainConfig`] bytes), then each motor tone source ([`AddVibration::Tones`]: at
//! most [`MAX_RPM_POINTS`] rpm points and [`MAX_HARMONICS`] harmonics, so one fits a frame) and
//! each shock ([`AddVibration::Shock`]), in the order the host's model adds them: the device
//! rebuilds its chain after each, with the same seeds.
//!
//! ```
//! use margemu_protocol::link::{AddVibration, Message, RpmProfile};
//! use margemu_model::vibration::{Harmonic, RpmPoint, ToneSource};
//! let mut profile = RpmProfile::new();
//! profile.push(RpmPoint { t_ns: 0, rpm: 12_000.0 }).unwrap();
//! let mut tones = ToneSource::new(4, profile);
//! tones.push(Harmonic { order: 1.0, linear: [0.0, 0.0, 5.0], angular: [0.0; 3] }).unwrap();
//! let msg = Message::AddVibration(AddVibration::Tones(tones));
//! let mut payload = [0u8; 1024];
//! let n = msg.emit(&mut payload)?;
//! assert_eq!(n, 1 + 1 + 8 + 1 + 16 + 1 + 56);
//! assert_eq!(Message::parse(0x06, &payload[..n])?, msg);
//! # Ok::<(), margemu_protocol::link::Error>(())
//! ```

use crate::chip::chain::{ChainConfig, MAX_ENCODED_LEN};
use crate::link::wire::{Reader, Writer};
use crate::link::Error;
use margemu_model::vibration::{Harmonic, RpmPoint, Shock, ToneSource, MAX_HARMONICS};

/// Most points of one tone source's rpm profile on the link.
pub const MAX_RPM_POINTS: usize = 16;

/// A tone source's rpm profile as the device holds it.
pub type RpmProfile = heapless::Vec<RpmPoint, MAX_RPM_POINTS>;

/// Host → device: one piece of the source-(b) sampling chain.
#[derive(Clone, Debug, PartialEq)]
#[allow(clippy::large_enum_variant)] // no alloc: a tone source is held by value, one at a time
pub enum AddVibration {
    /// Which path the chain runs: `Some` settings for the chip's internal path, `None` for the
    /// output path.
    Path(Option<ChainConfig>),
    /// One motor tone source (amplitudes in the chip's axes).
    Tones(ToneSource<RpmProfile>),
    /// One half-sine shock (peaks in the chip's axes).
    Shock(Shock),
}

const PATH: u8 = 0;
const TONES: u8 = 1;
const SHOCK: u8 = 2;

impl AddVibration {
    pub(crate) fn buffer_len(&self) -> usize {
        1 + match self {
            Self::Path(None) => 1,
            Self::Path(Some(c)) => 1 + c.encode(&mut [0u8; MAX_ENCODED_LEN]),
            Self::Tones(t) => 1 + 8 + 1 + 16 * t.profile.len() + 1 + 56 * t.harmonics().len(),
            Self::Shock(_) => 16 + 48,
        }
    }

    pub(crate) fn parse(r: &mut Reader<'_>) -> Result<Self, Error> {
        match r.u8()? {
            PATH => {
                let len = usize::from(r.u8()?);
                if len == 0 {
                    return Ok(Self::Path(None));
                }
                if len > MAX_ENCODED_LEN {
                    return Err(Error::InvalidValue);
                }
                let config = ChainConfig::decode(r.bytes(len)?).map_err(|_| Error::InvalidValue)?;
                Ok(Self::Path(Some(config)))
            }
            TONES => {
                let motors = r.u8()?;
                let spread = r.f64()?;
                let mut profile = RpmProfile::new();
                for _ in 0..r.u8()? {
                    let p = RpmPoint {
                        t_ns: r.u64()?,
                        rpm: r.f64()?,
                    };
                    profile.push(p).map_err(|_| Error::InvalidValue)?;
                }
                let mut tones = ToneSource::new(motors, profile);
                tones.spread = spread;
                let count = usize::from(r.u8()?);
                if count > MAX_HARMONICS {
                    return Err(Error::InvalidValue);
                }
                for _ in 0..count {
                    let h = Harmonic {
                        order: r.f64()?,
                        linear: r.f64s()?,
                        angular: r.f64s()?,
                    };
                    tones.push(h).map_err(|_| Error::InvalidValue)?;
                }
                Ok(Self::Tones(tones))
            }
            SHOCK => Ok(Self::Shock(Shock {
                t_ns: r.u64()?,
                duration_ns: r.u64()?,
                linear: r.f64s()?,
                angular: r.f64s()?,
            })),
            _ => Err(Error::InvalidValue),
        }
    }

    pub(crate) fn emit(&self, w: &mut Writer<'_>) -> Result<(), Error> {
        match self {
            Self::Path(config) => {
                let mut bytes = [0u8; MAX_ENCODED_LEN];
                let len = config.map_or(0, |c| c.encode(&mut bytes));
                w.bytes(&[PATH, len as u8])?;
                w.bytes(bytes.get(..len).unwrap_or(&[]))
            }
            Self::Tones(t) => {
                w.bytes(&[TONES, t.motors])?;
                w.f64(t.spread)?;
                // At most MAX_RPM_POINTS (16) and MAX_HARMONICS (6).
                w.u8(t.profile.len() as u8)?;
                for p in &t.profile {
                    w.u64(p.t_ns)?;
                    w.f64(p.rpm)?;
                }
                w.u8(t.harmonics().len() as u8)?;
                for h in t.harmonics() {
                    w.f64(h.order)?;
                    w.f64s(&h.linear)?;
                    w.f64s(&h.angular)?;
                }
                Ok(())
            }
            Self::Shock(s) => {
                w.u8(SHOCK)?;
                w.u64(s.t_ns)?;
                w.u64(s.duration_ns)?;
                w.f64s(&s.linear)?;
                w.f64s(&s.angular)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::chip::ChipModel;
    use crate::link::{Message, Rate};

    fn tones(points: usize, harmonics: usize) -> ToneSource<RpmProfile> {
        let mut profile = RpmProfile::new();
        for i in 0..points {
            let p = RpmPoint {
                t_ns: i as u64 * 1_000_000,
                rpm: 1000.0 * i as f64,
            };
            profile.push(p).unwrap();
        }
        let mut t = ToneSource::new(3, profile);
        t.spread = 0.02;
        for i in 0..harmonics {
            let h = Harmonic {
                order: 1.0 + i as f64,
                linear: [1.0, -2.0, 3.5],
                angular: [0.25, 0.0, -0.5],
            };
            t.push(h).unwrap();
        }
        t
    }

    fn all() -> [AddVibration; 6] {
        let config = ChainConfig::default_for(ChipModel::Icm20602, Rate::hz(8000).unwrap());
        let shock = Shock {
            t_ns: 5_000_000,
            duration_ns: 2_000_000,
            linear: [50.0, 0.0, -1.0],
            angular: [0.0, 3.0, 0.0],
        };
        [
            AddVibration::Path(None),
            AddVibration::Path(Some(config.unwrap())),
            AddVibration::Tones(tones(1, 1)),
            AddVibration::Tones(tones(MAX_RPM_POINTS, MAX_HARMONICS)),
            AddVibration::Tones(tones(0, 0)),
            AddVibration::Shock(shock),
        ]
    }

    type Bytes = heapless::Vec<u8, { crate::link::MAX_PAYLOAD_LEN }>;

    fn emit(msg: &Message<'_>) -> Bytes {
        let mut buf = [0u8; crate::link::MAX_PAYLOAD_LEN];
        let n = msg.emit(&mut buf).unwrap();
        assert_eq!(n, msg.buffer_len(), "{msg:?}");
        Bytes::from_slice(&buf[..n]).unwrap()
    }

    #[test]
    fn every_piece_round_trips_within_a_frame() {
        for v in all() {
            let msg = Message::AddVibration(v);
            let bytes = emit(&msg);
            assert_eq!(Message::parse(0x06, &bytes).unwrap(), msg);
        }
    }

    #[test]
    fn every_truncation_and_extension_is_refused() {
        for v in all() {
            let bytes = emit(&Message::AddVibration(v));
            for n in 0..bytes.len() {
                assert!(
                    Message::parse(0x06, &bytes[..n]).is_err(),
                    "{n} of {bytes:?}"
                );
            }
            let mut long = bytes.clone();
            long.push(0).unwrap();
            assert_eq!(Message::parse(0x06, &long), Err(Error::PayloadTooLong));
        }
    }

    #[test]
    fn malformed_values_are_refused() {
        let path = emit(&Message::AddVibration(all()[1].clone()));
        let full = emit(&Message::AddVibration(all()[3].clone()));
        // An unknown piece, a config longer than any.
        let fixed: [&[u8]; 3] = [&[3], &[0xFF, 0], &[PATH, 8, 0, 0, 0, 0, 0, 0, 0, 0]];
        for bytes in fixed {
            assert!(Message::parse(0x06, bytes).is_err(), "{bytes:?}");
        }
        let harmonics_at = 11 + 16 * MAX_RPM_POINTS;
        // No such chain family, too few values for the family (codes are the device's to check),
        // a point and a harmonic too many.
        let edits = [
            (&path, 2, 9u8),
            (&path, 1, 3),
            (&full, 10, MAX_RPM_POINTS as u8 + 1),
            (&full, harmonics_at, MAX_HARMONICS as u8 + 1),
        ];
        for (bytes, at, value) in edits {
            let mut m = bytes.clone();
            m[at] = value;
            assert!(Message::parse(0x06, &m).is_err(), "{m:?}");
        }
        // Every byte value at every position parses or is refused, never panics.
        for bytes in [path, full] {
            for i in 0..bytes.len() {
                for b in [0u8, 1, 7, 0x80, 0xFF] {
                    let mut m = bytes.clone();
                    m[i] = b;
                    let _ = Message::parse(0x06, &m);
                }
            }
        }
    }
}
