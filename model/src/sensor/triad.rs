//! The per-sample pipeline of one three-axis sensor, compiled from its [`SensorErrors`].
//!
//! Order of the terms (each skipped when not configured):
//! 1. input limited to `±INPUT_LIMIT` (so no later product overflows, and ±∞ saturates);
//! 2. `y = L·x` with `L = (I + ΔS)·M` (times `B_si` for the magnetometer);
//! 3. `+ extra` (the gyroscope's `G·f`), `+ offset` (bias, and `(I + ΔS)·M·b_hi`);
//! 4. `+ c·(T − T_ref)`, `+` Gauss–Markov bias, `+` rate random walk, `+` white noise;
//! 5. rounded to the resolution step, then clipped to the range.

use super::config::SensorErrors;
use crate::error::{each3, finite, finite3x3, non_negative, positive, Error};
use crate::noise::{GaussMarkov, RandomWalk, WhiteNoise};
use crate::rng::stream;
use crate::vec3::{add, clamp, identity_plus, mat_mul_f64, mat_vec, mat_vec_f64};
use crate::vec3::{Mat3, Mat3d, Vec3, IDENTITY};

/// Inputs are limited to this magnitude before any arithmetic: far beyond any physical value,
/// small enough that squares and products with the coefficients stay finite in `f32`.
pub const INPUT_LIMIT: f32 = 1e15;

/// Which sensor a triad is: it names the random streams and the configuration fields in errors.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Kind {
    Gyro,
    Accel,
    Mag,
}

/// `"<kind><suffix>"` as a `&'static str`.
macro_rules! named {
    ($kind:expr, $suffix:literal) => {
        match $kind {
            Kind::Gyro => concat!("gyro", $suffix),
            Kind::Accel => concat!("accel", $suffix),
            Kind::Mag => concat!("mag", $suffix),
        }
    };
}

/// `"<prefix><kind>"` as a `&'static str` (the stream names).
macro_rules! stream_name {
    ($prefix:literal, $kind:expr) => {
        match $kind {
            Kind::Gyro => concat!($prefix, "gyro"),
            Kind::Accel => concat!($prefix, "accel"),
            Kind::Mag => concat!($prefix, "mag"),
        }
    };
}

/// A coefficient rounded to `f32`, refused if that overflows.
pub(crate) fn to_f32(x: f64, what: &'static str) -> Result<f32, Error> {
    let y = x as f32;
    if y.is_finite() {
        Ok(y)
    } else {
        Err(Error::ParameterTooLarge { what })
    }
}

/// A vector rounded to `f32`, refused if any component overflows.
pub(crate) fn vec_f32(v: [f64; 3], what: &'static str) -> Result<Vec3, Error> {
    Ok([
        to_f32(v[0], what)?,
        to_f32(v[1], what)?,
        to_f32(v[2], what)?,
    ])
}

/// A matrix rounded to `f32`, refused if any entry overflows.
pub(crate) fn mat_f32(m: &Mat3d, what: &'static str) -> Result<Mat3, Error> {
    Ok([
        vec_f32(m[0], what)?,
        vec_f32(m[1], what)?,
        vec_f32(m[2], what)?,
    ])
}

/// The compiled pipeline.
#[derive(Clone, Debug)]
pub(crate) struct Triad {
    ideal: bool,
    linear: Option<Mat3>,
    offset: Option<Vec3>,
    temperature: Option<(Vec3, f32)>,
    instability: Option<GaussMarkov>,
    walk: Option<RandomWalk>,
    white: Option<WhiteNoise>,
    resolution: Option<Vec3>,
    range: Option<Vec3>,
}

impl Triad {
    /// Compiles `errors` (with the magnetometer's soft and hard iron, if any) at `rate_hz`, which
    /// the caller has checked; the streams are `noise/<kind>`, `bias_instability/<kind>` and
    /// `rate_random_walk/<kind>`.
    pub(crate) fn new(
        kind: Kind,
        e: &SensorErrors,
        soft_iron: Option<Mat3d>,
        hard_iron: Option<[f64; 3]>,
        rate_hz: f64,
        seed: u64,
    ) -> Result<Self, Error> {
        let ideal = e.is_ideal() && soft_iron.is_none() && hard_iron.is_none();
        let scale = check_matrix(e.scale_factor, named!(kind, ".scale_factor"))?;
        let misalign = check_matrix(e.misalignment, named!(kind, ".misalignment"))?;
        let soft = check_matrix(soft_iron, "mag.soft_iron")?;
        // T = (I + ΔS)·M acts on the hard iron; L = T·B_si on the field.
        let t = mat_mul_f64(
            &identity_plus(&scale.unwrap_or([[0.0; 3]; 3])),
            &misalign.unwrap_or(IDENTITY),
        );
        let linear = match scale.is_some() || misalign.is_some() || soft.is_some() {
            true => Some(mat_f32(
                &mat_mul_f64(&t, &soft.unwrap_or(IDENTITY)),
                named!(kind, ".scale_factor"),
            )?),
            false => None,
        };

        let bias = check_vector(e.bias, named!(kind, ".bias"), finite)?;
        let hard = check_vector(hard_iron, "mag.hard_iron", finite)?;
        let offset = match (bias, hard) {
            (None, None) => None,
            (b, h) => {
                let (b, h) = (
                    b.unwrap_or([0.0; 3]),
                    mat_vec_f64(&t, h.unwrap_or([0.0; 3])),
                );
                Some(vec_f32(
                    [h[0] + b[0], h[1] + b[1], h[2] + b[2]],
                    named!(kind, ".bias"),
                )?)
            }
        };

        let temperature = match e.temperature_bias {
            None => None,
            Some(tb) => {
                let what = named!(kind, ".temperature_bias");
                let c = vec_f32(each3(tb.coefficient, what, finite)?, what)?;
                Some((c, to_f32(finite(tb.reference_c, what)?, what)?))
            }
        };

        let instability = match e.bias_instability {
            None => None,
            Some(bi) => {
                let what = named!(kind, ".bias_instability");
                let b = each3(bi.coefficient, what, non_negative)?;
                let tau = positive(bi.correlation_time_s, what)?;
                let rng = stream(seed, stream_name!("bias_instability/", kind));
                Some(GaussMarkov::new(b, tau, rate_hz, rng, what)?)
            }
        };
        let walk = match check_vector(
            e.rate_random_walk,
            named!(kind, ".rate_random_walk"),
            non_negative,
        )? {
            None => None,
            Some(k) => {
                let rng = stream(seed, stream_name!("rate_random_walk/", kind));
                Some(RandomWalk::new(
                    k,
                    rate_hz,
                    rng,
                    named!(kind, ".rate_random_walk"),
                )?)
            }
        };
        let white = match check_vector(
            e.noise_density,
            named!(kind, ".noise_density"),
            non_negative,
        )? {
            None => None,
            Some(d) => {
                let rng = stream(seed, stream_name!("noise/", kind));
                Some(WhiteNoise::new(
                    d,
                    rate_hz,
                    rng,
                    named!(kind, ".noise_density"),
                )?)
            }
        };

        let resolution = check_vector(e.resolution, named!(kind, ".resolution"), positive)?;
        let range = check_vector(e.range, named!(kind, ".range"), positive)?;
        Ok(Self {
            ideal,
            linear,
            offset,
            temperature,
            instability,
            walk,
            white,
            resolution: resolution
                .map(|r| vec_f32(r, named!(kind, ".resolution")))
                .transpose()?,
            range: range
                .map(|r| vec_f32(r, named!(kind, ".range")))
                .transpose()?,
        })
    }

    /// Whether no term is configured: the output is the input.
    pub(crate) fn is_ideal(&self) -> bool {
        self.ideal
    }

    /// One output sample from the true input `x`, the additive `extra` (in sensor axes, already
    /// limited) and the temperature.
    #[inline(always)]
    pub(crate) fn apply(
        &mut self,
        x: Vec3,
        extra: Option<Vec3>,
        temperature_c: Option<f32>,
    ) -> Vec3 {
        let x = clamp(x, INPUT_LIMIT);
        let mut y = match &self.linear {
            Some(l) => mat_vec(l, x),
            None => x,
        };
        if let Some(e) = extra {
            y = add(y, e);
        }
        if let Some(o) = self.offset {
            y = add(y, o);
        }
        if let (Some((c, t_ref)), Some(t)) = (self.temperature, temperature_c) {
            let d = t.clamp(-INPUT_LIMIT, INPUT_LIMIT) - t_ref;
            y = add(y, [c[0] * d, c[1] * d, c[2] * d]);
        }
        if let Some(gm) = &mut self.instability {
            y = add(y, gm.sample());
        }
        if let Some(rw) = &mut self.walk {
            y = add(y, rw.sample());
        }
        if let Some(w) = &mut self.white {
            y = add(y, w.sample());
        }
        if let Some(step) = self.resolution {
            for i in 0..3 {
                y[i] = quantize(y[i], step[i]);
            }
        }
        if let Some(r) = self.range {
            for i in 0..3 {
                y[i] = y[i].clamp(-r[i], r[i]);
            }
        }
        y
    }
}

/// `x` rounded to the nearest multiple of `step` (ties away from zero); values beyond 2²³ steps,
/// where `f32` cannot resolve the grid any more, and NaN are returned as they are.
#[inline(always)]
pub(crate) fn quantize(x: f32, step: f32) -> f32 {
    let q = x / step;
    if libm::fabsf(q) < 8_388_608.0 {
        libm::roundf(q) * step
    } else {
        x
    }
}

fn check_matrix(m: Option<Mat3d>, what: &'static str) -> Result<Option<Mat3d>, Error> {
    m.map(|m| finite3x3(m, what)).transpose()
}

fn check_vector(
    v: Option<[f64; 3]>,
    what: &'static str,
    check: fn(f64, &'static str) -> Result<f64, Error>,
) -> Result<Option<[f64; 3]>, Error> {
    v.map(|v| each3(v, what, check)).transpose()
}
