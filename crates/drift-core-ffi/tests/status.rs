//! The C functions' status codes on the host: each bad input gets its own, never a crash, and a
//! context is usable only after a successful `gyrodrift_init`. (The outputs themselves are checked
//! bit for bit on the Cortex-M4F by the C example: scripts/check-c-example.sh.)
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic,
    clippy::arithmetic_side_effects,
    clippy::float_cmp
)]

use drift_core_ffi::*;

fn image(name: &str) -> Vec<u8> {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../testdata/vectors.json"
    ))
    .unwrap();
    let json: serde_json::Value = serde_json::from_str(&text).unwrap();
    let model = json["models"]
        .as_array()
        .unwrap()
        .iter()
        .find(|m| m["name"] == name)
        .unwrap();
    let hex = model["image_hex"].as_str().unwrap();
    (0..hex.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&hex[i..i + 2], 16).unwrap())
        .collect()
}

fn context() -> Box<GyrodriftContext> {
    Box::new(GyrodriftContext {
        opaque: [0; GYRODRIFT_CONTEXT_BYTES],
    })
}

fn init(ctx: &mut GyrodriftContext, bytes: &[u8]) -> GyrodriftStatus {
    // SAFETY: a whole context and `bytes.len()` readable bytes.
    unsafe { gyrodrift_init(ctx, bytes.as_ptr(), bytes.len()) }
}

#[test]
fn each_bad_image_gets_its_own_status_and_leaves_the_context_unusable() {
    let mut ctx = context();
    let good = image("modified");
    let mut damaged = good.clone();
    damaged[100] ^= 1;
    let cases = [
        (vec![0xff; 64], GyrodriftStatus::Erased),
        (b"NOPE and more bytes".to_vec(), GyrodriftStatus::BadHeader),
        (image("standard"), GyrodriftStatus::WrongKind),
        (good[..good.len() - 1].to_vec(), GyrodriftStatus::BadLength),
        (damaged, GyrodriftStatus::CrcMismatch),
    ];
    let sample = GyrodriftSample::default();
    let mut out = GyrodriftOutput::default();
    for (bytes, expected) in cases {
        assert_eq!(init(&mut ctx, &good), GyrodriftStatus::Ok);
        assert_eq!(init(&mut ctx, &bytes), expected);
        // SAFETY: valid pointers to a context, a sample and an output.
        let status = unsafe { gyrodrift_correct(&mut *ctx, &sample, &mut out) };
        assert_eq!(status, GyrodriftStatus::NotInitialised);
    }
}

#[test]
fn a_ready_context_corrects_and_null_pointers_are_errors() {
    let mut ctx = context();
    let sample = GyrodriftSample {
        since_power_on_ms: 1000,
        rate_dps: [0.5, 0.0, 0.0],
        temperature_raw: [6600.0; 3],
    };
    let mut out = GyrodriftOutput::default();
    // SAFETY: every pointer is null or valid for what the function reads or writes.
    unsafe {
        assert_eq!(
            gyrodrift_correct(&mut *ctx, &sample, &mut out),
            GyrodriftStatus::NotInitialised
        );
        assert_eq!(
            gyrodrift_init(core::ptr::null_mut(), [0u8].as_ptr(), 1),
            GyrodriftStatus::NullPointer
        );
        assert_eq!(init(&mut ctx, &image("recommended")), GyrodriftStatus::Ok);
        assert_eq!(
            gyrodrift_correct(&mut *ctx, core::ptr::null(), &mut out),
            GyrodriftStatus::NullPointer
        );
        // Before a power-on the rate passes through, flagged.
        assert_eq!(
            gyrodrift_correct(&mut *ctx, &sample, &mut out),
            GyrodriftStatus::Ok
        );
        assert_eq!(out.corrected_dps[0], 0.5);
        assert_ne!(out.flags[0], 0);
        let nan = [f32::NAN; 3];
        assert_eq!(
            gyrodrift_power_on(&mut *ctx, nan.as_ptr(), core::ptr::null_mut()),
            GyrodriftStatus::BadSwitchOn
        );
        let mut flags = [u16::MAX; 3];
        let mut previous = [GyrodriftPrevious {
            ambient_celsius: f32::NAN,
            switch_off_celsius: f32::NAN,
        }; 3];
        let raw = [6600.0_f32; 3];
        assert_eq!(
            gyrodrift_power_on_after(
                &mut *ctx,
                raw.as_ptr(),
                previous.as_mut_ptr(),
                flags.as_mut_ptr()
            ),
            GyrodriftStatus::Ok
        );
        assert!(previous[0].ambient_celsius.is_finite());
        assert_eq!(
            gyrodrift_correct(&mut *ctx, &sample, &mut out),
            GyrodriftStatus::Ok
        );
        assert!(out.corrected_dps[0].is_finite());
        assert_eq!(
            gyrodrift_keep(&mut *ctx, previous.as_mut_ptr()),
            GyrodriftStatus::Ok
        );
        assert_eq!(previous[0].switch_off_celsius, 33.0);
        assert_eq!(gyrodrift_power_off(&mut *ctx), GyrodriftStatus::Ok);
    }
}

#[test]
fn counts_with_the_missing_sentinel_make_a_sample() {
    let mut sample = GyrodriftSample::default();
    let rate = [0.1_f32, 0.2, 0.3];
    let counts = [6600_i16, GYRODRIFT_MISSING_TEMPERATURE, -40];
    // SAFETY: three values each, and a sample to write.
    let status =
        unsafe { gyrodrift_sample_from_counts(5, rate.as_ptr(), counts.as_ptr(), &mut sample) };
    assert_eq!(status, GyrodriftStatus::Ok);
    assert_eq!(sample.temperature_raw[0], 6600.0);
    assert!(sample.temperature_raw[1].is_nan());
    assert_eq!(sample.rate_dps, rate);
}

#[test]
fn the_large_profile_takes_the_same_images() {
    let mut large = Box::new(GyrodriftLargeContext {
        opaque: [0; GYRODRIFT_LARGE_CONTEXT_BYTES],
    });
    let bytes = image("by_history");
    let raw = [6600.0_f32; 3];
    let mut out = GyrodriftOutput::default();
    let sample = GyrodriftSample {
        since_power_on_ms: 1000,
        rate_dps: [0.5; 3],
        temperature_raw: raw,
    };
    // SAFETY: a whole large context, the image's bytes, three readable floats, a sample and an
    // output.
    unsafe {
        assert_eq!(
            gyrodrift_large_init(&mut *large, bytes.as_ptr(), bytes.len()),
            GyrodriftStatus::Ok
        );
        assert_eq!(
            gyrodrift_large_power_on(&mut *large, raw.as_ptr(), core::ptr::null_mut()),
            GyrodriftStatus::Ok
        );
        assert_eq!(
            gyrodrift_large_correct(&mut *large, &sample, &mut out),
            GyrodriftStatus::Ok
        );
    }
    assert!(out.corrected_dps[0].is_finite());
}

#[test]
fn a_measured_ambient_starts_where_the_tables_read_it_and_a_bad_one_is_refused() {
    let mut ctx = context();
    let sample = GyrodriftSample {
        since_power_on_ms: 20_000,
        rate_dps: [0.5, 0.0, 0.0],
        temperature_raw: [6700.0; 3],
    };
    let raw = [6600.0_f32; 3];
    let mut flags = [0u16; 3];
    let run = |start: &dyn Fn(&mut GyrodriftContext) -> GyrodriftStatus| {
        let mut ctx = context();
        assert_eq!(init(&mut ctx, &image("modified")), GyrodriftStatus::Ok);
        assert_eq!(start(&mut ctx), GyrodriftStatus::Ok);
        let mut out = GyrodriftOutput::default();
        // SAFETY: valid pointers to a context, a sample and an output.
        let status = unsafe { gyrodrift_correct(&mut *ctx, &sample, &mut out) };
        assert_eq!(status, GyrodriftStatus::Ok);
        out.bias_dps
    };
    let paper = run(&|ctx| {
        // SAFETY: valid pointers to a context and three readings; null flags.
        unsafe { gyrodrift_power_on(ctx, raw.as_ptr(), core::ptr::null_mut()) }
    });
    let at = |ambient: f32| {
        move |ctx: &mut GyrodriftContext| {
            // SAFETY: valid pointers to a context and three readings; null flags.
            unsafe {
                gyrodrift_power_on_at_ambient(ctx, raw.as_ptr(), ambient, core::ptr::null_mut())
            }
        }
    };
    // The switch-on temperature of 6600 raw units: a start at that ambient is the paper's.
    let celsius = drift_core::Settings::default().celsius(raw[0]);
    assert_eq!(run(&at(celsius)), paper, "at {celsius} °C");
    assert_ne!(run(&at(celsius - 3.0)), paper);
    assert_eq!(init(&mut ctx, &image("modified")), GyrodriftStatus::Ok);
    let mut previous = [GyrodriftPrevious {
        ambient_celsius: f32::NAN,
        switch_off_celsius: f32::NAN,
    }; 3];
    // SAFETY: valid pointers to a context, three readings, three kept entries and three flags.
    unsafe {
        assert_eq!(
            gyrodrift_power_on_at_ambient(&mut *ctx, raw.as_ptr(), f32::NAN, flags.as_mut_ptr()),
            GyrodriftStatus::BadAmbient
        );
        assert_eq!(
            gyrodrift_power_on_after_at_ambient(
                &mut *ctx,
                raw.as_ptr(),
                f32::INFINITY,
                previous.as_mut_ptr(),
                flags.as_mut_ptr()
            ),
            GyrodriftStatus::BadAmbient
        );
        assert!(previous[0].ambient_celsius.is_nan(), "previous unchanged");
        assert_eq!(
            gyrodrift_power_on_after_at_ambient(
                &mut *ctx,
                raw.as_ptr(),
                29.0,
                previous.as_mut_ptr(),
                flags.as_mut_ptr()
            ),
            GyrodriftStatus::Ok
        );
        assert_eq!(previous[0].ambient_celsius, 29.0);
    }
}
