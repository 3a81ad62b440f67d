//! A tuning's results as text: the paper's Table 3 layout (parameters, `F`, MSE and STD per
//! Euler angle, initial against tuned) plus the geodesic RMS, and the tuned parameters as a
//! parameters file for `margemu filter --params`.
//!
//! Every score in the table is the mean over the seeds of that score.

use super::TuneResult;
use std::fmt::Write as _;

/// The table of initial against tuned values.
pub fn table(r: &TuneResult) -> String {
    let mut out = String::new();
    let (a, b) = (&r.initial, &r.tuned);
    let _ = writeln!(
        out,
        "{:<16} {:>12} {:>12}",
        r.kind.name().to_uppercase(),
        "initial",
        "tuned"
    );
    for ((spec, x), (_, y)) in a.params.iter().zip(b.params.iter()) {
        let _ = writeln!(out, "{:<16} {:>12.5e} {:>12.5e}", spec.name, x, y);
    }
    let mut row = |name: &str, of: &dyn Fn(&crate::evaluate::Scores) -> f64| {
        let _ = writeln!(
            out,
            "{:<16} {:>12.4} {:>12.4}",
            name,
            a.mean(of),
            b.mean(of)
        );
    };
    row("F (rad²)", &|s| s.f);
    for (i, angle) in ["φ", "θ", "ψ"].iter().enumerate() {
        row(&format!("MSE ({angle})"), &|s| s.angles[i].mse);
        row(&format!("STD ({angle})"), &|s| s.angles[i].std);
    }
    row("geodesic RMS", &|s| s.geodesic_rms);
    out
}

/// One line on the search: evaluations, distinct candidates, restarts and why it stopped.
pub fn search_line(r: &TuneResult) -> String {
    let s = &r.search;
    format!(
        "{} evaluations ({} distinct, {} filter runs), {} Nelder–Mead run{}; stopped: {}",
        s.evaluations,
        s.distinct,
        s.distinct * r.seeds.len(),
        s.runs,
        if s.runs == 1 { "" } else { "s" },
        s.stop
    )
}

/// `existing` (a parameters file, possibly empty) with the table of `r.kind` replaced by the
/// tuned values, and a comment above it saying where they come from. Other tables and comments
/// are kept. `Err` when `existing` is not TOML.
pub fn params_file(existing: &str, r: &TuneResult) -> Result<String, toml_edit::TomlError> {
    let mut doc: toml_edit::DocumentMut = existing.parse()?;
    let mut table = toml_edit::Table::new();
    for (spec, v) in r.tuned.params.iter() {
        table.insert(spec.name, toml_edit::value(v));
    }
    let seeds = match (r.seeds.first(), r.seeds.last()) {
        (Some(a), Some(b)) if a != b => format!("seeds {a}–{b}"),
        (Some(a), _) => format!("seed {a}"),
        _ => String::new(),
    };
    table.decor_mut().set_prefix(format!(
        "\n# margemu tune {} --filter {}: {seeds}, warm-up {} s, {} {:.6} (initial {:.6})\n",
        r.scene, r.kind, r.warmup_s, r.objective, r.tuned.objective, r.initial.objective
    ));
    doc.insert(r.kind.name(), toml_edit::Item::Table(table));
    Ok(doc.to_string().trim_start().to_owned())
}
