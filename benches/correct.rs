//! Corrector throughput (3-axis samples per second): the paper's model beside both baselines in one
//! group, per sample and per block, so the ratios come from one run.

mod common;

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use drift_core::{
    Corrector, Extension, ExtraTerm, Model, ModifiedTables, Output, Sample, Term, AUX_INPUTS,
};

fn per_sample<M: Model>(model: &M, samples: &[Sample]) -> f32 {
    let mut corrector = Corrector::new(model).expect("valid model");
    corrector.power_on(common::SWITCH_ON_RAW).expect("power on");
    let mut sum = 0.0;
    for sample in samples {
        sum += corrector.correct(black_box(sample)).corrected_dps[0];
    }
    sum
}

/// The paper's tables plus the 4 extra terms of the test vectors' extended model.
fn extended(modified: &ModifiedTables) -> ModifiedTables {
    let term = |term, centre, coefficient| ExtraTerm {
        term,
        centre,
        coefficient,
    };
    let terms = [
        term(
            Term::TemperatureRate {
                time_constant_ms: 5000,
            },
            [0.01, 0.012, 0.008],
            [0.1, -0.08, 0.05],
        ),
        term(
            Term::Aux {
                input: 0,
                time_constant_ms: 1000,
            },
            [5.0; 3],
            [0.01, -0.012, 0.008],
        ),
        term(Term::AxisRise { axis: 0 }, [2.0; 3], [0.0, 0.002, -0.0015]),
        term(
            Term::RiseSquared,
            [6.0, 7.0, 5.0],
            [0.0003, -0.0002, 0.0001],
        ),
    ];
    let extension = Extension {
        terms: terms.into_iter().collect(),
        ..Extension::NONE
    };
    modified
        .clone()
        .with_extension(extension)
        .expect("valid extension")
}

fn per_sample_with_aux<M: Model>(model: &M, samples: &[Sample]) -> f32 {
    let mut corrector = Corrector::new(model).expect("valid model");
    corrector.power_on(common::SWITCH_ON_RAW).expect("power on");
    let aux: [f32; AUX_INPUTS] = [5.0, 0.0, 0.0, 1.0];
    let mut sum = 0.0;
    for sample in samples {
        sum += corrector
            .correct_with_aux(black_box(sample), black_box(&aux))
            .corrected_dps[0];
    }
    sum
}

fn per_block<M: Model>(model: &M, samples: &[Sample], out: &mut [Output]) -> usize {
    let mut corrector = Corrector::new(model).expect("valid model");
    corrector.power_on(common::SWITCH_ON_RAW).expect("power on");
    corrector.correct_block(black_box(samples), out)
}

fn bench(c: &mut Criterion) {
    let samples = common::activation();
    let modified = common::modified();
    let extended = extended(&modified);
    let standard = common::polynomial("standard");
    let third_order = common::polynomial("third_order");
    let mut out = vec![Output::default(); samples.len()];
    let mut group = c.benchmark_group("correct_2min_activation");
    group.throughput(Throughput::Elements(samples.len() as u64));
    group.sample_size(20);
    group.bench_function(BenchmarkId::new("per_sample", "modified"), |b| {
        b.iter(|| per_sample(&modified, &samples))
    });
    group.bench_function(BenchmarkId::new("per_sample", "extended"), |b| {
        b.iter(|| per_sample_with_aux(&extended, &samples))
    });
    group.bench_function(BenchmarkId::new("per_sample", "standard"), |b| {
        b.iter(|| per_sample(&standard, &samples))
    });
    group.bench_function(BenchmarkId::new("per_sample", "third_order"), |b| {
        b.iter(|| per_sample(&third_order, &samples))
    });
    group.bench_function(BenchmarkId::new("per_block", "modified"), |b| {
        b.iter(|| per_block(&modified, &samples, &mut out))
    });
    group.bench_function(BenchmarkId::new("per_block", "standard"), |b| {
        b.iter(|| per_block(&standard, &samples, &mut out))
    });
    group.bench_function(BenchmarkId::new("per_block", "third_order"), |b| {
        b.iter(|| per_block(&third_order, &samples, &mut out))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
