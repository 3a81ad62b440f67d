//! The chips' sampling chains: every table row's −3 dB point and delay, every error, the
//! defaults at every rate each model supports, and the settings' bytes.

use margemu_protocol::chip::chain::tables::{self, Row};
use margemu_protocol::chip::chain::{row_design, MAX_ENCODED_LEN};
use margemu_protocol::chip::{ChainConfig, ChainError, ChipChain, ChipModel, ChipSettings};
use margemu_protocol::link::Rate;

/// −3 dB within 0.1 dB: 0.7079 ± 1 %.
fn is_3db(gain: f64) -> bool {
    (gain / 0.707_946 - 1.0).abs() < 0.01
}

/// `(table, rows whose delay no causal low-pass can meet)`.
fn row_tables() -> [(&'static str, &'static [Row], &'static [u8]); 6] {
    [
        ("MPU-6500 gyro", &tables::MPU6500_GYRO, &[]),
        ("MPU-6500 accel", &tables::MPU6500_ACCEL, &[]),
        ("ICM-20602 gyro", &tables::ICM20602_GYRO, &[]),
        ("ICM-20602 accel", &tables::ICM20602_ACCEL, &[]),
        ("MPU-6000 gyro", &tables::MPU6000_GYRO, &[5, 6]),
        ("MPU-6000 accel", &tables::MPU6000_ACCEL, &[5, 6]),
    ]
}

#[test]
fn every_6xxx_row_has_its_bandwidth_and_delay() {
    for (name, table, unmet) in row_tables() {
        for row in table {
            let d = row_design(row).unwrap();
            let rate = 1e9 / row.period_ns as f64;
            assert!(is_3db(d.gain_at(row.bandwidth_hz)), "{name} {}", row.code);
            let want = row.delay_ms.unwrap() * 1e-3;
            let err = (d.delay_s() - want).abs() * rate;
            if unmet.contains(&row.code) {
                assert!(
                    d.delay_s() > want + 0.5 / rate,
                    "{name} {} is met",
                    row.code
                );
                assert_eq!(
                    (d.order(), d.delay_samples()),
                    (1, 0),
                    "{name} {}",
                    row.code
                );
            } else {
                assert!(err <= 0.5, "{name} {}: {} vs {want}", row.code, d.delay_s());
            }
        }
    }
}

fn hz(rate: f64) -> Rate {
    if rate.fract() == 0.0 {
        Rate::hz(rate as u32).unwrap()
    } else {
        Rate::new((rate * 8.0) as u32, 8).unwrap()
    }
}

fn chain(model: ChipModel, config: ChainConfig, rate: f64) -> Result<ChipChain, ChainError> {
    ChipChain::new(&ChipSettings::power_on(model), &config, hz(rate))
}

fn icm(delt: u8, order: u8, bw: u8) -> ChainConfig {
    ChainConfig::Icm42688p {
        gyro_aaf_delt: delt,
        accel_aaf_delt: delt,
        gyro_ui_order: order,
        gyro_ui_bw: bw,
        accel_ui_order: order,
        accel_ui_bw: bw,
    }
}

#[test]
fn every_icm42688p_aaf_row_has_its_bandwidth() {
    for (i, want) in tables::ICM42688P_AAF_HZ.iter().enumerate() {
        let c = chain(ChipModel::Icm42688p, icm(i as u8 + 1, 1, 15), 8000.0).unwrap();
        for s in [c.gyro, c.accel] {
            assert_eq!((s.period_ns, s.filter.order()), (31_250, 2));
            assert!(is_3db(s.filter.gain_at(f64::from(*want))), "delt {}", i + 1);
            assert!((s.bandwidth_hz - f64::from(*want)).abs() < 1e-3 * f64::from(*want));
        }
    }
}

#[test]
fn every_icm42688p_ui_filter_row_has_its_bandwidth() {
    let odrs = [
        32_000.0, 16_000.0, 8000.0, 4000.0, 2000.0, 1000.0, 500.0, 200.0, 100.0, 50.0, 25.0, 12.5,
    ];
    for odr in odrs {
        for order in 0..=2u8 {
            for bw in 0..=7u8 {
                let c = chain(ChipModel::Icm42688p, icm(0, order, bw), odr).unwrap();
                let div = tables::ICM42688P_UI_DIVISORS[usize::from(bw)];
                let want = if bw == 0 {
                    odr / div
                } else {
                    f64::max(odr, 400.0) / div
                };
                if want < 0.45 * 32_000.0 {
                    assert_eq!(c.gyro.filter.order(), usize::from(order) + 1);
                    assert!(is_3db(c.gyro.filter.gain_at(want)), "{odr} {order} {bw}");
                    assert!(is_3db(c.accel.filter.gain_at(c.accel.bandwidth_hz)));
                } else {
                    assert_eq!(c.gyro.filter.order(), 0, "{odr} {order} {bw}");
                }
            }
            for bw in [14, 15] {
                let c = chain(ChipModel::Icm42688p, icm(0, order, bw), odr).unwrap();
                assert_eq!(c.gyro.filter.order(), 0);
            }
        }
    }
}

#[test]
fn every_bmi088_row_has_its_bandwidth() {
    for row in tables::BMI088_GYRO {
        let odr = 1e9 / row.period_ns as f64;
        for (acc_bwp, shift) in [(0xA, 1.0), (0x9, 2.0), (0x8, 4.0)] {
            let config = ChainConfig::Bmi088 {
                gyro_bandwidth: row.code,
                acc_bwp,
            };
            let c = chain(ChipModel::Bmi088, config, odr).unwrap();
            assert_eq!(
                (c.gyro.period_ns, c.output_period_ns),
                (row.period_ns, row.period_ns)
            );
            assert!(
                is_3db(c.gyro.filter.gain_at(row.bandwidth_hz)),
                "gyro {}",
                row.code
            );
            assert_eq!(c.gyro.bandwidth_hz, row.bandwidth_hz);
            // The accel ODR at or below the gyro's; its normal −3 dB at ODR / shift.
            let acc_odr = 1e9 / c.accel.period_ns as f64;
            assert!(acc_odr <= odr && acc_odr * 2.0 > odr);
            let idx = [12.5, 25.0, 50.0, 100.0, 200.0, 400.0, 800.0, 1600.0]
                .iter()
                .position(|&r| (r - acc_odr / shift).abs() < 1e-9);
            if let Some(i) = idx {
                assert_eq!(c.accel.bandwidth_hz, tables::BMI088_ACCEL_NORMAL_HZ[i]);
            }
            assert!(is_3db(c.accel.filter.gain_at(c.accel.bandwidth_hz)));
        }
    }
}

#[test]
fn every_bmi270_rate_and_bwp_builds_its_bandwidth() {
    let (acc_frac, gyro_frac) = tables::BMI270_NORMAL_FRACTION;
    for k in 0..8 {
        let odr = 25.0 * f64::from(1u32 << k);
        for bwp in 0..=2u8 {
            let config = ChainConfig::Bmi270 {
                gyro_filter_perf: true,
                gyro_bwp: bwp,
                acc_filter_perf: false,
                acc_bwp: bwp,
            };
            let c = chain(ChipModel::Bmi270, config, odr).unwrap();
            let div = f64::from(1u8 << (2 - bwp));
            assert!((c.gyro.bandwidth_hz - gyro_frac * odr / div).abs() < 1e-3);
            assert!(is_3db(c.gyro.filter.gain_at(c.gyro.bandwidth_hz)));
            let acc_odr = odr.min(1600.0);
            assert!((c.accel.bandwidth_hz - acc_frac * acc_odr / div).abs() < 1e-3);
            assert!(is_3db(c.accel.filter.gain_at(c.accel.bandwidth_hz)));
        }
    }
}

#[test]
fn table_rates_agree_with_the_register_rate_rules() {
    for model in [
        ChipModel::Mpu6500,
        ChipModel::Mpu9250,
        ChipModel::Icm20602,
        ChipModel::Mpu6000,
    ] {
        let is_6000 = model == ChipModel::Mpu6000;
        for dlpf_cfg in 0..if is_6000 { 7 } else { 8 } {
            let out = if matches!(dlpf_cfg, 0 | 7) {
                8000.0
            } else {
                1000.0
            };
            let config = ChainConfig::Mpu6xxx {
                dlpf_cfg,
                fchoice_b: 0,
                a_dlpf_cfg: if is_6000 { 0 } else { dlpf_cfg },
                accel_fchoice_b: false,
            };
            let c = chain(model, config, out).unwrap();
            let table = match model {
                ChipModel::Mpu6000 => &tables::MPU6000_GYRO[..],
                ChipModel::Icm20602 => &tables::ICM20602_GYRO[..],
                _ => &tables::MPU6500_GYRO[..],
            };
            // The DLPF runs on the ADC's samples (8 kHz gyro, 4 kHz accel) before the register
            // rate of the table; the MPU-6000's accelerometer at its 1 kHz.
            assert_eq!(
                c.gyro.period_ns,
                table[usize::from(dlpf_cfg)].period_ns.min(125_000),
                "{model:?} {dlpf_cfg}"
            );
            assert_eq!(c.accel.period_ns, if is_6000 { 1_000_000 } else { 250_000 });
        }
    }
    let c = chain(
        ChipModel::Mpu9250,
        ChainConfig::Mpu6xxx {
            dlpf_cfg: 0,
            fchoice_b: 2,
            a_dlpf_cfg: 0,
            accel_fchoice_b: true,
        },
        32_000.0,
    )
    .unwrap();
    assert_eq!((c.gyro.period_ns, c.accel.period_ns), (31_250, 250_000));
    assert_eq!(
        (c.gyro.bandwidth_hz, c.accel.bandwidth_hz),
        (3600.0, 1130.0)
    );
}

/// Candidate output rates: every rate a model's registers can give is among these.
fn candidate_rates() -> Vec<f64> {
    let mut r: Vec<f64> = vec![
        32_000.0, 16_000.0, 4000.0, 2000.0, 3200.0, 1600.0, 800.0, 400.0, 500.0, 200.0, 100.0,
        50.0, 25.0, 12.5,
    ];
    for n in 1..=256u32 {
        r.push(8000.0 / f64::from(n));
        r.push(1000.0 / f64::from(n));
    }
    r
}

#[test]
fn defaults_build_at_every_rate_of_every_model() {
    let mut built = 0;
    for model in ChipModel::ALL {
        let rates: Vec<Rate> = candidate_rates()
            .into_iter()
            .filter(|&r| model.has_output_rate(r))
            .map(|r| {
                if r.fract() == 0.0 {
                    Rate::hz(r as u32).unwrap()
                } else {
                    // 8000/n or 1000/n or 12.5 as an exact fraction.
                    (1..=256u32)
                        .find_map(|n| {
                            let num = (r * f64::from(n)).round();
                            ((num / f64::from(n) - r).abs() < 1e-9 * r)
                                .then(|| Rate::new(num as u32, n).unwrap())
                        })
                        .unwrap()
                }
            })
            .collect();
        if model.is_magnetometer_only() {
            assert_eq!(
                ChainConfig::default_for(model, Rate::hz(100).unwrap()),
                None
            );
            let config =
                ChainConfig::default_for(ChipModel::Mpu6000, Rate::hz(100).unwrap()).unwrap();
            let e = ChipChain::new(
                &ChipSettings::power_on(model),
                &config,
                Rate::hz(100).unwrap(),
            );
            assert_eq!(e, Err(ChainError::NoChain { model }));
            continue;
        }
        assert!(!rates.is_empty());
        for rate in rates {
            let config = ChainConfig::default_for(model, rate).unwrap();
            let c = ChipChain::new(&ChipSettings::power_on(model), &config, rate)
                .unwrap_or_else(|e| panic!("{model:?} at {} Hz: {e}", rate.as_hz_f64()));
            assert_eq!(c.output_period_ns % c.gyro.period_ns, 0);
            assert!(c.accel.range > 0.0 && c.gyro.range > 0.0);
            built += 1;
        }
    }
    assert!(built > 1000, "{built}");
}

#[test]
fn ranges_are_the_full_scales_in_si() {
    let model = ChipModel::Mpu6000;
    let rate = Rate::hz(1000).unwrap();
    let c = ChipChain::new(
        &ChipSettings::power_on(model),
        &ChainConfig::default_for(model, rate).unwrap(),
        rate,
    )
    .unwrap();
    assert!((c.accel.range - 2.0 * 9.80665).abs() < 1e-5); // ±2 g at power-on
    assert!((c.gyro.range - 250f32.to_radians()).abs() < 1e-5); // ±250 °/s
}

#[test]
fn every_error_names_the_field_the_value_and_what_is_allowed() {
    let mpu = |d, f, a, b| ChainConfig::Mpu6xxx {
        dlpf_cfg: d,
        fchoice_b: f,
        a_dlpf_cfg: a,
        accel_fchoice_b: b,
    };
    let cases: Vec<(ChipModel, ChainConfig, f64, &str)> = vec![
        (ChipModel::Mpu6500, mpu(8, 0, 0, false), 1000.0, "filters: dlpf_cfg = 8 is out of range (allowed: 0-7)"),
        (ChipModel::Mpu6500, mpu(1, 4, 0, false), 1000.0, "filters: fchoice_b = 4 is out of range (allowed: 0-3)"),
        (ChipModel::Mpu6500, mpu(1, 0, 9, false), 1000.0, "filters: a_dlpf_cfg = 9 is out of range (allowed: 0-7)"),
        (ChipModel::Mpu6000, mpu(1, 1, 0, false), 1000.0, "filters: fchoice_b = 1 does not fit the MPU-6000 (allowed: 0: the MPU-6000 has no FCHOICE_B)"),
        (ChipModel::Mpu6000, mpu(1, 0, 2, false), 1000.0, "filters: a_dlpf_cfg = 2 does not fit the MPU-6000 (allowed: 0: the MPU-6000 has one DLPF, DLPF_CFG, for both sensors)"),
        (ChipModel::Mpu6000, mpu(1, 0, 0, true), 1000.0, "filters: accel_fchoice_b = 1 does not fit the MPU-6000 (allowed: 0: the MPU-6000 has one DLPF, DLPF_CFG, for both sensors)"),
        (ChipModel::Mpu6000, mpu(7, 0, 0, false), 8000.0, "filters: dlpf_cfg = 7 does not fit the MPU-6000 (allowed: 0-6: 7 is reserved on the MPU-6000)"),
        (ChipModel::Mpu6500, mpu(0, 0, 0, false), 1000.0, "filters: output rate 1000 Hz cannot be produced with dlpf_cfg = 0 (DLPF_CFG 0 and 7 give 8 kHz only: SMPLRT_DIV divides only at 1 kHz)"),
        (ChipModel::Mpu9250, mpu(1, 1, 0, false), 8000.0, "filters: output rate 8000 Hz cannot be produced with fchoice_b = 1 (FCHOICE_B gives 32 kHz only)"),
        (ChipModel::Mpu6500, mpu(1, 0, 0, false), 8000.0, "filters: output rate 8000 Hz cannot be produced with dlpf_cfg = 1 (1 kHz / (1 + SMPLRT_DIV))"),
        (ChipModel::Mpu6000, mpu(1, 0, 0, false), 3000.0, "filters: output rate 3000 Hz cannot be produced with dlpf_cfg = 1 (the gyro rate (8 kHz at DLPF_CFG 0, else 1 kHz) / (1 + SMPLRT_DIV))"),
        (ChipModel::Icm42688p, icm(64, 1, 15), 1000.0, "filters: gyro_aaf_delt = 64 is out of range (allowed: 1-63, or 0 for the AAF off)"),
        (ChipModel::Icm42688p, icm(6, 3, 15), 1000.0, "filters: gyro_ui_order = 3 is out of range (allowed: 0 (first), 1 (second), 2 (third order))"),
        (ChipModel::Icm42688p, icm(6, 1, 9), 1000.0, "filters: gyro_ui_bw = 9 is out of range (allowed: 0-7, 14, 15)"),
        (ChipModel::Icm42688p, icm(6, 1, 1), 300.0, "filters: output rate 300 Hz cannot be produced with output rate = 0 (the ICM-42688-P's ODRs: 32k, 16k, 8k, 4k, 2k, 1k, 500, 200, 100, 50, 25, 12.5 Hz)"),
        (ChipModel::Bmi088, ChainConfig::Bmi088 { gyro_bandwidth: 8, acc_bwp: 0xA }, 2000.0, "filters: gyro_bandwidth = 8 is out of range (allowed: 0-7)"),
        (ChipModel::Bmi088, ChainConfig::Bmi088 { gyro_bandwidth: 0, acc_bwp: 7 }, 2000.0, "filters: acc_bwp = 7 is out of range (allowed: 8 (OSR4), 9 (OSR2), 10 (normal))"),
        (ChipModel::Bmi088, ChainConfig::Bmi088 { gyro_bandwidth: 0, acc_bwp: 0xA }, 1000.0, "filters: output rate 1000 Hz cannot be produced with gyro_bandwidth = 0 (GYRO_BANDWIDTH sets the ODR: 0-1 2 kHz, 2 1 kHz, 3 400 Hz, 4 and 6 200 Hz, 5 and 7 100 Hz)"),
        (ChipModel::Bmi270, ChainConfig::Bmi270 { gyro_filter_perf: true, gyro_bwp: 3, acc_filter_perf: true, acc_bwp: 2 }, 3200.0, "filters: gyro_bwp = 3 is out of range (allowed: 0 (OSR4), 1 (OSR2), 2 (normal))"),
        (ChipModel::Bmi270, ChainConfig::Bmi270 { gyro_filter_perf: true, gyro_bwp: 2, acc_filter_perf: true, acc_bwp: 2 }, 1000.0, "filters: output rate 1000 Hz cannot be produced with output rate = 0 (the BMI270's gyro ODRs: 25 Hz to 3.2 kHz, doubling)"),
        (ChipModel::Bmi270, mpu(1, 0, 0, false), 1600.0, "filters: the BMI270 takes the keys gyro_filter_perf, gyro_bwp, acc_filter_perf, acc_bwp"),
    ];
    for (model, config, rate, want) in cases {
        let e = chain(model, config, rate).unwrap_err();
        assert_eq!(e.to_string(), want, "{e:?}");
    }
    assert_eq!(
        ChainError::NoChain {
            model: ChipModel::Ist8310
        }
        .to_string(),
        "filters: the IST8310 has no sampling chain"
    );
    assert_eq!(
        ChainError::Malformed.to_string(),
        "filters: malformed settings bytes"
    );
}

#[test]
fn settings_bytes_round_trip() {
    let mut buf = [0u8; MAX_ENCODED_LEN];
    for model in ChipModel::ALL {
        for rate in [1000, 2000, 8000, 32_000, 3200, 100] {
            let Some(config) = ChainConfig::default_for(model, Rate::hz(rate).unwrap()) else {
                continue;
            };
            let n = config.encode(&mut buf);
            assert_eq!(n, 1 + ChainConfig::keys(config.family()).len());
            assert_eq!(ChainConfig::decode(&buf[..n]), Ok(config));
            assert_eq!(config.encode(&mut buf[..n - 1]), 0);
            assert_eq!(
                ChainConfig::decode(&buf[..n - 1]),
                Err(ChainError::Malformed)
            );
        }
    }
    assert_eq!(ChainConfig::decode(&[]), Err(ChainError::Malformed));
    assert_eq!(ChainConfig::decode(&[9, 1, 2]), Err(ChainError::Malformed));
    // A flag is 0 or 1 on the link (found by the message fuzzer: 0x70 decoded as true and
    // re-encoded as 1).
    assert_eq!(
        ChainConfig::decode(&[0, 5, 0, 0, 0x70]),
        Err(ChainError::Malformed)
    );
    assert!(ChainConfig::decode(&[0, 5, 0, 0, 1]).is_ok());
    assert_eq!(
        ChainConfig::decode(&[2, 2, 2, 1, 2]),
        Err(ChainError::Malformed)
    );
    assert_eq!(
        ChainConfig::decode(&[3, 1, 0xA]),
        Ok(ChainConfig::Bmi088 {
            gyro_bandwidth: 1,
            acc_bwp: 0xA
        })
    );
}
