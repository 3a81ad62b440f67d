//! The user guide (`docs/`, an mdBook) and the README are checked like code:
//!
//! - **Links.** Every relative link `[text](target)` outside code resolves: the file exists, and
//!   a `#anchor` names a heading of the target page under mdBook's rule (the heading's text,
//!   trimmed and lowercased; alphanumerics, `_` and `-` kept, whitespace turned into `-`, anything
//!   else dropped; a repeated id gets `-1`, `-2`, …). Links with a scheme (`https:`) are not
//!   followed.
//! - **The table of contents.** Every page under `docs/` is a chapter of `SUMMARY.md` (`mdbook
//!   build` itself catches a chapter that is listed but missing).
//! - **Scene examples.** A ```` ```toml ```` block is a scene example when it has a top-level
//!   `duration` key (a whole scene), or when its first table header is a scene table (`[chip]`,
//!   `[bench]`, `[joints.…]`, …: a fragment, parsed after `duration`, `rate` and `seed` lines).
//!   Other TOML blocks (a `meta.toml` table, a filter parameters file) are not scenes. Each
//!   scene example must parse and validate with [`Scene::parse_str`].
//! - **Command examples.** In ```` ```sh ```` and ```` ```text ```` blocks, every `margemu WORD`
//!   and `cargo run --release -- WORD` names a subcommand of the real binary (`margemu WORD
//!   --help` succeeds), and a subcommand of a command group (`margemu bench stream`) too.

use std::collections::{BTreeMap, BTreeSet, HashSet};
use std::path::{Component, Path, PathBuf};
use std::process::Command;

use margemu::scene::Scene;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

/// Every Markdown page of the guide, then the README, as (path, text).
fn pages() -> Vec<(PathBuf, String)> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(&path, out);
            } else if path.extension().is_some_and(|e| e == "md") {
                out.push(path);
            }
        }
    }
    let mut paths = Vec::new();
    walk(&root().join("docs"), &mut paths);
    paths.sort();
    paths.push(root().join("README.md"));
    paths
        .into_iter()
        .map(|p| {
            let text = std::fs::read_to_string(&p).unwrap();
            (p, text)
        })
        .collect()
}

/// A fenced code block: its info string (`toml`, `sh`, …), first line number and text.
struct Block {
    lang: String,
    line: usize,
    text: String,
}

/// Splits a page into its prose lines (with line numbers; code fences removed) and its fenced
/// code blocks.
fn split(text: &str) -> (Vec<(usize, &str)>, Vec<Block>) {
    let mut prose = Vec::new();
    let mut blocks = Vec::new();
    let mut open: Option<Block> = None;
    for (i, line) in text.lines().enumerate() {
        let trimmed = line.trim_start();
        match (&mut open, trimmed.strip_prefix("```")) {
            (None, Some(info)) => {
                open = Some(Block {
                    lang: info.trim().to_string(),
                    line: i + 1,
                    text: String::new(),
                })
            }
            (Some(_), Some(_)) => blocks.push(open.take().unwrap()),
            (Some(block), None) => {
                block.text.push_str(line);
                block.text.push('\n');
            }
            (None, None) => prose.push((i + 1, line)),
        }
    }
    assert!(open.is_none(), "an unclosed code fence");
    (prose, blocks)
}

/// The line with its inline code spans removed (links inside backticks are not links).
fn without_code_spans(line: &str) -> String {
    let mut out = String::new();
    for (i, part) in line.split('`').enumerate() {
        if i % 2 == 0 {
            out.push_str(part);
        }
    }
    out
}

/// The targets of the inline links `[text](target)` on a line.
fn link_targets(line: &str) -> Vec<String> {
    let line = without_code_spans(line);
    let mut targets = Vec::new();
    let mut rest = line.as_str();
    while let Some(at) = rest.find("](") {
        let after = &rest[at + 2..];
        let end = after.find(')').unwrap_or(after.len());
        targets.push(after[..end].trim().to_string());
        rest = &after[end..];
    }
    targets
}

/// mdBook's id of a heading's text (`mdbook-html`'s `id_from_content`), markup removed first.
fn heading_id(heading: &str) -> String {
    let text: String = heading
        .chars()
        .filter(|c| !matches!(c, '`' | '*'))
        .collect();
    text.trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| {
            if c.is_alphanumeric() || c == '_' || c == '-' {
                Some(c)
            } else if c.is_whitespace() {
                Some('-')
            } else {
                None
            }
        })
        .collect()
}

/// The ids mdBook gives a page's headings, repeated ones numbered as mdBook numbers them.
fn anchors(text: &str) -> HashSet<String> {
    let (prose, _) = split(text);
    let mut used = HashSet::new();
    for (_, line) in prose {
        let hashes = line.chars().take_while(|&c| c == '#').count();
        if (1..=6).contains(&hashes) && line[hashes..].starts_with(' ') {
            let id = heading_id(&line[hashes..]);
            let mut unique = id.clone();
            let mut n = 1;
            while !used.insert(unique.clone()) {
                unique = format!("{id}-{n}");
                n += 1;
            }
        }
    }
    used
}

/// `path` with `.` and `..` resolved lexically.
fn normalise(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for part in path.components() {
        match part {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            other => out.push(other),
        }
    }
    out
}

/// The broken links of one page, each as `file:line: target: cause`.
fn broken_links(page: &Path, text: &str) -> Vec<String> {
    let (prose, _) = split(text);
    let mut broken = Vec::new();
    for (number, line) in prose {
        for target in link_targets(line) {
            if target.is_empty() || target.contains("://") || target.starts_with("mailto:") {
                continue;
            }
            let (file, anchor) = match target.split_once('#') {
                Some((file, anchor)) => (file, Some(anchor)),
                None => (target.as_str(), None),
            };
            let resolved = if file.is_empty() {
                page.to_path_buf()
            } else {
                normalise(&page.parent().unwrap().join(file))
            };
            let place = format!("{}:{number}: {target}", page.display());
            if !resolved.exists() {
                broken.push(format!("{place}: no such file"));
                continue;
            }
            let Some(anchor) = anchor else { continue };
            let target_text = if file.is_empty() {
                text.to_string()
            } else {
                std::fs::read_to_string(&resolved).unwrap_or_default()
            };
            if resolved.extension().is_none_or(|e| e != "md") {
                broken.push(format!("{place}: an anchor into a file that is not a page"));
            } else if !anchors(&target_text).contains(anchor) {
                broken.push(format!("{place}: no heading with that id"));
            }
        }
    }
    broken
}

#[test]
fn every_relative_link_and_anchor_resolves() {
    let mut broken = Vec::new();
    let mut links = 0;
    for (page, text) in pages() {
        links += split(&text)
            .0
            .iter()
            .map(|(_, line)| link_targets(line).len())
            .sum::<usize>();
        broken.extend(broken_links(&page, &text));
    }
    assert!(
        links > 100,
        "only {links} links found: is the scanner broken?"
    );
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}

#[test]
fn the_link_checker_catches_a_missing_file_and_a_missing_anchor() {
    let page = root().join("docs/introduction.md");
    let text = "# Title\n\nSee [a](chips.md), [b](missing.md), [c](chips.md#no-such-heading), \
                [d](#title), [e](#nope), `[f](not-a-link.md)`.\n\n```text\n[g](in-code.md)\n```\n";
    let broken = broken_links(&page, text);
    assert_eq!(broken.len(), 3, "{broken:#?}");
    assert!(
        broken[0].contains("missing.md: no such file"),
        "{broken:#?}"
    );
    assert!(
        broken[1].contains("chips.md#no-such-heading: no heading"),
        "{broken:#?}"
    );
    assert!(broken[2].contains("#nope: no heading"), "{broken:#?}");
}

#[test]
fn heading_ids_follow_mdbooks_rule() {
    assert_eq!(heading_id(" Scene files"), "scene-files");
    assert_eq!(
        heading_id(" The demo: the case study (Table 3)"),
        "the-demo-the-case-study-table-3"
    );
    assert_eq!(heading_id(" `margemu tune`"), "margemu-tune");
    assert_eq!(heading_id(" Size (measured)"), "size-measured");
    let ids = anchors("# A\n## Tests\n```sh\n# not a heading\n```\n## Tests\n");
    let expected: HashSet<String> = ["a", "tests", "tests-1"].map(String::from).into();
    assert_eq!(ids, expected);
}

#[test]
fn every_page_of_the_guide_is_in_the_summary() {
    let docs = root().join("docs");
    let summary = std::fs::read_to_string(docs.join("SUMMARY.md")).unwrap();
    let listed: BTreeSet<PathBuf> = split(&summary)
        .0
        .iter()
        .flat_map(|(_, line)| link_targets(line))
        .map(|target| docs.join(target))
        .collect();
    let missing: Vec<_> = pages()
        .into_iter()
        .map(|(path, _)| path)
        .filter(|path| path.starts_with(&docs) && !path.ends_with("SUMMARY.md"))
        .filter(|path| !listed.contains(path))
        .collect();
    assert!(missing.is_empty(), "pages not in SUMMARY.md: {missing:?}");
}

/// Tables a scene has at its top level: a TOML block whose first header is one of these is a
/// scene fragment.
const SCENE_TABLES: [&str; 11] = [
    "integrator",
    "field",
    "bench",
    "control",
    "joints",
    "sensors",
    "perturbation",
    "chip",
    "device",
    "vibration",
    "fault",
];

/// A TOML block as scene text, or `None` when it is not a scene example (see the module docs).
fn scene_example(block: &str) -> Option<String> {
    let mut lines = block
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'));
    if block.lines().any(|l| {
        l.strip_prefix("duration")
            .is_some_and(|rest| rest.trim_start().starts_with('='))
    }) {
        return Some(block.to_string());
    }
    let header = lines.next()?.strip_prefix('[')?.trim_start_matches('[');
    let table = header.split(['.', ']']).next()?.trim();
    SCENE_TABLES
        .contains(&table)
        .then(|| format!("duration = 0.1\nrate = 1000.0\nseed = 1\n{block}"))
}

#[test]
fn every_scene_example_in_the_guide_is_a_valid_scene() {
    let mut checked = 0;
    let mut whole = 0;
    for (page, text) in pages() {
        for block in split(&text).1.iter().filter(|b| b.lang == "toml") {
            let Some(scene) = scene_example(&block.text) else {
                continue;
            };
            whole += usize::from(scene == block.text);
            // Blank lines in front put the block's text on its own lines of the page, so an
            // error names the page's line and column (a fragment's added lines just above).
            let added = scene.lines().count() - block.text.lines().count();
            let scene = "\n".repeat(block.line - added) + &scene;
            if let Err(e) = Scene::parse_str(&scene, &page) {
                panic!("a scene example does not parse: {e}");
            }
            checked += 1;
        }
    }
    // The scene file chapter's two whole scenes and the chips chapter's `[chip]` fragment at
    // least: a rule that matched nothing would make this test pass vacuously.
    assert!(
        whole >= 2 && checked >= 3,
        "{whole} whole, {checked} in all"
    );
}

#[test]
fn scene_examples_are_told_from_other_toml() {
    assert!(scene_example("duration = 1.0\nrate = 10.0\nseed = 1\n").is_some());
    assert!(scene_example("# a comment\n[joints.x]\ntype = \"constant\"\n").is_some());
    assert!(scene_example("[completion]\nstatus = \"complete\"\n").is_none());
    assert!(scene_example("[ecf]\nkp = 1.0\n").is_none());
    let broken = scene_example("[bench]\nplate_mass = -0.2\n").unwrap();
    assert!(Scene::parse_str(&broken, Path::new("example")).is_err());
}

/// The subcommand words after `margemu ` or `cargo run --release -- ` in a command example.
fn commands_named(block: &str) -> BTreeSet<Vec<String>> {
    let mut found = BTreeSet::new();
    for line in block.lines() {
        for prefix in ["margemu ", "cargo run --release -- "] {
            let mut rest = line;
            while let Some(at) = rest.find(prefix) {
                let before = rest[..at].chars().last();
                rest = &rest[at + prefix.len()..];
                if before.is_some_and(|c| c.is_alphanumeric() || c == '-' || c == '_') {
                    continue;
                }
                let words: Vec<String> = rest
                    .split_whitespace()
                    .take(2)
                    .take_while(|w| {
                        w.chars().all(|c| c.is_ascii_lowercase() || c == '-')
                            && w.chars().next().is_some_and(|c| c.is_ascii_lowercase())
                    })
                    .map(String::from)
                    .collect();
                if !words.is_empty() {
                    found.insert(words);
                }
            }
        }
    }
    found
}

fn help(args: &[&str]) -> Result<String, String> {
    let out = Command::new(env!("CARGO_BIN_EXE_margemu"))
        .args(args)
        .arg("--help")
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    if out.status.success() {
        Ok(text)
    } else {
        Err(String::from_utf8_lossy(&out.stderr).into_owned())
    }
}

#[test]
fn every_command_in_the_examples_exists() {
    // Where each command word first appears.
    let mut named: BTreeMap<Vec<String>, String> = BTreeMap::new();
    for (page, text) in pages() {
        for block in split(&text).1 {
            if block.lang == "sh" || block.lang == "text" {
                for words in commands_named(&block.text) {
                    named
                        .entry(words)
                        .or_insert_with(|| format!("{}:{}", page.display(), block.line));
                }
            }
        }
    }
    let firsts: BTreeSet<&str> = named.keys().map(|w| w[0].as_str()).collect();
    assert!(firsts.len() >= 10, "only {firsts:?} found");
    let mut missing = Vec::new();
    for first in &firsts {
        let place = &named.iter().find(|(w, _)| w[0] == *first).unwrap().1;
        match help(&[first]) {
            Err(e) => missing.push(format!("{place}: margemu {first}: {e}")),
            // A command group: the word after it must be one of its subcommands.
            Ok(text) if text.contains("<COMMAND>") => {
                for (words, place) in named.iter().filter(|(w, _)| w[0] == *first) {
                    let Some(second) = words.get(1) else { continue };
                    if let Err(e) = help(&[first, second]) {
                        missing.push(format!("{place}: margemu {first} {second}: {e}"));
                    }
                }
            }
            Ok(_) => {}
        }
    }
    assert!(missing.is_empty(), "{}", missing.join("\n"));
}

#[test]
fn command_words_are_found_after_either_prefix() {
    let found = commands_named(
        "cargo run --release -- demo  # x\n$ margemu bench stream --rates 1\nnot_margemu fake\n",
    );
    let expected: BTreeSet<Vec<String>> = [vec!["demo"], vec!["bench", "stream"]]
        .into_iter()
        .map(|w| w.into_iter().map(String::from).collect())
        .collect();
    assert_eq!(found, expected);
}
