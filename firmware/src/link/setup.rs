//! Applying a [`Configure`]: the chip variant, its register overrides, and the model of source
//! mode (b).

use margemu_model::sensor::{Marg, Truth};
use margemu_protocol::link::{
    Chips, Configure, ErrorCode, ModelParams, Rate, RegisterFile, RegisterOverride, Source,
};
use margemu_protocol::regmap::mpu6xxx::convert::TEMP_OFFSET_C;
use margemu_protocol::regmap::mpu6xxx::image::{ImageRepr, IMAGE_LEN};

use crate::chip::{Config, I2cTarget, Mpu6xxx, SpiTarget, Variant};

/// The chips this device emulates.
pub const CHIPS: Chips =
    Chips(Chips::MPU9250.0 | Chips::MPU9255.0 | Chips::MPU6500.0 | Chips::WHO_AM_I_68.0);

/// The chip variant of a WHO_AM_I value.
pub fn variant(who_am_i: u8) -> Option<Variant> {
    [
        Variant::Mpu9250,
        Variant::Mpu9255,
        Variant::Mpu6500,
        Variant::WhoAmI68,
    ]
    .into_iter()
    .find(|v| v.who_am_i() == who_am_i)
}

const INT_PIN_CFG: u8 = 0x37;
const USER_CTRL: u8 = 0x6A;
const BYPASS_EN: u8 = 0x02;
const I2C_MST_EN: u8 = 0x20;
const AK8963_ADDRESS: u8 = 0x0C;

fn spi_write(chip: &mut Mpu6xxx, register: u8, value: u8) {
    chip.select();
    chip.exchange(register & 0x7F);
    chip.exchange(value);
    chip.deselect();
}

/// Applies one override through the chip's own bus targets (SPI for the MPU-9250; the AK8963
/// through I2C bypass, INT_PIN_CFG and USER_CTRL restored afterwards). The writes land in the
/// write log; the caller empties it.
fn apply_override(chip: &mut Mpu6xxx, o: &RegisterOverride) {
    match o.file {
        RegisterFile::Mpu9250 => spi_write(chip, o.register, o.value),
        RegisterFile::Ak8963 => {
            let (pin_cfg, user_ctrl) = (chip.peek(INT_PIN_CFG), chip.peek(USER_CTRL));
            spi_write(chip, INT_PIN_CFG, pin_cfg | BYPASS_EN);
            spi_write(chip, USER_CTRL, user_ctrl & !I2C_MST_EN);
            if chip.start(AK8963_ADDRESS, false) {
                chip.write(o.register);
                chip.write(o.value);
            }
            chip.stop();
            spi_write(chip, USER_CTRL, user_ctrl & !I2C_MST_EN);
            spi_write(chip, INT_PIN_CFG, pin_cfg);
            // Restoring I2C_MST_EN last: it may start the auxiliary master.
            if user_ctrl & I2C_MST_EN != 0 {
                spi_write(chip, USER_CTRL, user_ctrl);
            }
        }
    }
}

/// A fresh chip of `cfg`'s variant with its overrides applied and its write log emptied.
pub fn build_chip(cfg: &Configure) -> Result<Mpu6xxx, ErrorCode> {
    let variant = variant(cfg.who_am_i).ok_or(ErrorCode::UnsupportedChip)?;
    let mut chip = Mpu6xxx::with_config(Config {
        variant,
        ..Config::default()
    });
    for o in &cfg.overrides {
        apply_override(&mut chip, o);
    }
    while chip.pop_write().is_some() {}
    Ok(chip)
}

/// Source mode (b): the shared sensor model at the output rate, fed by the latest kinematics.
#[derive(Clone, Debug)]
pub struct Model {
    marg: Marg,
    truth_rate: Rate,
    mag_ut_per_unit: f64,
    held: Option<Truth>,
}

impl Model {
    /// The model of `params` at the output `rate`; `None` if the model refuses the terms.
    /// A perturbation is refused by the caller (it needs buffers this device does not have).
    pub fn new(params: &ModelParams, rate: Rate) -> Option<Self> {
        let marg = Marg::new(&params.marg, rate.as_hz_f64(), params.seed).ok()?;
        Some(Self {
            marg,
            truth_rate: params.truth_rate,
            mag_ut_per_unit: params.mag_ut_per_unit,
            held: None,
        })
    }

    /// The kinematics index in effect at scene time `t_ns`: the latest `j` with
    /// `truth_rate.sample_time_ns(j) ≤ t_ns`.
    pub fn truth_index_at(&self, t_ns: u64) -> u64 {
        truth_index_at(self.truth_rate, t_ns)
    }

    /// Holds `truth` as the latest kinematics sample.
    pub fn hold(&mut self, truth: Truth) {
        self.held = Some(truth);
    }

    /// Whether a kinematics sample has been held yet.
    pub fn has_truth(&self) -> bool {
        self.held.is_some()
    }

    /// One output sample from the held kinematics, as the register image the chip serves
    /// (`None` before the first kinematics sample: the model does not step).
    pub fn image(&mut self, chip: &Mpu6xxx) -> Option<[u8; IMAGE_LEN]> {
        let truth = self.held?;
        Some(model_image(
            &mut self.marg,
            &truth,
            self.mag_ut_per_unit,
            chip,
        ))
    }
}

/// The kinematics index in effect at scene time `t_ns` for kinematics at `rate`: the largest `j`
/// with `floor(j·den·10⁹/num) ≤ t_ns`, i.e. `floor(((t_ns+1)·num − 1) / (den·10⁹))`.
pub fn truth_index_at(rate: Rate, t_ns: u64) -> u64 {
    let num = u128::from(rate.num());
    let den = u128::from(rate.den()) * 1_000_000_000;
    let j = ((u128::from(t_ns) + 1) * num - 1) / den;
    u64::try_from(j).unwrap_or(u64::MAX)
}

/// The image of one model step, exactly as the device computes it in source mode (b), so a
/// host can predict it: the model's sample, the field scaled to µT as
/// `(f64::from(mag) * mag_ut_per_unit) as f32`, the temperature of the kinematics (21 °C, TEMP_OUT
/// 0, when absent), converted with the chip's current [`Mpu6xxx::image_config`].
pub fn model_image(
    marg: &mut Marg,
    truth: &Truth,
    mag_ut_per_unit: f64,
    chip: &Mpu6xxx,
) -> [u8; IMAGE_LEN] {
    let s = marg.sample(truth);
    let mag = s.mag.map(|m| (f64::from(m) * mag_ut_per_unit) as f32);
    let temp = truth.temperature_c.unwrap_or(TEMP_OFFSET_C);
    ImageRepr::from_physical(s.acc, s.gyr, temp, mag, &chip.image_config()).emit()
}

/// Whether the device can serve `source` (no perturbation in mode (b) yet).
pub fn source_supported(source: &Source) -> bool {
    match source {
        Source::Images => true,
        Source::Model(p) => p.perturbation.is_none(),
    }
}
