//! Turns `testdata/vectors.json` into firmware data: the model images as binary files and the cases
//! as `static` arrays, so the MCU decodes the very bytes the host tests decode.

use std::fmt::Write as _;
use std::path::PathBuf;

#[path = "../crates/drift-core/tests/common/format.rs"]
#[allow(dead_code)]
mod format;

#[path = "../crates/drift-core/tests/common/sigma_format.rs"]
#[allow(dead_code)]
mod sigma_format;

#[path = "../crates/drift-core/tests/common/stillness_format.rs"]
#[allow(dead_code)]
mod stillness_format;

fn unhex(hex: &str) -> Vec<u8> {
    (0..hex.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&hex[i..i + 2], 16).expect("hex image"))
        .collect()
}

fn main() {
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("OUT_DIR"));
    std::fs::copy("memory.x", out.join("memory.x")).expect("memory.x");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=../testdata/vectors.json");

    let text = std::fs::read_to_string("../testdata/vectors.json").expect("testdata/vectors.json");
    let file: format::VectorFile = serde_json::from_str(&text).expect("vector file");
    let mut code = String::new();
    for model in &file.models {
        let path = out.join(format!("{}.bin", model.name));
        std::fs::write(&path, unhex(&model.image_hex)).expect("write image");
        writeln!(
            code,
            "pub static {}: &[u8] = include_bytes!({:?});",
            model.name.to_uppercase(),
            path.display().to_string()
        )
        .unwrap();
    }
    writeln!(code, "pub static CASES: &[Case] = &[").unwrap();
    for case in &file.cases {
        let model = match case.model.as_str() {
            "modified" => "ModelName::Modified",
            "standard" => "ModelName::Standard",
            "third_order" => "ModelName::ThirdOrder",
            "extended" => "ModelName::Extended",
            "by_history" => "ModelName::ByHistory",
            "warm_started" => "ModelName::WarmStarted",
            "recommended" => "ModelName::Recommended",
            other => panic!("unknown model {other}"),
        };
        writeln!(
            code,
            "Case {{ name: {:?}, model: {model}, switch_on_raw: {:?}, previous: {:?}, power_on_fails: {}, samples: &{:?}, expected: &{:?}, aux: &{:?} }},",
            case.name, case.switch_on_raw, case.previous, case.power_on_fails, case.samples, case.expected, case.aux
        )
        .unwrap();
    }
    writeln!(code, "];").unwrap();

    println!("cargo:rerun-if-changed=../testdata/sigma-vectors.json");
    let text = std::fs::read_to_string("../testdata/sigma-vectors.json")
        .expect("testdata/sigma-vectors.json");
    let sigma: sigma_format::SigmaVectors = serde_json::from_str(&text).expect("σ(t) vector file");
    let path = out.join("sigma.bin");
    std::fs::write(&path, unhex(&sigma.section_hex)).expect("write σ(t) section");
    writeln!(
        code,
        "pub static SIGMA_SECTION: &[u8] = include_bytes!({:?});",
        path.display().to_string()
    )
    .unwrap();
    writeln!(code, "pub static SIGMA_CASES: &[SigmaCase] = &[").unwrap();
    for case in &sigma.cases {
        writeln!(
            code,
            "SigmaCase {{ name: {:?}, switch_on_celsius: {:?}, previous: {:?}, times_ms: &{:?}, expected: &{:?} }},",
            case.name, case.switch_on_celsius, case.previous, case.times_ms, case.expected
        )
        .unwrap();
    }
    writeln!(code, "];").unwrap();

    println!("cargo:rerun-if-changed=../testdata/stillness-vectors.json");
    let text = std::fs::read_to_string("../testdata/stillness-vectors.json")
        .expect("testdata/stillness-vectors.json");
    let stillness: stillness_format::StillnessVectors =
        serde_json::from_str(&text).expect("stillness vector file");
    writeln!(code, "pub static STILLNESS_CASES: &[StillnessCase] = &[").unwrap();
    for case in &stillness.cases {
        writeln!(
            code,
            "StillnessCase {{ name: {:?}, settings: {:?}, start_offset: {:?}, accel_every: {}, accel: &{:?}, rate: &{:?}, expected: &{:?}, states: &{:?}, final_offset: {:?} }},",
            case.name,
            case.settings,
            case.start_offset,
            case.accel_every,
            case.accel,
            case.rate,
            case.expected,
            case.states,
            case.final_offset
        )
        .unwrap();
    }
    writeln!(code, "];").unwrap();
    std::fs::write(out.join("vectors.rs"), code).expect("write vectors.rs");
}
