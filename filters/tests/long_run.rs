//! One hour of paper-like motion at 200 Hz (section 3.2: the paper's noise densities, body rates
//! up to about ±50 rad/s, ±4 g external accelerations, 0–4 field-unit magnetic bursts), through
//! the project's sensor model: every filter stays finite and unit in `f32` and `f64`, and the
//! EKF covariance stays exactly symmetric and positive definite (Cholesky and eigenvalues,
//! checked every simulated second); `f32` and `f64` agree within `PRECISION_TOLERANCE`.
//!
//! The full hour takes about a minute unoptimized, so a debug build runs the first
//! `DEBUG_SECONDS` of the same scene and an optimized build (`cargo test --release`) the whole
//! hour.

mod common;

use common::{widen, Scene};
use margemu_filters::ekf::covariance::{Cov, N};
use margemu_filters::quat::geodesic_angle;
use margemu_filters::{AttitudeFilter, Ecf, EcfConfig, Ekf, EkfConfig, Gda, GdaConfig, Real};
use nalgebra::SMatrix;

const RATE: f64 = 200.0;
const DEBUG_SECONDS: f64 = 600.0;
/// Largest angle (rad) between the `f32` and `f64` estimates of one filter fed the same samples.
/// Measured over the hour: 4.4e-6 (ECF), 7.0e-6 (GDA), 2.2e-5 (EKF).
const PRECISION_TOLERANCE: f64 = 1e-4;

struct Bank<T> {
    ecf: Ecf<T>,
    gda: Gda<T>,
    ekf: Ekf<T>,
    /// Smallest and largest eigenvalue of the EKF covariance seen.
    eig: (f64, f64),
    /// Sum of squared attitude errors of ECF, GDA, EKF.
    sq_err: [f64; 3],
}

impl<T: Real> Bank<T> {
    fn new() -> Self {
        Self {
            ecf: Ecf::new(&EcfConfig::default()).unwrap(),
            gda: Gda::new(&GdaConfig::default()).unwrap(),
            ekf: Ekf::new(&EkfConfig::default()).unwrap(),
            eig: (f64::INFINITY, 0.0),
            sq_err: [0.0; 3],
        }
    }

    fn update(&mut self, imu: &margemu_filters::Imu<T>, truth: [f64; 4], k: usize) {
        let dt = T::from_f64(1.0 / RATE);
        let filters: [&mut dyn AttitudeFilter<T>; 3] =
            [&mut self.ecf, &mut self.gda, &mut self.ekf];
        for (i, f) in filters.into_iter().enumerate() {
            f.update(imu, dt);
            let q = f.quaternion().map(|c| c.to_f64());
            let n2: f64 = q.iter().map(|c| c * c).sum();
            assert!(
                q.iter().all(|c| c.is_finite()) && (n2 - 1.0).abs() < 1e-5,
                "filter {i} at {k}: {q:?}"
            );
            self.sq_err[i] += geodesic_angle(q, truth).powi(2);
        }
        assert!(self.ekf.bias().iter().all(|c| c.to_f64().is_finite()));
        if k.is_multiple_of(RATE as usize) {
            self.check_covariance(k);
        }
    }

    fn check_covariance(&mut self, k: usize) {
        let p: Cov<T> = self.ekf.covariance();
        for (i, row) in p.iter().enumerate() {
            for (j, v) in row.iter().enumerate() {
                assert!(v.is_finite(), "P[{i}][{j}] at {k}");
                assert_eq!(*v, p[j][i], "P not symmetric at {k}");
            }
        }
        let m = SMatrix::<f64, N, N>::from_fn(|i, j| p[i][j].to_f64());
        assert!(
            m.cholesky().is_some(),
            "P not positive definite at sample {k}: {m}"
        );
        let eig = m.symmetric_eigenvalues();
        let (lo, hi) = (eig.min(), eig.max());
        assert!(lo > 0.0, "P eigenvalue {lo} at sample {k}");
        self.eig = (self.eig.0.min(lo), self.eig.1.max(hi));
    }
}

#[test]
fn an_hour_of_paper_like_motion_keeps_filters_finite_alike_in_f32_and_f64_and_the_ekf_covariance_positive_definite(
) {
    let seconds = if cfg!(debug_assertions) {
        DEBUG_SECONDS
    } else {
        3600.0
    };
    let steps = (seconds * RATE) as usize;
    let mut scene = Scene::new(RATE, 7);
    let mut single = Bank::<f32>::new();
    let mut double = Bank::<f64>::new();
    let mut max_rate = 0.0f32;
    let mut max_mag = 0.0f32;
    let mut max_diff = [0.0f64; 3];
    for k in 0..steps {
        let (truth, imu) = scene.next();
        max_rate = imu.gyro.iter().fold(max_rate, |m, c| m.max(c.abs()));
        max_mag = max_mag.max(imu.mag.iter().map(|c| c * c).sum::<f32>().sqrt());
        single.update(&imu, truth, k);
        double.update(&widen(&imu), truth, k);
        let pairs = [
            (single.ecf.quaternion(), double.ecf.quaternion()),
            (single.gda.quaternion(), double.gda.quaternion()),
            (single.ekf.quaternion(), double.ekf.quaternion()),
        ];
        for (i, (a, b)) in pairs.into_iter().enumerate() {
            max_diff[i] = max_diff[i].max(geodesic_angle(a.map(f64::from), b));
        }
    }
    eprintln!(
        "f32 vs f64: largest angle ECF {:.1e} GDA {:.1e} EKF {:.1e} rad",
        max_diff[0], max_diff[1], max_diff[2]
    );
    assert!(
        max_diff.iter().all(|&d| d < PRECISION_TOLERANCE),
        "{max_diff:?}"
    );
    // The scene is what it claims: fast oscillations and large magnetic bursts.
    assert!(max_rate > 40.0 && max_mag > 3.0, "{max_rate} {max_mag}");
    for (name, bank) in [
        ("f32", (single.eig, single.sq_err, single.ekf.diagnostics())),
        ("f64", (double.eig, double.sq_err, double.ekf.diagnostics())),
    ] {
        let (eig, sq, diag) = bank;
        let rms = sq.map(|s| (s / steps as f64).sqrt());
        eprintln!(
            "{name}: {seconds} s, EKF P eigenvalues in [{:.2e}, {:.2e}], rms error ECF {:.3} GDA {:.3} EKF {:.3} rad, EKF {diag:?}",
            eig.0, eig.1, rms[0], rms[1], rms[2]
        );
        assert_eq!(diag.rejected, 0, "{name}");
        // They track the motion (default parameters; the scene is harsher than the paper's).
        assert!(rms.iter().all(|&e| e < 0.5), "{name}: {rms:?}");
        assert_eq!(diag.updates, steps as u64, "{name}");
    }
}
