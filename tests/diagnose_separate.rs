//! `gyrodrift diagnose --calibration-data A --evaluation-data B`: the closed loop fits, chooses and
//! ranks on one source and judges on another. Its choices and ranking are those of `diagnose A`
//! (they come from A's calibration and training activations only), and every held-out activation
//! is one of B's; evaluation data of other units is refused.

use std::path::Path;

use drift_recording::read_campaign_dir;

mod common;

use common::{gyrodrift, ok};

fn simulate(dir: &Path, name: &str, seed: u32, set_points: &str) -> String {
    let toml = dir.join(format!("{name}.toml"));
    std::fs::write(
        &toml,
        format!(
            "seed = {seed}\nunits = 1\nsample_rate_hz = 100\nset_points_celsius = [{set_points}]\n\
             [protocol]\nintervals_min = [1, 30]\nrepeats = 2\nactivation_s = 60\n\
             [field]\nsessions = 1\nactivations = 3\nactivation_s = [30, 60]\n"
        ),
    )
    .unwrap();
    let out = dir.join(name);
    ok(&[
        "simulate",
        "-q",
        "--campaign",
        toml.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    out.to_str().unwrap().to_owned()
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

#[test]
fn diagnose_fits_and_ranks_on_one_source_and_judges_on_another() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let a = simulate(d, "calibration", 3, "30, 40, 33");
    let b = simulate(d, "evaluation", 3, "33, 35");
    let separate = d.join("separate");
    let (out, text) = gyrodrift(&[
        "diagnose",
        "-q",
        "--calibration-data",
        &a,
        "--evaluation-data",
        &b,
        "-o",
        separate.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{text}");
    let evaluated: usize = read_campaign_dir(Path::new(&b))
        .unwrap()
        .iter()
        .map(|r| r.segments.len())
        .sum();
    assert!(
        text.contains(&format!(
            "held out: {evaluated} activations of the evaluation data {b}"
        )),
        "{text}"
    );
    let md = std::fs::read_to_string(separate.join("diagnosis.md")).unwrap();
    assert!(
        md.contains(&format!(
            "Held out: the {evaluated} activations of the evaluation data `{b}`"
        )),
        "{md}"
    );
    // Every held-out activation is one of B's: at B's set points, one profile each.
    let unit = &json(&separate.join("diagnosis.json"))[0];
    let profiles = unit["profiles"].as_array().unwrap();
    assert_eq!(profiles.len(), evaluated);
    let at = |p: &serde_json::Value| p["set_point_celsius"].as_f64().unwrap();
    assert!(profiles.iter().any(|p| at(p) == 35.0));
    assert!(profiles.iter().all(|p| at(p) == 33.0 || at(p) == 35.0));
    // The choices and the ranking are A's alone: the same as diagnosing A by itself.
    let alone = d.join("alone");
    ok(&["diagnose", "-q", &a, "-o", alone.to_str().unwrap()]);
    let alone = &json(&alone.join("diagnosis.json"))[0];
    for key in ["stage3", "warm_start", "axes"] {
        assert_eq!(unit[key], alone[key], "{key}");
    }
    assert_ne!(unit["profiles"], alone["profiles"]);

    // Evaluation data of another unit: refused, naming both.
    let toml = d.join("other.toml");
    std::fs::write(&toml, "seed = 3\nunits = 2\nsample_rate_hz = 100\nset_points_celsius = [33]\n[protocol]\nintervals_min = [1]\nrepeats = 1\nactivation_s = 10\n").unwrap();
    let other = d.join("other");
    ok(&[
        "simulate",
        "-q",
        "--campaign",
        toml.to_str().unwrap(),
        "-o",
        other.to_str().unwrap(),
    ]);
    // Keep only the second unit's recordings.
    let first_unit = read_campaign_dir(Path::new(&a)).unwrap()[0].unit_id.clone();
    for entry in std::fs::read_dir(other.join("recordings")).unwrap() {
        let path = entry.unwrap().path();
        if path
            .file_name()
            .unwrap()
            .to_string_lossy()
            .starts_with(&first_unit)
        {
            std::fs::remove_file(path).unwrap();
        }
    }
    let (out, text) = gyrodrift(&[
        "diagnose",
        "-q",
        "--calibration-data",
        &a,
        "--evaluation-data",
        other.to_str().unwrap(),
        "-o",
        d.join("refused").to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2), "{text}");
    assert!(
        text.contains("are none of the units fitted on the calibration data")
            && text.contains(&first_unit),
        "{text}"
    );
}

/// `--diagnosis-data`: another source's series are the diagnosis data, cross-fitted by series.
/// Each half ranks on its own series and is judged on the other's (every activation of the
/// diagnosis data is in exactly one half's diagnosis), both halves are reported with whether they
/// agree, and nothing of the calibration source's protocol is diagnosed.
#[test]
fn diagnosis_data_are_cross_fitted_by_series() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let a = simulate(d, "campaign", 5, "30, 40, 33");
    let b = simulate(d, "diagnosis", 5, "33");
    let out_dir = d.join("crossfit");
    let (out, text) = gyrodrift(&[
        "diagnose",
        "-q",
        &a,
        "--calibration",
        "30,40",
        "--diagnosis-data",
        &b,
        "-o",
        out_dir.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{text}");
    let md = std::fs::read_to_string(out_dir.join("diagnosis.md")).unwrap();
    for needle in ["half 1 of 2", "half 2 of 2", "do the halves agree?"] {
        assert!(md.contains(needle), "no `{needle}` in {md}");
    }
    let halves = json(&out_dir.join("diagnosis.json"));
    let halves = halves.as_array().unwrap();
    assert_eq!(halves.len(), 2, "{halves:#?}");
    assert_eq!(halves[0]["half"], 0);
    assert_eq!(halves[1]["half"], 1);
    // Every activation of the diagnosis data is ranked by one half or the other, never by both.
    let named: u64 = read_campaign_dir(Path::new(&b))
        .unwrap()
        .iter()
        .map(|r| r.segments.len() as u64)
        .sum();
    let diagnosed: Vec<u64> = halves
        .iter()
        .map(|h| h["axes"][0]["activations"].as_u64().unwrap())
        .collect();
    let training = |h: &serde_json::Value| h["stage3"][0]["training_activations"].as_u64().unwrap();
    let own = |i: usize| diagnosed[i] - training(&halves[i]);
    assert_eq!(own(0) + own(1), named, "{diagnosed:?}");
    assert!(own(0) > 0 && own(1) > 0, "{diagnosed:?}");
}
