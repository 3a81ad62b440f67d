//! The analogue of the paper's Table 3: `F` (eq. 27), MSE and STD per Euler angle of each filter,
//! initial and tuned, with the paper's figures beside ours, plus the geodesic RMS (which the
//! paper does not give), as terminal text or Markdown.

use super::{DemoRun, Variant};
use margemu_eval::evaluate::Scores;
use margemu_sim::filter_params::FilterKind;

/// One row of the paper's Table 3 per filter: `[initial, tuned]`.
struct PaperRow {
    name: &'static str,
    value: fn(&Scores) -> f64,
    /// ECF, GDA, EKF.
    paper: [[f64; 2]; 3],
}

const ROWS: [PaperRow; 7] = [
    PaperRow {
        name: "F (rad²)",
        value: |s| s.f,
        paper: [[0.5237, 0.1471], [1.1950, 0.1812], [0.2891, 0.1033]],
    },
    PaperRow {
        name: "MSE (φ) (rad²)",
        value: |s| s.angles[0].mse,
        paper: [[0.4405, 0.1831], [1.2361, 0.2349], [0.2351, 0.0856]],
    },
    PaperRow {
        name: "STD (φ) (rad)",
        value: |s| s.angles[0].std,
        paper: [[0.6307, 0.4275], [0.9103, 0.4835], [0.4848, 0.2881]],
    },
    PaperRow {
        name: "MSE (θ) (rad²)",
        value: |s| s.angles[1].mse,
        paper: [[0.3713, 0.0773], [0.5610, 0.0977], [0.1068, 0.0676]],
    },
    PaperRow {
        name: "STD (θ) (rad)",
        value: |s| s.angles[1].std,
        paper: [[0.5996, 0.2756], [0.7410, 0.3069], [0.3184, 0.2593]],
    },
    PaperRow {
        name: "MSE (ψ) (rad²)",
        value: |s| s.angles[2].mse,
        paper: [[0.8784, 0.2248], [2.4607, 0.2589], [0.9618, 0.1906]],
    },
    PaperRow {
        name: "STD (ψ) (rad)",
        value: |s| s.angles[2].std,
        paper: [[0.6384, 0.4476], [1.0554, 0.4871], [0.9774, 0.4115]],
    },
];

/// The paper's value of a row for a filter and variant.
fn paper(row: &PaperRow, kind: FilterKind, variant: Variant) -> f64 {
    let k = match kind {
        FilterKind::Ecf => 0,
        FilterKind::Gda => 1,
        FilterKind::Ekf => 2,
    };
    row.paper[k][usize::from(variant == Variant::Tuned)]
}

/// The table's file in the demo's directory.
pub const FILE: &str = "table3.md";

/// The table: one column per run, each cell `ours (paper)`; `markdown` for `table3.md`.
pub fn render(runs: &[DemoRun], markdown: bool) -> String {
    let header: Vec<String> = runs
        .iter()
        .map(|r| format!("{} {}", r.kind.name().to_uppercase(), r.variant.name()))
        .collect();
    let mut rows: Vec<(String, Vec<String>)> = ROWS
        .iter()
        .map(|row| {
            let cells = runs
                .iter()
                .map(|r| {
                    format!(
                        "{:.4} ({:.4})",
                        (row.value)(&r.scores),
                        paper(row, r.kind, r.variant)
                    )
                })
                .collect();
            (row.name.to_string(), cells)
        })
        .collect();
    rows.push((
        "geodesic RMS (rad)".into(),
        runs.iter()
            .map(|r| format!("{:.4} (–)", r.scores.geodesic_rms))
            .collect(),
    ));
    rows.push((
        "N".into(),
        runs.iter().map(|r| r.scores.count.to_string()).collect(),
    ));
    let mut out = String::new();
    if markdown {
        out.push_str(&format!("| | {} |\n", header.join(" | ")));
        out.push_str(&format!("|---|{}\n", "---|".repeat(header.len())));
        for (name, cells) in rows {
            out.push_str(&format!("| {name} | {} |\n", cells.join(" | ")));
        }
    } else {
        out.push_str(&format!("{:<20}", ""));
        for h in &header {
            out.push_str(&format!("{h:>19}"));
        }
        out.push('\n');
        for (name, cells) in rows {
            out.push_str(&format!("{name:<20}"));
            for c in cells {
                out.push_str(&format!("{c:>19}"));
            }
            out.push('\n');
        }
    }
    out
}

/// The filters of `variant` ordered by `F`, best first, beside the paper's order: `EKF < ECF
/// < GDA (paper: EKF < ECF < GDA)`; `None` with fewer than two.
pub fn ordering(runs: &[DemoRun], variant: Variant) -> Option<String> {
    let mut ours: Vec<&DemoRun> = runs.iter().filter(|r| r.variant == variant).collect();
    if ours.len() < 2 {
        return None;
    }
    ours.sort_by(|a, b| a.scores.f.total_cmp(&b.scores.f));
    let mut theirs: Vec<FilterKind> = ours.iter().map(|r| r.kind).collect();
    theirs.sort_by(|a, b| paper(&ROWS[0], *a, variant).total_cmp(&paper(&ROWS[0], *b, variant)));
    let names = |k: &mut dyn Iterator<Item = FilterKind>| {
        k.map(|k| k.name().to_uppercase())
            .collect::<Vec<_>>()
            .join(" < ")
    };
    let same = ours.iter().map(|r| r.kind).eq(theirs.iter().copied());
    Some(format!(
        "{} by F: {} (paper: {}){}",
        variant.name(),
        names(&mut ours.iter().map(|r| r.kind)),
        names(&mut theirs.into_iter()),
        if same {
            ", the same order"
        } else {
            ", a different order"
        }
    ))
}
