//! The compact, deterministic encoding of the sensor model's terms
//! ([`MargConfig`](margemu_model::sensor::MargConfig)) and of the magnetic perturbation
//! ([`PerturbationConfig`](margemu_model::perturbation::PerturbationConfig)).
//!
//! Each sensor (gyroscope, accelerometer, magnetometer, in that order) is a `u16` presence mask
//! followed by its present terms in bit order, each `f64` little-endian, matrices row-major:
//!
//! | bit | term | bytes |
//! |-----|------|-------|
//! | 0 | `scale_factor` | 72 |
//! | 1 | `misalignment` | 72 |
//! | 2 | `bias` | 24 |
//! | 3 | `noise_density` | 24 |
//! | 4 | `bias_instability` (coefficient[3], correlation_time_s) | 32 |
//! | 5 | `rate_random_walk` | 24 |
//! | 6 | `temperature_bias` (coefficient[3], reference_c) | 32 |
//! | 7 | `resolution` | 24 |
//! | 8 | `range` | 24 |
//! | 9 | gyro `g_sensitivity` (72), accel `lever_arm_m` (24), mag `soft_iron` (72) | |
//! | 10 | mag `hard_iron` (24); reserved (0) for gyro and accel | |
//!
//! Bits 11..15 are reserved and must be 0. Values are carried bit for bit; the model validates
//! them when the device builds it. The types are the model's own (its one definition of the
//! sensor configuration, which the host's scenes also read into); this module only fixes their
//! byte order, and names their fields nowhere else.

use margemu_model::perturbation::{Amplitude, PerturbationConfig, Placement};
use margemu_model::sensor::{
    AccelConfig, BiasInstability, GyroConfig, MagConfig, MargConfig, SensorErrors, TemperatureBias,
};
use margemu_model::vec3::Mat3d;

use crate::link::wire::{Reader, Writer};
use crate::link::Error;

const MAT: usize = 72;
const VEC: usize = 24;
const SHARED_MAX: usize = 2 * MAT + 5 * VEC + 2 * (VEC + 8);
/// Largest encoding of a [`MargConfig`] (every term present).
pub const MAX_MARG_CONFIG_LEN: usize = 3 * 2 + 3 * SHARED_MAX + MAT + VEC + MAT + VEC;
/// Largest encoding of a [`PerturbationConfig`] (without its presence byte).
pub const MAX_PERTURBATION_LEN: usize = 8 + 8 + 1 + 16 + 16 + 1 + VEC;

fn bit(mask: u16, b: u16) -> bool {
    mask & (1 << b) != 0
}

fn read_mat(r: &mut Reader<'_>) -> Result<Mat3d, Error> {
    Ok([r.f64s()?, r.f64s()?, r.f64s()?])
}

fn write_mat(w: &mut Writer<'_>, m: &Mat3d) -> Result<(), Error> {
    m.iter().try_for_each(|row| w.f64s(row))
}

fn opt<T>(present: bool, f: impl FnOnce() -> Result<T, Error>) -> Result<Option<T>, Error> {
    present.then(f).transpose()
}

/// The shared terms' presence bits (0..=8).
fn shared_mask(e: &SensorErrors) -> u16 {
    [
        e.scale_factor.is_some(),
        e.misalignment.is_some(),
        e.bias.is_some(),
        e.noise_density.is_some(),
        e.bias_instability.is_some(),
        e.rate_random_walk.is_some(),
        e.temperature_bias.is_some(),
        e.resolution.is_some(),
        e.range.is_some(),
    ]
    .iter()
    .enumerate()
    .fold(0, |m, (i, &p)| m | (u16::from(p) << i))
}

fn write_shared(w: &mut Writer<'_>, e: &SensorErrors) -> Result<(), Error> {
    let vec = |w: &mut Writer<'_>, v: &Option<[f64; 3]>| v.map_or(Ok(()), |v| w.f64s(&v));
    e.scale_factor.map_or(Ok(()), |m| write_mat(w, &m))?;
    e.misalignment.map_or(Ok(()), |m| write_mat(w, &m))?;
    vec(w, &e.bias)?;
    vec(w, &e.noise_density)?;
    if let Some(b) = e.bias_instability {
        w.f64s(&b.coefficient)?;
        w.f64(b.correlation_time_s)?;
    }
    vec(w, &e.rate_random_walk)?;
    if let Some(t) = e.temperature_bias {
        w.f64s(&t.coefficient)?;
        w.f64(t.reference_c)?;
    }
    vec(w, &e.resolution)?;
    vec(w, &e.range)
}

fn read_shared(r: &mut Reader<'_>, mask: u16) -> Result<SensorErrors, Error> {
    Ok(SensorErrors {
        scale_factor: opt(bit(mask, 0), || read_mat(r))?,
        misalignment: opt(bit(mask, 1), || read_mat(r))?,
        bias: opt(bit(mask, 2), || r.f64s())?,
        noise_density: opt(bit(mask, 3), || r.f64s())?,
        bias_instability: opt(bit(mask, 4), || {
            Ok(BiasInstability {
                coefficient: r.f64s()?,
                correlation_time_s: r.f64()?,
            })
        })?,
        rate_random_walk: opt(bit(mask, 5), || r.f64s())?,
        temperature_bias: opt(bit(mask, 6), || {
            Ok(TemperatureBias {
                coefficient: r.f64s()?,
                reference_c: r.f64()?,
            })
        })?,
        resolution: opt(bit(mask, 7), || r.f64s())?,
        range: opt(bit(mask, 8), || r.f64s())?,
    })
}

/// Reads a presence mask and refuses bits beyond `allowed`.
fn read_mask(r: &mut Reader<'_>, allowed: u16) -> Result<u16, Error> {
    let mask = r.u16()?;
    if mask & !allowed != 0 {
        return Err(Error::InvalidValue);
    }
    Ok(mask)
}

/// Writes `cfg` in the encoding above.
pub(crate) fn write_marg(w: &mut Writer<'_>, cfg: &MargConfig) -> Result<(), Error> {
    let g = &cfg.gyro;
    w.u16(shared_mask(&g.errors) | u16::from(g.g_sensitivity.is_some()) << 9)?;
    write_shared(w, &g.errors)?;
    g.g_sensitivity.map_or(Ok(()), |m| write_mat(w, &m))?;
    let a = &cfg.accel;
    w.u16(shared_mask(&a.errors) | u16::from(a.lever_arm_m.is_some()) << 9)?;
    write_shared(w, &a.errors)?;
    a.lever_arm_m.map_or(Ok(()), |v| w.f64s(&v))?;
    let m = &cfg.mag;
    let mask = shared_mask(&m.errors)
        | u16::from(m.soft_iron.is_some()) << 9
        | u16::from(m.hard_iron.is_some()) << 10;
    w.u16(mask)?;
    write_shared(w, &m.errors)?;
    m.soft_iron.map_or(Ok(()), |s| write_mat(w, &s))?;
    m.hard_iron.map_or(Ok(()), |v| w.f64s(&v))
}

/// Reads the encoding above.
pub(crate) fn read_marg(r: &mut Reader<'_>) -> Result<MargConfig, Error> {
    let mask = read_mask(r, 0x03FF)?;
    let gyro = GyroConfig {
        errors: read_shared(r, mask)?,
        g_sensitivity: opt(bit(mask, 9), || read_mat(r))?,
    };
    let mask = read_mask(r, 0x03FF)?;
    let accel = AccelConfig {
        errors: read_shared(r, mask)?,
        lever_arm_m: opt(bit(mask, 9), || r.f64s())?,
    };
    let mask = read_mask(r, 0x07FF)?;
    let mag = MagConfig {
        errors: read_shared(r, mask)?,
        soft_iron: opt(bit(mask, 9), || read_mat(r))?,
        hard_iron: opt(bit(mask, 10), || r.f64s())?,
    };
    Ok(MargConfig { gyro, accel, mag })
}

/// Its encoded length.
pub(crate) fn marg_len(cfg: &MargConfig) -> usize {
    let shared = |e: &SensorErrors| {
        let m = shared_mask(e);
        let sizes = [MAT, MAT, VEC, VEC, VEC + 8, VEC, VEC + 8, VEC, VEC];
        2 + (0..9)
            .filter(|&b| bit(m, b))
            .map(|b| sizes[b as usize])
            .sum::<usize>()
    };
    shared(&cfg.gyro.errors)
        + cfg.gyro.g_sensitivity.map_or(0, |_| MAT)
        + shared(&cfg.accel.errors)
        + cfg.accel.lever_arm_m.map_or(0, |_| VEC)
        + shared(&cfg.mag.errors)
        + cfg.mag.soft_iron.map_or(0, |_| MAT)
        + cfg.mag.hard_iron.map_or(0, |_| VEC)
}

/// `window_s`, `cutoff_hz`, amplitude (tag 0 `Uniform` + lo, hi; tag 1 `Reference`), `gap_s`,
/// placement (tag 0 `PerAxis`; 1 `Direction` + [3]; 2 `RandomDirection`).
pub(crate) fn write_perturbation(w: &mut Writer<'_>, p: &PerturbationConfig) -> Result<(), Error> {
    w.f64(p.window_s)?;
    w.f64(p.cutoff_hz)?;
    match p.amplitude {
        Amplitude::Uniform { lo, hi } => {
            w.u8(0)?;
            w.f64s(&[lo, hi])?;
        }
        Amplitude::Reference => w.u8(1)?,
    }
    w.f64s(&p.gap_s)?;
    match p.placement {
        Placement::PerAxis => w.u8(0),
        Placement::Direction(d) => {
            w.u8(1)?;
            w.f64s(&d)
        }
        Placement::RandomDirection => w.u8(2),
    }
}

pub(crate) fn read_perturbation(r: &mut Reader<'_>) -> Result<PerturbationConfig, Error> {
    let window_s = r.f64()?;
    let cutoff_hz = r.f64()?;
    let amplitude = match r.u8()? {
        0 => Amplitude::Uniform {
            lo: r.f64()?,
            hi: r.f64()?,
        },
        1 => Amplitude::Reference,
        _ => return Err(Error::InvalidValue),
    };
    let gap_s = r.f64s()?;
    let placement = match r.u8()? {
        0 => Placement::PerAxis,
        1 => Placement::Direction(r.f64s()?),
        2 => Placement::RandomDirection,
        _ => return Err(Error::InvalidValue),
    };
    Ok(PerturbationConfig {
        window_s,
        cutoff_hz,
        amplitude,
        gap_s,
        placement,
    })
}

pub(crate) fn perturbation_len(p: &PerturbationConfig) -> usize {
    let amplitude = match p.amplitude {
        Amplitude::Uniform { .. } => 17,
        Amplitude::Reference => 1,
    };
    let placement = match p.placement {
        Placement::Direction(_) => 1 + VEC,
        _ => 1,
    };
    16 + amplitude + 16 + placement
}
