//! Any input, finite or not, never panics and never yields a NaN: the quaternion stays finite
//! and unit, the EKF's bias and covariance finite, exactly symmetric and with a positive
//! diagonal, and every call is counted.

use margemu_filters::quat::Quat;
use margemu_filters::{
    AttitudeFilter, Ecf, EcfConfig, Ekf, EkfConfig, Gda, GdaConfig, GdaNormalization, Imu, Initial,
    Real,
};
use proptest::prelude::*;

/// Mostly plausible numbers, often the special ones.
fn num() -> BoxedStrategy<f64> {
    prop_oneof![
        4 => -60.0..60.0f64,
        1 => -1e-3..1e-3f64,
        1 => any::<f64>(),
        2 => prop::sample::select(vec![
            0.0, -0.0, f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e300, -1e300, 3e38, -3e38,
            1e-40, 1e-310, f64::MIN_POSITIVE,
        ]),
    ]
    .boxed()
}

fn dt() -> BoxedStrategy<f64> {
    prop_oneof![
        4 => 1e-4..0.1f64,
        1 => num(),
        1 => prop::sample::select(vec![1e6, 1e30, 5e-324]),
    ]
    .boxed()
}

fn vec3() -> BoxedStrategy<[f64; 3]> {
    prop_oneof![
        3 => prop::array::uniform3(num()),
        1 => Just([0.0; 3]),
        1 => prop::array::uniform3(-10.0..10.0f64),
    ]
    .boxed()
}

fn sample() -> impl Strategy<Value = (Imu<f64>, f64)> {
    (vec3(), vec3(), vec3(), dt()).prop_map(|(gyro, acc, mag, dt)| (Imu { gyro, acc, mag }, dt))
}

fn initial() -> impl Strategy<Value = Initial> {
    prop_oneof![
        Just(Initial::FirstSample),
        prop::array::uniform4(-1.0..1.0f64)
            .prop_filter("nonzero", |q| q.iter().any(|c| c.abs() > 1e-3))
            .prop_map(Initial::Attitude),
    ]
}

fn narrow(imu: &Imu<f64>) -> Imu<f32> {
    let n = |v: [f64; 3]| v.map(|c| c as f32);
    Imu {
        gyro: n(imu.gyro),
        acc: n(imu.acc),
        mag: n(imu.mag),
    }
}

fn check_unit<T: Real>(q: Quat<T>, what: &str) {
    let q = q.map(|c| c.to_f64());
    let n2: f64 = q.iter().map(|c| c * c).sum();
    assert!(q.iter().all(|c| c.is_finite()), "{what}: {q:?}");
    assert!((n2 - 1.0).abs() < 1e-5, "{what}: |q|² = {n2}");
}

fn check_ekf<T: Real>(ekf: &Ekf<T>) {
    let p = ekf.covariance();
    for (i, row) in p.iter().enumerate() {
        assert!(row[i] > T::ZERO, "P[{i}][{i}] = {:?}", row[i]);
        for (j, v) in row.iter().enumerate() {
            assert!(v.is_finite() && *v == p[j][i], "P[{i}][{j}]");
        }
    }
    assert!(ekf.bias().iter().all(|c| c.is_finite()));
}

/// Runs all three filters in `T` over `samples`, checking after every call.
fn run_all<T: Real>(initial: Initial, beta_residual: bool, samples: &[(Imu<T>, T)]) {
    let normalization = if beta_residual {
        GdaNormalization::Residual
    } else {
        GdaNormalization::Gradient
    };
    let mut ecf = Ecf::<T>::new(&EcfConfig {
        ki: 0.5,
        initial,
        ..EcfConfig::default()
    })
    .unwrap();
    let mut gda = Gda::<T>::new(&GdaConfig {
        normalization,
        initial,
        ..GdaConfig::default()
    })
    .unwrap();
    let mut ekf = Ekf::<T>::new(&EkfConfig {
        initial,
        ..EkfConfig::default()
    })
    .unwrap();
    for (imu, dt) in samples {
        ecf.update(imu, *dt);
        gda.update(imu, *dt);
        ekf.update(imu, *dt);
        check_unit(ecf.quaternion(), "ecf");
        check_unit(gda.quaternion(), "gda");
        check_unit(ekf.quaternion(), "ekf");
        assert!(ecf.integral().iter().all(|c| c.is_finite()));
        check_ekf(&ekf);
    }
    for d in [ecf.diagnostics(), gda.diagnostics(), ekf.diagnostics()] {
        assert_eq!(d.updates + d.skipped_updates, samples.len() as u64, "{d:?}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    #[test]
    fn any_input_keeps_every_filter_finite_and_unit(
        initial in initial(),
        residual in any::<bool>(),
        samples in prop::collection::vec(sample(), 1..60),
    ) {
        run_all::<f64>(initial, residual, &samples);
        let single: Vec<(Imu<f32>, f32)> = samples.iter().map(|(i, d)| (narrow(i), *d as f32)).collect();
        run_all::<f32>(initial, residual, &single);
    }

    #[test]
    fn any_reset_quaternion_restarts_at_a_unit_attitude(q in prop::array::uniform4(num())) {
        let mut f = Ekf::<f32>::new(&EkfConfig::default()).unwrap();
        f.reset(q.map(|c| c as f32));
        check_unit(f.quaternion(), "reset");
        check_ekf(&f);
        let mut g = Gda::<f64>::new(&GdaConfig::default()).unwrap();
        g.reset(q);
        check_unit(g.quaternion(), "reset");
    }
}

#[test]
fn degenerate_inputs_are_skipped_and_counted() {
    let level = Imu {
        gyro: [0.0; 3],
        acc: [0.0, 0.0, 9.81],
        mag: [0.5, 0.0, -0.83],
    };
    let mut f = Ekf::<f64>::new(&EkfConfig::default()).unwrap();
    f.update(&level, 0.005); // initializes
    f.update(
        &Imu {
            acc: [0.0; 3],
            ..level
        },
        0.005,
    );
    f.update(
        &Imu {
            mag: [f64::NAN, 0.0, 0.0],
            ..level
        },
        0.005,
    );
    f.update(
        &Imu {
            gyro: [f64::INFINITY, 0.0, 0.0],
            ..level
        },
        0.005,
    );
    f.update(&level, 0.0);
    f.update(&level, -0.005);
    f.update(&level, f64::NAN);
    let d = f.diagnostics();
    assert_eq!(
        (d.updates, d.skipped_updates, d.skipped_accel, d.skipped_mag),
        (3, 4, 1, 1)
    );
    assert_eq!(d.rejected, 0);
    // A step too long to be finite is undone whole.
    f.update(
        &Imu {
            gyro: [1e300, 1e300, 1e300],
            ..level
        },
        1e300,
    );
    assert_eq!(f.diagnostics().rejected, 1);
    check_unit(f.quaternion(), "after a rejected step");
}
