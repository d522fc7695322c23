//! What `gyrodrift report` and `gyrodrift demo` print is what their report says first: the drift
//! table, the absolute-error verdict and the field-like results; and its figures read as a user
//! reads them.

use std::path::Path;

use drift_evaluate::pipeline::Options;
use gyrodrift::cli::demo;

mod common;

use common::ok;

/// A short campaign of one unit at 100 Hz with a field session per set point.
fn simulate(dir: &Path) -> String {
    simulate_named(dir, "campaign", &[])
}

/// [`simulate`] into `dir/<name>`, with further `simulate` flags.
fn simulate_named(dir: &Path, name: &str, flags: &[&str]) -> String {
    let toml = dir.join(format!("{name}.toml"));
    std::fs::write(
        &toml,
        "seed = 5\nunits = 1\nsample_rate_hz = 100\nset_points_celsius = [30, 40, 33]\n\
         [protocol]\nintervals_min = [1, 30]\nrepeats = 2\nactivation_s = 60\n\
         [field]\nsessions = 1\nactivations = 3\nactivation_s = [30, 60]\n",
    )
    .unwrap();
    let out = dir.join(name);
    let mut args = vec![
        "simulate",
        "-q",
        "--campaign",
        toml.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(flags);
    ok(&args);
    out.to_str().unwrap().to_owned()
}

/// The console holds the drift table's validation row, the report's verdict word for word and
/// the field-like means as the report's table has them.
fn assert_console_says_what_the_report_says(console: &str, md: &str) {
    assert!(console.contains("| +33 °C | validation |"), "{console}");
    let start = md
        .find("In ")
        .filter(|&i| md[i..].contains("unit × axis × set point × activation-class cells"))
        .expect("a verdict in report.md");
    let verdict = &md[start..start + md[start..].find(" residual bias RMS").unwrap()];
    assert!(
        console.contains(verdict),
        "no `{verdict}` in the console:\n{console}"
    );
    let field = console
        .lines()
        .find(|l| l.starts_with("Field-like use (never fitted), mean drift, °/s: uncorrected "))
        .unwrap_or_else(|| panic!("no field-like line in\n{console}"));
    let modified_mean = md
        .lines()
        .skip_while(|l| !l.starts_with("## Field-like use"))
        .find(|l| l.starts_with("| modified |"))
        .and_then(|l| l.trim_end_matches(" |").rsplit("| ").next())
        .expect("the field table's modified row")
        .to_owned();
    assert!(
        field.contains(&format!("modified {modified_mean},")),
        "{field} against {modified_mean}"
    );
}

/// The texts of an SVG's `<text>` elements.
fn texts(svg: &str) -> Vec<&str> {
    svg.split("<text")
        .skip(1)
        .filter_map(|t| {
            let body = &t[t.find('>')? + 1..];
            Some(body[..body.find("</text>")?].trim())
        })
        .collect()
}

#[test]
fn report_prints_the_verdict_and_the_field_results_beside_the_drift_table() {
    let dir = tempfile::tempdir().unwrap();
    let campaign = simulate(dir.path());
    let report = dir.path().join("report");
    let console = ok(&["report", &campaign, "-q", "-o", report.to_str().unwrap()]);
    let md = std::fs::read_to_string(report.join("report.md")).unwrap();
    assert_console_says_what_the_report_says(&console, &md);

    // Before/after draws every standard baseline, the relative ones among them.
    let svg = std::fs::read_to_string(report.join("fig-drift-before-after.svg")).unwrap();
    let labels = texts(&svg);
    for model in [
        "uncorrected",
        "standard",
        "3rd-order",
        "relative",
        "relative-cubic",
    ] {
        assert!(labels.contains(&model), "no legend `{model}` in {labels:?}");
    }
    assert!(
        labels
            .iter()
            .any(|l| l.contains("validation activation (from 1")),
        "{labels:?}"
    );
    // No tick reads "-0.000": a zero is "0" in every figure.
    for entry in std::fs::read_dir(&report).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "svg") {
            let svg = std::fs::read_to_string(&path).unwrap();
            for label in texts(&svg) {
                if label.parse::<f64>().is_ok_and(|v| v == 0.0) {
                    assert_eq!(label, "0", "{}", path.display());
                }
            }
        }
    }
}

/// `demo` reports its campaigns as `report --noise-floor` does and prints [`demo::console`]; the
/// demo's own campaigns take minutes, so its last step runs here on the short campaign and a
/// zero-drift twin of it.
#[test]
fn demo_prints_the_verdict_and_the_field_results_beside_the_drift_table() {
    let dir = tempfile::tempdir().unwrap();
    let campaign = simulate(dir.path());
    let noise = simulate_named(dir.path(), "noise-floor", &["--zero-drift", "--seed", "6"]);
    let report = dir.path().join("report");
    let options = Options::default();
    let (_, outcome) = gyrodrift::cli::report::make(
        Path::new(&campaign),
        Some(Path::new(&noise)),
        &options,
        &report,
        Vec::new(),
        true,
    )
    .unwrap();
    let console = demo::console(&outcome, &options, &report, 1.0);
    let md = std::fs::read_to_string(report.join("report.md")).unwrap();
    assert_console_says_what_the_report_says(&console, &md);
    assert!(
        console.contains(&format!("report:  {}", report.join("report.md").display())),
        "{console}"
    );
}
