//! Corrector throughput (3-axis samples per second): the paper's model beside both baselines in one
//! group, per sample and per block, so the ratios come from one run.

mod common;

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use drift_core::{Corrector, Model, Output, Sample};

fn per_sample<M: Model>(model: &M, samples: &[Sample]) -> f32 {
    let mut corrector = Corrector::new(model).expect("valid model");
    corrector.power_on(common::SWITCH_ON_RAW).expect("power on");
    let mut sum = 0.0;
    for sample in samples {
        sum += corrector.correct(black_box(sample)).corrected_dps[0];
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
    let standard = common::polynomial("standard");
    let third_order = common::polynomial("third_order");
    let mut out = vec![Output::default(); samples.len()];
    let mut group = c.benchmark_group("correct_2min_activation");
    group.throughput(Throughput::Elements(samples.len() as u64));
    group.sample_size(20);
    group.bench_function(BenchmarkId::new("per_sample", "modified"), |b| {
        b.iter(|| per_sample(&modified, &samples))
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
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
