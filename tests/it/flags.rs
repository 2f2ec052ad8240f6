//! Flags that mean the same in every command (issue 11): a number may be
//! negative wherever a number is asked for, and `-q/--quiet` silences
//! warnings and progress bars on stderr, never results.

use crate::util::{axcomp, shared_data};

const SAMPLE: &str = "fixtures/sample-x.rtl";

/// Every subcommand, as `axcomp --help` lists them.
fn subcommands() -> Vec<String> {
    let help = axcomp(["--help"]);
    assert_eq!(help.code, 0);
    let commands = help.stdout.split("Commands:\n").nth(1).unwrap();
    commands
        .lines()
        .take_while(|line| line.starts_with("  "))
        .filter_map(|line| line.split_whitespace().next())
        .filter(|name| *name != "help")
        .map(str::to_string)
        .collect()
}

#[test]
fn a_negative_step_reaches_axcomp_not_the_flag_parser() {
    let directory = tempfile::tempdir().unwrap();
    let output = directory.path().join("X.COM");
    let output = output.to_str().unwrap();
    // Stepping down from 750 is not a table axcomp writes: the reason is axcomp's own.
    let run = axcomp([
        "convert",
        SAMPLE,
        "--controller",
        "tnc640",
        "-o",
        output,
        "--start",
        "750",
        "--step",
        "-50",
    ]);
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert_eq!(
        run.stderr,
        "axcomp: error: invalid grid: step must be positive, found -50 mm\n"
    );
    // A reference outside the table: the same, for a negative position.
    let run = axcomp([
        "convert",
        SAMPLE,
        "--controller",
        "tnc640",
        "-o",
        output,
        "--reference",
        "-10",
    ]);
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert_eq!(
        run.stderr,
        "axcomp: error: reference position -10 mm is outside the table 0 … 750 mm\n"
    );
    assert!(!directory.path().join("X.COM").exists());

    // A grid that starts below zero, zero there: negative --start and --reference are used.
    let run = axcomp([
        "convert",
        SAMPLE,
        "--controller",
        "tnc640",
        "-o",
        output,
        "--start",
        "-50",
        "--step",
        "50",
        "--count",
        "17",
        "--extrapolate",
        "hold",
        "--reference",
        "-50",
        "--json",
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let json: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    assert_eq!(json["start_mm"], -50.0);
    assert_eq!(json["reference_mm"], -50.0);
    let positions = json["positions_mm"].as_array().unwrap();
    assert_eq!(
        (positions.len(), &positions[0]),
        (17, &serde_json::json!(-50.0))
    );
    // Held below the first target and zero at the reference: 0 and 0.
    assert_eq!(json["values_um"]["mean"][0], 0.0);
    assert_eq!(json["values_um"]["mean"][1], 0.0);
}

#[test]
fn negative_values_elsewhere_get_a_value_error_not_an_unexpected_argument() {
    for args in [
        &["tolerance", "--straightness", "-0.01"][..],
        &["tolerance", "--sweep", "--sweep-values", "-0.1,0.2"],
        &[
            "convert",
            SAMPLE,
            "--controller",
            "tnc640",
            "-o",
            "X.COM",
            "--step",
            "50",
            "--count",
            "-3",
        ],
    ] {
        let run = axcomp(args);
        assert_eq!(run.code, 2, "{args:?}: {}", run.stderr);
        assert!(
            run.stderr.contains("error: invalid value '-"),
            "{args:?}: {}",
            run.stderr
        );
        assert!(
            !run.stderr.contains("unexpected argument"),
            "{args:?}: {}",
            run.stderr
        );
    }
}

#[test]
fn quiet_is_documented_the_same_in_every_command() {
    let commands = subcommands();
    assert_eq!(commands.len(), 13, "{commands:?}");
    // `thermal` groups commands: each of them has -q.
    let commands: Vec<String> = commands
        .into_iter()
        .flat_map(|c| match c.as_str() {
            "thermal" => ["evaluate", "fit", "apply", "hal"]
                .map(|s| format!("thermal {s}"))
                .to_vec(),
            _ => vec![c],
        })
        .collect();
    for command in &commands {
        let mut args: Vec<&str> = command.split(' ').collect();
        args.push("--help");
        let help = axcomp(&args);
        assert_eq!(help.code, 0, "{command}");
        // The text follows on the next line (long help) or on the same line (short help).
        let quiet = help
            .stdout
            .split("  -q, --quiet")
            .nth(1)
            .unwrap_or_else(|| panic!("{command} has no -q, --quiet"));
        let quiet = quiet.strip_prefix('\n').unwrap_or(quiet);
        assert_eq!(
            quiet.lines().next().unwrap().trim(),
            "No warnings and no progress bars on stderr (results and errors are unchanged)",
            "{command}"
        );
    }
}

#[test]
fn quiet_silences_warnings_in_every_command_and_changes_no_result() {
    // A unidirectional test with one run: evaluate, convert and report warn about it.
    let pos = shared_data("api-xd/example__8055__X Axis Forward.pos");
    let pos = pos.to_str().unwrap();
    let directory = tempfile::tempdir().unwrap();
    let file = |name: &str| directory.path().join(name).display().to_string();
    let (table, page) = (file("X.COM"), file("report.html"));
    let commands: [Vec<&str>; 4] = [
        vec!["evaluate", pos],
        vec![
            "convert",
            pos,
            "--controller",
            "tnc640",
            "-o",
            &table,
            "--force",
        ],
        vec!["report", pos, "-o", &page, "--force"],
        vec!["tolerance", "--samples", "100", "--json"],
    ];
    for args in commands {
        let loud = axcomp(&args);
        let table_loud = std::fs::read(&table).ok();
        let quiet = axcomp(args.iter().chain(&["-q"]));
        assert_eq!((loud.code, quiet.code), (0, 0), "{args:?}: {}", loud.stderr);
        assert_eq!(quiet.stderr, "", "{args:?}");
        assert_eq!(quiet.stdout, loud.stdout, "{args:?}: the result changed");
        assert_eq!(std::fs::read(&table).ok(), table_loud, "{args:?}");
        if args[0] != "tolerance" {
            assert!(
                loud.stderr.contains("axcomp: warning: unidirectional test"),
                "{args:?}: {}",
                loud.stderr
            );
        }
    }
    // Errors are not silenced.
    let run = axcomp(["diagnose", "--after", pos, "-q"]);
    assert_eq!(run.code, 2);
    assert!(run.stderr.starts_with("axcomp: error: "), "{}", run.stderr);
}
