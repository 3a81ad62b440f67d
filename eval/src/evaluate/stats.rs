//! Summary statistics of scored instants (see [`score`](mod@super::score) for the definitions).

use super::score::Compared;

/// Statistics of one angle's errors (rad, rad²).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AngleStats {
    /// Mean error (rad).
    pub mean: f64,
    /// Mean squared error (rad²).
    pub mse: f64,
    /// Standard deviation about the mean (rad).
    pub std: f64,
    /// Largest absolute error (rad).
    pub max_abs: f64,
}

/// The scores of one estimate over a set of scored instants.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Scores {
    /// Instants scored (`N` of eq. 27).
    pub count: usize,
    /// Roll, pitch, yaw.
    pub angles: [AngleStats; 3],
    /// `∛(MSE_φ·MSE_θ·MSE_ψ)` (eq. 27, rad²).
    pub f: f64,
    /// RMS of the geodesic angle (rad).
    pub geodesic_rms: f64,
    /// Largest geodesic angle (rad).
    pub geodesic_max: f64,
    /// RMS of the heading and inclination errors `[h, ι]` (rad, BROAD's split).
    pub heading_inclination_rms: [f64; 2],
    /// Largest heading and inclination errors (rad).
    pub heading_inclination_max: [f64; 2],
}

impl Scores {
    /// The scores of a set of compared instants; `None` when it is empty.
    pub fn from_compared<'a>(compared: impl Iterator<Item = &'a Compared>) -> Option<Self> {
        let mut acc = Accumulator::default();
        compared.for_each(|c| acc.add(c));
        acc.scores()
    }
}

/// Scores gathered one compared instant at a time, in constant memory: sums for the means
/// (`mean`, `MSE`, the geodesic RMS, in the order the instants come), Welford's update for the
/// spread about the mean (`STD`, equal to the two-pass `√(Σ(e − mean)²/N)` to within rounding).
#[derive(Clone, Copy, Debug, Default)]
pub struct Accumulator {
    n: usize,
    sum: [f64; 3],
    sum_sq: [f64; 3],
    welford_mean: [f64; 3],
    welford_m2: [f64; 3],
    max_abs: [f64; 3],
    geodesic_sq: f64,
    geodesic_max: f64,
    split_sq: [f64; 2],
    split_max: [f64; 2],
}

impl Accumulator {
    /// Adds one compared instant.
    pub fn add(&mut self, c: &Compared) {
        self.n += 1;
        let n = self.n as f64;
        for (i, &e) in c.error.iter().enumerate() {
            self.sum[i] += e;
            self.sum_sq[i] += e * e;
            let delta = e - self.welford_mean[i];
            self.welford_mean[i] += delta / n;
            self.welford_m2[i] += delta * (e - self.welford_mean[i]);
            self.max_abs[i] = self.max_abs[i].max(e.abs());
        }
        self.geodesic_sq += c.geodesic * c.geodesic;
        self.geodesic_max = self.geodesic_max.max(c.geodesic);
        for (i, &e) in c.heading_inclination.iter().enumerate() {
            self.split_sq[i] += e * e;
            self.split_max[i] = self.split_max[i].max(e);
        }
    }

    /// The scores so far; `None` before the first instant.
    pub fn scores(&self) -> Option<Scores> {
        if self.n == 0 {
            return None;
        }
        let nf = self.n as f64;
        let angles = [0, 1, 2].map(|i| AngleStats {
            mean: self.sum[i] / nf,
            mse: self.sum_sq[i] / nf,
            std: (self.welford_m2[i] / nf).sqrt(),
            max_abs: self.max_abs[i],
        });
        Some(Scores {
            count: self.n,
            angles,
            f: (angles[0].mse * angles[1].mse * angles[2].mse).cbrt(),
            geodesic_rms: (self.geodesic_sq / nf).sqrt(),
            geodesic_max: self.geodesic_max,
            heading_inclination_rms: self.split_sq.map(|s| (s / nf).sqrt()),
            heading_inclination_max: self.split_max,
        })
    }
}
