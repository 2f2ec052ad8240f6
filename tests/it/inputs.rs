//! No silent default behind a number the engineer loads or signs: a file is
//! never both input and output, the uncertainty comes from a known
//! instrument, profiles are checked, users read references (the acceptance
//! tests of these rules, through the binary, on the real files where the
//! problems were found).

use std::path::{Path, PathBuf};

use crate::util::{axcomp, shared_data};

const SAMPLE: &str = "fixtures/sample-x.rtl";

/// A copy of `source` in a fresh folder, as the engineer's only copy.
fn only_copy(source: &Path, name: &str) -> (tempfile::TempDir, PathBuf) {
    let directory = tempfile::tempdir().unwrap();
    let path = directory.path().join(name);
    std::fs::copy(source, &path).unwrap();
    (directory, path)
}

fn strings(args: &[&dyn AsRef<std::ffi::OsStr>]) -> Vec<std::ffi::OsString> {
    args.iter().map(|a| a.as_ref().to_os_string()).collect()
}

// --- a file is never both input and output ----------------------------------

#[test]
fn convert_and_report_never_replace_the_measurement_they_read() {
    let (directory, measurement) = only_copy(Path::new(SAMPLE), "X.rtl");
    let original = std::fs::read(&measurement).unwrap();
    // The same path, and the same file by another spelling.
    let other_spelling = directory.path().join(".").join("X.rtl");
    for output in [&measurement, &other_spelling] {
        for args in [
            strings(&[
                &"convert",
                &measurement,
                &"--controller",
                &"tnc640",
                &"-o",
                output,
                &"--force",
            ]),
            strings(&[&"report", &measurement, &"-o", output, &"--force"]),
        ] {
            let run = axcomp(&args);
            assert_eq!(run.code, 2, "{args:?}: {}", run.stderr);
            assert!(
                run.stderr.contains("is also an input of this command"),
                "{args:?}: {}",
                run.stderr
            );
            assert_eq!(std::fs::read(&measurement).unwrap(), original, "{args:?}");
        }
    }
    // A real ecmc test as `report --after` and as the output: refused too.
    let (directory, first) = only_copy(
        &shared_data(
            "ecmc/ecmc_target_muts_logger/muts__data__week42_22__xyz__target_x_report_ILD50.md_ISO230.dat",
        ),
        "first.dat",
    );
    let after = directory.path().join("after.dat");
    std::fs::copy(
        shared_data(
            "ecmc/ecmc_target_muts_logger/muts__data__week42_22__xyz__back__target_x_report_2.md_ISO230.dat",
        ),
        &after,
    )
    .unwrap();
    let kept = std::fs::read(&after).unwrap();
    let run = axcomp(strings(&[
        &"report", &first, &"--after", &after, &"-o", &after, &"--force",
    ]));
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert!(
        run.stderr.contains("after.dat: is also an input"),
        "{}",
        run.stderr
    );
    assert_eq!(std::fs::read(&after).unwrap(), kept);
}

#[test]
fn report_png_into_a_missing_parent_folder_is_refused() {
    let directory = tempfile::tempdir().unwrap();
    let html = directory.path().join("report.html");
    let deep = directory.path().join("no").join("such").join("dir");
    let run = axcomp(strings(&[
        &"report", &SAMPLE, &"-o", &html, &"--png", &deep,
    ]));
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert!(
        run.stderr.contains(&format!(
            "the folder {} does not exist",
            directory.path().join("no").join("such").display()
        )),
        "{}",
        run.stderr
    );
    assert!(!directory.path().join("no").exists(), "no folder is made");
    assert!(!html.exists(), "nothing is written");
    // A missing last folder whose parent exists is still made.
    let plots = directory.path().join("plots");
    let run = axcomp(strings(&[
        &"report", &SAMPLE, &"-o", &html, &"--png", &plots,
    ]));
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(plots.join("deviation.png").exists());
}

// --- profiles and inputs are checked, not guessed ----------------------------

/// A machine profile with `text` in a fresh folder.
fn profile(text: &str) -> (tempfile::TempDir, PathBuf) {
    let directory = tempfile::tempdir().unwrap();
    let path = directory.path().join("M.toml");
    std::fs::write(&path, text).unwrap();
    (directory, path)
}

#[test]
fn a_misspelt_profile_table_or_value_is_refused_at_its_line_by_every_command() {
    let pos = shared_data("api-xd/example__8055__X Axis Forward.pos");
    // `[controler]` wrote an mm Fagor table from an inch profile, exit 0.
    let (directory, misspelt) = profile("[controler]\nunits = \"inch\"\n");
    let table = directory.path().join("ALX");
    let run = axcomp(strings(&[
        &"convert",
        &pos,
        &"--controller",
        &"fagor8055",
        &"--axis",
        &"X",
        &"-o",
        &table,
        &"--machine",
        &misspelt,
    ]));
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert_eq!(
        run.stderr,
        format!(
            "axcomp: error: {}:1:2: a machine profile has no table or key \"controler\"; \
             expected name, controller, kinematics, acceptance\n",
            misspelt.display()
        )
    );
    assert!(!table.exists());
    // `[acceptence]` gave no verdict and no word.
    let (_directory, acceptance) = profile("name = \"VC 1810\"\n[acceptence]\nA = 10\n");
    let run = axcomp(strings(&[&"evaluate", &pos, &"--machine", &acceptance]));
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert!(
        run.stderr.contains(&format!(
            "{}:2:2: a machine profile has no table or key \"acceptence\"",
            acceptance.display()
        )),
        "{}",
        run.stderr
    );
    // `units = "furlong"` passed `evaluate`, which reads only [acceptance].
    let (_directory, furlong) =
        profile("[controller]\nunits = \"furlong\"\n[acceptance]\nA = 10\n");
    let run = axcomp(strings(&[&"evaluate", &pos, &"--machine", &furlong]));
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert!(
        run.stderr.contains(&format!(
            "{}:2:9: controller.units must be \"mm\" or \"inch\", found \"furlong\"",
            furlong.display()
        )),
        "{}",
        run.stderr
    );
    // The well-spelt profile is read (the verdict appears).
    let (_directory, good) = profile("[controller]\nunits = \"inch\"\n[acceptance]\nA = 1000\n");
    let run = axcomp(strings(&[
        &"evaluate",
        &pos,
        &"--machine",
        &good,
        &"--json",
    ]));
    assert_eq!(run.code, 0, "{}", run.stderr);
    let json: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    assert_eq!(json["verdict"]["checks"][0]["figure"], "A");
}

#[test]
fn evaluate_json_gives_no_axis_name_where_the_file_records_none() {
    // The ecmccfg example records no axis (no TGT_SET_PV, no axis in its name).
    let file = shared_data("ecmc/ecmccfg/examples__mcu1025_fat_sat__report.md_ISO230.dat");
    let run = axcomp(strings(&[&"evaluate", &file, &"--json"]));
    assert_eq!(run.code, 0, "{}", run.stderr);
    let json: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    assert_eq!(json["axis"], serde_json::Value::Null);
    assert_eq!(json["axis_source"]["kind"], "not_recorded");
    let run = axcomp(strings(&[&"evaluate", &file, &"--json", &"--axis", &"Z"]));
    let json: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    assert_eq!(json["axis"], "Z");
    // A file that records its axis keeps it.
    let file = shared_data(
        "ecmc/ecmc_target_muts_logger/muts__data__week42_22__xyz__target_y_report_ILD50.md_ISO230.dat",
    );
    let run = axcomp(strings(&[&"evaluate", &file, &"--json"]));
    let json: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    assert_eq!(json["axis"], "Y");
}

// --- uncertainty from a known instrument -------------------------------------

const ILD50_X: &str =
    "ecmc/ecmc_target_muts_logger/muts__data__week42_22__xyz__target_x_report_ILD50.md_ISO230.dat";

fn json_of(args: &[&dyn AsRef<std::ffi::OsStr>]) -> serde_json::Value {
    let run = axcomp(strings(args));
    assert_eq!(run.code, 0, "{}", run.stderr);
    serde_json::from_str(&run.stdout).unwrap()
}

#[test]
fn a_sensor_or_encoder_test_gets_no_laser_uncertainty_unless_equipment_is_given() {
    // Every real ecmc test: the reference is a sensor or an encoder (REF_PV).
    for file in crate::util::shared_files("ecmc/ecmc_target_muts_logger", ".dat") {
        let json = json_of(&[&"evaluate", &file, &"--json"]);
        assert!(json.get("uncertainty_um").is_none(), "{}", file.display());
        let warnings = json["warnings"].to_string();
        assert!(
            warnings.contains("not evaluated: instrument unknown (give --equipment)"),
            "{}: {warnings}",
            file.display()
        );
    }
    let file = shared_data(ILD50_X);
    // With --equipment the budget is the user's.
    let json = json_of(&[
        &"evaluate",
        &file,
        &"--json",
        &"--equipment",
        &"fixtures/equipment/hene-default.toml",
    ]);
    assert!(json["uncertainty_um"]["A"].as_f64().unwrap() > 0.0);
    // Under ISO 14253-1 the check says why it has no U.
    let json = json_of(&[
        &"evaluate",
        &file,
        &"--json",
        &"--decision",
        &"iso14253-1",
        &"--limit",
        &"A=200",
    ]);
    let check = &json["verdict"]["checks"][0];
    assert_eq!(check["U_um"], serde_json::Value::Null);
    assert_eq!(
        check["U_note"],
        "U(A) not evaluated: instrument unknown (give --equipment); compared by its value alone"
    );
    // The acceptance report a customer signs shows no ± U for A either.
    let directory = tempfile::tempdir().unwrap();
    let html = directory.path().join("report.html");
    let run = axcomp(strings(&[&"report", &file, &"-o", &html]));
    assert_eq!(run.code, 0, "{}", run.stderr);
    let page = std::fs::read_to_string(&html).unwrap();
    assert!(!page.contains("id=\"uncertainty\""), "no budget section");
    assert!(page.contains("instrument unknown (give --equipment)"));
}

#[test]
fn laser_files_keep_their_uncertainty_and_pa_has_the_u_of_m() {
    // A Renishaw .rtl and an API laser's .pos record a laser interferometer.
    let pos = shared_data("api-xd/example__8055__X Axis Forward.pos");
    for file in [PathBuf::from(SAMPLE), pos] {
        let json = json_of(&[&"evaluate", &file, &"--json"]);
        assert!(
            json["uncertainty_um"]["A"].as_f64().unwrap() > 0.0,
            "{}",
            file.display()
        );
    }
    // VDI 3441's Pa is M's formula (the range of the bidirectional means):
    // the same U, and the same number judged the same way.
    let iso = json_of(&[&"evaluate", &SAMPLE, &"--json"]);
    let vdi = json_of(&[
        &"evaluate",
        &SAMPLE,
        &"--json",
        &"--standard",
        &"vdi3441",
        &"--decision",
        &"iso14253-1",
        &"--limit",
        &"Pa=8.5",
        &"--limit",
        &"P=100",
    ]);
    let m = iso["figures_um"]["M"].as_f64().unwrap();
    let u_m = iso["uncertainty_um"]["M"].as_f64().unwrap();
    let checks = vdi["verdict"]["checks"].as_array().unwrap();
    let pa = checks.iter().find(|c| c["figure"] == "Pa").unwrap();
    assert!((pa["value_um"].as_f64().unwrap() - m).abs() < 1e-9);
    assert_eq!(pa["U_um"].as_f64().unwrap(), u_m);
    // M = 8.064 µm, U = 1.82 µm: 8.064 + 1.82 > 8.5 ≥ 8.064 − 1.82.
    assert_eq!(pa["conformance"], "not-proven");
    let p = checks.iter().find(|c| c["figure"] == "P").unwrap();
    assert_eq!(
        p["U_note"],
        "U(P) not evaluated: no published form of its uncertainty; compared by its value alone"
    );
}

// --- users read references, not project jargon -------------------------------

/// Names of the project's own sources that a customer cannot look up.
const JARGON: [&str; 7] = [
    "seed 0",
    "Seed 0",
    "the thesis",
    "thesis's",
    "issue 1",
    "NumPy peer",
    "the issue",
];

#[test]
fn help_report_and_page_cite_publications_not_project_jargon() {
    let commands = [
        "demo",
        "evaluate",
        "convert",
        "synth",
        "predict",
        "diagnose",
        "tolerance",
        "servo-sim",
        "report",
        "serve",
    ];
    let mut texts = vec![("axcomp --help".to_string(), axcomp(["--help"]).stdout)];
    for command in commands {
        let run = axcomp([command, "--help"]);
        assert_eq!(run.code, 0, "{command}: {}", run.stderr);
        texts.push((format!("{command} --help"), run.stdout));
    }
    let directory = tempfile::tempdir().unwrap();
    let html = directory.path().join("report.html");
    let run = axcomp(strings(&[&"report", &SAMPLE, &"-o", &html]));
    assert_eq!(run.code, 0, "{}", run.stderr);
    let page = std::fs::read_to_string(&html).unwrap();
    assert!(
        page.contains("Edlén 1966"),
        "the report cites Edlén by year"
    );
    texts.push(("the report".into(), page));
    let app = std::fs::read_to_string("assets/serve/index.html").unwrap()
        + &std::fs::read_to_string("assets/serve/app.js").unwrap();
    texts.push(("the web page".into(), app));
    for (what, text) in &texts {
        for word in JARGON {
            assert!(!text.contains(word), "{what} says {word:?}");
        }
    }
    // The help cites the models' sources by author and year.
    let tolerance = &texts
        .iter()
        .find(|(w, _)| w == "tolerance --help")
        .unwrap()
        .1;
    assert!(tolerance.contains("Valášek (2021)"), "{tolerance}");
    let servo = &texts
        .iter()
        .find(|(w, _)| w == "servo-sim --help")
        .unwrap()
        .1;
    assert!(servo.contains("Mendřický 2006"), "{servo}");
    // The references page lists them with the standards.
    let references = std::fs::read_to_string("docs/src/references.md").unwrap();
    for cited in [
        "Valášek, A. (2021)",
        "Mendřický, R. (2006)",
        "Edlén, B. (1966)",
        "Birch, K. P. and Downs, M. J. (1993)",
        "ISO 230-2:2014",
        "ISO 14253-1",
        "VDI/DGQ 3441",
    ] {
        assert!(references.contains(cited), "references.md lacks {cited}");
    }
}

// --- smaller: messages that say what differs, tables read by rank -------------

#[test]
fn joining_files_whose_targets_differ_says_which_target() {
    let directory = tempfile::tempdir().unwrap();
    // The same count and ends, one target 0.25 mm elsewhere.
    let file = |name: &str, middle: f64, direction: &str| {
        let mut text = String::from("# axis: X\ntarget_mm,run,direction,deviation_um\n");
        for target in [0.0, 150.0, middle, 450.0, 600.0, 750.0] {
            text.push_str(&format!("{target},1,{direction},1.0\n"));
        }
        let path = directory.path().join(name);
        std::fs::write(&path, text).unwrap();
        path
    };
    let up = file("up.csv", 300.0, "up");
    let down = file("down.csv", 300.25, "down");
    let run = axcomp(strings(&[&"evaluate", &up, &down]));
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert!(
        run.stderr.contains(
            "targets differ (6 targets 0.0…750.0 mm against 6 targets 0.0…750.0 mm): \
             target 3 is at 300.0 mm in the first and 300.25 mm in the second"
        ),
        "{}",
        run.stderr
    );
}

#[test]
fn a_start_beyond_the_measured_range_is_said_so() {
    let directory = tempfile::tempdir().unwrap();
    let table = directory.path().join("X.COM");
    // The sample measures 0 … 750 mm.
    let run = axcomp(strings(&[
        &"convert",
        &SAMPLE,
        &"--controller",
        &"tnc640",
        &"-o",
        &table,
        &"--start",
        &"800",
        &"--step",
        &"50",
    ]));
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert!(
        run.stderr.contains(
            "the grid starts at 800 mm with a step of 50 mm, but the test measured 0 … 750 mm: \
             no second point lies within it (give a start below 700 mm, or --count)"
        ),
        "{}",
        run.stderr
    );
    assert!(!table.exists());
}

#[test]
fn the_sweep_table_is_printed_by_rank() {
    let run = axcomp([
        "tolerance",
        "--samples",
        "200",
        "--sweep",
        "--sweep-values",
        "0.015,0.03,0.045",
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let table = run.stdout.split("Sensitivity of P90").nth(1).unwrap();
    // Markdown rows after the header and its rule: `| rank | tolerance | …`.
    let rows: Vec<(String, String)> = table
        .lines()
        .filter(|line| line.starts_with('|'))
        .skip(2)
        .map(|line| {
            let cells: Vec<&str> = line.split('|').map(str::trim).collect();
            (cells[1].to_string(), cells[2].to_string())
        })
        .collect();
    assert_eq!(rows.len(), 13, "{table}");
    let ranks: Vec<usize> = rows
        .iter()
        .filter_map(|(rank, _)| rank.parse().ok())
        .collect();
    assert_eq!(ranks.len(), 12, "{table}");
    assert_eq!(ranks[0], 1, "{table}");
    assert!(ranks.windows(2).all(|w| w[0] <= w[1]), "{table}");
    assert_eq!(rows.last().unwrap(), &(String::new(), "all".to_string()));
}
