//! Noise-free static inputs: from a wrong start each filter converges to the true attitude, at
//! every attitude of `common::attitudes` (yaw near ±π, pitch near ±80°, upside down), in `f32`
//! and `f64`; started from the first sample it is right at once; `q` and `−q` are one attitude.

mod common;

use common::{attitudes, static_imu, turned};
use margemu_filters::quat::{euler_zyx, from_euler_zyx, geodesic_angle, Quat};
use margemu_filters::{
    AttitudeFilter, Ecf, EcfConfig, Ekf, EkfConfig, Gda, GdaConfig, Initial, Real,
};

const DT: f64 = 0.005;

const BETA: f64 = 0.1;

fn ekf_config(initial: Initial) -> EkfConfig {
    EkfConfig {
        gyro_bias_walk: 1e-2,
        accel_noise: 0.05,
        mag_noise: 0.05,
        initial,
        ..EkfConfig::default()
    }
}

/// The filters under test, tuned to converge within the test's 60 s. The ECF's slowest error
/// direction sees the gains times 0.143 (1 − |up·m̂|), so `Kp = 5, Ki = 2` put its poles at
/// −0.36 ± 0.39i 1/s. The EKF trusts the (noise-free) vectors more than by default, and its bias
/// loop is faster with a larger bias walk (the default of 1e-4 takes minutes to forget the bias
/// transient of a 60° start).
fn filters<T: Real>(initial: Initial) -> Vec<(&'static str, Box<dyn AttitudeFilter<T>>)> {
    let ecf = EcfConfig {
        kp: 5.0,
        ki: 2.0,
        initial,
        ..EcfConfig::default()
    };
    let gda = GdaConfig {
        beta: BETA,
        initial,
        ..GdaConfig::default()
    };
    let ekf = ekf_config(initial);
    vec![
        ("ecf", Box::new(Ecf::new(&ecf).unwrap())),
        ("gda", Box::new(Gda::new(&gda).unwrap())),
        ("ekf", Box::new(Ekf::new(&ekf).unwrap())),
    ]
}

/// The largest error of each filter during the last second of `seconds`, over all attitudes,
/// starting 60° off about a skew axis.
fn final_errors<T: Real>(seconds: f64) -> Vec<(&'static str, f64)> {
    let axis = [0.48, -0.6, 0.64];
    let mut worst: Vec<(&'static str, f64)> = Vec::new();
    for e in attitudes() {
        let truth = from_euler_zyx(e);
        let start = turned(truth, axis, 60f64.to_radians());
        let imu = static_imu::<T>(truth, [0.0; 3]);
        for (i, (name, mut f)) in filters::<T>(Initial::Attitude(start))
            .into_iter()
            .enumerate()
        {
            let steps = (seconds / DT) as usize;
            let mut err = 0.0f64;
            for k in 0..steps {
                f.update(&imu, T::from_f64(DT));
                if k + 200 >= steps {
                    err = err.max(geodesic_angle(f.quaternion().map(|c| c.to_f64()), truth));
                }
            }
            if worst.len() <= i {
                worst.push((name, 0.0));
            }
            worst[i].1 = worst[i].1.max(err);
            assert_eq!(f.diagnostics().rejected, 0);
        }
    }
    worst
}

#[test]
fn each_filter_converges_from_60_degrees_off_in_f64() {
    for (name, err) in final_errors::<f64>(60.0) {
        // GDA dithers around the optimum within its step, 2·β·dt (see gda.rs); the others
        // converge exponentially.
        let bound = if name == "gda" {
            2.0 * BETA * DT + 1e-9
        } else if name == "ecf" {
            1e-8
        } else {
            1e-12
        };
        assert!(err < bound, "{name}: {err:e} >= {bound:e}");
    }
}

#[test]
fn each_filter_converges_from_60_degrees_off_in_f32() {
    for (name, err) in final_errors::<f32>(60.0) {
        let bound = if name == "gda" {
            2.0 * BETA * DT + 1e-6
        } else {
            1e-5
        };
        assert!(err < bound, "{name}: {err:e} >= {bound:e}");
    }
}

#[test]
fn started_from_the_first_sample_each_filter_is_right_at_once() {
    for e in attitudes() {
        let truth = from_euler_zyx(e);
        for (name, mut f) in filters::<f64>(Initial::FirstSample) {
            assert_eq!(
                f.quaternion(),
                [1.0, 0.0, 0.0, 0.0],
                "{name}: identity until a sample"
            );
            let imu = static_imu(truth, [0.0; 3]);
            f.update(&imu, DT);
            let err = geodesic_angle(f.quaternion(), truth);
            assert!(err < 1e-12, "{name} {e:?}: {err:e}");
            let ypr = f.euler();
            let want = euler_zyx(truth);
            for i in 0..3 {
                assert!(
                    (ypr[i] - want[i]).abs() < 1e-9,
                    "{name} {e:?}: {ypr:?} vs {want:?}"
                );
            }
        }
        for (name, mut f) in filters::<f32>(Initial::FirstSample) {
            f.update(&static_imu(truth, [0.0; 3]), DT as f32);
            let err = geodesic_angle(f.quaternion().map(f64::from), truth);
            assert!(err < 1e-6, "{name} {e:?} f32: {err:e}");
        }
    }
}

#[test]
fn q_and_minus_q_are_the_same_attitude() {
    let truth = from_euler_zyx([0.2, -1.35, 3.1]);
    let start = turned(truth, [0.0, 0.6, 0.8], 0.5);
    let minus: Quat<f64> = start.map(|c| -c);
    assert_eq!(geodesic_angle(start, minus), 0.0);
    let (e1, e2) = (euler_zyx(start), euler_zyx(minus));
    for i in 0..3 {
        assert!((e1[i] - e2[i]).abs() < 1e-15);
    }
    let imu = static_imu(truth, [0.0; 3]);
    let plus_filters = filters::<f64>(Initial::Attitude(start));
    let minus_filters = filters::<f64>(Initial::Attitude(minus));
    for ((name, mut a), (_, mut b)) in plus_filters.into_iter().zip(minus_filters) {
        for _ in 0..2000 {
            a.update(&imu, DT);
            b.update(&imu, DT);
            // Every step of every filter is odd in q: −q stays the exact negative.
            let (qa, qb) = (a.quaternion(), b.quaternion());
            assert!((0..4).all(|i| qa[i] == -qb[i]), "{name}: {qa:?} {qb:?}");
        }
        // Resetting to −q is the same attitude as resetting to q.
        a.reset(truth);
        b.reset(truth.map(|c| -c));
        a.update(&imu, DT);
        b.update(&imu, DT);
        assert!(
            geodesic_angle(a.quaternion(), b.quaternion()) < 1e-15,
            "{name}"
        );
        let bound = if name == "gda" {
            2.0 * BETA * DT + 1e-9
        } else {
            1e-12
        };
        assert!(geodesic_angle(b.quaternion(), truth) < bound, "{name}");
    }
}

#[test]
fn ecf_integrator_and_ekf_bias_states_remove_a_constant_gyro_bias() {
    let bias = [0.02, -0.01, 0.03];
    for e in [[0.3, -0.2, 2.0], [0.4, 79.5f64.to_radians(), 3.1]] {
        let truth = from_euler_zyx(e);
        let imu = static_imu(truth, bias);
        let initial = Initial::Attitude(turned(truth, [1.0, 0.0, 0.0], 0.3));
        let mut ecf = Ecf::<f64>::new(&EcfConfig {
            kp: 5.0,
            ki: 2.0,
            initial,
            ..EcfConfig::default()
        })
        .unwrap();
        let mut ekf = Ekf::<f64>::new(&ekf_config(initial)).unwrap();
        for _ in 0..(60.0 / DT) as usize {
            ecf.update(&imu, DT);
            ekf.update(&imu, DT);
        }
        assert!(geodesic_angle(ecf.quaternion(), truth) < 1e-8, "{e:?}");
        assert!(geodesic_angle(ekf.quaternion(), truth) < 1e-12, "{e:?}");
        // Ki·∫e cancels the bias; the EKF estimates it.
        for ((b, integral), estimate) in bias.iter().zip(ecf.integral()).zip(ekf.bias()) {
            assert!((2.0 * integral + b).abs() < 1e-8, "{e:?}");
            assert!((estimate - b).abs() < 1e-12, "{e:?}");
        }
    }
}
