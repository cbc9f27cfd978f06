//! The command examples of README.md and docs/*.md run as written, and the outputs they quote
//! are what the program prints.
//!
//! Every ```sh, ```bash and ```console block with a `tiltnoise ...` or `cargo run --release --
//! ...` line runs under `sh -e` in a fresh directory that holds the repository's committed
//! inputs (`tilt_data/`, `examples/`) and an empty `plots/`, with the built binary first on
//! `PATH` as `tiltnoise` (`cargo run --release --` and `target/release/tiltnoise` are rewritten
//! to it). Lines that only build or test the repository itself (`cargo build`, `cargo test`)
//! are left out; `python3`, `pip` and `cargo` otherwise fail, so that `cargo test` needs no Python.
//!
//! Markers, an HTML comment on the line before a block:
//! - `<!-- docs-run: skip (why) -->`: the block is not run; the reason is printed.
//! - `<!-- docs-run: output `tiltnoise ARGS`[, ignoring columns N,M] (why) -->` before a
//!   ```text block: ARGS are run and every line the block quotes must appear among the
//!   printed lines, word for word except the listed columns (1-based, e.g. timings); a quoted
//!   `...` ends the comparison of its line.
//!
//! A block that reads `../shared/` (the GPL/LGPL record kept out of the repository) runs when
//! that data is beside the repository and is skipped with a printed line otherwise.
//!
//! The figures a block draws into `plots/` are compared with the committed ones
//! (`committed_figures`): a committed figure that differs from what its block draws now, or
//! that no block draws, fails.

use crate::committed_figures;
use crate::common::{disable_hdf5_file_locking, repo};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::Command;

/// One line on standard error past the test harness's capture, so that `cargo test` shows
/// what ran and what was skipped.
fn say(line: &str) {
    use std::io::Write;
    let _ = writeln!(std::io::stderr(), "{line}");
}

/// A fenced block of a Markdown file.
struct Block {
    /// `README.md:27`: the file and the line of the opening fence.
    place: String,
    /// The info string (`sh`, `text`, ...).
    lang: String,
    text: String,
    /// The `docs-run:` marker on the line before the fence, without the comment's brackets.
    marker: Option<String>,
}

/// The Markdown files whose blocks are checked.
fn documents() -> Vec<PathBuf> {
    let mut docs: Vec<PathBuf> = std::fs::read_dir(repo("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    docs.sort();
    docs.insert(0, repo("README.md"));
    docs
}

/// Every fenced block of `path`, with the marker before it.
fn blocks(path: &Path) -> Vec<Block> {
    let name = path.strip_prefix(repo("")).unwrap().display().to_string();
    let text = std::fs::read_to_string(path).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let Some(lang) = lines[i].strip_prefix("```") else {
            i += 1;
            continue;
        };
        let start = i;
        i += 1;
        while i < lines.len() && !lines[i].starts_with("```") {
            i += 1;
        }
        let marker = start
            .checked_sub(1)
            .map(|p| lines[p].trim())
            .and_then(|l| l.strip_prefix("<!-- docs-run:"))
            .and_then(|l| l.strip_suffix("-->"))
            .map(|m| m.trim().to_string());
        out.push(Block {
            place: format!("{name}:{}", start + 1),
            lang: lang.trim().to_string(),
            text: lines[start + 1..i.min(lines.len())].join("\n"),
            marker,
        });
        i += 1;
    }
    out
}

/// The shell script of a command block: console prompts stripped (lines without one are
/// output), the repository's own build and test lines left out, the ways of calling the
/// program written as `tiltnoise`.
fn script(block: &Block) -> String {
    let lines: Vec<&str> = match block.lang.as_str() {
        "console" => block
            .text
            .lines()
            .filter_map(|l| l.strip_prefix("$ "))
            .collect(),
        _ => block.text.lines().collect(),
    };
    lines
        .into_iter()
        .filter(|l| {
            let l = l.trim_start();
            let own_build = l.starts_with("cargo build") || l.starts_with("cargo test");
            !own_build || l.contains("&&") || l.contains(';')
        })
        .map(|l| {
            l.replace("cargo run --release --", "tiltnoise")
                .replace("target/release/tiltnoise", "tiltnoise")
        })
        .collect::<Vec<_>>()
        .join("\n")
}

fn is_command_block(block: &Block) -> bool {
    ["sh", "bash", "console"].contains(&block.lang.as_str())
        && script(block)
            .lines()
            .any(|l| l.split_whitespace().any(|w| w == "tiltnoise"))
}

/// A working directory with the committed inputs, `plots/` and a `bin/` with `tiltnoise` and
/// the failing stand-ins for the tools a block must not need. `../shared` is linked beside it
/// when it is beside the repository.
struct Workspace {
    _root: tempfile::TempDir,
    dir: PathBuf,
    bin: PathBuf,
}

impl Workspace {
    fn new() -> Self {
        let root = tempfile::tempdir().unwrap();
        let dir = root.path().join("repo");
        let bin = root.path().join("bin");
        for d in [&dir, &bin, &dir.join("plots")] {
            std::fs::create_dir_all(d).unwrap();
        }
        for input in ["tilt_data", "examples"] {
            std::os::unix::fs::symlink(repo(input), dir.join(input)).unwrap();
        }
        let shared = repo("../shared");
        if shared.exists() {
            std::os::unix::fs::symlink(shared, root.path().join("shared")).unwrap();
        }
        std::os::unix::fs::symlink(env!("CARGO_BIN_EXE_tiltnoise"), bin.join("tiltnoise")).unwrap();
        for tool in ["cargo", "python", "python3", "pip", "pip3"] {
            let stand_in = bin.join(tool);
            std::fs::write(
                &stand_in,
                format!(
                    "#!/bin/sh\necho \"docs-run: {tool} is not run by cargo test; mark the \
                     block <!-- docs-run: skip (why) -->\" >&2\nexit 97\n"
                ),
            )
            .unwrap();
            use std::os::unix::fs::PermissionsExt;
            std::fs::set_permissions(&stand_in, std::fs::Permissions::from_mode(0o755)).unwrap();
        }
        Workspace {
            dir,
            bin,
            _root: root,
        }
    }

    /// Runs `script` under `sh -e`: standard output, or the failure with what it printed.
    fn run(&self, script: &str) -> Result<String, String> {
        disable_hdf5_file_locking();
        let path = format!(
            "{}:{}",
            self.bin.display(),
            std::env::var("PATH").unwrap_or_default()
        );
        let out = Command::new("sh")
            .args(["-e", "-c", script])
            .current_dir(&self.dir)
            .env("PATH", path)
            .env("HDF5_USE_FILE_LOCKING", "FALSE")
            .output()
            .expect("sh runs");
        let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
        match out.status.success() {
            true => Ok(stdout),
            false => Err(format!(
                "exit {:?}\n--- stdout\n{stdout}\n--- stderr\n{}",
                out.status.code(),
                String::from_utf8_lossy(&out.stderr)
            )),
        }
    }
}

/// The command and ignored columns of an `output` marker.
fn output_marker(marker: &str) -> Option<(String, Vec<usize>)> {
    let rest = marker.strip_prefix("output `")?;
    let (command, rest) = rest.split_once('`')?;
    let ignored = rest
        .trim_start_matches(',')
        .trim()
        .strip_prefix("ignoring column")
        .map(|r| {
            r.trim_start_matches('s')
                .split_whitespace()
                .next()
                .unwrap_or("")
                .split(',')
                .map(|n| n.parse().expect("column numbers"))
                .collect()
        })
        .unwrap_or_default();
    Some((command.to_string(), ignored))
}

/// Whether the printed `line` shows the quoted one: the same words, but in `ignored` columns
/// and after a quoted `...`.
fn shows(line: &str, quoted: &str, ignored: &[usize]) -> bool {
    let got: Vec<&str> = line.split_whitespace().collect();
    let want: Vec<&str> = quoted.split_whitespace().collect();
    let cut = want.iter().position(|w| *w == "...");
    let want = &want[..cut.unwrap_or(want.len())];
    if cut.is_none() && got.len() != want.len() || got.len() < want.len() {
        return false;
    }
    want.iter()
        .zip(&got)
        .enumerate()
        .all(|(k, (w, g))| ignored.contains(&(k + 1)) || w == g)
}

#[test]
fn readme_and_docs_blocks_run_and_quote_what_the_program_prints() {
    let work = Workspace::new();
    let shared_present = repo("../shared/tilt_data").exists();
    let (mut ran, mut skipped, mut checked) = (0, 0, 0);
    let mut failures = Vec::new();
    let committed = committed_figures::committed();
    let mut compared = BTreeSet::new();
    // Committed figures of blocks that did not run here, or ran on data not in the repository.
    let mut not_compared: BTreeMap<String, String> = BTreeMap::new();
    let mut leave = |block: &Block, why: &str| {
        for name in committed_figures::figures_named(&script(block)) {
            not_compared.insert(name, format!("{} ({why})", block.place));
        }
    };
    for doc in documents() {
        for block in blocks(&doc) {
            let marker = block.marker.as_deref().unwrap_or("");
            if let Some((command, ignored)) = output_marker(marker) {
                let printed = match work.run(&command) {
                    Ok(p) => p,
                    Err(e) => {
                        failures.push(format!("{} ({command}): {e}", block.place));
                        continue;
                    }
                };
                for quoted in block.text.lines().filter(|l| !l.trim().is_empty()) {
                    if !printed.lines().any(|l| shows(l, quoted, &ignored)) {
                        failures.push(format!(
                            "{}: `{command}` does not print\n  {quoted}\nit prints:\n{printed}",
                            block.place
                        ));
                    }
                }
                checked += 1;
                continue;
            }
            if !is_command_block(&block) {
                continue;
            }
            if let Some(why) = marker.strip_prefix("skip") {
                say(&format!(
                    "docs-run: skipped {}: {}",
                    block.place,
                    why.trim()
                ));
                leave(&block, "skipped");
                skipped += 1;
                continue;
            }
            let from_shared = block.text.contains("../shared/");
            if from_shared && !shared_present {
                say(&format!(
                    "docs-run: skipped {}: reads ../shared/tilt_data, not beside the repository \
                     (GPL/LGPL data kept out of it; CI has it)",
                    block.place
                ));
                leave(&block, "skipped");
                skipped += 1;
                continue;
            }
            match work.run(&script(&block)) {
                Ok(_) => ran += 1,
                Err(e) => {
                    failures.push(format!("{}: {e}", block.place));
                    continue;
                }
            }
            if from_shared {
                leave(
                    &block,
                    "drawn from ../shared, not from the repository's data",
                );
                continue;
            }
            for name in committed_figures::figures_named(&script(&block)) {
                let Some(committed) = committed.get(&name) else {
                    continue;
                };
                match committed_figures::difference(&work.dir.join("plots").join(&name), committed)
                {
                    Ok(None) => {
                        compared.insert(name);
                    }
                    Ok(Some(why)) => failures.push(format!(
                        "{}: plots/{name} differs from what the block draws now ({why}); run \
                         the block's command and commit the figure it draws",
                        block.place
                    )),
                    Err(e) => failures.push(format!("{}: plots/{name}: {e}", block.place)),
                }
            }
        }
    }
    for name in committed.keys().filter(|n| !compared.contains(*n)) {
        let not_redrawn = committed_figures::NOT_REDRAWN
            .iter()
            .find(|(n, _)| *n == name.as_str())
            .map(|(_, why)| why.to_string());
        match not_compared.get(name).cloned().or(not_redrawn) {
            Some(why) => say(&format!("docs-run: plots/{name} not compared: {why}")),
            None => failures.push(format!(
                "plots/{name} is committed, but no command block of README.md or docs/*.md \
                 draws it (add the command that draws it, or remove the figure)"
            )),
        }
    }
    say(&format!(
        "docs-run: {ran} command blocks ran, {skipped} skipped, {checked} quoted outputs checked, \
         {} committed figures the same as drawn now",
        compared.len()
    ));
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
    assert!(ran > 0 && checked > 0, "no block ran or was checked");
}

#[test]
fn quoted_lines_match_word_for_word_but_in_ignored_columns() {
    let printed = "modal            5.38e2      phi/eta_t    1.0000e-5          249  yes";
    assert!(shows(
        printed,
        "modal 5.38e2 phi/eta_t 1.0000e-5 300 yes",
        &[5]
    ));
    assert!(!shows(
        printed,
        "modal 1.09e2 phi_a/eta_t 1.0000e-5 249 yes",
        &[5]
    ));
    assert!(!shows(
        printed,
        "modal 5.38e2 phi/eta_t 1.0000e-5 300 yes",
        &[]
    ));
    assert!(shows(
        "torsion2  not usable: the model has",
        "torsion2 not usable: ...",
        &[]
    ));
    assert!(
        !shows(printed, "modal 5.38e2", &[]),
        "a quoted line is the whole line"
    );
    assert_eq!(
        output_marker("output `tiltnoise methods`, ignoring columns 5,6 (times vary)"),
        Some(("tiltnoise methods".to_string(), vec![5, 6]))
    );
    assert_eq!(
        output_marker("output `tiltnoise modes` (the table)"),
        Some(("tiltnoise modes".to_string(), vec![]))
    );
}

/// Every schema the program writes, with the version its files carry.
const WRITTEN_SCHEMAS: [(&str, i64); 10] = [
    (tiltnoise_io::SCHEMA_TF, tiltnoise_io::SCHEMA_VERSION_TF),
    (
        tiltnoise_io::SCHEMA_TF_CSV,
        tiltnoise_io::SCHEMA_VERSION_TF_CSV as i64,
    ),
    (
        tiltnoise_io::SCHEMA_BUDGET,
        tiltnoise_io::SCHEMA_VERSION_BUDGET,
    ),
    (
        tiltnoise_io::SCHEMA_BUDGET_CSV,
        tiltnoise_io::SCHEMA_VERSION_BUDGET_CSV as i64,
    ),
    (
        tiltnoise_io::SCHEMA_COHERENCE,
        tiltnoise_io::SCHEMA_VERSION_COHERENCE,
    ),
    (
        tiltnoise_io::SCHEMA_COHERENCE_CSV,
        tiltnoise_io::SCHEMA_VERSION_COHERENCE_CSV as i64,
    ),
    (tiltnoise_io::SCHEMA_FIT, tiltnoise_io::SCHEMA_VERSION_FIT),
    (tiltnoise_io::SCHEMA_MC, tiltnoise_io::SCHEMA_VERSION_MC),
    (
        tiltnoise_io::SCHEMA_OBSERVABLE_SERIES,
        tiltnoise_io::SCHEMA_VERSION_OBSERVABLE_SERIES,
    ),
    (
        tiltnoise_io::SCHEMA_OBSERVABLE_ASD_CSV,
        tiltnoise_io::SCHEMA_VERSION_OBSERVABLE_ASD_CSV as i64,
    ),
];

/// The leading digits of `text`, as a number.
fn leading_number(text: &str) -> Option<i64> {
    let digits: String = text.chars().take_while(char::is_ascii_digit).collect();
    digits.parse().ok()
}

/// The versions a line quotes: `` `tiltnoise.NAME`, version N `` or `` `tiltnoise.NAME`, N ``.
fn quoted_versions(line: &str) -> Vec<(&str, i64)> {
    let mut found = Vec::new();
    for (at, _) in line.match_indices("`tiltnoise.") {
        let rest = &line[at + 1..];
        let Some(end) = rest.find('`') else { continue };
        let (name, after) = (&rest[..end], &rest[end + 1..]);
        let after = after.trim_start_matches([',', ' ']);
        let after = after.strip_prefix("version ").unwrap_or(after);
        if let Some(v) = leading_number(after) {
            found.push((name, v));
        }
    }
    found
}

#[test]
fn the_docs_quote_the_schema_versions_the_files_carry() {
    let written: std::collections::BTreeMap<&str, i64> = WRITTEN_SCHEMAS.into_iter().collect();
    let mut wrong = Vec::new();
    let mut checked = 0;
    for doc in documents() {
        let name = doc.strip_prefix(repo("")).unwrap().display().to_string();
        let text = std::fs::read_to_string(&doc).unwrap();
        // The schema of the section: its heading names it.
        let mut section: Option<String> = None;
        for (k, line) in text.lines().enumerate() {
            if line.starts_with('#') {
                section = line
                    .split('`')
                    .find(|w| w.starts_with("tiltnoise."))
                    .map(str::to_string);
            }
            let mut quoted = quoted_versions(line);
            let table_cell = line
                .starts_with('|')
                .then(|| line.trim_end_matches('|').rsplit('|').next())
                .flatten()
                .map(|c| c.trim().trim_matches('`'));
            if let (true, Some(cell), Some(schema)) = (
                line.contains("`schema_version`"),
                table_cell,
                section.as_deref(),
            ) {
                if let Some(v) = leading_number(cell).filter(|_| cell.len() <= 2) {
                    quoted.push((schema, v));
                }
            }
            for (schema, v) in quoted {
                if let Some(&version) = written.get(schema) {
                    checked += 1;
                    if v != version {
                        wrong.push(format!(
                            "{name}:{}: {schema} version {v}; the files carry {version}",
                            k + 1
                        ));
                    }
                }
            }
        }
    }
    say(&format!(
        "docs-run: {checked} quoted schema versions checked"
    ));
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    assert!(
        checked >= WRITTEN_SCHEMAS.len(),
        "only {checked} versions found in the docs"
    );
}
