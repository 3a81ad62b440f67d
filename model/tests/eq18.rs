//! Eq. 18 and the deterministic extra terms on hand-computed vectors. The values are chosen to
//! be exact in binary, so the expectations are literal and compared bit for bit.

use margemu_model::sensor::{
    AccelConfig, GyroConfig, Mag, MagConfig, Marg, MargConfig, SensorErrors, TemperatureBias, Truth,
};
use margemu_model::Error;

#[test]
fn gyro_scale_misalignment_and_bias() {
    // (I + ΔS) = diag(1.5, 0.75, 1.125); T = (I + ΔS)·M = [[1.5, .75, 0], [0, .75, .1875],
    // [−.5625, 0, 1.125]]; T·(1, 2, 4) = (3, 2.25, 3.9375); + bias.
    let cfg = MargConfig {
        gyro: GyroConfig {
            errors: SensorErrors {
                scale_factor: Some([[0.5, 0.0, 0.0], [0.0, -0.25, 0.0], [0.0, 0.0, 0.125]]),
                misalignment: Some([[1.0, 0.5, 0.0], [0.0, 1.0, 0.25], [-0.5, 0.0, 1.0]]),
                bias: Some([0.25, -0.5, 1.0]),
                ..SensorErrors::default()
            },
            g_sensitivity: None,
        },
        ..MargConfig::default()
    };
    let mut marg = Marg::new(&cfg, 100.0, 1).unwrap();
    let t = Truth {
        angular_rate: [1.0, 2.0, 4.0],
        ..Truth::default()
    };
    assert_eq!(marg.sample(&t).gyr, [3.25, 1.75, 4.9375]);
}

#[test]
fn accel_scale_misalignment_and_bias() {
    // T = diag(0.5, 1, 1.25)·[[1,0,0],[.25,1,0],[0,0,1]]; T·(2, −4, 8) = (1, −3.5, 10); + a₀.
    let mut cfg = MargConfig::default();
    cfg.accel.errors = SensorErrors {
        scale_factor: Some([[-0.5, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.25]]),
        misalignment: Some([[1.0, 0.0, 0.0], [0.25, 1.0, 0.0], [0.0, 0.0, 1.0]]),
        bias: Some([0.0, 0.0, -0.5]),
        ..SensorErrors::default()
    };
    let mut marg = Marg::new(&cfg, 100.0, 1).unwrap();
    let t = Truth {
        specific_force: [2.0, -4.0, 8.0],
        ..Truth::default()
    };
    let s = marg.sample(&t);
    assert_eq!(s.acc, [1.0, -3.5, 9.5]);
    assert_eq!(s.gyr, [0.0; 3]); // the other sensors are ideal
}

#[test]
fn mag_soft_and_hard_iron() {
    // B_si·h = (1, −.375, −.375); + b_hi = (2, −1.375, 1.625);
    // (I + ΔS)·M with ΔS = [[0, .25, 0], [0, .5, 0], 0] and M = I: (1.65625, −2.0625, 1.625);
    // + h₀ = (2.15625, −2.0625, 1.375).
    let cfg = MagConfig {
        errors: SensorErrors {
            scale_factor: Some([[0.0, 0.25, 0.0], [0.0, 0.5, 0.0], [0.0, 0.0, 0.0]]),
            bias: Some([0.5, 0.0, -0.25]),
            ..SensorErrors::default()
        },
        soft_iron: Some([[2.0, 0.0, 0.0], [0.0, 1.0, 0.5], [0.0, 0.0, 0.5]]),
        hard_iron: Some([1.0, -1.0, 2.0]),
    };
    let mut mag = Mag::new(&cfg, 100.0, 1).unwrap();
    let out = mag.sample([0.5, 0.0, -0.75], None);
    assert_eq!(out, [2.15625, -2.0625, 1.375]);
    assert_eq!(
        out.map(f32::to_bits),
        [0x400a_0000, 0xc004_0000, 0x3fb0_0000]
    );
}

#[test]
fn lever_arm_g_sensitivity_and_temperature() {
    // r = (.5, 0, 0), ω = (0, 0, 2), ω̇ = (0, 0, 1): ω̇×r = (0, .5, 0), ω×(ω×r) = (−2, 0, 0).
    // G·f = (.125·8, 0, .5·(−2)) = (1, 0, −1). Temperature 29 °C against 25 °C: 4·c.
    let cfg = MargConfig {
        gyro: GyroConfig {
            errors: SensorErrors::default(),
            g_sensitivity: Some([[0.0, 0.0, 0.125], [0.0, 0.0, 0.0], [0.5, 0.0, 0.0]]),
        },
        accel: AccelConfig {
            errors: SensorErrors {
                temperature_bias: Some(TemperatureBias {
                    coefficient: [0.5, -0.25, 1.0],
                    reference_c: 25.0,
                }),
                ..SensorErrors::default()
            },
            lever_arm_m: Some([0.5, 0.0, 0.0]),
        },
        mag: MagConfig::default(),
    };
    let mut marg = Marg::new(&cfg, 100.0, 1).unwrap();
    let mut t = Truth {
        angular_rate: [0.0, 0.0, 2.0],
        angular_acceleration: [0.0, 0.0, 1.0],
        specific_force: [0.0, 0.0, 8.0],
        magnetic_field: [0.5, 0.0, -0.83],
        temperature_c: Some(29.0),
    };
    let s = marg.sample(&t);
    assert_eq!(s.acc, [-2.0 + 2.0, 0.5 - 1.0, 8.0 + 4.0]);
    assert_eq!(s.gyr, [1.0, 0.0, 1.0]);
    assert_eq!(s.mag, [0.5, 0.0, -0.83]);
    t.temperature_c = None; // no temperature: the reference one
    assert_eq!(marg.sample(&t).acc, [-2.0, 0.5, 8.0]);
}

#[test]
fn ideal_path_is_a_copy() {
    let mut marg = Marg::new(&MargConfig::default(), 100.0, 1).unwrap();
    assert!(marg.is_ideal());
    let t = Truth {
        angular_rate: [f32::NAN, 1e38, -0.0],
        specific_force: [0.1, 0.2, 9.80665],
        magnetic_field: [0.5, f32::INFINITY, -0.83],
        ..Truth::default()
    };
    let s = marg.sample(&t);
    assert_eq!(s.acc, t.specific_force);
    assert_eq!(s.mag.map(f32::to_bits), t.magnetic_field.map(f32::to_bits));
    assert_eq!(s.gyr.map(f32::to_bits), t.angular_rate.map(f32::to_bits));
}

#[test]
fn invalid_configurations_name_the_field() {
    let mut cfg = MargConfig::default();
    cfg.gyro.errors.noise_density = Some([0.1, f64::NAN, 0.1]);
    assert_eq!(
        Marg::new(&cfg, 100.0, 0).unwrap_err(),
        Error::NonFiniteParameter {
            what: "gyro.noise_density"
        }
    );
    cfg.gyro.errors.noise_density = Some([0.1, -0.1, 0.1]);
    assert_eq!(
        Marg::new(&cfg, 100.0, 0).unwrap_err(),
        Error::NegativeParameter {
            what: "gyro.noise_density"
        }
    );
    cfg.gyro.errors.noise_density = None;
    cfg.mag.errors.range = Some([1.0, 0.0, 1.0]);
    assert_eq!(
        Marg::new(&cfg, 100.0, 0).unwrap_err(),
        Error::NonPositiveParameter { what: "mag.range" }
    );
    cfg.mag.errors.range = None;
    cfg.accel.errors.bias = Some([1e300, 0.0, 0.0]);
    assert_eq!(
        Marg::new(&cfg, 100.0, 0).unwrap_err(),
        Error::ParameterTooLarge { what: "accel.bias" }
    );
    assert_eq!(
        Marg::new(&MargConfig::default(), 0.0, 0).unwrap_err(),
        Error::InvalidRate
    );
    assert_eq!(
        Marg::new(&MargConfig::default(), f64::NAN, 0).unwrap_err(),
        Error::InvalidRate
    );
}
