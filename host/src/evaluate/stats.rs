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
}

impl Scores {
    /// The scores of a set of compared instants; `None` when it is empty.
    pub fn from_compared<'a>(compared: impl Iterator<Item = &'a Compared> + Clone) -> Option<Self> {
        let n = compared.clone().count();
        if n == 0 {
            return None;
        }
        let nf = n as f64;
        let angles = [0, 1, 2].map(|i| {
            let mean = compared.clone().map(|c| c.error[i]).sum::<f64>() / nf;
            let mse = compared.clone().map(|c| c.error[i].powi(2)).sum::<f64>() / nf;
            let var = compared
                .clone()
                .map(|c| (c.error[i] - mean).powi(2))
                .sum::<f64>()
                / nf;
            let max_abs = compared
                .clone()
                .fold(0.0f64, |m, c| m.max(c.error[i].abs()));
            AngleStats {
                mean,
                mse,
                std: var.sqrt(),
                max_abs,
            }
        });
        let g2 = compared.clone().map(|c| c.geodesic.powi(2)).sum::<f64>() / nf;
        Some(Self {
            count: n,
            angles,
            f: (angles[0].mse * angles[1].mse * angles[2].mse).cbrt(),
            geodesic_rms: g2.sqrt(),
            geodesic_max: compared.fold(0.0f64, |m, c| m.max(c.geodesic)),
        })
    }
}
