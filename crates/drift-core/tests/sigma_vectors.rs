//! The σ(t) test vectors: the committed file is current, and drift-core reproduces it bit for bit
//! from the firmware section (what the Cortex-M4 run checks too, `embedded/`).
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::arithmetic_side_effects,
    missing_docs
)]

#[path = "common/sigma_format.rs"]
mod sigma_format;

use drift_core::blob::{decode_section, encode_section, section_len};
use drift_core::{Previous, SwitchOn, Uncertainty};
use sigma_format::{SigmaCase, SigmaVectors};

const PATH: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../testdata/sigma-vectors.json"
);

/// Uneven values, so that rounding in the interpolation is exercised.
fn uncertainty() -> Uncertainty {
    Uncertainty {
        knots_ms: [0, 2_000, 5_000, 10_000, 20_000, 40_000, 80_000, 160_000],
        sigma_dps: [
            [
                0.003_71, 0.002_93, 0.002_17, 0.001_83, 0.001_51, 0.001_32, 0.001_19, 0.001_07,
            ],
            [
                0.006_13, 0.004_77, 0.003_39, 0.002_61, 0.002_03, 0.001_71, 0.001_43, 0.001_29,
            ],
        ],
        warm_above_celsius: 0.5,
        ambient_min_celsius: 30.0,
        ambient_max_celsius: 40.0,
        per_celsius_outside_dps: 0.000_37,
        most_residual_heat_celsius: [4.5, 5.0, 4.25],
        per_residual_celsius_beyond_dps: 0.001_23,
    }
}

const TIMES_MS: [u32; 14] = [
    0,
    1,
    999,
    2_000,
    3_517,
    7_777,
    15_001,
    39_999,
    60_000,
    159_999,
    160_000,
    3_600_000,
    u32::MAX - 1,
    u32::MAX,
];

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

fn unhex(hex: &str) -> Vec<u8> {
    (0..hex.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&hex[i..i + 2], 16).unwrap())
        .collect()
}

/// What was kept of the previous activation, per axis `[ambient, switch-off]` (f32 bits).
type Kept = Option<[[u32; 2]; 3]>;

fn kept(previous: Kept) -> Option<[Previous; 3]> {
    previous.map(|p| {
        p.map(|[ambient, off]| Previous {
            ambient_celsius: f32::from_bits(ambient),
            switch_off_celsius: f32::from_bits(off),
        })
    })
}

/// What firmware computes: the switch-on estimate per axis, the class and distance, σ per time.
fn run(
    u: &Uncertainty,
    switch_on_celsius: [u32; 3],
    previous: Option<[[u32; 2]; 3]>,
    times: &[u32],
) -> Vec<[u32; 3]> {
    let kept = kept(previous);
    let switch_on: [SwitchOn; 3] = std::array::from_fn(|a| {
        SwitchOn::estimate(f32::from_bits(switch_on_celsius[a]), kept.map(|k| k[a]))
    });
    let state = u.start(&switch_on);
    times
        .iter()
        .map(|&ms| u.sigma_dps(&state, ms).map(f32::to_bits))
        .collect()
}

fn build() -> SigmaVectors {
    let u = uncertainty();
    let mut section = vec![0; section_len(&u).unwrap()];
    let n = encode_section(&u, &mut section).unwrap();
    section.truncate(n);
    let bits = |v: [f32; 3]| v.map(f32::to_bits);
    let previous = |ambient: f32, off: f32| Some([[ambient.to_bits(), off.to_bits()]; 3]);
    let cases: [(&str, [u32; 3], Kept); 7] = [
        ("cold inside the envelope", bits([33.0, 33.25, 32.9]), None),
        (
            "warm restart, 4 °C residual heat",
            bits([34.0, 34.1, 33.8]),
            previous(30.0, 36.0),
        ),
        (
            "residual heat at the class threshold and just above",
            bits([30.5, 30.500_03, 30.4]),
            previous(30.0, 36.0),
        ),
        (
            "cold below and above the envelope",
            bits([24.3, 41.7, 40.0]),
            None,
        ),
        (
            "warm restart outside the envelope",
            bits([45.0, 45.0, 45.0]),
            previous(42.0, 48.0),
        ),
        (
            "warm restart beyond the calibrated residual heat",
            bits([40.0, 41.3, 39.2]),
            previous(30.0, 45.0),
        ),
        (
            "no temperature at switch-on",
            bits([f32::NAN, f32::INFINITY, f32::NEG_INFINITY]),
            None,
        ),
    ];
    SigmaVectors {
        section_hex: hex(&section),
        cases: cases
            .into_iter()
            .map(|(name, switch_on_celsius, previous)| SigmaCase {
                name: name.into(),
                switch_on_celsius,
                previous,
                times_ms: TIMES_MS.to_vec(),
                expected: run(&u, switch_on_celsius, previous, &TIMES_MS),
            })
            .collect(),
    }
}

#[test]
fn committed_sigma_vectors_are_current_and_reproduced_from_the_section() {
    let built = build();
    if std::env::var_os("GYRODRIFT_BLESS").is_some() {
        let text = serde_json::to_string_pretty(&built).unwrap();
        std::fs::write(PATH, text + "\n").unwrap();
    }
    let text = std::fs::read_to_string(PATH)
        .expect("testdata/sigma-vectors.json (regenerate: GYRODRIFT_BLESS=1)");
    let file: SigmaVectors = serde_json::from_str(&text).unwrap();
    assert!(
        file == built,
        "testdata/sigma-vectors.json is stale: run GYRODRIFT_BLESS=1 cargo test -p drift-core --test sigma_vectors"
    );
    let u = decode_section(&unhex(&file.section_hex)).unwrap();
    for case in &file.cases {
        let got = run(&u, case.switch_on_celsius, case.previous, &case.times_ms);
        assert_eq!(got, case.expected, "{}", case.name);
        for sigma in got.iter().flatten() {
            let sigma = f32::from_bits(*sigma);
            assert!(sigma.is_finite() && sigma >= 0.0, "{}: {sigma}", case.name);
        }
    }
}
