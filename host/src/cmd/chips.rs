//! `margemu chips`: every chip model margemu emulates, with what a scene's `[chip]` table may
//! choose (identity, bus, address, full scales, output rates) and what is and is not emulated.

use anyhow::Result;
use margemu::scene::chip::{hexes, ranges};
use margemu_protocol::chip::{ChipModel, ChipSettings};

#[derive(clap::Args)]
pub struct Cmd {
    /// Only this model (`margemu chips icm42688p`).
    model: Option<String>,
}

impl Cmd {
    pub fn run(self) -> Result<()> {
        let models: Vec<ChipModel> = match &self.model {
            None => ChipModel::ALL.to_vec(),
            Some(name) => vec![ChipModel::from_name(name).ok_or_else(|| {
                anyhow::anyhow!(
                    "no chip model {name:?}; margemu emulates {}",
                    margemu::scene::chip::model_names()
                )
            })?],
        };
        for (i, model) in models.into_iter().enumerate() {
            if i > 0 {
                println!();
            }
            print!("{}", describe(model));
        }
        Ok(())
    }
}

fn list(values: impl Iterator<Item = String>) -> String {
    values.collect::<Vec<_>>().join(", ")
}

/// The description `margemu chips` prints for `model`.
pub fn describe(model: ChipModel) -> String {
    let power_on = ChipSettings::power_on(model);
    let mut out = format!(
        "{} ([chip] model = \"{}\")\n",
        model.part_name(),
        model.name()
    );
    let id = format!("{}:", model.identity_register());
    out += &format!("  {id:<14}{}\n", hexes(model.identities()));
    let spi = model.buses().contains(margemu_protocol::link::Buses::SPI);
    out += &match model.second_die_i2c_address(model.i2c_addresses()[0]) {
        Some(_) => {
            let gyro: Vec<u8> = (model.i2c_addresses().iter())
                .filter_map(|&a| model.second_die_i2c_address(a))
                .collect();
            format!(
                "  buses:        SPI on {} chip selects (accel die, then gyro die), I2C at {} \
                 (accel die; gyro die at {} alike)\n",
                model.spi_selects(),
                hexes(model.i2c_addresses()),
                hexes(&gyro)
            )
        }
        None => format!(
            "  buses:        {}I2C at {}\n",
            if spi { "SPI, " } else { "" },
            hexes(model.i2c_addresses())
        ),
    };
    if let Some(fs) = power_on.full_scale() {
        out += &format!(
            "  accel ranges: ± {} g (power-on ±{} g)\n",
            ranges(ChipSettings::accel_ranges_g(model)),
            fs.accel_g
        );
        out += &format!(
            "  gyro ranges:  ± {} °/s (power-on ±{} °/s)\n",
            ranges(ChipSettings::gyro_ranges_dps(model)),
            fs.gyro_dps
        );
        out += &format!("  output rates: {}\n", rates(model));
    }
    let mag_ranges = ChipSettings::mag_ranges_gauss(model);
    if let Some(gauss) = power_on.mag_range_gauss() {
        out += &format!(
            "  mag ranges:   ± {} G (power-on ±{gauss} G)\n",
            ranges(mag_ranges.iter().copied())
        );
    }
    let magnetometer = match model {
        ChipModel::Mpu9250 => "AK8963 behind the auxiliary I2C master or in bypass at 0x0c",
        _ if model.is_magnetometer_only() => {
            "the chip itself, measuring on its own schedule (any scene rate)"
        }
        _ => "none",
    };
    out += &format!("  magnetometer: {magnetometer}\n");
    out += &format!(
        "  image:        {} bytes per sample on the link\n",
        model.image_len()
    );
    out += "  emulated:\n";
    for item in model.emulated() {
        out += &format!("    - {item}\n");
    }
    out += "  not emulated:\n";
    for item in model.not_emulated() {
        out += &format!("    - {item}\n");
    }
    out
}

/// The output rates of `model` in words.
fn rates(model: ChipModel) -> String {
    let candidates: &[f64] = match model {
        // The gyro ODRs, 100 Hz · 2^n.
        ChipModel::Bmi270 => &[3_200.0, 1_600.0, 800.0, 400.0, 200.0, 100.0, 50.0, 25.0],
        // The gyro ODRs of GYRO_BANDWIDTH.
        ChipModel::Bmi088 => &[2_000.0, 1_000.0, 400.0, 200.0, 100.0],
        _ => &[
            32_000.0, 16_000.0, 8_000.0, 4_000.0, 2_000.0, 1_000.0, 500.0, 200.0, 100.0, 50.0,
            25.0, 12.5,
        ],
    };
    let listed = list(
        candidates
            .iter()
            .filter(|r| model.has_output_rate(**r))
            .map(|r| format!("{r} Hz")),
    );
    match model {
        ChipModel::Mpu6000 => format!("{listed}, … (8 kHz or 1 kHz / (1 + SMPLRT_DIV))"),
        ChipModel::Icm42688p => listed,
        ChipModel::Bmi270 | ChipModel::Bmi088 => {
            format!("{listed} (the gyro's ODR; the accelerometer at its own, at most 1.6 kHz)")
        }
        _ => format!("{listed}, … (32 kHz, 8 kHz, or 1 kHz / (1 + SMPLRT_DIV))"),
    }
}
