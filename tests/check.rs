//! `gyrodrift check`: a unit's stored tables pass on its own recordings, fail on another unit's or
//! against tight limits (exit status 1, the report still written); another unit's image and
//! missing tables are named (exit status 2). `gyrodrift export image` provisions the same tables.

use std::path::Path;

mod common;

use common::{gyrodrift, ok};
use drift_core::blob::decode;
use drift_core::RecommendedTables;

fn path(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// `gyrodrift check <campaign> --tables <tables> -q -o <out> <extra…>`.
fn check(
    campaign: &Path,
    tables: &Path,
    out: &Path,
    extra: &[&str],
) -> (std::process::Output, String) {
    let mut args = vec![
        "check",
        path(campaign),
        "--tables",
        path(tables),
        "-q",
        "-o",
        path(out),
    ];
    args.extend_from_slice(extra);
    gyrodrift(&args)
}

fn verdicts(json: &Path) -> Vec<(String, bool)> {
    let value: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap();
    value["units"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|unit| {
            let id = unit["unit_id"].as_str().unwrap().to_owned();
            unit["axes"]
                .as_array()
                .unwrap()
                .iter()
                .map(move |axis| (id.clone(), axis["failures"].as_array().unwrap().is_empty()))
        })
        .collect()
}

#[test]
fn stored_tables_pass_on_their_unit_and_fail_on_another() {
    let dir = tempfile::tempdir().unwrap();
    let campaign = dir.path().join("campaign");
    ok(&[
        "simulate",
        "-q",
        "-o",
        path(&campaign),
        "--units",
        "2",
        "--set-points",
        "30,40",
        "--intervals",
        "1,30",
        "--repeats",
        "2",
        "--seed",
        "5",
    ]);
    let tables = dir.path().join("tables");
    ok(&["fit", path(&campaign), "-q", "-o", path(&tables)]);

    // Each unit's own tables on its own recordings: the recommended image unless told.
    let report = dir.path().join("check");
    let (out, text) = check(&campaign, &tables, &report, &[]);
    assert!(out.status.success(), "{text}");
    assert!(text.contains("| GIU-02 | Z | 40 |"), "{text}");
    // The share outside the calibrated envelope, per unit, over activations × axes and samples.
    assert!(
        text.contains("GIU-02: outside the calibrated envelope: ") && text.contains(" of 120), "),
        "{text}"
    );
    let own = verdicts(&report.join("check.json"));
    assert_eq!(own.len(), 6);
    assert!(own.iter().all(|(_, passed)| *passed), "{own:?}");
    let json = std::fs::read_to_string(report.join("check.json")).unwrap();
    assert!(json.contains("GIU-01/recommended.bin"), "{json}");
    // The paper's tables, asked for by name, pass too.
    let paper = dir.path().join("paper");
    let (out, text) = check(&campaign, &tables, &paper, &["--model", "modified"]);
    assert!(out.status.success(), "{text}");
    let json = std::fs::read_to_string(paper.join("check.json")).unwrap();
    assert!(json.contains("GIU-01/modified.bin"), "{json}");
    assert!(verdicts(&paper.join("check.json")).iter().all(|(_, p)| *p));

    // The same, with a drift limit no unit can meet: exit status 1, report written, axes named.
    let tight = dir.path().join("tight");
    let (out, text) = check(&campaign, &tables, &tight, &["--max-drift", "0.0001"]);
    assert_eq!(out.status.code(), Some(1), "{text}");
    assert!(
        text.contains("misses the limits on 6 of 6 unit × axis: GIU-01 X, GIU-01 Y"),
        "{text}"
    );
    let md = std::fs::read_to_string(tight.join("check.md")).unwrap();
    assert!(md.contains("**fail**: drift left"), "{md}");

    // GIU-01's image in GIU-02's folder: its header names GIU-01, so check refuses it (exit
    // status 2), naming both units, and writes nothing.
    let swapped = dir.path().join("swapped");
    for unit in ["GIU-01", "GIU-02"] {
        std::fs::create_dir_all(swapped.join(unit)).unwrap();
        std::fs::copy(
            tables.join("GIU-01/recommended.bin"),
            swapped.join(unit).join("recommended.bin"),
        )
        .unwrap();
    }
    let refused = dir.path().join("refused");
    let (out, text) = check(&campaign, &swapped, &refused, &[]);
    assert_eq!(out.status.code(), Some(2), "{text}");
    assert!(
        text.contains("GIU-02/recommended.bin: this image is unit GIU-01's")
            && text.contains("records unit GIU-02"),
        "{text}"
    );
    assert!(!refused.exists());

    // GIU-01's tables in an image that names no unit, flashed into GIU-02: GIU-02 fails, GIU-01
    // still passes.
    let own: RecommendedTables =
        decode(&std::fs::read(tables.join("GIU-01/recommended.bin")).unwrap()).unwrap();
    let anonymous = drift_evaluate::tables_folder::image_bytes(&own).unwrap();
    for unit in ["GIU-01", "GIU-02"] {
        std::fs::write(swapped.join(unit).join("recommended.bin"), &anonymous).unwrap();
    }
    let wrong = dir.path().join("wrong");
    let (out, text) = check(&campaign, &swapped, &wrong, &[]);
    assert_eq!(out.status.code(), Some(1), "{text}");
    assert!(text.contains(": GIU-02 "), "{text}");
    let swapped_verdicts = verdicts(&wrong.join("check.json"));
    let failed = |unit: &str| {
        swapped_verdicts
            .iter()
            .filter(|(u, passed)| u == unit && !passed)
            .count()
    };
    // Units differ most in their offsets and temperature coefficients; at least two of GIU-02's
    // axes are far off with GIU-01's tables (seed 5: RMS 0.18 and 0.25 °/s on Y and Z).
    assert_eq!(failed("GIU-01"), 0, "{swapped_verdicts:?}");
    assert!(failed("GIU-02") >= 2, "{swapped_verdicts:?}");

    // A unit without stored tables: the error names the file it looked for; nothing written.
    std::fs::remove_dir_all(swapped.join("GIU-02")).unwrap();
    let missing = dir.path().join("missing");
    let (out, text) = check(&campaign, &swapped, &missing, &[]);
    // Exit status 2: check could not run, which is not "the calibration is invalid" (1).
    assert_eq!(out.status.code(), Some(2), "{text}");
    assert!(text.contains("GIU-02/recommended.bin"), "{text}");
    assert!(!missing.exists());

    // A limit that means nothing is refused before anything is read.
    let (out, text) = check(&campaign, &tables, &missing, &["--max-rms", "-1"]);
    assert_eq!(out.status.code(), Some(2), "{text}");
    assert!(
        text.contains("--max-rms must be a finite number ≥ 0, got -1"),
        "{text}"
    );
    assert!(!missing.exists());

    // The baselines are checked the same way, to a verdict (0 or 1, never "check broken"). The
    // absolute standard polynomial may even add drift on this unit (its capsule lags the sensor the
    // polynomial reads), so only that the check ran is asserted, with loose limits.
    let standard = dir.path().join("standard");
    let loose = [
        "--model",
        "standard",
        "--max-drift",
        "1",
        "--max-rms",
        "1",
        "--min-removed",
        "0",
    ];
    let ran = |out: &std::process::Output, text: &str, folder: &Path| {
        assert!(matches!(out.status.code(), Some(0 | 1)), "{text}");
        assert_eq!(verdicts(&folder.join("check.json")).len(), 6, "{text}");
    };
    let (out, text) = check(&campaign, &tables, &standard, &loose);
    ran(&out, &text, &standard);
    // The relative baseline runs its own image (kind 3), with the switch-on bias it registers.
    let relative = dir.path().join("relative");
    let mut relative_args = loose;
    relative_args[1] = "relative";
    let (out, text) = check(&campaign, &tables, &relative, &relative_args);
    ran(&out, &text, &relative);
    assert_ne!(
        std::fs::read(relative.join("check.json")).unwrap(),
        std::fs::read(standard.join("check.json")).unwrap(),
        "the relative baseline was checked with the standard one's image"
    );

    // Provisioning: one image per unit, each naming its unit, a manifest, Intel HEX at an address.
    let images = dir.path().join("images");
    let text = ok(&[
        "export",
        "image",
        path(&tables),
        "-o",
        path(&images),
        "--address",
        "0x08060000",
    ]);
    assert!(text.contains("2 units' recommended images"), "{text}");
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(images.join("manifest.json")).unwrap())
            .unwrap();
    assert_eq!(manifest["address"], "0x08060000");
    for (entry, unit) in manifest["units"]
        .as_array()
        .unwrap()
        .iter()
        .zip(["GIU-01", "GIU-02"])
    {
        assert_eq!(entry["unit_id"], unit);
        let bytes = std::fs::read(images.join(format!("{unit}.bin"))).unwrap();
        assert_eq!(
            bytes,
            std::fs::read(tables.join(unit).join("recommended.bin")).unwrap()
        );
        assert_eq!(entry["bytes"], bytes.len());
        let header = drift_core::blob::header(&bytes).unwrap();
        assert_eq!(header.provenance.unit_id.as_str(), unit);
        assert_eq!(entry["capacities"]["curves"], header.needs.unwrap().curves);
        let hex = std::fs::read_to_string(images.join(format!("{unit}.hex"))).unwrap();
        assert!(hex.starts_with(":020000040806"), "{hex}");
    }
    // A unit's folder holding another unit's image is refused, naming both; nothing is made.
    for unit in ["GIU-01", "GIU-02"] {
        std::fs::create_dir_all(swapped.join(unit)).unwrap();
        std::fs::copy(
            tables.join("GIU-01/recommended.bin"),
            swapped.join(unit).join("recommended.bin"),
        )
        .unwrap();
    }
    let none = dir.path().join("none");
    let (out, text) = gyrodrift(&["export", "image", path(&swapped), "-o", path(&none)]);
    assert_eq!(out.status.code(), Some(2), "{text}");
    assert!(
        text.contains("this image is unit GIU-01's, but it sits in unit GIU-02's folder"),
        "{text}"
    );
    assert!(!none.exists());
}
