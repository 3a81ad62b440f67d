//! Motor tones: harmonics of motors that follow an rpm profile.

use super::Sense;
use crate::error::Error;
use crate::rng;
use crate::vec3::Vec3;

/// Most harmonics of one tone source.
pub const MAX_HARMONICS: usize = 6;
/// Most motors of one tone source.
pub const MAX_MOTORS: usize = 8;

/// A point of an rpm profile: at `t_ns` the motors turn at `rpm`; between points the rpm is
/// interpolated linearly, before the first it is the first's and after the last the last's. Two
/// points at one instant make a step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RpmPoint {
    /// Instant, ns from the scene start.
    pub t_ns: u64,
    /// Revolutions per minute (≥ 0).
    pub rpm: f64,
}

/// One harmonic of the motor rotation.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Harmonic {
    /// Multiple of the rotation frequency (1 = the rotation itself; blade passes are 2 or 3).
    pub order: f64,
    /// Peak linear acceleration per axis and motor, m/s².
    pub linear: [f64; 3],
    /// Peak angular rate per axis and motor, rad/s.
    pub angular: [f64; 3],
}

/// Motors following one rpm profile, with their harmonics.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToneSource<P> {
    /// Number of motors (1..=[`MAX_MOTORS`]).
    pub motors: u8,
    /// Relative rpm spread between motors (0 = all alike; 0.02 = each within ±2 %).
    pub spread: f64,
    /// The rpm profile, points in time order.
    pub profile: P,
    harmonics: [Harmonic; MAX_HARMONICS],
    harmonic_count: usize,
}

impl<P: AsRef<[RpmPoint]>> ToneSource<P> {
    /// `motors` motors on `profile` without spread or harmonics yet.
    pub fn new(motors: u8, profile: P) -> Self {
        Self {
            motors,
            spread: 0.0,
            profile,
            harmonics: [Harmonic::default(); MAX_HARMONICS],
            harmonic_count: 0,
        }
    }

    /// Adds a harmonic; refuses more than [`MAX_HARMONICS`].
    pub fn push(&mut self, harmonic: Harmonic) -> Result<(), Error> {
        let slot = self.harmonics.get_mut(self.harmonic_count);
        *slot.ok_or(Error::TooManyVibrationSources)? = harmonic;
        self.harmonic_count += 1;
        Ok(())
    }

    /// Changes every harmonic with `f` (e.g. to turn its amplitudes into other axes).
    pub fn map_harmonics(&mut self, f: impl FnMut(&mut Harmonic)) {
        self.harmonics
            .iter_mut()
            .take(self.harmonic_count)
            .for_each(f);
    }

    /// Whether some harmonic has an amplitude in `sense`.
    pub fn moves(&self, sense: Sense) -> bool {
        self.harmonics().iter().any(|h| {
            let a = match sense {
                Sense::Linear => h.linear,
                Sense::Angular => h.angular,
            };
            a != [0.0; 3]
        })
    }

    /// The harmonics.
    pub fn harmonics(&self) -> &[Harmonic] {
        self.harmonics.get(..self.harmonic_count).unwrap_or(&[])
    }

    /// The highest tone frequency the source reaches, Hz (max rpm · (1 + spread) / 60 · order).
    pub fn max_frequency_hz(&self) -> f64 {
        let rpm = self
            .profile
            .as_ref()
            .iter()
            .map(|p| p.rpm)
            .fold(0.0, f64::max);
        let order = self.harmonics().iter().map(|h| h.order).fold(0.0, f64::max);
        rpm * (1.0 + self.spread) / 60.0 * order
    }
}

/// A tone source running at one sensor's internal period.
pub(super) struct Tones<P> {
    profile: P,
    period_ns: u64,
    /// Cycles per internal sample per rpm, per motor: `(1 + spread·u)/60 · period`.
    motor_scale: [f32; MAX_MOTORS],
    motors: usize,
    orders: [f32; MAX_HARMONICS],
    amplitudes: [[f32; 3]; MAX_HARMONICS],
    harmonics: usize,
    /// Phase in cycles, [0, 1), per motor and harmonic.
    phase: [[f32; MAX_HARMONICS]; MAX_MOTORS],
    /// Profile segment the last instant fell in.
    segment: usize,
}

impl<P: AsRef<[RpmPoint]>> Tones<P> {
    pub(super) fn new(
        source: ToneSource<P>,
        sense: Sense,
        period_ns: u64,
        seed: u64,
        index: usize,
    ) -> Result<Self, Error> {
        let motors = usize::from(source.motors);
        if motors == 0 || motors > MAX_MOTORS {
            return Err(Error::InvalidMotorCount);
        }
        let spread = crate::error::non_negative(source.spread, "vibration.tones.spread")?;
        if spread >= 1.0 {
            return Err(Error::ParameterTooLarge {
                what: "vibration.tones.spread",
            });
        }
        let points = source.profile.as_ref();
        if points.is_empty() || points.windows(2).any(|w| w[1].t_ns < w[0].t_ns) {
            return Err(Error::InvalidRpmProfile);
        }
        for p in points {
            crate::error::non_negative(p.rpm, "vibration.tones.rpm")?;
        }
        let mut names = [0u8; 24];
        let name = stream_name(&mut names, index);
        let mut rng = rng::stream(seed, name);
        let period_s = period_ns as f64 * 1e-9;
        let mut motor_scale = [0.0f32; MAX_MOTORS];
        let mut phase = [[0.0f32; MAX_HARMONICS]; MAX_MOTORS];
        for (scale, phases) in motor_scale.iter_mut().zip(&mut phase).take(motors) {
            let u = rng::uniform(&mut rng, -1.0, 1.0);
            *scale = ((1.0 + spread * u) / 60.0 * period_s) as f32;
            for p in phases.iter_mut() {
                *p = rng::unit_f64(&mut rng) as f32;
            }
        }
        let mut orders = [0.0f32; MAX_HARMONICS];
        let mut amplitudes = [[0.0f32; 3]; MAX_HARMONICS];
        for (i, h) in source.harmonics().iter().enumerate() {
            let order = crate::error::positive(h.order, "vibration.tones.order")?;
            let amp = match sense {
                Sense::Linear => h.linear,
                Sense::Angular => h.angular,
            };
            if let (Some(o), Some(a)) = (orders.get_mut(i), amplitudes.get_mut(i)) {
                *o = order as f32;
                *a = crate::sensor::vec_f32_checked(amp, "vibration.tones.amplitude")?;
            }
        }
        Ok(Self {
            profile: source.profile,
            period_ns,
            motor_scale,
            motors,
            orders,
            amplitudes,
            harmonics: source.harmonic_count,
            phase,
            segment: 0,
        })
    }

    /// The rpm at `t_ns` (instants come in increasing order).
    fn rpm_at(&mut self, t_ns: u64) -> f32 {
        let points = self.profile.as_ref();
        while points.get(self.segment + 1).is_some_and(|p| p.t_ns <= t_ns) {
            self.segment += 1;
        }
        match (points.get(self.segment), points.get(self.segment + 1)) {
            (Some(a), Some(b)) if t_ns >= a.t_ns => {
                let span = (b.t_ns - a.t_ns) as f32;
                let into = (t_ns - a.t_ns) as f32;
                let (r0, r1) = (a.rpm as f32, b.rpm as f32);
                r0 + (r1 - r0) * (into / span)
            }
            (Some(a), _) => a.rpm as f32,
            _ => 0.0,
        }
    }

    /// The tones at `t_ns`, the next internal instant; then every phase advances one period.
    #[inline]
    pub(super) fn next(&mut self, t_ns: u64) -> Vec3 {
        let rpm = self.rpm_at(t_ns);
        let _ = self.period_ns;
        let mut v = [0.0f32; 3];
        let n = self.harmonics;
        for (scale, phases) in self
            .motor_scale
            .iter()
            .zip(&mut self.phase)
            .take(self.motors)
        {
            let cycles = rpm * *scale;
            for ((p, order), amp) in phases
                .iter_mut()
                .zip(&self.orders)
                .zip(&self.amplitudes)
                .take(n)
            {
                let s = super::sine::sin_cycles(*p);
                v = [v[0] + amp[0] * s, v[1] + amp[1] * s, v[2] + amp[2] * s];
                let q = *p + cycles * *order;
                *p = q - libm::floorf(q);
            }
        }
        v
    }
}

/// `vibration/tones/<index>` in `buf`.
fn stream_name(buf: &mut [u8; 24], index: usize) -> &str {
    const PREFIX: &[u8] = b"vibration/tones/";
    let mut len = 0;
    for (dst, src) in buf.iter_mut().zip(PREFIX) {
        *dst = *src;
        len += 1;
    }
    if let Some(d) = buf.get_mut(len) {
        *d = b'0' + (index % 10) as u8;
        len += 1;
    }
    core::str::from_utf8(buf.get(..len).unwrap_or(&[])).unwrap_or("vibration/tones")
}
