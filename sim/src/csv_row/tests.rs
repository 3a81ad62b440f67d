//! [`RowBuf`] against the writer it replaced, kept here as the oracle: `write!` for the time
//! stamp, `ryu` for every float.

use super::*;
use proptest::prelude::*;
use std::fmt::Write as _;

/// The rows as margemu wrote them before [`RowBuf`]: the oracle.
fn ryu_row<F: ryu::Float>(t_ns: u64, values: &[F]) -> Vec<u8> {
    let mut out = String::new();
    let mut float = ryu::Buffer::new();
    write!(out, "{t_ns}").unwrap();
    for v in values {
        out.push(',');
        out.push_str(float.format(*v));
    }
    out.push('\n');
    out.into_bytes()
}

/// [`RowBuf::format`]'s row, owned.
fn row_of<F: CsvFloat>(t_ns: u64, values: &[F]) -> Vec<u8> {
    RowBuf::default()
        .format(t_ns, values.iter().copied())
        .to_vec()
}

fn assert_as_ryu_f64(values: &[f64]) {
    let mut row = RowBuf::default();
    for (i, v) in values.iter().enumerate() {
        let t = i as u64 * 1_000_003;
        let got = row.format(t, [*v]).to_vec();
        let want = ryu_row(t, &[*v]);
        assert_eq!(
            String::from_utf8(got).unwrap(),
            String::from_utf8(want).unwrap(),
            "{v:e} ({:#x})",
            v.to_bits()
        );
    }
}

fn assert_as_ryu_f32(values: &[f32]) {
    let mut row = RowBuf::default();
    for v in values {
        let got = row.format(u64::MAX, [*v]).to_vec();
        let want = ryu_row(u64::MAX, &[*v]);
        assert_eq!(
            String::from_utf8(got).unwrap(),
            String::from_utf8(want).unwrap(),
            "{v:e} ({:#x})",
            v.to_bits()
        );
    }
}

/// Each value, its neighbours one ulp away, and their negations.
fn with_neighbours_f64(values: &[f64]) -> Vec<f64> {
    let mut out = Vec::new();
    for &v in values {
        let bits = v.to_bits();
        for b in [bits.wrapping_sub(1), bits, bits.wrapping_add(1)] {
            out.push(f64::from_bits(b));
            out.push(-f64::from_bits(b));
        }
    }
    out
}

fn with_neighbours_f32(values: &[f32]) -> Vec<f32> {
    let mut out = Vec::new();
    for &v in values {
        let bits = v.to_bits();
        for b in [bits.wrapping_sub(1), bits, bits.wrapping_add(1)] {
            out.push(f32::from_bits(b));
            out.push(-f32::from_bits(b));
        }
    }
    out
}

#[test]
fn awkward_f64_values_are_spelled_as_ryu_spells_them() {
    let mut values = vec![
        0.0,
        1.0,
        0.1,
        0.1 + 0.2,
        1.0 / 3.0,
        9.80665,
        f64::MIN_POSITIVE,
        5e-324,
        2.225073858507201e-308,
        1e-300,
        1e300,
        f64::MAX,
        f64::EPSILON,
        core::f64::consts::PI,
        123456.0,
        9007199254740992.0,
        9007199254740994.0,
        1e15,
        9.999999999999998e15,
        1e16,
        1.2345e16,
        1e17,
        1e21,
        1e22,
        1e23,
        1e-4,
        1e-5,
        9.999999999999999e-6,
        1e-6,
        1e-7,
        1.5e-7,
        5e-5,
        0.5,
        2.5,
        1e7,
        9999999.999999998,
    ];
    values.extend((-30..=30).map(|e| 10f64.powi(e)));
    values.extend((0..64).map(|s| (1u64 << s) as f64));
    assert_as_ryu_f64(&with_neighbours_f64(&values));
    assert_as_ryu_f64(&[f64::NAN, -f64::NAN, f64::INFINITY, f64::NEG_INFINITY]);
}

#[test]
fn awkward_f32_values_are_spelled_as_ryu_spells_them() {
    let mut values = vec![
        0.0f32,
        1.0,
        0.1,
        9.80665,
        f32::MIN_POSITIVE,
        1e-45,
        1e-40,
        1e-38,
        f32::MAX,
        f32::EPSILON,
        16777216.0,
        16777218.0,
        1e7,
        1e8,
        1e9,
        1e10,
        1e12,
        1e13,
        1e-4,
        1e-5,
        1e-6,
        1e-7,
        0.5,
        2.5,
        1e30,
    ];
    values.extend((-30..=30).map(|e| 10f32.powi(e)));
    values.extend((0..32).map(|s| (1u32 << s) as f32));
    assert_as_ryu_f32(&with_neighbours_f32(&values));
    assert_as_ryu_f32(&[f32::NAN, -f32::NAN, f32::INFINITY, f32::NEG_INFINITY]);
}

#[test]
fn time_stamps_are_plain_integers() {
    let mut row = RowBuf::default();
    for t in [0, 1, 9, 10, 999_999_999, 1_000_000_000, u64::MAX] {
        assert_eq!(row.format(t, [0.0f64]), ryu_row(t, &[0.0f64]).as_slice());
    }
    assert_eq!(row.format::<f32>(42, []), b"42\n");
}

#[test]
fn rows_go_out_whole_and_the_buffer_is_reused() {
    let mut row = RowBuf::default();
    let mut out = Vec::new();
    row.write(&mut out, 1, [1.5f64, -2.0]).unwrap();
    row.write(&mut out, 2, [0.25f32]).unwrap();
    assert_eq!(out, b"1,1.5,-2.0\n2,0.25\n");
    assert_eq!(header(&["t_ns", "x"]), "t_ns,x\n");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4096))]

    /// Any bit pattern: every exponent, subnormals, NaNs with payloads.
    #[test]
    fn any_f64_bits_are_spelled_as_ryu_spells_them(bits in any::<u64>(), t in any::<u64>()) {
        let v = f64::from_bits(bits);
        prop_assert_eq!(row_of(t, &[v]), ryu_row(t, &[v]));
    }

    #[test]
    fn any_f32_bits_are_spelled_as_ryu_spells_them(bits in any::<u32>()) {
        let v = f32::from_bits(bits);
        prop_assert_eq!(row_of(0, &[v]), ryu_row(0, &[v]));
    }

    /// The magnitudes the files hold (random bits rarely land there).
    #[test]
    fn rows_of_ordinary_values_are_as_ryu_wrote_them(
        t in any::<u64>(),
        values in prop::collection::vec(-1e4f64..1e4, 0..40),
        scale in -12i32..12,
    ) {
        let values: Vec<f64> = values.iter().map(|v| v * 10f64.powi(scale)).collect();
        prop_assert_eq!(row_of(t, &values), ryu_row(t, &values));
        let narrow: Vec<f32> = values.iter().map(|&v| v as f32).collect();
        prop_assert_eq!(row_of(t, &narrow), ryu_row(t, &narrow));
    }
}
