//! `margemu scenes [NAME]`: the built-in scenes (`margemu::scene::builtin`), one line each with
//! its duration, rate, motion, chip and description; with a name, that scene's text (a starting
//! point for a scene file of one's own).

use anyhow::Result;
use margemu::scene::{builtin, Scene};

#[derive(clap::Args)]
pub struct Cmd {
    /// Print this built-in scene's TOML text instead of the list.
    name: Option<String>,
}

impl Cmd {
    pub fn run(self) -> Result<()> {
        if let Some(name) = &self.name {
            let name = name.strip_prefix(builtin::PREFIX).unwrap_or(name);
            let scene = builtin::load(name)?;
            print!("{}", scene.text);
            return Ok(());
        }
        let scenes = builtin::NAMES
            .iter()
            .map(|name| builtin::load(name))
            .collect::<Result<Vec<_>, _>>()?;
        let rows: Vec<[String; 6]> = scenes.iter().map(row).collect();
        let header =
            ["name", "duration", "rate", "motion", "chip", "description"].map(String::from);
        let mut widths = [0; 5];
        for r in std::iter::once(&header).chain(&rows) {
            for (w, cell) in widths.iter_mut().zip(r) {
                *w = (*w).max(cell.chars().count());
            }
        }
        for r in std::iter::once(&header).chain(&rows) {
            let mut line = String::new();
            for (w, cell) in widths.iter().zip(r) {
                line += &format!("{cell:<w$}  ");
            }
            line += &r[5];
            println!("{line}");
        }
        println!(
            "\nA command takes a built-in scene's name wherever it takes a scene file (a file of \
             that name in the current directory comes first; builtin:NAME never reads one); \
             `margemu scenes NAME` prints its text."
        );
        Ok(())
    }
}

/// Name, duration, rate, motion, chip and description of a built-in scene.
fn row(scene: &Scene) -> [String; 6] {
    [
        scene.stem(),
        format!("{} s", scene.spec.duration),
        format!("{} Hz", scene.clock.hz()),
        scene.spec.motion.name().to_owned(),
        scene.chip.model.name().to_owned(),
        description(scene),
    ]
}

/// The scene's `description`, or else the first line of its leading comment, or else nothing.
fn description(scene: &Scene) -> String {
    if let Some(d) = &scene.spec.description {
        return d.clone();
    }
    scene
        .text
        .lines()
        .next()
        .and_then(|l| l.strip_prefix('#'))
        .map(|l| l.trim().to_owned())
        .unwrap_or_default()
}
