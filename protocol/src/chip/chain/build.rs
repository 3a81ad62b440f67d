//! Building each family's chains from its table rows (see the parent module's docs).

use super::tables::{self, Row};
use super::{ChainConfig, ChainError, ChipChain, FilterDesign, SensorChain};
use crate::chip::ChipModel;
use crate::regmap::mpu6xxx::{rates, variant::Variant};
use crate::regmap::{bmi088, bmi270, icm42688p};

fn rate_of(period_ns: u64) -> f64 {
    1e9 / period_ns as f64
}

/// The low-pass of a table row: 2nd order, or first order if the 2nd's delay exceeds the
/// row's by more than half a sample; then whole samples of pure delay up to the row's delay.
pub fn row_design(row: &Row) -> Result<FilterDesign, ChainError> {
    let rate = rate_of(row.period_ns);
    let second = FilterDesign::butterworth(2, row.bandwidth_hz, rate)?;
    let Some(delay_ms) = row.delay_ms else {
        return Ok(second);
    };
    let want = delay_ms * 1e-3;
    let design = if second.delay_s() > want + 0.5 / rate {
        FilterDesign::first_order(row.bandwidth_hz, rate)?
    } else {
        second
    };
    // Round half up; a negative shortfall (the filter alone is slower) adds nothing.
    let extra = ((want - design.delay_s()) * rate + 0.5).max(0.0) as usize;
    Ok(design.with_delay(extra)?)
}

fn row_chain(row: &Row, period_ns: u64) -> Result<SensorChain, ChainError> {
    let row = Row { period_ns, ..*row };
    let filter = row_design(&row)?;
    Ok(SensorChain {
        period_ns,
        filter,
        range: 0.0,
        bandwidth_hz: row.bandwidth_hz,
        delay_s: row.delay_ms.map_or(filter.delay_s(), |ms| ms * 1e-3),
    })
}

fn design_chain(filter: FilterDesign, period_ns: u64) -> SensorChain {
    SensorChain {
        period_ns,
        filter,
        range: 0.0,
        bandwidth_hz: filter.bandwidth_hz().unwrap_or(0.5 * filter.rate_hz()),
        delay_s: filter.delay_s(),
    }
}

fn find(table: &[Row], code: u8) -> Option<&Row> {
    table.iter().find(|r| r.code == code)
}

fn out_of_range(field: &'static str, value: u8, allowed: &'static str) -> ChainError {
    ChainError::CodeOutOfRange {
        field,
        value,
        allowed,
    }
}

/// The chains of `model` (of `config`'s family) at an output of `hz`, period `out_ns`.
pub fn chains(
    model: ChipModel,
    config: &ChainConfig,
    hz: f64,
    out_ns: u64,
) -> Result<ChipChain, ChainError> {
    let (accel, gyro, field, value, allowed) = match *config {
        ChainConfig::Mpu6xxx {
            dlpf_cfg,
            fchoice_b,
            a_dlpf_cfg,
            accel_fchoice_b,
        } => {
            return mpu6xxx(
                model,
                [dlpf_cfg, fchoice_b, a_dlpf_cfg],
                accel_fchoice_b,
                hz,
                out_ns,
            )
        }
        ChainConfig::Icm42688p {
            gyro_aaf_delt,
            accel_aaf_delt,
            gyro_ui_order,
            gyro_ui_bw,
            accel_ui_order,
            accel_ui_bw,
        } => {
            let odr = icm42688p::Odr::gyro_of_hz(hz)
                .filter(|odr| odr.period_ns() == out_ns)
                .ok_or(ChainError::OutputRate {
                    rate_hz: hz,
                    field: "output rate",
                    value: 0,
                    allowed: "the ICM-42688-P's ODRs: 32k, 16k, 8k, 4k, 2k, 1k, 500, 200, 100, 50, 25, 12.5 Hz",
                })?;
            let odr_hz = rate_of(odr.period_ns());
            let g = icm(
                ("gyro_aaf_delt", gyro_aaf_delt),
                ("gyro_ui_order", gyro_ui_order),
                ("gyro_ui_bw", gyro_ui_bw),
                odr_hz,
            )?;
            let a = icm(
                ("accel_aaf_delt", accel_aaf_delt),
                ("accel_ui_order", accel_ui_order),
                ("accel_ui_bw", accel_ui_bw),
                odr_hz,
            )?;
            return Ok(ChipChain {
                accel: a,
                gyro: g,
                output_period_ns: out_ns,
            });
        }
        ChainConfig::Bmi088 {
            gyro_bandwidth,
            acc_bwp,
        } => {
            let row = find(&tables::BMI088_GYRO, gyro_bandwidth).ok_or(out_of_range(
                "gyro_bandwidth",
                gyro_bandwidth,
                "0-7",
            ))?;
            let gyro = row_chain(row, row.period_ns)?;
            let shift = match acc_bwp {
                0xA => 0,
                0x9 => 1,
                0x8 => 2,
                _ => {
                    return Err(out_of_range(
                        "acc_bwp",
                        acc_bwp,
                        "8 (OSR4), 9 (OSR2), 10 (normal)",
                    ))
                }
            };
            let odr = bmi088::accel::Odr::at_most_hz(hz).ok_or(ChainError::OutputRate {
                rate_hz: hz,
                field: "gyro_bandwidth",
                value: gyro_bandwidth,
                allowed: "the accelerometer needs at least 12.5 Hz",
            })?;
            let index = i32::from(odr.code()) - 5 - shift;
            let normal = &tables::BMI088_ACCEL_NORMAL_HZ;
            let bw = match usize::try_from(index) {
                Ok(i) => normal.get(i).copied().unwrap_or(280.0),
                Err(_) => normal[0] / f64::from(1u32 << (-index).min(8) as u32),
            };
            let accel = design_chain(FilterDesign::butterworth(2, bw, odr.hz())?, odr.period_ns());
            let accel = SensorChain {
                bandwidth_hz: bw,
                ..accel
            };
            (accel, gyro, "gyro_bandwidth", gyro_bandwidth, "GYRO_BANDWIDTH sets the ODR: 0-1 2 kHz, 2 1 kHz, 3 400 Hz, 4 and 6 200 Hz, 5 and 7 100 Hz")
        }
        ChainConfig::Bmi270 {
            gyro_bwp, acc_bwp, ..
        } => {
            let shift = |field, bwp: u8| match bwp {
                0..=2 => Ok(f64::from(1u8 << (2 - bwp))),
                _ => Err(out_of_range(field, bwp, "0 (OSR4), 1 (OSR2), 2 (normal)")),
            };
            let (g_div, a_div) = (shift("gyro_bwp", gyro_bwp)?, shift("acc_bwp", acc_bwp)?);
            let (a_frac, g_frac) = tables::BMI270_NORMAL_FRACTION;
            let odr = bmi270::Odr::gyro_of_hz(hz)
                .filter(|o| o.period_ns() == out_ns)
                .ok_or(ChainError::OutputRate {
                    rate_hz: hz,
                    field: "output rate",
                    value: 0,
                    allowed: "the BMI270's gyro ODRs: 25 Hz to 3.2 kHz, doubling",
                })?;
            let acc = bmi270::Odr::accel_of_hz(odr.hz().min(1600.0)).unwrap_or(bmi270::Odr::HZ1600);
            let g_bw = g_frac * odr.hz() / g_div;
            let a_bw = a_frac * acc.hz() / a_div;
            let gyro = design_chain(
                FilterDesign::butterworth(2, g_bw, odr.hz())?,
                odr.period_ns(),
            );
            let accel = design_chain(
                FilterDesign::butterworth(2, a_bw, acc.hz())?,
                acc.period_ns(),
            );
            (accel, gyro, "output rate", 0, "")
        }
    };
    if gyro.period_ns != out_ns {
        return Err(ChainError::OutputRate {
            rate_hz: hz,
            field,
            value,
            allowed,
        });
    }
    Ok(ChipChain {
        accel,
        gyro,
        output_period_ns: out_ns,
    })
}

/// One ICM-42688-P sensor: AAF at 32 kHz, then the UI filter.
fn icm(
    (aaf_key, delt): (&'static str, u8),
    (order_key, order): (&'static str, u8),
    (bw_key, bw): (&'static str, u8),
    odr_hz: f64,
) -> Result<SensorChain, ChainError> {
    const RATE: f64 = 32_000.0;
    let aaf = match delt {
        0 => FilterDesign::identity(RATE)?,
        _ => {
            let hz = tables::ICM42688P_AAF_HZ
                .get(usize::from(delt) - 1)
                .ok_or(out_of_range(aaf_key, delt, "1-63, or 0 for the AAF off"))?;
            FilterDesign::butterworth(2, f64::from(*hz), RATE)?
        }
    };
    if order > 2 {
        return Err(out_of_range(
            order_key,
            order,
            "0 (first), 1 (second), 2 (third order)",
        ));
    }
    let ui = match bw {
        0..=7 => {
            let div = tables::ICM42688P_UI_DIVISORS[usize::from(bw)];
            let base = if bw == 0 { odr_hz } else { odr_hz.max(400.0) };
            let hz = base / div;
            if hz < 0.45 * RATE {
                FilterDesign::butterworth(order + 1, hz, RATE)?
            } else {
                FilterDesign::identity(RATE)?
            }
        }
        14 | 15 => FilterDesign::identity(RATE)?,
        _ => return Err(out_of_range(bw_key, bw, "0-7, 14, 15")),
    };
    Ok(design_chain(aaf.then(ui)?, 31_250))
}

/// The 6xxx chains: codes `[DLPF_CFG, FCHOICE_B, A_DLPF_CFG]`.
fn mpu6xxx(
    model: ChipModel,
    [dlpf, fchoice_b, a_dlpf]: [u8; 3],
    accel_fchoice_b: bool,
    hz: f64,
    out_ns: u64,
) -> Result<ChipChain, ChainError> {
    for (field, value, max) in [
        ("dlpf_cfg", dlpf, 7),
        ("fchoice_b", fchoice_b, 3),
        ("a_dlpf_cfg", a_dlpf, 7),
    ] {
        if value > max {
            return Err(out_of_range(
                field,
                value,
                if max == 3 { "0-3" } else { "0-7" },
            ));
        }
    }
    let variant = Variant::for_model(model, model.who_am_i()).unwrap_or(Variant::Mpu6500);
    let (gyro_table, accel_table): (&[Row], &[Row]) = match model {
        ChipModel::Mpu6000 => (&tables::MPU6000_GYRO, &tables::MPU6000_ACCEL),
        ChipModel::Icm20602 => (&tables::ICM20602_GYRO, &tables::ICM20602_ACCEL),
        _ => (&tables::MPU6500_GYRO, &tables::MPU6500_ACCEL),
    };
    let not_for = |field, value, allowed| ChainError::NotForModel {
        field,
        value,
        model,
        allowed,
    };
    let (gyro_code, accel_code) = if model == ChipModel::Mpu6000 {
        let one_dlpf = "0: the MPU-6000 has one DLPF, DLPF_CFG, for both sensors";
        match (fchoice_b, a_dlpf, accel_fchoice_b, dlpf) {
            (1.., ..) => {
                return Err(not_for(
                    "fchoice_b",
                    fchoice_b,
                    "0: the MPU-6000 has no FCHOICE_B",
                ))
            }
            (_, 1.., ..) => return Err(not_for("a_dlpf_cfg", a_dlpf, one_dlpf)),
            (_, _, true, _) => return Err(not_for("accel_fchoice_b", 1, one_dlpf)),
            (.., 7) => return Err(not_for("dlpf_cfg", 7, "0-6: 7 is reserved on the MPU-6000")),
            _ => (dlpf, dlpf),
        }
    } else {
        let gyro = match fchoice_b {
            1 | 3 => 8,
            2 => 9,
            _ => dlpf,
        };
        (gyro, if accel_fchoice_b { 8 } else { a_dlpf })
    };
    let config2 = a_dlpf
        | if accel_fchoice_b {
            rates::ACCEL_FCHOICE_B
        } else {
            0
        };
    let gyro_ns = rates::gyro_period_ns(variant, dlpf, fchoice_b);
    let accel_ns = rates::accel_period_ns(variant, config2);
    let row = |table: &[Row], code| {
        find(table, code)
            .copied()
            .ok_or(out_of_range("dlpf_cfg", code, "0-7"))
    };
    // The DLPF filters the ADC's samples before the register rate drops to 1 kHz: the gyro's at
    // 8 kHz, the accelerometer's at 4 kHz (the rate ACCEL_FCHOICE_B exposes). The MPU-6000's
    // accelerometer ADC rate is not documented; it stays at its 1 kHz output.
    let gyro_filter_ns = gyro_ns.min(125_000);
    let accel_filter_ns = match model {
        ChipModel::Mpu6000 => accel_ns,
        _ => accel_ns.min(250_000),
    };
    let gyro = row_chain(&row(gyro_table, gyro_code)?, gyro_filter_ns)?;
    let accel = row_chain(&row(accel_table, accel_code)?, accel_filter_ns)?;
    let divides =
        (0..=255u8).any(|div| rates::sample_period_ns(variant, dlpf, fchoice_b, div) == out_ns);
    if !divides {
        let (field, value) = if fchoice_b != 0 {
            ("fchoice_b", fchoice_b)
        } else {
            ("dlpf_cfg", dlpf)
        };
        let allowed = match (model, gyro_ns) {
            (_, 31_250) => "FCHOICE_B gives 32 kHz only",
            (ChipModel::Mpu6000, _) => {
                "the gyro rate (8 kHz at DLPF_CFG 0, else 1 kHz) / (1 + SMPLRT_DIV)"
            }
            (_, 125_000) => "DLPF_CFG 0 and 7 give 8 kHz only: SMPLRT_DIV divides only at 1 kHz",
            _ => "1 kHz / (1 + SMPLRT_DIV)",
        };
        return Err(ChainError::OutputRate {
            rate_hz: hz,
            field,
            value,
            allowed,
        });
    }
    Ok(ChipChain {
        accel,
        gyro,
        output_period_ns: out_ns,
    })
}
