//! One vocabulary across the commands, read from clap's command tree: every long option is in
//! the table below with its one meaning, no two names share a meaning, ranges are written
//! `LO:HI`, help lists only what a command accepts, and no default prints as a long decimal.
//! Then the old spellings kept as hidden aliases, run through the binary.

use crate::common::tiltnoise;
use clap::CommandFactory;
use std::collections::BTreeMap;
use tiltnoise::cli::Cli;

/// Every long option of every command, with its meaning. A new option is added here, with a
/// meaning no other name has; an option whose name is here means this wherever it appears.
const VOCABULARY: &[(&str, &str)] = &[
    ("params", "parameter file (TOML)"),
    ("set", "one parameter override KEY=VALUE"),
    ("help", "print help"),
    ("format", "how results print on the terminal"),
    ("save", "output file, format from the extension"),
    ("save-time", "time-series figure of a simulation"),
    ("observables", "which observables to compute"),
    (
        "plot-observables",
        "which computed observables a figure draws",
    ),
    ("input", "model inputs (columns of the transfer matrix)"),
    (
        "per",
        "floor motion per unit displacement, velocity or acceleration",
    ),
    ("tilt", "file: the tilt (witness) record"),
    ("measured", "file: measured record of the observables"),
    ("measured-modes", "file: measured mode frequencies"),
    ("colocated", "file: a second witness beside the first"),
    (
        "colocated-ratio",
        "noise ratio of the co-located instrument",
    ),
    ("visibility", "file: mode visibilities"),
    ("freq", "frequency grid FLO:N:FHI or one frequency"),
    ("freq-file", "file: one frequency per line"),
    ("at", "frequencies to read results at"),
    ("at-band", "relative half-width of the band means"),
    ("band", "fit band FLO:FHI"),
    ("fit-band", "band of the measured/model fit FLO:FHI"),
    ("report-band", "band of the residual summaries FLO:FHI"),
    ("xlim", "frequency range of figures LO:HI"),
    ("ylim", "y range of figures LO:HI"),
    ("size", "figure size WxH"),
    ("dpi", "figure resolution"),
    ("phase", "Bode phase panels"),
    ("method", "evaluation method of the transfer functions"),
    ("rel-tol", "tolerance of the method planner"),
    ("block-freqs", "frequencies per evaluated block"),
    ("explain", "say why the planner picked a method"),
    ("axes", "axis map of a record's channels"),
    ("quantity", "angle or rate"),
    ("gaps", "what to do with non-finite samples"),
    ("scale", "scale factor of a source channel"),
    ("units", "unit of a source channel"),
    ("corrected", "translation channels free of tilt"),
    (
        "pendulum-tiltmeter",
        "tilt channels read by a pendulum tiltmeter",
    ),
    ("nperseg", "Welch segment length"),
    ("overlap", "Welch overlap"),
    ("average", "Welch averaging"),
    (
        "segment-duration",
        "segments of a record for a percentile band",
    ),
    ("percentiles", "percentiles of the band LO:HI"),
    ("confidence", "confidence level"),
    ("readout", "readout noise of an observable"),
    ("term", "user-named noise term"),
    ("witness-noise", "the witness's own noise"),
    ("keep-zero-columns", "keep all-zero CSV columns"),
    ("fit", "model parameters fitted besides gains and delay"),
    ("free", "free parameters of the mode fit"),
    ("bound-sigmas", "box half-width in error bars"),
    ("prior", "Gaussian prior in chi^2"),
    ("holdout", "held-out fraction"),
    ("max-delay", "largest delay searched"),
    ("samples", "number of Monte Carlo draws"),
    ("seed", "seed of the random streams"),
    ("threads", "worker threads"),
    ("duration", "length of a simulated record"),
    ("step", "sampling step of a simulation"),
    ("init", "initial coordinates"),
    ("init-rate", "initial velocities"),
    ("kick-x", "kick test displacement"),
    ("mode-energy", "energy per mode of the default excitation"),
    ("with-coordinates", "also write the generalized coordinates"),
    ("chunk-samples", "samples per simulated chunk"),
    ("oversample", "fine steps per record sample"),
    ("drive-gain", "gain of the drive"),
    ("drive-delay", "delay of the drive"),
];

/// Old spellings kept as hidden aliases, with the option they now spell.
const ALIASES: &[(&str, &str, &str)] = &[
    ("tf", "output", "observables"),
    ("coherence", "output", "observables"),
    ("subtract", "tilt-noise", "witness-noise"),
    ("visibility", "record", "measured"),
    // In `fit` alone, where it has always meant the mode frequencies.
    ("fit", "measured", "measured-modes"),
];

/// Every subcommand with its long options (visible and hidden), global ones included.
fn commands() -> Vec<(String, Vec<clap::Arg>)> {
    let mut root = Cli::command();
    root.build();
    root.get_subcommands()
        .filter(|c| c.get_name() != "help")
        .map(|c| {
            let args = c.get_arguments().cloned().collect();
            (c.get_name().to_string(), args)
        })
        .collect()
}

#[test]
fn every_option_has_one_name_and_one_meaning() {
    let mut meanings: BTreeMap<&str, &str> = BTreeMap::new();
    for (name, meaning) in VOCABULARY {
        if let Some(other) = meanings.insert(meaning, name) {
            panic!("`{meaning}` has two names: --{other} and --{name}");
        }
    }
    let table: BTreeMap<&str, &str> = VOCABULARY.iter().copied().collect();
    assert_eq!(table.len(), VOCABULARY.len(), "a name listed twice");
    let mut seen = std::collections::BTreeSet::new();
    for (command, args) in commands() {
        for arg in &args {
            let Some(long) = arg.get_long() else { continue };
            assert!(
                table.contains_key(long),
                "{command} --{long}: not in the vocabulary (add it with its meaning, or use \
                 the name that already has it)"
            );
            seen.insert(long.to_string());
            for alias in arg.get_all_aliases().unwrap_or_default() {
                assert!(
                    ALIASES.contains(&(command.as_str(), alias, long)),
                    "{command} --{alias}: an alias of --{long} not in the table of old spellings"
                );
            }
            if arg.get_visible_aliases().is_some_and(|a| !a.is_empty()) {
                panic!("{command} --{long}: aliases are hidden (help shows one name)");
            }
        }
    }
    let unused: Vec<&&str> = table.keys().filter(|n| !seen.contains(**n)).collect();
    assert!(
        unused.is_empty(),
        "names in the vocabulary no command has: {unused:?}"
    );
}

#[test]
fn ranges_are_written_lo_colon_hi() {
    for (command, args) in commands() {
        for arg in &args {
            let (Some(long), Some(names)) = (arg.get_long(), arg.get_value_names()) else {
                continue;
            };
            for name in names {
                let name = name.as_str();
                let is_range = name.contains("LO") || name.contains("HI");
                assert!(
                    !is_range || (name.contains(':') && !name.contains(',')),
                    "{command} --{long} <{name}>: a range is LO:HI"
                );
            }
        }
    }
}

/// A default printed in plain decimal with four or more zeros after the point
/// (`0.000000001`), or with more than six significant digits: help shows `1e-9`.
fn is_long_decimal(text: &str) -> bool {
    let Ok(x) = text.parse::<f64>() else {
        return false;
    };
    let digits: String = text.chars().filter(char::is_ascii_digit).collect();
    let significant = digits.trim_start_matches('0').trim_end_matches('0');
    !text.contains(['e', 'E']) && x != 0.0 && (text.contains(".0000") || significant.len() > 6)
}

#[test]
fn help_defaults_print_in_scientific_notation() {
    assert!(is_long_decimal("0.000000001") && is_long_decimal("0.1234567"));
    assert!(!is_long_decimal("1e-9") && !is_long_decimal("43200") && !is_long_decimal("0.25"));
    let mut root = Cli::command();
    for (command, args) in commands() {
        for arg in &args {
            for default in arg.get_default_values() {
                let text = default.to_string_lossy();
                assert!(
                    !is_long_decimal(&text),
                    "{command} --{}: default {text} (help prints defaults as 1e-9)",
                    arg.get_id()
                );
            }
        }
        let help = root
            .find_subcommand_mut(&command)
            .unwrap()
            .render_long_help()
            .to_string();
        for word in help.split(|c: char| c.is_whitespace() || "[](),;:=".contains(c)) {
            assert!(!is_long_decimal(word), "{command} --help prints {word}");
        }
    }
}

#[test]
fn figures_without_a_frequency_axis_list_no_axis_limits() {
    for (command, args) in commands() {
        let longs: Vec<&str> = args.iter().filter_map(|a| a.get_long()).collect();
        if ["mc", "methods"].contains(&command.as_str()) {
            assert!(
                longs.contains(&"size") && longs.contains(&"dpi"),
                "{command}"
            );
            for limit in ["xlim", "ylim"] {
                assert!(!longs.contains(&limit), "{command} lists --{limit}");
            }
        }
    }
}

/// A short tilt CSV the coherence runs read: 1 Hz, two axes, in rad.
fn write_tilt_and_measured(dir: &std::path::Path) -> (String, String) {
    let tilt = dir.join("tilt.csv");
    let measured = dir.join("measured.csv");
    let mut t = String::from("# units: rad\ntime_s,E,N\n");
    let mut m = String::from("time_s,X,phi\n");
    let mut state = 12345u64;
    let mut noise = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    for k in 0..4096 {
        let (e, n) = (1e-8 * noise(), 1e-8 * noise());
        t.push_str(&format!("{k},{e:e},{n:e}\n"));
        m.push_str(&format!(
            "{k},{:e},{:e}\n",
            1e-9 * noise() + 0.1 * n,
            1e-9 * noise()
        ));
    }
    std::fs::write(&tilt, t).unwrap();
    std::fs::write(&measured, m).unwrap();
    (
        tilt.to_string_lossy().into_owned(),
        measured.to_string_lossy().into_owned(),
    )
}

/// Standard output without the `# created_by:` line, which quotes the command line.
fn results(out: &std::process::Output) -> String {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter(|l| !l.starts_with("# created_by:"))
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn old_spellings_still_work_as_hidden_aliases() {
    let base = ["tf", "--freq", "1e-3:5:1", "--input", "eta_t"];
    let new = results(&tiltnoise(
        &[&base[..], &["--observables", "X,phi"]].concat(),
    ));
    let old = results(&tiltnoise(&[&base[..], &["--output", "X,phi"]].concat()));
    assert_eq!(new, old, "tf --output is --observables");
    assert!(new.contains("X.eta_t") && !new.contains("Y.eta_t"), "{new}");
    let help = tiltnoise(&["tf", "--help"]);
    let help = String::from_utf8_lossy(&help.stdout);
    assert!(help.contains("--observables") && help.contains("--plot-observables"));
    assert!(!help.contains("--output"), "old spellings are hidden");

    let dir = tempfile::tempdir().unwrap();
    let (tilt, measured) = write_tilt_and_measured(dir.path());
    let coherence = |spelling: &str| {
        results(&tiltnoise(&[
            "coherence",
            "--tilt",
            &tilt,
            "--measured",
            &measured,
            "--nperseg",
            "512",
            spelling,
            "X",
        ]))
    };
    let (new, old) = (coherence("--observables"), coherence("--output"));
    assert_eq!(new, old, "coherence --output is --observables");
    assert!(new.contains("  X: ") && !new.contains("  phi: "), "{new}");

    let modes = crate::REPO_ROOT.to_string() + "/examples/fit/torsion_modes.csv";
    let fit = |spelling: &str| {
        results(&tiltnoise(&[
            "fit",
            spelling,
            &modes,
            "--free",
            "torsion.k_a_n_m_per_rad",
            "--format",
            "json",
        ]))
    };
    let (new, old) = (fit("--measured-modes"), fit("--measured"));
    assert_eq!(new, old, "fit --measured is --measured-modes");
    let json: serde_json::Value = serde_json::from_str(&new).unwrap();
    assert_eq!(
        json["modes"].as_array().unwrap().len(),
        2,
        "the file's two modes"
    );
}

#[test]
fn ranges_accept_both_separators() {
    let dir = tempfile::tempdir().unwrap();
    let png = |name: &str| dir.path().join(name).to_string_lossy().into_owned();
    let (colon, comma) = (png("colon.png"), png("comma.png"));
    for (xlim, path) in [("1e-3:1", &colon), ("1e-3,1", &comma)] {
        let out = tiltnoise(&[
            "tf",
            "--freq",
            "1e-3:20:1",
            "--xlim",
            xlim,
            "--ylim",
            "1e-6:1e3",
            "--save",
            path,
        ]);
        assert!(
            out.status.success(),
            "{xlim}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    assert_eq!(
        std::fs::read(&colon).unwrap(),
        std::fs::read(&comma).unwrap(),
        "--xlim 1e-3:1 and 1e-3,1 draw the same figure"
    );
    let out = tiltnoise(&["mc", "--samples", "10", "--xlim", "1e-3:1"]);
    assert_eq!(out.status.code(), Some(2), "mc takes no --xlim");
}

#[test]
fn commands_that_print_a_summary_take_format() {
    let visibility = commands()
        .into_iter()
        .find(|(c, _)| c == "visibility")
        .unwrap();
    let format = visibility.1.iter().find(|a| a.get_long() == Some("format"));
    let values: Vec<String> = format
        .map(|a| {
            a.get_possible_values()
                .iter()
                .map(|v| v.get_name().to_string())
                .collect()
        })
        .unwrap_or_default();
    assert_eq!(
        values,
        ["table", "csv", "json"],
        "visibility prints its table, its CSV or its JSON"
    );
    for (command, args) in commands() {
        if [
            "modes",
            "budget",
            "coherence",
            "subtract",
            "fit",
            "mc",
            "methods",
            "tf",
            "simulate",
        ]
        .contains(&command.as_str())
        {
            let format = args.iter().find(|a| a.get_long() == Some("format"));
            let values: Vec<String> = format
                .map(|a| {
                    a.get_possible_values()
                        .iter()
                        .map(|v| v.get_name().to_string())
                        .collect()
                })
                .unwrap_or_default();
            assert_eq!(values, ["table", "json"], "{command} --format");
        }
    }
}

#[test]
fn coherence_json_holds_the_numbers_of_its_table() {
    let dir = tempfile::tempdir().unwrap();
    let (tilt, measured) = write_tilt_and_measured(dir.path());
    let run = |format: &str| {
        results(&tiltnoise(&[
            "coherence",
            "--tilt",
            &tilt,
            "--measured",
            &measured,
            "--nperseg",
            "512",
            "--format",
            format,
        ]))
    };
    let (table, json) = (run("table"), run("json"));
    let json: serde_json::Value = serde_json::from_str(&json).expect("--format json is JSON");
    let thresholds = format!(
        "ordinary coherence {:.3}, multiple coherence with 2 axes {:.3}",
        json["coherence_threshold"].as_f64().unwrap(),
        json["multiple_coherence_threshold"].as_f64().unwrap()
    );
    assert!(table.contains(&thresholds), "{thresholds}\n{table}");
    let observables = json["observables"].as_array().unwrap();
    assert_eq!(observables.len(), 2, "X and phi");
    for ob in observables {
        let name = ob["observable"].as_str().unwrap();
        let line = format!(
            "  {name}: multiple coherence significant in {} of {} bins",
            ob["significant_bins"], json["bins"]
        );
        assert!(table.contains(&line), "{line}\n{table}");
        for axis in ob["axes"].as_array().unwrap() {
            let peak = format!(
                "    {:<7} max coherence {:.3} at {:.3e} Hz",
                axis["axis"].as_str().unwrap(),
                axis["max_coherence"].as_f64().unwrap(),
                axis["max_coherence_at_hz"].as_f64().unwrap()
            );
            assert!(table.contains(&peak), "{peak}\n{table}");
        }
    }
    let eta = &observables[0]["axes"][1];
    assert_eq!(eta["axis"], "eta_t");
    let gain = eta["measured_over_model"]["gain"].as_f64().unwrap();
    // X sees eta_t in the model (and the measured X holds a part of the N channel, eta_t = -N
    // by the default axis map): the comparison with the model is there, with a gain.
    assert!(gain.is_finite() && gain > 0.0, "{gain}");
}
