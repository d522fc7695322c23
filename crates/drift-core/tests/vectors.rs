//! The shared test vectors: the committed file is current, and the corrector reproduces it bit for
//! bit from the firmware images (what the Cortex-M4 run and the Python tests check too).
#![allow(clippy::print_stderr)]
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]
#![allow(
    clippy::arithmetic_side_effects,
    clippy::float_cmp,
    clippy::cast_possible_truncation,
    missing_docs
)]

mod common;

use common::format::{Case, VectorFile};
use drift_core::blob::{decode, Image};
use drift_core::{
    Corrector, Model, ModifiedTables, PolynomialTables, Previous, RecommendedTables, Sample,
};

const PATH: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../testdata/vectors.json");

fn load() -> VectorFile {
    if std::env::var_os("GYRODRIFT_BLESS").is_some() {
        // Another test is rewriting the file right now.
        return common::cases::build();
    }
    let text = std::fs::read_to_string(PATH)
        .expect("testdata/vectors.json (regenerate: GYRODRIFT_BLESS=1)");
    serde_json::from_str(&text).unwrap()
}

fn unhex(hex: &str) -> Vec<u8> {
    (0..hex.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&hex[i..i + 2], 16).unwrap())
        .collect()
}

#[test]
fn committed_vectors_are_current() {
    let built = common::cases::build();
    if std::env::var_os("GYRODRIFT_BLESS").is_some() {
        let text = serde_json::to_string_pretty(&built).unwrap();
        std::fs::write(PATH, text + "\n").unwrap();
    }
    assert!(load() == built, "testdata/vectors.json is stale: run GYRODRIFT_BLESS=1 cargo test -p drift-core --test vectors");
}

fn same(expected: u32, got: u32) -> bool {
    let (e, g) = (f32::from_bits(expected), f32::from_bits(got));
    expected == got || (e.is_nan() && g.is_nan())
}

fn check_case<M: Model>(model: &M, case: &Case) -> usize {
    let mut corrector = Corrector::new(model).unwrap();
    if let Some(raw) = case.switch_on_raw {
        let raw = raw.map(f32::from_bits);
        let started = match kept(case) {
            Some(mut previous) => corrector.power_on_after(raw, &mut previous),
            None => corrector.power_on(raw),
        };
        assert_eq!(started.is_err(), case.power_on_fails, "{}", case.name);
    }
    let mut mismatches = 0;
    for (i, (input, expected)) in case.samples.iter().zip(&case.expected).enumerate() {
        let sample = Sample {
            since_power_on_ms: input[0],
            rate_dps: [input[1], input[2], input[3]].map(f32::from_bits),
            temperature_raw: [input[4], input[5], input[6]].map(f32::from_bits),
        };
        let out = match case.aux.get(i) {
            Some(aux) => corrector.correct_with_aux(&sample, &aux.map(f32::from_bits)),
            None => corrector.correct(&sample),
        };
        let got: Vec<u32> = out
            .corrected_dps
            .iter()
            .chain(&out.bias_dps)
            .map(|v| v.to_bits())
            .chain(out.flags.iter().map(|f| u32::from(f.0)))
            .collect();
        for (k, (&e, &g)) in expected.iter().zip(&got).enumerate() {
            if !same(e, g) {
                mismatches += 1;
                eprintln!(
                    "{} sample {i} output {k}: expected {e:#010x}, got {g:#010x}",
                    case.name
                );
            }
        }
    }
    mismatches
}

/// The case's kept previous activation, as drift-core takes it.
fn kept(case: &Case) -> Option<[Previous; 3]> {
    case.previous.map(|kept| {
        kept.map(|[ambient, off]| Previous {
            ambient_celsius: f32::from_bits(ambient),
            switch_off_celsius: f32::from_bits(off),
        })
    })
}

fn model<M: Image>(file: &VectorFile, name: &str) -> M {
    let named = file.models.iter().find(|m| m.name == name).unwrap();
    decode::<M>(&unhex(&named.image_hex)).unwrap()
}

#[test]
fn corrector_reproduces_vectors_bit_for_bit() {
    let file = load();
    let modified: ModifiedTables = model(&file, "modified");
    let standard: PolynomialTables = model(&file, "standard");
    let third_order: PolynomialTables = model(&file, "third_order");
    let extended: ModifiedTables = model(&file, "extended");
    let by_history: ModifiedTables = model(&file, "by_history");
    assert!(by_history.axes.iter().all(|axis| axis.keyed_by_history()));
    let warm_started: ModifiedTables = model(&file, "warm_started");
    assert!(warm_started
        .axes
        .iter()
        .all(|axis| axis.warm_started() && !axis.keyed_by_history()));
    let recommended: RecommendedTables = model(&file, "recommended");
    let mut total = 0;
    let mut samples = 0;
    for case in &file.cases {
        samples += case.samples.len();
        total += match case.model.as_str() {
            "modified" => check_case(&modified, case),
            "standard" => check_case(&standard, case),
            "third_order" => check_case(&third_order, case),
            "extended" => check_case(&extended, case),
            "by_history" => check_case(&by_history, case),
            "warm_started" => check_case(&warm_started, case),
            "recommended" => check_case(&recommended, case),
            other => panic!("unknown model {other}"),
        };
    }
    assert!(samples > 1000, "too few vector samples: {samples}");
    assert_eq!(total, 0, "{total} outputs differ from the vectors");
}

#[test]
fn json_tables_equal_the_images() {
    let file = load();
    for named in &file.models {
        let bytes = unhex(&named.image_hex);
        match named.kind.as_str() {
            "modified" => {
                let from_json: ModifiedTables =
                    serde_json::from_value(named.tables.clone()).unwrap();
                assert_eq!(
                    from_json,
                    decode::<ModifiedTables>(&bytes).unwrap(),
                    "{}",
                    named.name
                );
            }
            "polynomial" => {
                let from_json: PolynomialTables =
                    serde_json::from_value(named.tables.clone()).unwrap();
                assert_eq!(
                    from_json,
                    decode::<PolynomialTables>(&bytes).unwrap(),
                    "{}",
                    named.name
                );
            }
            "recommended" => {
                let from_json: RecommendedTables =
                    serde_json::from_value(named.tables.clone()).unwrap();
                assert_eq!(
                    from_json,
                    decode::<RecommendedTables>(&bytes).unwrap(),
                    "{}",
                    named.name
                );
            }
            other => panic!("unknown kind {other}"),
        }
    }
}

#[test]
fn every_case_name_and_flag_kind_is_covered() {
    use drift_core::Flags;
    let file = load();
    let mut seen = Flags::NONE;
    for case in &file.cases {
        for expected in &case.expected {
            for flags in &expected[6..9] {
                seen |= Flags(*flags as u16);
            }
        }
    }
    for flag in [
        Flags::AMBIENT_OUT_OF_RANGE,
        Flags::RISE_OUT_OF_SPAN,
        Flags::PAST_LAST_REFERENCE,
        Flags::TEMPERATURE_OUT_OF_RANGE,
        Flags::TEMPERATURE_INVALID,
        Flags::TEMPERATURE_STUCK,
        Flags::RATE_INVALID,
        Flags::NOT_POWERED_ON,
        Flags::EXTENSION_INPUT_INVALID,
    ] {
        assert!(seen.contains(flag), "no vector exercises flag {flag:?}");
    }
}
