//! Reading [`SensorTable`] (and the terms with fields of their own) with serde, under the
//! `serde` feature: one table per sensor, keyed by the field names of [`SensorErrors`] and
//! [`SensorTable`] (`lever_arm` for [`SensorTable::lever_arm_m`]), absent keys off, unknown keys
//! refused with the key's own error so a format that knows positions (TOML) points at it.

use core::fmt;

use serde::de::{self, Deserialize, Deserializer, MapAccess, Visitor};

use super::config::{SensorErrors, SensorTable};

/// Every key of a sensor table, in the order error messages list them.
const KEYS: &[&str] = &[
    "scale_factor",
    "misalignment",
    "bias",
    "noise_density",
    "bias_instability",
    "rate_random_walk",
    "temperature_bias",
    "resolution",
    "range",
    "g_sensitivity",
    "lever_arm",
    "soft_iron",
    "hard_iron",
];

/// A key of [`KEYS`].
struct Key(&'static str);

impl<'de> Deserialize<'de> for Key {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct KeyVisitor;
        impl Visitor<'_> for KeyVisitor {
            type Value = Key;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("field identifier")
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Key, E> {
                KEYS.iter()
                    .find(|k| **k == v)
                    .map(|k| Key(k))
                    .ok_or_else(|| E::unknown_field(v, KEYS))
            }
        }
        d.deserialize_identifier(KeyVisitor)
    }
}

/// Sets `slot` from the map's next value, refusing a second one for the same key.
fn take<'de, A: MapAccess<'de>, T: Deserialize<'de>>(
    map: &mut A,
    slot: &mut Option<T>,
    key: &'static str,
) -> Result<(), A::Error> {
    if slot.is_some() {
        return Err(de::Error::duplicate_field(key));
    }
    *slot = Some(map.next_value()?);
    Ok(())
}

struct TableVisitor;

impl<'de> Visitor<'de> for TableVisitor {
    type Value = SensorTable;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // What the scene's former derived reader said, kept word for word.
        f.write_str("struct SensorSpec")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<SensorTable, A::Error> {
        let mut t = SensorTable::default();
        while let Some(Key(key)) = map.next_key()? {
            let e: &mut SensorErrors = &mut t.errors;
            match key {
                "scale_factor" => take(&mut map, &mut e.scale_factor, key)?,
                "misalignment" => take(&mut map, &mut e.misalignment, key)?,
                "bias" => take(&mut map, &mut e.bias, key)?,
                "noise_density" => take(&mut map, &mut e.noise_density, key)?,
                "bias_instability" => take(&mut map, &mut e.bias_instability, key)?,
                "rate_random_walk" => take(&mut map, &mut e.rate_random_walk, key)?,
                "temperature_bias" => take(&mut map, &mut e.temperature_bias, key)?,
                "resolution" => take(&mut map, &mut e.resolution, key)?,
                "range" => take(&mut map, &mut e.range, key)?,
                "g_sensitivity" => take(&mut map, &mut t.g_sensitivity, key)?,
                "lever_arm" => take(&mut map, &mut t.lever_arm_m, key)?,
                "soft_iron" => take(&mut map, &mut t.soft_iron, key)?,
                "hard_iron" => take(&mut map, &mut t.hard_iron, key)?,
                _ => return Err(de::Error::unknown_field(key, KEYS)),
            }
        }
        Ok(t)
    }
}

impl<'de> Deserialize<'de> for SensorTable {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_struct("SensorSpec", KEYS, TableVisitor)
    }
}
