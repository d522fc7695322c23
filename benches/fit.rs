//! Fitting a whole campaign, the way `gyrodrift fit` does: from the recordings (read + analyse +
//! fit), the reading alone (the fit should cost at most 1.1× the reading: the analysis and all but
//! the last unit's fit run while the recordings are decoded), and the fit alone from
//! already-analysed activations — one group, so the ratios come from one run.
//!
//! The campaign is simulated in set-up (untimed). Full runs (`cargo bench --bench fit`) use the
//! default (paper's) campaign: 2 units, of which the fit decodes the +30/+40 °C calibration
//! recordings, 50.4 M samples. In criterion's `--test` mode (`cargo bench -- --test`, run by
//! scripts/check.sh) a small campaign of 240 000 samples is used instead, so the binary finishes in
//! seconds on 2 cores.
//!
//! Throughput is in calibration samples (what the fit reads), for every bench of the group.

#[path = "common/campaign.rs"]
mod campaign;

use std::collections::BTreeMap;
use std::hint::black_box;
use std::path::PathBuf;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use drift_evaluate::pipeline::{self, Options};
use drift_fit::analyse::Analysed;
use drift_fit::{fit_unit, FitSettings};
use drift_recording::OpenRecording;

fn options() -> Options {
    // `gyrodrift fit`'s options: default settings, +30/+40 °C, no evaluation pass.
    Options {
        calibration_set_points: vec![30.0, 40.0],
        validation_set_points: Vec::new(),
        fit: FitSettings::default(),
        held_out_repeats: false,
        evaluate: false,
        switch_on_ambient: None,
    }
}

/// What the fit reads, read the way the pipeline reads it (each file once: its metadata, then the
/// calibration files decoded and validated activation by activation), and nothing else. Returns
/// the samples read.
fn read_only(files: &[PathBuf], options: &Options) -> u64 {
    let mut samples = 0;
    for path in files {
        let file = OpenRecording::open(path).expect("metadata");
        if pipeline::calibration_metadata(file.metadata(), options) == Some(false) {
            continue;
        }
        file.for_each_activation(|activation| {
            samples += black_box(activation).len() as u64;
            true
        })
        .expect("read");
    }
    samples
}

fn bench(c: &mut Criterion) {
    let quick = campaign::quick();
    let simulated = campaign::simulate(&if quick {
        campaign::small_fit_campaign()
    } else {
        campaign::default_campaign()
    });
    let options = options();
    let outcome =
        pipeline::run(&simulated.files, &options, false, drift_recording::QUIET).expect("fit");
    let samples = outcome.samples_read;
    let mut by_unit: BTreeMap<String, Vec<Analysed>> = BTreeMap::new();
    for a in outcome.calibration {
        by_unit.entry(a.labels.unit_id.clone()).or_default().push(a);
    }

    let mut group = c.benchmark_group("fit_campaign");
    group.throughput(Throughput::Elements(samples));
    group.sample_size(10);
    if !quick {
        // One read-analyse-fit iteration of the default campaign takes several seconds.
        group.measurement_time(Duration::from_secs(60));
    }
    group.bench_function("read_only", |b| {
        b.iter(|| read_only(black_box(&simulated.files), &options))
    });
    group.bench_function("read_analyse_fit", |b| {
        b.iter(|| {
            pipeline::run(
                black_box(&simulated.files),
                &options,
                false,
                drift_recording::QUIET,
            )
            .expect("fit")
            .fitted
        })
    });
    group.bench_function("fit_from_analysed", |b| {
        b.iter(|| {
            by_unit
                .values()
                .map(|activations| fit_unit(black_box(activations), &options.fit).expect("fit"))
                .collect::<Vec<_>>()
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
