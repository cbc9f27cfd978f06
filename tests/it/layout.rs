//! The house as the README describes it: every folder of every crate's sources is named in the
//! README's `Layout` block (and every folder the block names exists), every command's job
//! folder is named in the layers table, and the front ends reach the file layer only through
//! the job crate (no `tiltnoise_io` or `tiltnoise_plot` in `src/` or `python/src/`).

use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn readme() -> String {
    std::fs::read_to_string(root().join("README.md")).expect("README.md")
}

/// The text of the README section headed `## {heading}`, up to the next `## `.
fn section(readme: &str, heading: &str) -> String {
    let start = readme
        .find(&format!("\n## {heading}\n"))
        .unwrap_or_else(|| panic!("README has no section `## {heading}`"));
    let rest = &readme[start + 4 + heading.len()..];
    rest[..rest.find("\n## ").unwrap_or(rest.len())].to_string()
}

/// The folders directly under `dir`, sorted.
fn folders(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// The library crates of the workspace.
fn crates() -> Vec<String> {
    folders(&root().join("crates"))
}

#[test]
fn the_layout_block_names_every_source_folder_of_every_crate() {
    let layout = section(&readme(), "Layout");
    let mut missing = Vec::new();
    for krate in crates() {
        for folder in folders(&root().join("crates").join(&krate).join("src")) {
            if !layout.contains(&format!("{folder}/")) {
                missing.push(format!("crates/{krate}/src/{folder}/"));
            }
        }
    }
    assert!(
        missing.is_empty(),
        "README's Layout block does not name: {}",
        missing.join(", ")
    );
}

#[test]
fn every_crate_source_folder_the_layout_block_names_exists() {
    let layout = section(&readme(), "Layout");
    // Lines of the block under `crates/NAME/src/`: folder names `word/` at the start of an entry.
    let mut current: Option<String> = None;
    let mut stale = Vec::new();
    for line in layout.lines() {
        if let Some(rest) = line.strip_prefix("crates/") {
            current = rest.split('/').next().map(str::to_string);
            continue;
        }
        if !line.starts_with(' ') {
            current = None;
            continue;
        }
        let Some(krate) = &current else { continue };
        let src = root().join("crates").join(krate).join("src");
        for word in line.split_whitespace() {
            let Some(name) = word.strip_suffix('/') else {
                continue;
            };
            if name.chars().all(|c| c.is_ascii_lowercase() || c == '_') && !src.join(name).is_dir()
            {
                stale.push(format!("crates/{krate}/src/{name}/"));
            }
        }
    }
    assert!(
        stale.is_empty(),
        "README's Layout block names folders that do not exist: {}",
        stale.join(", ")
    );
}

#[test]
fn the_layers_table_names_every_command_job() {
    let layers = section(&readme(), "Crates: the layers");
    let jobs = folders(&root().join("crates/tiltnoise-job/src"));
    let row = layers
        .lines()
        .find(|l| l.contains("[`tiltnoise-job`]"))
        .expect("the layers table has a tiltnoise-job row");
    let missing: Vec<&String> = jobs
        .iter()
        .filter(|j| !row.contains(&format!("`{j}/`")))
        .collect();
    assert!(
        missing.is_empty(),
        "the tiltnoise-job row of README's layers table does not name the job folders {missing:?}"
    );
}

/// The code of a Rust line, without its `//` comment.
fn code_of(line: &str) -> &str {
    let mut in_str = false;
    let b = line.as_bytes();
    for i in 0..b.len() {
        if b[i] == b'"' && (i == 0 || b[i - 1] != b'\\') {
            in_str = !in_str;
        }
        if !in_str && b[i..].starts_with(b"//") {
            return &line[..i];
        }
    }
    line
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|x| x == "rs") {
            out.push(path);
        }
    }
}

#[test]
fn the_front_ends_reach_the_file_layer_only_through_the_job_crate() {
    let mut files = Vec::new();
    for front in ["src", "python/src"] {
        rust_files(&root().join(front), &mut files);
    }
    files.sort();
    let mut found = Vec::new();
    for file in &files {
        let text = std::fs::read_to_string(file).unwrap();
        for (n, line) in text.lines().enumerate() {
            let code = code_of(line);
            let names_lower = ["tiltnoise_io", "tiltnoise_plot"].iter().any(|c| {
                code.match_indices(c).any(|(i, _)| {
                    let after = code[i + c.len()..].chars().next();
                    let before = code[..i].chars().next_back();
                    !after.is_some_and(|a| a.is_alphanumeric() || a == '_')
                        && !before.is_some_and(|b| b.is_alphanumeric() || b == '_')
                })
            });
            let shown = file.strip_prefix(root()).unwrap().display().to_string();
            if names_lower {
                found.push(format!("{shown}:{}: {}", n + 1, line.trim()));
            }
        }
    }
    assert!(
        found.is_empty(),
        "the front ends must import the file layer through tiltnoise_job (its `files` and \
         `figures` re-exports and the jobs' outcomes):\n{}",
        found.join("\n")
    );
}
