//! The library crates keep their roles, read from their sources: no option spelling in
//! tiltnoise-core, tiltnoise-io, tiltnoise-plot or tiltnoise-job (an error names the option by
//! its key and each front end spells it), and no core function takes an option's name as text
//! to put into its messages (it takes an `OptionKey`).

use std::path::{Path, PathBuf};

/// The library crates, whose messages name options by key only.
const LIBRARIES: [&str; 4] = [
    "tiltnoise-core",
    "tiltnoise-io",
    "tiltnoise-plot",
    "tiltnoise-job",
];

/// Every `.rs` file under `dir`, sorted.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap_or_else(|e| panic!("{}: {e}", d.display())) {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|x| x == "rs") {
                files.push(path);
            }
        }
    }
    files.sort();
    files
}

/// The string literals of Rust source `src` (plain, raw and byte strings, escapes left as
/// written), each with its line; comments (doc comments too), character literals and
/// lifetimes are skipped.
fn string_literals(src: &str) -> Vec<(usize, String)> {
    let b = src.as_bytes();
    let line_of = |i: usize| src[..i].bytes().filter(|&c| c == b'\n').count() + 1;
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let ident_before = i > 0 && (b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_');
        if b[i..].starts_with(b"//") {
            i = src[i..].find('\n').map_or(b.len(), |n| i + n);
        } else if b[i..].starts_with(b"/*") {
            let mut depth = 0;
            loop {
                if b[i..].starts_with(b"/*") {
                    depth += 1;
                    i += 2;
                } else if b[i..].starts_with(b"*/") {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
        } else if !ident_before && raw_string_start(&b[i..]).is_some() {
            let (skip, hashes) = raw_string_start(&b[i..]).unwrap();
            let start = i + skip;
            let end = format!("\"{}", "#".repeat(hashes));
            let len = src[start..].find(&end).expect("an unterminated raw string");
            out.push((line_of(i), src[start..start + len].to_string()));
            i = start + len + end.len();
        } else if b[i] == b'"' {
            let start = i + 1;
            let mut j = start;
            while b[j] != b'"' {
                j += if b[j] == b'\\' { 2 } else { 1 };
            }
            out.push((line_of(i), src[start..j].to_string()));
            i = j + 1;
        } else if b[i] == b'\'' {
            // A character literal ('x', '\n', '\u{..}', '"'); otherwise a lifetime.
            if b.get(i + 1) == Some(&b'\\') {
                i += 2 + src[i + 2..].find('\'').expect("an unterminated character") + 1;
            } else {
                let c = src[i + 1..].chars().next().map_or(1, char::len_utf8);
                i += if b.get(i + 1 + c) == Some(&b'\'') {
                    c + 2
                } else {
                    1
                };
            }
        } else {
            i += 1;
        }
    }
    out
}

/// `(prefix length, number of #)` when `b` starts a raw string: `r"`, `r#"`, `br"`, ...
fn raw_string_start(b: &[u8]) -> Option<(usize, usize)> {
    let r = usize::from(b.first() == Some(&b'b'));
    if b.get(r) != Some(&b'r') {
        return None;
    }
    let hashes = b[r + 1..].iter().take_while(|&&c| c == b'#').count();
    (b.get(r + 1 + hashes) == Some(&b'"')).then_some((r + 2 + hashes, hashes))
}

/// Whether `text` holds an option spelled as a flag: `--` then a lower-case letter.
fn names_a_flag(text: &str) -> bool {
    text.as_bytes()
        .windows(3)
        .any(|w| w[0] == b'-' && w[1] == b'-' && w[2].is_ascii_lowercase())
}

#[test]
fn the_lexer_sees_strings_and_skips_comments() {
    let src =
        "// \"--a\"\n/// \"--b\"\nlet x = \"--c\"; /* \"--d\" /* \"--e\" */ */ let y: &'a str = \
               r#\"--f \"q\"\"#; let c = '\"'; let z = b\"--g\\\"--h\";";
    let found: Vec<String> = string_literals(src).into_iter().map(|(_, s)| s).collect();
    assert_eq!(found, ["--c", "--f \"q\"", "--g\\\"--h"]);
    assert!(names_a_flag("use a shorter --nperseg") && !names_a_flag("a -- b, --X, -x"));
}

#[test]
fn libraries_spell_no_option() {
    let root = Path::new(crate::REPO_ROOT).join("crates");
    let mut found = Vec::new();
    for lib in LIBRARIES {
        for file in rust_files(&root.join(lib).join("src")) {
            let src = std::fs::read_to_string(&file).unwrap();
            for (line, text) in string_literals(&src) {
                if names_a_flag(&text) {
                    found.push(format!("{}:{line}: \"{text}\"", file.display()));
                }
            }
        }
    }
    assert!(
        found.is_empty(),
        "{} string literals in the library crates spell an option as a flag; name it by its \
         key (tiltnoise_core::option_key::OptionKey) and let the front end spell it:\n{}",
        found.len(),
        found.join("\n")
    );
}

/// Whether the code `line` (comments left out) declares an option's name as text: a parameter
/// or field `option` or `flag` of type `&str`, `&'static str` or `String`.
fn takes_an_option_name_as_text(line: &str) -> bool {
    let code: String = line
        .split("//")
        .next()
        .unwrap_or("")
        .chars()
        .filter(|c| !c.is_whitespace())
        .collect();
    ["option", "flag"].iter().any(|name| {
        ["&str", "&'staticstr", "String"]
            .iter()
            .any(|ty| code.contains(&format!("{name}:{ty}")))
    })
}

#[test]
fn core_takes_option_keys_not_names() {
    assert!(takes_an_option_name_as_text("    option: &str,"));
    assert!(takes_an_option_name_as_text("fn f(flag: &'static str) {"));
    assert!(takes_an_option_name_as_text("        option: String,"));
    assert!(!takes_an_option_name_as_text("    option: OptionKey,"));
    assert!(!takes_an_option_name_as_text("/// option: &str is refused"));
    let src = Path::new(crate::REPO_ROOT).join("crates/tiltnoise-core/src");
    let mut found = Vec::new();
    for file in rust_files(&src) {
        let text = std::fs::read_to_string(&file).unwrap();
        for (i, line) in text.lines().enumerate() {
            if takes_an_option_name_as_text(line) {
                found.push(format!("{}:{}: {}", file.display(), i + 1, line.trim()));
            }
        }
    }
    assert!(
        found.is_empty(),
        "{} declarations in tiltnoise-core take an option's name as text; take an \
         OptionKey (tiltnoise_core::option_key), which the front end spells:\n{}",
        found.len(),
        found.join("\n")
    );
}
